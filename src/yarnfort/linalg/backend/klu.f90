! SPDX-License-Identifier: MIT
!> Sparse LU with KLU's 64-bit interface (`klu_l_*`): BTF + AMD ordering, fastest for
!> small systems such as unit cells (docs/decisions.md, 'Linear solver: KLU up to 5,000
!> unknowns, UMFPACK above'). After the first factorisation
!> `factor` refactors with the old pivot order (`klu_l_refactor`) and falls back to a
!> full pivoting factorisation when that hits a zero pivot or the cheap reciprocal
!> condition estimate drops below `refactor_rcond_min` (the rule of SUNDIALS'
!> SUNLinSol_KLU).
module yarnfort_linalg_backend_klu
    use, intrinsic :: iso_c_binding, only: c_long, c_ptr, c_null_ptr, c_null_funptr, &
        c_associated, c_f_pointer
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_linalg_backend_direct, only: direct_solver_type, describe_status
    use yarnfort_text, only: format_integer
    use yarnfort_linalg_binding_klu, only: klu_l_common, klu_ok, klu_singular, &
        klu_out_of_memory, klu_invalid, klu_too_large, klu_l_defaults, klu_l_analyze, &
        klu_l_analyze_given, klu_l_factor, klu_l_refactor, klu_l_solve, klu_l_rcond, &
        klu_l_free_symbolic, klu_l_numeric_sizes, klu_l_symbolic, klu_l_free_numeric
    implicit none
    private

    public :: klu_solver_type, default_refactor_rcond_min

    !> Smallest crude reciprocal condition number (min|U(k,k)|/max|U(k,k)|) accepted after
    !> a refactorisation with the old pivot order: epsilon**(2/3), as in SUNLinSol_KLU.
    real(wp), parameter :: default_refactor_rcond_min = epsilon(1.0_wp)**(2.0_wp / 3.0_wp)

    !> C TRUE as returned by the klu_l_* functions and stored in klu_l_common flags.
    integer(c_long), parameter :: c_true = 1

    !> KLU solver. Owns C handles: never copy an analysed object by assignment.
    type, extends(direct_solver_type) :: klu_solver_type
        private
        !> Refactorisations below this reciprocal condition estimate are redone with pivoting.
        real(wp), public :: refactor_rcond_min = default_refactor_rcond_min
        !> Fill-reducing ordering: AMD on A + A^T (KLU's default), or, for unsymmetric
        !> patterns, the sparser of AMD and COLAMD, chosen by factoring the first matrix
        !> both ways: neither wins everywhere on the friction Jacobian (docs/decisions.md,
        !> 'KLU ordering of the friction Jacobian: the sparser of AMD and COLAMD').
        logical, public :: unsymmetric_ordering = .false.
        !> A symmetric column order (0-based: column given_order(k) is the k-th) to use
        !> instead of AMD's (klu_l_analyze_given, the rows in the same order; BTF still
        !> splits reducible patterns); set before `analyse`.
        integer(c_long), allocatable, public :: given_order(:)
        type(klu_l_common) :: common
        logical :: common_ready = .false.
        type(c_ptr) :: symbolic = c_null_ptr
        type(c_ptr) :: numeric = c_null_ptr
        !> The COLAMD analysis, until the first factorisation has chosen between the two.
        type(c_ptr) :: symbolic_colamd = c_null_ptr
    contains
        procedure :: analyse_pattern
        procedure :: factor_values
        procedure :: solve_rhs_columns
        procedure :: release
        procedure :: get_name
        !> AMD's prediction of the factorisation's cost and its ordering
        !> (yarnfort_linalg_composite_lu_choice).
        procedure :: get_prediction
        procedure :: get_symmetric_order
        final :: finalize
    end type klu_solver_type

contains

    !> Order the pattern (BTF + AMD).
    subroutine analyse_pattern(self, error)
        class(klu_solver_type), intent(inout) :: self
        type(error_type), allocatable, intent(out) :: error

        if (klu_l_defaults(self%common) /= c_true) then
            call fatal_error(error, 'klu: klu_l_defaults failed')
            return
        end if
        self%common%user_order = c_null_funptr
        self%common%user_data = c_null_ptr
        self%common%halt_if_singular = c_true
        self%common_ready = .true.
        if (allocated(self%given_order)) then
            self%symbolic = klu_l_analyze_given(self%n, self%col_ptr, self%row_index, &
                self%given_order, self%given_order, self%common)
        else
            self%symbolic = klu_l_analyze(self%n, self%col_ptr, self%row_index, self%common)
        end if
        if (.not. c_associated(self%symbolic)) then
            call self%fail(error, 'symbolic analysis', status_message(self%common%status))
            return
        end if
        if (self%unsymmetric_ordering) then
            self%common%ordering = 1
            self%symbolic_colamd = klu_l_analyze(self%n, self%col_ptr, self%row_index, &
                self%common)
            self%common%ordering = 0
        end if
    end subroutine analyse_pattern

    !> Refactor with the old pivot order when possible, else factor with pivoting.
    subroutine factor_values(self, values, error)
        class(klu_solver_type), intent(inout) :: self
        real(wp), intent(in) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        integer(c_long) :: ok

        if (c_associated(self%numeric)) then
            ok = klu_l_refactor(self%col_ptr, self%row_index, values, self%symbolic, &
                self%numeric, self%common)
            if (ok == c_true .and. self%common%status == klu_ok) then
                ok = klu_l_rcond(self%symbolic, self%numeric, self%common)
                if (ok == c_true .and. self%common%rcond >= self%refactor_rcond_min) return
            end if
            ok = klu_l_free_numeric(self%numeric, self%common)
        end if

        if (c_associated(self%symbolic_colamd)) call choose_ordering()
        self%numeric = klu_l_factor(self%col_ptr, self%row_index, values, self%symbolic, &
            self%common)
        if (c_associated(self%numeric)) return
        if (self%common%status == klu_singular) then
            call self%fail(error, 'factorisation', 'matrix is singular (zero pivot in ' &
                // 'column ' // format_integer(int(self%common%singular_col, ik)) &
                // ', KLU_SINGULAR)')
        else
            call self%fail(error, 'factorisation', status_message(self%common%status))
        end if
    contains
        !> Factor with the COLAMD analysis; keep it if its factors are sparser than
        !> AMD's (then the AMD factorisation below is the only one made twice).
        subroutine choose_ordering()
            type(c_ptr) :: trial, amd_numeric
            type(klu_l_numeric_sizes), pointer :: colamd_sizes, amd_sizes

            trial = klu_l_factor(self%col_ptr, self%row_index, values, self%symbolic_colamd, &
                self%common)
            amd_numeric = klu_l_factor(self%col_ptr, self%row_index, values, self%symbolic, &
                self%common)
            if (c_associated(trial) .and. c_associated(amd_numeric)) then
                call c_f_pointer(trial, colamd_sizes)
                call c_f_pointer(amd_numeric, amd_sizes)
                if (colamd_sizes%lnz + colamd_sizes%unz < amd_sizes%lnz + amd_sizes%unz) then
                    ok = klu_l_free_symbolic(self%symbolic, self%common)
                    self%symbolic = self%symbolic_colamd
                    self%symbolic_colamd = c_null_ptr
                end if
            end if
            if (c_associated(trial)) ok = klu_l_free_numeric(trial, self%common)
            if (c_associated(amd_numeric)) ok = klu_l_free_numeric(amd_numeric, self%common)
            if (c_associated(self%symbolic_colamd)) then
                ok = klu_l_free_symbolic(self%symbolic_colamd, self%common)
            end if
            self%symbolic_colamd = c_null_ptr
        end subroutine choose_ordering
    end subroutine factor_values

    !> Overwrite each column of rhs with its solution in one call, in place, without
    !> allocation (KLU sweeps the factors once for every 4 columns; each column's
    !> arithmetic is that of a single solve).
    subroutine solve_rhs_columns(self, rhs, error)
        class(klu_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: rhs(:, :)
        type(error_type), allocatable, intent(out) :: error
        integer(c_long) :: ok

        ok = klu_l_solve(self%symbolic, self%numeric, self%n, size(rhs, 2, kind=c_long), &
            rhs, self%common)
        if (ok /= c_true) then
            call self%fail(error, 'solve', status_message(self%common%status))
        end if
    end subroutine solve_rhs_columns

    !> Free the Numeric and Symbolic objects.
    subroutine release(self)
        class(klu_solver_type), intent(inout) :: self
        integer(c_long) :: ok

        if (self%common_ready) then
            if (c_associated(self%numeric)) ok = klu_l_free_numeric(self%numeric, self%common)
            if (c_associated(self%symbolic)) then
                ok = klu_l_free_symbolic(self%symbolic, self%common)
            end if
            if (c_associated(self%symbolic_colamd)) then
                ok = klu_l_free_symbolic(self%symbolic_colamd, self%common)
            end if
        end if
        self%numeric = c_null_ptr
        self%symbolic = c_null_ptr
        self%symbolic_colamd = c_null_ptr
    end subroutine release

    !> Flops of a factorisation and nonzeros of L + U that the AMD ordering of the last
    !> analysis predicts without pivoting (KLU's factors of the friction Jacobians never
    !> pivot off the diagonal: docs/decisions.md, 'Not kept: KLU pivoting threshold, row
    !> scaling, no BTF'); 0 before analyse.
    subroutine get_prediction(self, flops, factor_nonzeros)
        class(klu_solver_type), intent(in) :: self
        real(wp), intent(out) :: flops, factor_nonzeros
        type(klu_l_symbolic), pointer :: estimates

        flops = 0.0_wp
        factor_nonzeros = 0.0_wp
        if (.not. c_associated(self%symbolic)) return
        call c_f_pointer(self%symbolic, estimates)
        flops = estimates%est_flops
        factor_nonzeros = estimates%lnz + estimates%unz
    end subroutine get_prediction

    !> The column order of the last analysis (0-based: column order(k) is the k-th) when
    !> it is a symmetric permutation (the rows in the same order: BTF matched every
    !> column to its diagonal, as on a zero-free diagonal) and AMD made it; with the
    !> symmetry AMD saw in the largest block. Not allocated otherwise.
    subroutine get_symmetric_order(self, order, symmetry)
        class(klu_solver_type), intent(in) :: self
        integer(c_long), allocatable, intent(out) :: order(:)
        real(wp), intent(out) :: symmetry
        type(klu_l_symbolic), pointer :: symbolic
        integer(c_long), pointer :: p(:), q(:)

        symmetry = 0.0_wp
        if (.not. c_associated(self%symbolic) .or. self%unsymmetric_ordering) return
        call c_f_pointer(self%symbolic, symbolic)
        if (symbolic%ordering /= 0) return
        call c_f_pointer(symbolic%p, p, [symbolic%n])
        call c_f_pointer(symbolic%q, q, [symbolic%n])
        if (any(p /= q)) return
        order = q
        symmetry = symbolic%symmetry
    end subroutine get_symmetric_order

    pure function get_name(self) result(name)
        class(klu_solver_type), intent(in) :: self
        character(len=:), allocatable :: name

        name = 'klu'
    end function get_name

    subroutine finalize(self)
        type(klu_solver_type), intent(inout) :: self

        call self%destroy()
    end subroutine finalize

    !> The klu.h name of a status code and what it means.
    pure function status_message(status) result(message)
        integer(c_long), intent(in) :: status
        character(len=:), allocatable :: message

        message = describe_status(int(status, c_long), [integer(c_long) :: &
            klu_singular, klu_out_of_memory, klu_invalid, klu_too_large], &
            [character(len=40) :: &
            'matrix is singular (KLU_SINGULAR)', &
            'out of memory (KLU_OUT_OF_MEMORY)', &
            'invalid matrix or argument (KLU_INVALID)', &
            'integer overflow (KLU_TOO_LARGE)'], 'KLU')
    end function status_message

end module yarnfort_linalg_backend_klu
