! SPDX-License-Identifier: MIT
!> A reader for the subset of XML that TexGen's model files (.tg3) use: nested elements
!> with attributes. Text content, comments, processing instructions (<?...?>),
!> declarations (<!...>) and CDATA sections are skipped; the five predefined entities and
!> numeric character references below 128 are decoded in attribute values. The whole file
!> becomes a flat list of elements, each with its parent, queried by name. Reading takes
!> time linear in the file's size; a tag with more attributes, or an attribute name or
!> value longer, than the limits below is an error (docs/decisions.md, "XML reader of
!> TexGen files").
!>
!> Neither Debian nor PyPI offers a maintained XML library for Fortran, and the program
!> must read the file without Python, so this is the one XML reader of the project.
module yarnfort_generate_xml_subset
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: read_file_text, format_integer
    implicit none
    private

    public :: xml_document_type, read_xml_file, parse_xml
    public :: max_attributes, max_attribute_length

    !> Most attributes one tag may have: TexGen writes at most about 50 (its <Textile>).
    integer, parameter :: max_attributes = 1000
    !> Longest attribute name or value (characters, as written): TexGen's longest are
    !> vectors of three numbers, about 60 characters.
    integer, parameter :: max_attribute_length = 2**20

    type :: xml_text_type
        character(len=:), allocatable :: text
    end type xml_text_type

    type :: xml_element_type
        character(len=:), allocatable :: name
        !> Index of the enclosing element (0 for the root).
        integer :: parent = 0
        !> The first element directly inside this one, and the next one inside its parent
        !> (0: none), so that children are found in time linear in their number.
        integer :: first_child = 0, next_sibling = 0
        type(xml_text_type), allocatable :: attribute_names(:), attribute_values(:)
    end type xml_element_type

    type :: xml_document_type
        integer :: n_elements = 0
        type(xml_element_type), allocatable :: elements(:)
        !> The first top-level element (0: none).
        integer :: first_root = 0
    contains
        !> Indices of the elements named `name` directly inside `parent` (0: the top level).
        procedure :: children
        !> The value of attribute `name` of element `element`; `found` false if absent.
        procedure :: attribute
    end type xml_document_type

contains

    !> Read and parse file `path` (errors do not repeat its name).
    subroutine read_xml_file(path, document, error)
        character(len=*), intent(in) :: path
        type(xml_document_type), intent(out) :: document
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: text

        call read_file_text(path, 'it', text, error)
        if (allocated(error)) return
        call parse_xml(text, document, error)
    end subroutine read_xml_file

    !> Parse XML text into `document`; an error names the line and what was wrong.
    subroutine parse_xml(text, document, error)
        character(len=*), intent(in) :: text
        type(xml_document_type), intent(out) :: document
        type(error_type), allocatable, intent(out) :: error
        integer :: i, n, close_at, current, depth
        character(len=:), allocatable :: name
        logical :: self_closing

        allocate(document%elements(64))
        n = len(text)
        i = 1
        current = 0
        depth = 0
        do while (i <= n)
            if (text(i:i) /= '<') then
                i = i + 1
                cycle
            end if
            if (starts(i, '<!--')) then
                if (.not. closed_by(4, '-->', 'a comment is not closed (-->)')) return
                i = close_at + 3
            else if (starts(i, '<![CDATA[')) then
                if (.not. closed_by(9, ']]>', 'a CDATA section is not closed (]]>)')) return
                i = close_at + 3
            else if (starts(i, '<?') .or. starts(i, '<!')) then
                if (.not. closed_by(2, '>', "a declaration is not closed ('>')")) return
                i = close_at + 1
            else if (starts(i, '</')) then
                if (.not. closed_by(2, '>', "a closing tag is not closed ('>')")) return
                name = trim(adjustl(text(i + 2:close_at - 1)))
                if (current == 0) then
                    call fail(i, "closing tag </" // shown(name) // "> without an open element")
                    return
                end if
                if (name /= document%elements(current)%name) then
                    call fail(i, "closing tag </" // shown(name) // "> does not match <" &
                        // shown(document%elements(current)%name) // ">")
                    return
                end if
                current = document%elements(current)%parent
                depth = depth - 1
                i = close_at + 1
            else
                call read_tag(i, close_at, self_closing)
                if (allocated(error)) return
                if (.not. self_closing) then
                    current = document%n_elements
                    depth = depth + 1
                end if
                i = close_at + 1
            end if
        end do
        if (current /= 0) then
            call fatal_error(error, 'the file ends inside element <' &
                // shown(document%elements(current)%name) // '> (not closed)')
            return
        end if
        if (document%n_elements == 0) call fail(1, 'no elements (not an XML file?)')
    contains
        !> Whether `closer` follows text(i + skip); close_at: where. An error if not.
        logical function closed_by(skip, closer, what)
            integer, intent(in) :: skip
            character(len=*), intent(in) :: closer, what
            close_at = find_from(i + skip, closer)
            closed_by = close_at /= 0
            if (.not. closed_by) call fail(i, what)
        end function closed_by

        !> Move j past blanks.
        subroutine skip_blanks(j)
            integer, intent(inout) :: j
            do while (j <= n)
                if (.not. is_blank(text(j:j))) exit
                j = j + 1
            end do
        end subroutine skip_blanks

        logical function starts(at, prefix)
            integer, intent(in) :: at
            character(len=*), intent(in) :: prefix
            starts = .false.
            if (at + len(prefix) - 1 <= n) starts = text(at:at + len(prefix) - 1) == prefix
        end function starts

        integer function find_from(at, what)
            integer, intent(in) :: at
            character(len=*), intent(in) :: what
            find_from = 0
            if (at > n) return
            find_from = index(text(at:), what)
            if (find_from > 0) find_from = find_from + at - 1
        end function find_from

        subroutine fail(at, what)
            integer, intent(in) :: at
            character(len=*), intent(in) :: what
            character(len=20) :: line
            integer :: k, lines
            lines = 1
            do k = 1, min(at, n)
                if (text(k:k) == new_line('a')) lines = lines + 1
            end do
            write(line, '(i0)') lines
            call fatal_error(error, 'line ' // trim(line) // ': ' // what)
        end subroutine fail

        !> An opening tag from text(at) = '<': name and attributes; close_at: its '>'.
        subroutine read_tag(at, close_at, self_closing)
            integer, intent(in) :: at
            integer, intent(out) :: close_at
            logical, intent(out) :: self_closing
            type(xml_element_type) :: element
            type(xml_text_type), allocatable :: names(:), values(:)
            integer :: j, name_start, value_end, count
            character(len=1) :: quote
            character(len=:), allocatable :: attribute_name

            j = at + 1
            name_start = j
            do while (j <= n)
                if (is_name_end(text(j:j))) exit
                j = j + 1
            end do
            if (j == name_start .or. j > n) then
                call fail(at, 'a tag without a name or not closed')
                return
            end if
            element%name = text(name_start:j - 1)
            element%parent = current
            allocate(names(8), values(8))
            count = 0
            self_closing = .false.
            do
                call skip_blanks(j)
                if (j > n) then
                    call fail(at, "tag <" // shown(element%name) // " is not closed ('>')")
                    return
                end if
                if (text(j:j) == '>') exit
                if (starts(j, '/>')) then
                    self_closing = .true.
                    j = j + 1
                    exit
                end if
                name_start = j
                do while (j <= n)
                    if (is_name_end(text(j:j)) .or. text(j:j) == '=') exit
                    j = j + 1
                end do
                if (j - name_start > max_attribute_length) then
                    call fail(at, "tag <" // shown(element%name) // ">: the name of an " &
                        // "attribute is longer than " // format_integer(max_attribute_length) &
                        // " characters (the limit of this reader)")
                    return
                end if
                attribute_name = text(name_start:j - 1)
                call skip_blanks(j)
                if (len(attribute_name) == 0 .or. j >= n .or. text(j:j) /= '=') then
                    call fail(at, "tag <" // shown(element%name) &
                        // ">: an attribute without '=value'")
                    return
                end if
                j = j + 1
                call skip_blanks(j)
                quote = ' '
                if (j <= n) quote = text(j:j)
                if (quote /= '"' .and. quote /= "'") then
                    call fail(at, "tag <" // shown(element%name) // ">: attribute " &
                        // shown(attribute_name) // " has no quoted value")
                    return
                end if
                value_end = find_from(j + 1, quote)
                if (value_end == 0) then
                    call fail(at, "tag <" // shown(element%name) // ">: the value of attribute " &
                        // shown(attribute_name) // " is not closed")
                    return
                end if
                if (value_end - j - 1 > max_attribute_length) then
                    call fail(at, "tag <" // shown(element%name) // ">: the value of attribute " &
                        // shown(attribute_name) // " is longer than " &
                        // format_integer(max_attribute_length) &
                        // " characters (the limit of this reader)")
                    return
                end if
                if (count == max_attributes) then
                    call fail(at, "tag <" // shown(element%name) // "> has more than " &
                        // format_integer(max_attributes) &
                        // " attributes (the limit of this reader)")
                    return
                end if
                if (count == size(names)) call grow(names, values)
                count = count + 1
                call move_alloc(attribute_name, names(count)%text)
                values(count)%text = decode(text(j + 1:value_end - 1))
                j = value_end + 1
            end do
            close_at = j
            allocate(element%attribute_names(count), element%attribute_values(count))
            do j = 1, count
                call move_alloc(names(j)%text, element%attribute_names(j)%text)
                call move_alloc(values(j)%text, element%attribute_values(j)%text)
            end do
            call add_element(document, element)
        end subroutine read_tag
    end subroutine parse_xml

    subroutine add_element(document, element)
        type(xml_document_type), intent(inout) :: document
        type(xml_element_type), intent(inout) :: element
        type(xml_element_type), allocatable :: grown(:)
        integer :: k

        if (document%n_elements == size(document%elements)) then
            allocate(grown(2 * size(document%elements)))
            do k = 1, document%n_elements
                call move_alloc_element(document%elements(k), grown(k))
            end do
            call move_alloc(grown, document%elements)
        end if
        document%n_elements = document%n_elements + 1
        associate(new => document%elements(document%n_elements))
            call move_alloc_element(element, new)
            ! Prepended to its parent's list: children() reverses it.
            if (new%parent == 0) then
                new%next_sibling = document%first_root
                document%first_root = document%n_elements
            else
                new%next_sibling = document%elements(new%parent)%first_child
                document%elements(new%parent)%first_child = document%n_elements
            end if
        end associate
    end subroutine add_element

    subroutine move_alloc_element(from, to)
        type(xml_element_type), intent(inout) :: from
        type(xml_element_type), intent(out) :: to
        call move_alloc(from%name, to%name)
        to%parent = from%parent
        to%first_child = from%first_child
        to%next_sibling = from%next_sibling
        call move_alloc(from%attribute_names, to%attribute_names)
        call move_alloc(from%attribute_values, to%attribute_values)
    end subroutine move_alloc_element

    !> Twice the room for attribute names and values (geometric growth: linear time).
    subroutine grow(names, values)
        type(xml_text_type), allocatable, intent(inout) :: names(:), values(:)
        type(xml_text_type), allocatable :: grown_names(:), grown_values(:)
        integer :: k

        allocate(grown_names(2 * size(names)), grown_values(2 * size(names)))
        do k = 1, size(names)
            call move_alloc(names(k)%text, grown_names(k)%text)
            call move_alloc(values(k)%text, grown_values(k)%text)
        end do
        call move_alloc(grown_names, names)
        call move_alloc(grown_values, values)
    end subroutine grow

    !> A name as shown in a message: at most 40 characters of it.
    pure function shown(name) result(text)
        character(len=*), intent(in) :: name
        character(len=:), allocatable :: text
        integer, parameter :: longest = 40

        if (len(name) <= longest) then
            text = name
        else
            text = name(:longest) // '...'
        end if
    end function shown

    pure logical function is_blank(c)
        character(len=1), intent(in) :: c
        is_blank = c == ' ' .or. c == achar(9) .or. c == achar(10) .or. c == achar(13)
    end function is_blank

    pure logical function is_name_end(c)
        character(len=1), intent(in) :: c
        is_name_end = is_blank(c) .or. c == '>' .or. c == '/'
    end function is_name_end

    !> Attribute text with the predefined entities and &#N; / &#xN; (N < 128) decoded;
    !> anything else is kept as it is. Written into one buffer (never longer than the raw
    !> text): linear time.
    pure function decode(raw) result(value)
        character(len=*), intent(in) :: raw
        character(len=:), allocatable :: value
        character(len=len(raw)) :: buffer
        integer :: i, m, semicolon, code, stat, amp

        m = 0
        i = 1
        do while (i <= len(raw))
            amp = index(raw(i:), '&')
            if (amp == 0) then
                buffer(m + 1:m + len(raw) - i + 1) = raw(i:)
                m = m + len(raw) - i + 1
                exit
            end if
            buffer(m + 1:m + amp - 1) = raw(i:i + amp - 2)
            m = m + amp - 1
            i = i + amp - 1
            ! raw(i:i) is '&': an entity ends at a ';' within 8 characters.
            semicolon = index(raw(i:min(i + 7, len(raw))), ';')
            if (semicolon == 0) then
                m = m + 1
                buffer(m:m) = '&'
                i = i + 1
                cycle
            end if
            m = m + 1
            select case (raw(i:i + semicolon - 1))
            case ('&lt;')
                buffer(m:m) = '<'
            case ('&gt;')
                buffer(m:m) = '>'
            case ('&amp;')
                buffer(m:m) = '&'
            case ('&quot;')
                buffer(m:m) = '"'
            case ('&apos;')
                buffer(m:m) = "'"
            case default
                stat = 1
                code = -1
                if (semicolon > 3 .and. raw(i + 1:i + 1) == '#') then
                    if (raw(i + 2:i + 2) == 'x' .or. raw(i + 2:i + 2) == 'X') then
                        read(raw(i + 3:i + semicolon - 2), '(z8)', iostat=stat) code
                    else
                        read(raw(i + 2:i + semicolon - 2), *, iostat=stat) code
                    end if
                end if
                if (stat == 0 .and. code >= 0 .and. code < 128) then
                    buffer(m:m) = achar(code)
                else
                    buffer(m:m + semicolon - 1) = raw(i:i + semicolon - 1)
                    m = m + semicolon - 1
                end if
            end select
            i = i + semicolon
        end do
        value = buffer(:m)
    end function decode

    function children(self, parent, name) result(found)
        class(xml_document_type), intent(in) :: self
        integer, intent(in) :: parent
        character(len=*), intent(in) :: name
        integer, allocatable :: found(:)
        integer :: k, count

        count = 0
        k = first_of(parent)
        do while (k > 0)
            if (self%elements(k)%name == name) count = count + 1
            k = self%elements(k)%next_sibling
        end do
        allocate(found(count))
        ! The list runs from the last child to the first.
        k = first_of(parent)
        do while (k > 0)
            if (self%elements(k)%name == name) then
                found(count) = k
                count = count - 1
            end if
            k = self%elements(k)%next_sibling
        end do
    contains
        integer function first_of(parent)
            integer, intent(in) :: parent
            if (parent == 0) then
                first_of = self%first_root
            else
                first_of = self%elements(parent)%first_child
            end if
        end function first_of
    end function children

    subroutine attribute(self, element, name, value, found)
        class(xml_document_type), intent(in) :: self
        integer, intent(in) :: element
        character(len=*), intent(in) :: name
        character(len=:), allocatable, intent(out) :: value
        logical, intent(out) :: found
        integer :: k

        found = .false.
        value = ''
        associate(e => self%elements(element))
            do k = 1, size(e%attribute_names)
                if (e%attribute_names(k)%text == name) then
                    value = e%attribute_values(k)%text
                    found = .true.
                    return
                end if
            end do
        end associate
    end subroutine attribute

end module yarnfort_generate_xml_subset
