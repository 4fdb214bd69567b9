! SPDX-License-Identifier: MIT
!> Build a scene (network, force laws, constraints, loads, load path) from the input.
module yarnfort_scene_builder
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error, prefix_error
    use yarnfort_input_config, only: config_type, material_config_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_material_law, only: force_law_type
    use yarnfort_material_linear, only: linear_law_type, new_linear_law
    use yarnfort_material_neo_hookean, only: neo_hookean_law_type, new_neo_hookean_law
    use yarnfort_material_table, only: table_law_type, read_table_law
    use yarnfort_input_config, only: contact_config_type
    use yarnfort_friction_law, only: friction_law_type
    use yarnfort_friction_coulomb, only: coulomb_law_type, new_coulomb_law
    use yarnfort_friction_adhesion, only: adhesion_law_type, new_adhesion_law
    use yarnfort_friction_decaying_adhesion, only: decaying_adhesion_law_type, &
        new_decaying_adhesion_law
    implicit none
    private

    public :: new_scene, new_force_law

contains

    !> Build `scene` from a checked `config`. Relative table paths are taken relative to
    !> the input file's folder (the working directory for standard input).
    subroutine new_scene(scene, config, error)
        type(scene_type), intent(out) :: scene
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer :: m

        scene%title = config%control%title
        scene%solver = config%solver
        scene%output = config%output
        allocate(scene%laws(size(config%materials)))
        do m = 1, size(config%materials)
            scene%laws(m)%name = config%materials(m)%name
            call new_force_law(scene%laws(m)%law, config%materials(m), error, &
                config%input_folder)
            if (allocated(error)) then
                call prefix_error(error, "&material '" // trim(config%materials(m)%name) // "'")
                return
            end if
        end do
        call build_network(scene, config, error)
        if (allocated(error)) return
        call build_constraints(scene, config, error)
        if (allocated(error)) return
        call build_loads(scene, config)
        call build_passages(scene, config, error)
        if (allocated(error)) return
        scene%path%time = config%path%time
        scene%path%p_force = config%path%p_force
        scene%path%p_disp = config%path%p_disp
        scene%force_scale = 0.0_wp
        do m = 1, size(scene%laws)
            scene%force_scale = max(scene%force_scale, scene%laws(m)%law%get_reference_stiffness())
        end do
        scene%length_scale = sum(scene%network%length0) / size(scene%network%length0)
    end subroutine new_scene

    !> The force law a &material group describes. A relative table_file is taken
    !> relative to `folder` (the input file's folder; the working directory if empty).
    subroutine new_force_law(law, material, error, folder)
        class(force_law_type), allocatable, intent(out) :: law
        type(material_config_type), intent(in) :: material
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in), optional :: folder
        character(len=:), allocatable :: path

        select case (trim(material%law))
        case ('linear')
            block
                type(linear_law_type), allocatable :: linear
                allocate(linear)
                call new_linear_law(linear, material%stiffness, error)
                call move_alloc(linear, law)
            end block
        case ('neo_hookean')
            block
                type(neo_hookean_law_type), allocatable :: neo
                allocate(neo)
                call new_neo_hookean_law(neo, material%modulus, material%area, error)
                call move_alloc(neo, law)
            end block
        case ('table')
            block
                type(table_law_type), allocatable :: table
                allocate(table)
                path = trim(material%table_file)
                if (present(folder)) then
                    if (len_trim(folder) > 0 .and. path(1:1) /= '/') &
                        path = trim(folder) // '/' // path
                end if
                call read_table_law(table, path, error)
                call move_alloc(table, law)
            end block
        case default
            call fatal_error(error, "law '" // trim(material%law) &
                // "' is unknown (use linear, neo_hookean or table)")
        end select
    end subroutine new_force_law

    !> Nodes, and elements from the yarns: each segment between listed nodes is split
    !> into elements_per_segment elements through new, evenly spaced nodes. Elements
    !> start stress-free (L0 = initial length).
    subroutine build_network(scene, config, error)
        type(scene_type), intent(inout) :: scene
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer :: n_nodes, n_elements, y, s, j, k, e, node, previous, material
        real(wp), allocatable :: position(:, :)
        logical, allocatable :: used(:)
        character(len=120) :: buffer

        n_nodes = size(config%node_positions, 2)
        n_elements = 0
        do y = 1, size(config%yarns)
            n_elements = n_elements + (size(config%yarns(y)%nodes) - 1) &
                * config%yarns(y)%elements_per_segment
        end do
        allocate(position(3, n_nodes + n_elements))
        position(:, 1:n_nodes) = config%node_positions
        allocate(scene%network%element_nodes(2, n_elements))
        allocate(scene%network%length0(n_elements), scene%network%element_material(n_elements))
        allocate(scene%network%yarn_first_element(size(config%yarns) + 1))
        allocate(used(n_nodes), source=.false.)
        e = 0
        node = n_nodes
        do y = 1, size(config%yarns)
            associate(yarn => config%yarns(y))
                scene%network%yarn_first_element(y) = e + 1
                material = find_material(config, yarn%material)
                previous = yarn%nodes(1)
                used(yarn%nodes) = .true.
                do s = 1, size(yarn%nodes) - 1
                    do k = 1, yarn%elements_per_segment
                        e = e + 1
                        if (k < yarn%elements_per_segment) then
                            node = node + 1
                            position(:, node) = config%node_positions(:, yarn%nodes(s)) &
                                + real(k, wp) / yarn%elements_per_segment &
                                * (config%node_positions(:, yarn%nodes(s + 1)) &
                                - config%node_positions(:, yarn%nodes(s)))
                            j = node
                        else
                            j = yarn%nodes(s + 1)
                        end if
                        scene%network%element_nodes(:, e) = [previous, j]
                        scene%network%element_material(e) = material
                        scene%network%length0(e) = norm2(position(:, j) - position(:, previous))
                        if (.not. (scene%network%length0(e) > 0.0_wp)) then
                            write(buffer, '("&yarn ", i0, ": nodes ", i0, " and ", i0, &
                                & " coincide (zero-length element)")') y, previous, j
                            call fatal_error(error, trim(buffer))
                            return
                        end if
                        previous = j
                    end do
                end do
            end associate
        end do
        scene%network%yarn_first_element(size(config%yarns) + 1) = e + 1
        scene%network%position = position(:, 1:node)
        do j = 1, n_nodes
            if (.not. used(j)) then
                write(buffer, '("&nodes: node ", i0, " belongs to no yarn")') j
                call fatal_error(error, trim(buffer))
                return
            end if
        end do
    end subroutine build_network

    integer function find_material(config, name) result(index)
        type(config_type), intent(in) :: config
        character(len=*), intent(in) :: name
        do index = 1, size(config%materials)
            if (trim(config%materials(index)%name) == trim(name)) return
        end do
        index = 0
    end function find_material

    !> Prescribed coordinates from the &support groups, then unknowns numbered in node
    !> order for the free coordinates.
    subroutine build_constraints(scene, config, error)
        type(scene_type), intent(inout) :: scene
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer :: n_coordinates, s, i, k, c, n, count
        integer, allocatable :: owner(:)
        character(len=1), parameter :: axis(3) = ['x', 'y', 'z']
        character(len=200) :: buffer

        n_coordinates = 3 * scene%network%n_nodes()
        allocate(owner(n_coordinates), source=0)
        allocate(scene%dofs%base(n_coordinates), scene%dofs%delta(n_coordinates))
        scene%dofs%base = 0.0_wp
        scene%dofs%delta = 0.0_wp
        allocate(scene%supports(size(config%supports)))
        do s = 1, size(config%supports)
            associate(support => config%supports(s))
                scene%supports(s)%name = support%name
                allocate(scene%supports(s)%coordinates(0))
                do i = 1, size(support%nodes)
                    n = support%nodes(i)
                    do k = 1, 3
                        if (index(support%fix, axis(k)) == 0) cycle
                        c = 3 * (n - 1) + k
                        if (owner(c) /= 0) then
                            write(buffer, '("&support ''", a, "'': node ", i0, " ", a, &
                                & " is already prescribed by &support ''", a, "''")') &
                                trim(support%name), n, axis(k), &
                                trim(config%supports(owner(c))%name)
                            call fatal_error(error, trim(buffer))
                            return
                        end if
                        owner(c) = s
                        scene%dofs%base(c) = scene%network%position(k, n)
                        scene%dofs%delta(c) = support%displacement(k)
                        scene%supports(s)%coordinates = [scene%supports(s)%coordinates, c]
                    end do
                end do
            end associate
        end do
        allocate(scene%dofs%unknown(n_coordinates), source=0)
        count = 0
        do c = 1, n_coordinates
            if (owner(c) == 0) then
                count = count + 1
                scene%dofs%unknown(c) = count
            end if
        end do
        scene%dofs%n_unknowns = count
    end subroutine build_constraints

    subroutine build_loads(scene, config)
        type(scene_type), intent(inout) :: scene
        type(config_type), intent(in) :: config
        integer :: l, i, n

        allocate(scene%external_force(3 * scene%network%n_nodes()), source=0.0_wp)
        do l = 1, size(config%loads)
            do i = 1, size(config%loads(l)%nodes)
                n = config%loads(l)%nodes(i)
                scene%external_force(3 * n - 2:3 * n) = scene%external_force(3 * n - 2:3 * n) &
                    + config%loads(l)%force
            end do
        end do
    end subroutine build_loads

    !> Friction laws from the &contact groups and the passages that use them: every
    !> time a yarn passes (does not end) at a node that another yarn (or another pass of
    !> the same yarn) also visits. Passages whose pair of yarn types is 'bonded' are
    !> plain shared nodes and get no passage. The law of a passage is that of its yarn's
    !> type paired with the type of the first other yarn at the node.
    subroutine build_passages(scene, config, error)
        type(scene_type), intent(inout) :: scene
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer :: c, y, e, node, n_nodes, n_passages, other, law, n_yarns, k
        integer, allocatable :: visits(:), first_yarn(:), second_yarn(:), contact_of(:, :)
        integer, allocatable :: yarn(:), at_node(:), before(:), after(:), laws(:)
        character(len=200) :: buffer

        n_yarns = size(config%yarns)
        allocate(scene%friction(size(config%contacts)))
        ! contact_of(type_a, type_b): index of the &contact group, 0 for none.
        allocate(contact_of(size(config%materials), size(config%materials)), source=0)
        do c = 1, size(config%contacts)
            call new_friction_law(scene%friction(c)%law, config%contacts(c), error)
            if (allocated(error)) then
                write(buffer, '("&contact #", i0)') c
                call prefix_error(error, trim(buffer))
                return
            end if
            associate(a => find_material(config, config%contacts(c)%materials(1)), &
                    b => find_material(config, config%contacts(c)%materials(2)))
                contact_of(a, b) = c
                contact_of(b, a) = c
            end associate
        end do
        allocate(scene%passages%at_start(scene%network%n_elements()), source=0)
        allocate(scene%passages%at_end(scene%network%n_elements()), source=0)
        allocate(yarn(0), at_node(0), before(0), after(0), laws(0))
        if (size(config%contacts) == 0) then
            scene%passages%yarn = yarn
            scene%passages%node = at_node
            scene%passages%element_before = before
            scene%passages%element_after = after
            scene%passages%law = laws
            return
        end if

        ! Yarns visiting each original node (the first two distinct visits suffice).
        n_nodes = size(config%node_positions, 2)
        allocate(visits(n_nodes), source=0)
        allocate(first_yarn(n_nodes), source=0)
        allocate(second_yarn(n_nodes), source=0)
        do y = 1, n_yarns
            do k = 1, size(config%yarns(y)%nodes)
                node = config%yarns(y)%nodes(k)
                visits(node) = visits(node) + 1
                if (visits(node) == 1) then
                    first_yarn(node) = y
                else if (visits(node) == 2) then
                    second_yarn(node) = y
                end if
            end do
        end do
        ! Passages: interior nodes of a yarn's list that are visited more than once.
        n_passages = 0
        do y = 1, n_yarns
            do k = 2, size(config%yarns(y)%nodes) - 1
                node = config%yarns(y)%nodes(k)
                if (visits(node) < 2) cycle
                other = first_yarn(node)
                if (other == y) other = second_yarn(node)
                c = contact_of(find_material(config, config%yarns(y)%material), &
                    find_material(config, config%yarns(other)%material))
                if (c == 0) cycle
                if (trim(config%contacts(c)%law) == 'bonded') cycle
                ! The elements before and after the node along the yarn.
                e = scene%network%yarn_first_element(y) - 1 &
                    + (k - 1) * config%yarns(y)%elements_per_segment
                yarn = [yarn, y]
                at_node = [at_node, node]
                before = [before, e]
                after = [after, e + 1]
                laws = [laws, c]
                n_passages = n_passages + 1
                scene%passages%at_end(e) = n_passages
                scene%passages%at_start(e + 1) = n_passages
            end do
        end do
        scene%passages%yarn = yarn
        scene%passages%node = at_node
        scene%passages%element_before = before
        scene%passages%element_after = after
        scene%passages%law = laws
    end subroutine build_passages

    !> The friction law of a &contact group ('bonded' gets none: it never slides).
    subroutine new_friction_law(law, contact, error)
        class(friction_law_type), allocatable, intent(out) :: law
        type(contact_config_type), intent(in) :: contact
        type(error_type), allocatable, intent(out) :: error

        select case (trim(contact%law))
        case ('bonded')
        case ('coulomb')
            block
                type(coulomb_law_type), allocatable :: coulomb
                allocate(coulomb)
                call new_coulomb_law(coulomb, contact%friction_coefficient, error)
                call move_alloc(coulomb, law)
            end block
        case ('adhesion')
            block
                type(adhesion_law_type), allocatable :: adhesion
                allocate(adhesion)
                call new_adhesion_law(adhesion, contact%friction_coefficient, &
                    contact%adhesion, error)
                call move_alloc(adhesion, law)
            end block
        case ('decaying_adhesion')
            block
                type(decaying_adhesion_law_type), allocatable :: decaying
                allocate(decaying)
                call new_decaying_adhesion_law(decaying, contact%friction_coefficient, &
                    contact%adhesion, contact%decay_start, contact%decay_end, error)
                call move_alloc(decaying, law)
            end block
        case default
            call fatal_error(error, "law '" // trim(contact%law) // "' is unknown")
        end select
    end subroutine new_friction_law

end module yarnfort_scene_builder
