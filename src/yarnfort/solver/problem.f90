! SPDX-License-Identifier: MIT
!> A square nonlinear system F(u) = 0 with a sparse Jacobian of fixed pattern: what the
!> Newton solver (KINSOL) needs from the elastic and the frictional problems.
module yarnfort_solver_problem
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_assembly_truss, only: no_stiffness_cap
    implicit none
    private

    public :: nonlinear_problem_type, regularisation_type, chosen_law

    !> The law a problem is evaluated with: the exact law (the default), or a regularised
    !> one that only the Newton solver's predictors pass (see yarnfort_assembly_truss).
    type :: regularisation_type
        !> Weight of the regularising spring in the model (0: the exact law).
        real(wp) :: spring = 0.0_wp
        !> Weight of the regularising spring in the tangent of slack strings only.
        real(wp) :: tangent_spring = 0.0_wp
        !> Laws stiffer than this are scaled down to it (get_truss_tension;
        !> no_stiffness_cap: the laws as they are).
        real(wp) :: stiffness_cap = no_stiffness_cap
    end type regularisation_type

    type, abstract :: nonlinear_problem_type
        !> Scale of the unknowns (KINSOL's scaling vector of u); residual rows are
        !> scaled by get_row_levels.
        real(wp) :: length_scale = 1.0_wp
        !> The scene (which must outlive the problem), the load channels' factors, the
        !> elements' reference lengths and a work array of node positions (3, n_nodes).
        type(scene_type), pointer :: scene => null()
        real(wp), allocatable :: factors(:), length0(:), x(:, :)
        !> The Jacobian's CSC pattern (0-based), fixed for the problem's lifetime.
        integer(ik), allocatable :: col_ptr(:), row_index(:)
    contains
        !> Number of unknowns (default: the order of the pattern).
        procedure :: get_size
        !> Number of stored entries of the Jacobian's CSC pattern.
        procedure :: get_nonzeros
        !> Write the Jacobian's CSC pattern into arrays of its size: the Newton solver
        !> restores it in KINSOL's matrix before each Jacobian, without a copy of its own.
        procedure :: copy_pattern
        !> The residual at u (every evaluation: with `law`, default the exact law).
        procedure(evaluate_interface), deferred :: evaluate_residual
        !> Jacobian values in the order of the pattern.
        procedure(evaluate_interface), deferred :: evaluate_jacobian
        !> The force level of each residual row at u and the rounding level of its
        !> evaluation: row i is converged when |F_i| <= tol * level_i + noise_i.
        procedure(get_row_levels_interface), deferred :: get_row_levels
        !> Called by the Newton solver before each solve with its initial guess: a problem
        !> may fix there what must stay constant during one solve (default: nothing).
        procedure :: prepare_solve
        !> Called by the Newton solver on a converged solution: a problem may reject it
        !> with an error (a spurious root outside its domain). Default: accept.
        procedure :: check_solution
        !> The largest reference stiffness of the scene's material laws.
        procedure :: get_max_reference_stiffness
    end type nonlinear_problem_type

    abstract interface
        subroutine evaluate_interface(self, u, values, error, law)
            import :: nonlinear_problem_type, regularisation_type, wp, error_type
            class(nonlinear_problem_type), intent(inout) :: self
            real(wp), intent(in) :: u(:)
            real(wp), intent(out) :: values(:)
            type(error_type), allocatable, intent(out) :: error
            type(regularisation_type), intent(in), optional :: law
        end subroutine evaluate_interface

        subroutine get_row_levels_interface(self, u, level, noise, error, law)
            import :: nonlinear_problem_type, regularisation_type, wp, error_type
            class(nonlinear_problem_type), intent(inout) :: self
            real(wp), intent(in) :: u(:)
            real(wp), intent(out) :: level(:), noise(:)
            type(error_type), allocatable, intent(out) :: error
            type(regularisation_type), intent(in), optional :: law
        end subroutine get_row_levels_interface
    end interface

contains

    pure integer function get_size(self)
        class(nonlinear_problem_type), intent(in) :: self
        get_size = size(self%col_ptr) - 1
    end function get_size

    pure integer(ik) function get_nonzeros(self)
        class(nonlinear_problem_type), intent(in) :: self
        get_nonzeros = size(self%row_index, kind=ik)
    end function get_nonzeros

    subroutine copy_pattern(self, col_ptr, row_index)
        class(nonlinear_problem_type), intent(in) :: self
        integer(ik), intent(out) :: col_ptr(:), row_index(:)
        col_ptr = self%col_ptr
        row_index = self%row_index
    end subroutine copy_pattern

    !> Nothing to prepare.
    subroutine prepare_solve(self, u, error, law)
        class(nonlinear_problem_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        type(error_type), allocatable, intent(out) :: error
        type(regularisation_type), intent(in), optional :: law
    end subroutine prepare_solve

    !> Every solution is acceptable.
    subroutine check_solution(self, u, error, law)
        class(nonlinear_problem_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        type(error_type), allocatable, intent(out) :: error
        type(regularisation_type), intent(in), optional :: law
    end subroutine check_solution

    !> `law` if present, else the exact law.
    pure type(regularisation_type) function chosen_law(law) result(used)
        type(regularisation_type), intent(in), optional :: law
        if (present(law)) used = law
    end function chosen_law

    !> The largest reference stiffness of the scene's material laws (the Newton
    !> solver's softened-yarn predictor starts below it).
    real(wp) function get_max_reference_stiffness(self) result(stiffest)
        class(nonlinear_problem_type), intent(in) :: self
        integer :: m
        stiffest = maxval([(self%scene%laws(m)%law%get_reference_stiffness(), &
            m = 1, size(self%scene%laws))])
    end function get_max_reference_stiffness

end module yarnfort_solver_problem
