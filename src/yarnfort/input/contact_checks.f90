! SPDX-License-Identifier: MIT
!> Checks of the &contact groups: two defined materials, one group per unordered pair,
!> the parameters of its friction law, and, when any &contact is given, one for every
!> pair of yarn types that meet at a node.
module yarnfort_input_contact_checks
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type, contact_config_type, name_length
    use yarnfort_input_groups, only: check_contact_variables
    use yarnfort_input_fields, only: suggestion, quoted_list
    use yarnfort_input_network_checks, only: yarn_label
    use yarnfort_input_contact_node_checks, only: check_node_contact, get_contact_node_sets
    use yarnfort_text, only: format_integer, format_real
    implicit none
    private

    public :: check_contacts

contains

    !> Contacts: two defined materials, one group per unordered pair, a known friction law
    !> with exactly its parameters; and, when any &contact is given, one for every pair
    !> of yarn types that meet at a node.
    subroutine check_contacts(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        character(len=name_length), allocatable :: material_names(:)
        !> `pair(a, b)`: the &contact of materials a and b (symmetric), or 0.
        integer, allocatable :: pair(:, :)
        integer :: c, i, a, b
        character(len=:), allocatable :: label

        if (.not. allocated(config%contacts)) return
        if (size(config%contacts) == 0) return
        material_names = config%materials%name
        allocate(pair(size(material_names), size(material_names)), source=0)
        do c = 1, size(config%contacts)
            associate(contact => config%contacts(c))
                label = '&contact #' // format_integer(c)
                if (len_trim(contact%at) > 0) then
                    ! The law of an obstacle or ring.
                    call check_node_contact(config, c, error)
                    if (allocated(error)) return
                    label = label // " (at = '" // trim(contact%at) // "')"
                else
                    do i = 1, 2
                        call check_contact_material(error, label, i, contact%materials(i), &
                            material_names)
                        if (allocated(error)) return
                    end do
                    a = findloc(material_names, contact%materials(1), dim=1)
                    b = findloc(material_names, contact%materials(2), dim=1)
                    label = label // ' (' // pair_text(contact) // ')'
                    if (pair(a, b) /= 0) then
                        call fatal_error(error, '&contact #' // format_integer(c) &
                            // ': materials = ' // pair_text(contact) // ' is the same pair ' &
                            // 'as &contact #' // format_integer(pair(a, b)) // ' (materials = ' &
                            // pair_text(config%contacts(pair(a, b))) // '; the order does ' &
                            // 'not matter): give one &contact per pair of yarn types')
                        return
                    end if
                    pair(a, b) = c
                    pair(b, a) = c
                end if
                call check_contact_variables(contact, label, error)
                if (allocated(error)) return
                if (contact%law == 'decaying_adhesion' &
                    .and. .not. (contact%decay_start < contact%decay_end)) then
                    call fatal_error(error, label // ': decay_start = ' &
                        // format_real(contact%decay_start) // ' must be less than ' &
                        // 'decay_end = ' // format_real(contact%decay_end) // ' (the ' &
                        // 'adhesion decays from tension decay_start to decay_end)')
                    return
                end if
            end associate
        end do
        call check_contacts_complete(config, pair, error)
    end subroutine check_contacts

    !> 'a', 'b' of a contact, as in its materials variable.
    pure function pair_text(contact) result(text)
        type(contact_config_type), intent(in) :: contact
        character(len=:), allocatable :: text

        text = quoted_list(contact%materials)
    end function pair_text

    !> materials(i) of a &contact: set, and the name of a &material.
    subroutine check_contact_material(error, label, i, name, material_names)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: label, name
        integer, intent(in) :: i
        character(len=*), intent(in) :: material_names(:)
        character(len=:), allocatable :: variable

        variable = 'materials(' // format_integer(i) // ')'
        if (len_trim(name) == 0) then
            call fatal_error(error, label // ': ' // variable // ' is not set (give the ' &
                // "two yarn types, e.g. materials = '" // trim(material_names(1)) // "', '" &
                // trim(material_names(size(material_names))) // "')")
            return
        end if
        if (.not. any(material_names == name)) then
            call fatal_error(error, label // ': ' // variable // " = '" // trim(name) &
                // "' is not defined by any &material (defined: " &
                // quoted_list(material_names) // ')' // suggestion(name, material_names))
        end if
    end subroutine check_contact_material

    !> With any &contact, every pair of yarn types meeting at a node needs one. A node
    !> meets when two different yarns list it (yarns of two types, or two of one type).
    !> The nodes of an &obstacle or &ring have the laws of their own (`at`) instead.
    subroutine check_contacts_complete(config, pair, error)
        type(config_type), intent(in) :: config
        integer, intent(in) :: pair(:, :)
        type(error_type), allocatable, intent(out) :: error
        integer, allocatable :: material_of(:), first(:), yarns_at(:), last_yarn(:), filled(:)
        integer, allocatable :: set_of(:)
        character(len=name_length), allocatable :: set_names(:)
        integer :: n_nodes, y, i, node, j, k, a, b, n_obstacles

        n_nodes = size(config%node_positions, 2)
        allocate(material_of(size(config%yarns)))
        do y = 1, size(config%yarns)
            material_of(y) = findloc(config%materials%name, config%yarns(y)%material, dim=1)
        end do
        ! Yarns through each node, each once (a yarn may list a node twice): the yarns
        ! at node n are yarns_at(first(n):first(n + 1) - 1).
        allocate(first(n_nodes + 1), source=0)
        allocate(last_yarn(n_nodes), source=0)
        do y = 1, size(config%yarns)
            do i = 1, size(config%yarns(y)%nodes)
                node = config%yarns(y)%nodes(i)
                if (last_yarn(node) == y) cycle
                last_yarn(node) = y
                first(node + 1) = first(node + 1) + 1
            end do
        end do
        first(1) = 1
        do node = 1, n_nodes
            first(node + 1) = first(node + 1) + first(node)
        end do
        allocate(yarns_at(first(n_nodes + 1) - 1))
        allocate(filled(n_nodes), source=0)
        last_yarn = 0
        do y = 1, size(config%yarns)
            do i = 1, size(config%yarns(y)%nodes)
                node = config%yarns(y)%nodes(i)
                if (last_yarn(node) == y) cycle
                last_yarn(node) = y
                yarns_at(first(node) + filled(node)) = y
                filled(node) = filled(node) + 1
            end do
        end do
        call get_contact_node_sets(config, set_of, set_names, n_obstacles)
        do node = 1, n_nodes
            if (set_of(node) /= 0) cycle
            do j = first(node), first(node + 1) - 1
                do k = j + 1, first(node + 1) - 1
                    a = material_of(yarns_at(j))
                    b = material_of(yarns_at(k))
                    if (pair(a, b) /= 0) cycle
                    call fatal_error(error, "no &contact for yarn types '" &
                        // trim(config%materials(a)%name) // "' and '" &
                        // trim(config%materials(b)%name) // "' (they meet at node " &
                        // format_integer(node) // '); ' // yarn_label(config, yarns_at(j)) &
                        // ' and ' // yarn_label(config, yarns_at(k)) // ' share it, and ' &
                        // 'with any &contact group every pair of yarn types that meet ' &
                        // 'needs one')
                    return
                end do
            end do
        end do
    end subroutine check_contacts_complete

end module yarnfort_input_contact_checks
