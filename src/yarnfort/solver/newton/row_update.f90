! SPDX-License-Identifier: MIT
!> A linear solver of its own: the matrix whose factors a linear solver holds with a few
!> rows replaced, solved with those factors and a low-rank (Sherman-Morrison-Woodbury)
!> correction, without a factorisation.
module yarnfort_solver_newton_row_update
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    use yarnfort_linalg_backend_dense, only: dense_solver_type
    use yarnfort_solver_sunlinsol_adapter, only: adapter_type, solve_counted, &
        solve_columns_counted
    implicit none
    private

    public :: row_update_type, new_row_update

    !> J + U V, J the matrix the adapter's solver holds the factors of, U the unit
    !> columns of the replaced rows and V their new values less J's.
    type :: row_update_type
        !> V's entries: the replaced row's slot (its place in `rows`), column, value.
        integer, allocatable :: entry_slot(:), entry_column(:)
        real(wp), allocatable :: entry_value(:)
        !> Z = J^-1 U and the factors of the capacitance matrix C = I + V Z.
        real(wp), allocatable :: z(:, :)
        type(dense_solver_type) :: correction
    contains
        !> x <- (J + U V)^-1 x.
        procedure :: solve => solve_updated
    end type row_update_type

contains

    !> The update of the rows `rows` of the matrix of CSC pattern (col_ptr, row_index)
    !> whose factors the adapter's solver holds (values `kept_values`) to the new values
    !> `values` of those rows (the rest of `values` is not read).
    subroutine new_row_update(self, adapter, rows, col_ptr, row_index, values, kept_values, &
            error)
        type(row_update_type), intent(out) :: self
        type(adapter_type), intent(inout) :: adapter
        integer, intent(in) :: rows(:)
        integer(ik), intent(in) :: col_ptr(:), row_index(:)
        real(wp), intent(in) :: values(:), kept_values(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: capacity(:, :)
        integer, allocatable :: slot(:)
        integer :: n, n_rows, n_entries, a, e, i, j

        n = size(col_ptr) - 1
        n_rows = size(rows)
        allocate(slot(n), source=0)
        do a = 1, n_rows
            slot(rows(a)) = a
        end do
        n_entries = count(slot(row_index + 1) > 0)
        allocate(self%entry_slot(n_entries), self%entry_column(n_entries), &
            self%entry_value(n_entries))
        i = 0
        do j = 1, n
            do e = int(col_ptr(j)) + 1, int(col_ptr(j + 1))
                a = slot(row_index(e) + 1)
                if (a == 0) cycle
                i = i + 1
                self%entry_slot(i) = a
                self%entry_column(i) = j
                self%entry_value(i) = values(e) - kept_values(e)
            end do
        end do
        ! Z = J^-1 U (U: the unit columns of the rows), C = I + V Z.
        allocate(self%z(n, n_rows), capacity(n_rows, n_rows))
        self%z = 0.0_wp
        do a = 1, n_rows
            self%z(rows(a), a) = 1.0_wp
        end do
        call solve_columns_counted(adapter, self%z, error)
        if (allocated(error)) return
        capacity = 0.0_wp
        do a = 1, n_rows
            capacity(a, a) = 1.0_wp
        end do
        do i = 1, n_entries
            capacity(self%entry_slot(i), :) = capacity(self%entry_slot(i), :) &
                + self%entry_value(i) * self%z(self%entry_column(i), :)
        end do
        call self%correction%analyse(int(n_rows, ik), [(int(a, ik) * n_rows, a = 0, n_rows)], &
            [((int(i, ik), i = 0, n_rows - 1), a = 1, n_rows)], error)
        if (allocated(error)) return
        call self%correction%factor(reshape(capacity, [n_rows * n_rows]), error)
    end subroutine new_row_update

    !> x <- (J + U V)^-1 x = J^-1 x - Z C^-1 V J^-1 x, with the adapter's factors of J.
    subroutine solve_updated(self, adapter, x, error)
        class(row_update_type), intent(inout) :: self
        type(adapter_type), intent(inout) :: adapter
        real(wp), intent(inout) :: x(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: y(:)
        integer :: i, b

        call solve_counted(adapter, x, error)
        if (allocated(error)) return
        allocate(y(size(self%z, 2)))
        y = 0.0_wp
        do i = 1, size(self%entry_slot)
            y(self%entry_slot(i)) = y(self%entry_slot(i)) &
                + self%entry_value(i) * x(self%entry_column(i))
        end do
        call self%correction%solve(y, error)
        if (allocated(error)) return
        do b = 1, size(y)
            x = x - y(b) * self%z(:, b)
        end do
    end subroutine solve_updated

end module yarnfort_solver_newton_row_update
