! SPDX-License-Identifier: MIT
!> Unit tests of the sparse direct solvers (UMFPACK, KLU, CHOLMOD, dense LAPACK) behind
!> linear_solver_type, and of the factory.
module test_linalg
    use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
    use, intrinsic :: iso_c_binding, only: c_size_t, c_long
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_testing, only: unittest_type, new_unittest, check
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_factory, only: new_linear_solver, default_linear_solver_name, &
        klu_max_order, chosen_lu_name
    use yarnfort_linalg_backend_klu, only: klu_solver_type
    use yarnfort_linalg_backend_umfpack, only: umfpack_solver_type, umfpack_memory_type
    use yarnfort_linalg_process_threads, only: apply_thread_policy, count_serial_regions
    use yarnfort_linalg_process_heap, only: apply_heap_policy
    use yarnfort_text, only: format_real, format_integer
    implicit none
    private

    public :: collect_linalg

    !> glibc's malloc statistics (struct mallinfo2, malloc.h): hblkhd is the bytes in
    !> blocks malloc mapped on their own.
    type, bind(C) :: mallinfo2_type
        integer(c_size_t) :: arena, ordblks, smblks, hblks, hblkhd, usmblks, fsmblks, &
            uordblks, fordblks, keepcost
    end type mallinfo2_type

    interface
        function mallinfo2() result(info) bind(C, name='mallinfo2')
            import :: mallinfo2_type
            type(mallinfo2_type) :: info
        end function mallinfo2
    end interface

    !> Relative residual ||A x - b|| / ||b|| accepted from a backward-stable direct solve.
    real(wp), parameter :: residual_tol = 1000 * epsilon(1.0_wp)
    !> Relative error of x accepted: residual_tol times a condition number bound of 1e3
    !> for the test matrices.
    real(wp), parameter :: solution_tol = 1.0e3_wp * residual_tol

    !> Grid size of the 2D Laplacian (n = m**2) and number of 3x3 blocks of the random
    !> matrices (n = 3*blocks).
    integer, parameter :: laplacian_grid = 30, random_blocks = 300
    !> Random extra off-diagonal blocks per block row, and the generator's seed.
    integer, parameter :: random_links = 3
    integer(ik), parameter :: random_seed = 20240917_ik

    !> A square CSC matrix with 0-based indices, as the solvers see it.
    type :: csc_type
        integer(ik) :: n = 0
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        real(wp), allocatable :: values(:)
    end type csc_type

contains

    !> Collect all tests of the linalg suite.
    subroutine collect_linalg(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)

        testsuite = [ &
            new_unittest('umfpack small known system', test_small_umfpack), &
            new_unittest('klu small known system', test_small_klu), &
            new_unittest('cholmod small known system', test_small_cholmod), &
            new_unittest('dense small known system', test_small_dense), &
            new_unittest('umfpack small unsymmetric system', test_unsymmetric_small_umfpack), &
            new_unittest('klu small unsymmetric system', test_unsymmetric_small_klu), &
            new_unittest('dense small unsymmetric system', test_unsymmetric_small_dense), &
            new_unittest('umfpack 2D Laplacian', test_laplacian_umfpack), &
            new_unittest('klu 2D Laplacian', test_laplacian_klu), &
            new_unittest('cholmod 2D Laplacian', test_laplacian_cholmod), &
            new_unittest('dense 2D Laplacian', test_laplacian_dense), &
            new_unittest('umfpack random SPD blocks', test_random_spd_umfpack), &
            new_unittest('klu random SPD blocks', test_random_spd_klu), &
            new_unittest('cholmod random SPD blocks', test_random_spd_cholmod), &
            new_unittest('umfpack random unsymmetric blocks', test_random_unsym_umfpack), &
            new_unittest('klu random unsymmetric blocks', test_random_unsym_klu), &
            new_unittest('umfpack refactor same pattern', test_refactor_umfpack), &
            new_unittest('klu refactor same pattern', test_refactor_klu), &
            new_unittest('cholmod refactor same pattern', test_refactor_cholmod), &
            new_unittest('dense refactor same pattern', test_refactor_dense), &
            new_unittest('umfpack refactor needing new pivots', test_repivot_umfpack), &
            new_unittest('klu refactor needing new pivots', test_repivot_klu), &
            new_unittest('dense refactor needing new pivots', test_repivot_dense), &
            new_unittest('klu refactor with a tiny pivot repivots', test_klu_tiny_pivot), &
            new_unittest('umfpack new pattern', test_new_pattern_umfpack), &
            new_unittest('klu new pattern', test_new_pattern_klu), &
            new_unittest('cholmod new pattern', test_new_pattern_cholmod), &
            new_unittest('dense new pattern', test_new_pattern_dense), &
            new_unittest('umfpack singular matrix is an error', test_singular_umfpack), &
            new_unittest('klu singular matrix is an error', test_singular_klu), &
            new_unittest('cholmod singular matrix is an error', test_singular_cholmod), &
            new_unittest('dense singular matrix is an error', test_singular_dense), &
            new_unittest('cholmod indefinite matrix is an error', test_cholmod_indefinite), &
            new_unittest('cholmod reads only the upper triangle', test_cholmod_upper), &
            new_unittest('cholmod several columns, simplicial and supernodal', &
                test_cholmod_columns), &
            new_unittest('destroy twice is safe, solver reusable', test_destroy_twice), &
            new_unittest('calls out of order are errors', test_out_of_order), &
            new_unittest('invalid patterns are errors', test_invalid_pattern), &
            new_unittest('wrong array sizes are errors', test_wrong_sizes), &
            new_unittest('factory creates every named solver', test_factory_names), &
            new_unittest('factory rejects an unknown name', test_factory_unknown), &
            new_unittest('default solver follows the measured table', test_default_rule), &
            new_unittest('umfpack analyses with the values', test_umfpack_strategy), &
            new_unittest('umfpack with a given column order', test_umfpack_given_order), &
            new_unittest('umfpack: a wrong column order is an error', &
                test_umfpack_bad_order), &
            new_unittest('thread policy applied once', test_thread_policy_once), &
            new_unittest('limited OpenMP regions run on the calling thread', &
                test_serial_regions), &
            new_unittest('heap policy: large blocks from the heap', test_heap_policy) &
            ]
    end subroutine collect_linalg

    ! ---- small known systems -------------------------------------------------------------

    subroutine test_small_umfpack(error)
        type(error_type), allocatable, intent(out) :: error
        call check_small_known('umfpack', error)
    end subroutine test_small_umfpack

    subroutine test_small_klu(error)
        type(error_type), allocatable, intent(out) :: error
        call check_small_known('klu', error)
    end subroutine test_small_klu

    subroutine test_small_cholmod(error)
        type(error_type), allocatable, intent(out) :: error
        call check_small_known('cholmod', error)
    end subroutine test_small_cholmod

    subroutine test_small_dense(error)
        type(error_type), allocatable, intent(out) :: error
        call check_small_known('dense', error)
    end subroutine test_small_dense

    !> SPD 5x5 matrix with integer entries and x = (1, -2, 3, -4, 5), so b is exact.
    subroutine check_small_known(name, error)
        character(len=*), intent(in) :: name
        type(error_type), allocatable, intent(out) :: error
        type(csc_type) :: a

        a = small_spd_matrix()
        call check_known_solution(name, 'small SPD', a, [1.0_wp, -2.0_wp, 3.0_wp, -4.0_wp, &
            5.0_wp], error)
    end subroutine check_small_known

    subroutine test_unsymmetric_small_umfpack(error)
        type(error_type), allocatable, intent(out) :: error
        call check_unsymmetric_small('umfpack', error)
    end subroutine test_unsymmetric_small_umfpack

    subroutine test_unsymmetric_small_klu(error)
        type(error_type), allocatable, intent(out) :: error
        call check_unsymmetric_small('klu', error)
    end subroutine test_unsymmetric_small_klu

    subroutine test_unsymmetric_small_dense(error)
        type(error_type), allocatable, intent(out) :: error
        call check_unsymmetric_small('dense', error)
    end subroutine test_unsymmetric_small_dense

    !> Unsymmetric 4x4 with a zero diagonal entry (row pivoting needed), x = (2, 1, -1, 3).
    subroutine check_unsymmetric_small(name, error)
        character(len=*), intent(in) :: name
        type(error_type), allocatable, intent(out) :: error
        type(csc_type) :: a

        ! A = [0 2 0 1; 3 1 0 0; 0 4 5 0; 1 0 2 6]
        a = from_dense(reshape([ &
            0.0_wp, 3.0_wp, 0.0_wp, 1.0_wp, &
            2.0_wp, 1.0_wp, 4.0_wp, 0.0_wp, &
            0.0_wp, 0.0_wp, 5.0_wp, 2.0_wp, &
            1.0_wp, 0.0_wp, 0.0_wp, 6.0_wp], [4, 4]), keep_zero_diagonal=.true.)
        call check_known_solution(name, 'small unsymmetric', a, &
            [2.0_wp, 1.0_wp, -1.0_wp, 3.0_wp], error)
    end subroutine check_unsymmetric_small

    ! ---- larger sparse systems -----------------------------------------------------------

    subroutine test_laplacian_umfpack(error)
        type(error_type), allocatable, intent(out) :: error
        call check_large(name='umfpack', kind='laplacian', error=error)
    end subroutine test_laplacian_umfpack

    subroutine test_laplacian_klu(error)
        type(error_type), allocatable, intent(out) :: error
        call check_large(name='klu', kind='laplacian', error=error)
    end subroutine test_laplacian_klu

    subroutine test_laplacian_cholmod(error)
        type(error_type), allocatable, intent(out) :: error
        call check_large(name='cholmod', kind='laplacian', error=error)
    end subroutine test_laplacian_cholmod

    subroutine test_laplacian_dense(error)
        type(error_type), allocatable, intent(out) :: error
        call check_large(name='dense', kind='laplacian', error=error)
    end subroutine test_laplacian_dense

    subroutine test_random_spd_umfpack(error)
        type(error_type), allocatable, intent(out) :: error
        call check_large(name='umfpack', kind='spd', error=error)
    end subroutine test_random_spd_umfpack

    subroutine test_random_spd_klu(error)
        type(error_type), allocatable, intent(out) :: error
        call check_large(name='klu', kind='spd', error=error)
    end subroutine test_random_spd_klu

    subroutine test_random_spd_cholmod(error)
        type(error_type), allocatable, intent(out) :: error
        call check_large(name='cholmod', kind='spd', error=error)
    end subroutine test_random_spd_cholmod

    subroutine test_random_unsym_umfpack(error)
        type(error_type), allocatable, intent(out) :: error
        call check_large(name='umfpack', kind='unsymmetric', error=error)
    end subroutine test_random_unsym_umfpack

    subroutine test_random_unsym_klu(error)
        type(error_type), allocatable, intent(out) :: error
        call check_large(name='klu', kind='unsymmetric', error=error)
    end subroutine test_random_unsym_klu

    !> Solve a larger system with a known random x; compare with x and with the dense solver.
    subroutine check_large(name, kind, error)
        character(len=*), intent(in) :: name, kind
        type(error_type), allocatable, intent(out) :: error
        type(csc_type) :: a
        real(wp), allocatable :: x_true(:), x(:), x_dense(:)

        a = test_matrix(kind)
        x_true = random_vector(a%n, random_seed + 1)
        call check_known_solution(name, kind, a, x_true, error, x)
        if (allocated(error)) return
        if (name == 'dense') return
        call solve_with(name='dense', a=a, rhs=multiply(a, x_true), x=x_dense, error=error)
        if (allocated(error)) return
        call check(error, relative_difference(x, x_dense) <= solution_tol, &
            name // ' ' // kind // ': solution differs from the dense solver''s by ' &
            // format_real(relative_difference(x, x_dense)))
    end subroutine check_large

    ! ---- refactorisation -----------------------------------------------------------------

    subroutine test_refactor_umfpack(error)
        type(error_type), allocatable, intent(out) :: error
        call check_refactor('umfpack', error)
    end subroutine test_refactor_umfpack

    subroutine test_refactor_klu(error)
        type(error_type), allocatable, intent(out) :: error
        call check_refactor('klu', error)
    end subroutine test_refactor_klu

    subroutine test_refactor_cholmod(error)
        type(error_type), allocatable, intent(out) :: error
        call check_refactor('cholmod', error)
    end subroutine test_refactor_cholmod

    subroutine test_refactor_dense(error)
        type(error_type), allocatable, intent(out) :: error
        call check_refactor('dense', error)
    end subroutine test_refactor_dense

    !> Analyse once, then factor and solve three sets of values on the same pattern.
    subroutine check_refactor(name, error)
        character(len=*), intent(in) :: name
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: solver
        type(csc_type) :: a, scaled
        real(wp), allocatable :: x_true(:), x(:)
        integer :: step

        a = test_matrix('spd')
        x_true = random_vector(a%n, random_seed + 2)
        call new_linear_solver(solver, name, error)
        if (allocated(error)) return
        call solver%analyse(a%n, a%col_ptr, a%row_index, error)
        if (allocated(error)) return
        do step = 1, 3
            scaled = a
            ! Keep the matrix SPD: scale it and strengthen the diagonal.
            scaled%values = real(step, wp) * a%values
            call add_to_diagonal(scaled, real(step - 1, wp))
            call solver%factor(scaled%values, error)
            if (allocated(error)) return
            x = multiply(scaled, x_true)
            call solver%solve(x, error)
            if (allocated(error)) return
            call check_solution(name // ' refactor step ' // format_integer(step), scaled, &
                multiply(scaled, x_true), x, x_true, error)
            if (allocated(error)) return
        end do
        call solver%destroy()
    end subroutine check_refactor

    subroutine test_repivot_umfpack(error)
        type(error_type), allocatable, intent(out) :: error
        call check_repivot('umfpack', error)
    end subroutine test_repivot_umfpack

    subroutine test_repivot_klu(error)
        type(error_type), allocatable, intent(out) :: error
        call check_repivot('klu', error)
    end subroutine test_repivot_klu

    subroutine test_repivot_dense(error)
        type(error_type), allocatable, intent(out) :: error
        call check_repivot('dense', error)
    end subroutine test_repivot_dense

    !> New values on the same pattern that make the first pivot order fail (a diagonal
    !> entry becomes zero): the solver must pivot again, not divide by zero.
    subroutine check_repivot(name, error)
        character(len=*), intent(in) :: name
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: solver
        type(csc_type) :: first, second
        real(wp), allocatable :: x(:)
        real(wp), parameter :: x_true(3) = [1.0_wp, 2.0_wp, 3.0_wp]

        first = from_dense(reshape([4.0_wp, 1.0_wp, 0.0_wp, 1.0_wp, 3.0_wp, 1.0_wp, &
            0.0_wp, 1.0_wp, 4.0_wp], [3, 3]))
        second = first
        ! second = [0 1 0; 1 3 1; 0 1 4] (det = -4), first diagonal pivot now zero
        second%values(1) = 0.0_wp
        call new_linear_solver(solver, name, error)
        if (allocated(error)) return
        call solver%analyse(first%n, first%col_ptr, first%row_index, error)
        if (allocated(error)) return
        call solver%factor(first%values, error)
        if (allocated(error)) return
        call solver%factor(second%values, error)
        if (allocated(error)) return
        x = multiply(second, x_true)
        call solver%solve(x, error)
        if (allocated(error)) return
        call check_solution(name // ' repivot', second, multiply(second, x_true), x, x_true, &
            error)
    end subroutine check_repivot

    !> New values make the old pivot order poor (a pivot of 1e-14): KLU's refactorisation
    !> fails the refactor_rcond_min check and factors again with pivoting.
    subroutine test_klu_tiny_pivot(error)
        type(error_type), allocatable, intent(out) :: error
        type(klu_solver_type) :: solver
        type(csc_type) :: first, second
        real(wp), allocatable :: x(:)
        real(wp), parameter :: x_true(3) = [1.0_wp, 2.0_wp, 3.0_wp]
        real(wp), parameter :: tiny_pivot = 1.0e-14_wp

        first = from_dense(reshape([4.0_wp, 1.0_wp, 0.0_wp, 1.0_wp, 3.0_wp, 1.0_wp, &
            0.0_wp, 1.0_wp, 4.0_wp], [3, 3]))
        second = first
        second%values(1) = tiny_pivot
        call check(error, solver%refactor_rcond_min > 0.0_wp, &
            'klu: default refactor_rcond_min should be positive')
        if (allocated(error)) return
        call solver%analyse(first%n, first%col_ptr, first%row_index, error)
        if (allocated(error)) return
        call solver%factor(first%values, error)
        if (allocated(error)) return
        call solver%factor(second%values, error)
        if (allocated(error)) return
        x = multiply(second, x_true)
        call solver%solve(x, error)
        if (allocated(error)) return
        call check_solution('klu tiny pivot', second, multiply(second, x_true), x, x_true, &
            error)
        call solver%destroy()
    end subroutine test_klu_tiny_pivot

    ! ---- new pattern ---------------------------------------------------------------------

    subroutine test_new_pattern_umfpack(error)
        type(error_type), allocatable, intent(out) :: error
        call check_new_pattern('umfpack', error)
    end subroutine test_new_pattern_umfpack

    subroutine test_new_pattern_klu(error)
        type(error_type), allocatable, intent(out) :: error
        call check_new_pattern('klu', error)
    end subroutine test_new_pattern_klu

    subroutine test_new_pattern_cholmod(error)
        type(error_type), allocatable, intent(out) :: error
        call check_new_pattern('cholmod', error)
    end subroutine test_new_pattern_cholmod

    subroutine test_new_pattern_dense(error)
        type(error_type), allocatable, intent(out) :: error
        call check_new_pattern('dense', error)
    end subroutine test_new_pattern_dense

    !> One solver object analyses three different patterns in turn.
    subroutine check_new_pattern(name, error)
        character(len=*), intent(in) :: name
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: solver
        type(csc_type) :: matrices(3)
        real(wp), allocatable :: x_true(:), x(:)
        integer :: i

        matrices(1) = laplacian_2d(laplacian_grid)
        matrices(2) = small_spd_matrix()
        matrices(3) = random_block_matrix(random_blocks / 3, symmetric=.true., &
            seed=random_seed + 3)
        call new_linear_solver(solver, name, error)
        if (allocated(error)) return
        do i = 1, size(matrices)
            call solver%analyse(matrices(i)%n, matrices(i)%col_ptr, matrices(i)%row_index, &
                error)
            if (allocated(error)) return
            call solver%factor(matrices(i)%values, error)
            if (allocated(error)) return
            x_true = random_vector(matrices(i)%n, random_seed + 4)
            x = multiply(matrices(i), x_true)
            call solver%solve(x, error)
            if (allocated(error)) return
            call check_solution(name // ' pattern ' // format_integer(i), matrices(i), &
                multiply(matrices(i), x_true), x, x_true, error)
            if (allocated(error)) return
        end do
    end subroutine check_new_pattern

    ! ---- failures ------------------------------------------------------------------------

    subroutine test_singular_umfpack(error)
        type(error_type), allocatable, intent(out) :: error
        call check_singular('umfpack', 'singular', error)
    end subroutine test_singular_umfpack

    subroutine test_singular_klu(error)
        type(error_type), allocatable, intent(out) :: error
        call check_singular('klu', 'singular', error)
    end subroutine test_singular_klu

    subroutine test_singular_cholmod(error)
        type(error_type), allocatable, intent(out) :: error
        call check_singular('cholmod', 'not positive definite', error)
    end subroutine test_singular_cholmod

    subroutine test_singular_dense(error)
        type(error_type), allocatable, intent(out) :: error
        call check_singular('dense', 'singular', error)
    end subroutine test_singular_dense

    !> A numerically singular matrix and one with an empty column: factor returns an error
    !> whose message contains `expected`, and a later solve is an error too (no NaN).
    subroutine check_singular(name, expected, error)
        character(len=*), intent(in) :: name, expected
        type(error_type), allocatable, intent(out) :: error
        type(csc_type) :: matrices(2)
        integer :: i

        ! [1 2 0; 2 4 0; 0 0 1]: row 2 = 2 * row 1, eliminated exactly.
        matrices(1) = from_dense(reshape([1.0_wp, 2.0_wp, 0.0_wp, 2.0_wp, 4.0_wp, 0.0_wp, &
            0.0_wp, 0.0_wp, 1.0_wp], [3, 3]))
        ! [1 0 1; 0 0 0; 1 0 2]: column 2 (and row 2) empty, structurally singular.
        matrices(2) = from_dense(reshape([1.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, &
            1.0_wp, 0.0_wp, 2.0_wp], [3, 3]))
        do i = 1, size(matrices)
            call check_factor_fails(name, 'singular matrix ' // format_integer(i), &
                matrices(i), expected, error)
            if (allocated(error)) return
        end do
    end subroutine check_singular

    !> CHOLMOD rejects symmetric indefinite matrices, small and large, with a clear message.
    subroutine test_cholmod_indefinite(error)
        type(error_type), allocatable, intent(out) :: error
        type(csc_type) :: a

        a = from_dense(reshape([1.0_wp, 2.0_wp, 2.0_wp, 1.0_wp], [2, 2]))
        call check_factor_fails('cholmod', 'indefinite 2x2', a, 'not positive definite', error)
        if (allocated(error)) return
        ! Laplacian - I: symmetric, smallest eigenvalue about 2 pi**2 / m**2 - 1 < 0.
        a = laplacian_2d(laplacian_grid)
        call add_to_diagonal(a, -1.0_wp)
        call check_factor_fails('cholmod', 'shifted Laplacian', a, 'not positive definite', &
            error)
        if (allocated(error)) return
        ! The same matrix is fine for UMFPACK, and for CHOLMOD with its KLU fallback.
        call check_known_solution('umfpack', 'shifted Laplacian', a, &
            random_vector(a%n, random_seed + 5), error)
        if (allocated(error)) return
        call check_known_solution('cholmod+klu', 'shifted Laplacian', a, &
            random_vector(a%n, random_seed + 6), error)
        if (allocated(error)) return
        ! And the fallback solver uses CHOLMOD itself while the matrix is SPD.
        call check_small_known('cholmod+klu', error)
    end subroutine test_cholmod_indefinite

    !> CHOLMOD ignores entries below the diagonal: garbage there must not change x.
    !> CHOLMOD factors the matrix permuted to its fill-reducing order and permutes the
    !> right-hand sides: several columns at once, on a simplicial factor (Laplacian 10 x
    !> 10) and a supernodal one (120 x 120), give the known X and the one-column solves.
    subroutine test_cholmod_columns(error)
        type(error_type), allocatable, intent(out) :: error
        integer, parameter :: sides(2) = [10, 120], n_columns = 3
        class(linear_solver_type), allocatable :: solver
        type(csc_type) :: a
        real(wp), allocatable :: x_true(:, :), columns(:, :), one_by_one(:, :)
        integer :: s, c

        do s = 1, size(sides)
            a = laplacian_2d(sides(s))
            allocate(x_true(a%n, n_columns), columns(a%n, n_columns))
            do c = 1, n_columns
                x_true(:, c) = random_vector(a%n, random_seed + 10 + c)
                columns(:, c) = multiply(a, x_true(:, c))
            end do
            one_by_one = columns
            call new_linear_solver(solver, 'cholmod', error)
            if (allocated(error)) return
            call solver%analyse(a%n, a%col_ptr, a%row_index, error)
            if (allocated(error)) return
            call solver%factor(a%values, error)
            if (allocated(error)) return
            call solver%solve_columns(columns, error)
            if (allocated(error)) return
            do c = 1, n_columns
                call solver%solve(one_by_one(:, c), error)
                if (allocated(error)) return
            end do
            call solver%destroy()
            call check(error, maxval(abs(columns - x_true)) <= solution_tol &
                * maxval(abs(x_true)), 'Laplacian ' // format_integer(sides(s)) &
                // ': columns differ from the known X')
            if (allocated(error)) return
            call check(error, maxval(abs(columns - one_by_one)) <= solution_tol &
                * maxval(abs(x_true)), 'Laplacian ' // format_integer(sides(s)) &
                // ': columns differ from the one-column solves')
            if (allocated(error)) return
            deallocate(x_true, columns)
        end do
    end subroutine test_cholmod_columns

    subroutine test_cholmod_upper(error)
        type(error_type), allocatable, intent(out) :: error
        type(csc_type) :: a, garbled
        real(wp), allocatable :: x_true(:), x(:)
        integer(ik) :: j, k

        a = laplacian_2d(laplacian_grid)
        garbled = a
        do j = 1, a%n
            do k = a%col_ptr(j) + 1, a%col_ptr(j + 1)
                if (a%row_index(k) + 1 > j) garbled%values(k) = 1.0e3_wp
            end do
        end do
        x_true = random_vector(a%n, random_seed + 6)
        call solve_with(name='cholmod', a=garbled, rhs=multiply(a, x_true), x=x, error=error)
        if (allocated(error)) return
        call check_solution('cholmod upper triangle', a, multiply(a, x_true), x, x_true, error)
    end subroutine test_cholmod_upper

    !> destroy on a new, an analysed and a factored solver, twice each; then reuse.
    subroutine test_destroy_twice(error)
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: solver
        type(csc_type) :: a
        real(wp), allocatable :: x(:)
        character(len=11), parameter :: names(5) = [character(len=11) :: 'umfpack', 'klu', &
            'cholmod', 'dense', chosen_lu_name]
        real(wp), parameter :: x_true(5) = [1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp, 5.0_wp]
        integer :: i

        a = small_spd_matrix()
        do i = 1, size(names)
            call new_linear_solver(solver, names(i), error)
            if (allocated(error)) return
            call solver%destroy()
            call solver%destroy()
            call solver%analyse(a%n, a%col_ptr, a%row_index, error)
            if (allocated(error)) return
            call solver%destroy()
            call solver%destroy()
            call solver%analyse(a%n, a%col_ptr, a%row_index, error)
            if (allocated(error)) return
            call solver%factor(a%values, error)
            if (allocated(error)) return
            call solver%destroy()
            call solver%destroy()
            x = x_true
            call solver%solve(x, error)
            call expect_error(trim(names(i)) // ' solve after destroy', 'factorisation', error)
            if (allocated(error)) return
            call solver%analyse(a%n, a%col_ptr, a%row_index, error)
            if (allocated(error)) return
            call solver%factor(a%values, error)
            if (allocated(error)) return
            x = multiply(a, x_true)
            call solver%solve(x, error)
            if (allocated(error)) return
            call check_solution(trim(names(i)) // ' after destroy', a, multiply(a, x_true), &
                x, x_true, error)
            if (allocated(error)) return
            ! Leave the last one for deallocation (finalisation) to free.
            deallocate(solver)
        end do
    end subroutine test_destroy_twice

    !> factor before analyse and solve before factor are errors, not crashes.
    subroutine test_out_of_order(error)
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: solver
        type(csc_type) :: a
        real(wp) :: rhs(5)
        character(len=11), parameter :: names(5) = [character(len=11) :: 'umfpack', 'klu', &
            'cholmod', 'dense', chosen_lu_name]
        integer :: i

        a = small_spd_matrix()
        do i = 1, size(names)
            call new_linear_solver(solver, names(i), error)
            if (allocated(error)) return
            call solver%factor(a%values, error)
            call expect_error(trim(names(i)) // ' factor before analyse', 'before analyse', &
                error)
            if (allocated(error)) return
            rhs = 1.0_wp
            call solver%solve(rhs, error)
            call expect_error(trim(names(i)) // ' solve before analyse', 'factorisation', error)
            if (allocated(error)) return
            call solver%analyse(a%n, a%col_ptr, a%row_index, error)
            if (allocated(error)) return
            call solver%solve(rhs, error)
            call expect_error(trim(names(i)) // ' solve before factor', 'factorisation', error)
            if (allocated(error)) return
        end do
    end subroutine test_out_of_order

    !> Patterns that are not valid 0-based square CSC with sorted rows are rejected.
    subroutine test_invalid_pattern(error)
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: solver
        ! 'cholmod+klu' checks the pattern itself before keeping it for the switch.
        character(len=11), parameter :: names(6) = [character(len=11) :: 'umfpack', 'klu', &
            'cholmod', 'dense', 'cholmod+klu', chosen_lu_name]
        integer :: i

        do i = 1, size(names)
            call new_linear_solver(solver, names(i), error)
            if (allocated(error)) return
            ! unsorted rows in column 0
            call solver%analyse(2_ik, [0_ik, 2_ik, 3_ik], [1_ik, 0_ik, 1_ik], error)
            call expect_error(trim(names(i)) // ' unsorted', 'not strictly increasing', error)
            if (allocated(error)) return
            ! duplicate rows in column 1
            call solver%analyse(2_ik, [0_ik, 1_ik, 3_ik], [0_ik, 1_ik, 1_ik], error)
            call expect_error(trim(names(i)) // ' duplicate', 'not strictly increasing', error)
            if (allocated(error)) return
            ! row index out of range
            call solver%analyse(2_ik, [0_ik, 1_ik, 2_ik], [0_ik, 2_ik], error)
            call expect_error(trim(names(i)) // ' out of range', 'outside 0..n-1', error)
            if (allocated(error)) return
            ! 1-based col_ptr
            call solver%analyse(2_ik, [1_ik, 2_ik, 3_ik], [0_ik, 1_ik], error)
            call expect_error(trim(names(i)) // ' 1-based', '0-based', error)
            if (allocated(error)) return
            ! wrong col_ptr size
            call solver%analyse(3_ik, [0_ik, 1_ik, 2_ik], [0_ik, 1_ik], error)
            call expect_error(trim(names(i)) // ' col_ptr size', 'expected n + 1', error)
            if (allocated(error)) return
            ! empty matrix
            call solver%analyse(0_ik, [0_ik], [integer(ik) ::], error)
            call expect_error(trim(names(i)) // ' n = 0', 'at least 1', error)
            if (allocated(error)) return
        end do
    end subroutine test_invalid_pattern

    !> Too few values and a right-hand side of the wrong length are errors.
    subroutine test_wrong_sizes(error)
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: solver
        type(csc_type) :: a
        real(wp) :: rhs(4)
        character(len=11), parameter :: names(5) = [character(len=11) :: 'umfpack', 'klu', &
            'cholmod', 'dense', chosen_lu_name]
        integer :: i

        a = small_spd_matrix()
        do i = 1, size(names)
            call new_linear_solver(solver, names(i), error)
            if (allocated(error)) return
            call solver%analyse(a%n, a%col_ptr, a%row_index, error)
            if (allocated(error)) return
            call solver%factor(a%values(2:), error)
            call expect_error(trim(names(i)) // ' short values', 'values has', error)
            if (allocated(error)) return
            call solver%factor(a%values, error)
            if (allocated(error)) return
            rhs = 1.0_wp
            call solver%solve(rhs, error)
            call expect_error(trim(names(i)) // ' short rhs', 'rhs has', error)
            if (allocated(error)) return
        end do
    end subroutine test_wrong_sizes

    ! ---- factory -------------------------------------------------------------------------

    !> Each valid name (any case, blanks around it) gives a solver of that name.
    subroutine test_factory_names(error)
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: solver
        character(len=*), parameter :: names(4) = [character(len=7) :: 'umfpack', 'klu', &
            'cholmod', 'dense']
        integer :: i

        do i = 1, size(names)
            call new_linear_solver(solver, trim(names(i)), error)
            if (allocated(error)) return
            call check(error, solver%get_name() == trim(names(i)), 'factory made ' &
                // solver%get_name() // ' for ' // trim(names(i)))
            if (allocated(error)) return
        end do
        call new_linear_solver(solver, '  UMFPACK ', error)
        if (allocated(error)) return
        call check(error, solver%get_name() == 'umfpack', 'factory is not case-insensitive')
    end subroutine test_factory_names

    subroutine test_factory_unknown(error)
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: solver

        call new_linear_solver(solver, 'superlu', error)
        call check(error, .not. allocated(solver), 'factory allocated a solver for superlu')
        if (allocated(error)) return
        call new_linear_solver(solver, 'superlu', error)
        call expect_error('factory unknown name', "unknown linear solver 'superlu'", error)
        if (allocated(error)) return
        call new_linear_solver(solver, 'superlu', error)
        call expect_error('factory unknown name', "'umfpack', 'klu', 'cholmod', 'cholmod+klu', 'dense'", &
            error)
    end subroutine test_factory_unknown

    !> KLU for small systems, CHOLMOD for large SPD, UMFPACK for large general ones.
    subroutine test_default_rule(error)
        type(error_type), allocatable, intent(out) :: error

        call check(error, default_linear_solver_name(1000_ik, .false.) == 'klu', &
            'default for 1e3 general should be klu')
        if (allocated(error)) return
        call check(error, default_linear_solver_name(klu_max_order, .false.) == 'klu', &
            'default for klu_max_order general should be klu')
        if (allocated(error)) return
        call check(error, default_linear_solver_name(10_ik, .true.) == 'cholmod+klu', &
            'default for SPD should be cholmod+klu')
        if (allocated(error)) return
        call check(error, default_linear_solver_name(1000000_ik, .true.) == 'cholmod+klu', &
            'default for 1e6 SPD should be cholmod+klu')
        if (allocated(error)) return
        call check(error, default_linear_solver_name(1000000_ik, .false.) == 'umfpack', &
            'default for 1e6 general should be umfpack')
        if (allocated(error)) return
        call check(error, default_linear_solver_name(klu_max_order + 1, .false.) &
            == 'umfpack', 'default above klu_max_order general should be umfpack')
    end subroutine test_default_rule

    !> UMFPACK's symbolic analysis sees the values: on a matrix with a symmetric pattern
    !> and a nonzero diagonal it takes the symmetric strategy (UMFPACK_STRATEGY_SYMMETRIC,
    !> 3), and the solution is right.
    subroutine test_umfpack_strategy(error)
        type(error_type), allocatable, intent(out) :: error
        type(umfpack_solver_type) :: solver
        type(umfpack_memory_type) :: memory
        type(csc_type) :: a
        real(wp), allocatable :: x_true(:), x(:)

        a = test_matrix('spd')
        x_true = random_vector(a%n, random_seed + 5)
        call solver%analyse(a%n, a%col_ptr, a%row_index, error)
        if (allocated(error)) return
        memory = solver%get_memory()
        call check(error, memory%strategy == 0, &
            'umfpack: a strategy before the first factorisation')
        if (allocated(error)) return
        call solver%factor(a%values, error)
        if (allocated(error)) return
        memory = solver%get_memory()
        call check(error, memory%strategy == 3, 'umfpack: strategy ' &
            // format_integer(memory%strategy) &
            // ' on an SPD matrix, expected 3 (symmetric)')
        if (allocated(error)) return
        x = multiply(a, x_true)
        call solver%solve(x, error)
        if (allocated(error)) return
        call check_solution('umfpack symmetric strategy', a, multiply(a, x_true), x, x_true, &
            error)
    end subroutine test_umfpack_strategy

    !> A given order is used: on a 2D Laplacian (grid m x m) the natural order fills the
    !> band of the factors (about m nonzeros per column of L) where UMFPACK's own AMD
    !> order fills far less; the symmetric strategy, and the right solution either way.
    subroutine test_umfpack_given_order(error)
        type(error_type), allocatable, intent(out) :: error
        type(csc_type) :: a
        real(wp), allocatable :: x_true(:)
        real(wp) :: own_nonzeros, natural_nonzeros
        integer(c_long) :: k

        a = laplacian_2d(laplacian_grid)
        x_true = random_vector(a%n, random_seed + 11)
        call factor_and_solve(.false., own_nonzeros, error)
        if (allocated(error)) return
        call factor_and_solve(.true., natural_nonzeros, error)
        if (allocated(error)) return
        call check(error, natural_nonzeros > 2.0_wp * own_nonzeros, 'umfpack: natural ' &
            // 'order L + U nonzeros ' // format_integer(nint(natural_nonzeros)) &
            // ' not above twice those of its own order, ' &
            // format_integer(nint(own_nonzeros)))
    contains
        subroutine factor_and_solve(natural, factor_nonzeros, error)
            logical, intent(in) :: natural
            real(wp), intent(out) :: factor_nonzeros
            type(error_type), allocatable, intent(out) :: error
            type(umfpack_solver_type) :: solver
            type(umfpack_memory_type) :: memory
            real(wp), allocatable :: x(:)

            factor_nonzeros = 0.0_wp
            call solver%analyse(a%n, a%col_ptr, a%row_index, error)
            if (allocated(error)) return
            if (natural) then
                call solver%set_column_order([(k, k = 0_c_long, int(a%n, c_long) - 1)], &
                    0.0_wp, error)
                if (allocated(error)) return
            end if
            call solver%factor(a%values, error)
            if (allocated(error)) return
            memory = solver%get_memory()
            factor_nonzeros = memory%l_nonzeros + memory%u_nonzeros
            call check(error, memory%strategy == 3, 'umfpack: strategy ' &
                // format_integer(memory%strategy) // ', expected 3 (symmetric)')
            if (allocated(error)) return
            x = multiply(a, x_true)
            call solver%solve(x, error)
            if (allocated(error)) return
            call check_solution('umfpack given order', a, multiply(a, x_true), x, x_true, &
                error)
        end subroutine factor_and_solve
    end subroutine test_umfpack_given_order

    !> A column order before analyse, of the wrong size, or after the first
    !> factorisation is an error.
    subroutine test_umfpack_bad_order(error)
        type(error_type), allocatable, intent(out) :: error
        type(umfpack_solver_type) :: solver
        type(csc_type) :: a
        integer(c_long) :: k

        a = laplacian_2d(4)
        call solver%set_column_order([(k, k = 0_c_long, 15_c_long)], 0.0_wp, error)
        call expect_error('umfpack column order', 'before analyse', error)
        if (allocated(error)) return
        call solver%analyse(a%n, a%col_ptr, a%row_index, error)
        if (allocated(error)) return
        call solver%set_column_order([(k, k = 0_c_long, 14_c_long)], 0.0_wp, error)
        call expect_error('umfpack column order', 'of size 15 for order 16', error)
        if (allocated(error)) return
        call solver%factor(a%values, error)
        if (allocated(error)) return
        call solver%set_column_order([(k, k = 0_c_long, 15_c_long)], 0.0_wp, error)
        call expect_error('umfpack column order', 'after the first factorisation', &
            error)
    end subroutine test_umfpack_bad_order

    !> The thread policy acts at most once per process: a second call changes nothing.
    subroutine test_thread_policy_once(error)
        type(error_type), allocatable, intent(out) :: error
        logical :: openmp_first, blas_first, openmp_again, blas_again

        call apply_thread_policy(openmp_first, blas_first)
        call apply_thread_policy(openmp_again, blas_again)
        call check(error, openmp_first .eqv. openmp_again .and. (blas_first .eqv. blas_again), &
            'the thread policy reported different actions on a second call')
    end subroutine test_thread_policy_once

    !> With the regions limited, CHOLMOD's supernodal factorisation (a 2D Laplacian of
    !> 14,400 unknowns is supernodal) enters its OpenMP regions through threads.c's
    !> GOMP_parallel and still solves; with the user's OMP_THREAD_LIMIT, libgomp's runs.
    subroutine test_serial_regions(error)
        type(error_type), allocatable, intent(out) :: error
        type(csc_type) :: a
        real(wp), allocatable :: x_true(:), x(:)
        logical :: openmp_limited, blas_set
        integer :: before

        call apply_thread_policy(openmp_limited, blas_set)
        a = laplacian_2d(120)
        x_true = random_vector(a%n, random_seed + 3)
        before = count_serial_regions()
        call check_known_solution('cholmod', 'Laplacian 120 x 120', a, x_true, error, x)
        if (allocated(error)) return
        if (openmp_limited) then
            call check(error, count_serial_regions() > before, 'CHOLMOD''s OpenMP regions ' &
                // 'did not run through yarnfort''s GOMP_parallel')
        else
            call check(error, count_serial_regions() == before, 'OpenMP regions ran on ' &
                // 'the calling thread although the policy left them to libgomp')
        end if
    end subroutine test_serial_regions

    !> With the heap policy in force (glibc, no malloc tuning by the user), a block of
    !> 64 MiB, twice glibc's largest mmap threshold, comes from the heap, not from a
    !> mapping of its own; a second call reports the same.
    subroutine test_heap_policy(error)
        type(error_type), allocatable, intent(out) :: error
        logical :: applied, applied_again
        real(wp), allocatable :: block(:)
        type(mallinfo2_type) :: before, with_block

        call apply_heap_policy(applied)
        call apply_heap_policy(applied_again)
        call check(error, applied .eqv. applied_again, &
            'the heap policy reported a different state on a second call')
        if (allocated(error) .or. .not. applied) return
        before = mallinfo2()
        allocate(block(8 * 1024 * 1024))
        block(1) = 1.0_wp
        with_block = mallinfo2()
        call check(error, with_block%hblkhd - before%hblkhd < 64 * 1024 * 1024, &
            'a block of 64 MiB was mapped on its own')
    end subroutine test_heap_policy

    ! ---- helpers: solving and checking ---------------------------------------------------

    !> Create solver `name`, analyse, factor and solve A x = rhs.
    subroutine solve_with(name, a, rhs, x, error)
        character(len=*), intent(in) :: name
        type(csc_type), intent(in) :: a
        real(wp), intent(in) :: rhs(:)
        real(wp), allocatable, intent(out) :: x(:)
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: solver

        call new_linear_solver(solver, name, error)
        if (allocated(error)) return
        call solver%analyse(a%n, a%col_ptr, a%row_index, error)
        if (allocated(error)) return
        call solver%factor(a%values, error)
        if (allocated(error)) return
        x = rhs
        call solver%solve(x, error)
        call solver%destroy()
    end subroutine solve_with

    !> Solve A x = A x_true with solver `name` and check residual and error of x.
    subroutine check_known_solution(name, what, a, x_true, error, x)
        character(len=*), intent(in) :: name, what
        type(csc_type), intent(in) :: a
        real(wp), intent(in) :: x_true(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable, intent(out), optional :: x(:)
        real(wp), allocatable :: b(:), solution(:)

        allocate(b, source=multiply(a, x_true))
        call solve_with(name, a, b, solution, error)
        if (allocated(error)) return
        call check_solution(name // ' ' // what, a, b, solution, x_true, error)
        if (present(x)) x = solution
    end subroutine check_known_solution

    !> Fail unless ||A x - b|| / ||b|| <= residual_tol and x is close to x_true.
    subroutine check_solution(what, a, b, x, x_true, error)
        character(len=*), intent(in) :: what
        type(csc_type), intent(in) :: a
        real(wp), intent(in) :: b(:), x(:), x_true(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: residual

        if (any(ieee_is_nan(x))) then
            call fatal_error(error, what // ': solution contains NaN')
            return
        end if
        residual = norm2(multiply(a, x) - b) / norm2(b)
        if (.not. (residual <= residual_tol)) then
            call fatal_error(error, what // ': relative residual ' // format_real(residual) &
                // ' > ' // format_real(residual_tol))
            return
        end if
        call check(error, relative_difference(x, x_true) <= solution_tol, what &
            // ': relative error of x ' // format_real(relative_difference(x, x_true)))
    end subroutine check_solution

    !> analyse succeeds, factor fails with a message containing `expected`, solve fails.
    subroutine check_factor_fails(name, what, a, expected, error)
        character(len=*), intent(in) :: name, what, expected
        type(csc_type), intent(in) :: a
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: solver
        real(wp), allocatable :: rhs(:)

        call new_linear_solver(solver, name, error)
        if (allocated(error)) return
        call solver%analyse(a%n, a%col_ptr, a%row_index, error)
        if (allocated(error)) return
        call solver%factor(a%values, error)
        call expect_error(name // ' ' // what // ' factor', expected, error)
        if (allocated(error)) return
        allocate(rhs(a%n), source=1.0_wp)
        call solver%solve(rhs, error)
        call expect_error(name // ' ' // what // ' solve after failed factor', &
            'factorisation', error)
        if (allocated(error)) return
        call solver%destroy()
    end subroutine check_factor_fails

    !> Turn "error with a message containing `expected`" into success, anything else into
    !> a failure of the test.
    subroutine expect_error(what, expected, error)
        character(len=*), intent(in) :: what, expected
        type(error_type), allocatable, intent(inout) :: error

        if (.not. allocated(error)) then
            call fatal_error(error, what // ': expected an error containing "' // expected &
                // '", got none')
        else if (index(error%message, expected) == 0) then
            error%message = what // ': expected an error containing "' // expected &
                // '", got "' // error%message // '"'
        else
            deallocate(error)
        end if
    end subroutine expect_error

    ! ---- helpers: matrices ---------------------------------------------------------------

    !> Test matrix of a kind: 'laplacian', 'spd' or 'unsymmetric' (random 3x3 blocks).
    function test_matrix(kind) result(a)
        character(len=*), intent(in) :: kind
        type(csc_type) :: a

        select case (kind)
        case ('laplacian')
            a = laplacian_2d(laplacian_grid)
        case ('spd')
            a = random_block_matrix(random_blocks, symmetric=.true., seed=random_seed)
        case default
            a = random_block_matrix(random_blocks, symmetric=.false., seed=random_seed)
        end select
    end function test_matrix

    !> SPD 5x5 with integer entries (diagonally dominant, some far off-diagonals).
    function small_spd_matrix() result(a)
        type(csc_type) :: a

        a = from_dense(reshape([ &
            6.0_wp, 1.0_wp, 0.0_wp, 2.0_wp, 0.0_wp, &
            1.0_wp, 5.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, &
            0.0_wp, 1.0_wp, 7.0_wp, 1.0_wp, 3.0_wp, &
            2.0_wp, 0.0_wp, 1.0_wp, 8.0_wp, 1.0_wp, &
            0.0_wp, 0.0_wp, 3.0_wp, 1.0_wp, 9.0_wp], [5, 5]))
    end function small_spd_matrix

    !> CSC of the nonzeros of a dense matrix (and, if asked, of its zero diagonal entries).
    function from_dense(dense, keep_zero_diagonal) result(a)
        real(wp), intent(in) :: dense(:, :)
        logical, intent(in), optional :: keep_zero_diagonal
        type(csc_type) :: a
        logical :: keep
        integer :: i, j, k

        keep = .false.
        if (present(keep_zero_diagonal)) keep = keep_zero_diagonal
        a%n = size(dense, 2)
        allocate(a%col_ptr(a%n + 1))
        allocate(a%row_index(size(dense)), a%values(size(dense)))
        k = 0
        a%col_ptr(1) = 0
        do j = 1, size(dense, 2)
            do i = 1, size(dense, 1)
                if (abs(dense(i, j)) > 0.0_wp .or. (keep .and. i == j)) then
                    k = k + 1
                    a%row_index(k) = i - 1
                    a%values(k) = dense(i, j)
                end if
            end do
            a%col_ptr(j + 1) = k
        end do
        a%row_index = a%row_index(1:k)
        a%values = a%values(1:k)
    end function from_dense

    !> 5-point Laplacian on an m x m grid (Dirichlet), n = m**2, SPD.
    function laplacian_2d(m) result(a)
        integer, intent(in) :: m
        type(csc_type) :: a
        integer(ik), allocatable :: rows(:), cols(:)
        real(wp), allocatable :: values(:)
        integer :: i, j, k, node

        allocate(rows(5 * m * m), cols(5 * m * m), values(5 * m * m))
        k = 0
        do j = 1, m
            do i = 1, m
                node = i + (j - 1) * m
                call push(node, node, 4.0_wp)
                if (i > 1) call push(node, node - 1, -1.0_wp)
                if (i < m) call push(node, node + 1, -1.0_wp)
                if (j > 1) call push(node, node - m, -1.0_wp)
                if (j < m) call push(node, node + m, -1.0_wp)
            end do
        end do
        a = from_triplets(int(m * m, ik), rows(1:k), cols(1:k), values(1:k))

    contains

        subroutine push(row, col, value)
            integer, intent(in) :: row, col
            real(wp), intent(in) :: value

            k = k + 1
            rows(k) = row
            cols(k) = col
            values(k) = value
        end subroutine push
    end function laplacian_2d

    !> Random matrix of 3x3 blocks on a ring of `blocks` nodes with `random_links` extra
    !> random links per node (like crossings of a net), made strictly diagonally dominant
    !> with a positive diagonal. Symmetric blocks (B_ji = B_ij**T) give an SPD matrix.
    function random_block_matrix(blocks, symmetric, seed) result(a)
        integer, intent(in) :: blocks
        logical, intent(in) :: symmetric
        integer(ik), intent(in) :: seed
        type(csc_type) :: a
        integer(ik), allocatable :: rows(:), cols(:)
        real(wp), allocatable :: values(:), row_sum(:)
        real(wp) :: block(3, 3), u(1)
        integer(ik) :: state
        integer :: node, other, link, k, capacity, r, c, i

        capacity = 2 * 9 * blocks * (random_links + 1) + 9 * blocks
        allocate(rows(capacity), cols(capacity), values(capacity))
        state = seed
        k = 0
        do node = 1, blocks
            ! off-diagonal entries inside the diagonal block
            block = reshape(random_numbers(state, 9), [3, 3]) - 0.5_wp
            if (symmetric) block = 0.5_wp * (block + transpose(block))
            do c = 1, 3
                do r = 1, 3
                    if (r /= c) call push(3 * node - 3 + r, 3 * node - 3 + c, block(r, c))
                end do
            end do
            do link = 0, random_links
                if (link == 0) then
                    other = modulo(node, blocks) + 1
                else
                    u = random_numbers(state, 1)
                    other = min(1 + int(real(blocks, wp) * u(1)), blocks)
                end if
                if (other == node) cycle
                block = reshape(random_numbers(state, 9), [3, 3]) - 0.5_wp
                do c = 1, 3
                    do r = 1, 3
                        call push(3 * node - 3 + r, 3 * other - 3 + c, block(r, c))
                    end do
                end do
                if (.not. symmetric) block = reshape(random_numbers(state, 9), [3, 3]) &
                    - 0.5_wp
                do c = 1, 3
                    do r = 1, 3
                        ! symmetric: B_ji = B_ij**T
                        call push(3 * other - 3 + c, 3 * node - 3 + r, block(r, c))
                    end do
                end do
            end do
        end do
        a = from_triplets(int(3 * blocks, ik), rows(1:k), cols(1:k), values(1:k))
        ! diagonal = row sum of |off-diagonals| + 1 + random in [0, 1)
        allocate(row_sum(a%n), source=0.0_wp)
        do i = 1, size(a%values)
            row_sum(a%row_index(i) + 1) = row_sum(a%row_index(i) + 1) + abs(a%values(i))
        end do
        row_sum = row_sum + 1.0_wp + random_numbers(state, int(a%n))
        k = 0
        do i = 1, int(a%n)
            call push(i, i, row_sum(i))
        end do
        a = add_triplets(a, rows(1:k), cols(1:k), values(1:k))

    contains

        subroutine push(row, col, value)
            integer, intent(in) :: row, col
            real(wp), intent(in) :: value

            k = k + 1
            rows(k) = row
            cols(k) = col
            values(k) = value
        end subroutine push
    end function random_block_matrix

    !> CSC (sorted rows, duplicates summed) from 1-based triplets.
    function from_triplets(n, rows, cols, values) result(a)
        integer(ik), intent(in) :: n
        integer(ik), intent(in) :: rows(:), cols(:)
        real(wp), intent(in) :: values(:)
        type(csc_type) :: a
        real(wp), allocatable :: column(:)
        logical, allocatable :: used(:)
        integer(ik), allocatable :: start(:), order(:), next(:)
        integer(ik) :: j, k, i, p

        ! bucket the triplets by column, then collect each column through a dense marker
        allocate(start(n + 1), source=0_ik)
        do k = 1, size(cols)
            start(cols(k) + 1) = start(cols(k) + 1) + 1
        end do
        start(1) = 1
        do j = 2, n + 1
            start(j) = start(j) + start(j - 1)
        end do
        allocate(order(size(cols)), next(n))
        next = start(1:n)
        do k = 1, size(cols)
            order(next(cols(k))) = k
            next(cols(k)) = next(cols(k)) + 1
        end do
        allocate(column(n), source=0.0_wp)
        allocate(used(n), source=.false.)
        a%n = n
        allocate(a%col_ptr(n + 1), a%row_index(size(rows)), a%values(size(rows)))
        a%col_ptr(1) = 0
        p = 0
        do j = 1, n
            do k = start(j), start(j + 1) - 1
                i = rows(order(k))
                column(i) = column(i) + values(order(k))
                used(i) = .true.
            end do
            do i = 1, n
                if (used(i)) then
                    p = p + 1
                    a%row_index(p) = i - 1
                    a%values(p) = column(i)
                    column(i) = 0.0_wp
                    used(i) = .false.
                end if
            end do
            a%col_ptr(j + 1) = p
        end do
        a%row_index = a%row_index(1:p)
        a%values = a%values(1:p)
    end function from_triplets

    !> a + the matrix given by 1-based triplets.
    function add_triplets(a, rows, cols, values) result(sum)
        type(csc_type), intent(in) :: a
        integer(ik), intent(in) :: rows(:), cols(:)
        real(wp), intent(in) :: values(:)
        type(csc_type) :: sum
        integer(ik), allocatable :: a_rows(:), a_cols(:)
        integer(ik) :: j, k

        allocate(a_rows(size(a%values)), a_cols(size(a%values)))
        do j = 1, a%n
            do k = a%col_ptr(j) + 1, a%col_ptr(j + 1)
                a_rows(k) = a%row_index(k) + 1
                a_cols(k) = j
            end do
        end do
        sum = from_triplets(a%n, [a_rows, rows], [a_cols, cols], [a%values, values])
    end function add_triplets

    !> a%values(diagonal) += shift (every diagonal entry must be in the pattern).
    subroutine add_to_diagonal(a, shift)
        type(csc_type), intent(inout) :: a
        real(wp), intent(in) :: shift
        integer(ik) :: j, k

        do j = 1, a%n
            do k = a%col_ptr(j) + 1, a%col_ptr(j + 1)
                if (a%row_index(k) + 1 == j) a%values(k) = a%values(k) + shift
            end do
        end do
    end subroutine add_to_diagonal

    !> y = A x for the full stored pattern.
    pure function multiply(a, x) result(y)
        type(csc_type), intent(in) :: a
        real(wp), intent(in) :: x(:)
        real(wp), allocatable :: y(:)
        integer(ik) :: j, k

        allocate(y(a%n), source=0.0_wp)
        do j = 1, a%n
            do k = a%col_ptr(j) + 1, a%col_ptr(j + 1)
                y(a%row_index(k) + 1) = y(a%row_index(k) + 1) + a%values(k) * x(j)
            end do
        end do
    end function multiply

    ! ---- helpers: numbers and text -------------------------------------------------------

    !> Deterministic vector with entries in [-1, 1).
    function random_vector(n, seed) result(x)
        integer(ik), intent(in) :: n, seed
        real(wp), allocatable :: x(:)
        integer(ik) :: state

        state = seed
        x = 2.0_wp * random_numbers(state, int(n)) - 1.0_wp
    end function random_vector

    !> n numbers in [0, 1) from a xorshift64 generator (shifts and xor only, no overflow).
    function random_numbers(state, n) result(r)
        integer(ik), intent(inout) :: state
        integer, intent(in) :: n
        real(wp) :: r(n)
        integer :: i

        if (state == 0) state = 88172645463325252_ik
        do i = 1, n
            state = ieor(state, shiftl(state, 13))
            state = ieor(state, shiftr(state, 7))
            state = ieor(state, shiftl(state, 17))
            r(i) = real(shiftr(state, 11), wp) * 2.0_wp**(-53)
        end do
    end function random_numbers

    !> ||x - y|| / ||y|| in the max norm.
    pure function relative_difference(x, y) result(difference)
        real(wp), intent(in) :: x(:), y(:)
        real(wp) :: difference

        difference = maxval(abs(x - y)) / maxval(abs(y))
    end function relative_difference

end module test_linalg
