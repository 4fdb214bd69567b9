! SPDX-License-Identifier: MIT
!> Newton's method for a nonlinear_problem_type (the network's equilibrium, with or
!> without sliding), driven by SUNDIALS KINSOL (line search globalisation) with the
!> analytic sparse Jacobian and a yarnfort linear solver behind a Fortran
!> SUNLinearSolver. Proxy module over solver/newton/: stats and options (stats.f90),
!> KINSOL and its callbacks (kinsol.f90), the shared state and steps (base.f90), the
!> chord paths (chord.f90), the row update, a low-rank solver of its own
!> (row_update.f90), pseudo-transient continuation (transient.f90) and the fallback
!> ladder (ladder.f90).
!> Convergence: row i is converged when |F_i| <= residual_tolerance * level_i + noise_i,
!> with the problem's row levels (the forces meeting at a node, a passage's tensions)
!> and the rounding level of the row's evaluation; levels are taken at the initial
!> guess and checked again at the solution (KINSOL goes on if they changed).
!> A solve that fails with the exact law goes down the fallback ladder (ladder.f90);
!> the answer is always that of the exact law.
module yarnfort_solver_newton
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: solver_config_type
    use yarnfort_solver_problem, only: nonlinear_problem_type
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_solver_newton_stats, only: newton_stats_type, solve_options_type
    use yarnfort_solver_newton_equilibrium, only: evaluate_timed
    use yarnfort_solver_newton_kinsol, only: new_kinsol
    use yarnfort_solver_newton_base, only: newton_base_type, start_newton, newton_step, &
        set_exact_law
    use yarnfort_solver_newton_chord, only: solve_chord, resume_chord, solve_row_update
    use yarnfort_solver_newton_ladder, only: solve_with_fallbacks
    implicit none
    private

    public :: newton_solver_type, newton_stats_type, solve_options_type, new_newton_solver

    !> Owns KINSOL's memory, vectors, matrix and the linear solver for one scene.
    type, extends(newton_base_type) :: newton_solver_type
    contains
        !> Solve for unknowns u (in: initial guess, out: solution).
        procedure :: solve
        !> One Newton step from u, without a convergence test.
        procedure :: take_newton_step
        !> The first Newton step and its chord steps only (no fallback): converged, or
        !> the best iterate to judge before solving on.
        procedure :: try_chord
        !> The chord steps of a try_chord path stopped after its Newton step.
        procedure :: resume_try_chord
        !> Chord steps of a problem whose rows `rows` changed since the last Newton step,
        !> with that step's factors and a low-rank correction (no factorisation).
        procedure :: try_row_update
    end type newton_solver_type

contains

    !> Set up KINSOL for `problem` (which must outlive the solver) with `linear` as the
    !> linear solver (ownership passes to the Newton solver) and the &solver options.
    subroutine new_newton_solver(self, problem, linear, options, error)
        type(newton_solver_type), intent(out) :: self
        class(nonlinear_problem_type), target, intent(in) :: problem
        class(linear_solver_type), allocatable, intent(inout) :: linear
        type(solver_config_type), intent(in) :: options
        type(error_type), allocatable, intent(out) :: error
        integer :: n

        self%options = options
        allocate(self%problem)
        self%problem%problem => problem
        self%problem%n = int(problem%get_size(), ik)
        self%problem%nnz = problem%get_nonzeros()
        allocate(self%problem%history(options%max_iterations + 2))
        n = problem%get_size()
        if (n == 0) then
            call fatal_error(error, 'the scene has no unknowns: every coordinate is prescribed')
            return
        end if

        allocate(self%linear, source=linear)
        deallocate(linear)
        allocate(self%adapter)
        self%adapter%solver => self%linear

        allocate(self%u(n), self%u_scale_data(n), self%f_scale_data(n))
        self%u = 0.0_wp
        self%u_scale_data = 1.0_wp / problem%length_scale
        self%f_scale_data = 1.0_wp
        self%problem%row_weight => self%f_scale_data
        call new_kinsol(self%kinsol, self%problem, self%adapter, self%u, self%u_scale_data, &
            self%f_scale_data, options, error)
    end subroutine new_newton_solver

    !> Solve from the initial guess u with every fallback (ladder.f90) unless
    !> options%quick, after options%chord_steps chord steps unless `after_chord` (u is
    !> where try_chord left off). stats add up all attempts.
    subroutine solve(self, u, stats, error, options, after_chord)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        type(newton_stats_type), intent(out) :: stats
        type(error_type), allocatable, intent(out) :: error
        type(solve_options_type), intent(in), optional :: options
        logical, intent(in), optional :: after_chord
        type(solve_options_type) :: chosen
        logical :: chorded

        if (present(options)) chosen = options
        chorded = .false.
        if (present(after_chord)) chorded = after_chord
        call solve_with_fallbacks(self, u, chosen, chorded, stats, error)
    end subroutine solve

    !> The chord fast path of `solve` alone (options%chord_steps chord steps):
    !> `converged`, u is the solution; else u is the best of its iterates (or the start),
    !> and the caller decides whether to solve on (`solve` from u) or to change the
    !> problem first.
    subroutine try_chord(self, u, stats, converged, error, options)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        type(newton_stats_type), intent(out) :: stats
        logical, intent(out) :: converged
        type(error_type), allocatable, intent(out) :: error
        type(solve_options_type), intent(in) :: options

        call set_exact_law(self)
        call solve_chord(self, u, options%chord_steps, options%finish_steps, stats, converged, &
            error)
    end subroutine try_chord

    !> The chord steps (options%chord_steps, finish_steps) of a try_chord path that took
    !> none, from its Newton step's iterate with that step's factors (resume_chord): the
    !> path try_chord with those steps would have taken; u and `converged` as there.
    subroutine resume_try_chord(self, u, stats, converged, options)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        type(newton_stats_type), intent(out) :: stats
        logical, intent(out) :: converged
        type(solve_options_type), intent(in) :: options

        call resume_chord(self, u, options%chord_steps, options%finish_steps, stats, &
            converged)
    end subroutine resume_try_chord

    !> Chord steps from u for a problem that differs from the one of the last Newton
    !> step in its rows `rows` only, with that step's factors (solve_row_update).
    subroutine try_row_update(self, u, rows, stats, converged, error)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        integer, intent(in) :: rows(:)
        type(newton_stats_type), intent(out) :: stats
        logical, intent(out) :: converged
        type(error_type), allocatable, intent(out) :: error

        call solve_row_update(self, u, rows, stats, converged, error)
    end subroutine try_row_update

    !> u <- u + one Newton step of the exact law from u (no convergence test): the
    !> direction a solve from u sets out in.
    subroutine take_newton_step(self, u, error)
        class(newton_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: u(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: residual(:)

        call set_exact_law(self)
        call start_newton(self, u, error)
        if (allocated(error)) return
        allocate(residual(size(u)))
        call evaluate_timed(self%problem, self%u, .false., residual, error)
        if (allocated(error)) return
        call newton_step(self, residual, error)
        if (allocated(error)) return
        u = self%u
    end subroutine take_newton_step

end module yarnfort_solver_newton
