! SPDX-License-Identifier: MIT
!> What the input prescribes: coordinates held by &support and &obstacle groups (and
!> the unknowns they leave), and the forces of the &load groups.
module yarnfort_scene_builder_supports
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type
    use yarnfort_scene_scene, only: scene_type, support_set_type
    use yarnfort_scene_channels, only: find_channel, default_force_channel, &
        default_displacement_channel
    implicit none
    private

    public :: build_constraints, build_loads

contains

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

end module yarnfort_scene_builder_supports
