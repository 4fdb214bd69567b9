! SPDX-License-Identifier: MIT
!> A force-controlled y period of a periodic cell (&fabric lateral_control 'force' or
!> 'ratio'): around every load step of another stepper, an outer iteration finds the
!> strain e22 (the factor of the scene's lateral channel) at which the membrane force
!> n22 is the one held: `lateral_force`, or `force_ratio` * n11.
!>
!> Each trial e22 is a full step of the inner stepper from the accepted state, accepted
!> to measure n22 and rolled back through its restart snapshot unless it holds the force
!> (so friction sees one step from the accepted state to the final e22, as with a
!> prescribed strain). The root is found by the secant rule, kept inside a bracket once
!> one is known (Illinois); e22 stays in [-0.9, 100] like `lateral_strain`. No e22 gives
!> the force where the cell collapses laterally: a string network has no resistance to
!> lateral compaction, so below the tension its yarns carry along y at the smallest
!> strain, n22 cannot be held; the step then fails and says so.
module yarnfort_solver_lateral_control
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: format_real, format_integer
    use yarnfort_solver_newton, only: newton_stats_type
    use yarnfort_solver_restart, only: restart_type
    use yarnfort_solver_stepper, only: load_stepper_type, step_state_type
    use yarnfort_output_membrane, only: get_membrane
    implicit none
    private

    public :: lateral_stepper_type, new_lateral_stepper

    !> The held force is reached to this many times the Newton residual_tolerance, relative
    !> to the larger of the held force and the membrane forces present: the nodal forces
    !> n22 sums are themselves only that accurate.
    real(wp), parameter :: tolerance_factor = 100.0_wp
    !> Most trial steps per load step, and the first trial change of e22 (when the
    !> previous step left no slope).
    integer, parameter :: max_trials = 40
    real(wp), parameter :: first_change = 1.0e-3_wp
    !> The range of e22 (that of lateral_strain).
    real(wp), parameter :: smallest_strain = -0.9_wp, largest_strain = 100.0_wp

    type, extends(load_stepper_type) :: lateral_stepper_type
        class(load_stepper_type), pointer :: inner => null()
        !> dn22/de22 of the last step's secant (0: none yet).
        real(wp) :: slope = 0.0_wp
        type(restart_type), private :: snapshot
        type(step_state_type), private :: state
    contains
        procedure :: try_step
        procedure :: accept
        procedure :: get_state
        procedure :: save_state
        procedure :: restore_state
    end type lateral_stepper_type

contains

    !> Wrap `inner` (which must outlive self) for the scene's lateral channel.
    subroutine new_lateral_stepper(self, inner)
        type(lateral_stepper_type), intent(out) :: self
        class(load_stepper_type), target, intent(in) :: inner

        self%inner => inner
        self%scene => inner%scene
    end subroutine new_lateral_stepper

    subroutine try_step(self, factors, stats, iterations, error)
        class(lateral_stepper_type), intent(inout) :: self
        real(wp), intent(in) :: factors(:)
        type(newton_stats_type), intent(out) :: stats
        integer, intent(out) :: iterations
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: trial(:)
        real(wp) :: e(0:1), g(0:1), low, high, g_low, g_high, e_new, scale, tolerance
        real(wp) :: held, n11_now, n22_now
        integer :: lateral, n, side
        logical :: bracketed, have_low, have_high
        character(len=:), allocatable :: history

        iterations = 0
        lateral = self%scene%lateral_channel
        tolerance = tolerance_factor * self%scene%solver%residual_tolerance
        call self%inner%save_state(self%snapshot)
        trial = factors
        history = ''
        have_low = .false.
        have_high = .false.
        side = 0
        e(1) = self%inner%factors(lateral)
        do n = 1, max_trials
            call evaluate(e(1), g(1), error)
            if (allocated(error)) then
                ! A trial the inner stepper cannot solve: back off half way to the last
                ! e22 it could (or to the accepted one).
                if (n == 1 .or. n == max_trials) return
                deallocate(error)
                e(1) = 0.5_wp * (e(0) + e(1))
                cycle
            end if
            if (abs(g(1)) <= tolerance * scale) then
                ! n22 = 0: every string across an x-parallel cut is slack, so the y period
                ! may shrink on at no force: no one state (a mechanism), no curve.
                if (abs(held) > tolerance * scale) return
                call restore(error)
                if (allocated(error)) return
                call fatal_error(error, "&fabric lateral_control = '" &
                    // trim(self%scene%lateral_control) // "': n22 is held at 0 (e22 = " &
                    // format_real(e(1)) // ', n11 = ' // format_real(n11_now) // ' N/m). ' &
                    // mechanism())
                return
            end if
            call restore(error)
            if (allocated(error)) return
            ! Keep the bracket: g < 0 at `low`, g > 0 at `high`.
            if (g(1) < 0.0_wp) then
                if (have_low .and. side == -1 .and. have_high) g_high = 0.5_wp * g_high
                low = e(1)
                g_low = g(1)
                have_low = .true.
                side = -1
            else
                if (have_high .and. side == 1 .and. have_low) g_low = 0.5_wp * g_low
                high = e(1)
                g_high = g(1)
                have_high = .true.
                side = 1
            end if
            bracketed = have_low .and. have_high
            if (bracketed) then
                ! Illinois: regula falsi with the stale end's value halved.
                e_new = (low * g_high - high * g_low) / (g_high - g_low)
            else if (n > 1 .and. e(1) /= e(0) .and. g(1) /= g(0)) then
                e_new = e(1) - g(1) * (e(1) - e(0)) / (g(1) - g(0))
                if ((g(1) - g(0)) / (e(1) - e(0)) > 0.0_wp) self%slope = (g(1) - g(0)) &
                    / (e(1) - e(0))
            else if (self%slope > 0.0_wp) then
                e_new = e(1) - g(1) / self%slope
            else
                e_new = e(1) - sign(first_change, g(1))
            end if
            ! n22 grows with e22 (a stretched y period pulls harder): a secant pointing
            ! the other way, or out of range, is replaced by a step of the right sign.
            if (.not. bracketed .and. (e_new - e(1)) * g(1) > 0.0_wp) &
                e_new = e(1) - sign(max(abs(e_new - e(1)), first_change), g(1))
            if (e_new <= smallest_strain) e_new = 0.5_wp * (e(1) + smallest_strain)
            if (e_new >= largest_strain) e_new = 0.5_wp * (e(1) + largest_strain)
            if (.not. bracketed .and. n > 2 .and. g(1) > 0.0_wp .and. &
                    e(1) - smallest_strain < 1.0e-3_wp) exit
            if (e_new == e(1)) exit
            e(0) = e(1)
            g(0) = g(1)
            e(1) = e_new
        end do
        call fatal_error(error, "&fabric lateral_control = '" &
            // trim(self%scene%lateral_control) // "': no lateral strain e22 holds n22 = " &
            // format_real(held) // ' N/m after ' // format_integer(n) // ' trials' &
            // history // '. ' // mechanism())
    contains

        !> Step the inner stepper to e22 = strain; g = n22 - the force held.
        subroutine evaluate(strain, g, error)
            real(wp), intent(in) :: strain
            real(wp), intent(out) :: g
            type(error_type), allocatable, intent(out) :: error
            integer :: used
            real(wp) :: values(6)

            trial(lateral) = strain
            call self%inner%try_step(trial, stats, used, error)
            iterations = iterations + used
            if (allocated(error)) return
            call self%inner%accept()
            call self%inner%get_state(self%state, error)
            if (allocated(error)) then
                call restore_quietly()
                return
            end if
            values = get_membrane(self%scene, self%state)
            n11_now = values(4)
            n22_now = values(5)
            if (self%scene%lateral_control == 'ratio') then
                held = self%scene%force_ratio * n11_now
            else
                held = self%scene%lateral_force
            end if
            g = n22_now - held
            scale = max(abs(held), abs(n11_now), abs(n22_now), tiny(1.0_wp))
            if (len(history) < 160) history = history // '; e22 = ' // format_real(strain) &
                // ': n22 = ' // format_real(n22_now)
        end subroutine evaluate

        subroutine restore(error)
            type(error_type), allocatable, intent(out) :: error
            call self%inner%restore_state(self%snapshot, error)
        end subroutine restore

        subroutine restore_quietly()
            type(error_type), allocatable :: ignored
            call self%inner%restore_state(self%snapshot, ignored)
        end subroutine restore_quietly

        function mechanism() result(text)
            character(len=:), allocatable :: text
            text = 'Lateral collapse: a string network has no resistance to lateral ' &
                // 'compaction (nothing models yarns jamming against each other); once the ' &
                // 'yarns across the cell go slack, n22 is 0 whatever e22, and the cell ' &
                // 'shrinks along y without limit. Hold a positive lateral force, or prescribe ' &
                // 'lateral_strain'
        end function mechanism
    end subroutine try_step

    !> The inner stepper accepted the trial that holds the force in try_step.
    subroutine accept(self)
        class(lateral_stepper_type), intent(inout) :: self
    end subroutine accept

    subroutine get_state(self, state, error)
        class(lateral_stepper_type), intent(inout) :: self
        type(step_state_type), intent(inout) :: state
        type(error_type), allocatable, intent(out) :: error
        call self%inner%get_state(state, error)
    end subroutine get_state

    subroutine save_state(self, snapshot)
        class(lateral_stepper_type), intent(in) :: self
        type(restart_type), intent(inout) :: snapshot
        call self%inner%save_state(snapshot)
    end subroutine save_state

    subroutine restore_state(self, snapshot, error)
        class(lateral_stepper_type), intent(inout) :: self
        type(restart_type), intent(in) :: snapshot
        type(error_type), allocatable, intent(out) :: error
        call self%inner%restore_state(snapshot, error)
    end subroutine restore_state

end module yarnfort_solver_lateral_control
