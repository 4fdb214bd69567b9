! SPDX-License-Identifier: MIT
!> Checks of the network part of a read `config_type`: nodes finite, yarns through
!> existing nodes of a defined material with no zero-length segments or elements and no
!> two segments joining the same two nodes, supports and loads on existing nodes with at
!> most one support per coordinate and no force on a prescribed one. Also the small
!> helpers the other checks share: a name defined, a list of node ids, bucketing by node.
module yarnfort_input_network_checks
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use, intrinsic :: iso_fortran_env, only: int64
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type, yarn_config_type
    use yarnfort_input_groups, only: check_yarn_variables, check_support_variables, &
        check_load_variables
    use yarnfort_input_fields, only: quoted_list, suggestion, check_item_name, group_label
    use yarnfort_text, only: format_integer, format_real
    use yarnfort_material_force_law, only: is_usable_stretch, max_stretch
    implicit none
    private

    public :: check_nodes, check_yarns, check_duplicate_segments, check_supports
    public :: check_loads, yarn_label, coincidence_tolerance, check_node_list
    public :: check_defined, sort_by_key

    !> A segment between consecutive yarn nodes is of zero length when it is not longer
    !> than this times the diagonal of the box around all nodes.
    real(wp), parameter :: coincidence_tolerance = 100 * epsilon(1.0_wp)
    !> Largest network the solver indexes with default integers: 3 unknowns per node and
    !> a 6 x 6 Jacobian block per element (elements_per_segment multiplies both).
    integer, parameter :: max_network_nodes = huge(1) / 3
    integer, parameter :: max_network_elements = huge(1) / 36
    character(len=1), parameter :: axis(3) = ['x', 'y', 'z']

contains

    subroutine check_nodes(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer :: n_nodes, bad(2)

        n_nodes = 0
        if (allocated(config%node_positions)) n_nodes = size(config%node_positions, 2)
        if (n_nodes == 0) then
            call fatal_error(error, "no nodes: give &nodes xyz = ... / or &geometry file = " &
                // "'...' /")
            return
        end if
        ! The first coordinate that is not finite (k, n), in input order.
        bad = findloc(ieee_is_finite(config%node_positions), .false.)
        if (bad(2) == 0) return
        associate(k => bad(1), n => bad(2))
            if (len_trim(config%geometry%file) > 0) then
                call fatal_error(error, node_source(config) // ': node ' // format_integer(n) &
                    // ' ' // axis(k) // ' = ' // format_real(config%node_positions(k, n)) &
                    // ' is not finite')
            else
                call fatal_error(error, '&nodes: xyz(' // format_integer(3 * (n - 1) + k) &
                    // ') = ' // format_real(config%node_positions(k, n)) // ' (node ' &
                    // format_integer(n) // ' ' // axis(k) // ') is not finite')
            end if
        end associate
    end subroutine check_nodes

    !> '&yarn #k', or 'yarn #k of the geometry file' when the yarns come from a file.
    function yarn_label(config, k) result(label)
        type(config_type), intent(in) :: config
        integer, intent(in) :: k
        character(len=:), allocatable :: label

        label = '&yarn #' // format_integer(k)
        if (len_trim(config%geometry%file) > 0) label = 'yarn #' // format_integer(k) &
            // " of &geometry file '" // trim(config%geometry%file) // "'"
    end function yarn_label

    subroutine check_yarns(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer :: y, i, n_nodes, n_yarns, a, b
        !> Elements and new nodes of the yarns so far (elements_per_segment may be large).
        integer(int64) :: n_elements, n_new_nodes
        logical, allocatable :: used(:)
        real(wp) :: scale
        character(len=:), allocatable :: label
        character(len=80) :: counts

        n_yarns = 0
        if (allocated(config%yarns)) n_yarns = size(config%yarns)
        if (n_yarns == 0) then
            call fatal_error(error, 'no yarns: give &yarn groups or yarn lines in the ' &
                // '&geometry file')
            return
        end if
        n_nodes = size(config%node_positions, 2)
        scale = norm2(maxval(config%node_positions, dim=2) - minval(config%node_positions, dim=2))
        allocate(used(n_nodes), source=.false.)
        n_elements = 0
        n_new_nodes = 0
        do y = 1, n_yarns
            associate(yarn => config%yarns(y))
                label = yarn_label(config, y)
                if (len_trim(yarn%material) == 0) then
                    call fatal_error(error, label // ': material is not set')
                    return
                end if
                call check_defined(error, label, 'material', yarn%material, &
                    config%materials%name, 'defined by any &material', 'defined')
                if (allocated(error)) return
                call check_yarn_variables(yarn, label, error)
                if (allocated(error)) return
                if (size(yarn%nodes) < 2) then
                    call fatal_error(error, label // ': nodes has ' &
                        // format_integer(size(yarn%nodes)) &
                        // ' node id(s); a yarn needs at least 2')
                    return
                end if
                n_elements = n_elements + (size(yarn%nodes) - 1) &
                    * int(yarn%elements_per_segment, int64)
                n_new_nodes = n_new_nodes + (size(yarn%nodes) - 1) &
                    * (int(yarn%elements_per_segment, int64) - 1)
                if (n_elements > max_network_elements &
                    .or. n_nodes + n_new_nodes > max_network_nodes) then
                    write(counts, '(i0, " elements and ", i0, " nodes")') n_elements, &
                        n_nodes + n_new_nodes
                    call fatal_error(error, label // ': elements_per_segment = ' &
                        // format_integer(yarn%elements_per_segment) // ' makes the network ' &
                        // trim(counts) // ' (with the yarns before it); at most ' &
                        // format_integer(max_network_elements) // ' elements and ' &
                        // format_integer(max_network_nodes) // ' nodes fit the solver')
                    return
                end if
                do i = 1, size(yarn%nodes)
                    call require_node(error, label, i, yarn%nodes(i), n_nodes)
                    if (allocated(error)) return
                    used(yarn%nodes(i)) = .true.
                end do
                do i = 1, size(yarn%nodes) - 1
                    a = yarn%nodes(i)
                    b = yarn%nodes(i + 1)
                    if (a == b) then
                        call fatal_error(error, label // ': nodes(' // format_integer(i) &
                            // ') = nodes(' // format_integer(i + 1) // ') = ' &
                            // format_integer(a) // ': zero-length segment')
                        return
                    end if
                    associate(x => config%node_positions(:, a))
                        if (norm2(config%node_positions(:, b) - x) &
                                <= coincidence_tolerance * scale) then
                            call fatal_error(error, label // ': nodes ' // format_integer(a) &
                                // ' and ' // format_integer(b) // ' (nodes(' &
                                // format_integer(i) // ') and nodes(' &
                                // format_integer(i + 1) // ')) are at the same position (' &
                                // format_real(x(1)) // ', ' // format_real(x(2)) // ', ' &
                                // format_real(x(3)) // '): zero-length element')
                            return
                        end if
                    end associate
                end do
                ! After the node ids and segment lengths: the stretches use them.
                call check_element_lengths(config, yarn, label, error)
                if (allocated(error)) return
            end associate
        end do
        i = findloc(used, .false., dim=1)
        if (i > 0) call fatal_error(error, node_source(config) // ': node ' &
            // format_integer(i) // ' is on no yarn (a node off all yarns has no stiffness)')
    end subroutine check_yarns

    !> Per-element reference lengths of a yarn (`length0` or `stretch`; yarns of a
    !> geometry file or a generator may leave them unallocated):
    !> one value per element, not both, and not on a yarn whose material has a prestress
    !> (which would set the same lengths another way). Their ranges (> 0) are checked
    !> with the group.
    subroutine check_element_lengths(config, yarn, label, error)
        type(config_type), intent(in) :: config
        type(yarn_config_type), intent(in) :: yarn
        character(len=*), intent(in) :: label
        type(error_type), allocatable, intent(out) :: error
        integer(int64) :: n_elements
        integer :: n_values, n(2), e, s
        real(wp) :: length, stretch, value
        character(len=:), allocatable :: name

        n = 0
        if (allocated(yarn%length0)) n(1) = size(yarn%length0)
        if (allocated(yarn%stretch)) n(2) = size(yarn%stretch)
        if (all(n > 0)) then
            call fatal_error(error, label // ': length0 and stretch are both given ' &
                // '(each sets the reference lengths of the elements: give one)')
            return
        end if
        n_values = maxval(n)
        if (n_values == 0) return
        name = trim(merge('length0', 'stretch', n(1) > 0))
        n_elements = (size(yarn%nodes) - 1) * int(yarn%elements_per_segment, int64)
        if (n_values /= n_elements) then
            call fatal_error(error, label // ': ' // name // ' has ' &
                // format_integer(n_values) // ' values but the yarn has ' &
                // format_integer(int(n_elements)) // ' elements (' &
                // format_integer(size(yarn%nodes) - 1) // ' segments of ' &
                // format_integer(yarn%elements_per_segment) &
                // '): give one value per element, in order along the yarn')
            return
        end if
        ! The material is defined (checked before).
        associate(material => config%materials(findloc(config%materials%name, &
                yarn%material, dim=1)))
            if (material%prestress > 0.0_wp) then
                call fatal_error(error, label // ': ' // name // " is given, but its " &
                    // "material '" // trim(yarn%material) // "' has prestress = " &
                    // format_real(material%prestress) // ' (both set the ' &
                    // 'reference lengths: give one)')
                return
            end if
        end associate
        ! Their stretches l / L0 within the bound of a prestress (is_usable_stretch);
        ! their values are > 0 and finite (checked with the group).
        do e = 1, n_values
            s = (e - 1) / yarn%elements_per_segment + 1
            length = norm2(config%node_positions(:, yarn%nodes(s + 1)) &
                - config%node_positions(:, yarn%nodes(s))) / yarn%elements_per_segment
            if (n(1) > 0) then
                value = yarn%length0(e)
                stretch = length / value
            else
                value = yarn%stretch(e)
                stretch = value
            end if
            if (is_usable_stretch(stretch)) cycle
            call fatal_error(error, label // ': ' // name // '(' // format_integer(e) &
                // ') = ' // format_real(value) // ' stretches element ' &
                // format_integer(e) // ' (length ' // format_real(length) &
                // ' m) by l / L0 = ' // format_real(stretch) &
                // ', outside [' // format_real(1 / max_stretch) // ', ' &
                // format_real(max_stretch) // '] (2**-60 to 2**60: the bound on the ' &
                // 'stretch a prestress gives)')
            return
        end do
    end subroutine check_element_lengths

    !> No two segments, of one yarn or of two, join the same two nodes: their elements
    !> would lie on top of each other (a yarn doubling back, or a yarn listed twice).
    !> Segments are bucketed by their lower node id, so the check is linear in their number.
    subroutine check_duplicate_segments(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        !> Segment s is nodes(i), nodes(i + 1) of a yarn (i = position_of(s)), from its
        !> lower to its upper node id.
        integer, allocatable :: yarn_of(:), position_of(:), lower(:), upper(:)
        !> The segments with lower node a: order(first(a):first(a + 1) - 1).
        integer, allocatable :: first(:), order(:)
        !> `seen(b)`: the last place k in `order` met with upper node b (one of the
        !> current lower node when it is >= first(a)).
        integer, allocatable :: seen(:)
        integer :: n_nodes, n, y, i, a, k

        n_nodes = size(config%node_positions, 2)
        n = sum([(size(config%yarns(y)%nodes) - 1, y = 1, size(config%yarns))])
        allocate(yarn_of(n), position_of(n), lower(n), upper(n))
        n = 0
        do y = 1, size(config%yarns)
            associate(nodes => config%yarns(y)%nodes)
                do i = 1, size(nodes) - 1
                    n = n + 1
                    yarn_of(n) = y
                    position_of(n) = i
                    lower(n) = min(nodes(i), nodes(i + 1))
                    upper(n) = max(nodes(i), nodes(i + 1))
                end do
            end associate
        end do
        call sort_by_key(lower, n_nodes, first, order)
        allocate(seen(n_nodes), source=0)
        do a = 1, n_nodes
            do k = first(a), first(a + 1) - 1
                associate(b => upper(order(k)))
                    if (seen(b) >= first(a)) then
                        call fatal_error(error, segment_text(order(k)) // ' join the same ' &
                            // 'two nodes as ' // segment_text(order(seen(b))) // ': ' &
                            // 'duplicate segment (two strings between one pair of nodes ' &
                            // 'would lie on top of each other)')
                        return
                    end if
                    seen(b) = k
                end associate
            end do
        end do

    contains

        !> "&yarn #2: nodes(3), nodes(4) = 5, 2"
        function segment_text(s) result(text)
            integer, intent(in) :: s
            character(len=:), allocatable :: text

            associate(nodes => config%yarns(yarn_of(s))%nodes, i => position_of(s))
                text = yarn_label(config, yarn_of(s)) // ': nodes(' // format_integer(i) &
                    // '), nodes(' // format_integer(i + 1) // ') = ' &
                    // format_integer(nodes(i)) // ', ' // format_integer(nodes(i + 1))
            end associate
        end function segment_text

    end subroutine check_duplicate_segments

    !> A counting sort of items 1..size(keys) by their key (1..n_keys), linear in both:
    !> the items with key a are order(first(a):first(a + 1) - 1), in their given order.
    pure subroutine sort_by_key(keys, n_keys, first, order)
        integer, intent(in) :: keys(:), n_keys
        integer, allocatable, intent(out) :: first(:), order(:)
        integer, allocatable :: next(:)
        integer :: i, a

        allocate(first(n_keys + 1), source=0)
        do i = 1, size(keys)
            first(keys(i) + 1) = first(keys(i) + 1) + 1
        end do
        first(1) = 1
        do a = 1, n_keys
            first(a + 1) = first(a + 1) + first(a)
        end do
        allocate(order(size(keys)))
        next = first(:n_keys)
        do i = 1, size(keys)
            order(next(keys(i))) = i
            next(keys(i)) = next(keys(i)) + 1
        end do
    end subroutine sort_by_key

    !> Where the nodes come from, for messages.
    function node_source(config) result(source)
        type(config_type), intent(in) :: config
        character(len=:), allocatable :: source

        source = '&nodes'
        if (len_trim(config%geometry%file) > 0) &
            source = "&geometry: file '" // trim(config%geometry%file) // "'"
    end function node_source

    !> Supports: names, fix letters, node ids, and at most one support per coordinate
    !> (`owner(k, node)` is the support prescribing component k of node, or 0).
    subroutine check_supports(config, owner, error)
        type(config_type), intent(in) :: config
        integer, allocatable, intent(out) :: owner(:, :)
        type(error_type), allocatable, intent(out) :: error
        integer :: s, k, i, node
        !> The components that the support prescribes.
        logical :: fixed(3)
        character(len=:), allocatable :: label
        character(len=24), allocatable :: labels(:)

        allocate(owner(3, size(config%node_positions, 2)), source=0)
        if (.not. allocated(config%supports)) return
        labels = [character(len=24) :: (group_label('support', s), s = 1, size(config%supports))]
        do s = 1, size(config%supports)
            associate(support => config%supports(s))
                call check_item_name(error, config%supports%name, labels, s, &
                    ' (give each support a name)', 'used', '')
                if (allocated(error)) return
                label = "&support '" // trim(support%name) // "'"
                call check_fix(error, label, support%fix)
                if (allocated(error)) return
                call check_support_variables(support, label, error)
                if (allocated(error)) return
                fixed = index(support%fix, axis) > 0
                k = findloc(support%displacement /= 0.0_wp .and. .not. fixed, .true., dim=1)
                if (k > 0) then
                    call fatal_error(error, label // ': displacement(' // format_integer(k) &
                        // ') = ' // format_real(support%displacement(k)) // ' but ' &
                        // axis(k) // " is not in fix = '" // trim(support%fix) &
                        // "' (it would be ignored)")
                    return
                end if
                call check_node_list(error, label, support%nodes, size(owner, 2))
                if (allocated(error)) return
                do i = 1, size(support%nodes)
                    node = support%nodes(i)
                    k = findloc(fixed .and. owner(:, node) /= 0, .true., dim=1)
                    if (k > 0) then
                        call fatal_error(error, label // ': node ' // format_integer(node) &
                            // ' ' // axis(k) // " is already prescribed by &support '" &
                            // trim(config%supports(owner(k, node))%name) // "'")
                        return
                    end if
                    where (fixed) owner(:, node) = s
                end do
            end associate
        end do
    end subroutine check_supports

    !> fix: one or more of 'x', 'y', 'z', each at most once.
    subroutine check_fix(error, label, fix)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, fix
        integer :: i

        if (len_trim(fix) == 0) then
            call fatal_error(error, label // ": fix = '' prescribes nothing (use any of x, y, z)")
            return
        end if
        do i = 1, len_trim(fix)
            if (index('xyz', fix(i:i)) == 0) then
                call fatal_error(error, label // ": fix = '" // trim(fix) // "' has '" &
                    // fix(i:i) // "' (use any of x, y, z)")
                return
            end if
            if (index(fix(:i - 1), fix(i:i)) > 0) then
                call fatal_error(error, label // ": fix = '" // trim(fix) // "' has '" &
                    // fix(i:i) // "' twice")
                return
            end if
        end do
    end subroutine check_fix

    !> Loads: node ids, finite forces, no force on a prescribed coordinate.
    subroutine check_loads(config, owner, error)
        type(config_type), intent(in) :: config
        integer, intent(in) :: owner(:, :)
        type(error_type), allocatable, intent(out) :: error
        integer :: l, i, k
        character(len=:), allocatable :: label

        if (.not. allocated(config%loads)) return
        do l = 1, size(config%loads)
            associate(load => config%loads(l))
                label = '&load #' // format_integer(l)
                call check_load_variables(load, label, error)
                if (allocated(error)) return
                call check_node_list(error, label, load%nodes, size(owner, 2))
                if (allocated(error)) return
                do i = 1, size(load%nodes)
                    associate(node => load%nodes(i))
                        k = findloc(load%force /= 0.0_wp .and. owner(:, node) /= 0, .true., &
                            dim=1)
                        if (k == 0) cycle
                        call fatal_error(error, label // ': node ' // format_integer(node) &
                            // ' has force(' // format_integer(k) // ') = ' &
                            // format_real(load%force(k)) // ' but its ' // axis(k) &
                            // " is prescribed by &support '" &
                            // trim(config%supports(owner(k, node))%name) &
                            // "' (the force would be ignored)")
                        return
                    end associate
                end do
            end associate
        end do
    end subroutine check_loads

    !> A list of node ids of a support, load, obstacle or ring: not empty, in range, no
    !> repeats.
    subroutine check_node_list(error, label, nodes, n_nodes)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label
        integer, intent(in) :: nodes(:)
        integer, intent(in) :: n_nodes
        integer, allocatable :: position(:)
        integer :: i

        if (size(nodes) == 0) then
            call fatal_error(error, label // ': nodes is empty (give at least one node id)')
            return
        end if
        allocate(position(n_nodes), source=0)
        do i = 1, size(nodes)
            call require_node(error, label, i, nodes(i), n_nodes)
            if (allocated(error)) return
            if (position(nodes(i)) /= 0) then
                call fatal_error(error, label // ': nodes(' // format_integer(position(nodes(i))) &
                    // ') and nodes(' // format_integer(i) // ') are both node ' &
                    // format_integer(nodes(i)))
                return
            end if
            position(nodes(i)) = i
        end do
    end subroutine check_node_list

    !> nodes(i) = node of group `label` is a node id (1..n_nodes).
    subroutine require_node(error, label, i, node, n_nodes)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label
        integer, intent(in) :: i, node, n_nodes

        if (node < 1 .or. node > n_nodes) then
            call fatal_error(error, label // ': nodes(' // format_integer(i) // ') = ' &
                // format_integer(node) // ' is not a node (node ids are 1..' &
                // format_integer(n_nodes) // ')')
        end if
    end subroutine require_node

    !> `name` is one of `names`; else "<label>: <variable> = 'name' is not <what>
    !> (<listed>: 'a', 'b')" and a did-you-mean.
    subroutine check_defined(error, label, variable, name, names, what, listed)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable, name, names(:), what, listed

        if (any(names == name)) return
        call fatal_error(error, label // ': ' // variable // " = '" // trim(name) &
            // "' is not " // what // ' (' // listed // ': ' // quoted_list(names) // ')' &
            // suggestion(name, names))
    end subroutine check_defined

end module yarnfort_input_network_checks
