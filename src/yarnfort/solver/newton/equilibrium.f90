! SPDX-License-Identifier: MIT
!> The problem as the Newton solver and KINSOL's callbacks see it: the problem, the law
!> it is evaluated with, its row weights, the convergence history and the assembly's
!> timing.
module yarnfort_solver_newton_equilibrium
    use, intrinsic :: iso_c_binding, only: c_double
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    use yarnfort_solver_problem, only: nonlinear_problem_type, regularisation_type
    use yarnfort_solver_timer, only: wall_time
    use yarnfort_solver_interrupt, only: check_interrupt
    implicit none
    private

    public :: equilibrium_type, evaluate_timed, get_levels_timed, get_scaled_norm

    !> What KINSOL's callbacks see through their user-data pointer.
    type :: equilibrium_type
        class(nonlinear_problem_type), pointer :: problem => null()
        !> The law the problem is evaluated with (the exact law, or a predictor's).
        type(regularisation_type) :: law
        !> Order and nonzeros of the Jacobian (its pattern stays with the problem).
        integer(ik) :: n = 0, nnz = 0
        !> KINSOL's Jacobian matrix holds the pattern (written at its first evaluation).
        logical :: pattern_written = .false.
        real(wp), allocatable :: history(:)
        integer :: n_history = 0
        !> Give up (an error) after full_step_patience iterations without a new smallest
        !> residual: the solve's first attempt of full steps, which a line search follows.
        logical :: watch_stall = .false.
        real(wp) :: best_residual = huge(1.0_wp)
        integer :: since_best = 0
        !> KINSOL's residual scaling, 1 / (level_i + noise_i / tol).
        real(c_double), pointer :: row_weight(:) => null()
        type(error_type), allocatable :: error
        character(len=:), allocatable :: kinsol_message
        !> Accumulated wall time of residual and Jacobian assembly, and of the row
        !> levels (get_row_levels: the first call at a new iterate also computes the
        !> problem's state, which the residual there then finds done).
        real(wp) :: residual_time = 0.0_wp, jacobian_time = 0.0_wp, levels_time = 0.0_wp
    end type equilibrium_type

contains

    !> The problem's residual at u, or with `jacobian` its Jacobian values; the wall time
    !> goes to residual_time or jacobian_time (get_timings), for our calls and KINSOL's.
    subroutine evaluate_timed(problem, u, jacobian, values, error)
        type(equilibrium_type), intent(inout) :: problem
        real(wp), intent(in) :: u(:)
        logical, intent(in) :: jacobian
        real(wp), intent(out) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: start
        ! Every Newton path evaluates here: Ctrl-C fails the solve within an iteration.
        call check_interrupt(error)
        if (allocated(error)) return
        start = wall_time()
        if (jacobian) then
            call problem%problem%evaluate_jacobian(u, values, error, problem%law)
            problem%jacobian_time = problem%jacobian_time + (wall_time() - start)
        else
            call problem%problem%evaluate_residual(u, values, error, problem%law)
            problem%residual_time = problem%residual_time + (wall_time() - start)
        end if
    end subroutine evaluate_timed

    !> The problem's row levels at u; the wall time goes to levels_time (get_timings).
    subroutine get_levels_timed(problem, u, level, noise, error)
        type(equilibrium_type), intent(inout) :: problem
        real(wp), intent(in) :: u(:)
        real(wp), intent(out) :: level(:), noise(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: start
        start = wall_time()
        call problem%problem%get_row_levels(u, level, noise, error, problem%law)
        problem%levels_time = problem%levels_time + (wall_time() - start)
    end subroutine get_levels_timed

    !> f = maxval([0, |residual| * weight]) (a NaN product is passed over, as by maxval)
    !> and whether every residual entry is finite, in one pass without a temporary.
    pure subroutine get_scaled_norm(residual, weight, f, finite)
        real(wp), intent(in) :: residual(:), weight(:)
        real(wp), intent(out) :: f
        logical, intent(out) :: finite
        real(wp) :: scaled
        integer :: i

        f = 0.0_wp
        finite = .true.
        do i = 1, size(residual)
            finite = finite .and. ieee_is_finite(residual(i))
            scaled = abs(residual(i)) * weight(i)
            if (scaled > f) f = scaled
        end do
    end subroutine get_scaled_norm

end module yarnfort_solver_newton_equilibrium
