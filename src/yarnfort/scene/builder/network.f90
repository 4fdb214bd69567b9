! SPDX-License-Identifier: MIT
!> The network of a scene: nodes and elements from the yarns, then the reference
!> lengths that pre-stress and per-element lengths give.
module yarnfort_scene_builder_network
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_text, only: format_real
    use yarnfort_scene_builder_laws, only: find_material
    implicit none
    private

    public :: build_network, apply_prestress, apply_element_lengths

contains

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

end module yarnfort_scene_builder_network
