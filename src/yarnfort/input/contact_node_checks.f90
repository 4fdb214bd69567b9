! SPDX-License-Identifier: MIT
!> Checks of the contact nodes of their own kind (yarnfort_scene_contact_nodes): their
!> &obstacle and &ring groups, and the &contact groups that name them (`at`).
module yarnfort_input_contact_node_checks
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type
    use yarnfort_input_fields, only: check_item_name, group_label
    use yarnfort_input_network_checks, only: check_node_list, yarn_label, check_defined
    use yarnfort_text, only: format_integer, format_real
    use yarnfort_scene_contact_nodes, only: node_set_type, get_node_sets, set_label, &
        find_node_contact
    implicit none
    private

    public :: check_contact_nodes, check_node_contact, check_contact_node_laws

contains

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
