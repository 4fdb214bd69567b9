! SPDX-License-Identifier: MIT
!> What the continuation needs from a load-step solver: try a step to new load factors
!> from the last accepted state, accept it, and report the accepted state. The base type
!> holds what every stepper shares (the scene, accepted and trial positions and factors,
!> the snapshot's common part) and serves, by default, a stepper without sliding.
module yarnfort_solver_stepper
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_newton, only: newton_stats_type
    use yarnfort_solver_restart, only: restart_type, stepper_elastic
    use yarnfort_solver_state, only: step_state_type, fill_step_state
    implicit none
    private

    public :: load_stepper_type, step_state_type, start_stepper, accept_trial, save_common, &
        restore_common

    type, abstract :: load_stepper_type
        !> The scene (which must outlive the stepper).
        type(scene_type), pointer :: scene => null()
        !> Accepted and trial position unknowns and load factors.
        real(wp), allocatable :: u(:), u_trial(:), factors(:), factors_trial(:)
    contains
        !> Solve for the channels' factors from the last accepted state (which stays as is).
        procedure(try_step_interface), deferred :: try_step
        !> After a step failed at every step size: try to reach the load factors by a
        !> jump (a non-quasi-static path to an equilibrium of the exact model), if the
        !> stepper has one for the way the step failed (`attempted`). Default: none.
        procedure :: try_jump
        !> Make the last successful trial the accepted state (default: u and factors).
        procedure :: accept => accept_trial
        !> The Newton iterations by which the step-size control judges the last successful
        !> try_step, given all it used; default: all of them.
        procedure :: growth_iterations
        !> The accepted state (positions, tensions, reactions, friction counts); default:
        !> without sliding, the reference lengths of the scene.
        procedure :: get_state
        !> Put the accepted state in a restart snapshot (its stepper part); default:
        !> without sliding (save_common).
        procedure :: save_state
        !> Make a snapshot's stepper part the accepted state; fails if it does not fit.
        !> Default: without sliding (restore_common).
        procedure :: restore_state
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

    !> The default: no jump.
    subroutine try_jump(self, factors, stats, iterations, attempted, error)
        class(load_stepper_type), intent(inout) :: self
        real(wp), intent(in) :: factors(:)
        type(newton_stats_type), intent(out) :: stats
        integer, intent(out) :: iterations
        logical, intent(out) :: attempted
        type(error_type), allocatable, intent(out) :: error
        iterations = 0
        attempted = .false.
    end subroutine try_jump

    !> The default: the step is judged by all its iterations.
    pure integer function growth_iterations(self, iterations) result(n)
        class(load_stepper_type), intent(in) :: self
        integer, intent(in) :: iterations

        n = iterations
    end function growth_iterations

    subroutine accept_trial(self)
        class(load_stepper_type), intent(inout) :: self
        self%u = self%u_trial
        self%factors = self%factors_trial
    end subroutine accept_trial

    subroutine get_state(self, state, error)
        class(load_stepper_type), intent(inout) :: self
        type(step_state_type), intent(inout) :: state
        type(error_type), allocatable, intent(out) :: error
        call fill_step_state(self%scene, self%u, self%scene%network%length0, self%factors, &
            state, error)
    end subroutine get_state

    subroutine save_state(self, snapshot)
        class(load_stepper_type), intent(in) :: self
        type(restart_type), intent(inout) :: snapshot
        call save_common(self, snapshot, stepper_elastic)
    end subroutine save_state

    !> The reference lengths never change without sliding: the snapshot's must be the
    !> scene's, bit for bit.
    subroutine restore_state(self, snapshot, error)
        class(load_stepper_type), intent(inout) :: self
        type(restart_type), intent(in) :: snapshot
        type(error_type), allocatable, intent(out) :: error
        call restore_common(self, snapshot, stepper_elastic, 'the restart file was written ' &
            // 'by a run with sliding passages, this scene has none', error)
    end subroutine restore_state

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
