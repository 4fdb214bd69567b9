! SPDX-License-Identifier: MIT
!> Unit tests of the bordered solver (yarnfort_linalg_composite_bordered): a symmetric positive
!> definite block K bordered by unsymmetric rows and columns, solved through the Schur
!> complement, through the whole-matrix solver when the border is too wide, and through
!> it too when K alone is singular; the analysis of K kept across patterns; the solve of
!> several columns at once (K^-1 B) that the border uses.
module test_bordered
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    use yarnfort_testing, only: unittest_type, new_unittest, check
    use yarnfort_linalg_composite_bordered, only: bordered_solver_type
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_factory, only: new_linear_solver, chosen_lu_name
    implicit none
    private

    public :: collect_bordered

    !> Relative error of x accepted from a backward-stable solve of these small,
    !> well-conditioned systems.
    real(wp), parameter :: solution_tol = 1.0e5_wp * epsilon(1.0_wp)
    !> Order of the matrix and of its leading block.
    integer, parameter :: order = 9, n_leading = 6

contains

    subroutine collect_bordered(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)

        testsuite = [ &
            new_unittest('border through the Schur complement', test_border), &
            new_unittest('a wide border goes to the general solver', test_wide_border), &
            new_unittest('a singular leading block goes to the general solver', &
                test_singular_leading), &
            new_unittest('no border: the leading block alone', test_no_border), &
            new_unittest('a new pattern with the same leading block', test_new_pattern), &
            new_unittest('several columns at once against one by one and dense', &
                test_solve_columns), &
            new_unittest('the border against a dense solve of the whole matrix', &
                test_border_against_dense), &
            new_unittest('a failed leading block is remembered for the next patterns', &
                test_remembered_failure) &
            ]
    end subroutine collect_bordered

    !> K symmetric positive definite (diagonally dominant, coupled neighbours), the border
    !> unsymmetric and diagonally dominant; `singular` zeroes K's last row and column
    !> (the border's columns and rows still reach that unknown).
    function test_matrix(n, singular) result(a)
        integer, intent(in) :: n
        logical, intent(in) :: singular
        real(wp) :: a(n, n)
        integer :: i, j

        a = 0.0_wp
        do j = 1, n
            do i = 1, n
                if (i <= n_leading .and. j <= n_leading) then
                    if (i == j) then
                        a(i, j) = 4.0_wp + mod(i, 3)
                    else if (abs(i - j) == 1) then
                        a(i, j) = -1.0_wp
                    end if
                else if (i == j) then
                    a(i, j) = 5.0_wp + mod(i, 2)
                else
                    a(i, j) = (0.25_wp + 0.125_wp * mod(i + 2 * j, 3)) &
                        * merge(1.0_wp, -1.0_wp, i < j)
                end if
            end do
        end do
        if (singular) then
            a(n_leading, 1:n_leading) = 0.0_wp
            a(1:n_leading, n_leading) = 0.0_wp
        end if
    end function test_matrix

    !> Every entry stored (zeros too).
    subroutine to_csc(a, col_ptr, row_index, values)
        real(wp), intent(in) :: a(:, :)
        integer(ik), allocatable, intent(out) :: col_ptr(:), row_index(:)
        real(wp), allocatable, intent(out) :: values(:)
        integer :: i, j, n

        n = size(a, 1)
        allocate(col_ptr(n + 1), row_index(n * n), values(n * n))
        col_ptr(1) = 0
        do j = 1, n
            do i = 1, n
                row_index((j - 1) * n + i) = i - 1
                values((j - 1) * n + i) = a(i, j)
            end do
            col_ptr(j + 1) = j * n
        end do
    end subroutine to_csc

    !> K by `leading_name` (default CHOLMOD falling back to KLU), the whole by KLU or
    !> UMFPACK.
    subroutine new_bordered(solver, error, leading_name)
        type(bordered_solver_type), intent(out) :: solver
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in), optional :: leading_name

        solver%n_leading = n_leading
        if (present(leading_name)) then
            call new_linear_solver(solver%leading, leading_name, error)
        else
            call new_linear_solver(solver%leading, 'cholmod+klu', error)
        end if
        if (allocated(error)) return
        call new_linear_solver(solver%general, chosen_lu_name, error)
    end subroutine new_bordered

    !> Analyse, factor and solve A x = A x_known for a matrix of order n; `name` is the
    !> path taken.
    subroutine solve_known(solver, n, singular, name, error)
        type(bordered_solver_type), intent(inout) :: solver
        integer, intent(in) :: n
        logical, intent(in) :: singular
        character(len=:), allocatable, intent(out) :: name
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: a(:, :), values(:), x(:), rhs(:)
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        integer :: i

        a = test_matrix(n, singular)
        call to_csc(a, col_ptr, row_index, values)
        call solver%analyse(int(n, ik), col_ptr, row_index, error)
        if (allocated(error)) return
        call solver%factor(values, error)
        if (allocated(error)) return
        name = solver%get_name()
        x = [(real(mod(i, 5) - 2, wp) + 0.5_wp, i = 1, n)]
        rhs = matmul(a, x)
        call solver%solve(rhs, error)
        if (allocated(error)) return
        call check(error, maxval(abs(rhs - x)) <= solution_tol * maxval(abs(x)), &
            name // ': solution differs from the known x')
    end subroutine solve_known

    subroutine test_border(error)
        type(error_type), allocatable, intent(out) :: error

        call check_path(order, .false., order - n_leading, .true., error)
    end subroutine test_border

    subroutine test_wide_border(error)
        type(error_type), allocatable, intent(out) :: error

        call check_path(order, .false., order - n_leading - 1, .false., error)
    end subroutine test_wide_border

    subroutine test_singular_leading(error)
        type(error_type), allocatable, intent(out) :: error

        call check_path(order, .true., order - n_leading, .false., error)
    end subroutine test_singular_leading

    subroutine test_no_border(error)
        type(error_type), allocatable, intent(out) :: error

        call check_path(n_leading, .false., 0, .true., error)
    end subroutine test_no_border

    !> Solve a known system of order n with at most max_border border unknowns; the path
    !> taken should be the border one (border) or the general solver.
    subroutine check_path(n, singular, max_border, border, error)
        integer, intent(in) :: n, max_border
        logical, intent(in) :: singular, border
        type(error_type), allocatable, intent(out) :: error
        type(bordered_solver_type) :: solver
        character(len=:), allocatable :: name

        call new_bordered(solver, error)
        if (allocated(error)) return
        solver%max_border = max_border
        call solve_known(solver, n, singular, name, error)
        if (allocated(error)) return
        call check(error, (index(name, 'bordered+') == 1) .eqv. border, &
            'unexpected path: ' // name)
    end subroutine check_path

    !> The border changes (as the slipping flows do), K does not: right answers each time.
    subroutine test_new_pattern(error)
        type(error_type), allocatable, intent(out) :: error
        type(bordered_solver_type) :: solver
        character(len=:), allocatable :: name

        call new_bordered(solver, error)
        if (allocated(error)) return
        call solve_known(solver, order, .false., name, error)
        if (allocated(error)) return
        call solve_known(solver, order - 1, .false., name, error)
        if (allocated(error)) return
        call solve_known(solver, order, .false., name, error)
        if (allocated(error)) return
        call check(error, solver%leading_analysed, 'the leading block should stay analysed')
    end subroutine test_new_pattern

    !> K X = B for several columns: CHOLMOD's one solve of all columns (directly and
    !> through the CHOLMOD-then-KLU fallback) and the column-by-column default (KLU) give
    !> the known X, the single-column solves and the dense LAPACK solve.
    subroutine test_solve_columns(error)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), parameter :: names(3) = [character(len=11) :: 'cholmod', &
            'cholmod+klu', 'klu']
        integer, parameter :: n_columns = 4
        real(wp) :: x(n_leading, n_columns)
        real(wp), allocatable :: columns(:, :), one_by_one(:, :), dense(:, :)
        integer :: i, c, k

        do c = 1, n_columns
            x(:, c) = [(real(mod(i * c, 7) - 3, wp) + 0.25_wp * c, i = 1, n_leading)]
        end do
        call solve_leading_columns('dense', .false., x, dense, error)
        if (allocated(error)) return
        do k = 1, size(names)
            call solve_leading_columns(trim(names(k)), .true., x, columns, error)
            if (allocated(error)) return
            call solve_leading_columns(trim(names(k)), .false., x, one_by_one, error)
            if (allocated(error)) return
            call check(error, maxval(abs(columns - x)) <= solution_tol * maxval(abs(x)), &
                trim(names(k)) // ': columns differ from the known X')
            if (allocated(error)) return
            call check(error, maxval(abs(columns - one_by_one)) <= solution_tol &
                * maxval(abs(x)), trim(names(k)) // ': columns differ from single solves')
            if (allocated(error)) return
            call check(error, maxval(abs(columns - dense)) <= solution_tol * maxval(abs(x)), &
                trim(names(k)) // ': columns differ from the dense solve')
            if (allocated(error)) return
        end do
    end subroutine test_solve_columns

    !> K^-1 (K x) for the leading block K of the test matrix, by the solver `name`, all
    !> columns in one `solve_columns` or one `solve` per column.
    subroutine solve_leading_columns(name, at_once, x, solution, error)
        character(len=*), intent(in) :: name
        logical, intent(in) :: at_once
        real(wp), intent(in) :: x(:, :)
        real(wp), allocatable, intent(out) :: solution(:, :)
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: solver
        real(wp), allocatable :: a(:, :), values(:)
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        integer :: j

        a = test_matrix(n_leading, .false.)
        call to_csc(a, col_ptr, row_index, values)
        call new_linear_solver(solver, name, error)
        if (allocated(error)) return
        call solver%analyse(int(n_leading, ik), col_ptr, row_index, error)
        if (allocated(error)) return
        call solver%factor(values, error)
        if (allocated(error)) return
        solution = matmul(a, x)
        if (at_once) then
            call solver%solve_columns(solution, error)
            return
        end if
        do j = 1, size(x, 2)
            call solver%solve(solution(:, j), error)
            if (allocated(error)) return
        end do
    end subroutine solve_leading_columns

    !> The border's answer (K^-1 B in one solve) against the dense LU of the whole matrix,
    !> for every right-hand side a unit vector (the whole inverse).
    subroutine test_border_against_dense(error)
        type(error_type), allocatable, intent(out) :: error
        type(bordered_solver_type) :: solver
        class(linear_solver_type), allocatable :: dense
        real(wp), allocatable :: a(:, :), values(:), by_border(:), by_dense(:)
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        integer :: i, j

        call new_bordered(solver, error)
        if (allocated(error)) return
        call new_linear_solver(dense, 'dense', error)
        if (allocated(error)) return
        a = test_matrix(order, .false.)
        call to_csc(a, col_ptr, row_index, values)
        call solver%analyse(int(order, ik), col_ptr, row_index, error)
        if (allocated(error)) return
        call solver%factor(values, error)
        if (allocated(error)) return
        call dense%analyse(int(order, ik), col_ptr, row_index, error)
        if (allocated(error)) return
        call dense%factor(values, error)
        if (allocated(error)) return
        call check(error, index(solver%get_name(), 'bordered+') == 1, &
            'unexpected path: ' // solver%get_name())
        if (allocated(error)) return
        do j = 1, order
            by_border = [(merge(1.0_wp, 0.0_wp, i == j), i = 1, order)]
            by_dense = by_border
            call solver%solve(by_border, error)
            if (allocated(error)) return
            call dense%solve(by_dense, error)
            if (allocated(error)) return
            call check(error, maxval(abs(by_border - by_dense)) <= solution_tol &
                * maxval(abs(by_dense)), 'column of the inverse differs from the dense one')
            if (allocated(error)) return
        end do
    end subroutine test_border_against_dense

    !> K by CHOLMOD alone, singular for five patterns, then regular: each pattern solved
    !> right; K tried at the 1st, 3rd (after skipping one pattern) and 6th pattern (after
    !> two; it factors there, and the border is used again).
    subroutine test_remembered_failure(error)
        type(error_type), allocatable, intent(out) :: error
        type(bordered_solver_type) :: solver
        character(len=:), allocatable :: name
        integer, parameter :: expected_failures(6) = [1, 1, 2, 2, 2, 2]
        integer :: k

        call new_bordered(solver, error, 'cholmod')
        if (allocated(error)) return
        do k = 1, size(expected_failures)
            call solve_known(solver, order, k <= 5, name, error)
            if (allocated(error)) return
            call check(error, solver%n_leading_failures == expected_failures(k), &
                'pattern ' // achar(iachar('0') + k) // ': unexpected count of K''s failures')
            if (allocated(error)) return
            call check(error, (index(name, 'bordered+') == 1) .eqv. (k == 6), &
                'pattern ' // achar(iachar('0') + k) // ': unexpected path ' // name)
            if (allocated(error)) return
        end do
    end subroutine test_remembered_failure

end module test_bordered
