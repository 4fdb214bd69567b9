! SPDX-License-Identifier: MIT
!> SUNDIALS KINSOL for the Newton solver: its context, memory, vectors and matrix, the
!> residual and Jacobian callbacks (which reach the problem through KINSOL's user data)
!> and its error handler.
module yarnfort_solver_newton_kinsol
    use, intrinsic :: iso_c_binding
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use fsundials_context_mod, only: FSUNContext_Create, FSUNContext_Free
    use fkinsol_mod, only: FKINCreate, FKINInit, FKINSetErrHandlerFn, FKINSetLinearSolver, &
        FKINSetJacFn, FKINSetMaxSetupCalls, FKINSetNumMaxIters, FKINSetFuncNormTol, &
        FKINSetScaledStepTol, FKINSetUserData, FKINSol, FKINGetNumNonlinSolvIters, &
        FKINGetNumFuncEvals, FKINGetNumJacEvals, FKINFree
    use fnvector_serial_mod, only: FN_VMake_Serial
    use fsunmatrix_sparse_mod, only: FSUNSparseMatrix, CSC_MAT, &
        FSUNSparseMatrix_IndexPointers, FSUNSparseMatrix_IndexValues, FSUNSparseMatrix_Data
    use fsundials_matrix_mod, only: SUNMatrix, SUNMatrix_Ops, FSUNMatDestroy
    use fsundials_nvector_mod, only: N_Vector, FN_VGetArrayPointer, FN_VDestroy
    use fsundials_linearsolver_mod, only: SUNLinearSolver, FSUNLinSolFree
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: solver_config_type
    use yarnfort_solver_newton_stats, only: newton_stats_type
    use yarnfort_solver_newton_equilibrium, only: equilibrium_type, evaluate_timed, &
        get_scaled_norm
    use yarnfort_solver_sunlinsol_adapter, only: adapter_type, new_sunlinsol_adapter
    use yarnfort_solver_timer, only: wall_time
    implicit none
    private

    public :: kinsol_type, new_kinsol, full_step_patience

    !> Full Newton steps (the first attempt of a solve, when a line search can follow)
    !> are given up once this many iterations in a row bring no new smallest scaled
    !> residual: they may wander far above the start for all max_iterations
    !> (docs/decisions.md, 'Newton: full steps given up after 5 iterations without
    !> progress').
    integer, parameter :: full_step_patience = 5

    interface
        !> C's strlen, for KINSOL's messages.
        function c_strlen(text) result(length) bind(C, name='strlen')
            import :: c_ptr, c_size_t
            type(c_ptr), value :: text
            integer(c_size_t) :: length
        end function c_strlen
    end interface

    !> KINSOL's context, memory, vectors (over the Newton solver's arrays), Jacobian
    !> matrix and SUNLinearSolver.
    type :: kinsol_type
        type(c_ptr) :: sunctx = c_null_ptr
        type(c_ptr) :: memory = c_null_ptr
        type(N_Vector), pointer :: u_vector => null(), u_scale => null(), f_scale => null()
        type(SUNMatrix), pointer :: jacobian => null()
        type(SUNLinearSolver), pointer :: sunls => null()
    contains
        !> One call of FKINSol with `strategy`; its counts are added to stats.
        procedure :: solve
        procedure :: destroy
    end type kinsol_type

contains

    !> KINSOL over the arrays u, u_scale and f_scale (which must outlive it), its user
    !> data `equilibrium`, its linear solver `adapter` and the &solver options.
    subroutine new_kinsol(self, equilibrium, adapter, u, u_scale, f_scale, options, error)
        type(kinsol_type), intent(inout) :: self
        type(equilibrium_type), pointer, intent(in) :: equilibrium
        type(adapter_type), pointer, intent(in) :: adapter
        real(c_double), pointer, intent(in) :: u(:), u_scale(:), f_scale(:)
        type(solver_config_type), intent(in) :: options
        type(error_type), allocatable, intent(out) :: error
        integer(c_int64_t) :: n, nnz
        integer(c_int) :: ierr
        type(SUNMatrix_Ops), pointer :: matrix_ops

        n = int(equilibrium%n, c_int64_t)
        nnz = max(int(equilibrium%nnz, c_int64_t), 1_c_int64_t)
        ierr = FSUNContext_Create(c_null_ptr, self%sunctx)
        if (ierr /= 0) then
            call fatal_error(error, 'SUNDIALS: could not create a context')
            return
        end if
        self%u_vector => FN_VMake_Serial(n, u, self%sunctx)
        self%u_scale => FN_VMake_Serial(n, u_scale, self%sunctx)
        self%f_scale => FN_VMake_Serial(n, f_scale, self%sunctx)
        self%jacobian => FSUNSparseMatrix(n, n, nnz, CSC_MAT, self%sunctx)
        self%sunls => new_sunlinsol_adapter(adapter, self%sunctx)
        if (.not. (associated(self%u_vector) .and. associated(self%jacobian) &
                .and. associated(self%sunls))) then
            call fatal_error(error, 'SUNDIALS: could not create vectors, matrix or linear solver')
            return
        end if
        ! jacobian_callback writes the pattern once and every value, so KINSOL's zeroing
        ! of the matrix before each evaluation is skipped (docs/decisions.md, 'KINSOL's
        ! Jacobian is not zeroed').
        call c_f_pointer(self%jacobian%ops, matrix_ops)
        matrix_ops%zero = c_funloc(keep_values)

        self%memory = FKINCreate(self%sunctx)
        if (.not. c_associated(self%memory)) then
            call fatal_error(error, 'KINSOL: could not create solver memory')
            return
        end if
        ! In this order (the Jacobian function needs the linear solver); the first
        ! failure is the error (the calls after it fail or do no harm).
        call set(FKINInit(self%memory, c_funloc(residual_callback), self%u_vector), 'FKINInit')
        call set(FKINSetErrHandlerFn(self%memory, c_funloc(error_handler), &
            c_loc(equilibrium)), 'FKINSetErrHandlerFn')
        call set(FKINSetLinearSolver(self%memory, self%sunls, self%jacobian), &
            'FKINSetLinearSolver')
        call set(FKINSetJacFn(self%memory, c_funloc(jacobian_callback)), 'FKINSetJacFn')
        call set(FKINSetMaxSetupCalls(self%memory, int(options%max_setup_calls, c_long)), &
            'FKINSetMaxSetupCalls')
        call set(FKINSetNumMaxIters(self%memory, int(options%max_iterations, c_long)), &
            'FKINSetNumMaxIters')
        call set(FKINSetFuncNormTol(self%memory, real(options%residual_tolerance, c_double)), &
            'FKINSetFuncNormTol')
        call set(FKINSetScaledStepTol(self%memory, real(options%step_tolerance, c_double)), &
            'FKINSetScaledStepTol')
        call set(FKINSetUserData(self%memory, c_loc(equilibrium)), 'FKINSetUserData')
    contains
        subroutine set(flag, name)
            integer(c_int), intent(in) :: flag
            character(len=*), intent(in) :: name
            if (.not. allocated(error)) call check(flag, name, error)
        end subroutine set
    end subroutine new_kinsol

    subroutine check(ierr, where, error)
        integer(c_int), intent(in) :: ierr
        character(len=*), intent(in) :: where
        type(error_type), allocatable, intent(out) :: error
        character(len=16) :: code
        if (ierr < 0) then
            write(code, '(i0)') ierr
            call fatal_error(error, 'SUNDIALS ' // where // ' failed with flag ' // trim(code))
        end if
    end subroutine check

    !> One call of FKINSol from the solution vector's values with `strategy` (KIN_NONE
    !> or KIN_LINESEARCH); returns its flag, and adds its counts to stats.
    integer(c_int) function solve(self, strategy, stats) result(ierr)
        class(kinsol_type), intent(inout) :: self
        integer(c_int), intent(in) :: strategy
        type(newton_stats_type), intent(inout) :: stats
        integer(c_long) :: count(1)

        ierr = FKINSol(self%memory, self%u_vector, strategy, self%u_scale, self%f_scale)
        stats%flag = ierr
        if (FKINGetNumNonlinSolvIters(self%memory, count) == 0) &
            stats%iterations = stats%iterations + int(count(1))
        if (FKINGetNumFuncEvals(self%memory, count) == 0) &
            stats%residual_evaluations = stats%residual_evaluations + int(count(1))
        if (FKINGetNumJacEvals(self%memory, count) == 0) &
            stats%jacobian_evaluations = stats%jacobian_evaluations + int(count(1))
    end function solve

    !> KINSOL residual callback F(u).
    integer(c_int) function residual_callback(sunvec_u, sunvec_f, user_data) &
            result(ierr) bind(C)
        type(N_Vector) :: sunvec_u, sunvec_f
        type(c_ptr), value :: user_data
        type(equilibrium_type), pointer :: problem
        real(c_double), pointer :: u(:), f(:)
        type(error_type), allocatable :: error

        call c_f_pointer(user_data, problem)
        u => FN_VGetArrayPointer(sunvec_u)
        f => FN_VGetArrayPointer(sunvec_f)
        call evaluate_timed(problem, u, .false., f, error)
        call move_alloc(error, problem%error)
        ierr = 0
        if (allocated(problem%error)) ierr = -1
        if (ierr == 0 .and. .not. all(ieee_is_finite(f))) then
            ierr = -1
            call fatal_error(problem%error, 'the residual is not a finite number (NaN or ' &
                // 'an overflow)')
        end if
    end function residual_callback

    !> KINSOL Jacobian callback: writes the CSC pattern at the first call (the matrix's
    !> `zero` is skipped, so it stays) and the values at each. It also records the
    !> residual norm of the current iterate for the convergence history.
    integer(c_int) function jacobian_callback(sunvec_u, sunvec_f, sunmat_j, user_data, &
            tmp1, tmp2) result(ierr) bind(C)
        type(N_Vector) :: sunvec_u, sunvec_f, tmp1, tmp2
        type(SUNMatrix) :: sunmat_j
        type(c_ptr), value :: user_data
        type(equilibrium_type), pointer :: problem
        real(c_double), pointer :: u(:), f(:), values(:)
        integer(c_int64_t), pointer :: col_ptr(:), row_index(:)
        integer(ik) :: n, nnz
        real(wp) :: start
        type(error_type), allocatable :: error
        integer(c_int64_t), pointer :: p(:)
        real(c_double), pointer :: d(:)
        real(wp) :: norm
        logical :: finite

        call c_f_pointer(user_data, problem)
        u => FN_VGetArrayPointer(sunvec_u)
        f => FN_VGetArrayPointer(sunvec_f)
        call get_scaled_norm(f, problem%row_weight, norm, finite)
        if (problem%n_history < size(problem%history)) then
            problem%n_history = problem%n_history + 1
            problem%history(problem%n_history) = norm
        end if
        if (problem%watch_stall) then
            if (norm < problem%best_residual) then
                problem%best_residual = norm
                problem%since_best = 0
            else
                problem%since_best = problem%since_best + 1
            end if
            if (problem%since_best >= full_step_patience) then
                call fatal_error(problem%error, 'full Newton steps made no progress')
                ierr = -1
                return
            end if
        end if
        start = wall_time()
        n = problem%n
        nnz = problem%nnz
        ! The pattern once: the matrix's `zero` does nothing (keep_values), so it stays.
        if (.not. problem%pattern_written) then
            p => FSUNSparseMatrix_IndexPointers(sunmat_j)
            call c_f_pointer(c_loc(p(1)), col_ptr, [n + 1])
            p => FSUNSparseMatrix_IndexValues(sunmat_j)
            call c_f_pointer(c_loc(p(1)), row_index, [nnz])
            call problem%problem%copy_pattern(col_ptr, row_index)
            problem%pattern_written = .true.
        end if
        d => FSUNSparseMatrix_Data(sunmat_j)
        call c_f_pointer(c_loc(d(1)), values, [nnz])
        ! The pattern's copy counts as Jacobian time too.
        problem%jacobian_time = problem%jacobian_time + (wall_time() - start)
        call evaluate_timed(problem, u, .true., values, error)
        call move_alloc(error, problem%error)
        ierr = 0
        if (allocated(problem%error)) ierr = -1
    end function jacobian_callback

    !> The Jacobian's `zero` operation: nothing to do (see new_kinsol).
    integer(c_int) function keep_values(matrix) result(ierr) bind(C)
        type(SUNMatrix) :: matrix
        ierr = 0
    end function keep_values

    !> KINSOL error handler: keep the message for our error value instead of printing.
    subroutine error_handler(error_code, module_name, function_name, message, user_data) bind(C)
        integer(c_int), value :: error_code
        type(c_ptr), value :: module_name, function_name, message, user_data
        type(equilibrium_type), pointer :: problem
        character(kind=c_char), pointer :: text(:)
        integer :: length

        call c_f_pointer(user_data, problem)
        length = int(c_strlen(message))
        call c_f_pointer(message, text, [length])
        ! KINSOL may report more than once in one call of FKINSol: keep the last message.
        if (allocated(problem%kinsol_message)) deallocate(problem%kinsol_message)
        allocate(character(len=length) :: problem%kinsol_message)
        problem%kinsol_message = transfer(text, problem%kinsol_message)
    end subroutine error_handler

    !> Free KINSOL's memory, the linear solver shell, the matrix, vectors and context.
    subroutine destroy(self)
        class(kinsol_type), intent(inout) :: self
        integer(c_int) :: ierr
        if (c_associated(self%memory)) call FKINFree(self%memory)
        self%memory = c_null_ptr
        if (associated(self%sunls)) ierr = FSUNLinSolFree(self%sunls)
        if (associated(self%jacobian)) call FSUNMatDestroy(self%jacobian)
        if (associated(self%u_vector)) call FN_VDestroy(self%u_vector)
        if (associated(self%u_scale)) call FN_VDestroy(self%u_scale)
        if (associated(self%f_scale)) call FN_VDestroy(self%f_scale)
        nullify(self%sunls, self%jacobian, self%u_vector, self%u_scale, self%f_scale)
        if (c_associated(self%sunctx)) ierr = FSUNContext_Free(self%sunctx)
        self%sunctx = c_null_ptr
    end subroutine destroy

end module yarnfort_solver_newton_kinsol
