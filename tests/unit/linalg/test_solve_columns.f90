! SPDX-License-Identifier: MIT
!> Unit tests of the solve of several right-hand sides at once (`solve_columns`) for
!> every solver type: KLU (its multi-column klu_l_solve), UMFPACK (column by column),
!> CHOLMOD, dense LAPACK, the KLU|UMFPACK choice, the condensed solver (its elimination
!> of all columns, then the inner solver's columns) with an LU or a bordered inner
!> solver, and the bordered solver with a border, with the whole matrix to `general`
!> (border too wide) and with no border unknowns. Each answer is checked against
!> LAPACK's dgesv of the dense matrix, against one `solve` per column and by its
!> residual.
module test_solve_columns
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    use yarnfort_testing, only: unittest_type, new_unittest, check
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_composite_condensed, only: condensed_solver_type
    use yarnfort_linalg_composite_bordered, only: bordered_solver_type
    use yarnfort_linalg_factory, only: new_linear_solver, chosen_lu_name
    implicit none
    private

    public :: collect_solve_columns

    !> Relative error accepted from a backward-stable solve of these small,
    !> well-conditioned systems (condition numbers below 10).
    real(wp), parameter :: solution_tol = 1.0e3_wp * epsilon(1.0_wp)
    !> Order of the matrices, of the symmetric leading block, first candidate row of the
    !> condensed solver; 6 right-hand sides (KLU solves them 4 and 2).
    integer, parameter :: order = 12, n_leading = 8, first_candidate = 9, n_columns = 6

    interface
        !> LAPACK's dense solve (the independent reference).
        subroutine dgesv(n, nrhs, a, lda, ipiv, b, ldb, info)
            import :: wp
            integer, intent(in) :: n, nrhs, lda, ldb
            real(wp), intent(inout) :: a(lda, *)
            integer, intent(out) :: ipiv(*)
            real(wp), intent(inout) :: b(ldb, *)
            integer, intent(out) :: info
        end subroutine dgesv
    end interface

contains

    subroutine collect_solve_columns(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)

        testsuite = [ &
            new_unittest('klu', test_klu), &
            new_unittest('umfpack', test_umfpack), &
            new_unittest('cholmod', test_cholmod), &
            new_unittest('dense', test_dense), &
            new_unittest('klu|umfpack', test_lu_choice), &
            new_unittest('condensed, LU inner solver', test_condensed_lu), &
            new_unittest('condensed, bordered inner solver', test_condensed_bordered), &
            new_unittest('bordered through the Schur complement', test_bordered_border), &
            new_unittest('bordered, border too wide', test_bordered_general), &
            new_unittest('bordered, no border unknowns', test_bordered_leading_only) &
            ]
    end subroutine collect_solve_columns

    subroutine test_klu(error)
        type(error_type), allocatable, intent(out) :: error
        call check_named('klu', 'bordered', error)
    end subroutine test_klu

    subroutine test_umfpack(error)
        type(error_type), allocatable, intent(out) :: error
        call check_named('umfpack', 'bordered', error)
    end subroutine test_umfpack

    subroutine test_cholmod(error)
        type(error_type), allocatable, intent(out) :: error
        call check_named('cholmod', 'spd', error)
    end subroutine test_cholmod

    subroutine test_dense(error)
        type(error_type), allocatable, intent(out) :: error
        call check_named('dense', 'bordered', error)
    end subroutine test_dense

    subroutine test_lu_choice(error)
        type(error_type), allocatable, intent(out) :: error
        call check_named(chosen_lu_name, 'bordered', error)
    end subroutine test_lu_choice

    !> The solver the factory makes under `name`, on the test matrix of `kind`.
    subroutine check_named(name, kind, error)
        character(len=*), intent(in) :: name, kind
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: solver

        call new_linear_solver(solver, name, error)
        if (allocated(error)) return
        call check_columns(solver, kind, error)
    end subroutine check_named

    !> Rows 10 and 12 eliminated, the rest (order 10) by KLU or UMFPACK.
    subroutine test_condensed_lu(error)
        type(error_type), allocatable, intent(out) :: error
        type(condensed_solver_type) :: solver

        solver%first_candidate = first_candidate
        call new_linear_solver(solver%inner, chosen_lu_name, error)
        if (allocated(error)) return
        call check_columns(solver, 'condensed', error, 'condensed+klu')
    end subroutine test_condensed_lu

    !> Rows 10 and 12 eliminated, the rest: the leading block by CHOLMOD and a border of
    !> two unknowns (the friction stepper's solver).
    subroutine test_condensed_bordered(error)
        type(error_type), allocatable, intent(out) :: error
        type(condensed_solver_type) :: solver
        type(bordered_solver_type), allocatable :: bordered

        solver%first_candidate = first_candidate
        allocate(bordered)
        call new_bordered(bordered, n_leading, error)
        if (allocated(error)) return
        call move_alloc(bordered, solver%inner)
        call check_columns(solver, 'condensed', error, 'condensed+bordered+cholmod')
    end subroutine test_condensed_bordered

    subroutine test_bordered_border(error)
        type(error_type), allocatable, intent(out) :: error
        type(bordered_solver_type) :: solver

        call new_bordered(solver, n_leading, error)
        if (allocated(error)) return
        call check_columns(solver, 'bordered', error, 'bordered+cholmod')
    end subroutine test_bordered_border

    subroutine test_bordered_general(error)
        type(error_type), allocatable, intent(out) :: error
        type(bordered_solver_type) :: solver

        call new_bordered(solver, n_leading, error)
        if (allocated(error)) return
        solver%max_border = 2
        call check_columns(solver, 'bordered', error, 'klu')
    end subroutine test_bordered_general

    subroutine test_bordered_leading_only(error)
        type(error_type), allocatable, intent(out) :: error
        type(bordered_solver_type) :: solver

        call new_bordered(solver, order, error)
        if (allocated(error)) return
        call check_columns(solver, 'spd', error, 'bordered+cholmod')
    end subroutine test_bordered_leading_only

    !> Leading block by CHOLMOD, the whole by KLU or UMFPACK.
    subroutine new_bordered(solver, leading, error)
        type(bordered_solver_type), intent(inout) :: solver
        integer, intent(in) :: leading
        type(error_type), allocatable, intent(out) :: error

        solver%n_leading = leading
        call new_linear_solver(solver%leading, 'cholmod', error)
        if (allocated(error)) return
        call new_linear_solver(solver%general, chosen_lu_name, error)
    end subroutine new_bordered

    !> The test matrices (order 12), diagonally dominant. 'spd': symmetric positive
    !> definite, couplings at distances 1 and 3. 'bordered': that on the leading 8 x 8
    !> block, the last 4 rows and columns unsymmetric and sparse. 'condensed': 'bordered'
    !> with rows 10 and 12 reduced to their diagonal (their columns still couple).
    !> `stored`: the pattern (the entries of 'bordered', or of 'spd'; zeros stay stored).
    subroutine test_matrix(kind, a, stored)
        character(len=*), intent(in) :: kind
        real(wp), intent(out) :: a(order, order)
        logical, intent(out) :: stored(order, order)
        integer :: i, j, leading

        leading = merge(order, n_leading, kind == 'spd')
        a = 0.0_wp
        do j = 1, order
            do i = 1, order
                if (i <= leading .and. j <= leading) then
                    if (i == j) then
                        a(i, j) = 5.0_wp + mod(i, 3)
                    else if (abs(i - j) == 1) then
                        a(i, j) = -1.0_wp
                    else if (abs(i - j) == 3) then
                        a(i, j) = -0.5_wp
                    end if
                else if (i == j) then
                    a(i, j) = 6.0_wp + mod(i, 2)
                else if (mod(i + 2 * j, 3) /= 0) then
                    a(i, j) = (0.25_wp + 0.125_wp * mod(i * j, 4)) &
                        * merge(1.0_wp, -1.0_wp, i < j)
                end if
            end do
        end do
        stored = a /= 0.0_wp
        if (kind == 'condensed') then
            do i = 10, order, 2
                a(i, 1:i - 1) = 0.0_wp
                a(i, i + 1:) = 0.0_wp
            end do
        end if
    end subroutine test_matrix

    !> The stored entries of `a` in CSC form (0-based rows).
    subroutine to_csc(a, stored, col_ptr, row_index, values)
        real(wp), intent(in) :: a(:, :)
        logical, intent(in) :: stored(:, :)
        integer(ik), allocatable, intent(out) :: col_ptr(:), row_index(:)
        real(wp), allocatable, intent(out) :: values(:)
        integer :: i, j, k, n

        n = size(a, 1)
        allocate(col_ptr(n + 1), row_index(count(stored)), values(count(stored)))
        col_ptr(1) = 0
        k = 0
        do j = 1, n
            do i = 1, n
                if (.not. stored(i, j)) cycle
                k = k + 1
                row_index(k) = i - 1
                values(k) = a(i, j)
            end do
            col_ptr(j + 1) = k
        end do
    end subroutine to_csc

    !> Factor the matrix `kind` with `solver` (whose name is then `name`, if given) and
    !> solve 6 right-hand sides (unit vectors and mixed ones) in one `solve_columns`:
    !> they must match LAPACK's dgesv, one `solve` per column, and leave a small residual.
    subroutine check_columns(solver, kind, error, name)
        class(linear_solver_type), intent(inout) :: solver
        character(len=*), intent(in) :: kind
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in), optional :: name
        real(wp) :: a(order, order), lu(order, order), b(order, n_columns)
        real(wp) :: reference(order, n_columns), columns(order, n_columns)
        real(wp) :: one_by_one(order, n_columns), residual
        logical :: stored(order, order)
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        real(wp), allocatable :: values(:)
        integer :: pivots(order), info, i, c
        character(len=:), allocatable :: label

        call test_matrix(kind, a, stored)
        call to_csc(a, stored, col_ptr, row_index, values)
        b = 0.0_wp
        b(3, 1) = 1.0_wp
        b(order, 2) = 1.0_wp
        do c = 3, n_columns
            b(:, c) = [(real(mod(i * c, 7) - 3, wp) + 0.25_wp * c, i = 1, order)]
        end do
        lu = a
        reference = b
        call dgesv(order, n_columns, lu, order, pivots, reference, order, info)
        call check(error, info == 0, kind // ': dgesv failed')
        if (allocated(error)) return

        call solver%analyse(int(order, ik), col_ptr, row_index, error)
        if (allocated(error)) return
        call solver%factor(values, error)
        if (allocated(error)) return
        label = solver%get_name() // ' (' // kind // ')'
        if (present(name)) then
            call check(error, solver%get_name() == name, label // ': expected the path ' &
                // name)
            if (allocated(error)) return
        end if
        columns = b
        call solver%solve_columns(columns, error)
        if (allocated(error)) return
        one_by_one = b
        do c = 1, n_columns
            call solver%solve(one_by_one(:, c), error)
            if (allocated(error)) return
        end do

        do c = 1, n_columns
            residual = norm2(matmul(a, columns(:, c)) - b(:, c)) / norm2(b(:, c))
            call check(error, residual <= solution_tol, label // ': residual too large')
            if (allocated(error)) return
        end do
        call check(error, maxval(abs(columns - reference)) <= solution_tol &
            * maxval(abs(reference)), label // ': columns differ from dgesv')
        if (allocated(error)) return
        call check(error, maxval(abs(columns - one_by_one)) <= solution_tol &
            * maxval(abs(reference)), label // ': columns differ from single solves')
    end subroutine check_columns

end module test_solve_columns
