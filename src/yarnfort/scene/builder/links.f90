! SPDX-License-Identifier: MIT
!> Links between nodes (periodic images and gap-holders): followers share their
!> root's unknowns, offset by the cell's stretch or the gap factor.
module yarnfort_scene_builder_links
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type
    use yarnfort_scene_scene, only: scene_type, support_set_type
    use yarnfort_scene_channels, only: find_channel, default_displacement_channel
    implicit none
    private

    public :: build_links

contains

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
        real(wp) :: offset(3), macro(3), gap(3), step(3), lattice(3), sheared
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
            ! A force-controlled x period: x = root + lattice_x * (1 + e11), whatever
            ! `strain` (p_disp then scales the force held).
            if (scene%axial_channel > 0) macro(1) = 0.0_wp
            ! Simple shear: an image one y period up moves along x with p_disp (the y
            ! strain's term above is componentwise; this one crosses from y to x).
            sheared = macro(1) + config%fabric%shear * lattice(2)
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
                        scene%dofs%delta(cr, displacement_channel) &
                        + merge(sheared, macro(k), k == 1)
                else
                    scene%dofs%base(c) = offset(k)
                    scene%dofs%delta(c, :) = 0.0_wp
                    scene%dofs%delta(c, displacement_channel) = merge(sheared, macro(k), k == 1)
                end if
                scene%dofs%gap(c) = gap(k)
                ! A force-controlled y period: y = root + lattice_y * (1 + e22).
                if (k == 2 .and. scene%lateral_channel > 0) &
                    scene%dofs%delta(c, scene%lateral_channel) = &
                    scene%dofs%delta(c, scene%lateral_channel) + lattice(2)
                if (k == 1 .and. scene%axial_channel > 0) &
                    scene%dofs%delta(c, scene%axial_channel) = &
                    scene%dofs%delta(c, scene%axial_channel) + lattice(1)
                if (scene%dofs%unknown(cr) == 0 .and. set_of(cr) > 0) then
                    associate(set => scene%supports(set_of(cr)))
                        set%followers = [set%followers, c]
                        set%follows = [set%follows, place_of(cr)]
                    end associate
                end if
            end do
            ! The x coordinates the macroscopic stretch moves ('stretch', force_per_width).
            if (macro(1) /= 0.0_wp .or. (scene%axial_channel > 0 .and. lattice(1) /= 0.0_wp)) &
                stretch_coordinates = [stretch_coordinates, 3 * n - 2]
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

end module yarnfort_scene_builder_links
