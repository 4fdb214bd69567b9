! SPDX-License-Identifier: MIT
!> Load steps without sliding: one Newton solve of the equilibrium per step.
module yarnfort_solver_elastic_stepper
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_solver_newton, only: newton_solver_type, new_newton_solver, newton_stats_type
    use yarnfort_solver_elastic_problem, only: elastic_problem_type, new_elastic_problem
    use yarnfort_solver_stepper, only: load_stepper_type, step_state_type
    use yarnfort_solver_state, only: fill_step_state
    use yarnfort_solver_restart, only: restart_type, stepper_elastic
    implicit none
    private

    public :: elastic_stepper_type, new_elastic_stepper

    type, extends(load_stepper_type) :: elastic_stepper_type
        type(scene_type), pointer :: scene => null()
        type(elastic_problem_type), pointer :: problem => null()
        type(newton_solver_type) :: newton
        !> Accepted and trial unknowns and load factors.
        real(wp), allocatable :: u(:), u_trial(:)
        real(wp), allocatable :: factors(:), factors_trial(:)
    contains
        procedure :: try_step
        procedure :: accept
        procedure :: get_state
        procedure :: save_state
        procedure :: restore_state
        final :: finalize
    end type elastic_stepper_type

contains

    subroutine new_elastic_stepper(self, scene, linear, error)
        type(elastic_stepper_type), intent(out) :: self
        type(scene_type), target, intent(in) :: scene
        class(linear_solver_type), allocatable, intent(inout) :: linear
        type(error_type), allocatable, intent(out) :: error

        self%scene => scene
        allocate(self%problem)
        call new_elastic_problem(self%problem, scene)
        call new_newton_solver(self%newton, self%problem, linear, scene%solver, error)
        if (allocated(error)) return
        allocate(self%u(scene%dofs%n_unknowns))
        call scene%dofs%restrict(scene%network%position, self%u)
        self%u_trial = self%u
        allocate(self%factors(scene%path%n_channels()), source=0.0_wp)
        self%factors_trial = self%factors
    end subroutine new_elastic_stepper

    subroutine try_step(self, factors, stats, iterations, error)
        class(elastic_stepper_type), intent(inout) :: self
        real(wp), intent(in) :: factors(:)
        type(newton_stats_type), intent(out) :: stats
        integer, intent(out) :: iterations
        type(error_type), allocatable, intent(out) :: error

        self%problem%factors = factors
        self%u_trial = self%u
        call self%newton%solve(self%u_trial, stats, error)
        iterations = stats%iterations
        self%factors_trial = factors
    end subroutine try_step

    subroutine accept(self)
        class(elastic_stepper_type), intent(inout) :: self
        self%u = self%u_trial
        self%factors = self%factors_trial
    end subroutine accept

    subroutine get_state(self, state, error)
        class(elastic_stepper_type), intent(inout) :: self
        type(step_state_type), intent(inout) :: state
        type(error_type), allocatable, intent(out) :: error
        call fill_step_state(self%scene, self%u, self%problem%length0, self%factors, state, &
            error)
    end subroutine get_state

    subroutine save_state(self, snapshot)
        class(elastic_stepper_type), intent(in) :: self
        type(restart_type), intent(inout) :: snapshot

        snapshot%stepper = stepper_elastic
        snapshot%factors = self%factors
        snapshot%u = self%u
        snapshot%length0 = self%problem%length0
    end subroutine save_state

    !> The reference lengths never change without sliding: the snapshot's must be the
    !> scene's, bit for bit.
    subroutine restore_state(self, snapshot, error)
        class(elastic_stepper_type), intent(inout) :: self
        type(restart_type), intent(in) :: snapshot
        type(error_type), allocatable, intent(out) :: error

        if (snapshot%stepper /= stepper_elastic) then
            call fatal_error(error, "the restart file was written by a run with sliding " &
                // "passages, this scene has none")
            return
        end if
        if (size(snapshot%u) /= size(self%u) .or. &
                size(snapshot%length0) /= size(self%problem%length0)) then
            call fatal_error(error, 'the restart file does not match the scene: other sizes')
            return
        end if
        if (any(snapshot%length0 /= self%problem%length0)) then
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
    end subroutine restore_state

    subroutine finalize(self)
        type(elastic_stepper_type), intent(inout) :: self
        call self%newton%destroy()
        if (associated(self%problem)) deallocate(self%problem)
    end subroutine finalize

end module yarnfort_solver_elastic_stepper
