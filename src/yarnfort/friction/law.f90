! SPDX-License-Identifier: MIT
!> The friction law of a contact node: the critical tension T_crit(T_min, alpha) that the
!> high-tension side of a yarn may carry before it slides, and the overflow-safe arithmetic
!> shared by the concrete laws.
!>
!> Every law is the flow of an autonomous initial value problem T' = g(T), T(0) = T_min,
!> evaluated at the bending angle alpha = pi - gamma (paper eqs. 34, 39, 41). Conventions
!> common to all laws:
!> - Negative T_min or alpha (round-off) are treated as zero. Angles above pi are allowed
!>   (a yarn over several nodes composes exactly into one node with the summed angle).
!> - alpha = 0 gives T_crit = T_min: a straight yarn has no friction resistance.
!> - Derivatives are right-sided (towards larger T_min and larger alpha) where a one-sided
!>   choice is needed. dT_crit/dalpha = g(T_crit); dT_crit/dT_min = g(T_crit)/g(T_min) when
!>   g(T_min) > 0, and exp(alpha*g'(T_min+)) when g(T_min) = 0 (T stays at T_min, an
!>   equilibrium; g'(T+) is the right derivative of the rate). All rates here are
!>   continuous, so T_crit is continuously differentiable wherever g(T_min) > 0: at regime
!>   boundaries only second derivatives jump and both one-sided derivatives agree. The
!>   choice matters only where g(T_min) = 0 (Coulomb at T_min = 0, where only the right
!>   side exists; decaying adhesion with mu = 0 at T_min = s_d; zeros of a table).
!> - Overflow: no output is ever Inf or NaN. A critical tension above `tension_limit` is
!>   returned as `tension_limit` (or T_min if that is larger) with zero derivatives, the
!>   derivatives of the capped function; a finite critical tension whose derivative
!>   exceeds `tension_limit` gets that derivative capped at `tension_limit`.
module yarnfort_friction_law
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: format_real
    implicit none
    private

    public :: friction_law_type
    public :: tension_limit, rate_limit, no_kink
    public :: scaled_exp, capped_product, capped_quotient, expm1, cap_critical_tension
    public :: check_parameter

    !> Largest critical tension (and derivative) a law returns, about 1.7e302. Below huge()
    !> by a factor that leaves callers and the Runge-Kutta stages headroom above it.
    real(wp), parameter :: tension_limit = huge(1.0_wp) / 2.0_wp**20

    !> Largest rate g(T) a law returns (room for Runge-Kutta stage sums of 32 terms).
    real(wp), parameter :: rate_limit = huge(1.0_wp) / 64.0_wp

    !> `get_next_kink` result when g has no kink or zero above the given tension.
    real(wp), parameter :: no_kink = huge(1.0_wp)

    !> Natural logarithm of `tension_limit`.
    real(wp), parameter :: log_tension_limit = log(tension_limit)

    !> Stick/slip law of a yarn passing a contact node.
    type, abstract :: friction_law_type
    contains
        !> Critical tension T_crit(T_min, alpha) and its two derivatives.
        procedure(get_critical_tension_interface), deferred :: get_critical_tension
        !> Rate g(T) of the law's ODE T' = g(T) and its right derivative dg/dT.
        procedure(get_rate_interface), deferred :: get_rate
        !> Smallest tension above the given one where g has a kink or a zero (integrators
        !> step onto it exactly); `no_kink` if none. Default: g smooth and positive.
        procedure :: get_next_kink
        !> True iff the passage sticks: T_max <= T_crit(T_min, alpha).
        procedure :: sticks
    end type friction_law_type

    abstract interface
        !> T_crit(T_min, alpha) with dT_crit/dT_min and dT_crit/dalpha (see module notes).
        pure subroutine get_critical_tension_interface(self, tension_min, angle, critical, &
                dcritical_dtension, dcritical_dangle)
            import :: friction_law_type, wp
            class(friction_law_type), intent(in) :: self
            real(wp), intent(in) :: tension_min, angle
            real(wp), intent(out) :: critical, dcritical_dtension, dcritical_dangle
        end subroutine get_critical_tension_interface

        !> Rate g(T) >= 0 for T >= 0, and its right derivative (the slope just above T).
        pure subroutine get_rate_interface(self, tension, rate, drate)
            import :: friction_law_type, wp
            class(friction_law_type), intent(in) :: self
            real(wp), intent(in) :: tension
            real(wp), intent(out) :: rate, drate
        end subroutine get_rate_interface
    end interface

contains

    !> True iff a yarn with side tensions `tension_min` <= `tension_max` bent by `angle`
    !> sticks, i.e. T_max <= T_crit(T_min, angle). Tensions given in the other order are
    !> swapped. Never a ratio: T_min = 0 is allowed.
    pure logical function sticks(self, tension_min, tension_max, angle)
        class(friction_law_type), intent(in) :: self
        real(wp), intent(in) :: tension_min, tension_max, angle
        real(wp) :: critical, dcritical_dtension, dcritical_dangle

        call self%get_critical_tension(min(tension_min, tension_max), angle, critical, &
            dcritical_dtension, dcritical_dangle)
        sticks = max(tension_min, tension_max) <= critical
    end function sticks

    !> Smallest tension above `tension` where the rate has a kink or a zero: none here.
    pure function get_next_kink(self, tension) result(kink)
        class(friction_law_type), intent(in) :: self
        real(wp), intent(in) :: tension
        real(wp) :: kink

        kink = no_kink
    end function get_next_kink

    !> scale*exp(exponent) for scale >= 0, capped at `tension_limit` without overflowing.
    elemental function scaled_exp(scale, exponent) result(value)
        real(wp), intent(in) :: scale, exponent
        real(wp) :: value
        real(wp) :: log_value

        if (scale <= 0.0_wp) then
            value = 0.0_wp
            return
        end if
        log_value = exponent + log(scale)
        if (log_value >= log_tension_limit) then
            value = tension_limit
        else if (exponent < log_tension_limit) then
            value = min(scale * exp(exponent), tension_limit)
        else
            value = min(exp(log_value), tension_limit)
        end if
    end function scaled_exp

    !> a*b for a, b >= 0 (0 if either is negative), capped at `limit` (default
    !> `tension_limit`) without overflowing.
    elemental function capped_product(a, b, limit) result(value)
        real(wp), intent(in) :: a, b
        real(wp), intent(in), optional :: limit
        real(wp) :: value
        real(wp) :: cap

        cap = tension_limit
        if (present(limit)) cap = limit
        ! Nested tests: Fortran does not short-circuit, cap/a must not be formed for tiny a.
        if (a <= 0.0_wp .or. b <= 0.0_wp) then
            value = 0.0_wp
        else if (a <= 1.0_wp) then
            value = min(a * b, cap)
        else if (b <= cap / a) then
            value = min(a * b, cap)
        else
            value = cap
        end if
    end function capped_product

    !> exp(x) - 1, accurate near x = 0 (Kahan's trick: (u - 1)*x/log(u) with u = exp(x)),
    !> capped at `tension_limit`.
    elemental function expm1(x) result(value)
        real(wp), intent(in) :: x
        real(wp) :: value
        real(wp) :: u

        if (x >= log_tension_limit) then
            value = tension_limit
            return
        end if
        u = exp(x)
        if (.not. abs(u - 1.0_wp) > 0.0_wp) then
            value = x
        else if (u - 1.0_wp <= -1.0_wp) then
            value = -1.0_wp
        else if (abs(x) < 1.0_wp) then
            value = (u - 1.0_wp) * x / log(u)
        else
            value = u - 1.0_wp
        end if
    end function expm1

    !> a/b for a >= 0, b > 0, capped at `tension_limit` without overflowing.
    elemental function capped_quotient(a, b) result(value)
        real(wp), intent(in) :: a, b
        real(wp) :: value

        if (a <= 0.0_wp) then
            value = 0.0_wp
        else if (b >= 1.0_wp) then
            value = min(a / b, tension_limit)
        else if (a <= b * tension_limit) then
            value = min(a / b, tension_limit)
        else
            value = tension_limit
        end if
    end function capped_quotient

    !> Apply the overflow convention of the module notes: a critical tension that reached
    !> `tension_limit` becomes max(tension_limit, T_min) with zero derivatives.
    pure subroutine cap_critical_tension(tension_min, critical, dcritical_dtension, &
            dcritical_dangle)
        real(wp), intent(in) :: tension_min
        real(wp), intent(inout) :: critical, dcritical_dtension, dcritical_dangle

        if (critical >= tension_limit) then
            critical = max(tension_limit, tension_min)
            dcritical_dtension = 0.0_wp
            dcritical_dangle = 0.0_wp
        end if
    end subroutine cap_critical_tension

    !> Fail unless `value` is finite and >= `minimum`; the message names the law, the
    !> parameter and the value.
    pure subroutine check_parameter(law_name, parameter_name, value, minimum, error)
        character(len=*), intent(in) :: law_name, parameter_name
        real(wp), intent(in) :: value, minimum
        type(error_type), allocatable, intent(out) :: error

        if (.not. ieee_is_finite(value)) then
            call fatal_error(error, law_name // ': ' // parameter_name // ' must be finite, got ' &
                // format_real(value))
        else if (value < minimum) then
            call fatal_error(error, law_name // ': ' // parameter_name // ' must be >= ' &
                // format_real(minimum) // ', got ' // format_real(value))
        end if
    end subroutine check_parameter

end module yarnfort_friction_law
