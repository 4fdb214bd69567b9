! SPDX-License-Identifier: MIT
!> Sparse Cholesky (LL') with CHOLMOD's 64-bit API, for symmetric positive definite
!> matrices, the fastest measured on them (docs/decisions.md, 'Linear solver: CHOLMOD,
!> falling back to KLU, ...'). The caller passes the
!> full symmetric pattern; only the upper triangle (row <= column) is read (stype = 1),
!> entries below the diagonal are ignored. A matrix that is not positive definite gives
!> an error value saying so, and the caller may fall back to a general solver
!> (yarnfort_linalg_composite_fallback).
module yarnfort_linalg_backend_cholmod
    use, intrinsic :: iso_c_binding, only: c_int, c_long, c_double, c_ptr, c_null_ptr, &
        c_associated
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_linalg_backend_direct, only: direct_solver_type, describe_status
    use yarnfort_text, only: format_integer
    use yarnfort_linalg_binding_cholmod, only: cholmod_ok, cholmod_not_posdef, &
        cholmod_dsmall, cholmod_not_installed, cholmod_out_of_memory, cholmod_too_large, &
        cholmod_invalid, cholmod_gpu_problem, cholmod_no_handle, yarnfort_cholmod_create, &
        yarnfort_cholmod_free, yarnfort_cholmod_analyze, yarnfort_cholmod_factorize, &
        yarnfort_cholmod_solve
    implicit none
    private

    public :: cholmod_solver_type, supernodal_switch

    !> Supernodal factor (dense blocks, BLAS) where the analysis predicts at least this
    !> many flops per nonzero of L, else simplicial (CHOLMOD's default: 40): below it the
    !> dense blocks are too small to pay (docs/decisions.md, 'CHOLMOD: supernodal from 25
    !> flops per nonzero of L').
    real(wp), parameter :: supernodal_switch = 25.0_wp

    !> CHOLMOD solver. Owns a C handle: never copy an analysed object by assignment.
    type, extends(direct_solver_type) :: cholmod_solver_type
        private
        !> Opaque cholmod_shim.c handle (common, factor, solve workspaces).
        type(c_ptr) :: handle = c_null_ptr
    contains
        procedure :: analyse_pattern
        procedure :: factor_values
        procedure :: solve_rhs_columns
        procedure :: release
        procedure :: get_name
        final :: finalize
    end type cholmod_solver_type

contains

    !> Order the pattern and build the symbolic factor.
    subroutine analyse_pattern(self, error)
        class(cholmod_solver_type), intent(inout) :: self
        type(error_type), allocatable, intent(out) :: error
        integer(c_int) :: status

        self%handle = yarnfort_cholmod_create(real(supernodal_switch, c_double))
        if (.not. c_associated(self%handle)) then
            call fatal_error(error, 'cholmod: could not start CHOLMOD (cholmod_l_start)')
            return
        end if
        status = yarnfort_cholmod_analyze(self%handle, self%n, self%col_ptr, self%row_index)
        if (status < cholmod_ok) call self%fail(error, 'symbolic analysis', &
            status_message(status))
    end subroutine analyse_pattern

    !> Numeric LL' factorisation; not positive definite is an error.
    subroutine factor_values(self, values, error)
        class(cholmod_solver_type), intent(inout) :: self
        real(wp), intent(in) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        integer(c_int) :: status
        integer(c_long) :: minor

        status = yarnfort_cholmod_factorize(self%handle, self%n, values, minor)
        if (status == cholmod_ok .or. status == cholmod_dsmall) then
            return
        else if (status == cholmod_not_posdef) then
            call self%fail(error, 'factorisation', 'matrix is not positive ' &
                // 'definite (pivot of column ' // format_integer(int(minor, ik)) &
                // ' in the fill-reducing order is not positive; use umfpack or klu)')
        else
            call self%fail(error, 'factorisation', status_message(status))
        end if
    end subroutine factor_values

    !> All columns in one CHOLMOD solve: the supernodal factor's dense blocks are applied
    !> to the m columns together (BLAS 3) instead of m times to one (workspaces allocated
    !> by the first solve, again when m changes).
    subroutine solve_rhs_columns(self, rhs, error)
        class(cholmod_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: rhs(:, :)
        type(error_type), allocatable, intent(out) :: error
        integer(c_int) :: status

        status = yarnfort_cholmod_solve(self%handle, self%n, size(rhs, 2, kind=c_long), rhs)
        if (status < cholmod_ok) then
            call self%fail(error, 'solve', status_message(status))
        end if
    end subroutine solve_rhs_columns

    !> Free the CHOLMOD handle.
    subroutine release(self)
        class(cholmod_solver_type), intent(inout) :: self

        if (c_associated(self%handle)) call yarnfort_cholmod_free(self%handle)
        self%handle = c_null_ptr
    end subroutine release

    pure function get_name(self) result(name)
        class(cholmod_solver_type), intent(in) :: self
        character(len=:), allocatable :: name

        name = 'cholmod'
    end function get_name

    subroutine finalize(self)
        type(cholmod_solver_type), intent(inout) :: self

        call self%destroy()
    end subroutine finalize

    !> The cholmod_core.h name of a status code and what it means.
    pure function status_message(status) result(message)
        integer(c_int), intent(in) :: status
        character(len=:), allocatable :: message

        message = describe_status(int(status, c_long), [integer(c_long) :: &
            cholmod_not_posdef, cholmod_not_installed, cholmod_out_of_memory, &
            cholmod_too_large, cholmod_invalid, cholmod_gpu_problem, cholmod_no_handle], &
            [character(len=52) :: &
            'matrix is not positive definite (CHOLMOD_NOT_POSDEF)', &
            'method not installed (CHOLMOD_NOT_INSTALLED)', &
            'out of memory (CHOLMOD_OUT_OF_MEMORY)', &
            'integer overflow (CHOLMOD_TOO_LARGE)', &
            'invalid input (CHOLMOD_INVALID)', &
            'GPU error (CHOLMOD_GPU_PROBLEM)', &
            'no CHOLMOD handle'], 'CHOLMOD')
    end function status_message

end module yarnfort_linalg_backend_cholmod
