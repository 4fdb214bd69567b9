! SPDX-License-Identifier: MIT
!> The friction stepper's state (the accepted and trial states, the predictor's
!> history, the step trace), shared by its schemes (yarnfort_contact_friction_stepper).
module yarnfort_contact_stepper_base
    use yarnfort_kinds, only: wp
    use yarnfort_solver_newton, only: newton_solver_type
    use yarnfort_solver_elastic_problem, only: elastic_problem_type
    use yarnfort_solver_stepper, only: load_stepper_type
    use yarnfort_contact_friction_problem, only: friction_problem_type
    use yarnfort_contact_stepper_trace, only: step_trace_type
    implicit none
    private

    public :: friction_stepper_base_type, start_trial, chord_steps

    !> Chord steps after the first Newton step of every friction solve
    !> (solve_options_type%chord_steps): they cost no factorisation and settle most
    !> steps sooner (docs/decisions.md, "Friction steps: chord steps in every solve").
    integer, parameter :: chord_steps = 3

    !> The data of friction_stepper_type; its bindings are the schemes'.
    type, abstract, extends(load_stepper_type) :: friction_stepper_base_type
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
        !> active set held over the last two steps (`have_older`); `set_repeated`: it held
        !> over the last one.
        real(wp), allocatable :: u_older(:), flow_older(:)
        real(wp) :: load_older = 0.0_wp
        logical :: have_older = .false., set_repeated = .false.
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
    end type friction_stepper_base_type

contains

    !> A new try from the accepted state to the load `factors`.
    subroutine start_trial(self, factors)
        class(friction_stepper_base_type), intent(inout) :: self
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
end module yarnfort_contact_stepper_base
