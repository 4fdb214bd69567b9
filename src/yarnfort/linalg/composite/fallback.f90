! SPDX-License-Identifier: MIT
!> A linear solver that tries a fast specialised solver first (CHOLMOD: symmetric
!> positive definite only) and switches for good to a general one (KLU) the first time
!> the specialised factorisation fails (e.g. "not positive definite").
module yarnfort_linalg_composite_fallback
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_backend_direct, only: direct_solver_type
    implicit none
    private

    public :: fallback_solver_type

    !> The pattern (checked and kept by direct_solver_type) analyses the general solver
    !> when switching.
    type, extends(direct_solver_type) :: fallback_solver_type
        !> The solver in use: the specialised one (set by the owner) until its first failed
        !> factorisation, then the general one, moved here from `general` (set by the owner).
        class(linear_solver_type), allocatable :: active, general
        logical :: switched = .false.
    contains
        procedure :: analyse_pattern
        procedure :: factor_values
        procedure :: solve_rhs_columns
        procedure :: release
        procedure :: get_name
    end type fallback_solver_type

contains

    subroutine analyse_pattern(self, error)
        class(fallback_solver_type), intent(inout) :: self
        type(error_type), allocatable, intent(out) :: error

        call self%active%analyse(self%n, int(self%col_ptr, ik), int(self%row_index, ik), error)
    end subroutine analyse_pattern

    !> On the first failure, switch to the general solver for good and factor with it.
    subroutine factor_values(self, values, error)
        class(fallback_solver_type), intent(inout) :: self
        real(wp), intent(in) :: values(:)
        type(error_type), allocatable, intent(out) :: error

        call self%active%factor(values, error)
        if (self%switched .or. .not. allocated(error)) return
        deallocate(error)
        self%switched = .true.
        call self%active%destroy()
        call move_alloc(self%general, self%active)
        call self%analyse_pattern(error)
        if (allocated(error)) return
        call self%active%factor(values, error)
    end subroutine factor_values

    subroutine solve_rhs_columns(self, rhs, error)
        class(fallback_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: rhs(:, :)
        type(error_type), allocatable, intent(out) :: error

        call self%active%solve_columns(rhs, error)
    end subroutine solve_rhs_columns

    subroutine release(self)
        class(fallback_solver_type), intent(inout) :: self

        if (allocated(self%active)) call self%active%destroy()
        if (allocated(self%general)) call self%general%destroy()
    end subroutine release

    pure function get_name(self) result(name)
        class(fallback_solver_type), intent(in) :: self
        character(len=:), allocatable :: name
        if (self%switched) then
            name = self%active%get_name()
        else
            name = self%active%get_name() // ' (falls back to ' // self%general%get_name() &
                // ')'
        end if
    end function get_name

end module yarnfort_linalg_composite_fallback
