! SPDX-License-Identifier: MIT
!> The stick/slip active-set rules, per passage, after each solve:
!>   stick -> slip forward  if T_after  > T_crit(T_before, alpha) (beyond tolerance);
!>   stick -> slip backward if T_before > T_crit(T_after, alpha);
!>   slip -> stick if the flow increment of the step has the wrong sign (at a held node:
!>   is not beyond the flows' accuracy in the right one), or -> slip the other way,
!>   unlocked, if it slipped away from a lock set in the step and stopped short of it
!>   (lifted_lock);
!>   and the stick passages that the new slips' fronts pass along their yarns, by the
!>   capstan relation, start to slip in the same round (yarnfort_contact_stepper_slip_front;
!>   docs/decisions.md, "Slip fronts: the capstan march").
!> A passage whose element would become shorter than min_length_ratio times its initial
!> reference length locks at that length (stick), and may not slip that way again while
!> the element keeps that length, in this step and the next ones. A passage that flips
!> more than max_flips times in one step is held in stick for the rest of the step
!> (chatter damping); the step fails if a held passage ends beyond its limit
!> (check_damped).
module yarnfort_contact_stepper_active_set
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: format_short
    use yarnfort_contact_friction_problem, only: friction_problem_type, mode_stick, &
        mode_forward, mode_backward, locked_both, node_level_floor
    use yarnfort_contact_stepper_slip_front, only: propagate_slips, is_at_held_node
    use yarnfort_contact_passages, only: is_at_minimum_length
    implicit none
    private

    public :: max_flips, update_active_set, stop_flowing_back, drop_slips_flowing_back, &
        is_at_min_length, &
        get_slip_tendency, check_damped, not_settled

    !> Flips of one passage's mode in a step before it is held in stick.
    integer, parameter :: max_flips = 6
    !> The stick test's dead band, in units of the uncertainty of the passage's
    !> tensions at convergence (residual_tolerance times their level plus rounding).
    real(wp), parameter :: dead_band_factor = 10.0_wp

contains

    !> The slipping passages whose flow went back at `iterate` (a Newton step from the
    !> start of a failed solve) stick, with their flows (in `flow`) at the `accepted`
    !> values, if some but not all of them did; `stopped`: they were changed.
    subroutine stop_flowing_back(iterate, accepted, mode, flow, stopped)
        real(wp), intent(in) :: iterate(:), accepted(:)
        integer, intent(inout) :: mode(:)
        real(wp), intent(inout) :: flow(:)
        logical, intent(out) :: stopped
        logical :: back(size(mode))

        back = flows_back(mode, iterate - accepted)
        stopped = any(back) .and. count(back) < count(mode /= mode_stick)
        if (.not. stopped) return
        where (back)
            mode = mode_stick
            flow = accepted
        end where
    end subroutine stop_flowing_back

    !> The new slips of a round whose solve failed (slipping in `mode`, stick in
    !> `good_mode`) whose flows the first Newton step from the round's `start` sends back
    !> (`iterate`) stick again, if some but not all of them did; `dropped`: how many.
    subroutine drop_slips_flowing_back(iterate, start, good_mode, mode, dropped)
        real(wp), intent(in) :: iterate(:), start(:)
        integer, intent(in) :: good_mode(:)
        integer, intent(inout) :: mode(:)
        integer, intent(out) :: dropped
        logical :: new(size(mode)), back(size(mode))

        new = good_mode == mode_stick .and. mode /= mode_stick
        back = new .and. flows_back(mode, iterate - start)
        dropped = count(back)
        if (dropped == count(new)) dropped = 0
        if (dropped == 0) return
        where (back) mode = mode_stick
    end subroutine drop_slips_flowing_back

    !> A passage that a lock at the minimum length stuck in this step (at flow `lock`)
    !> and that slipped away from it ends at `flow`, strictly between the lock and the
    !> step's start `start`: over the step it moved towards the lock without reaching
    !> it, so it slips that way, unlocked, and the next solve tells whether it reaches
    !> the lock. Such locks come from provisional iterates that overshoot; stuck at them
    !> again, the passage slipped off and stuck for ever (docs/decisions.md, "A slip
    !> away from a lock it never reached").
    elemental logical function lifted_lock(lock, flow, start)
        real(wp), intent(in) :: lock, flow, start
        lifted_lock = (lock < flow .and. flow < start) .or. (start < flow .and. flow < lock)
    end function lifted_lock

    !> A slipping passage (mode) whose flow `increment` has the wrong sign.
    elemental logical function flows_back(mode, increment)
        integer, intent(in) :: mode
        real(wp), intent(in) :: increment
        flows_back = (mode == mode_forward .and. increment < 0.0_wp) &
            .or. (mode == mode_backward .and. increment > 0.0_wp)
    end function flows_back

    !> Update the active set from the solved state held in `problem` (its update_state
    !> was called at the solution). `flow` are the solved flows, `accepted` those at the
    !> start of the step. Returns the number of passages whose mode changed.
    subroutine update_active_set(problem, flow, accepted, mode, flips, locked_forward, &
            locked_backward, changed, max_new_slips, new_slips, residual, at_limit, propagate, &
            marched)
        type(friction_problem_type), intent(inout) :: problem
        real(wp), intent(in) :: flow(:), accepted(:)
        integer, intent(inout) :: mode(:), flips(:)
        logical, intent(inout) :: locked_forward(:), locked_backward(:)
        integer, intent(out) :: changed
        !> At most this many stick passages start to slip (the most violated first).
        integer, intent(in) :: max_new_slips
        !> How many did.
        integer, intent(out) :: new_slips
        !> The scaled residual of the state when above the tolerance (a provisional
        !> iterate): the stick test's dead band grows with it (get_slip_tendency).
        real(wp), intent(in), optional :: residual
        !> The stick test's at_limit flag of each passage that was stick (on entry), at
        !> this state without `residual` (predict_modes' test of an accepted state).
        logical, allocatable, intent(inout), optional :: at_limit(:)
        !> March the new slips' fronts along their yarns (propagate_slips).
        logical, intent(in), optional :: propagate
        !> Passages whose slip a march predicted (propagate_slips) in this step: they
        !> count no flip, and neither does their stop. Given (the monolithic rounds), a
        !> slipping passage at a held node must also move (`still` below).
        logical, intent(inout), optional :: marched(:)
        integer :: p, new_mode, before, after, n_candidates, k, direction_p
        integer, allocatable :: predicted_mode(:)
        logical, allocatable :: started(:), predicted(:)
        integer :: unlocked_direction
        real(wp) :: min_before, min_after, increment, floor, measure, unlocked_measure, still
        integer, allocatable :: candidate(:), direction(:)
        real(wp), allocatable :: violation(:)
        associate(scene => problem%scene, passages => problem%scene%passages)
            floor = node_level_floor * problem%get_force_level()
            changed = 0
            new_slips = 0
            n_candidates = 0
            allocate(candidate(size(mode)), direction(size(mode)), violation(size(mode)))
            if (present(at_limit)) then
                if (allocated(at_limit)) deallocate(at_limit)
                allocate(at_limit(size(mode)), source=.false.)
            end if
            do p = 1, size(mode)
                if (flips(p) > max_flips) then
                    ! Held in stick (chatter damping): no test but its flag.
                    if (present(at_limit) .and. mode(p) == mode_stick) &
                        call get_slip_tendency(problem, p, floor, .false., .false., &
                        direction_p, measure, at_limit(p), residual=residual)
                    cycle
                end if
                before = passages%element_before(p)
                after = passages%element_after(p)
                min_before = scene%solver%min_length_ratio * scene%network%length0(before)
                min_after = scene%solver%min_length_ratio * scene%network%length0(after)
                new_mode = mode(p)
                increment = flow(p) - accepted(p)
                ! A slipping passage at a held node must move beyond the solve's accuracy
                ! of a flow (a stick row's tolerance), else it sticks: its flow is its only
                ! motion, so one that stays at its limit without moving is stuck, as the
                ! exact law has it (a march, or the last step's set, may slip a passage
                ! that sits at its limit). Not at a free node, where a tiny flow can carry a
                ! large change of tension (docs/decisions.md, "A slipping passage at a held
                ! node that does not move sticks").
                still = 0.0_wp
                if (present(marched)) then
                    if (is_at_held_node(problem, p)) still = scene%solver%residual_tolerance &
                        * problem%length_scale
                end if
                select case (mode(p))
                case (mode_stick)
                    ! An element locked at its minimum length in an earlier step stays so.
                    if (is_at_min_length(problem, before)) locked_forward(p) = .true.
                    if (is_at_min_length(problem, after)) locked_backward(p) = .true.
                    if (present(at_limit) .and. .not. (locked_forward(p) &
                            .or. locked_backward(p))) then
                        call get_slip_tendency(problem, p, floor, .false., .false., &
                            direction_p, measure, at_limit(p), residual=residual)
                    else
                        call get_slip_tendency(problem, p, floor, locked_forward(p), &
                            locked_backward(p), direction_p, measure, residual=residual)
                        ! The flag as predict_modes takes it, without locks (a lock lets
                        ! the test go on past the first limit, which may change it).
                        if (present(at_limit)) call get_slip_tendency(problem, p, floor, &
                            .false., .false., unlocked_direction, unlocked_measure, &
                            at_limit(p), residual=residual)
                    end if
                    if (direction_p /= mode_stick) call add_candidate(direction_p, measure)
                case (mode_forward)
                    if (flows_back(mode(p), increment - still)) new_mode = mode_stick
                    if (new_mode == mode_stick .and. locked_backward(p)) then
                        if (lifted_lock(problem%flow_target(p), flow(p), accepted(p))) then
                            new_mode = mode_backward
                            call lift_lock(locked_backward(p))
                        end if
                    end if
                    ! Forward flow shortens the element before the node.
                    if (problem%length0(before) < min_before) then
                        new_mode = mode_stick
                        locked_forward(p) = .true.
                        problem%locked(p) = mode_forward
                        problem%flow_target(p) = flow(p) + (problem%length0(before) &
                            - min_before) / passages%share(before)
                    end if
                case (mode_backward)
                    if (flows_back(mode(p), increment + still)) new_mode = mode_stick
                    if (new_mode == mode_stick .and. locked_forward(p)) then
                        if (lifted_lock(problem%flow_target(p), flow(p), accepted(p))) then
                            new_mode = mode_forward
                            call lift_lock(locked_forward(p))
                        end if
                    end if
                    if (problem%length0(after) < min_after) then
                        new_mode = mode_stick
                        locked_backward(p) = .true.
                        problem%locked(p) = mode_backward
                        problem%flow_target(p) = flow(p) - (problem%length0(after) &
                            - min_after) / passages%share(after)
                    end if
                end select
                call set_mode(p, new_mode)
            end do
            ! Stick passages that start to slip: the most violated first, up to the cap.
            allocate(started(size(mode)), predicted(size(mode)), source=.false.)
            do k = 1, min(n_candidates, max_new_slips)
                p = maxloc(violation(1:n_candidates), dim=1)
                call set_mode(candidate(p), direction(p))
                started(candidate(p)) = mode(candidate(p)) /= mode_stick
                violation(p) = -huge(1.0_wp)
                new_slips = new_slips + 1
            end do
            ! Their fronts along the yarns (yarnfort_contact_stepper_slip_front), no cap in
            ! force (after a failed round the rounds go one front step at a time).
            if (present(propagate) .and. max_new_slips >= huge(1) / 2) then
                if (propagate .and. any(started)) then
                    predicted_mode = mode
                    call propagate_slips(problem, started, scene%solver%friction_tolerance, &
                        locked_forward .or. flips > max_flips, &
                        locked_backward .or. flips > max_flips, predicted_mode, predicted)
                    do p = 1, size(mode)
                        if (.not. predicted(p)) cycle
                        if (present(marched)) then
                            mode(p) = predicted_mode(p)
                            marched(p) = .true.
                            changed = changed + 1
                        else
                            call set_mode(p, predicted_mode(p))
                        end if
                        new_slips = new_slips + 1
                    end do
                end if
            end if
        end associate
    contains
        !> Passage p's lock is lifted: its element is above the minimum length again, and
        !> it sticks (if it does) at the step's start, not at the lock.
        subroutine lift_lock(locked)
            logical, intent(inout) :: locked
            locked = .false.
            problem%locked(p) = 0
            problem%flow_target(p) = accepted(p)
        end subroutine lift_lock

        subroutine add_candidate(new_direction, measure)
            integer, intent(in) :: new_direction
            real(wp), intent(in) :: measure
            n_candidates = n_candidates + 1
            candidate(n_candidates) = p
            direction(n_candidates) = new_direction
            violation(n_candidates) = measure
        end subroutine add_candidate

        subroutine set_mode(passage, new_mode)
            integer, intent(in) :: passage, new_mode
            if (new_mode == mode(passage)) return
            mode(passage) = new_mode
            if (present(marched)) then
                if (marched(passage)) then
                    marched(passage) = .false.
                    changed = changed + 1
                    return
                end if
            end if
            flips(passage) = flips(passage) + 1
            changed = changed + 1
            if (flips(passage) > max_flips) then
                mode(passage) = mode_stick
                problem%locked(passage) = locked_both
            end if
        end subroutine set_mode
    end subroutine update_active_set

    !> Element e's reference length (in `problem`) is at its minimum
    !> (is_at_minimum_length).
    pure logical function is_at_min_length(problem, e)
        type(friction_problem_type), intent(in) :: problem
        integer, intent(in) :: e
        associate(scene => problem%scene)
            is_at_min_length = is_at_minimum_length(problem%length0(e), &
                scene%network%length0(e), scene%passages%share(e), &
                scene%solver%min_length_ratio, &
                scene%solver%residual_tolerance * scene%length_scale)
        end associate
    end function is_at_min_length

    !> Stick test of stick passage p at the state held in `problem` (update_state):
    !> `direction` is the way it starts to slip (mode_forward, mode_backward; not a
    !> locked one) and `measure` the relative excess of its high tension over the
    !> critical one, or `direction` is mode_stick. `floor`: node_level_floor times the
    !> scene's largest force.
    subroutine get_slip_tendency(problem, p, floor, locked_forward, locked_backward, &
            direction, measure, at_limit, residual)
        type(friction_problem_type), intent(in) :: problem
        integer, intent(in) :: p
        real(wp), intent(in) :: floor
        logical, intent(in) :: locked_forward, locked_backward
        integer, intent(out) :: direction
        real(wp), intent(out) :: measure
        !> The passage is within its dead band of the limit (either way).
        logical, intent(out), optional :: at_limit
        !> The state's scaled residual, when above the residual tolerance: it replaces
        !> that in the dead band.
        real(wp), intent(in), optional :: residual
        real(wp) :: t_before, t_after, angle, critical, d1, d2, tol, band, level
        real(wp) :: noise_before, noise_after

        direction = mode_stick
        measure = 0.0_wp
        associate(scene => problem%scene, passages => problem%scene%passages)
            tol = scene%solver%friction_tolerance
            level = scene%solver%residual_tolerance
            if (present(residual)) level = max(level, residual)
            call problem%get_passage_state(p, t_before, t_after, angle)
            noise_before = problem%get_element_noise(passages%element_before(p))
            noise_after = problem%get_element_noise(passages%element_after(p))
            ! The dead band of the stick test is the uncertainty of the passage's own
            ! tensions at convergence: the residual tolerance times their level (floored,
            ! like the nodes', by the scene's largest force) plus their rounding.
            associate(law => scene%friction(passages%law(p))%law)
                call law%get_critical_tension(t_before, angle, critical, d1, d2)
                band = dead_band_factor * (level &
                    * max(t_before, t_after, floor) + noise_after + abs(d1) * noise_before)
                if (present(at_limit)) at_limit = t_after >= critical * (1 - tol) - band
                if (t_after > critical * (1 + tol) + band .and. .not. locked_forward) then
                    direction = mode_forward
                    measure = (t_after - critical) / max(critical + band, tiny(1.0_wp))
                    return
                end if
                call law%get_critical_tension(t_after, angle, critical, d1, d2)
                band = dead_band_factor * (level &
                    * max(t_before, t_after, floor) + noise_before + abs(d1) * noise_after)
                if (present(at_limit)) at_limit = at_limit &
                    .or. t_before >= critical * (1 - tol) - band
                if (t_before > critical * (1 + tol) + band .and. .not. locked_backward) then
                    direction = mode_backward
                    measure = (t_before - critical) / max(critical + band, tiny(1.0_wp))
                end if
            end associate
        end associate
    end subroutine get_slip_tendency

    !> A passage held in stick by chatter damping must meet the stick test at the
    !> solved state held in `problem`: a held passage beyond its limit is not a solution
    !> of the friction law but an end of the search, and the step fails (it is cut)
    !> instead of being accepted: accepted, such states can take a run onto another
    !> branch (docs/decisions.md, "Neutral slip sets: no state beyond the limit").
    subroutine check_damped(problem, flips, locked_forward, locked_backward, error)
        type(friction_problem_type), intent(in) :: problem
        integer, intent(in) :: flips(:)
        logical, intent(in) :: locked_forward(:), locked_backward(:)
        type(error_type), allocatable, intent(out) :: error
        integer :: p, direction, n_beyond
        real(wp) :: floor, measure, worst
        character(len=200) :: buffer

        if (all(flips <= max_flips)) return
        floor = node_level_floor * problem%get_force_level()
        n_beyond = 0
        worst = 0.0_wp
        do p = 1, size(flips)
            if (flips(p) <= max_flips) cycle
            call get_slip_tendency(problem, p, floor, locked_forward(p), locked_backward(p), &
                direction, measure)
            if (direction == mode_stick) cycle
            n_beyond = n_beyond + 1
            worst = max(worst, measure)
        end do
        if (n_beyond == 0) return
        write(buffer, '("stick/slip active set did not settle: ", i0, " passages held in &
            &stick after more than ", i0, " flips are beyond their limit (up to ", a, &
            &" of the critical tension)")') n_beyond, max_flips, format_short(worst)
        call fatal_error(error, trim(buffer))
    end subroutine check_damped

    subroutine not_settled(error, rounds, flips)
        type(error_type), allocatable, intent(out) :: error
        integer, intent(in) :: rounds, flips(:)
        character(len=200) :: buffer
        write(buffer, '("stick/slip active set did not settle in ", i0, &
            & " rounds (max_friction_iterations); most flips of one passage: ", i0)') &
            rounds, maxval([0, flips])
        call fatal_error(error, trim(buffer))
    end subroutine not_settled
end module yarnfort_contact_stepper_active_set
