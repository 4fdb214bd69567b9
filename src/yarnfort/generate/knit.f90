! SPDX-License-Identifier: MIT
!> Weft-knitted single jersey with an optional elastic inlay yarn (paper Fig. 5), as a
!> planar string network with point contacts.
!>
!> Between contacts a string under tension is straight, so the generator places nodes
!> only where yarns touch. Course j is one yarn along x; in wale i (x from i*w to
!> (i+1)*w) its loop runs
!>     foot A(i,j-1) -> top A(i,j) -> top B(i,j) -> foot B(i,j-1) -> sinker -> A(i+1,j-1)
!> where A(i,j) = (i*w + (1-h)*w/2, (j+1)*c) and B(i,j) = (i*w + (1+h)*w/2, (j+1)*c),
!> h = head_width. A(i,j) and B(i,j) are contacts: the head of loop (i,j) wraps there
!> around the legs of loop (i,j+1), which start at them. Both courses' yarns bend by
!> 90 degrees there, so both have capstan friction. A loop is 2*c + w long.
!> An inlay yarn in course j runs along x at inlay_offset*c above the course line,
!> alternately in front of the left legs and behind the right legs of the loops. At
!> each crossing the leg and the inlay have a node of their own, `gap` apart in z and
!> joined by a gap-holder (as in the woven fabric), so both bend there and both feel
!> capstan friction; the holder carries the force between them.
!>
!> Boundaries: a periodic cell has its x edges at the middle of the sinkers (symmetry
!> planes of the loops, where no yarn slides through) and its y edges at the feet of
!> course 0, which are periodic images of the top course's contacts. A clamped sample
!> holds the yarn ends at x = 0 and pulls those at the right edge.
module yarnfort_generate_knit
    use yarnfort_kinds, only: wp
    use yarnfort_input_config, only: fabric_config_type
    use yarnfort_generate_net_builder, only: net_builder_type
    implicit none
    private

    public :: generate_knit

contains

    !> Fill `net`; also returns the width across which the x force is carried and the
    !> index of the support pulled along x (0 for a periodic cell).
    subroutine generate_knit(fabric, net, width, pulled)
        type(fabric_config_type), intent(in) :: fabric
        type(net_builder_type), intent(inout) :: net
        real(wp), intent(out) :: width
        integer, intent(out) :: pulled
        integer :: nw, nc, i, j, k
        real(wp) :: w, c, a, y_inlay, strain(3)
        integer, allocatable :: sinker(:, :), left(:, :), right(:, :)
        integer, allocatable :: leg_left(:, :), leg_right(:, :), inlay_left(:, :)
        integer, allocatable :: inlay_right(:, :), inlay_end(:, :)
        integer, allocatable :: course(:), inlay(:)
        real(wp) :: half_gap
        logical :: periodic, has_inlay
        logical, allocatable :: inlaid(:)

        nw = fabric%cells(1)
        nc = fabric%cells(2)
        w = fabric%spacing(1)
        c = fabric%spacing(2)
        a = 0.5_wp * (1.0_wp - fabric%head_width) * w
        periodic = fabric%boundary == 'periodic'
        has_inlay = len_trim(fabric%inlay_material) > 0
        strain = [fabric%strain, fabric%lateral_strain, 0.0_wp]

        allocate(inlaid(0:nc - 1))
        inlaid = .false.
        if (has_inlay) then
            do j = 0, nc - 1
                inlaid(j) = mod(j, fabric%inlay_every) == 0
            end do
        end if

        ! sinker(i, j): middle of the sinker before wale i of course j (yarn ends at i = 0
        ! and i = nw; inner ones only where an inlay crosses).
        allocate(sinker(0:nw, 0:nc - 1), source=0)
        allocate(left(0:nw - 1, -1:nc - 1), right(0:nw - 1, -1:nc - 1))
        allocate(leg_left(0:nw - 1, 0:nc - 1), leg_right(0:nw - 1, 0:nc - 1), source=0)
        allocate(inlay_left(0:nw - 1, 0:nc - 1), inlay_right(0:nw - 1, 0:nc - 1), source=0)
        allocate(inlay_end(2, 0:nc - 1), source=0)
        half_gap = 0.5_wp * max(fabric%gap, 0.0_wp)
        do j = -1, nc - 1
            do i = 0, nw - 1
                left(i, j) = net%add_node([i * w + a, (j + 1) * c, 0.0_wp])
                right(i, j) = net%add_node([(i + 1) * w - a, (j + 1) * c, 0.0_wp])
            end do
        end do
        do j = 0, nc - 1
            sinker(0, j) = net%add_node([0.0_wp, j * c, 0.0_wp])
            sinker(nw, j) = net%add_node([nw * w, j * c, 0.0_wp])
            if (.not. inlaid(j)) cycle
            y_inlay = (j + fabric%inlay_offset) * c
            do i = 0, nw - 1
                leg_left(i, j) = net%add_node([i * w + a, y_inlay, -half_gap])
                inlay_left(i, j) = net%add_node([i * w + a, y_inlay, half_gap])
                call net%add_link(inlay_left(i, j), leg_left(i, j), [0.0_wp, 0.0_wp, 0.0_wp], &
                    .true.)
                leg_right(i, j) = net%add_node([(i + 1) * w - a, y_inlay, half_gap])
                inlay_right(i, j) = net%add_node([(i + 1) * w - a, y_inlay, -half_gap])
                call net%add_link(inlay_right(i, j), leg_right(i, j), &
                    [0.0_wp, 0.0_wp, 0.0_wp], .true.)
            end do
            ! Inlay ends half way between a right and a left crossing (z = 0).
            inlay_end(1, j) = net%add_node([0.0_wp, y_inlay, 0.0_wp])
            inlay_end(2, j) = net%add_node([nw * w, y_inlay, 0.0_wp])
        end do

        do j = 0, nc - 1
            allocate(course(0))
            do i = 0, nw - 1
                if (i == 0) course = [course, sinker(i, j)]
                course = [course, left(i, j - 1)]
                if (inlaid(j)) course = [course, leg_left(i, j)]
                course = [course, left(i, j), right(i, j)]
                if (inlaid(j)) course = [course, leg_right(i, j)]
                course = [course, right(i, j - 1)]
            end do
            course = [course, sinker(nw, j)]
            call net%add_yarn(fabric%knit_material, course, fabric%elements_per_segment)
            deallocate(course)
            if (.not. inlaid(j)) cycle
            allocate(inlay(0))
            inlay = [inlay_end(1, j)]
            do i = 0, nw - 1
                inlay = [inlay, inlay_left(i, j), inlay_right(i, j)]
            end do
            inlay = [inlay, inlay_end(2, j)]
            call net%add_yarn(fabric%inlay_material, inlay, fabric%elements_per_segment)
            deallocate(inlay)
        end do

        width = nc * c
        pulled = 0
        if (periodic) then
            do j = 0, nc - 1
                call net%add_link(sinker(nw, j), sinker(0, j), strain, .false.)
                if (inlaid(j)) call net%add_link(inlay_end(2, j), inlay_end(1, j), strain, &
                    .false.)
            end do
            do i = 0, nw - 1
                call net%add_link(left(i, -1), left(i, nc - 1), strain, .false.)
                call net%add_link(right(i, -1), right(i, nc - 1), strain, .false.)
            end do
            ! Rigid-body translation: hold one contact.
            call net%add_support('anchor', [left(0, 0)], 'xyz', [0.0_wp, 0.0_wp, 0.0_wp])
        else
            call net%add_support('left', [sinker(0, :), pack(inlay_end(1, :), inlaid)], 'xyz', &
                [0.0_wp, 0.0_wp, 0.0_wp])
            call net%add_support('right', [sinker(nw, :), pack(inlay_end(2, :), inlaid)], 'xyz', &
                [fabric%strain * nw * w, 0.0_wp, 0.0_wp])
            pulled = 2
            if (fabric%sides == 'rollers') then
                call net%add_support('sides', [left(:, -1), right(:, -1), left(:, nc - 1), &
                    right(:, nc - 1)], 'y', [0.0_wp, 0.0_wp, 0.0_wp])
            end if
        end if
    end subroutine generate_knit

end module yarnfort_generate_knit
