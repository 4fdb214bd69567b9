! SPDX-License-Identifier: MIT
!> Checks of the network part of a read `config_type`: nodes finite, yarns through
!> existing nodes of a defined material with no zero-length segments or elements and no
!> two segments joining the same two nodes, supports and loads on existing nodes with at
!> most one support per coordinate and no force on a prescribed one.
module yarnfort_input_network_checks
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use, intrinsic :: iso_fortran_env, only: int64
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type, name_length, yarn_config_type
    use yarnfort_input_groups, only: check_yarn_variables, check_support_variables, &
        check_load_variables
    use yarnfort_input_fields, only: quoted_list, suggestion, check_item_name, group_label
    use yarnfort_text, only: format_integer, format_real
    implicit none
    private

    public :: check_nodes, check_yarns, check_duplicate_segments, check_supports
    public :: check_loads, yarn_label, coincidence_tolerance, check_node_list

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
        integer :: n, k

        if (.not. allocated(config%node_positions)) then
            call fatal_error(error, "no nodes: give &nodes xyz = ... / or &geometry file = " &
                // "'...' /")
            return
        end if
        if (size(config%node_positions, 2) == 0) then
            call fatal_error(error, "no nodes: give &nodes xyz = ... / or &geometry file = " &
                // "'...' /")
            return
        end if
        do n = 1, size(config%node_positions, 2)
            do k = 1, 3
                if (ieee_is_finite(config%node_positions(k, n))) cycle
                if (len_trim(config%geometry%file) > 0) then
                    call fatal_error(error, "&geometry: file '" &
                        // trim(config%geometry%file) // "': node " // format_integer(n) &
                        // ' ' // axis(k) // ' = ' // format_real(config%node_positions(k, n)) &
                        // ' is not finite')
                else
                    call fatal_error(error, '&nodes: xyz(' // format_integer(3 * (n - 1) + k) &
                        // ') = ' // format_real(config%node_positions(k, n)) // ' (node ' &
                        // format_integer(n) // ' ' // axis(k) // ') is not finite')
                end if
                return
            end do
        end do
    end subroutine check_nodes

    !> '&yarn #k', or 'yarn #k of the geometry file' when the yarns come from a file.
    function yarn_label(config, k) result(label)
        type(config_type), intent(in) :: config
        integer, intent(in) :: k
        character(len=:), allocatable :: label

        if (len_trim(config%geometry%file) > 0) then
            label = 'yarn #' // format_integer(k) // " of &geometry file '" &
                // trim(config%geometry%file) // "'"
        else
            label = '&yarn #' // format_integer(k)
        end if
    end function yarn_label

    subroutine check_yarns(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer :: y, i, n_nodes, a, b
        !> Elements and new nodes of the yarns so far (elements_per_segment may be large).
        integer(int64) :: n_elements, n_new_nodes
        logical, allocatable :: used(:)
        real(wp) :: scale, length
        character(len=:), allocatable :: label
        character(len=name_length), allocatable :: material_names(:)
        character(len=80) :: counts

        if (.not. allocated(config%yarns)) then
            call fatal_error(error, 'no yarns: give &yarn groups or yarn lines in the ' &
                // '&geometry file')
            return
        end if
        if (size(config%yarns) == 0) then
            call fatal_error(error, 'no yarns: give &yarn groups or yarn lines in the ' &
                // '&geometry file')
            return
        end if
        material_names = config%materials%name
        n_nodes = size(config%node_positions, 2)
        scale = norm2(maxval(config%node_positions, dim=2) - minval(config%node_positions, dim=2))
        allocate(used(n_nodes), source=.false.)
        n_elements = 0
        n_new_nodes = 0
        do y = 1, size(config%yarns)
            associate(yarn => config%yarns(y))
                label = yarn_label(config, y)
                if (len_trim(yarn%material) == 0) then
                    call fatal_error(error, label // ': material is not set')
                    return
                end if
                if (.not. any(material_names == yarn%material)) then
                    call fatal_error(error, label // ": material = '" // trim(yarn%material) &
                        // "' is not defined by any &material (defined: " &
                        // quoted_list(material_names) // ')' &
                        // suggestion(yarn%material, material_names))
                    return
                end if
                if (allocated(yarn%length0) .and. allocated(yarn%stretch)) then
                    call check_yarn_variables(yarn, label, error)
                else
                    ! Yarns of a geometry file or a generator may leave the lists unset.
                    call check_yarn_variables(with_lists(yarn), label, error)
                end if
                if (allocated(error)) return
                if (size(yarn%nodes) < 2) then
                    call fatal_error(error, label // ': nodes has ' &
                        // format_integer(size(yarn%nodes)) &
                        // ' node id(s); a yarn needs at least 2')
                    return
                end if
                call check_element_lengths(config, y, label, error)
                if (allocated(error)) return
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
                    call require_node(error, label, 'nodes', i, yarn%nodes(i), n_nodes)
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
                    length = norm2(config%node_positions(:, b) - config%node_positions(:, a))
                    if (length <= coincidence_tolerance * scale) then
                        call fatal_error(error, label // ': nodes ' // format_integer(a) &
                            // ' and ' // format_integer(b) // ' (nodes(' // format_integer(i) &
                            // ') and nodes(' // format_integer(i + 1) // ')) are at the ' &
                            // 'same position (' // format_position(config%node_positions(:, a)) &
                            // '): zero-length element')
                        return
                    end if
                end do
            end associate
        end do
        do i = 1, n_nodes
            if (.not. used(i)) then
                call fatal_error(error, node_source(config) // ': node ' // format_integer(i) &
                    // ' is on no yarn (a node off all yarns has no stiffness)')
                return
            end if
        end do
    end subroutine check_yarns

    !> A copy of `yarn` with its unset per-element lists empty.
    function with_lists(yarn) result(copy)
        type(yarn_config_type), intent(in) :: yarn
        type(yarn_config_type) :: copy

        copy = yarn
        if (.not. allocated(copy%length0)) allocate(copy%length0(0))
        if (.not. allocated(copy%stretch)) allocate(copy%stretch(0))
    end function with_lists

    !> Per-element reference lengths of yarn y (`length0` or `stretch`): one value per
    !> element, not both, and not on a yarn whose material has a prestress (which would
    !> set the same lengths another way). Their ranges (> 0) are checked with the group.
    subroutine check_element_lengths(config, y, label, error)
        type(config_type), intent(in) :: config
        integer, intent(in) :: y
        character(len=*), intent(in) :: label
        type(error_type), allocatable, intent(out) :: error
        integer(int64) :: n_elements
        integer :: m
        character(len=:), allocatable :: name

        associate(yarn => config%yarns(y))
            if (is_given(yarn%length0) .and. is_given(yarn%stretch)) then
                call fatal_error(error, label // ': length0 and stretch are both given ' &
                    // '(each sets the reference lengths of the elements: give one)')
                return
            end if
            if (is_given(yarn%length0)) then
                name = 'length0'
                n_elements = size(yarn%length0)
            else if (is_given(yarn%stretch)) then
                name = 'stretch'
                n_elements = size(yarn%stretch)
            else
                return
            end if
            if (n_elements /= (size(yarn%nodes) - 1) * int(yarn%elements_per_segment, int64)) &
                    then
                call fatal_error(error, label // ': ' // name // ' has ' &
                    // format_integer(int(n_elements)) // ' values but the yarn has ' &
                    // format_integer(int((size(yarn%nodes) - 1) &
                    * int(yarn%elements_per_segment, int64))) // ' elements (' &
                    // format_integer(size(yarn%nodes) - 1) // ' segments of ' &
                    // format_integer(yarn%elements_per_segment) &
                    // '): give one value per element, in order along the yarn')
                return
            end if
            do m = 1, size(config%materials)
                if (trim(config%materials(m)%name) /= trim(yarn%material)) cycle
                if (config%materials(m)%prestress > 0.0_wp) then
                    call fatal_error(error, label // ': ' // name // " is given, but its " &
                        // "material '" // trim(yarn%material) // "' has prestress = " &
                        // format_real(config%materials(m)%prestress) // ' (both set the ' &
                        // 'reference lengths: give one)')
                    return
                end if
            end do
        end associate
    contains
        pure logical function is_given(values)
            real(wp), allocatable, intent(in) :: values(:)
            is_given = allocated(values)
            if (is_given) is_given = size(values) > 0
        end function is_given
    end subroutine check_element_lengths

    !> No two segments, of one yarn or of two, join the same two nodes: their elements
    !> would lie on top of each other (a yarn doubling back, or a yarn listed twice).
    !> Segments are bucketed by their lower node id, so the check is linear in their number.
    subroutine check_duplicate_segments(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        !> The segments whose lower node is `a` are slots first(a):first(a + 1) - 1, each
        !> with its yarn and its position i in the yarn (nodes(i), nodes(i + 1)).
        integer, allocatable :: first(:), filled(:), yarn_of(:), position_of(:)
        !> `seen(b)`: the last slot met with upper node b (a slot of the current lower
        !> node when it is >= first(a)).
        integer, allocatable :: seen(:)
        integer :: n_nodes, y, i, a, b, k, slot

        n_nodes = size(config%node_positions, 2)
        allocate(first(n_nodes + 1), source=0)
        do y = 1, size(config%yarns)
            associate(nodes => config%yarns(y)%nodes)
                do i = 1, size(nodes) - 1
                    a = min(nodes(i), nodes(i + 1))
                    first(a + 1) = first(a + 1) + 1
                end do
            end associate
        end do
        first(1) = 1
        do a = 1, n_nodes
            first(a + 1) = first(a + 1) + first(a)
        end do
        allocate(yarn_of(first(n_nodes + 1) - 1), position_of(first(n_nodes + 1) - 1))
        allocate(filled(n_nodes), source=0)
        do y = 1, size(config%yarns)
            associate(nodes => config%yarns(y)%nodes)
                do i = 1, size(nodes) - 1
                    a = min(nodes(i), nodes(i + 1))
                    slot = first(a) + filled(a)
                    yarn_of(slot) = y
                    position_of(slot) = i
                    filled(a) = filled(a) + 1
                end do
            end associate
        end do
        allocate(seen(n_nodes), source=0)
        do a = 1, n_nodes
            do k = first(a), first(a + 1) - 1
                b = upper_node(k)
                if (seen(b) >= first(a)) then
                    call fatal_error(error, segment_text(k) // ' join the same two nodes as ' &
                        // segment_text(seen(b)) // ': duplicate segment (two strings ' &
                        // 'between one pair of nodes would lie on top of each other)')
                    return
                end if
                seen(b) = k
            end do
        end do

    contains

        integer function upper_node(slot)
            integer, intent(in) :: slot

            associate(nodes => config%yarns(yarn_of(slot))%nodes, i => position_of(slot))
                upper_node = max(nodes(i), nodes(i + 1))
            end associate
        end function upper_node

        !> "&yarn #2: nodes(3), nodes(4) = 5, 2"
        function segment_text(slot) result(text)
            integer, intent(in) :: slot
            character(len=:), allocatable :: text

            associate(nodes => config%yarns(yarn_of(slot))%nodes, i => position_of(slot))
                text = yarn_label(config, yarn_of(slot)) // ': nodes(' // format_integer(i) &
                    // '), nodes(' // format_integer(i + 1) // ') = ' &
                    // format_integer(nodes(i)) // ', ' // format_integer(nodes(i + 1))
            end associate
        end function segment_text

    end subroutine check_duplicate_segments

    !> Where the nodes come from, for messages.
    function node_source(config) result(source)
        type(config_type), intent(in) :: config
        character(len=:), allocatable :: source

        if (len_trim(config%geometry%file) > 0) then
            source = "&geometry: file '" // trim(config%geometry%file) // "'"
        else
            source = '&nodes'
        end if
    end function node_source

    !> Supports: names, fix letters, node ids, and at most one support per coordinate
    !> (`owner(k, node)` is the support prescribing component k of node, or 0).
    subroutine check_supports(config, owner, error)
        type(config_type), intent(in) :: config
        integer, allocatable, intent(out) :: owner(:, :)
        type(error_type), allocatable, intent(out) :: error
        integer :: s, i, k, n_nodes, node
        character(len=:), allocatable :: label
        character(len=24), allocatable :: labels(:)

        n_nodes = size(config%node_positions, 2)
        allocate(owner(3, n_nodes), source=0)
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
                do k = 1, 3
                    if (support%displacement(k) /= 0.0_wp &
                        .and. index(support%fix, axis(k)) == 0) then
                        call fatal_error(error, label // ': displacement(' &
                            // format_integer(k) // ') = ' &
                            // format_real(support%displacement(k)) // ' but ' // axis(k) &
                            // " is not in fix = '" // trim(support%fix) &
                            // "' (it would be ignored)")
                        return
                    end if
                end do
                call check_node_list(error, label, support%nodes, n_nodes)
                if (allocated(error)) return
                do i = 1, size(support%nodes)
                    node = support%nodes(i)
                    do k = 1, 3
                        if (index(support%fix, axis(k)) == 0) cycle
                        if (owner(k, node) /= 0) then
                            call fatal_error(error, label // ': node ' // format_integer(node) &
                                // ' ' // axis(k) // " is already prescribed by &support '" &
                                // trim(config%supports(owner(k, node))%name) // "'")
                            return
                        end if
                        owner(k, node) = s
                    end do
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
        integer :: l, i, k, node
        character(len=:), allocatable :: label

        if (.not. allocated(config%loads)) return
        do l = 1, size(config%loads)
            associate(load => config%loads(l))
                label = '&load #' // format_integer(l)
                call check_load_variables(load, label, error)
                if (allocated(error)) return
                call check_node_list(error, label, load%nodes, size(config%node_positions, 2))
                if (allocated(error)) return
                do i = 1, size(load%nodes)
                    node = load%nodes(i)
                    do k = 1, 3
                        if (load%force(k) == 0.0_wp .or. owner(k, node) == 0) cycle
                        call fatal_error(error, label // ': node ' // format_integer(node) &
                            // ' has force(' // format_integer(k) // ') = ' &
                            // format_real(load%force(k)) // ' but its ' // axis(k) &
                            // " is prescribed by &support '" &
                            // trim(config%supports(owner(k, node))%name) &
                            // "' (the force would be ignored)")
                        return
                    end do
                end do
            end associate
        end do
    end subroutine check_loads

    !> A list of node ids of a support or load: not empty, in range, no repeats.
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
            call require_node(error, label, 'nodes', i, nodes(i), n_nodes)
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

    subroutine require_node(error, label, variable, i, node, n_nodes)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, variable
        integer, intent(in) :: i, node, n_nodes

        if (node < 1 .or. node > n_nodes) then
            call fatal_error(error, label // ': ' // variable // '(' // format_integer(i) &
                // ') = ' // format_integer(node) // ' is not a node (node ids are 1..' &
                // format_integer(n_nodes) // ')')
        end if
    end subroutine require_node

    function format_position(x) result(text)
        real(wp), intent(in) :: x(3)
        character(len=:), allocatable :: text

        text = format_real(x(1)) // ', ' // format_real(x(2)) // ', ' // format_real(x(3))
    end function format_position

end module yarnfort_input_network_checks
