! SPDX-License-Identifier: MIT
!> The bookkeeping every linear solver over a kept pattern shares (UMFPACK, KLU, CHOLMOD,
!> dense LAPACK and the CHOLMOD-then-KLU fallback): the copy of the CSC pattern read
!> again at factor time, the checks of the call sequence and of array sizes, forgetting
!> it all on destroy, and the messages of a failed library call and of a status code.
!> Each solver keeps only its library calls, its own objects and its table of codes.
module yarnfort_linalg_direct
    use, intrinsic :: iso_c_binding, only: c_long
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_csc_pattern, only: check_csc_pattern, check_array_size, format_integer
    implicit none
    private

    public :: direct_solver_type, describe_status

    !> A linear solver that keeps the pattern (as 64-bit C arrays, what the libraries read).
    type, abstract, extends(linear_solver_type) :: direct_solver_type
        !> Matrix order, 0 before `analyse`.
        integer(ik) :: n = 0
        !> Copies of the pattern (the libraries read them again at factor time).
        integer(c_long), allocatable :: col_ptr(:), row_index(:)
    contains
        !> Check a pattern and keep a copy of it (after destroying what was there).
        procedure :: keep_pattern
        !> Keep a copy of a pattern without checking it (a solver that only delegates).
        procedure :: copy_pattern
        !> Check that `factor` may run (analysed) with these values.
        procedure :: check_factor_call
        !> Check that `solve` may run (`factored`) on this right-hand side.
        procedure :: check_solve_call
        !> Drop the pattern copy (for `destroy`).
        procedure :: forget_pattern
        !> Set `error` to '<name>: <stage> failed: <reason>'.
        procedure :: fail
    end type direct_solver_type

contains

    subroutine keep_pattern(self, n, col_ptr, row_index, error)
        class(direct_solver_type), intent(inout) :: self
        integer(ik), intent(in) :: n
        integer(ik), intent(in) :: col_ptr(:), row_index(:)
        type(error_type), allocatable, intent(out) :: error

        call self%destroy()
        call check_csc_pattern(self%get_name(), n, col_ptr, row_index, error)
        if (allocated(error)) return
        call self%copy_pattern(n, col_ptr, row_index)
    end subroutine keep_pattern

    subroutine copy_pattern(self, n, col_ptr, row_index)
        class(direct_solver_type), intent(inout) :: self
        integer(ik), intent(in) :: n
        integer(ik), intent(in) :: col_ptr(:), row_index(:)

        self%col_ptr = col_ptr(1:n + 1)
        self%row_index = row_index(1:col_ptr(n + 1))
    end subroutine copy_pattern

    subroutine check_factor_call(self, analysed, values, error)
        class(direct_solver_type), intent(in) :: self
        logical, intent(in) :: analysed
        real(wp), intent(in) :: values(:)
        type(error_type), allocatable, intent(out) :: error

        if (.not. analysed) then
            call fatal_error(error, self%get_name() // ': factor called before analyse')
            return
        end if
        call check_array_size(self%get_name(), 'values', size(values, kind=ik), &
            int(size(self%row_index), ik), error, at_least=.true.)
    end subroutine check_factor_call

    subroutine check_solve_call(self, factored, rhs, error)
        class(direct_solver_type), intent(in) :: self
        logical, intent(in) :: factored
        real(wp), intent(in) :: rhs(:)
        type(error_type), allocatable, intent(out) :: error

        if (.not. factored) then
            call fatal_error(error, self%get_name() &
                // ': solve called without a valid factorisation')
            return
        end if
        call check_array_size(self%get_name(), 'rhs', size(rhs, kind=ik), self%n, error)
    end subroutine check_solve_call

    subroutine forget_pattern(self)
        class(direct_solver_type), intent(inout) :: self

        self%n = 0
        if (allocated(self%col_ptr)) deallocate(self%col_ptr)
        if (allocated(self%row_index)) deallocate(self%row_index)
    end subroutine forget_pattern

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

end module yarnfort_linalg_direct
