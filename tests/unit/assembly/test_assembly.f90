! SPDX-License-Identifier: MIT
!> Truss element and global assembly checked against finite differences.
module test_assembly
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_testing, only: unittest_type, new_unittest, check, check_close
    use yarnfort_material_linear, only: linear_law_type, new_linear_law
    use yarnfort_material_neo_hookean, only: neo_hookean_law_type, new_neo_hookean_law
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_assembly_truss, only: get_truss_response
    use yarnfort_assembly_pattern, only: pattern_type, new_pattern
    use yarnfort_assembly_assemble, only: assemble_residual, assemble_jacobian, &
        assemble_internal_force
    implicit none
    private

    public :: collect_assembly

    !> Finite-difference step and agreement expected for first derivatives.
    real(wp), parameter :: fd_step = 1.0e-6_wp
    real(wp), parameter :: fd_tolerance = 1.0e-7_wp

contains

    subroutine collect_assembly(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
            new_unittest('element_force_is_energy_gradient', test_element_force), &
            new_unittest('element_tangent_matches_fd', test_element_tangent), &
            new_unittest('slack_element_force_and_tangent', test_slack_element), &
            new_unittest('capped_element_is_the_scaled_law', test_capped_element), &
            new_unittest('pattern_is_symmetric_and_sorted', test_pattern), &
            new_unittest('global_jacobian_matches_fd', test_global_jacobian), &
            new_unittest('internal_forces_balance', test_internal_balance), &
            new_unittest('load_channels_superpose', test_load_channels), &
            new_unittest('path_factors_per_channel', test_path_factors) ]
    end subroutine collect_assembly

    !> Two load channels: the residual at factors (a, b) is the internal force minus
    !> a times the first channel's forces minus b times the second's, and the prescribed
    !> coordinates move by a * delta_1 + b * delta_2.
    subroutine test_load_channels(error)
        type(error_type), allocatable, intent(out) :: error
        type(scene_type) :: scene
        real(wp), allocatable :: u(:), x(:, :), x0(:, :), r(:), r0(:), expected(:)
        real(wp), parameter :: a = 0.7_wp, b = -0.4_wp, identity = 100 * epsilon(1.0_wp)
        real(wp) :: scale
        integer :: c, node, k

        call make_scene(scene, error)
        if (allocated(error)) return
        ! The scene's force is on channel 1; give channel 2 forces and displacements too.
        scene%external_force(5, 2) = 0.25_wp
        scene%external_force(11, 2) = -0.1_wp
        do c = 1, size(scene%dofs%unknown)
            if (scene%dofs%unknown(c) == 0) scene%dofs%delta(c, 1) = -0.02_wp * c
        end do
        allocate(u(scene%dofs%n_unknowns), x(3, 6), x0(3, 6), r(scene%dofs%n_unknowns), &
            r0(scene%dofs%n_unknowns), expected(scene%dofs%n_unknowns))
        call scene%dofs%restrict(scene%network%position, u)
        call scene%dofs%expand(u, [a, b], x)
        call scene%dofs%expand(u, [0.0_wp, 0.0_wp], x0)
        scale = maxval(abs(scene%network%position))
        do c = 1, 18
            node = (c - 1) / 3 + 1
            k = c - 3 * (node - 1)
            call check_close(error, x(k, node) - x0(k, node), &
                a * scene%dofs%delta(c, 1) + b * scene%dofs%delta(c, 2), identity, &
                'prescribed displacement', abs_tol=identity * scale)
            if (allocated(error)) return
        end do
        ! At the same positions the residuals differ by P^T (a f_1 + b f_2).
        call assemble_residual(scene, x, scene%network%length0, [a, b], r, error)
        if (allocated(error)) return
        call assemble_residual(scene, x, scene%network%length0, [0.0_wp, 0.0_wp], r0, error)
        if (allocated(error)) return
        call scene%dofs%gather(a * scene%external_force(:, 1) + b * scene%external_force(:, 2), &
            expected)
        call check_close(error, r0 - r, expected, identity, 'residual of two channels', &
            abs_tol=identity * maxval(abs(r0)))
    end subroutine test_load_channels

    !> Each channel is interpolated on its own column, clamped at the ends.
    subroutine test_path_factors(error)
        type(error_type), allocatable, intent(out) :: error
        type(scene_type) :: scene
        real(wp) :: factors(3)

        scene%path%time = [0.0_wp, 1.0_wp, 3.0_wp]
        scene%path%factor = reshape([0.0_wp, 1.0_wp, 1.0_wp, &
                                     0.0_wp, 0.0_wp, 2.0_wp, &
                                     5.0_wp, -1.0_wp, 3.0_wp], [3, 3])
        call check(error, scene%path%n_channels() == 3, 'three channels')
        if (allocated(error)) return
        call scene%path%get_factors(2.0_wp, factors)
        call check_close(error, factors, [1.0_wp, 1.0_wp, 1.0_wp], 100 * epsilon(1.0_wp), &
            'factors at t = 2')
        if (allocated(error)) return
        call scene%path%get_factors(0.5_wp, factors)
        call check_close(error, factors, [0.5_wp, 0.0_wp, 2.0_wp], 100 * epsilon(1.0_wp), &
            'factors at t = 0.5')
        if (allocated(error)) return
        call scene%path%get_factors(-1.0_wp, factors)
        call check_close(error, factors, [0.0_wp, 0.0_wp, 5.0_wp], 0.0_wp, 'clamped before')
        if (allocated(error)) return
        call scene%path%get_factors(4.0_wp, factors)
        call check_close(error, factors, [1.0_wp, 2.0_wp, 3.0_wp], 0.0_wp, 'clamped after')
    end subroutine test_path_factors

    subroutine test_element_force(error)
        type(error_type), allocatable, intent(out) :: error
        type(neo_hookean_law_type) :: law
        real(wp) :: x1(3), x2(3), force(3), tension, stretch, xp(3), xm(3), fd(3)
        real(wp), parameter :: length0 = 0.8_wp
        integer :: k

        call new_neo_hookean_law(law, 2.0e6_wp, 1.0e-6_wp, error)
        if (allocated(error)) return
        x1 = [0.1_wp, -0.2_wp, 0.3_wp]
        x2 = [0.9_wp, 0.25_wp, 0.1_wp]
        call get_truss_response(law, 0.0_wp, length0, x1, x2, tension, stretch, force)
        do k = 1, 3
            xp = x2
            xm = x2
            xp(k) = xp(k) + fd_step
            xm(k) = xm(k) - fd_step
            fd(k) = length0 * (law%get_energy(norm2(xp - x1) / length0) &
                - law%get_energy(norm2(xm - x1) / length0)) / (2 * fd_step)
        end do
        call check_close(error, force, fd, fd_tolerance, 'dU/dx2', abs_tol=fd_tolerance * norm2(fd))
    end subroutine test_element_force

    subroutine test_element_tangent(error)
        type(error_type), allocatable, intent(out) :: error
        type(linear_law_type) :: law
        real(wp) :: x1(3), x2(3), force(3), block(3, 3), tension, stretch
        real(wp) :: fp(3), fm(3), xp(3), xm(3), fd(3, 3)
        real(wp), parameter :: length0 = 0.5_wp
        integer :: k

        call new_linear_law(law, 3.0_wp, error)
        if (allocated(error)) return
        x1 = [0.0_wp, 0.0_wp, 0.0_wp]
        x2 = [0.45_wp, 0.3_wp, -0.1_wp]
        call get_truss_response(law, 0.0_wp, length0, x1, x2, tension, stretch, force, block)
        do k = 1, 3
            xp = x2
            xm = x2
            xp(k) = xp(k) + fd_step
            xm(k) = xm(k) - fd_step
            call get_truss_response(law, 0.0_wp, length0, x1, xp, tension, stretch, fp)
            call get_truss_response(law, 0.0_wp, length0, x1, xm, tension, stretch, fm)
            fd(:, k) = (fp - fm) / (2 * fd_step)
        end do
        call check_close(error, reshape(block, [9]), reshape(fd, [9]), fd_tolerance, 'Z', &
            abs_tol=fd_tolerance * maxval(abs(fd)))
    end subroutine test_element_tangent

    !> The regularised tension adds slack_stiffness * k_ref * (stretch - 1/2), and the
    !> tangent is its exact derivative; with slack_stiffness = 0 a slack element carries
    !> nothing and has no stiffness.
    subroutine test_slack_element(error)
        type(error_type), allocatable, intent(out) :: error
        type(linear_law_type) :: law
        real(wp) :: force(3), block(3, 3), tension, stretch
        real(wp), parameter :: ratio = 1.0e-4_wp, ea = 5.0_wp

        call new_linear_law(law, ea, error)
        if (allocated(error)) return
        call get_truss_response(law, ratio, 1.0_wp, [0.0_wp, 0.0_wp, 0.0_wp], &
            [0.5_wp, 0.0_wp, 0.0_wp], tension, stretch, force, block)
        call check_close(error, tension, ratio * ea * (0.5_wp - 0.5_wp), 1.0e-14_wp, &
            'slack tension', abs_tol=1.0e-18_wp)
        if (allocated(error)) return
        call check_close(error, block(1, 1), ratio * ea / 1.0_wp, 1.0e-14_wp, 'axial stiffness')
        if (allocated(error)) return
        call check_close(error, block(2, 2), 0.0_wp, 1.0e-14_wp, 'transverse stiffness T/l', &
            abs_tol=1.0e-18_wp)
        if (allocated(error)) return
        call get_truss_response(law, ratio, 1.0_wp, [0.0_wp, 0.0_wp, 0.0_wp], &
            [1.5_wp, 0.0_wp, 0.0_wp], tension, stretch, force, block)
        call check_close(error, tension, ea * 0.5_wp + ratio * ea * (1.5_wp - 0.5_wp), &
            1.0e-14_wp, 'taut tension')
        if (allocated(error)) return
        call get_truss_response(law, ratio, 1.0_wp, [0.0_wp, 0.0_wp, 0.0_wp], &
            [1.0_wp, 0.0_wp, 0.0_wp], tension, stretch, force, block)
        call check_close(error, block(2, 2), ratio * ea * 0.5_wp, 1.0e-14_wp, &
            'transverse stiffness at the reference length')
        if (allocated(error)) return
        ! The spring in the tangent only: the force stays that of the exact law.
        call get_truss_response(law, 0.0_wp, 1.0_wp, [0.0_wp, 0.0_wp, 0.0_wp], &
            [0.5_wp, 0.0_wp, 0.0_wp], tension, stretch, force, block, tangent_spring=ratio)
        call check(error, tension == 0.0_wp .and. all(force == 0.0_wp), &
            'tangent-only spring: a slack element still carries nothing')
        if (allocated(error)) return
        call check_close(error, block(1, 1), ratio * ea / 1.0_wp, 1.0e-14_wp, &
            'tangent-only spring: axial stiffness of a slack element')
        if (allocated(error)) return
        call check_close(error, block(2, 2), ratio * ea * 0.5_wp / 0.5_wp, 1.0e-14_wp, &
            'tangent-only spring: transverse stiffness k / (2 l) of a slack element')
        if (allocated(error)) return
        call get_truss_response(law, 0.0_wp, 1.0_wp, [0.0_wp, 0.0_wp, 0.0_wp], &
            [0.5_wp, 0.0_wp, 0.0_wp], tension, stretch, force, block)
        call check(error, abs(tension) + maxval(abs(block)) <= 0.0_wp, &
            'exact tension-only law: a slack element carries nothing')
    end subroutine test_slack_element

    !> The stiffness cap of Newton's softened predictor: below the law's reference
    !> stiffness (EA for the linear law) a taut element's tension, force and tangent are
    !> the exact ones times cap / EA and the tangent is still the force's derivative
    !> (finite differences); at or above EA nothing changes; a slack element's
    !> regularising spring takes the capped stiffness.
    subroutine test_capped_element(error)
        type(error_type), allocatable, intent(out) :: error
        type(linear_law_type) :: law
        real(wp) :: force(3), block(3, 3), tension, stretch, exact_force(3)
        real(wp) :: exact_block(3, 3), exact_tension, fp(3), fm(3), xp(3), xm(3), fd(3, 3)
        real(wp), parameter :: ea = 3.0_wp, cap = 0.75_wp, length0 = 0.5_wp, ratio = 1.0e-4_wp
        real(wp), parameter :: x1(3) = [0.0_wp, 0.0_wp, 0.0_wp]
        real(wp), parameter :: x2(3) = [0.45_wp, 0.3_wp, -0.1_wp]
        integer :: k

        call new_linear_law(law, ea, error)
        if (allocated(error)) return
        call get_truss_response(law, 0.0_wp, length0, x1, x2, exact_tension, stretch, &
            exact_force, exact_block)
        call get_truss_response(law, 0.0_wp, length0, x1, x2, tension, stretch, force, block, &
            stiffness_cap=cap)
        call check_close(error, [tension, force, reshape(block, [9])], (cap / ea) &
            * [exact_tension, exact_force, reshape(exact_block, [9])], 1.0e-14_wp, &
            'capped tension, force and block', abs_tol=1.0e-15_wp)
        if (allocated(error)) return
        do k = 1, 3
            xp = x2
            xm = x2
            xp(k) = xp(k) + fd_step
            xm(k) = xm(k) - fd_step
            call get_truss_response(law, 0.0_wp, length0, x1, xp, tension, stretch, fp, &
                stiffness_cap=cap)
            call get_truss_response(law, 0.0_wp, length0, x1, xm, tension, stretch, fm, &
                stiffness_cap=cap)
            fd(:, k) = (fp - fm) / (2 * fd_step)
        end do
        call check_close(error, reshape(block, [9]), reshape(fd, [9]), fd_tolerance, &
            'capped Z', abs_tol=fd_tolerance * maxval(abs(fd)))
        if (allocated(error)) return
        call get_truss_response(law, 0.0_wp, length0, x1, x2, tension, stretch, force, block, &
            stiffness_cap=ea)
        call check(error, tension == exact_tension .and. all(force == exact_force) &
            .and. all(block == exact_block), 'a cap at EA changes nothing')
        if (allocated(error)) return
        call get_truss_response(law, ratio, 1.0_wp, x1, [0.5_wp, 0.0_wp, 0.0_wp], tension, &
            stretch, force, block, stiffness_cap=cap)
        call check_close(error, block(1, 1), ratio * cap / 1.0_wp, 1.0e-14_wp, &
            'slack element: axial stiffness of the spring of the capped law')
    end subroutine test_capped_element

    !> A small 3D net: 6 nodes, 8 elements, two laws, nodes 1 and 6 fully prescribed and
    !> node 3 prescribed in z.
    subroutine make_scene(scene, error)
        type(scene_type), intent(out) :: scene
        type(error_type), allocatable, intent(out) :: error
        type(linear_law_type), allocatable :: linear
        type(neo_hookean_law_type), allocatable :: neo
        integer :: c, count
        integer, parameter :: prescribed(7) = [1, 2, 3, 9, 16, 17, 18]

        allocate(scene%laws(2))
        allocate(linear, neo)
        call new_linear_law(linear, 4.0_wp, error)
        if (allocated(error)) return
        call new_neo_hookean_law(neo, 1.0e6_wp, 2.0e-6_wp, error)
        if (allocated(error)) return
        call move_alloc(linear, scene%laws(1)%law)
        call move_alloc(neo, scene%laws(2)%law)
        scene%network%position = reshape([ &
            0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.1_wp, 0.0_wp, 2.0_wp, 0.0_wp, 0.2_wp, &
            0.1_wp, 1.0_wp, 0.1_wp, 1.1_wp, 1.2_wp, -0.1_wp, 2.2_wp, 1.0_wp, 0.0_wp], [3, 6])
        scene%network%element_nodes = reshape([1, 2, 2, 3, 4, 5, 5, 6, 1, 4, 2, 5, 3, 6, &
            2, 4], [2, 8])
        scene%network%element_material = [1, 1, 2, 2, 1, 2, 1, 2]
        scene%network%yarn_first_element = [1, 9]
        scene%network%length0 = 0.9_wp * [1.0_wp, 1.0_wp, 1.0_wp, 1.1_wp, 1.0_wp, 1.1_wp, &
            1.0_wp, 1.4_wp]
        allocate(scene%dofs%unknown(18), scene%dofs%base(18), scene%dofs%delta(18, 2))
        scene%dofs%base = 0.0_wp
        scene%dofs%delta = 0.0_wp
        count = 0
        do c = 1, 18
            if (any(prescribed == c)) then
                scene%dofs%unknown(c) = 0
                scene%dofs%base(c) = scene%network%position(mod(c - 1, 3) + 1, (c - 1) / 3 + 1)
                scene%dofs%delta(c, 2) = 0.05_wp * c
            else
                count = count + 1
                scene%dofs%unknown(c) = count
            end if
        end do
        scene%dofs%n_unknowns = count
        allocate(scene%external_force(18, 2), source=0.0_wp)
        scene%external_force(8, 1) = -0.3_wp
        scene%solver%slack_stiffness = 1.0e-6_wp
    end subroutine make_scene

    subroutine test_pattern(error)
        type(error_type), allocatable, intent(out) :: error
        type(scene_type) :: scene
        type(pattern_type) :: pattern
        integer :: j, p, i, q
        logical :: found

        call make_scene(scene, error)
        if (allocated(error)) return
        call new_pattern(pattern, scene%network, scene%dofs)
        call check(error, pattern%n == scene%dofs%n_unknowns, 'pattern size')
        if (allocated(error)) return
        do j = 1, int(pattern%n)
            do p = int(pattern%col_ptr(j)) + 1, int(pattern%col_ptr(j + 1))
                if (p > int(pattern%col_ptr(j)) + 1) then
                    call check(error, pattern%row_index(p) > pattern%row_index(p - 1), &
                        'rows ascending and unique in each column')
                    if (allocated(error)) return
                end if
                i = int(pattern%row_index(p)) + 1
                found = .false.
                do q = int(pattern%col_ptr(i)) + 1, int(pattern%col_ptr(i + 1))
                    if (pattern%row_index(q) == j - 1) found = .true.
                end do
                call check(error, found, 'pattern symmetric')
                if (allocated(error)) return
            end do
        end do
    end subroutine test_pattern

    !> Every entry of the assembled sparse Jacobian against central differences of the
    !> residual, at a deformed state with stretched and slack elements.
    subroutine test_global_jacobian(error)
        type(error_type), allocatable, intent(out) :: error
        type(scene_type) :: scene
        type(pattern_type) :: pattern
        real(wp), allocatable :: u(:), up(:), rp(:), rm(:), values(:), dense(:, :), x(:, :)
        real(wp), parameter :: p_disp = 0.7_wp, p_force = 0.4_wp
        real(wp), parameter :: factors(2) = [p_force, p_disp]
        integer :: n, j, p

        call make_scene(scene, error)
        if (allocated(error)) return
        call new_pattern(pattern, scene%network, scene%dofs)
        n = scene%dofs%n_unknowns
        allocate(u(n), rp(n), rm(n), values(pattern%nnz), dense(n, n), x(3, 6))
        call scene%dofs%restrict(scene%network%position, u)
        u = u + 0.03_wp * [(sin(real(3 * j, wp)), j = 1, n)]
        call scene%dofs%expand(u, factors, x)
        call assemble_jacobian(scene, pattern, x, scene%network%length0, values, error)
        if (allocated(error)) return
        dense = 0.0_wp
        do j = 1, n
            do p = int(pattern%col_ptr(j)) + 1, int(pattern%col_ptr(j + 1))
                dense(pattern%row_index(p) + 1, j) = values(p)
            end do
        end do
        do j = 1, n
            up = u
            up(j) = u(j) + fd_step
            call scene%dofs%expand(up, factors, x)
            call assemble_residual(scene, x, scene%network%length0, factors, rp, error)
            if (allocated(error)) return
            up(j) = u(j) - fd_step
            call scene%dofs%expand(up, factors, x)
            call assemble_residual(scene, x, scene%network%length0, factors, rm, error)
            if (allocated(error)) return
            call check_close(error, dense(:, j), (rp - rm) / (2 * fd_step), fd_tolerance, &
                'Jacobian column', abs_tol=fd_tolerance * maxval(abs(dense)))
            if (allocated(error)) return
        end do
    end subroutine test_global_jacobian

    !> Internal forces of a free net sum to zero (each element pulls its nodes equally
    !> and oppositely).
    subroutine test_internal_balance(error)
        type(error_type), allocatable, intent(out) :: error
        type(scene_type) :: scene
        real(wp) :: internal(18), tension(8), stretch(8), total(3)
        integer :: k

        call make_scene(scene, error)
        if (allocated(error)) return
        call assemble_internal_force(scene, scene%network%position * 1.2_wp, &
            scene%network%length0, internal, tension, stretch, error)
        if (allocated(error)) return
        total = [(sum(internal(k::3)), k = 1, 3)]
        call check(error, maxval(abs(total)) <= 100 * epsilon(1.0_wp) * maxval(abs(internal)), &
            'internal forces balance')
    end subroutine test_internal_balance

end module test_assembly
