! SPDX-License-Identifier: MIT
!> The start of a load step: the predicted state (secant, or the parabola through three
!> states of one active set; reversed secant across a turn) and the stick passages that
!> it takes across their limit slipping, with their slip fronts (predict_modes).
module yarnfort_contact_stepper_predictor
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_contact_friction_problem, only: friction_problem_type, mode_stick, &
        node_level_floor
    use yarnfort_contact_stepper_slip_front, only: propagate_slips
    use yarnfort_contact_stepper_active_set, only: get_slip_tendency, is_at_min_length
    use yarnfort_contact_stepper_base, only: friction_stepper_base_type
    implicit none
    private

    public :: predicted_state, reversed, predict, predict_modes

    !> Outcomes of the predictor (predict).
    integer, parameter :: predicted_state = 1, reversed = -1

contains

    !> Secant predictor for the monolithic unknowns: extrapolate positions and the flows
    !> of slipping passages along the last accepted increment, scaled by the ratio of
    !> load increments (of the sum of the channels' factors), while the loading keeps its
    !> direction. Where the last three accepted states share one active set and lie in
    !> the same direction of the loading, the parabola through them (in the load) is
    !> extrapolated instead. When the loading turns, the positions go back along that
    !> increment (flows kept: the step starts in stick). Why: a step started closer to
    !> its solution takes fewer Newton iterations (docs/decisions.md, "Predictor:
    !> secant, parabola along one active set, reversed at a turn").
    !> `outcome`: predicted_state, else reversed when the loading turned, else 0.
    subroutine predict(self, unknowns, outcome, quadratic)
        class(friction_stepper_base_type), intent(in) :: self
        real(wp), intent(inout) :: unknowns(:)
        integer, intent(out) :: outcome
        !> The parabola may be used (not by the staggered scheme: it measured no gain
        !> there; same entry).
        logical, intent(in) :: quadratic
        real(wp) :: ratio, load, load_now, w_older, w_old, w_now
        integer :: n_x

        outcome = 0
        if (.not. self%have_old) return
        load = sum(self%factors_trial)
        load_now = sum(self%factors)
        if (load_now == self%load_old) return
        ratio = (load - load_now) / (load_now - self%load_old)
        n_x = size(self%u)
        if (ratio < 0.0_wp) then
            outcome = reversed
            if (ratio >= -2.0_wp) unknowns(1:n_x) = self%u + ratio * (self%u - self%u_old)
            return
        end if
        if (.not. (ratio > 0.0_wp .and. ratio <= 2.0_wp)) return
        outcome = predicted_state
        if (self%have_older .and. quadratic) then
            if ((self%load_old - self%load_older) * (load_now - self%load_old) > 0.0_wp) then
                ! Lagrange weights of the three states at the load of the step.
                w_older = (load - self%load_old) * (load - load_now) &
                    / ((self%load_older - self%load_old) * (self%load_older - load_now))
                w_old = (load - self%load_older) * (load - load_now) &
                    / ((self%load_old - self%load_older) * (self%load_old - load_now))
                w_now = (load - self%load_older) * (load - self%load_old) &
                    / ((load_now - self%load_older) * (load_now - self%load_old))
                unknowns(1:n_x) = w_older * self%u_older + w_old * self%u_old + w_now * self%u
                where (self%mode /= mode_stick) unknowns(n_x + 1:) = w_older * self%flow_older &
                    + w_old * self%flow_old + w_now * self%flow
                return
            end if
        end if
        unknowns(1:n_x) = self%u + ratio * (self%u - self%u_old)
        where (self%mode /= mode_stick) unknowns(n_x + 1:) = self%flow &
            + ratio * (self%flow - self%flow_old)
    end subroutine predict

    !> Start modes of a step from its predicted `unknowns`: each stick passage that
    !> fails the stick test there (and is not at its minimum length) slips, unless it
    !> was already at its limit (within the dead band) in the `accepted` state, with
    !> load factors `accepted_factors`. `changed`: some did.
    !> A stick passage at its limit is often held there by equilibrium with slipping
    !> neighbours (the heads of inputs/knit3d.nml by the sinkers: the two tensions are
    !> equal at the node pair); its stick and slip are then both admissible, and slip
    !> can close a neutral mode (singular Jacobian). Such passages are left to the
    !> rounds, which slip them only when a solved state violates the stick test, as
    !> they would without a prediction (docs/decisions.md, "Start modes: passages at
    !> their limit left to the rounds").
    !> `accepted_limits`: the stick passages' at_limit flags at the accepted state, kept
    !> from the last round of the step that reached it (update_active_set, the same test
    !> of the same state); without them the test is done here.
    subroutine predict_modes(problem, accepted, accepted_factors, unknowns, mode, changed, &
            error, accepted_limits)
        type(friction_problem_type), intent(inout) :: problem
        real(wp), intent(in) :: accepted(:), accepted_factors(:), unknowns(:)
        integer, intent(inout) :: mode(:)
        logical, intent(out) :: changed
        type(error_type), allocatable, intent(out) :: error
        logical, intent(in), optional :: accepted_limits(:)
        integer :: p, direction
        real(wp) :: floor, measure
        real(wp), allocatable :: trial_factors(:)
        logical, allocatable :: at_limit(:), started(:), blocked_forward(:), &
            blocked_backward(:), predicted(:)

        changed = .false.
        if (present(accepted_limits)) then
            at_limit = accepted_limits
        else
            allocate(at_limit(size(mode)), source=.false.)
            trial_factors = problem%factors
            problem%factors = accepted_factors
            call problem%update_state(accepted, error)
            problem%factors = trial_factors
            if (allocated(error)) return
            floor = node_level_floor * problem%get_force_level()
            do p = 1, size(mode)
                if (mode(p) /= mode_stick) cycle
                call get_slip_tendency(problem, p, floor, .false., .false., direction, &
                    measure, at_limit(p))
            end do
        end if
        call problem%update_state(unknowns, error)
        if (allocated(error)) return
        floor = node_level_floor * problem%get_force_level()
        associate(passages => problem%scene%passages)
            allocate(started(size(mode)), predicted(size(mode)), source=.false.)
            allocate(blocked_forward(size(mode)), blocked_backward(size(mode)))
            do p = 1, size(mode)
                blocked_forward(p) = at_limit(p) &
                    .or. is_at_min_length(problem, passages%element_before(p))
                blocked_backward(p) = at_limit(p) &
                    .or. is_at_min_length(problem, passages%element_after(p))
                if (mode(p) /= mode_stick .or. at_limit(p)) cycle
                call get_slip_tendency(problem, p, floor, blocked_forward(p), &
                    blocked_backward(p), direction, measure)
                if (direction == mode_stick) cycle
                mode(p) = direction
                started(p) = .true.
                changed = .true.
            end do
            ! Their fronts along the yarns, as in the rounds (update_active_set).
            if (changed) then
                call propagate_slips(problem, started, &
                    problem%scene%solver%friction_tolerance, blocked_forward, &
                    blocked_backward, mode, predicted)
            end if
        end associate
    end subroutine predict_modes
end module yarnfort_contact_stepper_predictor
