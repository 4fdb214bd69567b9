! SPDX-License-Identifier: MIT
!> What the generated readers, checks and echo of yarnfort_input_groups do with one
!> namelist variable: take a value read into a buffer (length, case, list length against
!> the "not set" markers), check it (range, choices, the parameters of a law), write it
!> back, and turn a failed namelist READ into a message naming group, variable and line.
module yarnfort_input_fields
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: to_lower, format_integer, format_real, join_names, closest_name
    use yarnfort_input_scan, only: namelist_scan_type, explain_read_error
    implicit none
    private

    public :: buffer_length, message_length, max_list, max_coordinates, indent
    public :: unset_real, unset_integer, other_real, other_integer
    public :: read_failed, post_read_error, too_many_found, group_label
    public :: take_text, unset_reals, unset_integers, count_set
    public :: check_real, check_at_least, check_choice, require_set, require_text, forbid_set
    public :: not_finite, suggestion, quoted_list, check_name
    public :: put, put_reals, put_integers, format_logical

    !> Most node ids in one &yarn, &support or &load group, and most knots in &path.
    integer, parameter :: max_list = 100000
    !> Most values of &nodes xyz (3 per node); larger scenes use &geometry.
    integer, parameter :: max_coordinates = 3 * max_list
    !> Mark list entries the input did not set. An input value equal to the first
    !> marker makes the reader read the group again with the second (see
    !> namelist_scan_type%holds_marker): an entry is unset where both reads left theirs.
    integer, parameter :: unset_integer = -huge(1), other_integer = huge(1)
    real(wp), parameter :: unset_real = -huge(1.0_wp), other_real = huge(1.0_wp)
    !> Length of the character buffers the namelists read into (longer than any config
    !> field, so that a value too long for its field is detected, not cut).
    integer, parameter :: buffer_length = 2048
    integer, parameter :: message_length = 512
    !> Indent of the variables in the echo, and values per line of its lists.
    character(len=*), parameter :: indent = '    '
    integer, parameter :: integers_per_line = 10, reals_per_line = 3
    !> Characters of material and support names.
    character(len=*), parameter :: name_characters = &
        'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-.'

    !> A law parameter that another law uses must stay unset.
    interface forbid_set
        module procedure forbid_real, forbid_text
    end interface forbid_set

contains

    !> '&name' for a singleton (occurrence 0), '&name #k' for the k-th of a repeatable.
    pure function group_label(name, occurrence) result(label)
        character(len=*), intent(in) :: name
        integer, intent(in) :: occurrence
        character(len=:), allocatable :: label

        label = '&' // name
        if (occurrence > 0) label = label // ' #' // format_integer(occurrence)
    end function group_label

    !> Turn a failed namelist READ into an error naming the group, with the reader's
    !> message and where possible the variable, the line and a suggestion.
    subroutine read_failed(error, scan, name, occurrence, stat, message, variables)
        type(error_type), allocatable, intent(out) :: error
        type(namelist_scan_type), intent(in) :: scan
        character(len=*), intent(in) :: name
        integer, intent(in) :: occurrence, stat
        character(len=*), intent(in) :: message
        character(len=*), intent(in) :: variables(:)
        integer :: g

        if (is_iostat_end(stat)) then
            g = scan%find_group(name, max(occurrence, 1))
            call fatal_error(error, group_label(name, occurrence) // ' (line ' &
                // format_integer(scan%groups(g)%first_line) // ') was not found by the ' &
                // "Fortran namelist reader: is there a '!' inside a character value " &
                // 'earlier on that line? (it hides the rest of the line)')
            return
        end if
        call fatal_error(error, group_label(name, occurrence) // ': ' &
            // explain_read_error(scan, name, max(occurrence, 1), trim(message), variables))
    end subroutine read_failed

    !> An error found after a successful READ, with the group's line.
    subroutine post_read_error(error, scan, name, occurrence, text)
        type(error_type), allocatable, intent(out) :: error
        type(namelist_scan_type), intent(in) :: scan
        character(len=*), intent(in) :: name
        integer, intent(in) :: occurrence
        character(len=*), intent(in) :: text
        integer :: g

        g = scan%find_group(name, max(occurrence, 1))
        if (g == 0) then
            call fatal_error(error, group_label(name, occurrence) // ': ' // text)
        else
            call fatal_error(error, group_label(name, occurrence) // ': ' // text &
                // ' (group on line ' // format_integer(scan%groups(g)%first_line) // ')')
        end if
    end subroutine post_read_error

    !> The namelist reader found more occurrences than the structural scan.
    subroutine too_many_found(error, name, n_expected)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: name
        integer, intent(in) :: n_expected

        call fatal_error(error, '&' // name // ': the Fortran namelist reader found more ' &
            // 'than the ' // format_integer(n_expected) // ' &' // name // ' groups of ' &
            // "the text; is '&" // name // "' inside a comment after a character value " &
            // "with '!'?")
    end subroutine too_many_found

    !> A character value read into `buffer` into its config `field`: it must fit; leading
    !> blanks dropped if `adjust`, folded to lower case if `lower`.
    subroutine take_text(error, scan, name, occurrence, variable, buffer, field, lower, adjust)
        type(error_type), allocatable, intent(out) :: error
        type(namelist_scan_type), intent(in) :: scan
        character(len=*), intent(in) :: name, variable
        integer, intent(in) :: occurrence
        character(len=*), intent(inout) :: buffer
        character(len=*), intent(out) :: field
        logical, intent(in) :: lower, adjust

        field = ''
        if (adjust) buffer = adjustl(buffer)
        if (len_trim(buffer) > len(field)) then
            call post_read_error(error, scan, name, occurrence, variable // " = '" &
                // buffer(:min(len_trim(buffer), 40)) // "...' is longer than " &
                // format_integer(len(field)) // ' characters')
            return
        end if
        if (lower) buffer = to_lower(buffer)
        field = buffer(:len(field))
    end subroutine take_text

    !> Which entries of a list read into `values` (prefilled with unset_real) the input
    !> did not set. If `again` is allocated, `values` holds a second read prefilled with
    !> other_real and `again` the first: an entry is unset only where both kept their
    !> marker (so an input value equal to a marker is a value).
    pure function unset_reals(values, again) result(unset)
        real(wp), intent(in) :: values(:)
        real(wp), allocatable, intent(in) :: again(:)
        logical :: unset(size(values))

        if (allocated(again)) then
            unset = values == other_real .and. again == unset_real
        else
            unset = values == unset_real
        end if
    end function unset_reals

    !> As unset_reals for integers (markers unset_integer and other_integer).
    pure function unset_integers(values, again) result(unset)
        integer, intent(in) :: values(:)
        integer, allocatable, intent(in) :: again(:)
        logical :: unset(size(values))

        if (allocated(again)) then
            unset = values == other_integer .and. again == unset_integer
        else
            unset = values == unset_integer
        end if
    end function unset_integers

    !> `n`, the last set entry of a list; an error for a set guard or an unset entry
    !> before the last set one.
    subroutine count_set(error, scan, name, occurrence, variable, unset, n)
        type(error_type), allocatable, intent(out) :: error
        type(namelist_scan_type), intent(in) :: scan
        character(len=*), intent(in) :: name, variable
        integer, intent(in) :: occurrence
        logical, intent(in) :: unset(:)
        integer, intent(out) :: n
        integer :: i

        n = 0
        do i = size(unset), 1, -1
            if (.not. unset(i)) then
                n = i
                exit
            end if
        end do
        if (n == size(unset)) then
            call post_read_error(error, scan, name, occurrence, variable // ' has more than ' &
                // format_integer(size(unset) - 1) // ' values (the most it can hold)')
            return
        end if
        i = findloc(unset(:n), .true., dim=1)
        if (i > 0) then
            call post_read_error(error, scan, name, occurrence, variable // '(' &
                // format_integer(i) // ') has no value, but later entries have (an ' &
                // 'empty entry between commas?)')
        end if
    end subroutine count_set

    !> A real that must be finite and, where bounds are given, within them (the texts
    !> of the bounds are those of the description, for the message).
    subroutine check_real(error, label, variable, value, lower, lower_text, lower_open, &
            upper, upper_text, upper_open)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable
        real(wp), intent(in) :: value
        real(wp), intent(in), optional :: lower, upper
        character(len=*), intent(in), optional :: lower_text, upper_text
        logical, intent(in), optional :: lower_open, upper_open
        character(len=:), allocatable :: rule
        logical :: outside

        if (.not. ieee_is_finite(value)) then
            call not_finite(error, label, variable, value)
            return
        end if
        if (.not. present(lower)) return
        if (present(upper)) then
            outside = value < lower .or. value > upper .or. (lower_open .and. value == lower) &
                .or. (upper_open .and. value == upper)
            if (lower_open .and. upper_open) then
                rule = 'must lie strictly between ' // lower_text // ' and ' // upper_text
            else
                rule = 'must lie in ' // merge('(', '[', lower_open) // lower_text // ', ' &
                    // upper_text // merge(')', ']', upper_open)
            end if
        else if (lower_open) then
            outside = value <= lower
            rule = 'must be > ' // lower_text
            if (lower == 0.0_wp) rule = 'must be positive'
        else
            outside = value < lower
            rule = 'must be >= ' // lower_text
        end if
        if (outside) call fatal_error(error, label // ': ' // variable // ' = ' &
            // format_real(value) // ' ' // rule)
    end subroutine check_real

    subroutine check_at_least(error, label, variable, value, minimum)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable
        integer, intent(in) :: value, minimum

        if (value < minimum) then
            call fatal_error(error, label // ': ' // variable // ' = ' // format_integer(value) &
                // ' must be >= ' // format_integer(minimum))
        end if
    end subroutine check_at_least

    !> A value that must be one of `choices`; '' is "not set" for a `required` one.
    subroutine check_choice(error, label, variable, value, choices, required)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable, value
        character(len=*), intent(in) :: choices(:)
        logical, intent(in) :: required

        if (any(choices == value)) return
        if (required .and. len_trim(value) == 0) then
            call fatal_error(error, label // ': ' // variable // ' is not set (use ' &
                // join_names(choices, '') // ')')
        else
            call fatal_error(error, label // ': ' // variable // " = '" // trim(value) &
                // "' is unknown (use " // join_names(choices, '') // ')' &
                // suggestion(value, choices))
        end if
    end subroutine check_choice

    !> A parameter of the selected law: set (not its "not set" default).
    subroutine require_set(error, label, variable, value, unset, law)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable, law
        real(wp), intent(in) :: value, unset

        if (value == unset) then
            call fatal_error(error, label // ': ' // variable // " is not set (law '" // law &
                // "' needs it)")
        end if
    end subroutine require_set

    subroutine require_text(error, label, variable, value, law)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable, value, law

        if (len_trim(value) == 0) then
            call fatal_error(error, label // ': ' // variable // " is not set (law '" // law &
                // "' needs it)")
        end if
    end subroutine require_text

    subroutine forbid_real(error, label, variable, value, unset, law)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable, law
        real(wp), intent(in) :: value, unset

        if (.not. (value == unset)) then
            call fatal_error(error, label // ': ' // variable // ' = ' // format_real(value) &
                // " is not used by law '" // law // "' (remove it)")
        end if
    end subroutine forbid_real

    subroutine forbid_text(error, label, variable, value, unset, law)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable, value, unset, law

        if (value /= unset) then
            call fatal_error(error, label // ': ' // variable // " = '" // trim(value) &
                // "' is not used by law '" // law // "' (remove it)")
        end if
    end subroutine forbid_text

    subroutine not_finite(error, label, variable, value)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable
        real(wp), intent(in) :: value

        call fatal_error(error, label // ': ' // variable // ' = ' // format_real(value) &
            // ' is not finite')
    end subroutine not_finite

    !> "; did you mean 'x'?" for the known name closest to `name`, or ''.
    pure function suggestion(name, names) result(text)
        character(len=*), intent(in) :: name
        character(len=*), intent(in) :: names(:)
        character(len=:), allocatable :: text

        text = closest_name(trim(name), names)
        if (len(text) > 0) text = "; did you mean '" // text // "'?"
    end function suggestion

    !> "'a', 'b', 'c'"
    pure function quoted_list(names) result(list)
        character(len=*), intent(in) :: names(:)
        character(len=:), allocatable :: list
        integer :: i

        list = ''
        do i = 1, size(names)
            if (i > 1) list = list // ', '
            list = list // "'" // trim(names(i)) // "'"
        end do
    end function quoted_list

    !> Names are single words (the geometry file and the curve CSV header use them).
    subroutine check_name(error, label, name)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, name

        if (verify(trim(name), name_characters) > 0) then
            call fatal_error(error, label // ": name = '" // trim(name) // "' may contain " &
                // "only letters, digits, '_', '-' and '.'")
        end if
    end subroutine check_name

    !> Write one line. A failed write does not stop the program: the caller that needs
    !> the file whole checks it when closing it (yarnfort_output_filesystem compares its
    !> size on disk with what was written).
    subroutine put(unit, line)
        integer, intent(in) :: unit
        character(len=*), intent(in) :: line
        integer :: status

        write(unit, '(a)', iostat=status) line
    end subroutine put

    !> `name = v1 v2 ...`, integers_per_line values per line; nothing for no values.
    subroutine put_integers(unit, name, values)
        integer, intent(in) :: unit
        character(len=*), intent(in) :: name
        integer, intent(in) :: values(:)

        call put_values(unit, name, size(values), integers_per_line, integer_text)
    contains
        function integer_text(i) result(text)
            integer, intent(in) :: i
            character(len=:), allocatable :: text

            text = format_integer(values(i))
        end function integer_text
    end subroutine put_integers

    !> `name = v1 v2 ...`, reals_per_line values per line; nothing for no values.
    subroutine put_reals(unit, name, values)
        integer, intent(in) :: unit
        character(len=*), intent(in) :: name
        real(wp), intent(in) :: values(:)

        call put_values(unit, name, size(values), reals_per_line, real_text)
    contains
        function real_text(i) result(text)
            integer, intent(in) :: i
            character(len=:), allocatable :: text

            text = format_real(values(i))
        end function real_text
    end subroutine put_reals

    !> `name = ` and the texts of values 1..n, `per_line` of them per line.
    subroutine put_values(unit, name, n, per_line, text_of)
        integer, intent(in) :: unit, n, per_line
        character(len=*), intent(in) :: name
        interface
            function text_of(i) result(text)
                integer, intent(in) :: i
                character(len=:), allocatable :: text
            end function text_of
        end interface
        character(len=:), allocatable :: line
        integer :: i

        if (n == 0) return
        line = indent // name // ' ='
        do i = 1, n
            line = line // ' ' // text_of(i)
            if (mod(i, per_line) == 0 .or. i == n) then
                call put(unit, line)
                line = indent // repeat(' ', len(name) + 2)
            end if
        end do
    end subroutine put_values

    pure function format_logical(value) result(text)
        logical, intent(in) :: value
        character(len=:), allocatable :: text

        text = merge('.true. ', '.false.', value)
        text = trim(text)
    end function format_logical

end module yarnfort_input_fields
