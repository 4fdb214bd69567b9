! SPDX-License-Identifier: MIT
!> The friction laws of the &contact groups and the passages (a yarn over a contact
!> node) that use them.
module yarnfort_scene_builder_passages
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error, prefix_error
    use yarnfort_input_config, only: config_type, name_length
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_scene_contact_nodes, only: get_contact_node_sets, find_node_contact
    use yarnfort_scene_builder_laws, only: new_friction_law, find_material
    implicit none
    private

    public :: build_passages

contains

    !> Friction laws from the &contact groups and the passages that use them: every
    !> time a yarn passes (does not end) at a node that another yarn (or another pass of
    !> the same yarn) also visits. The law of a passage is the &contact of its yarn's
    !> type paired with the types of the node's other visits; it must be the same for
    !> every pair that has one (else an error), so the order of the input never matters.
    !> 'bonded' pairs, and nodes with no &contact for any pair, are plain shared nodes.
    !> At a node of an &obstacle or &ring every pass of a yarn is a passage, even the
    !> only one, and its law is the node's (find_node_contact); pair laws do not apply.
    subroutine build_passages(scene, config, error)
        type(scene_type), intent(inout) :: scene
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer :: c, y, e, node, n_nodes, n_passages, n_yarns, k
        integer, allocatable :: visits(:), visitor(:), visit_index(:), filled(:), contact_of(:, :)
        integer, allocatable :: root(:)
        integer :: m
        integer, allocatable :: yarn(:), at_node(:), before(:), after(:), laws(:)
        integer, allocatable :: set_of(:)
        character(len=name_length), allocatable :: set_names(:)
        integer :: n_obstacles
        character(len=200) :: buffer

        n_yarns = size(config%yarns)
        allocate(scene%friction(size(config%contacts)))
        ! contact_of(type_a, type_b): index of the &contact group, 0 for none.
        allocate(contact_of(size(config%materials), size(config%materials)), source=0)
        do c = 1, size(config%contacts)
            call new_friction_law(scene%friction(c)%law, config%contacts(c), error, &
                config%input_folder)
            if (allocated(error)) then
                write(buffer, '("&contact #", i0)') c
                call prefix_error(error, trim(buffer))
                return
            end if
            if (len_trim(config%contacts(c)%at) > 0) cycle     ! an obstacle's or ring's
            associate(a => find_material(config, config%contacts(c)%materials(1)), &
                    b => find_material(config, config%contacts(c)%materials(2)))
                contact_of(a, b) = c
                contact_of(b, a) = c
            end associate
        end do
        allocate(scene%passages%at_start(scene%network%n_elements()), source=0)
        allocate(scene%passages%at_end(scene%network%n_elements()), source=0)
        allocate(scene%passages%share(scene%network%n_elements()), source=1.0_wp)
        ! At most every interior node of every yarn is a passage (filled below, trimmed
        ! by store_passages; appending one at a time was quadratic in the passages).
        n_passages = sum([(max(size(config%yarns(y)%nodes) - 2, 0), y = 1, n_yarns)])
        allocate(yarn(n_passages), at_node(n_passages), before(n_passages), &
            after(n_passages), laws(n_passages))
        n_passages = 0
        if (size(config%contacts) == 0) then
            call store_passages()
            return
        end if

        ! Obstacles and rings: every passage there takes the node's own law.
        call get_contact_node_sets(config, set_of, set_names, n_obstacles)
        ! Visits of each original node by the yarns, listed per node (CSR). Nodes joined
        ! by links (gap-holders, periodic images) count as one contact: visits are
        ! counted at the root of each node's chain of links. Bonded gap links do not
        ! join contacts (their nodes are sewn together).
        n_nodes = size(config%node_positions, 2)
        allocate(root(n_nodes))
        root = [(node, node = 1, n_nodes)]
        if (allocated(config%links)) then
            do k = 1, size(config%links)
                if (config%links(k)%bonded) cycle
                root(config%links(k)%follower) = config%links(k)%leader
            end do
        end if
        do node = 1, n_nodes
            do k = 1, n_nodes
                if (root(root(node)) == root(node)) exit
                root(node) = root(root(node))
            end do
        end do
        allocate(visits(n_nodes + 1), source=0)
        do y = 1, n_yarns
            do k = 1, size(config%yarns(y)%nodes)
                node = root(config%yarns(y)%nodes(k))
                visits(node + 1) = visits(node + 1) + 1
            end do
        end do
        do node = 1, n_nodes
            visits(node + 1) = visits(node + 1) + visits(node)
        end do
        allocate(visitor(visits(n_nodes + 1)), visit_index(visits(n_nodes + 1)))
        allocate(filled(n_nodes), source=0)
        do y = 1, n_yarns
            do k = 1, size(config%yarns(y)%nodes)
                node = root(config%yarns(y)%nodes(k))
                filled(node) = filled(node) + 1
                visitor(visits(node) + filled(node)) = y
                visit_index(visits(node) + filled(node)) = k
            end do
        end do
        ! Passages: interior nodes of a yarn's list that are visited more than once. The
        ! law of a passage: the &contact of its yarn's type paired with the type of each
        ! other visit of the node (other yarns, or other passes of the same yarn); pairs
        ! without a &contact do not count. None: a plain shared node. Several different
        ! ones: an error (the law would depend on the order of the input).
        do y = 1, n_yarns
            do k = 2, size(config%yarns(y)%nodes) - 1
                node = config%yarns(y)%nodes(k)
                call find_passage_contact(root(node), y, k, c, error)
                if (allocated(error)) return
                if (c == 0) cycle
                if (trim(config%contacts(c)%law) == 'bonded') cycle
                ! The elements before and after the node along the yarn.
                e = scene%network%yarn_first_element(y) - 1 &
                    + (k - 1) * config%yarns(y)%elements_per_segment
                n_passages = n_passages + 1
                yarn(n_passages) = y
                at_node(n_passages) = node
                before(n_passages) = e
                after(n_passages) = e + 1
                laws(n_passages) = c
                ! Every element of the segments before and after the node.
                m = config%yarns(y)%elements_per_segment
                scene%passages%at_end(e - m + 1:e) = n_passages
                scene%passages%at_start(e + 1:e + m) = n_passages
            end do
        end do
        ! Each element's share of its segment's initial reference length.
        do y = 1, n_yarns
            m = config%yarns(y)%elements_per_segment
            do e = scene%network%yarn_first_element(y), scene%network%yarn_first_element(y + 1) &
                    - 1, m
                scene%passages%share(e:e + m - 1) = scene%network%length0(e:e + m - 1) &
                    / sum(scene%network%length0(e:e + m - 1))
            end do
        end do
        call store_passages()
    contains
        !> Hand the passages found (none without &contact groups) to the scene.
        subroutine store_passages()
            scene%passages%yarn = yarn(1:n_passages)
            scene%passages%node = at_node(1:n_passages)
            scene%passages%element_before = before(1:n_passages)
            scene%passages%element_after = after(1:n_passages)
            scene%passages%law = laws(1:n_passages)
        end subroutine store_passages

        !> The &contact of yarn y's k-th listed node (visits at `node`, a root), or 0.
        subroutine find_passage_contact(node, y, k, contact, error)
            integer, intent(in) :: node, y, k
            integer, intent(out) :: contact
            type(error_type), allocatable, intent(out) :: error
            integer :: v, candidate, own
            character(len=300) :: message

            contact = 0
            if (set_of(node) /= 0) then
                contact = find_node_contact(config, set_names(set_of(node)), &
                    config%yarns(y)%material)
                if (contact == 0) call fatal_error(error, "no &contact for yarn type '" &
                    // trim(config%yarns(y)%material) // "' at '" &
                    // trim(set_names(set_of(node))) // "'")
                return
            end if
            own = find_material(config, config%yarns(y)%material)
            do v = visits(node) + 1, visits(node + 1)
                if (visitor(v) == y .and. visit_index(v) == k) cycle
                candidate = contact_of(own, find_material(config, config%yarns(visitor(v))%material))
                if (candidate == 0 .or. candidate == contact) cycle
                if (contact /= 0) then
                    write(message, '("node ", i0, ": &yarn ", i0, " (type ''", a, "'') meets ", &
                        &"yarns whose types pair with it under two different &contact groups (#", &
                        &i0, " and #", i0, "): give one law for the node, e.g. the same &contact ", &
                        &"for both pairs")') config%yarns(y)%nodes(k), y, &
                        trim(config%yarns(y)%material), min(contact, candidate), &
                        max(contact, candidate)
                    call fatal_error(error, trim(message))
                    return
                end if
                contact = candidate
            end do
        end subroutine find_passage_contact
    end subroutine build_passages

end module yarnfort_scene_builder_passages
