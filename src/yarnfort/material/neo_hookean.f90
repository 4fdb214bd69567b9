! SPDX-License-Identifier: MIT
!> Incompressible neo-Hookean string (the paper's eq. 4): Cauchy stress
!> sigma = C*(lambda**2 - 1/lambda) on the deformed cross-section S1/lambda (that of an
!> incompressible string, whatever the paper's eq. 4 prints), so the
!> tension is f = S1*C*(lambda - lambda**(-2)) for lambda > 1, zero when slack.
module yarnfort_material_neo_hookean
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_material_force_law, only: force_law_type
    use yarnfort_text, only: format_real
    implicit none
    private

    public :: neo_hookean_law_type, new_neo_hookean_law

    !> Incompressible neo-Hookean string, tension-only.
    type, extends(force_law_type) :: neo_hookean_law_type
        !> Material constant C in Pa.
        real(wp) :: modulus = 0.0_wp
        !> Reference cross-section S1 = S(lambda = 1) in m**2.
        real(wp) :: area = 0.0_wp
    contains
        procedure :: get_taut_force
        procedure :: get_taut_energy
        procedure :: get_reference_stiffness
    end type neo_hookean_law_type

contains

    !> Create a neo-Hookean law from C in Pa and S1 in m**2 (both finite and > 0).
    subroutine new_neo_hookean_law(self, modulus, area, error)
        type(neo_hookean_law_type), intent(out) :: self
        real(wp), intent(in) :: modulus, area
        type(error_type), allocatable, intent(out) :: error

        call check_positive('modulus', 'Pa', modulus, error)
        if (allocated(error)) return
        call check_positive('area', 'm**2', area, error)
        if (allocated(error)) return
        self%modulus = modulus
        self%area = area
    end subroutine new_neo_hookean_law

    !> Fail unless `value` is finite and > 0; the message names the parameter and value.
    subroutine check_positive(name, unit, value, error)
        character(len=*), intent(in) :: name, unit
        real(wp), intent(in) :: value
        type(error_type), allocatable, intent(out) :: error

        if (.not. ieee_is_finite(value)) then
            call fatal_error(error, 'neo-Hookean law: ' // name // ' ' &
                // format_real(value) // ' is not finite')
        else if (value <= 0.0_wp) then
            call fatal_error(error, 'neo-Hookean law: ' // name // ' ' &
                // format_real(value) // ' ' // unit // ' must be greater than 0')
        end if
    end subroutine check_positive

    !> Tension S1*C*(lambda - lambda**(-2)) and its derivative S1*C*(1 + 2*lambda**(-3)).
    pure subroutine get_taut_force(self, stretch, force, dforce)
        class(neo_hookean_law_type), intent(in) :: self
        real(wp), intent(in) :: stretch
        real(wp), intent(out) :: force, dforce
        real(wp) :: scale

        scale = self%area * self%modulus
        force = scale * (stretch - 1.0_wp / stretch**2)
        dforce = scale * (1.0_wp + 2.0_wp / stretch**3)
    end subroutine get_taut_force

    !> Energy per unit reference length, the integral of f from 1 to lambda:
    !> S1*C*((lambda**2 - 1)/2 + 1/lambda - 1) = S1*C*(lambda - 1)**2*(lambda + 2)/(2*lambda),
    !> evaluated in the factored form (no cancellation near lambda = 1).
    pure function get_taut_energy(self, stretch) result(energy)
        class(neo_hookean_law_type), intent(in) :: self
        real(wp), intent(in) :: stretch
        real(wp) :: energy

        energy = self%area * self%modulus * (stretch - 1.0_wp)**2 * (stretch + 2.0_wp) &
            / (2.0_wp * stretch)
    end function get_taut_energy

    !> The right-hand slope at lambda = 1, 3*S1*C.
    pure function get_reference_stiffness(self) result(stiffness)
        class(neo_hookean_law_type), intent(in) :: self
        real(wp) :: stiffness

        stiffness = 3.0_wp * self%area * self%modulus
    end function get_reference_stiffness

end module yarnfort_material_neo_hookean
