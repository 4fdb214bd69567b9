! SPDX-License-Identifier: MIT
!> Contact nodes of their own kind: fixed obstacles (&obstacle) and free rings (&ring),
!> nodes that one or more yarns pass through with a friction law of the node. Their sets,
!> and the one rule that picks the law of a yarn at such a node: shared by the input
!> checks (yarnfort_input_contact_node_checks) and the scene builder.
module yarnfort_scene_contact_nodes
    use yarnfort_input_config, only: config_type, name_length
    implicit none
    private

    public :: node_set_type, get_node_sets, set_label, get_contact_node_sets, find_node_contact

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

end module yarnfort_scene_contact_nodes
