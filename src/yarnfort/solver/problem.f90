! SPDX-License-Identifier: MIT
!> A square nonlinear system F(u) = 0 with a sparse Jacobian of fixed pattern: what the
!> Newton solver (KINSOL) needs from the elastic and the frictional problems.
module yarnfort_solver_problem
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    implicit none
    private

    public :: nonlinear_problem_type

    type, abstract :: nonlinear_problem_type
        !> Scale of the unknowns (KINSOL's scaling vector of u); residual rows are
        !> scaled by get_row_levels.
        real(wp) :: length_scale = 1.0_wp
        !> Set by the Newton solver before each solve: the weight of the regularising
        !> spring in the model (a predictor solve; 0 for the exact law) and in the
        !> tangent of slack strings only (see yarnfort_assembly_truss).
        real(wp) :: spring = 0.0_wp
        real(wp) :: tangent_spring = 0.0_wp
    contains
        !> Number of unknowns.
        procedure(get_size_interface), deferred :: get_size
        !> Number of stored entries of the Jacobian's CSC pattern.
        procedure(get_nonzeros_interface), deferred :: get_nonzeros
        !> Write the Jacobian's CSC pattern (0-based, fixed for the problem's lifetime)
        !> into arrays of its size: the Newton solver restores it in KINSOL's matrix
        !> before each Jacobian, without a copy of its own.
        procedure(copy_pattern_interface), deferred :: copy_pattern
        procedure(evaluate_residual_interface), deferred :: evaluate_residual
        !> Jacobian values in the order of the pattern.
        procedure(evaluate_jacobian_interface), deferred :: evaluate_jacobian
        !> The force level of each residual row at u and the rounding level of its
        !> evaluation: row i is converged when |F_i| <= tol * level_i + noise_i.
        procedure(get_row_levels_interface), deferred :: get_row_levels
        !> Called by the Newton solver before each solve with its initial guess: a problem
        !> may fix there what must stay constant during one solve (default: nothing).
        procedure :: prepare_solve
        !> Called by the Newton solver on a converged solution: a problem may reject it
        !> with an error (a spurious root outside its domain). Default: accept.
        procedure :: check_solution
    end type nonlinear_problem_type

    abstract interface
        pure integer function get_size_interface(self)
            import :: nonlinear_problem_type
            class(nonlinear_problem_type), intent(in) :: self
        end function get_size_interface

        pure integer(ik) function get_nonzeros_interface(self)
            import :: nonlinear_problem_type, ik
            class(nonlinear_problem_type), intent(in) :: self
        end function get_nonzeros_interface

        subroutine copy_pattern_interface(self, col_ptr, row_index)
            import :: nonlinear_problem_type, ik
            class(nonlinear_problem_type), intent(in) :: self
            integer(ik), intent(out) :: col_ptr(:), row_index(:)
        end subroutine copy_pattern_interface

        subroutine evaluate_residual_interface(self, u, residual, error)
            import :: nonlinear_problem_type, wp, error_type
            class(nonlinear_problem_type), intent(inout) :: self
            real(wp), intent(in) :: u(:)
            real(wp), intent(out) :: residual(:)
            type(error_type), allocatable, intent(out) :: error
        end subroutine evaluate_residual_interface

        subroutine evaluate_jacobian_interface(self, u, values, error)
            import :: nonlinear_problem_type, wp, error_type
            class(nonlinear_problem_type), intent(inout) :: self
            real(wp), intent(in) :: u(:)
            real(wp), intent(out) :: values(:)
            type(error_type), allocatable, intent(out) :: error
        end subroutine evaluate_jacobian_interface

        subroutine get_row_levels_interface(self, u, level, noise, error)
            import :: nonlinear_problem_type, wp, error_type
            class(nonlinear_problem_type), intent(inout) :: self
            real(wp), intent(in) :: u(:)
            real(wp), intent(out) :: level(:), noise(:)
            type(error_type), allocatable, intent(out) :: error
        end subroutine get_row_levels_interface
    end interface

contains

    !> Nothing to prepare.
    subroutine prepare_solve(self, u, error)
        class(nonlinear_problem_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        type(error_type), allocatable, intent(out) :: error
    end subroutine prepare_solve

    !> Every solution is acceptable.
    subroutine check_solution(self, u, error)
        class(nonlinear_problem_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        type(error_type), allocatable, intent(out) :: error
    end subroutine check_solution

end module yarnfort_solver_problem
