! SPDX-License-Identifier: MIT
!> The two-node truss element (paper eqs. 6-13): internal force and tangent block.
module yarnfort_assembly_truss
    use yarnfort_kinds, only: wp
    use yarnfort_material_law, only: force_law_type
    implicit none
    private

    public :: get_truss_tension, get_truss_response

contains

    !> Tension and stretch of an element, with the slack regularisation: for stretch <= 1
    !> the tension is slack_stiffness * k_ref * (stretch - 1) (a tiny compression
    !> stiffness, k_ref the law's reference stiffness) instead of exactly zero, which
    !> keeps a net of slack strings from having a singular tangent; slack_stiffness = 0
    !> gives the exact tension-only law.
    pure subroutine get_truss_tension(law, slack_stiffness, stretch, tension, dtension)
        class(force_law_type), intent(in) :: law
        real(wp), intent(in) :: slack_stiffness, stretch
        real(wp), intent(out) :: tension, dtension
        real(wp) :: k_slack

        if (stretch > 1.0_wp) then
            call law%get_force(stretch, tension, dtension)
        else
            k_slack = slack_stiffness * law%get_reference_stiffness()
            tension = k_slack * (stretch - 1.0_wp)
            dtension = k_slack
        end if
    end subroutine get_truss_tension

    !> Force on node 2 (node 1 gets its negative) and the 3x3 block Z of the element
    !> tangent K = [Z -Z; -Z Z] (eq. 12) for nodes at x1, x2 and reference length L0.
    !> The transverse (geometric) part of Z uses max(tension, slack_stiffness * k_ref)
    !> so a straight string at zero tension still has a small transverse stiffness: this
    !> changes only the Jacobian (Newton's path), never the residual or the solution.
    pure subroutine get_truss_response(law, slack_stiffness, length0, x1, x2, &
            tension, stretch, force, block)
        class(force_law_type), intent(in) :: law
        real(wp), intent(in) :: slack_stiffness, length0, x1(3), x2(3)
        real(wp), intent(out) :: tension, stretch, force(3)
        real(wp), intent(out), optional :: block(3, 3)
        real(wp) :: d(3), length, c(3), dtension, transverse
        integer :: k

        d = x2 - x1
        length = norm2(d)
        stretch = length / length0
        call get_truss_tension(law, slack_stiffness, stretch, tension, dtension)
        if (length > 0.0_wp) then
            c = d / length
        else
            c = 0.0_wp
        end if
        force = tension * c
        if (present(block)) then
            transverse = max(tension, slack_stiffness * law%get_reference_stiffness()) / length
            do k = 1, 3
                block(:, k) = (dtension / length0 - transverse) * c * c(k)
                block(k, k) = block(k, k) + transverse
            end do
        end if
    end subroutine get_truss_response

end module yarnfort_assembly_truss
