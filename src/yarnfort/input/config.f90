! SPDX-License-Identifier: MIT
!> What the user asked for, as read from the namelist input, before any scene is built.
!> Plain data with defaults; units are SI (N, m) unless a unit is given.
!> Reading is in yarnfort_input_namelist; building the scene from it is in yarnfort_scene.
module yarnfort_input_config
    use yarnfort_kinds, only: wp
    implicit none
    private

    public :: config_type, control_config_type, solver_config_type, material_config_type
    public :: yarn_config_type, support_config_type, load_config_type, path_config_type
    public :: output_config_type, geometry_config_type, name_length, path_length
    public :: contact_config_type, fabric_config_type, link_config_type
    public :: solver_presets, get_solver_preset

    integer, parameter :: name_length = 64
    integer, parameter :: path_length = 512

    !> Values of &solver preset: 'custom' keeps the defaults of solver_config_type, the
    !> others set those of initial_step, max_step, residual_tolerance and scheme to values
    !> chosen from the speed-accuracy study (verification/speed_accuracy; get_solver_preset).
    character(len=*), parameter :: solver_presets(*) = [character(len=8) :: 'custom', &
        'fast', 'balanced', 'accurate']

    !> &control: what the run is.
    type :: control_config_type
        character(len=256) :: title = ''
        !> Stop after reading and checking the input (no solve, no output).
        logical :: check_only = .false.
        !> Continue from the restart file of the &output folder (its last converged step)
        !> instead of starting at the first knot.
        logical :: restart = .false.
        !> Stop after this many converged load steps of this run (0: no limit); a later
        !> run with restart = .true. goes on from there.
        integer :: max_steps = 0
    end type control_config_type

    !> &solver: nonlinear and linear solver settings, continuation step control.
    type :: solver_config_type
        !> 'auto', 'umfpack', 'klu', 'cholmod' or 'dense'.
        character(len=16) :: linear_solver = 'auto'
        !> Relative: Newton stops when every row has |F_i| <= residual_tolerance *
        !> level_i + noise_i (the forces meeting at the row's node, the rounding of its
        !> evaluation; yarnfort_solver_newton). No material stiffness enters.
        real(wp) :: residual_tolerance = 1.0e-10_wp
        !> Newton also stops when the scaled step is below this (then checked against
        !> the residual tolerance, never accepted alone).
        real(wp) :: step_tolerance = 1.0e-14_wp
        integer :: max_iterations = 50
        !> Newton iterations between Jacobian updates (1 = full Newton).
        integer :: max_setup_calls = 1
        !> Full Newton steps first; a failed solve is repeated with a line search.
        logical :: line_search = .true.
        !> Regularisation of the Newton solve, never of the answer: a weak spring of rest
        !> length L0/2, slack_stiffness * k_ref (k_ref the law's reference stiffness), in
        !> the tangent of slack strings, and in the model of a predictor solve when the
        !> exact one fails (then corrected with the exact law). 0 switches it off.
        real(wp) :: slack_stiffness = 1.0e-6_wp
        !> Continuation: first, smallest and largest step, as fractions of the knot
        !> interval being followed.
        real(wp) :: initial_step = 0.1_wp
        real(wp) :: min_step = 1.0e-6_wp
        real(wp) :: max_step = 0.25_wp
        !> Step growth factor after easy convergence and cut factor after a failure.
        real(wp) :: step_growth = 1.5_wp
        real(wp) :: step_cut = 0.5_wp
        !> A step converged in at most this many Newton iterations is "easy".
        integer :: easy_iterations = 4
        !> Give up after this many consecutive step cuts.
        integer :: max_step_cuts = 30
        !> Friction: 'monolithic' (positions and sliding solved together with a
        !> stick/slip active set) or 'staggered' (the paper's two-step scheme).
        character(len=16) :: scheme = 'monolithic'
        !> Friction: most stick/slip active-set updates (monolithic) or elastic/sliding
        !> alternations (staggered) per load step.
        integer :: max_friction_iterations = 200
        !> Friction: sliding never makes an element's reference length shorter than this
        !> fraction of its initial length (the passage then locks in that direction).
        !> Much shorter elements make the wrap angle ill-conditioned: on the woven
        !> benchmark net, elements at 1 % of their length stalled Newton.
        real(wp) :: min_length_ratio = 0.05_wp
        !> Friction: relative slack in the stick test T_max <= T_crit (1 + tol) + band,
        !> band = 10 times the uncertainty of the passage's own tensions at convergence.
        real(wp) :: friction_tolerance = 1.0e-9_wp
        !> Named defaults of initial_step, max_step, residual_tolerance and scheme (one of
        !> solver_presets); a variable set in &solver overrides its preset value.
        character(len=16) :: preset = 'custom'
    end type solver_config_type

    !> &material: one yarn type and its force law (one group per yarn type).
    type :: material_config_type
        character(len=name_length) :: name = ''
        !> 'linear', 'neo_hookean' or 'table'.
        character(len=16) :: law = ''
        !> linear: EA in N.
        real(wp) :: stiffness = -1.0_wp
        !> neo_hookean: modulus C in Pa and undeformed cross-section S(1) in m^2.
        real(wp) :: modulus = -1.0_wp
        real(wp) :: area = -1.0_wp
        !> table: CSV file of (strain, force in N), relative to the input file's folder
        !> or the working directory.
        character(len=path_length) :: table_file = ''
        !> Pre-stress (N): the tension every element of this yarn type carries in the
        !> initial geometry; its reference length L0 is chosen so (0: stress-free).
        real(wp) :: prestress = 0.0_wp
    end type material_config_type

    !> &yarn: one yarn, a polyline through node ids, split into elements.
    type :: yarn_config_type
        character(len=name_length) :: material = ''
        integer, allocatable :: nodes(:)
        !> Each segment between listed nodes is split into this many elements.
        integer :: elements_per_segment = 1
    end type yarn_config_type

    !> &support: a named set of nodes whose listed components are prescribed.
    type :: support_config_type
        character(len=name_length) :: name = ''
        integer, allocatable :: nodes(:)
        !> Which components are prescribed: any of 'x', 'y', 'z'.
        character(len=3) :: fix = 'xyz'
        !> Displacement D at load factor p_disp = 1 (m), per component.
        real(wp) :: displacement(3) = 0.0_wp
    end type support_config_type

    !> &load: a force P (N) at load factor p_force = 1 on each listed node.
    type :: load_config_type
        integer, allocatable :: nodes(:)
        real(wp) :: force(3) = 0.0_wp
    end type load_config_type

    !> &path: the load path as knots over pseudo-time, linear in between.
    type :: path_config_type
        real(wp), allocatable :: time(:)
        real(wp), allocatable :: p_force(:)
        real(wp), allocatable :: p_disp(:)
    end type path_config_type

    !> &geometry: node positions and yarns from a plain text file instead of &nodes and
    !> &yarn groups (format in inputs/REFERENCE.md).
    type :: geometry_config_type
        !> Geometry file; a relative name is resolved against `config_type%input_folder`.
        !> Empty: no geometry file.
        character(len=path_length) :: file = ''
    end type geometry_config_type

    !> &output: where and what to write.
    type :: output_config_type
        character(len=path_length) :: folder = 'out'
        !> Write a VTK state every this many converged steps (0: none; the last step is
        !> always written when vtk_every > 0).
        integer :: vtk_every = 1
        !> Encoding of the VTK data: 'binary' (appended, base64) or 'ascii' (inline).
        character(len=8) :: vtk_format = 'binary'
        !> Progress lines on stderr.
        logical :: progress = .true.
        !> Also print each step's Newton residual history (scaled max-norm per iterate).
        logical :: residual_history = .false.
    end type output_config_type

    !> &fabric: a generated fabric (knitted with inlay, or woven) instead of &nodes,
    !> &yarn and &support groups. Geometry and parameters: inputs/REFERENCE.md.
    type :: fabric_config_type
        !> 'knit' (weft-knitted jersey, optional inlay), 'plain' or 'twill' (woven).
        character(len=16) :: kind = ''
        !> Repeats along x and y: wales x courses (knit); weft x warp yarns (woven).
        integer :: cells(2) = [4, 4]
        !> Repeat spacing along x and y (m): wale and course spacing; weft and warp
        !> yarn spacing.
        real(wp) :: spacing(2) = -1.0_wp
        !> 'periodic' (a unit cell, eq. 53, with a macroscopic stretch) or 'clamped' (a
        !> finite sample: left edge fixed, right edge pulled).
        character(len=16) :: boundary = 'periodic'
        !> Engineering strain along x at p_disp = 1 (1.0 stretches to twice the length).
        real(wp) :: strain = 1.0_wp
        !> Periodic: engineering strain of the y period at p_disp = 1 (prescribed).
        real(wp) :: lateral_strain = 0.0_wp
        !> Clamped: 'free' side edges, or 'rollers' (side-edge yarn ends held in y).
        character(len=16) :: sides = 'free'
        !> Elements per yarn segment between generated nodes.
        integer :: elements_per_segment = 1
        !> Knit: yarn type of the loops and of the inlay ('' = no inlay).
        character(len=name_length) :: knit_material = ''
        character(len=name_length) :: inlay_material = ''
        !> Knit: width of a loop's head between its two contacts, as a fraction of the
        !> wale spacing (the sinker between loops takes the rest). In this polygon model
        !> a loop is 2*spacing(2) + spacing(1) long.
        real(wp) :: head_width = 0.5_wp
        !> Knit: an inlay yarn in every inlay_every-th course, crossing the loop legs at
        !> inlay_offset * spacing(2) above the course line and the sinkers on it.
        integer :: inlay_every = 1
        real(wp) :: inlay_offset = 0.5_wp
        !> Woven: yarn types along x (warp, the loaded direction) and y (weft).
        character(len=name_length) :: warp_material = ''
        character(len=name_length) :: weft_material = ''
        !> Woven: distance between warp and weft axes at a crossing (m), kept by a
        !> gap-holder (paper Fig. 12).
        real(wp) :: gap = -1.0_wp
        !> Woven: gap factor (multiplies gap) as a piecewise-linear function of the
        !> displacement factor p_disp (paper Fig. 13b). Empty: factor 1.
        real(wp), allocatable :: gap_factor_p_disp(:)
        real(wp), allocatable :: gap_factor(:)
    end type fabric_config_type

    !> A node that follows another one: a periodic image (eq. 53) or the other side of
    !> a gap-holder. Made by the fabric generators.
    type :: link_config_type
        integer :: follower = 0
        integer :: leader = 0
        !> follower = leader + offset + p_disp * strain * offset (componentwise), with
        !> offset the initial difference of their positions; a gap link scales the
        !> offset by the gap factor instead.
        real(wp) :: strain(3) = 0.0_wp
        logical :: gap = .false.
    end type link_config_type

    !> The whole input.
    !> &contact: the friction law where yarns of two types cross (one group per pair;
    !> the pair is unordered and a type may pair with itself). Without any &contact
    !> group every contact node is a plain shared node (no sliding).
    type :: contact_config_type
        !> The two yarn types (material names).
        character(len=name_length) :: materials(2) = ''
        !> 'bonded' (never slides), 'coulomb', 'adhesion' or 'decaying_adhesion'.
        character(len=32) :: law = ''
        !> Friction coefficient mu (1), for every law but 'bonded'.
        real(wp) :: friction_coefficient = -1.0_wp
        !> Adhesion beta (N), for 'adhesion' and 'decaying_adhesion'.
        real(wp) :: adhesion = -1.0_wp
        !> Decaying adhesion: tension w_d (N) where the adhesion starts to decay and s_d
        !> (N) where it has vanished, 0 <= w_d < s_d.
        real(wp) :: decay_start = -1.0_wp
        real(wp) :: decay_end = -1.0_wp
    end type contact_config_type

    type :: config_type
        type(control_config_type) :: control
        type(solver_config_type) :: solver
        type(material_config_type), allocatable :: materials(:)
        !> &geometry group: a file with the nodes and yarns (then no &nodes or &yarn).
        type(geometry_config_type) :: geometry
        !> &nodes group or geometry file: node coordinates (3, n_nodes), ids 1..n_nodes.
        real(wp), allocatable :: node_positions(:, :)
        !> &yarn groups or geometry file.
        type(yarn_config_type), allocatable :: yarns(:)
        type(support_config_type), allocatable :: supports(:)
        type(load_config_type), allocatable :: loads(:)
        type(contact_config_type), allocatable :: contacts(:)
        !> &fabric group (kind = '': none) and the links its generator made.
        type(fabric_config_type) :: fabric
        type(link_config_type), allocatable :: links(:)
        !> Generated fabrics: width (m) across which the x force is carried, and the
        !> support whose x reaction is the fabric's force (0: not a fabric).
        real(wp) :: fabric_width = 0.0_wp
        integer :: fabric_support = 0
        type(path_config_type) :: path
        type(output_config_type) :: output
        !> Not a namelist variable: the folder of the input file, against which relative
        !> file names in the input are resolved ('' = the working directory, as for stdin).
        character(len=path_length) :: input_folder = ''
    end type config_type

contains

    !> The &solver defaults of preset `name` (lower case, one of solver_presets): the type's
    !> defaults with initial_step = max_step, residual_tolerance and scheme of the preset,
    !> and preset = name. The values come from verification/speed_accuracy: the error of
    !> the force curve is set by the step (pseudo-time; the example scenes have one unit
    !> per stretch or release), the tolerance only has to stay well below it, and the
    !> monolithic scheme was the faster one. `found` is false for an unknown name (then
    !> the type's defaults).
    pure subroutine get_solver_preset(name, solver, found)
        character(len=*), intent(in) :: name
        type(solver_config_type), intent(out) :: solver
        logical, intent(out) :: found
        real(wp) :: step, tolerance

        found = .true.
        solver%preset = name
        select case (name)
        case ('fast')           ! 4 steps per knot interval
            step = 0.25_wp
            tolerance = 1.0e-6_wp
        case ('balanced')       ! 20 steps per knot interval
            step = 0.05_wp
            tolerance = 1.0e-9_wp
        case ('accurate')       ! 100 steps per knot interval
            step = 0.01_wp
            tolerance = 1.0e-11_wp
        case default
            found = name == 'custom'
            return
        end select
        solver%initial_step = step
        solver%max_step = step
        solver%residual_tolerance = tolerance
        solver%scheme = 'monolithic'
    end subroutine get_solver_preset

end module yarnfort_input_config
