! SPDX-License-Identifier: MIT
!> A clamped sample of copies of a TexGen cell.
module yarnfort_generate_texgen_tiling
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: fabric_config_type, link_config_type
    use yarnfort_generate_net_builder, only: net_builder_type
    use yarnfort_generate_texgen_curves, only: lattice_tolerance
    implicit none
    private

    public :: tile_sample

contains

    !> A clamped sample of fabric%cells(1) x fabric%cells(2) copies of the periodic cell
    !> `unit` (lattice `period`, m). Each yarn runs on through the copies along its own
    !> period as one yarn (it may slide across the cells' edges); its ends are the first
    !> and the last copy's. A gap-holder whose partner lies in a copy outside the sample
    !> is dropped with its two contact nodes (the yarns run straight past them). Yarns
    !> along x are held at their left end (`left`) and pulled at the right (`right`,
    !> strain * sample length); the others' ends are free or held in y and z ('rollers',
    !> set `sides`), as for the woven generator.
    subroutine tile_sample(fabric, unit, period, net, error)
        type(fabric_config_type), intent(in) :: fabric
        type(net_builder_type), intent(in) :: unit
        real(wp), intent(in) :: period(2)
        type(net_builder_type), intent(inout) :: net
        type(error_type), allocatable, intent(out) :: error
        integer :: nx, ny, a, b, k, y, n, step(2), shift(2), first, last
        integer, allocatable :: id(:, :, :), chain(:), left(:), right(:), sides(:)
        integer, allocatable :: moved(:, :)
        ! The gap-holders (links) and the copies between each one's follower and leader.
        integer, allocatable :: gaps(:), gap_copies(:, :)
        logical, allocatable :: orphan(:, :, :)
        real(wp) :: offset(3)
        character(len=200) :: buffer

        nx = fabric%cells(1)
        ny = fabric%cells(2)
        n = unit%n_nodes
        allocate(id(n, 0:nx - 1, 0:ny - 1), source=0)
        allocate(orphan(n, 0:nx - 1, 0:ny - 1), source=.false.)
        allocate(left(0), right(0), sides(0))
        call get_window_shifts(error)
        if (allocated(error)) return
        ! Gap-holders: the leader of the follower in copy (a, b) is in copy (a, b) + its
        ! lattice part; outside the sample both contact nodes go.
        allocate(gaps(0))
        do k = 1, unit%n_links
            if (unit%links(k)%gap) gaps = [gaps, k]
        end do
        allocate(gap_copies(2, size(gaps)))
        do k = 1, size(gaps)
            gap_copies(:, k) = lattice_part(unit%links(gaps(k)))
        end do
        do k = 1, size(gaps)
            associate(link => unit%links(gaps(k)), copies => gap_copies(:, k))
                do b = 0, ny - 1
                    do a = 0, nx - 1
                        if (.not. inside(a + copies(1), b + copies(2))) &
                            orphan(link%follower, a, b) = .true.
                        if (.not. inside(a - copies(1), b - copies(2))) &
                            orphan(link%leader, a, b) = .true.
                    end do
                end do
            end associate
        end do
        do y = 1, size(unit%yarns)
            associate(list => unit%yarns(y)%nodes)
                first = list(1)
                last = list(size(list))
                offset = unit%position(:, last) - unit%position(:, first)
                step = nint(offset(1:2) / period)
                if (any(abs(offset(1:2) - step * period) > lattice_tolerance &
                        * maxval(period)) .or. all(step == 0)) then
                    write(buffer, '("TexGen yarn ", i0, " does not end one lattice vector ", &
                        & "from its start: cannot tile it into a sample")') y - 1
                    call fatal_error(error, trim(buffer))
                    return
                end if
                ! One yarn per chain of copies along `step`, from each copy whose
                ! predecessor lies outside the sample.
                do b = 0, ny - 1
                    do a = 0, nx - 1
                        if (inside(a - step(1), b - step(2))) cycle
                        chain = [node_of(first, a, b)]
                        shift = [a, b]
                        do while (inside(shift(1), shift(2)))
                            do k = 2, size(list)
                                if (orphan(list(k), shift(1), shift(2))) cycle
                                chain = [chain, node_of(list(k), shift(1), shift(2))]
                            end do
                            shift = shift + step
                        end do
                        call net%add_yarn(unit%yarns(y)%material, chain, &
                            unit%yarns(y)%elements_per_segment)
                        if (step(1) /= 0) then
                            if (step(1) > 0) then
                                left = [left, chain(1)]
                                right = [right, chain(size(chain))]
                            else
                                left = [left, chain(size(chain))]
                                right = [right, chain(1)]
                            end if
                        else
                            sides = [sides, chain(1), chain(size(chain))]
                        end if
                    end do
                end do
            end associate
        end do
        do k = 1, size(gaps)
            associate(link => unit%links(gaps(k)), copies => gap_copies(:, k))
                do b = 0, ny - 1
                    do a = 0, nx - 1
                        if (orphan(link%follower, a, b)) cycle
                        call net%add_link(node_of(link%follower, a, b), node_of(link%leader, &
                            a + copies(1), b + copies(2)), [0.0_wp, 0.0_wp, 0.0_wp], .true.)
                    end do
                end do
            end associate
        end do
        call net%add_support('left', left, 'xyz', [0.0_wp, 0.0_wp, 0.0_wp])
        call net%add_support('right', right, 'xyz', &
            [fabric%strain * nx * period(1), 0.0_wp, 0.0_wp])
        if (fabric%sides == 'rollers' .and. size(sides) > 0) &
            call net%add_support('sides', sides, 'yz', [0.0_wp, 0.0_wp, 0.0_wp])
    contains
        logical function inside(i, j)
            integer, intent(in) :: i, j
            inside = i >= 0 .and. i < nx .and. j >= 0 .and. j < ny
        end function inside

        !> Node k of copy (i, j), made on first use.
        integer function node_of(k, i, j) result(found)
            integer, intent(in) :: k, i, j
            if (id(k, i, j) == 0) id(k, i, j) = net%add_node(unit%position(:, k) &
                + [(i - moved(1, k)) * period(1), (j - moved(2, k)) * period(2), 0.0_wp])
            found = id(k, i, j)
        end function node_of

        !> Copies between a gap-holder's follower and its leader, once both yarns are
        !> moved into the window.
        function lattice_part(link) result(copies)
            type(link_config_type), intent(in) :: link
            integer :: copies(2)
            copies = nint(link%period(1:2) / period) - moved(:, link%follower) &
                + moved(:, link%leader)
        end function lattice_part

        !> The sample's window starts where the yarns along x start (x) and where those
        !> along y start (y); every yarn of the cell is moved by whole periods so that
        !> its middle lies in the window's first cell (moved(:, node) for its nodes), so
        !> the sample's edges are the cell's yarn ends.
        subroutine get_window_shifts(error)
            type(error_type), allocatable, intent(out) :: error
            real(wp) :: origin(2), middle(3), span(3)
            integer :: yy, d
            origin = huge(1.0_wp)
            do yy = 1, size(unit%yarns)
                associate(list => unit%yarns(yy)%nodes)
                    span = unit%position(:, list(size(list))) - unit%position(:, list(1))
                    do d = 1, 2
                        if (abs(span(d)) > 0.5_wp * period(d)) origin(d) = min(origin(d), &
                            min(unit%position(d, list(1)), unit%position(d, list(size(list)))))
                    end do
                end associate
            end do
            do d = 1, 2
                if (origin(d) == huge(1.0_wp)) then
                    call fatal_error(error, 'no yarn runs along ' // merge('x', 'y', d == 1) &
                        // ' through the cell: cannot clamp a sample of it')
                    return
                end if
            end do
            allocate(moved(2, n), source=0)
            do yy = 1, size(unit%yarns)
                associate(list => unit%yarns(yy)%nodes)
                    middle = 0.5_wp * (unit%position(:, list(1)) &
                        + unit%position(:, list(size(list))))
                    do d = 1, 2
                        moved(d, list) = floor((middle(d) - origin(d)) / period(d) &
                            + lattice_tolerance)
                    end do
                end associate
            end do
        end subroutine get_window_shifts
    end subroutine tile_sample

end module yarnfort_generate_texgen_tiling
