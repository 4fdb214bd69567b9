! SPDX-License-Identifier: MIT
!> Sparse LU with UMFPACK's 64-bit interface (`umfpack_dl_*`): the general solver for
!> unsymmetric or indefinite matrices. The Symbolic object is built at the first
!> factorisation after analyse, with the values: UMFPACK then sees which diagonal entries
!> are nonzero and can choose its symmetric strategy (AMD on A + A^T, diagonal pivots
!> preferred) where it fits; given the pattern alone it assumes a zero-free diagonal is
!> unlikely and takes the unsymmetric one, which is slower on the tangents. The object is
!> kept while the pattern is unchanged (later factorisations are numeric only) and
!> iterative refinement is off, Newton corrects (docs/decisions.md, 'UMFPACK analysed
!> with the values; no iterative refinement').
module yarnfort_linalg_backend_umfpack
    use, intrinsic :: iso_c_binding, only: c_long, c_double, c_ptr, c_null_ptr, c_associated
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_linalg_backend_direct, only: direct_solver_type, describe_status
    use yarnfort_text, only: format_integer, format_short
    use yarnfort_linalg_binding_umfpack, only: umfpack_control, umfpack_info, umfpack_prl, &
        umfpack_irstep, umfpack_rcond, umfpack_a, umfpack_ok, &
        umfpack_warning_singular_matrix, umfpack_error_out_of_memory, &
        umfpack_error_invalid_numeric_object, umfpack_error_invalid_symbolic_object, &
        umfpack_error_argument_missing, umfpack_error_n_nonpositive, &
        umfpack_error_invalid_matrix, umfpack_error_different_pattern, &
        umfpack_error_invalid_system, umfpack_error_invalid_permutation, &
        umfpack_error_internal_error, umfpack_error_ordering_failed, umfpack_dl_defaults, &
        umfpack_dl_symbolic, umfpack_dl_qsymbolic, umfpack_dl_numeric, umfpack_dl_wsolve, &
        umfpack_dl_free_symbolic, umfpack_dl_free_numeric, umfpack_size_of_unit, &
        umfpack_numeric_size, umfpack_peak_memory, umfpack_lnz, umfpack_unz, &
        umfpack_strategy_used, umfpack_strategy, umfpack_strategy_symmetric, &
        umfpack_alloc_init, umfpack_lnz_estimate, umfpack_unz_estimate
    implicit none
    private

    public :: umfpack_solver_type, umfpack_refinement_steps, umfpack_memory_type

    !> Iterative refinement steps per solve (Control(UMFPACK_IRSTEP)): none, Newton
    !> corrects (docs/decisions.md, 'UMFPACK analysed with the values; no iterative
    !> refinement').
    integer, parameter :: umfpack_refinement_steps = 0
    !> UMFPACK print level (Control(UMFPACK_PRL)): library code never prints.
    integer, parameter :: umfpack_print_level = 0

    !> UMFPACK's own account of its memory at the last numeric factorisation.
    type :: umfpack_memory_type
        !> Bytes of the Numeric object (the LU factors and their indices), and peak bytes
        !> UMFPACK held during symbolic analysis and numeric factorisation.
        real(wp) :: numeric_bytes = 0.0_wp, peak_bytes = 0.0_wp
        !> Nonzeros of L and U, diagonal included.
        real(wp) :: l_nonzeros = 0.0_wp, u_nonzeros = 0.0_wp
        !> Strategy of the symbolic analysis (UMFPACK_STRATEGY_USED: 1 unsymmetric, 3
        !> symmetric), 0 before the first factorisation.
        integer :: strategy = 0
    end type umfpack_memory_type

    !> UMFPACK solver. Owns C handles: never copy an analysed object by assignment.
    type, extends(direct_solver_type) :: umfpack_solver_type
        private
        real(c_double) :: control(0:umfpack_control - 1) = 0.0_c_double
        real(c_double) :: info(0:umfpack_info - 1) = 0.0_c_double
        type(c_ptr) :: symbolic = c_null_ptr
        type(c_ptr) :: numeric = c_null_ptr
        !> Solve workspace (umfpack_dl_wsolve) and a copy of the right-hand side.
        integer(c_long), allocatable :: int_work(:)
        real(c_double), allocatable :: real_work(:), rhs_copy(:)
        type(umfpack_memory_type) :: memory
        !> A column order given for this pattern (set_column_order), 0-based, and the
        !> nonzeros of L + U it gives without pivoting (diagonals included).
        integer(c_long), allocatable :: column_order(:)
        real(wp) :: order_factor_nonzeros = 0.0_wp
    contains
        procedure :: set_column_order
        !> UMFPACK's memory figures of the last numeric factorisation and the strategy of its
    !> symbolic analysis (benchmarks).
        procedure :: get_memory
        procedure :: analyse_pattern
        procedure :: factor_values
        procedure :: solve_rhs_columns
        procedure :: release
        procedure :: get_name
        final :: finalize
    end type umfpack_solver_type

contains

    !> Set the controls; the Symbolic object follows at the first factorisation.
    subroutine analyse_pattern(self, error)
        class(umfpack_solver_type), intent(inout) :: self
        type(error_type), allocatable, intent(out) :: error

        call umfpack_dl_defaults(self%control)
        self%control(umfpack_irstep) = real(umfpack_refinement_steps, c_double)
        self%control(umfpack_prl) = real(umfpack_print_level, c_double)
        allocate(self%int_work(self%n), self%real_work(self%n), self%rhs_copy(self%n))
    end subroutine analyse_pattern

    !> Use `order` (0-based: column order(k) is the k-th) for both the rows and the
    !> columns, with the symmetric strategy, in the symbolic analysis of the analysed
    !> pattern instead of UMFPACK's own ordering: for an AMD order of A + A^T already
    !> at hand (lu_choice), what UMFPACK's symmetric strategy would compute again.
    !> `factor_nonzeros` (L + U, diagonals included, diagonal pivots) sizes the numeric
    !> factorisation's first allocation as UMFPACK sizes it after its own AMD; without
    !> it UMFPACK starts from its upper bound (woven net of 963,600 unknowns: peak RSS
    !> 3.6 -> 7.6 GB).
    subroutine set_column_order(self, order, factor_nonzeros, error)
        class(umfpack_solver_type), intent(inout) :: self
        integer(c_long), intent(in) :: order(:)
        real(wp), intent(in) :: factor_nonzeros
        type(error_type), allocatable, intent(out) :: error

        if (self%n == 0 .or. c_associated(self%symbolic)) then
            call fatal_error(error, 'umfpack: set_column_order called before analyse ' &
                // 'or after the first factorisation')
        else if (size(order, kind=ik) /= self%n) then
            call fatal_error(error, 'umfpack: column order of size ' &
                // format_integer(size(order, kind=ik)) // ' for order ' &
                // format_integer(self%n))
        else
            self%column_order = order
            self%order_factor_nonzeros = factor_nonzeros
        end if
    end subroutine set_column_order

    !> Numeric factorisation with the analysed Symbolic object; a singular matrix is an error.
    subroutine factor_values(self, values, error)
        class(umfpack_solver_type), intent(inout) :: self
        real(wp), intent(in) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        integer(c_long) :: status

        call umfpack_dl_free_numeric(self%numeric)
        if (.not. c_associated(self%symbolic)) then
            if (allocated(self%column_order)) then
                self%control(umfpack_strategy) = real(umfpack_strategy_symmetric, c_double)
                status = umfpack_dl_qsymbolic(self%n, self%n, self%col_ptr, &
                    self%row_index, values, self%column_order, self%symbolic, &
                    self%control, self%info)
            else
                status = umfpack_dl_symbolic(self%n, self%n, self%col_ptr, &
                    self%row_index, values, self%symbolic, self%control, self%info)
            end if
            if (status /= umfpack_ok) then
                call umfpack_dl_free_symbolic(self%symbolic)
                call self%fail(error, 'symbolic analysis', status_message(status))
                return
            end if
            self%memory%strategy = nint(self%info(umfpack_strategy_used))
            if (allocated(self%column_order)) call set_first_allocation()
        end if
        status = umfpack_dl_numeric(self%col_ptr, self%row_index, values, self%symbolic, &
            self%numeric, self%control, self%info)
        if (status == umfpack_ok) then
            associate(unit => self%info(umfpack_size_of_unit))
                self%memory%numeric_bytes = self%info(umfpack_numeric_size) * unit
                self%memory%peak_bytes = self%info(umfpack_peak_memory) * unit
            end associate
            self%memory%l_nonzeros = self%info(umfpack_lnz)
            self%memory%u_nonzeros = self%info(umfpack_unz)
            return
        end if

        call umfpack_dl_free_numeric(self%numeric)
        if (status == umfpack_warning_singular_matrix) then
            call self%fail(error, 'numeric factorisation', 'matrix is ' &
                // 'singular (zero pivot, UMFPACK_WARNING_singular_matrix, rcond = ' &
                // format_short(self%info(umfpack_rcond), 4) // ')')
        else
            call self%fail(error, 'numeric factorisation', status_message(status))
        end if
    contains
        !> UMFPACK's own rule after AMD (umfpack_numeric.c): 1.2 min(1, (nonzeros of A +
        !> AMD's L + U, the diagonal once) / the symbolic bound on L + U, the diagonal
        !> once).
        subroutine set_first_allocation()
            real(wp) :: bound

            bound = self%info(umfpack_lnz_estimate) + self%info(umfpack_unz_estimate) &
                - real(self%n, wp)
            if (bound <= 0.0_wp .or. self%order_factor_nonzeros <= 0.0_wp) return
            self%control(umfpack_alloc_init) = 1.2_wp * min(1.0_wp, (real(size( &
                self%row_index), wp) + self%order_factor_nonzeros - real(self%n, wp)) / bound)
        end subroutine set_first_allocation
    end subroutine factor_values

    !> Overwrite each column of rhs with its solution, one column at a time, without
    !> refinement and without allocation.
    subroutine solve_rhs_columns(self, rhs, error)
        class(umfpack_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: rhs(:, :)
        type(error_type), allocatable, intent(out) :: error
        integer(c_long) :: status
        integer :: c

        do c = 1, size(rhs, 2)
            self%rhs_copy(:) = rhs(:, c)
            status = umfpack_dl_wsolve(umfpack_a, x=rhs(:, c), b=self%rhs_copy, &
                numeric=self%numeric, control=self%control, info=self%info, &
                wi=self%int_work, w=self%real_work)
            if (status /= umfpack_ok) then
                call self%fail(error, 'solve', status_message(status))
                return
            end if
        end do
    end subroutine solve_rhs_columns

    !> Free the Numeric and Symbolic objects.
    subroutine release(self)
        class(umfpack_solver_type), intent(inout) :: self

        if (c_associated(self%numeric)) call umfpack_dl_free_numeric(self%numeric)
        if (c_associated(self%symbolic)) call umfpack_dl_free_symbolic(self%symbolic)
        self%numeric = c_null_ptr
        self%symbolic = c_null_ptr
        if (allocated(self%int_work)) deallocate(self%int_work)
        if (allocated(self%real_work)) deallocate(self%real_work)
        if (allocated(self%rhs_copy)) deallocate(self%rhs_copy)
        if (allocated(self%column_order)) deallocate(self%column_order)
    end subroutine release

    pure function get_memory(self) result(memory)
        class(umfpack_solver_type), intent(in) :: self
        type(umfpack_memory_type) :: memory

        memory = self%memory
    end function get_memory

    pure function get_name(self) result(name)
        class(umfpack_solver_type), intent(in) :: self
        character(len=:), allocatable :: name

        name = 'umfpack'
    end function get_name

    subroutine finalize(self)
        type(umfpack_solver_type), intent(inout) :: self

        call self%destroy()
    end subroutine finalize

    !> The umfpack.h name of a status code and what it means.
    pure function status_message(status) result(message)
        integer(c_long), intent(in) :: status
        character(len=:), allocatable :: message

        message = describe_status(int(status, c_long), [integer(c_long) :: &
            umfpack_warning_singular_matrix, umfpack_error_out_of_memory, &
            umfpack_error_invalid_numeric_object, umfpack_error_invalid_symbolic_object, &
            umfpack_error_argument_missing, umfpack_error_n_nonpositive, &
            umfpack_error_invalid_matrix, umfpack_error_different_pattern, &
            umfpack_error_invalid_system, umfpack_error_invalid_permutation, &
            umfpack_error_internal_error, umfpack_error_ordering_failed], &
            [character(len=63) :: &
            'matrix is singular (UMFPACK_WARNING_singular_matrix)', &
            'out of memory (UMFPACK_ERROR_out_of_memory)', &
            'invalid Numeric object (UMFPACK_ERROR_invalid_Numeric_object)', &
            'invalid Symbolic object (UMFPACK_ERROR_invalid_Symbolic_object)', &
            'argument missing (UMFPACK_ERROR_argument_missing)', &
            'matrix order not positive (UMFPACK_ERROR_n_nonpositive)', &
            'invalid CSC matrix (UMFPACK_ERROR_invalid_matrix)', &
            'pattern changed since analyse (UMFPACK_ERROR_different_pattern)', &
            'invalid system (UMFPACK_ERROR_invalid_system)', &
            'invalid permutation (UMFPACK_ERROR_invalid_permutation)', &
            'internal error (UMFPACK_ERROR_internal_error)', &
            'ordering failed (UMFPACK_ERROR_ordering_failed)'], 'UMFPACK')
    end function status_message

end module yarnfort_linalg_backend_umfpack
