! SPDX-License-Identifier: MIT
!> MONO_HEADER
module yarnfort_contact_stepper_monolithic
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_solver_newton, only: newton_stats_type
    use yarnfort_contact_friction_problem, only: friction_problem_type, mode_stick
    use yarnfort_contact_stepper_base, only: friction_stepper_base_type
    use yarnfort_contact_stepper_trace, only: record_solve, record_step, record_changes
    use yarnfort_contact_stepper_active_set, only: max_flips, update_active_set, &
        stop_flowing_back, check_damped, not_settled
    use yarnfort_contact_stepper_predictor, only: predicted_state, reversed, predict, &
        predict_modes
    implicit none
    private

    public :: try_monolithic


    !> Provisional rounds of a monolithic step (try_monolithic): a round's active set is
    !> judged at the chord path's iterate (newton_solver_type%try_chord: one Newton step
    !> and its chord steps) when that is not yet the solution but cut the scaled residual
    !> by provisional_contraction, with the stick test's dead band widened to
    !> provisional_band times that iterate's scaled residual; a set that changes there
    !> goes to the next round without being solved to the tolerance. A set that holds
    !> takes another such pass (up to
    !> provisional_passes), then is solved on from there (KINSOL) as before and judged
    !> again at its solution, which alone ends a step. At most max_provisional_rounds
    !> set changes per step are provisional, and none after a failed solve of the step
    !> (the rounds then go on from a fallback state). Measured (benchmarks/
    !> steps_results.md, section 10; Newton iterations per step, before -> after):
    !> inputs/knit_clamped.nml 3.27 -> 2.23; loading to strain 1, 4 x 4 clamped default /
    !> taut / rollers 3.15 / 1.90 / 2.20 -> 2.15 / 1.75 / 2.00, periodic 1.70 -> 1.60;
    !> 8 x 8 4.80 / 2.30 / 2.50 -> 4.25 / 1.90 / 2.15, periodic 1.75 -> 1.65; woven nets
    !> equal or fewer (skewed 22: 2.00 -> 1.85); same steps, no cut, forces within 6e-11
    !> of the peak. Judged at every iterate, however far (no contraction test), the step
    !> from the unloaded state turned hundreds of passages that the solution stopped
    !> again: knit_clamped 2.73, the 8 x 8 periodic cell 3.50, the 10 x 10 woven net 8.88
    !> (against 1.13). Without the widened dead band or with provisional rounds after a
    !> failed solve, the 8 x 4 twill of tests/verification/test_texgen.py took 9.35
    !> instead of 3.90 and, from TexGen's copy of the same net, ended 5e-6 of the peak
    !> force away from the built-in one's answer.
    !> Measured (benchmarks/steps_results.md, section 12; loading to strain 1 / one
    !> stretch cycle, Newton iterations per step): the band at 0.2 of the iterate's
    !> residual (1 before) and up to 8 provisional set changes per step (4 before), with
    !> the stops-only judgement of try_monolithic in every round but the first: the
    !> 8 x 8 clamped knit (default edge threads) 2.90 / 2.77 -> 2.60 / 2.52, 4 x 4
    !> 2.15 / 2.17 -> 2.10 / 2.15, the TexGen twill 2.65 -> 2.30, inputs/knit_clamped.nml
    !> 2.23 -> 2.20; the band alone 2.75 / 2.67; forces within 1e-13 of the peak. At 0.1
    !> the built-in twill took 3.40 instead of 2.80, at 0.03 4.05; at 0.5 the 8 x 8 knit
    !> 2.65 / 2.58. With that band, a contraction of 0.8 instead of 0.5: 4 x 4 clamped
    !> taut thread 1.75 / 1.80 -> 1.60 / 1.73, default cycle 2.15 -> 2.12, the periodic
    !> knit3d 2 x 2 cell (max_step 0.025) 2.00 -> 1.81, no scene worse; at 0.9 the
    !> TexGen twill 2.30 -> 2.65 and knit3d 4 x 2 (0.0125) 1.50 -> 1.54.
    integer, parameter :: max_provisional_rounds = 8, provisional_passes = 4
    real(wp), parameter :: provisional_contraction = 0.8_wp, provisional_band = 0.2_wp

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
        integer :: failed_before, q
        logical, allocatable :: marched(:), good_marched(:)
        !> Active set of the last Newton step's factors (try_chord, take_newton_step).
        integer, allocatable :: factored_mode(:), passage_index(:)
        logical :: have_good, guessed, full_retry, sign_tried, stopped, solved, moved, chorded
        !> The last round's set was solved (see `cap` where a round solves).
        logical :: solved_before
        type(error_type), allocatable :: step_error
        type(newton_stats_type) :: carried

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
                ! The loading turned: slipping passages start the step in stick (measured:
                ! the last step's slip set first cost a failed or wasted solve, then a
                ! round).
                guessed = any(self%mode_trial /= mode_stick)
                self%mode_trial = mode_stick
            case default
                ! The first load step from the initial state (no predictor): all-stick, the
                ! elastic trial, and the rounds let the slip zone in. Measured
                ! (benchmarks/steps_results.md, section 11): step 1 of the 8 x 8 clamped
                ! knit (default edge threads) took 27 Newton iterations instead of 30 from
                ! the initial state's slip set; no other scene changed.
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
            full_retry = .false.
            sign_tried = .false.
            provisional_rounds = 0
            solved_before = .false.
            failed_before = self%trace%failed_solves
            do round = 1, scene%solver%max_friction_iterations
                problem%mode = self%mode_trial
                ! The last step's active set, when it has no solution nearby, is cheaper to
                ! replace by all-stick (below) than to push through Newton's fallbacks:
                ! measured on a clamped 4 x 4 knit (stretch cycles to 2x), such failures
                ! took 200-300 iterations each; solved fast (full steps only) the run
                ! took 2591 Newton iterations instead of 4522 (same 81 steps), 1.15 s CPU
                ! instead of 1.85 s.
                ! Later rounds are fast too, from a solved state: their new slips should
                ! move it a little. Newton's fallbacks (line search, pseudo-transient) may
                ! instead find a far solution of the set, which meets every stick/slip
                ! condition and is not the continuation of the path. Measured on
                ! inputs/knit3d.nml (1 x 1 cell, max_step 0.0125): where unloading turns
                ! the loop's four passages back to slip at once, that set has a neutral
                ! mode (the yarn running round the loop); 53 iterations took it 2e-4 m (a
                ! fifth of the course spacing) along that mode and the answer left the
                ! small-step limit by 15 % of the peak force for a third of the unloading
                ! (benchmarks/steps_results.md, section 5). A fast round that fails is
                ! retried with half its new slips from the solved state; one with a single
                ! new slip or none is solved again with the fallbacks.
                self%newton_full%quick = any(self%mode_trial /= mode_stick) .and. .not. full_retry
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
                ! cost a factorisation each. Measured (benchmarks/steps_results.md,
                ! section 13; Newton iterations per step, before -> after): woven cycle
                ! 10,120 unknowns aligned 1.27 -> 1.20, skewed 1.83 -> 1.42, 96,600
                ! aligned 1.72 -> 1.40, skewed 2.75 -> 1.68; clamped knits 8 x 8 (loading)
                ! default 2.60 -> 2.50, taut 1.90 -> 1.80, rollers 2.15 -> 1.95,
                ! inputs/knit_clamped.nml 2.20 -> 2.12; periodic cells equal; residual
                ! evaluations per step up to +11 % (8 x 8 default cycle 9.40 -> 10.43);
                ! same steps, forces within 1e-12 of the peak on 28 scenes.
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
                        call self%newton_full%try_chord(unknowns, stats, solved, step_error)
                        factored_mode = problem%mode
                        iterations = iterations + stats%iterations
                        call stats%add_earlier(carried)
                        carried = stats
                        chorded = .not. allocated(step_error)
                        if (allocated(step_error) .or. solved) exit
                        if (.not. allocated(stats%residual_history)) exit
                        if (.not. (stats%residual_norm <= provisional_contraction &
                            * stats%residual_history(1))) then
                            ! Not contracting, in a round after a solved state: its stops
                            ! only (the first Newton step sends their flows back, as in
                            ! stop_flowing_back), no new slips. Measured
                            ! (benchmarks/steps_results.md, section 11): the 8 x 8 clamped
                            ! knit, step 1 from rest 27 -> 13 Newton iterations (224 new
                            ! slips at the elastic trial, 100 of them stop), loading 3.60 ->
                            ! 2.90 per step, cycle 3.12 -> 2.77; no other scene changed.
                            ! Also in any other round but the step's first (section 12: step
                            ! 2 of that knit, after its guessed set failed, 12 -> 9 Newton
                            ! iterations with max_provisional_rounds 8; with 4, 13).
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
                if (guessed .and. .not. (have_good .or. solved) .and. chorded) then
                    ! A guessed start set (predict_modes, or stick at a turn) whose first
                    ! Newton step raised the scaled residual is given up without KINSOL;
                    ! the last step's set from the predicted state follows (below).
                    ! Measured (benchmarks/steps_results.md, section 11; Newton iterations
                    ! per step): the 8 x 4 twill of tests/verification/test_texgen.py
                    ! built-in / TexGen 3.85 / 3.95 -> 2.85 / 2.65, inputs/belt.nml 3.12
                    ! -> 2.77, the 8 x 8 clamped knit 3.90 -> 3.60 (step 2: the set
                    ! predicted from the unloaded state took 7 iterations to fail).
                    if (first_step_rose(carried)) then
                        call fatal_error(error, 'the guessed active set diverges')
                        stats = carried
                        solved = .true.
                    end if
                end if
                if (.not. solved) then
                    call self%newton_full%solve(unknowns, stats, error, after_chord=chorded)
                    iterations = iterations + stats%iterations
                    call stats%add_earlier(carried)
                end if
                call record_solve(self%trace, stats, allocated(error))
                if (allocated(error)) then
                    solved_before = .false.
                    if (self%newton_full%quick .and. .not. (have_good .or. guessed &
                        .or. sign_tried)) then
                        ! The step's first set failed, with no new slip: where a set that
                        ! slips as a whole must end (a periodic knit cell's passages at the
                        ! end of the release), the residual drives its neutral modes, and
                        ! the passages whose flows the first Newton step from the start
                        ! sends back are those that stop. They stick and the set is solved
                        ! again from the start; the rounds then judge the result as any
                        ! other. Measured (benchmarks/steps_results.md, section 8): the
                        ! planar 4 x 2 cell at max_step 0.05 took 24 rounds and 122 Newton
                        ! iterations at t = 1.95 through all-stick and halving, now 2 rounds
                        ! (at 0.04 main cut that step). The last iterate of the failed solve
                        ! instead, where the modes have run off, gave sets that failed again
                        ! once the start moved a little (with the chord path).
                        sign_tried = .true.
                        failed_mode = self%mode_trial
                        direction = start
                        call self%newton_full%take_newton_step(direction, step_error)
                        factored_mode = problem%mode
                        call record_step(self%trace)
                        iterations = iterations + 1
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
                    if (have_good) then
                        if (new_slips <= 1) then
                            if (.not. self%newton_full%quick) return
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
                        ! provisional. Measured (benchmarks/steps_results.md, section 11):
                        ! the 8 x 8 clamped knit 4.10 -> 3.90 Newton iterations per step
                        ! (loading), the built-in twill 3.95 -> 3.85, inputs/belt.nml 3.20
                        ! -> 3.12, no scene worse.
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
                ! A failed round halves the cap on new slips (above); two solved rounds in
                ! a row double it again. Without that the cap kept its lowest value for
                ! the rest of the step: the first load step of a 24 x 24 clamped knit
                ! (default edge threads, 4,512 passages, about 2,200 of which start to
                ! slip) failed at 1,104, 552, ... 2 new slips and then took 2 per round
                ! until the 200 rounds ran out (a cut; the step at half the load took
                ! 213 rounds and 1,258 Newton iterations). Doubling after every solved
                ! round took 24 x 24 to 14.8 Newton iterations per load step from 59.6 but
                ! 32 x 32 to 57.5 from 18.4 (every other round failed at twice a cap that
                ! solved); after two in a row: 13.2 and 18.7 (benchmarks/steps_results.md,
                ! section 23).
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
