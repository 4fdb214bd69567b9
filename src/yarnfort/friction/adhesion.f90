! SPDX-License-Identifier: MIT
!> Capstan law with adhesion: g(T) = max(mu*T, beta) (paper eqs. 30-36, 49).
!>
!> Closed form (paper eq. 35 with alpha* = 1/mu - T0/beta, T0 = T_min):
!> - mu*T0 >= beta: T(alpha) = T0*exp(mu*alpha);
!> - otherwise T = T0 + beta*alpha up to alpha*, where T reaches beta/mu, then
!>   T = (beta/mu)*exp(mu*(alpha - alpha*)).
!> Special cases: mu = 0 gives pure adhesion T0 + beta*alpha, beta = 0 pure Coulomb.
module yarnfort_friction_adhesion
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_friction_law, only: friction_law_type, scaled_exp, capped_product, &
        capped_quotient, cap_critical_tension, check_parameter, tension_limit, rate_limit, &
        no_kink
    use yarnfort_friction_coulomb, only: coulomb_law_type
    implicit none
    private

    public :: adhesion_law_type, new_adhesion_law

    !> Capstan friction with adhesion: even a slack side (T_min = 0) holds up to beta*alpha.
    type, extends(friction_law_type) :: adhesion_law_type
        !> Friction coefficient mu >= 0 (dimensionless).
        real(wp) :: friction_coefficient = 0.0_wp
        !> Adhesion beta >= 0 (N per radian of wrap).
        real(wp) :: adhesion = 0.0_wp
    contains
        procedure :: get_critical_tension
        procedure :: get_rate
        procedure :: get_next_kink
    end type adhesion_law_type

contains

    !> Create an adhesion law; fails unless `friction_coefficient` (mu) and `adhesion` (beta)
    !> are finite and >= 0.
    pure subroutine new_adhesion_law(self, friction_coefficient, adhesion, error)
        type(adhesion_law_type), intent(out) :: self
        real(wp), intent(in) :: friction_coefficient, adhesion
        type(error_type), allocatable, intent(out) :: error

        call check_parameter('adhesion friction law', 'friction_coefficient (mu)', &
            friction_coefficient, 0.0_wp, error)
        if (allocated(error)) return
        call check_parameter('adhesion friction law', 'adhesion (beta)', adhesion, 0.0_wp, &
            error)
        if (allocated(error)) return
        self%friction_coefficient = friction_coefficient
        self%adhesion = adhesion
    end subroutine new_adhesion_law

    !> Closed-form T_crit(T_min, alpha) of T' = max(mu*T, beta) with its derivatives:
    !> dT_crit/dalpha = g(T_crit), dT_crit/dT_min = g(T_crit)/g(T_min) (1 on the linear
    !> part, exp(mu*(alpha - alpha*)) on the exponential part after the linear one).
    pure subroutine get_critical_tension(self, tension_min, angle, critical, &
            dcritical_dtension, dcritical_dangle)
        class(adhesion_law_type), intent(in) :: self
        real(wp), intent(in) :: tension_min, angle
        real(wp), intent(out) :: critical, dcritical_dtension, dcritical_dangle
        type(coulomb_law_type) :: coulomb
        real(wp) :: mu, beta, tension_start, wrap, mu_angle, linear_angle

        mu = self%friction_coefficient
        beta = self%adhesion
        tension_start = max(tension_min, 0.0_wp)
        wrap = max(angle, 0.0_wp)

        ! Coulomb from the start: no adhesion, or mu*T0 already dominates beta.
        if (beta <= 0.0_wp .or. (mu > 0.0_wp .and. capped_product(mu, tension_start) >= beta)) &
                then
            coulomb%friction_coefficient = mu
            call coulomb%get_critical_tension(tension_start, wrap, critical, &
                dcritical_dtension, dcritical_dangle)
            return
        end if

        ! Linear part T0 + beta*alpha; with mu > 0 it lasts for mu*alpha <= linear_angle,
        ! linear_angle = mu*alpha* = (beta - mu*T0)/beta in (0, 1].
        mu_angle = capped_product(mu, wrap)
        if (mu > 0.0_wp) then
            linear_angle = (beta - mu * tension_start) / beta
        else
            linear_angle = huge(1.0_wp)
        end if
        if (mu_angle <= linear_angle) then
            critical = min(tension_start + capped_product(beta, wrap), tension_limit)
            dcritical_dtension = 1.0_wp
            dcritical_dangle = beta
        else
            critical = scaled_exp(capped_quotient(beta, mu), mu_angle - linear_angle)
            dcritical_dtension = scaled_exp(1.0_wp, mu_angle - linear_angle)
            dcritical_dangle = capped_product(mu, critical)
        end if
        call cap_critical_tension(tension_start, critical, dcritical_dtension, &
            dcritical_dangle)
    end subroutine get_critical_tension

    !> g(T) = max(mu*T, beta); right derivative mu once mu*T >= beta, else 0.
    pure subroutine get_rate(self, tension, rate, drate)
        class(adhesion_law_type), intent(in) :: self
        real(wp), intent(in) :: tension
        real(wp), intent(out) :: rate, drate
        real(wp) :: coulomb_rate

        coulomb_rate = capped_product(self%friction_coefficient, max(tension, 0.0_wp), &
            rate_limit)
        rate = max(coulomb_rate, self%adhesion)
        if (coulomb_rate >= self%adhesion) then
            drate = self%friction_coefficient
        else
            drate = 0.0_wp
        end if
    end subroutine get_rate

    !> The kink of g at T = beta/mu (none if mu = 0 or beta = 0).
    pure function get_next_kink(self, tension) result(kink)
        class(adhesion_law_type), intent(in) :: self
        real(wp), intent(in) :: tension
        real(wp) :: kink

        kink = no_kink
        if (self%friction_coefficient > 0.0_wp .and. self%adhesion > 0.0_wp) then
            kink = capped_quotient(self%adhesion, self%friction_coefficient)
            if (.not. kink > tension) kink = no_kink
        end if
    end function get_next_kink

end module yarnfort_friction_adhesion
