! SPDX-License-Identifier: MIT
!> Sliding contact: passages, conservation of reference length, and the Jacobian of the
!> frictional problem against finite differences.
module test_contact
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_testing, only: unittest_type, new_unittest, check, check_close
    use yarnfort_input_config, only: config_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_scene_builder, only: new_scene
    use yarnfort_contact_friction_problem, only: friction_problem_type, new_friction_problem, &
        mode_stick, mode_forward, mode_backward
    use yarnfort_contact_wrap_angle, only: get_wrap_angle
    use yarnfort_contact_stepper_active_set, only: drop_slips_flowing_back
    use yarnfort_generate_fabric, only: generate_fabric
    use two_pegs_scene, only: make_scene
    implicit none
    private

    public :: collect_contact

    real(wp), parameter :: fd_step = 1.0e-7_wp
    real(wp), parameter :: fd_tolerance = 1.0e-6_wp
    real(wp), parameter :: pi = acos(-1.0_wp)

contains

    subroutine collect_contact(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
            new_unittest('passages_found', test_passages), &
            new_unittest('flows_conserve_yarn_length', test_conservation), &
            new_unittest('wrap_angle_and_gradient', test_wrap_angle), &
            new_unittest('jacobian_matches_fd_monolithic', test_jacobian_full), &
            new_unittest('jacobian_matches_fd_positions_frozen', test_jacobian_frozen), &
            new_unittest('jacobian_matches_fd_periodic_gap_holders', test_jacobian_links), &
            new_unittest('links_follow_leaders', test_links_follow), &
            new_unittest('failed_round_drops_new_slips_flowing_back', test_drop_slips) ]
    end subroutine collect_contact

    !> A periodic 2 x 2 plain-weave cell from the generator: gap-holders at the crossings
    !> (gap factor 1 -> 0.7 over p_disp 0 -> 1) and periodic yarn ends with a macroscopic
    !> strain; warp and weft slide with adhesion.
    subroutine make_woven_scene(scene, error)
        type(scene_type), intent(out) :: scene
        type(error_type), allocatable, intent(out) :: error
        type(config_type) :: config

        allocate(config%materials(2))
        config%materials(1)%name = 'warp'
        config%materials(1)%law = 'neo_hookean'
        config%materials(1)%modulus = 1.0e6_wp
        config%materials(1)%area = 1.0e-5_wp
        config%materials(1)%prestress = 0.5_wp
        config%materials(2)%name = 'weft'
        config%materials(2)%law = 'linear'
        config%materials(2)%stiffness = 20.0_wp
        config%materials(2)%prestress = 0.3_wp
        allocate(config%contacts(1))
        config%contacts(1)%materials = [character(len=64) :: 'warp', 'weft']
        config%contacts(1)%law = 'adhesion'
        config%contacts(1)%friction_coefficient = 0.3_wp
        config%contacts(1)%adhesion = 0.05_wp
        config%fabric%kind = 'plain'
        config%fabric%cells = [2, 2]
        config%fabric%spacing = [1.0_wp, 0.8_wp]
        config%fabric%strain = 0.2_wp
        config%fabric%lateral_strain = -0.05_wp
        config%fabric%warp_material = 'warp'
        config%fabric%weft_material = 'weft'
        config%fabric%gap = 0.3_wp
        config%fabric%gap_factor_p_disp = [0.0_wp, 1.0_wp]
        config%fabric%gap_factor = [1.0_wp, 0.7_wp]
        config%path%time = [0.0_wp, 1.0_wp]
        config%path%p_force = [0.0_wp, 0.0_wp]
        config%path%p_disp = [0.0_wp, 1.0_wp]
        allocate(config%loads(0))
        call generate_fabric(config, error)
        if (allocated(error)) return
        call new_scene(scene, config, error)
    end subroutine make_woven_scene

    subroutine test_jacobian_links(error)
        type(error_type), allocatable, intent(out) :: error
        call check_jacobian(.false., error, woven=.true.)
    end subroutine test_jacobian_links

    !> Expanded positions: a gap-holder's far node sits at its leader plus the scaled gap,
    !> a periodic image at its leader plus the stretched period.
    subroutine test_links_follow(error)
        type(error_type), allocatable, intent(out) :: error
        type(scene_type) :: scene
        real(wp), allocatable :: u(:), x(:, :)
        real(wp), parameter :: p_disp = 0.4_wp, factor = 1.0_wp - 0.3_wp * p_disp
        integer :: j

        call make_woven_scene(scene, error)
        if (allocated(error)) return
        allocate(u(scene%dofs%n_unknowns), x(3, scene%network%n_nodes()))
        call scene%dofs%restrict(scene%network%position, u)
        u = u + 0.01_wp * [(sin(real(3 * j, wp)), j = 1, size(u))]
        call scene%dofs%expand(u, [0.0_wp, p_disp], x)
        ! Generator order: warp node, weft node per crossing (crossing (0,0) first, warp
        ! over, gap 0.3); then the warp ends at x = 0 and x = 2 of warp 0.
        call check_close(error, x(:, 2) - x(:, 1), [0.0_wp, 0.0_wp, -0.3_wp * factor], &
            1.0e-14_wp, 'gap-holder offset')
        if (allocated(error)) return
        call check_close(error, x(:, 10) - x(:, 9), [2.0_wp * (1.0_wp + 0.2_wp * p_disp), &
            0.0_wp, 0.0_wp], 1.0e-14_wp, 'periodic image offset')
    end subroutine test_links_follow

    !> A failed round's new slips (stick in the solved set, slipping in the failed one)
    !> whose flow increment has the wrong sign stick again; a passage already slipping
    !> stays, and nothing changes when every new slip flows back.
    subroutine test_drop_slips(error)
        type(error_type), allocatable, intent(out) :: error
        integer, parameter :: good(4) = [mode_stick, mode_stick, mode_stick, mode_forward]
        integer :: mode(4), dropped
        real(wp), parameter :: start(4) = [1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp]

        mode = [mode_forward, mode_backward, mode_forward, mode_forward]
        ! Increments +1, +1 (backward: back), -1 (forward: back), -1 (not new).
        call drop_slips_flowing_back(start + [1.0_wp, 1.0_wp, -1.0_wp, -1.0_wp], start, &
            good, mode, dropped)
        call check(error, dropped == 2 .and. all(mode == [mode_forward, mode_stick, &
            mode_stick, mode_forward]), 'the two new slips flowing back stick')
        if (allocated(error)) return
        mode = [mode_forward, mode_backward, mode_stick, mode_forward]
        call drop_slips_flowing_back(start + [-1.0_wp, 1.0_wp, 0.0_wp, 1.0_wp], start, &
            good, mode, dropped)
        call check(error, dropped == 0 .and. all(mode == [mode_forward, mode_backward, &
            mode_stick, mode_forward]), 'all new slips flowing back: none dropped')
    end subroutine test_drop_slips

    subroutine test_passages(error)
        type(error_type), allocatable, intent(out) :: error
        type(scene_type) :: scene

        call make_scene(scene, error)
        if (allocated(error)) return
        call check(error, scene%passages%size() == 2, 'two passages (C and E)')
        if (allocated(error)) return
        call check(error, all(scene%passages%node == [2, 3]) .and. &
            all(scene%passages%element_before == [2, 4]) .and. &
            all(scene%passages%element_after == [3, 5]), 'passage nodes and elements')
        if (allocated(error)) return
        call check(error, scene%passages%at_end(2) == 1 .and. scene%passages%at_start(3) == 1 &
            .and. scene%passages%at_start(1) == 0, 'element-passage links')
    end subroutine test_passages

    subroutine test_conservation(error)
        type(error_type), allocatable, intent(out) :: error
        type(scene_type) :: scene
        real(wp) :: length0(8)
        integer :: y, first, last

        call make_scene(scene, error)
        if (allocated(error)) return
        call scene%passages%get_length0(scene%network%length0, [0.123_wp, -0.0456_wp], length0)
        do y = 1, 3
            first = scene%network%yarn_first_element(y)
            last = scene%network%yarn_first_element(y + 1) - 1
            call check_close(error, sum(length0(first:last)), &
                sum(scene%network%length0(first:last)), 10 * epsilon(1.0_wp), 'yarn length')
            if (allocated(error)) return
        end do
    end subroutine test_conservation

    subroutine test_wrap_angle(error)
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: angle, dangle(3, 3), xb(3), xn(3), xa(3), xp(3), xm(3), ap, am, g(3, 3)
        integer :: node, k

        ! A right angle bend: alpha = pi/2; straight: alpha = 0; folded back: alpha = pi.
        call get_wrap_angle([1.0_wp, 0.0_wp, 0.0_wp], [0.0_wp, 0.0_wp, 0.0_wp], &
            [0.0_wp, 2.0_wp, 0.0_wp], 1.0e-8_wp, angle, dangle)
        call check_close(error, angle, pi / 2, 1.0e-15_wp, 'right angle')
        if (allocated(error)) return
        call get_wrap_angle([-1.0_wp, 0.0_wp, 0.0_wp], [0.0_wp, 0.0_wp, 0.0_wp], &
            [3.0_wp, 0.0_wp, 0.0_wp], 1.0e-8_wp, angle, dangle)
        call check_close(error, angle, 0.0_wp, 0.0_wp, 'straight', abs_tol=1.0e-15_wp)
        if (allocated(error)) return
        xb = [0.3_wp, 0.9_wp, -0.2_wp]
        xn = [0.0_wp, 0.1_wp, 0.0_wp]
        xa = [1.1_wp, 0.4_wp, 0.5_wp]
        call get_wrap_angle(xb, xn, xa, 1.0e-8_wp, angle, dangle)
        do node = 1, 3
            do k = 1, 3
                xp = 0.0_wp
                xp(k) = fd_step
                xm = -xp
                select case (node)
                case (1)
                    call get_wrap_angle(xb + xp, xn, xa, 1.0e-8_wp, ap, g)
                    call get_wrap_angle(xb + xm, xn, xa, 1.0e-8_wp, am, g)
                case (2)
                    call get_wrap_angle(xb, xn + xp, xa, 1.0e-8_wp, ap, g)
                    call get_wrap_angle(xb, xn + xm, xa, 1.0e-8_wp, am, g)
                case (3)
                    call get_wrap_angle(xb, xn, xa + xp, 1.0e-8_wp, ap, g)
                    call get_wrap_angle(xb, xn, xa + xm, 1.0e-8_wp, am, g)
                end select
                call check_close(error, dangle(k, node), (ap - am) / (2 * fd_step), &
                    fd_tolerance, 'd alpha / d x', abs_tol=fd_tolerance)
                if (allocated(error)) return
            end do
        end do
    end subroutine test_wrap_angle

    subroutine test_jacobian_full(error)
        type(error_type), allocatable, intent(out) :: error
        call check_jacobian(.false., error)
    end subroutine test_jacobian_full

    subroutine test_jacobian_frozen(error)
        type(error_type), allocatable, intent(out) :: error
        call check_jacobian(.true., error)
    end subroutine test_jacobian_frozen

    !> Every column of the assembled Jacobian against central differences of the
    !> residual, for each combination of modes of the two passages.
    subroutine check_jacobian(frozen, error, woven)
        logical, intent(in) :: frozen
        type(error_type), allocatable, intent(out) :: error
        !> The periodic woven cell (all passages in one mode per combination) instead.
        logical, intent(in), optional :: woven
        type(scene_type), target :: scene
        type(friction_problem_type) :: problem
        real(wp), allocatable :: u(:), up(:), rp(:), rm(:), values(:), dense(:, :), x0(:)
        integer :: n, j, p, m1, m2
        integer, parameter :: modes(3) = [mode_stick, mode_forward, mode_backward]

        if (present(woven)) then
            call make_woven_scene(scene, error)
        else
            call make_scene(scene, error)
        end if
        if (allocated(error)) return
        ! The exact tension-only law: the slack regularisation's transverse floor is a
        ! deliberate Jacobian approximation (see yarnfort_assembly_truss).
        scene%solver%slack_stiffness = 0.0_wp
        call new_friction_problem(problem, scene, frozen)
        problem%factors = [0.0_wp, 0.6_wp]
        problem%flow_target = [(0.01_wp * cos(real(j, wp)), j = 1, problem%n_p)]
        allocate(x0(scene%dofs%n_unknowns))
        call scene%dofs%restrict(scene%network%position, x0)
        x0 = x0 + 0.02_wp * [(cos(real(5 * j, wp)), j = 1, size(x0))]
        if (frozen) then
            problem%u_frozen = x0
            u = [(0.02_wp * sin(real(j, wp)), j = 1, problem%n_p)]
        else
            u = [x0, [(0.02_wp * sin(real(j, wp)), j = 1, problem%n_p)]]
        end if
        n = problem%get_size()
        allocate(rp(n), rm(n), values(size(problem%row_index)), dense(n, n))
        do m1 = 1, 3
            do m2 = 1, 3
                ! Alternate the two modes over the passages.
                problem%mode = [(merge(modes(m1), modes(m2), mod(p, 2) == 1), p = 1, problem%n_p)]
                call problem%evaluate_jacobian(u, values, error)
                if (allocated(error)) return
                dense = 0.0_wp
                do j = 1, n
                    do p = int(problem%col_ptr(j)) + 1, int(problem%col_ptr(j + 1))
                        dense(problem%row_index(p) + 1, j) = values(p)
                    end do
                end do
                do j = 1, n
                    up = u
                    up(j) = u(j) + fd_step
                    call problem%evaluate_residual(up, rp, error)
                    if (allocated(error)) return
                    up(j) = u(j) - fd_step
                    call problem%evaluate_residual(up, rm, error)
                    if (allocated(error)) return
                    call check_close(error, dense(:, j), (rp - rm) / (2 * fd_step), &
                        fd_tolerance, 'Jacobian column', abs_tol=fd_tolerance * maxval(abs(dense)))
                    if (allocated(error)) return
                end do
            end do
        end do
    end subroutine check_jacobian

end module test_contact
