! SPDX-License-Identifier: MIT
!> The capstan predictor of a slip front: when stick passages start to slip in an
!> active-set round, the stick passages beyond them along their yarns that the capstan
!> relation says the front will also pass start to slip in the same round.
!> Why: a stick passage's row fixes its flow, so a solve with the front at passage p
!> changes no tension beyond p; the rounds alone then move a front by one passage each
!> (a yarn over K pins took about K rounds per step that moves its front across them).
!> The prediction, from the state at which the round judged its set: a passage p that
!> starts to slip ends at its limit; with the tension on one side of p held, the other
!> side's tension is that limit (T_crit(T_before) after, or T_crit^-1(T_after) before,
!> forward; the reverse backward). The next passage along the yarn on that side sees
!> that tension on its side of the segment they share; if that takes it across its
!> limit it starts to slip too, and the march goes on from it, until a passage holds
!> (or is not stick, or may not slip that way, or the yarn ends). Holding the far side
!> overstates each change, so a predicted front runs ahead of the solution rather than
!> behind it; the rounds' rule for a flow that goes back then stops the passages past
!> the front in one round, while a front that falls short would cost a round per
!> passage again. Only the active set is predicted: every answer is judged by the
!> stick/slip test of the solved state as before.
module yarnfort_contact_stepper_slip_front
    use yarnfort_kinds, only: wp
    use yarnfort_friction_law, only: friction_law_type
    use yarnfort_contact_friction_problem, only: friction_problem_type, mode_stick, &
        mode_forward, mode_backward
    implicit none
    private

    public :: propagate_slips, is_at_held_node

    !> Sides of a passage along its yarn.
    integer, parameter :: side_before = 1, side_after = 2
    !> Bisection steps of T_crit^-1 (monotone in T_min: halves the bracket each).
    integer, parameter :: max_inverse_steps = 200

contains

    !> March the passages that start to slip (`started`; their direction in `mode`)
    !> along their yarns (module notes): stick passages that the march takes across
    !> their limit by more than `tolerance` (relative to the critical tension) get the
    !> direction of that violation in `mode` and are flagged in `predicted`. A passage
    !> with `blocked_forward` / `blocked_backward` does not start to slip that way.
    !> `problem` holds the judged state (update_state). Deterministic: the started
    !> passages are taken in index order.
    subroutine propagate_slips(problem, started, tolerance, blocked_forward, &
            blocked_backward, mode, predicted)
        type(friction_problem_type), intent(in) :: problem
        logical, intent(in) :: started(:), blocked_forward(:), blocked_backward(:)
        real(wp), intent(in) :: tolerance
        integer, intent(inout) :: mode(:)
        logical, intent(out) :: predicted(:)
        integer :: p, side

        predicted = .false.
        do p = 1, size(mode)
            if (.not. started(p) .or. mode(p) == mode_stick) cycle
            if (.not. is_held(p)) cycle
            do side = side_before, side_after
                call march(p, side)
            end do
        end do
    contains
        !> From passage `from` (at its limit once it slips), along the yarn on `side`.
        subroutine march(from, side)
            integer, intent(in) :: from, side
            integer :: p, q, direction
            real(wp) :: t_before, t_after, angle, shared

            p = from
            call problem%get_passage_state(p, t_before, t_after, angle)
            shared = get_limit_side(p, mode(p), side, t_before, t_after, angle)
            do
                q = get_next(p, side)
                if (q == 0) return
                if (mode(q) /= mode_stick .or. .not. is_held(q)) return
                call problem%get_passage_state(q, t_before, t_after, angle)
                ! q's side of the segment it shares with p: the opposite side.
                if (side == side_before) then
                    t_after = shared
                else
                    t_before = shared
                end if
                ! A front of one direction: material runs one way along it.
                direction = get_violation(q, t_before, t_after, angle)
                if (direction /= mode(from)) return
                mode(q) = direction
                predicted(q) = .true.
                shared = get_limit_side(q, direction, side, t_before, t_after, angle)
                p = q
            end do
        end subroutine march

        pure logical function is_held(p)
            integer, intent(in) :: p
            is_held = is_at_held_node(problem, p)
        end function is_held

        !> The passage at the other end of p's segment on `side` (0: none).
        pure integer function get_next(p, side) result(q)
            integer, intent(in) :: p, side
            associate(passages => problem%scene%passages)
                if (side == side_before) then
                    q = passages%at_start(passages%element_before(p))
                else
                    q = passages%at_end(passages%element_after(p))
                end if
            end associate
        end function get_next

        !> The direction passage q starts to slip in with these tensions, beyond
        !> `tolerance` and not blocked, or mode_stick.
        integer function get_violation(q, t_before, t_after, angle) result(direction)
            integer, intent(in) :: q
            real(wp), intent(in) :: t_before, t_after, angle
            real(wp) :: critical, d1, d2
            direction = mode_stick
            associate(law => problem%scene%friction(problem%scene%passages%law(q))%law)
                call law%get_critical_tension(t_before, angle, critical, d1, d2)
                if (t_after > critical * (1 + tolerance) .and. .not. blocked_forward(q)) then
                    direction = mode_forward
                    return
                end if
                call law%get_critical_tension(t_after, angle, critical, d1, d2)
                if (t_before > critical * (1 + tolerance) .and. .not. blocked_backward(q)) &
                    direction = mode_backward
            end associate
        end function get_violation

        !> Tension on `side` of passage p at its limit in `direction`, the other side's
        !> held.
        real(wp) function get_limit_side(p, direction, side, t_before, t_after, angle) &
                result(tension)
            integer, intent(in) :: p, direction, side
            real(wp), intent(in) :: t_before, t_after, angle
            real(wp) :: d1, d2
            associate(law => problem%scene%friction(problem%scene%passages%law(p))%law)
                if ((direction == mode_forward) .eqv. (side == side_after)) then
                    ! The high side: T_crit of the low one.
                    call law%get_critical_tension(merge(t_before, t_after, &
                        side == side_after), angle, tension, d1, d2)
                else
                    tension = get_inverse_critical(law, merge(t_after, t_before, &
                        side == side_before), angle)
                end if
            end associate
        end function get_limit_side
    end subroutine propagate_slips

    !> Passage p's node has a prescribed position (an obstacle's pin, a support).
    pure logical function is_at_held_node(problem, p)
        type(friction_problem_type), intent(in) :: problem
        integer, intent(in) :: p
        associate(node => problem%scene%passages%node(p))
            is_at_held_node = all(problem%scene%dofs%unknown(3 * node - 2:3 * node) == 0)
        end associate
    end function is_at_held_node

    !> The low-side tension T_min >= 0 with T_crit(T_min, angle) = `high` (0 where even
    !> T_min = 0 gives at least `high`), by bisection on [0, high] (T_crit(T) >= T).
    real(wp) function get_inverse_critical(law, high, angle) result(low)
        class(friction_law_type), intent(in) :: law
        real(wp), intent(in) :: high, angle
        real(wp) :: lower, upper, critical, d1, d2
        integer :: k

        low = 0.0_wp
        call law%get_critical_tension(0.0_wp, angle, critical, d1, d2)
        if (.not. (critical < high)) return
        lower = 0.0_wp
        upper = high
        do k = 1, max_inverse_steps
            low = 0.5_wp * (lower + upper)
            if (low <= lower .or. low >= upper) exit
            call law%get_critical_tension(low, angle, critical, d1, d2)
            if (critical < high) then
                lower = low
            else
                upper = low
            end if
        end do
    end function get_inverse_critical

end module yarnfort_contact_stepper_slip_front
