! SPDX-License-Identifier: MIT
!> Sparse LU by KLU or UMFPACK, chosen for each pattern from the cost KLU's symbolic
!> analysis (BTF + AMD) predicts, before any factorisation: the same pattern always gives
!> the same choice. KLU factors column by column with sparse operations (Gilbert-Peierls),
!> cheap per nonzero of the factors; UMFPACK assembles dense frontal matrices and factors
!> them with the BLAS, dearer per nonzero but faster per flop. So the flops per factor
!> nonzero decide: few on chain-like patterns (the woven nets' reduced friction systems),
!> many where the factors fill in two dimensions (the knit's, or any net at 1e6 unknowns).
module yarnfort_linalg_composite_lu_choice
    use, intrinsic :: iso_c_binding, only: c_long, c_double
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_backend_klu, only: klu_solver_type
    use yarnfort_linalg_backend_umfpack, only: umfpack_solver_type
    use yarnfort_linalg_binding_cholmod, only: yarnfort_cholmod_metis_order, cholmod_ok
    implicit none
    private

    public :: lu_choice_solver_type, prefers_umfpack, umfpack_min_flops_per_nonzero
    public :: metis_min_flops_per_nonzero

    !> UMFPACK is chosen when KLU's predicted flops per nonzero of L + U reach this: many
    !> flops per nonzero is where UMFPACK's BLAS-based fronts beat KLU's sparse column
    !> updates (docs/decisions.md, 'Reduced friction systems: UMFPACK from 80 predicted
    !> flops per factor nonzero').
    real(wp), parameter :: umfpack_min_flops_per_nonzero = 80.0_wp
    !> UMFPACK's automatic strategy takes the symmetric one at this symmetry of the
    !> pattern (matched entries over off-diagonal entries) and a nonzero diagonal.
    real(wp), parameter :: umfpack_min_symmetry = 0.5_wp
    !> From this many predicted flops per factor nonzero (AMD's order) up to UMFPACK's
    !> threshold, METIS' nested dissection of A + A^T is tried too, and KLU takes its
    !> order when it predicts fewer factor nonzeros than AMD's; below it METIS filled
    !> more; not for UMFPACK, which factored slower on it (docs/decisions.md, 'KLU on
    !> METIS' order from 50 predicted flops per nonzero').
    real(wp), parameter :: metis_min_flops_per_nonzero = 50.0_wp

    !> KLU or UMFPACK (owned), chosen again at each `analyse`; the chosen solver checks
    !> the calls and keeps the pattern.
    type, extends(linear_solver_type) :: lu_choice_solver_type
        class(linear_solver_type), allocatable :: chosen
        !> KLU's prediction for the pattern: flops of a factorisation, nonzeros of L + U.
        real(wp) :: predicted_flops = 0.0_wp, predicted_nonzeros = 0.0_wp
        !> KLU was handed METIS' order (metis_min_flops_per_nonzero), and the nonzeros of
        !> L + U predicted for the order the chosen solver factors with (AMD's otherwise).
        logical :: metis_order = .false.
        real(wp) :: ordered_nonzeros = 0.0_wp
    contains
        procedure :: analyse
        procedure :: factor
        procedure :: solve_columns
        procedure :: destroy
        procedure :: get_name
    end type lu_choice_solver_type

contains

    !> KLU's analysis, kept if KLU is chosen, else UMFPACK's. UMFPACK is handed KLU's
    !> AMD order when that is symmetric and so is the pattern by UMFPACK's own test
    !> (umfpack_min_symmetry): its symmetric strategy would order A + A^T again. KLU from
    !> metis_min_flops_per_nonzero on is analysed again with METIS' order of A + A^T
    !> when that predicts fewer factor nonzeros (the choice stays AMD's prediction's).
    subroutine analyse(self, n, col_ptr, row_index, error)
        class(lu_choice_solver_type), intent(inout) :: self
        integer(ik), intent(in) :: n
        integer(ik), intent(in) :: col_ptr(:), row_index(:)
        type(error_type), allocatable, intent(out) :: error
        type(klu_solver_type), allocatable :: klu
        type(umfpack_solver_type), allocatable :: umfpack
        integer(c_long), allocatable :: order(:)
        real(wp) :: symmetry

        call self%destroy()
        allocate(klu)
        call klu%analyse(n, col_ptr, row_index, error)
        if (allocated(error)) return
        call klu%get_prediction(self%predicted_flops, self%predicted_nonzeros)
        call klu%get_symmetric_order(order, symmetry)
        self%ordered_nonzeros = self%predicted_nonzeros
        if (prefers_umfpack(self%predicted_flops, self%predicted_nonzeros)) then
            call klu%destroy()
            allocate(umfpack)
            call umfpack%analyse(n, col_ptr, row_index, error)
            if (allocated(error)) return
            if (allocated(order) .and. symmetry >= umfpack_min_symmetry) then
                call umfpack%set_column_order(order, self%predicted_nonzeros, error)
                if (allocated(error)) return
            end if
            call move_alloc(umfpack, self%chosen)
        else
            if (allocated(order) .and. symmetry >= umfpack_min_symmetry .and. &
                    self%predicted_flops >= metis_min_flops_per_nonzero &
                    * self%predicted_nonzeros) call try_metis()
            if (self%metis_order) then
                call move_alloc(order, klu%given_order)
                call klu%analyse(n, col_ptr, row_index, error)
                if (allocated(error)) return
            end if
            call move_alloc(klu, self%chosen)
        end if
    contains
        !> METIS' order in place of AMD's when it predicts fewer nonzeros of L + U (twice
        !> those of the Cholesky factor of A + A^T: L and U both hold the diagonal).
        subroutine try_metis()
            integer(c_long), allocatable :: metis_order(:)
            real(c_double) :: lnz

            allocate(metis_order(n))
            if (yarnfort_cholmod_metis_order(int(n, c_long), klu%col_ptr, klu%row_index, &
                    metis_order, lnz) /= cholmod_ok) return
            if (2.0_wp * lnz >= self%ordered_nonzeros) return
            call move_alloc(metis_order, order)
            self%ordered_nonzeros = 2.0_wp * lnz
            self%metis_order = .true.
        end subroutine try_metis
    end subroutine analyse

    !> The rule: UMFPACK when the predicted flops per factor nonzero reach
    !> umfpack_min_flops_per_nonzero.
    pure function prefers_umfpack(flops, factor_nonzeros) result(umfpack)
        real(wp), intent(in) :: flops, factor_nonzeros
        logical :: umfpack

        umfpack = flops >= umfpack_min_flops_per_nonzero * factor_nonzeros
    end function prefers_umfpack

    subroutine factor(self, values, error)
        class(lu_choice_solver_type), intent(inout) :: self
        real(wp), intent(in) :: values(:)
        type(error_type), allocatable, intent(out) :: error

        call require_solver(self, 'factor called before analyse', error)
        if (allocated(error)) return
        call self%chosen%factor(values, error)
    end subroutine factor

    subroutine solve_columns(self, rhs, error)
        class(lu_choice_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: rhs(:, :)
        type(error_type), allocatable, intent(out) :: error

        call require_solver(self, 'solve called without a valid factorisation', error)
        if (allocated(error)) return
        call self%chosen%solve_columns(rhs, error)
    end subroutine solve_columns

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
        self%metis_order = .false.
        self%ordered_nonzeros = 0.0_wp
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

end module yarnfort_linalg_composite_lu_choice
