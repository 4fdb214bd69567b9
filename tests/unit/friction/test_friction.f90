! SPDX-License-Identifier: MIT
!> Unit tests of the friction laws: every closed form against the Runge-Kutta integration
!> of its own rate in each regime, table laws against both, analytic derivatives against
!> finite differences (central away from kinks, one-sided at them), composition over
!> several nodes, monotonicity, overflow and parameter validation.
module test_friction
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_value, ieee_quiet_nan
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_testing, only: unittest_type, new_unittest, check, check_close
    use yarnfort_friction_law, only: friction_law_type, tension_limit
    use yarnfort_friction_coulomb, only: coulomb_law_type, new_coulomb_law
    use yarnfort_friction_adhesion, only: adhesion_law_type, new_adhesion_law
    use yarnfort_friction_decaying_adhesion, only: decaying_adhesion_law_type, &
        new_decaying_adhesion_law
    use yarnfort_friction_general, only: table_law_type, numerical_law_type, new_table_law, &
        new_numerical_law, integration_converged, integration_capped, integration_out_of_steps
    implicit none
    private

    public :: collect_friction

    real(wp), parameter :: pi = acos(-1.0_wp)
    !> Tolerance requested from the numerical twins.
    real(wp), parameter :: integration_request = 1.0e-12_wp
    !> Agreement demanded between a closed form and the integration of its rate (global
    !> error over many steps; observed up to 3e-12 in values, 6e-11 in derivatives).
    real(wp), parameter :: integration_tolerance = 100 * integration_request
    !> Identities that hold up to rounding (composition, exact table walk, reductions).
    real(wp), parameter :: identity_tolerance = 1000 * epsilon(1.0_wp)
    !> Central finite differences: step eps**(1/3) (relative), tolerance sqrt(eps).
    real(wp), parameter :: central_step = epsilon(1.0_wp)**(1.0_wp / 3)
    real(wp), parameter :: central_tolerance = sqrt(epsilon(1.0_wp))
    !> One-sided finite differences at kinks: step sqrt(eps), error O(step).
    real(wp), parameter :: one_sided_step = sqrt(epsilon(1.0_wp))
    real(wp), parameter :: one_sided_tolerance = 10 * sqrt(epsilon(1.0_wp))
    !> Angles covering alpha = 0, near 0, mid range, near pi and pi.
    real(wp), parameter :: angles(*) = [0.0_wp, 1.0e-10_wp, 1.0e-3_wp, 0.5_wp, 1.0_wp, &
        2.0_wp, pi - 1.0e-10_wp, pi]

    !> A law of any kind, so that tests can loop over laws.
    type :: law_holder
        class(friction_law_type), allocatable :: law
        character(len=:), allocatable :: name
    end type law_holder

contains

    !> Collect all friction tests.
    subroutine collect_friction(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)

        testsuite = [ &
            new_unittest('coulomb_vs_numerical', test_coulomb_vs_numerical), &
            new_unittest('adhesion_vs_numerical', test_adhesion_vs_numerical), &
            new_unittest('adhesion_hand_values', test_adhesion_hand_values), &
            new_unittest('decaying_vs_numerical', test_decaying_vs_numerical), &
            new_unittest('decaying_reduces_to_adhesion', test_decaying_reduces), &
            new_unittest('decaying_zero_friction', test_decaying_zero_friction), &
            new_unittest('tiny_adhesion', test_tiny_adhesion), &
            new_unittest('huge_friction_no_overflow', test_huge_friction), &
            new_unittest('table_vs_closed_forms', test_table_vs_closed_forms), &
            new_unittest('table_zero_and_steep_rate', test_table_zero_and_steep), &
            new_unittest('derivatives_central', test_derivatives_central), &
            new_unittest('derivatives_at_kinks', test_derivatives_at_kinks), &
            new_unittest('composition', test_composition), &
            new_unittest('monotonicity', test_monotonicity), &
            new_unittest('straight_yarn_and_sticks', test_straight_and_sticks), &
            new_unittest('integrator_status', test_integrator_status), &
            new_unittest('reject_bad_parameters', test_reject_bad_parameters), &
            new_unittest('reject_bad_tables', test_reject_bad_tables) &
            ]
    end subroutine collect_friction

    ! ----------------------------------------------------------------- helpers

    !> Label "what at T_min=..., alpha=...".
    function at(what, tension, angle) result(label)
        character(len=*), intent(in) :: what
        real(wp), intent(in) :: tension, angle
        character(len=:), allocatable :: label
        character(len=80) :: buffer

        write(buffer, '(" at T_min=", es12.5, ", alpha=", es12.5)') tension, angle
        label = what // trim(buffer)
    end function at

    !> Closed form vs Runge-Kutta integration of the law's own rate, values and derivatives.
    subroutine check_against_numerical(error, law, tensions, what)
        type(error_type), allocatable, intent(out) :: error
        class(friction_law_type), intent(in) :: law
        real(wp), intent(in) :: tensions(:)
        character(len=*), intent(in) :: what
        type(numerical_law_type) :: twin
        real(wp) :: closed(3), numerical(3)
        integer :: i, j

        call new_numerical_law(twin, law, error, relative_tolerance=integration_request)
        if (allocated(error)) return
        do i = 1, size(tensions)
            do j = 1, size(angles)
                call law%get_critical_tension(tensions(i), angles(j), closed(1), closed(2), &
                    closed(3))
                call twin%get_critical_tension(tensions(i), angles(j), numerical(1), &
                    numerical(2), numerical(3))
                call check_close(error, numerical, closed, integration_tolerance, &
                    at(what // ' [T_crit, dT/dT_min, dT/dalpha]', tensions(i), angles(j)))
                if (allocated(error)) return
            end do
        end do
    end subroutine check_against_numerical

    !> T_crit only.
    function critical_of(law, tension, angle) result(critical)
        class(friction_law_type), intent(in) :: law
        real(wp), intent(in) :: tension, angle
        real(wp) :: critical
        real(wp) :: dtension, dangle

        call law%get_critical_tension(tension, angle, critical, dtension, dangle)
    end function critical_of

    !> Analytic derivatives vs central differences at (tension, angle).
    subroutine check_central(error, law, tension, angle, what)
        type(error_type), allocatable, intent(out) :: error
        class(friction_law_type), intent(in) :: law
        real(wp), intent(in) :: tension, angle
        character(len=*), intent(in) :: what
        real(wp) :: critical, dtension, dangle, h, fd

        call law%get_critical_tension(tension, angle, critical, dtension, dangle)
        h = central_step * max(tension, 1.0_wp)
        fd = (critical_of(law, tension + h, angle) - critical_of(law, tension - h, angle)) &
            / (2 * h)
        call check_close(error, dtension, fd, central_tolerance, &
            at(what // ' dT_crit/dT_min', tension, angle), abs_tol=central_tolerance)
        if (allocated(error)) return
        h = central_step * max(angle, 1.0_wp)
        fd = (critical_of(law, tension, angle + h) - critical_of(law, tension, angle - h)) &
            / (2 * h)
        call check_close(error, dangle, fd, central_tolerance, &
            at(what // ' dT_crit/dalpha', tension, angle), abs_tol=central_tolerance)
    end subroutine check_central

    !> One-sided difference quotient in T_min (side = +1 right, -1 left) vs `expected`.
    subroutine check_one_sided_tension(error, law, tension, angle, side, expected, what)
        type(error_type), allocatable, intent(out) :: error
        class(friction_law_type), intent(in) :: law
        real(wp), intent(in) :: tension, angle, side, expected
        character(len=*), intent(in) :: what
        real(wp) :: h, fd

        h = side * one_sided_step * max(tension, 1.0_wp)
        fd = (critical_of(law, tension + h, angle) - critical_of(law, tension, angle)) / h
        call check_close(error, fd, expected, one_sided_tolerance, &
            at(what // ' one-sided dT_crit/dT_min', tension, angle), abs_tol=one_sided_tolerance)
    end subroutine check_one_sided_tension

    !> One-sided difference quotient in alpha (side = +1 right, -1 left) vs `expected`.
    subroutine check_one_sided_angle(error, law, tension, angle, side, expected, what)
        type(error_type), allocatable, intent(out) :: error
        class(friction_law_type), intent(in) :: law
        real(wp), intent(in) :: tension, angle, side, expected
        character(len=*), intent(in) :: what
        real(wp) :: h, fd

        h = side * one_sided_step * max(angle, 1.0_wp)
        fd = (critical_of(law, tension, angle + h) - critical_of(law, tension, angle)) / h
        call check_close(error, fd, expected, one_sided_tolerance, &
            at(what // ' one-sided dT_crit/dalpha', tension, angle), abs_tol=one_sided_tolerance)
    end subroutine check_one_sided_angle

    !> The laws used by the property tests, one per regime family.
    subroutine make_laws(laws, error)
        type(law_holder), allocatable, intent(out) :: laws(:)
        type(error_type), allocatable, intent(out) :: error
        type(coulomb_law_type) :: coulomb
        type(adhesion_law_type) :: adhesion, pure_adhesion
        type(decaying_adhesion_law_type) :: decaying, decaying_frictionless

        call new_coulomb_law(coulomb, 0.3_wp, error)
        if (allocated(error)) return
        call new_adhesion_law(adhesion, 0.3_wp, 0.2_wp, error)
        if (allocated(error)) return
        call new_adhesion_law(pure_adhesion, 0.0_wp, 0.2_wp, error)
        if (allocated(error)) return
        call new_decaying_adhesion_law(decaying, 0.3_wp, 0.5_wp, 0.4_wp, 2.0_wp, error)
        if (allocated(error)) return
        call new_decaying_adhesion_law(decaying_frictionless, 0.0_wp, 0.5_wp, 0.4_wp, 2.0_wp, &
            error)
        if (allocated(error)) return
        allocate(laws(5))
        allocate(laws(1)%law, source=coulomb)
        laws(1)%name = 'Coulomb'
        allocate(laws(2)%law, source=adhesion)
        laws(2)%name = 'adhesion'
        allocate(laws(3)%law, source=pure_adhesion)
        laws(3)%name = 'pure adhesion'
        allocate(laws(4)%law, source=decaying)
        laws(4)%name = 'decaying adhesion'
        allocate(laws(5)%law, source=decaying_frictionless)
        laws(5)%name = 'decaying adhesion mu=0'
    end subroutine make_laws

    !> Append a copy of `law` to `laws`.
    subroutine append_law(laws, law, name)
        type(law_holder), allocatable, intent(inout) :: laws(:)
        class(friction_law_type), intent(in) :: law
        character(len=*), intent(in) :: name
        type(law_holder), allocatable :: longer(:)
        integer :: i

        allocate(longer(size(laws) + 1))
        do i = 1, size(laws)
            call move_alloc(laws(i)%law, longer(i)%law)
            call move_alloc(laws(i)%name, longer(i)%name)
        end do
        allocate(longer(size(longer))%law, source=law)
        longer(size(longer))%name = name
        call move_alloc(longer, laws)
    end subroutine append_law

    ! ------------------------------------------------------------------- tests

    !> Coulomb closed form vs integration, mu = 0 included; T_min = 0 gives T_crit = 0.
    subroutine test_coulomb_vs_numerical(error)
        type(error_type), allocatable, intent(out) :: error
        type(coulomb_law_type) :: law
        real(wp), parameter :: frictions(*) = [0.0_wp, 0.3_wp, 1.0_wp, 5.0_wp]
        real(wp) :: values(3)
        integer :: i

        do i = 1, size(frictions)
            call new_coulomb_law(law, frictions(i), error)
            if (allocated(error)) return
            call check_against_numerical(error, law, [0.0_wp, 1.0e-3_wp, 1.0_wp, 10.0_wp], &
                'Coulomb')
            if (allocated(error)) return
        end do
        call law%get_critical_tension(0.0_wp, 2.0_wp, values(1), values(2), values(3))
        call check_close(error, values, [0.0_wp, exp(10.0_wp), 0.0_wp], identity_tolerance, &
            'Coulomb mu=5 at T_min=0 [T_crit, dT/dT_min, dT/dalpha]')
    end subroutine test_coulomb_vs_numerical

    !> Adhesion closed form vs integration: T_min = 0, below, at and above beta/mu;
    !> mu = 0 (pure adhesion) and beta = 0 (pure Coulomb).
    subroutine test_adhesion_vs_numerical(error)
        type(error_type), allocatable, intent(out) :: error
        type(adhesion_law_type) :: law
        type(coulomb_law_type) :: coulomb
        integer :: i, j

        call new_adhesion_law(law, 0.3_wp, 0.2_wp, error)
        if (allocated(error)) return
        call check_against_numerical(error, law, [0.0_wp, 0.3_wp, 0.2_wp / 0.3_wp, &
            0.2_wp / 0.3_wp * (1 + 1.0e-9_wp), 1.0_wp, 10.0_wp], 'adhesion mu=0.3 beta=0.2')
        if (allocated(error)) return
        call new_adhesion_law(law, 2.0_wp, 1.0_wp, error)
        if (allocated(error)) return
        call check_against_numerical(error, law, [0.0_wp, 0.25_wp, 0.5_wp, 2.0_wp], &
            'adhesion mu=2 beta=1')
        if (allocated(error)) return
        call new_adhesion_law(law, 0.0_wp, 0.2_wp, error)
        if (allocated(error)) return
        call check_against_numerical(error, law, [0.0_wp, 1.0_wp], 'adhesion mu=0')
        if (allocated(error)) return
        call new_adhesion_law(law, 0.3_wp, 0.0_wp, error)
        if (allocated(error)) return
        call check_against_numerical(error, law, [0.0_wp, 1.0_wp], 'adhesion beta=0')
        if (allocated(error)) return
        ! beta = 0 is the Coulomb law exactly.
        call new_coulomb_law(coulomb, 0.3_wp, error)
        if (allocated(error)) return
        do i = 1, size(angles)
            do j = 0, 4
                call check_close(error, critical_of(law, 0.5_wp * j, angles(i)), &
                    critical_of(coulomb, 0.5_wp * j, angles(i)), identity_tolerance, &
                    at('adhesion beta=0 vs Coulomb', 0.5_wp * j, angles(i)))
                if (allocated(error)) return
            end do
        end do
    end subroutine test_adhesion_vs_numerical

    !> Values computed by hand from eq. 35 with alpha* = 1/mu - T0/beta.
    subroutine test_adhesion_hand_values(error)
        type(error_type), allocatable, intent(out) :: error
        type(adhesion_law_type) :: law

        call new_adhesion_law(law, 0.5_wp, 1.0_wp, error)
        if (allocated(error)) return
        ! T0 = 0: linear up to alpha* = 2 (T = 2), then 2*exp(0.5*(alpha - 2)).
        call check_close(error, critical_of(law, 0.0_wp, 1.5_wp), 1.5_wp, identity_tolerance, &
            'adhesion linear part')
        if (allocated(error)) return
        call check_close(error, critical_of(law, 0.0_wp, 3.0_wp), 2 * exp(0.5_wp), &
            identity_tolerance, 'adhesion exponential part')
        if (allocated(error)) return
        ! T0 = 1: alpha* = 1, T(pi) = 2*exp(0.5*(pi - 1)).
        call check_close(error, critical_of(law, 1.0_wp, pi), 2 * exp(0.5_wp * (pi - 1)), &
            identity_tolerance, 'adhesion from T0 = 1')
        if (allocated(error)) return
        ! T0 = 3 >= beta/mu: pure exponential.
        call check_close(error, critical_of(law, 3.0_wp, pi), 3 * exp(0.5_wp * pi), &
            identity_tolerance, 'adhesion above beta/mu')
    end subroutine test_adhesion_hand_values

    !> Decaying adhesion vs integration in every regime: T0 <= w_d (linear, relaxation,
    !> exponential), w_d < T0 <= T*, T0 > T*, T0 >= s_d; w_d = 0; beta = 0.
    subroutine test_decaying_vs_numerical(error)
        type(error_type), allocatable, intent(out) :: error
        type(decaying_adhesion_law_type) :: law
        real(wp) :: tension_star

        call new_decaying_adhesion_law(law, 0.3_wp, 0.5_wp, 0.4_wp, 2.0_wp, error)
        if (allocated(error)) return
        tension_star = 0.5_wp * 2.0_wp / (0.3_wp * 1.6_wp + 0.5_wp)
        call check_against_numerical(error, law, [0.0_wp, 0.2_wp, 0.4_wp, 0.7_wp, &
            tension_star, 1.5_wp, 2.0_wp, 3.0_wp], 'decaying mu=0.3 beta=0.5 w=0.4 s=2')
        if (allocated(error)) return
        ! T* = 0.8; from T0 = 0 all three parts within alpha < 0.5.
        call new_decaying_adhesion_law(law, 1.0_wp, 2.0_wp, 0.5_wp, 1.0_wp, error)
        if (allocated(error)) return
        call check_against_numerical(error, law, [0.0_wp, 0.25_wp, 0.5_wp, 0.6_wp, 0.8_wp, &
            0.9_wp, 1.0_wp, 2.0_wp], 'decaying mu=1 beta=2 w=0.5 s=1')
        if (allocated(error)) return
        call new_decaying_adhesion_law(law, 0.3_wp, 0.5_wp, 0.0_wp, 2.0_wp, error)
        if (allocated(error)) return
        call check_against_numerical(error, law, [0.0_wp, 0.5_wp, 1.0_wp / 0.98_wp, 3.0_wp], &
            'decaying w=0')
        if (allocated(error)) return
        call new_decaying_adhesion_law(law, 0.3_wp, 0.0_wp, 0.4_wp, 2.0_wp, error)
        if (allocated(error)) return
        call check_against_numerical(error, law, [0.0_wp, 1.0_wp], 'decaying beta=0')
    end subroutine test_decaying_vs_numerical

    !> mu*w_d >= beta: decaying adhesion is plain adhesion.
    subroutine test_decaying_reduces(error)
        type(error_type), allocatable, intent(out) :: error
        type(decaying_adhesion_law_type) :: law
        type(adhesion_law_type) :: adhesion
        real(wp), parameter :: tensions(*) = [0.0_wp, 0.1_wp, 0.2_wp, 0.4_wp, 1.0_wp, 3.0_wp]
        integer :: i, j

        ! mu*w_d = 0.2 >= beta = 0.1, and the boundary case mu*w_d = beta.
        call new_decaying_adhesion_law(law, 0.5_wp, 0.1_wp, 0.4_wp, 2.0_wp, error)
        if (allocated(error)) return
        call new_adhesion_law(adhesion, 0.5_wp, 0.1_wp, error)
        if (allocated(error)) return
        call check_against_numerical(error, law, tensions, 'decaying mu*w_d > beta')
        if (allocated(error)) return
        do i = 1, size(tensions)
            do j = 1, size(angles)
                call check_close(error, critical_of(law, tensions(i), angles(j)), &
                    critical_of(adhesion, tensions(i), angles(j)), identity_tolerance, &
                    at('decaying mu*w_d > beta vs adhesion', tensions(i), angles(j)))
                if (allocated(error)) return
            end do
        end do
        call new_decaying_adhesion_law(law, 0.5_wp, 0.2_wp, 0.4_wp, 2.0_wp, error)
        if (allocated(error)) return
        call check_against_numerical(error, law, tensions, 'decaying mu*w_d = beta')
    end subroutine test_decaying_reduces

    !> mu = 0: T_crit tends to s_d and never passes it; above s_d there is no resistance.
    subroutine test_decaying_zero_friction(error)
        type(error_type), allocatable, intent(out) :: error
        type(decaying_adhesion_law_type) :: law
        real(wp) :: values(3)

        call new_decaying_adhesion_law(law, 0.0_wp, 0.5_wp, 0.4_wp, 2.0_wp, error)
        if (allocated(error)) return
        call check_against_numerical(error, law, [0.0_wp, 0.2_wp, 0.4_wp, 1.0_wp, 1.99_wp, &
            2.0_wp, 3.0_wp], 'decaying mu=0')
        if (allocated(error)) return
        call check(error, critical_of(law, 0.0_wp, 1.0e3_wp) <= 2.0_wp, &
            'decaying mu=0: T_crit must not exceed s_d')
        if (allocated(error)) return
        call check_close(error, critical_of(law, 0.0_wp, 1.0e3_wp), 2.0_wp, identity_tolerance, &
            'decaying mu=0: T_crit tends to s_d')
        if (allocated(error)) return
        ! Relaxation from T0 = 1: T = 2 - exp(-0.5/1.6*alpha).
        call check_close(error, critical_of(law, 1.0_wp, pi), 2 - exp(-0.3125_wp * pi), &
            identity_tolerance, 'decaying mu=0 relaxation')
        if (allocated(error)) return
        call law%get_critical_tension(3.0_wp, pi, values(1), values(2), values(3))
        call check_close(error, values, [3.0_wp, 1.0_wp, 0.0_wp], identity_tolerance, &
            'decaying mu=0 above s_d [T_crit, dT/dT_min, dT/dalpha]')
    end subroutine test_decaying_zero_friction

    !> beta = 1e-12: the linear part is tiny but must still be followed exactly.
    subroutine test_tiny_adhesion(error)
        type(error_type), allocatable, intent(out) :: error
        type(adhesion_law_type) :: adhesion
        type(decaying_adhesion_law_type) :: decaying

        call new_adhesion_law(adhesion, 0.3_wp, 1.0e-12_wp, error)
        if (allocated(error)) return
        call check_against_numerical(error, adhesion, [0.0_wp, 1.0e-12_wp, 1.0_wp], &
            'adhesion beta=1e-12')
        if (allocated(error)) return
        call new_decaying_adhesion_law(decaying, 0.3_wp, 1.0e-12_wp, 1.0e-12_wp, 1.0e-11_wp, &
            error)
        if (allocated(error)) return
        call check_against_numerical(error, decaying, [0.0_wp, 5.0e-13_wp, 2.0e-12_wp, &
            1.0_wp], 'decaying beta=1e-12')
    end subroutine test_tiny_adhesion

    !> mu = 1e4: exp(mu*alpha) overflows; results are capped at tension_limit, never Inf/NaN,
    !> and closed forms and integration agree on the cap.
    subroutine test_huge_friction(error)
        type(error_type), allocatable, intent(out) :: error
        type(law_holder), allocatable :: laws(:)
        type(coulomb_law_type) :: coulomb
        type(adhesion_law_type) :: adhesion
        type(decaying_adhesion_law_type) :: decaying
        real(wp), parameter :: tensions(*) = [0.0_wp, 1.0e-300_wp, 1.0_wp, 1.0e300_wp]
        real(wp), parameter :: wide_angles(*) = [0.0_wp, 1.0e-3_wp, 0.05_wp, pi, 100.0_wp]
        real(wp), parameter :: frictions(*) = [1.0e4_wp, 1.0e300_wp]
        real(wp) :: values(3)
        integer :: i, j, l, m

        call new_coulomb_law(coulomb, 1.0e4_wp, error)
        if (allocated(error)) return
        call check_against_numerical(error, coulomb, [0.0_wp, 1.0_wp], 'Coulomb mu=1e4')
        if (allocated(error)) return
        call check_close(error, critical_of(coulomb, 1.0_wp, pi), tension_limit, 0.0_wp, &
            'Coulomb mu=1e4 capped')
        if (allocated(error)) return
        call new_adhesion_law(adhesion, 1.0e4_wp, 0.1_wp, error)
        if (allocated(error)) return
        call check_against_numerical(error, adhesion, [0.0_wp, 1.0e-5_wp, 1.0_wp], &
            'adhesion mu=1e4')
        if (allocated(error)) return
        call new_decaying_adhesion_law(decaying, 1.0e4_wp, 1.0e3_wp, 0.01_wp, 1.0_wp, error)
        if (allocated(error)) return
        call check_against_numerical(error, decaying, [0.0_wp, 0.005_wp, 0.05_wp, 2.0_wp], &
            'decaying mu=1e4')
        if (allocated(error)) return

        do m = 1, size(frictions)
            allocate(laws(3))
            call new_coulomb_law(coulomb, frictions(m), error)
            if (allocated(error)) return
            call new_adhesion_law(adhesion, frictions(m), 0.1_wp, error)
            if (allocated(error)) return
            call new_decaying_adhesion_law(decaying, frictions(m), 1.0e3_wp, 0.0_wp, 1.0_wp, &
                error)
            if (allocated(error)) return
            allocate(laws(1)%law, source=coulomb)
            allocate(laws(2)%law, source=adhesion)
            allocate(laws(3)%law, source=decaying)
            do l = 1, size(laws)
                do i = 1, size(tensions)
                    do j = 1, size(wide_angles)
                        call laws(l)%law%get_critical_tension(tensions(i), wide_angles(j), &
                            values(1), values(2), values(3))
                        call check(error, all(ieee_is_finite(values)) &
                            .and. all(values >= 0.0_wp) .and. values(1) >= tensions(i), &
                            at('finite, non-negative, >= T_min for huge mu', tensions(i), &
                            wide_angles(j)))
                        if (allocated(error)) return
                    end do
                end do
            end do
            deallocate(laws)
        end do
    end subroutine test_huge_friction

    !> Tables that reproduce the closed-form rates: the exact piecewise walk and the
    !> Runge-Kutta integration of the table both match the closed forms.
    subroutine test_table_vs_closed_forms(error)
        type(error_type), allocatable, intent(out) :: error
        type(law_holder), allocatable :: laws(:)
        type(table_law_type) :: table
        real(wp), parameter :: tensions(*) = [0.0_wp, 0.1_wp, 0.4_wp, 0.7_wp, 1.0_wp, &
            1.5_wp, 2.0_wp, 3.0_wp]
        real(wp) :: tension_star, closed(3), exact(3), numerical(3)
        integer :: l, i, j

        call make_laws(laws, error)
        if (allocated(error)) return
        tension_star = 0.5_wp * 2.0_wp / (0.3_wp * 1.6_wp + 0.5_wp)
        do l = 1, size(laws)
            select case (l)
            case (1)
                call new_table_law(table, [0.0_wp, 1.0_wp], [0.0_wp, 0.3_wp], error, &
                    relative_tolerance=integration_request)
            case (2)
                call new_table_law(table, [0.0_wp, 0.2_wp / 0.3_wp, 2.0_wp], &
                    [0.2_wp, 0.2_wp, 0.6_wp], error, relative_tolerance=integration_request)
            case (3)
                call new_table_law(table, [0.0_wp, 1.0_wp], [0.2_wp, 0.2_wp], error, &
                    relative_tolerance=integration_request)
            case (4)
                call new_table_law(table, [0.0_wp, 0.4_wp, tension_star, 2 * tension_star], &
                    [0.5_wp, 0.5_wp, 0.3_wp * tension_star, 0.6_wp * tension_star], error, &
                    relative_tolerance=integration_request)
            case (5)
                call new_table_law(table, [0.0_wp, 0.4_wp, 2.0_wp, 3.0_wp], &
                    [0.5_wp, 0.5_wp, 0.0_wp, 0.0_wp], error, &
                    relative_tolerance=integration_request)
            end select
            if (allocated(error)) return
            do i = 1, size(tensions)
                do j = 1, size(angles)
                    call laws(l)%law%get_critical_tension(tensions(i), angles(j), closed(1), &
                        closed(2), closed(3))
                    call table%get_critical_tension(tensions(i), angles(j), exact(1), &
                        exact(2), exact(3))
                    call table%get_critical_tension_numerical(tensions(i), angles(j), &
                        numerical(1), numerical(2), numerical(3))
                    call check_close(error, exact, closed, identity_tolerance, &
                        at('table walk vs ' // laws(l)%name, tensions(i), angles(j)), &
                        abs_tol=identity_tolerance)
                    if (allocated(error)) return
                    call check_close(error, numerical, closed, integration_tolerance, &
                        at('table Runge-Kutta vs ' // laws(l)%name, tensions(i), angles(j)), &
                        abs_tol=integration_tolerance)
                    if (allocated(error)) return
                end do
            end do
        end do
    end subroutine test_table_vs_closed_forms

    !> A rate with an interior zero behind a very steep (stiff) drop: T never passes the
    !> zero, a start on the zero stays, a start beyond it grows; a falling last piece
    !> extrapolates to a zero like decaying adhesion with mu = 0.
    subroutine test_table_zero_and_steep(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: table
        type(decaying_adhesion_law_type) :: decaying
        real(wp), parameter :: zero_at = 1.0_wp + 1.0e-6_wp
        real(wp) :: values(3)
        integer :: j

        call new_table_law(table, [0.0_wp, 1.0_wp, zero_at, 3.0_wp], &
            [1.0_wp, 1.0_wp, 0.0_wp, 2.0_wp], error)
        if (allocated(error)) return
        values(1) = critical_of(table, 0.0_wp, pi)
        call check(error, values(1) >= 1.0_wp .and. values(1) <= zero_at, &
            'table: T_crit stays below the zero of g')
        if (allocated(error)) return
        call check_close(error, values(1), zero_at, identity_tolerance, &
            'table: T_crit approaches the zero of g')
        if (allocated(error)) return
        call table%get_critical_tension(zero_at, pi, values(1), values(2), values(3))
        call check_close(error, values, [zero_at, exp(2 / (3 - zero_at) * pi), 0.0_wp], &
            identity_tolerance, 'table: start on the zero [T_crit, dT/dT_min, dT/dalpha]')
        if (allocated(error)) return
        call check(error, critical_of(table, 1.5_wp, 1.0_wp) > 1.5_wp, &
            'table: a start beyond the zero grows')
        if (allocated(error)) return

        ! g = 1 - T/2 extrapolated: decaying adhesion beta = 1, w_d = 0, s_d = 2, mu = 0.
        call new_table_law(table, [0.0_wp, 1.0_wp], [1.0_wp, 0.5_wp], error)
        if (allocated(error)) return
        call new_decaying_adhesion_law(decaying, 0.0_wp, 1.0_wp, 0.0_wp, 2.0_wp, error)
        if (allocated(error)) return
        do j = 1, size(angles)
            call check_close(error, critical_of(table, 0.5_wp, angles(j)), &
                critical_of(decaying, 0.5_wp, angles(j)), identity_tolerance, &
                at('falling table vs decaying mu=0', 0.5_wp, angles(j)))
            if (allocated(error)) return
            call check_close(error, critical_of(table, 4.0_wp, angles(j)), 4.0_wp, 0.0_wp, &
                at('falling table beyond its zero', 4.0_wp, angles(j)))
            if (allocated(error)) return
        end do
    end subroutine test_table_zero_and_steep

    !> Analytic derivatives vs central differences away from the regime kinks, for the
    !> property-test laws and a table law.
    subroutine test_derivatives_central(error)
        type(error_type), allocatable, intent(out) :: error
        type(law_holder), allocatable :: laws(:)
        type(table_law_type) :: table
        type(numerical_law_type) :: twin
        real(wp), parameter :: tensions(*) = [0.1_wp, 0.3_wp, 1.3_wp, 5.0_wp]
        real(wp), parameter :: test_angles(*) = [0.25_wp, 1.1_wp, 2.9_wp]
        integer :: l, i, j

        call make_laws(laws, error)
        if (allocated(error)) return
        do l = 1, size(laws)
            do i = 1, size(tensions)
                do j = 1, size(test_angles)
                    call check_central(error, laws(l)%law, tensions(i), test_angles(j), &
                        laws(l)%name)
                    if (allocated(error)) return
                end do
            end do
        end do
        call new_table_law(table, [0.0_wp, 0.5_wp, 1.0_wp, 2.0_wp], &
            [0.2_wp, 0.4_wp, 0.1_wp, 1.0_wp], error)
        if (allocated(error)) return
        do i = 1, size(tensions)
            do j = 1, size(test_angles)
                call check_central(error, table, tensions(i), test_angles(j), 'table')
                if (allocated(error)) return
            end do
        end do
        ! The Runge-Kutta twin is smooth enough for differences at a tight tolerance.
        call new_numerical_law(twin, laws(1)%law, error, relative_tolerance=1.0e-14_wp)
        if (allocated(error)) return
        call check_central(error, twin, 1.3_wp, 1.1_wp, 'numerical Coulomb')
    end subroutine test_derivatives_central

    !> One-sided differences on both sides of each kink match the analytic derivative (g
    !> is continuous, so T_crit is C1 there), except where g(T_min) = 0: the analytic
    !> derivative is then the right-sided one.
    subroutine test_derivatives_at_kinks(error)
        type(error_type), allocatable, intent(out) :: error
        type(coulomb_law_type) :: coulomb
        type(adhesion_law_type) :: adhesion
        type(decaying_adhesion_law_type) :: decaying
        real(wp) :: kink, tension_star, values(3)
        real(wp), parameter :: sides(*) = [-1.0_wp, 1.0_wp]
        integer :: s

        call new_coulomb_law(coulomb, 0.3_wp, error)
        if (allocated(error)) return
        call coulomb%get_critical_tension(0.0_wp, 2.0_wp, values(1), values(2), values(3))
        call check_one_sided_tension(error, coulomb, 0.0_wp, 2.0_wp, 1.0_wp, values(2), &
            'Coulomb at T_min=0')
        if (allocated(error)) return

        call new_adhesion_law(adhesion, 0.3_wp, 0.2_wp, error)
        if (allocated(error)) return
        do s = 1, 2
            ! T_min = beta/mu.
            call check_kink(adhesion, 0.2_wp / 0.3_wp, 1.0_wp, sides(s), 'adhesion T=beta/mu')
            if (allocated(error)) return
            ! alpha = alpha* = 1/mu - T0/beta for T0 = 0.1; and alpha = 0 (right only).
            call check_kink(adhesion, 0.1_wp, 1 / 0.3_wp - 0.1_wp / 0.2_wp, sides(s), &
                'adhesion alpha=alpha*')
            if (allocated(error)) return
        end do
        call adhesion%get_critical_tension(0.1_wp, 0.0_wp, values(1), values(2), values(3))
        call check_one_sided_angle(error, adhesion, 0.1_wp, 0.0_wp, 1.0_wp, values(3), &
            'adhesion at alpha=0')
        if (allocated(error)) return

        call new_decaying_adhesion_law(decaying, 0.3_wp, 0.5_wp, 0.4_wp, 2.0_wp, error)
        if (allocated(error)) return
        tension_star = 0.5_wp * 2.0_wp / (0.3_wp * 1.6_wp + 0.5_wp)
        do s = 1, 2
            call check_kink(decaying, 0.4_wp, 1.0_wp, sides(s), 'decaying T=w_d')
            if (allocated(error)) return
            call check_kink(decaying, 0.4_wp, pi, sides(s), 'decaying T=w_d')
            if (allocated(error)) return
            call check_kink(decaying, tension_star, 1.0_wp, sides(s), 'decaying T=T*')
            if (allocated(error)) return
            ! From T0 = 0.1: linear until alpha1 = 0.6, relaxation until alpha2.
            call check_kink(decaying, 0.1_wp, 0.6_wp, sides(s), 'decaying alpha=alpha1')
            if (allocated(error)) return
            kink = 0.6_wp + 1.6_wp / 0.5_wp * log(0.98_wp / 0.6_wp)
            call check_kink(decaying, 0.1_wp, kink, sides(s), 'decaying alpha=alpha2')
            if (allocated(error)) return
        end do

        ! mu = 0 at T_min = s_d: g(T_min) = 0; right derivative 1 (returned), left exp(-k*alpha).
        call new_decaying_adhesion_law(decaying, 0.0_wp, 0.5_wp, 0.4_wp, 2.0_wp, error)
        if (allocated(error)) return
        call decaying%get_critical_tension(2.0_wp, 1.0_wp, values(1), values(2), values(3))
        call check_close(error, values(2), 1.0_wp, identity_tolerance, &
            'decaying mu=0 at s_d: returned dT/dT_min is the right derivative')
        if (allocated(error)) return
        call check_one_sided_tension(error, decaying, 2.0_wp, 1.0_wp, 1.0_wp, 1.0_wp, &
            'decaying mu=0 at s_d (right)')
        if (allocated(error)) return
        call check_one_sided_tension(error, decaying, 2.0_wp, 1.0_wp, -1.0_wp, &
            exp(-0.3125_wp), 'decaying mu=0 at s_d (left)')

    contains

        !> One-sided differences in T_min and alpha on `side` vs the analytic derivatives.
        subroutine check_kink(law, tension, angle, side, what)
            class(friction_law_type), intent(in) :: law
            real(wp), intent(in) :: tension, angle, side
            character(len=*), intent(in) :: what
            real(wp) :: critical, dtension, dangle

            call law%get_critical_tension(tension, angle, critical, dtension, dangle)
            call check_one_sided_tension(error, law, tension, angle, side, dtension, what)
            if (allocated(error)) return
            call check_one_sided_angle(error, law, tension, angle, side, dangle, what)
        end subroutine check_kink

    end subroutine test_derivatives_at_kinks

    !> A yarn over two or three nodes equals one node with the summed angle.
    subroutine test_composition(error)
        type(error_type), allocatable, intent(out) :: error
        type(law_holder), allocatable :: laws(:)
        type(table_law_type) :: table
        real(wp), parameter :: tensions(*) = [0.0_wp, 0.1_wp, 0.5_wp, 1.0_wp, 3.0_wp]
        real(wp), parameter :: first(*) = [0.3_wp, 1.0_wp, pi, 0.01_wp, 2.5_wp]
        real(wp), parameter :: second(*) = [0.7_wp, 2.0_wp, pi, 3.0_wp, 0.4_wp]
        real(wp) :: two_nodes, three_nodes, one_node
        integer :: l, i, j

        call make_laws(laws, error)
        if (allocated(error)) return
        call new_table_law(table, [0.0_wp, 0.5_wp, 1.0_wp, 2.0_wp], &
            [0.2_wp, 0.4_wp, 0.1_wp, 1.0_wp], error)
        if (allocated(error)) return
        call append_law(laws, table, 'table')
        do l = 1, size(laws)
            associate(law => laws(l)%law)
                do i = 1, size(tensions)
                    do j = 1, size(first)
                        one_node = critical_of(law, tensions(i), first(j) + second(j))
                        two_nodes = critical_of(law, critical_of(law, tensions(i), first(j)), &
                            second(j))
                        three_nodes = critical_of(law, critical_of(law, critical_of(law, &
                            tensions(i), first(j) / 2), first(j) / 2), second(j))
                        call check_close(error, [two_nodes, three_nodes], [one_node, one_node], &
                            identity_tolerance, at(laws(l)%name // ' composition', &
                            tensions(i), first(j)), abs_tol=tiny(1.0_wp))
                        if (allocated(error)) return
                    end do
                end do
            end associate
        end do
    end subroutine test_composition

    !> T_crit >= T_min, non-decreasing in T_min and alpha, derivatives consistent in sign.
    subroutine test_monotonicity(error)
        type(error_type), allocatable, intent(out) :: error
        type(law_holder), allocatable :: laws(:)
        integer, parameter :: grid = 60
        real(wp) :: t, a, values(3), previous_tension, previous_angle
        integer :: l, i, j

        call make_laws(laws, error)
        if (allocated(error)) return
        do l = 1, size(laws)
            do i = 0, grid
                t = 5.0_wp * i / grid
                previous_angle = -1.0_wp
                do j = 0, grid
                    a = pi * j / grid
                    call laws(l)%law%get_critical_tension(t, a, values(1), values(2), values(3))
                    call check(error, values(1) >= t .and. values(1) >= previous_angle &
                        .and. values(2) > 0.0_wp .and. values(3) >= 0.0_wp, &
                        at(laws(l)%name // ': monotone in alpha', t, a))
                    if (allocated(error)) return
                    previous_angle = values(1)
                end do
            end do
            do j = 0, grid
                a = pi * j / grid
                previous_tension = -1.0_wp
                do i = 0, grid
                    t = 5.0_wp * i / grid
                    values(1) = critical_of(laws(l)%law, t, a)
                    call check(error, values(1) > previous_tension, &
                        at(laws(l)%name // ': increasing in T_min', t, a))
                    if (allocated(error)) return
                    previous_tension = values(1)
                end do
            end do
        end do
    end subroutine test_monotonicity

    !> alpha = 0 gives no resistance; `sticks` compares without a ratio, in either order.
    subroutine test_straight_and_sticks(error)
        type(error_type), allocatable, intent(out) :: error
        type(law_holder), allocatable :: laws(:)
        type(coulomb_law_type) :: coulomb
        type(adhesion_law_type) :: adhesion
        real(wp) :: values(3)
        integer :: l, i

        call make_laws(laws, error)
        if (allocated(error)) return
        do l = 1, size(laws)
            do i = 0, 4
                call laws(l)%law%get_critical_tension(0.75_wp * i, 0.0_wp, values(1), &
                    values(2), values(3))
                call check_close(error, values(1:2), [0.75_wp * i, 1.0_wp], 0.0_wp, &
                    at(laws(l)%name // ': alpha=0 gives T_crit=T_min, dT/dT_min=1', &
                    0.75_wp * i, 0.0_wp))
                if (allocated(error)) return
            end do
        end do
        call new_coulomb_law(coulomb, 0.3_wp, error)
        if (allocated(error)) return
        call check(error, coulomb%sticks(0.0_wp, 0.0_wp, 1.0_wp), &
            'Coulomb: T_min = T_max = 0 sticks')
        if (allocated(error)) return
        call check(error, .not. coulomb%sticks(0.0_wp, 1.0e-300_wp, 1.0_wp), &
            'Coulomb: T_min = 0 < T_max slides')
        if (allocated(error)) return
        call check(error, coulomb%sticks(1.0_wp, 1.3_wp, 1.0_wp) &
            .and. coulomb%sticks(1.3_wp, 1.0_wp, 1.0_wp), &
            'Coulomb: 1.3 <= exp(0.3) sticks in either order')
        if (allocated(error)) return
        call check(error, .not. coulomb%sticks(1.0_wp, 1.4_wp, 1.0_wp), &
            'Coulomb: 1.4 > exp(0.3) slides')
        if (allocated(error)) return
        call new_adhesion_law(adhesion, 0.3_wp, 0.2_wp, error)
        if (allocated(error)) return
        call check(error, adhesion%sticks(0.0_wp, 0.19_wp, 1.0_wp) &
            .and. .not. adhesion%sticks(0.0_wp, 0.21_wp, 1.0_wp), &
            'adhesion: a slack side holds up to beta*alpha')
    end subroutine test_straight_and_sticks

    !> The integrator reports convergence, the cap and an exhausted step budget.
    subroutine test_integrator_status(error)
        type(error_type), allocatable, intent(out) :: error
        type(coulomb_law_type) :: coulomb
        type(numerical_law_type) :: twin
        type(table_law_type) :: table
        real(wp) :: tension
        integer :: steps, status

        call new_coulomb_law(coulomb, 1.0e4_wp, error)
        if (allocated(error)) return
        call new_numerical_law(twin, coulomb, error)
        if (allocated(error)) return
        call twin%integrate(1.0_wp, 1.0e-3_wp, tension, steps, status)
        call check(error, status == integration_converged .and. steps < 1000, &
            'integrator: mu*alpha = 10 converges in under 1000 steps')
        if (allocated(error)) return
        call twin%integrate(1.0_wp, pi, tension, steps, status)
        call check(error, status == integration_capped, &
            'integrator: mu*alpha = 3e4 is capped at tension_limit')
        if (allocated(error)) return
        call check_close(error, tension, tension_limit, 0.0_wp, 'integrator: capped tension')
        if (allocated(error)) return
        ! Stiff drop to a zero of g: the integrator stops on the zero (a kink of the table)
        ! instead of creeping towards it; a too small budget is reported.
        call new_table_law(table, [0.0_wp, 1.0_wp, 1.0_wp + 1.0e-6_wp, 3.0_wp], &
            [1.0_wp, 1.0_wp, 0.0_wp, 2.0_wp], error)
        if (allocated(error)) return
        call table%integrate(0.0_wp, pi, tension, steps, status)
        call check(error, status == integration_converged .and. steps < 1000, &
            'integrator: stiff table converges in under 1000 steps')
        if (allocated(error)) return
        call check_close(error, tension, critical_of(table, 0.0_wp, pi), &
            table%relative_tolerance, 'integrator: stiff table vs exact walk')
        if (allocated(error)) return
        table%max_steps = 10
        call table%integrate(0.0_wp, pi, tension, steps, status)
        call check(error, status == integration_out_of_steps .and. steps == 10, &
            'integrator: a budget of 10 steps is reported as exhausted')
    end subroutine test_integrator_status

    !> Constructors reject bad parameters with messages that name them and their values.
    subroutine test_reject_bad_parameters(error)
        type(error_type), allocatable, intent(out) :: error
        type(error_type), allocatable :: failure
        type(coulomb_law_type) :: coulomb
        type(adhesion_law_type) :: adhesion
        type(decaying_adhesion_law_type) :: decaying
        type(numerical_law_type) :: twin
        real(wp) :: nan

        nan = ieee_value(nan, ieee_quiet_nan)

        call new_coulomb_law(coulomb, -1.0_wp, failure)
        call expect(failure, ['friction_coefficient (mu)', 'got -1.0                 '])
        if (allocated(error)) return
        call new_coulomb_law(coulomb, nan, failure)
        call expect(failure, ['friction_coefficient (mu)', 'finite                   '])
        if (allocated(error)) return
        call new_adhesion_law(adhesion, 0.3_wp, -0.5_wp, failure)
        call expect(failure, ['adhesion (beta)', 'got -0.5       '])
        if (allocated(error)) return
        call new_adhesion_law(adhesion, -0.3_wp, 0.5_wp, failure)
        call expect(failure, ['friction_coefficient (mu)', 'got -0.3                 '])
        if (allocated(error)) return
        call new_decaying_adhesion_law(decaying, 0.3_wp, 0.5_wp, 2.0_wp, 1.0_wp, failure)
        call expect(failure, ['decay_end (s_d) = 1.0        ', &
            'decay_start (w_d) = 2.0      '])
        if (allocated(error)) return
        call new_decaying_adhesion_law(decaying, 0.3_wp, 0.5_wp, 1.0_wp, 1.0_wp, failure)
        call expect(failure, ['decay_end (s_d)  ', 'decay_start (w_d)'])
        if (allocated(error)) return
        call new_decaying_adhesion_law(decaying, 0.3_wp, 0.5_wp, -1.0_wp, 1.0_wp, failure)
        call expect(failure, ['decay_start (w_d)', 'got -1.0         '])
        if (allocated(error)) return
        call new_decaying_adhesion_law(decaying, 0.3_wp, 0.5_wp, 0.0_wp, nan, failure)
        call expect(failure, ['decay_end (s_d)', 'NaN            '])
        if (allocated(error)) return
        call new_coulomb_law(coulomb, 0.3_wp, failure)
        call check(error, .not. allocated(failure), 'Coulomb mu=0.3 must be accepted')
        if (allocated(error)) return
        call new_numerical_law(twin, coulomb, failure, relative_tolerance=0.0_wp)
        call expect(failure, ['relative_tolerance', 'got 0.0           '])

    contains

        !> Fail unless `failure` is set and its message contains every piece.
        subroutine expect(failure, pieces)
            type(error_type), allocatable, intent(in) :: failure
            character(len=*), intent(in) :: pieces(:)
            integer :: i

            if (.not. allocated(failure)) then
                call check(error, .false., 'expected a failure mentioning ' // trim(pieces(1)))
                return
            end if
            do i = 1, size(pieces)
                call check(error, index(failure%message, trim(pieces(i))) > 0, &
                    'message "' // failure%message // '" lacks "' // trim(pieces(i)) // '"')
                if (allocated(error)) return
            end do
        end subroutine expect

    end subroutine test_reject_bad_parameters

    !> Table constructor rejects malformed tables, naming the offending entry.
    subroutine test_reject_bad_tables(error)
        type(error_type), allocatable, intent(out) :: error
        type(error_type), allocatable :: failure
        type(table_law_type) :: table

        call new_table_law(table, [0.0_wp, 1.0_wp], [1.0_wp], failure)
        call expect(failure, 'rate has 1 values, tension has 2')
        if (allocated(error)) return
        call new_table_law(table, [0.0_wp], [1.0_wp], failure)
        call expect(failure, 'at least 2 points')
        if (allocated(error)) return
        call new_table_law(table, [0.5_wp, 1.0_wp], [1.0_wp, 1.0_wp], failure)
        call expect(failure, 'tension(1) must be 0')
        if (allocated(error)) return
        call new_table_law(table, [0.0_wp, 1.0_wp, 1.0_wp], [1.0_wp, 1.0_wp, 1.0_wp], failure)
        call expect(failure, 'tension(3) = 1.0 <= 1.0')
        if (allocated(error)) return
        call new_table_law(table, [0.0_wp, 1.0_wp], [1.0_wp, -2.0_wp], failure)
        call expect(failure, 'rate(2) must be finite, >= 0')
        if (allocated(error)) return
        call new_table_law(table, [0.0_wp, 1.0e-300_wp], [0.0_wp, 1.0e10_wp], failure)
        call expect(failure, 'too steep')
        if (allocated(error)) return
        call new_table_law(table, [0.0_wp, 1.0_wp], [1.0_wp, 1.0_wp], failure, &
            relative_tolerance=1.0_wp)
        call expect(failure, 'relative_tolerance')

    contains

        !> Fail unless `failure` is set and its message contains `piece`.
        subroutine expect(failure, piece)
            type(error_type), allocatable, intent(in) :: failure
            character(len=*), intent(in) :: piece

            if (.not. allocated(failure)) then
                call check(error, .false., 'expected a failure mentioning ' // piece)
                return
            end if
            call check(error, index(failure%message, piece) > 0, &
                'message "' // failure%message // '" lacks "' // piece // '"')
        end subroutine expect

    end subroutine test_reject_bad_tables

end module test_friction
