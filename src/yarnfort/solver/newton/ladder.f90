! SPDX-License-Identifier: MIT
!> The Newton solver's fallback ladder: KINSOL with full steps, then with a line search,
!> then pseudo-transient continuation; a solve that still fails is predicted with a
!> regularised law (a spring in the model, then yarns softened) and corrected with the
!> exact law, so the answer is always the exact law's.
module yarnfort_solver_newton_ladder
    use, intrinsic :: iso_c_binding, only: c_int, c_double
    use fkinsol_mod, only: KIN_NONE, KIN_LINESEARCH
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: format_short
    use yarnfort_assembly_truss, only: no_stiffness_cap
    use yarnfort_solver_problem, only: regularisation_type
    use yarnfort_solver_newton_stats, only: newton_stats_type, solve_options_type
    use yarnfort_solver_newton_equilibrium, only: evaluate_timed, get_levels_timed, &
        get_scaled_norm
    use yarnfort_solver_newton_base, only: newton_base_type, set_row_weights, set_exact_law
    use yarnfort_solver_newton_chord, only: solve_chord
    use yarnfort_solver_newton_transient, only: solve_transient
    implicit none
    private

    public :: solve_with_fallbacks

    !> Times KINSOL goes on from its solution when the row levels taken there ask for
    !> a smaller residual than those of the initial guess.
    integer, parameter :: max_level_rounds = 4
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

contains

    !> Solve from the initial guess u: with the exact law (after options%chord_steps
    !> chord steps unless `after_chord`); if that fails and slack_stiffness > 0,
    !> predicted with the regularising spring and corrected with the exact law from the
    !> prediction; last, predicted with softened yarns (solve_stiffening). No fallback
    !> with options%quick. stats add up all attempts.
    subroutine solve_with_fallbacks(self, u, options, after_chord, stats, error)
        class(newton_base_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        type(solve_options_type), intent(in) :: options
        !> u is where a chord path left off: go on without another one.
        logical, intent(in) :: after_chord
        type(newton_stats_type), intent(out) :: stats
        type(error_type), allocatable, intent(out) :: error
        type(error_type), allocatable :: exact_error
        logical :: converged, tried

        call set_exact_law(self)
        if (options%chord_steps > 0 .and. .not. after_chord) then
            call solve_chord(self, u, options%chord_steps, options%finish_steps, stats, &
                converged, error)
            if (allocated(error) .or. converged) return
        end if
        call solve_once(self, u, options%quick, stats, exact_error)
        if (.not. allocated(exact_error)) return
        if (options%quick) then
            call move_alloc(exact_error, error)
            return
        end if
        if (self%options%slack_stiffness > 0.0_wp) then
            call predict_with_spring(self, u, stats, error)
            if (.not. allocated(error)) return
            exact_error%message = exact_error%message // error%message
            deallocate(error)
        end if
        call solve_stiffening(self, u, stats, tried, error)
        if (allocated(error)) then
            error%message = exact_error%message // error%message
        else if (.not. tried) then
            call move_alloc(exact_error, error)
        end if
    end subroutine solve_with_fallbacks

    !> Predict with the spring in the model, weight driven down from predictor_weight to
    !> slack_stiffness by factors of 10 (each solve from the last), then correct with
    !> the exact law. An error says where it failed.
    subroutine predict_with_spring(self, u, stats, error)
        class(newton_base_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        type(newton_stats_type), intent(inout) :: stats
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: guess(:)
        real(wp) :: weight

        associate(spring => self%options%slack_stiffness)
            guess = u
            weight = max(predictor_weight, spring)
            do
                self%problem%law = regularisation_type(spring=weight)
                call solve_once(self, guess, .false., stats, error)
                if (allocated(error)) then
                    call set_exact_law(self)
                    error%message = '; with the regularised law as predictor: ' &
                        // error%message
                    return
                end if
                if (weight <= spring) exit
                weight = max(spring, weight / 10)
            end do
            call set_exact_law(self)
            call solve_once(self, guess, .false., stats, error)
            if (allocated(error)) then
                error%message = '; corrected from the regularised prediction: ' &
                    // error%message
                return
            end if
            u = guess
        end associate
    end subroutine predict_with_spring

    !> The last fallback, for yarns far stiffer than the forces they carry: a full
    !> Newton step can move a node along such a yarn by only about sqrt(l T / EA) (the
    !> stretch it causes grows with the step's square), so a ring that must slide far
    !> along it takes thousands of them. Solved first with every law stiffer than
    !> first_cap_per_force times the largest force of the rows at u scaled down to that
    !> stiffness (get_truss_tension), then with the cap raised by stiffening_factor per
    !> solve, each from the last, until no law is capped, and corrected with the exact
    !> laws: only the initial guess of that last solve changes, so the answer is the
    !> exact laws'. `tried` is false (u unchanged, no error) when no law is that stiff;
    !> an error when a solve fails.
    subroutine solve_stiffening(self, u, stats, tried, error)
        class(newton_base_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        type(newton_stats_type), intent(inout) :: stats
        logical, intent(out) :: tried
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: guess(:), level(:), noise(:)
        real(wp) :: cap, stiffest

        associate(problem => self%problem%problem)
            allocate(level(size(u)), noise(size(u)))
            call get_levels_timed(self%problem, u, level, noise, error)
            if (allocated(error)) return
            stiffest = problem%get_max_reference_stiffness()
            cap = first_cap_per_force * maxval([0.0_wp, level])
            tried = cap > 0.0_wp .and. cap < stiffest
            if (.not. tried) return
            guess = u
            do while (cap < stiffest)
                self%problem%law%stiffness_cap = cap
                call solve_once(self, guess, .false., stats, error)
                self%problem%law%stiffness_cap = no_stiffness_cap
                if (allocated(error)) then
                    error%message = '; with the yarns softened to a stiffness of ' &
                        // format_short(cap, 4) // ' as predictor: ' // error%message
                    return
                end if
                cap = cap * stiffening_factor
            end do
            call solve_once(self, guess, .false., stats, error)
            if (allocated(error)) then
                error%message = '; corrected from the softened prediction: ' // error%message
                return
            end if
            u = guess
        end associate
    end subroutine solve_stiffening

    !> One Newton solve with the problem's current law: KINSOL with full steps and then
    !> (with line_search, unless `quick`) with a line search, then pseudo-transient
    !> continuation. Rows are scaled by their levels at the initial guess; at the end
    !> the levels are taken again at the solution and, should the residual not meet
    !> them, KINSOL goes on from there.
    subroutine solve_once(self, u, quick, stats, error)
        class(newton_base_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        logical, intent(in) :: quick
        type(newton_stats_type), intent(inout) :: stats
        type(error_type), allocatable, intent(out) :: error
        integer(c_int) :: ierr, strategy
        real(c_double) :: residual(size(u))
        integer :: round, attempt, n_attempts
        logical :: converged, finite
        character(len=200) :: buffer

        ! KINSOL's factors and prepare_solve's weights are not those of newton_step.
        self%kept_factorisation = -1
        ! Full Newton steps first; with line_search, a failed attempt is repeated from
        ! the initial guess with KINSOL's line search (back-tracking where needed only).
        n_attempts = merge(2, 1, self%options%line_search .and. .not. quick)
        do attempt = 1, n_attempts
            strategy = merge(KIN_NONE, KIN_LINESEARCH, attempt == 1)
            self%problem%n_history = 0
            self%problem%watch_stall = attempt < n_attempts .or. quick
            self%problem%best_residual = huge(1.0_wp)
            self%problem%since_best = 0
            if (allocated(self%problem%error)) deallocate(self%problem%error)
            if (allocated(self%problem%kinsol_message)) deallocate(self%problem%kinsol_message)
            if (allocated(self%adapter%error)) deallocate(self%adapter%error)
            call self%problem%problem%prepare_solve(u, error, self%problem%law)
            if (allocated(error)) return
            self%u = u
            call set_row_weights(self, .true., error)
            if (allocated(error)) return
            converged = .false.
            do round = 1, max_level_rounds
                ierr = self%kinsol%solve(strategy, stats)
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
        if (.not. converged .and. self%options%line_search .and. .not. quick) then
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
        call self%problem%problem%check_solution(self%u, error, self%problem%law)
        if (allocated(error)) return
        u = self%u
    end subroutine solve_once

end module yarnfort_solver_newton_ladder
