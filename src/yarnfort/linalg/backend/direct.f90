! SPDX-License-Identifier: MIT
!> The bookkeeping every linear solver over a kept pattern shares (UMFPACK, KLU, CHOLMOD,
!> dense LAPACK and the CHOLMOD-then-KLU fallback): `analyse`, `factor` and
!> `solve_columns` check the pattern, the call sequence and the array sizes, keep the
!> copy of the CSC pattern the libraries read again at factor time and the state
!> (analysed, factored), and call the solver's own `analyse_pattern`, `factor_values` and
!> `solve_rhs_columns`, which hold only the library calls; `destroy` calls the solver's
!> `release` and drops the pattern and the state. Also the messages of a failed library
!> call and of a status code.
module yarnfort_linalg_backend_direct
    use, intrinsic :: iso_c_binding, only: c_long
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_backend_csc_pattern, only: check_csc_pattern, check_array_size
    use yarnfort_text, only: format_integer
    implicit none
    private

    public :: direct_solver_type, describe_status, get_subpattern

    !> A linear solver that keeps the pattern (as 64-bit C arrays, what the libraries read).
    type, abstract, extends(linear_solver_type) :: direct_solver_type
        !> Matrix order, 0 before a successful `analyse`.
        integer(ik) :: n = 0
        !> Copies of the pattern (the libraries read them again at factor time).
        integer(c_long), allocatable :: col_ptr(:), row_index(:)
        !> The last `factor` succeeded (and nothing was destroyed since).
        logical :: factored = .false.
    contains
        procedure :: analyse
        procedure :: factor
        procedure :: solve_columns
        procedure :: destroy
        !> The solver's analysis of the kept pattern (n, col_ptr, row_index are set); a
        !> failure destroys the solver.
        procedure(analyse_pattern_interface), deferred :: analyse_pattern
        !> The solver's factorisation of these values (enough of them, after analyse).
        procedure(factor_values_interface), deferred :: factor_values
        !> The solver's solve of n x m columns (m >= 1) with the last factorisation.
        procedure(solve_rhs_columns_interface), deferred :: solve_rhs_columns
        !> Free the solver's own handles and buffers (safe to call twice; for `destroy`).
        procedure(release_interface), deferred :: release
        !> Set `error` to '<name>: <stage> failed: <reason>'.
        procedure :: fail
    end type direct_solver_type

    abstract interface
        subroutine analyse_pattern_interface(self, error)
            import :: direct_solver_type, error_type
            class(direct_solver_type), intent(inout) :: self
            type(error_type), allocatable, intent(out) :: error
        end subroutine analyse_pattern_interface

        subroutine factor_values_interface(self, values, error)
            import :: direct_solver_type, wp, error_type
            class(direct_solver_type), intent(inout) :: self
            real(wp), intent(in) :: values(:)
            type(error_type), allocatable, intent(out) :: error
        end subroutine factor_values_interface

        subroutine solve_rhs_columns_interface(self, rhs, error)
            import :: direct_solver_type, wp, error_type
            class(direct_solver_type), intent(inout) :: self
            real(wp), intent(inout) :: rhs(:, :)
            type(error_type), allocatable, intent(out) :: error
        end subroutine solve_rhs_columns_interface

        subroutine release_interface(self)
            import :: direct_solver_type
            class(direct_solver_type), intent(inout) :: self
        end subroutine release_interface
    end interface

contains

    !> Check the pattern, keep a copy of it (after destroying what was there) and analyse it.
    subroutine analyse(self, n, col_ptr, row_index, error)
        class(direct_solver_type), intent(inout) :: self
        integer(ik), intent(in) :: n
        integer(ik), intent(in) :: col_ptr(:), row_index(:)
        type(error_type), allocatable, intent(out) :: error

        call self%destroy()
        call check_csc_pattern(self%get_name(), n, col_ptr, row_index, error)
        if (allocated(error)) return
        self%col_ptr = col_ptr
        self%row_index = row_index(1:col_ptr(n + 1))
        self%n = n
        call self%analyse_pattern(error)
        if (allocated(error)) call self%destroy()
    end subroutine analyse

    !> Factor the matrix with the analysed pattern and these values.
    subroutine factor(self, values, error)
        class(direct_solver_type), intent(inout) :: self
        real(wp), intent(in) :: values(:)
        type(error_type), allocatable, intent(out) :: error

        self%factored = .false.
        if (self%n == 0) then
            call fatal_error(error, self%get_name() // ': factor called before analyse')
            return
        end if
        call check_array_size(self%get_name(), 'values', size(values, kind=ik), &
            int(size(self%row_index), ik), error, at_least=.true.)
        if (allocated(error)) return
        call self%factor_values(values, error)
        self%factored = .not. allocated(error)
    end subroutine factor

    !> Overwrite each column of rhs with its solution, using the last factorisation.
    subroutine solve_columns(self, rhs, error)
        class(direct_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: rhs(:, :)
        type(error_type), allocatable, intent(out) :: error

        if (.not. self%factored) then
            call fatal_error(error, self%get_name() &
                // ': solve called without a valid factorisation')
            return
        end if
        call check_array_size(self%get_name(), 'rhs', size(rhs, 1, kind=ik), self%n, error)
        if (allocated(error) .or. size(rhs, 2) == 0) return
        call self%solve_rhs_columns(rhs, error)
    end subroutine solve_columns

    !> Free the solver's handles and buffers, the pattern copy and the state (safe to call
    !> twice).
    subroutine destroy(self)
        class(direct_solver_type), intent(inout) :: self

        call self%release()
        self%n = 0
        self%factored = .false.
        if (allocated(self%col_ptr)) deallocate(self%col_ptr)
        if (allocated(self%row_index)) deallocate(self%row_index)
    end subroutine destroy

    !> The pattern of the submatrix of a kept pattern (col_ptr, row_index) made of the rows
    !> and columns j with index(j) > 0, numbered index(j) (1..m, increasing with j):
    !> sub_col_ptr(m + 1) and 0-based sub_row_index, and for each of its entries the entry
    !> (1-based) of the whole pattern it comes from. For solvers that hand part of the
    !> matrix to another solver.
    pure subroutine get_subpattern(col_ptr, row_index, index, sub_col_ptr, sub_row_index, &
            source)
        integer(c_long), intent(in) :: col_ptr(:), row_index(:)
        integer(ik), intent(in) :: index(:)
        integer(ik), allocatable, intent(out) :: sub_col_ptr(:), sub_row_index(:), source(:)
        integer(ik) :: j, k, i, kept

        allocate(sub_col_ptr(count(index > 0) + 1), sub_row_index(size(row_index)), &
            source(size(row_index)))
        sub_col_ptr(1) = 0
        kept = 0
        do j = 1, size(col_ptr, kind=ik) - 1
            if (index(j) == 0) cycle
            do k = col_ptr(j) + 1, col_ptr(j + 1)
                i = row_index(k) + 1
                if (index(i) == 0) cycle
                kept = kept + 1
                sub_row_index(kept) = index(i) - 1
                source(kept) = k
            end do
            sub_col_ptr(index(j) + 1) = kept
        end do
        sub_row_index = sub_row_index(1:kept)
        source = source(1:kept)
    end subroutine get_subpattern

    subroutine fail(self, error, stage, reason)
        class(direct_solver_type), intent(in) :: self
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: stage, reason

        call fatal_error(error, self%get_name() // ': ' // stage // ' failed: ' // reason)
    end subroutine fail

    !> The text of a library status code from the library's table of codes and texts
    !> (its header's name and what it means), or '<library> status <code>'.
    pure function describe_status(status, codes, texts, library) result(message)
        integer(c_long), intent(in) :: status
        integer(c_long), intent(in) :: codes(:)
        character(len=*), intent(in) :: texts(:), library
        character(len=:), allocatable :: message
        integer :: k

        k = findloc(codes, status, dim=1)
        if (k > 0) then
            message = trim(texts(k))
        else
            message = library // ' status ' // format_integer(int(status, ik))
        end if
    end function describe_status

end module yarnfort_linalg_backend_direct
