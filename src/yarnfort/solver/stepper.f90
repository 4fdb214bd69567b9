! SPDX-License-Identifier: MIT
!> What the continuation needs from a load-step solver: try a step to new load factors
!> from the last accepted state, accept it, and report the accepted state.
module yarnfort_solver_stepper
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_newton, only: newton_stats_type
    use yarnfort_solver_restart, only: restart_type
    implicit none
    private

    public :: load_stepper_type, step_state_type, start_stepper, accept_trial, save_common, &
        restore_common

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
        !> The scene (which must outlive the stepper).
        type(scene_type), pointer :: scene => null()
        !> Accepted and trial position unknowns and load factors.
        real(wp), allocatable :: u(:), u_trial(:), factors(:), factors_trial(:)
    contains
        !> Solve for the channels' factors from the last accepted state (which stays as is).
        procedure(try_step_interface), deferred :: try_step
        !> Make the last successful trial the accepted state (default: u and factors).
        procedure :: accept => accept_trial
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

contains

    !> The accepted and trial states of `scene`'s initial positions at load factors 0.
    subroutine start_stepper(self, scene)
        class(load_stepper_type), intent(inout) :: self
        type(scene_type), target, intent(in) :: scene

        self%scene => scene
        allocate(self%u(scene%dofs%n_unknowns))
        call scene%dofs%restrict(scene%network%position, self%u)
        self%u_trial = self%u
        allocate(self%factors(scene%path%n_channels()), source=0.0_wp)
        self%factors_trial = self%factors
    end subroutine start_stepper

    subroutine accept_trial(self)
        class(load_stepper_type), intent(inout) :: self
        self%u = self%u_trial
        self%factors = self%factors_trial
    end subroutine accept_trial

    !> The snapshot part every stepper writes: its kind, the accepted factors, position
    !> unknowns and reference lengths (those of the scene, or given by the passages'
    !> `flow`).
    subroutine save_common(self, snapshot, stepper, flow)
        class(load_stepper_type), intent(in) :: self
        type(restart_type), intent(inout) :: snapshot
        character(len=*), intent(in) :: stepper
        real(wp), intent(in), optional :: flow(:)

        snapshot%stepper = stepper
        snapshot%factors = self%factors
        snapshot%u = self%u
        call get_length0(self%scene, snapshot%length0, flow)
    end subroutine save_common

    !> Check that `snapshot` was written by a `stepper` run of this scene (else the
    !> error `other_kind`, or that of the first thing that differs: sizes, reference
    !> lengths, load channels) and take its factors and position unknowns as the
    !> accepted and trial state. With sliding passages (`n_flows` of them), the reference
    !> lengths follow from the snapshot's flows and must be its own, bit for bit.
    subroutine restore_common(self, snapshot, stepper, other_kind, error, n_flows)
        class(load_stepper_type), intent(inout) :: self
        type(restart_type), intent(in) :: snapshot
        character(len=*), intent(in) :: stepper, other_kind
        type(error_type), allocatable, intent(out) :: error
        integer, intent(in), optional :: n_flows
        real(wp), allocatable :: length0(:)
        logical :: same_sizes

        if (snapshot%stepper /= stepper) then
            call fatal_error(error, other_kind)
            return
        end if
        same_sizes = size(snapshot%u) == size(self%u) &
            .and. size(snapshot%length0) == self%scene%network%n_elements()
        if (present(n_flows)) same_sizes = same_sizes .and. size(snapshot%flow) == n_flows
        if (.not. same_sizes) then
            call fatal_error(error, 'the restart file does not match the scene: other sizes')
            return
        end if
        if (present(n_flows)) then
            call get_length0(self%scene, length0, snapshot%flow)
        else
            call get_length0(self%scene, length0)
        end if
        if (any(snapshot%length0 /= length0)) then
            call fatal_error(error, 'the restart file does not match the scene: other ' &
                // 'element reference lengths')
            return
        end if
        if (size(snapshot%factors) /= size(self%factors)) then
            call fatal_error(error, 'the restart file does not match the scene: other ' &
                // 'load channels')
            return
        end if
        ! Every check passed: a snapshot that does not fit leaves the stepper as it was.
        self%u = snapshot%u
        self%u_trial = snapshot%u
        self%factors = snapshot%factors
        self%factors_trial = snapshot%factors
    end subroutine restore_common

    !> The elements' reference lengths: the scene's, or with the passages' `flow` theirs.
    subroutine get_length0(scene, length0, flow)
        type(scene_type), intent(in) :: scene
        real(wp), allocatable, intent(inout) :: length0(:)
        real(wp), intent(in), optional :: flow(:)

        if (.not. present(flow)) then
            length0 = scene%network%length0
            return
        end if
        if (.not. allocated(length0)) allocate(length0(scene%network%n_elements()))
        call scene%passages%get_length0(scene%network%length0, flow, length0)
    end subroutine get_length0

end module yarnfort_solver_stepper
