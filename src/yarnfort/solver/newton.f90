! SPDX-License-Identifier: MIT
!> Newton's method for a nonlinear_problem_type (the network's equilibrium, with or
!> without sliding), driven by SUNDIALS KINSOL (line search globalisation) with the
!> analytic sparse Jacobian and a yarnfort linear solver behind a Fortran
!> SUNLinearSolver.
!> Convergence: row i is converged when |F_i| <= residual_tolerance * level_i + noise_i,
!> with the problem's row levels (the forces meeting at a node, a passage's tensions)
!> and the rounding level of the row's evaluation; levels are taken at the initial
!> guess and checked again at the solution (KINSOL goes on if they changed).
!> Regularisation: every solve is first tried with the exact tension-only law (the
!> regularising spring, weight slack_stiffness, only in the tangent of slack strings).
!> If that fails, it is predicted with the spring in the model (weight falling from 0.1
!> to slack_stiffness by factors of 10, each solve from the last) and corrected from
!> there with the exact law, so the answer is always that of the exact law. A solve
!> whose full Newton steps fail is repeated with a line search, and then by
!> pseudo-transient continuation (solve_transient). Last, a solve that still fails is
!> predicted with the laws far stiffer than its forces scaled down, then stiffened
!> tenfold per solve, and corrected with the exact laws (solve_stiffening).
module yarnfort_solver_newton
    use, intrinsic :: iso_c_binding
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use fsundials_context_mod
    use fkinsol_mod
    use fnvector_serial_mod
    use fsunmatrix_sparse_mod
    use fsundials_matrix_mod
    use fsundials_nvector_mod
    use fsundials_linearsolver_mod
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: format_short
    use yarnfort_input_config, only: solver_config_type
    use yarnfort_solver_problem, only: nonlinear_problem_type
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_backend_dense, only: dense_solver_type
    use yarnfort_solver_sunlinsol_adapter, only: adapter_type, new_sunlinsol_adapter, get_csc, &
        analyse_counted, factor_counted, solve_counted, solve_columns_counted
    use yarnfort_solver_timer, only: wall_time
    use yarnfort_solver_interrupt, only: check_interrupt
    use yarnfort_assembly_truss, only: no_stiffness_cap
    implicit none
    private

    public :: newton_solver_type, newton_stats_type, new_newton_solver

    !> Times KINSOL goes on from its solution when the row levels taken there ask for
    !> a smaller residual than those of the initial guess.
    integer, parameter :: max_level_rounds = 4
    !> Full Newton steps (the first attempt of a solve, when a line search can follow)
    !> are given up once this many iterations in a row bring no new smallest scaled
    !> residual. Measured on the cable net of benchmarks/bench_newton (one load step):
    !> the full steps jump to 4e3 times the initial residual and wander there for all
    !> max_iterations (200 iterations wasted before the line search took 11).
    integer, parameter :: full_step_patience = 5
    !> Most rows that try_row_update replaces (it stores as many vectors of the order
    !> of the system).
    integer, parameter :: max_update_rows = 16
    !> Most chord steps of try_row_update (each cuts the residual tenfold).
    integer, parameter :: max_update_steps = 8
    !> try_row_update gives up at once (one residual evaluation) above this scaled
    !> residual at its start. Measured (benchmarks/steps_results.md, section 13): of the
    !> updates tried on inputs/knit_clamped.nml, inputs/belt.nml and the 10,120 woven
    !> nets, 8 of the 13 that started above 1e-2 failed at their first chord step (each
    !> a Jacobian evaluation and one solve per row wasted), 7 of the 77 below; without
    !> this limit the 8 x 8 clamped knit took 10.20 instead of 9.85 residual evaluations
    !> per load step (2.45 instead of 2.50 Newton iterations) and more CPU.
    real(wp), parameter :: max_update_start = 1.0e-2_wp
    !> Iterations of the pseudo-transient fallback, in units of max_iterations.
    integer, parameter :: transient_iterations = 4
    !> The fallback gives up when its shift exceeds this multiple of the row levels per
    !> length (steps too short to matter).
    real(wp), parameter :: max_transient_shift = 1.0e12_wp
    !> First weight of the regularising spring when a solve needs the predictor: a net
    !> of strings that all carry a tenth of their reference stiffness is regular and
    !> well conditioned from any start; the weight then falls by factors of 10.
    real(wp), parameter :: predictor_weight = 0.1_wp
    !> First stiffness cap of solve_stiffening, in units of the largest force of the
    !> solve's rows: strings that stretch by about 1 % under the forces of the scene,
    !> where a Newton step may move a node along a yarn by a tenth of its length. The
    !> cap then rises by stiffening_factor per solve.
    real(wp), parameter :: first_cap_per_force = 100.0_wp
    real(wp), parameter :: stiffening_factor = 10.0_wp

    interface
        !> C's strlen, for KINSOL's messages.
        function c_strlen(text) result(length) bind(C, name='strlen')
            import :: c_ptr, c_size_t
            type(c_ptr), value :: text
            integer(c_size_t) :: length
        end function c_strlen
    end interface

    !> Figures of one Newton solve.
    type :: newton_stats_type
        integer :: iterations = 0
        integer :: residual_evaluations = 0
        integer :: jacobian_evaluations = 0
        !> Scaled max-norm of the residual, max |F_i| / (level_i + noise_i / tol), at
        !> each iterate (iterate 0 is the initial guess) and at the end: converged <= tol.
        real(wp), allocatable :: residual_history(:)
        real(wp) :: residual_norm = huge(1.0_wp)
        !> KINSOL's return flag.
        integer :: flag = 0
    contains
        procedure :: add_earlier => add_earlier_stats
    end type newton_stats_type

    !> What KINSOL's callbacks see through their user-data pointer.
    type :: equilibrium_type
        class(nonlinear_problem_type), pointer :: problem => null()
        !> Order and nonzeros of the Jacobian (its pattern stays with the problem).
        integer(ik) :: n = 0, nnz = 0
        !> KINSOL's Jacobian matrix holds the pattern (written at its first evaluation).
        logical :: pattern_written = .false.
        real(wp), allocatable :: history(:)
        integer :: n_history = 0
        !> Give up (an error) after full_step_patience iterations without a new smallest
        !> residual: the solve's first attempt of full steps, which a line search follows.
        logical :: watch_stall = .false.
        real(wp) :: best_residual = huge(1.0_wp)
        integer :: since_best = 0
        !> KINSOL's residual scaling, 1 / (level_i + noise_i / tol).
        real(c_double), pointer :: row_weight(:) => null()
        type(error_type), allocatable :: error
        character(len=:), allocatable :: kinsol_message
        !> Accumulated wall time of residual and Jacobian assembly, and of the row
        !> levels (get_row_levels: the first call at a new iterate also computes the
        !> problem's state, which the residual there then finds done).
        real(wp) :: residual_time = 0.0_wp, jacobian_time = 0.0_wp, levels_time = 0.0_wp
    end type equilibrium_type

    !> Owns KINSOL's memory, vectors, matrix and the linear solver for one scene.
    type :: newton_solver_type
        type(c_ptr) :: sunctx = c_null_ptr
        type(c_ptr) :: kinsol = c_null_ptr
        type(N_Vector), pointer :: u_vector => null(), u_scale => null(), f_scale => null()
        type(SUNMatrix), pointer :: jacobian => null()
        type(SUNLinearSolver), pointer :: sunls => null()
        real(c_double), pointer :: u(:) => null(), u_scale_data(:) => null()
        real(c_double), pointer :: f_scale_data(:) => null()
        type(equilibrium_type), pointer :: problem => null()
        type(adapter_type), pointer :: adapter => null()
        type(solver_config_type) :: options
        class(linear_solver_type), pointer :: linear => null()
        !> Fail fast: full Newton steps only, given up after full_step_patience
        !> iterations without progress; no line search, no pseudo-transient fallback, no
        !> regularised predictor. For solves whose failure the caller handles more
        !> cheaply than those fallbacks do (a guessed stick/slip active set).
        logical :: quick = .false.
        !> Chord steps after the first Newton step of a solve (solve_chord); 0: none.
        integer :: chord_steps = 0
        !> The Jacobian values of the last Newton step (newton_step) and the linear
        !> solver's factorisation count just after it: while that count holds, its
        !> factors are still the linear solver's (try_row_update).
        real(wp), allocatable :: kept_values(:)
        integer :: kept_factorisation = -1
    contains
        !> Solve for unknowns u (in: initial guess, out: solution).
        procedure :: solve
        !> One Newton step from u, without a convergence test.
        procedure :: take_newton_step
        !> The first Newton step and its chord steps only (no fallback): converged, or
        !> the best iterate to judge before solving on.
        procedure :: try_chord
        !> Chord steps of a problem whose rows `rows` changed since the last Newton step,
        !> with that step's factors and a low-rank correction (no factorisation).
        procedure :: try_row_update
        !> Timing and counters of assembly and linear algebra so far.
        procedure :: get_timings
        procedure :: destroy
        final :: finalize
    end type newton_solver_type

contains

    !> Add the counts of `earlier` (an earlier part of the same solve, such as the
    !> provisional passes of a friction round) to these, its residuals first.
    pure subroutine add_earlier_stats(stats, earlier)
        class(newton_stats_type), intent(inout) :: stats
        type(newton_stats_type), intent(in) :: earlier
        stats%iterations = stats%iterations + earlier%iterations
        stats%residual_evaluations = stats%residual_evaluations + earlier%residual_evaluations
        stats%jacobian_evaluations = stats%jacobian_evaluations + earlier%jacobian_evaluations
        if (allocated(earlier%residual_history)) then
            if (allocated(stats%residual_history)) then
                stats%residual_history = [earlier%residual_history, stats%residual_history]
            else
                stats%residual_history = earlier%residual_history
            end if
        end if
    end subroutine add_earlier_stats

    !> Set up KINSOL for `problem` (which must outlive the solver) with `linear` as the
    !> linear solver (ownership passes to the Newton solver) and the &solver options.
    subroutine new_newton_solver(self, problem, linear, options, error)
        type(newton_solver_type), intent(out) :: self
        class(nonlinear_problem_type), target, intent(in) :: problem
        class(linear_solver_type), allocatable, intent(inout) :: linear
        type(solver_config_type), intent(in) :: options
        type(error_type), allocatable, intent(out) :: error
        integer(c_int64_t) :: n, nnz
        integer(c_int) :: ierr
        type(SUNMatrix_Ops), pointer :: matrix_ops

        self%options = options
        allocate(self%problem)
        self%problem%problem => problem
        self%problem%n = int(problem%get_size(), ik)
        self%problem%nnz = problem%get_nonzeros()
        allocate(self%problem%history(options%max_iterations + 2))
        n = int(problem%get_size(), c_int64_t)
        nnz = max(int(self%problem%nnz, c_int64_t), 1_c_int64_t)
        if (n == 0) then
            call fatal_error(error, 'the scene has no unknowns: every coordinate is prescribed')
            return
        end if

        allocate(self%linear, source=linear)
        deallocate(linear)
        allocate(self%adapter)
        self%adapter%solver => self%linear

        ierr = FSUNContext_Create(c_null_ptr, self%sunctx)
        if (ierr /= 0) then
            call fatal_error(error, 'SUNDIALS: could not create a context')
            return
        end if
        allocate(self%u(n), self%u_scale_data(n), self%f_scale_data(n))
        self%u = 0.0_wp
        self%u_scale_data = 1.0_wp / problem%length_scale
        self%f_scale_data = 1.0_wp
        self%problem%row_weight => self%f_scale_data
        self%u_vector => FN_VMake_Serial(n, self%u, self%sunctx)
        self%u_scale => FN_VMake_Serial(n, self%u_scale_data, self%sunctx)
        self%f_scale => FN_VMake_Serial(n, self%f_scale_data, self%sunctx)
        self%jacobian => FSUNSparseMatrix(n, n, nnz, CSC_MAT, self%sunctx)
        self%sunls => new_sunlinsol_adapter(self%adapter, self%sunctx)
        if (.not. (associated(self%u_vector) .and. associated(self%jacobian) &
                .and. associated(self%sunls))) then
            call fatal_error(error, 'SUNDIALS: could not create vectors, matrix or linear solver')
            return
        end if
        ! KINSOL zeroes the Jacobian (values, row indices, column pointers) before every
        ! evaluation; jacobian_callback writes the pattern (once) and every value, so the
        ! zeroing is skipped (measured: 5 % of the CPU of a friction cycle on the woven
        ! net of 1e4 unknowns, benchmarks/steps_trace).
        call c_f_pointer(self%jacobian%ops, matrix_ops)
        matrix_ops%zero = c_funloc(keep_values)

        self%kinsol = FKINCreate(self%sunctx)
        if (.not. c_associated(self%kinsol)) then
            call fatal_error(error, 'KINSOL: could not create solver memory')
            return
        end if
        ! In this order (the Jacobian function needs the linear solver); the first
        ! failure is the error (the calls after it fail or do no harm).
        call set(FKINInit(self%kinsol, c_funloc(residual_callback), self%u_vector), 'FKINInit')
        call set(FKINSetErrHandlerFn(self%kinsol, c_funloc(error_handler), &
            c_loc(self%problem)), 'FKINSetErrHandlerFn')
        call set(FKINSetLinearSolver(self%kinsol, self%sunls, self%jacobian), &
            'FKINSetLinearSolver')
        call set(FKINSetJacFn(self%kinsol, c_funloc(jacobian_callback)), 'FKINSetJacFn')
        call set(FKINSetMaxSetupCalls(self%kinsol, int(options%max_setup_calls, c_long)), &
            'FKINSetMaxSetupCalls')
        call set(FKINSetNumMaxIters(self%kinsol, int(options%max_iterations, c_long)), &
            'FKINSetNumMaxIters')
        call set(FKINSetFuncNormTol(self%kinsol, real(options%residual_tolerance, c_double)), &
            'FKINSetFuncNormTol')
        call set(FKINSetScaledStepTol(self%kinsol, real(options%step_tolerance, c_double)), &
            'FKINSetScaledStepTol')
        call set(FKINSetUserData(self%kinsol, c_loc(self%problem)), 'FKINSetUserData')
    contains
        subroutine set(flag, name)
            integer(c_int), intent(in) :: flag
            character(len=*), intent(in) :: name
            if (.not. allocated(error)) call check(flag, name, error)
        end subroutine set
    end subroutine new_newton_solver

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

    !> Solve from the initial guess u: with the exact law; if that fails and
    !> slack_stiffness > 0, predicted with the regularising spring and corrected with
    !> the exact law from the prediction (module notes). stats add up all attempts.
    subroutine solve(self, u, stats, error, after_chord)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        type(newton_stats_type), intent(out) :: stats
        type(error_type), allocatable, intent(out) :: error
        !> u is where try_chord left off: go on without another chord path.
        logical, intent(in), optional :: after_chord
        type(error_type), allocatable :: exact_error
        real(wp), allocatable :: guess(:)
        real(wp) :: weight
        logical :: converged, tried
        associate(problem => self%problem%problem, spring => self%options%slack_stiffness)
            problem%spring = 0.0_wp
            problem%tangent_spring = spring
            if (self%chord_steps > 0 .and. .not. present_and_true(after_chord)) then
                call solve_chord(self, u, stats, converged, error)
                if (allocated(error) .or. converged) return
            end if
            call solve_once(self, u, stats, exact_error)
            if (.not. allocated(exact_error)) return
            if (self%quick) then
                call move_alloc(exact_error, error)
                return
            end if
            if (spring > 0.0_wp) then
                call predict_with_spring()
                if (.not. allocated(error)) return
                exact_error%message = exact_error%message // error%message
                deallocate(error)
            end if
            call solve_stiffening(self, u, stats, tried, error)
            if (allocated(error)) then
                call combine(error, '')
            else if (.not. tried) then
                call move_alloc(exact_error, error)
            end if
        end associate
    contains
        !> Predict with the spring in the model, weight driven down from
        !> predictor_weight to slack_stiffness by factors of 10 (each solve from the
        !> last), then correct with the exact law. An error says where it failed.
        subroutine predict_with_spring()
            associate(problem => self%problem%problem, spring => self%options%slack_stiffness)
                guess = u
                weight = max(predictor_weight, spring)
                do
                    problem%spring = weight
                    problem%tangent_spring = 0.0_wp
                    call solve_once(self, guess, stats, error)
                    if (allocated(error)) then
                        problem%spring = 0.0_wp
                        problem%tangent_spring = spring
                        error%message = '; with the regularised law as predictor: ' &
                            // error%message
                        return
                    end if
                    if (weight <= spring) exit
                    weight = max(spring, weight / 10)
                end do
                problem%spring = 0.0_wp
                problem%tangent_spring = spring
                call solve_once(self, guess, stats, error)
                if (allocated(error)) then
                    error%message = '; corrected from the regularised prediction: ' &
                        // error%message
                    return
                end if
                u = guess
            end associate
        end subroutine predict_with_spring

        pure logical function present_and_true(flag)
            logical, intent(in), optional :: flag
            present_and_true = .false.
            if (present(flag)) present_and_true = flag
        end function present_and_true

        subroutine combine(later, link)
            type(error_type), intent(inout) :: later
            character(len=*), intent(in) :: link
            later%message = exact_error%message // link // later%message
        end subroutine combine
    end subroutine solve

    !> The last fallback of `solve`, for yarns far stiffer than the forces they carry:
    !> a full Newton step can move a node along such a yarn by only about
    !> sqrt(l T / EA) (the stretch it causes grows with the step's square), so a ring
    !> that must slide far along it takes thousands of them. Solved first with every
    !> law stiffer than first_cap_per_force times the largest force of the rows at u
    !> scaled down to that stiffness (get_truss_tension), then with the cap raised by
    !> stiffening_factor per solve, each from the last, until no law is capped, and
    !> corrected with the exact laws: only the initial guess of that last solve changes,
    !> so the answer is the exact laws'. `tried` is false (u unchanged, no error) when no
    !> law is that stiff; an error when a solve fails.
    subroutine solve_stiffening(self, u, stats, tried, error)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        type(newton_stats_type), intent(inout) :: stats
        logical, intent(out) :: tried
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: guess(:), level(:), noise(:)
        real(wp) :: cap, stiffest
        integer :: m

        associate(problem => self%problem%problem)
            allocate(level(size(u)), noise(size(u)))
            call get_levels_timed(self%problem, u, level, noise, error)
            if (allocated(error)) return
            stiffest = maxval([(problem%scene%laws(m)%law%get_reference_stiffness(), &
                m = 1, size(problem%scene%laws))])
            cap = first_cap_per_force * maxval([0.0_wp, level])
            tried = cap > 0.0_wp .and. cap < stiffest
            if (.not. tried) return
            guess = u
            do while (cap < stiffest)
                problem%stiffness_cap = cap
                call solve_once(self, guess, stats, error)
                problem%stiffness_cap = no_stiffness_cap
                if (allocated(error)) then
                    error%message = '; with the yarns softened to a stiffness of ' &
                        // format_short(cap, 4) // ' as predictor: ' // error%message
                    return
                end if
                cap = cap * stiffening_factor
            end do
            call solve_once(self, guess, stats, error)
            if (allocated(error)) then
                error%message = '; corrected from the softened prediction: ' // error%message
                return
            end if
            u = guess
        end associate
    end subroutine solve_stiffening

    !> One Newton solve with the problem's current spring weights. Rows are scaled by
    !> their levels at the initial guess; at the end the levels are taken again at the
    !> solution and, should the residual not meet them, KINSOL goes on from there.
    subroutine solve_once(self, u, stats, error)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        type(newton_stats_type), intent(inout) :: stats
        type(error_type), allocatable, intent(out) :: error
        integer(c_int) :: ierr, strategy
        integer(c_long) :: count(1)
        real(c_double) :: residual(size(u))
        integer :: round, attempt, n_attempts
        logical :: converged, finite
        character(len=200) :: buffer

        ! KINSOL's factors and prepare_solve's weights are not those of newton_step.
        self%kept_factorisation = -1
        ! Full Newton steps first; with line_search, a failed attempt is repeated from
        ! the initial guess with KINSOL's line search (back-tracking where needed only).
        n_attempts = merge(2, 1, self%options%line_search .and. .not. self%quick)
        do attempt = 1, n_attempts
            strategy = merge(KIN_NONE, KIN_LINESEARCH, attempt == 1)
            self%problem%n_history = 0
            self%problem%watch_stall = attempt < n_attempts .or. self%quick
            self%problem%best_residual = huge(1.0_wp)
            self%problem%since_best = 0
            if (allocated(self%problem%error)) deallocate(self%problem%error)
            if (allocated(self%problem%kinsol_message)) deallocate(self%problem%kinsol_message)
            if (allocated(self%adapter%error)) deallocate(self%adapter%error)
            call self%problem%problem%prepare_solve(u, error)
            if (allocated(error)) return
            self%u = u
            call set_row_weights(self, .true., error)
            if (allocated(error)) return
            converged = .false.
            do round = 1, max_level_rounds
                ierr = FKINSol(self%kinsol, self%u_vector, strategy, self%u_scale, self%f_scale)
                stats%flag = ierr
                if (FKINGetNumNonlinSolvIters(self%kinsol, count) == 0) &
                    stats%iterations = stats%iterations + int(count(1))
                if (FKINGetNumFuncEvals(self%kinsol, count) == 0) &
                    stats%residual_evaluations = stats%residual_evaluations + int(count(1))
                if (FKINGetNumJacEvals(self%kinsol, count) == 0) &
                    stats%jacobian_evaluations = stats%jacobian_evaluations + int(count(1))
                if (allocated(self%problem%error)) then
                    if (attempt < n_attempts) exit
                    call move_alloc(self%problem%error, error)
                    return
                end if
                if (allocated(self%adapter%error) .and. ierr < 0) then
                    if (attempt < n_attempts) exit
                    call fatal_error(error, 'linear solver (' // self%linear%get_name() // &
                        '): ' // self%adapter%error%message)
                    return
                end if
                ! Judge convergence by our own test on the final iterate, with its levels.
                call set_row_weights(self, .false., error)
                if (allocated(error)) return
                call evaluate_timed(self%problem, self%u, .false., residual, error)
                if (allocated(error)) then
                    if (attempt == n_attempts) return
                    deallocate(error)
                    exit
                end if
                call get_scaled_norm(residual, self%f_scale_data, stats%residual_norm, finite)
                ! Our test decides: a line search that stalls at a converged iterate is fine.
                converged = stats%residual_norm <= self%options%residual_tolerance
                if (ierr < 0 .or. converged) exit
            end do
            if (converged) exit
        end do
        if (.not. converged .and. self%options%line_search .and. .not. self%quick) then
            ! Neither full nor line-searched Newton steps: pseudo-transient continuation.
            call solve_transient(self, u, stats, converged, error)
            if (allocated(error)) return
        end if
        self%problem%n_history = min(self%problem%n_history + 1, size(self%problem%history))
        self%problem%history(self%problem%n_history) = stats%residual_norm
        stats%residual_history = self%problem%history(1:self%problem%n_history)

        if (.not. converged) then
            write(buffer, '("Newton did not converge: KINSOL flag ", i0, ", ", i0, &
                & " iterations, scaled residual ", a, " > tolerance ", a)') ierr, &
                stats%iterations, format_short(stats%residual_norm, 4), &
                format_short(self%options%residual_tolerance, 4)
            if (allocated(self%problem%kinsol_message)) then
                call fatal_error(error, trim(buffer) // ' (' // self%problem%kinsol_message // ')')
            else
                call fatal_error(error, trim(buffer))
            end if
            return
        end if
        call self%problem%problem%check_solution(self%u, error)
        if (allocated(error)) return
        u = self%u
    end subroutine solve_once

    !> The linear solver's symbolic analysis of the problem's pattern, once.
    subroutine analyse_once(self, col_ptr, row_index, error)
        class(newton_solver_type), intent(inout) :: self
        integer(ik), intent(in) :: col_ptr(:), row_index(:)
        type(error_type), allocatable, intent(out) :: error
        if (self%adapter%analysed) return
        call analyse_counted(self%adapter, int(size(col_ptr) - 1, ik), col_ptr, row_index, &
            error)
        if (allocated(error)) return
        self%adapter%analysed = .true.
    end subroutine analyse_once

    !> Chord fast path: one Newton step from u, then up to chord_steps steps with its
    !> factors while each cuts the scaled residual (rows at their own levels) tenfold,
    !> until it meets the tolerance. `converged`: u is then the solution; else u is the
    !> best iterate (the caller solves from there as usual).
    !> A steady load step starts close enough that the chord steps contract like Newton
    !> steps, and costs one factorisation instead of two.
    !> The steps stop at the tolerance (the solve's own test), no longer at 1 % of it:
    !> a step there (a solve and a residual) moved no answer by more than 5e-11 of the
    !> peak force. Measured (benchmarks/steps_results.md, section 21; residual
    !> evaluations / solves per step): woven cycle 10,120 aligned 4.90 / 3.97 -> 4.22 /
    !> 3.28, skewed 7.38 / 6.85 -> 6.57 / 6.03; 8 x 8 clamped knit cycle 10.43 / 10.00
    !> -> 9.85 / 9.43; the same steps on 28 scenes, the same Newton iterations, rounds
    !> and factorisations on 20 of 21 (woven skewed 840: one round fewer in 60 steps).
    subroutine solve_chord(self, u, stats, converged, error)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        type(newton_stats_type), intent(inout) :: stats
        logical, intent(out) :: converged
        type(error_type), allocatable, intent(out) :: error
        type(error_type), allocatable :: trial_error
        real(wp), allocatable :: residual(:), step(:), history(:)
        real(wp) :: f
        integer :: k
        logical :: accepted

        converged = .false.
        associate(problem => self%problem%problem, tol => self%options%residual_tolerance)
            call start_newton(self, u, error)
            if (allocated(error)) return
            allocate(residual(size(u)), step(size(u)))
            call get_scaled_residual(self, residual, f, trial_error)
            stats%residual_evaluations = stats%residual_evaluations + 1
            if (allocated(trial_error)) return
            history = [f]
            if (f > tol) then
                call newton_step(self, residual, trial_error)
                stats%jacobian_evaluations = stats%jacobian_evaluations + 1
                if (allocated(trial_error)) return
                stats%iterations = stats%iterations + 1
                call get_scaled_residual(self, residual, f, trial_error)
                stats%residual_evaluations = stats%residual_evaluations + 1
                if (allocated(trial_error)) return
                history = [history, f]
                ! The Newton step and the chord steps together within max_iterations.
                do k = 1, min(self%chord_steps, self%options%max_iterations - 1)
                    if (f <= tol) exit
                    step = -residual
                    call solve_counted(self%adapter, step, trial_error)
                    if (allocated(trial_error)) exit
                    call take_chord_step(self, step, residual, f, history, stats, accepted)
                    if (.not. accepted) exit
                end do
            end if
            call finish_chord(self, u, f, history, stats, converged)
        end associate
    end subroutine solve_chord

    !> self%u + step replaces self%u if it cuts the scaled residual tenfold (`accepted`;
    !> residual, f and history then follow it), else self%u stays.
    subroutine take_chord_step(self, step, residual, f, history, stats, accepted)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(in) :: step(:)
        real(wp), intent(inout) :: residual(:), f
        real(wp), allocatable, intent(inout) :: history(:)
        type(newton_stats_type), intent(inout) :: stats
        logical, intent(out) :: accepted
        type(error_type), allocatable :: trial_error
        real(wp), allocatable :: kept(:)
        real(wp) :: f_trial

        kept = self%u
        self%u = self%u + step
        call get_scaled_residual(self, residual, f_trial, trial_error)
        stats%residual_evaluations = stats%residual_evaluations + 1
        accepted = .not. allocated(trial_error)
        if (accepted) accepted = f_trial <= f / 10
        if (.not. accepted) then
            self%u = kept
            return
        end if
        f = f_trial
        history = [history, f]
    end subroutine take_chord_step

    !> The end of a chord path at self%u with scaled residual f: u takes it if it is the
    !> best iterate, stats its residuals; `converged` where f is within the tolerance
    !> and the problem accepts the solution.
    subroutine finish_chord(self, u, f, history, stats, converged)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        real(wp), intent(in) :: f, history(:)
        type(newton_stats_type), intent(inout) :: stats
        logical, intent(out) :: converged
        type(error_type), allocatable :: trial_error

        if (f < history(1)) u = self%u
        stats%residual_norm = f
        stats%residual_history = history
        converged = .false.
        if (.not. (f <= self%options%residual_tolerance)) return
        call self%problem%problem%check_solution(self%u, trial_error)
        converged = .not. allocated(trial_error)
    end subroutine finish_chord

    !> The chord fast path of `solve` alone (solve_chord): `converged`, u is the
    !> solution; else u is the best of its iterates (or the start), and the caller
    !> decides whether to solve on (`solve` from u) or to change the problem first.
    subroutine try_chord(self, u, stats, converged, error)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        type(newton_stats_type), intent(out) :: stats
        logical, intent(out) :: converged
        type(error_type), allocatable, intent(out) :: error

        associate(problem => self%problem%problem)
            problem%spring = 0.0_wp
            problem%tangent_spring = self%options%slack_stiffness
            call solve_chord(self, u, stats, converged, error)
        end associate
    end subroutine try_chord

    !> Chord steps from u for a problem that differs from the one of the last Newton
    !> step (newton_step) in its rows `rows` only (a friction step's active-set round:
    !> passages turned stick or slip), while the linear solver still holds that step's
    !> factors: the kept Jacobian with those rows replaced by the new ones at u, solved
    !> by the Sherman-Morrison-Woodbury formula (size(rows) solves with the kept factors
    !> and a dense system of that order), without a factorisation. The rows keep the
    !> weights of that solve (no prepare_solve). Steps go on while each cuts the scaled
    !> residual tenfold, until it meets the tolerance, as in solve_chord; `converged`: u is
    !> the solution, else u is the best iterate (or the start) and the caller solves on
    !> as usual. Nothing is tried (converged false, no evaluation) without kept factors
    !> or with more than max_update_rows rows.
    subroutine try_row_update(self, u, rows, stats, converged, error)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        integer, intent(in) :: rows(:)
        type(newton_stats_type), intent(out) :: stats
        logical, intent(out) :: converged
        type(error_type), allocatable, intent(out) :: error
        type(error_type), allocatable :: trial_error
        real(wp), allocatable :: residual(:), step(:), history(:), values(:)
        real(wp), allocatable :: z(:, :), capacity(:, :), y(:), entry_value(:)
        integer, allocatable :: slot(:), entry_slot(:), entry_column(:)
        type(dense_solver_type) :: correction
        integer :: k, n_rows, j, e, n_entries, a, b, i
        real(wp) :: f
        logical :: accepted

        converged = .false.
        n_rows = size(rows)
        if (n_rows == 0 .or. n_rows > max_update_rows) return
        if (self%kept_factorisation /= self%adapter%n_factorisations) return
        if (.not. allocated(self%kept_values)) return
        associate(problem => self%problem%problem, tol => self%options%residual_tolerance, &
                n => size(u), col_ptr => self%problem%problem%col_ptr, &
                row_index => self%problem%problem%row_index)
            self%u = u
            allocate(residual(n), step(n))
            call get_scaled_residual(self, residual, f, trial_error)
            stats%residual_evaluations = stats%residual_evaluations + 1
            if (allocated(trial_error)) return
            history = [f]
            stats%residual_norm = f
            stats%residual_history = history
            if (f > max_update_start) return
            if (f > tol) then
                ! The new rows (Jacobian at u) less the kept ones: V, a few entries per row.
                allocate(values(self%problem%nnz))
                call evaluate_timed(self%problem, self%u, .true., values, trial_error)
                stats%jacobian_evaluations = stats%jacobian_evaluations + 1
                if (allocated(trial_error)) return
                allocate(slot(n), source=0)
                do a = 1, n_rows
                    slot(rows(a)) = a
                end do
                n_entries = count(slot(row_index + 1) > 0)
                allocate(entry_slot(n_entries), entry_column(n_entries), entry_value(n_entries))
                i = 0
                do j = 1, n
                    do e = int(col_ptr(j)) + 1, int(col_ptr(j + 1))
                        a = slot(row_index(e) + 1)
                        if (a == 0) cycle
                        i = i + 1
                        entry_slot(i) = a
                        entry_column(i) = j
                        entry_value(i) = values(e) - self%kept_values(e)
                    end do
                end do
                deallocate(values)
                ! Z = J^-1 U (U: the unit columns of the rows), C = I + V Z.
                allocate(z(n, n_rows), capacity(n_rows, n_rows), y(n_rows))
                z = 0.0_wp
                do a = 1, n_rows
                    z(rows(a), a) = 1.0_wp
                end do
                call solve_columns_counted(self%adapter, z, trial_error)
                if (allocated(trial_error)) return
                capacity = 0.0_wp
                do a = 1, n_rows
                    capacity(a, a) = 1.0_wp
                end do
                do i = 1, n_entries
                    capacity(entry_slot(i), :) = capacity(entry_slot(i), :) &
                        + entry_value(i) * z(entry_column(i), :)
                end do
                call correction%analyse(int(n_rows, ik), [(int(a, ik) * n_rows, a = 0, n_rows)], &
                    [((int(i, ik), i = 0, n_rows - 1), a = 1, n_rows)], trial_error)
                if (allocated(trial_error)) return
                call correction%factor(reshape(capacity, [n_rows * n_rows]), trial_error)
                if (allocated(trial_error)) return
                do k = 1, max_update_steps
                    if (f <= tol) exit
                    step = -residual
                    call solve_counted(self%adapter, step, trial_error)
                    if (allocated(trial_error)) exit
                    y = 0.0_wp
                    do i = 1, n_entries
                        y(entry_slot(i)) = y(entry_slot(i)) &
                            + entry_value(i) * step(entry_column(i))
                    end do
                    call correction%solve(y, trial_error)
                    if (allocated(trial_error)) exit
                    do b = 1, n_rows
                        step = step - y(b) * z(:, b)
                    end do
                    call take_chord_step(self, step, residual, f, history, stats, accepted)
                    if (.not. accepted) exit
                end do
            end if
            call finish_chord(self, u, f, history, stats, converged)
        end associate
    end subroutine try_row_update

    !> u <- u + one Newton step of the exact law from u (no convergence test): the
    !> direction a solve from u sets out in.
    subroutine take_newton_step(self, u, error)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: residual(:)

        associate(problem => self%problem%problem)
            problem%spring = 0.0_wp
            problem%tangent_spring = self%options%slack_stiffness
            call start_newton(self, u, error)
            if (allocated(error)) return
            allocate(residual(size(u)))
            call evaluate_timed(self%problem, self%u, .false., residual, error)
            if (allocated(error)) return
            call newton_step(self, residual, error)
            if (allocated(error)) return
            u = self%u
        end associate
    end subroutine take_newton_step

    !> Analyse the pattern (once), fix the problem's solve-wide weights at u, self%u = u.
    subroutine start_newton(self, u, error)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        type(error_type), allocatable, intent(out) :: error

        ! The problem's own pattern (fixed for its lifetime), not a copy per solve.
        associate(problem => self%problem%problem)
            call analyse_once(self, problem%col_ptr, problem%row_index, error)
        end associate
        if (allocated(error)) return
        ! New row weights (prepare_solve): the kept factors no longer match them.
        self%kept_factorisation = -1
        call self%problem%problem%prepare_solve(u, error)
        if (allocated(error)) return
        self%u = u
    end subroutine start_newton

    !> self%u <- self%u - J(self%u)^-1 residual (the residual at self%u, whose state the
    !> problem holds); the factors stay for chord steps.
    subroutine newton_step(self, residual, error)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(in) :: residual(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: values(:), step(:)

        allocate(values(self%problem%nnz))
        call evaluate_timed(self%problem, self%u, .true., values, error)
        if (allocated(error)) return
        call factor_counted(self%adapter, values, error)
        if (allocated(error)) return
        call move_alloc(values, self%kept_values)
        self%kept_factorisation = self%adapter%n_factorisations
        step = -residual
        call solve_counted(self%adapter, step, error)
        if (allocated(error)) return
        self%u = self%u + step
    end subroutine newton_step

    !> The problem's residual at u, or with `jacobian` its Jacobian values; the wall time
    !> goes to residual_time or jacobian_time (get_timings), for our calls and KINSOL's.
    subroutine evaluate_timed(problem, u, jacobian, values, error)
        type(equilibrium_type), intent(inout) :: problem
        real(wp), intent(in) :: u(:)
        logical, intent(in) :: jacobian
        real(wp), intent(out) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: start
        ! Every Newton path evaluates here: Ctrl-C fails the solve within an iteration.
        call check_interrupt(error)
        if (allocated(error)) return
        start = wall_time()
        if (jacobian) then
            call problem%problem%evaluate_jacobian(u, values, error)
            problem%jacobian_time = problem%jacobian_time + (wall_time() - start)
        else
            call problem%problem%evaluate_residual(u, values, error)
            problem%residual_time = problem%residual_time + (wall_time() - start)
        end if
    end subroutine evaluate_timed

    !> The residual at self%u and its scaled max-norm, the row levels taken there.
    subroutine get_scaled_residual(self, residual, f, error)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(out) :: residual(:), f
        type(error_type), allocatable, intent(out) :: error

        logical :: finite

        f = huge(1.0_wp)
        call set_row_weights(self, .false., error)
        if (allocated(error)) return
        call evaluate_timed(self%problem, self%u, .false., residual, error)
        if (allocated(error)) return
        call get_scaled_norm(residual, self%f_scale_data, f, finite)
        if (.not. finite) then
            f = huge(1.0_wp)
            call fatal_error(error, 'the residual is not a finite number (NaN or an overflow)')
            return
        end if
    end subroutine get_scaled_residual

    !> f = maxval([0, |residual| * weight]) (a NaN product is passed over, as by maxval)
    !> and whether every residual entry is finite, in one pass without a temporary.
    pure subroutine get_scaled_norm(residual, weight, f, finite)
        real(wp), intent(in) :: residual(:), weight(:)
        real(wp), intent(out) :: f
        logical, intent(out) :: finite
        real(wp) :: scaled
        integer :: i

        f = 0.0_wp
        finite = .true.
        do i = 1, size(residual)
            finite = finite .and. ieee_is_finite(residual(i))
            scaled = abs(residual(i)) * weight(i)
            if (scaled > f) f = scaled
        end do
    end subroutine get_scaled_norm

    !> Pseudo-transient continuation (switched evolution relaxation): Newton steps on
    !> F(u) + mu D du = 0, D_i = level_i / length_scale, with mu falling as the scaled
    !> residual f does (mu <- mu f_new / f_old) and a step that raises f rejected (mu
    !> times 10). Far from the solution it follows a damped, implicit-Euler path that
    !> handles stiff directions (an inextensible yarn) and slow ones (a ring sliding
    !> along it) together, where a line search on |F| crawls; as mu -> 0 it is Newton.
    !> Works on self%u from u; on success self%u is the solution, `converged` is set.
    subroutine solve_transient(self, u, stats, converged, error)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        type(newton_stats_type), intent(inout) :: stats
        logical, intent(out) :: converged
        type(error_type), allocatable, intent(out) :: error
        type(error_type), allocatable :: trial_error
        real(wp), allocatable :: residual(:), trial(:), values(:), step(:), shift(:)
        real(wp), allocatable :: level(:), noise(:)
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        integer, allocatable :: diagonal(:)
        integer :: i, k, iteration
        real(wp) :: mu, f, merit, merit_trial
        logical :: finite

        converged = .false.
        associate(problem => self%problem%problem, n => size(u))
            allocate(col_ptr(n + 1), row_index(self%problem%nnz), values(self%problem%nnz))
            call problem%copy_pattern(col_ptr, row_index)
            allocate(diagonal(n), source=0)
            do i = 1, n
                do k = int(col_ptr(i)) + 1, int(col_ptr(i + 1))
                    if (row_index(k) == i - 1) diagonal(i) = k
                end do
            end do
            if (any(diagonal == 0)) return
            call analyse_once(self, col_ptr, row_index, error)
            if (allocated(error)) return
            call problem%prepare_solve(u, error)
            if (allocated(error)) return
            self%u = u
            allocate(residual(n), step(n), level(n), noise(n), shift(n))
            call get_levels_timed(self%problem, self%u, level, noise, error)
            if (allocated(error)) return
            shift = max(level, tiny(1.0_wp)) / problem%length_scale
            call set_row_weights(self, .false., error)
            if (allocated(error)) return
            call evaluate_timed(self%problem, self%u, .false., residual, error)
            if (allocated(error)) return
            call get_scaled_norm(residual, self%f_scale_data, f, finite)
            merit = norm2(residual * self%f_scale_data)
            mu = 1.0_wp
            do iteration = 1, transient_iterations * self%options%max_iterations
                if (f <= self%options%residual_tolerance) exit
                call evaluate_timed(self%problem, self%u, .true., values, error)
                if (allocated(error)) return
                values(diagonal) = values(diagonal) + mu * shift
                call factor_counted(self%adapter, values, trial_error)
                stats%jacobian_evaluations = stats%jacobian_evaluations + 1
                if (.not. allocated(trial_error)) then
                    step = -residual
                    call solve_counted(self%adapter, step, trial_error)
                end if
                if (.not. allocated(trial_error)) then
                    trial = self%u + step
                    call evaluate_timed(self%problem, trial, .false., residual, trial_error)
                    stats%residual_evaluations = stats%residual_evaluations + 1
                end if
                ! Accept a step that lowers the weighted 2-norm of the residual (a smooth
                ! merit: the max-norm test stalls on steps that trade one row for another).
                if (allocated(trial_error)) then
                    deallocate(trial_error)
                    merit_trial = huge(1.0_wp)
                else
                    merit_trial = norm2(residual * self%f_scale_data)
                end if
                if (merit_trial < merit) then
                    stats%iterations = stats%iterations + 1
                    self%u = trial
                    mu = mu * merit_trial / merit
                    ! The levels follow the state (as in solve_once).
                    call set_row_weights(self, .false., error)
                    if (allocated(error)) return
                    call get_scaled_norm(residual, self%f_scale_data, f, finite)
                    merit = norm2(residual * self%f_scale_data)
                else
                    mu = 10 * mu
                    if (mu > max_transient_shift) exit
                    call evaluate_timed(self%problem, self%u, .false., residual, error)
                    if (allocated(error)) return
                end if
            end do
            stats%residual_norm = f
            converged = f <= self%options%residual_tolerance
        end associate
    end subroutine solve_transient

    !> KINSOL's residual scaling from the problem's row levels at the current iterate:
    !> 1 / (level + noise / tol), so that |F_i| * weight_i <= tol is the row's test. A
    !> row with no force and no rounding (a scene without any force, whose exact
    !> residual is zero) gets weight 1. `uniform`: every row gets the weight of the
    !> largest level instead, for the first pass of KINSOL from an initial guess (the
    !> levels there may be far from those at the solution, and a line search on rows
    !> weighted by them stalls: measured on a yarn through two free contact nodes
    !> whose slack posts start at the floor level); the rows' own levels then finish.
    subroutine set_row_weights(self, uniform, error)
        class(newton_solver_type), intent(inout) :: self
        logical, intent(in) :: uniform
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: level(:), noise(:)
        real(wp) :: row_level
        integer :: i

        allocate(level(size(self%u)), noise(size(self%u)))
        call get_levels_timed(self%problem, self%u, level, noise, error)
        if (allocated(error)) return
        if (uniform) then
            level = level + noise / self%options%residual_tolerance
            level = maxval([0.0_wp, level])
            where (level > 0.0_wp)
                self%f_scale_data = 1.0_wp / level
            elsewhere
                self%f_scale_data = 1.0_wp
            end where
            return
        end if
        ! The same arithmetic in one pass (the weights at every new iterate).
        do i = 1, size(level)
            row_level = level(i) + noise(i) / self%options%residual_tolerance
            if (row_level > 0.0_wp) then
                self%f_scale_data(i) = 1.0_wp / row_level
            else
                self%f_scale_data(i) = 1.0_wp
            end if
        end do
    end subroutine set_row_weights

    !> The problem's row levels at u; the wall time goes to levels_time (get_timings).
    subroutine get_levels_timed(problem, u, level, noise, error)
        type(equilibrium_type), intent(inout) :: problem
        real(wp), intent(in) :: u(:)
        real(wp), intent(out) :: level(:), noise(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: start
        start = wall_time()
        call problem%problem%get_row_levels(u, level, noise, error)
        problem%levels_time = problem%levels_time + (wall_time() - start)
    end subroutine get_levels_timed

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

    !> The Jacobian's `zero` operation: nothing to do (see new_newton_solver).
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

    !> Accumulated figures: assembly (residual, Jacobian) and linear algebra times, and
    !> the row levels' time (`levels_time`: the state's computation at most iterates).
    subroutine get_timings(self, residual_time, jacobian_time, analyse_time, factor_time, &
            solve_time, n_factorisations, n_solves, levels_time)
        class(newton_solver_type), intent(in) :: self
        real(wp), intent(out) :: residual_time, jacobian_time, analyse_time, factor_time
        real(wp), intent(out) :: solve_time
        integer, intent(out) :: n_factorisations
        integer, intent(out), optional :: n_solves
        real(wp), intent(out), optional :: levels_time
        if (present(levels_time)) levels_time = 0.0_wp
        if (.not. associated(self%problem)) then
            residual_time = 0.0_wp
            jacobian_time = 0.0_wp
            analyse_time = 0.0_wp
            factor_time = 0.0_wp
            solve_time = 0.0_wp
            n_factorisations = 0
            if (present(n_solves)) n_solves = 0
            return
        end if
        residual_time = self%problem%residual_time
        jacobian_time = self%problem%jacobian_time
        analyse_time = self%adapter%analyse_time
        factor_time = self%adapter%factor_time
        solve_time = self%adapter%solve_time
        n_factorisations = self%adapter%n_factorisations
        if (present(n_solves)) n_solves = self%adapter%n_solves
        if (present(levels_time)) levels_time = self%problem%levels_time
    end subroutine get_timings

    subroutine destroy(self)
        class(newton_solver_type), intent(inout) :: self
        integer(c_int) :: ierr
        if (c_associated(self%kinsol)) call FKINFree(self%kinsol)
        self%kinsol = c_null_ptr
        if (associated(self%sunls)) ierr = FSUNLinSolFree(self%sunls)
        if (associated(self%jacobian)) call FSUNMatDestroy(self%jacobian)
        if (associated(self%u_vector)) call FN_VDestroy(self%u_vector)
        if (associated(self%u_scale)) call FN_VDestroy(self%u_scale)
        if (associated(self%f_scale)) call FN_VDestroy(self%f_scale)
        nullify(self%sunls, self%jacobian, self%u_vector, self%u_scale, self%f_scale)
        if (c_associated(self%sunctx)) ierr = FSUNContext_Free(self%sunctx)
        self%sunctx = c_null_ptr
        if (associated(self%linear)) then
            call self%linear%destroy()
            deallocate(self%linear)
        end if
        if (associated(self%adapter)) deallocate(self%adapter)
        if (associated(self%problem)) deallocate(self%problem)
        if (associated(self%u)) deallocate(self%u, self%u_scale_data, self%f_scale_data)
    end subroutine destroy

    subroutine finalize(self)
        type(newton_solver_type), intent(inout) :: self
        call self%destroy()
    end subroutine finalize

end module yarnfort_solver_newton
