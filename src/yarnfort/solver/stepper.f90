! SPDX-License-Identifier: MIT
!> What the continuation needs from a load-step solver: try a step to new load factors
!> from the last accepted state, accept it, and report the accepted state.
module yarnfort_solver_stepper
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_solver_newton, only: newton_stats_type
    use yarnfort_solver_restart, only: restart_type
    implicit none
    private

    public :: load_stepper_type, step_state_type

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
        !> Figures of the step's (last) Newton solve; total Newton iterations of the step.
        type(newton_stats_type) :: newton
        integer :: newton_iterations = 0
        !> Friction: passages that slipped in this step, and all sliding passages.
        integer :: n_slipping = 0, n_passages = 0
        !> Friction: passages held in stick by chatter damping in this step (their mode
        !> flipped too often; each ended within its limit, else the step failed).
        integer :: n_held = 0
        !> 1 while the load factors grow, -1 while they shrink, 0 at rest.
        integer :: direction = 0
        !> Step cuts before this step converged, and its wall time in seconds.
        integer :: step_cuts = 0
        real(wp) :: wall_time = 0.0_wp
    end type step_state_type

    type, abstract :: load_stepper_type
    contains
        !> Solve for the channels' factors from the last accepted state (which stays as is).
        procedure(try_step_interface), deferred :: try_step
        !> Make the last successful trial the accepted state.
        procedure(accept_interface), deferred :: accept
        !> The accepted state (positions, tensions, reactions, friction counts).
        procedure(get_state_interface), deferred :: get_state
        !> Put the accepted state in a restart snapshot (its stepper part).
        procedure(save_state_interface), deferred :: save_state
        !> Make a snapshot's stepper part the accepted state; fails if it does not fit.
        procedure(restore_state_interface), deferred :: restore_state
    end type load_stepper_type

    abstract interface
        subroutine try_step_interface(self, factors, stats, iterations, error)
            import :: load_stepper_type, wp, newton_stats_type, error_type
            class(load_stepper_type), intent(inout) :: self
            real(wp), intent(in) :: factors(:)
            type(newton_stats_type), intent(out) :: stats
            integer, intent(out) :: iterations
            type(error_type), allocatable, intent(out) :: error
        end subroutine try_step_interface

        subroutine accept_interface(self)
            import :: load_stepper_type
            class(load_stepper_type), intent(inout) :: self
        end subroutine accept_interface

        subroutine get_state_interface(self, state, error)
            import :: load_stepper_type, step_state_type, error_type
            class(load_stepper_type), intent(inout) :: self
            type(step_state_type), intent(inout) :: state
            type(error_type), allocatable, intent(out) :: error
        end subroutine get_state_interface

        subroutine save_state_interface(self, snapshot)
            import :: load_stepper_type, restart_type
            class(load_stepper_type), intent(in) :: self
            type(restart_type), intent(inout) :: snapshot
        end subroutine save_state_interface

        subroutine restore_state_interface(self, snapshot, error)
            import :: load_stepper_type, restart_type, error_type
            class(load_stepper_type), intent(inout) :: self
            type(restart_type), intent(in) :: snapshot
            type(error_type), allocatable, intent(out) :: error
        end subroutine restore_state_interface
    end interface

end module yarnfort_solver_stepper
