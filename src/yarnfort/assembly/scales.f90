! SPDX-License-Identifier: MIT
!> Force levels that the equilibrium residual is judged against: at each node, the
!> largest force that meets there (the tensions of its elements and its applied load),
!> and the rounding level of the residual's evaluation. They depend only on the forces
!> present, so convergence tests and dead bands scale with the scene's own forces and
!> not with a material stiffness or a choice of units.
module yarnfort_assembly_scales
    use yarnfort_kinds, only: wp
    use yarnfort_scene_scene, only: scene_type, get_loaded_nodes, get_force_scale
    use yarnfort_assembly_truss, only: get_truss_tension, get_tension_rounding
    use yarnfort_material_force_law, only: force_law_type
    implicit none
    private

    public :: get_node_force_levels, gather_node_force_levels, get_unknown_levels
    public :: node_level_floor

    !> A node where no force meets (a slack region) is judged against this fraction of
    !> the largest force of the scene.
    real(wp), parameter :: node_level_floor = 1.0e-6_wp

contains

    !> For nodes at x (3, n_nodes), reference lengths length0 and channel factors:
    !> level(n) = max(largest |tension| of the elements at n, |applied force at n|),
    !> floored at node_level_floor * the largest such force of the scene (max_force);
    !> noise(n) = the rounding error of the residual at n (sum over its elements of
    !> get_tension_rounding). `spring` and `stiffness_cap` as in
    !> get_truss_tension. With no force anywhere (max_force = 0) every level is 0.
    pure subroutine get_node_force_levels(scene, x, length0, factors, spring, level, noise, &
            max_force, stiffness_cap)
        type(scene_type), intent(in) :: scene
        real(wp), intent(in) :: x(:, :), length0(:), factors(:), spring
        real(wp), intent(out) :: level(:), noise(:), max_force
        real(wp), intent(in), optional :: stiffness_cap
        real(wp), allocatable :: tension(:), rounding(:), magnitude(:, :)
        integer, allocatable :: loaded(:)
        integer :: e

        allocate(tension(scene%network%n_elements()), rounding(scene%network%n_elements()))
        do e = 1, scene%network%n_elements()
            associate(nodes => scene%network%element_nodes(:, e))
                call get_tension_with_noise(scene%laws(scene%network%element_material(e))%law, &
                    spring, x(:, nodes(1)), x(:, nodes(2)), length0(e), tension(e), rounding(e), &
                    stiffness_cap)
            end associate
        end do
        call get_loaded_nodes(scene, loaded, magnitude)
        call gather_node_force_levels(scene, tension, rounding, factors, loaded, magnitude, &
            level, noise, max_force)
    end subroutine get_node_force_levels

    !> The same from each element's tension and its rounding error, where these are at
    !> hand (assemble_internal_force gives them with the internal force), and the loaded
    !> nodes with their channels' force magnitudes (get_loaded_nodes; at every other
    !> node the applied force's scale is 0).
    pure subroutine gather_node_force_levels(scene, tension, rounding, factors, loaded, &
            magnitude, level, noise, max_force)
        type(scene_type), intent(in) :: scene
        real(wp), intent(in) :: tension(:), rounding(:), factors(:), magnitude(:, :)
        integer, intent(in) :: loaded(:)
        real(wp), intent(out) :: level(:), noise(:), max_force
        integer :: e, n, k

        level = 0.0_wp
        noise = 0.0_wp
        do e = 1, scene%network%n_elements()
            associate(nodes => scene%network%element_nodes(:, e))
                do k = 1, 2
                    level(nodes(k)) = max(level(nodes(k)), abs(tension(e)))
                    noise(nodes(k)) = noise(nodes(k)) + rounding(e)
                end do
            end associate
        end do
        do k = 1, size(loaded)
            n = loaded(k)
            level(n) = max(level(n), get_force_scale(factors, magnitude(:, k)))
        end do
        max_force = maxval([0.0_wp, level])
        level = max(level, node_level_floor * max_force)
    end subroutine gather_node_force_levels

    !> Tension of an element with nodes at x1, x2 and its rounding error
    !> (get_tension_rounding).
    pure subroutine get_tension_with_noise(law, spring, x1, x2, length0, tension, noise, &
            stiffness_cap)
        class(force_law_type), intent(in) :: law
        real(wp), intent(in) :: spring, x1(3), x2(3), length0
        real(wp), intent(out) :: tension, noise
        real(wp), intent(in), optional :: stiffness_cap
        real(wp) :: length, dtension

        length = norm2(x2 - x1)
        call get_truss_tension(law, spring, length / length0, tension, dtension, stiffness_cap)
        noise = get_tension_rounding(law, norm2(x1) + norm2(x2), length, length0, tension, &
            dtension)
    end subroutine get_tension_with_noise

    !> The levels of the equilibrium rows (one per unknown coordinate) from the node
    !> levels: a row that gathers several nodes (linked nodes share unknowns) takes the
    !> largest of their levels and the sum of their noise.
    pure subroutine get_unknown_levels(scene, level, noise, row_level, row_noise)
        type(scene_type), intent(in) :: scene
        real(wp), intent(in) :: level(:), noise(:)
        real(wp), intent(out) :: row_level(:), row_noise(:)
        integer :: c, i, n

        row_level = 0.0_wp
        row_noise = 0.0_wp
        do c = 1, size(scene%dofs%unknown)
            i = scene%dofs%unknown(c)
            if (i == 0) cycle
            n = (c - 1) / 3 + 1
            row_level(i) = max(row_level(i), level(n))
            row_noise(i) = row_noise(i) + noise(n)
        end do
    end subroutine get_unknown_levels

end module yarnfort_assembly_scales
