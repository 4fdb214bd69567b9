! SPDX-License-Identifier: MIT
!> Create a linear solver by name, and choose the default one for a system's size and
!> symmetry (docs/decisions.md, 'Linear solver: ...' entries).
module yarnfort_linalg_factory
    use yarnfort_kinds, only: ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_backend_umfpack, only: umfpack_solver_type
    use yarnfort_linalg_backend_klu, only: klu_solver_type
    use yarnfort_linalg_backend_cholmod, only: cholmod_solver_type
    use yarnfort_linalg_backend_dense, only: dense_solver_type
    use yarnfort_linalg_composite_fallback, only: fallback_solver_type
    use yarnfort_linalg_composite_lu_choice, only: lu_choice_solver_type
    use yarnfort_text, only: to_lower
    implicit none
    private

    public :: new_linear_solver, default_linear_solver_name, get_friction_solver_names
    public :: linear_solver_names, klu_max_order, chosen_lu_name

    !> Names accepted by `new_linear_solver` (with chosen_lu_name).
    character(len=*), parameter :: linear_solver_names = &
        "'umfpack', 'klu', 'cholmod', 'cholmod+klu', 'dense'"

    !> Name of KLU or UMFPACK chosen per pattern from KLU's predicted cost
    !> (yarnfort_linalg_composite_lu_choice): the friction stepper's solver of the reduced systems,
    !> not one of the names offered to users (&solver linear_solver).
    character(len=*), parameter :: chosen_lu_name = 'klu|umfpack'

    !> Largest order for which KLU is the default for unsymmetric or indefinite
    !> systems: above it UMFPACK's BLAS-based frontal factorisation is faster (docs/
    !> decisions.md, 'Linear solver: KLU up to 5,000 unknowns, UMFPACK above').
    integer(ik), parameter :: klu_max_order = 5000_ik

contains

    !> Allocate `solver` as the solver called `name` ('umfpack', 'klu', 'cholmod' or
    !> 'dense'; case and surrounding blanks are ignored). Any old solver is destroyed.
    !> The process-wide settings of the libraries are the program's to make
    !> (yarnfort_linalg_process), not this constructor's.
    subroutine new_linear_solver(solver, name, error, unsymmetric)
        class(linear_solver_type), allocatable, intent(out) :: solver
        character(len=*), intent(in) :: name
        type(error_type), allocatable, intent(out) :: error
        !> The matrices have a strongly unsymmetric pattern (the friction Jacobian): KLU
        !> then keeps the sparser of its AMD and COLAMD orderings.
        logical, intent(in), optional :: unsymmetric

        select case (to_lower(trim(adjustl(name))))
        case ('umfpack')
            allocate(umfpack_solver_type :: solver)
        case ('klu')
            block
                type(klu_solver_type), allocatable :: klu
                allocate(klu)
                if (present(unsymmetric)) klu%unsymmetric_ordering = unsymmetric
                call move_alloc(klu, solver)
            end block
        case ('cholmod')
            allocate(cholmod_solver_type :: solver)
        case ('dense')
            allocate(dense_solver_type :: solver)
        case (chosen_lu_name)
            allocate(lu_choice_solver_type :: solver)
        case ('cholmod+klu')
            block
                type(fallback_solver_type), allocatable :: fallback
                allocate(fallback)
                allocate(cholmod_solver_type :: fallback%active)
                allocate(klu_solver_type :: fallback%general)
                call move_alloc(fallback, solver)
            end block
        case default
            call fatal_error(error, "unknown linear solver '" // trim(adjustl(name)) &
                // "'; valid names are " // linear_solver_names)
        end select
    end subroutine new_linear_solver

    !> Default solver for a system of order n: symmetric positive definite: 'cholmod+klu'
    !> (CHOLMOD, the fastest measured, falling back to KLU for good if a factorisation
    !> turns out not positive definite); otherwise 'klu' up to klu_max_order unknowns,
    !> 'umfpack' above (docs/decisions.md, 'Linear solver: ...').
    pure function default_linear_solver_name(n, symmetric_positive_definite) result(name)
        integer(ik), intent(in) :: n
        logical, intent(in) :: symmetric_positive_definite
        character(len=:), allocatable :: name

        if (symmetric_positive_definite) then
            name = 'cholmod+klu'
        else if (n <= klu_max_order) then
            name = 'klu'
        else
            name = 'umfpack'
        end if
    end function default_linear_solver_name

    !> The solvers of a friction stepper's unsymmetric systems for a run whose elastic
    !> solves use `linear_name`: with a Cholesky one (which cannot factor them), the
    !> flows-only system (order n_passages) gets the default for unsymmetric systems and
    !> the reduced monolithic one chosen_lu_name (KLU or UMFPACK per pattern,
    !> yarnfort_linalg_composite_lu_choice); otherwise both get `linear_name`.
    pure subroutine get_friction_solver_names(linear_name, n_passages, flows_name, full_name)
        character(len=*), intent(in) :: linear_name
        integer(ik), intent(in) :: n_passages
        character(len=:), allocatable, intent(out) :: flows_name, full_name

        if (linear_name == 'cholmod' .or. linear_name == 'cholmod+klu') then
            flows_name = default_linear_solver_name(n_passages, .false.)
            full_name = chosen_lu_name
        else
            flows_name = linear_name
            full_name = linear_name
        end if
    end subroutine get_friction_solver_names

end module yarnfort_linalg_factory
