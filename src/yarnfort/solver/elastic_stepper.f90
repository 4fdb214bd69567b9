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
        real(wp) :: p_force = 0.0_wp, p_disp = 0.0_wp
        real(wp) :: p_force_trial = 0.0_wp, p_disp_trial = 0.0_wp
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
    end subroutine new_elastic_stepper

    subroutine try_step(self, p_force, p_disp, stats, iterations, error)
        class(elastic_stepper_type), intent(inout) :: self
        real(wp), intent(in) :: p_force, p_disp
        type(newton_stats_type), intent(out) :: stats
        integer, intent(out) :: iterations
        type(error_type), allocatable, intent(out) :: error

        self%problem%p_force = p_force
        self%problem%p_disp = p_disp
        self%u_trial = self%u
        call self%newton%solve(self%u_trial, stats, error)
        iterations = stats%iterations
        self%p_force_trial = p_force
        self%p_disp_trial = p_disp
    end subroutine try_step

    subroutine accept(self)
        class(elastic_stepper_type), intent(inout) :: self
        self%u = self%u_trial
        self%p_force = self%p_force_trial
        self%p_disp = self%p_disp_trial
    end subroutine accept

    subroutine get_state(self, state, error)
        class(elastic_stepper_type), intent(inout) :: self
        type(step_state_type), intent(inout) :: state
        type(error_type), allocatable, intent(out) :: error
        call fill_step_state(self%scene, self%u, self%problem%length0, self%p_force, &
            self%p_disp, state, error)
    end subroutine get_state

    subroutine save_state(self, snapshot)
        class(elastic_stepper_type), intent(in) :: self
        type(restart_type), intent(inout) :: snapshot

        snapshot%stepper = stepper_elastic
        snapshot%p_force = self%p_force
        snapshot%p_disp = self%p_disp
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
        self%u = snapshot%u
        self%u_trial = snapshot%u
        self%p_force = snapshot%p_force
        self%p_disp = snapshot%p_disp
        self%p_force_trial = snapshot%p_force
        self%p_disp_trial = snapshot%p_disp
    end subroutine restore_state

    subroutine finalize(self)
        type(elastic_stepper_type), intent(inout) :: self
        call self%newton%destroy()
        if (associated(self%problem)) deallocate(self%problem)
    end subroutine finalize

end module yarnfort_solver_elastic_stepper
