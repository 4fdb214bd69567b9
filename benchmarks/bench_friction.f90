! SPDX-License-Identifier: MIT
!> Counts steps, Newton iterations and slipping passages of a run.
module bench_friction_counter
    use, intrinsic :: iso_fortran_env, only: error_unit
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_continuation, only: step_observer_type, step_state_type
    implicit none
    private
    public :: counter_type

    type, extends(step_observer_type) :: counter_type
        integer :: steps = 0, newton = 0, max_slipping = 0
    contains
        procedure :: on_step
        procedure :: on_cut
    end type counter_type

contains

    subroutine on_step(self, scene, state, error)
        class(counter_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        type(error_type), allocatable, intent(out) :: error
        if (state%step == 0) return
        self%steps = self%steps + 1
        self%newton = self%newton + state%newton_iterations
        self%max_slipping = max(self%max_slipping, state%n_slipping)
    end subroutine on_step

    subroutine on_cut(self, time, step, reason)
        class(counter_type), intent(inout) :: self
        real(wp), intent(in) :: time, step
        character(len=*), intent(in) :: reason
        write(error_unit, '(a, g0.4, a)') 'bench_friction: cut at t = ', time, ': ' // reason
    end subroutine on_cut

end module bench_friction_counter

!> Benchmark of a load/unload cycle with sliding on a generated crimped woven net.
!>     bench_friction <crossings per side> <monolithic|staggered> [elements per segment
!>                    [linear solver]] [--skewed] [--steps N] [--no-line-search]
!>                    [--no-factor-times] [--max-border M]
!>     bench_friction --input <file.nml> <monolithic|staggered> [--steps N] ...
!> --input: the scene of a namelist input (e.g. benchmarks/knit40.nml; relative file
!> names in it are read from the working directory) instead of the woven net.
!> --skewed: every crossing node moved by a small fixed pseudo-random offset (up to 2 %
!> of the spacing in x and y, 0.01 in z), so that no element is aligned with an axis
!> (`zeros` in the `factors:` line: the fractions of exact zeros among the stored
!> entries of the friction Jacobian, in all and in its position block, flow rows and
!> flow columns, and of the elastic Jacobian). --steps N: only the first N load steps
!> of 0.05 (N <= 20: loading only; for the largest nets). --no-line-search: Newton
!> without KINSOL's line search. --no-factor-times: the `factors:` line without the
!> timed factorisations (-1; they take longer than the run itself above 1e5 unknowns).
!> --max-border M: the bordered solver's limit on slipping flows (default_max_border).
!> Prints, for the whole cycle: unknowns, passages, load steps, Newton iterations and
!> sparse factorisations per step, time per step, and the split of time between
!> assembly, factorisation, solves and the rest; peak resident memory; process CPU time
!> per step (the cycle alone).
!> Then a second line, `factors:` (both schemes: the staggered one finishes its steps
!> with monolithic solves), on the Jacobians at the final
!> state (bench_floor, CPU ms per factorisation + solve, nonzeros of L + U): the friction
!> Jacobian (final active set) with KLU's AMD and COLAMD orderings and UMFPACK, and the
!> elastic Jacobian of the same net and state with KLU and yarnfort's CHOLMOD.
!> Then, when the monolithic solver eliminates stick flows, a line `reduced:` (the
!> reduced system at the final state, as the `factors:` line, the reductions per step,
!> and KLU's predicted flops per factor nonzero with the solver they chose:
!> yarnfort_linalg_composite_lu_choice, and whether it was handed METIS' order), before it a line
!> `variants:` (bare KLU on the reduced system with scale 0 and 1, with METIS' order of
!> A + A^T, with AMD without aggressive absorption and with AMD's dense threshold 1:
!> nonzeros of L + U and CPU ms of refactor + solve; bench_floor's with_variants), and a
!> line `iteration:`: one Newton iteration of each problem at the final
!> state with the solvers yarnfort uses, and the cycle's CPU time per step against the
!> elastic one (write_iterations).
program bench_friction
    use, intrinsic :: iso_fortran_env, only: output_unit
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_input_config, only: config_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_scene_builder, only: new_scene
    use yarnfort_driver, only: get_linear_solver_name
    use yarnfort_solver_continuation, only: step_observer_type, step_state_type, &
        run_continuation
    use yarnfort_contact_friction_stepper, only: friction_stepper_type, new_friction_stepper
    use yarnfort_solver_timer, only: wall_time
    use bench_friction_counter, only: counter_type
    use bench_common, only: peak_memory_mib, fail, fail_usage, stop_if_help, &
        read_integer_argument
    use bench_woven_net, only: make_woven_net, skew_net
    use bench_iteration, only: time_iteration
    use bench_floor, only: floor_type, measure_floor
    use yarnfort_kinds, only: ik
    use yarnfort_solver_elastic_problem, only: elastic_problem_type, new_elastic_problem
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_factory, only: new_linear_solver
    use yarnfort_linalg_composite_condensed, only: condensed_solver_type
    use yarnfort_linalg_composite_lu_choice, only: lu_choice_solver_type
    use yarnfort_linalg_composite_bordered, only: bordered_solver_type
    use yarnfort_input_namelist, only: read_config_from_file, check_config
    use yarnfort_generate_fabric, only: generate_fabric
    use yarnfort_linalg_process, only: apply_process_settings
    implicit none

    type(config_type) :: config
    type(scene_type), target :: scene
    type(friction_stepper_type) :: stepper
    type(counter_type) :: counter
    type(error_type), allocatable :: error
    real(wp) :: total, start, times(3, 6), cpu_start, cpu_total
    integer :: side, per_segment, factorisations(3), n_positional, k, max_steps, max_border
    character(len=32) :: argument, scheme, positional(4)
    character(len=:), allocatable :: input_file
    logical :: skewed, line_search, time_factors
    character(len=*), parameter :: usage = 'usage: bench_friction --header' // new_line('a') &
        // '       bench_friction <crossings per side> <scheme> [elements per segment] ' // &
        '[linear solver] [options]' // new_line('a') // &
        '       bench_friction --input <scene.nml> <scheme> [options]' // new_line('a') // &
        'scheme: monolithic | staggered; options: --skewed --steps N --max-border M ' // &
        '--no-line-search --no-factor-times (see the comment at the top of ' // &
        'benchmarks/bench_friction.f90)'

    call stop_if_help(usage)
    call apply_process_settings()
    call get_command_argument(1, argument)
    if (trim(argument) == '--header') then
        write(output_unit, '(a)') '    scheme  unknowns  passages  steps  newton/step' // &
            '  factor/step     ms/step  assembly_%  factor_%  solve_%  other_%  max_slipping' // &
            '  peak_MiB  cpu_ms/step'
        stop
    end if
    skewed = .false.
    line_search = .true.
    time_factors = .true.
    max_steps = 0
    max_border = -1
    n_positional = 0
    k = 0
    do while (k < command_argument_count())
        k = k + 1
        call get_command_argument(k, argument)
        select case (trim(argument))
        case ('--skewed')
            skewed = .true.
        case ('--no-line-search')
            line_search = .false.
        case ('--no-factor-times')
            time_factors = .false.
        case ('--input')
            k = k + 1
            allocate(character(len=4096) :: input_file)
            call get_command_argument(k, input_file)
            input_file = trim(input_file)
        case ('--max-border')
            k = k + 1
            call get_command_argument(k, argument)
            max_border = read_integer_argument('bench_friction', '--max-border', argument, usage)
        case ('--steps')
            k = k + 1
            call get_command_argument(k, argument)
            max_steps = read_integer_argument('bench_friction', '--steps', argument, usage)
            if (max_steps < 1 .or. max_steps > 20) call fail_usage('bench_friction', &
                '--steps must be 1 to 20', usage)
        case default
            if (n_positional == size(positional)) call fail_usage('bench_friction', &
                "unexpected argument '" // trim(argument) // "'", usage)
            n_positional = n_positional + 1
            positional(n_positional) = argument
        end select
    end do
    if (allocated(input_file)) then
        if (n_positional /= 1) call fail_usage('bench_friction', &
            'need --input <file> <scheme>', usage)
        call read_config_from_file(input_file, config, error, from_working_directory=.true.)
        if (allocated(error)) call fail('bench_friction', error)
        call generate_fabric(config, error)
        if (allocated(error)) call fail('bench_friction', error)
        call check_config(config, error)
        if (allocated(error)) call fail('bench_friction', error)
        scheme = positional(1)
        config%solver%scheme = scheme
    else
        if (n_positional < 2) call fail_usage('bench_friction', &
            'need <crossings per side> <scheme>', usage)
        side = read_integer_argument('bench_friction', 'crossings per side', positional(1), &
            usage)
        scheme = positional(2)
        per_segment = 2
        if (n_positional >= 3) per_segment = read_integer_argument('bench_friction', &
            'elements per segment', positional(3), usage)
        call make_woven_net(config, side, per_segment, scheme)
        if (n_positional >= 4) config%solver%linear_solver = positional(4)
        if (skewed) call skew_net(config, side)
    end if
    if (max_steps > 0) then
        config%path%time = [0.0_wp, 0.05_wp * max_steps]
        config%path%p_force = [0.0_wp, 0.0_wp]
        config%path%p_disp = [0.0_wp, 0.05_wp * max_steps]
        config%solver%initial_step = 1.0_wp / max_steps
        config%solver%max_step = 1.0_wp / max_steps
    end if
    config%solver%line_search = line_search
    call new_scene(scene, config, error)
    if (allocated(error)) call fail('bench_friction', error)
    call new_friction_stepper(stepper, scene, get_linear_solver_name(scene), error)
    if (allocated(error)) call fail('bench_friction', error)
    if (max_border >= 0) call set_max_border(max_border)
    call cpu_time(cpu_start)
    start = wall_time()
    call run_continuation(scene, stepper, counter, error)
    total = wall_time() - start
    call cpu_time(cpu_total)
    cpu_total = cpu_total - cpu_start
    if (allocated(error)) call fail('bench_friction', error)
    times = 0.0_wp
    factorisations = 0
    ! Assembly: residuals, Jacobians and row levels (the first row-level call at a new
    ! iterate computes the problem's state, which the residual there then finds done).
    call stepper%newton_full%get_timings(times(1, 1), times(1, 2), times(1, 3), times(1, 4), &
        times(1, 5), factorisations(1), levels_time=times(1, 6))
    call stepper%newton_elastic%get_timings(times(2, 1), times(2, 2), times(2, 3), &
        times(2, 4), times(2, 5), factorisations(2), levels_time=times(2, 6))
    call stepper%newton_sliding%get_timings(times(3, 1), times(3, 2), times(3, 3), &
        times(3, 4), times(3, 5), factorisations(3), levels_time=times(3, 6))
    associate(assembly => sum(times(:, [1, 2, 6])), factor => sum(times(:, 3:4)), &
            solve => sum(times(:, 5)))
        write(output_unit, '(a10, i10, i10, i7, f13.2, f13.2, f12.2, 4f10.1, i14, f10.1, &
            & f13.2)') &
            trim(scheme), scene%dofs%n_unknowns, scene%passages%size(), counter%steps, &
            real(counter%newton, wp) / counter%steps, &
            real(sum(factorisations), wp) / counter%steps, 1e3_wp * total / counter%steps, &
            100 * assembly / total, 100 * factor / total, 100 * solve / total, &
            100 * (total - assembly - factor - solve) / total, counter%max_slipping, &
            peak_memory_mib(), 1e3_wp * cpu_total / counter%steps
    end associate
    call write_border_counts()
    if (associated(stepper%full)) call write_factors()
    ! Only where the run used its monolithic solver (a staggered run may never need its
    ! monolithic finish; its friction Jacobian was then never analysed).
    if (associated(stepper%full)) then
        if (stepper%newton_full%adapter%analysed) call write_iterations()
    end if

contains

    !> The bordered solver's limit (the monolithic solver's reduced systems).
    subroutine set_max_border(limit)
        integer, intent(in) :: limit

        select type (linear => stepper%newton_full%linear)
        type is (condensed_solver_type)
            select type (inner => linear%inner)
            type is (bordered_solver_type)
                inner%max_border = limit
            end select
        end select
    end subroutine set_max_border

    !> The `bordered:` line: the reduced systems' factorisations through the border and
    !> through the whole-matrix LU, their border unknowns (slipping flows; mean over all
    !> factorisations and most), K's failed factorisations, the patterns sent to the LU
    !> after them without trying K, and K's solver at the end.
    subroutine write_border_counts()
        select type (linear => stepper%newton_full%linear)
        type is (condensed_solver_type)
            select type (inner => linear%inner)
            type is (bordered_solver_type)
                write(output_unit, '(a, i0, a, i0, a, i0, a, f0.2, a, i0, a, i0, a, i0, a)') &
                    'bordered: limit ', inner%max_border, ' factorisations border ', &
                    inner%n_border_factors, ' general ', inner%n_general_factors, &
                    ' width mean ', real(inner%width_sum, wp) &
                    / max(1, inner%n_border_factors + inner%n_general_factors), ' max ', &
                    inner%max_width, ' leading failures ', inner%n_leading_failures, &
                    ' skipped patterns ', inner%n_skipped_patterns, &
                    ' leading ' // inner%leading%get_name()
            end select
        end select
    end subroutine write_border_counts

    !> The `border costs:` line: CPU ms of yarnfort's CHOLMOD factorisation of the elastic
    !> Jacobian at the final state (the bordered solver's K) and of its solves, per
    !> column, with 1, 8 and 32 columns at once (what each border unknown costs), and 4
    !> at once followed by 1.
    subroutine write_border_costs(n, col_ptr, row_index, values)
        integer(ik), intent(in) :: n, col_ptr(:), row_index(:)
        real(wp), intent(in) :: values(:)
        integer, parameter :: widths(3) = [1, 8, 32]
        real(wp), parameter :: target_seconds = 0.3_wp
        class(linear_solver_type), allocatable :: solver
        real(wp) :: factor_ms, column_ms(size(widths)), start, finish
        integer :: k, repeats

        call new_linear_solver(solver, 'cholmod', error)
        if (allocated(error)) call fail('bench_friction', error)
        call solver%analyse(n, col_ptr, row_index, error)
        if (allocated(error)) call fail('bench_friction', error)
        repeats = 0
        call cpu_time(start)
        finish = start
        do while (finish - start < target_seconds .or. repeats == 0)
            call solver%factor(values, error)
            if (allocated(error)) then
                write(output_unit, '(a)') 'border costs: ' // error%message
                return
            end if
            repeats = repeats + 1
            call cpu_time(finish)
        end do
        factor_ms = 1e3_wp * (finish - start) / repeats
        do k = 1, size(widths)
            column_ms(k) = solve_ms(solver, n, widths(k), .false.)
        end do
        write(output_unit, '(a, f0.3, a, 3(a, i0, a, f0.4, a), a, f0.4, a)') &
            'border costs: K factor ', factor_ms, ' ms; solve per column', &
            (' (', widths(k), ' at once) ', column_ms(k), ' ms', k = 1, size(widths)), &
            ' (4 at once, then 1) ', solve_ms(solver, n, 4, .true.), ' ms'

    end subroutine write_border_costs

    !> CPU ms per column of `width` columns solved at once by `solver` (then one more
    !> column alone, as the border's solve and a Newton step alternate, with `then_one`).
    real(wp) function solve_ms(solver, n, width, then_one)
        class(linear_solver_type), intent(inout) :: solver
        integer(ik), intent(in) :: n
        integer, intent(in) :: width
        logical, intent(in) :: then_one
        real(wp), parameter :: target_seconds = 0.3_wp
        real(wp), allocatable :: rhs(:, :)
        real(wp) :: start, finish
        integer :: repeats

        allocate(rhs(n, width))
        repeats = 0
        call cpu_time(start)
        finish = start
        do while (finish - start < target_seconds .or. repeats == 0)
            rhs = 1.0_wp
            call solver%solve_columns(rhs, error)
            if (allocated(error)) call fail('bench_friction', error)
            if (then_one) call solver%solve(rhs(:, 1), error)
            if (allocated(error)) call fail('bench_friction', error)
            repeats = repeats + 1
            call cpu_time(finish)
        end do
        solve_ms = 1e3_wp * (finish - start) / (repeats * (width + merge(1, 0, then_one)))
    end function solve_ms

    !> The `iteration:` line: CPU ms of one Newton iteration at the final state
    !> (residual, Jacobian, factorisation and solve with the solver the run used) of the
    !> monolithic friction problem and of the elastic problem of the same net (its
    !> default solver), the cycle's CPU ms per load step and its ratio to the elastic
    !> iteration.
    subroutine write_iterations()
        type(elastic_problem_type), target :: problem
        class(linear_solver_type), allocatable :: elastic_solver
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        real(wp), allocatable :: values(:), residual(:), u(:)
        real(wp) :: friction_ms(2), elastic_ms(2)
        character(len=:), allocatable :: elastic_name
        type(floor_type) :: reduced

        associate(full => stepper%full)
            u = [stepper%u, stepper%flow]
            full%mode = stepper%mode
            call full%prepare_solve(u, error)
            if (allocated(error)) call fail('bench_friction', error)
            allocate(values(full%get_nonzeros()), residual(size(u)))
            call time_iteration(full, stepper%newton_full%linear, u, values, residual, &
                friction_ms, 'bench_friction')
        end associate
        select type (linear => stepper%newton_full%linear)
        type is (condensed_solver_type)
            call measure_floor('klu', linear%n_reduced, linear%reduced_col_ptr, &
                linear%reduced_row_index, values(linear%source), reduced, error, &
                with_metis=.true., with_variants=.true.)
            if (allocated(error)) call fail('bench_friction', error)
            write(output_unit, '(a, 5(es9.2, a, f8.2, a))') 'variants: klu scale0 ', &
                reduced%variant_lu(1), ' (', reduced%variant_ms(1), ' ms) scale1 ', &
                reduced%variant_lu(2), ' (', reduced%variant_ms(2), ' ms) metis ', &
                reduced%variant_lu(3), ' (', reduced%variant_ms(3), ' ms) amd-noaggr ', &
                reduced%variant_lu(4), ' (', reduced%variant_ms(4), ' ms) amd-dense1 ', &
                reduced%variant_lu(5), ' (', reduced%variant_ms(5), ' ms)'
            write(output_unit, '(a, i0, a, i0, a, f8.2, a, 3(es9.2, a, f8.2, a), a, &
                & 3(f9.2, a))', advance='no') &
                'reduced: n ', linear%n_reduced, ' nnz ', size(linear%source), &
                ' reductions/step ', real(linear%n_reductions, wp) / counter%steps, &
                ' LU: klu-amd ', reduced%klu_lu, ' (', reduced%klu_ms, ' ms)  umfpack ', &
                reduced%umfpack_lu, ' (', reduced%umfpack_ms, ' ms)  umfpack-metis ', &
                reduced%umfpack_metis_lu, ' (', reduced%umfpack_metis_ms, ' ms)', &
                ' analyse ms: klu ', reduced%klu_analyse_ms, ' umfpack ', &
                reduced%umfpack_analyse_ms, ' umfpack-metis ', &
                reduced%umfpack_metis_analyse_ms, ' |'
            select type (inner => linear%inner)
            type is (bordered_solver_type)
                ! The whole-matrix LU's prediction, if this pattern went to it.
                write(output_unit, '(a)', advance='no') ' ' // inner%get_name()
                if (.not. inner%use_border) call write_choice(inner%general)
            class default
                call write_choice(inner)
            end select
            write(output_unit, '(a)') ''
        end select
        call new_elastic_problem(problem, scene)
        call scene%passages%get_length0(scene%network%length0, stepper%flow, problem%length0)
        problem%factors = stepper%factors
        elastic_name = get_linear_solver_name(scene)
        call new_linear_solver(elastic_solver, elastic_name, error)
        if (allocated(error)) call fail('bench_friction', error)
        allocate(col_ptr(problem%get_size() + 1), row_index(problem%get_nonzeros()))
        call problem%copy_pattern(col_ptr, row_index)
        call elastic_solver%analyse(int(problem%get_size(), ik), col_ptr, row_index, error)
        if (allocated(error)) call fail('bench_friction', error)
        deallocate(values, residual)
        allocate(values(problem%get_nonzeros()), residual(problem%get_size()))
        call time_iteration(problem, elastic_solver, stepper%u, values, residual, elastic_ms, &
            'bench_friction', error)
        if (allocated(error)) then
            ! Slack elements at the final state can leave the elastic Jacobian singular.
            write(output_unit, '(a)') 'iteration: elastic ' // elastic_name // &
                ' at the final state: ' // error%message
            return
        end if
        write(output_unit, '(a, 2(f9.3, a), f9.3, a, f9.3, a, f9.2, a, f8.2)') &
            'iteration: friction ', sum(friction_ms), ' ms (assembly ', friction_ms(1), &
            ' ms, ' // stepper%newton_full%linear%get_name() // ') | elastic ', &
            sum(elastic_ms), ' ms (assembly ', elastic_ms(1), ' ms, ' // elastic_name // &
            ') | cpu ms/step ', 1e3_wp * cpu_total / counter%steps, ' = elastic x ', &
            1e3_wp * cpu_total / counter%steps / sum(elastic_ms)
    end subroutine write_iterations

    !> KLU's prediction and the choice of a lu_choice solver, else the solver's name.
    subroutine write_choice(solver)
        class(linear_solver_type), intent(in) :: solver

        select type (solver)
        type is (lu_choice_solver_type)
            write(output_unit, '(a, es9.2, a, es9.2, a, f8.1, a)', advance='no') &
                ' predicted flops ', solver%predicted_flops, ' LU ', &
                solver%predicted_nonzeros, ' flops/nonzero ', &
                solver%predicted_flops / max(1.0_wp, solver%predicted_nonzeros), &
                ' -> ' // solver%get_name()
            if (solver%metis_order) write(output_unit, '(a, es9.2, a)', advance='no') &
                ' with metis order (LU ', solver%ordered_nonzeros, ')'
        class default
            write(output_unit, '(a)', advance='no') ' ' // solver%get_name()
        end select
    end subroutine write_choice

    !> The `factors:` line (program notes).
    subroutine write_factors()
        type(floor_type) :: friction, elastic
        type(elastic_problem_type), target :: problem
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        real(wp), allocatable :: values(:)
        integer(ik) :: n, nnz, n_elastic, nnz_elastic
        real(wp) :: zeros, zeros_elastic, zero_blocks(3)

        associate(full => stepper%full)
            n = full%get_size()
            nnz = full%get_nonzeros()
            allocate(col_ptr(n + 1), row_index(nnz), values(nnz))
            call full%copy_pattern(col_ptr, row_index)
            full%mode = stepper%mode
            call full%prepare_solve([stepper%u, stepper%flow], error)
            if (allocated(error)) call fail('bench_friction', error)
            call full%evaluate_jacobian([stepper%u, stepper%flow], values, error)
            if (allocated(error)) call fail('bench_friction', error)
            zeros = real(count(values == 0.0_wp), wp) / nnz
            call count_zeros(n, col_ptr, row_index, values, zero_blocks)
            if (time_factors) then
                call measure_floor('klu', n, col_ptr, row_index, values, friction, error)
                if (allocated(error)) call fail('bench_friction', error)
            end if
        end associate
        call new_elastic_problem(problem, scene)
        call scene%passages%get_length0(scene%network%length0, stepper%flow, problem%length0)
        problem%factors = stepper%factors
        n_elastic = problem%get_size()
        nnz_elastic = problem%get_nonzeros()
        deallocate(col_ptr, row_index, values)
        allocate(col_ptr(n_elastic + 1), row_index(nnz_elastic), values(nnz_elastic))
        call problem%copy_pattern(col_ptr, row_index)
        call problem%evaluate_jacobian(stepper%u, values, error)
        if (allocated(error)) call fail('bench_friction', error)
        zeros_elastic = real(count(values == 0.0_wp), wp) / nnz_elastic
        if (time_factors) then
            call measure_floor('cholmod', n_elastic, col_ptr, row_index, values, elastic, error)
            if (allocated(error)) call fail('bench_friction', error)
            call write_border_costs(n_elastic, col_ptr, row_index, values)
        end if
        write(output_unit, '(a, i0, a, i0, a, 4(es9.2, a, f8.2, a), a, i0, a, i0, a, &
            & es9.2, a, f8.2, a, f8.2, a, 5(f5.1, a))') &
            'factors: friction n ', n, ' nnz ', nnz, &
            ' LU: klu-amd ', friction%klu_lu, ' (', friction%klu_ms, ' ms)  klu-colamd ', &
            friction%klu_colamd_lu, ' (', friction%klu_colamd_ms, ' ms)  klu-amd-nobtf ', &
            friction%klu_nobtf_lu, ' (', friction%klu_nobtf_ms, ' ms)  umfpack ', &
            friction%umfpack_lu, ' (', friction%umfpack_ms, ' ms)', &
            ' | elastic n ', n_elastic, ' nnz ', nnz_elastic, ' LU: klu-amd ', &
            elastic%klu_lu, ' (', elastic%klu_ms, ' ms)  cholmod (', elastic%yarnfort_ms, &
            ' ms) | zeros: friction ', 100 * zeros, ' % (positions ', 100 * zero_blocks(1), &
            ' %, flow rows ', 100 * zero_blocks(2), ' %, flow columns ', 100 * zero_blocks(3), &
            ' %) elastic ', 100 * zeros_elastic, ' %'
    end subroutine write_factors

    !> Fractions of exact zeros among the stored entries of the friction Jacobian: in the
    !> position block, the flow rows and the flow columns (rows and columns past
    !> scene%dofs%n_unknowns are the flows').
    subroutine count_zeros(n, col_ptr, row_index, values, fractions)
        integer(ik), intent(in) :: n, col_ptr(:), row_index(:)
        real(wp), intent(in) :: values(:)
        real(wp), intent(out) :: fractions(3)
        integer :: column, k, n_positions, block_index
        integer :: zeros(3), stored(3)
        logical :: flow_row, flow_column

        n_positions = scene%dofs%n_unknowns
        zeros = 0
        stored = 0
        do column = 1, int(n)
            flow_column = column > n_positions
            do k = int(col_ptr(column)) + 1, int(col_ptr(column + 1))
                flow_row = row_index(k) + 1 > n_positions
                if (flow_row .and. flow_column) cycle
                block_index = 1
                if (flow_row) block_index = 2
                if (flow_column) block_index = 3
                stored(block_index) = stored(block_index) + 1
                if (values(k) == 0.0_wp) zeros(block_index) = zeros(block_index) + 1
            end do
        end do
        fractions = real(zeros, wp) / max(1, stored)
    end subroutine count_zeros

end program bench_friction
