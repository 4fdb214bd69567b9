! SPDX-License-Identifier: MIT
!> The units a measurement file may state (a table's column header, a geometry file's
!> `unit` line, the `&material` and `&geometry` unit variables) and their exact factors
!> to the units of the scene: strain 1, force N, length m.
!>
!> A value v in unit u is v * numerator / denominator in the scene's unit. The prefixes
!> are exact integer denominators, so 5 % is 5 / 100, correctly rounded, the same
!> double as a hand-written 0.05.
module yarnfort_units
    use yarnfort_kinds, only: wp
    use yarnfort_text, only: to_lower, string_type, format_integer, quote_string
    implicit none
    private

    public :: unit_type, find_unit, unit_names, to_scene_unit, get_header_unit
    public :: get_header_units, get_note_units, same_unit, note_unit_message
    public :: find_note_conflict, unit_parser
    public :: header_shape_message
    public :: strain_kind, length_kind, force_kind

    !> The kinds of quantity a unit measures.
    character(len=*), parameter :: strain_kind = 'strain', length_kind = 'length', &
        force_kind = 'force'

    !> One unit: its spelling, what it measures and its exact factor to the scene's unit.
    type :: unit_type
        character(len=8) :: name = '1'
        character(len=6) :: kind = strain_kind
        real(wp) :: numerator = 1.0_wp
        real(wp) :: denominator = 1.0_wp
        !> Also matched in any letter case (no SI prefix it could be confused with).
        logical :: any_case = .false.
    end type unit_type

    !> The standard acceleration of gravity (CGPM 1901), m/s^2: 1 gf = 9.80665e-3 N exactly.
    real(wp), parameter :: standard_gravity = 9.80665_wp
    !> The avoirdupois pound-force, N (1 lb = 0.45359237 kg exactly, times standard_gravity).
    real(wp), parameter :: pound_force = 4.4482216152605_wp
    !> 'per mille' sign and micro sign in UTF-8.
    character(len=*), parameter :: per_mille = char(226) // char(128) // char(176)
    character(len=*), parameter :: micro = char(194) // char(181)

    !> Every unit a tensile tester or a CAD export writes for strain, elongation and force.
    type(unit_type), parameter :: known_units(*) = [ &
        unit_type('1', strain_kind, 1.0_wp, 1.0_wp, .false.), &
        unit_type('-', strain_kind, 1.0_wp, 1.0_wp, .false.), &
        unit_type('%', strain_kind, 1.0_wp, 100.0_wp, .false.), &
        unit_type('permille', strain_kind, 1.0_wp, 1000.0_wp, .true.), &
        unit_type(per_mille, strain_kind, 1.0_wp, 1000.0_wp, .false.), &
        unit_type('m', length_kind, 1.0_wp, 1.0_wp, .false.), &
        unit_type('cm', length_kind, 1.0_wp, 100.0_wp, .false.), &
        unit_type('mm', length_kind, 1.0_wp, 1000.0_wp, .false.), &
        unit_type('um', length_kind, 1.0_wp, 1.0e6_wp, .false.), &
        unit_type(micro // 'm', length_kind, 1.0_wp, 1.0e6_wp, .false.), &
        unit_type('N', force_kind, 1.0_wp, 1.0_wp, .false.), &
        unit_type('cN', force_kind, 1.0_wp, 100.0_wp, .false.), &
        unit_type('mN', force_kind, 1.0_wp, 1000.0_wp, .false.), &
        unit_type('kN', force_kind, 1000.0_wp, 1.0_wp, .false.), &
        unit_type('gf', force_kind, standard_gravity, 1000.0_wp, .true.), &
        unit_type('kgf', force_kind, standard_gravity, 1.0_wp, .true.), &
        unit_type('lbf', force_kind, pound_force, 1.0_wp, .true.)]

    abstract interface
        !> The unit of a table's column `column` spelled `text` (`found` false for one
        !> that column cannot take).
        pure subroutine unit_parser(text, column, unit, found)
            import :: unit_type
            character(len=*), intent(in) :: text
            integer, intent(in) :: column
            type(unit_type), intent(out) :: unit
            logical, intent(out) :: found
        end subroutine unit_parser
    end interface

contains

    !> The unit spelled `text` (exactly, or in any case for gf, kgf, lbf, permille);
    !> `found` is false for an unknown spelling.
    pure subroutine find_unit(text, unit, found)
        character(len=*), intent(in) :: text
        type(unit_type), intent(out) :: unit
        logical, intent(out) :: found
        integer :: i

        do i = 1, size(known_units)
            found = trim(known_units(i)%name) == trim(text)
            if (.not. found .and. known_units(i)%any_case) &
                found = trim(known_units(i)%name) == to_lower(trim(text))
            if (found) then
                unit = known_units(i)
                return
            end if
        end do
    end subroutine find_unit

    !> "'1', '-', '%', ..." : the spellings of the units of one kind, for messages.
    pure function unit_names(kind) result(names)
        character(len=*), intent(in) :: kind
        character(len=:), allocatable :: names
        integer :: i

        names = ''
        do i = 1, size(known_units)
            if (known_units(i)%kind /= kind) cycle
            if (len(names) > 0) names = names // ', '
            names = names // "'" // trim(known_units(i)%name) // "'"
        end do
    end function unit_names

    !> A value in `unit` converted to the scene's unit of its kind.
    elemental function to_scene_unit(value, unit) result(converted)
        real(wp), intent(in) :: value
        type(unit_type), intent(in) :: unit
        real(wp) :: converted

        ! Left to right: a numerator of 1 is exact, so 5 % is 5 / 100, one rounding.
        converted = (value * unit%numerator) / unit%denominator
    end function to_scene_unit

    !> The unit a column header `field` states, as text: the contents of its last (...)
    !> or [...] ('Force (cN)', 'strain [%]'), else its last word after a blank or '/' when
    !> that is a known unit ('Force in cN', 'Force/cN', 'mm'). `stated` is false when the
    !> field states none ('strain', 'force'): such a header keeps the default units.
    pure subroutine get_header_unit(field, text, stated)
        character(len=*), intent(in) :: field
        character(len=:), allocatable, intent(out) :: text
        logical, intent(out) :: stated
        character(len=:), allocatable :: name
        type(unit_type) :: unit
        integer :: last, first

        name = trim(adjustl(field))
        last = scan(name, ')]', back=.true.)
        if (last > 0) then
            if (name(last:last) == ')') then
                first = index(name(:last), '(', back=.true.)
            else
                first = index(name(:last), '[', back=.true.)
            end if
            stated = first > 0
            if (stated) then
                text = trim(adjustl(name(first + 1:last - 1)))
                return
            end if
        end if
        text = name(scan(name, ' /', back=.true.) + 1:)
        call find_unit(text, unit, stated)
    end subroutine get_header_unit

    !> The fields of a two-column header line and the unit text each states
    !> (`get_header_unit`); a line without exactly two comma-separated fields states none.
    pure subroutine get_header_units(header, fields, texts, stated)
        character(len=*), intent(in) :: header
        type(string_type), intent(out) :: fields(2), texts(2)
        logical, intent(out) :: stated(2)
        integer :: comma, c

        stated(:) = .false.
        fields(1)%text = ''
        fields(2)%text = ''
        texts(1)%text = ''
        texts(2)%text = ''
        comma = index(header, ',')
        if (comma == 0) return
        if (index(header(comma + 1:), ',') /= 0) return
        fields(1)%text = trim(adjustl(header(:comma - 1)))
        fields(2)%text = trim(adjustl(header(comma + 1:)))
        do c = 1, 2
            if (len(fields(c)%text) > 0) call get_header_unit(fields(c)%text, texts(c)%text, &
                stated(c))
        end do
    end subroutine get_header_units

    !> '' for a header line of two comma-separated fields (whose units are read), or for
    !> one that states no unit in brackets; otherwise the message (starting ', line L: ')
    !> for a header whose units would not be read: 'Elongation (%),Force (cN),' (a third,
    !> empty field), 'Elongation (%);Force (cN)', or the fields separated by tabs.
    pure function header_shape_message(header, header_line, names) result(message)
        character(len=*), intent(in) :: header, names
        integer, intent(in) :: header_line
        character(len=:), allocatable :: message
        type(unit_type) :: unit
        integer :: comma, first, last
        logical :: found

        message = ''
        comma = index(header, ',')
        if (comma > 0) then
            if (index(header(comma + 1:), ',') == 0) return
        end if
        ! Every (...) and [...] of the line: the first that holds a known unit.
        last = 0
        do
            first = last + scan(header(last + 1:), '([')
            if (first == last) return
            last = first + scan(header(first + 1:), ')]')
            if (last == first) return
            call find_unit(trim(adjustl(header(first + 1:last - 1))), unit, found)
            if (found) exit
        end do
        message = ', line ' // format_integer(header_line) // ': the header states the ' &
            // 'unit ' // quote_string(trim(unit%name)) // ' but is not two comma-separated ' &
            // 'fields (' // names // '), so its units would not be read: write it as ' &
            // 'two fields separated by one comma, without a trailing comma'
    end function header_shape_message

    !> The units a note before a table's rows (a '#' comment, an earlier header line)
    !> states, where it reads as a header of the two columns: both fields state a unit
    !> (`get_header_units`) and neither has a digit outside it ('gauge 500 mm, 0.5 cN'
    !> records settings, not column names). `stated` is false otherwise.
    pure subroutine get_note_units(note, fields, texts, stated)
        character(len=*), intent(in) :: note
        type(string_type), intent(out) :: fields(2), texts(2)
        logical, intent(out) :: stated(2)
        character(len=:), allocatable :: name
        integer :: c, at

        call get_header_units(note, fields, texts, stated)
        if (.not. all(stated)) then
            stated(:) = .false.
            return
        end if
        do c = 1, 2
            at = index(fields(c)%text, texts(c)%text, back=.true.)
            name = fields(c)%text(:at - 1) // fields(c)%text(at + len(texts(c)%text):)
            if (scan(name, '0123456789') > 0) stated(:) = .false.
        end do
    end subroutine get_note_units

    !> The first note before a table's rows (`notes`) that states, for a column whose
    !> unit no header or setting gave (`open_column`), a unit (read by `parse`) other
    !> than the one the column is read in (`units`): its index `note` and column
    !> `column`, with the unit as written in `text`; `note` = 0 if there is none. Why:
    !> such a note is a header the reader did not take, and its unit would be ignored.
    subroutine find_note_conflict(notes, open_column, units, parse, note, column, text)
        type(string_type), intent(in) :: notes(:)
        logical, intent(in) :: open_column(2)
        type(unit_type), intent(in) :: units(2)
        procedure(unit_parser) :: parse
        integer, intent(out) :: note, column
        type(string_type), intent(out) :: text
        type(string_type) :: fields(2), texts(2)
        type(unit_type) :: unit
        logical :: stated(2), found
        integer :: c, k

        note = 0
        column = 0
        do k = 1, size(notes)
            call get_note_units(notes(k)%text, fields, texts, stated)
            do c = 1, 2
                if (.not. (stated(c) .and. open_column(c))) cycle
                call parse(texts(c)%text, c, unit, found)
                if (.not. found) cycle
                if (same_unit(unit, units(c))) cycle
                note = k
                column = c
                text = texts(c)
                return
            end do
        end do
    end subroutine find_note_conflict

    !> Whether two units measure the same kind with the same factor ('1' and '-').
    elemental logical function same_unit(a, b)
        type(unit_type), intent(in) :: a, b

        same_unit = a%kind == b%kind .and. a%numerator == b%numerator .and. &
            a%denominator == b%denominator
    end function same_unit

    !> The message for a note on line `line` whose field `field` states the unit `stated`
    !> for column `column`, which is read in `used` (no header or variable states one):
    !> the units of a table come from its last header line only, so the note's would be
    !> ignored. `remedy` says how else to state it.
    pure function note_unit_message(line, column, field, stated, used, remedy) &
            result(message)
        integer, intent(in) :: line, column
        character(len=*), intent(in) :: field, stated, used, remedy
        character(len=:), allocatable :: message

        message = ', line ' // format_integer(line) // ', column ' // format_integer(column) &
            // ' (' // quote_string(field) // '): states the unit ' // quote_string(stated) &
            // ', but units are read ' &
            // 'only from the last header line before the rows (not from a ''#'' comment ' &
            // 'or an earlier line), which states none for this column: it would be read ' &
            // 'in ' // quote_string(used) // '. Make this line that header (without ''#'', ' &
            // 'directly before the rows), or ' // remedy
    end function note_unit_message

end module yarnfort_units
