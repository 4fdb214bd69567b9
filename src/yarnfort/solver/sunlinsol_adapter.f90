! SPDX-License-Identifier: MIT
!> A SUNDIALS SUNLinearSolver written in Fortran that hands KINSOL's sparse Jacobian to
!> any yarnfort linear_solver_type (UMFPACK, KLU, CHOLMOD, dense). The symbolic analysis
!> is done once and reused while the sparsity pattern stays the same.
module yarnfort_solver_sunlinsol_adapter
    use, intrinsic :: iso_c_binding
    use fsundials_linearsolver_mod
    use fsundials_matrix_mod
    use fsundials_nvector_mod
    use fsunmatrix_sparse_mod
    use fnvector_serial_mod
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_solver_timer, only: wall_time
    implicit none
    private

    public :: adapter_type, new_sunlinsol_adapter, get_csc, analyse_counted, &
        factor_counted, solve_counted, solve_columns_counted

    !> What the SUNLinearSolver's content points to.
    type :: adapter_type
        class(linear_solver_type), pointer :: solver => null()
        logical :: analysed = .false.
        !> Set by the owner when the Jacobian's pattern changed (then analyse again).
        logical :: pattern_changed = .false.
        !> Counters and accumulated wall time of analyses, factorisations and solves.
        integer :: n_analyses = 0, n_factorisations = 0, n_solves = 0
        !> Factorisations not repeated: the matrix was the one whose factors are held.
        integer :: n_refactorisations_skipped = 0
        !> The values of the held factors (valid while `holds_factors`).
        real(wp), allocatable :: factored_values(:)
        logical :: holds_factors = .false.
        real(wp) :: analyse_time = 0.0_wp, factor_time = 0.0_wp, solve_time = 0.0_wp
        !> The last failure, for the caller to report.
        type(error_type), allocatable :: error
    end type adapter_type

contains

    !> A SUNLinearSolver whose content is `adapter` (which must outlive it).
    function new_sunlinsol_adapter(adapter, sunctx) result(sunls)
        type(adapter_type), target, intent(inout) :: adapter
        type(c_ptr), intent(in) :: sunctx
        type(SUNLinearSolver), pointer :: sunls
        type(SUNLinearSolver_Ops), pointer :: ops

        sunls => FSUNLinSolNewEmpty(sunctx)
        if (.not. associated(sunls)) return
        sunls%content = c_loc(adapter)
        call c_f_pointer(sunls%ops, ops)
        ops%gettype = c_funloc(adapter_get_type)
        ops%setup = c_funloc(adapter_setup)
        ops%solve = c_funloc(adapter_solve)
        ops%free = c_funloc(adapter_free)
    end function new_sunlinsol_adapter

    integer(SUNLinearSolver_Type) function adapter_get_type(sunls) result(id) bind(C)
        type(SUNLinearSolver) :: sunls
        id = SUNLINEARSOLVER_DIRECT
    end function adapter_get_type

    !> Numeric factorisation of A (symbolic analysis first when needed).
    integer(c_int) function adapter_setup(sunls, sunmat_a) result(ierr) bind(C)
        type(SUNLinearSolver) :: sunls
        type(SUNMatrix) :: sunmat_a
        type(adapter_type), pointer :: adapter
        integer(c_int64_t), pointer :: col_ptr(:), row_index(:)
        real(c_double), pointer :: values(:)
        integer(ik) :: n, nnz

        call c_f_pointer(sunls%content, adapter)
        call get_csc(sunmat_a, n, nnz, col_ptr, row_index, values)
        if (.not. adapter%analysed .or. adapter%pattern_changed) then
            call analyse_counted(adapter, n, col_ptr, row_index, adapter%error)
            if (allocated(adapter%error)) then
                ierr = -1
                return
            end if
            adapter%analysed = .true.
            adapter%pattern_changed = .false.
        end if
        call factor_counted(adapter, values, adapter%error)
        ! A failed factorisation (e.g. singular) is recoverable for KINSOL: positive code.
        ierr = merge(1_c_int, 0_c_int, allocated(adapter%error))
    end function adapter_setup

    !> x = A^{-1} b with the last factorisation.
    integer(c_int) function adapter_solve(sunls, sunmat_a, sunvec_x, sunvec_b, tol) &
            result(ierr) bind(C)
        type(SUNLinearSolver) :: sunls
        type(SUNMatrix) :: sunmat_a
        type(N_Vector) :: sunvec_x, sunvec_b
        real(c_double), value :: tol
        type(adapter_type), pointer :: adapter
        real(c_double), pointer :: x(:), b(:)

        call c_f_pointer(sunls%content, adapter)
        x => FN_VGetArrayPointer(sunvec_x)
        b => FN_VGetArrayPointer(sunvec_b)
        x = b
        call solve_counted(adapter, x, adapter%error)
        ierr = merge(1_c_int, 0_c_int, allocated(adapter%error))
    end function adapter_solve

    !> Symbolic analysis by the adapter's solver, counted and timed.
    subroutine analyse_counted(adapter, n, col_ptr, row_index, error)
        type(adapter_type), intent(inout) :: adapter
        integer(ik), intent(in) :: n, col_ptr(:), row_index(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: start
        start = wall_time()
        adapter%holds_factors = .false.
        call adapter%solver%analyse(n, col_ptr, row_index, error)
        adapter%analyse_time = adapter%analyse_time + (wall_time() - start)
        adapter%n_analyses = adapter%n_analyses + 1
    end subroutine analyse_counted

    !> Numeric factorisation by the adapter's solver, counted and timed (for KINSOL's
    !> setup and for the Newton steps yarnfort takes itself).
    subroutine factor_counted(adapter, values, error)
        type(adapter_type), intent(inout) :: adapter
        real(wp), intent(in) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: start

        ! The matrix of the held factors again (a solve that starts where a Newton step
        ! was factored, e.g. after a chord path whose first step rose): same factors.
        if (adapter%holds_factors) then
            if (size(values) == size(adapter%factored_values)) then
                if (all(values == adapter%factored_values)) then
                    adapter%n_refactorisations_skipped = adapter%n_refactorisations_skipped + 1
                    return
                end if
            end if
        end if
        start = wall_time()
        adapter%holds_factors = .false.
        call adapter%solver%factor(values, error)
        adapter%factor_time = adapter%factor_time + (wall_time() - start)
        adapter%n_factorisations = adapter%n_factorisations + 1
        if (allocated(error)) return
        adapter%factored_values = values
        adapter%holds_factors = .true.
    end subroutine factor_counted

    !> x <- A^{-1} x with the last factorisation, counted and timed.
    subroutine solve_counted(adapter, x, error)
        type(adapter_type), intent(inout) :: adapter
        real(wp), intent(inout) :: x(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: start
        start = wall_time()
        call adapter%solver%solve(x, error)
        adapter%solve_time = adapter%solve_time + (wall_time() - start)
        adapter%n_solves = adapter%n_solves + 1
    end subroutine solve_counted

    !> Each column of x <- A^{-1} x with the last factorisation, in one call of the
    !> solver's `solve_columns`; timed, and counted as one solve per column.
    subroutine solve_columns_counted(adapter, x, error)
        type(adapter_type), intent(inout) :: adapter
        real(wp), intent(inout) :: x(:, :)
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: start
        start = wall_time()
        call adapter%solver%solve_columns(x, error)
        adapter%solve_time = adapter%solve_time + (wall_time() - start)
        adapter%n_solves = adapter%n_solves + size(x, 2)
    end subroutine solve_columns_counted

    !> Free the SUNLinearSolver shell; the adapter and its solver belong to the caller.
    integer(c_int) function adapter_free(sunls) result(ierr) bind(C)
        type(SUNLinearSolver), target :: sunls
        sunls%content = c_null_ptr
        call FSUNLinSolFreeEmpty(sunls)
        ierr = 0
    end function adapter_free

    !> The CSC arrays of a SUNSparseMatrix with their true lengths (SUNDIALS 6.4.1's
    !> accessors return pointers of shape [1]).
    subroutine get_csc(sunmat, n, nnz, col_ptr, row_index, values)
        type(SUNMatrix) :: sunmat
        integer(ik), intent(out) :: n, nnz
        integer(c_int64_t), pointer, intent(out) :: col_ptr(:), row_index(:)
        real(c_double), pointer, intent(out) :: values(:)
        integer(c_int64_t), pointer :: p(:)
        real(c_double), pointer :: d(:)

        n = FSUNSparseMatrix_NP(sunmat)
        p => FSUNSparseMatrix_IndexPointers(sunmat)
        call c_f_pointer(c_loc(p(1)), col_ptr, [n + 1])
        nnz = col_ptr(n + 1)
        p => FSUNSparseMatrix_IndexValues(sunmat)
        call c_f_pointer(c_loc(p(1)), row_index, [max(nnz, 1_ik)])
        d => FSUNSparseMatrix_Data(sunmat)
        call c_f_pointer(c_loc(d(1)), values, [max(nnz, 1_ik)])
        row_index => row_index(1:nnz)
        values => values(1:nnz)
    end subroutine get_csc

end module yarnfort_solver_sunlinsol_adapter
