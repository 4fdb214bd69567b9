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
!> holds the yarn ends at x = 0 and pulls those at the right edge. Its first course's
!> feet and last course's heads touch one yarn only; rollers hold them in y, or (free
!> sides) a cast-on and a bind-off thread sewn to them close the edges (add_edge_threads).
!>
!> Three-dimensional knit (knit_depth = d > 0): the same loops, interlaced in depth. Each
!> course's feet and sinkers lie at z = +d/2 (in front), its heads at z = -d/2 (behind),
!> and its legs slope between them, so a loop's legs pass in front of the head of the loop
!> below where they are drawn through it. A loop contact is no longer a shared node: the
!> head of loop (i,j) has its node at (x, (j+1)*c, -d/2), the foot of loop (i,j+1) its
!> own at (x, (j+1)*c, +d/2), and a gap-holder of length d joins them (as at the inlay
!> crossings). A leg is sqrt(c**2 + d**2) long, a loop 2*sqrt(c**2 + d**2) + w. The legs
!> lie in planes x = const and the heads and sinkers along x, so the wrap angle at every
!> loop contact is pi/2 on both yarns, as in the planar knit; the contact force has a
!> component in depth, which the gap-holder carries. An inlay crosses the legs at their
!> depth there, d/2 - inlay_offset*d, with the inlay's gap about it.
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
        integer :: nw, nc, i, j
        real(wp) :: w, c, a, y_inlay, strain(3)
        integer, allocatable :: sinker(:, :), left(:, :), right(:, :)
        integer, allocatable :: leg_left(:, :), leg_right(:, :), inlay_left(:, :)
        integer, allocatable :: inlay_right(:, :), inlay_end(:, :)
        real(wp) :: half_gap
        logical :: periodic
        logical, allocatable :: inlaid(:)

        if (fabric%knit_depth > 0.0_wp) then
            call generate_knit_3d(fabric, net, width, pulled)
            return
        end if
        nw = fabric%cells(1)
        nc = fabric%cells(2)
        w = fabric%spacing(1)
        c = fabric%spacing(2)
        a = 0.5_wp * (1.0_wp - fabric%head_width) * w
        periodic = fabric%boundary == 'periodic'
        strain = [fabric%strain, fabric%lateral_strain, 0.0_wp]
        call get_inlaid_courses(fabric, inlaid)

        ! sinker(i, j): middle of the sinker before wale i of course j (yarn ends at i = 0
        ! and i = nw; inner ones only where an inlay crosses).
        allocate(sinker(0:nw, 0:nc - 1), source=0)
        allocate(left(0:nw - 1, -1:nc - 1), right(0:nw - 1, -1:nc - 1))
        allocate(leg_left(0:nw - 1, 0:nc - 1), leg_right(0:nw - 1, 0:nc - 1), source=0)
        allocate(inlay_left(0:nw - 1, 0:nc - 1), inlay_right(0:nw - 1, 0:nc - 1), source=0)
        allocate(inlay_end(2, 0:nc - 1), source=0)
        half_gap = 0.0_wp
        if (allocated(fabric%gap)) half_gap = 0.5_wp * max(fabric%gap, 0.0_wp)
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
                call add_crossing(net, [i * w + a, y_inlay, 0.0_wp], half_gap, leg_left(i, j), &
                    inlay_left(i, j))
                call add_crossing(net, [(i + 1) * w - a, y_inlay, 0.0_wp], -half_gap, &
                    leg_right(i, j), inlay_right(i, j))
            end do
            ! Inlay ends half way between a right and a left crossing (z = 0).
            inlay_end(1, j) = net%add_node([0.0_wp, y_inlay, 0.0_wp])
            inlay_end(2, j) = net%add_node([nw * w, y_inlay, 0.0_wp])
        end do

        do j = 0, nc - 1
            call add_course(fabric, net, [sinker(0, j), sinker(nw, j)], left(:, j - 1), &
                right(:, j - 1), left(:, j), right(:, j), leg_left(:, j), leg_right(:, j), &
                inlaid(j))
            if (inlaid(j)) call add_inlay(fabric, net, inlay_end(:, j), inlay_left(:, j), &
                inlay_right(:, j))
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
            call clamp_knit(fabric, net, [sinker(0, :), pack(inlay_end(1, :), inlaid)], &
                [sinker(nw, :), pack(inlay_end(2, :), inlaid)], reshape([left(:, -1), &
                right(:, -1)], [nw, 2]), reshape([left(:, nc - 1), right(:, nc - 1)], [nw, 2]))
            pulled = 2
        end if
    end subroutine generate_knit

    !> The courses (0-based) that hold an inlay: every inlay_every-th from course 0, when
    !> the knit has an inlay_material.
    subroutine get_inlaid_courses(fabric, inlaid)
        type(fabric_config_type), intent(in) :: fabric
        logical, allocatable, intent(out) :: inlaid(:)
        integer :: j

        allocate(inlaid(0:fabric%cells(2) - 1), source=.false.)
        if (len_trim(fabric%inlay_material) == 0) return
        do j = 0, fabric%cells(2) - 1
            inlaid(j) = mod(j, fabric%inlay_every) == 0
        end do
    end subroutine get_inlaid_courses

    !> An inlay crossing a leg at `x`: a node of each yarn, the inlay's `offset` in z from
    !> x and the leg's at -offset, joined by a gap-holder.
    subroutine add_crossing(net, x, offset, leg, inlay)
        type(net_builder_type), intent(inout) :: net
        real(wp), intent(in) :: x(3), offset
        integer, intent(out) :: leg, inlay

        leg = net%add_node([x(1), x(2), x(3) - offset])
        inlay = net%add_node([x(1), x(2), x(3) + offset])
        call net%add_link(inlay, leg, [0.0_wp, 0.0_wp, 0.0_wp], .true.)
    end subroutine add_crossing

    !> The yarn of a course, from `ends(1)` to `ends(2)` through each loop i: its left foot,
    !> its left leg's crossing with the inlay (`inlaid`), its two heads, its right leg's
    !> crossing and its right foot.
    subroutine add_course(fabric, net, ends, foot_left, foot_right, head_left, head_right, &
            leg_left, leg_right, inlaid)
        type(fabric_config_type), intent(in) :: fabric
        type(net_builder_type), intent(inout) :: net
        integer, intent(in) :: ends(2), foot_left(:), foot_right(:), head_left(:)
        integer, intent(in) :: head_right(:), leg_left(:), leg_right(:)
        logical, intent(in) :: inlaid
        integer :: i

        if (inlaid) then
            call net%add_yarn(fabric%knit_material, [ends(1), (foot_left(i), leg_left(i), &
                head_left(i), head_right(i), leg_right(i), foot_right(i), &
                i = 1, size(foot_left)), ends(2)], fabric%elements_per_segment)
        else
            call net%add_yarn(fabric%knit_material, [ends(1), (foot_left(i), head_left(i), &
                head_right(i), foot_right(i), i = 1, size(foot_left)), ends(2)], &
                fabric%elements_per_segment)
        end if
    end subroutine add_course

    !> The inlay yarn of a course, from `ends(1)` through its crossings of the loops'
    !> left and right legs to `ends(2)`.
    subroutine add_inlay(fabric, net, ends, left, right)
        type(fabric_config_type), intent(in) :: fabric
        type(net_builder_type), intent(inout) :: net
        integer, intent(in) :: ends(2), left(:), right(:)
        integer :: i

        call net%add_yarn(fabric%inlay_material, [ends(1), (left(i), right(i), &
            i = 1, size(left)), ends(2)], fabric%elements_per_segment)
    end subroutine add_inlay

    !> A clamped knit: the course (and inlay) ends `left` held, those at the right edge
    !> (`right`) pulled along x; the first course's feet and the last course's heads
    !> (`feet(i, 1:2)`, `heads(i, 1:2)`: left and right of loop i) on rollers in y or, with
    !> free sides, closed by edge threads.
    subroutine clamp_knit(fabric, net, left, right, feet, heads)
        type(fabric_config_type), intent(in) :: fabric
        type(net_builder_type), intent(inout) :: net
        integer, intent(in) :: left(:), right(:), feet(:, :), heads(:, :)

        call net%add_support('left', left, 'xyz', [0.0_wp, 0.0_wp, 0.0_wp])
        call net%add_support('right', right, 'xyz', &
            [fabric%strain * size(feet, 1) * fabric%spacing(1), 0.0_wp, 0.0_wp])
        if (fabric%sides == 'rollers') then
            call net%add_support('sides', [feet, heads], 'y', [0.0_wp, 0.0_wp, 0.0_wp])
        else
            call add_edge_threads(fabric, net, feet, heads)
        end if
    end subroutine clamp_knit

    !> Free sides of a clamped knit: a cast-on thread through the feet of the first
    !> course (`feet(i, 1:2)`: left and right foot of loop i) and a bind-off thread
    !> through the heads of the last course (`heads`), each straight along its course
    !> line, its ends held by the clamps (sets `edge_left`, `edge_right`, not `left`,
    !> `right`: their force is not the fabric's). The threads are sewn to the loops:
    !> each has its own node at every foot or head, bonded to it (a gap-holder of
    !> length 0 that makes no passage), so neither yarn slides there, as before.
    subroutine add_edge_threads(fabric, net, feet, heads)
        type(fabric_config_type), intent(in) :: fabric
        type(net_builder_type), intent(inout) :: net
        integer, intent(in) :: feet(:, :), heads(:, :)
        integer :: ends(2, 2), nw, i, j, k, loop_node
        integer, allocatable :: thread(:)
        real(wp) :: length, first(3)
        character(len=:), allocatable :: material

        nw = size(feet, 1)
        length = nw * fabric%spacing(1)
        material = trim(fabric%edge_material)
        if (len(material) == 0) material = trim(fabric%knit_material)
        do k = 1, 2
            if (k == 1) then
                first = net%position(:, feet(1, 1))
            else
                first = net%position(:, heads(1, 1))
            end if
            ends(1, k) = net%add_node([0.0_wp, first(2), first(3)])
            ends(2, k) = net%add_node([length, first(2), first(3)])
            thread = [ends(1, k)]
            do i = 1, nw
                do j = 1, 2
                    if (k == 1) then
                        loop_node = feet(i, j)
                    else
                        loop_node = heads(i, j)
                    end if
                    thread = [thread, net%add_node(net%position(:, loop_node))]
                    call net%add_link(thread(size(thread)), loop_node, [0.0_wp, 0.0_wp, &
                        0.0_wp], .true., bonded=.true.)
                end do
            end do
            thread = [thread, ends(2, k)]
            call net%add_yarn(material, thread, fabric%elements_per_segment)
        end do
        call net%add_support('edge_left', ends(1, :), 'xyz', [0.0_wp, 0.0_wp, 0.0_wp])
        call net%add_support('edge_right', ends(2, :), 'xyz', &
            [fabric%strain * length, 0.0_wp, 0.0_wp])
    end subroutine add_edge_threads

    !> The three-dimensional knit (knit_depth > 0; see the module text): nodes of its own
    !> for the head and the feet at every loop contact, joined by gap-holders.
    subroutine generate_knit_3d(fabric, net, width, pulled)
        type(fabric_config_type), intent(in) :: fabric
        type(net_builder_type), intent(inout) :: net
        real(wp), intent(out) :: width
        integer, intent(out) :: pulled
        integer :: nw, nc, i, j
        real(wp) :: w, c, a, d, y_inlay, z_leg, half_gap, strain(3)
        integer, allocatable :: foot_left(:, :), foot_right(:, :), head_left(:, :)
        integer, allocatable :: head_right(:, :), sinker(:, :), leg_left(:, :), leg_right(:, :)
        integer, allocatable :: inlay_left(:, :), inlay_right(:, :), inlay_end(:, :)
        logical :: periodic
        logical, allocatable :: inlaid(:)

        nw = fabric%cells(1)
        nc = fabric%cells(2)
        w = fabric%spacing(1)
        c = fabric%spacing(2)
        a = 0.5_wp * (1.0_wp - fabric%head_width) * w
        d = fabric%knit_depth
        periodic = fabric%boundary == 'periodic'
        strain = [fabric%strain, fabric%lateral_strain, 0.0_wp]
        half_gap = 0.0_wp
        if (allocated(fabric%gap)) half_gap = 0.5_wp * max(fabric%gap, 0.0_wp)
        call get_inlaid_courses(fabric, inlaid)
        allocate(foot_left(0:nw - 1, 0:nc - 1), foot_right(0:nw - 1, 0:nc - 1))
        allocate(head_left(0:nw - 1, 0:nc - 1), head_right(0:nw - 1, 0:nc - 1))
        allocate(leg_left(0:nw - 1, 0:nc - 1), leg_right(0:nw - 1, 0:nc - 1), source=0)
        allocate(inlay_left(0:nw - 1, 0:nc - 1), inlay_right(0:nw - 1, 0:nc - 1), source=0)
        allocate(sinker(2, 0:nc - 1), inlay_end(2, 0:nc - 1), source=0)
        ! The legs run from z = d/2 at the feet to -d/2 at the heads; an inlay at height
        ! inlay_offset*c above the course line crosses them at z_leg.
        z_leg = 0.5_wp * d - fabric%inlay_offset * d
        do j = 0, nc - 1
            sinker(1, j) = net%add_node([0.0_wp, j * c, 0.5_wp * d])
            sinker(2, j) = net%add_node([nw * w, j * c, 0.5_wp * d])
            y_inlay = (j + fabric%inlay_offset) * c
            do i = 0, nw - 1
                foot_left(i, j) = net%add_node([i * w + a, j * c, 0.5_wp * d])
                head_left(i, j) = net%add_node([i * w + a, (j + 1) * c, -0.5_wp * d])
                head_right(i, j) = net%add_node([(i + 1) * w - a, (j + 1) * c, -0.5_wp * d])
                foot_right(i, j) = net%add_node([(i + 1) * w - a, j * c, 0.5_wp * d])
                if (.not. inlaid(j)) cycle
                call add_crossing(net, [i * w + a, y_inlay, z_leg], half_gap, leg_left(i, j), &
                    inlay_left(i, j))
                call add_crossing(net, [(i + 1) * w - a, y_inlay, z_leg], -half_gap, &
                    leg_right(i, j), inlay_right(i, j))
            end do
            if (.not. inlaid(j)) cycle
            inlay_end(1, j) = net%add_node([0.0_wp, y_inlay, z_leg])
            inlay_end(2, j) = net%add_node([nw * w, y_inlay, z_leg])
        end do

        do j = 0, nc - 1
            call add_course(fabric, net, sinker(:, j), foot_left(:, j), foot_right(:, j), &
                head_left(:, j), head_right(:, j), leg_left(:, j), leg_right(:, j), inlaid(j))
            if (inlaid(j)) call add_inlay(fabric, net, inlay_end(:, j), inlay_left(:, j), &
                inlay_right(:, j))
        end do

        ! Loop contacts: the feet of course j + 1 follow the head of course j, d in front.
        do j = 0, nc - 2
            do i = 0, nw - 1
                call net%add_link(foot_left(i, j + 1), head_left(i, j), strain, .true.)
                call net%add_link(foot_right(i, j + 1), head_right(i, j), strain, .true.)
            end do
        end do

        width = nc * c
        pulled = 0
        if (periodic) then
            ! The heads of the top course wrap the feet of course 0's image one y period
            ! up: gap-holders across the lattice vector (0, nc*c, 0).
            do i = 0, nw - 1
                call net%add_link(head_left(i, nc - 1), foot_left(i, 0), strain, .true., &
                    [0.0_wp, nc * c, 0.0_wp])
                call net%add_link(head_right(i, nc - 1), foot_right(i, 0), strain, .true., &
                    [0.0_wp, nc * c, 0.0_wp])
            end do
            do j = 0, nc - 1
                call net%add_link(sinker(2, j), sinker(1, j), strain, .false.)
                if (inlaid(j)) call net%add_link(inlay_end(2, j), inlay_end(1, j), strain, &
                    .false.)
            end do
            call net%add_support('anchor', [foot_left(0, 0)], 'xyz', [0.0_wp, 0.0_wp, 0.0_wp])
        else
            call clamp_knit(fabric, net, [sinker(1, :), pack(inlay_end(1, :), inlaid)], &
                [sinker(2, :), pack(inlay_end(2, :), inlaid)], reshape([foot_left(:, 0), &
                foot_right(:, 0)], [nw, 2]), reshape([head_left(:, nc - 1), &
                head_right(:, nc - 1)], [nw, 2]))
            pulled = 2
        end if
    end subroutine generate_knit_3d

end module yarnfort_generate_knit
