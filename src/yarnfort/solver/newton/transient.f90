! SPDX-License-Identifier: MIT
!> Pseudo-transient continuation: the Newton solver's fallback where neither full nor
!> line-searched Newton steps converge.
module yarnfort_solver_newton_transient
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    use yarnfort_solver_sunlinsol_adapter, only: factor_counted, solve_counted
    use yarnfort_solver_newton_stats, only: newton_stats_type
    use yarnfort_solver_newton_equilibrium, only: evaluate_timed, get_levels_timed, &
        get_scaled_norm
    use yarnfort_solver_newton_base, only: newton_base_type, analyse_once, set_row_weights
    implicit none
    private

    public :: solve_transient

    !> Iterations of the pseudo-transient fallback, in units of max_iterations.
    integer, parameter :: transient_iterations = 4
    !> The fallback gives up when its shift exceeds this multiple of the row levels per
    !> length (steps too short to matter).
    real(wp), parameter :: max_transient_shift = 1.0e12_wp

contains

    !> Pseudo-transient continuation (switched evolution relaxation): Newton steps on
    !> F(u) + mu D du = 0, D_i = level_i / length_scale, with mu falling as the scaled
    !> residual f does (mu <- mu f_new / f_old) and a step that raises f rejected (mu
    !> times 10). Far from the solution it follows a damped, implicit-Euler path that
    !> handles stiff directions (an inextensible yarn) and slow ones (a ring sliding
    !> along it) together, where a line search on |F| crawls; as mu -> 0 it is Newton.
    !> Works on self%u from u; on success self%u is the solution, `converged` is set.
    subroutine solve_transient(self, u, stats, converged, error)
        class(newton_base_type), intent(inout) :: self
        real(wp), intent(in) :: u(:)
        type(newton_stats_type), intent(inout) :: stats
        logical, intent(out) :: converged
        type(error_type), allocatable, intent(out) :: error
        type(error_type), allocatable :: trial_error
        real(wp), allocatable :: residual(:), trial(:), values(:), step(:), shift(:)
        real(wp), allocatable :: level(:), noise(:)
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        integer, allocatable :: diagonal(:)
        integer :: i, k, iteration
        real(wp) :: mu, f, merit, merit_trial
        logical :: finite

        converged = .false.
        associate(problem => self%problem%problem, n => size(u))
            allocate(col_ptr(n + 1), row_index(self%problem%nnz), values(self%problem%nnz))
            call problem%copy_pattern(col_ptr, row_index)
            allocate(diagonal(n), source=0)
            do i = 1, n
                do k = int(col_ptr(i)) + 1, int(col_ptr(i + 1))
                    if (row_index(k) == i - 1) diagonal(i) = k
                end do
            end do
            if (any(diagonal == 0)) return
            call analyse_once(self, col_ptr, row_index, error)
            if (allocated(error)) return
            call problem%prepare_solve(u, error, self%problem%law)
            if (allocated(error)) return
            self%u = u
            allocate(residual(n), step(n), level(n), noise(n), shift(n))
            call get_levels_timed(self%problem, self%u, level, noise, error)
            if (allocated(error)) return
            shift = max(level, tiny(1.0_wp)) / problem%length_scale
            call set_row_weights(self, .false., error)
            if (allocated(error)) return
            call evaluate_timed(self%problem, self%u, .false., residual, error)
            if (allocated(error)) return
            call get_scaled_norm(residual, self%f_scale_data, f, finite)
            merit = norm2(residual * self%f_scale_data)
            mu = 1.0_wp
            do iteration = 1, transient_iterations * self%options%max_iterations
                if (f <= self%options%residual_tolerance) exit
                call evaluate_timed(self%problem, self%u, .true., values, error)
                if (allocated(error)) return
                values(diagonal) = values(diagonal) + mu * shift
                call factor_counted(self%adapter, values, trial_error)
                stats%jacobian_evaluations = stats%jacobian_evaluations + 1
                if (.not. allocated(trial_error)) then
                    step = -residual
                    call solve_counted(self%adapter, step, trial_error)
                end if
                if (.not. allocated(trial_error)) then
                    trial = self%u + step
                    call evaluate_timed(self%problem, trial, .false., residual, trial_error)
                    stats%residual_evaluations = stats%residual_evaluations + 1
                end if
                ! Accept a step that lowers the weighted 2-norm of the residual (a smooth
                ! merit: the max-norm test stalls on steps that trade one row for another).
                if (allocated(trial_error)) then
                    deallocate(trial_error)
                    merit_trial = huge(1.0_wp)
                else
                    merit_trial = norm2(residual * self%f_scale_data)
                end if
                if (merit_trial < merit) then
                    stats%iterations = stats%iterations + 1
                    self%u = trial
                    mu = mu * merit_trial / merit
                    ! The levels follow the state (as in solve_once).
                    call set_row_weights(self, .false., error)
                    if (allocated(error)) return
                    call get_scaled_norm(residual, self%f_scale_data, f, finite)
                    merit = norm2(residual * self%f_scale_data)
                else
                    mu = 10 * mu
                    if (mu > max_transient_shift) exit
                    call evaluate_timed(self%problem, self%u, .false., residual, error)
                    if (allocated(error)) return
                end if
            end do
            stats%residual_norm = f
            converged = f <= self%options%residual_tolerance
        end associate
    end subroutine solve_transient

end module yarnfort_solver_newton_transient
