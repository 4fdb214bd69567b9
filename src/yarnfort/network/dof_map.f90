! SPDX-License-Identifier: MIT
!> Map between the solver's unknowns u and the nodal coordinates x of the network.
!> Constrained coordinates are eliminated, not penalised: every coordinate is
!>     x(i) = u(unknown(i)) + base(i) + sum_c p_c * delta(i, c) + (g(p_g) - 1) * gap(i),
!> with unknown(i) = 0 for a prescribed coordinate (then base is its initial value and
!> delta(i, c) its prescribed displacement at factor p_c = 1 of load channel c; today's
!> p_disp is one channel). A free coordinate has base = delta = 0. p_g is the factor of
!> channel gap_channel (p_disp).
!> Several coordinates may share one unknown: a periodic image (eq. 53; base is the
!> offset, delta the macroscopic stretch) or the far side of a gap-holder (gap is the
!> holder's offset, scaled by the gap factor g, a piecewise-linear function of p_disp).
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
        !> Prescribed displacement per coordinate and load channel (n_coordinates, n_channels).
        real(wp), allocatable :: delta(:, :)
        !> Gap-holder offsets (zero where there is none), the gap factor's knots and the
        !> channel whose factor they follow.
        real(wp), allocatable :: gap(:)
        integer :: gap_channel = 2
        real(wp), allocatable :: gap_p_disp(:), gap_factor(:)
    contains
        !> The gap factor g(p_disp) (1 without knots; constant beyond the end knots).
        procedure :: get_gap_factor
        !> Coordinates x (3, n_nodes) from unknowns u at the channels' factors.
        procedure :: expand
        !> The part of x that does not depend on u (x at u = 0).
        procedure :: get_prescribed
        !> x <- x + the unknowns' part (expand is get_prescribed, then this).
        procedure :: add_unknowns
        !> Unknowns u from coordinates x (the inverse on free coordinates).
        procedure :: restrict
        !> Add a full coordinate vector into unknown space (transpose of the map).
        procedure :: gather
    end type dof_map_type

contains

    pure subroutine expand(self, u, factors, x)
        class(dof_map_type), intent(in) :: self
        real(wp), intent(in) :: u(:), factors(:)
        real(wp), intent(out) :: x(:, :)

        call self%get_prescribed(factors, x)
        call self%add_unknowns(u, x)
    end subroutine expand

    !> A caller that keeps the prescribed part for its factors (it changes once per
    !> load step, u at every iterate) gets expand's x, bitwise, from add_unknowns alone.
    pure subroutine get_prescribed(self, factors, x)
        class(dof_map_type), intent(in) :: self
        real(wp), intent(in) :: factors(:)
        real(wp), intent(out) :: x(:, :)
        integer :: i, node, k, c
        real(wp) :: gap_change

        gap_change = 0.0_wp
        if (allocated(self%gap)) then
            if (self%gap_channel >= 1 .and. self%gap_channel <= size(factors)) &
                gap_change = self%get_gap_factor(factors(self%gap_channel)) - 1.0_wp
        end if
        do i = 1, size(self%unknown)
            node = (i - 1) / 3 + 1
            k = i - 3 * (node - 1)
            x(k, node) = self%base(i)
            do c = 1, size(self%delta, 2)
                x(k, node) = x(k, node) + factors(c) * self%delta(i, c)
            end do
            if (allocated(self%gap)) x(k, node) = x(k, node) + gap_change * self%gap(i)
        end do
    end subroutine get_prescribed

    pure subroutine add_unknowns(self, u, x)
        class(dof_map_type), intent(in) :: self
        real(wp), intent(in) :: u(:)
        real(wp), intent(inout) :: x(:, :)
        integer :: i, node, k

        do i = 1, size(self%unknown)
            if (self%unknown(i) <= 0) cycle
            node = (i - 1) / 3 + 1
            k = i - 3 * (node - 1)
            x(k, node) = x(k, node) + u(self%unknown(i))
        end do
    end subroutine add_unknowns

    pure real(wp) function get_gap_factor(self, p_disp) result(factor)
        class(dof_map_type), intent(in) :: self
        real(wp), intent(in) :: p_disp
        integer :: i, n
        real(wp) :: w

        factor = 1.0_wp
        if (.not. allocated(self%gap_factor)) return
        n = size(self%gap_factor)
        if (n == 0) return
        if (p_disp <= self%gap_p_disp(1)) then
            factor = self%gap_factor(1)
        else if (p_disp >= self%gap_p_disp(n)) then
            factor = self%gap_factor(n)
        else
            do i = 1, n - 1
                if (p_disp <= self%gap_p_disp(i + 1)) exit
            end do
            w = (p_disp - self%gap_p_disp(i)) / (self%gap_p_disp(i + 1) - self%gap_p_disp(i))
            factor = (1.0_wp - w) * self%gap_factor(i) + w * self%gap_factor(i + 1)
        end if
    end function get_gap_factor

    !> The inverse of expand at p_disp = 0 with gap factor 1 (base offsets only): for
    !> initial positions, where followers sit at their leaders' offsets.
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
