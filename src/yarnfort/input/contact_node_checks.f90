! SPDX-License-Identifier: MIT
!> Contact nodes of their own kind: fixed obstacles (&obstacle) and free rings (&ring),
!> nodes that one or more yarns pass through with a friction law of the node. Checks of
!> their groups, of the &contact groups that name them (`at`), and the one rule that
!> picks the law of a yarn at such a node (used by the checks and by the scene builder).
module yarnfort_input_contact_node_checks
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type, name_length
    use yarnfort_input_fields, only: check_item_name, group_label
    use yarnfort_input_network_checks, only: check_node_list, yarn_label, check_defined
    use yarnfort_text, only: format_integer, format_real
    implicit none
    private

    public :: check_contact_nodes, check_node_contact, check_contact_node_laws
    public :: get_contact_node_sets, find_node_contact

    !> An &obstacle or &ring group: 'obstacle' or 'ring', its number among the groups of
    !> its kind, its name and its node ids.
    type :: node_set_type
        character(len=8) :: group = ''
        integer :: number = 0
        character(len=name_length) :: name = ''
        integer, allocatable :: nodes(:)
    end type node_set_type

contains

    !> The contact-node sets of `config`, obstacles first, then rings: `set_of(node)` is
    !> the set of each node of the input (0: an ordinary node), `names(s)` the name of
    !> set s, `n_obstacles` the number of &obstacle sets. The node ids must be checked.
    subroutine get_contact_node_sets(config, set_of, names, n_obstacles)
        type(config_type), intent(in) :: config
        integer, allocatable, intent(out) :: set_of(:)
        character(len=name_length), allocatable, intent(out) :: names(:)
        integer, intent(out) :: n_obstacles
        type(node_set_type), allocatable :: sets(:)

        call get_node_sets(config, sets, set_of)
        names = sets%name
        n_obstacles = count(sets%group == 'obstacle')
    end subroutine get_contact_node_sets

    !> The &obstacle groups, then the &ring groups; with `set_of`, the set of each node
    !> (0: none; the node ids must be checked).
    subroutine get_node_sets(config, sets, set_of)
        type(config_type), intent(in) :: config
        type(node_set_type), allocatable, intent(out) :: sets(:)
        integer, allocatable, intent(out), optional :: set_of(:)
        integer :: s

        allocate(sets(0))
        if (allocated(config%obstacles)) sets = [(node_set_type('obstacle', s, &
            config%obstacles(s)%name, config%obstacles(s)%nodes), s = 1, size(config%obstacles))]
        if (allocated(config%rings)) sets = [sets, (node_set_type('ring', s, &
            config%rings(s)%name, config%rings(s)%nodes), s = 1, size(config%rings))]
        if (.not. present(set_of)) return
        allocate(set_of(size(config%node_positions, 2)), source=0)
        do s = 1, size(sets)
            set_of(sets(s)%nodes) = s
        end do
    end subroutine get_node_sets

    !> "&obstacle 'name'" or "&ring 'name'".
    pure function set_label(set) result(label)
        type(node_set_type), intent(in) :: set
        character(len=:), allocatable :: label

        label = '&' // trim(set%group) // " '" // trim(set%name) // "'"
    end function set_label

    !> The law of a yarn of type `material` at a node of the obstacle or ring `name`: the
    !> &contact with at = name and materials(1) = material; else the one with at = name
    !> and materials(1) empty (every yarn type); else 0. Pair laws never apply there.
    pure integer function find_node_contact(config, name, material) result(contact)
        type(config_type), intent(in) :: config
        character(len=*), intent(in) :: name, material

        contact = 0
        if (.not. allocated(config%contacts)) return
        associate(at => config%contacts%at, first => config%contacts%materials(1))
            contact = findloc(at == name .and. first == material, .true., dim=1)
            if (contact == 0) contact = findloc(at == name .and. first == '', .true., dim=1, &
                back=.true.)
        end associate
    end function find_node_contact

    !> &obstacle and &ring groups: named (one word, unique among obstacles, rings and
    !> supports), node lists in range without repeats, each node in one set only, passed
    !> through (never ended at) by every yarn that lists it and by at least one; no
    !> &load on an obstacle's node (it is held).
    subroutine check_contact_nodes(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        type(node_set_type), allocatable :: sets(:)
        integer, allocatable :: set_of(:), visits(:)
        character(len=24), allocatable :: labels(:)
        character(len=:), allocatable :: what
        integer :: n_nodes, s, other, i, y, node, l, k

        call get_node_sets(config, sets)
        if (size(sets) == 0) return
        n_nodes = size(config%node_positions, 2)
        allocate(set_of(n_nodes), source=0)
        labels = [character(len=24) :: (group_label(trim(sets(s)%group), sets(s)%number), &
            s = 1, size(sets))]
        do s = 1, size(sets)
            associate(set => sets(s))
                call check_item_name(error, sets%name, labels, s, ' (give each ' &
                    // trim(set%group) // " a name; &contact at = 'name' gives its friction " &
                    // 'law)', 'used', '; &contact at names one of them')
                if (allocated(error)) return
                other = 0
                if (allocated(config%supports)) &
                    other = findloc(config%supports%name, set%name, dim=1)
                if (other > 0) then
                    call fatal_error(error, '&' // trim(set%group) // ": name = '" &
                        // trim(set%name) // "' is also the name of &support #" &
                        // format_integer(other) // ' (they would share the reaction ' &
                        // 'columns of curve.csv)')
                    return
                end if
                call check_node_list(error, set_label(set), set%nodes, n_nodes)
                if (allocated(error)) return
                i = findloc(set_of(set%nodes) /= 0, .true., dim=1)
                if (i > 0) then
                    call fatal_error(error, set_label(set) // ': node ' &
                        // format_integer(set%nodes(i)) // ' is already a node of ' &
                        // set_label(sets(set_of(set%nodes(i)))) &
                        // ' (a node is one obstacle or one ring)')
                    return
                end if
                set_of(set%nodes) = s
            end associate
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
                            // set_label(sets(set_of(node))) // ': a yarn passes ' &
                            // 'through an obstacle or a ring (a node on each side); to fix ' &
                            // 'a yarn end there, end it at a node of its own held by a ' &
                            // '&support')
                        return
                    end if
                    visits(node) = visits(node) + 1
                end do
            end associate
        end do
        do s = 1, size(sets)
            i = findloc(visits(sets(s)%nodes), 0, dim=1)
            if (i == 0) cycle
            if (sets(s)%group == 'obstacle') then
                what = 'an obstacle with no yarn has nothing to hold'
            else
                what = 'a ring needs at least one yarn through it'
            end if
            call fatal_error(error, set_label(sets(s)) // ': no yarn passes through node ' &
                // format_integer(sets(s)%nodes(i)) // ' (nodes(' // format_integer(i) &
                // '); ' // what // ')')
            return
        end do
        if (.not. allocated(config%loads)) return
        do l = 1, size(config%loads)
            associate(load => config%loads(l))
                k = findloc(load%force /= 0.0_wp, .true., dim=1)
                if (k == 0) cycle
                do i = 1, size(load%nodes)
                    node = load%nodes(i)
                    if (node < 1 .or. node > n_nodes) cycle
                    if (set_of(node) == 0) cycle
                    if (sets(set_of(node))%group /= 'obstacle') cycle
                    call fatal_error(error, '&load #' // format_integer(l) // ': node ' &
                        // format_integer(node) // ' has force(' // format_integer(k) &
                        // ') = ' // format_real(load%force(k)) // ' but it is a node of ' &
                        // set_label(sets(set_of(node))) // ', held in place (the force ' &
                        // 'would be ignored; a &ring is free)')
                    return
                end do
            end associate
        end do
    end subroutine check_contact_nodes

    !> A &contact with `at` set (contact c): `at` names an &obstacle or &ring,
    !> materials(1) is empty or a defined &material, materials(2) is empty, and no earlier
    !> &contact has the same `at` and materials(1).
    subroutine check_node_contact(config, c, error)
        type(config_type), intent(in) :: config
        integer, intent(in) :: c
        type(error_type), allocatable, intent(out) :: error
        type(node_set_type), allocatable :: sets(:)
        character(len=:), allocatable :: label, which
        integer :: other

        call get_node_sets(config, sets)
        associate(contact => config%contacts(c), before => config%contacts(:c - 1))
            label = '&contact #' // format_integer(c)
            if (size(sets) == 0) then
                call fatal_error(error, label // ": at = '" // trim(contact%at) &
                    // "' names no &obstacle or &ring (the input has none; leave at " &
                    // 'empty for the law of a pair of yarn types)')
                return
            end if
            call check_defined(error, label, 'at', contact%at, sets%name, &
                'the name of an &obstacle or &ring', 'defined')
            if (allocated(error)) return
            if (len_trim(contact%materials(2)) > 0) then
                call fatal_error(error, label // ": at = '" // trim(contact%at) &
                    // "' with materials(2) = '" // trim(contact%materials(2)) // "': a law " &
                    // 'at an obstacle or ring takes one yarn type, materials(1), or none ' &
                    // '(every yarn type)')
                return
            end if
            which = "' for every yarn type"
            if (len_trim(contact%materials(1)) > 0) then
                call check_defined(error, label, 'materials(1)', contact%materials(1), &
                    config%materials%name, 'defined by any &material', 'defined')
                if (allocated(error)) return
                which = "', materials = '" // trim(contact%materials(1)) // "'"
            end if
            other = findloc(before%at == contact%at &
                .and. before%materials(1) == contact%materials(1), .true., dim=1)
            if (other > 0) then
                call fatal_error(error, label // ": at = '" // trim(contact%at) // which &
                    // ' is also &contact #' // format_integer(other) // ': give one law ' &
                    // 'per obstacle or ring and yarn type')
            end if
        end associate
    end subroutine check_node_contact

    !> Every yarn through an obstacle or ring has a law there (find_node_contact).
    subroutine check_contact_node_laws(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        type(node_set_type), allocatable :: sets(:)
        integer, allocatable :: set_of(:)
        integer :: y, i, s

        call get_node_sets(config, sets, set_of)
        if (size(sets) == 0) return
        do y = 1, size(config%yarns)
            associate(yarn => config%yarns(y))
                do i = 2, size(yarn%nodes) - 1
                    s = set_of(yarn%nodes(i))
                    if (s == 0) cycle
                    if (find_node_contact(config, sets(s)%name, yarn%material) > 0) cycle
                    call fatal_error(error, "no &contact for yarn type '" &
                        // trim(yarn%material) // "' at " // set_label(sets(s)) // ' (' &
                        // yarn_label(config, y) // ' passes through its node ' &
                        // format_integer(yarn%nodes(i)) // "); give one, e.g. &contact " &
                        // "at = '" // trim(sets(s)%name) // "', materials = '" &
                        // trim(yarn%material) // "', law = 'coulomb', " &
                        // 'friction_coefficient = 0.3 / (or leave materials out for every ' &
                        // 'yarn type)')
                    return
                end do
            end associate
        end do
    end subroutine check_contact_node_laws

end module yarnfort_input_contact_node_checks
