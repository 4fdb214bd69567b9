! SPDX-License-Identifier: MIT
!> A reader for the subset of XML that TexGen's model files (.tg3) use: nested elements
!> with attributes. Text content, comments, processing instructions (<?...?>),
!> declarations (<!...>) and CDATA sections are skipped; the five predefined entities and
!> numeric character references below 128 are decoded in attribute values. The whole file
!> becomes a flat list of elements, each with its parent, queried by name.
!>
!> Neither Debian nor PyPI offers a maintained XML library for Fortran, and the program
!> must read the file without Python, so this is the one XML reader of the project.
module yarnfort_generate_xml_subset
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: read_file_text
    implicit none
    private

    public :: xml_document_type, read_xml_file, parse_xml

    type :: xml_text_type
        character(len=:), allocatable :: text
    end type xml_text_type

    type :: xml_element_type
        character(len=:), allocatable :: name
        !> Index of the enclosing element (0 for the root).
        integer :: parent = 0
        type(xml_text_type), allocatable :: attribute_names(:), attribute_values(:)
    end type xml_element_type

    type :: xml_document_type
        integer :: n_elements = 0
        type(xml_element_type), allocatable :: elements(:)
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
                    call fail(i, "closing tag </" // name // "> without an open element")
                    return
                end if
                if (name /= document%elements(current)%name) then
                    call fail(i, "closing tag </" // name // "> does not match <" &
                        // document%elements(current)%name // ">")
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
                // document%elements(current)%name // '> (not closed)')
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
            integer :: j, name_start, value_end
            character(len=1) :: quote
            character(len=:), allocatable :: attribute_name, decoded

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
            allocate(element%attribute_names(0), element%attribute_values(0))
            self_closing = .false.
            do
                call skip_blanks(j)
                if (j > n) then
                    call fail(at, "tag <" // element%name // " is not closed ('>')")
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
                attribute_name = text(name_start:j - 1)
                call skip_blanks(j)
                if (len(attribute_name) == 0 .or. j >= n .or. text(j:j) /= '=') then
                    call fail(at, "tag <" // element%name // ">: an attribute without '=value'")
                    return
                end if
                j = j + 1
                call skip_blanks(j)
                quote = ' '
                if (j <= n) quote = text(j:j)
                if (quote /= '"' .and. quote /= "'") then
                    call fail(at, "tag <" // element%name // ">: attribute " // attribute_name &
                        // " has no quoted value")
                    return
                end if
                value_end = find_from(j + 1, quote)
                if (value_end == 0) then
                    call fail(at, "tag <" // element%name // ">: the value of attribute " &
                        // attribute_name // " is not closed")
                    return
                end if
                decoded = decode(text(j + 1:value_end - 1))
                call append_text(element%attribute_names, attribute_name)
                call append_text(element%attribute_values, decoded)
                j = value_end + 1
            end do
            close_at = j
            call add_element(document, element)
        end subroutine read_tag
    end subroutine parse_xml

    subroutine add_element(document, element)
        type(xml_document_type), intent(inout) :: document
        type(xml_element_type), intent(in) :: element
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
        document%elements(document%n_elements) = element
    end subroutine add_element

    subroutine move_alloc_element(from, to)
        type(xml_element_type), intent(inout) :: from
        type(xml_element_type), intent(out) :: to
        call move_alloc(from%name, to%name)
        to%parent = from%parent
        call move_alloc(from%attribute_names, to%attribute_names)
        call move_alloc(from%attribute_values, to%attribute_values)
    end subroutine move_alloc_element

    subroutine append_text(list, text)
        type(xml_text_type), allocatable, intent(inout) :: list(:)
        character(len=*), intent(in) :: text
        type(xml_text_type), allocatable :: grown(:)
        integer :: k

        allocate(grown(size(list) + 1))
        do k = 1, size(list)
            call move_alloc(list(k)%text, grown(k)%text)
        end do
        grown(size(grown))%text = text
        call move_alloc(grown, list)
    end subroutine append_text

    pure logical function is_blank(c)
        character(len=1), intent(in) :: c
        is_blank = c == ' ' .or. c == achar(9) .or. c == achar(10) .or. c == achar(13)
    end function is_blank

    pure logical function is_name_end(c)
        character(len=1), intent(in) :: c
        is_name_end = is_blank(c) .or. c == '>' .or. c == '/'
    end function is_name_end

    !> Attribute text with the predefined entities and &#N; / &#xN; (N < 128) decoded;
    !> anything else is kept as it is.
    pure function decode(raw) result(value)
        character(len=*), intent(in) :: raw
        character(len=:), allocatable :: value
        integer :: i, semicolon, code, stat

        value = ''
        i = 1
        do while (i <= len(raw))
            semicolon = 0
            if (raw(i:i) == '&') semicolon = index(raw(i:), ';')
            if (semicolon == 0 .or. semicolon > 8) then
                value = value // raw(i:i)
                i = i + 1
                cycle
            end if
            select case (raw(i:i + semicolon - 1))
            case ('&lt;')
                value = value // '<'
            case ('&gt;')
                value = value // '>'
            case ('&amp;')
                value = value // '&'
            case ('&quot;')
                value = value // '"'
            case ('&apos;')
                value = value // "'"
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
                    value = value // achar(code)
                else
                    value = value // raw(i:i + semicolon - 1)
                end if
            end select
            i = i + semicolon
        end do
    end function decode

    function children(self, parent, name) result(found)
        class(xml_document_type), intent(in) :: self
        integer, intent(in) :: parent
        character(len=*), intent(in) :: name
        integer, allocatable :: found(:)
        integer :: k

        allocate(found(0))
        do k = 1, self%n_elements
            if (self%elements(k)%parent /= parent) cycle
            if (self%elements(k)%name == name) found = [found, k]
        end do
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
