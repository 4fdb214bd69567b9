! SPDX-License-Identifier: MIT
!> The plain text geometry file of &geometry: nodes and yarns of large scenes.
!>
!>     # comment (to the end of the line)
!>     node <id> <x> <y> <z>
!>     yarn <material> <elements_per_segment> <id> <id> ... [&]
!>     length0 <L0 of element 1> <L0 of element 2> ... [&]   (optional, after its yarn)
!>     stretch <stretch of element 1> ... [&]                 (or this instead)
!>     unit <length unit>                                      (optional, once: mm, ...)
!>
!> Words are separated by blanks; keywords are case-insensitive. Node ids are 1..n, each
!> defined exactly once, in any order. A yarn line ending in '&' continues on the next
!> line. Node and yarn lines may be mixed in any order. With a unit (the `unit` line or
!> `&geometry unit`, which must agree) coordinates and length0 values are converted to m.
module yarnfort_input_geometry_file
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: yarn_config_type, name_length
    use yarnfort_text, only: string_type, to_lower, format_integer, split_words, &
        parse_integer, parse_real, read_file_text, drop_byte_order_mark, quote_string
    use yarnfort_units, only: unit_type, find_unit, unit_names, to_scene_unit, length_kind
    implicit none
    private

    public :: read_geometry_file

contains

    !> Read node positions (3, n) and yarns from the geometry file `path`. `stated_unit`
    !> ('&geometry unit', '' for none) and a `unit` line of the file give the length unit
    !> of its coordinates and length0 values (they must agree), converted to m; none: m.
    subroutine read_geometry_file(path, node_positions, yarns, error, stated_unit)
        character(len=*), intent(in) :: path
        real(wp), allocatable, intent(out) :: node_positions(:, :)
        type(yarn_config_type), allocatable, intent(out) :: yarns(:)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in), optional :: stated_unit
        character(len=:), allocatable :: content, line, record, keyword
        type(string_type), allocatable :: words(:)
        integer :: position, line_number, first_line, n_nodes, n_yarns, id, k, i
        integer, allocatable :: node_ids(:), node_lines(:), yarn_lines(:), defined_on(:)
        real(wp), allocatable :: node_xyz(:, :), values(:)
        real(wp) :: xyz(3)
        logical :: ok
        integer :: stat, unit_line
        character(len=256) :: message
        type(unit_type) :: unit, declared

        call read_file_text(path, "file '" // path // "'", content, error)
        if (allocated(error)) then
            error%message = '&geometry: ' // error%message
            return
        end if
        call drop_byte_order_mark(content)
        allocate(node_ids(1024), node_lines(1024), node_xyz(3, 1024), yarns(16), &
            yarn_lines(16), stat=stat, errmsg=message)
        call check_memory()
        if (allocated(error)) return
        n_nodes = 0
        n_yarns = 0
        line_number = 0
        position = 1
        unit_line = 0
        read_lines: do
            ! A logical line: lines joined while they end in '&'.
            record = ''
            first_line = line_number + 1
            do
                if (position > len(content)) then
                    if (len_trim(record) > 0) then
                        call fail(line_number, "the last line ends in '&' but nothing follows")
                        return
                    end if
                    exit read_lines
                end if
                call next_line(content, position, line)
                line_number = line_number + 1
                if (index(line, '#') > 0) line = line(:index(line, '#') - 1)
                line = trim(line)
                if (len(line) > 0 .and. index(line, '&', back=.true.) == len(line)) then
                    record = record // ' ' // line(:len(line) - 1)
                    cycle
                end if
                record = record // ' ' // line
                exit
            end do
            call split_words(record, words)
            if (size(words) == 0) cycle read_lines
            keyword = to_lower(words(1)%text)
            select case (keyword)
            case ('node')
                if (size(words) /= 5) then
                    call fail(first_line, 'a node line is: node <id> <x> <y> <z>')
                    return
                end if
                call parse_integer(words(2)%text, id, ok)
                if (.not. ok .or. id < 1) then
                    call fail(first_line, "node id '" // words(2)%text &
                        // "' is not an integer >= 1")
                    return
                end if
                do k = 1, 3
                    call parse_real(words(2 + k)%text, xyz(k), ok)
                    if (.not. ok) then
                        call fail(first_line, 'node ' // format_integer(id) // ': ' &
                            // 'xyz'(k:k) // " = '" // words(2 + k)%text &
                            // "' is not a number")
                        return
                    end if
                end do
                if (n_nodes == size(node_ids)) call grow_nodes()
                if (allocated(error)) return
                n_nodes = n_nodes + 1
                node_ids(n_nodes) = id
                node_lines(n_nodes) = first_line
                node_xyz(:, n_nodes) = xyz
            case ('yarn')
                if (size(words) < 5) then
                    call fail(first_line, 'a yarn line is: yarn <material> ' &
                        // '<elements_per_segment> <id> <id> ... (at least 2 node ids)')
                    return
                end if
                if (len(words(2)%text) > name_length) then
                    call fail(first_line, "material name '" // words(2)%text &
                        // "' is longer than " // format_integer(name_length) &
                        // ' characters')
                    return
                end if
                if (n_yarns == size(yarns)) call grow_yarns()
                if (allocated(error)) return
                n_yarns = n_yarns + 1
                yarn_lines(n_yarns) = first_line
                yarns(n_yarns)%material = words(2)%text
                call parse_integer(words(3)%text, yarns(n_yarns)%elements_per_segment, ok)
                if (.not. ok) then
                    call fail(first_line, "elements_per_segment '" // words(3)%text &
                        // "' is not an integer")
                    return
                end if
                allocate(yarns(n_yarns)%nodes(size(words) - 3), stat=stat, errmsg=message)
                call check_memory()
                if (allocated(error)) return
                do k = 4, size(words)
                    call parse_integer(words(k)%text, yarns(n_yarns)%nodes(k - 3), ok)
                    if (.not. ok) then
                        call fail(first_line, "yarn node id '" // words(k)%text &
                            // "' is not an integer")
                        return
                    end if
                end do
            case ('length0', 'stretch')
                ! Per-element reference lengths or stretches of the yarn line before it.
                if (n_yarns == 0) then
                    call fail(first_line, "a '" // keyword // "' line belongs to the yarn " &
                        // 'line before it, and there is none')
                    return
                end if
                if (allocated(yarns(n_yarns)%length0) .or. allocated(yarns(n_yarns)%stretch)) &
                        then
                    call fail(first_line, 'the yarn of line ' &
                        // format_integer(yarn_lines(n_yarns)) // " already has a 'length0' " &
                        // "or 'stretch' line (give one of them, once)")
                    return
                end if
                if (size(words) < 2) then
                    call fail(first_line, "a '" // keyword // "' line lists one value per " &
                        // 'element of the yarn before it')
                    return
                end if
                allocate(values(size(words) - 1), stat=stat, errmsg=message)
                call check_memory()
                if (allocated(error)) return
                do k = 2, size(words)
                    call parse_real(words(k)%text, values(k - 1), ok)
                    if (.not. ok) then
                        call fail(first_line, keyword // " value '" &
                            // words(k)%text // "' is not a number")
                        return
                    end if
                end do
                if (keyword == 'length0') then
                    call move_alloc(values, yarns(n_yarns)%length0)
                else
                    call move_alloc(values, yarns(n_yarns)%stretch)
                end if
            case ('unit')
                if (unit_line > 0) then
                    call fail(first_line, 'a second unit line (the first is line ' &
                        // format_integer(unit_line) // ')')
                    return
                end if
                if (size(words) /= 2) then
                    call fail(first_line, 'a unit line is: unit <length unit> (' &
                        // unit_names(length_kind) // ')')
                    return
                end if
                call take_length_unit(words(2)%text, unit, message, ok)
                if (.not. ok) then
                    call fail(first_line, trim(message))
                    return
                end if
                unit_line = first_line
            case default
                call fail(first_line, "unknown keyword '" // words(1)%text &
                    // "' (a line is 'node ...', 'yarn ...', 'length0 ...', 'stretch ...' " &
                    // "or 'unit ...'; comments start with #)")
                return
            end select
        end do read_lines

        if (n_nodes == 0) then
            if (len(content) == 0) then
                call fatal_error(error, "&geometry: file '" // path // "' is empty (0 bytes " &
                    // 'read; a device or a pipe reads as empty): it must hold the node and ' &
                    // 'yarn lines')
            else
                call fatal_error(error, "&geometry: file '" // path // "' has no node lines " &
                    // '(' // format_integer(line_number) // ' lines read; a node line is: ' &
                    // 'node <id> <x> <y> <z>)')
            end if
            return
        end if

        ! The length unit: the file's and &geometry's must agree; none: m (factor 1).
        if (present(stated_unit)) then
            if (len_trim(stated_unit) > 0) then
                call take_length_unit(trim(adjustl(stated_unit)), declared, message, ok)
                if (.not. ok) then
                    call fatal_error(error, '&geometry: unit ' // trim(message))
                    return
                end if
                if (unit_line == 0) then
                    unit = declared
                else if (unit%name /= declared%name) then
                    call fail(unit_line, 'unit ' // quote_string(trim(unit%name)) &
                        // ' but &geometry unit = ' // quote_string(trim(adjustl(stated_unit))))
                    return
                end if
            end if
        end if
        node_xyz(:, :n_nodes) = to_scene_unit(node_xyz(:, :n_nodes), unit)
        do i = 1, n_yarns
            if (allocated(yarns(i)%length0)) yarns(i)%length0 = to_scene_unit( &
                yarns(i)%length0, unit)
        end do

        ! Node ids must be exactly 1..n. An id above the number of node lines means that
        ! some id up to it is missing (found below): nothing is allocated by such an id,
        ! which may be huge.
        yarns = yarns(:n_yarns)
        id = 0
        if (n_nodes > 0) id = maxval(node_ids(:n_nodes))
        allocate(node_positions(3, min(id, n_nodes)), defined_on(min(id, n_nodes)), stat=stat, &
            errmsg=message)
        call check_memory()
        if (allocated(error)) return
        defined_on = 0
        do i = 1, n_nodes
            if (node_ids(i) > size(defined_on)) cycle
            if (defined_on(node_ids(i)) /= 0) then
                call fail(node_lines(i), 'node ' // format_integer(node_ids(i)) &
                    // ' is defined twice (lines ' // format_integer(defined_on(node_ids(i))) &
                    // ' and ' // format_integer(node_lines(i)) // ')')
                return
            end if
            defined_on(node_ids(i)) = node_lines(i)
            node_positions(:, node_ids(i)) = node_xyz(:, i)
        end do
        i = findloc(defined_on, 0, dim=1)
        if (i > 0) then
            call fatal_error(error, "&geometry: file '" // path // "': node " &
                // format_integer(i) // ' is missing (node ids must be 1..n, each ' &
                // 'once; the largest id is ' // format_integer(id) // ')')
            return
        end if
        do i = 1, n_yarns
            associate(nodes => yarns(i)%nodes)
                k = findloc(nodes < 1 .or. nodes > id, .true., dim=1)
                if (k == 0) cycle
                call fail(yarn_lines(i), 'yarn node id ' // format_integer(nodes(k)) &
                    // ' is not a node (ids are 1..' // format_integer(id) // ')')
                return
            end associate
        end do

    contains

        !> Double the node arrays (explicit allocations, so that a failure is an error).
        subroutine grow_nodes()
            real(wp), allocatable :: grown(:, :)

            call grow_integers(node_ids)
            call grow_integers(node_lines)
            if (allocated(error)) return
            allocate(grown(3, 2 * size(node_xyz, 2)), stat=stat, errmsg=message)
            call check_memory()
            if (allocated(error)) return
            grown(:, :size(node_xyz, 2)) = node_xyz
            call move_alloc(grown, node_xyz)
        end subroutine grow_nodes

        subroutine grow_yarns()
            type(yarn_config_type), allocatable :: grown(:)

            allocate(grown(2 * size(yarns)), stat=stat, errmsg=message)
            call check_memory()
            if (allocated(error)) return
            grown(:size(yarns)) = yarns
            call move_alloc(grown, yarns)
            call grow_integers(yarn_lines)
        end subroutine grow_yarns

        subroutine grow_integers(values)
            integer, allocatable, intent(inout) :: values(:)
            integer, allocatable :: grown(:)

            if (allocated(error)) return
            allocate(grown(2 * size(values)), stat=stat, errmsg=message)
            call check_memory()
            if (allocated(error)) return
            grown(:size(values)) = values
            call move_alloc(grown, values)
        end subroutine grow_integers

        !> After an allocation with stat=stat, errmsg=message: an error if it failed.
        subroutine check_memory()
            if (stat == 0) return
            call fatal_error(error, "&geometry: file '" // path // "': not enough memory " &
                // 'to read it (' // trim(message) // ')')
        end subroutine check_memory

        subroutine fail(line, text)
            integer, intent(in) :: line
            character(len=*), intent(in) :: text

            call fatal_error(error, "&geometry: file '" // path // "', line " &
                // format_integer(line) // ': ' // text)
        end subroutine fail

    end subroutine read_geometry_file

    !> The length unit spelled `text`; `ok` false and `message` set if it is not one.
    pure subroutine take_length_unit(text, unit, message, ok)
        character(len=*), intent(in) :: text
        type(unit_type), intent(out) :: unit
        character(len=*), intent(out) :: message
        logical, intent(out) :: ok

        message = ''
        call find_unit(text, unit, ok)
        if (ok) ok = unit%kind == length_kind
        if (.not. ok) message = quote_string(text) // ' is not a known length unit (' &
            // unit_names(length_kind) // ')'
    end subroutine take_length_unit

    !> The line of `content` starting at `position` (without its end: LF, CR LF or a lone
    !> CR, as old Mac editors write); `position` moves to the start of the next line.
    pure subroutine next_line(content, position, line)
        character(len=*), intent(in) :: content
        integer, intent(inout) :: position
        character(len=:), allocatable, intent(out) :: line
        integer :: last

        last = scan(content(position:), achar(10) // achar(13))
        if (last == 0) then
            line = content(position:)
            position = len(content) + 1
            return
        end if
        last = position + last - 1
        line = content(position:last - 1)
        position = last + 1
        if (content(last:last) == achar(13) .and. position <= len(content)) then
            if (content(position:position) == achar(10)) position = position + 1
        end if
    end subroutine next_line

end module yarnfort_input_geometry_file
