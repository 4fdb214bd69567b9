! SPDX-License-Identifier: MIT
!> Create a linear solver by name and choose the default one from the measured timings of
!> design.md section 5.
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

    public :: new_linear_solver, default_linear_solver_name
    public :: linear_solver_names, klu_max_order, chosen_lu_name

    !> Names accepted by `new_linear_solver` (with chosen_lu_name).
    character(len=*), parameter :: linear_solver_names = &
        "'umfpack', 'klu', 'cholmod', 'cholmod+klu', 'dense'"

    !> Name of KLU or UMFPACK chosen per pattern from KLU's predicted cost
    !> (yarnfort_linalg_composite_lu_choice): the friction stepper's solver of the reduced systems,
    !> not one of the names offered to users (&solver linear_solver).
    character(len=*), parameter :: chosen_lu_name = 'klu|umfpack'

    !> Largest order for which KLU is the default for unsymmetric or indefinite
    !> systems. Measured on cable-net tangents (benchmarks/bench_newton's floor columns,
    !> 2 cores, CPU ms per factorisation + solve of the same Jacobian, one thread):
    !> KLU 0.73 / 40 / 341 ms against UMFPACK 2.0 / 33 / 131 ms at 1e3 / 1e4 / 3e4
    !> unknowns, now that UMFPACK is analysed with the values (symmetric strategy; with
    !> the pattern alone it took 2.1 / 47 / 198 ms and the switch sat at 2e5). design.md
    !> section 5 has UMFPACK 2.6x faster than KLU at 1e6. The monolithic friction
    !> Jacobian gives the same switch (benchmarks/bench_friction's `factors:` line, woven
    !> nets with 4 elements per segment, final active set, L + U nonzeros): 2.4e3
    !> unknowns KLU 1.2 ms (8.0e4) against UMFPACK 3.8 ms (3.6e4); 4.6e3: 6.8 ms (2.1e5)
    !> against 9.3 ms (7.7e4); 1.1e4: 152 ms (9.2e5) against 49 ms (2.2e5), KLU with
    !> COLAMD 1300 ms (3.7e6); whole load cycles at 1.1e4: 410 ms per step with UMFPACK
    !> against 2408 ms with KLU (wall time, same run).
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

    !> Default solver for a system of order n, from the measurements above:
    !> symmetric positive definite: 'cholmod+klu' (CHOLMOD, fastest at every size
    !> measured: 0.9 / 39 / 1134 ms at 1e3 / 1e4 / 1e5, falling back to KLU for good if a
    !> factorisation turns out not positive definite);
    !> otherwise 'klu' up to klu_max_order unknowns, 'umfpack' above.
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

end module yarnfort_linalg_factory
