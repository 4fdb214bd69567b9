! SPDX-License-Identifier: MIT
!> Unit tests of the condensed solver (yarnfort_linalg_composite_condensed): unknowns whose rows
!> hold only their diagonal are eliminated exactly, the rest goes to KLU.
module test_condensed
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    use yarnfort_testing, only: unittest_type, new_unittest, check
    use yarnfort_linalg_composite_condensed, only: condensed_solver_type
    use yarnfort_linalg_factory, only: new_linear_solver
    implicit none
    private

    public :: collect_condensed

    !> Relative error of x accepted from a backward-stable solve of these small,
    !> well-conditioned systems.
    real(wp), parameter :: solution_tol = 1.0e5_wp * epsilon(1.0_wp)
    integer, parameter :: order = 8
    !> Unknowns first_candidate..order may be eliminated (the "flows").
    integer, parameter :: first_candidate = 6

contains

    subroutine collect_condensed(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)

        testsuite = [ &
            new_unittest('stick rows eliminated, the rest solved', test_eliminated), &
            new_unittest('a changed set is reduced again', test_changed_set), &
            new_unittest('a superset reduction is kept while the set fits', test_superset), &
            new_unittest('no row eliminated', test_none_eliminated), &
            new_unittest('every row eliminated', test_all_eliminated), &
            new_unittest('a zero candidate row is a singular matrix', test_singular), &
            new_unittest('calls out of order are errors', test_out_of_order) &
            ]
    end subroutine collect_condensed

    !> The stored pattern: a dense coupled block 1..5, every candidate column coupled
    !> to the coordinates (as a flow's column is), every candidate row to rows 1..5 and
    !> its neighbours (as a slip row is); `a` holds the values (zeros stay stored).
    subroutine to_csc(a, col_ptr, row_index, values)
        real(wp), intent(in) :: a(order, order)
        integer(ik), allocatable, intent(out) :: col_ptr(:), row_index(:)
        real(wp), allocatable, intent(out) :: values(:)
        integer :: i, j

        allocate(col_ptr(order + 1), row_index(0), values(0))
        col_ptr(1) = 0
        do j = 1, order
            do i = 1, order
                row_index = [row_index, int(i - 1, ik)]
                values = [values, a(i, j)]
            end do
            col_ptr(j + 1) = size(row_index)
        end do
    end subroutine to_csc

    !> A diagonally dominant unsymmetric matrix whose candidate rows `stick` hold only
    !> their diagonal.
    function test_matrix(stick) result(a)
        logical, intent(in) :: stick(first_candidate:order)
        real(wp) :: a(order, order)
        integer :: i, j

        do j = 1, order
            do i = 1, order
                a(i, j) = 1.0_wp / (1 + i + 2 * j) - 0.1_wp * mod(i * j, 3)
            end do
            a(j, j) = 10.0_wp + j
        end do
        do i = first_candidate, order
            if (stick(i)) then
                a(i, :) = 0.0_wp
                a(i, i) = 3.0_wp * i
            end if
        end do
    end function test_matrix

    !> Factor `a` with `solver` (analysed), solve for a known x and compare.
    subroutine check_solve(solver, a, what, error)
        type(condensed_solver_type), intent(inout) :: solver
        real(wp), intent(in) :: a(order, order)
        character(len=*), intent(in) :: what
        type(error_type), allocatable, intent(out) :: error
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        real(wp), allocatable :: values(:)
        real(wp) :: x(order), rhs(order)
        integer :: i

        x = [(real((-1)**i * i, wp), i = 1, order)]
        rhs = matmul(a, x)
        call to_csc(a, col_ptr, row_index, values)
        call solver%factor(values, error)
        if (allocated(error)) return
        call solver%solve(rhs, error)
        if (allocated(error)) return
        call check(error, maxval(abs(rhs - x)) <= solution_tol * maxval(abs(x)), &
            what // ': solution differs from the known x')
    end subroutine check_solve

    subroutine new_analysed(solver, candidate, error)
        type(condensed_solver_type), intent(out) :: solver
        integer, intent(in) :: candidate
        type(error_type), allocatable, intent(out) :: error
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        real(wp), allocatable :: values(:)

        call new_linear_solver(solver%inner, 'klu', error)
        if (allocated(error)) return
        solver%first_candidate = candidate
        call to_csc(test_matrix([.false., .false., .false.]), col_ptr, row_index, values)
        call solver%analyse(int(order, ik), col_ptr, row_index, error)
    end subroutine new_analysed

    subroutine test_eliminated(error)
        type(error_type), allocatable, intent(out) :: error
        type(condensed_solver_type) :: solver

        call new_analysed(solver, first_candidate, error)
        if (allocated(error)) return
        call check_solve(solver, test_matrix([.true., .false., .true.]), 'rows 6, 8 stick', &
            error)
        if (allocated(error)) return
        call check(error, solver%n_reduced == order - 2, 'two unknowns should be eliminated')
    end subroutine test_eliminated

    subroutine test_changed_set(error)
        type(error_type), allocatable, intent(out) :: error
        type(condensed_solver_type) :: solver

        call new_analysed(solver, first_candidate, error)
        if (allocated(error)) return
        call check_solve(solver, test_matrix([.true., .true., .true.]), 'all stick', error)
        if (allocated(error)) return
        call check_solve(solver, test_matrix([.true., .true., .true.]) * 2, &
            'all stick again', error)
        if (allocated(error)) return
        call check(error, solver%n_reductions == 1, 'the same set should not be reduced again')
        if (allocated(error)) return
        call check_solve(solver, test_matrix([.false., .true., .false.]), 'row 7 sticks', &
            error)
        if (allocated(error)) return
        call check(error, solver%n_reductions == 2 .and. solver%n_reduced == order - 1, &
            'the new set should be reduced again, one unknown eliminated')
    end subroutine test_changed_set

    !> Above superset_above kept rows, the neighbours of a non-trivial row stay too (in
    !> this dense pattern every candidate is a neighbour of every other) when
    !> superset_fraction leaves room, trivial rows kept are solved exactly, and a set
    !> that fits in the kept one needs no new reduction; at or below superset_above, or
    !> without room, the reduction is exact.
    subroutine test_superset(error)
        type(error_type), allocatable, intent(out) :: error
        type(condensed_solver_type) :: solver

        call new_analysed(solver, first_candidate, error)
        if (allocated(error)) return
        solver%superset_above = 0
        solver%superset_fraction = 1.0_wp
        call check_solve(solver, test_matrix([.true., .false., .true.]), 'row 7 slips', error)
        if (allocated(error)) return
        call check(error, solver%n_reductions == 1 .and. solver%n_reduced == order, &
            'the neighbours of row 7 (rows 6 and 8) should be kept')
        if (allocated(error)) return
        call check_solve(solver, test_matrix([.false., .true., .true.]), 'row 6 slips', error)
        if (allocated(error)) return
        call check(error, solver%n_reductions == 1, &
            'a set within the kept one should not be reduced again')
        if (allocated(error)) return
        call check_solve(solver, test_matrix([.true., .true., .true.]), 'all stick', error)
        if (allocated(error)) return
        call check(error, solver%n_reductions == 2 .and. solver%n_reduced == order - 3, &
            'no slipping row: every candidate should be eliminated')
        if (allocated(error)) return
        ! No trivial row may be kept: the exact set.
        call new_analysed(solver, first_candidate, error)
        if (allocated(error)) return
        solver%superset_above = 0
        solver%superset_fraction = 0.0_wp
        call check_solve(solver, test_matrix([.true., .false., .true.]), &
            'row 7 slips, no superset', error)
        if (allocated(error)) return
        call check(error, solver%n_reduced == order - 2, &
            'without room for trivial rows only row 7 of the candidates should be kept')
    end subroutine test_superset

    subroutine test_none_eliminated(error)
        type(error_type), allocatable, intent(out) :: error
        type(condensed_solver_type) :: solver

        call new_analysed(solver, first_candidate, error)
        if (allocated(error)) return
        call check_solve(solver, test_matrix([.false., .false., .false.]), 'none stick', error)
        if (allocated(error)) return
        ! Only candidates are eliminated, even when a row before them is trivial.
        call new_analysed(solver, order + 1, error)
        if (allocated(error)) return
        call check_solve(solver, test_matrix([.true., .true., .true.]), 'no candidates', error)
        if (allocated(error)) return
        call check(error, solver%n_reduced == order, 'no unknown may be eliminated')
    end subroutine test_none_eliminated

    subroutine test_all_eliminated(error)
        type(error_type), allocatable, intent(out) :: error
        type(condensed_solver_type) :: solver
        real(wp) :: a(order, order)
        integer :: i

        call new_analysed(solver, 1, error)
        if (allocated(error)) return
        a = 0.0_wp
        do i = 1, order
            a(i, i) = -2.0_wp * i
        end do
        call check_solve(solver, a, 'diagonal matrix', error)
        if (allocated(error)) return
        call check(error, solver%n_reduced == 0, 'every unknown should be eliminated')
    end subroutine test_all_eliminated

    subroutine test_singular(error)
        type(error_type), allocatable, intent(out) :: error
        type(condensed_solver_type) :: solver
        real(wp) :: a(order, order)
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        real(wp), allocatable :: values(:)
        logical :: failed

        call new_analysed(solver, first_candidate, error)
        if (allocated(error)) return
        a = test_matrix([.true., .true., .true.])
        a(7, 7) = 0.0_wp
        call to_csc(a, col_ptr, row_index, values)
        call solver%factor(values, error)
        failed = allocated(error)
        call check(error, failed, 'a zero row should make the factorisation fail')
    end subroutine test_singular

    subroutine test_out_of_order(error)
        type(error_type), allocatable, intent(out) :: error
        type(condensed_solver_type) :: solver
        real(wp) :: rhs(order), values(order * order)
        logical :: failed

        rhs = 1.0_wp
        values = 1.0_wp
        call solver%factor(values, error)
        failed = allocated(error)
        call check(error, failed, 'factor before analyse should fail')
        if (allocated(error)) return
        call solver%solve(rhs, error)
        failed = allocated(error)
        call check(error, failed, 'solve before factor should fail')
        if (allocated(error)) return
        call new_analysed(solver, first_candidate, error)
        if (allocated(error)) return
        call solver%solve(rhs, error)
        failed = allocated(error)
        call check(error, failed, 'solve after analyse only should fail')
    end subroutine test_out_of_order

end module test_condensed
