! SPDX-License-Identifier: MIT
!> The tokenizer of namelist input text: finds every '&group ... /' occurrence with its
!> lines and tokens (names before '=', values, null values between two commas), and
!> rejects what is not namelist syntax (unknown or misspelt group names, text outside
!> groups, a group not closed with '/', a character value not closed on its line).
!> `get_assignments` gives a group's assignments, each variable checked against the
!> group's names. Values are converted (and entries set twice found) by
!> yarnfort_input_fields.
module yarnfort_input_scan
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: string_type, read_line, to_lower, format_integer, &
        closest_name, join_names, drop_byte_order_mark, parse_integer, remove_characters
    implicit none
    private

    public :: namelist_scan_type, scan_namelist, assignment_type, get_assignments
    public :: group_label

    !> A word of a group's text: a variable name (followed by '=') or a value (empty,
    !> last < first, for a null value).
    type :: token_type
        integer :: line = 0
        !> Columns of the token on its line.
        integer :: first = 0, last = 0
        !> Followed by '=': a variable name, possibly with a subscript.
        logical :: is_name = .false.
    end type token_type

    !> One '&name ... /' group in the text, with the range of its tokens in the scan's.
    type :: group_occurrence_type
        character(len=:), allocatable :: name
        integer :: first_line = 0
        integer :: first_token = 1, last_token = 0
    end type group_occurrence_type

    !> The text and its groups, in the order of the text.
    type :: namelist_scan_type
        type(string_type), allocatable :: lines(:)
        type(group_occurrence_type), allocatable :: groups(:)
        integer :: n_groups = 0
        !> The tokens of all groups, in the order of the text.
        type(token_type), allocatable :: tokens(:)
    contains
        !> Number of occurrences of a group.
        procedure :: count_group
        !> Index in `groups` of the k-th occurrence (k >= 1) of a group (0 if there is none).
        procedure :: find_group
        !> Text of a token.
        procedure :: token_text
    end type namelist_scan_type

    !> One assignment `name = values` or `name(first) = values` of a group occurrence.
    type :: assignment_type
        !> Variable name in lower case, without subscript.
        character(len=:), allocatable :: name
        !> The subscript or section first:last (1 and no limit for none).
        integer :: first = 1, last = huge(1)
        logical :: subscripted = .false.
        integer :: line = 0
        !> The value words as written (repeat counts r*v kept; '' for a null value).
        type(string_type), allocatable :: values(:)
    end type assignment_type

    character(len=1), parameter :: tab = achar(9), carriage_return = achar(13)
    character(len=*), parameter :: name_characters = &
        'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_'
    !> Characters that end a bare (unquoted) word inside a group.
    character(len=*), parameter :: word_ends = " ,;=/!&$'""" // tab // carriage_return

contains

    !> Read the rest of the text of `unit` and find its groups. `known_groups` are the
    !> valid group names in lower case; `where` starts a message on a line of the text.
    subroutine scan_namelist(unit, where, known_groups, scan, error)
        integer, intent(in) :: unit
        character(len=*), intent(in) :: where
        character(len=*), intent(in) :: known_groups(:)
        type(namelist_scan_type), intent(out) :: scan
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: line
        character(len=512) :: message
        integer :: stat, n_lines
        type(string_type), allocatable :: grown(:)

        allocate(scan%lines(64))
        n_lines = 0
        do
            call read_line(unit, line, stat, message)
            if (is_iostat_end(stat)) exit
            if (stat /= 0) then
                call fatal_error(error, trim(where) // ' ' // format_integer(n_lines + 1) &
                    // ': ' // trim(message))
                return
            end if
            if (n_lines == size(scan%lines)) then
                allocate(grown(2 * n_lines))
                grown(:n_lines) = scan%lines
                call move_alloc(grown, scan%lines)
            end if
            n_lines = n_lines + 1
            if (n_lines == 1) call drop_byte_order_mark(line)
            call move_alloc(line, scan%lines(n_lines)%text)
        end do
        scan%lines = scan%lines(:n_lines)
        call find_groups(scan, known_groups, error)
    end subroutine scan_namelist

    subroutine find_groups(scan, known_groups, error)
        type(namelist_scan_type), intent(inout) :: scan
        character(len=*), intent(in) :: known_groups(:)
        type(error_type), allocatable, intent(out) :: error
        logical :: in_group, after_comma
        character(len=1) :: c
        character(len=:), allocatable :: name, hint
        integer :: iline, i, j, k, depth, n_tokens

        allocate(scan%groups(16), scan%tokens(64))
        n_tokens = 0
        in_group = .false.
        after_comma = .false.
        do iline = 1, size(scan%lines)
            associate(text => scan%lines(iline)%text)
                i = 1
                do while (i <= len(text))
                    c = text(i:i)
                    if (.not. in_group) then
                        select case (c)
                        case (' ', tab, carriage_return)
                            i = i + 1
                        case ('!')
                            exit
                        case ('&', '$')
                            call read_name(text, i + 1, j, name)
                            if (len(name) == 0) then
                                call fail(": '" // c // "' is not followed by a group name")
                            else if (name == 'end') then
                                call fail(': ' // c // 'end outside a group')
                            else if (.not. any(known_groups == name)) then
                                hint = closest_name(text(i + 1:j - 1), known_groups)
                                if (len(hint) > 0) then
                                    hint = ' (did you mean &' // hint // '?)'
                                else
                                    hint = ' (known groups: ' // join_names(known_groups, '&') &
                                        // ')'
                                end if
                                call fatal_error(error, 'unknown group &' // text(i + 1:j - 1) &
                                    // ' on line ' // format_integer(iline) // hint)
                            end if
                            if (allocated(error)) return
                            call start_group()
                            i = j
                        case default
                            call fail(": text outside a group: '" // shorten(text(i:)) &
                                // "' (a group starts with &name and ends with /; " &
                                // 'comments start with !)')
                            return
                        end select
                        cycle
                    end if
                    ! In a group.
                    if (c /= ',' .and. index(' ;!' // tab // carriage_return, c) == 0) &
                        after_comma = .false.
                    select case (c)
                    case (',')
                        ! Two commas with nothing but blanks between: a null value.
                        if (after_comma) call add_token(i, i - 1)
                        after_comma = .true.
                        i = i + 1
                    case (' ', tab, carriage_return, ';')
                        i = i + 1
                    case ('!')
                        exit
                    case ("'", '"')
                        ! To the closing quote (a doubled one is a quote of the value).
                        j = i + 1
                        do
                            k = index(text(j:), c)
                            if (k == 0) then
                                call add_token(i, len(text))
                                call fail(': character value not closed with ' // c &
                                    // ' on its line: ' // open_value())
                                return
                            end if
                            j = j + k
                            if (j > len(text)) exit
                            if (text(j:j) /= c) exit
                            j = j + 1
                        end do
                        call add_token(i, j - 1)
                        i = j
                    case ('=')
                        call mark_name()
                        if (allocated(error)) return
                        ! A comma right after '=' follows a null value too.
                        after_comma = .true.
                        i = i + 1
                    case ('/', '&', '$')
                        ! '/' or '&end' ends the group; another '&' is an error.
                        name = 'end'
                        j = i + 1
                        if (c /= '/') call read_name(text, i + 1, j, name)
                        associate(group => scan%groups(scan%n_groups))
                            if (len(name) == 0) then
                                call fail(": stray '" // c // "' in &" // group%name)
                            else if (name /= 'end') then
                                call fail(': ' // text(i:j - 1) // ' starts before &' &
                                    // group%name // ' (line ' &
                                    // format_integer(group%first_line) // ") is closed with '/'")
                            end if
                        end associate
                        if (allocated(error)) return
                        in_group = .false.
                        i = j
                    case default
                        ! A bare word; a subscript in parentheses may contain blanks.
                        j = i
                        depth = 0
                        do while (j <= len(text))
                            if (text(j:j) == '(') depth = depth + 1
                            if (text(j:j) == ')') depth = max(depth - 1, 0)
                            if (depth == 0 .and. index(word_ends, text(j:j)) > 0) exit
                            j = j + 1
                        end do
                        call add_token(i, j - 1)
                        i = j
                    end select
                end do
            end associate
        end do
        if (in_group) then
            associate(group => scan%groups(scan%n_groups))
                call fatal_error(error, '&' // group%name // ' (line ' &
                    // format_integer(group%first_line) // ") is not closed with '/'")
            end associate
        end if
        scan%groups = scan%groups(:scan%n_groups)
        scan%tokens = scan%tokens(:n_tokens)

    contains

        !> An error on the line being read.
        subroutine fail(text)
            character(len=*), intent(in) :: text

            call fatal_error(error, 'line ' // format_integer(iline) // text)
        end subroutine fail

        subroutine start_group()
            type(group_occurrence_type), allocatable :: more(:)

            if (scan%n_groups == size(scan%groups)) then
                allocate(more(2 * scan%n_groups))
                more(:scan%n_groups) = scan%groups
                call move_alloc(more, scan%groups)
            end if
            scan%n_groups = scan%n_groups + 1
            scan%groups(scan%n_groups) = group_occurrence_type(name, iline, n_tokens + 1, &
                n_tokens)
            in_group = .true.
        end subroutine start_group

        subroutine add_token(first, last)
            integer, intent(in) :: first, last
            type(token_type), allocatable :: more(:)

            if (n_tokens == size(scan%tokens)) then
                allocate(more(2 * n_tokens))
                more(:n_tokens) = scan%tokens
                call move_alloc(more, scan%tokens)
            end if
            n_tokens = n_tokens + 1
            scan%tokens(n_tokens) = token_type(iline, first, last, .false.)
            scan%groups(scan%n_groups)%last_token = n_tokens
        end subroutine add_token

        !> The token before '=' is a variable name: a word of this group, not a value in
        !> quotes, not a null value, not already a name.
        subroutine mark_name()
            logical :: ok

            ok = n_tokens >= scan%groups(scan%n_groups)%first_token
            if (ok) then
                associate(last => scan%tokens(n_tokens))
                    ok = .not. last%is_name .and. last%last >= last%first .and. &
                        index("'""", scan%lines(last%line)%text(last%first:last%first)) == 0
                    last%is_name = ok
                end associate
            end if
            if (.not. ok) call fail(": '=' without a variable name before it in &" &
                // scan%groups(scan%n_groups)%name)
        end subroutine mark_name

        !> The group, the variable and the start of the character value being read:
        !> "&control title = 'see &yarn..." (the variable is the last name before it).
        function open_value() result(text)
            character(len=:), allocatable :: text
            integer :: k

            text = '&' // scan%groups(scan%n_groups)%name
            do k = n_tokens - 1, scan%groups(scan%n_groups)%first_token, -1
                if (scan%tokens(k)%is_name) then
                    text = text // ' ' // scan%token_text(scan%tokens(k)) // ' ='
                    exit
                end if
            end do
            text = text // ' ' // shorten(scan%lines(iline)%text(scan%tokens(n_tokens)%first:))
        end function open_value

    end subroutine find_groups

    !> The name (letters, digits, '_') starting at column `first`, in lower case; `next`
    !> is the column after it.
    pure subroutine read_name(text, first, next, name)
        character(len=*), intent(in) :: text
        integer, intent(in) :: first
        integer, intent(out) :: next
        character(len=:), allocatable, intent(out) :: name

        next = first
        do while (next <= len(text))
            if (index(name_characters, text(next:next)) == 0) exit
            next = next + 1
        end do
        name = to_lower(text(first:next - 1))
    end subroutine read_name

    !> At most 40 characters of a text for a message.
    pure function shorten(text) result(short)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: short
        integer, parameter :: max_length = 40

        if (len_trim(text) > max_length) then
            short = text(:max_length) // '...'
        else
            short = trim(text)
        end if
    end function shorten

    pure function count_group(self, name) result(n)
        class(namelist_scan_type), intent(in) :: self
        character(len=*), intent(in) :: name
        integer :: n, k

        n = count([(self%groups(k)%name == name, k = 1, self%n_groups)])
    end function count_group

    pure function find_group(self, name, occurrence) result(index)
        class(namelist_scan_type), intent(in) :: self
        character(len=*), intent(in) :: name
        integer, intent(in) :: occurrence
        integer :: index, n

        n = 0
        do index = 1, self%n_groups
            if (self%groups(index)%name == name) n = n + 1
            if (n == occurrence) return
        end do
        index = 0
    end function find_group

    !> The assignments of the `occurrence`-th group `name` (1 for a singleton), in text
    !> order. An error for a value before the first name, a variable not in `variables`
    !> (with the closest one), a known variable name among the values (a missing '='),
    !> and a subscript that is not one integer.
    subroutine get_assignments(scan, name, occurrence, variables, sets, error)
        type(namelist_scan_type), intent(in) :: scan
        character(len=*), intent(in) :: name
        integer, intent(in) :: occurrence
        character(len=*), intent(in) :: variables(:)
        type(assignment_type), allocatable, intent(out) :: sets(:)
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: text, label, guess
        integer :: k, n, m, g, paren
        logical :: ok

        label = group_label(name, occurrence)
        g = scan%find_group(name, max(occurrence, 1))
        associate(tokens => scan%tokens(scan%groups(g)%first_token:scan%groups(g)%last_token))
            allocate(sets(count(tokens%is_name)))
            n = 0
            do k = 1, size(tokens)
                text = scan%token_text(tokens(k))
                if (tokens(k)%is_name) then
                    n = n + 1
                    sets(n)%line = tokens(k)%line
                    ! Its values: the tokens up to the next name.
                    allocate(sets(n)%values(findloc([tokens(k + 1:)%is_name, .true.], .true., &
                        dim=1) - 1))
                    m = 0
                    ! The name in lower case without blanks, then without its subscript.
                    sets(n)%name = to_lower(remove_characters(text, ' ' // tab))
                    paren = index(sets(n)%name, '(')
                    sets(n)%subscripted = paren > 0
                    if (paren > 0) then
                        call read_subscript(sets(n)%name(paren:), sets(n), ok)
                        if (.not. ok) then
                            call fatal_error(error, label // ': ' // sets(n)%name // ' (line ' &
                                // format_integer(sets(n)%line) // '): a subscript is an ' &
                                // 'integer or a section, as in ' // sets(n)%name(:paren - 1) &
                                // '(2) or ' // sets(n)%name(:paren - 1) // '(2:3)')
                            return
                        end if
                        sets(n)%name = sets(n)%name(:paren - 1)
                    end if
                    if (.not. any(variables == sets(n)%name)) then
                        guess = closest_name(sets(n)%name, variables)
                        if (len(guess) > 0) then
                            guess = ', did you mean ' // guess // '?'
                        else
                            guess = '; &' // name // ' has ' // join_names(variables, '')
                        end if
                        call fatal_error(error, label // ': unknown variable ' &
                            // sets(n)%name // ' (line ' // format_integer(sets(n)%line) &
                            // ')' // guess)
                        return
                    end if
                else if (n == 0) then
                    call fatal_error(error, label // ' (line ' // format_integer(tokens(k)%line) &
                        // '): value ' // text // ' before any variable name')
                    return
                else if (any(variables == to_lower(text))) then
                    call fatal_error(error, label // ": '=' must follow the variable name " &
                        // text // ' (line ' // format_integer(tokens(k)%line) // ': ' &
                        // shorten(adjustl(scan%lines(tokens(k)%line)%text)) // ')')
                    return
                else
                    m = m + 1
                    sets(n)%values(m)%text = text
                end if
            end do
        end associate
    end subroutine get_assignments

    !> '(i)', '(i:j)', '(i:)' or '(:j)' into the entries an assignment starts at and may
    !> reach; `ok` is false for another form.
    pure subroutine read_subscript(text, set, ok)
        character(len=*), intent(in) :: text
        type(assignment_type), intent(inout) :: set
        logical, intent(out) :: ok
        integer :: colon

        ok = text(len(text):) == ')'
        if (.not. ok) return
        colon = index(text, ':')
        if (colon == 0) then
            call parse_integer(text(2:len(text) - 1), set%first, ok)
            return
        end if
        if (colon > 2) call parse_integer(text(2:colon - 1), set%first, ok)
        if (ok .and. colon < len(text) - 1) call parse_integer(text(colon + 1:len(text) - 1), &
            set%last, ok)
    end subroutine read_subscript

    pure function token_text(self, token) result(text)
        class(namelist_scan_type), intent(in) :: self
        type(token_type), intent(in) :: token
        character(len=:), allocatable :: text

        text = self%lines(token%line)%text(token%first:token%last)
    end function token_text

    !> '&name' for a singleton (occurrence 0), '&name #k' for the k-th of a repeatable.
    pure function group_label(name, occurrence) result(label)
        character(len=*), intent(in) :: name
        integer, intent(in) :: occurrence
        character(len=:), allocatable :: label

        label = '&' // name
        if (occurrence > 0) label = label // ' #' // format_integer(occurrence)
    end function group_label

end module yarnfort_input_scan
