! SPDX-License-Identifier: MIT
!> Coulomb capstan (Euler-Eytelwein) law: g(T) = mu*T, T_crit = T_min*exp(mu*alpha)
!> (paper eqs. 20, 48, written without the ratio so that T_min = 0 is allowed).
module yarnfort_friction_coulomb
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_friction_law, only: friction_law_type, scaled_exp, capped_product, &
        cap_critical_tension, check_parameter, rate_limit
    implicit none
    private

    public :: coulomb_law_type, new_coulomb_law

    !> Coulomb capstan law. With T_min = 0 the critical tension is 0: the yarn slides
    !> unless T_max = 0 too (only adhesion lets a slack side hold).
    type, extends(friction_law_type) :: coulomb_law_type
        !> Friction coefficient mu >= 0 (dimensionless).
        real(wp) :: friction_coefficient = 0.0_wp
    contains
        procedure :: get_critical_tension
        procedure :: get_rate
    end type coulomb_law_type

contains

    !> Create a Coulomb law; fails unless `friction_coefficient` (mu) is finite and >= 0.
    pure subroutine new_coulomb_law(self, friction_coefficient, error)
        type(coulomb_law_type), intent(out) :: self
        real(wp), intent(in) :: friction_coefficient
        type(error_type), allocatable, intent(out) :: error

        call check_parameter('Coulomb friction law', 'friction_coefficient (mu)', &
            friction_coefficient, 0.0_wp, error)
        if (allocated(error)) return
        self%friction_coefficient = friction_coefficient
    end subroutine new_coulomb_law

    !> T_crit = T_min*exp(mu*alpha); dT_crit/dT_min = exp(mu*alpha) (also at T_min = 0),
    !> dT_crit/dalpha = mu*T_crit.
    pure subroutine get_critical_tension(self, tension_min, angle, critical, &
            dcritical_dtension, dcritical_dangle)
        class(coulomb_law_type), intent(in) :: self
        real(wp), intent(in) :: tension_min, angle
        real(wp), intent(out) :: critical, dcritical_dtension, dcritical_dangle
        real(wp) :: tension_start, exponent

        tension_start = max(tension_min, 0.0_wp)
        exponent = capped_product(self%friction_coefficient, max(angle, 0.0_wp))
        critical = scaled_exp(tension_start, exponent)
        dcritical_dtension = scaled_exp(1.0_wp, exponent)
        dcritical_dangle = capped_product(self%friction_coefficient, critical)
        call cap_critical_tension(tension_start, critical, dcritical_dtension, &
            dcritical_dangle)
    end subroutine get_critical_tension

    !> g(T) = mu*T, g'(T) = mu.
    pure subroutine get_rate(self, tension, rate, drate)
        class(coulomb_law_type), intent(in) :: self
        real(wp), intent(in) :: tension
        real(wp), intent(out) :: rate, drate

        rate = capped_product(self%friction_coefficient, max(tension, 0.0_wp), rate_limit)
        drate = self%friction_coefficient
    end subroutine get_rate

end module yarnfort_friction_coulomb
