! SPDX-License-Identifier: MIT
!> newton_solver_type%try_chord's finishing steps (solve_options_type%finish_steps) on
!> u_i + a u_i^3 = 1 from u = 0: the Newton step there has J = 1, so every chord step
!> is u <- u - F(u) and contracts by about 3 a u*^2 (0.029 for a = 0.01, 0.085 for
!> a = 0.03). Residuals by hand (a = 0.01): 1, 1e-2, 2.97e-4, 8.74e-6, 2.57e-7 after the
!> three chord steps, then 7.6e-9, 2.2e-10, 6.5e-12: the tolerance 1e-10 needs all three
!> finishing steps. For a = 0.03 the last chord step leaves 1.9e-5 at r = 0.085, which
!> three more steps would take to 1.2e-8 only: none is taken. A path stopped after its
!> Newton step and resumed (resume_try_chord) is the same path.
module test_chord
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    use yarnfort_testing, only: unittest_type, new_unittest, check, check_close
    use yarnfort_input_config, only: solver_config_type
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_factory, only: new_linear_solver
    use yarnfort_solver_problem, only: nonlinear_problem_type, regularisation_type
    use yarnfort_solver_newton, only: newton_solver_type, new_newton_solver, newton_stats_type, &
        solve_options_type
    implicit none
    private

    public :: collect_chord

    !> Two uncoupled rows u_i + a u_i^3 - 1, each judged at level 1 (no rounding noise).
    type, extends(nonlinear_problem_type) :: cubic_problem_type
        real(wp) :: a = 0.0_wp
    contains
        procedure :: evaluate_residual
        procedure :: evaluate_jacobian
        procedure :: get_row_levels
    end type cubic_problem_type

contains

    subroutine collect_chord(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)
        testsuite = [ &
            new_unittest('finishing_steps_save_a_factorisation', test_finishing), &
            new_unittest('no_finishing_step_without_the_rate', test_slow_rate), &
            new_unittest('resumed_path_is_the_whole_path', test_resumed), &
            new_unittest('no_resume_after_other_factors', test_no_resume) ]
    end subroutine collect_chord

    subroutine evaluate_residual(self, u, values, error, law)
        class(cubic_problem_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        real(wp), intent(out) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        type(regularisation_type), intent(in), optional :: law
        values = u + self%a * u**3 - 1.0_wp
    end subroutine evaluate_residual

    subroutine evaluate_jacobian(self, u, values, error, law)
        class(cubic_problem_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        real(wp), intent(out) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        type(regularisation_type), intent(in), optional :: law
        values = 1.0_wp + 3.0_wp * self%a * u**2
    end subroutine evaluate_jacobian

    subroutine get_row_levels(self, u, level, noise, error, law)
        class(cubic_problem_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        real(wp), intent(out) :: level(:), noise(:)
        type(error_type), allocatable, intent(out) :: error
        type(regularisation_type), intent(in), optional :: law
        level = 1.0_wp
        noise = 0.0_wp
    end subroutine get_row_levels

    !> try_chord from u = 0 with 3 chord steps and `finish` finishing steps: its stats,
    !> whether it converged, the solution and the solver's factorisations and solves.
    subroutine run_chord(a, finish, u, stats, converged, n_factorisations, n_solves, error)
        real(wp), intent(in) :: a
        integer, intent(in) :: finish
        real(wp), allocatable, intent(out) :: u(:)
        type(newton_stats_type), intent(out) :: stats
        logical, intent(out) :: converged
        integer, intent(out) :: n_factorisations, n_solves
        type(error_type), allocatable, intent(out) :: error
        type(cubic_problem_type), target :: problem
        type(newton_solver_type) :: newton
        real(wp) :: t(5)

        call new_cubic(a, problem, newton, u, error)
        if (allocated(error)) return
        call newton%try_chord(u, stats, converged, error, &
            solve_options_type(chord_steps=3, finish_steps=finish))
        if (allocated(error)) return
        call newton%get_timings(t(1), t(2), t(3), t(4), t(5), n_factorisations, n_solves)
    end subroutine run_chord

    !> a = 0.01: without finishing steps the path stops at 2.6e-7 (a second Newton step
    !> would follow); with three it converges to the root on its one factorisation.
    subroutine test_finishing(error)
        type(error_type), allocatable, intent(out) :: error
        type(newton_stats_type) :: stats
        real(wp), allocatable :: u(:)
        real(wp) :: root
        logical :: converged
        integer :: n_factorisations, n_solves, k

        call run_chord(0.01_wp, 0, u, stats, converged, n_factorisations, n_solves, error)
        if (allocated(error)) return
        call check(error, .not. converged .and. size(stats%residual_history) == 5, &
            'without finishing steps: one Newton step and three chord steps, not converged')
        if (allocated(error)) return
        call check_close(error, stats%residual_norm, 2.57e-7_wp, 1.0e-2_wp, &
            'residual after them')
        if (allocated(error)) return

        call run_chord(0.01_wp, 3, u, stats, converged, n_factorisations, n_solves, error)
        if (allocated(error)) return
        call check(error, converged .and. n_factorisations == 1 .and. n_solves == 7, &
            'with three finishing steps: converged on one factorisation, seven solves')
        if (allocated(error)) return
        ! The root of u + 0.01 u^3 = 1 by bisection (independent of the solver).
        block
            real(wp) :: lo, hi
            lo = 0.0_wp
            hi = 1.0_wp
            do k = 1, 200
                root = 0.5_wp * (lo + hi)
                if (root + 0.01_wp * root**3 > 1.0_wp) then
                    hi = root
                else
                    lo = root
                end if
            end do
        end block
        call check_close(error, u(1), root, 1.0e-10_wp, 'solution')
        if (allocated(error)) return
        call check_close(error, u(2), root, 1.0e-10_wp, 'solution, second row')
    end subroutine test_finishing

    !> a = 0.03: the rate after the chord steps (0.085) does not reach the tolerance in
    !> three more steps, so none is taken (four solves: the Newton step, three chord).
    subroutine test_slow_rate(error)
        type(error_type), allocatable, intent(out) :: error
        type(newton_stats_type) :: stats
        real(wp), allocatable :: u(:)
        logical :: converged
        integer :: n_factorisations, n_solves

        call run_chord(0.03_wp, 3, u, stats, converged, n_factorisations, n_solves, error)
        if (allocated(error)) return
        call check(error, .not. converged .and. n_factorisations == 1 .and. n_solves == 4, &
            'no finishing step: not converged, one factorisation, four solves')
        if (allocated(error)) return
        call check_close(error, stats%residual_norm, 1.89e-5_wp, 1.0e-2_wp, &
            'residual after the chord steps')
    end subroutine test_slow_rate

    !> The root of u + a u^3 = 1 by bisection (independent of the solver).
    pure real(wp) function cubic_root(a) result(root)
        real(wp), intent(in) :: a
        real(wp) :: lo, hi
        integer :: k
        lo = 0.0_wp
        hi = 1.0_wp
        root = 0.5_wp
        do k = 1, 200
            root = 0.5_wp * (lo + hi)
            if (root + a * root**3 > 1.0_wp) then
                hi = root
            else
                lo = root
            end if
        end do
    end function cubic_root

    !> A new solver of the two cubic rows with coefficient a from u = 0.
    subroutine new_cubic(a, problem, newton, u, error)
        real(wp), intent(in) :: a
        type(cubic_problem_type), target, intent(inout) :: problem
        type(newton_solver_type), intent(out) :: newton
        real(wp), allocatable, intent(out) :: u(:)
        type(error_type), allocatable, intent(out) :: error
        type(solver_config_type) :: options
        class(linear_solver_type), allocatable :: linear

        problem%a = a
        problem%col_ptr = [0_ik, 1_ik, 2_ik]
        problem%row_index = [0_ik, 1_ik]
        call new_linear_solver(linear, 'klu', error)
        if (allocated(error)) return
        call new_newton_solver(newton, problem, linear, options, error)
        if (allocated(error)) return
        allocate(u(2), source=0.0_wp)
    end subroutine new_cubic

    !> a = 0.01, the Newton step alone (residual 1e-2 by hand), then resumed with three
    !> chord and three finishing steps: the six residuals by hand (2.97e-4 ... 6.5e-12),
    !> the root, one factorisation and seven solves, as the whole path (test_finishing).
    subroutine test_resumed(error)
        type(error_type), allocatable, intent(out) :: error
        type(cubic_problem_type), target :: problem
        type(newton_solver_type) :: newton
        type(newton_stats_type) :: stats
        real(wp), allocatable :: u(:)
        real(wp) :: t(5)
        real(wp), parameter :: by_hand(6) = [2.97e-4_wp, 8.74e-6_wp, 2.57e-7_wp, &
            7.6e-9_wp, 2.2e-10_wp, 6.5e-12_wp]
        logical :: converged
        integer :: n_factorisations, n_solves, k

        call new_cubic(0.01_wp, problem, newton, u, error)
        if (allocated(error)) return
        call newton%try_chord(u, stats, converged, error, &
            solve_options_type(chord_steps=0, finish_steps=0))
        if (allocated(error)) return
        call check(error, .not. converged .and. size(stats%residual_history) == 2, &
            'stopped after the Newton step')
        if (allocated(error)) return
        call check_close(error, stats%residual_norm, 1.0e-2_wp, 1.0e-2_wp, &
            'residual after the Newton step')
        if (allocated(error)) return
        call newton%resume_try_chord(u, stats, converged, &
            solve_options_type(chord_steps=3, finish_steps=3))
        call newton%get_timings(t(1), t(2), t(3), t(4), t(5), n_factorisations, n_solves)
        call check(error, converged .and. n_factorisations == 1 .and. n_solves == 7 &
            .and. size(stats%residual_history) == 6, &
            'resumed: converged on one factorisation, seven solves, six residuals')
        if (allocated(error)) return
        do k = 1, 6
            call check_close(error, stats%residual_history(k), by_hand(k), 2.0e-2_wp, &
                'residual of the resumed path')
            if (allocated(error)) return
        end do
        call check_close(error, u(1), cubic_root(0.01_wp), 1.0e-10_wp, 'solution')
    end subroutine test_resumed

    !> After another Newton step (new factors) a stopped path is not resumed: u stays.
    subroutine test_no_resume(error)
        type(error_type), allocatable, intent(out) :: error
        type(cubic_problem_type), target :: problem
        type(newton_solver_type) :: newton
        type(newton_stats_type) :: stats
        real(wp), allocatable :: u(:), kept(:)
        logical :: converged

        call new_cubic(0.01_wp, problem, newton, u, error)
        if (allocated(error)) return
        call newton%try_chord(u, stats, converged, error, &
            solve_options_type(chord_steps=0, finish_steps=0))
        if (allocated(error)) return
        kept = u
        call newton%take_newton_step(kept, error)
        if (allocated(error)) return
        kept = u
        call newton%resume_try_chord(u, stats, converged, &
            solve_options_type(chord_steps=3, finish_steps=3))
        call check(error, .not. converged .and. all(u == kept) &
            .and. .not. allocated(stats%residual_history), 'not resumed, u unchanged')
    end subroutine test_no_resume

end module test_chord
