! SPDX-License-Identifier: MIT
!> Sparsity pattern of the equilibrium Jacobian in compressed sparse column form, built
!> once per topology, with the map from each element's 6x6 tangent to value slots.
module yarnfort_assembly_pattern
    use yarnfort_kinds, only: ik
    use yarnfort_network_network, only: network_type
    use yarnfort_network_dof_map, only: dof_map_type
    use yarnfort_sort, only: sort_index
    implicit none
    private

    public :: pattern_type, new_pattern, build_clique_pattern

    !> CSC pattern with 0-based int64 indices (the layout of a SUNSparseMatrix).
    type :: pattern_type
        integer(ik) :: n = 0
        integer(ik) :: nnz = 0
        !> Column starts, (n + 1), 0-based.
        integer(ik), allocatable :: col_ptr(:)
        !> Row of each stored entry, (nnz), 0-based, ascending in each column.
        integer(ik), allocatable :: row_index(:)
        !> Value slot (1-based) of entry (a, b) of each element's 6x6 tangent, (6, 6,
        !> n_elements); 0 where row or column is prescribed. Local order: node 1 xyz,
        !> node 2 xyz.
        integer, allocatable :: element_slot(:, :, :)
    end type pattern_type

contains

    !> Build the pattern of P^T K P for the network's elements and the unknowns of
    !> `dofs`: for each unknown, the unknowns that share an element with it.
    subroutine new_pattern(self, network, dofs)
        type(pattern_type), intent(out) :: self
        type(network_type), intent(in) :: network
        type(dof_map_type), intent(in) :: dofs
        integer, allocatable :: element_unknowns(:, :)
        integer :: e, a, k

        allocate(element_unknowns(6, network%n_elements()))
        do e = 1, network%n_elements()
            do a = 1, 2
                do k = 1, 3
                    element_unknowns(3 * (a - 1) + k, e) = &
                        dofs%unknown(3 * (network%element_nodes(a, e) - 1) + k)
                end do
            end do
        end do
        call build_clique_pattern(dofs%n_unknowns, element_unknowns, self%col_ptr, &
            self%row_index, self%element_slot)
        self%n = dofs%n_unknowns
        self%nnz = size(self%row_index)
    end subroutine new_pattern

    !> CSC pattern (0-based, rows ascending) of n unknowns where the unknowns of each
    !> clique (a column of `cliques`, entries 0 ignored) are all coupled; and the value
    !> slot (1-based, 0 where an entry is 0) of every pair (a, b) of each clique.
    subroutine build_clique_pattern(n, cliques, col_ptr, row_index, slots)
        integer, intent(in) :: n, cliques(:, :)
        integer(ik), allocatable, intent(out) :: col_ptr(:), row_index(:)
        integer, allocatable, intent(out) :: slots(:, :, :)
        integer :: n_cliques, width, c, a, b, i, j, col, pos, first, last, n_rows
        integer, allocatable :: count(:), start(:), members(:), stamp(:), rows(:)
        integer(ik), allocatable :: all_rows(:)
        integer :: capacity, used

        width = size(cliques, 1)
        n_cliques = size(cliques, 2)
        ! Cliques touching each unknown (compressed lists).
        allocate(count(n), source=0)
        do c = 1, n_cliques
            do a = 1, width
                i = cliques(a, c)
                if (i > 0) count(i) = count(i) + 1
            end do
        end do
        allocate(start(n + 1))
        start(1) = 1
        do i = 1, n
            start(i + 1) = start(i) + count(i)
        end do
        allocate(members(start(n + 1) - 1))
        count = 0
        do c = 1, n_cliques
            do a = 1, width
                i = cliques(a, c)
                if (i > 0) then
                    members(start(i) + count(i)) = c
                    count(i) = count(i) + 1
                end if
            end do
        end do

        ! Rows of each column: the unknowns of the cliques touching it, deduplicated
        ! with a stamp and sorted (short lists).
        allocate(col_ptr(n + 1))
        allocate(stamp(n), source=0)
        allocate(rows(64))
        col_ptr(1) = 0
        capacity = 9 * width * n + 16
        allocate(all_rows(capacity))
        used = 0
        do col = 1, n
            n_rows = 0
            do pos = start(col), start(col + 1) - 1
                c = members(pos)
                do a = 1, width
                    i = cliques(a, c)
                    if (i > 0) then
                        if (stamp(i) /= col) then
                            stamp(i) = col
                            n_rows = n_rows + 1
                            if (n_rows > size(rows)) call grow(rows)
                            rows(n_rows) = i
                        end if
                    end if
                end do
            end do
            rows(1:n_rows) = rows(sort_index(rows(1:n_rows)))
            if (used + n_rows > capacity) then
                capacity = max(2 * capacity, used + n_rows)
                call grow_ik(all_rows, capacity)
            end if
            all_rows(used + 1:used + n_rows) = int(rows(1:n_rows) - 1, ik)
            used = used + n_rows
            col_ptr(col + 1) = used
        end do
        row_index = all_rows(1:used)

        ! Slot of each clique entry: search the row in its column.
        allocate(slots(width, width, n_cliques), source=0)
        do c = 1, n_cliques
            do b = 1, width
                j = cliques(b, c)
                if (j == 0) cycle
                first = int(col_ptr(j)) + 1
                last = int(col_ptr(j + 1))
                do a = 1, width
                    i = cliques(a, c)
                    if (i == 0) cycle
                    slots(a, b, c) = find_row(row_index(first:last), i - 1) + first - 1
                end do
            end do
        end do
    contains
        subroutine grow(array)
            integer, allocatable, intent(inout) :: array(:)
            integer, allocatable :: tmp(:)
            allocate(tmp(2 * size(array)))
            tmp(1:size(array)) = array
            call move_alloc(tmp, array)
        end subroutine grow

        subroutine grow_ik(array, capacity)
            integer(ik), allocatable, intent(inout) :: array(:)
            integer, intent(in) :: capacity
            integer(ik), allocatable :: tmp(:)
            allocate(tmp(capacity))
            tmp(1:size(array)) = array
            call move_alloc(tmp, array)
        end subroutine grow_ik
    end subroutine build_clique_pattern

    !> Position (1-based) of `row` in the ascending list `rows` (binary search).
    pure integer function find_row(rows, row) result(pos)
        integer(ik), intent(in) :: rows(:)
        integer, intent(in) :: row
        integer :: lo, hi, mid
        lo = 1
        hi = size(rows)
        pos = 0
        do while (lo <= hi)
            mid = (lo + hi) / 2
            if (rows(mid) == row) then
                pos = mid
                return
            else if (rows(mid) < row) then
                lo = mid + 1
            else
                hi = mid - 1
            end if
        end do
    end function find_row

end module yarnfort_assembly_pattern
