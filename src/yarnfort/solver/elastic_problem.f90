! SPDX-License-Identifier: MIT
!> Equilibrium of the network at given load factors with reference lengths held fixed
!> (paper eqs. 51-52): the unknowns are the free coordinates.
module yarnfort_solver_elastic_problem
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_assembly_pattern, only: pattern_type, new_pattern
    use yarnfort_assembly_assemble, only: assemble_residual, assemble_jacobian
    use yarnfort_assembly_scales, only: get_node_force_levels, get_unknown_levels
    use yarnfort_solver_problem, only: nonlinear_problem_type, regularisation_type, chosen_law
    implicit none
    private

    public :: elastic_problem_type, new_elastic_problem

    type, extends(nonlinear_problem_type) :: elastic_problem_type
        !> The Jacobian's value slots per element (its CSC arrays moved to the base type).
        type(pattern_type) :: pattern
    contains
        procedure :: evaluate_residual
        procedure :: evaluate_jacobian
        procedure :: get_row_levels
    end type elastic_problem_type

contains

    !> The problem for `scene` (which must outlive it), reference lengths from the scene.
    subroutine new_elastic_problem(self, scene)
        type(elastic_problem_type), intent(out) :: self
        type(scene_type), target, intent(in) :: scene

        self%scene => scene
        call new_pattern(self%pattern, scene%network, scene%dofs)
        call move_alloc(self%pattern%col_ptr, self%col_ptr)
        call move_alloc(self%pattern%row_index, self%row_index)
        self%length0 = scene%network%length0
        allocate(self%factors(scene%path%n_channels()), source=0.0_wp)
        allocate(self%x(3, scene%network%n_nodes()))
        self%length_scale = scene%length_scale
    end subroutine new_elastic_problem

    subroutine evaluate_residual(self, u, values, error, law)
        class(elastic_problem_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        real(wp), intent(out) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        type(regularisation_type), intent(in), optional :: law
        type(regularisation_type) :: used
        used = chosen_law(law)
        call self%scene%dofs%expand(u, self%factors, self%x)
        call assemble_residual(self%scene, self%x, self%length0, self%factors, values, error, &
            used%spring, used%stiffness_cap)
    end subroutine evaluate_residual

    subroutine evaluate_jacobian(self, u, values, error, law)
        class(elastic_problem_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        real(wp), intent(out) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        type(regularisation_type), intent(in), optional :: law
        type(regularisation_type) :: used
        used = chosen_law(law)
        call self%scene%dofs%expand(u, self%factors, self%x)
        call assemble_jacobian(self%scene, self%pattern, self%x, self%length0, values, error, &
            used%spring, used%tangent_spring, used%stiffness_cap)
    end subroutine evaluate_jacobian

    !> Each coordinate row is judged against the forces meeting at its node.
    subroutine get_row_levels(self, u, level, noise, error, law)
        class(elastic_problem_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        real(wp), intent(out) :: level(:), noise(:)
        type(error_type), allocatable, intent(out) :: error
        type(regularisation_type), intent(in), optional :: law
        real(wp), allocatable :: node_level(:), node_noise(:)
        real(wp) :: max_force
        type(regularisation_type) :: used
        used = chosen_law(law)

        allocate(node_level(self%scene%network%n_nodes()), node_noise(self%scene%network%n_nodes()))
        call self%scene%dofs%expand(u, self%factors, self%x)
        call get_node_force_levels(self%scene, self%x, self%length0, self%factors, used%spring, &
            node_level, node_noise, max_force, used%stiffness_cap)
        call get_unknown_levels(self%scene, node_level, node_noise, level, noise)
    end subroutine get_row_levels

end module yarnfort_solver_elastic_problem
