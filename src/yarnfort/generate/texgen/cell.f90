! SPDX-License-Identifier: MIT
!> The periodic cell of a TexGen model: nodes, yarns, gap-holders, periodic links, anchor.
!>
!> The network: between contacts a string under tension is straight, so each yarn gets a
!> node at each of its contacts and is otherwise straight; its ends lie in the middle of
!> its longest stretch without contacts and are periodic images of each other (one
!> yarn period apart). The two nodes of a contact are joined by a gap-holder of the
!> actual distance (scaled by the gap factor); for a contact with a periodic image the
!> holder's offset also carries the lattice vector, which follows the macroscopic strain.
module yarnfort_generate_texgen_cell
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: fabric_config_type
    use yarnfort_generate_net_builder, only: net_builder_type
    use yarnfort_sort, only: sort_index
    use yarnfort_text, only: format_integer, format_short
    use yarnfort_generate_texgen_curves, only: texgen_yarn_type, lattice_tolerance, point_at
    use yarnfort_generate_texgen_contacts, only: contact_type
    implicit none
    private

    public :: build_cell

    !> Contacts closer along a yarn than this fraction of its length in one period are
    !> at one point (the contact search locates them to about 1e-10 of it): one node.
    real(wp), parameter :: same_point_tolerance = 1.0e-6_wp

contains

    !> Nodes, yarns, gap-holders, periodic links and the anchor of the cell (in m).
    subroutine build_cell(fabric, yarns, cell, scale, contacts, net, error)
        type(fabric_config_type), intent(in) :: fabric
        type(texgen_yarn_type), intent(in) :: yarns(:)
        real(wp), intent(in) :: cell(2), scale
        type(contact_type), intent(inout) :: contacts(:)
        type(net_builder_type), intent(inout) :: net
        type(error_type), allocatable, intent(out) :: error
        integer :: y, k, n, c, side, first, last, anchor
        real(wp) :: total, cut, strain(3), period(3), position(3)
        real(wp), allocatable :: s(:), gaps(:), chain(:, :), along(:)
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
            ! From the cut onwards; points before it lie one period on. Contacts at one
            ! point of the yarn (a yarn pressed by two others there, e.g. between two
            ! layers or between its neighbours on either side) share one node: two nodes
            ! there would make a zero-length element.
            allocate(list(0), chain(3, n), along(n))
            do k = 1, n
                side = who(1 + modulo(k - 1 + count(s < cut), n))
                c = (side - 1) / 2 + 1
                side = side - 2 * (c - 1)
                chain(:, k) = contacts(c)%point(:, side)
                wrapped(side, c) = contacts(c)%s(side) < cut
                along(k) = contacts(c)%s(side)
                if (wrapped(side, c)) then
                    chain(:, k) = chain(:, k) + yarns(y)%period
                    along(k) = along(k) + total
                end if
                if (k > 1) then
                    if (along(k) - along(k - 1) <= same_point_tolerance * total) then
                        chain(:, k) = chain(:, k - 1)
                        contacts(c)%node(side) = list(size(list))
                        cycle
                    end if
                end if
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
                write(buffer, '("TexGen yarn ", i0, " spans ", i0, " cells along x in one ", &
                    & "period (its last master node lies ", i0, " x repeats from its first); ", &
                    & "only yarns that repeat after one cell along x (or run along y) are ", &
                    & "supported: give it the master nodes of one x repeat")') y - 1, &
                    nint(abs(period(1)) / (scale * cell(1))), &
                    nint(abs(period(1)) / (scale * cell(1)))
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
            deallocate(s, who, list, chain, along)
        end do
        call link_contacts(yarns, cell, scale, strain, contacts, wrapped, net, anchor, error)
        if (allocated(error)) return
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

    !> Gap-holders of the contacts between their nodes. Nodes joined by contacts form
    !> groups (one node on a yarn may be in several contacts); each group gets a tree of
    !> gap-holders whose root lies furthest towards -x (then -y), so that every node lies
    !> at most one cell along +x from its root: the force across the cell is then the
    !> sum of the x reactions of the nodes one cell on. A contact that would close a loop
    !> of gap-holders (the same two nodes touching again through a periodic image, e.g.
    !> a yarn between its two neighbours when widths equal the spacing) adds none: the
    !> holders are rigid, and the loop's lattice vector would pin the cell's period.
    !> `anchor`: the root of the first contact's group (unchanged without contacts).
    subroutine link_contacts(yarns, cell, scale, strain, contacts, wrapped, net, anchor, &
            error)
        type(texgen_yarn_type), intent(in) :: yarns(:)
        real(wp), intent(in) :: cell(2), scale, strain(3)
        type(contact_type), intent(in) :: contacts(:)
        logical, intent(in) :: wrapped(:, :)
        type(net_builder_type), intent(inout) :: net
        integer, intent(inout) :: anchor
        type(error_type), allocatable, intent(out) :: error
        ! Per contact: lattice vector from node 1 to node 2 besides the gap; the child end
        ! (1 or 2) of a tree edge, 0 for a contact that adds no gap-holder.
        real(wp) :: period(3, size(contacts)), small
        integer :: child(size(contacts))
        ! Per node of the net: lattice offset in its group, group, root of the group.
        real(wp), allocatable :: offset(:, :)
        integer, allocatable :: group(:), root(:), queue(:)
        integer :: c, k, g, head, node, other, cells_x
        character(len=60) :: buffer

        small = lattice_tolerance * scale * maxval(cell)
        do c = 1, size(contacts)
            associate(p => contacts(c))
                period(:, c) = scale * (merge(yarns(p%yarn(2))%period, 0.0_wp * p%shift, &
                    wrapped(2, c)) - merge(yarns(p%yarn(1))%period, 0.0_wp * p%shift, &
                    wrapped(1, c)) - p%shift)
                if (all(abs(period(:, c)) <= small)) period(:, c) = 0.0_wp
            end associate
        end do
        allocate(offset(3, net%n_nodes), source=0.0_wp)
        allocate(group(net%n_nodes), source=0)
        allocate(root(0), queue(0))
        child = 0
        ! Groups by breadth-first search from each contact's first node not yet grouped.
        do c = 1, size(contacts)
            if (group(contacts(c)%node(1)) /= 0) cycle
            g = size(root) + 1
            root = [root, contacts(c)%node(1)]
            group(contacts(c)%node(1)) = g
            queue = [contacts(c)%node(1)]
            head = 1
            do while (head <= size(queue))
                node = queue(head)
                head = head + 1
                do k = 1, size(contacts)
                    if (all(contacts(k)%node /= node)) cycle
                    if (contacts(k)%node(1) == node) then
                        other = contacts(k)%node(2)
                        if (group(other) /= 0) cycle
                        offset(:, other) = offset(:, node) + period(:, k)
                    else
                        other = contacts(k)%node(1)
                        if (group(other) /= 0) cycle
                        offset(:, other) = offset(:, node) - period(:, k)
                    end if
                    group(other) = g
                    queue = [queue, other]
                    ! Root: furthest towards -x, then -y.
                    if (before(offset(:, other), offset(:, root(g)))) root(g) = other
                end do
            end do
        end do
        ! Tree edges from each root outwards (the same search again, now from the root).
        group = -group
        do g = 1, size(root)
            group(root(g)) = g
            queue = [root(g)]
            head = 1
            do while (head <= size(queue))
                node = queue(head)
                head = head + 1
                do k = 1, size(contacts)
                    if (child(k) /= 0 .or. all(contacts(k)%node /= node)) cycle
                    other = sum(contacts(k)%node) - node
                    if (other == node .or. group(other) > 0) cycle
                    group(other) = g
                    queue = [queue, other]
                    child(k) = merge(2, 1, contacts(k)%node(2) == other)
                    cells_x = nint((offset(1, other) - offset(1, root(g))) / (scale * cell(1)))
                    if (cells_x > 1) then
                        write(buffer, '("TexGen yarns ", i0, " and ", i0)') &
                            contacts(k)%yarn - 1
                        call fatal_error(error, trim(buffer) // ' touch at (' &
                            // format_short(contacts(k)%point(1, 1)) // ', ' &
                            // format_short(contacts(k)%point(2, 1)) // ', ' &
                            // format_short(contacts(k)%point(3, 1)) // ') in a group of ' &
                            // 'contacts that reaches over ' // format_integer(cells_x + 1) &
                            // ' cells along x; at most two neighbouring cells are ' &
                            // "supported: let every yarn's first master node lie in the " &
                            // 'same cell')
                        return
                    end if
                end do
            end do
        end do
        do c = 1, size(contacts)
            if (child(c) == 0) cycle
            associate(p => contacts(c))
                node = p%node(child(c))
                other = p%node(3 - child(c))
                call net%add_link(node, other, strain, .true., offset(:, node) &
                    - offset(:, other))
            end associate
        end do
        if (size(contacts) > 0) anchor = root(group(contacts(1)%node(1)))
    contains
        !> Lattice offset u before v: smaller x, then smaller y (beyond rounding).
        logical function before(u, v)
            real(wp), intent(in) :: u(3), v(3)
            before = u(1) < v(1) - small .or. (abs(u(1) - v(1)) <= small .and. &
                u(2) < v(2) - small)
        end function before
    end subroutine link_contacts

end module yarnfort_generate_texgen_cell
