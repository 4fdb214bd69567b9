! SPDX-License-Identifier: MIT
!> One interface for the sparse direct solvers (UMFPACK, KLU, CHOLMOD, dense LAPACK).
!> A solver sees a square matrix in compressed sparse column (CSC) form with 0-based
!> 64-bit indices, the layout of a SUNDIALS SUNSparseMatrix.
module yarnfort_linalg_linear_solver
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    implicit none
    private

    public :: linear_solver_type

    !> Call sequence: analyse once per sparsity pattern, then factor for each new set of
    !> values, then solve any number of times. `analyse` may be called again when the
    !> pattern changes; the solver keeps whatever it needs (copies or its own objects).
    type, abstract :: linear_solver_type
    contains
        !> Symbolic analysis of the pattern: n columns, col_ptr(0:n) (size n+1),
        !> row_index(1:nnz) 0-based. Kept until the next call of `analyse` or `destroy`.
        procedure(analyse_interface), deferred :: analyse
        !> Numeric factorisation of the matrix with the analysed pattern and these values.
        procedure(factor_interface), deferred :: factor
        !> Overwrite rhs with the solution of A x = rhs using the last factorisation: the
        !> one-column case of `solve_columns`.
        procedure, non_overridable :: solve
        !> Overwrite each column of rhs (n x m) with its solution; each column's arithmetic
        !> is that of a single solve.
        procedure(solve_columns_interface), deferred :: solve_columns
        !> Free every handle and buffer (safe to call twice).
        procedure(destroy_interface), deferred :: destroy
        !> Short lowercase name, e.g. 'umfpack'.
        procedure(get_name_interface), deferred :: get_name
    end type linear_solver_type

    abstract interface
        subroutine analyse_interface(self, n, col_ptr, row_index, error)
            import :: linear_solver_type, ik, error_type
            class(linear_solver_type), intent(inout) :: self
            integer(ik), intent(in) :: n
            integer(ik), intent(in) :: col_ptr(:), row_index(:)
            type(error_type), allocatable, intent(out) :: error
        end subroutine analyse_interface

        subroutine factor_interface(self, values, error)
            import :: linear_solver_type, wp, error_type
            class(linear_solver_type), intent(inout) :: self
            real(wp), intent(in) :: values(:)
            type(error_type), allocatable, intent(out) :: error
        end subroutine factor_interface

        subroutine solve_columns_interface(self, rhs, error)
            import :: linear_solver_type, wp, error_type
            class(linear_solver_type), intent(inout) :: self
            real(wp), intent(inout) :: rhs(:, :)
            type(error_type), allocatable, intent(out) :: error
        end subroutine solve_columns_interface

        subroutine destroy_interface(self)
            import :: linear_solver_type
            class(linear_solver_type), intent(inout) :: self
        end subroutine destroy_interface

        pure function get_name_interface(self) result(name)
            import :: linear_solver_type
            class(linear_solver_type), intent(in) :: self
            character(len=:), allocatable :: name
        end function get_name_interface
    end interface

contains

    subroutine solve(self, rhs, error)
        class(linear_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: rhs(:)
        type(error_type), allocatable, intent(out) :: error

        call solve_one_column(self, size(rhs, kind=ik), rhs, error)
    end subroutine solve

    !> rhs seen as the n x 1 matrix it is.
    subroutine solve_one_column(self, n, rhs, error)
        class(linear_solver_type), intent(inout) :: self
        integer(ik), intent(in) :: n
        real(wp), intent(inout) :: rhs(n, 1)
        type(error_type), allocatable, intent(out) :: error

        call self%solve_columns(rhs, error)
    end subroutine solve_one_column

end module yarnfort_linalg_linear_solver
