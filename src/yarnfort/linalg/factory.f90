! SPDX-License-Identifier: MIT
!> Create a linear solver by name and choose the default one from the measured timings of
!> design.md section 5.
module yarnfort_linalg_factory
    use yarnfort_kinds, only: ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_umfpack, only: umfpack_solver_type
    use yarnfort_linalg_klu, only: klu_solver_type
    use yarnfort_linalg_cholmod, only: cholmod_solver_type
    use yarnfort_linalg_dense, only: dense_solver_type
    implicit none
    private

    public :: new_linear_solver, default_linear_solver_name
    public :: linear_solver_names, klu_max_order

    !> Names accepted by `new_linear_solver`.
    character(len=*), parameter :: linear_solver_names = "'umfpack', 'klu', 'cholmod', 'dense'"

    !> Largest order for which KLU is the default. Source: design.md section 5 (numeric
    !> refactorisation + one solve, woven-net tangents, 2 cores). At 1e3 DOFs KLU is the
    !> fastest (0.09 ms vs 0.1-0.36 ms CHOLMOD, 0.58 ms UMFPACK); at 1e4 it is 4x faster
    !> than UMFPACK and within 20 % of CHOLMOD (1.9 vs 1.6 ms), which covers unit cells.
    integer(ik), parameter :: klu_max_order = 10000_ik

contains

    !> Allocate `solver` as the solver called `name` ('umfpack', 'klu', 'cholmod' or
    !> 'dense'; case and surrounding blanks are ignored). Any old solver is destroyed.
    subroutine new_linear_solver(solver, name, error)
        class(linear_solver_type), allocatable, intent(out) :: solver
        character(len=*), intent(in) :: name
        type(error_type), allocatable, intent(out) :: error

        select case (to_lower(trim(adjustl(name))))
        case ('umfpack')
            allocate(umfpack_solver_type :: solver)
        case ('klu')
            allocate(klu_solver_type :: solver)
        case ('cholmod')
            allocate(cholmod_solver_type :: solver)
        case ('dense')
            allocate(dense_solver_type :: solver)
        case default
            call fatal_error(error, "unknown linear solver '" // trim(adjustl(name)) &
                // "'; valid names are " // linear_solver_names)
        end select
    end subroutine new_linear_solver

    !> Default solver for a system of order n (design.md section 5):
    !> n <= klu_max_order: 'klu' (fastest for unit cells, SPD or not);
    !> larger and symmetric positive definite: 'cholmod' (fastest at 1e5 and 1e6 DOFs:
    !> 45 ms and 0.86 s against KLU's 68 ms and 3.95 s, UMFPACK's 99 ms and 1.49 s);
    !> larger otherwise: 'umfpack', the general solver for unsymmetric or indefinite
    !> Jacobians (2.6x faster than KLU at 1e6).
    pure function default_linear_solver_name(n, symmetric_positive_definite) result(name)
        integer(ik), intent(in) :: n
        logical, intent(in) :: symmetric_positive_definite
        character(len=:), allocatable :: name

        if (n <= klu_max_order) then
            name = 'klu'
        else if (symmetric_positive_definite) then
            name = 'cholmod'
        else
            name = 'umfpack'
        end if
    end function default_linear_solver_name

    !> Lowercase copy of an ASCII string.
    pure function to_lower(text) result(lower)
        character(len=*), intent(in) :: text
        character(len=len(text)) :: lower
        integer :: i, code

        do i = 1, len(text)
            code = iachar(text(i:i))
            if (code >= iachar('A') .and. code <= iachar('Z')) then
                lower(i:i) = achar(code - iachar('A') + iachar('a'))
            else
                lower(i:i) = text(i:i)
            end if
        end do
    end function to_lower

end module yarnfort_linalg_factory
