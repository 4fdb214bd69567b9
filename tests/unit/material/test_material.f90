! SPDX-License-Identifier: MIT
!> Unit tests of the yarn force laws: linear, neo-Hookean and measured tables (PCHIP).
module test_material
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf
    use, intrinsic :: iso_fortran_env, only: int64
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_testing, only: unittest_type, new_unittest, check, check_close
    use yarnfort_material_force_law, only: force_law_type
    use yarnfort_material_linear, only: linear_law_type, new_linear_law
    use yarnfort_material_neo_hookean, only: neo_hookean_law_type, new_neo_hookean_law
    use yarnfort_material_table, only: table_law_type, new_table_law, read_table_law, &
        default_end_slope_ratio
    implicit none
    private

    public :: collect_material

    !> Identities that hold up to rounding (relative).
    real(wp), parameter :: identity_tol = 100 * epsilon(1.0_wp)
    !> Analytic derivative against a central finite difference (relative).
    real(wp), parameter :: fd_tol = sqrt(epsilon(1.0_wp))
    !> Central-difference step as a fraction of the local interval width.
    real(wp), parameter :: fd_step_ratio = epsilon(1.0_wp)**(1.0_wp / 3.0_wp)
    !> Offset from a knot (fraction of the interval width, a power of 2) for one-sided limits.
    real(wp), parameter :: limit_step_ratio = 2.0_wp**(-27)
    !> Fractions of each interval where derivatives are sampled (near both knots too).
    real(wp), parameter :: sample_fraction(*) = [0.001_wp, 0.01_wp, 0.1_wp, 0.3_wp, &
        0.5_wp, 0.7_wp, 0.9_wp, 0.99_wp, 0.999_wp]
    !> Sub-panels of each interval in the composite Gauss-Legendre quadrature.
    integer, parameter :: quadrature_panels = 16
    !> Grid points per table interval in the monotonicity tests.
    integer, parameter :: grid_points = 2000
    !> Random tables in the monotonicity test and their rows.
    integer, parameter :: random_tables = 200, random_rows = 9

    !> Five-point Gauss-Legendre nodes on [-1, 1] and weights.
    real(wp), parameter :: gauss_node(5) = [-0.9061798459386640_wp, -0.5384693101056831_wp, &
        0.0_wp, 0.5384693101056831_wp, 0.9061798459386640_wp]
    real(wp), parameter :: gauss_weight(5) = [0.2369268850561891_wp, 0.4786286704993665_wp, &
        0.5688888888888889_wp, 0.4786286704993665_wp, 0.2369268850561891_wp]

    !> Axial stiffness of the linear law, N.
    real(wp), parameter :: linear_stiffness = 250.0_wp
    !> Neo-Hookean constant (Pa) and reference cross-section (m**2): S1*C = 10 N.
    real(wp), parameter :: neo_modulus = 2.0e9_wp, neo_area = 5.0e-9_wp

    !> A law under test with the stretches where its second derivative may jump (the
    !> table knots; the analytic laws get a few sampling breaks) and beyond which it is
    !> sampled once more.
    type :: law_case_type
        character(len=:), allocatable :: name
        class(force_law_type), allocatable :: law
        real(wp), allocatable :: breaks(:)
    end type law_case_type

contains

    !> Collect all material tests.
    subroutine collect_material(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)

        testsuite = [ &
            new_unittest('slack in compression', test_slack), &
            new_unittest('force derivative by finite differences', test_force_derivative), &
            new_unittest('energy derivative is the force', test_energy_derivative), &
            new_unittest('energy against Gauss quadrature', test_energy_quadrature), &
            new_unittest('reference stiffness', test_reference_stiffness), &
            new_unittest('table reproduces its rows', test_table_rows), &
            new_unittest('table is C1 at the knots', test_table_c1), &
            new_unittest('table slopes in the monotone region', test_table_slopes), &
            new_unittest('table strictly increasing on nasty data', test_table_monotone), &
            new_unittest('table monotone on random data', test_table_random), &
            new_unittest('two-row table equals the linear law', test_two_row_table), &
            new_unittest('table end-slope floor', test_end_slope_floor), &
            new_unittest('table rejects bad arrays', test_table_rejects), &
            new_unittest('analytic laws reject bad parameters', test_analytic_rejects), &
            new_unittest('table read from CSV', test_read_csv), &
            new_unittest('table CSV rejects bad files', test_read_csv_rejects) &
            ]
    end subroutine collect_material

    ! ---------------------------------------------------------------- laws under test

    !> Table of f = 10*(exp(5*strain) - 1) N, smooth and convex.
    subroutine smooth_table(strain, force)
        real(wp), allocatable, intent(out) :: strain(:), force(:)

        strain = [0.0_wp, 0.02_wp, 0.05_wp, 0.1_wp, 0.15_wp, 0.2_wp, 0.3_wp]
        force = 10.0_wp * (exp(5.0_wp * strain) - 1.0_wp)
    end subroutine smooth_table

    !> Steep, very flat, steep, very flat, moderate; strains are dyadic so that 1 + strain
    !> and the knot offsets are exact.
    subroutine nasty_table(strain, force)
        real(wp), allocatable, intent(out) :: strain(:), force(:)

        strain = [0.0_wp, 2.0_wp**(-13), 0.25_wp, 0.25_wp + 2.0_wp**(-13), 0.5_wp, 0.75_wp]
        force = [0.0_wp, 10.0_wp, 10.001_wp, 20.0_wp, 20.000001_wp, 30.0_wp]
    end subroutine nasty_table

    !> Every law under test.
    subroutine get_cases(cases, error)
        type(law_case_type), allocatable, intent(out) :: cases(:)
        type(error_type), allocatable, intent(out) :: error
        type(linear_law_type) :: linear
        type(neo_hookean_law_type) :: neo_hookean
        type(table_law_type) :: smooth, nasty
        real(wp), allocatable :: strain(:), force(:)

        call new_linear_law(linear, linear_stiffness, error)
        if (allocated(error)) return
        call new_neo_hookean_law(neo_hookean, neo_modulus, neo_area, error)
        if (allocated(error)) return
        call smooth_table(strain, force)
        call new_table_law(smooth, strain, force, error)
        if (allocated(error)) return
        call nasty_table(strain, force)
        call new_table_law(nasty, strain, force, error)
        if (allocated(error)) return

        allocate(cases(4))
        cases(1)%name = 'linear'
        allocate(cases(1)%law, source=linear)
        cases(1)%breaks = [1.0_wp, 1.1_wp, 1.5_wp, 2.0_wp]
        cases(2)%name = 'neo-Hookean'
        allocate(cases(2)%law, source=neo_hookean)
        cases(2)%breaks = [1.0_wp, 1.1_wp, 1.5_wp, 2.0_wp, 3.0_wp]
        call smooth_table(strain, force)
        cases(3)%name = 'smooth table'
        allocate(cases(3)%law, source=smooth)
        cases(3)%breaks = 1.0_wp + strain
        call nasty_table(strain, force)
        cases(4)%name = 'nasty table'
        allocate(cases(4)%law, source=nasty)
        cases(4)%breaks = 1.0_wp + strain
    end subroutine get_cases

    !> Sample stretches inside every interval between breaks and one interval beyond the
    !> last break (as wide as the last interval), each with its interval width.
    subroutine get_samples(breaks, stretch, width)
        real(wp), intent(in) :: breaks(:)
        real(wp), allocatable, intent(out) :: stretch(:), width(:)
        real(wp) :: edges(size(breaks) + 1)
        integer :: i, j, m, nf

        m = size(breaks)
        edges(:m) = breaks
        edges(m + 1) = breaks(m) + (breaks(m) - breaks(m - 1))
        nf = size(sample_fraction)
        allocate(stretch((m) * nf), width((m) * nf))
        do i = 1, m
            do j = 1, nf
                width((i - 1) * nf + j) = edges(i + 1) - edges(i)
                stretch((i - 1) * nf + j) = edges(i) &
                    + sample_fraction(j) * (edges(i + 1) - edges(i))
            end do
        end do
    end subroutine get_samples

    ! ---------------------------------------------------------------- tests

    !> f = 0, df = 0 and energy = 0 at lambda = 1 and in compression, for every law.
    subroutine test_slack(error)
        type(error_type), allocatable, intent(out) :: error
        type(law_case_type), allocatable :: cases(:)
        real(wp), parameter :: stretches(*) = [0.0_wp, 0.3_wp, 0.9_wp, 1.0_wp - epsilon(1.0_wp), &
            1.0_wp]
        real(wp) :: force, dforce
        integer :: i, j

        call get_cases(cases, error)
        if (allocated(error)) return
        do i = 1, size(cases)
            do j = 1, size(stretches)
                call cases(i)%law%get_force(stretches(j), force, dforce)
                call check(error, .not. (abs(force) > 0.0_wp .or. abs(dforce) > 0.0_wp &
                    .or. abs(cases(i)%law%get_energy(stretches(j))) > 0.0_wp), &
                    cases(i)%name // ': not slack at or below lambda = 1')
                if (allocated(error)) return
            end do
            call cases(i)%law%get_force(1.0_wp + epsilon(1.0_wp), force, dforce)
            call check(error, force > 0.0_wp .and. dforce > 0.0_wp, &
                cases(i)%name // ': no tension just above lambda = 1')
            if (allocated(error)) return
        end do
    end subroutine test_slack

    !> df/dlambda against central differences inside every interval and beyond the table.
    !> Tolerance: fd_tol relative, plus the rounding of f amplified by 1/step.
    subroutine test_force_derivative(error)
        type(error_type), allocatable, intent(out) :: error
        type(law_case_type), allocatable :: cases(:)
        real(wp), allocatable :: stretch(:), width(:)
        real(wp) :: force, dforce, force_plus, force_minus, dummy, step, estimate
        real(wp) :: plus, minus
        integer :: i, j

        call get_cases(cases, error)
        if (allocated(error)) return
        do i = 1, size(cases)
            call get_samples(cases(i)%breaks, stretch, width)
            do j = 1, size(stretch)
                call get_stencil(stretch(j), fd_step_ratio * width(j), plus, minus, step)
                call cases(i)%law%get_force(stretch(j), force, dforce)
                call cases(i)%law%get_force(plus, force_plus, dummy)
                call cases(i)%law%get_force(minus, force_minus, dummy)
                estimate = (force_plus - force_minus) / (2.0_wp * step)
                call check_close(error, dforce, estimate, fd_tol, cases(i)%name &
                    // ': df/dlambda against finite differences', &
                    abs_tol=identity_tol * abs(force) / step)
                if (allocated(error)) return
            end do
        end do
    end subroutine test_force_derivative

    !> Central-difference stencil x +- step with the half-width actually represented.
    subroutine get_stencil(x, step_wanted, plus, minus, step)
        real(wp), intent(in) :: x, step_wanted
        real(wp), intent(out) :: plus, minus, step

        plus = x + step_wanted
        minus = x - step_wanted
        step = 0.5_wp * (plus - minus)
    end subroutine get_stencil

    !> d(energy)/dlambda against f by central differences.
    subroutine test_energy_derivative(error)
        type(error_type), allocatable, intent(out) :: error
        type(law_case_type), allocatable :: cases(:)
        real(wp), allocatable :: stretch(:), width(:)
        real(wp) :: force, dforce, energy, step, estimate, plus, minus
        integer :: i, j

        call get_cases(cases, error)
        if (allocated(error)) return
        do i = 1, size(cases)
            call get_samples(cases(i)%breaks, stretch, width)
            do j = 1, size(stretch)
                call get_stencil(stretch(j), fd_step_ratio * width(j), plus, minus, step)
                call cases(i)%law%get_force(stretch(j), force, dforce)
                energy = cases(i)%law%get_energy(stretch(j))
                estimate = (cases(i)%law%get_energy(plus) - cases(i)%law%get_energy(minus)) &
                    / (2.0_wp * step)
                call check_close(error, force, estimate, fd_tol, cases(i)%name &
                    // ': d(energy)/dlambda against the force', &
                    abs_tol=identity_tol * abs(energy) / step)
                if (allocated(error)) return
            end do
        end do
    end subroutine test_energy_derivative

    !> Energy against composite 5-point Gauss-Legendre quadrature of f, split at the
    !> breaks (exact for the cubic pieces of a table). The quadrature nodes carry rounding
    !> of about eps*lambda, so the absolute tolerance scales with lambda*f.
    subroutine test_energy_quadrature(error)
        type(error_type), allocatable, intent(out) :: error
        type(law_case_type), allocatable :: cases(:)
        real(wp), allocatable :: stretch(:), width(:)
        real(wp) :: expected, force, dforce
        integer :: i, j

        call get_cases(cases, error)
        if (allocated(error)) return
        do i = 1, size(cases)
            call get_samples(cases(i)%breaks, stretch, width)
            do j = 1, size(stretch)
                expected = integrate_force(cases(i)%law, cases(i)%breaks, stretch(j))
                call cases(i)%law%get_force(stretch(j), force, dforce)
                call check_close(error, cases(i)%law%get_energy(stretch(j)), expected, &
                    identity_tol, cases(i)%name // ': energy against quadrature', &
                    abs_tol=identity_tol * stretch(j) * force)
                if (allocated(error)) return
            end do
        end do
    end subroutine test_energy_quadrature

    !> Integral of f from 1 to `stretch`, by Gauss-Legendre panels between the breaks.
    function integrate_force(law, breaks, stretch) result(integral)
        class(force_law_type), intent(in) :: law
        real(wp), intent(in) :: breaks(:), stretch
        real(wp) :: integral
        real(wp) :: low, high, a, b, force, dforce
        integer :: i, p, g

        integral = 0.0_wp
        do i = 1, size(breaks)
            low = breaks(i)
            if (low >= stretch) exit
            high = stretch
            if (i < size(breaks)) high = min(breaks(i + 1), stretch)
            do p = 1, quadrature_panels
                a = low + (high - low) * real(p - 1, wp) / quadrature_panels
                b = low + (high - low) * real(p, wp) / quadrature_panels
                do g = 1, size(gauss_node)
                    call law%get_force(0.5_wp * (a + b) + 0.5_wp * (b - a) * gauss_node(g), &
                        force, dforce)
                    integral = integral + 0.5_wp * (b - a) * gauss_weight(g) * force
                end do
            end do
        end do
    end function integrate_force

    !> Reference stiffness: EA, 3*S1*C, and the table's right-hand slope at lambda = 1.
    subroutine test_reference_stiffness(error)
        type(error_type), allocatable, intent(out) :: error
        type(law_case_type), allocatable :: cases(:)
        real(wp) :: force, dforce, step
        integer :: i

        call get_cases(cases, error)
        if (allocated(error)) return
        call check_close(error, cases(1)%law%get_reference_stiffness(), linear_stiffness, &
            identity_tol, 'linear reference stiffness')
        if (allocated(error)) return
        call check_close(error, cases(2)%law%get_reference_stiffness(), &
            3.0_wp * neo_modulus * neo_area, identity_tol, 'neo-Hookean reference stiffness')
        if (allocated(error)) return
        do i = 1, size(cases)
            ! The right-hand limit of df/dlambda at 1, from just above the first knot.
            step = limit_step_ratio * (cases(i)%breaks(2) - cases(i)%breaks(1))
            call cases(i)%law%get_force(1.0_wp + step, force, dforce)
            call check_close(error, cases(i)%law%get_reference_stiffness(), dforce, fd_tol, &
                cases(i)%name // ': reference stiffness against df/dlambda at 1+')
            if (allocated(error)) return
        end do
    end subroutine test_reference_stiffness

    !> The interpolant passes through every row.
    subroutine test_table_rows(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: law
        real(wp), allocatable :: strain(:), force(:)
        real(wp) :: value, dforce
        integer :: round, k

        do round = 1, 2
            if (round == 1) call smooth_table(strain, force)
            if (round == 2) call nasty_table(strain, force)
            call new_table_law(law, strain, force, error)
            if (allocated(error)) return
            do k = 1, size(strain)
                call law%get_force(1.0_wp + strain(k), value, dforce)
                ! 1 + strain rounds the strain by up to one ulp of 1.
                call check_close(error, value, force(k), identity_tol, 'table row value', &
                    abs_tol=identity_tol * dforce)
                if (allocated(error)) return
            end do
        end do
    end subroutine test_table_rows

    !> f and df/dlambda have equal one-sided limits at every knot (linear extrapolation
    !> from two exact offsets on each side), including the last knot.
    subroutine test_table_c1(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: law
        real(wp), allocatable :: strain(:), force(:), width(:), secant(:)
        real(wp) :: knot, offset, limit_left(2), limit_right(2), scale
        integer :: k, n

        call nasty_table(strain, force)
        call new_table_law(law, strain, force, error)
        if (allocated(error)) return
        n = size(strain)
        width = [strain(2:) - strain(:n - 1), strain(n) - strain(n - 1)]
        secant = [(force(2:) - force(:n - 1)) / width(:n - 1), law%slope(n)]
        do k = 2, n
            knot = 1.0_wp + strain(k)
            offset = limit_step_ratio * min(width(k - 1), width(k))
            limit_left = one_sided_limit(law, knot, -offset)
            limit_right = one_sided_limit(law, knot, offset)
            call check_close(error, limit_left(1), limit_right(1), identity_tol, &
                'table force continuity at knot')
            if (allocated(error)) return
            call check_close(error, limit_left(1), force(k), identity_tol, &
                'table force at knot')
            if (allocated(error)) return
            ! Rounding in df grows with the secants the Hermite terms cancel.
            scale = max(secant(k - 1), secant(k), abs(limit_right(2)))
            call check_close(error, limit_left(2), limit_right(2), identity_tol, &
                'table slope continuity at knot', abs_tol=identity_tol * scale)
            if (allocated(error)) return
            call check_close(error, limit_right(2), law%slope(k), identity_tol, &
                'table slope at knot', abs_tol=identity_tol * scale)
            if (allocated(error)) return
        end do
    end subroutine test_table_c1

    !> Limits of (f, df) at `knot` from the side of `offset`, extrapolated linearly from
    !> knot + offset and knot + 2*offset (exact stretches: dyadic knot and offset).
    function one_sided_limit(law, knot, offset) result(limit)
        class(force_law_type), intent(in) :: law
        real(wp), intent(in) :: knot, offset
        real(wp) :: limit(2)
        real(wp) :: near(2), far(2)

        call law%get_force(knot + offset, near(1), near(2))
        call law%get_force(knot + 2.0_wp * offset, far(1), far(2))
        limit = 2.0_wp * near - far
    end function one_sided_limit

    !> Knot slopes by hand for (0,0), (1,1), (3,5), secants 1 and 2: the interior slope
    !> is the Fritsch-Butland weighted harmonic mean 9/(5/1 + 4/2) = 9/7, the ends follow
    !> the three-point formula: 1 + 1*(1 - 2)/3 = 2/3 and 2 + 2*(2 - 1)/3 = 8/3. Then
    !> every slope lies in the open Fritsch-Carlson square: 0 < slope < 3*secant of each
    !> adjacent interval.
    subroutine test_table_slopes(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: law
        real(wp), allocatable :: strain(:), force(:), secant(:)
        integer :: round, k, n

        call new_table_law(law, [0.0_wp, 1.0_wp, 3.0_wp], [0.0_wp, 1.0_wp, 5.0_wp], error)
        if (allocated(error)) return
        call check_close(error, law%slope, [2.0_wp / 3.0_wp, 9.0_wp / 7.0_wp, 8.0_wp / 3.0_wp], &
            identity_tol, 'table slopes by hand')
        if (allocated(error)) return

        do round = 1, 2
            if (round == 1) call smooth_table(strain, force)
            if (round == 2) call nasty_table(strain, force)
            call new_table_law(law, strain, force, error)
            if (allocated(error)) return
            n = size(strain)
            secant = (force(2:) - force(:n - 1)) / (strain(2:) - strain(:n - 1))
            do k = 1, n
                call check(error, law%slope(k) > 0.0_wp, 'table slope not positive')
                if (allocated(error)) return
                if (k > 1) call check(error, law%slope(k) < 3.0_wp * secant(k - 1), &
                    'table slope not below 3 times the left secant')
                if (allocated(error)) return
                if (k < n) call check(error, law%slope(k) < 3.0_wp * secant(k), &
                    'table slope not below 3 times the right secant')
                if (allocated(error)) return
            end do
        end do
    end subroutine test_table_slopes

    !> On a dense grid over the nasty table and beyond it, f rises strictly and df > 0.
    subroutine test_table_monotone(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: law
        real(wp), allocatable :: strain(:), force(:)

        call nasty_table(strain, force)
        call new_table_law(law, strain, force, error)
        if (allocated(error)) return
        call check_grid(law, strain, .true., error)
    end subroutine test_table_monotone

    !> Walk `grid_points` per interval (and one interval beyond the table): df > 0 and f
    !> increasing (strictly when `strict`; otherwise rounding may leave equal values).
    subroutine check_grid(law, strain, strict, error)
        type(table_law_type), intent(in) :: law
        real(wp), intent(in) :: strain(:)
        logical, intent(in) :: strict
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: edges(size(strain) + 1)
        real(wp) :: stretch, force, dforce, previous
        integer :: k, j, n
        logical :: ok
        character(len=120) :: where

        n = size(strain)
        edges(:n) = strain
        edges(n + 1) = 2.0_wp * strain(n) - strain(n - 1)
        previous = 0.0_wp
        do k = 1, n
            do j = 1, grid_points
                stretch = 1.0_wp + edges(k) + (edges(k + 1) - edges(k)) * j / grid_points
                call law%get_force(stretch, force, dforce)
                ok = dforce > 0.0_wp .and. force > previous
                if (.not. strict) ok = dforce > 0.0_wp .and. force >= previous
                if (.not. ok) then
                    ! Only a failure pays for the message.
                    write(where, '("at lambda = ", es24.16, ", interval ", i0)') stretch, k
                    if (dforce > 0.0_wp) then
                        call check(error, .false., 'table force not increasing ' // trim(where))
                    else
                        call check(error, .false., 'table df/dlambda not positive ' &
                            // trim(where))
                    end if
                    return
                end if
                previous = force
            end do
        end do
    end subroutine check_grid

    !> Random tables with widths and secants spread over six decades stay monotone.
    subroutine test_table_random(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: law
        real(wp) :: strain(random_rows), force(random_rows)
        integer :: round, k
        integer :: seed

        seed = 12345
        do round = 1, random_tables
            strain(1) = 0.0_wp
            force(1) = 0.0_wp
            do k = 2, random_rows
                strain(k) = strain(k - 1) + 10.0_wp**(-3.0_wp + 3.0_wp * next_uniform(seed))
                force(k) = force(k - 1) + (strain(k) - strain(k - 1)) &
                    * 10.0_wp**(-3.0_wp + 6.0_wp * next_uniform(seed))
            end do
            call new_table_law(law, strain, force, error)
            if (allocated(error)) return
            call check_grid(law, strain, .false., error)
            if (allocated(error)) return
        end do
    end subroutine test_table_random

    !> Uniform number in [0, 1) from a small linear congruential generator (reproducible).
    function next_uniform(seed) result(uniform)
        integer, intent(inout) :: seed
        real(wp) :: uniform
        integer, parameter :: multiplier = 16807, modulus = 2147483647

        seed = int(mod(int(seed, int64) * multiplier, int(modulus, int64)))
        uniform = real(seed, wp) / modulus
    end function next_uniform

    !> A table of (0, 0) and one more row is the linear law, inside and beyond the table.
    subroutine test_two_row_table(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: table
        type(linear_law_type) :: linear
        real(wp), parameter :: stretches(*) = [0.5_wp, 1.0_wp, 1.01_wp, 1.05_wp, 1.1_wp, &
            1.2_wp, 1.7_wp, 3.0_wp]
        real(wp) :: force_table, dforce_table, force_linear, dforce_linear
        integer :: j

        call new_table_law(table, [0.0_wp, 0.1_wp], [0.0_wp, 0.1_wp * linear_stiffness], error)
        if (allocated(error)) return
        call new_linear_law(linear, linear_stiffness, error)
        if (allocated(error)) return
        do j = 1, size(stretches)
            call table%get_force(stretches(j), force_table, dforce_table)
            call linear%get_force(stretches(j), force_linear, dforce_linear)
            call check_close(error, force_table, force_linear, identity_tol, 'two-row force')
            if (allocated(error)) return
            call check_close(error, dforce_table, dforce_linear, identity_tol, &
                'two-row df/dlambda')
            if (allocated(error)) return
            call check_close(error, table%get_energy(stretches(j)), &
                linear%get_energy(stretches(j)), identity_tol, 'two-row energy')
            if (allocated(error)) return
        end do
    end subroutine test_two_row_table

    !> Where the three-point end formula gives <= 0 the end slope is ratio * secant.
    subroutine test_end_slope_floor(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: law
        type(error_type), allocatable :: law_error
        real(wp), parameter :: ratio = 0.25_wp

        ! f = strain**2: the three-point slope at 0 is exactly 0.
        call new_table_law(law, [0.0_wp, 0.5_wp, 1.0_wp], [0.0_wp, 0.25_wp, 1.0_wp], error)
        if (allocated(error)) return
        call check_close(error, law%get_reference_stiffness(), &
            default_end_slope_ratio * 0.5_wp, identity_tol, 'convex start: floored slope')
        if (allocated(error)) return
        call new_table_law(law, [0.0_wp, 0.5_wp, 1.0_wp], [0.0_wp, 0.25_wp, 1.0_wp], error, &
            end_slope_ratio=ratio)
        if (allocated(error)) return
        call check_close(error, law%get_reference_stiffness(), ratio * 0.5_wp, identity_tol, &
            'convex start: floored slope with a given ratio')
        if (allocated(error)) return
        ! Saturating data: the three-point slope at the last row is negative.
        call new_table_law(law, [0.0_wp, 0.1_wp, 1.0_wp], [0.0_wp, 10.0_wp, 10.5_wp], error)
        if (allocated(error)) return
        call check_close(error, law%slope(3), default_end_slope_ratio * 0.5_wp / 0.9_wp, &
            identity_tol, 'saturating end: floored slope')
        if (allocated(error)) return
        call check_grid(law, law%strain, .true., error)
        if (allocated(error)) return
        ! A mild end keeps the three-point formula.
        call new_table_law(law, [0.0_wp, 1.0_wp, 2.0_wp], [0.0_wp, 2.0_wp, 3.0_wp], error)
        if (allocated(error)) return
        call check_close(error, law%get_reference_stiffness(), 2.5_wp, identity_tol, &
            'three-point end slope')
        if (allocated(error)) return
        call new_table_law(law, [0.0_wp, 1.0_wp], [0.0_wp, 1.0_wp], law_error, &
            end_slope_ratio=0.0_wp)
        call check_error(law_error, [character(len=40) :: 'end_slope_ratio 0', 'must lie in'], &
            error)
    end subroutine test_end_slope_floor

    !> Bad arrays are rejected with a message naming the row and value.
    subroutine test_table_rejects(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: law
        type(error_type), allocatable :: law_error
        real(wp) :: nan

        nan = ieee_value(1.0_wp, ieee_quiet_nan)
        call new_table_law(law, [0.0_wp, 0.2_wp, 0.1_wp], [0.0_wp, 1.0_wp, 2.0_wp], law_error)
        call check_error(law_error, [character(len=40) :: 'row 3', 'strain 0.1', &
            'not greater than 0.2 on row 2', 'strains must increase strictly'], error)
        if (allocated(error)) return
        call new_table_law(law, [0.0_wp, 0.1_wp, 0.2_wp], [0.0_wp, 0.35_wp, 0.31_wp], law_error)
        call check_error(law_error, [character(len=40) :: 'row 3', 'force 0.31', &
            'not greater than 0.35 on row 2', 'forces must increase strictly'], error)
        if (allocated(error)) return
        call new_table_law(law, [0.0_wp, 0.1_wp, 0.2_wp], [0.0_wp, 1.0_wp, 1.0_wp], law_error)
        call check_error(law_error, [character(len=40) :: 'row 3', 'force 1', &
            'forces must increase strictly'], error)
        if (allocated(error)) return
        call new_table_law(law, [0.01_wp, 0.1_wp], [0.0_wp, 1.0_wp], law_error)
        call check_error(law_error, [character(len=40) :: 'row 1', 'first row', &
            'strain 0, force 0', '0.01'], error)
        if (allocated(error)) return
        call new_table_law(law, [0.0_wp, 0.1_wp], [0.5_wp, 1.0_wp], law_error)
        call check_error(law_error, [character(len=40) :: 'row 1', 'first row', '0.5'], error)
        if (allocated(error)) return
        call new_table_law(law, [0.0_wp, 0.1_wp, 0.2_wp], [0.0_wp, nan, 2.0_wp], law_error)
        call check_error(law_error, [character(len=40) :: 'row 2', 'force NaN', &
            'not finite'], error)
        if (allocated(error)) return
        call new_table_law(law, [0.0_wp, ieee_value(1.0_wp, ieee_positive_inf)], &
            [0.0_wp, 1.0_wp], law_error)
        call check_error(law_error, [character(len=40) :: 'row 2', 'strain Infinity', &
            'not finite'], error)
        if (allocated(error)) return
        call new_table_law(law, [0.0_wp], [0.0_wp], law_error)
        call check_error(law_error, [character(len=40) :: 'found 1 data rows', &
            'at least 2'], error)
        if (allocated(error)) return
        call new_table_law(law, [0.0_wp, 0.1_wp, 0.2_wp], [0.0_wp, 1.0_wp], law_error)
        call check_error(law_error, [character(len=40) :: '3 strains but 2 forces'], error)
    end subroutine test_table_rejects

    !> Non-positive and non-finite parameters are rejected with the value named.
    subroutine test_analytic_rejects(error)
        type(error_type), allocatable, intent(out) :: error
        type(linear_law_type) :: linear
        type(neo_hookean_law_type) :: neo_hookean
        type(error_type), allocatable :: law_error
        real(wp) :: nan

        nan = ieee_value(1.0_wp, ieee_quiet_nan)
        call new_linear_law(linear, 0.0_wp, law_error)
        call check_error(law_error, [character(len=40) :: 'stiffness 0', &
            'must be greater than 0'], error)
        if (allocated(error)) return
        call new_linear_law(linear, -3.5_wp, law_error)
        call check_error(law_error, [character(len=40) :: 'stiffness -3.5'], error)
        if (allocated(error)) return
        call new_linear_law(linear, nan, law_error)
        call check_error(law_error, [character(len=40) :: 'stiffness NaN', 'not finite'], &
            error)
        if (allocated(error)) return
        call new_neo_hookean_law(neo_hookean, -1.0e9_wp, neo_area, law_error)
        call check_error(law_error, [character(len=40) :: 'modulus -1.0e9', &
            'must be greater than 0'], error)
        if (allocated(error)) return
        call new_neo_hookean_law(neo_hookean, neo_modulus, 0.0_wp, law_error)
        call check_error(law_error, [character(len=40) :: 'area 0', 'm**2'], error)
        if (allocated(error)) return
        call new_neo_hookean_law(neo_hookean, neo_modulus, &
            ieee_value(1.0_wp, ieee_positive_inf), law_error)
        call check_error(law_error, [character(len=40) :: 'area Infinity', 'not finite'], &
            error)
    end subroutine test_analytic_rejects

    !> A CSV table with a header, comments, blanks, tabs, CRLF and no final newline reads
    !> to the same law as the arrays.
    subroutine test_read_csv(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: from_file, from_arrays
        character(len=*), parameter :: path = 'test_material_good.csv'
        character(len=*), parameter :: lf = achar(10), cr = achar(13), tab = achar(9)
        real(wp), parameter :: strain(*) = [0.0_wp, 0.05_wp, 0.1_wp, 0.2_wp]
        real(wp), parameter :: force(*) = [0.0_wp, 0.8_wp, 2.5_wp, 9.0_wp]
        call write_file(path, '# yarn 42, measured 2024' // lf // 'strain , force (N)' // cr &
            // lf // '0,0' // lf // '' // lf // '  0.05 ,' // tab // '0.8  ' // cr // lf &
            // '# comment between rows' // lf // '1.0e-1,2.5' // lf // '2E-1, 9.0')
        call read_table_law(from_file, path, error)
        call delete_file(path)
        if (allocated(error)) return
        call new_table_law(from_arrays, strain, force, error)
        if (allocated(error)) return
        call check(error, size(from_file%strain) == size(strain), 'CSV: number of rows')
        if (allocated(error)) return
        ! Exact: the CSV text and the literals are rounded the same way.
        call check_close(error, from_file%strain, strain, 0.0_wp, 'CSV strains')
        if (allocated(error)) return
        call check_close(error, from_file%force, force, 0.0_wp, 'CSV forces')
        if (allocated(error)) return
        call check_close(error, from_file%slope, from_arrays%slope, 0.0_wp, 'CSV slopes')
    end subroutine test_read_csv

    !> Bad CSV files: the message names the file, the line and the value.
    subroutine test_read_csv_rejects(error)
        type(error_type), allocatable, intent(out) :: error
        type(table_law_type) :: law
        type(error_type), allocatable :: law_error
        character(len=*), parameter :: path = 'test_material_bad.csv'
        character(len=*), parameter :: lf = achar(10)
        character(len=*), parameter :: good = 'strain,force' // lf // '0,0' // lf

        call write_file(path, good // '0.1,0.2' // lf // '0.2,0.3' // lf // '0.3,0.33' // lf &
            // '0.4, 0.35' // lf // '0.5,0.31' // lf)
        call read_table_law(law, path, law_error)
        call check_message(law_error, "table 'test_material_bad.csv', line 7: force 0.31 is " &
            // 'not greater than 0.35 on line 6 (forces must increase strictly)', error)
        if (allocated(error)) return

        call write_file(path, good // '0.1,0.2' // lf // '0.1,0.3' // lf)
        call read_table_law(law, path, law_error)
        call check_error(law_error, [character(len=50) :: path, 'line 4', 'strain 0.1', &
            'on line 3', 'strains must increase strictly'], error)
        if (allocated(error)) return

        call write_file(path, good // '0.1,0.2' // lf // '0.2;0.3' // lf)
        call read_table_law(law, path, law_error)
        call check_error(law_error, [character(len=50) :: path, 'line 4', '''0.2;0.3''', &
            'strain,force'], error)
        if (allocated(error)) return

        call write_file(path, good // '0.1,abc' // lf)
        call read_table_law(law, path, law_error)
        call check_error(law_error, [character(len=50) :: path, 'line 3', &
            'force ''abc'' is not a number'], error)
        if (allocated(error)) return

        call write_file(path, good // '0.1,0.2,0.3' // lf)
        call read_table_law(law, path, law_error)
        call check_error(law_error, [character(len=50) :: path, 'line 3', &
            'expected 2 comma-separated values'], error)
        if (allocated(error)) return

        call write_file(path, good // '0.1,0.2' // lf // '0.2,nan' // lf)
        call read_table_law(law, path, law_error)
        call check_error(law_error, [character(len=50) :: path, 'line 4', 'force nan', &
            'not finite'], error)
        if (allocated(error)) return

        call write_file(path, 'strain,force' // lf // '0.0,0.1' // lf // '0.1,0.2' // lf)
        call read_table_law(law, path, law_error)
        call check_error(law_error, [character(len=50) :: path, 'line 2', 'first row', &
            '0.0, 0.1'], error)
        if (allocated(error)) return

        call write_file(path, '# only a header' // lf // good)
        call read_table_law(law, path, law_error)
        call check_error(law_error, [character(len=50) :: path, 'found 1 data rows', &
            'at least 2'], error)
        if (allocated(error)) return

        call write_file(path, '')
        call read_table_law(law, path, law_error)
        call check_error(law_error, [character(len=50) :: path, 'found 0 data rows'], error)
        call delete_file(path)
        if (allocated(error)) return

        call read_table_law(law, 'no_such_dir/missing.csv', law_error)
        call check_error(law_error, [character(len=50) :: &
            "table 'no_such_dir/missing.csv'", 'cannot open'], error)
        if (allocated(error)) return

        call write_file(path, good // '0.1,0.2' // lf)
        call read_table_law(law, path, law_error, end_slope_ratio=2.0_wp)
        call delete_file(path)
        call check_error(law_error, [character(len=50) :: path, 'end_slope_ratio 2'], error)
    end subroutine test_read_csv_rejects

    ! ---------------------------------------------------------------- helpers

    !> Fail unless `law_error` is set and its message holds every one of `words`.
    subroutine check_error(law_error, words, error)
        type(error_type), allocatable, intent(in) :: law_error
        character(len=*), intent(in) :: words(:)
        type(error_type), allocatable, intent(out) :: error
        integer :: i

        call check(error, allocated(law_error), 'expected an error containing "' &
            // trim(words(1)) // '", got none')
        if (allocated(error)) return
        do i = 1, size(words)
            call check(error, index(law_error%message, trim(words(i))) > 0, &
                'expected "' // trim(words(i)) // '" in the message: ' // law_error%message)
            if (allocated(error)) return
        end do
    end subroutine check_error

    !> Fail unless `law_error` is set with exactly `message`.
    subroutine check_message(law_error, message, error)
        type(error_type), allocatable, intent(in) :: law_error
        character(len=*), intent(in) :: message
        type(error_type), allocatable, intent(out) :: error

        call check(error, allocated(law_error), 'expected the error: ' // message)
        if (allocated(error)) return
        call check(error, law_error%message == message, 'expected the message "' // message &
            // '", got "' // law_error%message // '"')
    end subroutine check_message

    !> Write `text` byte for byte (newlines as given) to `path`.
    subroutine write_file(path, text)
        character(len=*), intent(in) :: path, text
        integer :: unit

        open(newunit=unit, file=path, access='stream', form='unformatted', &
            status='replace', action='write')
        write(unit) text
        close(unit)
    end subroutine write_file

    !> Remove a file written by a test.
    subroutine delete_file(path)
        character(len=*), intent(in) :: path
        integer :: unit, stat

        open(newunit=unit, file=path, status='old', iostat=stat)
        if (stat == 0) close(unit, status='delete')
    end subroutine delete_file

end module test_material
