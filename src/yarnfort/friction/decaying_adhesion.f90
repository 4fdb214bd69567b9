! SPDX-License-Identifier: MIT
!> Capstan law with decaying adhesion (paper eqs. 40-45, 50):
!> g(T) = max(beta*min(1, (s_d - T)/(s_d - w_d)), mu*T), 0 <= w_d < s_d.
!> Full adhesion beta up to T = w_d, decaying linearly to zero at T = s_d.
!>
!> Closed form, derived from the ODE (the paper's eqs. 42-44 read with w = w_d).
!> With d = s_d - w_d, k = beta/d:
!> - mu*w_d >= beta: g = max(mu*T, beta) for all T >= 0, plain adhesion (includes beta = 0).
!> - Otherwise beta > mu*w_d, the adhesion branch dominates up to
!>   T* = beta*s_d/(mu*d + beta) (w_d < T* <= s_d; T* = s_d iff mu = 0), mu*T after.
!>   * T0 <= w_d: T = T0 + beta*alpha until alpha1 = (w_d - T0)/beta, then relaxation
!>     T = s_d - d*exp(-k*(alpha - alpha1)) until T*, reached after a further
!>     ln((mu*d + beta)/(mu*s_d))/k, then T = T*exp(mu*(alpha - alpha2)).
!>   * w_d < T0 <= T*: T = s_d - (s_d - T0)*exp(-k*alpha) until
!>     alpha2 = ln((s_d - T0)/(s_d - T*))/k, then T = T*exp(mu*(alpha - alpha2)).
!>   * T0 > T*: T = T0*exp(mu*alpha).
!> - mu = 0: g(T) -> 0 as T -> s_d, so T_crit tends to s_d from below and never exceeds it;
!>   for T0 >= s_d, g = 0 and T_crit = T0 (no resistance), dT_crit/dT0 = 1 (right-sided;
!>   the left derivative at T0 = s_d is exp(-k*alpha)).
!> g is continuous, so T_crit is continuously differentiable wherever g(T0) > 0; only
!> second derivatives jump at the regime boundaries.
module yarnfort_friction_decaying_adhesion
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_friction_law, only: friction_law_type, scaled_exp, capped_product, &
        capped_quotient, expm1, cap_critical_tension, check_parameter, rate_limit, &
        no_kink
    use yarnfort_friction_coulomb, only: coulomb_law_type
    use yarnfort_text, only: format_real
    use yarnfort_friction_adhesion, only: adhesion_law_type
    implicit none
    private

    public :: decaying_adhesion_law_type, new_decaying_adhesion_law

    !> Capstan friction with adhesion that decays between the tensions w_d and s_d.
    type, extends(friction_law_type) :: decaying_adhesion_law_type
        !> Friction coefficient mu >= 0 (dimensionless).
        real(wp) :: friction_coefficient = 0.0_wp
        !> Adhesion beta >= 0 at low tension (N per radian of wrap).
        real(wp) :: adhesion = 0.0_wp
        !> Tension w_d >= 0 up to which the adhesion is full (N).
        real(wp) :: decay_start = 0.0_wp
        !> Tension s_d > w_d at which the adhesion has decayed to zero (N).
        real(wp) :: decay_end = 1.0_wp
    contains
        procedure :: get_critical_tension
        procedure :: get_rate
        procedure :: get_next_kink
    end type decaying_adhesion_law_type

    character(len=*), parameter :: law_name = 'decaying adhesion friction law'

contains

    !> Create a decaying adhesion law; fails unless mu, beta, w_d are finite and >= 0 and
    !> s_d is finite and > w_d.
    pure subroutine new_decaying_adhesion_law(self, friction_coefficient, adhesion, &
            decay_start, decay_end, error)
        type(decaying_adhesion_law_type), intent(out) :: self
        real(wp), intent(in) :: friction_coefficient, adhesion, decay_start, decay_end
        type(error_type), allocatable, intent(out) :: error

        call check_parameter(law_name, 'friction_coefficient (mu)', friction_coefficient, &
            0.0_wp, error)
        if (allocated(error)) return
        call check_parameter(law_name, 'adhesion (beta)', adhesion, 0.0_wp, error)
        if (allocated(error)) return
        call check_parameter(law_name, 'decay_start (w_d)', decay_start, 0.0_wp, error)
        if (allocated(error)) return
        call check_parameter(law_name, 'decay_end (s_d)', decay_end, 0.0_wp, error)
        if (allocated(error)) return
        if (.not. decay_end > decay_start) then
            call fatal_error(error, law_name // ': decay_end (s_d) = ' // format_real(decay_end) &
                // ' must be > decay_start (w_d) = ' // format_real(decay_start))
            return
        end if
        self%friction_coefficient = friction_coefficient
        self%adhesion = adhesion
        self%decay_start = decay_start
        self%decay_end = decay_end
    end subroutine new_decaying_adhesion_law

    !> Closed-form T_crit(T_min, alpha) (module notes) with dT_crit/dalpha = g(T_crit) and
    !> dT_crit/dT_min = g(T_crit)/g(T_min), which is exp(-k*(relaxation angle)) during the
    !> relaxation and 1 on the initial linear part.
    pure subroutine get_critical_tension(self, tension_min, angle, critical, &
            dcritical_dtension, dcritical_dangle)
        class(decaying_adhesion_law_type), intent(in) :: self
        real(wp), intent(in) :: tension_min, angle
        real(wp), intent(out) :: critical, dcritical_dtension, dcritical_dangle
        type(adhesion_law_type) :: adhesion
        type(coulomb_law_type) :: coulomb
        real(wp) :: mu, beta, w, s, d, k, tension_start, wrap
        real(wp) :: gap_star, tension_star, linear_angle, relax_start, relax_angle
        real(wp) :: decay, relaxed, angle_to_star, rate_start

        mu = self%friction_coefficient
        beta = self%adhesion
        w = self%decay_start
        s = self%decay_end
        tension_start = max(tension_min, 0.0_wp)
        wrap = max(angle, 0.0_wp)

        ! Adhesion never decays below mu*T: plain adhesion law (also beta = 0).
        if (capped_product(mu, w) >= beta) then
            adhesion%friction_coefficient = mu
            adhesion%adhesion = beta
            call adhesion%get_critical_tension(tension_start, wrap, critical, &
                dcritical_dtension, dcritical_dangle)
            return
        end if

        ! From here beta > mu*w_d >= 0.
        d = s - w
        k = capped_quotient(beta, d)
        call get_tension_star(self, tension_star, gap_star)

        if (mu <= 0.0_wp .and. tension_start >= s) then
            ! g = 0 at and above s_d: T stays (right-sided derivative 1).
            critical = tension_start
            dcritical_dtension = 1.0_wp
            dcritical_dangle = 0.0_wp
            return
        end if
        if (tension_start > tension_star) then
            coulomb%friction_coefficient = mu
            call coulomb%get_critical_tension(tension_start, wrap, critical, &
                dcritical_dtension, dcritical_dangle)
            return
        end if

        if (tension_start <= w) then
            rate_start = beta
            linear_angle = capped_quotient(w - tension_start, beta)
            if (wrap <= linear_angle) then
                critical = tension_start + beta * wrap
                dcritical_dtension = 1.0_wp
                dcritical_dangle = beta
                return
            end if
            relax_start = w
            relax_angle = wrap - linear_angle
        else
            rate_start = beta * ((s - tension_start) / d)
            relax_start = tension_start
            relax_angle = wrap
        end if

        ! Relaxation towards s_d from relax_start in [w_d, T*].
        decay = exp(-capped_product(k, relax_angle))
        relaxed = relax_start - (s - relax_start) * expm1(-capped_product(k, relax_angle))
        if (relaxed <= tension_star) then
            critical = relaxed
            dcritical_dtension = decay
            dcritical_dangle = capped_product(k, (s - relax_start) * decay)
        else
            ! T* reached after angle_to_star, exponential growth afterwards (mu > 0).
            angle_to_star = (log(s - relax_start) - log(gap_star)) / k
            critical = scaled_exp(tension_star, capped_product(mu, relax_angle - angle_to_star))
            dcritical_dangle = capped_product(mu, critical)
            dcritical_dtension = capped_quotient(dcritical_dangle, rate_start)
        end if
        call cap_critical_tension(tension_start, critical, dcritical_dtension, &
            dcritical_dangle)
    end subroutine get_critical_tension

    !> g(T) = max(beta*min(1, (s_d - T)/d), mu*T) with its right derivative.
    pure subroutine get_rate(self, tension, rate, drate)
        class(decaying_adhesion_law_type), intent(in) :: self
        real(wp), intent(in) :: tension
        real(wp), intent(out) :: rate, drate
        real(wp) :: t, adhesion_rate, dadhesion_rate, coulomb_rate

        t = max(tension, 0.0_wp)
        if (t < self%decay_start) then
            adhesion_rate = self%adhesion
            dadhesion_rate = 0.0_wp
        else
            ! Negative beyond s_d, clipped at 0 there since g >= mu*T >= 0 anyway.
            if (t < self%decay_end) then
                adhesion_rate = self%adhesion * ((self%decay_end - t) &
                    / (self%decay_end - self%decay_start))
            else
                adhesion_rate = 0.0_wp
            end if
            dadhesion_rate = -capped_quotient(self%adhesion, self%decay_end - self%decay_start)
        end if
        coulomb_rate = capped_product(self%friction_coefficient, t, rate_limit)
        rate = max(adhesion_rate, coulomb_rate)
        if (adhesion_rate > coulomb_rate) then
            drate = dadhesion_rate
        else if (coulomb_rate > adhesion_rate) then
            drate = self%friction_coefficient
        else
            drate = max(dadhesion_rate, self%friction_coefficient)
        end if
    end subroutine get_rate

    !> T* = beta*s_d/(mu*d + beta) where mu*T meets the decaying adhesion (s_d if mu = 0),
    !> and s_d - T*, computed without cancellation. Meaningful when beta > mu*w_d.
    pure subroutine get_tension_star(self, tension_star, gap_star)
        class(decaying_adhesion_law_type), intent(in) :: self
        real(wp), intent(out) :: tension_star, gap_star
        real(wp) :: mu_d

        mu_d = capped_product(self%friction_coefficient, self%decay_end - self%decay_start)
        gap_star = self%decay_end * (mu_d / (mu_d + self%adhesion))
        tension_star = self%decay_end - gap_star
    end subroutine get_tension_star

    !> Kinks of g: beta/mu in the plain adhesion case, otherwise w_d and T* (for mu = 0,
    !> T* = s_d is the zero of g).
    pure function get_next_kink(self, tension) result(kink)
        class(decaying_adhesion_law_type), intent(in) :: self
        real(wp), intent(in) :: tension
        real(wp) :: kink
        real(wp) :: tension_star, gap_star

        kink = no_kink
        if (capped_product(self%friction_coefficient, self%decay_start) >= self%adhesion) then
            if (self%friction_coefficient > 0.0_wp .and. self%adhesion > 0.0_wp) then
                kink = capped_quotient(self%adhesion, self%friction_coefficient)
                if (.not. kink > tension) kink = no_kink
            end if
            return
        end if
        call get_tension_star(self, tension_star, gap_star)
        if (self%decay_start > tension) then
            kink = self%decay_start
        else if (tension_star > tension) then
            kink = tension_star
        end if
    end function get_next_kink

end module yarnfort_friction_decaying_adhesion
