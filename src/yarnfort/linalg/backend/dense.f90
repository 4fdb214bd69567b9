! SPDX-License-Identifier: MIT
!> Dense LU with partial pivoting (LAPACK dgetrf/dgetrs) on a dense copy of the CSC
!> matrix: a reference for tests and a solver for tiny systems (memory and time grow as
!> n**2 and n**3).
module yarnfort_linalg_backend_dense
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_linalg_backend_direct, only: direct_solver_type
    use yarnfort_text, only: format_integer
    implicit none
    private

    public :: dense_solver_type, dense_max_order

    !> Largest order accepted: LAPACK's default integer, and a dense copy of 8*n**2 bytes.
    integer(ik), parameter :: dense_max_order = 46340

    interface
        !> LAPACK LU factorisation with partial pivoting (reference interface).
        subroutine dgetrf(m, n, a, lda, ipiv, info)
            import :: wp
            integer, intent(in) :: m, n, lda
            real(wp), intent(inout) :: a(lda, *)
            integer, intent(out) :: ipiv(*)
            integer, intent(out) :: info
        end subroutine dgetrf

        !> LAPACK solve with the factors of dgetrf.
        subroutine dgetrs(trans, n, nrhs, a, lda, ipiv, b, ldb, info)
            import :: wp
            character(len=1), intent(in) :: trans
            integer, intent(in) :: n, nrhs, lda, ldb
            real(wp), intent(in) :: a(lda, *)
            integer, intent(in) :: ipiv(*)
            real(wp), intent(inout) :: b(ldb, *)
            integer, intent(out) :: info
        end subroutine dgetrs
    end interface

    !> Dense LAPACK solver (no C handles; destroy only frees memory).
    type, extends(direct_solver_type) :: dense_solver_type
        private
        !> Dense matrix, overwritten by its LU factors.
        real(wp), allocatable :: lu(:, :)
        integer, allocatable :: pivots(:)
    contains
        procedure :: analyse_pattern
        procedure :: factor_values
        procedure :: solve_rhs_columns
        procedure :: release
        procedure :: get_name
    end type dense_solver_type

contains

    !> Allocate the dense matrix.
    subroutine analyse_pattern(self, error)
        class(dense_solver_type), intent(inout) :: self
        type(error_type), allocatable, intent(out) :: error

        if (self%n > dense_max_order) then
            call fatal_error(error, 'dense: matrix order n = ' // format_integer(self%n) &
                // ' exceeds dense_max_order = ' // format_integer(dense_max_order))
            return
        end if
        allocate(self%lu(self%n, self%n), self%pivots(self%n))
    end subroutine analyse_pattern

    !> Scatter the values into the dense matrix and factor it; singular is an error.
    subroutine factor_values(self, values, error)
        class(dense_solver_type), intent(inout) :: self
        real(wp), intent(in) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        integer(ik) :: j, k
        integer :: info, n

        n = int(self%n)
        self%lu(:, :) = 0.0_wp
        do j = 1, self%n
            do k = self%col_ptr(j) + 1, self%col_ptr(j + 1)
                self%lu(self%row_index(k) + 1, j) = values(k)
            end do
        end do
        call dgetrf(n, n, self%lu, n, self%pivots, info)
        if (info > 0) then
            call self%fail(error, 'factorisation', 'matrix is singular ' &
                // '(dgetrf: U(' // format_integer(int(info, ik)) // ',' &
                // format_integer(int(info, ik)) // ') is exactly zero)')
        else if (info < 0) then
            call fatal_error(error, 'dense: dgetrf rejected argument ' &
                // format_integer(int(-info, ik)))
        end if
    end subroutine factor_values

    !> Overwrite each column of rhs with its solution (one dgetrs for all of them).
    subroutine solve_rhs_columns(self, rhs, error)
        class(dense_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: rhs(:, :)
        type(error_type), allocatable, intent(out) :: error
        integer :: info, n

        n = int(self%n)
        call dgetrs('N', n, size(rhs, 2), self%lu, n, self%pivots, rhs, n, info)
        if (info /= 0) then
            call fatal_error(error, 'dense: dgetrs rejected argument ' &
                // format_integer(int(-info, ik)))
        end if
    end subroutine solve_rhs_columns

    !> Free the dense matrix.
    subroutine release(self)
        class(dense_solver_type), intent(inout) :: self

        if (allocated(self%lu)) deallocate(self%lu)
        if (allocated(self%pivots)) deallocate(self%pivots)
    end subroutine release

    pure function get_name(self) result(name)
        class(dense_solver_type), intent(in) :: self
        character(len=:), allocatable :: name

        name = 'dense'
    end function get_name

end module yarnfort_linalg_backend_dense
