! SPDX-License-Identifier: MIT
!> Where a friction load step's work goes: counts the stepper records in each step for
!> benchmarks/steps_trace (no answer depends on them).
module yarnfort_contact_stepper_trace
    use yarnfort_kinds, only: wp
    use yarnfort_solver_newton, only: newton_stats_type
    use yarnfort_contact_friction_problem, only: mode_stick
    implicit none
    private

    public :: step_trace_type, record_solve, record_step, record_changes

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

contains

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
end module yarnfort_contact_stepper_trace
