! SPDX-License-Identifier: MIT
!> Build a scene (network, force laws, constraints, loads, load path) from the input.
module yarnfort_scene_builder
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error, prefix_error
    use yarnfort_input_config, only: config_type, material_config_type
    use yarnfort_scene_scene, only: scene_type, support_set_type, lateral_channel_name
    use yarnfort_text, only: format_real
    use yarnfort_material_force_law, only: force_law_type
    use yarnfort_material_linear, only: linear_law_type, new_linear_law
    use yarnfort_material_neo_hookean, only: neo_hookean_law_type, new_neo_hookean_law
    use yarnfort_material_table, only: table_law_type, read_table_law
    use yarnfort_input_config, only: contact_config_type
    use yarnfort_friction_law, only: friction_law_type
    use yarnfort_friction_coulomb, only: coulomb_law_type, new_coulomb_law
    use yarnfort_friction_adhesion, only: adhesion_law_type, new_adhesion_law
    use yarnfort_friction_decaying_adhesion, only: decaying_adhesion_law_type, &
        new_decaying_adhesion_law
    use yarnfort_friction_general, only: rate_table_law_type => table_law_type, &
        read_rate_table
    use yarnfort_text, only: resolve_path, quote_string
    use yarnfort_input_config, only: name_length
    use yarnfort_scene_contact_nodes, only: get_contact_node_sets, find_node_contact
    use yarnfort_scene_channels, only: get_channel_names, get_channel_factors, &
        find_channel, default_force_channel, default_displacement_channel
    implicit none
    private

    public :: new_scene, new_force_law, new_friction_law

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
        scene%path%channel = get_channel_names(config%path)
        ! A force-controlled y period of a periodic cell: e22 is the factor of a channel
        ! of its own (the path leaves it at 0; the outer iteration sets it).
        if (len_trim(config%fabric%kind) > 0 .and. config%fabric%boundary == 'periodic' &
                .and. config%fabric%lateral_control /= 'strain') then
            scene%path%channel = [character(len=name_length) :: scene%path%channel, &
                lateral_channel_name]
            scene%lateral_channel = size(scene%path%channel)
            scene%lateral_control = config%fabric%lateral_control
            scene%lateral_force = config%fabric%lateral_force
            scene%force_ratio = config%fabric%force_ratio
        end if
        call build_network(scene, config, error)
        if (allocated(error)) return
        call apply_prestress(scene, config, error)
        if (allocated(error)) return
        call apply_element_lengths(scene, config)
        call build_constraints(scene, config, error)
        if (allocated(error)) return
        call build_links(scene, config, error)
        if (allocated(error)) return
        call build_loads(scene, config)
        call build_passages(scene, config, error)
        if (allocated(error)) return
        ! Something to solve: a free coordinate or a passage that slides (an input error
        ! here, before anything is written; yarnfort_input_validate finds the plain case).
        if (scene%dofs%n_unknowns == 0 .and. scene%passages%size() == 0) then
            call fatal_error(error, 'every coordinate of every node is prescribed (by ' &
                // '&support, &obstacle or the links of a generated fabric) and no yarn ' &
                // 'slides at a contact: the scene has no unknowns (nothing to solve)')
            return
        end if
        if (config%fabric_width > 0.0_wp) then
            scene%fabric_width = config%fabric_width
            scene%fabric_strain = config%fabric%strain
            if (config%fabric_support > 0) scene%fabric_set = config%fabric_support
            ! A periodic cell's periods are its longest lattice vectors along x and y
            ! (images lie one period away; a corner image both).
            scene%periodic_cell = config%fabric%boundary == 'periodic'
            if (scene%periodic_cell) then
                scene%cell_period = maxval(abs(scene%cell_lattice(1:2, :)), dim=2)
                scene%cell_strain = [config%fabric%strain, config%fabric%lateral_strain]
            end if
        end if
        scene%path%time = config%path%time
        scene%path%channel = get_channel_names(config%path)
        scene%path%factor = get_channel_factors(config%path)
        if (scene%lateral_channel > 0) then
            scene%path%channel = [character(len=name_length) :: scene%path%channel, &
                lateral_channel_name]
            block
                real(wp), allocatable :: factor(:, :)
                allocate(factor(size(scene%path%time), scene%lateral_channel), source=0.0_wp)
                factor(:, :scene%lateral_channel - 1) = scene%path%factor
                call move_alloc(factor, scene%path%factor)
            end block
        end if
        scene%length_scale = sum(scene%network%length0) / size(scene%network%length0)
    end subroutine new_scene

    !> The force law a &material group describes. A relative table_file is taken
    !> relative to `folder` (the input file's folder; the working directory if empty).
    subroutine new_force_law(law, material, error, folder)
        class(force_law_type), allocatable, intent(out) :: law
        type(material_config_type), intent(in) :: material
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in), optional :: folder
        type(linear_law_type) :: linear
        type(neo_hookean_law_type) :: neo
        type(table_law_type) :: table
        character(len=:), allocatable :: path

        if (trim(material%law) /= 'table') then
            call check_table_units_unset(material, error)
            if (allocated(error)) return
        end if
        select case (trim(material%law))
        case ('linear')
            call new_linear_law(linear, material%stiffness, error)
            allocate(law, source=linear)
        case ('neo_hookean')
            call new_neo_hookean_law(neo, material%modulus, material%area, error)
            allocate(law, source=neo)
        case ('table')
            path = trim(material%table_file)
            if (present(folder)) path = resolve_path(path, folder)
            if (.not. allocated(material%gauge_length)) then
                call read_table_law(table, path, error, strain_unit=trim(material%strain_unit), &
                    force_unit=trim(material%force_unit))
            else
                call read_table_law(table, path, error, strain_unit=trim(material%strain_unit), &
                    force_unit=trim(material%force_unit), gauge_length=material%gauge_length)
            end if
            allocate(law, source=table)
        case default
            call fatal_error(error, "law '" // trim(material%law) &
                // "' is unknown (use linear, neo_hookean or table)")
        end select
    end subroutine new_force_law

    !> The units of a table file are not set for another law (they would be ignored).
    subroutine check_table_units_unset(material, error)
        type(material_config_type), intent(in) :: material
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: name, text

        if (len_trim(material%strain_unit) > 0) then
            name = 'strain_unit'
            text = quote_string(trim(material%strain_unit))
        else if (len_trim(material%force_unit) > 0) then
            name = 'force_unit'
            text = quote_string(trim(material%force_unit))
        else if (allocated(material%gauge_length)) then
            name = 'gauge_length'
            text = format_real(material%gauge_length)
        else
            return
        end if
        call fatal_error(error, name // ' = ' // text // " is not used by law '" &
            // trim(material%law) // "' (only by 'table'; remove it)")
    end subroutine check_table_units_unset

    !> Nodes, and elements from the yarns: each segment between listed nodes is split
    !> into elements_per_segment elements through new, evenly spaced nodes. Elements
    !> start stress-free (L0 = initial length).
    subroutine build_network(scene, config, error)
        type(scene_type), intent(inout) :: scene
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer :: n_nodes, n_elements, y, s, j, k, e, node, previous, material, status
        real(wp), allocatable :: position(:, :)
        logical, allocatable :: used(:)
        character(len=120) :: buffer

        n_nodes = size(config%node_positions, 2)
        n_elements = 0
        do y = 1, size(config%yarns)
            n_elements = n_elements + (size(config%yarns(y)%nodes) - 1) &
                * config%yarns(y)%elements_per_segment
        end do
        allocate(position(3, n_nodes + n_elements), scene%network%element_nodes(2, n_elements), &
            scene%network%length0(n_elements), scene%network%element_material(n_elements), &
            stat=status)
        if (status /= 0) then
            write(buffer, '("the network of ", i0, " elements does not fit in memory")') &
                n_elements
            call fatal_error(error, trim(buffer))
            return
        end if
        position(:, 1:n_nodes) = config%node_positions
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
        integer :: n_coordinates, s, i, k, c, n, count, channel
        integer, allocatable :: owner(:)
        character(len=1), parameter :: axis(3) = ['x', 'y', 'z']
        character(len=200) :: buffer

        n_coordinates = 3 * scene%network%n_nodes()
        allocate(owner(n_coordinates), source=0)
        allocate(scene%dofs%base(n_coordinates), &
            scene%dofs%delta(n_coordinates, size(scene%path%channel)))
        scene%dofs%base = 0.0_wp
        scene%dofs%delta = 0.0_wp
        allocate(scene%supports(size(config%supports)))
        do s = 1, size(config%supports)
            associate(support => config%supports(s))
                channel = find_channel(scene%path%channel, support%channel, &
                    default_displacement_channel, len_trim(config%path%channels(1)) > 0)
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
                        ! Checked: a support without a channel has no displacement.
                        if (channel > 0) scene%dofs%delta(c, channel) = support%displacement(k)
                        scene%supports(s)%coordinates = [scene%supports(s)%coordinates, c]
                    end do
                end do
            end associate
        end do
        call hold_obstacles(scene, config, owner)
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

    !> Obstacles: every coordinate of an &obstacle's nodes that no &support prescribes is
    !> held at its initial position, by a support set named after the obstacle (its
    !> reaction is the force of the yarns on those coordinates). A &support that lists an
    !> obstacle's node moves it like any supported node.
    subroutine hold_obstacles(scene, config, owner)
        type(scene_type), intent(inout) :: scene
        type(config_type), intent(in) :: config
        integer, intent(inout) :: owner(:)
        type(support_set_type) :: held
        integer :: o, i, k, c

        if (.not. allocated(config%obstacles)) return
        do o = 1, size(config%obstacles)
            held%name = config%obstacles(o)%name
            allocate(held%coordinates(0))
            do i = 1, size(config%obstacles(o)%nodes)
                do k = 1, 3
                    c = 3 * (config%obstacles(o)%nodes(i) - 1) + k
                    if (owner(c) /= 0) cycle
                    owner(c) = size(config%supports) + o
                    scene%dofs%base(c) = scene%network%position(k, config%obstacles(o)%nodes(i))
                    scene%dofs%delta(c, :) = 0.0_wp
                    held%coordinates = [held%coordinates, c]
                end do
            end do
            if (size(held%coordinates) > 0) scene%supports = [scene%supports, held]
            deallocate(held%coordinates)
        end do
    end subroutine hold_obstacles

    !> Pre-stress: elements of a yarn type with prestress > 0 get the reference length
    !> at which they carry that tension in the initial geometry.
    subroutine apply_prestress(scene, config, error)
        type(scene_type), intent(inout) :: scene
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer :: m, e
        real(wp) :: stretch
        logical :: found

        do m = 1, size(config%materials)
            if (.not. (config%materials(m)%prestress > 0.0_wp)) cycle
            call scene%laws(m)%law%get_stretch_at_force(config%materials(m)%prestress, &
                stretch, found)
            if (.not. found) then
                call fatal_error(error, "&material '" // trim(config%materials(m)%name) &
                    // "': prestress = " // format_real(config%materials(m)%prestress) &
                    // ' N is more than the force law reaches')
                return
            end if
            do e = 1, scene%network%n_elements()
                if (scene%network%element_material(e) == m) then
                    scene%network%length0(e) = scene%network%length0(e) / stretch
                end if
            end do
        end do
    end subroutine apply_prestress

    !> Per-element reference lengths of the yarns that give them (checked: one value per
    !> element, > 0): `length0` as given, or `stretch` lambda as L0 = l / lambda (the
    !> operation of apply_prestress, so that lambda_p per element gives its lengths).
    subroutine apply_element_lengths(scene, config)
        type(scene_type), intent(inout) :: scene
        type(config_type), intent(in) :: config
        integer :: y, first, last

        do y = 1, size(config%yarns)
            first = scene%network%yarn_first_element(y)
            last = scene%network%yarn_first_element(y + 1) - 1
            associate(yarn => config%yarns(y))
                if (allocated(yarn%length0)) then
                    if (size(yarn%length0) > 0) scene%network%length0(first:last) = yarn%length0
                end if
                if (allocated(yarn%stretch)) then
                    if (size(yarn%stretch) > 0) scene%network%length0(first:last) = &
                        scene%network%length0(first:last) / yarn%stretch
                end if
            end associate
        end do
    end subroutine apply_element_lengths

    !> Links (periodic images, eq. 53, and gap-holders): a follower node's coordinates
    !> share the unknowns of its leader (followed to the end of a chain), offset by their
    !> initial difference, plus the macroscopic stretch (periodic) or scaled by the gap
    !> factor (gap-holder). Periodic followers that move with the x stretch form the
    !> force set 'stretch': its x reaction is the force carried across the cell. A
    !> follower coordinate of a prescribed root is prescribed too; it is listed among the
    !> followers of the root's support set, whose reaction at the root is then the whole
    !> force on the root and every coordinate that follows it.
    subroutine build_links(scene, config, error)
        type(scene_type), intent(inout) :: scene
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer :: n_nodes, l, n, r, k, c, cr, hops, displacement_channel, s, i
        integer, allocatable :: leader(:), link_of(:), stretch_coordinates(:)
        integer, allocatable :: set_of(:), place_of(:)
        real(wp) :: offset(3), macro(3), gap(3), step(3), lattice(3)
        character(len=200) :: buffer

        n_nodes = scene%network%n_nodes()
        displacement_channel = max(1, find_channel(scene%path%channel, '', &
            default_displacement_channel, .false.))
        scene%dofs%gap_channel = displacement_channel
        allocate(scene%dofs%gap(3 * n_nodes), source=0.0_wp)
        if (allocated(config%fabric%gap_factor)) then
            scene%dofs%gap_p_disp = config%fabric%gap_factor_p_disp
            scene%dofs%gap_factor = config%fabric%gap_factor
        end if
        allocate(scene%link_nodes(2, 0), scene%link_is_gap(0))
        allocate(scene%link_period(3, 0), scene%link_strain(3, 0))
        allocate(scene%cell_lattice(3, n_nodes), source=0.0_wp)
        if (.not. allocated(config%links)) return
        if (size(config%links) == 0) return
        scene%link_nodes = reshape([(config%links(l)%leader, config%links(l)%follower, &
            l = 1, size(config%links))], [2, size(config%links)])
        scene%link_is_gap = config%links%gap
        deallocate(scene%link_period, scene%link_strain)
        allocate(scene%link_period(3, size(config%links)), scene%link_strain(3, &
            size(config%links)))
        do l = 1, size(config%links)
            associate(link => config%links(l))
                scene%link_strain(:, l) = link%strain
                scene%link_period(:, l) = link%period
                if (.not. link%gap) scene%link_period(:, l) = scene%network%position(:, &
                    link%follower) - scene%network%position(:, link%leader)
            end associate
        end do
        allocate(leader(n_nodes), link_of(n_nodes), source=0)
        do l = 1, size(config%links)
            n = config%links(l)%follower
            if (leader(n) /= 0) then
                write(buffer, '("node ", i0, " follows both node ", i0, " and node ", i0)') &
                    n, leader(n), config%links(l)%leader
                call fatal_error(error, trim(buffer))
                return
            end if
            if (any(scene%dofs%unknown(3 * n - 2:3 * n) == 0)) then
                write(buffer, '("node ", i0, " follows node ", i0, &
                    & " and cannot also be supported")') n, config%links(l)%leader
                call fatal_error(error, trim(buffer))
                return
            end if
            leader(n) = config%links(l)%leader
            link_of(n) = l
        end do
        ! The support set of every prescribed coordinate and its place in that set.
        allocate(set_of(3 * n_nodes), place_of(3 * n_nodes), source=0)
        do s = 1, size(scene%supports)
            associate(coordinates => scene%supports(s)%coordinates)
                set_of(coordinates) = s
                place_of(coordinates) = [(i, i = 1, size(coordinates))]
            end associate
            allocate(scene%supports(s)%followers(0), scene%supports(s)%follows(0))
        end do
        allocate(stretch_coordinates(0))
        do n = 1, n_nodes
            if (leader(n) == 0) cycle
            ! Walk to the root, summing the offsets of every hop.
            offset = 0.0_wp
            macro = 0.0_wp
            gap = 0.0_wp
            lattice = 0.0_wp
            r = n
            hops = 0
            do while (leader(r) /= 0)
                hops = hops + 1
                if (hops > n_nodes) then
                    write(buffer, '("node ", i0, " is in a cycle of links")') n
                    call fatal_error(error, trim(buffer))
                    return
                end if
                associate(link => config%links(link_of(r)))
                    step = scene%network%position(:, r) - scene%network%position(:, leader(r))
                    offset = offset + step
                    if (link%gap) then
                        gap = gap + step - link%period
                        macro = macro + link%strain * link%period
                        lattice = lattice + link%period
                    else
                        macro = macro + link%strain * step
                        lattice = lattice + step
                    end if
                end associate
                r = leader(r)
            end do
            scene%cell_lattice(:, n) = lattice
            do k = 1, 3
                c = 3 * (n - 1) + k
                cr = 3 * (r - 1) + k
                scene%dofs%unknown(c) = scene%dofs%unknown(cr)
                ! The macroscopic stretch follows p_disp (fabrics have the two default
                ! channels; links come from fabrics only).
                if (scene%dofs%unknown(cr) == 0) then
                    scene%dofs%base(c) = scene%dofs%base(cr) + offset(k)
                    scene%dofs%delta(c, :) = scene%dofs%delta(cr, :)
                    scene%dofs%delta(c, displacement_channel) = &
                        scene%dofs%delta(cr, displacement_channel) + macro(k)
                else
                    scene%dofs%base(c) = offset(k)
                    scene%dofs%delta(c, :) = 0.0_wp
                    scene%dofs%delta(c, displacement_channel) = macro(k)
                end if
                scene%dofs%gap(c) = gap(k)
                ! A force-controlled y period: y = root + lattice_y * (1 + e22).
                if (k == 2 .and. scene%lateral_channel > 0) &
                    scene%dofs%delta(c, scene%lateral_channel) = &
                    scene%dofs%delta(c, scene%lateral_channel) + lattice(2)
                if (scene%dofs%unknown(cr) == 0 .and. set_of(cr) > 0) then
                    associate(set => scene%supports(set_of(cr)))
                        set%followers = [set%followers, c]
                        set%follows = [set%follows, place_of(cr)]
                    end associate
                end if
            end do
            if (macro(1) /= 0.0_wp) stretch_coordinates = [stretch_coordinates, 3 * n - 2]
        end do
        call renumber_unknowns(scene%dofs%unknown, scene%dofs%n_unknowns)
        if (size(stretch_coordinates) > 0) then
            block
                type(support_set_type) :: stretch
                stretch%name = 'stretch'
                stretch%coordinates = stretch_coordinates
                allocate(stretch%followers(0), stretch%follows(0))
                scene%supports = [scene%supports, stretch]
                if (config%fabric_width > 0.0_wp) scene%fabric_set = size(scene%supports)
            end block
        end if
    end subroutine build_links

    !> Renumber the unknowns 1..n in order of first use (followers leave gaps).
    subroutine renumber_unknowns(unknown, n)
        integer, intent(inout) :: unknown(:)
        integer, intent(out) :: n
        integer, allocatable :: new(:)
        integer :: c

        allocate(new(maxval([0, unknown])), source=0)
        n = 0
        do c = 1, size(unknown)
            if (unknown(c) == 0) cycle
            if (new(unknown(c)) == 0) then
                n = n + 1
                new(unknown(c)) = n
            end if
            unknown(c) = new(unknown(c))
        end do
    end subroutine renumber_unknowns

    !> External forces per load channel and the node sets of the &load groups.
    subroutine build_loads(scene, config)
        type(scene_type), intent(inout) :: scene
        type(config_type), intent(in) :: config
        integer :: l, i, n, channel

        allocate(scene%external_force(3 * scene%network%n_nodes(), size(scene%path%channel)), &
            source=0.0_wp)
        allocate(scene%loads(size(config%loads)))
        do l = 1, size(config%loads)
            scene%loads(l)%nodes = config%loads(l)%nodes
            channel = find_channel(scene%path%channel, config%loads(l)%channel, &
                default_force_channel, len_trim(config%path%channels(1)) > 0)
            ! Checked: a load without a channel has no force.
            if (channel == 0) cycle
            do i = 1, size(config%loads(l)%nodes)
                n = config%loads(l)%nodes(i)
                scene%external_force(3 * n - 2:3 * n, channel) = &
                    scene%external_force(3 * n - 2:3 * n, channel) + config%loads(l)%force
            end do
        end do
    end subroutine build_loads

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

    !> The friction law of a &contact group ('bonded' gets none: it never slides). A
    !> relative rate_table is taken relative to `folder` (as a &material table_file).
    subroutine new_friction_law(law, contact, error, folder)
        class(friction_law_type), allocatable, intent(out) :: law
        type(contact_config_type), intent(in) :: contact
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: folder
        type(coulomb_law_type) :: coulomb
        type(adhesion_law_type) :: adhesion
        type(decaying_adhesion_law_type) :: decaying
        type(rate_table_law_type) :: general

        select case (trim(contact%law))
        case ('bonded')
        case ('coulomb')
            call new_coulomb_law(coulomb, contact%friction_coefficient, error)
            allocate(law, source=coulomb)
        case ('adhesion')
            call new_adhesion_law(adhesion, contact%friction_coefficient, contact%adhesion, &
                error)
            allocate(law, source=adhesion)
        case ('decaying_adhesion')
            call new_decaying_adhesion_law(decaying, contact%friction_coefficient, &
                contact%adhesion, contact%decay_start, contact%decay_end, error)
            allocate(law, source=decaying)
        case ('general')
            call read_rate_table(general, resolve_path(contact%rate_table, folder), error)
            allocate(law, source=general)
        case default
            call fatal_error(error, "law '" // trim(contact%law) // "' is unknown")
        end select
    end subroutine new_friction_law

end module yarnfort_scene_builder
