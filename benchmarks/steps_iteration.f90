! SPDX-License-Identifier: MIT
!> One Newton iteration's CPU time (residual, Jacobian, factorisation and solve) of a
!> problem at a given state: the unit of the friction benchmarks' step costs
!> (benchmarks/bench_friction, benchmarks/steps_trace).
module bench_iteration
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_problem, only: nonlinear_problem_type
    use yarnfort_solver_elastic_problem, only: elastic_problem_type, new_elastic_problem
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_factory, only: new_linear_solver
    use bench_common, only: fail
    implicit none
    private

    public :: time_iteration, time_elastic_iteration

contains

    !> CPU ms of residual + Jacobian (times(1)) and factorisation + solve (times(2)),
    !> the mean of repetitions filling about 0.3 s; `program_name` for a failure.
    subroutine time_iteration(problem, solver, u, values, residual, times, program_name, &
            failure)
        class(nonlinear_problem_type), intent(inout) :: problem
        class(linear_solver_type), intent(inout) :: solver
        real(wp), intent(in) :: u(:)
        real(wp), intent(inout) :: values(:), residual(:)
        real(wp), intent(out) :: times(2)
        character(len=*), intent(in) :: program_name
        !> Where given, a failed factorisation or solve (a Jacobian singular at `u`, e.g.
        !> with slack elements) comes back here instead of stopping the program.
        type(error_type), allocatable, intent(out), optional :: failure
        type(error_type), allocatable :: error
        real(wp) :: t0, t1, t2
        integer :: repetitions

        times = 0.0_wp
        repetitions = 0
        call cpu_time(t0)
        t2 = t0
        do while (t2 - t0 < 0.3_wp .or. repetitions < 3)
            call cpu_time(t1)
            call problem%evaluate_residual(u, residual, error)
            if (allocated(error)) call fail(program_name, error)
            call problem%evaluate_jacobian(u, values, error)
            if (allocated(error)) call fail(program_name, error)
            call cpu_time(t2)
            times(1) = times(1) + (t2 - t1)
            call solver%factor(values, error)
            if (.not. allocated(error)) call solver%solve(residual, error)
            if (allocated(error)) then
                if (.not. present(failure)) call fail(program_name, error)
                call move_alloc(error, failure)
                return
            end if
            call cpu_time(t1)
            times(2) = times(2) + (t1 - t2)
            t2 = t1
            repetitions = repetitions + 1
        end do
        times = 1e3_wp * times / repetitions
    end subroutine time_iteration

    !> CPU ms of one elastic Newton iteration of `scene` at positions `u`, reference
    !> lengths from the passages' `flow` and load factors `factors`, with the linear
    !> solver `linear_name`.
    real(wp) function time_elastic_iteration(scene, u, flow, factors, linear_name, &
            program_name) result(ms)
        type(scene_type), target, intent(in) :: scene
        real(wp), intent(in) :: u(:), flow(:), factors(:)
        character(len=*), intent(in) :: linear_name, program_name
        type(elastic_problem_type), target :: problem
        class(linear_solver_type), allocatable :: solver
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        real(wp), allocatable :: values(:), residual(:)
        real(wp) :: times(2)
        type(error_type), allocatable :: error

        call new_elastic_problem(problem, scene)
        call scene%passages%get_length0(scene%network%length0, flow, problem%length0)
        problem%factors = factors
        call new_linear_solver(solver, linear_name, error)
        if (allocated(error)) call fail(program_name, error)
        allocate(col_ptr(problem%get_size() + 1), row_index(problem%get_nonzeros()))
        call problem%copy_pattern(col_ptr, row_index)
        call solver%analyse(int(problem%get_size(), ik), col_ptr, row_index, error)
        if (allocated(error)) call fail(program_name, error)
        allocate(values(problem%get_nonzeros()), residual(problem%get_size()))
        call time_iteration(problem, solver, u, values, residual, times, program_name)
        ms = sum(times)
        call solver%destroy()
    end function time_elastic_iteration

end module bench_iteration
