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

end module yarnfort_scene_builder
