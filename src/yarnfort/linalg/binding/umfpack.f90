! SPDX-License-Identifier: MIT
!> bind(C) interfaces to the 64-bit UMFPACK API (`umfpack_dl_*`, SuiteSparse_long = C long)
!> and the array indices and status codes of umfpack.h (SuiteSparse 5.x). Only
!> yarnfort_linalg_backend_umfpack uses this module.
module yarnfort_linalg_binding_umfpack
    use, intrinsic :: iso_c_binding, only: c_long, c_double, c_ptr
    implicit none
    private

    public :: umfpack_control, umfpack_info
    public :: umfpack_size_of_unit, umfpack_numeric_size, umfpack_peak_memory, umfpack_lnz, &
        umfpack_unz, umfpack_strategy_used
    public :: umfpack_prl, umfpack_irstep, umfpack_status, umfpack_rcond
    public :: umfpack_ordering, umfpack_ordering_amd, umfpack_ordering_metis
    public :: umfpack_flops_estimate
    public :: umfpack_a
    public :: umfpack_ok, umfpack_warning_singular_matrix, umfpack_error_out_of_memory
    public :: umfpack_error_invalid_numeric_object, umfpack_error_invalid_symbolic_object
    public :: umfpack_error_argument_missing, umfpack_error_n_nonpositive
    public :: umfpack_error_invalid_matrix, umfpack_error_different_pattern
    public :: umfpack_error_invalid_system, umfpack_error_invalid_permutation
    public :: umfpack_error_internal_error, umfpack_error_ordering_failed
    public :: umfpack_dl_defaults, umfpack_dl_symbolic, umfpack_dl_qsymbolic
    public :: umfpack_dl_numeric
    public :: umfpack_strategy, umfpack_strategy_symmetric, umfpack_symbolic_time
    public :: umfpack_alloc_init, umfpack_lnz_estimate, umfpack_unz_estimate
    public :: umfpack_dl_wsolve, umfpack_dl_free_symbolic, umfpack_dl_free_numeric

    !> Sizes of the Control and Info arrays (UMFPACK_CONTROL, UMFPACK_INFO).
    integer, parameter :: umfpack_control = 20, umfpack_info = 90

    !> 0-based indices into Control: print level, maximum iterative refinement steps.
    integer, parameter :: umfpack_prl = 0, umfpack_irstep = 7
    !> 0-based index into Control: the fill-reducing ordering, and two of its values
    !> (AMD/COLAMD, UMFPACK's default; METIS, through CHOLMOD).
    integer, parameter :: umfpack_ordering = 10
    integer, parameter :: umfpack_ordering_amd = 1, umfpack_ordering_metis = 3
    !> 0-based indices into Info: status, reciprocal condition estimate.
    integer, parameter :: umfpack_status = 0, umfpack_rcond = 67
    !> 0-based indices into Info: bytes per Unit; size of the Numeric object and peak
    !> memory of symbolic analysis and numeric factorisation, in Units; nonzeros of L
    !> and U (diagonal included).
    integer, parameter :: umfpack_size_of_unit = 3, umfpack_numeric_size = 40, &
        umfpack_peak_memory = 41, umfpack_lnz = 43, umfpack_unz = 44
    !> 0-based index into Control: the strategy, and its symmetric value (AMD on A + A^T,
    !> diagonal pivots preferred; with a given column order, that order for both).
    integer, parameter :: umfpack_strategy = 5, umfpack_strategy_symmetric = 3
    !> 0-based index into Info: the strategy used (1 unsymmetric, 3 symmetric).
    integer, parameter :: umfpack_strategy_used = 18
    !> 0-based index into Info: CPU seconds of the symbolic analysis.
    integer, parameter :: umfpack_symbolic_time = 15
    !> 0-based index into Control: the numeric factorisation's first allocation for
    !> the factors and fronts, as a fraction of the symbolic analysis's upper bound
    !> (used unless UMFPACK ordered with AMD itself).
    integer, parameter :: umfpack_alloc_init = 6
    !> 0-based indices into Info: the symbolic analysis's upper bounds on the nonzeros
    !> of L and U (diagonal included).
    integer, parameter :: umfpack_lnz_estimate = 23, umfpack_unz_estimate = 24
    !> 0-based index into Info: the flops of the factorisation that the symbolic
    !> analysis predicts.
    integer, parameter :: umfpack_flops_estimate = 22

    !> System to solve: A x = b.
    integer(c_long), parameter :: umfpack_a = 0

    !> Status codes returned by the umfpack_dl_* functions.
    integer(c_long), parameter :: umfpack_ok = 0
    integer(c_long), parameter :: umfpack_warning_singular_matrix = 1
    integer(c_long), parameter :: umfpack_error_out_of_memory = -1
    integer(c_long), parameter :: umfpack_error_invalid_numeric_object = -3
    integer(c_long), parameter :: umfpack_error_invalid_symbolic_object = -4
    integer(c_long), parameter :: umfpack_error_argument_missing = -5
    integer(c_long), parameter :: umfpack_error_n_nonpositive = -6
    integer(c_long), parameter :: umfpack_error_invalid_matrix = -8
    integer(c_long), parameter :: umfpack_error_different_pattern = -11
    integer(c_long), parameter :: umfpack_error_invalid_system = -13
    integer(c_long), parameter :: umfpack_error_invalid_permutation = -15
    integer(c_long), parameter :: umfpack_error_internal_error = -911
    integer(c_long), parameter :: umfpack_error_ordering_failed = -18

    interface
        !> void umfpack_dl_defaults(double Control[UMFPACK_CONTROL])
        subroutine umfpack_dl_defaults(control) bind(C, name='umfpack_dl_defaults')
            import :: c_double
            real(c_double), intent(out) :: control(*)
        end subroutine umfpack_dl_defaults

        !> Symbolic analysis; Ax may be absent (NULL): the analysis then uses the pattern.
        function umfpack_dl_symbolic(n_row, n_col, ap, ai, ax, symbolic, control, info) &
                result(status) bind(C, name='umfpack_dl_symbolic')
            import :: c_long, c_double, c_ptr
            integer(c_long), value :: n_row, n_col
            integer(c_long), intent(in) :: ap(*), ai(*)
            real(c_double), intent(in), optional :: ax(*)
            type(c_ptr), intent(inout) :: symbolic
            real(c_double), intent(in) :: control(*)
            real(c_double), intent(inout) :: info(*)
            integer(c_long) :: status
        end function umfpack_dl_symbolic

        !> Symbolic analysis with the given column pre-ordering (0-based) instead of
        !> AMD or COLAMD.
        function umfpack_dl_qsymbolic(n_row, n_col, ap, ai, ax, qinit, symbolic, control, &
                info) result(status) bind(C, name='umfpack_dl_qsymbolic')
            import :: c_long, c_double, c_ptr
            integer(c_long), value :: n_row, n_col
            integer(c_long), intent(in) :: ap(*), ai(*)
            real(c_double), intent(in), optional :: ax(*)
            integer(c_long), intent(in) :: qinit(*)
            type(c_ptr), intent(inout) :: symbolic
            real(c_double), intent(in) :: control(*)
            real(c_double), intent(inout) :: info(*)
            integer(c_long) :: status
        end function umfpack_dl_qsymbolic

        function umfpack_dl_numeric(ap, ai, ax, symbolic, numeric, control, info) &
                result(status) bind(C, name='umfpack_dl_numeric')
            import :: c_long, c_double, c_ptr
            integer(c_long), intent(in) :: ap(*), ai(*)
            real(c_double), intent(in) :: ax(*)
            type(c_ptr), value :: symbolic
            type(c_ptr), intent(inout) :: numeric
            real(c_double), intent(in) :: control(*)
            real(c_double), intent(inout) :: info(*)
            integer(c_long) :: status
        end function umfpack_dl_numeric

        !> Solve with caller-provided workspace (no allocation). Ap, Ai, Ax may be absent
        !> (NULL) when Control(UMFPACK_IRSTEP) == 0. X and B must not overlap.
        function umfpack_dl_wsolve(sys, ap, ai, ax, x, b, numeric, control, info, wi, w) &
                result(status) bind(C, name='umfpack_dl_wsolve')
            import :: c_long, c_double, c_ptr
            integer(c_long), value :: sys
            integer(c_long), intent(in), optional :: ap(*), ai(*)
            real(c_double), intent(in), optional :: ax(*)
            real(c_double), intent(inout) :: x(*)
            real(c_double), intent(in) :: b(*)
            type(c_ptr), value :: numeric
            real(c_double), intent(in) :: control(*)
            real(c_double), intent(inout) :: info(*)
            integer(c_long), intent(inout) :: wi(*)
            real(c_double), intent(inout) :: w(*)
            integer(c_long) :: status
        end function umfpack_dl_wsolve

        !> Free and nullify the Symbolic object (a NULL handle is ignored).
        subroutine umfpack_dl_free_symbolic(symbolic) bind(C, name='umfpack_dl_free_symbolic')
            import :: c_ptr
            type(c_ptr), intent(inout) :: symbolic
        end subroutine umfpack_dl_free_symbolic

        !> Free and nullify the Numeric object (a NULL handle is ignored).
        subroutine umfpack_dl_free_numeric(numeric) bind(C, name='umfpack_dl_free_numeric')
            import :: c_ptr
            type(c_ptr), intent(inout) :: numeric
        end subroutine umfpack_dl_free_numeric
    end interface

end module yarnfort_linalg_binding_umfpack
