! SPDX-License-Identifier: MIT
!> The floor of a Newton iteration's linear algebra: the bare SuiteSparse calls on a
!> captured Jacobian, timed in the same run as yarnfort's own solver on the same matrix.
!> Per iteration (after a first analysis and factorisation, not timed):
!> - yarnfort: `factor` + `solve` of the solver the benchmark names;
!> - bare UMFPACK: umfpack_dl_numeric + umfpack_dl_wsolve with the Symbolic object of
!>   umfpack_dl_symbolic given the values (its defaults, no iterative refinement), and
!>   the same with the Symbolic object of the pattern alone (what yarnfort did before);
!> - bare KLU: klu_l_refactor + klu_l_solve after klu_l_analyze (its defaults) and
!>   klu_l_factor, with KLU's AMD ordering (its default) and with COLAMD;
!> - bare CHOLMOD (only where the solver named is 'cholmod' or 'cholmod+klu', i.e. the
!>   matrix is symmetric positive definite): cholmod_l_factorize + cholmod_l_solve after
!>   cholmod_l_analyze, its defaults but yarnfort's supernodal switch (bench_cholmod.c).
!> Also the nonzeros of the factors (L + U) of each.
!> Times are process CPU times (cpu_time): everything here runs on one thread, and on a
!> machine shared with other work the CPU time of a run moves far less than its wall time.
module bench_floor
    use, intrinsic :: iso_c_binding, only: c_long, c_double, c_ptr, c_null_ptr, &
        c_null_funptr, c_associated, c_f_pointer, c_int
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_factory, only: new_linear_solver
    use yarnfort_linalg_backend_cholmod, only: supernodal_switch
    use yarnfort_linalg_binding_cholmod, only: yarnfort_cholmod_metis_order, cholmod_ok
    use yarnfort_linalg_binding_umfpack, only: umfpack_control, umfpack_info, umfpack_irstep, &
        umfpack_prl, umfpack_a, umfpack_ok, umfpack_strategy_used, umfpack_dl_defaults, &
        umfpack_dl_symbolic, umfpack_dl_numeric, umfpack_dl_wsolve, &
        umfpack_dl_free_symbolic, umfpack_dl_free_numeric, umfpack_lnz, umfpack_unz, &
        umfpack_ordering, umfpack_ordering_metis
    use yarnfort_linalg_binding_klu, only: klu_l_common, klu_l_defaults, klu_l_analyze, &
        klu_l_factor, klu_l_refactor, klu_l_solve, klu_l_free_symbolic, klu_l_free_numeric, &
        klu_l_numeric_sizes, klu_l_analyze_given
    implicit none
    private

    public :: floor_type, measure_floor

    !> AMD (amd.h), for orders with Control settings KLU does not expose.
    interface
        subroutine amd_l_defaults(control) bind(C, name='amd_l_defaults')
            import :: c_double
            real(c_double), intent(out) :: control(*)
        end subroutine amd_l_defaults

        function amd_l_order(n, ap, ai, p, control, info) result(status) &
                bind(C, name='amd_l_order')
            import :: c_long, c_double
            integer(c_long), value :: n
            integer(c_long), intent(in) :: ap(*), ai(*)
            integer(c_long), intent(out) :: p(*)
            real(c_double), intent(in) :: control(*)
            real(c_double), intent(out) :: info(*)
            integer(c_long) :: status
        end function amd_l_order
    end interface

    interface
        !> bench_cholmod.c
        function bench_cholmod_time(n, col_ptr, row_index, values, target_seconds, &
                max_repetitions, supernodal_switch, ms, lnz) result(status) &
                bind(C, name='bench_cholmod_time')
            import :: c_long, c_double, c_int
            integer(c_long), value :: n
            integer(c_long), intent(in) :: col_ptr(*), row_index(*)
            real(c_double), intent(in) :: values(*)
            real(c_double), value :: target_seconds
            integer(c_int), value :: max_repetitions
            real(c_double), value :: supernodal_switch
            real(c_double), intent(out) :: ms, lnz
            integer(c_int) :: status
        end function bench_cholmod_time
    end interface

    !> Wall time spent on each measurement (s): repetitions are chosen to fill it.
    real(wp), parameter :: target_seconds = 0.3_wp
    integer, parameter :: max_repetitions = 20

    !> Milliseconds per factorisation + solve; a negative time was not measured.
    type :: floor_type
        real(wp) :: yarnfort_ms = -1.0_wp
        real(wp) :: umfpack_ms = -1.0_wp, umfpack_pattern_ms = -1.0_wp, klu_ms = -1.0_wp
        real(wp) :: klu_colamd_ms = -1.0_wp, klu_nobtf_ms = -1.0_wp, cholmod_ms = -1.0_wp
        !> UMFPACK (values given) with METIS instead of its default AMD ordering
        !> (with_metis), and the CPU ms of the symbolic analyses: KLU (AMD), UMFPACK (AMD,
        !> METIS).
        real(wp) :: umfpack_metis_ms = -1.0_wp, umfpack_metis_lu = 0.0_wp
        real(wp) :: klu_analyse_ms = -1.0_wp, umfpack_analyse_ms = -1.0_wp
        real(wp) :: umfpack_metis_analyse_ms = -1.0_wp
        !> Nonzeros of L of bare CHOLMOD (its analysis' count).
        real(wp) :: cholmod_lnz = 0.0_wp
        !> Nonzeros of L + U: UMFPACK analysed with the values, KLU with AMD and COLAMD.
        real(wp) :: umfpack_lu = 0.0_wp, klu_lu = 0.0_wp, klu_colamd_lu = 0.0_wp
        !> KLU with AMD and without its block triangular form (btf = 0).
        real(wp) :: klu_nobtf_lu = 0.0_wp
        !> UMFPACK's strategy with and without the values (1 unsymmetric, 3 symmetric).
        integer :: strategy = 0, strategy_pattern = 0
        !> with_variants: bare KLU (refactor + solve) with scale 0 / 1, with METIS' order of
        !> A + A^T as lu_choice finds it (klu_l_analyze_given), with AMD without
        !> aggressive absorption, and with AMD's dense threshold 1: ms and L + U.
        real(wp) :: variant_ms(5) = -1.0_wp, variant_lu(5) = 0.0_wp
    end type floor_type

contains

    !> Process CPU time (s).
    real(wp) function cpu_seconds()
        call cpu_time(cpu_seconds)
    end function cpu_seconds

    !> Time `solver_name` and the bare libraries on the CSC matrix (0-based indices).
    subroutine measure_floor(solver_name, n, col_ptr, row_index, values, floor, error, &
            with_klu, with_metis, with_variants)
        character(len=*), intent(in) :: solver_name
        integer(ik), intent(in) :: n
        integer(ik), intent(in) :: col_ptr(:), row_index(:)
        real(wp), intent(in) :: values(:)
        type(floor_type), intent(out) :: floor
        type(error_type), allocatable, intent(out) :: error
        !> Time bare KLU (default true).
        logical, intent(in), optional :: with_klu
        !> Also time UMFPACK with the METIS ordering (default false).
        logical, intent(in), optional :: with_metis
        !> Also time the KLU variants (default false).
        logical, intent(in), optional :: with_variants
        class(linear_solver_type), allocatable :: solver
        real(wp), allocatable :: rhs(:)
        real(wp) :: start, first
        integer :: k, repetitions
        logical :: klu

        allocate(rhs(n))
        call new_linear_solver(solver, solver_name, error)
        if (allocated(error)) return
        call solver%analyse(n, col_ptr, row_index, error)
        if (allocated(error)) return
        start = cpu_seconds()
        call solver%factor(values, error)
        if (allocated(error)) return
        rhs = 1.0_wp
        call solver%solve(rhs, error)
        if (allocated(error)) return
        first = cpu_seconds() - start
        repetitions = count_repetitions(first)
        start = cpu_seconds()
        do k = 1, repetitions
            call solver%factor(values, error)
            if (allocated(error)) return
            rhs = 1.0_wp
            call solver%solve(rhs, error)
            if (allocated(error)) return
        end do
        floor%yarnfort_ms = 1e3_wp * (cpu_seconds() - start) / repetitions
        call solver%destroy()

        call time_umfpack(.true., floor%umfpack_ms, floor%strategy, floor%umfpack_lu, &
            analyse_ms=floor%umfpack_analyse_ms)
        call time_umfpack(.false., floor%umfpack_pattern_ms, floor%strategy_pattern)
        if (present(with_metis)) then
            if (with_metis) call time_umfpack(.true., floor%umfpack_metis_ms, k, &
                floor%umfpack_metis_lu, umfpack_ordering_metis, floor%umfpack_metis_analyse_ms)
        end if
        klu = .true.
        if (present(with_klu)) klu = with_klu
        if (klu) then
            call time_klu(0, 1, floor%klu_ms, floor%klu_lu, floor%klu_analyse_ms)
            call time_klu(1, 1, floor%klu_colamd_ms, floor%klu_colamd_lu)
            call time_klu(0, 0, floor%klu_nobtf_ms, floor%klu_nobtf_lu)
        end if
        if (present(with_variants)) then
            if (with_variants) call time_variants()
        end if
        if (solver_name == 'cholmod' .or. solver_name == 'cholmod+klu') then
            block
                real(c_double) :: ms, lnz
                if (bench_cholmod_time(int(n, c_long), col_ptr, row_index, values, &
                        real(target_seconds, c_double), int(max_repetitions, c_int), &
                        real(supernodal_switch, c_double), ms, lnz) == 0) then
                    floor%cholmod_ms = ms
                    floor%cholmod_lnz = lnz
                end if
            end block
        end if

    contains

        integer function count_repetitions(seconds)
            real(wp), intent(in) :: seconds
            count_repetitions = max(1, min(max_repetitions, &
                int(target_seconds / max(seconds, 1e-6_wp))))
        end function count_repetitions

        subroutine time_umfpack(with_values, ms, strategy, lu, ordering, analyse_ms)
            logical, intent(in) :: with_values
            real(wp), intent(out) :: ms
            integer, intent(out) :: strategy
            real(wp), intent(out), optional :: lu
            !> Control(UMFPACK_ORDERING) (default: UMFPACK's own, AMD).
            integer, intent(in), optional :: ordering
            real(wp), intent(out), optional :: analyse_ms
            real(c_double) :: control(0:umfpack_control - 1), info(0:umfpack_info - 1)
            real(c_double), allocatable :: b(:), x(:), w(:)
            integer(c_long), allocatable :: wi(:)
            type(c_ptr) :: symbolic, numeric
            integer(c_long) :: status

            ms = -1.0_wp
            strategy = 0
            symbolic = c_null_ptr
            numeric = c_null_ptr
            allocate(b(n), x(n), w(n), wi(n))
            b = 1.0_wp
            call umfpack_dl_defaults(control)
            control(umfpack_irstep) = 0
            control(umfpack_prl) = 0
            if (present(ordering)) control(umfpack_ordering) = real(ordering, c_double)
            start = cpu_seconds()
            if (with_values) then
                status = umfpack_dl_symbolic(int(n, c_long), int(n, c_long), col_ptr, &
                    row_index, values, symbolic, control, info)
            else
                status = umfpack_dl_symbolic(int(n, c_long), int(n, c_long), col_ptr, &
                    row_index, symbolic=symbolic, control=control, info=info)
            end if
            if (status /= umfpack_ok) return
            if (present(analyse_ms)) analyse_ms = 1e3_wp * (cpu_seconds() - start)
            strategy = nint(info(umfpack_strategy_used))
            start = cpu_seconds()
            status = umfpack_dl_numeric(col_ptr, row_index, values, symbolic, numeric, &
                control, info)
            if (status == umfpack_ok) status = umfpack_dl_wsolve(umfpack_a, x=x, b=b, &
                numeric=numeric, control=control, info=info, wi=wi, w=w)
            first = cpu_seconds() - start
            if (status == umfpack_ok) then
                repetitions = count_repetitions(first)
                start = cpu_seconds()
                do k = 1, repetitions
                    call umfpack_dl_free_numeric(numeric)
                    status = umfpack_dl_numeric(col_ptr, row_index, values, symbolic, numeric, &
                        control, info)
                    status = umfpack_dl_wsolve(umfpack_a, x=x, b=b, numeric=numeric, &
                        control=control, info=info, wi=wi, w=w)
                end do
                ms = 1e3_wp * (cpu_seconds() - start) / repetitions
                if (present(lu)) lu = info(umfpack_lnz) + info(umfpack_unz)
            end if
            call umfpack_dl_free_numeric(numeric)
            call umfpack_dl_free_symbolic(symbolic)
        end subroutine time_umfpack

        subroutine time_variants()
            integer(c_long), allocatable :: order(:)
            real(c_double) :: amd_control(0:4), amd_info(0:19), lnz
            integer(c_long) :: status
            integer :: k

            call time_klu(0, 1, floor%variant_ms(1), floor%variant_lu(1), scale=0)
            call time_klu(0, 1, floor%variant_ms(2), floor%variant_lu(2), scale=1)
            allocate(order(n))
            if (yarnfort_cholmod_metis_order(int(n, c_long), col_ptr, row_index, order, &
                    lnz) == cholmod_ok) call time_klu(0, 1, floor%variant_ms(3), &
                floor%variant_lu(3), given=order)
            ! AMD without aggressive absorption (variant 4), with dense threshold 1 (5).
            do k = 4, 5
                call amd_l_defaults(amd_control)
                if (k == 4) amd_control(1) = 0
                if (k == 5) amd_control(0) = 1
                status = amd_l_order(int(n, c_long), col_ptr, row_index, order, amd_control, &
                    amd_info)
                if (status >= 0) call time_klu(0, 1, floor%variant_ms(k), floor%variant_lu(k), &
                    given=order)
            end do
        end subroutine time_variants

        subroutine time_klu(ordering, btf, ms, lu, analyse_ms, scale, given)
            integer, intent(in) :: ordering, btf
            real(wp), intent(out) :: ms, lu
            real(wp), intent(out), optional :: analyse_ms
            integer, intent(in), optional :: scale
            integer(c_long), intent(in), optional :: given(:)
            type(klu_l_common) :: common
            type(c_ptr) :: symbolic, numeric
            type(klu_l_numeric_sizes), pointer :: sizes
            real(c_double), allocatable :: b(:)
            integer(c_long) :: ok

            ms = -1.0_wp
            lu = 0.0_wp
            allocate(b(n))
            ok = klu_l_defaults(common)
            common%user_order = c_null_funptr
            common%user_data = c_null_ptr
            common%ordering = ordering
            common%btf = btf
            if (present(scale)) common%scale = scale
            start = cpu_seconds()
            if (present(given)) then
                symbolic = klu_l_analyze_given(int(n, c_long), col_ptr, row_index, given, &
                    given, common)
            else
                symbolic = klu_l_analyze(int(n, c_long), col_ptr, row_index, common)
            end if
            if (.not. c_associated(symbolic)) return
            if (present(analyse_ms)) analyse_ms = 1e3_wp * (cpu_seconds() - start)
            start = cpu_seconds()
            numeric = klu_l_factor(col_ptr, row_index, values, symbolic, common)
            if (c_associated(numeric)) then
                b = 1.0_wp
                ok = klu_l_solve(symbolic, numeric, int(n, c_long), 1_c_long, b, common)
                first = cpu_seconds() - start
                repetitions = count_repetitions(first)
                start = cpu_seconds()
                do k = 1, repetitions
                    ok = klu_l_refactor(col_ptr, row_index, values, symbolic, numeric, common)
                    b = 1.0_wp
                    ok = klu_l_solve(symbolic, numeric, int(n, c_long), 1_c_long, b, common)
                end do
                ms = 1e3_wp * (cpu_seconds() - start) / repetitions
                call c_f_pointer(numeric, sizes)
                lu = real(sizes%lnz + sizes%unz, wp)
                ok = klu_l_free_numeric(numeric, common)
            end if
            ok = klu_l_free_symbolic(symbolic, common)
        end subroutine time_klu
    end subroutine measure_floor

end module bench_floor
