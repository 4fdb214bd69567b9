! SPDX-License-Identifier: MIT
!> The force law of a yarn type: tension as a function of stretch (a string carries no
!> compression). Concrete laws extend `force_law_type`.
module yarnfort_material_force_law
    use yarnfort_kinds, only: wp
    implicit none
    private

    public :: force_law_type, max_stretch, is_usable_stretch

    !> Largest stretch l / L0 of an element: a prestress is refused when its law needs
    !> more (get_stretch_at_force searches up to it), and so are per-element reference
    !> lengths that give more, or less than its inverse (is_usable_stretch; docs/
    !> decisions.md, One bound on an element's stretch).
    real(wp), parameter :: max_stretch = 2.0_wp**60

    !> Tension f(lambda) of a yarn, lambda = l/L0. f(lambda) = 0 and df/dlambda = 0 for
    !> lambda <= 1 (slack), here for every law. Contract for each law's taut branch: f
    !> strictly increasing for lambda > 1, continuous with a continuous first derivative.
    type, abstract :: force_law_type
    contains
        !> Tension and its derivative with respect to stretch.
        procedure, non_overridable :: get_force
        !> Stored energy per unit reference length, integral from 1 to lambda of f.
        procedure, non_overridable :: get_energy
        !> The law's tension and derivative for lambda > 1 (called by get_force).
        procedure(get_taut_force_interface), deferred :: get_taut_force
        !> The law's energy for lambda > 1 (called by get_energy).
        procedure(get_taut_energy_interface), deferred :: get_taut_energy
        !> A positive scale of df/dlambda near lambda = 1 (used to size regularisations).
        procedure(get_reference_stiffness_interface), deferred :: get_reference_stiffness
        !> The stretch at which the yarn carries a given tension (the law's inverse).
        procedure :: get_stretch_at_force
    end type force_law_type

    abstract interface
        pure subroutine get_taut_force_interface(self, stretch, force, dforce)
            import :: force_law_type, wp
            class(force_law_type), intent(in) :: self
            real(wp), intent(in) :: stretch
            real(wp), intent(out) :: force, dforce
        end subroutine get_taut_force_interface

        pure function get_taut_energy_interface(self, stretch) result(energy)
            import :: force_law_type, wp
            class(force_law_type), intent(in) :: self
            real(wp), intent(in) :: stretch
            real(wp) :: energy
        end function get_taut_energy_interface

        pure function get_reference_stiffness_interface(self) result(stiffness)
            import :: force_law_type, wp
            class(force_law_type), intent(in) :: self
            real(wp) :: stiffness
        end function get_reference_stiffness_interface
    end interface

contains

    !> Zero when slack (lambda <= 1), else the law's taut branch.
    pure subroutine get_force(self, stretch, force, dforce)
        class(force_law_type), intent(in) :: self
        real(wp), intent(in) :: stretch
        real(wp), intent(out) :: force, dforce

        if (stretch <= 1.0_wp) then
            force = 0.0_wp
            dforce = 0.0_wp
        else
            call self%get_taut_force(stretch, force, dforce)
        end if
    end subroutine get_force

    !> Zero when slack (lambda <= 1), else the law's taut branch.
    pure function get_energy(self, stretch) result(energy)
        class(force_law_type), intent(in) :: self
        real(wp), intent(in) :: stretch
        real(wp) :: energy

        if (stretch <= 1.0_wp) then
            energy = 0.0_wp
        else
            energy = self%get_taut_energy(stretch)
        end if
    end function get_energy

    !> The one bound on the stretch l / L0 of an element, however its reference length
    !> is given (prestress, length0, stretch): between 1 / max_stretch and max_stretch.
    elemental logical function is_usable_stretch(stretch)
        real(wp), intent(in) :: stretch

        is_usable_stretch = stretch >= 1.0_wp / max_stretch .and. stretch <= max_stretch
    end function is_usable_stretch

    !> Stretch lambda > 1 with f(lambda) = force > 0, by Newton's method safeguarded by
    !> bisection on a bracket grown from [1, 2]. `found` is false if no usable stretch
    !> (up to max_stretch) carries the force or the iteration does not converge.
    pure subroutine get_stretch_at_force(self, force, stretch, found)
        class(force_law_type), intent(in) :: self
        real(wp), intent(in) :: force
        real(wp), intent(out) :: stretch
        logical, intent(out) :: found
        integer, parameter :: max_iterations = 200
        real(wp), parameter :: tolerance = 8.0_wp * epsilon(1.0_wp)
        real(wp) :: low, high, f, df
        integer :: k

        found = .false.
        stretch = 1.0_wp
        if (.not. (force > 0.0_wp)) then
            found = force == 0.0_wp
            return
        end if
        low = 1.0_wp
        high = 2.0_wp
        do
            call self%get_force(high, f, df)
            if (f >= force .or. .not. is_usable_stretch(2.0_wp * high)) exit
            low = high
            high = 2.0_wp * high
        end do
        if (f < force) return
        stretch = 0.5_wp * (low + high)
        do k = 1, max_iterations
            call self%get_force(stretch, f, df)
            if (f > force) then
                high = stretch
            else
                low = stretch
            end if
            if (abs(f - force) <= tolerance * force .or. high - low <= tolerance * high) then
                found = .true.
                return
            end if
            ! Newton when it stays inside the bracket, bisection otherwise.
            if (df > 0.0_wp) stretch = stretch - (f - force) / df
            if (.not. (stretch > low .and. stretch < high)) stretch = 0.5_wp * (low + high)
        end do
    end subroutine get_stretch_at_force

end module yarnfort_material_force_law
