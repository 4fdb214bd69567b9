! SPDX-License-Identifier: MIT
!> Equilibrium with sliding at contact nodes for a fixed stick/slip active set. The
!> unknowns are the free coordinates and one flow s per passage (or the flows alone,
!> with positions frozen, for the sliding step of the staggered scheme). Rows:
!>   coordinates: P^T (internal force(x, L0(s)) - p_force * external force);
!>   stick passage: k (s - s_target), k = the scene's largest force / length_scale;
!>   slip forward (T_after > T_before, s grows):    T_crit(T_before, alpha) - T_after;
!>   slip backward (T_before > T_after, s shrinks): T_before - T_crit(T_after, alpha).
!> Tensions enter the friction conditions as max(T, 0) (a slack string pulls nothing).
!> Each slip row is divided by w = max(1, dT_crit/dT_min), fixed per Newton solve
!> (`prepare_solve`): unweighted, T_min's rounding times dT_crit/dT_min keeps the row
!> above the tolerance once exp(mu alpha) is large (docs/decisions.md, 'Friction slip
!> rows weighted per solve'). Rows are judged (get_row_levels) against the forces at
!> their node, the passage's larger tension / w (slip) or the largest force (stick).
!> `locked` forbids a direction (minimum reference length reached, or chatter damping).
!> The active set is the stepper's (yarnfort_contact_friction_stepper); modes chosen at
!> every evaluation were not kept (docs/decisions.md, 'Not kept: semismooth Newton for
!> the slip modes').
!> Viscous slip (`viscosity` > 0, set only by the stepper's slip-instability jump) adds
!> eta (s - s_start) to each slip row: implicit Euler steps of a viscoplastic slip law,
!> well posed where the rate-independent law has no consistent active set.
!> The tangent (never the residual) of each slip row gets neutral_shift times its
!> largest flow derivative on its own flow, so that Newton does not move along a
!> neutral mode of a slipping set by rounding (docs/decisions.md, 'Neutral slip sets').
module yarnfort_contact_friction_problem
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: format_short
    use yarnfort_scene_scene, only: scene_type, get_applied_force, get_loaded_nodes, &
        get_force_scale
    use yarnfort_assembly_truss, only: get_truss_tension, capped_stiffness
    use yarnfort_assembly_pattern, only: build_clique_pattern
    use yarnfort_assembly_assemble, only: assemble_internal_force, add_element_tangents
    use yarnfort_assembly_scales, only: gather_node_force_levels, get_unknown_levels, &
        node_level_floor
    use yarnfort_contact_wrap_angle, only: get_wrap_angle
    use yarnfort_solver_problem, only: nonlinear_problem_type, regularisation_type, chosen_law
    implicit none
    private

    public :: friction_problem_type, new_friction_problem
    public :: mode_stick, mode_forward, mode_backward, locked_both, node_level_floor

    integer, parameter :: mode_stick = 0, mode_forward = 1, mode_backward = -1
    !> Value of `locked` that holds a passage in stick (chatter damping).
    integer, parameter :: locked_both = 2

    !> Shift of a slip row's own-flow derivative in the Jacobian (not the residual), in
    !> units of the row's largest flow derivative (module notes: neutral modes).
    real(wp), parameter :: neutral_shift = 1.0e-12_wp
    !> Smallest sin(gamma) used in the derivative of the wrap angle (see get_wrap_angle).
    real(wp), parameter :: min_sine = 1.0e-8_wp
    !> A slack string within this of stretch 1 sits at the kink of max(T, 0) (round-off
    !> of length / L0 for a string at its reference length).
    real(wp), parameter :: kink_round_off = 8 * epsilon(1.0_wp)

    type, extends(nonlinear_problem_type) :: friction_problem_type
        !> Flows are the only unknowns; positions come from `u_frozen`.
        logical :: positions_frozen = .false.
        integer :: n_x = 0, n_p = 0
        !> Active set: mode of each passage, and the flow a stick passage keeps.
        integer, allocatable :: mode(:)
        real(wp), allocatable :: flow_target(:)
        !> Divisor of each slip row, fixed per Newton solve (module notes).
        real(wp), allocatable :: slip_weight(:)
        !> Viscous slip, in units of stick_scale (module notes; 0: the exact law).
        real(wp) :: viscosity = 0.0_wp
        !> Direction a passage may not slip in (mode_forward or mode_backward), both
        !> (locked_both), or 0.
        integer, allocatable :: locked(:)
        !> Position unknowns used while positions are frozen.
        real(wp), allocatable :: u_frozen(:)
        real(wp) :: stick_scale = 1.0_wp
        !> Cliques: element [6 coordinates, flow at start, flow at end]; passage
        !> [coordinates of the node before, the node, the node after, own flow, flow at
        !> the start of the element before, flow at the end of the element after].
        integer, allocatable :: element_slot(:, :, :), passage_slot(:, :, :)
        !> The slots the Jacobian fills, packed after keep_used_entries (the clique
        !> tables above are then freed): each element's 6x6 tangent (element slots
        !> (1:6, 1:6)) and its flow columns ((1:6, 7:8)), each passage's row ((10, 1:12)).
        !> Contiguous per element and passage: read from the clique tables, the
        !> Jacobian's scatter touched a cache line per entry of a passage row.
        integer, allocatable :: tangent_slot(:, :, :), flow_slot(:, :, :), row_slot(:, :)
        integer, allocatable :: element_clique(:, :), passage_clique(:, :)
        !> Work arrays (besides x and length0).
        real(wp), allocatable :: internal(:), tension(:), stretch(:)
        !> Rounding error of each element's tension at that state (the row levels' noise).
        real(wp), allocatable :: rounding(:)
        !> Each element's d(force on node 2)/dL0, from the Jacobian's element tangents.
        real(wp), allocatable :: dforce_dl0(:, :)
        !> The loaded nodes and their channels' force magnitudes (get_loaded_nodes).
        integer, allocatable :: loaded(:)
        real(wp), allocatable :: load_magnitude(:, :)
        !> The positions' prescribed part (dofs%get_prescribed) and the applied forces
        !> (3 * n_nodes) at the factors they were taken at (set_load): they change once
        !> per load step, the unknowns at every iterate.
        real(wp), allocatable :: x_prescribed(:, :), applied(:), load_factors(:)
        !> What the work arrays were last computed from (update_state): the unknowns, the
        !> frozen positions, the load factors, the law's spring weight and cap. A solve asks
        !> for the same state several times (initial guess, row levels, the last iterate,
        !> the solution check, the stepper's active-set test); it is computed once.
        logical :: state_valid = .false.
        real(wp), allocatable :: state_u(:), state_u_frozen(:), state_factors(:)
        real(wp) :: state_spring = 0.0_wp, state_stiffness_cap = 0.0_wp
        !> Each slipping passage's tensions, wrap angle and its gradient, and its row's
        !> critical tension, at the state of the last update_state and for the mode
        !> slip_mode(p) they were taken in (mode_stick: not taken): the row levels, the
        !> residual and the Jacobian at one iterate share them (take_slip_row).
        integer, allocatable :: slip_mode(:)
        real(wp), allocatable :: slip_before(:), slip_after(:), slip_angle(:), &
            slip_dangle(:, :, :), slip_critical(:), slip_dcrit_dt(:), slip_dcrit_da(:)
    contains
        procedure :: get_size
        procedure :: evaluate_residual
        procedure :: evaluate_jacobian
        procedure :: prepare_solve
        procedure :: check_solution
        procedure :: get_row_levels
        !> Largest force of the scene at the current state (update_state).
        procedure :: get_force_level
        !> Rounding error of an element's tension at the current state.
        procedure :: get_element_noise
        !> Split unknowns into position unknowns and flows; set the work arrays (with
        !> `law`, default the exact law).
        procedure :: update_state
        !> Tensions (clipped at 0) on both sides and the wrap angle of passage p.
        procedure :: get_passage_state
    end type friction_problem_type

contains

    subroutine new_friction_problem(self, scene, positions_frozen)
        type(friction_problem_type), intent(out) :: self
        type(scene_type), target, intent(in) :: scene
        logical, intent(in) :: positions_frozen
        integer :: e, p, a, k, n_elements, node

        self%scene => scene
        self%positions_frozen = positions_frozen
        self%n_x = scene%dofs%n_unknowns
        self%n_p = scene%passages%size()
        self%length_scale = scene%length_scale
        self%stick_scale = 1.0_wp / scene%length_scale
        n_elements = scene%network%n_elements()
        allocate(self%factors(scene%path%n_channels()), source=0.0_wp)
        allocate(self%mode(self%n_p), source=mode_stick)
        allocate(self%locked(self%n_p), source=0)
        allocate(self%flow_target(self%n_p), source=0.0_wp)
        allocate(self%slip_weight(self%n_p), source=1.0_wp)
        allocate(self%slip_mode(self%n_p), source=mode_stick)
        allocate(self%slip_before(self%n_p), self%slip_after(self%n_p), &
            self%slip_angle(self%n_p), self%slip_dangle(3, 3, self%n_p), &
            self%slip_critical(self%n_p), self%slip_dcrit_dt(self%n_p), &
            self%slip_dcrit_da(self%n_p))
        allocate(self%u_frozen(self%n_x), source=0.0_wp)
        allocate(self%x(3, scene%network%n_nodes()), self%length0(n_elements))
        allocate(self%internal(3 * scene%network%n_nodes()))
        allocate(self%tension(n_elements), self%stretch(n_elements), self%rounding(n_elements))
        allocate(self%dforce_dl0(3, n_elements))
        call get_loaded_nodes(scene, self%loaded, self%load_magnitude)

        allocate(self%element_clique(8, n_elements), source=0)
        do e = 1, n_elements
            do a = 1, 2
                node = scene%network%element_nodes(a, e)
                do k = 1, 3
                    self%element_clique(3 * (a - 1) + k, e) = x_column(node, k)
                end do
            end do
            self%element_clique(7, e) = s_column(scene%passages%at_start(e))
            self%element_clique(8, e) = s_column(scene%passages%at_end(e))
        end do
        allocate(self%passage_clique(12, self%n_p), source=0)
        do p = 1, self%n_p
            associate(before => scene%passages%element_before(p), &
                    after => scene%passages%element_after(p))
                do k = 1, 3
                    self%passage_clique(k, p) = x_column(scene%network%element_nodes(1, before), k)
                    self%passage_clique(3 + k, p) = x_column(scene%passages%node(p), k)
                    self%passage_clique(6 + k, p) = x_column(scene%network%element_nodes(2, after), k)
                end do
                self%passage_clique(10, p) = s_column(p)
                self%passage_clique(11, p) = s_column(scene%passages%at_start(before))
                self%passage_clique(12, p) = s_column(scene%passages%at_end(after))
            end associate
        end do
        block
            integer, allocatable :: cliques(:, :), slots(:, :, :)
            allocate(cliques(12, n_elements + self%n_p), source=0)
            cliques(1:8, 1:n_elements) = self%element_clique
            cliques(:, n_elements + 1:) = self%passage_clique
            call build_clique_pattern(self%get_size(), cliques, self%col_ptr, &
                self%row_index, slots)
            self%element_slot = slots(1:8, 1:8, 1:n_elements)
            self%passage_slot = slots(:, :, n_elements + 1:)
        end block
        call keep_used_entries(self)
        self%tangent_slot = self%element_slot(1:6, 1:6, :)
        self%flow_slot = self%element_slot(1:6, 7:8, :)
        self%row_slot = self%passage_slot(10, :, :)
        deallocate(self%element_slot, self%passage_slot)
    contains
        integer function x_column(node, k)
            integer, intent(in) :: node, k
            x_column = 0
            if (.not. positions_frozen) x_column = scene%dofs%unknown(3 * (node - 1) + k)
        end function x_column

        integer function s_column(passage)
            integer, intent(in) :: passage
            s_column = 0
            if (passage == 0) return
            s_column = passage
            if (.not. positions_frozen) s_column = passage + scene%dofs%n_unknowns
        end function s_column
    end subroutine new_friction_problem

    !> Drop the entries of the clique pattern that the Jacobian never fills. The cliques
    !> are symmetric, the Jacobian is not: a coordinate row has entries in the columns
    !> of its elements' coordinates and of the flows that change their reference lengths
    !> (element slots (1:6, 1:8)), a passage row in the columns of its clique (passage
    !> slots (10, 1:12)); every other clique entry stays an exact zero, and a
    !> factorisation treats a stored zero as a nonzero. Measured on the woven net of
    !> benchmarks/bench_friction (2.4e3 unknowns, final active set, KLU with AMD): the
    !> full cliques store 3.5e4 entries, 39 % of them zeros (also the exact zeros of the
    !> aligned elastic tangent), and give factors of 7.9e4 nonzeros and 2.9e6 flops.
    subroutine keep_used_entries(self)
        type(friction_problem_type), intent(inout) :: self
        logical, allocatable :: used(:)
        integer, allocatable :: new_slot(:)
        integer(ik), allocatable :: col_ptr(:)
        integer :: j, k, n, kept

        allocate(used(size(self%row_index)), source=.false.)
        call mark(self%element_slot(1:6, :, :))
        call mark(self%passage_slot(10:10, :, :))
        n = self%get_size()
        do j = 1, n
            ! The diagonal always stays (the pseudo-transient shift lands there).
            do k = int(self%col_ptr(j)) + 1, int(self%col_ptr(j + 1))
                if (self%row_index(k) == j - 1) used(k) = .true.
            end do
        end do
        allocate(new_slot(0:size(used)), source=0)
        allocate(col_ptr(n + 1))
        col_ptr(1) = 0
        kept = 0
        do j = 1, n
            do k = int(self%col_ptr(j)) + 1, int(self%col_ptr(j + 1))
                if (.not. used(k)) cycle
                kept = kept + 1
                new_slot(k) = kept
            end do
            col_ptr(j + 1) = kept
        end do
        self%row_index = pack(self%row_index, used)
        call move_alloc(col_ptr, self%col_ptr)
        self%element_slot = reshape(new_slot(pack(self%element_slot, .true.)), &
            shape(self%element_slot))
        self%passage_slot = reshape(new_slot(pack(self%passage_slot, .true.)), &
            shape(self%passage_slot))
    contains
        subroutine mark(slots)
            integer, intent(in) :: slots(:, :, :)
            integer :: a, b, c
            do c = 1, size(slots, 3)
                do b = 1, size(slots, 2)
                    do a = 1, size(slots, 1)
                        if (slots(a, b, c) > 0) used(slots(a, b, c)) = .true.
                    end do
                end do
            end do
        end subroutine mark
    end subroutine keep_used_entries

    pure integer function get_size(self)
        class(friction_problem_type), intent(in) :: self
        get_size = self%n_p
        if (.not. self%positions_frozen) get_size = self%n_x + self%n_p
    end function get_size

    !> Positions, reference lengths, internal forces and tensions for unknowns u.
    subroutine update_state(self, u, error, law)
        class(friction_problem_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        type(error_type), allocatable, intent(out) :: error
        type(regularisation_type), intent(in), optional :: law
        type(regularisation_type) :: used

        used = chosen_law(law)
        if (self%state_valid) then
            if (self%state_spring == used%spring .and. all(self%state_u == u) &
                    .and. self%state_stiffness_cap == used%stiffness_cap &
                    .and. all(self%state_factors == self%factors)) then
                if (.not. self%positions_frozen) return
                if (all(self%state_u_frozen == self%u_frozen)) return
            end if
        end if
        self%state_valid = .false.
        self%slip_mode = mode_stick
        associate(scene => self%scene)
            call set_load(self)
            ! dofs%expand, with the prescribed part kept.
            self%x = self%x_prescribed
            if (self%positions_frozen) then
                call scene%dofs%add_unknowns(self%u_frozen, self%x)
                call scene%passages%get_length0(scene%network%length0, u, self%length0)
            else
                call scene%dofs%add_unknowns(u(1:self%n_x), self%x)
                call scene%passages%get_length0(scene%network%length0, u(self%n_x + 1:), &
                    self%length0)
            end if
            call assemble_internal_force(scene, self%x, self%length0, self%internal, &
                self%tension, self%stretch, error, used%spring, self%rounding, &
                used%stiffness_cap)
        end associate
        if (allocated(error)) return
        self%state_valid = size(u) == self%get_size()
        self%state_u = u
        self%state_factors = self%factors
        self%state_spring = used%spring
        self%state_stiffness_cap = used%stiffness_cap
        if (self%positions_frozen) self%state_u_frozen = self%u_frozen
    end subroutine update_state

    !> The prescribed positions and the applied forces at the current factors.
    subroutine set_load(self)
        class(friction_problem_type), intent(inout) :: self

        if (allocated(self%load_factors)) then
            if (all(self%load_factors == self%factors)) return
        end if
        self%load_factors = self%factors
        if (.not. allocated(self%x_prescribed)) allocate(self%x_prescribed, mold=self%x)
        if (.not. allocated(self%applied)) allocate(self%applied, mold=self%internal)
        call self%scene%dofs%get_prescribed(self%factors, self%x_prescribed)
        call get_applied_force(self%scene, self%factors, self%applied)
    end subroutine set_load

    pure subroutine get_passage_state(self, p, tension_before, tension_after, angle, dangle)
        class(friction_problem_type), intent(in) :: self
        integer, intent(in) :: p
        real(wp), intent(out) :: tension_before, tension_after, angle
        real(wp), intent(out), optional :: dangle(3, 3)
        real(wp) :: work(3, 3)

        associate(net => self%scene%network, passages => self%scene%passages)
            tension_before = max(self%tension(passages%element_before(p)), 0.0_wp)
            tension_after = max(self%tension(passages%element_after(p)), 0.0_wp)
            call get_wrap_angle(self%x(:, net%element_nodes(1, passages%element_before(p))), &
                self%x(:, passages%node(p)), &
                self%x(:, net%element_nodes(2, passages%element_after(p))), min_sine, &
                angle, work)
            if (present(dangle)) dangle = work
        end associate
    end subroutine get_passage_state

    !> Passage p's slip quantities (the slip_* arrays) at the state of the last
    !> update_state, for its mode (a slip mode), taken once per state and mode: the
    !> critical tension of the side that is the minimum in that mode.
    subroutine take_slip_row(self, p)
        type(friction_problem_type), intent(inout) :: self
        integer, intent(in) :: p
        real(wp) :: t_min

        if (self%slip_mode(p) == self%mode(p)) return
        call self%get_passage_state(p, self%slip_before(p), self%slip_after(p), &
            self%slip_angle(p), self%slip_dangle(:, :, p))
        t_min = merge(self%slip_before(p), self%slip_after(p), self%mode(p) == mode_forward)
        call self%scene%friction(self%scene%passages%law(p))%law%get_critical_tension( &
            t_min, self%slip_angle(p), self%slip_critical(p), self%slip_dcrit_dt(p), &
            self%slip_dcrit_da(p))
        self%slip_mode(p) = self%mode(p)
    end subroutine take_slip_row

    !> Reject a solution whose flows leave an element a reference length <= 0. Newton's
    !> iterates may pass there (forbidding it made KINSOL's five step halvings too few on
    !> test_friction's bollard), but a string with L0 <= 0 counts as slack, so such a
    !> state can satisfy the equations spuriously (measured: a flow through a pin that
    !> overshot to L0 = -7 m "converged" with zero tension on both sides instead of the
    !> slip solution; the stepper then locked the passage at its minimum length). The
    !> failed solve makes the step be retried (fewer new slips, or a shorter step).
    subroutine check_solution(self, u, error, law)
        class(friction_problem_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        type(error_type), allocatable, intent(out) :: error
        type(regularisation_type), intent(in), optional :: law
        integer :: e
        character(len=160) :: buffer

        call self%update_state(u, error, law)
        if (allocated(error)) return
        if (all(self%length0 > 0.0_wp)) return
        e = findloc(self%length0 > 0.0_wp, .false., dim=1)
        write(buffer, '("Newton converged to a spurious state: sliding left element ", i0, &
            &" a reference length of ", a)') e, format_short(self%length0(e), 4)
        call fatal_error(error, trim(buffer))
    end subroutine check_solution

    !> Fix the slip rows' weights w = max(1, dT_crit/dT_min) at the initial guess u.
    subroutine prepare_solve(self, u, error, law)
        class(friction_problem_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        type(error_type), allocatable, intent(out) :: error
        type(regularisation_type), intent(in), optional :: law
        integer :: p

        self%slip_weight = 1.0_wp
        call self%update_state(u, error, law)
        if (allocated(error)) return
        ! Stick rows in units of the scene's forces (it only scales the rows).
        self%stick_scale = self%get_force_level() / self%length_scale
        if (.not. (self%stick_scale > 0.0_wp)) self%stick_scale = 1.0_wp / self%length_scale
        if (all(self%mode == mode_stick)) return
        do p = 1, self%n_p
            if (self%mode(p) == mode_stick) cycle
            call take_slip_row(self, p)
            self%slip_weight(p) = max(1.0_wp, self%slip_dcrit_dt(p))
        end do
    end subroutine prepare_solve

    !> Largest force of the scene at the state of the last update_state: the largest
    !> tension and the largest applied nodal force.
    real(wp) function get_force_level(self) result(level)
        class(friction_problem_type), intent(in) :: self
        integer :: k
        level = maxval([0.0_wp, abs(self%tension)])
        ! At the other nodes the applied force's scale is 0 (get_loaded_nodes).
        do k = 1, size(self%loaded)
            level = max(level, get_force_scale(self%factors, self%load_magnitude(:, k)))
        end do
    end function get_force_level

    !> Coordinate rows: the forces meeting at their node. Stick rows k (s - s_target):
    !> the largest force (a flow to residual_tolerance * length_scale). Slip rows
    !> (T_crit - T_hi) / w: the passage's larger tension / w, floored like the nodes,
    !> and the rounding of T_crit - T_hi.
    subroutine get_row_levels(self, u, level, noise, error, law)
        class(friction_problem_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        real(wp), intent(out) :: level(:), noise(:)
        type(error_type), allocatable, intent(out) :: error
        type(regularisation_type), intent(in), optional :: law
        real(wp), allocatable :: node_level(:), node_noise(:)
        real(wp) :: max_force, noise_lo, noise_hi
        integer :: p, row, lo, hi

        call self%update_state(u, error, law)
        if (allocated(error)) return
        allocate(node_level(self%scene%network%n_nodes()), node_noise(self%scene%network%n_nodes()))
        ! From the tensions and their rounding at this state (update_state), not evaluated
        ! again: a second loop over the elements cost 6-8 % of a woven cycle (docs/
        ! decisions.md, 'Row levels from the state's tensions').
        call gather_node_force_levels(self%scene, self%tension, self%rounding, self%factors, &
            self%loaded, self%load_magnitude, node_level, node_noise, max_force)
        row = 0
        if (.not. self%positions_frozen) then
            call get_unknown_levels(self%scene, node_level, node_noise, level(1:self%n_x), &
                noise(1:self%n_x))
            row = self%n_x
        end if
        do p = 1, self%n_p
            noise(row + p) = 0.0_wp
            if (self%mode(p) == mode_stick) then
                level(row + p) = self%stick_scale * self%length_scale
                cycle
            end if
            call take_slip_row(self, p)
            if (self%mode(p) == mode_forward) then
                lo = self%scene%passages%element_before(p)
                hi = self%scene%passages%element_after(p)
            else
                lo = self%scene%passages%element_after(p)
                hi = self%scene%passages%element_before(p)
            end if
            level(row + p) = max(self%slip_before(p), self%slip_after(p), &
                node_level_floor * max_force) / self%slip_weight(p)
            noise_lo = self%get_element_noise(lo)
            noise_hi = self%get_element_noise(hi)
            noise(row + p) = (abs(self%slip_dcrit_dt(p)) * noise_lo + noise_hi) &
                / self%slip_weight(p)
        end do
    end subroutine get_row_levels

    !> Rounding error of element e's tension at the state of the last update_state.
    pure real(wp) function get_element_noise(self, e) result(noise)
        class(friction_problem_type), intent(in) :: self
        integer, intent(in) :: e
        noise = self%rounding(e)
    end function get_element_noise

    subroutine evaluate_residual(self, u, values, error, law)
        class(friction_problem_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        real(wp), intent(out) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        type(regularisation_type), intent(in), optional :: law
        integer :: p, row
        real(wp) :: flow

        call self%update_state(u, error, law)
        if (allocated(error)) return
        row = 0
        if (.not. self%positions_frozen) then
            ! The applied forces at these factors: update_state (set_load).
            call self%scene%dofs%gather(self%internal - self%applied, values(1:self%n_x))
            row = self%n_x
        end if
        do p = 1, self%n_p
            flow = u(row + p)
            select case (self%mode(p))
            case (mode_stick)
                values(row + p) = self%stick_scale * (flow - self%flow_target(p))
            case (mode_forward)
                call take_slip_row(self, p)
                values(row + p) = (self%slip_critical(p) - self%slip_after(p) &
                    + self%viscosity * self%stick_scale * (flow - self%flow_target(p))) &
                    / self%slip_weight(p)
            case (mode_backward)
                call take_slip_row(self, p)
                values(row + p) = (self%slip_before(p) - self%slip_critical(p) &
                    + self%viscosity * self%stick_scale * (flow - self%flow_target(p))) &
                    / self%slip_weight(p)
            end select
        end do
    end subroutine evaluate_residual

    subroutine evaluate_jacobian(self, u, values, error, law)
        class(friction_problem_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        real(wp), intent(out) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        type(regularisation_type), intent(in), optional :: law
        integer :: e, p, a, b, slot
        real(wp) :: dforce_dl0(3)
        type(regularisation_type) :: used

        used = chosen_law(law)
        call self%update_state(u, error, law)
        if (allocated(error)) return
        values = 0.0_wp
        associate(scene => self%scene, net => self%scene%network)
            if (.not. self%positions_frozen) then
                ! Dependence on L0: d(force on node 2)/dL0 = c dT/dL0, dT/dL0 = -T' l/L0^2,
                ! from the tangents' own evaluation of each element.
                call add_element_tangents(scene, self%tangent_slot, self%x, self%length0, &
                    values, error, used%spring, used%tangent_spring, self%dforce_dl0, &
                    used%stiffness_cap)
                if (allocated(error)) return
                do e = 1, net%n_elements()
                    ! L0 changes by share(e) times the flows bounding its segment.
                    dforce_dl0 = self%dforce_dl0(:, e) * scene%passages%share(e)
                    do b = 7, 8
                        do a = 1, 6
                            slot = self%flow_slot(a, b - 6, e)
                            if (slot == 0) cycle
                            ! L0 grows with the flow at its start, shrinks with the one at its end.
                            values(slot) = values(slot) + merge(1.0_wp, -1.0_wp, b == 7) &
                                * merge(-1.0_wp, 1.0_wp, a <= 3) * dforce_dl0(mod(a - 1, 3) + 1)
                        end do
                    end do
                end do
            end if
            do p = 1, self%n_p
                call add_passage_row(p)
            end do
        end associate
    contains
        !> Derivatives of passage p's row with respect to its clique's unknowns.
        subroutine add_passage_row(p)
            integer, intent(in) :: p
            real(wp) :: row(12), d_before(12), d_after(12)
            integer :: k

            if (self%mode(p) == mode_stick) then
                slot = self%row_slot(10, p)
                values(slot) = values(slot) + self%stick_scale
                return
            end if
            call take_slip_row(self, p)
            call tension_derivative(self%scene%passages%element_before(p), 1, 11, 10, d_before)
            call tension_derivative(self%scene%passages%element_after(p), 4, 10, 12, d_after)
            associate(dcrit_dt => self%slip_dcrit_dt(p), dcrit_da => self%slip_dcrit_da(p), &
                    dangle => self%slip_dangle(:, :, p))
                if (self%mode(p) == mode_forward) then
                    row = dcrit_dt * d_before - d_after
                    row(1:9) = row(1:9) + dcrit_da * reshape(dangle, [9])
                else
                    row = d_before - dcrit_dt * d_after
                    row(1:9) = row(1:9) - dcrit_da * reshape(dangle, [9])
                end if
            end associate
            row(10) = row(10) + self%viscosity * self%stick_scale
            row = row / self%slip_weight(p)
            ! Tangent only: neutral modes (module notes).
            row(10) = row(10) + sign(neutral_shift * maxval(abs(row(10:12))), row(10))
            do k = 1, 12
                slot = self%row_slot(k, p)
                if (slot /= 0) values(slot) = values(slot) + row(k)
            end do
        end subroutine add_passage_row

        !> Gradient of max(T_e, 0) over the passage clique: element e's first node sits at
        !> clique coordinates first..first+2 and its second node at first+3..first+5; the
        !> flows at its start and end sit at members start_slot and end_slot.
        subroutine tension_derivative(e, first, start_slot, end_slot, gradient)
            integer, intent(in) :: e, first, start_slot, end_slot
            real(wp), intent(out) :: gradient(12)
            real(wp) :: t, dt, c(3), length, lambda

            gradient = 0.0_wp
            associate(net => self%scene%network)
                length = norm2(self%x(:, net%element_nodes(2, e)) - self%x(:, net%element_nodes(1, e)))
                c = (self%x(:, net%element_nodes(2, e)) - self%x(:, net%element_nodes(1, e))) / length
                lambda = length / self%length0(e)
                if (self%tension(e) <= 0.0_wp) then
                    ! Slack: max(T, 0) is flat, except at its kink lambda = 1 (a string at
                    ! its reference length with slack_stiffness = 0, e.g. every string of
                    ! the stress-free start). There the taut side's slope is taken: the
                    ! low-tension side of a slipping passage is pulled taut by the flow,
                    ! and the flat side's 0 drops T_crit's dependence on it from the
                    ! Jacobian (with a large mu the first Newton step then overshoots the
                    ! flow by the factor exp(mu alpha), and the line search fails).
                    if (abs(lambda - 1.0_wp) > kink_round_off) return
                    t = 0.0_wp
                    dt = capped_stiffness(self%scene%laws(net%element_material(e))%law, &
                        used%stiffness_cap)
                else
                    call get_truss_tension(self%scene%laws(net%element_material(e))%law, &
                        used%spring, lambda, t, dt, used%stiffness_cap)
                end if
                gradient(first:first + 2) = -dt / self%length0(e) * c
                gradient(first + 3:first + 5) = dt / self%length0(e) * c
                gradient(start_slot) = gradient(start_slot) &
                    - dt * lambda / self%length0(e) * self%scene%passages%share(e)
                gradient(end_slot) = gradient(end_slot) &
                    + dt * lambda / self%length0(e) * self%scene%passages%share(e)
            end associate
        end subroutine tension_derivative
    end subroutine evaluate_jacobian

end module yarnfort_contact_friction_problem
