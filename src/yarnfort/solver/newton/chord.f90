! SPDX-License-Identifier: MIT
!> Chord paths: one Newton step, then steps with its factors while they contract; and
!> steps with the factors of the last Newton step and a row update (row_update.f90) for
!> a problem whose rows changed since (a friction step's active-set round).
module yarnfort_solver_newton_chord
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_solver_newton_stats, only: newton_stats_type
    use yarnfort_solver_newton_equilibrium, only: evaluate_timed
    use yarnfort_solver_newton_row_update, only: row_update_type, new_row_update
    use yarnfort_solver_newton_base, only: newton_base_type, get_scaled_residual, &
        start_newton, newton_step, take_chord_steps, finish_chord
    implicit none
    private

    public :: solve_chord, resume_chord, solve_row_update

    !> Most rows that solve_row_update replaces (it stores as many vectors of the order
    !> of the system).
    integer, parameter :: max_update_rows = 16
    !> Most chord steps of solve_row_update (each cuts the residual tenfold).
    integer, parameter :: max_update_steps = 8
    !> solve_row_update gives up at once (one residual evaluation) above this scaled
    !> residual at its start: an update started far off mostly fails at its first step
    !> (docs/decisions.md, 'Active-set rounds solved with the kept factors').
    real(wp), parameter :: max_update_start = 1.0e-2_wp

contains

    !> Chord fast path: one Newton step from u, then up to chord_steps steps with its
    !> factors while each cuts the scaled residual (rows at their own levels) tenfold,
    !> until it meets the tolerance, then up to finish_steps more if they finish the path
    !> (take_chord_steps). `converged`: u is then the solution; else u is the
    !> best iterate (the caller solves from there as usual). A steady load step starts
    !> close enough that the chord steps contract like Newton steps, and costs one
    !> factorisation instead of two; the steps stop at the solve's own tolerance
    !> (docs/decisions.md, 'Friction steps: chord steps in every solve').
    subroutine solve_chord(self, u, chord_steps, finish_steps, stats, converged, error)
        class(newton_base_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        !> Chord steps, and those beyond them that only finish (take_chord_steps).
        integer, intent(in) :: chord_steps, finish_steps
        type(newton_stats_type), intent(inout) :: stats
        logical, intent(out) :: converged
        type(error_type), allocatable, intent(out) :: error
        type(error_type), allocatable :: trial_error
        real(wp), allocatable :: residual(:), history(:)
        real(wp) :: f

        converged = .false.
        associate(tol => self%options%residual_tolerance)
            call start_newton(self, u, error)
            if (allocated(error)) return
            allocate(residual(size(u)))
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
                call take_chord_steps(self, min(chord_steps, self%options%max_iterations - 1), &
                    residual, f, history, stats, max_finish=min(finish_steps, &
                    self%options%max_iterations - 1 - chord_steps))
                ! A path stopped after its Newton step, for resume_chord.
                if (chord_steps == 0 .and. finish_steps == 0) then
                    self%path_residual = residual
                    self%path_history = history
                    self%path_factorisation = self%adapter%n_factorisations
                end if
            end if
            call finish_chord(self, u, f, history, stats, converged)
        end associate
    end subroutine solve_chord

    !> The chord steps of a path that solve_chord, with no chord steps, stopped after its
    !> Newton step (that step's iterate self%u, its residual and factors, still held):
    !> the path solve_chord with those steps would have taken, from the same iterate
    !> and history; u and `converged` as there, stats of these steps only. Nothing is
    !> tried (converged false, u unchanged) when the linear solver holds other factors
    !> or self%u moved since (start_newton, solve_row_update).
    subroutine resume_chord(self, u, chord_steps, finish_steps, stats, converged)
        class(newton_base_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        integer, intent(in) :: chord_steps, finish_steps
        type(newton_stats_type), intent(inout) :: stats
        logical, intent(out) :: converged
        real(wp), allocatable :: residual(:), history(:)
        real(wp) :: f
        integer :: n_path

        converged = .false.
        if (self%path_factorisation /= self%adapter%n_factorisations) return
        self%path_factorisation = -1
        call move_alloc(self%path_residual, residual)
        call move_alloc(self%path_history, history)
        n_path = size(history)
        f = history(n_path)
        call take_chord_steps(self, min(chord_steps, self%options%max_iterations - 1), &
            residual, f, history, stats, max_finish=min(finish_steps, &
            self%options%max_iterations - 1 - chord_steps))
        call finish_chord(self, u, f, history, stats, converged)
        stats%residual_history = history(n_path + 1:)
    end subroutine resume_chord

    !> Chord steps from u for a problem that differs from the one of the last Newton
    !> step in its rows `rows` only (a friction step's active-set round: passages turned
    !> stick or slip), while the linear solver still holds that step's factors, with the
    !> row update (row_update_type: no factorisation). The rows keep the weights of that
    !> solve (no prepare_solve). Steps go on while each cuts the scaled residual tenfold,
    !> until it meets the tolerance, as in solve_chord; `converged`: u is the solution,
    !> else u is the best iterate (or the start) and the caller solves on as usual.
    !> Nothing is tried (converged false, no evaluation) without kept factors or with
    !> more than max_update_rows rows.
    subroutine solve_row_update(self, u, rows, stats, converged, error)
        class(newton_base_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        integer, intent(in) :: rows(:)
        type(newton_stats_type), intent(out) :: stats
        logical, intent(out) :: converged
        type(error_type), allocatable, intent(out) :: error
        type(error_type), allocatable :: trial_error
        real(wp), allocatable :: residual(:), history(:), values(:)
        type(row_update_type) :: update
        integer :: n_rows
        real(wp) :: f

        converged = .false.
        n_rows = size(rows)
        if (n_rows == 0 .or. n_rows > max_update_rows) return
        ! self%u moves: a stopped chord path (resume_chord) is not resumed after this.
        self%path_factorisation = -1
        if (self%kept_factorisation /= self%adapter%n_factorisations) return
        if (.not. self%adapter%holds_factors) return
        associate(tol => self%options%residual_tolerance, n => size(u))
            self%u = u
            allocate(residual(n))
            call get_scaled_residual(self, residual, f, trial_error)
            stats%residual_evaluations = stats%residual_evaluations + 1
            if (allocated(trial_error)) return
            history = [f]
            stats%residual_norm = f
            stats%residual_history = history
            if (f > max_update_start) return
            if (f > tol) then
                ! The new rows: the Jacobian at u.
                allocate(values(self%problem%nnz))
                call evaluate_timed(self%problem, self%u, .true., values, trial_error)
                stats%jacobian_evaluations = stats%jacobian_evaluations + 1
                if (allocated(trial_error)) return
                call new_row_update(update, self%adapter, rows, self%problem%problem%col_ptr, &
                    self%problem%problem%row_index, values, self%adapter%factored_values, trial_error)
                if (allocated(trial_error)) return
                deallocate(values)
                call take_chord_steps(self, max_update_steps, residual, f, history, stats, &
                    update)
            end if
            call finish_chord(self, u, f, history, stats, converged)
        end associate
    end subroutine solve_row_update

end module yarnfort_solver_newton_chord
