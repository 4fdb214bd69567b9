! SPDX-License-Identifier: MIT
!> Sparse LU by KLU or UMFPACK, chosen for each pattern from the cost KLU's symbolic
!> analysis (BTF + AMD) predicts, before any factorisation: the same pattern always gives
!> the same choice. KLU factors column by column with sparse operations (Gilbert-Peierls):
!> its time goes with the flops, at a high cost per flop. UMFPACK assembles dense frontal
!> matrices and factors them with the BLAS: about 3x cheaper per flop, but it pays per
!> column (its fronts) and per factor nonzero. So UMFPACK wins where the flops are many
!> for the order and the factor nonzeros: where the factors fill in two dimensions with
!> large fronts everywhere (the knits' reduced friction systems), not on the woven nets'
!> chain-like systems, nor at 1e6 unknowns, where a few large separators hold the flops
!> but most columns stay small.
module yarnfort_linalg_lu_choice
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_klu, only: klu_solver_type
    use yarnfort_linalg_umfpack, only: umfpack_solver_type
    implicit none
    private

    public :: lu_choice_solver_type, prefers_umfpack
    public :: umfpack_min_flops_per_nonzero, umfpack_min_flops_per_column

    !> UMFPACK is chosen when KLU's predicted flops reach umfpack_min_flops_per_nonzero
    !> times the predicted nonzeros of L + U plus umfpack_min_flops_per_column times the
    !> order: where UMFPACK's predicted time is below KLU's. Fitted to CPU times of KLU's
    !> refactorisation and UMFPACK's numeric factorisation of the same reduced friction
    !> matrices (benchmarks/results-lu-choice.md: woven nets 1e4-1e6 unknowns, knits
    !> 20 x 20 to 60 x 60 loops; within 20 % on all but one of 11): KLU 1.03 ns per flop
    !> + 0.32 us per column, UMFPACK 0.29 ns per flop + 19 ns per factor nonzero + 2.8 us
    !> per column. The rule before, 100 flops per factor nonzero, chose UMFPACK on the
    !> woven 1e6 net (127 per nonzero, 3,020 per column) where KLU is 1.27x faster, and
    !> KLU on the 30 x 30 knit (92, 7,850 per column) where UMFPACK is 1.3x faster.
    real(wp), parameter :: umfpack_min_flops_per_nonzero = 25.0_wp
    real(wp), parameter :: umfpack_min_flops_per_column = 3300.0_wp

    !> KLU or UMFPACK (owned), chosen again at each `analyse`; the chosen solver checks
    !> the calls and keeps the pattern.
    type, extends(linear_solver_type) :: lu_choice_solver_type
        class(linear_solver_type), allocatable :: chosen
        !> KLU's prediction for the pattern: flops of a factorisation, nonzeros of L + U.
        real(wp) :: predicted_flops = 0.0_wp, predicted_nonzeros = 0.0_wp
    contains
        procedure :: analyse
        procedure :: factor
        procedure :: solve
        procedure :: destroy
        procedure :: get_name
    end type lu_choice_solver_type

contains

    !> KLU's analysis, kept if KLU is chosen, else UMFPACK's.
    subroutine analyse(self, n, col_ptr, row_index, error)
        class(lu_choice_solver_type), intent(inout) :: self
        integer(ik), intent(in) :: n
        integer(ik), intent(in) :: col_ptr(:), row_index(:)
        type(error_type), allocatable, intent(out) :: error
        type(klu_solver_type), allocatable :: klu

        call self%destroy()
        allocate(klu)
        call klu%analyse(n, col_ptr, row_index, error)
        if (allocated(error)) return
        call klu%get_prediction(self%predicted_flops, self%predicted_nonzeros)
        if (prefers_umfpack(self%predicted_flops, self%predicted_nonzeros, &
                real(n, wp))) then
            call klu%destroy()
            allocate(umfpack_solver_type :: self%chosen)
            call self%chosen%analyse(n, col_ptr, row_index, error)
        else
            call move_alloc(klu, self%chosen)
        end if
    end subroutine analyse

    !> The rule: UMFPACK when the predicted flops of a factorisation reach
    !> umfpack_min_flops_per_nonzero per factor nonzero plus umfpack_min_flops_per_column
    !> per column of the matrix (order n).
    pure function prefers_umfpack(flops, factor_nonzeros, n) result(umfpack)
        real(wp), intent(in) :: flops, factor_nonzeros, n
        logical :: umfpack

        umfpack = flops >= umfpack_min_flops_per_nonzero * factor_nonzeros &
            + umfpack_min_flops_per_column * n
    end function prefers_umfpack

    subroutine factor(self, values, error)
        class(lu_choice_solver_type), intent(inout) :: self
        real(wp), intent(in) :: values(:)
        type(error_type), allocatable, intent(out) :: error

        call require_solver(self, 'factor called before analyse', error)
        if (allocated(error)) return
        call self%chosen%factor(values, error)
    end subroutine factor

    subroutine solve(self, rhs, error)
        class(lu_choice_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: rhs(:)
        type(error_type), allocatable, intent(out) :: error

        call require_solver(self, 'solve called without a valid factorisation', error)
        if (allocated(error)) return
        call self%chosen%solve(rhs, error)
    end subroutine solve

    !> An error with `message` if no solver was chosen yet (no successful `analyse`).
    subroutine require_solver(self, message, error)
        class(lu_choice_solver_type), intent(in) :: self
        character(len=*), intent(in) :: message
        type(error_type), allocatable, intent(out) :: error

        if (.not. allocated(self%chosen)) call fatal_error(error, self%get_name() // ': ' &
            // message)
    end subroutine require_solver

    !> Free the chosen solver (safe to call twice).
    subroutine destroy(self)
        class(lu_choice_solver_type), intent(inout) :: self

        if (allocated(self%chosen)) then
            call self%chosen%destroy()
            deallocate(self%chosen)
        end if
        self%predicted_flops = 0.0_wp
        self%predicted_nonzeros = 0.0_wp
    end subroutine destroy

    !> The chosen solver's name, 'klu|umfpack' before the first analysis.
    pure function get_name(self) result(name)
        class(lu_choice_solver_type), intent(in) :: self
        character(len=:), allocatable :: name

        if (allocated(self%chosen)) then
            name = self%chosen%get_name()
        else
            name = 'klu|umfpack'
        end if
    end function get_name

end module yarnfort_linalg_lu_choice
