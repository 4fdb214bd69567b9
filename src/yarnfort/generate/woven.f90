! SPDX-License-Identifier: MIT
!> Woven fabric (plain weave or 2/2 twill) with gap-holders (paper Figs. 9-12).
!>
!> Warp yarns run along x (the loaded direction), weft yarns along y. Crossing (i, j)
!> of weft i and warp j lies at ((i+1/2)*sx, (j+1/2)*sy). There the warp has its own
!> node at z = +gap/2 when it lies over the weft (-gap/2 under), and the weft a node
!> at the mirrored height. A gap-holder (Fig. 12) keeps the weft node at the fixed
!> offset (0, 0, -/+gap) * factor(p_disp) from the warp node: the pair moves as one
!> rigid body without rotating, so each yarn keeps its own bend angle (and capstan
!> friction) at its own node while the two act on each other through the holder.
!> Warp over weft where plain: i + j even; twill: mod(i + j, 4) < 2.
!>
!> Yarn ends lie half way between crossings. A periodic cell pairs the ends at x = 0
!> with those at x = nx*sx (and the weft ends along y): points of symmetry of the weave,
!> where no yarn slides through. A clamped sample holds the warp ends at x = 0 and
!> pulls those at the right edge; its weft ends are free or held in y and z ('rollers',
!> which stands for a selvedge that keeps the weft from pulling out and from folding).
module yarnfort_generate_woven
    use yarnfort_kinds, only: wp
    use yarnfort_input_config, only: fabric_config_type
    use yarnfort_generate_net_builder, only: net_builder_type
    implicit none
    private

    public :: generate_woven, warp_over

contains

    !> Whether warp j lies over weft i at their crossing.
    pure logical function warp_over(kind, i, j)
        character(len=*), intent(in) :: kind
        integer, intent(in) :: i, j
        if (kind == 'twill') then
            warp_over = mod(i + j, 4) < 2
        else
            warp_over = mod(i + j, 2) == 0
        end if
    end function warp_over

    subroutine generate_woven(fabric, net, width, pulled)
        type(fabric_config_type), intent(in) :: fabric
        type(net_builder_type), intent(inout) :: net
        real(wp), intent(out) :: width
        integer, intent(out) :: pulled
        integer :: nx, ny, i, j
        real(wp) :: sx, sy, half_gap, z, strain(3)
        real(wp), allocatable :: side(:, :)
        integer, allocatable :: warp_node(:, :), weft_node(:, :), ends(:, :), weft_ends(:, :)
        integer, allocatable :: yarn(:)
        logical :: periodic

        nx = fabric%cells(1)
        ny = fabric%cells(2)
        sx = fabric%spacing(1)
        sy = fabric%spacing(2)
        half_gap = 0.5_wp * fabric%gap
        periodic = fabric%boundary == 'periodic'
        strain = [fabric%strain, fabric%lateral_strain, 0.0_wp]

        ! side(i, j) = +1 where the warp lies over the weft.
        allocate(side(0:nx - 1, 0:ny - 1))
        do j = 0, ny - 1
            do i = 0, nx - 1
                side(i, j) = merge(1.0_wp, -1.0_wp, warp_over(fabric%kind, i, j))
            end do
        end do
        allocate(warp_node(0:nx - 1, 0:ny - 1), weft_node(0:nx - 1, 0:ny - 1))
        do j = 0, ny - 1
            do i = 0, nx - 1
                warp_node(i, j) = net%add_node([(i + 0.5_wp) * sx, (j + 0.5_wp) * sy, &
                    side(i, j) * half_gap])
                weft_node(i, j) = net%add_node([(i + 0.5_wp) * sx, (j + 0.5_wp) * sy, &
                    -side(i, j) * half_gap])
                call net%add_link(weft_node(i, j), warp_node(i, j), [0.0_wp, 0.0_wp, 0.0_wp], &
                    .true.)
            end do
        end do
        ! Yarn ends half way between the first and the last crossing (as seen periodically).
        allocate(ends(2, 0:ny - 1), weft_ends(2, 0:nx - 1))
        do j = 0, ny - 1
            z = 0.5_wp * (side(0, j) + side(nx - 1, j)) * half_gap
            ends(1, j) = net%add_node([0.0_wp, (j + 0.5_wp) * sy, z])
            ends(2, j) = net%add_node([nx * sx, (j + 0.5_wp) * sy, z])
            yarn = [ends(1, j), warp_node(:, j), ends(2, j)]
            call net%add_yarn(fabric%warp_material, yarn, fabric%elements_per_segment)
        end do
        do i = 0, nx - 1
            z = -0.5_wp * (side(i, 0) + side(i, ny - 1)) * half_gap
            weft_ends(1, i) = net%add_node([(i + 0.5_wp) * sx, 0.0_wp, z])
            weft_ends(2, i) = net%add_node([(i + 0.5_wp) * sx, ny * sy, z])
            yarn = [weft_ends(1, i), weft_node(i, :), weft_ends(2, i)]
            call net%add_yarn(fabric%weft_material, yarn, fabric%elements_per_segment)
        end do

        width = ny * sy
        pulled = 0
        if (periodic) then
            do j = 0, ny - 1
                call net%add_link(ends(2, j), ends(1, j), strain, .false.)
            end do
            do i = 0, nx - 1
                call net%add_link(weft_ends(2, i), weft_ends(1, i), strain, .false.)
            end do
            call net%add_support('anchor', [warp_node(0, 0)], 'xyz', [0.0_wp, 0.0_wp, 0.0_wp])
        else
            call net%add_support('left', ends(1, :), 'xyz', [0.0_wp, 0.0_wp, 0.0_wp])
            call net%add_support('right', ends(2, :), 'xyz', &
                [fabric%strain * nx * sx, 0.0_wp, 0.0_wp])
            pulled = 2
            if (fabric%sides == 'rollers') then
                call net%add_support('sides', [weft_ends(1, :), weft_ends(2, :)], 'yz', &
                    [0.0_wp, 0.0_wp, 0.0_wp])
            end if
        end if
    end subroutine generate_woven

end module yarnfort_generate_woven
