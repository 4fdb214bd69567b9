! SPDX-License-Identifier: MIT
!> What the generated readers, checks and echo of yarnfort_input_groups do with one
!> namelist variable: take its values from the assignments of a group (type, entries,
!> length, case; each error naming group, variable, value and line), check it (range,
!> choices, the parameters of a law), and write it back.
module yarnfort_input_fields
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: to_lower, format_integer, format_real, join_names, closest_name, &
        parse_integer, parse_real, string_type
    use yarnfort_input_scan, only: assignment_type, group_label
    implicit none
    private

    public :: max_list, max_coordinates, indent
    public :: group_label, take_scalar, take_optional, take_array, list_length, is_assigned
    public :: optional_text
    public :: check_range, check_choice, check_retired, check_law_parameter
    public :: suggestion, quoted_list, check_name, check_item_name, put, put_list

    !> Most node ids in one &yarn, &support or &load group, and most knots in &path.
    integer, parameter :: max_list = 100000
    !> Most values of &nodes xyz (3 per node); larger scenes use &geometry.
    integer, parameter :: max_coordinates = 3 * max_list
    !> Indent of the variables in the echo, and values per line of its lists.
    character(len=*), parameter :: indent = '    '
    integer, parameter :: integers_per_line = 10, reals_per_line = 3
    !> Characters of material and support names.
    character(len=*), parameter :: name_characters = &
        'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-.'

contains

    !> Scalar variable `name` of group `label` (real(wp), integer, logical or character,
    !> folded to lower case if `lower`, leading blanks dropped if `adjust`) from its
    !> assignment among `sets`; unchanged where none sets it or its value is null.
    subroutine take_scalar(sets, label, name, field, error, lower, adjust)
        type(assignment_type), intent(in) :: sets(:)
        character(len=*), intent(in) :: label, name
        class(*), intent(inout) :: field
        type(error_type), allocatable, intent(out) :: error
        logical, intent(in) :: lower, adjust
        type(string_type), allocatable :: words(:)
        integer :: k, first

        first = 0
        do k = 1, size(sets)
            if (sets(k)%name /= name) cycle
            if (sets(k)%subscripted) then
                call fatal_error(error, label // ': ' // name // '(' &
                    // format_integer(sets(k)%first) // ') (line ' &
                    // format_integer(sets(k)%line) // '): ' // name // ' is not an array')
                return
            else if (first > 0) then
                call fatal_error(error, label // ': ' // name // ' is set twice (lines ' &
                    // format_integer(sets(first)%line) // ' and ' &
                    // format_integer(sets(k)%line) // ')')
                return
            end if
            first = k
        end do
        if (first == 0) return
        call expand(sets(first), label, 1, words, error)
        if (allocated(error) .or. size(words) == 0) return
        if (len(words(1)%text) == 0) return
        call convert(words(1)%text, sets(first)%line, label, name, field, error, lower, adjust)
    end subroutine take_scalar

    !> Optional real variable `name` (one without a default, such as a law parameter):
    !> allocated with its value where an assignment among `sets` gives one; unallocated
    !> (not set) otherwise. Any value a user writes is a value, checked as such.
    subroutine take_optional(sets, label, name, field, error)
        type(assignment_type), intent(in) :: sets(:)
        character(len=*), intent(in) :: label, name
        real(wp), allocatable, intent(inout) :: field
        type(error_type), allocatable, intent(out) :: error
        type(string_type), allocatable :: words(:)
        real(wp) :: value
        integer :: k

        value = 0.0_wp
        call take_scalar(sets, label, name, value, error, .false., .false.)
        if (allocated(error)) return
        ! take_scalar found at most one assignment; a null value (`name = ,`) sets nothing.
        do k = 1, size(sets)
            if (sets(k)%name /= name) cycle
            call expand(sets(k), label, 1, words, error)
            if (allocated(error)) return
            if (size(words) == 0) return
            if (len(words(1)%text) > 0) field = value
        end do
    end subroutine take_optional

    !> An optional real as text for a message: its value, or 'not set'.
    function optional_text(value) result(text)
        real(wp), allocatable, intent(in) :: value
        character(len=:), allocatable :: text

        if (allocated(value)) then
            text = format_real(value)
        else
            text = 'not set'
        end if
    end function optional_text

    !> Array variable `name` of group `label` from its assignments among `sets`: `name =`
    !> sets the entries from 1 on, `name(i) =` from i on; the others stay as they are. A
    !> list (`most` entries at most, `field` as long as list_length says) may have null
    !> values beyond its last value.
    subroutine take_array(sets, label, name, field, error, lower, adjust, most)
        type(assignment_type), intent(in) :: sets(:)
        character(len=*), intent(in) :: label, name
        class(*), intent(inout) :: field(:)
        type(error_type), allocatable, intent(out) :: error
        logical, intent(in) :: lower, adjust
        integer, intent(in), optional :: most
        type(string_type), allocatable :: words(:)
        integer, allocatable :: owner(:)
        integer :: k, j, limit

        limit = size(field)
        if (present(most)) limit = most
        call map_entries(sets, label, name, limit, owner, error)
        do k = 1, size(sets)
            if (allocated(error)) return
            if (sets(k)%name /= name) cycle
            call expand(sets(k), label, limit, words, error)
            do j = 1, size(words)
                if (len(words(j)%text) == 0 .or. allocated(error)) cycle
                call convert(words(j)%text, sets(k)%line, label, name // '(' &
                    // format_integer(sets(k)%first + j - 1) // ')', &
                    field(sets(k)%first + j - 1), error, lower, adjust)
            end do
        end do
    end subroutine take_array

    !> `n`, the last entry of list `name` of group `label` that `sets` give a value (at
    !> most `most`); an error for an entry without a value before it.
    subroutine list_length(sets, label, name, most, n, error)
        type(assignment_type), intent(in) :: sets(:)
        character(len=*), intent(in) :: label, name
        integer, intent(in) :: most
        integer, intent(out) :: n
        type(error_type), allocatable, intent(out) :: error
        integer, allocatable :: owner(:)
        integer :: j

        call map_entries(sets, label, name, most, owner, error)
        n = 0
        if (allocated(error)) return
        n = findloc(owner > 0, .true., dim=1, back=.true.)
        j = findloc(owner(:n) > 0, .false., dim=1)
        if (j > 0) call fatal_error(error, label // ': ' // name // '(' // format_integer(j) &
            // ') has no value, but later entries have (an empty entry between commas?)')
    end subroutine list_length

    !> Whether an assignment among `sets` sets variable `name` (any of its entries).
    pure logical function is_assigned(sets, name)
        type(assignment_type), intent(in) :: sets(:)
        character(len=*), intent(in) :: name
        integer :: k

        is_assigned = any([(sets(k)%name == name, k = 1, size(sets))])
    end function is_assigned

    !> For each entry of array `name` (at most `most`) up to the last one its assignments
    !> reach, the assignment that sets it (negative for a null value, 0 for none); an
    !> error for an entry that two assignments set.
    subroutine map_entries(sets, label, name, most, owner, error)
        type(assignment_type), intent(in) :: sets(:)
        character(len=*), intent(in) :: label, name
        integer, intent(in) :: most
        integer, allocatable, intent(out) :: owner(:)
        type(error_type), allocatable, intent(out) :: error
        type(string_type), allocatable :: words(:)
        integer :: k, j, pass, n, i

        n = 0
        do pass = 1, 2
            if (pass == 2) allocate(owner(n), source=0)
            do k = 1, size(sets)
                if (sets(k)%name /= name) cycle
                if (sets(k)%first < 1 .or. sets(k)%first > most) then
                    call fatal_error(error, label // ': ' // assigned(sets(k)) // ' (line ' &
                        // format_integer(sets(k)%line) // '): the subscript is outside 1..' &
                        // format_integer(most) // ', the entries of ' // name)
                    return
                end if
                call expand(sets(k), label, min(most, sets(k)%last) - sets(k)%first + 1, words, &
                    error)
                if (allocated(error)) return
                n = max(n, sets(k)%first + size(words) - 1)
                if (pass == 1) cycle
                do j = 1, size(words)
                    i = sets(k)%first + j - 1
                    if (owner(i) /= 0) then
                        call fatal_error(error, label // ': ' // assigned(sets(k)) &
                            // ' (line ' // format_integer(sets(k)%line) // ') sets again ' &
                            // 'an entry that ' // assigned(sets(abs(owner(i)))) // ' (line ' &
                            // format_integer(sets(abs(owner(i)))%line) // ') sets; each ' &
                            // 'entry may be set only once')
                        return
                    end if
                    owner(i) = merge(k, -k, len(words(j)%text) > 0)
                end do
            end do
        end do
    end subroutine map_entries

    !> 'x' or 'x(i)', as the assignment writes it.
    pure function assigned(set) result(text)
        type(assignment_type), intent(in) :: set
        character(len=:), allocatable :: text

        text = set%name
        if (set%subscripted) text = text // '(' // format_integer(set%first) // ')'
    end function assigned

    !> The values of an assignment with repeat counts r*v written out (r*: r null values),
    !> at most `most` of them.
    subroutine expand(set, label, most, words, error)
        type(assignment_type), intent(in) :: set
        character(len=*), intent(in) :: label
        integer, intent(in) :: most
        type(string_type), allocatable, intent(out) :: words(:)
        type(error_type), allocatable, intent(out) :: error
        integer, allocatable :: repeats(:), skip(:)
        integer :: j, star, n
        logical :: ok

        allocate(repeats(size(set%values)), source=1)
        allocate(skip(size(set%values)), source=0)
        n = 0
        do j = 1, size(set%values)
            associate(word => set%values(j)%text)
                star = index(word, '*')
                if (star > 1) then
                    if (verify(word(:star - 1), '0123456789') == 0) then
                        skip(j) = star
                        call parse_integer(word(:star - 1), repeats(j), ok)
                        if (.not. ok .or. repeats(j) < 1) then
                            call fatal_error(error, label // ': ' // word // ' (line ' &
                                // format_integer(set%line) // ') in ' // set%name &
                                // ': a repeat count is a positive integer')
                            return
                        end if
                    end if
                end if
                if (repeats(j) > most - n) then
                    call fatal_error(error, label // ': ' // set%name // ' has more than ' &
                        // format_integer(most) // trim(merge(' value ', ' values', most == 1)) &
                        // ' (line ' // format_integer(set%line) &
                        // '): more values than ' // set%name // ' holds')
                    return
                end if
                n = n + repeats(j)
            end associate
        end do
        allocate(words(n))
        n = 0
        do j = 1, size(set%values)
            words(n + 1:n + repeats(j)) = string_type(set%values(j)%text(skip(j) + 1:))
            n = n + repeats(j)
        end do
    end subroutine expand

    !> The value word `word` (of `variable`, assigned on `line`) into `field`.
    subroutine convert(word, line, label, variable, field, error, lower, adjust)
        character(len=*), intent(in) :: word, label, variable
        integer, intent(in) :: line
        class(*), intent(inout) :: field
        type(error_type), allocatable, intent(out) :: error
        logical, intent(in) :: lower, adjust
        character(len=:), allocatable :: text, expected
        logical :: ok

        text = to_lower(word)
        ok = .false.
        expected = ''
        select type (field)
        type is (real(wp))
            call parse_real(word, field, ok)
            expected = 'a real number is expected'
        type is (integer)
            call parse_integer(word, field, ok)
            expected = 'an integer is expected'
        type is (logical)
            if (text(1:1) == '.') text = text(2:)
            ok = any(text == [character(len=6) :: 't', 'f', 'true', 'false', 't.', 'f.', &
                'true.', 'false.'])
            if (ok) field = text(1:1) == 't'
            expected = 'a logical is expected: .true. or .false.'
        type is (character(len=*))
            ok = len(word) >= 2 .and. scan(word(1:1), "'""") == 1
            if (ok) ok = word(len(word):) == word(1:1)
            expected = "a character value is expected, in quotes: 'text'"
            if (ok) then
                text = unquoted(word(2:len(word) - 1), word(1:1))
                if (adjust) text = adjustl(text)
                if (len_trim(text) > len(field)) then
                    call fatal_error(error, label // ': ' // variable // " = '" &
                        // text(:min(len_trim(text), 40)) // "...' is longer than " &
                        // format_integer(len(field)) // ' characters (line ' &
                        // format_integer(line) // ')')
                    return
                end if
                if (lower) text = to_lower(text)
                field = text
            end if
        end select
        if (.not. ok) call fatal_error(error, label // ': ' // word &
            // ' is not a valid value of ' // variable // ' (line ' // format_integer(line) &
            // ': ' // expected // ')')
    end subroutine convert

    !> The text of a character value between its quotes, doubled quotes made single.
    pure function unquoted(inner, quote) result(text)
        character(len=*), intent(in) :: inner, quote
        character(len=:), allocatable :: text
        integer :: i, n

        allocate(character(len=len(inner)) :: text)
        n = 0
        i = 1
        do while (i <= len(inner))
            n = n + 1
            text(n:n) = inner(i:i)
            if (inner(i:i) == quote) i = i + 1
            i = i + 1
        end do
        text = text(:n)
    end function unquoted

    !> A real or integer `value` that must lie where `inside` says (`rule`, from the
    !> description, says where: 'must be >= 0'); a real must also be finite.
    subroutine check_range(error, label, variable, value, inside, rule)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable, rule
        class(*), intent(in) :: value
        logical, intent(in) :: inside
        character(len=:), allocatable :: text

        select type (value)
        type is (integer)
            text = format_integer(value)
        type is (real(wp))
            text = format_real(value)
            if (.not. ieee_is_finite(value)) then
                call fatal_error(error, label // ': ' // variable // ' = ' // text &
                    // ' is not finite')
                return
            end if
        end select
        if (.not. inside) call fatal_error(error, label // ': ' // variable // ' = ' // text &
            // ' ' // rule)
    end subroutine check_range

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

    !> A value no longer offered (variables.py `retired`): refused with `advice` (what to
    !> use instead), not as unknown, so that an old input says what changed.
    subroutine check_retired(error, label, variable, value, retired, advice)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable, value, retired, advice

        if (value /= retired) return
        call fatal_error(error, label // ': ' // variable // " = '" // retired &
            // "' is no longer offered: " // trim(advice))
    end subroutine check_retired

    !> Parameter `variable` of a law: needed by the selected law `law` and then to be set,
    !> or not used by it and then not to be set; `text` is its value for the message.
    subroutine check_law_parameter(error, label, variable, is_set, text, law, needed)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable, text, law
        logical, intent(in) :: is_set, needed

        if (needed .and. .not. is_set) then
            call fatal_error(error, label // ': ' // variable // " is not set (law '" // law &
                // "' needs it)")
        else if (is_set .and. .not. needed) then
            call fatal_error(error, label // ': ' // variable // ' = ' // text &
                // " is not used by law '" // law // "' (remove it)")
        end if
    end subroutine check_law_parameter

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

    !> The name of item k of a group of named items (`labels`: their '&group #i'): set
    !> (else "<label>: name is empty" and `hint`), one word, and not that of an earlier
    !> item ("&group: name = 'x' is <twice> twice (<label i> and <label k><note>)", '#k'
    !> alone for an item of the same group).
    subroutine check_item_name(error, names, labels, k, hint, twice, note)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: names(:), labels(:), hint, twice, note
        integer, intent(in) :: k
        character(len=:), allocatable :: group, second
        integer :: other

        if (len_trim(names(k)) == 0) then
            call fatal_error(error, trim(labels(k)) // ': name is empty' // hint)
            return
        end if
        call check_name(error, trim(labels(k)), names(k))
        if (allocated(error)) return
        group = labels(k)(:index(labels(k), ' #') - 1)
        do other = 1, k - 1
            if (names(other) /= names(k)) cycle
            second = trim(labels(k))
            if (labels(other)(:index(labels(other), ' #') - 1) == group) &
                second = second(len(group) + 2:)
            call fatal_error(error, group // ": name = '" // trim(names(k)) // "' is " &
                // twice // ' twice (' // trim(labels(other)) // ' and ' // second // note &
                // ')')
            return
        end do
    end subroutine check_item_name

    !> Write one line. A failed write does not stop the program: the caller that needs
    !> the file whole checks it when closing it (yarnfort_output_filesystem compares its
    !> size on disk with what was written).
    subroutine put(unit, line)
        integer, intent(in) :: unit
        character(len=*), intent(in) :: line
        integer :: status

        write(unit, '(a)', iostat=status) line
    end subroutine put

    !> `name = v1 v2 ...` (integers or reals), integers_per_line or reals_per_line values
    !> per line; nothing for no values.
    subroutine put_list(unit, name, values)
        integer, intent(in) :: unit
        character(len=*), intent(in) :: name
        class(*), intent(in) :: values(:)
        character(len=:), allocatable :: line
        integer :: i, per_line

        line = indent // name // ' ='
        per_line = integers_per_line
        do i = 1, size(values)
            select type (values)
            type is (integer)
                line = line // ' ' // format_integer(values(i))
                per_line = integers_per_line
            type is (real(wp))
                line = line // ' ' // format_real(values(i))
                per_line = reals_per_line
            end select
            if (mod(i, per_line) == 0 .or. i == size(values)) then
                call put(unit, line)
                line = indent // repeat(' ', len(name) + 2)
            end if
        end do
    end subroutine put_list

end module yarnfort_input_fields
