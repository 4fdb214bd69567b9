! SPDX-License-Identifier: MIT
!> The two-node truss element (paper eqs. 6-13): internal force and tangent block.
module yarnfort_assembly_truss
    use yarnfort_kinds, only: wp
    use yarnfort_material_force_law, only: force_law_type
    implicit none
    private

    public :: get_truss_tension, get_truss_response, get_tension_rounding, slack_rest_stretch
    public :: capped_stiffness, no_stiffness_cap

    !> The `stiffness_cap` of the exact laws (no law is scaled).
    real(wp), parameter :: no_stiffness_cap = huge(1.0_wp)

    !> Rest stretch of the regularising spring (see get_truss_tension).
    real(wp), parameter :: slack_rest_stretch = 0.5_wp
    !> Rounding of one element force, in units of eps * (|T| + r dT/dlambda) where
    !> r = (|x1| + |x2| + l) / L0: the tension is computed from lambda = l/L0, and l
    !> from coordinate differences that carry the rounding of the coordinates.
    real(wp), parameter :: rounding_factor = 8.0_wp

contains

    !> Tension of an element at `stretch` under the tension-only law (zero at or below
    !> stretch 1), plus, when `spring` > 0, that of a weak spring of rest length L0/2,
    !> spring * k_ref * (stretch - 1/2) (k_ref the law's reference stiffness). The spring
    !> is a regularisation of the Newton solve only (yarnfort_solver_newton): a solve
    !> that fails with the exact law is predicted with the spring and corrected without
    !> it, so no converged answer carries it. spring = 0 is the exact law.
    !> `stiffness_cap` (another predictor of the Newton solve, never of an answer): a law
    !> whose reference stiffness k_ref exceeds the cap is scaled by cap / k_ref, so that
    !> it and its spring act as a law of reference stiffness `cap`; absent or
    !> no_stiffness_cap: the law as it is.
    pure subroutine get_truss_tension(law, slack_stiffness, stretch, tension, dtension, &
            stiffness_cap)
        class(force_law_type), intent(in) :: law
        real(wp), intent(in) :: slack_stiffness, stretch
        real(wp), intent(out) :: tension, dtension
        real(wp), intent(in), optional :: stiffness_cap
        real(wp) :: k_slack, k_ref, k_capped

        k_ref = law%get_reference_stiffness()
        k_capped = k_ref
        if (present(stiffness_cap)) k_capped = min(k_ref, stiffness_cap)
        if (stretch > 1.0_wp) then
            call law%get_force(stretch, tension, dtension)
            if (k_capped < k_ref) then
                tension = tension * (k_capped / k_ref)
                dtension = dtension * (k_capped / k_ref)
            end if
        else
            tension = 0.0_wp
            dtension = 0.0_wp
        end if
        k_slack = slack_stiffness * k_capped
        tension = tension + k_slack * (stretch - slack_rest_stretch)
        dtension = dtension + k_slack
    end subroutine get_truss_tension

    !> Force on node 2 (node 1 gets its negative) and the 3x3 block Z of the element
    !> tangent K = [Z -Z; -Z Z] (eq. 12) for nodes at x1, x2 and reference length L0:
    !> Z = T/l (I - c c^T) + (dT/dlambda)/L0 c c^T, the exact derivative of the force.
    !> `tangent_spring` > 0 adds to the block of a slack string (stretch <= 1, whose
    !> exact block is zero) the block of the regularising spring at its reference
    !> length, k (I - c c^T) / (2 l) + k c c^T / L0 with k = tangent_spring * k_ref: the
    !> force is unchanged, so a Newton step keeps a regular matrix while the converged
    !> state is that of the exact law.
    !> `rounding`: the rounding error of the tension (get_tension_rounding).
    !> `dforce_dlength0`: the derivative of the force on node 2 with respect to L0,
    !> -c (dT/dlambda) lambda / L0 (a sliding flow changes L0).
    !> `known_length`: norm2(x2 - x1), `position_norm`: norm2(x1) + norm2(x2) (for
    !> `rounding`), where the caller has them (they are not computed again).
    !> `stiffness_cap` as for get_truss_tension.
    pure subroutine get_truss_response(law, spring, length0, x1, x2, &
            tension, stretch, force, block, tangent_spring, rounding, dforce_dlength0, &
            known_length, position_norm, stiffness_cap)
        class(force_law_type), intent(in) :: law
        real(wp), intent(in) :: spring, length0, x1(3), x2(3)
        real(wp), intent(out) :: tension, stretch, force(3)
        real(wp), intent(out), optional :: block(3, 3)
        real(wp), intent(in), optional :: tangent_spring
        real(wp), intent(out), optional :: rounding, dforce_dlength0(3)
        real(wp), intent(in), optional :: known_length, position_norm, stiffness_cap
        real(wp) :: d(3), length, c(3), dtension, transverse, axial, k_tangent
        integer :: k

        d = x2 - x1
        if (present(known_length)) then
            length = known_length
        else
            length = norm2(d)
        end if
        stretch = length / length0
        call get_truss_tension(law, spring, stretch, tension, dtension, stiffness_cap)
        if (present(rounding)) then
            if (present(position_norm)) then
                rounding = get_tension_rounding(law, position_norm, length, length0, tension, &
                    dtension)
            else
                rounding = get_tension_rounding(law, norm2(x1) + norm2(x2), length, length0, &
                    tension, dtension)
            end if
        end if
        if (length > 0.0_wp) then
            c = d / length
        else
            c = 0.0_wp
        end if
        force = tension * c
        if (present(dforce_dlength0)) dforce_dlength0 = -c * dtension * stretch / length0
        if (present(block)) then
            transverse = tension / length
            axial = dtension / length0
            if (present(tangent_spring)) then
                if (tangent_spring > 0.0_wp .and. stretch <= 1.0_wp) then
                    k_tangent = tangent_spring * capped_stiffness(law, stiffness_cap)
                    transverse = transverse + k_tangent * (1.0_wp - slack_rest_stretch) / length
                    axial = axial + k_tangent / length0
                end if
            end if
            do k = 1, 3
                block(:, k) = (axial - transverse) * c * c(k)
                block(k, k) = block(k, k) + transverse
            end do
        end if
    end subroutine get_truss_response

    !> Rounding error of the tension of an element with nodes at x1, x2 (length l,
    !> reference length L0; position_norm = |x1| + |x2|), computed as get_truss_tension
    !> gives tension and dtension:
    !> rounding_factor * eps * (|T| + r |dT/dlambda|), r = (|x1| + |x2| + l) / L0. A
    !> string within that rounding of stretch 1 (the kink of the tension-only law)
    !> counts with the slope of its taut side.
    pure real(wp) function get_tension_rounding(law, position_norm, length, length0, tension, &
            dtension) result(rounding)
        class(force_law_type), intent(in) :: law
        real(wp), intent(in) :: position_norm, length, length0, tension, dtension
        real(wp) :: r, slope

        r = (position_norm + length) / length0
        slope = dtension
        if (dtension == 0.0_wp .and. length / length0 > 1.0_wp - rounding_factor &
                * epsilon(1.0_wp) * r) slope = law%get_reference_stiffness()
        rounding = rounding_factor * epsilon(1.0_wp) * (abs(tension) + r * abs(slope))
    end function get_tension_rounding

    !> The reference stiffness of `law` under `stiffness_cap` (get_truss_tension).
    pure real(wp) function capped_stiffness(law, stiffness_cap) result(stiffness)
        class(force_law_type), intent(in) :: law
        real(wp), intent(in), optional :: stiffness_cap

        stiffness = law%get_reference_stiffness()
        if (present(stiffness_cap)) stiffness = min(stiffness, stiffness_cap)
    end function capped_stiffness

end module yarnfort_assembly_truss
