! SPDX-License-Identifier: MIT
!> The two-node truss element (paper eqs. 6-13): internal force and tangent block.
module yarnfort_assembly_truss
    use yarnfort_kinds, only: wp
    use yarnfort_material_law, only: force_law_type
    implicit none
    private

    public :: get_truss_tension, get_truss_response, slack_rest_stretch

    !> Rest stretch of the regularising spring (see get_truss_tension).
    real(wp), parameter :: slack_rest_stretch = 0.5_wp

contains

    !> Tension of an element at `stretch`, with the slack regularisation: the law's
    !> tension plus that of a weak spring of rest length L0/2, slack_stiffness * k_ref *
    !> (stretch - 1/2) (k_ref the law's reference stiffness). A string at its reference
    !> length then still carries slack_stiffness * k_ref / 2, so a slack or straight
    !> string keeps a small positive transverse stiffness and the tangent stays regular
    !> and exact (paper 2.6's x^4 degeneracy); an unloaded dangling end rests at half its
    !> reference length instead of being undetermined. The price is a relative change
    !> of order slack_stiffness / strain in taut strings. slack_stiffness = 0 gives the
    !> exact tension-only law.
    pure subroutine get_truss_tension(law, slack_stiffness, stretch, tension, dtension)
        class(force_law_type), intent(in) :: law
        real(wp), intent(in) :: slack_stiffness, stretch
        real(wp), intent(out) :: tension, dtension
        real(wp) :: k_slack

        if (stretch > 1.0_wp) then
            call law%get_force(stretch, tension, dtension)
        else
            tension = 0.0_wp
            dtension = 0.0_wp
        end if
        k_slack = slack_stiffness * law%get_reference_stiffness()
        tension = tension + k_slack * (stretch - slack_rest_stretch)
        dtension = dtension + k_slack
    end subroutine get_truss_tension

    !> Force on node 2 (node 1 gets its negative) and the 3x3 block Z of the element
    !> tangent K = [Z -Z; -Z Z] (eq. 12) for nodes at x1, x2 and reference length L0:
    !> Z = T/l (I - c c^T) + (dT/dlambda)/L0 c c^T, the exact derivative of the force.
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
            transverse = tension / length
            do k = 1, 3
                block(:, k) = (dtension / length0 - transverse) * c * c(k)
                block(k, k) = block(k, k) + transverse
            end do
        end if
    end subroutine get_truss_response

end module yarnfort_assembly_truss
