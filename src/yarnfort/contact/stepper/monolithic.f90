! SPDX-License-Identifier: MIT
!> The monolithic scheme: positions and flows solved together (friction_problem_type)
!> for a stick/slip active set, which is updated after each solve (update_active_set)
!> like a return mapping until it settles; each round after the first is a fast Newton
!> solve (full steps only), one that fails is retried with fewer new slips.
module yarnfort_contact_stepper_monolithic
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_solver_newton, only: newton_stats_type, solve_options_type
    use yarnfort_contact_friction_problem, only: friction_problem_type, mode_stick
    use yarnfort_contact_stepper_base, only: friction_stepper_base_type, chord_steps
    use yarnfort_contact_stepper_trace, only: record_solve, record_step, record_changes
    use yarnfort_contact_stepper_active_set, only: max_flips, update_active_set, &
        stop_flowing_back, drop_slips_flowing_back, check_damped, not_settled
    use yarnfort_contact_stepper_predictor, only: predicted_state, reversed, predict, &
        predict_modes
    use yarnfort_solver_interrupt, only: interrupt_requested
    implicit none
    private

    public :: try_monolithic

    !> Provisional rounds: a round's active set is judged at the chord path's iterate
    !> (newton_solver_type%try_chord: one Newton step and its chord steps) when that is
    !> not yet the solution but cut the scaled residual by provisional_contraction, with
    !> the stick test's dead band widened to provisional_band times that iterate's scaled
    !> residual; a set that changes there goes to the next round unsolved. Where the
    !> Newton step alone cut the scaled residual by newton_contraction, its iterate is
    !> judged so first, before the path's chord steps, which then follow only for a set
    !> that holds there (docs/decisions.md, "Provisional rounds judged at the Newton
    !> step"). A set that holds takes another such pass (up to provisional_passes), then
    !> is solved on (KINSOL) and judged at its solution, which alone ends a step. At most
    !> max_provisional_rounds set changes per step are provisional, none after a failed
    !> solve of the step. Why: most rounds' changes show well before convergence
    !> (docs/decisions.md, "Provisional active-set rounds (0.2 / 8 / 0.8)").
    integer, parameter :: max_provisional_rounds = 8, provisional_passes = 4
    real(wp), parameter :: provisional_contraction = 0.8_wp, provisional_band = 0.2_wp
    !> Judged at a looser iterate, the widened band hides new slips that the path's end
    !> shows, and they cost rounds (same entry).
    real(wp), parameter :: newton_contraction = 0.02_wp

contains

    subroutine try_monolithic(self, stats, iterations, error)
        class(friction_stepper_base_type), intent(inout) :: self
        type(newton_stats_type), intent(out) :: stats
        integer, intent(out) :: iterations
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: unknowns(:), good_unknowns(:), start(:), direction(:)
        integer, allocatable :: flips(:), good_mode(:), good_flips(:), failed_mode(:)
        logical, allocatable :: locked_forward(:), locked_backward(:)
        integer :: round, n_x, changed, cap, new_slips, outcome, provisional_rounds, pass
        integer :: failed_before, q, dropped
        logical, allocatable :: marched(:), good_marched(:)
        !> Active set of the last Newton step's factors (try_chord, take_newton_step).
        integer, allocatable :: factored_mode(:), passage_index(:)
        logical :: have_good, guessed, full_retry, sign_tried, stopped, solved, moved, chorded
        !> A provisional pass judges the set at its Newton step's iterate first.
        logical :: newton_first
        type(solve_options_type) :: step_options
        real(wp) :: newton_residual
        !> The new slips of the last solved round's set were given a drop (below).
        logical :: drop_tried
        !> This round's set is all-stick after other sets of the step (see full_options).
        logical :: fallback_stick
        !> Why a round is given up before KINSOL ('' when it is not).
        character(len=:), allocatable :: diverged
        !> The last round's set was solved (see `cap` where a round solves).
        logical :: solved_before
        type(error_type), allocatable :: step_error
        type(newton_stats_type) :: carried
        !> The options of this round's solves (quick: rounds with slipping passages).
        type(solve_options_type) :: full_options

        associate(problem => self%full, scene => self%scene)
            n_x = scene%dofs%n_unknowns
            problem%factors = self%factors_trial
            problem%flow_target = self%flow
            unknowns = [self%u, self%flow]
            call predict(self, unknowns, outcome, quadratic=.true.)
            guessed = .false.
            select case (outcome)
            case (predicted_state)
                ! Stick passages that the predicted state takes across their limit start
                ! the step slipping: a growing slip zone then costs no round per step.
                if (self%have_limits) then
                    call predict_modes(problem, [self%u, self%flow], self%factors, unknowns, &
                        self%mode_trial, guessed, error, self%at_limit)
                else
                    call predict_modes(problem, [self%u, self%flow], self%factors, unknowns, &
                        self%mode_trial, guessed, error)
                end if
                if (allocated(error)) return
            case (reversed)
                ! The loading turned: slipping passages start the step in stick (the last
                ! step's slip set costs a wasted solve; docs/decisions.md, "Predictor:
                ! secant, parabola along one active set, reversed at a turn").
                guessed = any(self%mode_trial /= mode_stick)
                self%mode_trial = mode_stick
            case default
                ! The first load step from the initial state (no predictor): all-stick, the
                ! elastic trial, and the rounds let the slip zone in (docs/decisions.md,
                ! "The first load step from rest starts all-stick").
                if (self%from_initial) self%mode_trial = mode_stick
            end select
            allocate(flips(size(self%flow)), source=0)
            allocate(locked_forward(size(self%flow)), locked_backward(size(self%flow)), &
                marched(size(self%flow)), source=.false.)
            passage_index = [(q, q = 1, size(self%flow))]
            iterations = 0
            problem%locked = 0
            cap = huge(1)
            have_good = .false.
            drop_tried = .false.
            full_retry = .false.
            sign_tried = .false.
            provisional_rounds = 0
            solved_before = .false.
            failed_before = self%trace%failed_solves
            do round = 1, scene%solver%max_friction_iterations
                if (interrupt_requested()) exit     ! Ctrl-C: the step fails, unsettled
                problem%mode = self%mode_trial
                ! Rounds with slipping passages are fast Newton solves (full steps only):
                ! a set with no solution nearby is cheaper to give up than to push through
                ! Newton's fallbacks, which may also end far along a neutral mode, off the
                ! path (docs/decisions.md, "Rounds with slipping passages: fast Newton
                ! solves, full steps only"). A fast round that fails is retried with half
                ! its new slips from the solved state; one with a single new slip or none
                ! is solved again with the fallbacks. A chord path just short of the
                ! tolerance finishes with chord steps (docs/decisions.md, "Chord paths
                ! finish at the tolerance").
                ! So is an all-stick set that is not the step's first (a fallback after
                ! failed sets, not the step from rest): it is far from the last state, and
                ! Newton's fallbacks took hundreds of iterations to fail or reach a spurious
                ! state; a cut is cheaper (docs/decisions.md, "A slip away from a lock it
                ! never reached").
                fallback_stick = round > 1 .and. .not. (self%from_initial .or. self%staggered)
                full_options = solve_options_type(quick=(any(self%mode_trial /= mode_stick) &
                    .or. fallback_stick) .and. .not. full_retry, &
                    chord_steps=merge(0, chord_steps, self%staggered), &
                    finish_steps=merge(0, chord_steps, self%staggered))
                start = unknowns
                solved = .false.
                carried = newton_stats_type()
                moved = .false.
                chorded = .false.
                ! After a failed solve the rounds go on from a fallback state: full rounds.
                if (self%trace%failed_solves > failed_before) &
                    provisional_rounds = max_provisional_rounds
                ! A set that changed in a few passages since the last Newton step's factors
                ! is first solved with those factors and its new passage rows
                ! (newton_solver_type%try_row_update: no factorisation); failing that (or
                ! with too many rows, other factors, or a start far off), as before from
                ! the best iterate. Most rounds after the first find a few passages that
                ! turn (a flow that goes back, a stick passage just over its limit) and
                ! cost a factorisation each (docs/decisions.md, "Active-set rounds solved
                ! with the kept factors (up to 16 changed passages)").
                if (round > 1 .and. allocated(factored_mode) .and. .not. full_retry) then
                    call self%newton_full%try_row_update(unknowns, n_x + pack(passage_index, &
                        self%mode_trial /= factored_mode), stats, solved, step_error)
                    if (allocated(step_error)) solved = .false.
                    carried = stats
                end if
                if (provisional_rounds < max_provisional_rounds .and. .not. (full_retry &
                        .or. solved)) then
                    ! Each pass is one Newton step: with the solve after them, within
                    ! max_iterations (a solve's limit).
                    do pass = 1, min(provisional_passes, scene%solver%max_iterations - 1)
                        ! The set is first judged at the Newton step's iterate where that
                        ! step contracted fast, before its chord steps: a set that changes
                        ! there has no use for them, and one that holds takes the same path
                        ! as before (docs/decisions.md, "Provisional rounds judged at the
                        ! Newton step").
                        newton_first = full_options%chord_steps > 0
                        step_options = full_options
                        if (newton_first) then
                            step_options%chord_steps = 0
                            step_options%finish_steps = 0
                        end if
                        call self%newton_full%try_chord(unknowns, stats, solved, step_error, &
                            step_options)
                        factored_mode = problem%mode
                        iterations = iterations + stats%iterations
                        call stats%add_earlier(carried)
                        carried = stats
                        chorded = .not. allocated(step_error)
                        if (allocated(step_error) .or. solved) exit
                        if (.not. allocated(stats%residual_history)) exit
                        if (newton_first) then
                            if (stats%residual_norm <= newton_contraction &
                                    * stats%residual_history(1)) then
                                call judge_provisional(problem, unknowns(n_x + 1:), &
                                    stats%residual_norm, changed)
                                moved = changed > 0
                                if (moved) exit
                            end if
                            ! The set holds there: the path's chord steps, with this Newton
                            ! step's factors (the path try_chord takes with them).
                            newton_residual = stats%residual_norm
                            call self%newton_full%resume_try_chord(unknowns, stats, solved, &
                                full_options)
                            ! Not resumed (other factors held): as after the Newton step.
                            if (.not. allocated(stats%residual_history)) &
                                stats%residual_norm = newton_residual
                            call stats%add_earlier(carried)
                            carried = stats
                            if (solved) exit
                        end if
                        if (.not. (stats%residual_norm <= provisional_contraction &
                            * stats%residual_history(1))) then
                            ! Not contracting, in a round after a solved state: its stops
                            ! only (the first Newton step sends their flows back, as in
                            ! stop_flowing_back), no new slips: such an iterate is too far
                            ! off to start new slips from (docs/decisions.md, "A provisional
                            ! iterate that does not contract: its stops only").
                            if (pass == 1 .and. (have_good .or. round > 1)) then
                                call judge_provisional(problem, unknowns(n_x + 1:), &
                                    stats%residual_norm, changed, 0)
                                moved = changed > 0
                            end if
                            exit
                        end if
                        call judge_provisional(problem, unknowns(n_x + 1:), &
                            stats%residual_norm, changed)
                        moved = changed > 0
                        if (moved) exit
                    end do
                    if (moved) then
                        provisional_rounds = provisional_rounds + 1
                        call record_solve(self%trace, carried, .false.)
                        cycle
                    end if
                    if (solved) then
                        stats = carried
                        carried = newton_stats_type()
                    end if
                end if
                full_retry = .false.
                ! A set whose first Newton step raised the scaled residual is given up
                ! without KINSOL where a better next set is known: a guessed start set
                ! (predict_modes, or stick at a turn) gives way to the last step's set from
                ! the predicted state (docs/decisions.md, "A guessed start set that
                ! diverges gives way to the last step's set"); new slips from a solved
                ! state fail the round, and those flowing back stick (below;
                ! docs/decisions.md, "A failed round: its new slips flowing back stick").
                if (chorded .and. .not. solved) then
                    if (guessed .and. .not. have_good) then
                        diverged = 'the guessed active set diverges'
                    else if (have_good .and. .not. drop_tried .and. new_slips > 1) then
                        diverged = 'the new slips diverge'
                    else
                        diverged = ''
                    end if
                    if (len(diverged) > 0 .and. first_step_rose(carried)) then
                        if (have_good) then
                            ! New slips: the round fails only where some of them flow back
                            ! (they stick, the rest goes on from the same start); where
                            ! none does, the set goes to KINSOL as any other: halving new
                            ! slips that all slip on cost rounds without end under a held
                            ! force (docs/decisions.md, "A failed round: its new slips
                            ! flowing back stick").
                            call drop_slips_back(problem, dropped)
                            if (dropped > 0) then
                                call record_solve(self%trace, carried, .true.)
                                solved_before = .false.
                                failed_before = self%trace%failed_solves
                                cycle
                            end if
                        else
                            call fatal_error(error, diverged)
                            stats = carried
                            solved = .true.
                        end if
                    end if
                end if
                if (.not. solved) then
                    call self%newton_full%solve(unknowns, stats, error, full_options, &
                        after_chord=chorded)
                    iterations = iterations + stats%iterations
                    call stats%add_earlier(carried)
                end if
                call record_solve(self%trace, stats, allocated(error))
                if (allocated(error)) then
                    solved_before = .false.
                    if (full_options%quick .and. .not. (have_good .or. guessed &
                        .or. sign_tried)) then
                        ! The step's first set failed, with no new slip: where a set that
                        ! slips as a whole must end (a periodic knit cell's passages at the
                        ! end of the release), the residual drives its neutral modes, and
                        ! the passages whose flows the first Newton step from the start
                        ! sends back are those that stop. They stick and the set is solved
                        ! again from the start; the rounds then judge the result as any
                        ! other (docs/decisions.md, "A failed first set: the passages
                        ! flowing back stick").
                        sign_tried = .true.
                        failed_mode = self%mode_trial
                        call step_from_start(problem)
                        if (.not. allocated(step_error)) then
                            unknowns = start
                            call stop_flowing_back(direction(n_x + 1:), self%flow, &
                                self%mode_trial, unknowns(n_x + 1:), stopped)
                            if (stopped) then
                                call record_changes(self%trace, failed_mode, self%mode_trial)
                                deallocate(error)
                                cycle
                            end if
                        end if
                    end if
                    ! A fixed active set may have no solution nearby. Go back to the last
                    ! solved state and let fewer passages start slipping at once (half as
                    ! many, most violated first); without such a state, restart from
                    ! all-stick (the elastic problem, which has a solution).
                    if (have_good .and. new_slips > 1 .and. .not. drop_tried) then
                        call drop_slips_back(problem, dropped)
                        if (dropped > 0) then
                            ! From a solved state, not a fallback's: its rounds may be
                            ! provisional.
                            failed_before = self%trace%failed_solves
                            deallocate(error)
                            cycle
                        end if
                    end if
                    if (have_good) then
                        if (new_slips <= 1) then
                            if (.not. full_options%quick) return
                            full_retry = .true.
                            deallocate(error)
                            cycle
                        end if
                        cap = max(1, new_slips / 2)
                        deallocate(error)
                        unknowns = good_unknowns
                        self%mode_trial = good_mode
                        flips = good_flips
                        marched = good_marched
                        call problem%update_state(unknowns, error)
                        if (allocated(error)) return
                        call update_active_set(problem, unknowns(n_x + 1:), self%flow, &
                            self%mode_trial, flips, locked_forward, locked_backward, changed, &
                            cap, new_slips)
                        cycle
                    end if
                    if (guessed) then
                        ! The guessed start failed: the last step's active set instead.
                        ! That restart is no fallback state, so its rounds may be
                        ! provisional (docs/decisions.md, "A guessed start set that diverges
                        ! gives way to the last step's set").
                        guessed = .false.
                        failed_before = self%trace%failed_solves
                        deallocate(error)
                        self%mode_trial = self%mode
                        unknowns = [self%u, self%flow]
                        call predict(self, unknowns, outcome, quadratic=.true.)
                        cycle
                    end if
                    if (all(self%mode_trial == mode_stick)) return
                    deallocate(error)
                    self%mode_trial = mode_stick
                    unknowns = [self%u, self%flow]
                    cycle
                end if
                call problem%update_state(unknowns, error)
                if (allocated(error)) return
                have_good = .true.
                drop_tried = .false.
                ! A failed round halves the cap on new slips (above); two solved rounds in
                ! a row double it again, so that the cap does not keep its lowest value
                ! for the rest of the step (docs/decisions.md, "Slip cap doubled after two
                ! solved rounds").
                if (solved_before .and. cap < huge(1) / 2) cap = 2 * cap
                solved_before = .true.
                good_unknowns = unknowns
                good_mode = self%mode_trial
                good_flips = flips
                good_marched = marched
                call update_active_set(problem, unknowns(n_x + 1:), self%flow, self%mode_trial, &
                    flips, locked_forward, locked_backward, changed, cap, new_slips, &
                    at_limit=self%at_limit_trial, propagate=.true., marched=marched)
                call record_changes(self%trace, good_mode, self%mode_trial)
                if (changed == 0) then
                    call check_damped(problem, flips, locked_forward, locked_backward, error)
                    self%unsettled = allocated(error)
                    if (allocated(error)) return
                    self%u_trial = unknowns(1:n_x)
                    self%flow_trial = unknowns(n_x + 1:)
                    self%n_damped = count(flips > max_flips)
                    ! No mode changed: the stick passages tested are the step's.
                    self%limits_trial = .true.
                    return
                end if
            end do
            call not_settled(error, scene%solver%max_friction_iterations, flips)
            self%unsettled = .true.
        end associate
    contains
        !> direction <- the round's start plus one Newton step of its set (the flows it
        !> sends back tell which passages stop), counted as an iteration.
        subroutine step_from_start(problem)
            type(friction_problem_type), intent(in) :: problem
            direction = start
            call self%newton_full%take_newton_step(direction, step_error)
            factored_mode = problem%mode
            call record_step(self%trace)
            iterations = iterations + 1
        end subroutine step_from_start

        !> A failed round's new slips whose flows its first Newton step sends back stick
        !> again (`dropped` of them) and the round starts again from its start: halving
        !> the new slips kept such a passage among the most violated and failed again
        !> and again (docs/decisions.md, "A failed round: its new slips flowing back
        !> stick"). Once per solved state (drop_tried).
        subroutine drop_slips_back(problem, dropped)
            type(friction_problem_type), intent(in) :: problem
            integer, intent(out) :: dropped

            drop_tried = .true.
            dropped = 0
            call step_from_start(problem)
            if (allocated(step_error)) return
            failed_mode = self%mode_trial
            call drop_slips_flowing_back(direction(n_x + 1:), start(n_x + 1:), good_mode, &
                self%mode_trial, dropped)
            if (dropped == 0) return
            where (failed_mode /= self%mode_trial) flips = good_flips
            new_slips = new_slips - dropped
            unknowns = start
            where (failed_mode /= self%mode_trial) unknowns(n_x + 1:) = problem%flow_target
        end subroutine drop_slips_back

        !> The active set judged at a provisional iterate (flows `flow`) as at a solved
        !> state; kept, with the rounds' bookkeeping, only if it changed (`changed`).
        subroutine judge_provisional(problem, flow, residual, changed, cap_here)
            type(friction_problem_type), intent(inout) :: problem
            real(wp), intent(in) :: flow(:), residual
            integer, intent(out) :: changed
            !> At most this many new slips (default: the rounds' cap); when given, the
            !> count of the last new slips (for halving) stays.
            integer, intent(in), optional :: cap_here
            integer, allocatable :: trial_mode(:), trial_flips(:), saved_locked(:)
            logical, allocatable :: trial_forward(:), trial_backward(:), trial_marched(:)
            real(wp), allocatable :: saved_target(:)
            type(error_type), allocatable :: state_error
            integer :: trial_new_slips, max_new_slips

            changed = 0
            call problem%update_state(unknowns, state_error)
            if (allocated(state_error)) return
            trial_mode = self%mode_trial
            trial_flips = flips
            trial_forward = locked_forward
            trial_backward = locked_backward
            trial_marched = marched
            saved_locked = problem%locked
            saved_target = problem%flow_target
            max_new_slips = cap
            if (present(cap_here)) max_new_slips = cap_here
            call update_active_set(problem, flow, self%flow, trial_mode, trial_flips, &
                trial_forward, trial_backward, changed, max_new_slips, &
                trial_new_slips, provisional_band * residual, propagate=.true., &
                marched=trial_marched)
            if (changed == 0) then
                problem%locked = saved_locked
                problem%flow_target = saved_target
                return
            end if
            call record_changes(self%trace, self%mode_trial, trial_mode)
            self%mode_trial = trial_mode
            flips = trial_flips
            locked_forward = trial_forward
            locked_backward = trial_backward
            marched = trial_marched
            if (.not. present(cap_here)) new_slips = trial_new_slips
        end subroutine judge_provisional
    end subroutine try_monolithic

    !> The first Newton step of a solve (chord path, `stats`) raised the scaled residual.
    pure logical function first_step_rose(stats)
        type(newton_stats_type), intent(in) :: stats
        first_step_rose = .false.
        if (.not. allocated(stats%residual_history)) return
        if (size(stats%residual_history) < 2) return
        first_step_rose = stats%residual_history(2) > stats%residual_history(1)
    end function first_step_rose
end module yarnfort_contact_stepper_monolithic
