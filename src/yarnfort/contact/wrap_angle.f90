! SPDX-License-Identifier: MIT
!> Tensions and wrap angle at a passage and their derivatives, for the friction
!> conditions. The wrap angle is alpha = pi - gamma, gamma the angle between the yarn's
!> two elements pointing away from the contact node (alpha = 0 for a straight yarn).
module yarnfort_contact_wrap_angle
    use yarnfort_kinds, only: wp
    implicit none
    private

    public :: get_wrap_angle

    real(wp), parameter :: pi = acos(-1.0_wp)

contains

    !> alpha at node x_node between neighbours x_before and x_after, and d alpha / d x
    !> for the three nodes, (3, 3) columns [before, node, after]. At a straight yarn
    !> alpha has a cone-shaped minimum (its gradient does not exist); the gradient
    !> returned uses sin(gamma) >= min_sine, a Jacobian-only approximation.
    pure subroutine get_wrap_angle(x_before, x_node, x_after, min_sine, angle, dangle)
        real(wp), intent(in) :: x_before(3), x_node(3), x_after(3), min_sine
        real(wp), intent(out) :: angle, dangle(3, 3)
        real(wp) :: c_a(3), c_b(3), l_a, l_b, cos_gamma, sine, dcos_a(3), dcos_b(3)

        c_a = x_before - x_node
        l_a = norm2(c_a)
        c_a = c_a / l_a
        c_b = x_after - x_node
        l_b = norm2(c_b)
        c_b = c_b / l_b
        cos_gamma = max(-1.0_wp, min(1.0_wp, dot_product(c_a, c_b)))
        ! sin(gamma) = |c_a x c_b| and atan2: acos(cos_gamma) would lose half the digits
        ! where the yarn is nearly straight or folded back (an error of ~1e-8 in alpha).
        sine = norm2([c_a(2) * c_b(3) - c_a(3) * c_b(2), c_a(3) * c_b(1) - c_a(1) * c_b(3), &
            c_a(1) * c_b(2) - c_a(2) * c_b(1)])
        angle = pi - atan2(sine, cos_gamma)
        sine = max(sine, min_sine)
        dcos_a = (c_b - cos_gamma * c_a) / l_a
        dcos_b = (c_a - cos_gamma * c_b) / l_b
        ! d alpha = d(cos gamma) / sin(gamma)
        dangle(:, 1) = dcos_a / sine
        dangle(:, 3) = dcos_b / sine
        dangle(:, 2) = -(dcos_a + dcos_b) / sine
    end subroutine get_wrap_angle

end module yarnfort_contact_wrap_angle
