! SPDX-License-Identifier: MIT
!> Figures of one Newton solve, and the options a caller passes to one solve.
module yarnfort_solver_newton_stats
    use yarnfort_kinds, only: wp
    implicit none
    private

    public :: newton_stats_type, solve_options_type

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

    !> How one solve goes (newton_solver_type%solve, try_chord); the default is a solve
    !> with every fallback and no chord steps.
    type :: solve_options_type
        !> Fail fast: full Newton steps only, given up after a few iterations without
        !> progress; no line search, no pseudo-transient fallback, no regularised
        !> predictor. For solves whose failure the caller handles more cheaply than those
        !> fallbacks do (a guessed stick/slip active set).
        logical :: quick = .false.
        !> Chord steps after the first Newton step of a solve (its factors reused); 0: none.
        integer :: chord_steps = 0
        !> Chord steps beyond chord_steps that a path just short of the tolerance may take
        !> to finish (take_chord_steps); 0: none.
        integer :: finish_steps = 0
    end type solve_options_type

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

end module yarnfort_solver_newton_stats
