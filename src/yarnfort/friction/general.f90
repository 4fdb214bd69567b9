! SPDX-License-Identifier: MIT
!> General friction law T' = g(T) (paper eqs. 37-39) for a rate g given by an extension.
!>
!> `general_law_type` integrates the ODE numerically with the embedded Dormand-Prince 5(4)
!> Runge-Kutta pair (local extrapolation, FSAL) under a purely relative error control:
!> each step's error estimate must stay below relative_tolerance*max(|T_old|, |T_new|),
!> which is scale-free like the capstan law itself (T_min = 0 with g(0) > 0 included).
!> Embedded error estimates are blind to kinks of g (they made the global error 300 times
!> the tolerance on the decaying adhesion law), so a rate reports its kinks and zeros
!> (`get_next_kink`) and a step that reaches one lands on it exactly: the angle to get
!> there is integral dT/g over the smooth stretch (autonomy), by Gauss-Legendre
!> quadrature. T never passes a zero of g (an equilibrium); a rate with unreported
!> kinks still works, with the accuracy that step rejection alone gives.
!> Derivatives follow from the autonomy of the ODE, not from a variational equation:
!> dT/dalpha = g(T(alpha)); dT/dT0 = g(T(alpha))/g(T0) if g(T0) > 0, otherwise T stays at
!> the equilibrium T0 and dT/dT0 = exp(alpha*g'(T0+)) (right-sided).
!>
!> Extensions provided here:
!> - `table_law_type`: g from a table of (T, g) points, interpolated piecewise linearly and
!>   extrapolated linearly beyond the last point (clipped at g = 0). This is the law read
!>   from the input. On each linear piece the ODE is solved exactly (g(T(alpha)) =
!>   g(T_a)*exp(m*alpha)), so `get_critical_tension` walks the pieces in closed form: exact
!>   to rounding, cost O(number of points), and free of the step restrictions an explicit
!>   integrator meets on steep (stiff) decreasing pieces. The Runge-Kutta integration of
!>   the same table stays available as `get_critical_tension_numerical`.
!> - `numerical_law_type`: the numerical twin of any friction law, integrating that law's
!>   own rate; used to check closed forms.
module yarnfort_friction_general
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_csv, only: csv_row_type, read_csv_pairs
    use yarnfort_text, only: format_integer, format_real, quote_string, string_type
    use yarnfort_units, only: unit_type, find_unit, unit_names, to_scene_unit, &
        get_header_units, get_note_units, find_note_conflict, note_unit_message, &
        header_shape_message, force_kind
    use yarnfort_friction_law, only: friction_law_type, tension_limit, rate_limit, no_kink, &
        scaled_exp, capped_product, capped_quotient, expm1, cap_critical_tension
    implicit none
    private

    public :: general_law_type, table_law_type, numerical_law_type
    public :: new_table_law, read_rate_table, new_numerical_law, check_integration_controls
    public :: default_relative_tolerance, default_max_steps
    public :: integration_converged, integration_capped, integration_out_of_steps

    !> Default relative tolerance of the Runge-Kutta integration.
    real(wp), parameter :: default_relative_tolerance = 1.0e-10_wp
    !> Default budget of Runge-Kutta step attempts (accepted and rejected) per integration.
    integer, parameter :: default_max_steps = 1000000
    !> Smallest and largest relative tolerance accepted.
    real(wp), parameter :: minimum_relative_tolerance = 10 * epsilon(1.0_wp)
    real(wp), parameter :: maximum_relative_tolerance = 0.1_wp

    !> Status of `integrate`: reached the angle; stopped at `tension_limit`; ran out of steps.
    integer, parameter :: integration_converged = 0, integration_capped = 1, &
        integration_out_of_steps = 2

    !> Runge-Kutta trial values above this, or rates with h*g above it, are rejected as
    !> overflowing; stage sums then stay below huge() (sum of |a_ij| < 32).
    real(wp), parameter :: stage_limit = huge(1.0_wp) / 1024.0_wp
    !> Most panels of the Gauss-Legendre quadrature that finds the angle to a kink.
    integer, parameter :: max_quadrature_panels = 1024
    !> First step: this fraction of relative_tolerance**(1/5) over the rate's growth scale.
    real(wp), parameter :: initial_step_fraction = 0.1_wp
    !> Step-size controller: safety factor and bounds of the change per step.
    real(wp), parameter :: step_safety = 0.9_wp, step_growth_max = 5.0_wp, &
        step_shrink_min = 0.2_wp, overflow_shrink = 0.25_wp
    !> log(1+x) is taken as a difference of logarithms once |log ratio| exceeds this.
    real(wp), parameter :: log_ratio_switch = 0.5_wp

    ! Dormand-Prince 5(4) coefficients (Hairer, Norsett, Wanner, Table II.5.2).
    real(wp), parameter :: a21 = 1.0_wp / 5
    real(wp), parameter :: a31 = 3.0_wp / 40, a32 = 9.0_wp / 40
    real(wp), parameter :: a41 = 44.0_wp / 45, a42 = -56.0_wp / 15, a43 = 32.0_wp / 9
    real(wp), parameter :: a51 = 19372.0_wp / 6561, a52 = -25360.0_wp / 2187, &
        a53 = 64448.0_wp / 6561, a54 = -212.0_wp / 729
    real(wp), parameter :: a61 = 9017.0_wp / 3168, a62 = -355.0_wp / 33, &
        a63 = 46732.0_wp / 5247, a64 = 49.0_wp / 176, a65 = -5103.0_wp / 18656
    real(wp), parameter :: b1 = 35.0_wp / 384, b3 = 500.0_wp / 1113, b4 = 125.0_wp / 192, &
        b5 = -2187.0_wp / 6784, b6 = 11.0_wp / 84
    real(wp), parameter :: e1 = 71.0_wp / 57600, e3 = -71.0_wp / 16695, &
        e4 = 71.0_wp / 1920, e5 = -17253.0_wp / 339200, e6 = 22.0_wp / 525, &
        e7 = -1.0_wp / 40

    !> A friction law given by its rate g(T) (deferred `get_rate`), integrated numerically.
    type, abstract, extends(friction_law_type) :: general_law_type
        !> Relative tolerance of the Runge-Kutta error control.
        real(wp) :: relative_tolerance = default_relative_tolerance
        !> Budget of step attempts per integration.
        integer :: max_steps = default_max_steps
    contains
        !> T_crit by Runge-Kutta integration (an extension may override it).
        procedure :: get_critical_tension => get_critical_tension_numerical
        !> T_crit by Runge-Kutta integration, whatever the extension does.
        procedure :: get_critical_tension_numerical
        !> The integration itself, with step count and status for diagnostics.
        procedure :: integrate
    end type general_law_type

    !> Rate g(T) from a table, linear between points and beyond the last one, g >= 0.
    type, extends(general_law_type) :: table_law_type
        !> Table tensions (N), strictly increasing from 0.
        real(wp), allocatable :: tension(:)
        !> Rates g >= 0 at the table tensions (N/rad).
        real(wp), allocatable :: rate(:)
        !> Slope of g on [tension(i), tension(i+1)]; the last one also holds beyond.
        real(wp), allocatable :: slope(:)
    contains
        procedure :: get_rate => get_rate_table
        procedure :: get_next_kink => get_next_kink_table
        !> Exact piece-by-piece solution (module notes).
        procedure :: get_critical_tension => get_critical_tension_table
    end type table_law_type

    !> Numerical integration of another law's rate (its closed form is not used).
    type, extends(general_law_type) :: numerical_law_type
        !> The law whose rate is integrated.
        class(friction_law_type), allocatable :: law
    contains
        procedure :: get_rate => get_rate_numerical
        procedure :: get_next_kink => get_next_kink_numerical
    end type numerical_law_type

contains

    !> Fail unless 10*epsilon <= relative_tolerance <= 0.1 and max_steps >= 1.
    pure subroutine check_integration_controls(law_name, relative_tolerance, max_steps, error)
        character(len=*), intent(in) :: law_name
        real(wp), intent(in) :: relative_tolerance
        integer, intent(in) :: max_steps
        type(error_type), allocatable, intent(out) :: error
        character(len=20) :: buffer

        if (.not. (relative_tolerance >= minimum_relative_tolerance &
                .and. relative_tolerance <= maximum_relative_tolerance)) then
            call fatal_error(error, law_name // ': relative_tolerance must lie in [' &
                // format_real(minimum_relative_tolerance) // ', ' &
                // format_real(maximum_relative_tolerance) // '], got ' &
                // format_real(relative_tolerance))
        else if (max_steps < 1) then
            write(buffer, '(i0)') max_steps
            call fatal_error(error, law_name // ': max_steps must be >= 1, got ' // trim(buffer))
        end if
    end subroutine check_integration_controls

    !> Create a table law from points (tension(i), rate(i)): at least two, tension(1) = 0,
    !> tensions strictly increasing, rates >= 0, all finite and <= tension_limit.
    pure subroutine new_table_law(self, tension, rate, error, relative_tolerance, max_steps)
        type(table_law_type), intent(out) :: self
        real(wp), intent(in) :: tension(:), rate(:)
        type(error_type), allocatable, intent(out) :: error
        !> Tolerance and step budget of `get_critical_tension_numerical` (defaults above).
        real(wp), intent(in), optional :: relative_tolerance
        integer, intent(in), optional :: max_steps
        character(len=*), parameter :: law_name = 'table friction law'
        real(wp) :: width, rise
        integer :: i, n
        character(len=20) :: index

        if (present(relative_tolerance)) self%relative_tolerance = relative_tolerance
        if (present(max_steps)) self%max_steps = max_steps
        call check_integration_controls(law_name, self%relative_tolerance, self%max_steps, &
            error)
        if (allocated(error)) return
        n = size(tension)
        if (size(rate) /= n) then
            write(index, '(i0)') size(rate)
            call fatal_error(error, law_name // ': rate has ' // trim(index) &
                // ' values, tension has ' // format_integer(n))
            return
        end if
        if (n < 2) then
            call fatal_error(error, law_name // ': needs at least 2 points, got ' // format_integer(n))
            return
        end if
        do i = 1, n
            write(index, '("(", i0, ")")') i
            if (.not. (ieee_is_finite(tension(i)) .and. abs(tension(i)) <= tension_limit)) then
                call fatal_error(error, law_name // ': tension' // trim(index) &
                    // ' must be finite and <= ' // format_real(tension_limit) // ', got ' &
                    // format_real(tension(i)))
                return
            end if
            if (.not. (ieee_is_finite(rate(i)) .and. rate(i) >= 0.0_wp &
                    .and. rate(i) <= tension_limit)) then
                call fatal_error(error, law_name // ': rate' // trim(index) &
                    // ' must be finite, >= 0 and <= ' // format_real(tension_limit) &
                    // ', got ' // format_real(rate(i)))
                return
            end if
        end do
        if (abs(tension(1)) > 0.0_wp) then
            call fatal_error(error, law_name // ': tension(1) must be 0 (g is needed for all ' &
                // 'T >= 0), got ' // format_real(tension(1)))
            return
        end if
        do i = 2, n
            write(index, '("(", i0, ")")') i
            if (.not. tension(i) > tension(i - 1)) then
                call fatal_error(error, law_name // ': tension must be strictly increasing, ' &
                    // 'tension' // trim(index) // ' = ' // format_real(tension(i)) &
                    // ' <= ' // format_real(tension(i - 1)))
                return
            end if
            width = tension(i) - tension(i - 1)
            rise = abs(rate(i) - rate(i - 1))
            if (width < 1.0_wp) then
                if (rise > width * tension_limit) then
                    call fatal_error(error, law_name // ': slope of the rate up to tension' &
                        // trim(index) // ' is too steep (rate changes by ' &
                        // format_real(rise) // ' over ' // format_real(width) // ')')
                    return
                end if
            end if
        end do
        self%tension = tension
        self%rate = rate
        self%slope = (rate(2:) - rate(:n - 1)) / (tension(2:) - tension(:n - 1))
    end subroutine new_table_law

    !> Read the rate table of the general law from a CSV file of rows "T,g" (tension in N,
    !> rate in N/rad; the CSV rules of `yarnfort_csv`). Stricter than `new_table_law`, as
    !> the input asks of every friction law: the first row is T = 0 with g >= 0, T
    !> increases strictly, g > 0 at every T > 0, all finite, and the last piece does not
    !> fall (the rate continues with it beyond the table and would reach zero). Messages
    !> name the file, the line and the value. A header may state the units of the columns
    !> as a `&material table_file` does: a force unit for T, that unit per radian for g
    !> ('T (cN),g (cN/rad)'); they are converted to N and N/rad.
    subroutine read_rate_table(self, path, error)
        type(table_law_type), intent(out) :: self
        character(len=*), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: context, header
        real(wp), allocatable :: tension(:), rate(:)
        integer, allocatable :: lines(:), note_lines(:)
        type(string_type), allocatable :: notes(:)
        type(unit_type) :: units(2)
        integer :: n, header_line

        context = "rate_table '" // path // "'"
        call read_csv_pairs(path, context, [character(len=1) :: 'T', 'g'], check_rate_row, &
            tension, rate, lines, error, header, header_line, notes, note_lines)
        if (allocated(error)) return
        call get_rate_units(header, header_line, units, error)
        if (.not. allocated(error)) call check_rate_notes(notes, note_lines, header, &
            header_line, units, error)
        if (allocated(error)) then
            error%message = context // error%message
            return
        end if
        tension = to_scene_unit(tension, units(1))
        rate = to_scene_unit(rate, units(2))
        n = size(tension)
        if (n < 2) then
            call fatal_error(error, context // ': found ' // format_integer(n) // ' data rows, at ' &
                // 'least 2 are needed (the first at T = 0)')
            return
        end if
        if (rate(n) < rate(n - 1)) then
            call fatal_error(error, context // ', line ' // format_integer(lines(n)) // ': the last ' &
                // 'piece falls (g = ' // format_real(rate(n - 1)) // ' to ' &
                // format_real(rate(n)) // '); g continues with that slope beyond the ' &
                // 'table and would reach 0: add a row where g no longer falls')
            return
        end if
        call new_table_law(self, tension, rate, error)
        if (allocated(error)) error%message = context // ': ' // error%message
    end subroutine read_rate_table

    !> The units a rate table's header states: a force unit for T, the same per radian
    !> for g ('N/rad', 'cN/rad'; a bare force unit too, radians being dimensionless);
    !> N where none is stated. Messages start with ', line L, column C'.
    subroutine get_rate_units(header, header_line, units, error)
        character(len=*), intent(in) :: header
        integer, intent(in) :: header_line
        type(unit_type), intent(out) :: units(2)
        type(error_type), allocatable, intent(out) :: error
        type(string_type) :: fields(2), texts(2)
        character(len=:), allocatable :: text
        logical :: stated(2), found
        integer :: c

        if (header_line > 0) then
            text = header_shape_message(header, header_line, 'T, g')
            if (len(text) > 0) then
                call fatal_error(error, text)
                return
            end if
        end if
        call get_header_units(header, fields, texts, stated)
        do c = 1, 2
            text = 'N'
            if (stated(c) .and. header_line > 0) text = texts(c)%text
            call find_rate_unit(text, c, units(c), found)
            if (.not. found) then
                if (c == 1) then
                    text = 'force unit (' // unit_names(force_kind) // ')'
                else
                    text = 'force unit per rad (' // unit_names(force_kind) // ', then /rad)'
                end if
                call fatal_error(error, ', line ' // format_integer(header_line) &
                    // ', column ' // format_integer(c) // ' (' // quote_string(fields(c)%text) &
                    // '): ' // quote_string(texts(c)%text) // ' is not a known ' // text)
                return
            end if
        end do
    end subroutine get_rate_units

    !> The unit of column `column` of a rate table spelled `text`: a force unit for T, a
    !> force unit or one per radian for g; `found` false for another.
    pure subroutine find_rate_unit(text, column, unit, found)
        character(len=*), intent(in) :: text
        integer, intent(in) :: column
        type(unit_type), intent(out) :: unit
        logical, intent(out) :: found
        character(len=:), allocatable :: force

        force = text
        if (column == 2 .and. len(force) > 4) then
            if (force(len(force) - 3:) == '/rad') force = force(:len(force) - 4)
        end if
        call find_unit(force, unit, found)
        if (found) found = unit%kind == force_kind
    end subroutine find_rate_unit

    !> A note before the rows (a '#' comment, an earlier header line) that states a unit
    !> other than N for a column whose header states none is an error: it would be read
    !> in N (as a `&material table_file`'s notes).
    subroutine check_rate_notes(notes, note_lines, header, header_line, units, error)
        type(string_type), intent(in) :: notes(:)
        integer, intent(in) :: note_lines(:), header_line
        character(len=*), intent(in) :: header
        type(unit_type), intent(in) :: units(2)
        type(error_type), allocatable, intent(out) :: error
        type(string_type) :: fields(2), texts(2), text
        logical :: stated(2)
        integer :: k, c

        call get_header_units(header, fields, texts, stated)
        call find_note_conflict(notes, .not. (stated .and. header_line > 0), units, &
            find_rate_unit, k, c, text)
        if (k == 0) return
        call get_note_units(notes(k)%text, fields, texts, stated)
        call fatal_error(error, note_unit_message(note_lines(k), c, fields(c)%text, &
            text%text, trim(units(c)%name), 'state the units in that header ' &
            // '(''T (cN),g (cN/rad)'')'))
    end subroutine check_rate_notes

    !> One row of a rate table on its own (the first: T = 0, g >= 0) or after the previous.
    pure subroutine check_rate_row(row, previous, error)
        type(csv_row_type), intent(in) :: row
        type(csv_row_type), intent(in), optional :: previous
        type(error_type), allocatable, intent(out) :: error

        if (.not. (ieee_is_finite(row%value(1)) .and. abs(row%value(1)) <= tension_limit)) then
            call fatal_error(error, 'T ' // row%first_text // ' must be finite and <= ' &
                // format_real(tension_limit))
        else if (.not. (ieee_is_finite(row%value(2)) .and. abs(row%value(2)) <= tension_limit)) &
                then
            call fatal_error(error, 'g ' // row%second_text // ' must be finite and <= ' &
                // format_real(tension_limit))
        else if (.not. present(previous)) then
            if (abs(row%value(1)) > 0.0_wp) then
                call fatal_error(error, 'the first row must be at T = 0 (g is needed for all ' &
                    // 'T >= 0), found T = ' // row%first_text)
            else if (row%value(2) < 0.0_wp) then
                call fatal_error(error, 'g(0) = ' // row%second_text // ' is negative (g >= 0 ' &
                    // 'at T = 0)')
            end if
        else if (.not. row%value(1) > previous%value(1)) then
            call fatal_error(error, 'T ' // row%first_text // ' is not greater than ' &
                // previous%first_text // ' on ' // previous%place &
                // ' (T must increase strictly)')
        else if (.not. row%value(2) > 0.0_wp) then
            call fatal_error(error, 'g ' // row%second_text // ' at T = ' // row%first_text &
                // ' is not positive (g > 0 for T > 0: a zero would be a tension the ' &
                // 'passage can never exceed)')
        end if
    end subroutine check_rate_row

    !> Create the numerical twin of `law`: integrates law%get_rate with the given tolerance.
    subroutine new_numerical_law(self, law, error, relative_tolerance, max_steps)
        type(numerical_law_type), intent(out) :: self
        class(friction_law_type), intent(in) :: law
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: relative_tolerance
        integer, intent(in), optional :: max_steps

        if (present(relative_tolerance)) self%relative_tolerance = relative_tolerance
        if (present(max_steps)) self%max_steps = max_steps
        call check_integration_controls('numerical friction law', self%relative_tolerance, &
            self%max_steps, error)
        if (allocated(error)) return
        allocate(self%law, source=law)
    end subroutine new_numerical_law

    !> T_crit(T_min, alpha) by Runge-Kutta integration of T' = g(T), derivatives from the
    !> rate (module notes). If the step budget runs out (only for a very stiff rate) the
    !> tension reached so far is returned: a lower bound, so the check errs towards slip;
    !> `integrate` reports that case.
    pure subroutine get_critical_tension_numerical(self, tension_min, angle, critical, &
            dcritical_dtension, dcritical_dangle)
        class(general_law_type), intent(in) :: self
        real(wp), intent(in) :: tension_min, angle
        real(wp), intent(out) :: critical, dcritical_dtension, dcritical_dangle
        real(wp) :: tension_start, wrap
        integer :: steps, status

        tension_start = max(tension_min, 0.0_wp)
        wrap = max(angle, 0.0_wp)
        call self%integrate(tension_start, wrap, critical, steps, status)
        call get_flow_derivatives(self, tension_start, wrap, critical, dcritical_dtension, &
            dcritical_dangle)
        if (status == integration_capped) critical = tension_limit
        call cap_critical_tension(tension_start, critical, dcritical_dtension, &
            dcritical_dangle)
    end subroutine get_critical_tension_numerical

    !> Integrate T' = g(T), T(0) = tension_start >= 0, up to `angle` >= 0 with Dormand-Prince
    !> 5(4). A step that reaches the next kink of g (`get_next_kink`) is replaced by a
    !> landing exactly on it: the angle to get there is the quadrature of 1/g over the
    !> smooth stretch (autonomy: alpha(T) = integral dT/g). A zero of g is never passed.
    !> `steps` counts step attempts; `status` is one of integration_converged,
    !> integration_capped (T passed tension_limit; `tension` = tension_limit) or
    !> integration_out_of_steps (`tension` is the value reached).
    pure subroutine integrate(self, tension_start, angle, tension, steps, status)
        class(general_law_type), intent(in) :: self
        real(wp), intent(in) :: tension_start, angle
        real(wp), intent(out) :: tension
        integer, intent(out) :: steps, status
        real(wp) :: k1, k2, k3, k4, k5, k6, k7, dk, y, y_new, h, position, growth, rtol
        real(wp) :: scale, estimate, ratio, factor, kink, rate_kink, to_kink
        logical :: last, overflow, rejected

        tension = tension_start
        steps = 0
        status = integration_converged
        if (angle <= 0.0_wp) return
        if (tension > tension_limit) then
            tension = tension_limit
            status = integration_capped
            return
        end if
        rtol = self%relative_tolerance
        call self%get_rate(tension, k1, dk)
        kink = self%get_next_kink(tension)

        ! First step from the rate's growth scale |g'|, g/T.
        growth = abs(dk)
        if (tension > 0.0_wp) growth = max(growth, capped_quotient(k1, tension))
        h = angle
        if (growth > 0.0_wp) h = min(angle, initial_step_fraction * rtol**0.2_wp / growth)

        position = 0.0_wp
        rejected = .false.
        do while (position < angle)
            if (steps >= self%max_steps) then
                status = integration_out_of_steps
                return
            end if
            steps = steps + 1
            if (.not. (k1 <= rate_limit)) then
                ! The rate at an accepted tension is beyond any representable growth.
                tension = tension_limit
                status = integration_capped
                return
            end if
            last = position + h >= angle * (1.0_wp - 4 * epsilon(1.0_wp))
            if (last) h = angle - position
            y = tension

            overflow = .false.
            call get_stage_rate(self, y + h * a21 * k1, h, k2, overflow)
            call get_stage_rate(self, y + h * (a31 * k1 + a32 * k2), h, k3, overflow)
            call get_stage_rate(self, y + h * (a41 * k1 + a42 * k2 + a43 * k3), h, k4, overflow)
            call get_stage_rate(self, y + h * (a51 * k1 + a52 * k2 + a53 * k3 + a54 * k4), h, &
                k5, overflow)
            call get_stage_rate(self, y + h * (a61 * k1 + a62 * k2 + a63 * k3 + a64 * k4 &
                + a65 * k5), h, k6, overflow)
            y_new = y + h * (b1 * k1 + b3 * k3 + b4 * k4 + b5 * k5 + b6 * k6)
            call get_stage_rate(self, y_new, h, k7, overflow)
            if (overflow) then
                h = h * overflow_shrink
                rejected = .true.
                cycle
            end if

            estimate = abs(h * (e1 * k1 + e3 * k3 + e4 * k4 + e5 * k5 + e6 * k6 + e7 * k7))
            scale = rtol * max(abs(y), abs(y_new))
            if (estimate <= 0.0_wp) then
                ratio = 0.0_wp
            else if (scale > 0.0_wp) then
                ratio = estimate / scale
            else
                ratio = huge(1.0_wp)
            end if
            if (.not. ratio <= 1.0_wp) then
                ! Rejected (also for a NaN ratio): retry smaller.
                if (ratio > 0.0_wp .and. ratio < huge(1.0_wp)) then
                    factor = max(step_shrink_min, step_safety * ratio**(-0.2_wp))
                else
                    factor = step_shrink_min
                end if
                h = h * factor
                rejected = .true.
                cycle
            end if

            if (y_new >= kink) then
                ! The step reaches the next kink: land on it exactly if the quadrature says
                ! it is reached within this step, else (a zero of g, or an overshoot within
                ! the tolerance) stop on it.
                call self%get_rate(kink, rate_kink, dk)
                to_kink = huge(1.0_wp)
                if (rate_kink > 0.0_wp) to_kink = get_angle_between(self, y, kink, rtol)
                tension = kink
                k1 = rate_kink
                if (to_kink < h) then
                    position = position + to_kink
                else
                    position = merge(angle, position + h, last)
                end if
                kink = self%get_next_kink(tension)
            else
                tension = y_new
                k1 = k7
                position = merge(angle, position + h, last)
            end if
            if (tension > tension_limit) then
                tension = tension_limit
                status = integration_capped
                return
            end if
            if (ratio > 0.0_wp) then
                factor = min(step_growth_max, max(step_shrink_min, &
                    step_safety * ratio**(-0.2_wp)))
            else
                factor = step_growth_max
            end if
            if (rejected) factor = min(factor, 1.0_wp)
            h = h * factor
            rejected = .false.
        end do
    end subroutine integrate

    !> Rate at a Runge-Kutta stage value for a step of size h. Once `overflow` is set (a
    !> trial value beyond stage_limit, or h*rate that could overflow the stage sums) later
    !> stages are skipped and return 0; the caller retries the step smaller.
    pure subroutine get_stage_rate(self, value, h, rate, overflow)
        class(general_law_type), intent(in) :: self
        real(wp), intent(in) :: value, h
        real(wp), intent(out) :: rate
        logical, intent(inout) :: overflow
        real(wp) :: drate

        rate = 0.0_wp
        if (overflow) return
        if (.not. (abs(value) <= stage_limit)) then
            overflow = .true.
            return
        end if
        call self%get_rate(value, rate, drate)
        if (.not. abs(rate) <= rate_limit) then
            overflow = .true.
        else if (h >= 1.0_wp) then
            ! Fortran does not short-circuit: divide only where it cannot overflow.
            if (abs(rate) > stage_limit / h) overflow = .true.
        end if
        if (overflow) rate = 0.0_wp
    end subroutine get_stage_rate

    !> Angle integral of dT/g(T) from `lower` to `upper`, g smooth and positive in between:
    !> composite 5-point Gauss-Legendre, panels doubled until two estimates agree to `rtol`.
    pure function get_angle_between(self, lower, upper, rtol) result(angle)
        class(general_law_type), intent(in) :: self
        real(wp), intent(in) :: lower, upper, rtol
        real(wp) :: angle
        real(wp), parameter :: nodes(5) = [-0.9061798459386640_wp, -0.5384693101056831_wp, &
            0.0_wp, 0.5384693101056831_wp, 0.9061798459386640_wp]
        real(wp), parameter :: weights(5) = [0.2369268850561891_wp, 0.4786286704993665_wp, &
            0.5688888888888889_wp, 0.4786286704993665_wp, 0.2369268850561891_wp]
        real(wp) :: previous, width, centre, rate, drate
        integer :: panels, p, q

        panels = 1
        previous = huge(1.0_wp)
        do
            width = (upper - lower) / panels
            angle = 0.0_wp
            do p = 1, panels
                centre = lower + (p - 0.5_wp) * width
                do q = 1, size(nodes)
                    call self%get_rate(centre + 0.5_wp * width * nodes(q), rate, drate)
                    angle = angle + weights(q) * capped_quotient(0.5_wp * width, rate)
                end do
            end do
            if (abs(angle - previous) <= rtol * angle .or. panels >= max_quadrature_panels) exit
            previous = angle
            panels = 2 * panels
        end do
    end function get_angle_between

    !> Derivatives of the flow T(alpha; T0) of an autonomous ODE at its end value `critical`.
    pure subroutine get_flow_derivatives(self, tension_start, angle, critical, &
            dcritical_dtension, dcritical_dangle)
        class(friction_law_type), intent(in) :: self
        real(wp), intent(in) :: tension_start, angle, critical
        real(wp), intent(out) :: dcritical_dtension, dcritical_dangle
        real(wp) :: rate_end, drate_end, rate_start, drate_start

        call self%get_rate(critical, rate_end, drate_end)
        call self%get_rate(tension_start, rate_start, drate_start)
        dcritical_dangle = min(max(rate_end, 0.0_wp), tension_limit)
        if (rate_start > 0.0_wp) then
            dcritical_dtension = capped_quotient(max(rate_end, 0.0_wp), rate_start)
        else if (drate_start >= 0.0_wp) then
            dcritical_dtension = scaled_exp(1.0_wp, capped_product(drate_start, angle))
        else
            dcritical_dtension = exp(-capped_product(-drate_start, angle))
        end if
    end subroutine get_flow_derivatives

    !> Rate of the law being integrated.
    pure subroutine get_rate_numerical(self, tension, rate, drate)
        class(numerical_law_type), intent(in) :: self
        real(wp), intent(in) :: tension
        real(wp), intent(out) :: rate, drate

        call self%law%get_rate(tension, rate, drate)
    end subroutine get_rate_numerical

    !> Kinks of the law being integrated.
    pure function get_next_kink_numerical(self, tension) result(kink)
        class(numerical_law_type), intent(in) :: self
        real(wp), intent(in) :: tension
        real(wp) :: kink

        kink = self%law%get_next_kink(tension)
    end function get_next_kink_numerical

    !> Next table point above `tension`, or the zero of a falling last piece.
    pure function get_next_kink_table(self, tension) result(kink)
        class(table_law_type), intent(in) :: self
        real(wp), intent(in) :: tension
        real(wp) :: kink
        integer :: i, n

        n = size(self%tension)
        i = find_piece(self%tension, max(tension, 0.0_wp))
        kink = no_kink
        if (i + 1 < n .or. self%tension(n) > tension) then
            kink = self%tension(i + 1)
        else if (self%slope(n - 1) < 0.0_wp .and. self%rate(n) > 0.0_wp) then
            kink = self%tension(n) + capped_quotient(self%rate(n), -self%slope(n - 1))
            if (.not. kink > tension) kink = no_kink
        end if
    end function get_next_kink_table

    !> Piecewise linear g with right derivative (the slope of the piece starting at T).
    pure subroutine get_rate_table(self, tension, rate, drate)
        class(table_law_type), intent(in) :: self
        real(wp), intent(in) :: tension
        real(wp), intent(out) :: rate, drate
        integer :: i

        i = find_piece(self%tension, max(tension, 0.0_wp))
        call get_piece_rate(self, i, max(tension, 0.0_wp), rate)
        drate = self%slope(i)
        if (rate <= 0.0_wp .and. drate < 0.0_wp) drate = 0.0_wp
    end subroutine get_rate_table

    !> Exact T_crit of the piecewise linear rate: on a piece with slope m starting at T_a,
    !> g(T(alpha)) = g(T_a)*exp(m*alpha); the angle to reach the piece's end is
    !> log(g_end/g(T_a))/m, and T never passes a zero of g.
    pure subroutine get_critical_tension_table(self, tension_min, angle, critical, &
            dcritical_dtension, dcritical_dangle)
        class(table_law_type), intent(in) :: self
        real(wp), intent(in) :: tension_min, angle
        real(wp), intent(out) :: critical, dcritical_dtension, dcritical_dangle
        real(wp) :: tension_start, remaining, rate_here, rate_end, to_end
        integer :: i, pieces

        tension_start = max(tension_min, 0.0_wp)
        remaining = max(angle, 0.0_wp)
        pieces = size(self%tension) - 1
        critical = tension_start
        i = find_piece(self%tension, critical)
        do while (remaining > 0.0_wp)
            call get_piece_rate(self, i, critical, rate_here)
            if (rate_here <= 0.0_wp) exit
            if (i < pieces) then
                rate_end = self%rate(i + 1)
                if (rate_end > 0.0_wp) then
                    to_end = angle_on_piece(self%tension(i + 1) - critical, rate_here, &
                        rate_end, self%slope(i))
                    if (to_end <= remaining) then
                        remaining = remaining - to_end
                        critical = self%tension(i + 1)
                        i = i + 1
                        cycle
                    end if
                end if
            end if
            critical = min(critical + advance_on_piece(rate_here, self%slope(i), remaining), &
                tension_limit)
            exit
        end do
        critical = max(critical, tension_start)
        call get_flow_derivatives(self, tension_start, max(angle, 0.0_wp), critical, &
            dcritical_dtension, dcritical_dangle)
        call cap_critical_tension(tension_start, critical, dcritical_dtension, &
            dcritical_dangle)
    end subroutine get_critical_tension_table

    !> Index i of the piece [tension(i), tension(i+1)) holding t >= 0; the last piece
    !> extends to infinity.
    pure integer function find_piece(tension, t) result(i)
        real(wp), intent(in) :: tension(:), t
        integer :: low, high, middle

        low = 1
        high = size(tension) - 1
        do while (low < high)
            middle = (low + high + 1) / 2
            if (tension(middle) <= t) then
                low = middle
            else
                high = middle - 1
            end if
        end do
        i = low
    end function find_piece

    !> Rate on piece i at tension t (linear, clipped at 0, overflow-safe).
    pure subroutine get_piece_rate(self, i, t, rate)
        class(table_law_type), intent(in) :: self
        integer, intent(in) :: i
        real(wp), intent(in) :: t
        real(wp), intent(out) :: rate
        real(wp) :: offset

        offset = max(t - self%tension(i), 0.0_wp)
        if (self%slope(i) >= 0.0_wp) then
            rate = min(self%rate(i) + capped_product(self%slope(i), offset, rate_limit), &
                rate_limit)
        else
            rate = max(self%rate(i) - capped_product(-self%slope(i), offset, rate_limit), 0.0_wp)
        end if
    end subroutine get_piece_rate

    !> Angle to climb `width` on a linear piece from rate g_a > 0 to rate g_end > 0 with
    !> slope m: log(g_end/g_a)/m, written as (width/g_a)*log(1+x)/x near x = 0.
    pure function angle_on_piece(width, rate_start, rate_end, slope) result(angle)
        real(wp), intent(in) :: width, rate_start, rate_end, slope
        real(wp) :: angle
        real(wp) :: log_ratio, u

        log_ratio = log(rate_end) - log(rate_start)
        if (abs(slope) > 0.0_wp .and. abs(log_ratio) > log_ratio_switch) then
            angle = capped_quotient(abs(log_ratio), abs(slope))
        else
            u = rate_end / rate_start
            angle = capped_quotient(max(width, 0.0_wp), rate_start)
            if (abs(u - 1.0_wp) > 0.0_wp) angle = angle * (log(u) / (u - 1.0_wp))
        end if
    end function angle_on_piece

    !> Tension gained over `angle` on a linear piece from rate g_a > 0 with slope m:
    !> g_a*expm1(m*angle)/m, accurate near m*angle = 0 and without overflow.
    pure function advance_on_piece(rate_start, slope, angle) result(gain)
        real(wp), intent(in) :: rate_start, slope, angle
        real(wp) :: gain
        real(wp) :: z, scale

        if (slope >= 0.0_wp) then
            z = capped_product(slope, angle)
        else
            z = -capped_product(-slope, angle)
        end if
        if (abs(z) <= 1.0_wp) then
            gain = capped_product(rate_start, angle)
            if (abs(z) > 0.0_wp) gain = capped_product(gain, expm1(z) / z)
        else if (z < 0.0_wp) then
            gain = capped_quotient(rate_start, -slope) * (-expm1(z))
        else
            scale = capped_quotient(rate_start, slope)
            gain = scaled_exp(scale, z) - scale
        end if
    end function advance_on_piece

end module yarnfort_friction_general
