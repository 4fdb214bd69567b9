! SPDX-License-Identifier: MIT
!> A periodic cell from a TexGen model file (.tg3, XML; read without TexGen), or a
!> clamped sample of copies of it.
!>
!> Read: the (one) textile's yarns with their master nodes (Position, Up), interpolation
!> (linear, or a cubic through the nodes for TexGen's Bezier and cubic kinds), repeat
!> vectors and section size (Width, Height of the first section, or the bounding box of a
!> polygon section), and the GeometryScale (mm, cm or m). The repeats must be the same
!> for every yarn: one along x and one along y (the cell's periods Lx, Ly), and each yarn
!> must be periodic, its last master node a lattice translate of its first.
!>
!> Centre lines become polylines of `texgen_samples` points per master-node span; the
!> centre line between master nodes is a Catmull-Rom cubic (tangents (P(i+1) - P(i-1))/2,
!> periodic at the ends), which can differ from TexGen's own curves between nodes by a
!> fraction of the yarn thickness. Contacts: the closest approaches between two yarns
!> (and between a yarn and the periodic images of all yarns), where the distance is at
!> most (1 + texgen_contact_tolerance) times the sum of the two half thicknesses, each
!> the radius of the elliptic section (Width x Height) in the direction of the other
!> yarn. Within one contact patch (both points within the sum of the two widths along
!> each yarn) only the closest pair is kept.
!>
!> The network: between contacts a string under tension is straight, so each yarn gets a
!> node at each of its contacts and is otherwise straight; its ends lie in the middle of
!> its longest stretch without contacts and are periodic images of each other (one
!> yarn period apart). The two nodes of a contact are joined by a gap-holder of the
!> actual distance (scaled by the gap factor); for a contact with a periodic image the
!> holder's offset also carries the lattice vector, which follows the macroscopic strain.
module yarnfort_generate_texgen
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: fabric_config_type, link_config_type
    use yarnfort_generate_net_builder, only: net_builder_type
    use yarnfort_generate_xml_subset, only: xml_document_type, read_xml_file
    use yarnfort_sort, only: sort_index
    use yarnfort_text, only: format_real, format_integer
    use yarnfort_input_magnitudes, only: max_coordinate
    implicit none
    private

    public :: generate_texgen

    !> Relative tolerance of lattice checks (repeats, yarn periods), of the cell size.
    real(wp), parameter :: lattice_tolerance = 1.0e-6_wp

    type :: texgen_yarn_type
        !> Sampled centre line (3, 0:m), point m = point 0 + period; arc length at each.
        real(wp), allocatable :: x(:, :), s(:)
        !> Up vector of each sample segment (3, m).
        real(wp), allocatable :: up(:, :)
        real(wp) :: period(3) = 0.0_wp
        real(wp) :: width = 0.0_wp, height = 0.0_wp
        real(wp) :: lower(3) = 0.0_wp, upper(3) = 0.0_wp
        !> The curve itself: master nodes (3, n), each span's end tangents (3, n - 1, 2),
        !> samples per span; linear: straight spans.
        real(wp), allocatable :: node(:, :), tangent(:, :, :)
        integer :: samples = 1
        logical :: linear = .false.
    end type texgen_yarn_type

    type :: contact_type
        integer :: yarn(2) = 0
        !> Arc length along each yarn's period, and the point there (yarn 2 unshifted).
        real(wp) :: s(2) = 0.0_wp, point(3, 2) = 0.0_wp
        !> Lattice shift of yarn 2's image.
        real(wp) :: shift(3) = 0.0_wp
        real(wp) :: distance = 0.0_wp
        integer :: node(2) = 0
    end type contact_type

contains

    !> Fill `net` from fabric%texgen_file (relative to `folder` unless absolute); also the
    !> width across which the x force is carried (the cell's y period, or the sample's
    !> height), the support pulled along x (0 for a periodic cell), and the counts of
    !> yarns and contacts found (in the cell).
    subroutine generate_texgen(fabric, path, net, width, pulled, n_yarns, n_contacts, error)
        type(fabric_config_type), intent(in) :: fabric
        character(len=*), intent(in) :: path
        type(net_builder_type), intent(inout) :: net
        real(wp), intent(out) :: width
        integer, intent(out) :: pulled, n_yarns, n_contacts
        type(error_type), allocatable, intent(out) :: error
        type(xml_document_type) :: document
        type(texgen_yarn_type), allocatable :: yarns(:)
        type(contact_type), allocatable :: contacts(:)
        type(net_builder_type) :: unit_cell
        real(wp) :: cell(2), scale

        width = 0.0_wp
        pulled = 0
        n_yarns = 0
        n_contacts = 0
        call read_xml_file(path, document, error)
        if (allocated(error)) goto 100
        call read_model(document, fabric%texgen_samples, yarns, cell, scale, error)
        if (allocated(error)) goto 100
        n_yarns = size(yarns)
        call find_contacts(yarns, cell, fabric%texgen_contact_tolerance, contacts)
        n_contacts = size(contacts)
        if (fabric%boundary == 'clamped') then
            call build_cell(fabric, yarns, cell, scale, contacts, unit_cell, error)
            if (allocated(error)) goto 100
            call tile_sample(fabric, unit_cell, cell * scale, net, error)
            if (allocated(error)) goto 100
            width = fabric%cells(2) * cell(2) * scale
            pulled = 2
            return
        end if
        call build_cell(fabric, yarns, cell, scale, contacts, net, error)
        if (allocated(error)) goto 100
        width = cell(2) * scale
        return
100     error%message = "texgen_file '" // trim(path) // "': " // error%message
    end subroutine generate_texgen

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
            call fatal_error(error, 'the textile has no yarns')
            return
        end if
        allocate(yarns(size(yarn_elements)))
        do y = 1, size(yarn_elements)
            write(buffer, '("yarn ", i0, ": ")') y - 1
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
                call fatal_error(error, 'its repeat vectors differ from those of yarn 0')
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

    !> Points along the centre line through master nodes p(:, 1:n), p(n) = p(1) + period.
    !> A node's tangent has the direction of `given` where that is not zero (TexGen's
    !> ForceMasterNodeTangent), else of (p(i+1) - p(i-1)), and the length |p(i+1) - p(i-1)|/2.
    subroutine sample_centre_line(p, up, given, linear, samples, yarn)
        real(wp), intent(in) :: p(:, :), up(:, :), given(:, :)
        logical, intent(in) :: linear
        integer, intent(in) :: samples
        type(texgen_yarn_type), intent(inout) :: yarn
        integer :: n, i, k, m
        real(wp) :: t, h00, h10, h01, h11, m0(3), m1(3), before(3), after(3)
        real(wp), allocatable :: node_tangent(:, :)

        n = size(p, 2)
        yarn%period = p(:, n) - p(:, 1)
        m = (n - 1) * samples
        allocate(yarn%x(3, 0:m), yarn%s(0:m), yarn%up(3, m))
        yarn%node = p
        yarn%samples = samples
        yarn%linear = linear
        allocate(yarn%tangent(3, n - 1, 2), source=0.0_wp)
        allocate(node_tangent(3, n))
        do i = 1, n - 1
            if (i > 1) then
                before = p(:, i - 1)
            else
                before = p(:, n - 1) - yarn%period
            end if
            after = p(:, i + 1)
            node_tangent(:, i) = 0.5_wp * (after - before)
            if (norm2(given(:, i)) > 0.0_wp) node_tangent(:, i) = given(:, i) &
                / norm2(given(:, i)) * norm2(node_tangent(:, i))
        end do
        node_tangent(:, n) = node_tangent(:, 1)
        do i = 1, n - 1
            m0 = node_tangent(:, i)
            m1 = node_tangent(:, i + 1)
            if (linear) then
                m0 = p(:, i + 1) - p(:, i)
                m1 = m0
            end if
            yarn%tangent(:, i, 1) = m0
            yarn%tangent(:, i, 2) = m1
            do k = 0, samples - 1
                t = real(k, wp) / samples
                if (linear) then
                    yarn%x(:, (i - 1) * samples + k) = (1.0_wp - t) * p(:, i) + t * p(:, i + 1)
                else
                    h00 = 2 * t**3 - 3 * t**2 + 1
                    h10 = t**3 - 2 * t**2 + t
                    h01 = -2 * t**3 + 3 * t**2
                    h11 = t**3 - t**2
                    yarn%x(:, (i - 1) * samples + k) = h00 * p(:, i) + h10 * m0 &
                        + h01 * p(:, i + 1) + h11 * m1
                end if
                yarn%up(:, (i - 1) * samples + k + 1) = up(:, i)
            end do
        end do
        yarn%x(:, m) = yarn%x(:, 0) + yarn%period
        yarn%s(0) = 0.0_wp
        do k = 1, m
            yarn%s(k) = yarn%s(k - 1) + norm2(yarn%x(:, k) - yarn%x(:, k - 1))
        end do
        yarn%lower = minval(yarn%x, dim=2)
        yarn%upper = maxval(yarn%x, dim=2)
    end subroutine sample_centre_line

    !> Closest approaches within the contact distance, one per contact patch.
    subroutine find_contacts(yarns, cell, tolerance, contacts)
        type(texgen_yarn_type), intent(in) :: yarns(:)
        real(wp), intent(in) :: cell(2), tolerance
        type(contact_type), allocatable, intent(out) :: contacts(:)
        type(contact_type), allocatable :: candidates(:)
        type(contact_type) :: c
        integer :: a, b, i, j, ka, kb, n_candidates, k, order_k
        integer :: range_x(2), range_y(2)
        real(wp) :: shift(3), reach, pa(3), pb(3), ta, tb, d, ra, rb, u(3)
        real(wp) :: lo(3), hi(3)
        integer, allocatable :: order(:)
        logical, allocatable :: kept(:)

        allocate(candidates(256))
        n_candidates = 0
        do a = 1, size(yarns)
            do b = a, size(yarns)
                reach = (1.0_wp + tolerance) * 0.5_wp * (max(yarns(a)%width, yarns(a)%height) &
                    + max(yarns(b)%width, yarns(b)%height))
                range_x = [floor((yarns(a)%lower(1) - yarns(b)%upper(1) - reach) / cell(1)), &
                    ceiling((yarns(a)%upper(1) - yarns(b)%lower(1) + reach) / cell(1))]
                range_y = [floor((yarns(a)%lower(2) - yarns(b)%upper(2) - reach) / cell(2)), &
                    ceiling((yarns(a)%upper(2) - yarns(b)%lower(2) + reach) / cell(2))]
                do j = range_y(1), range_y(2)
                    do i = range_x(1), range_x(2)
                        shift = [i * cell(1), j * cell(2), 0.0_wp]
                        ! A yarn and its own image: each pair once (the shift with i > 0,
                        ! or i = 0 and j > 0); the yarn itself (no shift) is not a contact.
                        if (a == b .and. (i < 0 .or. (i == 0 .and. j <= 0))) cycle
                        if (any(yarns(a)%lower - reach > yarns(b)%upper + shift) .or. &
                            any(yarns(a)%upper + reach < yarns(b)%lower + shift)) cycle
                        do ka = 1, size(yarns(a)%s) - 1
                            lo = min(yarns(a)%x(:, ka - 1), yarns(a)%x(:, ka)) - reach
                            hi = max(yarns(a)%x(:, ka - 1), yarns(a)%x(:, ka)) + reach
                            do kb = 1, size(yarns(b)%s) - 1
                                if (any(max(yarns(b)%x(:, kb - 1), yarns(b)%x(:, kb)) + shift &
                                    < lo) .or. any(min(yarns(b)%x(:, kb - 1), &
                                    yarns(b)%x(:, kb)) + shift > hi)) cycle
                                call closest_points(yarns(a)%x(:, ka - 1), yarns(a)%x(:, ka), &
                                    yarns(b)%x(:, kb - 1) + shift, yarns(b)%x(:, kb) + shift, &
                                    ta, tb)
                                pa = yarns(a)%x(:, ka - 1) + ta * (yarns(a)%x(:, ka) &
                                    - yarns(a)%x(:, ka - 1))
                                pb = yarns(b)%x(:, kb - 1) + tb * (yarns(b)%x(:, kb) &
                                    - yarns(b)%x(:, kb - 1)) + shift
                                d = norm2(pb - pa)
                                if (d > reach) cycle
                                u = 0.0_wp
                                if (d > 0.0_wp) u = (pb - pa) / d
                                ra = half_thickness(yarns(a), ka, u)
                                rb = half_thickness(yarns(b), kb, u)
                                if (d > (1.0_wp + tolerance) * (ra + rb)) cycle
                                if (a == b) then
                                    if (same_yarn_nearby(yarns(a), yarns(a)%s(ka - 1) &
                                        + ta * (yarns(a)%s(ka) - yarns(a)%s(ka - 1)), &
                                        yarns(b)%s(kb - 1) + tb * (yarns(b)%s(kb) &
                                        - yarns(b)%s(kb - 1)), shift)) cycle
                                end if
                                c%yarn = [a, b]
                                c%s = [yarns(a)%s(ka - 1) + ta * (yarns(a)%s(ka) &
                                    - yarns(a)%s(ka - 1)), yarns(b)%s(kb - 1) + tb &
                                    * (yarns(b)%s(kb) - yarns(b)%s(kb - 1))]
                                c%point(:, 1) = pa
                                c%point(:, 2) = pb - shift
                                c%shift = shift
                                c%distance = d
                                call append(c)
                            end do
                        end do
                    end do
                end do
            end do
        end do
        ! Keep the closest pair of each patch.
        allocate(order(n_candidates), kept(n_candidates))
        order = sort_index(candidates(1:n_candidates)%distance)
        kept = .false.
        do k = 1, n_candidates
            order_k = order(k)
            kept(order_k) = .true.
            do i = 1, k - 1
                if (.not. kept(order(i))) cycle
                if (same_patch(candidates(order(i)), candidates(order_k))) then
                    kept(order_k) = .false.
                    exit
                end if
            end do
        end do
        contacts = pack(candidates(1:n_candidates), kept)
        do k = 1, size(contacts)
            call refine_contact(yarns(contacts(k)%yarn(1)), yarns(contacts(k)%yarn(2)), &
                contacts(k))
        end do
    contains
        subroutine append(item)
            type(contact_type), intent(in) :: item
            type(contact_type), allocatable :: grown(:)
            if (n_candidates == size(candidates)) then
                allocate(grown(2 * size(candidates)))
                grown(1:n_candidates) = candidates(1:n_candidates)
                call move_alloc(grown, candidates)
            end if
            n_candidates = n_candidates + 1
            candidates(n_candidates) = item
        end subroutine append

        !> Two candidates of one contact patch: the same yarns, and both points within
        !> the sum of the widths of the other's, up to a lattice translation (also with
        !> the two points swapped, for a yarn and its own image).
        logical function same_patch(p, q)
            type(contact_type), intent(in) :: p, q
            real(wp) :: patch
            same_patch = .false.
            if (any(p%yarn /= q%yarn)) return
            patch = yarns(p%yarn(1))%width + yarns(p%yarn(2))%width
            same_patch = close_pair(p%point(:, 1), p%point(:, 2) + p%shift, &
                q%point(:, 1), q%point(:, 2) + q%shift, patch)
            if (p%yarn(1) == p%yarn(2) .and. .not. same_patch) same_patch = &
                close_pair(p%point(:, 1), p%point(:, 2) + p%shift, q%point(:, 2), &
                q%point(:, 1) - q%shift, patch)
        end function same_patch

        logical function close_pair(a1, b1, a2, b2, patch)
            real(wp), intent(in) :: a1(3), b1(3), a2(3), b2(3), patch
            real(wp) :: translation(3)
            translation = [cell(1) * nint((a1(1) - a2(1)) / cell(1)), &
                cell(2) * nint((a1(2) - a2(2)) / cell(2)), 0.0_wp]
            close_pair = norm2(a1 - a2 - translation) < patch .and. &
                norm2(b1 - b2 - translation) < patch
        end function close_pair

        !> A yarn near itself along its length (its image one or more periods on, at a
        !> distance along the yarn below half a turn of a bend as tight as the yarn is
        !> thick): not a contact.
        logical function same_yarn_nearby(yarn, s1, s2, shift)
            type(texgen_yarn_type), intent(in) :: yarn
            real(wp), intent(in) :: s1, s2, shift(3)
            real(wp) :: periods, total
            same_yarn_nearby = .false.
            periods = dot_product(shift, yarn%period) / dot_product(yarn%period, yarn%period)
            if (norm2(shift - nint(periods) * yarn%period) > lattice_tolerance &
                * maxval(cell)) return
            total = yarn%s(size(yarn%s) - 1)
            same_yarn_nearby = abs(s2 + nint(periods) * total - s1) &
                < acos(-1.0_wp) * max(yarn%width, yarn%height)
        end function same_yarn_nearby
    end subroutine find_contacts

    !> The closest points of the two curves themselves (not of their samples), from the
    !> candidate's sample points: Gauss-Newton on the distance vector, kept within one
    !> sample of the start. Arc lengths follow linearly between samples.
    subroutine refine_contact(a, b, contact)
        type(texgen_yarn_type), intent(in) :: a, b
        type(contact_type), intent(inout) :: contact
        !> Iterations: the distance is quadratic near its minimum; a few suffice.
        integer, parameter :: max_iterations = 20
        real(wp) :: u(2), u0(2), d(3), xa(3), xb(3), ta(3), tb(3), j(3, 2), m(2, 2), r(2)
        real(wp) :: step(2), determinant
        integer :: iteration

        u0 = [parameter_of(a, contact%s(1)), parameter_of(b, contact%s(2))]
        u = u0
        do iteration = 1, max_iterations
            call curve_point(a, u(1), xa, ta)
            call curve_point(b, u(2), xb, tb)
            d = xb + contact%shift - xa
            j(:, 1) = -ta
            j(:, 2) = tb
            m = matmul(transpose(j), j)
            r = matmul(transpose(j), d)
            determinant = m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1)
            if (abs(determinant) <= epsilon(1.0_wp) * m(1, 1) * m(2, 2)) exit
            step = -[m(2, 2) * r(1) - m(1, 2) * r(2), m(1, 1) * r(2) - m(2, 1) * r(1)] &
                / determinant
            u = min(max(u + step, u0 - 1.0_wp / [a%samples, b%samples]), &
                u0 + 1.0_wp / [a%samples, b%samples])
            if (all(abs(step) <= 10 * epsilon(1.0_wp) * max(1.0_wp, abs(u)))) exit
        end do
        u = [modulo(u(1), real(size(a%node, 2) - 1, wp)), &
            modulo(u(2), real(size(b%node, 2) - 1, wp))]
        call curve_point(a, u(1), xa, ta)
        call curve_point(b, u(2), xb, tb)
        contact%point(:, 1) = xa
        contact%point(:, 2) = xb
        contact%distance = norm2(xb + contact%shift - xa)
        contact%s = [arc_of(a, u(1)), arc_of(b, u(2))]
    end subroutine refine_contact

    !> Span parameter (0 at the first master node, 1 per span) of arc length s.
    pure real(wp) function parameter_of(yarn, s) result(u)
        type(texgen_yarn_type), intent(in) :: yarn
        real(wp), intent(in) :: s
        integer :: k
        do k = 1, size(yarn%s) - 1
            if (yarn%s(k) >= s) exit
        end do
        k = min(k, size(yarn%s) - 1)
        u = (k - 1 + (s - yarn%s(k - 1)) / (yarn%s(k) - yarn%s(k - 1))) / yarn%samples
    end function parameter_of

    pure real(wp) function arc_of(yarn, u) result(s)
        type(texgen_yarn_type), intent(in) :: yarn
        real(wp), intent(in) :: u
        integer :: k
        real(wp) :: t
        k = min(int(u * yarn%samples), size(yarn%s) - 2)
        t = u * yarn%samples - k
        s = yarn%s(k) + t * (yarn%s(k + 1) - yarn%s(k))
    end function arc_of

    !> Point and derivative (per unit span parameter) of the curve at span parameter u.
    pure subroutine curve_point(yarn, u, x, dx)
        type(texgen_yarn_type), intent(in) :: yarn
        real(wp), intent(in) :: u
        real(wp), intent(out) :: x(3), dx(3)
        real(wp) :: t, shift(3), v
        integer :: i, n_spans, wraps

        n_spans = size(yarn%node, 2) - 1
        wraps = floor(u / n_spans)
        v = u - wraps * n_spans
        shift = wraps * yarn%period
        i = min(int(v) + 1, n_spans)
        t = v - (i - 1)
        associate(p0 => yarn%node(:, i), p1 => yarn%node(:, i + 1), &
                m0 => yarn%tangent(:, i, 1), m1 => yarn%tangent(:, i, 2))
            if (yarn%linear) then
                x = p0 + t * (p1 - p0)
                dx = p1 - p0
            else
                x = (2 * t**3 - 3 * t**2 + 1) * p0 + (t**3 - 2 * t**2 + t) * m0 &
                    + (-2 * t**3 + 3 * t**2) * p1 + (t**3 - t**2) * m1
                dx = (6 * t**2 - 6 * t) * p0 + (3 * t**2 - 4 * t + 1) * m0 &
                    + (-6 * t**2 + 6 * t) * p1 + (3 * t**2 - 2 * t) * m1
            end if
        end associate
        x = x + shift
    end subroutine curve_point

    !> Radius of yarn y's elliptic section (Width x Height) at sample segment k in
    !> direction u (u = 0: the larger half axis).
    pure real(wp) function half_thickness(yarn, k, u) result(r)
        type(texgen_yarn_type), intent(in) :: yarn
        integer, intent(in) :: k
        real(wp), intent(in) :: u(3)
        real(wp) :: t(3), v(3), side(3), up(3), c1, c2

        t = yarn%x(:, k) - yarn%x(:, k - 1)
        t = t / norm2(t)
        v = u - dot_product(u, t) * t
        r = 0.5_wp * max(yarn%width, yarn%height)
        if (norm2(v) <= epsilon(1.0_wp)) return
        v = v / norm2(v)
        up = yarn%up(:, k) - dot_product(yarn%up(:, k), t) * t
        if (norm2(up) <= epsilon(1.0_wp)) return
        up = up / norm2(up)
        side = [t(2) * up(3) - t(3) * up(2), t(3) * up(1) - t(1) * up(3), &
            t(1) * up(2) - t(2) * up(1)]
        c1 = dot_product(v, side) / (0.5_wp * yarn%width)
        c2 = dot_product(v, up) / (0.5_wp * yarn%height)
        r = 1.0_wp / sqrt(c1**2 + c2**2)
    end function half_thickness

    !> Parameters (in [0, 1]) of the closest points of segments p0-p1 and q0-q1.
    pure subroutine closest_points(p0, p1, q0, q1, s, t)
        real(wp), intent(in) :: p0(3), p1(3), q0(3), q1(3)
        real(wp), intent(out) :: s, t
        real(wp) :: d1(3), d2(3), r(3), a, e, f, c, b, denominator

        d1 = p1 - p0
        d2 = q1 - q0
        r = p0 - q0
        a = dot_product(d1, d1)
        e = dot_product(d2, d2)
        f = dot_product(d2, r)
        c = dot_product(d1, r)
        b = dot_product(d1, d2)
        denominator = a * e - b * b
        s = 0.0_wp
        if (denominator > epsilon(1.0_wp) * a * e) s = min(max((b * f - c * e) / denominator, &
            0.0_wp), 1.0_wp)
        t = (b * s + f) / e
        if (t < 0.0_wp) then
            t = 0.0_wp
            s = min(max(-c / a, 0.0_wp), 1.0_wp)
        else if (t > 1.0_wp) then
            t = 1.0_wp
            s = min(max((b - c) / a, 0.0_wp), 1.0_wp)
        end if
    end subroutine closest_points

    !> Nodes, yarns, gap-holders, periodic links and the anchor of the cell (in m).
    subroutine build_cell(fabric, yarns, cell, scale, contacts, net, error)
        type(fabric_config_type), intent(in) :: fabric
        type(texgen_yarn_type), intent(in) :: yarns(:)
        real(wp), intent(in) :: cell(2), scale
        type(contact_type), intent(inout) :: contacts(:)
        type(net_builder_type), intent(inout) :: net
        type(error_type), allocatable, intent(out) :: error
        integer :: y, k, n, c, side, first, last, leader, follower, anchor
        real(wp) :: total, cut, strain(3), gap(3), period(3), position(3)
        real(wp), allocatable :: s(:), gaps(:), chain(:, :)
        integer, allocatable :: who(:), order(:), list(:)
        logical, allocatable :: wrapped(:, :)
        character(len=300) :: buffer

        strain = [fabric%strain, fabric%lateral_strain, 0.0_wp]
        allocate(wrapped(2, size(contacts)), source=.false.)
        anchor = 0
        do y = 1, size(yarns)
            total = yarns(y)%s(size(yarns(y)%s) - 1)
            ! This yarn's contact points, coded 2 * (contact - 1) + side.
            allocate(s(0), who(0))
            do c = 1, size(contacts)
                do side = 1, 2
                    if (contacts(c)%yarn(side) /= y) cycle
                    s = [s, contacts(c)%s(side)]
                    who = [who, 2 * (c - 1) + side]
                end do
            end do
            n = size(s)
            order = sort_index(s)
            s = s(order)
            who = who(order)
            ! Cut in the middle of the longest stretch without contacts.
            cut = 0.0_wp
            if (n > 0) then
                gaps = [s(2:n) - s(1:n - 1), s(1) + total - s(n)]
                k = maxloc(gaps, dim=1)
                cut = modulo(s(k) + 0.5_wp * gaps(k), total)
                ! A clamped sample: of equally long stretches the one whose middle lies
                ! first along the yarn's period (modulo the cell), so that the yarns of
                ! one direction end in line.
                if (fabric%boundary == 'clamped') call first_of_ties(yarns(y), s, gaps, cut)
            end if
            ! From the cut onwards; points before it lie one period on.
            allocate(list(0), chain(3, n))
            do k = 1, n
                side = who(1 + modulo(k - 1 + count(s < cut), n))
                c = (side - 1) / 2 + 1
                side = side - 2 * (c - 1)
                chain(:, k) = contacts(c)%point(:, side)
                wrapped(side, c) = contacts(c)%s(side) < cut
                if (wrapped(side, c)) chain(:, k) = chain(:, k) + yarns(y)%period
                contacts(c)%node(side) = net%add_node(scale * chain(:, k))
                list = [list, contacts(c)%node(side)]
            end do
            ! The ends: half way between the last contact (one period back) and the first,
            ! on the straight string between them (not on the curve: a string under
            ! tension is straight between contacts, and an end off that line would be a
            ! kink no passage accounts for).
            if (n > 0) then
                position = 0.5_wp * (chain(:, n) - yarns(y)%period + chain(:, 1))
            else
                position = point_at(yarns(y), cut)
            end if
            first = net%add_node(scale * position)
            last = net%add_node(scale * (position + yarns(y)%period))
            list = [first, list, last]
            call net%add_yarn(trim(material_of(y)), list, fabric%elements_per_segment)
            ! The end is the start's image one yarn period on (or the other way round, so
            ! that the follower lies on the +x side and carries the force across the cell).
            period = scale * yarns(y)%period
            ! The force across the cell is the sum of the x reactions of the images one
            ! x period on: a yarn that spans several x periods would count once.
            if (abs(abs(period(1)) - scale * cell(1)) > lattice_tolerance * scale * cell(1) &
                    .and. abs(period(1)) > lattice_tolerance * scale * cell(1)) then
                write(buffer, '("yarn ", i0, " spans ", g0, " cells along x in one period; ", &
                    & "only yarns of one x period (or none) are supported")') y - 1, &
                    period(1) / (scale * cell(1))
                call fatal_error(error, trim(buffer))
                return
            end if
            if (positive(period)) then
                call net%add_link(last, first, strain, .false.)
                if (anchor == 0) anchor = first
            else
                call net%add_link(first, last, strain, .false.)
                if (anchor == 0) anchor = last
            end if
            deallocate(s, who, list, chain)
        end do
        do c = 1, size(contacts)
            associate(p => contacts(c))
                ! gap: the actual distance vector; period: what separates the two nodes
                ! besides it (the lattice vector of the image and the yarns' unwrapping).
                gap = scale * (p%point(:, 2) + p%shift - p%point(:, 1))
                period = scale * (merge(yarns(p%yarn(2))%period, 0.0_wp * gap, &
                    wrapped(2, c)) - merge(yarns(p%yarn(1))%period, 0.0_wp * gap, &
                    wrapped(1, c)) - p%shift)
                if (positive(period) .or. all(abs(period) <= lattice_tolerance * scale &
                        * maxval(cell))) then
                    leader = p%node(1)
                    follower = p%node(2)
                else
                    leader = p%node(2)
                    follower = p%node(1)
                    period = -period
                end if
                if (all(abs(period) <= lattice_tolerance * scale * maxval(cell))) &
                    period = 0.0_wp
                if (abs(period(1)) > lattice_tolerance * scale * cell(1) .and. &
                        abs(period(1) - scale * cell(1)) > lattice_tolerance * scale * cell(1)) &
                        then
                    write(buffer, '("contact ", i0, " between yarns ", i0, " and ", i0, &
                        & " spans ", g0, " cells along x; only neighbouring cells are ", &
                        & "supported")') c, p%yarn - 1, period(1) / (scale * cell(1))
                    call fatal_error(error, trim(buffer))
                    return
                end if
                call net%add_link(follower, leader, strain, .true., period)
                ! Hold one contact against rigid translation (a leader: not linked).
                if (c == 1) anchor = leader
            end associate
        end do
        call net%add_support('anchor', [anchor], 'xyz', [0.0_wp, 0.0_wp, 0.0_wp])
    contains
        subroutine first_of_ties(yarn, s, gaps, cut)
            type(texgen_yarn_type), intent(in) :: yarn
            real(wp), intent(in) :: s(:), gaps(:)
            real(wp), intent(inout) :: cut
            real(wp) :: candidate, key, best, direction(2)
            integer :: j
            direction = abs(yarn%period(1:2)) / norm2(yarn%period(1:2))
            best = huge(1.0_wp)
            do j = 1, size(gaps)
                if (gaps(j) < (1.0_wp - lattice_tolerance) * maxval(gaps)) cycle
                candidate = modulo(s(j) + 0.5_wp * gaps(j), total)
                key = modulo(dot_product(point_at(yarn, candidate), [direction, 0.0_wp] &
                    * [1.0_wp / cell(1), 1.0_wp / cell(2), 0.0_wp]) + lattice_tolerance, &
                    1.0_wp)
                if (key < best) then
                    best = key
                    cut = candidate
                end if
            end do
        end subroutine first_of_ties

        logical function positive(v)
            real(wp), intent(in) :: v(3)
            real(wp) :: small
            small = lattice_tolerance * scale * maxval(cell)
            positive = v(1) > small .or. (abs(v(1)) <= small .and. v(2) > small)
        end function positive

        function material_of(y) result(name)
            integer, intent(in) :: y
            character(len=:), allocatable :: name
            integer :: last_given
            last_given = 0
            do k = 1, size(fabric%texgen_materials)
                if (len_trim(fabric%texgen_materials(k)) > 0) last_given = k
            end do
            name = trim(fabric%texgen_materials(min(y, last_given)))
        end function material_of
    end subroutine build_cell

    !> A clamped sample of fabric%cells(1) x fabric%cells(2) copies of the periodic cell
    !> `unit` (lattice `period`, m). Each yarn runs on through the copies along its own
    !> period as one yarn (it may slide across the cells' edges); its ends are the first
    !> and the last copy's. A gap-holder whose partner lies in a copy outside the sample
    !> is dropped with its two contact nodes (the yarns run straight past them). Yarns
    !> along x are held at their left end (`left`) and pulled at the right (`right`,
    !> strain * sample length); the others' ends are free or held in y and z ('rollers',
    !> set `sides`), as for the woven generator.
    subroutine tile_sample(fabric, unit, period, net, error)
        type(fabric_config_type), intent(in) :: fabric
        type(net_builder_type), intent(in) :: unit
        real(wp), intent(in) :: period(2)
        type(net_builder_type), intent(inout) :: net
        type(error_type), allocatable, intent(out) :: error
        integer :: nx, ny, a, b, k, y, n, step(2), shift(2), node, first, last
        integer, allocatable :: id(:, :, :), chain(:), left(:), right(:), sides(:)
        integer, allocatable :: moved(:, :)
        ! The gap-holders (links) and the copies between each one's follower and leader.
        integer, allocatable :: gaps(:), gap_copies(:, :)
        logical, allocatable :: orphan(:, :, :)
        real(wp) :: offset(3)
        character(len=200) :: buffer

        nx = fabric%cells(1)
        ny = fabric%cells(2)
        n = unit%n_nodes
        allocate(id(n, 0:nx - 1, 0:ny - 1), source=0)
        allocate(orphan(n, 0:nx - 1, 0:ny - 1), source=.false.)
        allocate(left(0), right(0), sides(0))
        call get_window_shifts(error)
        if (allocated(error)) return
        ! Gap-holders: the leader of the follower in copy (a, b) is in copy (a, b) + its
        ! lattice part; outside the sample both contact nodes go.
        allocate(gaps(0))
        do k = 1, unit%n_links
            if (unit%links(k)%gap) gaps = [gaps, k]
        end do
        allocate(gap_copies(2, size(gaps)))
        do k = 1, size(gaps)
            gap_copies(:, k) = lattice_part(unit%links(gaps(k)))
        end do
        do k = 1, size(gaps)
            associate(link => unit%links(gaps(k)), copies => gap_copies(:, k))
                do b = 0, ny - 1
                    do a = 0, nx - 1
                        if (.not. inside(a + copies(1), b + copies(2))) &
                            orphan(link%follower, a, b) = .true.
                        if (.not. inside(a - copies(1), b - copies(2))) &
                            orphan(link%leader, a, b) = .true.
                    end do
                end do
            end associate
        end do
        do y = 1, size(unit%yarns)
            associate(list => unit%yarns(y)%nodes)
                first = list(1)
                last = list(size(list))
                offset = unit%position(:, last) - unit%position(:, first)
                step = nint(offset(1:2) / period)
                if (any(abs(offset(1:2) - step * period) > lattice_tolerance &
                        * maxval(period)) .or. all(step == 0)) then
                    write(buffer, '("yarn ", i0, " does not end one lattice vector from its ", &
                        & "start: cannot tile it into a sample")') y - 1
                    call fatal_error(error, trim(buffer))
                    return
                end if
                ! One yarn per chain of copies along `step`, from each copy whose
                ! predecessor lies outside the sample.
                do b = 0, ny - 1
                    do a = 0, nx - 1
                        if (inside(a - step(1), b - step(2))) cycle
                        chain = [node_of(first, a, b)]
                        shift = [a, b]
                        do while (inside(shift(1), shift(2)))
                            do k = 2, size(list)
                                if (orphan(list(k), shift(1), shift(2))) cycle
                                chain = [chain, node_of(list(k), shift(1), shift(2))]
                            end do
                            shift = shift + step
                        end do
                        call net%add_yarn(unit%yarns(y)%material, chain, &
                            unit%yarns(y)%elements_per_segment)
                        if (step(1) /= 0) then
                            if (step(1) > 0) then
                                left = [left, chain(1)]
                                right = [right, chain(size(chain))]
                            else
                                left = [left, chain(size(chain))]
                                right = [right, chain(1)]
                            end if
                        else
                            sides = [sides, chain(1), chain(size(chain))]
                        end if
                    end do
                end do
            end associate
        end do
        do k = 1, size(gaps)
            associate(link => unit%links(gaps(k)), copies => gap_copies(:, k))
                do b = 0, ny - 1
                    do a = 0, nx - 1
                        if (orphan(link%follower, a, b)) cycle
                        call net%add_link(node_of(link%follower, a, b), node_of(link%leader, &
                            a + copies(1), b + copies(2)), [0.0_wp, 0.0_wp, 0.0_wp], .true.)
                    end do
                end do
            end associate
        end do
        call net%add_support('left', left, 'xyz', [0.0_wp, 0.0_wp, 0.0_wp])
        call net%add_support('right', right, 'xyz', &
            [fabric%strain * nx * period(1), 0.0_wp, 0.0_wp])
        if (fabric%sides == 'rollers' .and. size(sides) > 0) &
            call net%add_support('sides', sides, 'yz', [0.0_wp, 0.0_wp, 0.0_wp])
    contains
        logical function inside(i, j)
            integer, intent(in) :: i, j
            inside = i >= 0 .and. i < nx .and. j >= 0 .and. j < ny
        end function inside

        !> Node k of copy (i, j), made on first use.
        integer function node_of(k, i, j) result(found)
            integer, intent(in) :: k, i, j
            if (id(k, i, j) == 0) id(k, i, j) = net%add_node(unit%position(:, k) &
                + [(i - moved(1, k)) * period(1), (j - moved(2, k)) * period(2), 0.0_wp])
            found = id(k, i, j)
        end function node_of

        !> Copies between a gap-holder's follower and its leader, once both yarns are
        !> moved into the window.
        function lattice_part(link) result(copies)
            type(link_config_type), intent(in) :: link
            integer :: copies(2)
            copies = nint(link%period(1:2) / period) - moved(:, link%follower) &
                + moved(:, link%leader)
        end function lattice_part

        !> The sample's window starts where the yarns along x start (x) and where those
        !> along y start (y); every yarn of the cell is moved by whole periods so that
        !> its middle lies in the window's first cell (moved(:, node) for its nodes), so
        !> the sample's edges are the cell's yarn ends.
        subroutine get_window_shifts(error)
            type(error_type), allocatable, intent(out) :: error
            real(wp) :: origin(2), middle(3), span(3)
            integer :: yy, d
            origin = huge(1.0_wp)
            do yy = 1, size(unit%yarns)
                associate(list => unit%yarns(yy)%nodes)
                    span = unit%position(:, list(size(list))) - unit%position(:, list(1))
                    do d = 1, 2
                        if (abs(span(d)) > 0.5_wp * period(d)) origin(d) = min(origin(d), &
                            min(unit%position(d, list(1)), unit%position(d, list(size(list)))))
                    end do
                end associate
            end do
            do d = 1, 2
                if (origin(d) == huge(1.0_wp)) then
                    call fatal_error(error, 'no yarn runs along ' // merge('x', 'y', d == 1) &
                        // ' through the cell: cannot clamp a sample of it')
                    return
                end if
            end do
            allocate(moved(2, n), source=0)
            do yy = 1, size(unit%yarns)
                associate(list => unit%yarns(yy)%nodes)
                    middle = 0.5_wp * (unit%position(:, list(1)) &
                        + unit%position(:, list(size(list))))
                    do d = 1, 2
                        moved(d, list) = floor((middle(d) - origin(d)) / period(d) &
                            + lattice_tolerance)
                    end do
                end associate
            end do
        end subroutine get_window_shifts
    end subroutine tile_sample

    !> The centre line's point at arc length s of the first period.
    pure function point_at(yarn, s) result(x)
        type(texgen_yarn_type), intent(in) :: yarn
        real(wp), intent(in) :: s
        real(wp) :: x(3), t
        integer :: k
        do k = 1, size(yarn%s) - 1
            if (yarn%s(k) >= s) exit
        end do
        k = min(k, size(yarn%s) - 1)
        t = (s - yarn%s(k - 1)) / (yarn%s(k) - yarn%s(k - 1))
        x = yarn%x(:, k - 1) + t * (yarn%x(:, k) - yarn%x(:, k - 1))
    end function point_at

end module yarnfort_generate_texgen
