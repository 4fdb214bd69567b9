! SPDX-License-Identifier: MIT
!> Unit tests of the choice between KLU and UMFPACK (yarnfort_linalg_composite_lu_choice): the rule
!> on KLU's predicted cost, the solver it picks for a chain and for a dense block, the
!> same pick for the same pattern, METIS' order where it fills less, and right solutions
!> either way.
module test_lu_choice
    use, intrinsic :: iso_c_binding, only: c_long
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    use yarnfort_testing, only: unittest_type, new_unittest, check
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_composite_lu_choice, only: lu_choice_solver_type, prefers_umfpack, &
        umfpack_min_flops_per_nonzero, metis_min_flops_per_nonzero
    use yarnfort_linalg_factory, only: new_linear_solver, chosen_lu_name
    use yarnfort_linalg_backend_klu, only: klu_solver_type
    implicit none
    private

    public :: collect_lu_choice

    !> Relative error of x accepted from a backward-stable solve of these diagonally
    !> dominant systems (condition numbers of a few units).
    real(wp), parameter :: solution_tol = 1.0e5_wp * epsilon(1.0_wp)

contains

    subroutine collect_lu_choice(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)

        testsuite = [ &
            new_unittest('the rule: flops per factor nonzero', test_rule), &
            new_unittest('a chain goes to KLU', test_chain), &
            new_unittest('a dense block goes to UMFPACK', test_dense), &
            new_unittest('the same pattern, the same choice', test_same_pattern), &
            new_unittest('a grid gets METIS'' order', test_grid_metis) &
            ]
    end subroutine collect_lu_choice

    subroutine test_rule(error)
        type(error_type), allocatable, intent(out) :: error
        real(wp), parameter :: nonzeros = 1.0e5_wp

        call check(error, prefers_umfpack(umfpack_min_flops_per_nonzero * nonzeros, &
            nonzeros), 'at the threshold the rule should pick UMFPACK')
        if (allocated(error)) return
        call check(error, .not. prefers_umfpack(0.99_wp * umfpack_min_flops_per_nonzero &
            * nonzeros, nonzeros), 'below the threshold the rule should pick KLU')
    end subroutine test_rule

    !> An unsymmetric, diagonally dominant matrix of order n in CSC form: a tridiagonal
    !> chain, or (dense) every entry stored.
    subroutine test_matrix(n, dense, col_ptr, row_index, values)
        integer, intent(in) :: n
        logical, intent(in) :: dense
        integer(ik), allocatable, intent(out) :: col_ptr(:), row_index(:)
        real(wp), allocatable, intent(out) :: values(:)
        integer :: i, j, k

        allocate(col_ptr(n + 1), row_index(n * n), values(n * n))
        col_ptr(1) = 0
        k = 0
        do j = 1, n
            do i = 1, n
                if (.not. dense .and. abs(i - j) > 1) cycle
                k = k + 1
                row_index(k) = i - 1
                if (i == j) then
                    values(k) = 4.0_wp + mod(j, 3)
                else
                    values(k) = (0.5_wp + 0.25_wp * mod(i + 2 * j, 3)) / max(1, n / 2) &
                        * merge(1.0_wp, -1.0_wp, i < j)
                end if
            end do
            col_ptr(j + 1) = k
        end do
        row_index = row_index(1:k)
        values = values(1:k)
    end subroutine test_matrix

    !> A x for CSC a.
    function multiply(n, col_ptr, row_index, values, x) result(y)
        integer, intent(in) :: n
        integer(ik), intent(in) :: col_ptr(:), row_index(:)
        real(wp), intent(in) :: values(:), x(:)
        real(wp) :: y(n)
        integer :: j
        integer(ik) :: k

        y = 0.0_wp
        do j = 1, n
            do k = col_ptr(j) + 1, col_ptr(j + 1)
                y(row_index(k) + 1) = y(row_index(k) + 1) + values(k) * x(j)
            end do
        end do
    end function multiply

    !> Analyse, factor and solve the test matrix; `name` is the solver chosen.
    subroutine choose_and_solve(n, dense, name, error)
        integer, intent(in) :: n
        logical, intent(in) :: dense
        character(len=:), allocatable, intent(out) :: name
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: solver
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        real(wp), allocatable :: values(:)

        call new_linear_solver(solver, chosen_lu_name, error)
        if (allocated(error)) return
        call test_matrix(n, dense, col_ptr, row_index, values)
        call solver%analyse(int(n, ik), col_ptr, row_index, error)
        if (allocated(error)) return
        name = solver%get_name()
        call factor_and_solve(solver, n, col_ptr, row_index, values, name, error)
    end subroutine choose_and_solve

    !> Factor the analysed `solver`, solve A x = A x_known, compare with x_known.
    subroutine factor_and_solve(solver, n, col_ptr, row_index, values, label, error)
        class(linear_solver_type), intent(inout) :: solver
        integer, intent(in) :: n
        integer(ik), intent(in) :: col_ptr(:), row_index(:)
        real(wp), intent(in) :: values(:)
        character(len=*), intent(in) :: label
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: x(:), rhs(:)
        integer :: i

        call solver%factor(values, error)
        if (allocated(error)) return
        x = [(real(mod(i, 7) - 3, wp), i = 1, n)]
        rhs = multiply(n, col_ptr, row_index, values, x)
        call solver%solve(rhs, error)
        if (allocated(error)) return
        call check(error, maxval(abs(rhs - x)) <= solution_tol * maxval(abs(x)), &
            label // ': solution differs from the known x')
    end subroutine factor_and_solve

    !> A chain fills nothing: about 2 flops per factor nonzero.
    subroutine test_chain(error)
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: name

        call choose_and_solve(300, .false., name, error)
        if (allocated(error)) return
        call check(error, name == 'klu', 'a chain should go to klu, not ' // name)
    end subroutine test_chain

    !> A dense block of order n: about 2 n^3 / 3 flops on n^2 nonzeros, so n = 300 is
    !> 2.5 times the threshold.
    subroutine test_dense(error)
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: name

        call choose_and_solve(300, .true., name, error)
        if (allocated(error)) return
        call check(error, name == 'umfpack', 'a dense block should go to umfpack, not ' &
            // name)
    end subroutine test_dense

    !> Analysing the same pattern again gives the same solver and prediction.
    subroutine test_same_pattern(error)
        type(error_type), allocatable, intent(out) :: error
        type(lu_choice_solver_type) :: solver
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        real(wp), allocatable :: values(:)
        character(len=:), allocatable :: first
        real(wp) :: flops
        integer :: k

        call test_matrix(120, .true., col_ptr, row_index, values)
        do k = 1, 3
            call solver%analyse(120_ik, col_ptr, row_index, error)
            if (allocated(error)) return
            if (k == 1) then
                first = solver%get_name()
                flops = solver%predicted_flops
                call check(error, flops > 0.0_wp, 'no predicted flops after analyse')
                if (allocated(error)) return
            else
                call check(error, solver%get_name() == first .and. &
                    solver%predicted_flops == flops, 'a second analysis chose differently')
                if (allocated(error)) return
            end if
        end do
        call solver%destroy()
    end subroutine test_same_pattern

    !> A 12 x 12 x 8 grid of unknowns, each coupled to its 6 neighbours (unsymmetric
    !> values, diagonally dominant): AMD's factors fill in three dimensions (70 flops per
    !> nonzero: KLU, past metis_min_flops_per_nonzero) and nested dissection fills 8 %
    !> less. KLU gets METIS' order and solves right; so does KLU given another order
    !> (the reverse one).
    subroutine test_grid_metis(error)
        type(error_type), allocatable, intent(out) :: error
        integer, parameter :: extent(3) = [12, 12, 8], n = product(extent)
        type(lu_choice_solver_type) :: solver
        type(klu_solver_type) :: klu
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        real(wp), allocatable :: values(:)
        integer :: i, d, k, row, column, place(3), step(3)

        allocate(col_ptr(n + 1), row_index(7 * n), values(7 * n))
        step = [1, extent(1), extent(1) * extent(2)]
        col_ptr(1) = 0
        k = 0
        do column = 1, n
            place = mod((column - 1) / step, extent)
            do d = -3, 3
                row = column
                if (d /= 0) then
                    i = abs(d)
                    if (place(i) + sign(1, d) < 0 .or. place(i) + sign(1, d) >= extent(i)) &
                        cycle
                    row = column + sign(step(i), d)
                end if
                k = k + 1
                row_index(k) = row - 1
                if (row == column) then
                    values(k) = 10.0_wp + mod(column, 3)
                else
                    values(k) = -(0.5_wp + 0.25_wp * mod(row + 2 * column, 3))
                end if
            end do
            col_ptr(column + 1) = k
        end do
        row_index = row_index(1:k)
        values = values(1:k)

        call solver%analyse(int(n, ik), col_ptr, row_index, error)
        if (allocated(error)) return
        call check(error, solver%predicted_flops >= metis_min_flops_per_nonzero &
            * solver%predicted_nonzeros, 'the grid should reach the METIS threshold')
        if (allocated(error)) return
        call check(error, solver%get_name() == 'klu' .and. solver%metis_order .and. &
            solver%ordered_nonzeros < solver%predicted_nonzeros, &
            'the grid should go to klu with METIS'' sparser order')
        if (allocated(error)) return
        call factor_and_solve(solver, n, col_ptr, row_index, values, &
            solver%get_name() // ' with METIS'' order', error)
        if (allocated(error)) return
        call solver%destroy()

        klu%given_order = [(int(n - i, c_long), i = 1, n)]
        call klu%analyse(int(n, ik), col_ptr, row_index, error)
        if (allocated(error)) return
        call factor_and_solve(klu, n, col_ptr, row_index, values, 'klu with a given order', &
            error)
        call klu%destroy()
    end subroutine test_grid_metis

end module test_lu_choice
