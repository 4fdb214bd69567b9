! SPDX-License-Identifier: MIT
!> Contact nodes of their own kind: fixed obstacles (&obstacle) and free rings (&ring),
!> nodes that one or more yarns pass through with a friction law of the node. Checks of
!> their groups, of the &contact groups that name them (`at`), and the one rule that
!> picks the law of a yarn at such a node (used by the checks and by the scene builder).
module yarnfort_input_contact_node_checks
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type, name_length
    use yarnfort_input_fields, only: suggestion, quoted_list, check_item_name, group_label
    use yarnfort_input_network_checks, only: check_node_list, yarn_label
    use yarnfort_text, only: format_integer, format_real
    implicit none
    private

    public :: check_contact_nodes, check_node_contact, check_contact_node_laws
    public :: get_contact_node_sets, find_node_contact, contact_node_label

contains

    !> The contact-node sets of `config`, obstacles first, then rings: `set_of(node)` is
    !> the set of each node of the input (0: an ordinary node), `names(s)` the name of
    !> set s, `n_obstacles` the number of &obstacle sets. The node ids must be checked.
    subroutine get_contact_node_sets(config, set_of, names, n_obstacles)
        type(config_type), intent(in) :: config
        integer, allocatable, intent(out) :: set_of(:)
        character(len=name_length), allocatable, intent(out) :: names(:)
        integer, intent(out) :: n_obstacles
        integer :: s

        allocate(set_of(size(config%node_positions, 2)), source=0)
        allocate(names(0))
        n_obstacles = 0
        if (allocated(config%obstacles)) then
            n_obstacles = size(config%obstacles)
            do s = 1, n_obstacles
                names = [names, config%obstacles(s)%name]
                set_of(config%obstacles(s)%nodes) = s
            end do
        end if
        if (allocated(config%rings)) then
            do s = 1, size(config%rings)
                names = [names, config%rings(s)%name]
                set_of(config%rings(s)%nodes) = n_obstacles + s
            end do
        end if
    end subroutine get_contact_node_sets

    !> "&obstacle 'name'" or "&ring 'name'" of set s (numbered as by get_contact_node_sets).
    function contact_node_label(config, s) result(label)
        type(config_type), intent(in) :: config
        integer, intent(in) :: s
        character(len=:), allocatable :: label
        integer :: n_obstacles

        n_obstacles = 0
        if (allocated(config%obstacles)) n_obstacles = size(config%obstacles)
        if (s <= n_obstacles) then
            label = "&obstacle '" // trim(config%obstacles(s)%name) // "'"
        else
            label = "&ring '" // trim(config%rings(s - n_obstacles)%name) // "'"
        end if
    end function contact_node_label

    !> The law of a yarn of type `material` at a node of the obstacle or ring `name`: the
    !> &contact with at = name and materials(1) = material; else the one with at = name
    !> and materials(1) empty (every yarn type); else 0. Pair laws never apply there.
    pure integer function find_node_contact(config, name, material) result(contact)
        type(config_type), intent(in) :: config
        character(len=*), intent(in) :: name, material
        integer :: c

        contact = 0
        if (.not. allocated(config%contacts)) return
        do c = 1, size(config%contacts)
            if (config%contacts(c)%at /= name) cycle
            if (config%contacts(c)%materials(1) == material) then
                contact = c
                return
            end if
            if (len_trim(config%contacts(c)%materials(1)) == 0) contact = c
        end do
    end function find_node_contact

    !> &obstacle and &ring groups: named (one word, unique among obstacles, rings and
    !> supports), node lists in range without repeats, each node in one set only, passed
    !> through (never ended at) by every yarn that lists it and by at least one; no
    !> &load on an obstacle's node (it is held).
    subroutine check_contact_nodes(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer, allocatable :: set_of(:), visits(:), nodes(:)
        character(len=name_length), allocatable :: names(:)
        character(len=24), allocatable :: labels(:)
        character(len=:), allocatable :: label, group, what
        integer :: n_obstacles, n_sets, n_nodes, s, other, i, y, node, l, k

        n_nodes = size(config%node_positions, 2)
        n_obstacles = 0
        n_sets = 0
        if (allocated(config%obstacles)) n_obstacles = size(config%obstacles)
        n_sets = n_obstacles
        if (allocated(config%rings)) n_sets = n_sets + size(config%rings)
        if (n_sets == 0) return
        allocate(set_of(n_nodes), source=0)
        allocate(names(n_sets), labels(n_sets))
        do s = 1, n_sets
            if (s <= n_obstacles) then
                names(s) = config%obstacles(s)%name
                labels(s) = group_label('obstacle', s)
            else
                names(s) = config%rings(s - n_obstacles)%name
                labels(s) = group_label('ring', s - n_obstacles)
            end if
        end do
        do s = 1, n_sets
            group = labels(s)(:index(labels(s), ' #') - 1)
            if (s <= n_obstacles) then
                nodes = config%obstacles(s)%nodes
            else
                nodes = config%rings(s - n_obstacles)%nodes
            end if
            call check_item_name(error, names, labels, s, ' (give each ' // group(2:) &
                // " a name; &contact at = 'name' gives its friction law)", 'used', &
                '; &contact at names one of them')
            if (allocated(error)) return
            if (allocated(config%supports)) then
                do other = 1, size(config%supports)
                    if (config%supports(other)%name == names(s)) then
                        call fatal_error(error, group // ": name = '" // trim(names(s)) &
                            // "' is also the name of &support #" // format_integer(other) &
                            // ' (they would share the reaction columns of curve.csv)')
                        return
                    end if
                end do
            end if
            label = group // " '" // trim(names(s)) // "'"
            call check_node_list(error, label, nodes, n_nodes)
            if (allocated(error)) return
            do i = 1, size(nodes)
                if (set_of(nodes(i)) /= 0) then
                    call fatal_error(error, label // ': node ' // format_integer(nodes(i)) &
                        // ' is already a node of ' &
                        // contact_node_label(config, set_of(nodes(i))) &
                        // ' (a node is one obstacle or one ring)')
                    return
                end if
                set_of(nodes(i)) = s
            end do
        end do
        ! Every yarn passes through the contact nodes it lists; every one has a yarn.
        allocate(visits(n_nodes), source=0)
        do y = 1, size(config%yarns)
            associate(list => config%yarns(y)%nodes)
                do i = 1, size(list)
                    node = list(i)
                    if (node < 1 .or. node > n_nodes) cycle     ! check_yarns reports it
                    if (set_of(node) == 0) cycle
                    if (i == 1 .or. i == size(list)) then
                        call fatal_error(error, yarn_label(config, y) // ' ends at node ' &
                            // format_integer(node) // ', a node of ' &
                            // contact_node_label(config, set_of(node)) // ': a yarn passes ' &
                            // 'through an obstacle or a ring (a node on each side); to fix ' &
                            // 'a yarn end there, end it at a node of its own held by a ' &
                            // '&support')
                        return
                    end if
                    visits(node) = visits(node) + 1
                end do
            end associate
        end do
        do s = 1, n_sets
            if (s <= n_obstacles) then
                nodes = config%obstacles(s)%nodes
                what = 'an obstacle with no yarn has nothing to hold'
            else
                nodes = config%rings(s - n_obstacles)%nodes
                what = 'a ring needs at least one yarn through it'
            end if
            do i = 1, size(nodes)
                if (visits(nodes(i)) > 0) cycle
                call fatal_error(error, contact_node_label(config, s) // ': no yarn passes ' &
                    // 'through node ' // format_integer(nodes(i)) // ' (nodes(' &
                    // format_integer(i) // '); ' // what // ')')
                return
            end do
        end do
        if (.not. allocated(config%loads)) return
        do l = 1, size(config%loads)
            do i = 1, size(config%loads(l)%nodes)
                node = config%loads(l)%nodes(i)
                if (node < 1 .or. node > n_nodes) cycle
                if (set_of(node) == 0 .or. set_of(node) > n_obstacles) cycle
                do k = 1, 3
                    if (config%loads(l)%force(k) == 0.0_wp) cycle
                    call fatal_error(error, '&load #' // format_integer(l) // ': node ' &
                        // format_integer(node) // ' has force(' // format_integer(k) &
                        // ') = ' // format_real(config%loads(l)%force(k)) &
                        // ' but it is a node of ' // contact_node_label(config, set_of(node)) &
                        // ', held in place (the force would be ignored; a &ring is free)')
                    return
                end do
            end do
        end do
    end subroutine check_contact_nodes

    !> A &contact with `at` set (contact c): `at` names an &obstacle or &ring,
    !> materials(1) is empty or a defined &material, materials(2) is empty, and no earlier
    !> &contact has the same `at` and materials(1).
    subroutine check_node_contact(config, c, error)
        type(config_type), intent(in) :: config
        integer, intent(in) :: c
        type(error_type), allocatable, intent(out) :: error
        integer, allocatable :: set_of(:)
        character(len=name_length), allocatable :: names(:)
        character(len=:), allocatable :: label
        integer :: n_obstacles, other

        call get_contact_node_sets(config, set_of, names, n_obstacles)
        associate(contact => config%contacts(c))
            label = '&contact #' // format_integer(c)
            if (.not. any(names == contact%at)) then
                if (size(names) == 0) then
                    call fatal_error(error, label // ": at = '" // trim(contact%at) &
                        // "' names no &obstacle or &ring (the input has none; leave at " &
                        // 'empty for the law of a pair of yarn types)')
                else
                    call fatal_error(error, label // ": at = '" // trim(contact%at) &
                        // "' is not the name of an &obstacle or &ring (defined: " &
                        // quoted_list(names) // ')' // suggestion(contact%at, names))
                end if
                return
            end if
            if (len_trim(contact%materials(2)) > 0) then
                call fatal_error(error, label // ": at = '" // trim(contact%at) &
                    // "' with materials(2) = '" // trim(contact%materials(2)) // "': a law " &
                    // 'at an obstacle or ring takes one yarn type, materials(1), or none ' &
                    // '(every yarn type)')
                return
            end if
            if (len_trim(contact%materials(1)) > 0 &
                .and. .not. any(config%materials%name == contact%materials(1))) then
                call fatal_error(error, label // ": materials(1) = '" &
                    // trim(contact%materials(1)) // "' is not defined by any &material " &
                    // '(defined: ' // quoted_list(config%materials%name) // ')' &
                    // suggestion(contact%materials(1), config%materials%name))
                return
            end if
            do other = 1, c - 1
                if (config%contacts(other)%at /= contact%at) cycle
                if (config%contacts(other)%materials(1) /= contact%materials(1)) cycle
                if (len_trim(contact%materials(1)) > 0) then
                    call fatal_error(error, label // ": at = '" // trim(contact%at) &
                        // "', materials = '" // trim(contact%materials(1)) // "' is also " &
                        // '&contact #' // format_integer(other) // ': give one law per ' &
                        // 'obstacle or ring and yarn type')
                else
                    call fatal_error(error, label // ": at = '" // trim(contact%at) &
                        // "' for every yarn type is also &contact #" &
                        // format_integer(other) // ': give one law per obstacle or ring ' &
                        // 'and yarn type')
                end if
                return
            end do
        end associate
    end subroutine check_node_contact

    !> Every yarn through an obstacle or ring has a law there (find_node_contact).
    subroutine check_contact_node_laws(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer, allocatable :: set_of(:)
        character(len=name_length), allocatable :: names(:)
        integer :: n_obstacles, y, i, s

        call get_contact_node_sets(config, set_of, names, n_obstacles)
        if (size(names) == 0) return
        do y = 1, size(config%yarns)
            do i = 2, size(config%yarns(y)%nodes) - 1
                s = set_of(config%yarns(y)%nodes(i))
                if (s == 0) cycle
                if (find_node_contact(config, names(s), config%yarns(y)%material) > 0) cycle
                call fatal_error(error, "no &contact for yarn type '" &
                    // trim(config%yarns(y)%material) // "' at " &
                    // contact_node_label(config, s) // ' (' // yarn_label(config, y) &
                    // ' passes through its node ' // format_integer(config%yarns(y)%nodes(i)) &
                    // "); give one, e.g. &contact at = '" // trim(names(s)) &
                    // "', materials = '" // trim(config%yarns(y)%material) // "', law = " &
                    // "'coulomb', friction_coefficient = 0.3 / (or leave materials out for " &
                    // 'every yarn type)')
                return
            end do
        end do
    end subroutine check_contact_node_laws

end module yarnfort_input_contact_node_checks
