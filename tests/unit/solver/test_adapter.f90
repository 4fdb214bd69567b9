! SPDX-License-Identifier: MIT
!> The SUNLinearSolver adapter's factor_counted: a matrix whose factors it already holds
!> is not factored again (same factors, so the same solutions), any other values are,
!> and a new symbolic analysis drops the held factors. The 2 x 2 system
!> A = [[4, 1], [2, 3]] (det 10), b = (1, 2): x = (1/10, 6/10) by hand; with A(1,1) = 5
!> (det 13): x = (1/13, 8/13).
module test_adapter
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    use yarnfort_testing, only: unittest_type, new_unittest, check
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_factory, only: new_linear_solver
    use yarnfort_solver_sunlinsol_adapter, only: adapter_type, analyse_counted, &
        factor_counted, solve_counted
    implicit none
    private

    public :: collect_adapter

    !> Column-compressed pattern of a full 2 x 2 matrix.
    integer(ik), parameter :: col_ptr(3) = [0_ik, 2_ik, 4_ik]
    integer(ik), parameter :: row_index(4) = [0_ik, 1_ik, 0_ik, 1_ik]

contains

    subroutine collect_adapter(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)
        testsuite = [new_unittest('held_factors_not_factored_again', test_held_factors)]
    end subroutine collect_adapter

    subroutine test_held_factors(error)
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable, target :: linear
        type(adapter_type) :: adapter
        real(wp) :: a(4), x(2)

        call new_linear_solver(linear, 'klu', error)
        if (allocated(error)) return
        adapter%solver => linear
        call analyse_counted(adapter, 2_ik, col_ptr, row_index, error)
        if (allocated(error)) return
        a = [4.0_wp, 2.0_wp, 1.0_wp, 3.0_wp]
        call factor_counted(adapter, a, error)
        if (allocated(error)) return
        call factor_counted(adapter, a, error)
        if (allocated(error)) return
        call check(error, adapter%n_factorisations == 1 &
            .and. adapter%n_refactorisations_skipped == 1, 'the same values: factored once')
        if (allocated(error)) return
        x = [1.0_wp, 2.0_wp]
        call solve_counted(adapter, x, error)
        if (allocated(error)) return
        call check(error, all(abs(x - [0.1_wp, 0.6_wp]) <= 4 * epsilon(1.0_wp)), &
            'the held factors solve A x = b')
        if (allocated(error)) return

        a(1) = 5.0_wp
        call factor_counted(adapter, a, error)
        if (allocated(error)) return
        call check(error, adapter%n_factorisations == 2, 'other values: factored')
        if (allocated(error)) return
        x = [1.0_wp, 2.0_wp]
        call solve_counted(adapter, x, error)
        if (allocated(error)) return
        call check(error, all(abs(x - [1.0_wp / 13, 8.0_wp / 13]) <= 4 * epsilon(1.0_wp)), &
            'the new factors solve the new system')
        if (allocated(error)) return

        call analyse_counted(adapter, 2_ik, col_ptr, row_index, error)
        if (allocated(error)) return
        call factor_counted(adapter, a, error)
        if (allocated(error)) return
        call check(error, adapter%n_factorisations == 3 &
            .and. adapter%n_refactorisations_skipped == 1, &
            'after a new analysis the same values are factored again')
    end subroutine test_held_factors

end module test_adapter
