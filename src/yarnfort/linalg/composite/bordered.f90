! SPDX-License-Identifier: MIT
!> A linear solver for a matrix whose leading block is symmetric and whose border (the
!> last few unknowns) is not: [K B; C D], K of order n_leading. With few border unknowns
!> it factors K alone (by `leading`, e.g. CHOLMOD) and the border through the dense Schur
!> complement S = D - C K^-1 B; with more it factors the whole matrix (by `general`).
!> Why: the friction Jacobian with its stick flows eliminated (yarnfort_linalg_composite_condensed)
!> is the elastic tangent bordered by the slipping flows, often a handful, and CHOLMOD
!> factors the elastic tangent faster than an LU factors the bordered matrix
!> (docs/decisions.md, 'Bordered solver: up to 16 border unknowns'). The
!> pattern of K does not change with the active set: its analysis is kept for the next
!> pattern while that block stays the same. K^-1 B is one solve of m columns (CHOLMOD
!> applies its dense blocks to all of them at once). A K that fails to factor sends the
!> next patterns to `general` without trying K (1, 2, 4, ... patterns while it keeps
!> failing).
module yarnfort_linalg_composite_bordered
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_backend_direct, only: direct_solver_type, get_subpattern
    use yarnfort_linalg_backend_dense, only: dense_solver_type
    implicit none
    private

    public :: bordered_solver_type, default_max_border

    !> Most border unknowns handled through the Schur complement: each costs a column of
    !> the solve with K's factors per factorisation and n_leading reals of memory; set
    !> from where the border stops paying (docs/decisions.md, 'Bordered solver: up to 16
    !> border unknowns').
    integer(ik), parameter :: default_max_border = 16
    !> Most patterns sent to `general` after K failed to factor, before K is tried again.
    integer, parameter :: max_skip_patterns = 16

    type, extends(direct_solver_type) :: bordered_solver_type
        !> Order of the symmetric leading block (set by the owner before analyse).
        integer(ik) :: n_leading = 0
        integer(ik) :: max_border = default_max_border
        !> Solvers of K and of the whole matrix (owned; set by the owner).
        class(linear_solver_type), allocatable :: leading, general
        !> The border is used for the current pattern (else `general` on the whole).
        logical :: use_border = .false.
        !> Pattern of K as analysed by `leading`, and for each of its entries the entry of
        !> the whole matrix.
        integer(ik), allocatable :: leading_col_ptr(:), leading_row_index(:), source(:)
        logical :: leading_analysed = .false.
        !> K^-1 B (n_leading x m) and the Schur complement's solver.
        real(wp), allocatable :: coupling(:, :)
        type(dense_solver_type) :: schur
        !> Entries of the border rows in the leading columns (C): entry, row (1..m), column,
        !> and their values at the last factorisation.
        integer(ik), allocatable :: c_entry(:), c_row(:), c_column(:)
        real(wp), allocatable :: c_values(:)
        !> Factorisations through the border and through `general` (any reason), the
        !> border unknowns of all of them summed and their most, and the failed
        !> factorisations of K: what the border limit is judged by (bench_friction).
        integer :: n_border_factors = 0, n_general_factors = 0, n_leading_failures = 0
        integer(ik) :: width_sum = 0, max_width = 0
        !> After K failed to factor (not positive definite), the next `skip_patterns`
        !> patterns go to `general` without trying K again; the skip doubles with each
        !> failure in a row (up to max_skip_patterns) and is reset when K factors.
        integer :: skip_patterns = 0, next_skip = 1
        !> Patterns sent to `general` that way.
        integer :: n_skipped_patterns = 0
    contains
        procedure :: analyse_pattern
        procedure :: factor_values
        procedure :: solve_rhs_columns
        procedure :: release
        procedure :: get_name
    end type bordered_solver_type

contains

    !> Choose the path for this pattern; analyse K (unless its pattern is the one already
    !> analysed) or the whole matrix.
    subroutine analyse_pattern(self, error)
        class(bordered_solver_type), intent(inout) :: self
        type(error_type), allocatable, intent(out) :: error
        integer(ik) :: m

        if (.not. (allocated(self%leading) .and. allocated(self%general))) then
            call fatal_error(error, self%get_name() // ': no leading or general solver')
            return
        end if
        m = self%n - self%n_leading
        self%use_border = self%n_leading > 0 .and. m >= 0 .and. m <= self%max_border
        if (self%use_border .and. self%skip_patterns > 0) then
            self%skip_patterns = self%skip_patterns - 1
            self%n_skipped_patterns = self%n_skipped_patterns + 1
            self%use_border = .false.
        end if
        if (.not. self%use_border) then
            call self%general%analyse(self%n, int(self%col_ptr, ik), int(self%row_index, ik), &
                error)
            return
        end if
        call analyse_leading(self, error)
        if (allocated(error)) return
        call find_border_rows(self)
        if (m > 0) then
            block
                integer(ik), allocatable :: dense_ptr(:), dense_rows(:)
                integer(ik) :: i, j
                dense_ptr = [(j * m, j = 0, m)]
                dense_rows = [((i, i = 0, m - 1), j = 1, m)]
                call self%schur%analyse(m, dense_ptr, dense_rows, error)
            end block
        end if
    end subroutine analyse_pattern

    !> The pattern of K and its source entries; `leading` analyses it unless it is the
    !> pattern it holds.
    subroutine analyse_leading(self, error)
        type(bordered_solver_type), intent(inout) :: self
        type(error_type), allocatable, intent(out) :: error
        integer(ik), allocatable :: col_ptr(:), row_index(:), index(:)
        integer(ik) :: j

        ! K: the leading rows and columns, numbered as in the whole matrix.
        allocate(index(self%n), source=0_ik)
        index(1:self%n_leading) = [(j, j = 1, self%n_leading)]
        call get_subpattern(self%col_ptr, self%row_index, index, col_ptr, row_index, self%source)
        if (self%leading_analysed) then
            if (size(self%leading_row_index) == size(row_index)) then
                if (all(self%leading_col_ptr == col_ptr) .and. &
                    all(self%leading_row_index == row_index)) return
            end if
            call self%leading%destroy()
            self%leading_analysed = .false.
        end if
        self%leading_col_ptr = col_ptr
        self%leading_row_index = row_index
        call self%leading%analyse(self%n_leading, self%leading_col_ptr, &
            self%leading_row_index, error)
        self%leading_analysed = .not. allocated(error)
    end subroutine analyse_leading

    !> The entries of the border rows in the leading columns (C).
    subroutine find_border_rows(self)
        type(bordered_solver_type), intent(inout) :: self
        integer(ik) :: j, k, count

        count = 0
        do j = 1, self%n_leading
            do k = self%col_ptr(j) + 1, self%col_ptr(j + 1)
                if (self%row_index(k) >= self%n_leading) count = count + 1
            end do
        end do
        allocate(self%c_entry(count), self%c_row(count), self%c_column(count))
        count = 0
        do j = 1, self%n_leading
            do k = self%col_ptr(j) + 1, self%col_ptr(j + 1)
                if (self%row_index(k) < self%n_leading) cycle
                count = count + 1
                self%c_entry(count) = k
                self%c_row(count) = self%row_index(k) + 1 - self%n_leading
                self%c_column(count) = j
            end do
        end do
    end subroutine find_border_rows

    !> Factor K, then S = D - C K^-1 B; the whole matrix by `general` when the border is
    !> too wide, or when K or S cannot be factored (for the rest of this pattern).
    subroutine factor_values(self, values, error)
        class(bordered_solver_type), intent(inout) :: self
        real(wp), intent(in) :: values(:)
        type(error_type), allocatable, intent(out) :: error

        self%width_sum = self%width_sum + (self%n - self%n_leading)
        self%max_width = max(self%max_width, self%n - self%n_leading)
        if (self%use_border) then
            call factor_border(self, values, error)
            if (.not. allocated(error)) then
                self%n_border_factors = self%n_border_factors + 1
                return
            end if
            deallocate(error)
            self%use_border = .false.
            call self%general%analyse(self%n, int(self%col_ptr, ik), int(self%row_index, ik), &
                error)
            if (allocated(error)) return
        end if
        self%n_general_factors = self%n_general_factors + 1
        call self%general%factor(values, error)
    end subroutine factor_values

    subroutine factor_border(self, values, error)
        type(bordered_solver_type), intent(inout) :: self
        real(wp), intent(in) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: s(:, :)
        integer(ik) :: m, c, k, j

        call self%leading%factor(values(self%source), error)
        if (allocated(error)) then
            self%n_leading_failures = self%n_leading_failures + 1
            self%skip_patterns = self%next_skip
            self%next_skip = min(2 * self%next_skip, max_skip_patterns)
            return
        end if
        self%next_skip = 1
        m = self%n - self%n_leading
        if (m == 0) return
        if (allocated(self%coupling)) deallocate(self%coupling)
        allocate(self%coupling(self%n_leading, m), s(m, m))
        s = 0.0_wp
        self%coupling = 0.0_wp
        ! B's and D's columns, then K^-1 B in one solve of m columns.
        do c = 1, m
            j = self%n_leading + c
            do k = self%col_ptr(j) + 1, self%col_ptr(j + 1)
                if (self%row_index(k) < self%n_leading) then
                    self%coupling(self%row_index(k) + 1, c) = values(k)
                else
                    s(self%row_index(k) + 1 - self%n_leading, c) = values(k)
                end if
            end do
        end do
        call self%leading%solve_columns(self%coupling, error)
        if (allocated(error)) return
        self%c_values = values(self%c_entry)
        do k = 1, size(self%c_entry, kind=ik)
            s(self%c_row(k), :) = s(self%c_row(k), :) &
                - self%c_values(k) * self%coupling(self%c_column(k), :)
        end do
        call self%schur%factor(reshape(s, [m * m]), error)
    end subroutine factor_border

    !> z = K^-1 r1, y = S^-1 (r2 - C z), x = z - K^-1 B y, for the m columns of rhs (each
    !> column's arithmetic that of a single solve): K^-1 of all of them in one
    !> `solve_columns` and the Schur complement's solve of all of them.
    subroutine solve_rhs_columns(self, rhs, error)
        class(bordered_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: rhs(:, :)
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: y(:, :)
        integer(ik) :: k, nl, c

        if (.not. self%use_border) then
            call self%general%solve_columns(rhs, error)
            return
        end if
        nl = self%n_leading
        call self%leading%solve_columns(rhs(1:nl, :), error)
        if (allocated(error) .or. self%n == nl) return
        y = rhs(nl + 1:, :)
        do k = 1, size(self%c_entry, kind=ik)
            y(self%c_row(k), :) = y(self%c_row(k), :) &
                - self%c_values(k) * rhs(self%c_column(k), :)
        end do
        call self%schur%solve_columns(y, error)
        if (allocated(error)) return
        do c = 1, size(rhs, 2)
            rhs(1:nl, c) = rhs(1:nl, c) - matmul(self%coupling, y(:, c))
        end do
        rhs(nl + 1:, :) = y
    end subroutine solve_rhs_columns

    !> Free the general solver and the border; the analysis of K is kept for the next
    !> pattern (freed with the object).
    subroutine release(self)
        class(bordered_solver_type), intent(inout) :: self

        if (allocated(self%general)) call self%general%destroy()
        call self%schur%destroy()
        if (allocated(self%coupling)) deallocate(self%coupling)
        if (allocated(self%c_entry)) deallocate(self%c_entry)
        if (allocated(self%c_row)) deallocate(self%c_row)
        if (allocated(self%c_column)) deallocate(self%c_column)
        if (allocated(self%c_values)) deallocate(self%c_values)
        if (allocated(self%source)) deallocate(self%source)
        self%use_border = .false.
    end subroutine release

    pure function get_name(self) result(name)
        class(bordered_solver_type), intent(in) :: self
        character(len=:), allocatable :: name

        name = 'bordered'
        if (self%use_border .and. allocated(self%leading)) then
            name = 'bordered+' // self%leading%get_name()
        else if (allocated(self%general)) then
            name = self%general%get_name()
        end if
    end function get_name

end module yarnfort_linalg_composite_bordered
