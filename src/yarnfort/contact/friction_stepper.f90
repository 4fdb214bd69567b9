! SPDX-License-Identifier: MIT
!> Load steps with sliding at contact nodes, by either scheme:
!> - monolithic: positions and flows solved together (friction_problem_type) for a
!>   stick/slip active set, which is updated like a return mapping until it settles;
!> - staggered (the paper's two-step method, Fig. 4): an elastic solve with reference
!>   lengths frozen, then a sliding solve with positions frozen, repeated until the
!>   equilibrium residual is small and the active set no longer changes; a step that
!>   the first round does not solve is finished by monolithic solves from the
!>   alternation's state (try_staggered, finish_monolithic).
!> Active-set rules, per passage, after each solve:
!>   stick -> slip forward  if T_after  > T_crit(T_before, alpha) (beyond tolerance);
!>   stick -> slip backward if T_before > T_crit(T_after, alpha);
!>   slip -> stick if the flow increment of the step has the wrong sign.
!> A step starts from the predicted state (secant, or the parabola through three states of
!> one active set; reversed secant across a turn) with the stick passages that it takes
!> across their limit slipping (predict_modes), or all-stick when it is the first load
!> step from the initial state; a guessed start set whose first Newton step raises the
!> residual gives way at once to the last step's set. Each round after the first is a fast
!> Newton solve (full steps only), and one that fails is retried with fewer new slips.
!> When the step's first set fails with no new slip, its passages whose flows the first
!> Newton step sends back stick and the set is solved again (stop_flowing_back). Every
!> solve starts with chord steps (solve_options_type%chord_steps), in both schemes.
!> A monolithic round's set may be judged and changed before it is solved, at the
!> chord path's iterate (provisional rounds, max_provisional_rounds); in any round but
!> the step's first, an iterate that does not contract is judged for its stops only.
!> A passage whose element would become shorter than min_length_ratio times its initial
!> reference length locks at that length (stick), and may not slip that way again while
!> the element keeps that length, in this step and the next ones. A passage that flips
!> more than max_flips times in one step is held in stick for the rest of the step
!> (chatter damping); the step fails if a held passage ends beyond its limit
!> (check_damped). A step whose rounds fail that way at every step size down to
!> min_step is a slip instability: the continuation then asks for a jump (try_jump).
module yarnfort_contact_friction_stepper
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error, prefix_error
    use yarnfort_text, only: format_short
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_factory, only: new_linear_solver, default_linear_solver_name, &
        chosen_lu_name
    use yarnfort_linalg_composite_condensed, only: condensed_solver_type
    use yarnfort_linalg_composite_bordered, only: bordered_solver_type
    use yarnfort_solver_newton, only: newton_solver_type, new_newton_solver, newton_stats_type, &
        solve_options_type
    use yarnfort_solver_elastic_problem, only: elastic_problem_type, new_elastic_problem
    use yarnfort_solver_stepper, only: load_stepper_type, step_state_type, start_stepper, &
        accept_trial, save_common, restore_common
    use yarnfort_solver_state, only: fill_step_state
    use yarnfort_solver_interrupt, only: interrupt_requested
    use yarnfort_solver_restart, only: restart_type, stepper_friction
    use yarnfort_contact_friction_problem, only: friction_problem_type, new_friction_problem, &
        mode_stick, mode_forward, mode_backward, locked_both, node_level_floor
    implicit none
    private

    public :: friction_stepper_type, new_friction_stepper, step_trace_type

    !> Where a load step's work goes (benchmarks/steps_trace): summed over every try
    !> since the last accepted step (cut tries included).
    type :: step_trace_type
        !> Tries of the step (1 + cuts), active-set rounds (monolithic solves, or the
        !> staggered scheme's alternations), Newton iterations, residual and Jacobian
        !> evaluations, solves that failed.
        integer :: tries = 0, rounds = 0, iterations = 0, residual_evaluations = 0
        integer :: jacobian_evaluations = 0, failed_solves = 0
        !> Mode changes by the rounds: stick -> slip, slip -> stick (a flow increment of
        !> the wrong sign, a lock at the minimum length, chatter damping).
        integer :: to_slip = 0, to_stick = 0
        !> Scaled residual of the first solve's initial guess (the predictor's quality).
        real(wp) :: start_residual = -1.0_wp
        !> Passages whose mode at the end differs from that at the start of the step.
        integer :: mode_changes = 0
    end type step_trace_type

    !> Bounds of the staggered scheme's Aitken relaxation factor.
    real(wp), parameter :: min_relaxation = 0.1_wp, max_relaxation = 100.0_wp
    !> Flips of one passage's mode in a step before it is held in stick.
    integer, parameter :: max_flips = 6
    !> The stick test's dead band, in units of the uncertainty of the passage's
    !> tensions at convergence (residual_tolerance times their level plus rounding).
    real(wp), parameter :: dead_band_factor = 10.0_wp

    !> Chord steps after the first Newton step of every friction solve
    !> (solve_options_type%chord_steps). Measured (benchmarks/steps_results.md, section
    !> 8), Newton iterations (factorisations) per step, without -> in the first solve of
    !> a step -> in every solve: inputs/knit_clamped.nml 4.42 -> 3.65 -> 3.27, woven
    !> 2,200 aligned 1.68 -> 1.18 -> 1.13, 10,120 skewed 3.42 -> 2.48 -> 2.00, no step
    !> cut in any of those runs. (Before stop_flowing_back, chord steps in every solve
    !> made the planar 4 x 2 periodic knit at max_step 0.05 cut a step.) The staggered
    !> scheme's elastic and sliding solves take them too: woven 840 / 2,200 / 10,120
    !> aligned 3.30 / 4.43 / 6.72 -> 2.05 / 2.95 / 4.50 Newton iterations per step,
    !> skewed 5.03 / 5.88 / 8.42 -> 3.32 / 4.10 / 5.88 (benchmarks/steps_trace), the
    !> examples' curves with scheme = 'staggered' within 1.2e-10 of their largest force.
    integer, parameter :: chord_steps = 3

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

    !> The slip-instability jump (try_jump): viscosity of its first viscous step (units
    !> of friction_problem's stick_scale, the scene's largest force per length_scale),
    !> the most it may grow to after failed ones, and the most viscous steps. Measured
    !> from the restart before the failing release step of the 32 x 32 free-sided
    !> clamped knit (benchmarks/steps_results.md, section 24), with the viscosity in
    !> the rounds of every step (an experiment): at 1 that step settled at once (2
    !> Newton iterations); at 1e-3 it did, and a later one failed; 1e-6 changed nothing.
    real(wp), parameter :: jump_viscosity = 1.0_wp, max_jump_viscosity = 1.0e6_wp
    integer, parameter :: max_jump_steps = 100

    !> Outcomes of the predictor (predict).
    integer, parameter :: predicted_state = 1, reversed = -1

    !> Round-off of a reference length locked at its minimum, relative to its initial
    !> length (the lock sets L0 = initial length - flow to the minimum).
    real(wp), parameter :: length_round_off = 64 * epsilon(1.0_wp)

    type, extends(load_stepper_type) :: friction_stepper_type
        logical :: staggered = .false.
        type(friction_problem_type), pointer :: full => null(), sliding => null()
        type(elastic_problem_type), pointer :: elastic => null()
        type(newton_solver_type) :: newton_full, newton_elastic, newton_sliding
        !> Accepted state besides u and factors: flows, active set.
        real(wp), allocatable :: flow(:)
        integer, allocatable :: mode(:)
        !> Trial state of the last successful try_step (with u_trial, factors_trial).
        real(wp), allocatable :: flow_trial(:)
        integer, allocatable :: mode_trial(:)
        !> The accepted state before the current one, for a secant predictor.
        real(wp), allocatable :: u_old(:), flow_old(:)
        real(wp) :: load_old = 0.0_wp
        logical :: have_old = .false.
        !> The accepted state before u_old, for a quadratic predictor: valid when the
        !> active set held over the last two steps (`have_older`); `held`: it held over
        !> the last one.
        real(wp), allocatable :: u_older(:), flow_older(:)
        real(wp) :: load_older = 0.0_wp
        logical :: have_older = .false., held = .false.
        !> The accepted state is the initial one (no load step accepted since).
        logical :: from_initial = .false.
        !> Passages held in stick by chatter damping in the last step.
        integer :: n_damped = 0
        !> The last try failed in the stick/slip rounds (chatter or no settling), not in
        !> a Newton solve: what try_jump starts from.
        logical :: unsettled = .false.
        !> The accepted state was reached by a jump.
        logical :: jumped = .false.
        !> The viscous steps of the jump that reached the last successful trial (0: it
        !> was not reached by a jump).
        integer :: jump_steps_trial = 0
        !> The stick test's at_limit flag (get_slip_tendency) of each stick passage at
        !> the accepted state (`have_limits`), from the last round of the step that
        !> reached it, and of the last successful try_step (`limits_trial`): the next
        !> step's predict_modes needs them and would test the same state again.
        logical, allocatable :: at_limit(:), at_limit_trial(:)
        logical :: have_limits = .false., limits_trial = .false.
        !> The current step's trace (since the last accept) and the last accepted one's.
        type(step_trace_type) :: trace, last_trace
    contains
        procedure :: try_step
        procedure :: try_jump
        procedure :: accept
        procedure :: get_state
        procedure :: save_state
        procedure :: restore_state
        final :: finalize
    end type friction_stepper_type

contains

    !> Set up the chosen scheme; `linear_name` is the linear solver for the elastic
    !> solves. The sliding systems are unsymmetric: when `linear_name` is a Cholesky
    !> solver, the flows-only one uses the measured default for unsymmetric systems and
    !> the monolithic one KLU or UMFPACK, chosen per reduced pattern (chosen_lu_name),
    !> else both use `linear_name`. The monolithic one first eliminates its stick flows
    !> (yarnfort_linalg_condensed).
    subroutine new_friction_stepper(self, scene, linear_name, error)
        type(friction_stepper_type), intent(out) :: self
        type(scene_type), target, intent(in) :: scene
        character(len=*), intent(in) :: linear_name
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: linear
        character(len=:), allocatable :: general_name, full_name
        integer :: n_p

        call start_stepper(self, scene)
        self%staggered = trim(scene%solver%scheme) == 'staggered'
        n_p = scene%passages%size()
        ! The flows-only system of the staggered sliding step has order n_p, the
        ! monolithic one (also the staggered step's finish) n_unknowns + n_p.
        general_name = linear_name
        full_name = linear_name
        if (linear_name == 'cholmod' .or. linear_name == 'cholmod+klu') then
            general_name = default_linear_solver_name(int(n_p, 8), .false.)
            full_name = chosen_lu_name
        end if
        if (self%staggered) then
            allocate(self%elastic, self%sliding)
            call new_elastic_problem(self%elastic, scene)
            if (scene%dofs%n_unknowns > 0) then
                call new_linear_solver(linear, linear_name, error)
                if (allocated(error)) return
                call new_newton_solver(self%newton_elastic, self%elastic, linear, scene%solver, &
                    error)
                if (allocated(error)) return
            end if
            call new_friction_problem(self%sliding, scene, positions_frozen=.true.)
            call new_linear_solver(linear, general_name, error, unsymmetric=.true.)
            if (allocated(error)) return
            call new_newton_solver(self%newton_sliding, self%sliding, linear, scene%solver, error)
            if (allocated(error)) return
        end if
        ! The monolithic problem: the whole solve, or the staggered scheme's finish of a
        ! step (finish_monolithic), which takes full Newton steps only.
        allocate(self%full)
        call new_friction_problem(self%full, scene, positions_frozen=.false.)
        block
            type(condensed_solver_type), allocatable :: condensed
            type(bordered_solver_type), allocatable :: bordered
            ! Stick flows eliminated before factorising (yarnfort_linalg_condensed); with
            ! the Cholesky default, the elastic block of the rest by `linear_name` and a
            ! few slipping flows as its border (yarnfort_linalg_bordered).
            allocate(condensed)
            if (full_name == chosen_lu_name) then
                allocate(bordered)
                bordered%n_leading = scene%dofs%n_unknowns
                call new_linear_solver(bordered%leading, linear_name, error)
                if (allocated(error)) return
                call new_linear_solver(bordered%general, full_name, error)
                if (allocated(error)) return
                call move_alloc(bordered, condensed%inner)
            else
                call new_linear_solver(condensed%inner, full_name, error)
                if (allocated(error)) return
            end if
            condensed%first_candidate = scene%dofs%n_unknowns + 1
            call move_alloc(condensed, linear)
        end block
        call new_newton_solver(self%newton_full, self%full, linear, scene%solver, error)
        if (allocated(error)) return
        allocate(self%flow(n_p), source=0.0_wp)
        allocate(self%mode(n_p), source=mode_stick)
        self%flow_trial = self%flow
        self%mode_trial = self%mode
        ! Written to restart files whether valid or not.
        self%u_older = self%u
        self%flow_older = self%flow
    end subroutine new_friction_stepper

    subroutine try_step(self, factors, stats, iterations, error)
        class(friction_stepper_type), intent(inout) :: self
        real(wp), intent(in) :: factors(:)
        type(newton_stats_type), intent(out) :: stats
        integer, intent(out) :: iterations
        type(error_type), allocatable, intent(out) :: error

        call start_trial(self, factors)
        if (self%staggered) then
            call try_staggered(self, stats, iterations, error)
        else
            call try_monolithic(self, stats, iterations, error)
        end if
    end subroutine try_step

    !> A new try from the accepted state to the load `factors`.
    subroutine start_trial(self, factors)
        type(friction_stepper_type), intent(inout) :: self
        real(wp), intent(in) :: factors(:)

        self%trace%tries = self%trace%tries + 1
        self%factors_trial = factors
        self%u_trial = self%u
        self%flow_trial = self%flow
        self%mode_trial = self%mode
        self%n_damped = 0
        self%limits_trial = .false.
        self%unsettled = .false.
        self%jump_steps_trial = 0
    end subroutine start_trial

    !> Jump to the load `factors` after a slip instability: the last try failed in the
    !> stick/slip rounds (chatter, or no settling) at the smallest step (`attempted`
    !> is false otherwise, and nothing is done). There the rounds find no consistent
    !> set: measured on the 32 x 32 free-sided clamped knit (benchmarks/
    !> steps_results.md, sections 23 and 24), mirror pairs of passages flip for ever
    !> (slipping, their flows go back; stuck, they exceed their limit, by an amount
    !> proportional to the step), the semismooth mode's line search stalls, and
    !> changing one passage per round (least index first) does not settle either.
    !> From the accepted state, viscous slip steps at the load `factors`
    !> (friction_problem's viscosity: implicit Euler steps of a viscoplastic law, whose
    !> stick/slip problem is well posed) relax the net: each starts from the last one's
    !> state, the viscosity halves after each solved step and grows fourfold after a
    !> failed one, until the viscous overstress of every slipping passage is within the
    !> solve's residual_tolerance of its own tensions. The rounds of the exact law then
    !> solve the load from that state; their result, checked as any step's, is the
    !> trial. The path in between is not quasi-static (the real net jumps with inertia
    !> and damping this model does not have): the state reached is an equilibrium of
    !> the exact law, one of possibly several after such a jump.
    subroutine try_jump(self, factors, stats, iterations, attempted, error)
        class(friction_stepper_type), intent(inout) :: self
        real(wp), intent(in) :: factors(:)
        type(newton_stats_type), intent(out) :: stats
        integer, intent(out) :: iterations
        logical, intent(out) :: attempted
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: u_accepted(:), flow_accepted(:), factors_accepted(:)
        integer, allocatable :: mode_accepted(:)
        logical :: have_old, from_initial, have_limits
        real(wp) :: viscosity, overstress
        integer :: k, step_iterations, solved_steps
        type(error_type), allocatable :: step_error
        character(len=200) :: buffer

        iterations = 0
        attempted = self%unsettled .and. .not. self%staggered
        if (.not. attempted) return
        u_accepted = self%u
        flow_accepted = self%flow
        mode_accepted = self%mode
        factors_accepted = self%factors
        have_old = self%have_old
        from_initial = self%from_initial
        have_limits = self%have_limits
        ! Every viscous step starts from the last one's state with its slip set (no
        ! extrapolation across the jump).
        self%have_old = .false.
        self%from_initial = .false.
        self%have_limits = .false.
        viscosity = jump_viscosity
        overstress = huge(1.0_wp)
        solved_steps = 0
        do k = 1, max_jump_steps
            self%full%viscosity = viscosity
            call start_trial(self, factors)
            call try_monolithic(self, stats, step_iterations, step_error)
            iterations = iterations + step_iterations
            if (allocated(step_error)) then
                deallocate(step_error)
                viscosity = 4 * viscosity
                if (viscosity > max_jump_viscosity) exit
                cycle
            end if
            solved_steps = solved_steps + 1
            overstress = get_overstress(self%full, self%flow_trial - self%flow)
            self%u = self%u_trial
            self%flow = self%flow_trial
            self%mode = self%mode_trial
            self%factors = factors
            if (overstress <= self%scene%solver%residual_tolerance) exit
            viscosity = viscosity / 2
        end do
        self%full%viscosity = 0.0_wp
        if (overstress <= self%scene%solver%residual_tolerance .and. solved_steps > 0) then
            call start_trial(self, factors)
            call try_monolithic(self, stats, step_iterations, error)
            iterations = iterations + step_iterations
            if (allocated(error)) call prefix_error(error, 'slip instability: the exact ' &
                // 'law did not settle after the viscous relaxation')
        else
            write(buffer, '("slip instability: the viscous relaxation did not come to rest (", &
                &i0, " viscous steps solved, viscosity ", a, ", overstress ", a, ")")') &
                solved_steps, format_short(viscosity), format_short(overstress)
            call fatal_error(error, trim(buffer))
        end if
        if (.not. allocated(error)) self%jump_steps_trial = solved_steps
        self%u = u_accepted
        self%flow = flow_accepted
        self%mode = mode_accepted
        self%factors = factors_accepted
        self%have_old = have_old
        self%from_initial = from_initial
        self%have_limits = have_limits
    end subroutine try_jump

    !> The largest viscous overstress of a slipping passage over its larger tension (the
    !> state held in `problem`: a viscous step's solution), for flow increments
    !> `increment` of the step.
    real(wp) function get_overstress(problem, increment) result(overstress)
        type(friction_problem_type), intent(in) :: problem
        real(wp), intent(in) :: increment(:)
        real(wp) :: t_before, t_after, angle, floor
        integer :: p

        overstress = 0.0_wp
        floor = node_level_floor * problem%get_force_level()
        do p = 1, size(increment)
            if (problem%mode(p) == mode_stick) cycle
            call problem%get_passage_state(p, t_before, t_after, angle)
            overstress = max(overstress, problem%viscosity * problem%stick_scale &
                * abs(increment(p)) / max(t_before, t_after, floor))
        end do
    end function get_overstress

    subroutine try_monolithic(self, stats, iterations, error)
        type(friction_stepper_type), intent(inout) :: self
        type(newton_stats_type), intent(out) :: stats
        integer, intent(out) :: iterations
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: unknowns(:), good_unknowns(:), start(:), direction(:)
        integer, allocatable :: flips(:), good_mode(:), good_flips(:), failed_mode(:)
        logical, allocatable :: locked_forward(:), locked_backward(:)
        integer :: round, n_x, changed, cap, new_slips, outcome, provisional_rounds, pass
        integer :: failed_before, q
        !> Active set of the last Newton step's factors (try_chord, take_newton_step).
        integer, allocatable :: factored_mode(:), passage_index(:)
        logical :: have_good, guessed, full_retry, sign_tried, stopped, solved, moved, chorded
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
                source=.false.)
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
                if (interrupt_requested()) exit     ! Ctrl-C: the step fails, unsettled
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
                full_options = solve_options_type(quick=any(self%mode_trial /= mode_stick) &
                    .and. .not. full_retry, chord_steps=merge(0, chord_steps, self%staggered))
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
                if (round > 1 .and. allocated(factored_mode) .and. .not. (full_retry &
                        .or. problem%semismooth)) then
                    call self%newton_full%try_row_update(unknowns, n_x + pack(passage_index, &
                        self%mode_trial /= factored_mode), stats, solved, step_error)
                    if (allocated(step_error)) solved = .false.
                    carried = stats
                end if
                if (provisional_rounds < max_provisional_rounds .and. .not. (full_retry &
                        .or. problem%semismooth .or. solved)) then
                    ! Each pass is one Newton step: with the solve after them, within
                    ! max_iterations (a solve's limit).
                    do pass = 1, min(provisional_passes, scene%solver%max_iterations - 1)
                        call self%newton_full%try_chord(unknowns, stats, solved, step_error, &
                            full_options)
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
                if (problem%semismooth) then
                    call problem%choose_modes(unknowns(n_x + 1:))
                    self%mode_trial = problem%mode
                end if
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
                call update_active_set(problem, unknowns(n_x + 1:), self%flow, self%mode_trial, &
                    flips, locked_forward, locked_backward, changed, cap, new_slips, &
                    at_limit=self%at_limit_trial)
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
            logical, allocatable :: trial_forward(:), trial_backward(:)
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
            saved_locked = problem%locked
            saved_target = problem%flow_target
            max_new_slips = cap
            if (present(cap_here)) max_new_slips = cap_here
            call update_active_set(problem, flow, self%flow, trial_mode, trial_flips, &
                trial_forward, trial_backward, changed, max_new_slips, &
                trial_new_slips, provisional_band * residual)
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
    !> A step of the staggered scheme from the secant-predicted state: rounds of an
    !> elastic solve and a sliding solve (whose own active set settles first), with
    !> Aitken relaxation of the flows. A round that ends at equilibrium with its active set
    !> unchanged ends the step (every stick-only step does, in one round). Otherwise the
    !> step is finished by monolithic solves (finish_monolithic) after the first round, or,
    !> should a finish fail to solve, after the next round whose active set held. The
    !> alternation alone contracts linearly (by a factor near 1 when contact nodes are
    !> free) and needed hundreds of rounds per step on inputs/belt.nml; the finish
    !> converges quadratically to the same fixed point. Measured with
    !> benchmarks/steps_trace (Newton iterations per step, before -> after): finishing
    !> after round 1 instead of after 3 rounds with the set held, woven net of 840
    !> unknowns 3.87 -> 3.47, of 1e4 9.30 -> 6.95, skewed 1e4 12.47 -> 8.65;
    !> inputs/knit_clamped 12.72 -> 10.47 (there the first finish of a step often fails,
    !> and a finish only once per step left up to 18 plain rounds).
    subroutine try_staggered(self, stats, iterations, error)
        type(friction_stepper_type), intent(inout) :: self
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
            ! stick when the loading turned, as the monolithic scheme does (measured on
            ! the woven net of steps_trace, 840 unknowns: 6.4 -> 3.9 Newton iterations
            ! per step; the all-stick start on reversal 3.47 -> 3.37, 1e4: 6.95 -> 6.83).
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
                    if (sliding%semismooth) then
                        call sliding%choose_modes(self%flow_trial)
                        self%mode_trial = sliding%mode
                    end if
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
    !> left as it was if none solved), and the alternation goes on from it. Going back
    !> to the alternation after every change measured far worse: the positions-frozen
    !> sliding step undid the finish's stick/slip changes each round (inputs/knit_clamped
    !> with the staggered scheme: up to 233 solves in a step, 4 step cuts, 427 steps
    !> instead of 40).
    subroutine finish_monolithic(self, flips, locked_forward, locked_backward, finished, &
            iterations, error)
        type(friction_stepper_type), intent(inout) :: self
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
            locked_backward, changed, max_new_slips, new_slips, residual, at_limit)
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
        integer :: p, new_mode, before, after, n_candidates, k, direction_p
        integer :: unlocked_direction
        real(wp) :: min_before, min_after, increment, floor, measure, unlocked_measure
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
                    if (flows_back(mode(p), increment)) new_mode = mode_stick
                    ! Forward flow shortens the element before the node.
                    if (problem%length0(before) < min_before) then
                        new_mode = mode_stick
                        locked_forward(p) = .true.
                        problem%locked(p) = mode_forward
                        problem%flow_target(p) = flow(p) + (problem%length0(before) &
                            - min_before) / passages%share(before)
                    end if
                case (mode_backward)
                    if (flows_back(mode(p), increment)) new_mode = mode_stick
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
            do k = 1, min(n_candidates, max_new_slips)
                p = maxloc(violation(1:n_candidates), dim=1)
                call set_mode(candidate(p), direction(p))
                violation(p) = -huge(1.0_wp)
                new_slips = new_slips + 1
            end do
        end associate
    contains
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
            flips(passage) = flips(passage) + 1
            changed = changed + 1
            if (flips(passage) > max_flips) then
                mode(passage) = mode_stick
                problem%locked(passage) = locked_both
            end if
        end subroutine set_mode
    end subroutine update_active_set

    !> Start modes of a step from its predicted `unknowns`: each stick passage that
    !> fails the stick test there (and is not at its minimum length) slips, unless it
    !> was already at its limit (within the dead band) in the `accepted` state, with
    !> load factors `accepted_factors`. `changed`: some did.
    !> A stick passage at its limit is often held there by equilibrium with slipping
    !> neighbours (the heads of inputs/knit3d.nml by the sinkers: the two tensions are
    !> equal at the node pair); its stick and slip are then both admissible, and slip
    !> can close a neutral mode (singular Jacobian). Such passages are left to the
    !> rounds, which slip them only when a solved state violates the stick test, as
    !> they would without a prediction. Measured (benchmarks/steps_results.md, section
    !> 5): without this exclusion the predicted start cut steps on the singular set,
    !> and over the knit3d cycle it reached other branches, up to 36 % of the peak force
    !> away from the small-step limit.
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
        logical, allocatable :: at_limit(:)

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
            do p = 1, size(mode)
                if (mode(p) /= mode_stick .or. at_limit(p)) cycle
                call get_slip_tendency(problem, p, floor, &
                    is_at_min_length(problem, passages%element_before(p)), &
                    is_at_min_length(problem, passages%element_after(p)), direction, measure)
                if (direction == mode_stick) cycle
                mode(p) = direction
                changed = .true.
            end do
        end associate
    end subroutine predict_modes

    !> Element e's reference length (in `problem`) is at its minimum, min_length_ratio
    !> times its initial one, within rounding.
    pure logical function is_at_min_length(problem, e)
        type(friction_problem_type), intent(in) :: problem
        integer, intent(in) :: e
        associate(initial => problem%scene%network%length0(e))
            is_at_min_length = problem%length0(e) <= problem%scene%solver%min_length_ratio &
                * initial + length_round_off * initial
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
    !> instead of being accepted. Measured on the planar 4 x 2 periodic knit
    !> (benchmarks/steps_results.md, section 7): accepted, such states (7 passages up
    !> to 3 % beyond their limit) took the runs onto another branch, 0.7 % of the
    !> release force away from the small-step limit.
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

    !> Secant predictor for the monolithic unknowns: extrapolate positions and the flows
    !> of slipping passages along the last accepted increment, scaled by the ratio of
    !> load increments (of the sum of the channels' factors), while the loading keeps its
    !> direction. Where the last three accepted states share one active set and lie in
    !> the same direction of the loading, the parabola through them (in the load) is
    !> extrapolated instead. Measured (benchmarks/steps_results.md, section 6): steady
    !> steps of the clamped knits started at scaled residuals of 6e-4 to 1e-2 and took 3
    !> Newton iterations where 2 would do below about 5e-4; the parabola starts them at
    !> 2e-5 to 1e-3.
    !> When the loading turns, the positions go back along that increment (flows kept:
    !> the step starts in stick). Measured (benchmarks/steps_results.md, section 6): the
    !> turning step of inputs/knit_clamped.nml started at a scaled residual of 0.99 from
    !> the accepted state and took 9 Newton iterations; from the reversed secant 1e-2 and
    !> 4 iterations. The unloading response is stiffer (all stick), but the positions
    !> follow the clamps nearly affinely either way.
    !> `outcome`: predicted_state, else reversed when the loading turned, else 0.
    subroutine predict(self, unknowns, outcome, quadratic)
        type(friction_stepper_type), intent(in) :: self
        real(wp), intent(inout) :: unknowns(:)
        integer, intent(out) :: outcome
        !> The parabola may be used (not by the staggered scheme: its alternation took
        !> 10.53 instead of 10.25 Newton iterations per step on inputs/knit_clamped.nml).
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

    !> Add a Newton solve to a step's trace (the first one's initial residual too).
    subroutine record_solve(trace, stats, failed)
        type(step_trace_type), intent(inout) :: trace
        type(newton_stats_type), intent(in) :: stats
        logical, intent(in) :: failed
        if (trace%rounds == 0 .and. allocated(stats%residual_history)) then
            if (size(stats%residual_history) > 0) &
                trace%start_residual = stats%residual_history(1)
        end if
        trace%rounds = trace%rounds + 1
        trace%iterations = trace%iterations + stats%iterations
        trace%residual_evaluations = trace%residual_evaluations + stats%residual_evaluations
        trace%jacobian_evaluations = trace%jacobian_evaluations + stats%jacobian_evaluations
        if (failed) trace%failed_solves = trace%failed_solves + 1
    end subroutine record_solve

    !> Add one Newton step outside a solve (take_newton_step) to a step's trace.
    pure subroutine record_step(trace)
        type(step_trace_type), intent(inout) :: trace
        trace%iterations = trace%iterations + 1
        trace%residual_evaluations = trace%residual_evaluations + 1
        trace%jacobian_evaluations = trace%jacobian_evaluations + 1
    end subroutine record_step

    !> Add an active-set update from mode `before` to mode `after` to a step's trace.
    pure subroutine record_changes(trace, before, after)
        type(step_trace_type), intent(inout) :: trace
        integer, intent(in) :: before(:), after(:)
        trace%to_slip = trace%to_slip + count(before == mode_stick .and. after /= mode_stick)
        trace%to_stick = trace%to_stick + count(before /= mode_stick .and. after == mode_stick)
    end subroutine record_changes

    subroutine accept(self)
        class(friction_stepper_type), intent(inout) :: self
        self%last_trace = self%trace
        self%last_trace%mode_changes = count(self%mode_trial /= self%mode)
        self%trace = step_trace_type()
        ! The quadratic predictor only along a stretch of one active set: across a change
        ! of the set the path has a kink, and extrapolating it cost iterations (measured
        ! on inputs/knit_clamped.nml, end of the release: 5.12 Newton iterations per step
        ! without this condition, 4.42 with it, 4.75 with the secant alone).
        self%have_older = self%have_old .and. self%held .and. all(self%mode_trial == self%mode)
        self%held = self%have_old .and. all(self%mode_trial == self%mode)
        if (self%have_older) then
            self%u_older = self%u_old
            self%flow_older = self%flow_old
            self%load_older = self%load_old
        end if
        self%from_initial = .not. (self%have_old .or. self%jumped)
        self%have_limits = self%limits_trial
        if (self%have_limits) self%at_limit = self%at_limit_trial
        self%u_old = self%u
        self%flow_old = self%flow
        self%load_old = sum(self%factors)
        self%have_old = .true.
        call accept_trial(self)
        self%flow = self%flow_trial
        self%mode = self%mode_trial
        ! Across a jump the path has no tangent: the next step is predicted from the new
        ! state alone.
        self%jumped = self%jump_steps_trial > 0
        if (self%jumped) then
            self%have_old = .false.
            self%have_older = .false.
            self%held = .false.
        end if
    end subroutine accept

    subroutine get_state(self, state, error)
        class(friction_stepper_type), intent(inout) :: self
        type(step_state_type), intent(inout) :: state
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: length0(:)

        allocate(length0(self%scene%network%n_elements()))
        call self%scene%passages%get_length0(self%scene%network%length0, self%flow, length0)
        call fill_step_state(self%scene, self%u, length0, self%factors, state, error)
        state%n_passages = size(self%mode)
        state%n_slipping = count(self%mode /= mode_stick)
        state%n_held = self%n_damped
        state%jump_steps = 0
        if (self%jumped) state%jump_steps = self%jump_steps_trial
    end subroutine get_state

    !> Everything a step depends on besides the scene: the accepted state (whose flows
    !> give the reference lengths and the locks at the minimum length) and the two before
    !> it for the predictor.
    subroutine save_state(self, snapshot)
        class(friction_stepper_type), intent(in) :: self
        type(restart_type), intent(inout) :: snapshot

        call save_common(self, snapshot, stepper_friction, self%flow)
        snapshot%flow = self%flow
        snapshot%mode = self%mode
        snapshot%have_old = self%have_old
        snapshot%load_old = self%load_old
        if (self%have_old) then
            snapshot%u_old = self%u_old
            snapshot%flow_old = self%flow_old
        else
            snapshot%u_old = self%u
            snapshot%flow_old = self%flow
        end if
        snapshot%have_older = self%have_older
        snapshot%held = self%held
        snapshot%load_older = self%load_older
        snapshot%u_older = self%u_older
        snapshot%flow_older = self%flow_older
    end subroutine save_state

    !> The reference lengths follow from the flows: the snapshot's must be those, bit
    !> for bit (else it was written for another scene).
    subroutine restore_state(self, snapshot, error)
        class(friction_stepper_type), intent(inout) :: self
        type(restart_type), intent(in) :: snapshot
        type(error_type), allocatable, intent(out) :: error

        call restore_common(self, snapshot, stepper_friction, 'the restart file was written ' &
            // 'by a run without sliding passages, this scene has some', error, size(self%flow))
        if (allocated(error)) return
        self%flow = snapshot%flow
        self%mode = snapshot%mode
        self%have_old = snapshot%have_old
        self%load_old = snapshot%load_old
        self%u_old = snapshot%u_old
        self%flow_old = snapshot%flow_old
        self%have_older = snapshot%have_older
        self%held = snapshot%held
        self%load_older = snapshot%load_older
        self%u_older = snapshot%u_older
        self%flow_older = snapshot%flow_older
        ! Restarted from the initial state: its first load step starts all-stick, as in
        ! the run that wrote the file (a 48 x 24 clamped knit's step 1 from the initial
        ! state's slip set took 625 Newton iterations instead of 25).
        self%from_initial = snapshot%step == 0
        ! Only a jump leaves a step after step 0 without a predictor state (accept).
        self%jumped = snapshot%step > 0 .and. .not. snapshot%have_old
        self%have_limits = .false.
        self%flow_trial = self%flow
        self%mode_trial = self%mode
    end subroutine restore_state

    subroutine finalize(self)
        type(friction_stepper_type), intent(inout) :: self
        call self%newton_full%destroy()
        call self%newton_elastic%destroy()
        call self%newton_sliding%destroy()
        if (associated(self%full)) deallocate(self%full)
        if (associated(self%sliding)) deallocate(self%sliding)
        if (associated(self%elastic)) deallocate(self%elastic)
    end subroutine finalize
end module yarnfort_contact_friction_stepper
