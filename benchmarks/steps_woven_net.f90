! SPDX-License-Identifier: MIT
!> The crimped woven net of benchmarks/bench_friction and benchmarks/steps_trace: a
!> generated square net of warp and weft yarns with capstan friction at the crossings,
!> aligned with the axes or skewed.
module bench_woven_net
    use yarnfort_kinds, only: wp, ik
    use yarnfort_input_config, only: config_type
    use bench_common, only: number_grid_nodes
    implicit none
    private

    public :: make_woven_net, skew_net

contains

    !> --skewed: move every crossing node by a fixed pseudo-random offset (bench_friction's notes);
    !> the boundary nodes stay.
    subroutine skew_net(config, side)
        type(config_type), intent(inout) :: config
        integer, intent(in) :: side
        integer, allocatable :: id(:, :)
        integer :: i, j, n

        call number_grid_nodes(side, id, n)
        do j = 1, side
            do i = 1, side
                associate(x => config%node_positions(:, id(i, j)))
                    x(1) = x(1) + 0.02_wp * offset(i, j, 1)
                    x(2) = x(2) + 0.02_wp * offset(i, j, 2)
                    x(3) = x(3) + 0.01_wp * offset(i, j, 3)
                end associate
            end do
        end do
    end subroutine skew_net

    !> A fixed pseudo-random number in [-1, 1) from (i, j, c) (integer hash: the same
    !> with every compiler).
    pure real(wp) function offset(i, j, c)
        integer, intent(in) :: i, j, c
        integer(ik) :: h
        h = modulo(int(i, ik) * 73856093_ik + int(j, ik) * 19349663_ik + &
            int(c, ik) * 83492791_ik, 1000003_ik)
        h = modulo(h * h + 12345_ik, 1000003_ik)
        offset = 2.0_wp * real(h, wp) / 1000003.0_wp - 1.0_wp
    end function offset

    !> side x side crossings of warp (along x) and weft (along y) yarns at unit
    !> spacing; crossing (i, j) sits at z = +-h in a checkerboard (crimp), so both yarns
    !> bend at every crossing. Yarn ends: west ends fixed, east ends pulled by 20 % in x
    !> while weft ends are pulled by 5 % in y (held in z); crossings keep their height;
    !> unload to half and reload.
    !> Capstan with adhesion at every crossing.
    subroutine make_woven_net(config, side, per_segment, scheme)
        type(config_type), intent(out) :: config
        integer, intent(in) :: side, per_segment
        character(len=*), intent(in) :: scheme
        integer :: i, j, n, y
        integer, allocatable :: id(:, :)
        real(wp), parameter :: crimp = 0.15_wp

        call number_grid_nodes(side, id, n)
        allocate(config%node_positions(3, n))
        do j = 0, side + 1
            do i = 0, side + 1
                if (id(i, j) == 0) cycle
                config%node_positions(:, id(i, j)) = [real(i, wp), real(j, wp), &
                    crimp * merge(1.0_wp, -1.0_wp, mod(i + j, 2) == 0)]
                if (i == 0 .or. j == 0 .or. i == side + 1 .or. j == side + 1) &
                    config%node_positions(3, id(i, j)) = 0.0_wp
            end do
        end do
        allocate(config%materials(2))
        config%materials(1)%name = 'warp'
        config%materials(1)%law = 'linear'
        config%materials(1)%stiffness = 10.0_wp
        config%materials(2)%name = 'weft'
        config%materials(2)%law = 'linear'
        config%materials(2)%stiffness = 5.0_wp
        allocate(config%yarns(2 * side))
        y = 0
        do j = 1, side
            y = y + 1
            config%yarns(y)%material = 'warp'
            config%yarns(y)%nodes = id(0:side + 1, j)
            config%yarns(y)%elements_per_segment = per_segment
        end do
        do i = 1, side
            y = y + 1
            config%yarns(y)%material = 'weft'
            config%yarns(y)%nodes = id(i, 0:side + 1)
            config%yarns(y)%elements_per_segment = per_segment
        end do
        allocate(config%supports(5))
        config%supports(1)%name = 'west'
        config%supports(1)%nodes = id(0, 1:side)
        config%supports(2)%name = 'east'
        config%supports(2)%nodes = id(side + 1, 1:side)
        config%supports(2)%displacement = [0.2_wp * (side + 1), 0.0_wp, 0.0_wp]
        config%supports(3)%name = 'south'
        config%supports(3)%nodes = id(1:side, 0)
        config%supports(3)%fix = 'yz'
        config%supports(3)%displacement = [0.0_wp, -0.025_wp * (side + 1), 0.0_wp]
        config%supports(4)%name = 'north'
        config%supports(4)%nodes = id(1:side, side + 1)
        config%supports(4)%fix = 'yz'
        config%supports(4)%displacement = [0.0_wp, 0.025_wp * (side + 1), 0.0_wp]
        ! Shared crossing nodes cannot keep warp over weft by themselves (both yarns
        ! would pull a crossing flat); holding the crossings' height keeps the crimp.
        config%supports(5)%name = 'crimp'
        config%supports(5)%nodes = pack(id(1:side, 1:side), .true.)
        config%supports(5)%fix = 'z'
        allocate(config%loads(0))
        allocate(config%contacts(merge(1, 0, scheme /= "none")))
        if (size(config%contacts) > 0) then
        config%contacts(1)%materials = [character(len=64) :: "warp", "weft"]
        config%contacts(1)%law = 'adhesion'
        config%contacts(1)%friction_coefficient = 0.3_wp
        config%contacts(1)%adhesion = 0.01_wp
        end if
        ! Biaxial stretch (warp 20 %, weft 5 %), then unload to half and reload: the net
        ! stays taut while the friction cycle runs.
        config%path%time = [0.0_wp, 1.0_wp, 2.0_wp, 3.0_wp]
        config%path%p_force = [0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp]
        config%path%p_disp = [0.0_wp, 1.0_wp, 0.5_wp, 1.0_wp]
        config%solver%scheme = scheme
        config%solver%initial_step = 0.05_wp
        config%solver%max_step = 0.05_wp
        config%solver%max_iterations = 100
        config%solver%max_friction_iterations = 1000
    end subroutine make_woven_net

end module bench_woven_net
