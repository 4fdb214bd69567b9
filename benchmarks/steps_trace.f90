! SPDX-License-Identifier: MIT
!> Prints, per load step, where a friction step's work goes (the stepper's trace).
module steps_trace_observer
    use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_continuation, only: step_observer_type, step_state_type
    use yarnfort_contact_friction_stepper, only: friction_stepper_type, step_trace_type
    implicit none
    private
    public :: trace_observer_type

    type, extends(step_observer_type) :: trace_observer_type
        type(friction_stepper_type), pointer :: stepper => null()
        logical :: per_step = .false.
        !> Sums over the load steps (step 0, the initial state, apart).
        integer :: steps = 0, cuts = 0
        type(step_trace_type) :: total, initial
        real(wp) :: cpu_total = 0.0_wp, cpu_last = 0.0_wp, start_residual = 0.0_wp
    contains
        procedure :: on_step
        procedure :: on_cut
    end type trace_observer_type

contains

    subroutine on_step(self, scene, state, error)
        class(trace_observer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: now

        call cpu_time(now)
        associate(t => self%stepper%last_trace)
            if (self%per_step) write(output_unit, '(a, i5, f9.4, 3i4, 3i5, i4, 4i5, es10.2, &
                    & f10.2)') 'step', state%step, state%time, t%tries, t%rounds, &
                    t%failed_solves, t%iterations, t%residual_evaluations, &
                    t%jacobian_evaluations, state%direction, t%to_slip, t%to_stick, &
                    t%mode_changes, state%n_slipping, t%start_residual, 1e3_wp * (now - self%cpu_last)
            if (state%step == 0) then
                self%initial = t
            else
                self%steps = self%steps + 1
                self%cpu_total = self%cpu_total + (now - self%cpu_last)
                self%total%tries = self%total%tries + t%tries
                self%total%rounds = self%total%rounds + t%rounds
                self%total%failed_solves = self%total%failed_solves + t%failed_solves
                self%total%iterations = self%total%iterations + t%iterations
                self%total%residual_evaluations = self%total%residual_evaluations &
                    + t%residual_evaluations
                self%total%jacobian_evaluations = self%total%jacobian_evaluations &
                    + t%jacobian_evaluations
                self%total%to_slip = self%total%to_slip + t%to_slip
                self%total%to_stick = self%total%to_stick + t%to_stick
                self%total%mode_changes = self%total%mode_changes + t%mode_changes
                self%start_residual = self%start_residual + max(t%start_residual, 0.0_wp)
            end if
        end associate
        call cpu_time(self%cpu_last)
    end subroutine on_step

    subroutine on_cut(self, time, step, reason)
        class(trace_observer_type), intent(inout) :: self
        real(wp), intent(in) :: time, step
        character(len=*), intent(in) :: reason
        self%cuts = self%cuts + 1
        if (self%per_step) write(error_unit, '(a, g0.4, a)') 'steps_trace: cut at t = ', &
            time, ': ' // reason
    end subroutine on_cut

end module steps_trace_observer

!> Where the iterations and active-set rounds of friction load steps go.
!>     steps_trace <scene.nml> [--scheme monolithic|staggered] [--per-step]
!>     steps_trace --woven <crossings per side> [--skewed] [--scheme ...] [--per-step]
!> A scene file is read as the program reads standard input (file names relative to
!> the working directory); --woven builds benchmarks/bench_friction's crimped woven net
!> with 4 elements per segment (full cycle: load, unload to half, reload, 60 steps).
!> --per-step: a line per converged step: step, time, tries (1 + cuts), Newton solves
!> (active-set rounds), failed solves, Newton iterations, residual and Jacobian
!> evaluations, load direction, passages turned stick -> slip and slip -> stick by the
!> rounds, passages whose mode differs from the step before, slipping passages, scaled
!> residual of the first solve's initial guess (the predictor's), CPU ms.
!> Last, one `summary` line: unknowns, passages, steps, cuts, Newton iterations per
!> step, rounds per step, residual evaluations per step, stick -> slip and slip ->
!> stick changes per step, CPU ms per step (the continuation alone), CPU ms of one
!> elastic Newton iteration of the same net at the final state (its default linear
!> solver) and the ratio of the two. Then one `timings` line: Jacobian evaluations,
!> factorisations and linear solves per step, and the monolithic solver's wall ms per
!> step in residual and Jacobian assembly, analysis, factorisation, solves and the row
!> levels (step 0 included). The row levels are taken before the residual at each new
!> iterate and compute the state (the element loop) there: residual + levels is the
!> residual's whole work.
program steps_trace
    use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_input_config, only: config_type
    use yarnfort_input_namelist, only: read_config_from_file, check_config
    use yarnfort_generate_fabric, only: generate_fabric
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_scene_builder, only: new_scene
    use yarnfort_driver, only: get_linear_solver_name
    use yarnfort_solver_continuation, only: run_continuation
    use yarnfort_contact_friction_stepper, only: friction_stepper_type, new_friction_stepper
    use bench_common, only: fail, fail_usage, stop_if_help, read_integer_argument
    use bench_woven_net, only: make_woven_net, skew_net
    use bench_iteration, only: time_elastic_iteration
    use steps_trace_observer, only: trace_observer_type
    use yarnfort_linalg_process, only: apply_process_settings
    implicit none

    type(config_type) :: config
    type(scene_type), target :: scene
    type(friction_stepper_type), target :: stepper
    type(trace_observer_type) :: observer
    type(error_type), allocatable :: error
    character(len=512) :: argument, source, scheme
    character(len=*), parameter :: usage = &
        'usage: steps_trace <scene.nml> [--scheme monolithic|staggered] [--per-step]' // &
        new_line('a') // '       steps_trace --woven <crossings per side> [--skewed] ' // &
        '[--scheme ...] [--per-step]' // new_line('a') // &
        '(the columns: the comment at the top of benchmarks/steps_trace.f90)'
    logical :: woven, skewed
    integer :: k, side
    real(wp) :: elastic_ms, per_step

    call stop_if_help(usage)
    call apply_process_settings()
    woven = .false.
    skewed = .false.
    scheme = ''
    source = ''
    k = 0
    do while (k < command_argument_count())
        k = k + 1
        call get_command_argument(k, argument)
        select case (trim(argument))
        case ('--woven')
            woven = .true.
        case ('--skewed')
            skewed = .true.
        case ('--per-step')
            observer%per_step = .true.
        case ('--scheme')
            k = k + 1
            call get_command_argument(k, scheme)
        case default
            if (argument(1:1) == '-') call fail_usage('steps_trace', &
                "unknown option '" // trim(argument) // "'", usage)
            if (len_trim(source) > 0) call fail_usage('steps_trace', &
                "unexpected argument '" // trim(argument) // "'", usage)
            source = argument
        end select
    end do
    if (len_trim(source) == 0) call fail_usage('steps_trace', &
        'need a scene file or --woven <side>', usage)
    if (woven) then
        side = read_integer_argument('steps_trace', '--woven', source, usage)
        call make_woven_net(config, side, 4, 'monolithic')
        if (skewed) call skew_net(config, side)
    else
        call read_config_from_file(trim(source), config, error, from_working_directory=.true.)
        if (allocated(error)) call fail('steps_trace', error)
        call generate_fabric(config, error)
        if (allocated(error)) call fail('steps_trace', error)
        call check_config(config, error)
        if (allocated(error)) call fail('steps_trace', error)
    end if
    if (len_trim(scheme) > 0) config%solver%scheme = scheme
    call new_scene(scene, config, error)
    if (allocated(error)) call fail('steps_trace', error)
    if (scene%passages%size() == 0) then
        write(error_unit, '(a)') 'steps_trace: the scene has no sliding passages'
        stop 2, quiet=.true.
    end if
    call new_friction_stepper(stepper, scene, get_linear_solver_name(scene), error)
    if (allocated(error)) call fail('steps_trace', error)
    observer%stepper => stepper
    call cpu_time(observer%cpu_last)
    call run_continuation(scene, stepper, observer, error)
    if (allocated(error)) call fail('steps_trace', error)
    ! A scene whose positions are all prescribed has no elastic iteration to compare
    ! with: its time and the ratio print as NaN.
    elastic_ms = ieee_value(elastic_ms, ieee_quiet_nan)
    if (scene%dofs%n_unknowns > 0) elastic_ms = time_elastic_iteration(scene, stepper%u, &
        stepper%flow, stepper%factors, get_linear_solver_name(scene), 'steps_trace')
    per_step = 1e3_wp * observer%cpu_total / max(observer%steps, 1)
    associate(n => real(max(observer%steps, 1), wp), t => observer%total)
        write(output_unit, '(a, 2i9, 2i6, 5f9.2, 2f10.3, f9.2)') 'summary', &
            scene%dofs%n_unknowns, scene%passages%size(), observer%steps, observer%cuts, &
            t%iterations / n, t%rounds / n, t%residual_evaluations / n, t%to_slip / n, &
            t%to_stick / n, per_step, elastic_ms, per_step / elastic_ms
    end associate
    ! Where the monolithic solver's time goes, per load step (wall ms, step 0 and the
    ! elastic iteration's timing apart from it are included: small).
    block
        real(wp) :: residual_time, jacobian_time, analyse_time, factor_time, solve_time
        real(wp) :: levels_time
        integer :: n_factorisations, n_solves
        call stepper%newton_full%get_timings(residual_time, jacobian_time, analyse_time, &
            factor_time, solve_time, n_factorisations, n_solves, levels_time)
        associate(n => real(max(observer%steps, 1), wp), t => observer%total)
            write(output_unit, '(a, 3f9.2, 6f9.2)') 'timings jacobians/step ' &
                // 'factorisations/step solves/step, wall ms/step: residual jacobian ' &
                // 'analyse factor solve levels', t%jacobian_evaluations / n, &
                n_factorisations / n, n_solves / n, &
                1e3_wp * [residual_time, jacobian_time, analyse_time, factor_time, &
                solve_time, levels_time] / n
        end associate
    end block
end program steps_trace
