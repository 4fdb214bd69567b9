! SPDX-License-Identifier: MIT
!> The TexGen model file read into yarns and the cell; refusals name the TexGen yarn.
!>
!> Read: the (one) textile's yarns with their master nodes (Position, Up), interpolation
!> (linear, or a cubic through the nodes for TexGen's Bezier and cubic kinds), repeat
!> vectors and section size (Width, Height of the first section, or the bounding box of a
!> polygon section), and the GeometryScale (mm, cm or m). The repeats must be the same
!> for every yarn: one along x and one along y (the cell's periods Lx, Ly), and each yarn
!> must be periodic, its last master node a lattice translate of its first.
module yarnfort_generate_texgen_model
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_generate_xml_subset, only: xml_document_type
    use yarnfort_text, only: format_real, format_integer, format_short
    use yarnfort_input_magnitudes, only: max_coordinate
    use yarnfort_generate_texgen_curves, only: texgen_yarn_type, lattice_tolerance, &
        sample_centre_line
    implicit none
    private

    public :: read_model, textile_hint, check_weft_knit

contains

    !> Yarns of the file's one textile, in TexGen's length unit; the cell's periods.
    subroutine read_model(document, samples, yarns, cell, scale, error)
        type(xml_document_type), intent(in) :: document
        integer, intent(in) :: samples
        type(texgen_yarn_type), allocatable, intent(out) :: yarns(:)
        real(wp), intent(out) :: cell(2), scale
        type(error_type), allocatable, intent(out) :: error
        integer, allocatable :: roots(:), textiles(:), yarn_elements(:), nodes(:), found(:)
        integer, allocatable :: repeats(:)
        real(wp), allocatable :: master(:, :), up(:, :), lattice(:, :), tangent(:, :)
        real(wp) :: vector(3), first_lattice(3, 2)
        character(len=:), allocatable :: value, kind
        character(len=120) :: buffer
        logical :: present, periodic, forced
        integer :: y, k

        cell = 0.0_wp
        scale = 1.0e-3_wp
        roots = document%children(0, 'TexGenModel')
        if (size(roots) /= 1) then
            call fatal_error(error, 'not a TexGen model (no <TexGenModel> element)')
            return
        end if
        textiles = document%children(roots(1), 'Textile')
        if (size(textiles) /= 1) then
            write(buffer, '("holds ", i0, " textiles; exactly one is supported")') size(textiles)
            call fatal_error(error, trim(buffer))
            return
        end if
        call document%attribute(textiles(1), 'GeometryScale', value, present)
        if (present) then
            select case (value)
            case ('mm')
                scale = 1.0e-3_wp
            case ('cm')
                scale = 1.0e-2_wp
            case ('m')
                scale = 1.0_wp
            case default
                call fatal_error(error, "GeometryScale '" // value // "' is not mm, cm or m")
                return
            end select
        end if
        yarn_elements = document%children(textiles(1), 'Yarn')
        if (size(yarn_elements) == 0) then
            call fatal_error(error, 'the textile has no <Yarn> elements (no TexGen yarns: ' &
                // 'saved with OUTPUT_MINIMAL, which keeps only the parameters TexGen builds ' &
                // 'the yarns from?); save it with OUTPUT_STANDARD')
            return
        end if
        allocate(yarns(size(yarn_elements)))
        do y = 1, size(yarn_elements)
            write(buffer, '("TexGen yarn ", i0, ": ")') y - 1
            nodes = document%children(yarn_elements(y), 'MasterNode')
            if (size(nodes) < 2) then
                call fatal_error(error, trim(buffer) // ' fewer than two master nodes')
                return
            end if
            allocate(master(3, size(nodes)), up(3, size(nodes)), tangent(3, size(nodes)))
            do k = 1, size(nodes)
                call read_vector(document, nodes(k), 'Position', master(:, k), .true., error)
                if (allocated(error)) goto 200
                call check_reach('master node ' // format_integer(k - 1) // ': Position', &
                    master(:, k), scale, error)
                if (allocated(error)) goto 200
                up(:, k) = [0.0_wp, 0.0_wp, 1.0_wp]
                call read_vector(document, nodes(k), 'Up', vector, .false., error)
                if (allocated(error)) goto 200
                if (norm2(vector) > 0.0_wp) up(:, k) = vector / norm2(vector)
                call read_vector(document, nodes(k), 'Tangent', tangent(:, k), .false., error)
                if (allocated(error)) goto 200
            end do
            found = document%children(yarn_elements(y), 'Interpolation')
            kind = 'CInterpolationCubic'
            periodic = .true.
            forced = .false.
            if (size(found) > 0) then
                call document%attribute(found(1), 'ForceMasterNodeTangent', value, present)
                if (present) forced = value /= '0'
                call document%attribute(found(1), 'type', value, present)
                if (present) kind = value
                call document%attribute(found(1), 'Periodic', value, present)
                if (present) periodic = value /= '0'
            end if
            select case (kind)
            case ('CInterpolationBezier', 'CInterpolationCubic', 'CInterpolationLinear')
            case default
                call fatal_error(error, trim(buffer) // " interpolation '" // kind &
                    // "' is not supported (Bezier, Cubic or Linear)")
                return
            end select
            if (.not. periodic) then
                call fatal_error(error, trim(buffer) // ' is not periodic (Interpolation ' &
                    // 'Periodic="0"): only periodic cells are imported')
                return
            end if
            repeats = document%children(yarn_elements(y), 'Repeat')
            allocate(lattice(3, size(repeats)))
            do k = 1, size(repeats)
                call read_vector(document, repeats(k), 'value', lattice(:, k), .true., error)
                if (allocated(error)) goto 200
                call check_reach('Repeat ' // format_integer(k) // ': value', lattice(:, k), &
                    scale, error)
                if (allocated(error)) goto 200
            end do
            if (y == 1) then
                call get_cell(lattice, first_lattice, error)
                if (allocated(error)) goto 200
                cell = [first_lattice(1, 1), first_lattice(2, 2)]
            else
                call get_cell(lattice, vector_pair=first_lattice, error=error)
                if (allocated(error)) goto 200
            end if
            call drop_repeated_nodes(master, up, tangent, lattice_tolerance * minval(cell))
            if (size(master, 2) < 2) then
                call fatal_error(error, trim(buffer) // ' all its master nodes are at one ' &
                    // 'point: give it master nodes along its path')
                return
            end if
            call read_section(document, yarn_elements(y), yarns(y)%width, yarns(y)%height, &
                error)
            if (allocated(error)) goto 200
            if (.not. forced) tangent = 0.0_wp
            call sample_centre_line(master, up, tangent, kind == 'CInterpolationLinear', &
                samples, yarns(y))
            vector = yarns(y)%period / [cell, 1.0_wp]
            if (norm2(yarns(y)%period) < lattice_tolerance * minval(cell) .or. &
                    any(abs(vector(1:2) - nint(vector(1:2))) > lattice_tolerance) .or. &
                    abs(yarns(y)%period(3)) > lattice_tolerance * minval(cell)) then
                call fatal_error(error, trim(buffer) // ' its last master node is not a ' &
                    // 'translate of its first by the repeat vectors (not one period of a ' &
                    // 'periodic yarn)')
                return
            end if
            deallocate(master, up, lattice, tangent)
        end do
        return
200     error%message = trim(buffer) // ' ' // error%message
    end subroutine read_model

    !> What to change in the TexGen textile's own parameters where its centre lines meet
    !> (empty for textiles without such a rule): a CTextileWeftKnit puts the sides of a
    !> loop's head CourseWidth / 4 - YarnThickness / 2 from the loop's middle, so at
    !> YarnThickness = CourseWidth / 2 the head touches its neighbour's at one point.
    function textile_hint(document) result(hint)
        type(xml_document_type), intent(in) :: document
        character(len=:), allocatable :: hint
        real(wp) :: thickness, width
        logical :: knit, sized

        hint = ''
        call get_weft_knit_sizes(document, knit, sized, thickness, width)
        if (.not. (knit .and. sized)) return
        hint = '; CTextileWeftKnit: give a YarnThickness (here ' // format_real(thickness) &
            // ') below CourseWidth / 2 (here ' // format_real(0.5_wp * width) // ')'
    end function textile_hint

    !> A CTextileWeftKnit cell (one loop) has at least two contacts: the head of each
    !> loop holds the loop above by its two legs. Fewer: the legs were not told apart
    !> (one contact patch), and the loop would hang on one leg.
    subroutine check_weft_knit(document, n_contacts, error)
        type(xml_document_type), intent(in) :: document
        integer, intent(in) :: n_contacts
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: thickness, width
        logical :: knit, sized

        if (n_contacts >= 2) return
        call get_weft_knit_sizes(document, knit, sized, thickness, width)
        if (.not. knit) return
        call fatal_error(error, 'TexGen yarn 0 (CTextileWeftKnit): ' &
            // format_integer(n_contacts) // ' contact(s) found in the cell, where the ' &
            // 'head of a loop holds the loop above by its two legs (2 contacts): the ' &
            // 'legs, CourseWidth / 2 - YarnThickness = ' &
            // format_short(0.5_wp * width - thickness) // ' apart at their feet ' &
            // '(YarnThickness ' // format_real(thickness) // '), are not told apart; ' &
            // 'give a smaller YarnThickness')
    end subroutine check_weft_knit

    !> Whether the file's textile is TexGen's CTextileWeftKnit, and its YarnThickness and
    !> CourseWidth (`sized`: both read; else 0).
    subroutine get_weft_knit_sizes(document, knit, sized, thickness, width)
        type(xml_document_type), intent(in) :: document
        logical, intent(out) :: knit, sized
        real(wp), intent(out) :: thickness, width
        integer, allocatable :: roots(:), textiles(:)
        character(len=:), allocatable :: value
        logical :: present
        integer :: stat(2)

        thickness = 0.0_wp
        width = 0.0_wp
        sized = .false.
        roots = document%children(0, 'TexGenModel')
        textiles = document%children(roots(1), 'Textile')
        call document%attribute(textiles(1), 'type', value, present)
        knit = value == 'CTextileWeftKnit'
        if (.not. knit) return
        call document%attribute(textiles(1), 'YarnThickness', value, present)
        read(value, *, iostat=stat(1)) thickness
        call document%attribute(textiles(1), 'CourseWidth', value, present)
        read(value, *, iostat=stat(2)) width
        sized = all(stat == 0)
        if (sized) return
        thickness = 0.0_wp
        width = 0.0_wp
    end subroutine get_weft_knit_sizes

    !> Master nodes at the position of the one before (within `tolerance`) are dropped:
    !> TexGen accepts them, but their span has no length, nor a direction to sample.
    !> The last node (the first's image one period on) stays.
    subroutine drop_repeated_nodes(master, up, tangent, tolerance)
        real(wp), allocatable, intent(inout) :: master(:, :), up(:, :), tangent(:, :)
        real(wp), intent(in) :: tolerance
        logical :: kept(size(master, 2))
        integer :: k, previous, n

        n = size(master, 2)
        kept = .true.
        previous = 1
        do k = 2, n
            if (norm2(master(:, k) - master(:, previous)) <= tolerance) then
                ! Of the last node and a repeat before it, the last stays.
                if (k == n .and. previous > 1) then
                    kept(previous) = .false.
                else
                    kept(k) = .false.
                    cycle
                end if
            end if
            previous = k
        end do
        if (all(kept)) return
        master = master(:, pack([(k, k = 1, n)], kept))
        up = up(:, pack([(k, k = 1, n)], kept))
        tangent = tangent(:, pack([(k, k = 1, n)], kept))
    end subroutine drop_repeated_nodes

    !> A position or repeat vector of the model (in its unit; `scale` m per unit) within
    !> the coordinate limit of every scene (yarnfort_input_magnitudes).
    subroutine check_reach(what, vector, scale, error)
        character(len=*), intent(in) :: what
        real(wp), intent(in) :: vector(3), scale
        type(error_type), allocatable, intent(out) :: error

        if (all(abs(vector) * scale <= max_coordinate)) return
        call fatal_error(error, what // ' ' // format_real(maxval(abs(vector))) // ' (' &
            // format_real(maxval(abs(vector)) * scale) // ' m) is above ' &
            // format_real(max_coordinate) // ' m, where squared lengths overflow')
    end subroutine check_reach

    !> The cell of a yarn's repeat vectors: one along x, one along y; a second call
    !> (vector_pair given) checks that the repeats are those.
    subroutine get_cell(lattice, cell, error, vector_pair)
        real(wp), intent(in) :: lattice(:, :)
        real(wp), intent(out), optional :: cell(3, 2)
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: vector_pair(3, 2)
        real(wp) :: found(3, 2), size_scale
        integer :: k

        if (size(lattice, 2) /= 2) then
            call fatal_error(error, 'needs two repeat vectors (one along x, one along y)')
            return
        end if
        found = 0.0_wp
        do k = 1, 2
            size_scale = norm2(lattice(:, k))
            if (abs(lattice(2, k)) + abs(lattice(3, k)) <= lattice_tolerance * size_scale &
                    .and. lattice(1, k) > 0.0_wp) then
                found(:, 1) = lattice(:, k)
            else if (abs(lattice(1, k)) + abs(lattice(3, k)) <= lattice_tolerance * size_scale &
                    .and. lattice(2, k) > 0.0_wp) then
                found(:, 2) = lattice(:, k)
            end if
        end do
        if (found(1, 1) <= 0.0_wp .or. found(2, 2) <= 0.0_wp) then
            call fatal_error(error, 'its repeat vectors are not one along +x and one along +y ' &
                // '(a rectangular periodic cell)')
            return
        end if
        if (present(vector_pair)) then
            if (any(abs(found - vector_pair) > lattice_tolerance * maxval(abs(vector_pair)))) &
                call fatal_error(error, 'its repeat vectors differ from those of TexGen yarn 0')
        end if
        if (present(cell)) cell = found
    end subroutine get_cell

    subroutine read_vector(document, element, name, vector, required, error)
        type(xml_document_type), intent(in) :: document
        integer, intent(in) :: element
        character(len=*), intent(in) :: name
        real(wp), intent(out) :: vector(3)
        logical, intent(in) :: required
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: value
        logical :: present
        integer :: stat

        vector = 0.0_wp
        call document%attribute(element, name, value, present)
        if (.not. present) then
            if (required) call fatal_error(error, '<' // document%elements(element)%name &
                // '> has no ' // name)
            return
        end if
        read(value, *, iostat=stat) vector
        if (stat /= 0 .or. any(vector /= vector) .or. any(abs(vector) > huge(1.0_wp))) &
            call fatal_error(error, '<' // document%elements(element)%name // '> ' // name &
                // '="' // value // '" is not three finite numbers')
    end subroutine read_vector

    !> Width and height of the yarn's first section (an ellipse or other section with
    !> Width and Height, or a polygon's bounding box in the section plane).
    subroutine read_section(document, yarn, width, height, error)
        type(xml_document_type), intent(in) :: document
        integer, intent(in) :: yarn
        real(wp), intent(out) :: width, height
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: value
        logical :: present, has_width, has_height
        integer :: k, j, stat
        real(wp) :: point(2), lower(2), upper(2)
        integer, allocatable :: points(:)

        width = 0.0_wp
        height = 0.0_wp
        do k = yarn + 1, document%n_elements
            if (.not. inside(k, yarn)) exit
            if (document%elements(k)%name /= 'Section') cycle
            call document%attribute(k, 'Width', value, has_width)
            if (has_width) read(value, *, iostat=stat) width
            call document%attribute(k, 'Height', value, has_height)
            if (has_height) read(value, *, iostat=stat) height
            if (.not. (has_width .and. has_height)) then
                points = document%children(k, 'PolygonPoint')
                lower = huge(1.0_wp)
                upper = -huge(1.0_wp)
                do j = 1, size(points)
                    call document%attribute(points(j), 'value', value, present)
                    if (.not. present) cycle
                    read(value, *, iostat=stat) point
                    if (stat /= 0) cycle
                    lower = min(lower, point)
                    upper = max(upper, point)
                end do
                if (size(points) >= 3) then
                    width = upper(1) - lower(1)
                    height = upper(2) - lower(2)
                end if
            end if
            exit
        end do
        if (.not. (width > 0.0_wp .and. height > 0.0_wp .and. width < huge(1.0_wp) .and. &
                height < huge(1.0_wp))) call fatal_error(error, 'has no section with a ' &
                // 'positive Width and Height (or polygon points)')
    contains
        logical function inside(element, ancestor)
            integer, intent(in) :: element, ancestor
            integer :: p
            inside = .false.
            p = document%elements(element)%parent
            do while (p > 0)
                if (p == ancestor) then
                    inside = .true.
                    return
                end if
                p = document%elements(p)%parent
            end do
        end function inside
    end subroutine read_section

end module yarnfort_generate_texgen_model
