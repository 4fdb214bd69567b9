! SPDX-License-Identifier: MIT
!> Slip jumps: a load step whose stick/slip rounds settle at no step size down to
!> min_step is reached through viscous slip steps, then solved by the exact law.
module yarnfort_contact_stepper_jump
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error, prefix_error
    use yarnfort_text, only: format_short
    use yarnfort_solver_newton, only: newton_stats_type
    use yarnfort_contact_friction_problem, only: friction_problem_type, mode_stick, &
        node_level_floor
    use yarnfort_contact_stepper_base, only: friction_stepper_base_type, start_trial
    use yarnfort_contact_stepper_monolithic, only: try_monolithic
    implicit none
    private

    public :: try_slip_jump

    !> The slip-instability jump (try_slip_jump): viscosity of its first viscous step
    !> (units of friction_problem's stick_scale, the scene's largest force per
    !> length_scale), the most it may grow to after failed ones, and the most viscous
    !> steps. A viscosity of the order of the stiffness settles such a step at once
    !> (docs/decisions.md, "Slip instabilities: a jump at `min_step`").
    real(wp), parameter :: jump_viscosity = 1.0_wp, max_jump_viscosity = 1.0e6_wp
    integer, parameter :: max_jump_steps = 100

contains

    !> Jump to the load `factors` after a slip instability: the last try failed in the
    !> stick/slip rounds (chatter, or no settling) at the smallest step (`attempted`
    !> is false otherwise, and nothing is done). There the rounds find no consistent
    !> set: mirror pairs of passages flip for ever (same entry).
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
    subroutine try_slip_jump(self, factors, stats, iterations, attempted, error)
        class(friction_stepper_base_type), intent(inout) :: self
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
    end subroutine try_slip_jump

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
end module yarnfort_contact_stepper_jump
