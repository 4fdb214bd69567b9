! SPDX-License-Identifier: MIT
!> TexGen yarns as curves: the centre line through the master nodes, its samples,
!> and points, tangents and section radii on it.
!>
!> Centre lines become polylines of `texgen_samples` points per master-node span; the
!> centre line between master nodes is a Catmull-Rom cubic (tangents (P(i+1) - P(i-1))/2,
!> periodic at the ends), which can differ from TexGen's own curves between nodes by a
!> fraction of the yarn thickness.
module yarnfort_generate_texgen_curves
    use yarnfort_kinds, only: wp
    implicit none
    private

    public :: texgen_yarn_type, lattice_tolerance
    public :: sample_centre_line, point_at, parameter_of, arc_of
    public :: curve_point, half_thickness

    !> Relative tolerance of lattice checks (repeats, yarn periods), of the cell size.
    real(wp), parameter :: lattice_tolerance = 1.0e-6_wp

    type :: texgen_yarn_type
        !> Sampled centre line (3, 0:m), point m = point 0 + period; arc length at each.
        real(wp), allocatable :: x(:, :), s(:)
        !> Up vector of each sample segment (3, m).
        real(wp), allocatable :: up(:, :)
        real(wp) :: period(3) = 0.0_wp
        real(wp) :: width = 0.0_wp, height = 0.0_wp
        real(wp) :: lower(3) = 0.0_wp, upper(3) = 0.0_wp
        !> The curve itself: master nodes (3, n), each span's end tangents (3, n - 1, 2),
        !> samples per span; linear: straight spans.
        real(wp), allocatable :: node(:, :), tangent(:, :, :)
        integer :: samples = 1
        logical :: linear = .false.
    end type texgen_yarn_type

contains

    !> Points along the centre line through master nodes p(:, 1:n), p(n) = p(1) + period.
    !> A node's tangent has the direction of `given` where that is not zero (TexGen's
    !> ForceMasterNodeTangent), else of (p(i+1) - p(i-1)), and the length |p(i+1) - p(i-1)|/2.
    subroutine sample_centre_line(p, up, given, linear, samples, yarn)
        real(wp), intent(in) :: p(:, :), up(:, :), given(:, :)
        logical, intent(in) :: linear
        integer, intent(in) :: samples
        type(texgen_yarn_type), intent(inout) :: yarn
        integer :: n, i, k, m
        real(wp) :: t, h00, h10, h01, h11, m0(3), m1(3), before(3), after(3)
        real(wp), allocatable :: node_tangent(:, :)

        n = size(p, 2)
        yarn%period = p(:, n) - p(:, 1)
        m = (n - 1) * samples
        allocate(yarn%x(3, 0:m), yarn%s(0:m), yarn%up(3, m))
        yarn%node = p
        yarn%samples = samples
        yarn%linear = linear
        allocate(yarn%tangent(3, n - 1, 2), source=0.0_wp)
        allocate(node_tangent(3, n))
        do i = 1, n - 1
            if (i > 1) then
                before = p(:, i - 1)
            else
                before = p(:, n - 1) - yarn%period
            end if
            after = p(:, i + 1)
            node_tangent(:, i) = 0.5_wp * (after - before)
            if (norm2(given(:, i)) > 0.0_wp) node_tangent(:, i) = given(:, i) &
                / norm2(given(:, i)) * norm2(node_tangent(:, i))
        end do
        node_tangent(:, n) = node_tangent(:, 1)
        do i = 1, n - 1
            m0 = node_tangent(:, i)
            m1 = node_tangent(:, i + 1)
            if (linear) then
                m0 = p(:, i + 1) - p(:, i)
                m1 = m0
            end if
            yarn%tangent(:, i, 1) = m0
            yarn%tangent(:, i, 2) = m1
            do k = 0, samples - 1
                t = real(k, wp) / samples
                if (linear) then
                    yarn%x(:, (i - 1) * samples + k) = (1.0_wp - t) * p(:, i) + t * p(:, i + 1)
                else
                    h00 = 2 * t**3 - 3 * t**2 + 1
                    h10 = t**3 - 2 * t**2 + t
                    h01 = -2 * t**3 + 3 * t**2
                    h11 = t**3 - t**2
                    yarn%x(:, (i - 1) * samples + k) = h00 * p(:, i) + h10 * m0 &
                        + h01 * p(:, i + 1) + h11 * m1
                end if
                yarn%up(:, (i - 1) * samples + k + 1) = up(:, i)
            end do
        end do
        yarn%x(:, m) = yarn%x(:, 0) + yarn%period
        yarn%s(0) = 0.0_wp
        do k = 1, m
            yarn%s(k) = yarn%s(k - 1) + norm2(yarn%x(:, k) - yarn%x(:, k - 1))
        end do
        yarn%lower = minval(yarn%x, dim=2)
        yarn%upper = maxval(yarn%x, dim=2)
    end subroutine sample_centre_line

    !> Span parameter (0 at the first master node, 1 per span) of arc length s.
    pure real(wp) function parameter_of(yarn, s) result(u)
        type(texgen_yarn_type), intent(in) :: yarn
        real(wp), intent(in) :: s
        integer :: k
        do k = 1, size(yarn%s) - 1
            if (yarn%s(k) >= s) exit
        end do
        k = min(k, size(yarn%s) - 1)
        u = (k - 1 + (s - yarn%s(k - 1)) / (yarn%s(k) - yarn%s(k - 1))) / yarn%samples
    end function parameter_of

    pure real(wp) function arc_of(yarn, u) result(s)
        type(texgen_yarn_type), intent(in) :: yarn
        real(wp), intent(in) :: u
        integer :: k
        real(wp) :: t
        k = min(int(u * yarn%samples), size(yarn%s) - 2)
        t = u * yarn%samples - k
        s = yarn%s(k) + t * (yarn%s(k + 1) - yarn%s(k))
    end function arc_of

    !> Point and derivative (per unit span parameter) of the curve at span parameter u.
    pure subroutine curve_point(yarn, u, x, dx)
        type(texgen_yarn_type), intent(in) :: yarn
        real(wp), intent(in) :: u
        real(wp), intent(out) :: x(3), dx(3)
        real(wp) :: t, shift(3), v
        integer :: i, n_spans, wraps

        n_spans = size(yarn%node, 2) - 1
        wraps = floor(u / n_spans)
        v = u - wraps * n_spans
        shift = wraps * yarn%period
        i = min(int(v) + 1, n_spans)
        t = v - (i - 1)
        associate(p0 => yarn%node(:, i), p1 => yarn%node(:, i + 1), &
                m0 => yarn%tangent(:, i, 1), m1 => yarn%tangent(:, i, 2))
            if (yarn%linear) then
                x = p0 + t * (p1 - p0)
                dx = p1 - p0
            else
                x = (2 * t**3 - 3 * t**2 + 1) * p0 + (t**3 - 2 * t**2 + t) * m0 &
                    + (-2 * t**3 + 3 * t**2) * p1 + (t**3 - t**2) * m1
                dx = (6 * t**2 - 6 * t) * p0 + (3 * t**2 - 4 * t + 1) * m0 &
                    + (-6 * t**2 + 6 * t) * p1 + (3 * t**2 - 2 * t) * m1
            end if
        end associate
        x = x + shift
    end subroutine curve_point

    !> Radius of yarn y's elliptic section (Width x Height) at sample segment k in
    !> direction u (u = 0: the larger half axis).
    pure real(wp) function half_thickness(yarn, k, u) result(r)
        type(texgen_yarn_type), intent(in) :: yarn
        integer, intent(in) :: k
        real(wp), intent(in) :: u(3)
        real(wp) :: t(3), v(3), side(3), up(3), c1, c2

        t = yarn%x(:, k) - yarn%x(:, k - 1)
        t = t / norm2(t)
        v = u - dot_product(u, t) * t
        r = 0.5_wp * max(yarn%width, yarn%height)
        if (norm2(v) <= epsilon(1.0_wp)) return
        v = v / norm2(v)
        up = yarn%up(:, k) - dot_product(yarn%up(:, k), t) * t
        if (norm2(up) <= epsilon(1.0_wp)) return
        up = up / norm2(up)
        side = [t(2) * up(3) - t(3) * up(2), t(3) * up(1) - t(1) * up(3), &
            t(1) * up(2) - t(2) * up(1)]
        c1 = dot_product(v, side) / (0.5_wp * yarn%width)
        c2 = dot_product(v, up) / (0.5_wp * yarn%height)
        r = 1.0_wp / sqrt(c1**2 + c2**2)
    end function half_thickness

    !> The centre line's point at arc length s of the first period.
    pure function point_at(yarn, s) result(x)
        type(texgen_yarn_type), intent(in) :: yarn
        real(wp), intent(in) :: s
        real(wp) :: x(3), t
        integer :: k
        do k = 1, size(yarn%s) - 1
            if (yarn%s(k) >= s) exit
        end do
        k = min(k, size(yarn%s) - 1)
        t = (s - yarn%s(k - 1)) / (yarn%s(k) - yarn%s(k - 1))
        x = yarn%x(:, k - 1) + t * (yarn%x(:, k) - yarn%x(:, k - 1))
    end function point_at

end module yarnfort_generate_texgen_curves
