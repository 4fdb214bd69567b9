! SPDX-License-Identifier: MIT
!> Load steps without sliding: one Newton solve of the equilibrium per step.
module yarnfort_solver_elastic_stepper
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_solver_newton, only: newton_solver_type, new_newton_solver, newton_stats_type
    use yarnfort_solver_elastic_problem, only: elastic_problem_type, new_elastic_problem
    use yarnfort_solver_stepper, only: load_stepper_type, start_stepper
    implicit none
    private

    public :: elastic_stepper_type, new_elastic_stepper

    type, extends(load_stepper_type) :: elastic_stepper_type
        type(elastic_problem_type), pointer :: problem => null()
        type(newton_solver_type) :: newton
    contains
        procedure :: try_step
        final :: finalize
    end type elastic_stepper_type

contains

    subroutine new_elastic_stepper(self, scene, linear, error)
        type(elastic_stepper_type), intent(out) :: self
        type(scene_type), target, intent(in) :: scene
        class(linear_solver_type), allocatable, intent(inout) :: linear
        type(error_type), allocatable, intent(out) :: error

        call start_stepper(self, scene)
        allocate(self%problem)
        call new_elastic_problem(self%problem, scene)
        call new_newton_solver(self%newton, self%problem, linear, scene%solver, error)
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

    subroutine finalize(self)
        type(elastic_stepper_type), intent(inout) :: self
        call self%newton%destroy()
        if (associated(self%problem)) deallocate(self%problem)
    end subroutine finalize

end module yarnfort_solver_elastic_stepper
