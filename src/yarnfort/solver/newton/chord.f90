! SPDX-License-Identifier: MIT
!> Chord steps: one Newton step, then steps with its factors while they contract.
module yarnfort_solver_newton_chord
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_solver_sunlinsol_adapter, only: solve_counted
    use yarnfort_solver_newton_stats, only: newton_stats_type
    use yarnfort_solver_newton_base, only: newton_base_type, get_scaled_residual, &
        start_newton, newton_step, take_chord_step, finish_chord
    implicit none
    private

    public :: solve_chord

contains

    !> Chord fast path: one Newton step from u, then up to chord_steps steps with its
    !> factors while each cuts the scaled residual (rows at their own levels) tenfold,
    !> until it meets the tolerance. `converged`: u is then the solution; else u is the
    !> best iterate (the caller solves from there as usual). A steady load step starts
    !> close enough that the chord steps contract like Newton steps, and costs one
    !> factorisation instead of two; the steps stop at the solve's own tolerance
    !> (docs/decisions.md, 'Friction steps: chord steps in every solve').
    subroutine solve_chord(self, u, chord_steps, stats, converged, error)
        class(newton_base_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        integer, intent(in) :: chord_steps
        type(newton_stats_type), intent(inout) :: stats
        logical, intent(out) :: converged
        type(error_type), allocatable, intent(out) :: error
        type(error_type), allocatable :: trial_error
        real(wp), allocatable :: residual(:), step(:), history(:)
        real(wp) :: f
        integer :: k
        logical :: accepted

        converged = .false.
        associate(tol => self%options%residual_tolerance)
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
                do k = 1, min(chord_steps, self%options%max_iterations - 1)
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

end module yarnfort_solver_newton_chord
