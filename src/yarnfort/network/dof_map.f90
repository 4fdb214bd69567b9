! SPDX-License-Identifier: MIT
!> Map between the solver's unknowns u and the nodal coordinates x of the network.
!> Constrained coordinates are eliminated, not penalised: every coordinate is
!>     x(i) = u(unknown(i)) + base(i) + p_disp * delta(i),
!> with unknown(i) = 0 for a prescribed coordinate (then base is its initial value and
!> delta its prescribed displacement at p_disp = 1). A free coordinate has base = delta = 0.
!> Several coordinates may share one unknown (periodic pairs, with base as the offset).
module yarnfort_network_dof_map
    use yarnfort_kinds, only: wp
    implicit none
    private

    public :: dof_map_type

    type :: dof_map_type
        integer :: n_unknowns = 0
        !> Unknown of each coordinate 3*(node-1)+k, or 0 if prescribed.
        integer, allocatable :: unknown(:)
        real(wp), allocatable :: base(:)
        real(wp), allocatable :: delta(:)
    contains
        !> Coordinates x (3, n_nodes) from unknowns u at displacement factor p_disp.
        procedure :: expand
        !> Unknowns u from coordinates x (the inverse on free coordinates).
        procedure :: restrict
        !> Add a full coordinate vector into unknown space (transpose of the map).
        procedure :: gather
    end type dof_map_type

contains

    pure subroutine expand(self, u, p_disp, x)
        class(dof_map_type), intent(in) :: self
        real(wp), intent(in) :: u(:), p_disp
        real(wp), intent(out) :: x(:, :)
        integer :: i, node, k

        do i = 1, size(self%unknown)
            node = (i - 1) / 3 + 1
            k = i - 3 * (node - 1)
            x(k, node) = self%base(i) + p_disp * self%delta(i)
            if (self%unknown(i) > 0) x(k, node) = x(k, node) + u(self%unknown(i))
        end do
    end subroutine expand

    pure subroutine restrict(self, x, u)
        class(dof_map_type), intent(in) :: self
        real(wp), intent(in) :: x(:, :)
        real(wp), intent(out) :: u(:)
        integer :: i, node, k

        u = 0.0_wp
        do i = 1, size(self%unknown)
            if (self%unknown(i) == 0) cycle
            node = (i - 1) / 3 + 1
            k = i - 3 * (node - 1)
            u(self%unknown(i)) = x(k, node) - self%base(i)
        end do
    end subroutine restrict

    pure subroutine gather(self, full, reduced)
        class(dof_map_type), intent(in) :: self
        real(wp), intent(in) :: full(:)
        real(wp), intent(out) :: reduced(:)
        integer :: i

        reduced = 0.0_wp
        do i = 1, size(self%unknown)
            if (self%unknown(i) > 0) reduced(self%unknown(i)) = reduced(self%unknown(i)) + full(i)
        end do
    end subroutine gather

end module yarnfort_network_dof_map
