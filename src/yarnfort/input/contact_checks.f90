! SPDX-License-Identifier: MIT
!> Checks of the &contact groups: two defined materials, one group per unordered pair,
!> the parameters of its friction law, and, when any &contact is given, one for every
!> pair of yarn types that meet at a node.
module yarnfort_input_contact_checks
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type, name_length
    use yarnfort_input_groups, only: check_contact_variables
    use yarnfort_input_fields, only: quoted_list
    use yarnfort_input_network_checks, only: yarn_label, check_defined, sort_by_key
    use yarnfort_input_contact_node_checks, only: check_node_contact
    use yarnfort_scene_contact_nodes, only: get_contact_node_sets
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
        character(len=:), allocatable :: label, variable

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
                    ! Both materials set and defined.
                    do i = 1, 2
                        variable = 'materials(' // format_integer(i) // ')'
                        if (len_trim(contact%materials(i)) == 0) then
                            call fatal_error(error, label // ': ' // variable // ' is not set ' &
                                // "(give the two yarn types, e.g. materials = '" &
                                // trim(material_names(1)) // "', '" &
                                // trim(material_names(size(material_names))) // "')")
                            return
                        end if
                        call check_defined(error, label, variable, contact%materials(i), &
                            material_names, 'defined by any &material', 'defined')
                        if (allocated(error)) return
                    end do
                    a = findloc(material_names, contact%materials(1), dim=1)
                    b = findloc(material_names, contact%materials(2), dim=1)
                    if (pair(a, b) /= 0) then
                        call fatal_error(error, label // ': materials = ' &
                            // quoted_list(contact%materials) // ' is the same pair as ' &
                            // '&contact #' // format_integer(pair(a, b)) // ' (materials = ' &
                            // quoted_list(config%contacts(pair(a, b))%materials) // '; the ' &
                            // 'order does not matter): give one &contact per pair of yarn ' &
                            // 'types')
                        return
                    end if
                    pair(a, b) = c
                    pair(b, a) = c
                    label = label // ' (' // quoted_list(contact%materials) // ')'
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

    !> With any &contact, every pair of yarn types meeting at a node needs one. A node
    !> meets when two different yarns list it (yarns of two types, or two of one type).
    !> The nodes of an &obstacle or &ring have the laws of their own (`at`) instead.
    subroutine check_contacts_complete(config, pair, error)
        type(config_type), intent(in) :: config
        integer, intent(in) :: pair(:, :)
        type(error_type), allocatable, intent(out) :: error
        !> Each yarn at each node it lists, once (a yarn may list a node twice): visit v
        !> is yarn yarn_of(v) at node node_of(v); the visits of node n are
        !> order(first(n):first(n + 1) - 1).
        integer, allocatable :: yarn_of(:), node_of(:), first(:), order(:)
        integer, allocatable :: material_of(:), last_yarn(:), set_of(:)
        character(len=name_length), allocatable :: set_names(:)
        integer :: n_nodes, n, y, i, node, j, k, a, b, n_obstacles

        n_nodes = size(config%node_positions, 2)
        allocate(material_of(size(config%yarns)))
        do y = 1, size(config%yarns)
            material_of(y) = findloc(config%materials%name, config%yarns(y)%material, dim=1)
        end do
        n = sum([(size(config%yarns(y)%nodes), y = 1, size(config%yarns))])
        allocate(yarn_of(n), node_of(n))
        allocate(last_yarn(n_nodes), source=0)
        n = 0
        do y = 1, size(config%yarns)
            do i = 1, size(config%yarns(y)%nodes)
                node = config%yarns(y)%nodes(i)
                if (last_yarn(node) == y) cycle
                last_yarn(node) = y
                n = n + 1
                yarn_of(n) = y
                node_of(n) = node
            end do
        end do
        call sort_by_key(node_of(:n), n_nodes, first, order)
        call get_contact_node_sets(config, set_of, set_names, n_obstacles)
        do node = 1, n_nodes
            if (set_of(node) /= 0) cycle
            associate(yarns => yarn_of(order(first(node):first(node + 1) - 1)))
                do j = 1, size(yarns)
                    do k = j + 1, size(yarns)
                        a = material_of(yarns(j))
                        b = material_of(yarns(k))
                        if (pair(a, b) /= 0) cycle
                        call fatal_error(error, "no &contact for yarn types '" &
                            // trim(config%materials(a)%name) // "' and '" &
                            // trim(config%materials(b)%name) // "' (they meet at node " &
                            // format_integer(node) // '); ' // yarn_label(config, yarns(j)) &
                            // ' and ' // yarn_label(config, yarns(k)) // ' share it, and ' &
                            // 'with any &contact group every pair of yarn types that meet ' &
                            // 'needs one')
                        return
                    end do
                end do
            end associate
        end do
    end subroutine check_contacts_complete

end module yarnfort_input_contact_checks
