! SPDX-License-Identifier: MIT
!> What every part of the Newton solver works on: the iterate, the row weights, the
!> problem as KINSOL sees it, the linear solver behind its adapter, the &solver options,
!> the factors of the last Newton step, and the steps they share (a Newton step, a
!> chord step, the scaled residual).
module yarnfort_solver_newton_base
    use, intrinsic :: iso_c_binding, only: c_double
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: solver_config_type
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_solver_problem, only: regularisation_type
    use yarnfort_solver_sunlinsol_adapter, only: adapter_type, analyse_counted, &
        factor_counted, solve_counted
    use yarnfort_solver_newton_stats, only: newton_stats_type
    use yarnfort_solver_newton_equilibrium, only: equilibrium_type, evaluate_timed, &
        get_levels_timed, get_scaled_norm
    use yarnfort_solver_newton_kinsol, only: kinsol_type
    use yarnfort_solver_newton_row_update, only: row_update_type
    implicit none
    private

    public :: newton_base_type, set_row_weights, get_scaled_residual, analyse_once, &
        start_newton, newton_step, take_chord_steps, finish_chord, set_exact_law

    !> Owns KINSOL, the arrays of its vectors and the linear solver for one problem.
    type :: newton_base_type
        type(kinsol_type) :: kinsol
        real(c_double), pointer :: u(:) => null(), u_scale_data(:) => null()
        real(c_double), pointer :: f_scale_data(:) => null()
        type(equilibrium_type), pointer :: problem => null()
        type(adapter_type), pointer :: adapter => null()
        type(solver_config_type) :: options
        class(linear_solver_type), pointer :: linear => null()
        !> The linear solver's factorisation count just after the last Newton step
        !> (newton_step): while that count holds, its factors, and their values
        !> (adapter%factored_values), are still the linear solver's (the row update).
        integer :: kept_factorisation = -1
        !> A chord path stopped after its Newton step (solve_chord with no chord steps):
        !> the residual at self%u, the path's scaled residuals and the factorisation
        !> count then; resume_chord goes on from there while that count holds.
        real(wp), allocatable :: path_residual(:), path_history(:)
        integer :: path_factorisation = -1
    contains
        !> Timing and counters of assembly and linear algebra so far.
        procedure :: get_timings
        procedure :: destroy
        final :: finalize
    end type newton_base_type

contains

    !> The exact law for the solves that follow: no regularising spring in the model,
    !> the tangent of slack strings regularised by slack_stiffness.
    subroutine set_exact_law(self)
        class(newton_base_type), intent(inout) :: self
        self%problem%law = regularisation_type(tangent_spring=self%options%slack_stiffness)
    end subroutine set_exact_law

    !> KINSOL's residual scaling from the problem's row levels at the current iterate:
    !> 1 / (level + noise / tol), so that |F_i| * weight_i <= tol is the row's test. A
    !> row with no force and no rounding (a scene without any force, whose exact
    !> residual is zero) gets weight 1. `uniform`: every row gets the weight of the
    !> largest level instead, for the first pass of KINSOL from an initial guess, whose
    !> levels may be far from the solution's (docs/decisions.md, 'Newton: a first pass
    !> with uniform row weights'); the rows' own levels then finish.
    subroutine set_row_weights(self, uniform, error)
        class(newton_base_type), intent(inout) :: self
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

    !> The residual at self%u and its scaled max-norm, the row levels taken there.
    subroutine get_scaled_residual(self, residual, f, error)
        class(newton_base_type), intent(inout) :: self
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

    !> The linear solver's symbolic analysis of the problem's pattern, once.
    subroutine analyse_once(self, col_ptr, row_index, error)
        class(newton_base_type), intent(inout) :: self
        integer(ik), intent(in) :: col_ptr(:), row_index(:)
        type(error_type), allocatable, intent(out) :: error
        if (self%adapter%analysed) return
        call analyse_counted(self%adapter, int(size(col_ptr) - 1, ik), col_ptr, row_index, &
            error)
        if (allocated(error)) return
        self%adapter%analysed = .true.
    end subroutine analyse_once

    !> Analyse the pattern (once), fix the problem's solve-wide weights at u, self%u = u.
    subroutine start_newton(self, u, error)
        class(newton_base_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        type(error_type), allocatable, intent(out) :: error

        ! The problem's own pattern (fixed for its lifetime), not a copy per solve.
        associate(problem => self%problem%problem)
            call analyse_once(self, problem%col_ptr, problem%row_index, error)
        end associate
        if (allocated(error)) return
        ! New row weights (prepare_solve): the kept factors no longer match them.
        self%kept_factorisation = -1
        self%path_factorisation = -1
        call self%problem%problem%prepare_solve(u, error, self%problem%law)
        if (allocated(error)) return
        self%u = u
    end subroutine start_newton

    !> self%u <- self%u - J(self%u)^-1 residual (the residual at self%u, whose state the
    !> problem holds); the factors stay for chord steps.
    subroutine newton_step(self, residual, error)
        class(newton_base_type), intent(inout) :: self
        real(wp), intent(in) :: residual(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: values(:), step(:)

        allocate(values(self%problem%nnz))
        call evaluate_timed(self%problem, self%u, .true., values, error)
        if (allocated(error)) return
        call factor_counted(self%adapter, values, error)
        if (allocated(error)) return
        self%kept_factorisation = self%adapter%n_factorisations
        step = -residual
        call solve_counted(self%adapter, step, error)
        if (allocated(error)) return
        self%u = self%u + step
    end subroutine newton_step

    !> Up to max_steps chord steps from self%u (its residual and scaled residual f) with the
    !> factors the linear solver holds, or with `update` (those factors and replaced
    !> rows), while each cuts f tenfold, until f meets the tolerance; residual, f and
    !> history follow the accepted steps. Then up to max_finish more (default none) while
    !> the last chord step's contraction, kept, meets the tolerance within them: a path
    !> that ends just short of the tolerance costs solves, not another factorisation
    !> (docs/decisions.md, 'Chord paths finish at the tolerance').
    subroutine take_chord_steps(self, max_steps, residual, f, history, stats, update, &
            max_finish)
        class(newton_base_type), intent(inout) :: self
        integer, intent(in) :: max_steps
        real(wp), intent(inout) :: residual(:), f
        real(wp), allocatable, intent(inout) :: history(:)
        type(newton_stats_type), intent(inout) :: stats
        type(row_update_type), intent(inout), optional :: update
        integer, intent(in), optional :: max_finish
        type(error_type), allocatable :: trial_error
        real(wp), allocatable :: step(:)
        integer :: k, n_finish, accepted_steps
        logical :: accepted

        n_finish = 0
        if (present(max_finish)) n_finish = max(max_finish, 0)
        accepted_steps = 0
        allocate(step(size(residual)))
        do k = 1, max_steps + n_finish
            if (f <= self%options%residual_tolerance) exit
            if (k > max_steps) then
                if (accepted_steps == 0) exit
                if (.not. finishes(max_steps + n_finish - k + 1)) exit
            end if
            step = -residual
            if (present(update)) then
                call update%solve(self%adapter, step, trial_error)
            else
                call solve_counted(self%adapter, step, trial_error)
            end if
            if (allocated(trial_error)) exit
            call take_chord_step(self, step, residual, f, history, stats, accepted)
            if (.not. accepted) exit
            accepted_steps = accepted_steps + 1
        end do
    contains
        !> The last chord step's contraction r, kept, takes f to the tolerance within
        !> `steps` more steps: f r^steps <= tolerance.
        logical function finishes(steps)
            integer, intent(in) :: steps
            real(wp) :: r

            associate(n => size(history), tol => self%options%residual_tolerance)
                r = history(n) / history(n - 1)
                finishes = f * r**steps <= tol
            end associate
        end function finishes
    end subroutine take_chord_steps

    !> self%u + step replaces self%u if it cuts the scaled residual tenfold (`accepted`;
    !> residual, f and history then follow it), else self%u stays.
    subroutine take_chord_step(self, step, residual, f, history, stats, accepted)
        class(newton_base_type), intent(inout) :: self
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
        class(newton_base_type), intent(inout) :: self
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
        call self%problem%problem%check_solution(self%u, trial_error, self%problem%law)
        converged = .not. allocated(trial_error)
    end subroutine finish_chord

    !> Accumulated figures: assembly (residual, Jacobian) and linear algebra times, and
    !> the row levels' time (`levels_time`: the state's computation at most iterates).
    subroutine get_timings(self, residual_time, jacobian_time, analyse_time, factor_time, &
            solve_time, n_factorisations, n_solves, levels_time)
        class(newton_base_type), intent(in) :: self
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
        class(newton_base_type), intent(inout) :: self
        call self%kinsol%destroy()
        if (associated(self%linear)) then
            call self%linear%destroy()
            deallocate(self%linear)
        end if
        if (associated(self%adapter)) deallocate(self%adapter)
        if (associated(self%problem)) deallocate(self%problem)
        if (associated(self%u)) deallocate(self%u, self%u_scale_data, self%f_scale_data)
    end subroutine destroy

    subroutine finalize(self)
        type(newton_base_type), intent(inout) :: self
        call self%destroy()
    end subroutine finalize

end module yarnfort_solver_newton_base
