! SPDX-License-Identifier: MIT
!> A linear solver that first eliminates the unknowns whose rows hold nothing but their
!> diagonal (in the friction Jacobian: the rows k (s - s_target) of sticking passages),
!> then hands the remaining system to another solver. Exact: for such a row
!> x_j = b_j / a_jj, and column j moves to the right-hand side of the other rows. The
!> reduced system is analysed again whenever the set of eliminated unknowns changes
!> (between the stick/slip active-set rounds of a step) and refactored otherwise.
!> Why: a sticking flow's column couples every coordinate of the two segments it
!> bounds, which is what makes the friction Jacobian's factors dense; with the stick
!> flows gone the reduced system is the elastic tangent plus the slipping flows
!> (docs/decisions.md, 'Stick flows eliminated before factorising (condensed solver)').
!> With more than `superset_above` kept candidates (the inner solver then factors the
!> whole reduced matrix, not a border) the reduction keeps a superset: the candidates
!> that must stay and their neighbours in the pattern up to `superset_reach` steps (the
!> flows of the passages next to a slipping one along its yarn), and the next sets are
!> solved with that reduction while they fit in it; the trivial rows kept are at most
!> `superset_fraction` of the coordinates. A kept trivial row is only not eliminated
!> (the solve stays exact); what it saves is the inner solver's analysis and full
!> factorisation, which a new pattern costs and a refactorisation does not
!> (docs/decisions.md, 'Condensed solver: superset reduction (16 / 4 / 2 %)').
module yarnfort_linalg_composite_condensed
    use yarnfort_kinds, only: wp, ik
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_linalg_linear_solver, only: linear_solver_type
    use yarnfort_linalg_backend_direct, only: direct_solver_type, get_subpattern
    implicit none
    private

    public :: condensed_solver_type

    !> Eliminates trivial rows, then calls `inner` on the rest. The pattern, the call
    !> order and the array sizes are checked by direct_solver_type.
    type, extends(direct_solver_type) :: condensed_solver_type
        !> The solver of the reduced system (owned).
        class(linear_solver_type), allocatable :: inner
        !> Only unknowns first_candidate..n may be eliminated (1-based): the owner knows
        !> which rows can be trivial (the flows); a coordinate row that happens to hold
        !> only its diagonal for one matrix would make the reduced pattern flicker.
        integer(ik) :: first_candidate = 1
        !> Reduced index of each unknown (1-based), 0 for an eliminated one; the reduced
        !> pattern and, for each of its entries, the entry of the full matrix.
        integer(ik), allocatable :: reduced(:)
        integer(ik), allocatable :: reduced_col_ptr(:), reduced_row_index(:), source(:)
        integer(ik) :: n_reduced = 0
        !> The unknown of each reduced one, and the eliminated unknowns (increasing): what
        !> `solve` gathers and scatters.
        integer(ik), allocatable :: kept(:), eliminated(:)
        !> Diagonal of each eliminated unknown's row (0 for the others).
        real(wp), allocatable :: pivot(:)
        !> Entry of each candidate's diagonal (0 if not stored), and the off-diagonal
        !> entries of the candidate rows with their rows: what decides which rows are
        !> trivial, found once per pattern.
        integer(ik), allocatable :: diagonal(:), candidate_entry(:), candidate_row(:)
        !> The last values of the candidate columns (entries col_ptr(first_candidate) + 1
        !> onwards: `solve` moves the eliminated columns to the right-hand side).
        real(wp), allocatable :: values(:)
        logical :: inner_analysed = .false.
        !> Analyses of the reduced system so far (each set of eliminated unknowns).
        integer :: n_reductions = 0
        !> Above this many kept candidates the reduction keeps a superset (module notes);
        !> at or below it, exactly the non-trivial rows (the default: the bordered
        !> solver's border limit, below which a new set costs no new analysis).
        integer(ik) :: superset_above = 16
        !> How far the superset reaches: candidates within this many steps of a
        !> non-trivial row in the pattern (along a yarn, the flows of the passages next
        !> to a slipping one); fewer new analyses per cycle as it grows, little gained
        !> beyond 4 (docs/decisions.md, 'Condensed solver: superset reduction').
        integer :: superset_reach = 4
        !> Most trivial rows kept, as a fraction of the unknowns before first_candidate
        !> (the coordinates): a kept stick flow costs the factors what a slipping one
        !> does, so a net where much slips gets the exact set (docs/decisions.md,
        !> 'Condensed solver: superset reduction').
        real(wp) :: superset_fraction = 0.02_wp
        !> Column of each of candidate_entry (its row is candidate_row): the neighbours.
        integer(ik), allocatable :: candidate_column(:)
    contains
        procedure :: analyse_pattern
        procedure :: factor_values
        procedure :: solve_rhs_columns
        procedure :: release
        procedure :: get_name
    end type condensed_solver_type

contains

    !> The candidates' entries of the kept pattern (direct_solver_type checked and kept it).
    subroutine analyse_pattern(self, error)
        class(condensed_solver_type), intent(inout) :: self
        type(error_type), allocatable, intent(out) :: error

        if (.not. allocated(self%inner)) then
            call fatal_error(error, self%get_name() // ': no solver for the reduced system')
            return
        end if
        allocate(self%reduced(self%n), source=0_ik)
        self%n_reductions = 0
        allocate(self%pivot(self%n), source=0.0_wp)
        call find_candidate_entries(self)
    end subroutine analyse_pattern

    !> Find the trivial rows of these values, reduce (analysing the reduced pattern
    !> again if the kept set changes: choose_reduction) and factor the reduced matrix.
    subroutine factor_values(self, values, error)
        class(condensed_solver_type), intent(inout) :: self
        real(wp), intent(in) :: values(:)
        type(error_type), allocatable, intent(out) :: error
        logical, allocatable :: trivial(:)
        integer(ik) :: j, k, m

        ! A candidate row is trivial when its only nonzero value is a nonzero diagonal.
        self%pivot = 0.0_wp
        do j = self%first_candidate, self%n
            if (self%diagonal(j) > 0) self%pivot(j) = values(self%diagonal(j))
        end do
        trivial = self%pivot /= 0.0_wp
        do k = 1, size(self%candidate_entry, kind=ik)
            if (values(self%candidate_entry(k)) /= 0.0_wp) &
                trivial(self%candidate_row(k)) = .false.
        end do
        where (.not. trivial) self%pivot = 0.0_wp
        call choose_reduction()
        self%values = values(self%col_ptr(self%first_candidate) + 1:size(self%row_index))
        if (self%n_reduced > 0) then
            if (.not. self%inner_analysed) then
                call self%inner%analyse(self%n_reduced, self%reduced_col_ptr, &
                    self%reduced_row_index, error)
                if (allocated(error)) return
                self%inner_analysed = .true.
            end if
            call self%inner%factor(values(self%source), error)
            if (allocated(error)) return
        end if
    contains
        !> Reduce again when a row that must stay was eliminated, or when the kept set
        !> differs from the one wanted (exactly the non-trivial rows up to superset_above
        !> of them; above, those and their neighbours, reused while it holds them and
        !> at most max_extra trivial rows besides).
        subroutine choose_reduction()
            logical, allocatable :: wanted(:), reached(:)
            integer(ik) :: n_must, n_kept, max_extra
            integer :: sweep

            allocate(wanted(self%n))
            wanted = .not. trivial
            n_must = count(wanted(self%first_candidate:), kind=ik)
            max_extra = int(self%superset_fraction * (self%first_candidate - 1), ik)
            if (n_must > self%superset_above) then
                do sweep = 1, self%superset_reach
                    allocate(reached, source=wanted)
                    do k = 1, size(self%candidate_entry, kind=ik)
                        if (self%candidate_column(k) < self%first_candidate) cycle
                        if (wanted(self%candidate_row(k))) &
                            reached(self%candidate_column(k)) = .true.
                        if (wanted(self%candidate_column(k))) &
                            reached(self%candidate_row(k)) = .true.
                    end do
                    call move_alloc(reached, wanted)
                    ! The sweeps only add rows: once past max_extra, the test below
                    ! takes the exact set whatever the later sweeps add.
                    if (count(wanted(self%first_candidate:), kind=ik) - n_must &
                        > max_extra) exit
                end do
                ! Too many neighbours (a large part of the flows slips): the exact set.
                if (count(wanted(self%first_candidate:), kind=ik) - n_must > max_extra) &
                    wanted = .not. trivial
                if (self%n_reductions > 0) then
                    n_kept = count(self%reduced(self%first_candidate:) /= 0, kind=ik)
                    if (.not. any(.not. trivial .and. self%reduced == 0) &
                        .and. n_kept - n_must <= max_extra) return
                end if
            else if (self%n_reductions > 0) then
                if (.not. any(wanted .neqv. (self%reduced /= 0))) return
            end if
            call reduce(.not. wanted)
        end subroutine choose_reduction

        !> The reduced pattern: the stored entries whose row and column both stay.
        subroutine reduce(eliminated)
            logical, intent(in) :: eliminated(:)

            m = 0
            do j = 1, self%n
                if (eliminated(j)) then
                    self%reduced(j) = 0
                else
                    m = m + 1
                    self%reduced(j) = m
                end if
            end do
            self%n_reduced = m
            self%kept = pack([(j, j = 1, self%n)], .not. eliminated)
            self%eliminated = pack([(j, j = 1, self%n)], eliminated)
            call get_subpattern(self%col_ptr, self%row_index, self%reduced, &
                self%reduced_col_ptr, self%reduced_row_index, self%source)
            if (self%inner_analysed) call self%inner%destroy()
            self%inner_analysed = .false.
            self%n_reductions = self%n_reductions + 1
        end subroutine reduce
    end subroutine factor_values

    !> Eliminated unknowns from their rows, their columns moved to the right-hand side,
    !> then the reduced system: the elimination for all m columns, then one
    !> `solve_columns` of the reduced system (each column's arithmetic that of a single
    !> solve).
    subroutine solve_rhs_columns(self, rhs, error)
        class(condensed_solver_type), intent(inout) :: self
        real(wp), intent(inout) :: rhs(:, :)
        type(error_type), allocatable, intent(out) :: error
        integer(ik) :: j, k, i, e, c, offset
        ! Per call, not kept: m columns of the reduced order (16 at 963,600 unknowns:
        ! 123 MB) would otherwise stay allocated for the whole run.
        real(wp), allocatable :: part(:, :)

        offset = self%col_ptr(self%first_candidate)
        ! Column by column (each column's arithmetic is its own; scalar updates, no
        ! row sections of rhs).
        do c = 1, size(rhs, 2, kind=ik)
            do e = 1, size(self%eliminated, kind=ik)
                j = self%eliminated(e)
                rhs(j, c) = rhs(j, c) / self%pivot(j)
                ! A zero moves nothing to the other rows: subtracting v * 0 changes no
                ! value (it could only turn a -0 entry into +0). Almost every stick flow's
                ! row is met exactly after the first step: 221,324 of 221,356 eliminated
                ! entries were 0 over the woven cycle of 10,120 unknowns.
                if (rhs(j, c) == 0.0_wp) cycle
                do k = self%col_ptr(j) + 1, self%col_ptr(j + 1)
                    i = self%row_index(k) + 1
                    if (self%reduced(i) /= 0) &
                        rhs(i, c) = rhs(i, c) - self%values(k - offset) * rhs(j, c)
                end do
            end do
        end do
        if (self%n_reduced == 0) return
        allocate(part(self%n_reduced, size(rhs, 2)))
        do c = 1, size(rhs, 2, kind=ik)
            part(:, c) = rhs(self%kept, c)
        end do
        call self%inner%solve_columns(part, error)
        if (allocated(error)) return
        do c = 1, size(rhs, 2, kind=ik)
            rhs(self%kept, c) = part(:, c)
        end do
    end subroutine solve_rhs_columns

    !> The diagonal entries of the candidate columns and the off-diagonal entries of the
    !> candidate rows (first_candidate clipped to 1..n + 1).
    subroutine find_candidate_entries(self)
        type(condensed_solver_type), intent(inout) :: self
        integer(ik) :: j, k, i, count

        self%first_candidate = min(max(self%first_candidate, 1_ik), self%n + 1)
        allocate(self%diagonal(self%n), source=0_ik)
        count = 0
        do j = 1, self%n
            do k = self%col_ptr(j) + 1, self%col_ptr(j + 1)
                i = self%row_index(k) + 1
                if (i < self%first_candidate) cycle
                if (i == j) then
                    self%diagonal(j) = k
                else
                    count = count + 1
                end if
            end do
        end do
        allocate(self%candidate_entry(count), self%candidate_row(count), &
            self%candidate_column(count))
        count = 0
        do j = 1, self%n
            do k = self%col_ptr(j) + 1, self%col_ptr(j + 1)
                i = self%row_index(k) + 1
                if (i < self%first_candidate .or. i == j) cycle
                count = count + 1
                self%candidate_entry(count) = k
                self%candidate_row(count) = i
                self%candidate_column(count) = j
            end do
        end do
    end subroutine find_candidate_entries

    !> Free the reduced system's solver and the reduction.
    subroutine release(self)
        class(condensed_solver_type), intent(inout) :: self

        if (allocated(self%inner)) call self%inner%destroy()
        self%inner_analysed = .false.
        self%n_reduced = 0
        if (allocated(self%reduced)) deallocate(self%reduced)
        if (allocated(self%kept)) deallocate(self%kept)
        if (allocated(self%eliminated)) deallocate(self%eliminated)
        if (allocated(self%reduced_col_ptr)) deallocate(self%reduced_col_ptr)
        if (allocated(self%reduced_row_index)) deallocate(self%reduced_row_index)
        if (allocated(self%source)) deallocate(self%source)
        if (allocated(self%pivot)) deallocate(self%pivot)
        if (allocated(self%diagonal)) deallocate(self%diagonal)
        if (allocated(self%candidate_entry)) deallocate(self%candidate_entry)
        if (allocated(self%candidate_row)) deallocate(self%candidate_row)
        if (allocated(self%candidate_column)) deallocate(self%candidate_column)
        if (allocated(self%values)) deallocate(self%values)
    end subroutine release

    pure function get_name(self) result(name)
        class(condensed_solver_type), intent(in) :: self
        character(len=:), allocatable :: name

        if (allocated(self%inner)) then
            name = 'condensed+' // self%inner%get_name()
        else
            name = 'condensed'
        end if
    end function get_name

end module yarnfort_linalg_composite_condensed
