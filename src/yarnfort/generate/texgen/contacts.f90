! SPDX-License-Identifier: MIT
!> Contacts of TexGen yarns, found on the sampled centre lines and refined on the
!> curves; neighbours side by side are not crossings; centre lines that meet refused.
!>
!> Contacts: the closest approaches between two yarns
!> (and between a yarn and the periodic images of all yarns), where the distance is at
!> most (1 + texgen_contact_tolerance) times the sum of the two half thicknesses, each
!> the radius of the elliptic section (Width x Height) in the direction of the other
!> yarn. Within one contact patch (both points within the sum of the two widths along
!> each yarn) only the closest pair is kept.
module yarnfort_generate_texgen_contacts
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_sort, only: sort_index
    use yarnfort_text, only: format_integer, format_short
    use yarnfort_generate_texgen_curves, only: texgen_yarn_type, lattice_tolerance, &
        parameter_of, arc_of, curve_point, half_thickness
    implicit none
    private

    public :: contact_type, find_contacts, check_meetings

    !> Yarns whose directions in the fabric plane differ by less than this (rad) run side
    !> by side (a woven crossing is pi/2; neighbours touching sideways, 0).
    real(wp), parameter :: side_by_side_angle = 10 * acos(-1.0_wp) / 180

    !> Centre lines closer at a contact than this fraction of the sum of the two half
    !> thicknesses meet there: no direction to press along, nor two places for nodes.
    real(wp), parameter :: meeting_tolerance = 1.0e-6_wp

    type :: contact_type
        integer :: yarn(2) = 0
        !> Arc length along each yarn's period, and the point there (yarn 2 unshifted).
        real(wp) :: s(2) = 0.0_wp, point(3, 2) = 0.0_wp
        !> Lattice shift of yarn 2's image.
        real(wp) :: shift(3) = 0.0_wp
        real(wp) :: distance = 0.0_wp
        !> Each curve's tangent there (per unit span parameter).
        real(wp) :: tangent(3, 2) = 0.0_wp
        integer :: node(2) = 0
    end type contact_type

contains

    !> Closest approaches within the contact distance, one per contact patch.
    subroutine find_contacts(yarns, cell, tolerance, contacts)
        type(texgen_yarn_type), intent(in) :: yarns(:)
        real(wp), intent(in) :: cell(2), tolerance
        type(contact_type), allocatable, intent(out) :: contacts(:)
        type(contact_type), allocatable :: candidates(:)
        type(contact_type) :: c
        integer :: a, b, i, j, ka, kb, n_candidates, k, order_k
        integer :: range_x(2), range_y(2)
        real(wp) :: shift(3), reach, pa(3), pb(3), ta, tb, d, ra, rb, u(3)
        real(wp) :: lo(3), hi(3)

        allocate(candidates(256))
        n_candidates = 0
        do a = 1, size(yarns)
            do b = a, size(yarns)
                reach = (1.0_wp + tolerance) * 0.5_wp * (max(yarns(a)%width, yarns(a)%height) &
                    + max(yarns(b)%width, yarns(b)%height))
                range_x = [floor((yarns(a)%lower(1) - yarns(b)%upper(1) - reach) / cell(1)), &
                    ceiling((yarns(a)%upper(1) - yarns(b)%lower(1) + reach) / cell(1))]
                range_y = [floor((yarns(a)%lower(2) - yarns(b)%upper(2) - reach) / cell(2)), &
                    ceiling((yarns(a)%upper(2) - yarns(b)%lower(2) + reach) / cell(2))]
                do j = range_y(1), range_y(2)
                    do i = range_x(1), range_x(2)
                        shift = [i * cell(1), j * cell(2), 0.0_wp]
                        ! A yarn and its own image: each pair once (the shift with i > 0,
                        ! or i = 0 and j > 0); the yarn itself (no shift) is not a contact.
                        if (a == b .and. (i < 0 .or. (i == 0 .and. j <= 0))) cycle
                        if (any(yarns(a)%lower - reach > yarns(b)%upper + shift) .or. &
                            any(yarns(a)%upper + reach < yarns(b)%lower + shift)) cycle
                        do ka = 1, size(yarns(a)%s) - 1
                            lo = min(yarns(a)%x(:, ka - 1), yarns(a)%x(:, ka)) - reach
                            hi = max(yarns(a)%x(:, ka - 1), yarns(a)%x(:, ka)) + reach
                            do kb = 1, size(yarns(b)%s) - 1
                                if (any(max(yarns(b)%x(:, kb - 1), yarns(b)%x(:, kb)) + shift &
                                    < lo) .or. any(min(yarns(b)%x(:, kb - 1), &
                                    yarns(b)%x(:, kb)) + shift > hi)) cycle
                                call closest_points(yarns(a)%x(:, ka - 1), yarns(a)%x(:, ka), &
                                    yarns(b)%x(:, kb - 1) + shift, yarns(b)%x(:, kb) + shift, &
                                    ta, tb)
                                pa = yarns(a)%x(:, ka - 1) + ta * (yarns(a)%x(:, ka) &
                                    - yarns(a)%x(:, ka - 1))
                                pb = yarns(b)%x(:, kb - 1) + tb * (yarns(b)%x(:, kb) &
                                    - yarns(b)%x(:, kb - 1)) + shift
                                d = norm2(pb - pa)
                                if (d > reach) cycle
                                u = 0.0_wp
                                if (d > 0.0_wp) u = (pb - pa) / d
                                ra = half_thickness(yarns(a), ka, u)
                                rb = half_thickness(yarns(b), kb, u)
                                if (d > (1.0_wp + tolerance) * (ra + rb)) cycle
                                if (a == b) then
                                    if (same_yarn_nearby(yarns(a), yarns(a)%s(ka - 1) &
                                        + ta * (yarns(a)%s(ka) - yarns(a)%s(ka - 1)), &
                                        yarns(b)%s(kb - 1) + tb * (yarns(b)%s(kb) &
                                        - yarns(b)%s(kb - 1)), shift)) cycle
                                end if
                                c%yarn = [a, b]
                                c%s = [yarns(a)%s(ka - 1) + ta * (yarns(a)%s(ka) &
                                    - yarns(a)%s(ka - 1)), yarns(b)%s(kb - 1) + tb &
                                    * (yarns(b)%s(kb) - yarns(b)%s(kb - 1))]
                                c%point(:, 1) = pa
                                c%point(:, 2) = pb - shift
                                c%shift = shift
                                c%distance = d
                                call append(c)
                            end do
                        end do
                    end do
                end do
            end do
        end do
        ! Keep the closest pair of each patch.
        contacts = pack(candidates(1:n_candidates), closest_of_patches(candidates(1: &
            n_candidates)))
        do k = 1, size(contacts)
            call refine_contact(yarns(contacts(k)%yarn(1)), yarns(contacts(k)%yarn(2)), &
                contacts(k))
        end do
        contacts = pack(contacts, .not. side_by_side(contacts))
    contains
        function closest_of_patches(list) result(kept)
            type(contact_type), intent(in) :: list(:)
            logical :: kept(size(list))
            integer :: order(size(list))
            order = sort_index(list%distance)
            kept = .false.
            do k = 1, size(list)
                order_k = order(k)
                kept(order_k) = .true.
                do i = 1, k - 1
                    if (.not. kept(order(i))) cycle
                    if (same_patch(list(order(i)), list(order_k))) then
                        kept(order_k) = .false.
                        exit
                    end if
                end do
            end do
        end function closest_of_patches

        subroutine append(item)
            type(contact_type), intent(in) :: item
            type(contact_type), allocatable :: grown(:)
            if (n_candidates == size(candidates)) then
                allocate(grown(2 * size(candidates)))
                grown(1:n_candidates) = candidates(1:n_candidates)
                call move_alloc(grown, candidates)
            end if
            n_candidates = n_candidates + 1
            candidates(n_candidates) = item
        end subroutine append

        !> Neighbours side by side: two different yarns whose directions in the fabric
        !> plane are parallel (within side_by_side_angle) and that touch sideways (the
        !> distance vector more in the plane than across it), as in a weave whose yarn
        !> widths equal the spacing. They touch along a line, and neither wraps the
        !> other; the string model's contacts are crossings (a rigid gap-holder and a
        !> capstan passage), which would weld such neighbours (decisions.md: "TexGen
        !> yarns side by side").
        elemental logical function side_by_side(p)
            type(contact_type), intent(in) :: p
            real(wp) :: cross, lengths, gap(3)
            side_by_side = .false.
            if (p%yarn(1) == p%yarn(2)) return
            cross = abs(p%tangent(1, 1) * p%tangent(2, 2) - p%tangent(2, 1) * p%tangent(1, 2))
            lengths = norm2(p%tangent(1:2, 1)) * norm2(p%tangent(1:2, 2))
            gap = p%point(:, 2) + p%shift - p%point(:, 1)
            side_by_side = lengths > 0.0_wp .and. cross <= sin(side_by_side_angle) * lengths &
                .and. abs(gap(3)) < norm2(gap(1:2))
        end function side_by_side

        !> Two candidates of one contact patch: the same yarns, and both points within
        !> the sum of the widths of the other's, up to a lattice translation (also with
        !> the two points swapped, for a yarn and its own image).
        logical function same_patch(p, q)
            type(contact_type), intent(in) :: p, q
            real(wp) :: patch
            same_patch = .false.
            if (any(p%yarn /= q%yarn)) return
            patch = yarns(p%yarn(1))%width + yarns(p%yarn(2))%width
            same_patch = close_pair(p%point(:, 1), p%point(:, 2) + p%shift, &
                q%point(:, 1), q%point(:, 2) + q%shift, patch)
            if (p%yarn(1) == p%yarn(2) .and. .not. same_patch) same_patch = &
                close_pair(p%point(:, 1), p%point(:, 2) + p%shift, q%point(:, 2), &
                q%point(:, 1) - q%shift, patch)
        end function same_patch


        logical function close_pair(a1, b1, a2, b2, patch)
            real(wp), intent(in) :: a1(3), b1(3), a2(3), b2(3), patch
            real(wp) :: translation(3)
            translation = [cell(1) * nint((a1(1) - a2(1)) / cell(1)), &
                cell(2) * nint((a1(2) - a2(2)) / cell(2)), 0.0_wp]
            close_pair = norm2(a1 - a2 - translation) < patch .and. &
                norm2(b1 - b2 - translation) < patch
        end function close_pair

        !> A yarn near itself along its length (its image one or more periods on, at a
        !> distance along the yarn below half a turn of a bend as tight as the yarn is
        !> thick): not a contact.
        logical function same_yarn_nearby(yarn, s1, s2, shift)
            type(texgen_yarn_type), intent(in) :: yarn
            real(wp), intent(in) :: s1, s2, shift(3)
            real(wp) :: periods, total
            same_yarn_nearby = .false.
            periods = dot_product(shift, yarn%period) / dot_product(yarn%period, yarn%period)
            if (norm2(shift - nint(periods) * yarn%period) > lattice_tolerance &
                * maxval(cell)) return
            total = yarn%s(size(yarn%s) - 1)
            same_yarn_nearby = abs(s2 + nint(periods) * total - s1) &
                < acos(-1.0_wp) * max(yarn%width, yarn%height)
        end function same_yarn_nearby
    end subroutine find_contacts

    !> Refused: a contact where the two centre lines meet (a yarn through another, or
    !> through itself): neither wraps the other there, and the gap-holder has no
    !> direction. `hint`: what to change in the textile's parameters, if known.
    subroutine check_meetings(yarns, contacts, hint, error)
        type(texgen_yarn_type), intent(in) :: yarns(:)
        type(contact_type), intent(in) :: contacts(:)
        character(len=*), intent(in) :: hint
        type(error_type), allocatable, intent(out) :: error
        integer :: k, side, node(2)
        real(wp) :: thickness
        character(len=:), allocatable :: who, what

        do k = 1, size(contacts)
            associate(p => contacts(k), a => yarns(contacts(k)%yarn(1)), &
                    b => yarns(contacts(k)%yarn(2)))
                thickness = 0.5_wp * (max(a%width, a%height) + max(b%width, b%height))
                if (p%distance > meeting_tolerance * thickness) cycle
                do side = 1, 2
                    associate(y => yarns(p%yarn(side)))
                        node(side) = modulo(nint(parameter_of(y, p%s(side))), &
                            size(y%node, 2) - 1)
                    end associate
                end do
                if (p%yarn(1) == p%yarn(2)) then
                    who = 'TexGen yarn ' // format_integer(p%yarn(1) - 1) // ' meets itself'
                    what = 'its centre line passes twice through one point'
                else
                    who = 'TexGen yarns ' // format_integer(p%yarn(1) - 1) // ' and ' &
                        // format_integer(p%yarn(2) - 1) // ' meet'
                    what = 'their centre lines pass through one point'
                end if
                call fatal_error(error, who // ' at (' // format_short(p%point(1, 1)) &
                    // ', ' // format_short(p%point(2, 1)) // ', ' &
                    // format_short(p%point(3, 1)) // ') (master nodes ' &
                    // format_integer(node(1)) // ' and ' // format_integer(node(2)) &
                    // '): ' // what // ', where neither pass wraps the other; the string ' &
                    // 'model needs them apart by the thickness of a contact' // hint)
                return
            end associate
        end do
    end subroutine check_meetings

    !> The closest points of the two curves themselves (not of their samples), from the
    !> candidate's sample points: Gauss-Newton on the distance vector, kept within one
    !> sample of the start. Arc lengths follow linearly between samples.
    subroutine refine_contact(a, b, contact)
        type(texgen_yarn_type), intent(in) :: a, b
        type(contact_type), intent(inout) :: contact
        !> Iterations: the distance is quadratic near its minimum; a few suffice.
        integer, parameter :: max_iterations = 20
        real(wp) :: u(2), u0(2), d(3), xa(3), xb(3), ta(3), tb(3), j(3, 2), m(2, 2), r(2)
        real(wp) :: step(2), determinant
        integer :: iteration, wraps(2)

        u0 = [parameter_of(a, contact%s(1)), parameter_of(b, contact%s(2))]
        u = u0
        do iteration = 1, max_iterations
            call curve_point(a, u(1), xa, ta)
            call curve_point(b, u(2), xb, tb)
            d = xb + contact%shift - xa
            j(:, 1) = -ta
            j(:, 2) = tb
            m = matmul(transpose(j), j)
            r = matmul(transpose(j), d)
            determinant = m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1)
            if (abs(determinant) <= epsilon(1.0_wp) * m(1, 1) * m(2, 2)) exit
            step = -[m(2, 2) * r(1) - m(1, 2) * r(2), m(1, 1) * r(2) - m(2, 1) * r(1)] &
                / determinant
            u = min(max(u + step, u0 - 1.0_wp / [a%samples, b%samples]), &
                u0 + 1.0_wp / [a%samples, b%samples])
            if (all(abs(step) <= 10 * epsilon(1.0_wp) * max(1.0_wp, abs(u)))) exit
        end do
        ! Back into the first period of each yarn; the image shift follows, so that the
        ! pair of points stays the same pair in space.
        wraps = floor(u / [size(a%node, 2) - 1, size(b%node, 2) - 1])
        u = u - wraps * [size(a%node, 2) - 1, size(b%node, 2) - 1]
        contact%shift = contact%shift + wraps(2) * b%period - wraps(1) * a%period
        call curve_point(a, u(1), xa, ta)
        call curve_point(b, u(2), xb, tb)
        contact%point(:, 1) = xa
        contact%point(:, 2) = xb
        contact%tangent(:, 1) = ta
        contact%tangent(:, 2) = tb
        contact%distance = norm2(xb + contact%shift - xa)
        contact%s = [arc_of(a, u(1)), arc_of(b, u(2))]
    end subroutine refine_contact

    !> Parameters (in [0, 1]) of the closest points of segments p0-p1 and q0-q1.
    pure subroutine closest_points(p0, p1, q0, q1, s, t)
        real(wp), intent(in) :: p0(3), p1(3), q0(3), q1(3)
        real(wp), intent(out) :: s, t
        real(wp) :: d1(3), d2(3), r(3), a, e, f, c, b, denominator

        d1 = p1 - p0
        d2 = q1 - q0
        r = p0 - q0
        a = dot_product(d1, d1)
        e = dot_product(d2, d2)
        f = dot_product(d2, r)
        c = dot_product(d1, r)
        b = dot_product(d1, d2)
        denominator = a * e - b * b
        s = 0.0_wp
        if (denominator > epsilon(1.0_wp) * a * e) s = min(max((b * f - c * e) / denominator, &
            0.0_wp), 1.0_wp)
        t = (b * s + f) / e
        if (t < 0.0_wp) then
            t = 0.0_wp
            s = min(max(-c / a, 0.0_wp), 1.0_wp)
        else if (t > 1.0_wp) then
            t = 1.0_wp
            s = min(max((b - c) / a, 0.0_wp), 1.0_wp)
        end if
    end subroutine closest_points

end module yarnfort_generate_texgen_contacts
