! SPDX-License-Identifier: MIT
!> Force law from a measured table of (strain, force) rows, strain = lambda - 1.
!>
!> The table is interpolated by a monotone C1 piecewise-cubic Hermite (PCHIP) in the
!> strain. Knot slopes follow Fritsch and Carlson (1980) with the weighted harmonic mean of
!> Fritsch and Butland (1984) at interior knots, as in SLATEC PCHIM and scipy's
!> PchipInterpolator. With strictly increasing data every secant slope is > 0, and:
!>
!> - interior slope: the weighted harmonic mean of the two secants is > 0 and strictly less
!>   than 3 times either secant;
!> - end slopes: the non-centred three-point formula, which is always below twice the end
!>   secant; where it falls below `end_slope_ratio` times the end secant (including when it
!>   is <= 0, for strongly convex or concave ends) it is raised to that floor. This keeps
!>   the end slope > 0 (so `get_reference_stiffness` is positive) and depends continuously
!>   on the data;
!>
!> so on every interval both ratios slope/secant lie in the open square (0, 3)**2, inside
!> the Fritsch-Carlson monotonicity region and away from the points where the cubic's
!> derivative touches zero: the interpolant is strictly increasing on the table range.
!>
!> Beyond the last row the law continues linearly with the last knot's slope (C1, strictly
!> increasing, energy quadratic). For lambda <= 1 the string is slack (f = 0).
module yarnfort_material_table
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_material_force_law, only: force_law_type
    use yarnfort_text, only: format_real, format_integer, quote_string, string_type, to_lower
    use yarnfort_csv, only: csv_row_type, read_csv_pairs
    use yarnfort_units, only: unit_type, find_unit, unit_names, to_scene_unit, &
        get_header_units, get_note_units, find_note_conflict, note_unit_message, &
        header_shape_message, strain_kind, length_kind, force_kind
    implicit none
    private

    public :: table_law_type, new_table_law, read_table_law
    public :: default_end_slope_ratio, max_table_strain

    !> Default floor of an end slope as a fraction of the adjacent secant slope.
    real(wp), parameter :: default_end_slope_ratio = 0.1_wp

    !> Largest end-slope floor accepted (the secant itself).
    real(wp), parameter :: max_end_slope_ratio = 1.0_wp

    !> Largest strain a table file may hold, after unit conversion (1000 %): above the
    !> elongation at break of any textile yarn, elastane included (docs/decisions.md,
    !> "Largest strain of a table file"); a larger one is a column misread.
    real(wp), parameter :: max_table_strain = 10.0_wp

    !> Longest gauge length accepted, m: 10 times the longest specimen of the textile
    !> tensile standards (500 mm, ISO 2062), below the 10 of a length in mm read as m
    !> (docs/decisions.md, "Largest gauge length of a table file").
    real(wp), parameter :: max_gauge_length = 5.0_wp

    !> Words that name a column of a force or of a strain in a table header, and words
    !> of quantities that are neither ('Stress', 'Tenacity': a force per area or tex).
    character(len=*), parameter :: force_words(*) = [character(len=10) :: 'force', 'load', &
        'tension']
    character(len=*), parameter :: strain_words(*) = [character(len=10) :: 'strain', &
        'elongation', 'extension', 'stretch']
    character(len=*), parameter :: other_words(*) = [character(len=10) :: 'stress', &
        'tenacity']

    !> Longest unit text taken from a `&material` variable.
    integer, parameter :: max_unit_text = 64

    !> Fewest rows in a table: (0, 0) and one more.
    integer, parameter :: min_rows = 2

    !> Tabulated string; the components are set by `new_table_law` / `read_table_law`.
    type, extends(force_law_type) :: table_law_type
        !> Knot strains (lambda - 1), strain(1) = 0, strictly increasing.
        real(wp), allocatable :: strain(:)
        !> Knot forces in N, force(1) = 0, strictly increasing.
        real(wp), allocatable :: force(:)
        !> Interpolant's df/dstrain at the knots (> 0).
        real(wp), allocatable :: slope(:)
        !> Energy per unit reference length at the knots, integral of f from 0 to strain(k).
        real(wp), allocatable :: energy(:)
        !> Floor of the end slopes as a fraction of the adjacent secant slope.
        real(wp) :: end_slope_ratio = default_end_slope_ratio
    contains
        procedure :: get_taut_force
        procedure :: get_taut_energy
        procedure :: get_reference_stiffness
    end type table_law_type

contains

    !> Create a table law from knot strains (lambda - 1) and forces in N. The first row must
    !> be (0, 0), both columns strictly increasing, at least 2 rows, all finite.
    !> `end_slope_ratio` (default `default_end_slope_ratio`, in (0, 1]) is the floor of the
    !> end slopes as a fraction of the adjacent secant slope.
    subroutine new_table_law(self, strain, force, error, end_slope_ratio)
        type(table_law_type), intent(out) :: self
        real(wp), intent(in) :: strain(:), force(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: end_slope_ratio
        character(len=*), parameter :: context = 'table'
        type(csv_row_type) :: row, previous
        integer :: i

        if (size(strain) /= size(force)) then
            call fatal_error(error, context // ': ' // format_integer(size(strain)) &
                // ' strains but ' // format_integer(size(force)) // ' forces')
            return
        end if
        do i = 1, size(strain)
            row%value = [strain(i), force(i)]
            row%first_text = format_real(strain(i))
            row%second_text = format_real(force(i))
            row%place = 'row ' // format_integer(i)
            call check_in_order(row, previous, i == 1, context, error)
            if (allocated(error)) return
            previous = row
        end do
        call finish_table(self, strain, force, context, 'row', [(i, i = 1, size(strain))], &
            end_slope_ratio, error)
    end subroutine new_table_law

    !> Read a table law from a CSV file of rows "strain,force" (spaces allowed). Lines
    !> before the first row that start with a non-numeric character and do not read as
    !> two numbers are headers; blank lines and lines starting with '#' are skipped
    !> anywhere. Same rules and `end_slope_ratio` as `new_table_law`; messages name the
    !> file, the line and the offending value.
    !>
    !> Units: the last header line, if it has two comma-separated fields, may state the
    !> unit of each column ('Elongation (%),Force (cN)', see `get_header_unit`);
    !> `strain_unit` and `force_unit` (the `&material` variables, '' for none) may state
    !> them too, and must then agree with the header. A column without a stated unit is in
    !> 1 (strain) or N (force). A strain column in a length unit is an elongation of a
    !> specimen `gauge_length` m long. The converted strains may not exceed
    !> `max_table_strain`.
    subroutine read_table_law(self, path, error, end_slope_ratio, strain_unit, force_unit, &
            gauge_length)
        type(table_law_type), intent(out) :: self
        character(len=*), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: end_slope_ratio
        character(len=*), intent(in), optional :: strain_unit, force_unit
        real(wp), intent(in), optional :: gauge_length
        character(len=:), allocatable :: context, header
        real(wp), allocatable :: strain(:), force(:)
        integer, allocatable :: lines(:), note_lines(:)
        type(string_type), allocatable :: notes(:)
        type(unit_type) :: units(2)
        integer :: header_line

        context = "table '" // path // "'"
        call read_csv_pairs(path, context, [character(len=6) :: 'strain', 'force'], &
            check_row, strain, force, lines, error, header, header_line, notes, note_lines)
        if (allocated(error)) return
        call get_column_units(header, header_line, strain_unit, force_unit, gauge_length, &
            units, error)
        if (.not. allocated(error)) call check_column_names(header, header_line, error)
        if (.not. allocated(error)) call check_note_units(notes, note_lines, header, &
            header_line, strain_unit, force_unit, units, error)
        if (allocated(error)) then
            error%message = context // error%message
            return
        end if
        strain = to_scene_unit(strain, units(1))
        if (units(1)%kind == length_kind) strain = strain / gauge_length
        force = to_scene_unit(force, units(2))
        call check_strain_range(strain, lines, units(1), gauge_length, error)
        if (allocated(error)) then
            error%message = context // error%message
            return
        end if
        call finish_table(self, strain, force, context, 'line', lines, end_slope_ratio, error)
    end subroutine read_table_law

    !> The unit of each column of a table file: from the header (`header` on line
    !> `header_line`; 0: none) and the stated `strain_unit`, `force_unit` ('' or absent:
    !> none), which must agree; 1 and N where neither states one. A strain column in a
    !> length unit needs `gauge_length` > 0, and `gauge_length` needs one. Messages start
    !> with ', line L, column C: ' or ': ' (for the table's context).
    subroutine get_column_units(header, header_line, strain_unit, force_unit, gauge_length, &
            units, error)
        character(len=*), intent(in) :: header
        integer, intent(in) :: header_line
        character(len=*), intent(in), optional :: strain_unit, force_unit
        real(wp), intent(in), optional :: gauge_length
        type(unit_type), intent(out) :: units(2)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), parameter :: names(2) = [character(len=11) :: 'strain_unit', &
            'force_unit']
        character(len=max_unit_text) :: stated(2)
        character(len=:), allocatable :: place
        type(string_type) :: fields(2), texts(2)
        type(unit_type) :: declared
        logical :: in_header(2)
        integer :: c

        ! The header's units (if it has two fields); the units stated in &material.
        call get_header_units(header, fields, texts, in_header)
        if (header_line == 0) in_header(:) = .false.
        stated(:) = ''
        if (present(strain_unit)) stated(1) = strain_unit
        if (present(force_unit)) stated(2) = force_unit

        do c = 1, 2
            place = ', line ' // format_integer(header_line) // ', column ' &
                // format_integer(c) // ' (' // quote_string(fields(c)%text) // ')'
            if (in_header(c)) then
                call take_unit(texts(c)%text, c, units(c), error)
                if (allocated(error)) then
                    error%message = place // ': ' // error%message
                    return
                end if
            end if
            if (len_trim(stated(c)) == 0) cycle
            call take_unit(trim(adjustl(stated(c))), c, declared, error)
            if (allocated(error)) then
                error%message = ': ' // trim(names(c)) // ' ' // error%message
                return
            end if
            if (.not. in_header(c)) then
                units(c) = declared
            else if (declared%name /= units(c)%name) then
                call fatal_error(error, place // ': the header states ' &
                    // quote_string(trim(units(c)%name)) // ' but ' // trim(names(c)) &
                    // ' = ' // quote_string(trim(adjustl(stated(c)))))
                return
            end if
        end do
        ! Neither states a unit: strain 1 (the default unit_type), force N.
        if (.not. (in_header(2) .or. len_trim(stated(2)) > 0)) call take_unit('N', 2, &
            units(2), error)

        if (units(1)%kind == length_kind .and. .not. present(gauge_length)) then
            call fatal_error(error, ': the strain column is an elongation in ' &
                // quote_string(trim(units(1)%name)) // ', which needs &material ' &
                // 'gauge_length (the initial length of the specimen, m)')
        else if (units(1)%kind /= length_kind .and. present(gauge_length)) then
            call fatal_error(error, ': gauge_length = ' // format_real(gauge_length) &
                // ' is set but the strain column is in ' // quote_string(trim(units(1)%name)) &
                // ', not a length (remove it, or state the length unit of the elongation)')
        else if (present(gauge_length)) then
            ! Nested tests: no ordered comparison with a NaN.
            if (.not. (ieee_is_finite(gauge_length) .and. gauge_length > 0.0_wp)) then
                call fatal_error(error, ': gauge_length = ' // format_real(gauge_length) &
                    // ' must be positive and finite')
            else if (gauge_length > max_gauge_length) then
                call fatal_error(error, ': gauge_length = ' // format_real(gauge_length) &
                    // ' m is longer than any tensile specimen (at most ' &
                    // format_real(max_gauge_length) // ' m): gauge_length is in m (500 mm ' &
                    // 'is 0.5)')
            end if
        end if
    end subroutine get_column_units

    !> A note before the rows (a '#' comment, an earlier header line) that states a unit
    !> for a column whose unit neither the header nor `strain_unit`/`force_unit` states is
    !> an error unless it is the unit the column is read in: 'Elongation (%),Force (cN)'
    !> as a comment, or above a line of notes, would otherwise be read in 1 and N.
    subroutine check_note_units(notes, note_lines, header, header_line, strain_unit, &
            force_unit, units, error)
        type(string_type), intent(in) :: notes(:)
        integer, intent(in) :: note_lines(:), header_line
        character(len=*), intent(in) :: header
        character(len=*), intent(in), optional :: strain_unit, force_unit
        type(unit_type), intent(in) :: units(2)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), parameter :: names(2) = [character(len=11) :: 'strain_unit', &
            'force_unit']
        type(string_type) :: fields(2), texts(2), text
        logical :: open_column(2), stated(2)
        integer :: k, c

        call get_header_units(header, fields, texts, stated)
        open_column = .not. (stated .and. header_line > 0)
        if (present(strain_unit)) open_column(1) = open_column(1) .and. len_trim(strain_unit) == 0
        if (present(force_unit)) open_column(2) = open_column(2) .and. len_trim(force_unit) == 0
        call find_note_conflict(notes, open_column, units, parse_unit, k, c, text)
        if (k == 0) return
        call get_note_units(notes(k)%text, fields, texts, stated)
        call fatal_error(error, note_unit_message(note_lines(k), c, fields(c)%text, &
            text%text, trim(units(c)%name), 'set &material ' // trim(names(c)) // ' = ' &
            // quote_string(text%text)))
    end subroutine check_note_units

    !> take_unit as a unit_parser (find_note_conflict).
    pure subroutine parse_unit(text, column, unit, found)
        character(len=*), intent(in) :: text
        integer, intent(in) :: column
        type(unit_type), intent(out) :: unit
        logical, intent(out) :: found
        type(error_type), allocatable :: unknown

        call take_unit(text, column, unit, unknown)
        found = .not. allocated(unknown)
    end subroutine parse_unit

    !> The header's column names in the table's order, strain then force: a header that
    !> names a force in column 1 or a strain in column 2 ('Force,Elongation') is a table
    !> whose columns are swapped, and one that names a stress or a tenacity is not a force.
    !> A header with units must be two comma-separated fields (`header_shape_message`).
    subroutine check_column_names(header, header_line, error)
        character(len=*), intent(in) :: header
        integer, intent(in) :: header_line
        type(error_type), allocatable, intent(out) :: error
        type(string_type) :: fields(2), texts(2)
        character(len=:), allocatable :: place, problem
        logical :: stated(2)
        integer :: c

        if (header_line == 0) return
        problem = header_shape_message(header, header_line, 'strain, force')
        if (len(problem) > 0) then
            call fatal_error(error, problem)
            return
        end if
        call get_header_units(header, fields, texts, stated)
        do c = 1, 2
            problem = ''
            if (names_any(fields(c)%text, other_words)) then
                problem = 'names a quantity that is not a ' // trim(merge('strain', 'force ', &
                    c == 1)) // ' (a table''s columns are strain, then the yarn''s force; a ' &
                    // 'stress or tenacity times the cross-section area or linear density ' &
                    // 'is that force)'
            else if (c == 1 .and. names_any(fields(c)%text, force_words) .and. .not. &
                    names_any(fields(c)%text, strain_words)) then
                problem = 'names a force, but column 1 is the strain (a table''s columns ' &
                    // 'are strain, then force: swap the columns)'
            else if (c == 2 .and. names_any(fields(c)%text, strain_words) .and. .not. &
                    names_any(fields(c)%text, force_words)) then
                problem = 'names a strain, but column 2 is the force (a table''s columns ' &
                    // 'are strain, then force: swap the columns)'
            end if
            if (len(problem) == 0) cycle
            place = ', line ' // format_integer(header_line) // ', column ' &
                // format_integer(c) // ' (' // quote_string(fields(c)%text) // '): '
            call fatal_error(error, place // problem)
            return
        end do
    end subroutine check_column_names

    !> Whether a header field has one of `words` as a word of its own (letters only,
    !> any case: 'Extension' is not 'tension').
    pure logical function names_any(field, words)
        character(len=*), intent(in) :: field
        character(len=*), intent(in) :: words(:)
        character(len=*), parameter :: letters = 'abcdefghijklmnopqrstuvwxyz'
        character(len=:), allocatable :: text
        integer :: first, last

        names_any = .false.
        text = to_lower(field)
        first = scan(text, letters)
        do while (first > 0)
            last = verify(text(first:), letters)
            if (last == 0) then
                last = len(text)
            else
                last = first + last - 2
            end if
            if (any(words == text(first:last))) then
                names_any = .true.
                return
            end if
            first = scan(text(last + 1:), letters)
            if (first > 0) first = first + last
        end do
    end function names_any

    !> The unit spelled `text` for column `column` (1: a strain or a length, 2: a force).
    pure subroutine take_unit(text, column, unit, error)
        character(len=*), intent(in) :: text
        integer, intent(in) :: column
        type(unit_type), intent(out) :: unit
        type(error_type), allocatable, intent(out) :: error
        logical :: found

        call find_unit(text, unit, found)
        if (column == 1) then
            if (found) found = unit%kind == strain_kind .or. unit%kind == length_kind
            if (.not. found) call fatal_error(error, quote_string(text) // ' is not a known ' &
                // 'strain unit (' // unit_names(strain_kind) // ') or length unit of an ' &
                // 'elongation (' // unit_names(length_kind) // ')')
        else
            if (found) found = unit%kind == force_kind
            if (.not. found) call fatal_error(error, quote_string(text) // ' is not a known ' &
                // 'force unit (' // unit_names(force_kind) // ')')
        end if
    end subroutine take_unit

    !> The strains, converted, must stay below `max_table_strain`: a larger one is a
    !> column in another unit than the one it was read in (5 % read as a strain of 5).
    subroutine check_strain_range(strain, lines, unit, gauge_length, error)
        real(wp), intent(in) :: strain(:)
        integer, intent(in) :: lines(:)
        type(unit_type), intent(in) :: unit
        real(wp), intent(in), optional :: gauge_length
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: read_as
        integer :: k

        ! Strains increase strictly: the first one above the limit is the row to name.
        k = findloc(strain > max_table_strain, .true., dim=1)
        if (k == 0) return
        read_as = 'in ' // quote_string(trim(unit%name))
        if (unit%kind == length_kind) read_as = read_as // ' over a gauge length of ' &
            // format_real(gauge_length) // ' m'
        call fatal_error(error, ', line ' // format_integer(lines(k)) // ', column 1: ' &
            // 'strain ' // format_real(strain(k)) // ' (the column read ' // read_as &
            // ') exceeds ' // format_real(max_table_strain) // ', more than any yarn ' &
            // 'stretches: state the unit of the column, e.g. a header ''strain (%)'' or ' &
            // '&material strain_unit = ''%'' (see inputs/REFERENCE.md, Table files)')
    end subroutine check_strain_range

    !> The part of new_table_law and read_table_law after the rows are read and in order:
    !> enough rows, the end slope ratio, the interpolant. `places(i)` is the row or line
    !> number (`place` says which) of knot i, for the message.
    subroutine finish_table(self, strain, force, context, place, places, end_slope_ratio, &
            error)
        type(table_law_type), intent(inout) :: self
        real(wp), intent(in) :: strain(:), force(:)
        character(len=*), intent(in) :: context, place
        integer, intent(in) :: places(:)
        real(wp), intent(in), optional :: end_slope_ratio
        type(error_type), allocatable, intent(out) :: error
        integer :: bad

        if (size(strain) < min_rows) then
            call fatal_error(error, context // ': ' // too_few_rows(size(strain)))
            return
        end if
        call set_ratio(self, end_slope_ratio, context, error)
        if (allocated(error)) return
        call setup_table(self, strain, force, bad)
        if (bad > 0) then
            call fatal_error(error, context // ', ' // place // ' ' &
                // format_integer(places(bad + 1)) // ': ' // slope_range_message(strain, &
                force, bad))
        end if
    end subroutine finish_table

    !> Tension and df/dlambda: the Hermite cubic of the interval holding the strain, the
    !> linear extension beyond the last row.
    pure subroutine get_taut_force(self, stretch, force, dforce)
        class(table_law_type), intent(in) :: self
        real(wp), intent(in) :: stretch
        real(wp), intent(out) :: force, dforce
        real(wp) :: strain, width, secant, t
        integer :: k, n

        n = size(self%strain)
        strain = stretch - 1.0_wp
        if (strain >= self%strain(n)) then
            force = self%force(n) + self%slope(n) * (strain - self%strain(n))
            dforce = self%slope(n)
            return
        end if
        k = find_interval(self%strain, strain)
        width = self%strain(k + 1) - self%strain(k)
        secant = (self%force(k + 1) - self%force(k)) / width
        t = (strain - self%strain(k)) / width
        ! Hermite basis form: exact values at t = 0 and accurate slopes at both ends.
        force = self%force(k) &
            + (self%force(k + 1) - self%force(k)) * t**2 * (3.0_wp - 2.0_wp * t) &
            + width * t * (1.0_wp - t) * ((1.0_wp - t) * self%slope(k) - t * self%slope(k + 1))
        dforce = 6.0_wp * secant * t * (1.0_wp - t) &
            + self%slope(k) * (1.0_wp - t) * (1.0_wp - 3.0_wp * t) &
            + self%slope(k + 1) * t * (3.0_wp * t - 2.0_wp)
    end subroutine get_taut_force

    !> Energy per unit reference length: the precomputed integral up to the knot below plus
    !> the closed-form integral of the Hermite cubic (or of the linear extension).
    pure function get_taut_energy(self, stretch) result(energy)
        class(table_law_type), intent(in) :: self
        real(wp), intent(in) :: stretch
        real(wp) :: energy
        real(wp) :: strain, step
        integer :: k, n

        n = size(self%strain)
        strain = stretch - 1.0_wp
        if (strain >= self%strain(n)) then
            step = strain - self%strain(n)
            energy = self%energy(n) + step * (self%force(n) + 0.5_wp * self%slope(n) * step)
            return
        end if
        k = find_interval(self%strain, strain)
        energy = self%energy(k) + hermite_integral(self, k, strain - self%strain(k))
    end function get_taut_energy

    !> The right-hand slope df/dlambda at lambda = 1 (the first knot slope, > 0).
    pure function get_reference_stiffness(self) result(stiffness)
        class(table_law_type), intent(in) :: self
        real(wp) :: stiffness

        stiffness = self%slope(1)
    end function get_reference_stiffness

    !> Integral of the Hermite cubic of interval k from its left knot over `step`:
    !> width * integral_0^t [y_k + dy*H01 + width*(d_k*H10 + d_k+1*H11)] with
    !> H01 = s**2*(3 - 2*s), H10 = s*(1 - s)**2, H11 = s**2*(s - 1).
    pure function hermite_integral(self, k, step) result(integral)
        type(table_law_type), intent(in) :: self
        integer, intent(in) :: k
        real(wp), intent(in) :: step
        real(wp) :: integral
        real(wp) :: width, t, t2

        width = self%strain(k + 1) - self%strain(k)
        t = step / width
        t2 = t**2
        integral = width * (self%force(k) * t &
            + (self%force(k + 1) - self%force(k)) * t2 * t * (1.0_wp - 0.5_wp * t) &
            + width * t2 * (self%slope(k) * (0.5_wp - t * (2.0_wp / 3.0_wp - 0.25_wp * t)) &
            - self%slope(k + 1) * t * (1.0_wp / 3.0_wp - 0.25_wp * t)))
    end function hermite_integral

    !> Index k of the interval with knot(k) <= x < knot(k+1), for knot(1) <= x < knot(n).
    pure function find_interval(knot, x) result(k)
        real(wp), intent(in) :: knot(:), x
        integer :: k
        integer :: high, middle

        k = 1
        high = size(knot)
        do while (high - k > 1)
            middle = (k + high) / 2
            if (x >= knot(middle)) then
                k = middle
            else
                high = middle
            end if
        end do
    end function find_interval

    !> Store the checked knots, compute the slopes and the cumulative energies. `bad` is the
    !> first interval whose secant slope is not a normal positive number, else 0.
    pure subroutine setup_table(self, strain, force, bad)
        type(table_law_type), intent(inout) :: self
        real(wp), intent(in) :: strain(:), force(:)
        integer, intent(out) :: bad
        real(wp), allocatable :: width(:), secant(:)
        real(wp) :: weight_left, weight_right
        integer :: k, n

        n = size(strain)
        allocate(width(n - 1), secant(n - 1))
        width(:) = strain(2:) - strain(:n - 1)
        secant(:) = (force(2:) - force(:n - 1)) / width
        bad = 0
        do k = 1, n - 1
            if (.not. (ieee_is_finite(secant(k)) .and. ieee_is_finite(1.0_wp / secant(k)))) then
                bad = k
                return
            end if
        end do

        self%strain = strain
        self%force = force
        allocate(self%slope(n), self%energy(n))
        if (n == 2) then
            self%slope(:) = secant(1)
        else
            ! Interior: weighted harmonic mean of the neighbouring secants (Fritsch-Butland).
            do k = 2, n - 1
                weight_left = (2.0_wp * width(k) + width(k - 1)) &
                    / (3.0_wp * (width(k) + width(k - 1)))
                weight_right = 1.0_wp - weight_left
                self%slope(k) = 1.0_wp / (weight_left / secant(k - 1) + weight_right / secant(k))
            end do
            self%slope(1) = end_slope(width(1), width(2), secant(1), secant(2), &
                self%end_slope_ratio)
            self%slope(n) = end_slope(width(n - 1), width(n - 2), secant(n - 1), &
                secant(n - 2), self%end_slope_ratio)
        end if

        self%energy(1) = 0.0_wp
        do k = 1, n - 1
            self%energy(k + 1) = self%energy(k) + width(k) * (0.5_wp * (force(k) + force(k + 1)) &
                + width(k) * (self%slope(k) - self%slope(k + 1)) / 12.0_wp)
        end do
    end subroutine setup_table

    !> End slope from the end interval (width, secant) and its neighbour: the non-centred
    !> three-point formula (< 2*secant for positive secants), raised to ratio*secant.
    pure function end_slope(width, next_width, secant, next_secant, ratio) result(slope)
        real(wp), intent(in) :: width, next_width, secant, next_secant, ratio
        real(wp) :: slope

        slope = secant + width * (secant - next_secant) / (width + next_width)
        slope = max(slope, ratio * secant)
    end function end_slope

    !> Check one row on its own (first row: must be 0, 0) or against the previous row.
    pure subroutine check_row(row, previous, error)
        type(csv_row_type), intent(in) :: row
        type(csv_row_type), intent(in), optional :: previous
        type(error_type), allocatable, intent(out) :: error

        if (.not. ieee_is_finite(row%value(1))) then
            call fatal_error(error, 'strain ' // row%first_text // ' is not finite')
        else if (.not. ieee_is_finite(row%value(2))) then
            call fatal_error(error, 'force ' // row%second_text // ' is not finite')
        else if (.not. present(previous)) then
            if (abs(row%value(1)) > 0.0_wp .or. abs(row%value(2)) > 0.0_wp) then
                call fatal_error(error, 'the first row must be strain 0, force 0 (f = 0 at ' &
                    // 'lambda = 1), found ' // row%first_text // ', ' // row%second_text)
            end if
        else if (.not. row%value(1) > previous%value(1)) then
            call fatal_error(error, 'strain ' // row%first_text // ' is not greater than ' &
                // previous%first_text // ' on ' // previous%place &
                // ' (strains must increase strictly)')
        else if (.not. row%value(2) > previous%value(2)) then
            call fatal_error(error, 'force ' // row%second_text // ' is not greater than ' &
                // previous%second_text // ' on ' // previous%place &
                // ' (forces must increase strictly)')
        end if
    end subroutine check_row

    !> Take the end-slope floor, checking it lies in (0, max_end_slope_ratio].
    subroutine set_ratio(self, ratio, context, error)
        type(table_law_type), intent(inout) :: self
        real(wp), intent(in), optional :: ratio
        character(len=*), intent(in) :: context
        type(error_type), allocatable, intent(out) :: error

        self%end_slope_ratio = default_end_slope_ratio
        if (.not. present(ratio)) return
        ! Nested tests: no ordered comparison with a NaN.
        if (ieee_is_finite(ratio)) then
            if (ratio > 0.0_wp .and. ratio <= max_end_slope_ratio) then
                self%end_slope_ratio = ratio
                return
            end if
        end if
        call fatal_error(error, context // ': end_slope_ratio ' // format_real(ratio) &
            // ' must lie in (0, ' // format_real(max_end_slope_ratio) // ']')
    end subroutine set_ratio

    !> Message for an interval whose secant slope leaves the floating-point range.
    pure function slope_range_message(strain, force, k) result(message)
        real(wp), intent(in) :: strain(:), force(:)
        integer, intent(in) :: k
        character(len=:), allocatable :: message

        message = 'force step ' // format_real(force(k + 1) - force(k)) &
            // ' over strain step ' // format_real(strain(k + 1) - strain(k)) &
            // ' gives a slope outside the floating-point range'
    end function slope_range_message

    !> Message for a table with fewer than `min_rows` rows.
    pure function too_few_rows(nrow) result(message)
        integer, intent(in) :: nrow
        character(len=:), allocatable :: message

        message = 'found ' // format_integer(nrow) // ' data rows, at least ' // format_integer(min_rows) &
            // ' rows are needed (the first row 0,0 and more)'
    end function too_few_rows

    !> Check a row, after `previous` unless it is the `first`; the message names the
    !> table (`context`) and the row's place.
    subroutine check_in_order(row, previous, first, context, error)
        type(csv_row_type), intent(in) :: row, previous
        logical, intent(in) :: first
        character(len=*), intent(in) :: context
        type(error_type), allocatable, intent(out) :: error

        if (first) then
            call check_row(row, error=error)
        else
            call check_row(row, previous, error)
        end if
        if (allocated(error)) error%message = context // ', ' // row%place // ': ' &
            // error%message
    end subroutine check_in_order

end module yarnfort_material_table
