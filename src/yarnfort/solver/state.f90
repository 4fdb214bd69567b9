! SPDX-License-Identifier: MIT
!> A converged state of the net (positions, tensions, reactions), filled from unknowns and
!> reference lengths.
module yarnfort_solver_state
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_scene_scene, only: scene_type, get_applied_force
    use yarnfort_assembly_assemble, only: assemble_internal_force
    use yarnfort_solver_newton, only: newton_stats_type
    implicit none
    private

    public :: step_state_type, fill_step_state

    !> A converged state of the net.
    type :: step_state_type
        integer :: step = 0
        real(wp) :: time = 0.0_wp
        !> Factors of the load channels (scene%path%channel).
        real(wp), allocatable :: factors(:)
        !> Node positions (3, n_nodes), element tension, stretch and reference length.
        real(wp), allocatable :: position(:, :), tension(:), stretch(:), length0(:)
        !> Force applied by each support set on the net, (3, n_supports).
        real(wp), allocatable :: reaction(:, :)
        !> The same per prescribed coordinate: the force on coordinate
        !> scene%supports(s)%coordinates(i), for s = 1, 2, ... and i in order, concatenated.
        real(wp), allocatable :: coordinate_reaction(:)
        !> Periodic cell: sum over nodes of (force on the node) (x) (its lattice vector),
        !> (3, 3), N m; the forces conjugate to the period vectors (yarnfort_solver_membrane).
        real(wp) :: virial(3, 3) = 0.0_wp
        !> Figures of the step's (last) Newton solve; total Newton iterations of the step.
        type(newton_stats_type) :: newton
        integer :: newton_iterations = 0
        !> Friction: passages that slipped in this step, and all sliding passages.
        integer :: n_slipping = 0, n_passages = 0
        !> Friction: passages held in stick by chatter damping in this step (their mode
        !> flipped too often; each ended within its limit, else the step failed).
        integer :: n_held = 0
        !> Friction: the viscous steps of the jump the step ended in after a slip
        !> instability (the rounds settled at no step size; friction_stepper try_jump),
        !> 0 for a step without a jump.
        integer :: jump_steps = 0
        !> 1 while the load factors grow, -1 while they shrink, 0 at rest.
        integer :: direction = 0
        !> Step cuts before this step converged, and its wall time in seconds.
        integer :: step_cuts = 0
        real(wp) :: wall_time = 0.0_wp
    end type step_state_type

contains

    !> The state of the net for position unknowns u (the first n_unknowns entries are
    !> used), reference lengths length0 and the load channels' factors.
    subroutine fill_step_state(scene, u, length0, factors, state, error)
        type(scene_type), intent(in) :: scene
        real(wp), intent(in) :: u(:), length0(:), factors(:)
        type(step_state_type), intent(inout) :: state
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: internal(:), applied(:)
        integer :: s, i, k, n_elements, n_coordinates, first

        n_elements = scene%network%n_elements()
        state%factors = factors
        if (.not. allocated(state%position)) then
            allocate(state%position(3, scene%network%n_nodes()))
            allocate(state%tension(n_elements), state%stretch(n_elements))
        end if
        state%length0 = length0
        call scene%dofs%expand(u(1:scene%dofs%n_unknowns), factors, state%position)
        allocate(internal(3 * scene%network%n_nodes()), applied(3 * scene%network%n_nodes()))
        call assemble_internal_force(scene, state%position, length0, internal, state%tension, &
            state%stretch, error)
        if (allocated(error)) return
        call get_applied_force(scene, factors, applied)
        internal = internal - applied
        if (allocated(state%reaction)) deallocate(state%reaction)
        allocate(state%reaction(3, size(scene%supports)), source=0.0_wp)
        if (allocated(state%coordinate_reaction)) deallocate(state%coordinate_reaction)
        n_coordinates = 0
        do s = 1, size(scene%supports)
            n_coordinates = n_coordinates + size(scene%supports(s)%coordinates)
        end do
        allocate(state%coordinate_reaction(n_coordinates))
        n_coordinates = 0
        do s = 1, size(scene%supports)
            associate(set => scene%supports(s))
                ! The reaction of a prescribed coordinate is the force on it and on every
                ! coordinate that follows it (its prescribed value moves them all).
                first = n_coordinates
                do i = 1, size(set%coordinates)
                    n_coordinates = n_coordinates + 1
                    state%coordinate_reaction(n_coordinates) = internal(set%coordinates(i))
                end do
                if (allocated(set%followers)) then
                    do i = 1, size(set%followers)
                        state%coordinate_reaction(first + set%follows(i)) = &
                            state%coordinate_reaction(first + set%follows(i)) &
                            + internal(set%followers(i))
                    end do
                end if
                do i = 1, size(set%coordinates)
                    k = mod(set%coordinates(i) - 1, 3) + 1
                    state%reaction(k, s) = state%reaction(k, s) &
                        + state%coordinate_reaction(first + i)
                end do
            end associate
            if (.not. all(ieee_is_finite(state%reaction(:, s)))) then
                call fatal_error(error, "the reaction of support set '" &
                    // trim(scene%supports(s)%name) // "' is not a finite number (its " &
                    // "tensions add up beyond double precision: the force law's scale is " &
                    // 'too large)')
                return
            end if
        end do
        state%virial = 0.0_wp
        if (scene%periodic_cell) then
            do i = 1, size(scene%cell_lattice, 2)
                if (all(scene%cell_lattice(:, i) == 0.0_wp)) cycle
                do k = 1, 3
                    state%virial(:, k) = state%virial(:, k) &
                        + internal(3 * i - 2:3 * i) * scene%cell_lattice(k, i)
                end do
            end do
        end if
        if (scene%fabric_set > 0) then
            if (.not. ieee_is_finite(state%reaction(1, scene%fabric_set) &
                    / scene%fabric_width)) then
                call fatal_error(error, 'the force per width of the fabric is not a finite ' &
                    // "number (the force law's scale is too large for double precision)")
                return
            end if
        end if
    end subroutine fill_step_state

end module yarnfort_solver_state
