! SPDX-License-Identifier: MIT
!> The staggered scheme (the paper's two-step method, Fig. 4): an elastic solve with
!> reference lengths frozen, then a sliding solve with positions frozen, repeated until
!> the equilibrium residual is small and the active set no longer changes; a step that
!> the first round does not solve is finished by monolithic solves from the
!> alternation's state (try_staggered, finish_monolithic).
module yarnfort_contact_stepper_staggered
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_solver_newton, only: newton_stats_type, solve_options_type
    use yarnfort_contact_friction_problem, only: mode_stick
    use yarnfort_contact_stepper_base, only: friction_stepper_base_type, chord_steps
    use yarnfort_contact_stepper_trace, only: record_solve
    use yarnfort_contact_stepper_active_set, only: max_flips, update_active_set, &
        check_damped, not_settled
    use yarnfort_contact_stepper_predictor, only: reversed, predict
    use yarnfort_solver_interrupt, only: interrupt_requested
    implicit none
    private

    public :: try_staggered

    !> Bounds of the staggered scheme's Aitken relaxation factor.
    real(wp), parameter :: min_relaxation = 0.1_wp, max_relaxation = 100.0_wp

contains

    !> A step of the staggered scheme from the secant-predicted state: rounds of an
    !> elastic solve and a sliding solve (whose own active set settles first), with
    !> Aitken relaxation of the flows. A round that ends at equilibrium with its active set
    !> unchanged ends the step (every stick-only step does, in one round). Otherwise the
    !> step is finished by monolithic solves (finish_monolithic) after the first round, or,
    !> should a finish fail to solve, after the next round whose active set held. The
    !> alternation alone contracts linearly (by a factor near 1 when contact nodes are
    !> free) and needed hundreds of rounds per step on inputs/belt.nml; the finish
    !> converges quadratically to the same fixed point (docs/decisions.md, "Staggered
    !> scheme: a monolithic finish after the first round").
    subroutine try_staggered(self, stats, iterations, error)
        class(friction_stepper_base_type), intent(inout) :: self
        type(newton_stats_type), intent(out) :: stats
        integer, intent(out) :: iterations
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: residual(:), level(:), noise(:)
        integer, allocatable :: flips(:), mode_before(:)
        logical, allocatable :: locked_forward(:), locked_backward(:)
        integer :: round, inner, changed, new_slips
        real(wp) :: residual_norm, omega, denominator
        real(wp), allocatable :: flow_in(:), update(:), update_previous(:)
        logical :: relax, may_finish, finished

        associate(scene => self%scene, elastic => self%elastic, sliding => self%sliding)
            elastic%factors = self%factors_trial
            sliding%factors = self%factors_trial
            sliding%flow_target = self%flow
            sliding%locked = 0
            ! Start from the secant-predicted state (positions, slipping flows), and in
            ! stick when the loading turned, as the monolithic scheme does: fewer
            ! iterations (docs/decisions.md, "Staggered scheme: a monolithic finish after
            ! the first round").
            block
                real(wp), allocatable :: unknowns(:)
                integer :: outcome
                unknowns = [self%u, self%flow]
                call predict(self, unknowns, outcome, quadratic=.false.)
                if (outcome == reversed) self%mode_trial = mode_stick
                self%u_trial = unknowns(1:size(self%u))
                self%flow_trial = unknowns(size(self%u) + 1:)
            end block
            allocate(flips(size(self%flow)), source=0)
            allocate(locked_forward(size(self%flow)), locked_backward(size(self%flow)), &
                source=.false.)
            allocate(residual(scene%dofs%n_unknowns))
            iterations = 0
            omega = 1.0_wp
            relax = .false.
            may_finish = scene%dofs%n_unknowns > 0
            do round = 1, scene%solver%max_friction_iterations
                if (interrupt_requested()) exit     ! Ctrl-C: the step fails, unsettled
                ! (1) Elastic step: reference lengths frozen.
                flow_in = self%flow_trial
                call scene%passages%get_length0(scene%network%length0, self%flow_trial, &
                    elastic%length0)
                if (scene%dofs%n_unknowns > 0) then
                    call self%newton_elastic%solve(self%u_trial, stats, error, &
                        solve_options_type(chord_steps=chord_steps))
                    iterations = iterations + stats%iterations
                    call record_solve(self%trace, stats, allocated(error))
                    if (allocated(error)) return
                end if
                ! (2) Sliding step: positions frozen; its own active set settles first.
                sliding%u_frozen = self%u_trial
                mode_before = self%mode_trial
                do inner = 1, scene%solver%max_friction_iterations
                    sliding%mode = self%mode_trial
                    call self%newton_sliding%solve(self%flow_trial, stats, error, &
                        solve_options_type(chord_steps=chord_steps))
                    iterations = iterations + stats%iterations
                    call record_solve(self%trace, stats, allocated(error))
                    if (allocated(error)) return
                    call sliding%update_state(self%flow_trial, error)
                    if (allocated(error)) return
                    call update_active_set(sliding, self%flow_trial, self%flow, &
                        self%mode_trial, flips, locked_forward, locked_backward, changed, &
                        huge(1), new_slips)
                    if (changed == 0) exit
                end do
                if (changed /= 0) then
                    call not_settled(error, scene%solver%max_friction_iterations, flips)
                    return
                end if
                ! (3) Done when the equilibrium holds with the new reference lengths.
                call scene%passages%get_length0(scene%network%length0, self%flow_trial, &
                    elastic%length0)
                call elastic%evaluate_residual(self%u_trial, residual, error)
                if (allocated(error)) return
                allocate(level(size(residual)), noise(size(residual)))
                call elastic%get_row_levels(self%u_trial, level, noise, error)
                if (allocated(error)) return
                level = level + noise / scene%solver%residual_tolerance
                residual_norm = maxval([0.0_wp, abs(residual) / merge(level, 1.0_wp, &
                    level > 0.0_wp)])
                deallocate(level, noise)
                if (residual_norm <= scene%solver%residual_tolerance &
                        .and. all(self%mode_trial == mode_before)) then
                    ! The sliding solve's state is this one (positions u_trial, flows
                    ! flow_trial): its held passages must be within their limit too.
                    call check_damped(sliding, flips, locked_forward, locked_backward, error)
                    if (allocated(error)) return
                    self%n_damped = count(flips > max_flips)
                    return
                end if
                if (may_finish .and. (round == 1 .or. all(self%mode_trial == mode_before))) then
                    call finish_monolithic(self, flips, locked_forward, locked_backward, &
                        finished, iterations, error)
                    if (allocated(error)) return
                    if (finished) then
                        self%n_damped = count(flips > max_flips)
                        return
                    end if
                    relax = .false.
                    omega = 1.0_wp
                    cycle
                end if
                ! (4) Aitken relaxation of the flow update while the active set holds: the
                ! plain alternation contracts by a factor close to 1 when contact nodes
                ! are free (the elastic step moves them along the yarn and undoes most of
                ! the sliding), and Aitken's secant estimate of that factor removes most
                ! of it. Reset to the plain update whenever the active set changes.
                update = self%flow_trial - flow_in
                if (relax .and. all(self%mode_trial == mode_before)) then
                    denominator = sum((update - update_previous)**2)
                    if (denominator > 0.0_wp) omega = -omega &
                        * sum(update_previous * (update - update_previous)) / denominator
                    omega = max(min_relaxation, min(max_relaxation, omega))
                else
                    omega = 1.0_wp
                end if
                relax = all(self%mode_trial == mode_before)
                update_previous = update
                if (omega /= 1.0_wp) then
                    ! Never relax an element below its minimum reference length.
                    call scene%passages%get_length0(scene%network%length0, &
                        flow_in + omega * update, elastic%length0)
                    if (any(elastic%length0 < scene%solver%min_length_ratio &
                            * scene%network%length0)) omega = 1.0_wp
                end if
                self%flow_trial = flow_in + omega * update
            end do
            ! Last, a monolithic finish with every fallback of the Newton solver (the
            ! rounds' finishes take full Newton steps only): where the alternation creeps,
            ! as on a ring sliding along a yarn 1e5 times stiffer than its load (residual
            ! 7e-4 falling by 1e-10 per round), the softened-yarn predictor solves it.
            if (may_finish) then
                call finish_monolithic(self, flips, locked_forward, locked_backward, &
                    finished, iterations, error)
                if (allocated(error)) return
                if (finished) then
                    self%n_damped = count(flips > max_flips)
                    return
                end if
            end if
            call fatal_error(error, 'staggered scheme: elastic and sliding steps did not agree &
                &within max_friction_iterations rounds')
        end associate
    end subroutine try_staggered

    !> The staggered step's monolithic finish (try_staggered): Newton solves of
    !> positions and flows from the alternation's state, starting with its active set,
    !> which is updated after each solve (as by try_monolithic) until it holds.
    !> `finished`: the last solve held the active set (the trial state is the solution).
    !> Otherwise the trial state is the last solution with the updated active set (or
    !> left as it was if none solved), and the alternation goes on from it: the
    !> positions-frozen sliding step would undo the finish's stick/slip changes (same
    !> entry).
    subroutine finish_monolithic(self, flips, locked_forward, locked_backward, finished, &
            iterations, error)
        class(friction_stepper_base_type), intent(inout) :: self
        integer, intent(inout) :: flips(:)
        logical, intent(inout) :: locked_forward(:), locked_backward(:)
        logical, intent(out) :: finished
        integer, intent(inout) :: iterations
        type(error_type), allocatable, intent(out) :: error
        type(newton_stats_type) :: stats
        type(error_type), allocatable :: solve_error
        real(wp), allocatable :: unknowns(:)
        integer :: n_x, changed, new_slips, round

        finished = .false.
        associate(full => self%full, sliding => self%sliding)
            n_x = size(self%u_trial)
            full%factors = self%factors_trial
            full%flow_target = sliding%flow_target
            full%locked = sliding%locked
            do round = 1, self%scene%solver%max_friction_iterations
                full%mode = self%mode_trial
                unknowns = [self%u_trial, self%flow_trial]
                call self%newton_full%solve(unknowns, stats, solve_error)
                iterations = iterations + stats%iterations
                call record_solve(self%trace, stats, allocated(solve_error))
                if (allocated(solve_error)) exit
                call full%update_state(unknowns, error)
                if (allocated(error)) return
                call update_active_set(full, unknowns(n_x + 1:), self%flow, self%mode_trial, &
                    flips, locked_forward, locked_backward, changed, huge(1), new_slips)
                self%u_trial = unknowns(1:n_x)
                self%flow_trial = unknowns(n_x + 1:)
                finished = changed == 0
                if (finished) then
                    call check_damped(full, flips, locked_forward, locked_backward, error)
                    exit
                end if
            end do
            sliding%flow_target = full%flow_target
            sliding%locked = full%locked
        end associate
    end subroutine finish_monolithic
end module yarnfort_contact_stepper_staggered
