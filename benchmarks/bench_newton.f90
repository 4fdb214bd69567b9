! SPDX-License-Identifier: MIT
!> Benchmark of one Newton solve on a generated pretensioned cable net.
!>     bench_newton <interior nodes per side> <linear solver> [max_setup_calls]
!> Prints one line of figures per run (see the header printed with --header): unknowns,
!> nonzeros, Newton iterations, factorisations, and per-iteration wall times of residual
!> assembly, Jacobian assembly, numeric factorisation, solve, and everything else;
!> total time and peak resident memory (VmHWM) of the process. Then memory per unknown
!> (bytes): the growth of the peak resident memory from before the net is built
!> (`grow_B/dof`), and for UMFPACK its own figures of the last factorisation: the
!> Numeric object, i.e. the LU factors (`umf_LU_B/dof`), and its peak during symbolic
!> analysis and numeric factorisation (`umf_peak_B/dof`), with the ratios of the growth
!> to each (`x_LU`, `x_peak`).
!> Then the floor (bench_floor) on the Jacobian at the solution: ms per factorisation +
!> solve of this solver in yarnfort (`yf_ms`), of bare UMFPACK analysed with the values
!> (`umf_ms`, its strategy `st`) and with the pattern only (`umf_pat_ms`, `st`), and of bare
!> KLU (`klu_ms`, -1 above 3e5 unknowns); the ratios of yarnfort's to the bare library
!> of the same name
!> (`x_bare`, '-' for dense) and of a whole yarnfort Newton iteration to the
!> fastest bare library (`iter_x_floor`), all in process CPU time; bare CHOLMOD
!> (`chol_ms`) for 'cholmod' and 'cholmod+klu'. `nnz` counts the free rows and columns
!> only. Last, the process CPU time of the solve (`cpu_s`) and the displacement along z
!> of the interior node nearest the centre (`w_centre`, m; compare.py checks it against
!> OpenSeesPy).
!> The optional 4th argument `linear` gives the net of benchmarks/compare.py: linear
!> strings (EA = 10 N, corotTruss with an elastic material in OpenSees) and a first
!> guess with the interior nodes at the homogeneous pre-stretch of the supports (both
!> codes start there: at the flat stress-free net the transverse stiffness of a truss
!> model is zero and OpenSees' first factorisation fails).
program bench_newton
    use, intrinsic :: iso_fortran_env, only: output_unit
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    use yarnfort_input_config, only: config_type
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_scene_builder, only: new_scene
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_factory, only: new_linear_solver
    use yarnfort_linalg_backend_umfpack, only: umfpack_solver_type, umfpack_memory_type
    use yarnfort_solver_newton, only: newton_solver_type, new_newton_solver, newton_stats_type
    use yarnfort_solver_elastic_problem, only: elastic_problem_type, new_elastic_problem
    use yarnfort_solver_timer, only: wall_time
    use bench_common, only: peak_memory_mib, fail, number_grid_nodes, fail_usage, &
        stop_if_help, read_integer_argument
    use bench_floor, only: floor_type, measure_floor
    use yarnfort_linalg_process, only: apply_process_settings
    implicit none
    type(config_type) :: config
    type(scene_type), target :: scene
    type(newton_solver_type) :: newton
    type(elastic_problem_type), target :: problem
    class(linear_solver_type), allocatable :: linear
    type(newton_stats_type) :: stats
    type(error_type), allocatable :: error
    real(wp), allocatable :: u(:)
    real(wp) :: t_residual, t_jacobian, t_analyse, t_factor, t_solve, total, start, other
    real(wp) :: baseline_mib, growth, cpu_start, cpu_total
    type(umfpack_memory_type) :: umfpack_memory
    logical :: have_umfpack
    integer :: side, setup_calls, n_factor, iterations
    character(len=32) :: argument, solver_name, variant
    !> Largest order at which the floor times bare KLU (above it one KLU factorisation of
    !> the cable net takes over a minute, and KLU is never the default there).
    integer, parameter :: klu_floor_max = 300000
    character(len=*), parameter :: usage = 'usage: bench_newton --header' // new_line('a') &
        // '       bench_newton <interior nodes per side> <linear solver> ' // &
        '[max_setup_calls] [neo_hookean | linear]'

    call stop_if_help(usage)
    call apply_process_settings()
    call get_command_argument(1, argument)
    if (trim(argument) == '--header') then
        write(output_unit, '(a)') 'solver  setup  unknowns       nnz  iters  facts' // &
            '  residual_ms  jacobian_ms  factor_ms  solve_ms  other_ms  other_%' // &
            '  analyse_ms  total_s  peak_MiB  grow_B/dof  umf_LU_B/dof  umf_peak_B/dof' // &
            '  x_LU  x_peak  yf_ms  umf_ms st  umf_pat_ms st  klu_ms  chol_ms  x_bare' // &
            '  iter_x_floor  cpu_s  w_centre'
        stop
    end if
    if (command_argument_count() < 2) call fail_usage('bench_newton', &
        'need <interior nodes per side> <linear solver>', usage)
    side = read_integer_argument('bench_newton', 'interior nodes per side', argument, usage)
    call get_command_argument(2, solver_name)
    setup_calls = 1
    if (command_argument_count() >= 3) then
        call get_command_argument(3, argument)
        setup_calls = read_integer_argument('bench_newton', 'max_setup_calls', argument, usage)
    end if
    variant = 'neo_hookean'
    if (command_argument_count() >= 4) call get_command_argument(4, variant)
    if (variant /= 'neo_hookean' .and. variant /= 'linear') then
        call fail_usage('bench_newton', "4th argument '" // trim(variant) // &
            "' is neither 'neo_hookean' nor 'linear'", usage)
    end if

    baseline_mib = peak_memory_mib()
    call make_cable_net(config, side, setup_calls, solver_name, variant)
    call new_scene(scene, config, error)
    if (allocated(error)) call fail('bench_newton', error)
    call new_linear_solver(linear, trim(solver_name), error)
    if (allocated(error)) call fail('bench_newton', error)
    call new_elastic_problem(problem, scene)
    problem%factors = [1.0_wp, 1.0_wp]
    call new_newton_solver(newton, problem, linear, scene%solver, error)
    if (allocated(error)) call fail('bench_newton', error)
    allocate(u(scene%dofs%n_unknowns))
    call scene%dofs%restrict(scene%network%position, u)
    if (variant == 'linear') call stretch_first_guess()

    call cpu_time(cpu_start)
    start = wall_time()
    call newton%solve(u, stats, error)
    total = wall_time() - start
    call cpu_time(cpu_total)
    cpu_total = cpu_total - cpu_start
    if (allocated(error)) call fail('bench_newton', error)
    call newton%get_timings(t_residual, t_jacobian, t_analyse, t_factor, t_solve, n_factor)
    iterations = max(stats%iterations, 1)
    other = total - (t_residual + t_jacobian + t_analyse + t_factor + t_solve)
    growth = (peak_memory_mib() - baseline_mib) * 1024.0_wp**2 / scene%dofs%n_unknowns
    have_umfpack = .false.
    select type (solver => newton%linear)
    type is (umfpack_solver_type)
        umfpack_memory = solver%get_memory()
        have_umfpack = .true.
    end select
    write(output_unit, '(a7, i6, i10, i10, i7, i7, 5f11.3, f9.1, f12.3, f9.3, f10.1, f12.0)', &
        advance='no') trim(solver_name), setup_calls, scene%dofs%n_unknowns, newton_nnz(), &
        iterations, n_factor, &
        1e3_wp * [t_residual, t_jacobian, t_factor, t_solve, other] / iterations, &
        100 * other / total, 1e3_wp * t_analyse, total, peak_memory_mib(), growth
    if (have_umfpack) then
        associate(lu => umfpack_memory%numeric_bytes / scene%dofs%n_unknowns, &
                peak => umfpack_memory%peak_bytes / scene%dofs%n_unknowns)
            write(output_unit, '(f14.0, f16.0, f6.2, f8.2)', advance='no') lu, peak, &
                growth / lu, growth / peak
        end associate
    else
        write(output_unit, '(a14, a16, a6, a8)', advance='no') '-', '-', '-', '-'
    end if
    call write_floor()

contains

    !> Nonzeros of the Jacobian of the free unknowns (prescribed rows and columns are
    !> eliminated, so not counted).
    integer function newton_nnz()
        newton_nnz = int(problem%get_nonzeros())
    end function newton_nnz

    !> The floor columns on the Jacobian at the solution.
    subroutine write_floor()
        type(floor_type) :: floor
        integer(ik), allocatable :: col_ptr(:), row_index(:)
        real(wp), allocatable :: values(:)
        real(wp) :: bare, fastest
        character(len=8) :: ratio

        allocate(col_ptr(size(u) + 1), row_index(problem%get_nonzeros()), &
            values(problem%get_nonzeros()))
        call problem%copy_pattern(col_ptr, row_index)
        call problem%evaluate_jacobian(u, values, error)
        if (allocated(error)) call fail('bench_newton', error)
        call measure_floor(trim(solver_name), int(size(u), ik), col_ptr, row_index, values, &
            floor, error, with_klu=size(u) <= klu_floor_max)
        if (allocated(error)) call fail('bench_newton', error)
        select case (trim(solver_name))
        case ('umfpack')
            bare = floor%umfpack_ms
        case ('klu')
            bare = floor%klu_ms
        case ('cholmod', 'cholmod+klu')
            bare = floor%cholmod_ms
        case default
            bare = -1.0_wp
        end select
        ratio = '-'
        if (bare > 0.0_wp) write(ratio, '(f8.2)') floor%yarnfort_ms / bare
        fastest = minval(pack([floor%umfpack_ms, floor%klu_ms, floor%cholmod_ms], &
            [floor%umfpack_ms, floor%klu_ms, floor%cholmod_ms] > 0.0_wp))
        write(output_unit, '(f10.2, f10.2, i3, f12.2, i3, f10.2, f10.2, a8, f14.2, f13.6, es25.16)') &
            floor%yarnfort_ms, floor%umfpack_ms, floor%strategy, floor%umfpack_pattern_ms, &
            floor%strategy_pattern, floor%klu_ms, floor%cholmod_ms, trim(ratio), &
            1e3_wp * cpu_total / iterations / fastest, cpu_total, centre_deflection()
    end subroutine write_floor

    !> First guess of the `linear` variant: every interior node where the supports'
    !> pre-stretch (1.04 along x and y, about the net's centre) takes it, in the plane.
    subroutine stretch_first_guess()
        real(wp), allocatable :: x(:, :)
        real(wp) :: centre
        x = scene%network%position
        centre = 0.5_wp * (side + 1)
        x(1:2, :) = centre + 1.04_wp * (x(1:2, :) - centre)
        call scene%dofs%restrict(x, u)
    end subroutine stretch_first_guess

    !> z displacement at the solution of interior node (c, c), c = (side + 1) / 2.
    real(wp) function centre_deflection()
        real(wp), allocatable :: x(:, :)
        integer, allocatable :: id(:, :)
        integer :: n, c
        allocate(x(3, scene%network%n_nodes()))
        call scene%dofs%expand(u, problem%factors, x)
        call number_grid_nodes(side, id, n)
        c = (side + 1) / 2
        centre_deflection = x(3, id(c, c)) - scene%network%position(3, id(c, c))
    end function centre_deflection

    !> side x side interior nodes, unit spacing, cables along x and y ending on boundary
    !> nodes that are pulled outward by 2 % (pretension); a transverse force on every
    !> interior node. Neo-Hookean cables. Everything ramps in one step.
    subroutine make_cable_net(config, side, setup_calls, solver_name, variant)
        type(config_type), intent(out) :: config
        integer, intent(in) :: side, setup_calls
        character(len=*), intent(in) :: solver_name, variant
        integer :: i, j, n, y
        integer, allocatable :: id(:, :)

        call number_grid_nodes(side, id, n)
        allocate(config%node_positions(3, n))
        do j = 0, side + 1
            do i = 0, side + 1
                if (id(i, j) > 0) config%node_positions(:, id(i, j)) = [real(i, wp), &
                    real(j, wp), 0.0_wp]
            end do
        end do
        allocate(config%materials(1))
        config%materials(1)%name = 'cable'
        if (variant == 'linear') then
            config%materials(1)%law = 'linear'
            config%materials(1)%stiffness = 2.0e6_wp * 5.0e-6_wp
        else
            config%materials(1)%law = 'neo_hookean'
            config%materials(1)%modulus = 2.0e6_wp
            config%materials(1)%area = 5.0e-6_wp
        end if
        allocate(config%yarns(2 * side))
        y = 0
        do j = 1, side
            y = y + 1
            config%yarns(y)%material = 'cable'
            config%yarns(y)%nodes = id(0:side + 1, j)
        end do
        do i = 1, side
            y = y + 1
            config%yarns(y)%material = 'cable'
            config%yarns(y)%nodes = id(i, 0:side + 1)
        end do
        allocate(config%supports(4))
        config%supports(1)%name = 'west'
        config%supports(1)%nodes = id(0, 1:side)
        config%supports(1)%displacement = [-0.02_wp * (side + 1), 0.0_wp, 0.0_wp]
        config%supports(2)%name = 'east'
        config%supports(2)%nodes = id(side + 1, 1:side)
        config%supports(2)%displacement = [0.02_wp * (side + 1), 0.0_wp, 0.0_wp]
        config%supports(3)%name = 'south'
        config%supports(3)%nodes = id(1:side, 0)
        config%supports(3)%displacement = [0.0_wp, -0.02_wp * (side + 1), 0.0_wp]
        config%supports(4)%name = 'north'
        config%supports(4)%nodes = id(1:side, side + 1)
        config%supports(4)%displacement = [0.0_wp, 0.02_wp * (side + 1), 0.0_wp]
        allocate(config%contacts(0))
        allocate(config%loads(1))
        config%loads(1)%nodes = pack(id(1:side, 1:side), .true.)
        config%loads(1)%force = [0.0_wp, 0.0_wp, -0.01_wp]
        config%path%time = [0.0_wp, 1.0_wp]
        config%path%p_force = [0.0_wp, 1.0_wp]
        config%path%p_disp = [0.0_wp, 1.0_wp]
        config%solver%linear_solver = solver_name
        config%solver%max_setup_calls = setup_calls
        config%solver%max_iterations = 200
    end subroutine make_cable_net


end program bench_newton
