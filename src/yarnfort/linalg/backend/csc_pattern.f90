! SPDX-License-Identifier: MIT
!> Checks shared by the linear solvers: a square CSC pattern with 0-based 64-bit indices,
!> sorted strictly increasing row indices in each column (UMFPACK requires this), and
!> value and right-hand-side arrays of the right size.
module yarnfort_linalg_backend_csc_pattern
    use yarnfort_kinds, only: ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: format_integer
    implicit none
    private

    public :: check_csc_pattern, check_array_size

contains

    !> Fail unless n >= 1, size(col_ptr) == n + 1, col_ptr(1) == 0, col_ptr is
    !> non-decreasing, size(row_index) >= col_ptr(n+1) and, in each column, the row
    !> indices lie in 0..n-1 and increase strictly (no duplicates).
    pure subroutine check_csc_pattern(solver, n, col_ptr, row_index, error)
        character(len=*), intent(in) :: solver
        integer(ik), intent(in) :: n
        integer(ik), intent(in) :: col_ptr(:), row_index(:)
        type(error_type), allocatable, intent(out) :: error
        integer(ik) :: j, k, nnz

        if (n < 1) then
            call fatal_error(error, solver // ': matrix order n = ' // format_integer(n) &
                // ' must be at least 1')
            return
        end if
        if (size(col_ptr, kind=ik) /= n + 1) then
            call fatal_error(error, solver // ': col_ptr has ' &
                // format_integer(size(col_ptr, kind=ik)) // ' entries, expected n + 1 = ' &
                // format_integer(n + 1))
            return
        end if
        if (col_ptr(1) /= 0) then
            call fatal_error(error, solver // ': col_ptr(0) = ' // format_integer(col_ptr(1)) &
                // ', expected 0 (indices are 0-based)')
            return
        end if
        do j = 1, n
            if (col_ptr(j + 1) < col_ptr(j)) then
                call fatal_error(error, solver // ': col_ptr decreases at column ' &
                    // format_integer(j - 1))
                return
            end if
        end do
        nnz = col_ptr(n + 1)
        if (size(row_index, kind=ik) < nnz) then
            call fatal_error(error, solver // ': row_index has ' &
                // format_integer(size(row_index, kind=ik)) // ' entries, col_ptr(n) = ' &
                // format_integer(nnz) // ' needs more')
            return
        end if
        do j = 1, n
            do k = col_ptr(j) + 1, col_ptr(j + 1)
                if (row_index(k) < 0 .or. row_index(k) >= n) then
                    call fatal_error(error, solver // ': row index ' &
                        // format_integer(row_index(k)) // ' in column ' &
                        // format_integer(j - 1) // ' is outside 0..n-1')
                    return
                end if
                if (k > col_ptr(j) + 1) then
                    if (row_index(k) <= row_index(k - 1)) then
                        call fatal_error(error, solver // ': row indices of column ' &
                            // format_integer(j - 1) &
                            // ' are not strictly increasing (unsorted or duplicate)')
                        return
                    end if
                end if
            end do
        end do
    end subroutine check_csc_pattern

    !> Fail unless an array called `what` has exactly (or, with `at_least`, at least)
    !> `expected` entries.
    pure subroutine check_array_size(solver, what, actual, expected, error, at_least)
        character(len=*), intent(in) :: solver, what
        integer(ik), intent(in) :: actual, expected
        type(error_type), allocatable, intent(out) :: error
        logical, intent(in), optional :: at_least
        logical :: minimum

        minimum = .false.
        if (present(at_least)) minimum = at_least
        if (actual == expected .or. (minimum .and. actual > expected)) return
        if (minimum) then
            call fatal_error(error, solver // ': ' // what // ' has ' &
                // format_integer(actual) // ' entries, expected at least ' &
                // format_integer(expected))
        else
            call fatal_error(error, solver // ': ' // what // ' has ' &
                // format_integer(actual) // ' entries, expected ' // format_integer(expected))
        end if
    end subroutine check_array_size

end module yarnfort_linalg_backend_csc_pattern
