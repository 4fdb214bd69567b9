! SPDX-License-Identifier: MIT
!> Linear tension-only force law: f = EA*(lambda - 1) for lambda > 1, slack otherwise.
module yarnfort_material_linear
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_material_force_law, only: force_law_type
    use yarnfort_text, only: format_real
    implicit none
    private

    public :: linear_law_type, new_linear_law

    !> Linear string: tension proportional to strain, zero in compression.
    type, extends(force_law_type) :: linear_law_type
        !> Axial stiffness EA in N (tension per unit strain).
        real(wp) :: stiffness = 0.0_wp
    contains
        procedure :: get_taut_force
        procedure :: get_taut_energy
        procedure :: get_reference_stiffness
    end type linear_law_type

contains

    !> Create a linear law with axial stiffness EA in N (finite and > 0).
    subroutine new_linear_law(self, stiffness, error)
        type(linear_law_type), intent(out) :: self
        real(wp), intent(in) :: stiffness
        type(error_type), allocatable, intent(out) :: error

        if (.not. ieee_is_finite(stiffness)) then
            call fatal_error(error, 'linear law: stiffness ' // format_real(stiffness) &
                // ' is not finite')
            return
        end if
        if (stiffness <= 0.0_wp) then
            call fatal_error(error, 'linear law: stiffness ' // format_real(stiffness) &
                // ' N must be greater than 0')
            return
        end if
        self%stiffness = stiffness
    end subroutine new_linear_law

    !> Tension EA*(lambda - 1) and its derivative EA for lambda > 1.
    pure subroutine get_taut_force(self, stretch, force, dforce)
        class(linear_law_type), intent(in) :: self
        real(wp), intent(in) :: stretch
        real(wp), intent(out) :: force, dforce

        force = self%stiffness * (stretch - 1.0_wp)
        dforce = self%stiffness
    end subroutine get_taut_force

    !> Energy per unit reference length EA*(lambda - 1)**2/2 for lambda > 1.
    pure function get_taut_energy(self, stretch) result(energy)
        class(linear_law_type), intent(in) :: self
        real(wp), intent(in) :: stretch
        real(wp) :: energy

        energy = 0.5_wp * self%stiffness * (stretch - 1.0_wp)**2
    end function get_taut_energy

    !> The right-hand slope at lambda = 1, EA.
    pure function get_reference_stiffness(self) result(stiffness)
        class(linear_law_type), intent(in) :: self
        real(wp) :: stiffness

        stiffness = self%stiffness
    end function get_reference_stiffness

end module yarnfort_material_linear
