! SPDX-License-Identifier: MIT
!> The force law of a yarn type: tension as a function of stretch (a string carries no
!> compression). Concrete laws extend `force_law_type`.
module yarnfort_material_law
    use yarnfort_kinds, only: wp
    implicit none
    private

    public :: force_law_type

    !> Tension f(lambda) of a yarn, lambda = l/L0. Contract for every law:
    !> f(lambda) = 0 and df/dlambda = 0 for lambda <= 1 (slack), f strictly increasing for
    !> lambda > 1, f continuous with a continuous first derivative for lambda > 1.
    type, abstract :: force_law_type
    contains
        !> Tension and its derivative with respect to stretch.
        procedure(get_force_interface), deferred :: get_force
        !> Stored energy per unit reference length, integral from 1 to lambda of f.
        procedure(get_energy_interface), deferred :: get_energy
        !> A positive scale of df/dlambda near lambda = 1 (used to size regularisations).
        procedure(get_reference_stiffness_interface), deferred :: get_reference_stiffness
    end type force_law_type

    abstract interface
        pure subroutine get_force_interface(self, stretch, force, dforce)
            import :: force_law_type, wp
            class(force_law_type), intent(in) :: self
            real(wp), intent(in) :: stretch
            real(wp), intent(out) :: force, dforce
        end subroutine get_force_interface

        pure function get_energy_interface(self, stretch) result(energy)
            import :: force_law_type, wp
            class(force_law_type), intent(in) :: self
            real(wp), intent(in) :: stretch
            real(wp) :: energy
        end function get_energy_interface

        pure function get_reference_stiffness_interface(self) result(stiffness)
            import :: force_law_type, wp
            class(force_law_type), intent(in) :: self
            real(wp) :: stiffness
        end function get_reference_stiffness_interface
    end interface

end module yarnfort_material_law
