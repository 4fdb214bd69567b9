! SPDX-License-Identifier: MIT
!> newton_solver_type%try_row_update: a friction problem whose passage row changed since
!> the last Newton step is solved with that step's factors and the new row, to the
!> solution a fresh solve of the changed problem finds, without a factorisation; and
!> nothing is tried once other factors (a KINSOL solve) replaced them.
module test_row_update
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_testing, only: unittest_type, new_unittest, check, check_close
    use yarnfort_scene_scene, only: scene_type
    use two_pegs_scene, only: make_scene
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_factory, only: new_linear_solver
    use yarnfort_solver_newton, only: newton_solver_type, new_newton_solver, newton_stats_type, &
        solve_options_type
    use yarnfort_contact_friction_problem, only: friction_problem_type, new_friction_problem, &
        mode_stick, mode_forward, mode_backward
    implicit none
    private

    public :: collect_row_update

    !> The friction stepper's solves: three chord steps after the first Newton step.
    type(solve_options_type), parameter :: chorded = solve_options_type(chord_steps=3)

contains

    subroutine collect_row_update(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
            new_unittest('stop_solved_with_kept_factors', test_stop), &
            new_unittest('slip_solved_with_kept_factors', test_slip), &
            new_unittest('nothing_tried_after_other_factors', test_other_factors) ]
    end subroutine collect_row_update

    !> The scene's friction problem at half the displacement, all stick, solved; a
    !> Newton solver with chord steps (as the friction stepper's) and the unknowns `u`.
    !> The yarn and the pegs are prestressed (2 N, 0.3 N), so the passages carry 1.3-1.4 N
    !> that differ by 3-8 %: a slip direction and a slipping solution near `u` exist.
    !> Without it the scene moves rigidly and the passages' tensions are 0 and 7e-15 N;
    !> the tests then forced a slip in a direction chosen by that round-off, and whether
    !> Newton found a solution depended on the BLAS kernels (OpenBLAS' Prescott and
    !> SkylakeX kernels: no; Haswell, Sandybridge, reference BLAS: yes).
    subroutine set_up(scene, problem, newton, u, error)
        type(scene_type), target, intent(inout) :: scene
        type(friction_problem_type), target, intent(inout) :: problem
        type(newton_solver_type), intent(inout) :: newton
        real(wp), allocatable, intent(out) :: u(:)
        type(error_type), allocatable, intent(out) :: error
        class(linear_solver_type), allocatable :: linear
        type(newton_stats_type) :: stats

        call make_scene(scene, error, prestress=[2.0_wp, 0.3_wp])
        if (allocated(error)) return
        call new_friction_problem(problem, scene, positions_frozen=.false.)
        problem%factors = [0.0_wp, 0.5_wp]
        problem%flow_target = 0.0_wp
        problem%locked = 0
        problem%mode = mode_stick
        call new_linear_solver(linear, 'umfpack', error)
        if (allocated(error)) return
        call new_newton_solver(newton, problem, linear, scene%solver, error)
        if (allocated(error)) return
        allocate(u(scene%dofs%n_unknowns + problem%n_p), source=0.0_wp)
        call scene%dofs%restrict(scene%network%position, u(1:scene%dofs%n_unknowns))
        call newton%solve(u, stats, error, chorded)
    end subroutine set_up

    !> The changed problem from `start`: by try_row_update (which must converge without
    !> a Newton iteration) and by a fresh solve; the two solutions agree.
    subroutine check_update(problem, newton, start, rows, error)
        type(friction_problem_type), intent(inout) :: problem
        type(newton_solver_type), intent(inout) :: newton
        real(wp), intent(in) :: start(:)
        integer, intent(in) :: rows(:)
        type(error_type), allocatable, intent(out) :: error
        type(newton_stats_type) :: stats
        real(wp), allocatable :: updated(:), fresh(:)
        logical :: converged

        updated = start
        call newton%try_row_update(updated, rows, stats, converged, error)
        if (allocated(error)) return
        call check(error, converged, 'try_row_update did not converge')
        if (allocated(error)) return
        call check(error, stats%iterations == 0 .and. stats%jacobian_evaluations == 1 &
            .and. size(stats%residual_history) > 2, 'try_row_update: no factorisation, ' &
            // 'one Jacobian evaluation, more than one chord step')
        if (allocated(error)) return
        call check(error, maxval(abs(updated - start)) > 1.0e-6_wp, &
            'try_row_update: the changed problem moved the unknowns')
        if (allocated(error)) return
        fresh = start
        call newton%solve(fresh, stats, error, chorded)
        if (allocated(error)) return
        ! Both to the residual tolerance (1e-8 of the forces): positions and flows agree to
        ! far less than the 1e-6 they moved.
        call check_close(error, updated, fresh, 0.0_wp, 'row update against a fresh solve', &
            abs_tol=1.0e-9_wp)
    end subroutine check_update

    !> Passage p slips (towards its higher tension at `u`) and the set is solved from u.
    subroutine solve_slipping(problem, newton, u, p, error)
        type(friction_problem_type), intent(inout) :: problem
        type(newton_solver_type), intent(inout) :: newton
        real(wp), intent(inout) :: u(:)
        integer, intent(in) :: p
        type(error_type), allocatable, intent(out) :: error
        type(newton_stats_type) :: stats
        real(wp) :: t_before, t_after, angle

        call problem%update_state(u, error)
        if (allocated(error)) return
        call problem%get_passage_state(p, t_before, t_after, angle)
        problem%mode(p) = merge(mode_forward, mode_backward, t_after > t_before)
        call newton%solve(u, stats, error, chorded)
    end subroutine solve_slipping

    !> Factors of a Newton step at `u` (a solution: the step stays there).
    subroutine factor_at(newton, u, error)
        type(newton_solver_type), intent(inout) :: newton
        real(wp), intent(in) :: u(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: stepped(:)
        stepped = u
        call newton%take_newton_step(stepped, error)
    end subroutine factor_at

    !> Passage 1 slips and is solved; with the factors there it stops at a flow 1e-4
    !> beyond the solved one.
    subroutine test_stop(error)
        type(error_type), allocatable, intent(out) :: error
        type(scene_type), target :: scene
        type(friction_problem_type), target :: problem
        type(newton_solver_type) :: newton
        real(wp), allocatable :: u(:)
        integer :: n_x

        call set_up(scene, problem, newton, u, error)
        if (allocated(error)) return
        n_x = scene%dofs%n_unknowns
        call solve_slipping(problem, newton, u, 1, error)
        if (allocated(error)) return
        call factor_at(newton, u, error)
        if (allocated(error)) return
        problem%mode(1) = mode_stick
        problem%flow_target(1) = u(n_x + 1) + 1.0e-4_wp
        call check_update(problem, newton, u, [n_x + 1], error)
    end subroutine test_stop

    !> Passage 2 slips and is solved, then sticks at a flow 1e-4 short of that and is
    !> solved; with the factors there it slips again (back to the first solution).
    subroutine test_slip(error)
        type(error_type), allocatable, intent(out) :: error
        type(scene_type), target :: scene
        type(friction_problem_type), target :: problem
        type(newton_solver_type) :: newton
        type(newton_stats_type) :: stats
        real(wp), allocatable :: u(:)
        integer :: n_x, direction

        call set_up(scene, problem, newton, u, error)
        if (allocated(error)) return
        n_x = scene%dofs%n_unknowns
        call solve_slipping(problem, newton, u, 2, error)
        if (allocated(error)) return
        direction = problem%mode(2)
        problem%mode(2) = mode_stick
        problem%flow_target(2) = u(n_x + 2) - merge(1.0e-4_wp, -1.0e-4_wp, &
            direction == mode_forward)
        call newton%solve(u, stats, error, chorded)
        if (allocated(error)) return
        call factor_at(newton, u, error)
        if (allocated(error)) return
        problem%mode(2) = direction
        call check_update(problem, newton, u, [n_x + 2], error)
    end subroutine test_slip

    !> After a KINSOL solve the kept factors are not the linear solver's: nothing is
    !> evaluated and the unknowns stay.
    subroutine test_other_factors(error)
        type(error_type), allocatable, intent(out) :: error
        type(scene_type), target :: scene
        type(friction_problem_type), target :: problem
        type(newton_solver_type) :: newton
        type(newton_stats_type) :: stats
        real(wp), allocatable :: u(:), start(:)
        logical :: converged
        integer :: n_x

        call set_up(scene, problem, newton, u, error)
        if (allocated(error)) return
        n_x = scene%dofs%n_unknowns
        call factor_at(newton, u, error)
        if (allocated(error)) return
        ! A solve from a moved start without the chord path: KINSOL factors again.
        start = u
        start(1:n_x) = start(1:n_x) + 1.0e-3_wp
        call newton%solve(start, stats, error)
        if (allocated(error)) return
        problem%flow_target(1) = 1.0e-4_wp
        start = u
        call newton%try_row_update(start, [n_x + 1], stats, converged, error)
        if (allocated(error)) return
        call check(error, .not. converged .and. stats%residual_evaluations == 0 &
            .and. all(start == u), 'try_row_update tried with other factors')
    end subroutine test_other_factors

end module test_row_update
