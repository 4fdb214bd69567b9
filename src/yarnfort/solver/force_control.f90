! SPDX-License-Identifier: MIT
!> A force-controlled period of a periodic cell: the x period (&fabric axial_control
!> 'force': n11 held at p_disp * `axial_force`) or the y period (lateral_control 'force'
!> or 'ratio': n22 held at `lateral_force`, or `force_ratio` * n11). Around every load
!> step of another stepper, an outer iteration finds the strain (e11 or e22, the factor of
!> the scene's axial or lateral channel) at which the membrane force is the one held.
!> With both periods force-controlled, the x stepper wraps the y stepper: every trial e11
!> is a full step at which n22 is held.
!>
!> Each trial strain is a full step of the inner stepper from the accepted state,
!> accepted to measure the force and rolled back through its restart snapshot unless it
!> holds the force (so friction sees one step from the accepted state to the final strain,
!> as with a prescribed strain). The root is found by the secant rule, kept inside a
!> bracket once one is known (Illinois); the strain stays in [-0.9, 100] like `strain`
!> and `lateral_strain`. A step's first guess takes the slope dn/de of the trials nearest
!> the last root; with both periods held, each trial of e11 starts the y period at the
!> e22 its earlier trials of the step found, extrapolated in e11 (docs/decisions.md,
!> "Held forces: the slope at the root and the y period's start"). No strain gives the force where the cell collapses along the axis:
!> a string network carries no compression and has no resistance to compaction, so below
!> the tension its yarns carry along that axis at the smallest strain, the force cannot be
!> held; the step then fails and says so.
module yarnfort_solver_force_control
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: format_real, format_integer
    use yarnfort_solver_newton, only: newton_stats_type
    use yarnfort_solver_restart, only: restart_type
    use yarnfort_solver_stepper, only: load_stepper_type, step_state_type
    use yarnfort_solver_membrane, only: get_membrane
    implicit none
    private

    public :: force_control_stepper_type, new_force_control_stepper

    !> The held force is reached to this many times the Newton residual_tolerance, relative
    !> to the larger of the held force and the membrane forces present: the nodal forces
    !> the membrane force sums are themselves only that accurate.
    real(wp), parameter :: tolerance_factor = 100.0_wp
    !> Most trial steps per load step, and the first trial change of the strain (when the
    !> previous step left no slope).
    integer, parameter :: max_trials = 40
    real(wp), parameter :: first_change = 1.0e-3_wp
    !> The range of the strain (that of strain and lateral_strain).
    real(wp), parameter :: smallest_strain = -0.9_wp, largest_strain = 100.0_wp
    !> Where n11 and n22 are in get_membrane's values.
    integer, parameter :: force_column(2) = [4, 5]
    !> A secant slope is kept only from two trials whose forces differ by more than this
    !> many times the tolerance: nearer, their difference is mostly the forces' error.
    real(wp), parameter :: slope_noise_factor = 1.0e3_wp

    type, extends(load_stepper_type) :: force_control_stepper_type
        class(load_stepper_type), pointer :: inner => null()
        !> The period held: 1 (x: e11, n11, &fabric axial_control) or 2 (y: e22, n22,
        !> lateral_control).
        integer :: axis = 2
        !> dn/de of the last step's secant (0: none yet); in the restart snapshot.
        real(wp) :: slope = 0.0_wp
        !> The y period wrapped by the x one: the strains (`found`) that held the force at
        !> this step's trials so far, against the other period's strain (`other`), the
        !> latest last; emptied by the x stepper at the start of each of its steps.
        integer, private :: n_found = 0
        real(wp), private :: found(2) = 0.0_wp, other(2) = 0.0_wp
        !> The iterations the inner stepper's step-size rule counts for the trial that
        !> held the force (growth_iterations).
        integer, private :: held_trial_iterations = 0
        type(restart_type), private :: snapshot
        type(step_state_type), private :: state
    contains
        procedure :: try_step
        procedure :: accept
        procedure :: growth_iterations
        procedure :: get_state
        procedure :: save_state
        procedure :: restore_state
    end type force_control_stepper_type

contains

    !> Wrap `inner` (which must outlive self) for the period `axis` (1: x, 2: y) of the
    !> scene's axial or lateral channel.
    subroutine new_force_control_stepper(self, inner, axis)
        type(force_control_stepper_type), intent(out) :: self
        class(load_stepper_type), target, intent(in) :: inner
        integer, intent(in) :: axis

        self%inner => inner
        self%scene => inner%scene
        self%axis = axis
        ! The accepted factors (an outer force-control stepper reads its strain here).
        self%factors = inner%factors
    end subroutine new_force_control_stepper

    subroutine try_step(self, factors, stats, iterations, error)
        class(force_control_stepper_type), intent(inout) :: self
        real(wp), intent(in) :: factors(:)
        type(newton_stats_type), intent(out) :: stats
        integer, intent(out) :: iterations
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: trial(:)
        real(wp) :: e(0:1), g(0:1), low, high, g_low, g_high, e_new, scale, tolerance
        real(wp) :: held, n_other, n_now
        integer :: channel, n, side, used
        logical :: bracketed, have_low, have_high
        character(len=:), allocatable :: history
        character(len=3) :: strain_name, force_name, other_name

        iterations = 0
        strain_name = merge('e11', 'e22', self%axis == 1)
        force_name = merge('n11', 'n22', self%axis == 1)
        other_name = merge('n22', 'n11', self%axis == 1)
        if (self%axis == 1) then
            channel = self%scene%axial_channel
            ! The force held along x follows the path: refuse one the net cannot carry
            ! before any trial (n11 = 0 leaves the x period free, n11 < 0 is compression).
            held = factors(self%scene%dofs%gap_channel) * self%scene%axial_force
            if (.not. held > 0.0_wp) then
                call fatal_error(error, "&fabric axial_control = 'force': n11 would be held " &
                    // 'at p_disp * axial_force = ' // format_real(held) // ' N/m (p_disp = ' &
                    // format_real(factors(self%scene%dofs%gap_channel)) // '). ' &
                    // mechanism())
                return
            end if
        else
            channel = self%scene%lateral_channel
        end if
        tolerance = tolerance_factor * self%scene%solver%residual_tolerance
        call self%inner%save_state(self%snapshot)
        trial = factors
        history = ''
        have_low = .false.
        have_high = .false.
        side = 0
        e(1) = self%inner%factors(channel)
        if (self%axis == 1) then
            select type (inner => self%inner)
            type is (force_control_stepper_type)
                inner%n_found = 0
            end select
        else if (self%scene%axial_channel > 0) then
            e(1) = start_from_found(self, e(1), factors(self%scene%axial_channel))
        end if
        do n = 1, max_trials
            call evaluate(e(1), g(1), error)
            if (allocated(error)) then
                ! A trial the inner stepper cannot solve: back off half way to the last
                ! strain it could (or to the accepted one).
                if (n == 1 .or. n == max_trials) return
                deallocate(error)
                e(1) = 0.5_wp * (e(0) + e(1))
                cycle
            end if
            ! The slope for the next step's first guess: the latest secant whose forces
            ! differ beyond their error, so at the root that of the trials nearest it.
            if (n > 1 .and. e(1) /= e(0)) then
                if ((g(1) - g(0)) / (e(1) - e(0)) > 0.0_wp .and. abs(g(1) - g(0)) &
                        > slope_noise_factor * tolerance * scale) &
                    self%slope = (g(1) - g(0)) / (e(1) - e(0))
            end if
            if (abs(g(1)) <= tolerance * scale) then
                ! A zero force: every string across a cut parallel to the other axis is
                ! slack, so the period may shrink on at no force: no one state (a
                ! mechanism), no curve.
                if (abs(held) > tolerance * scale) then
                    self%factors = self%inner%factors
                    if (self%axis == 2 .and. self%scene%axial_channel > 0) &
                        call remember_found(self, e(1), factors(self%scene%axial_channel))
                    self%held_trial_iterations = self%inner%growth_iterations(used)
                    return
                end if
                call restore(error)
                if (allocated(error)) return
                call fatal_error(error, "&fabric " // control_name() // " = '" &
                    // control_value() // "': " // force_name // ' is held at 0 (' &
                    // strain_name // ' = ' // format_real(e(1)) // ', ' // other_name &
                    // ' = ' // format_real(n_other) // ' N/m). ' // mechanism())
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
            else if (self%slope > 0.0_wp) then
                e_new = e(1) - g(1) / self%slope
            else
                e_new = e(1) - sign(first_change, g(1))
            end if
            ! The force grows with the strain (a stretched period pulls harder): a secant
            ! pointing the other way, or out of range, is replaced by a step of the right
            ! sign.
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
        call fatal_error(error, "&fabric " // control_name() // " = '" // control_value() &
            // "': no " // trim(merge('axial  ', 'lateral', self%axis == 1)) // ' strain ' &
            // strain_name // ' holds ' // force_name // ' = ' // format_real(held) &
            // ' N/m after ' // format_integer(n) // ' trials' // history // '. ' &
            // mechanism())
    contains

        !> Step the inner stepper to the strain; g = the force - the force held.
        subroutine evaluate(strain, g, error)
            real(wp), intent(in) :: strain
            real(wp), intent(out) :: g
            type(error_type), allocatable, intent(out) :: error
            real(wp) :: values(6)

            trial(channel) = strain
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
            n_now = values(force_column(self%axis))
            n_other = values(force_column(3 - self%axis))
            if (self%axis == 1) then
                held = factors(self%scene%dofs%gap_channel) * self%scene%axial_force
            else if (self%scene%lateral_control == 'ratio') then
                held = self%scene%force_ratio * n_other
            else
                held = self%scene%lateral_force
            end if
            g = n_now - held
            scale = max(abs(held), abs(n_other), abs(n_now), tiny(1.0_wp))
            if (len(history) < 160) history = history // '; ' // strain_name // ' = ' &
                // format_real(strain) // ': ' // force_name // ' = ' // format_real(n_now)
        end subroutine evaluate

        subroutine restore(error)
            type(error_type), allocatable, intent(out) :: error
            call self%inner%restore_state(self%snapshot, error)
        end subroutine restore

        subroutine restore_quietly()
            type(error_type), allocatable :: ignored
            call self%inner%restore_state(self%snapshot, ignored)
        end subroutine restore_quietly

        function control_name() result(text)
            character(len=:), allocatable :: text
            text = trim(merge('axial_control  ', 'lateral_control', self%axis == 1))
        end function control_name

        function control_value() result(text)
            character(len=:), allocatable :: text
            if (self%axis == 1) then
                text = 'force'
            else
                text = trim(self%scene%lateral_control)
            end if
        end function control_value

        function mechanism() result(text)
            character(len=:), allocatable :: text
            if (self%axis == 1) then
                text = 'Axial collapse: a string network carries no compression and has no ' &
                    // 'resistance to compaction along x; once the yarns along the cell go ' &
                    // 'slack, n11 is 0 whatever e11, and the cell shrinks along x without ' &
                    // 'limit. Hold a positive force (p_disp * axial_force > 0 at every ' &
                    // 'step: start and end the path at p_disp > 0), or prescribe strain'
            else
                text = 'Lateral collapse: a string network has no resistance to lateral ' &
                    // 'compaction (nothing models yarns jamming against each other); once ' &
                    // 'the yarns across the cell go slack, n22 is 0 whatever e22, and the ' &
                    // 'cell shrinks along y without limit. Hold a positive lateral force, ' &
                    // 'or prescribe lateral_strain'
            end if
        end function mechanism
    end subroutine try_step

    !> The first trial strain of the y period wrapped by the x one, at the other period's
    !> strain `other_now`: the strain found at this step's last trial (`accepted` if none),
    !> or the line through the last two, within the strain's range. Why: each trial of
    !> e11 moved e22 from the accepted one again, and the y period took about as many
    !> trials for it as the x period (docs/decisions.md, "Held forces: the slope at the
    !> root and the y period's start").
    pure real(wp) function start_from_found(self, accepted, other_now) result(start)
        class(force_control_stepper_type), intent(in) :: self
        real(wp), intent(in) :: accepted, other_now

        start = accepted
        if (self%n_found == 0) return
        start = self%found(2)
        if (self%n_found >= 2 .and. self%other(2) /= self%other(1)) start = self%found(2) &
            + (other_now - self%other(2)) * (self%found(2) - self%found(1)) &
            / (self%other(2) - self%other(1))
        if (.not. (start > smallest_strain .and. start < largest_strain)) &
            start = self%found(2)
    end function start_from_found

    !> Keep the strain that held the force at the other period's strain `other_now`.
    pure subroutine remember_found(self, strain, other_now)
        class(force_control_stepper_type), intent(inout) :: self
        real(wp), intent(in) :: strain, other_now

        self%found(1) = self%found(2)
        self%other(1) = self%other(2)
        self%found(2) = strain
        self%other(2) = other_now
        self%n_found = self%n_found + 1
    end subroutine remember_found

    !> A step is judged by the trial that held the force, not by all trials: each trial
    !> is a step of that size from the accepted state, and the number of trials says how
    !> well the secant guessed the strain, not how hard the step is (docs/decisions.md,
    !> "Step growth under force control: the held trial's iterations").
    pure integer function growth_iterations(self, iterations) result(n)
        class(force_control_stepper_type), intent(in) :: self
        integer, intent(in) :: iterations

        n = self%held_trial_iterations
    end function growth_iterations

    !> The inner stepper accepted the trial that holds the force in try_step.
    subroutine accept(self)
        class(force_control_stepper_type), intent(inout) :: self
    end subroutine accept

    subroutine get_state(self, state, error)
        class(force_control_stepper_type), intent(inout) :: self
        type(step_state_type), intent(inout) :: state
        type(error_type), allocatable, intent(out) :: error
        call self%inner%get_state(state, error)
    end subroutine get_state

    !> The inner stepper's snapshot and this axis's secant slope (which the next step's
    !> trials use: a restart without it would take other trials).
    subroutine save_state(self, snapshot)
        class(force_control_stepper_type), intent(in) :: self
        type(restart_type), intent(inout) :: snapshot
        call self%inner%save_state(snapshot)
        snapshot%held_slope(self%axis) = self%slope
    end subroutine save_state

    subroutine restore_state(self, snapshot, error)
        class(force_control_stepper_type), intent(inout) :: self
        type(restart_type), intent(in) :: snapshot
        type(error_type), allocatable, intent(out) :: error
        call self%inner%restore_state(snapshot, error)
        if (allocated(error)) return
        self%slope = snapshot%held_slope(self%axis)
        self%factors = self%inner%factors
    end subroutine restore_state

end module yarnfort_solver_force_control
