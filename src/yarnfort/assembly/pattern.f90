! SPDX-License-Identifier: MIT
!> Sparsity pattern of the equilibrium Jacobian in compressed sparse column form, built
!> once per topology, with the map from each element's 6x6 tangent to value slots.
module yarnfort_assembly_pattern
    use yarnfort_kinds, only: wp, ik
    use yarnfort_network_network, only: network_type
    use yarnfort_network_dof_map, only: dof_map_type
    implicit none
    private

    public :: pattern_type, new_pattern

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
        integer :: n, n_elements, e, a, b, i, j, col, pos, first, last
        integer, allocatable :: element_unknowns(:, :), count(:), start(:), members(:)
        integer, allocatable :: stamp(:), rows(:)
        integer :: n_rows, k

        n = dofs%n_unknowns
        n_elements = network%n_elements()
        self%n = n
        allocate(element_unknowns(6, n_elements))
        do e = 1, n_elements
            do a = 1, 2
                do k = 1, 3
                    element_unknowns(3 * (a - 1) + k, e) = &
                        dofs%unknown(3 * (network%element_nodes(a, e) - 1) + k)
                end do
            end do
        end do

        ! Elements touching each unknown (compressed lists).
        allocate(count(n), source=0)
        do e = 1, n_elements
            do a = 1, 6
                i = element_unknowns(a, e)
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
        do e = 1, n_elements
            do a = 1, 6
                i = element_unknowns(a, e)
                if (i > 0) then
                    members(start(i) + count(i)) = e
                    count(i) = count(i) + 1
                end if
            end do
        end do

        ! Rows of each column: the unknowns of the elements touching it, deduplicated
        ! with a stamp and sorted (short lists: insertion sort).
        allocate(self%col_ptr(n + 1))
        allocate(stamp(n), source=0)
        allocate(rows(64))
        self%col_ptr(1) = 0
        allocate(self%row_index(0))
        block
            integer(ik), allocatable :: all_rows(:)
            integer :: capacity, used
            capacity = 27 * n + 16
            allocate(all_rows(capacity))
            used = 0
            do col = 1, n
                n_rows = 0
                do pos = start(col), start(col + 1) - 1
                    e = members(pos)
                    do a = 1, 6
                        i = element_unknowns(a, e)
                        if (i > 0 .and. stamp(i) /= col) then
                            stamp(i) = col
                            n_rows = n_rows + 1
                            if (n_rows > size(rows)) call grow(rows)
                            rows(n_rows) = i
                        end if
                    end do
                end do
                call insertion_sort(rows(1:n_rows))
                if (used + n_rows > capacity) then
                    capacity = max(2 * capacity, used + n_rows)
                    call grow_ik(all_rows, capacity)
                end if
                all_rows(used + 1:used + n_rows) = int(rows(1:n_rows) - 1, ik)
                used = used + n_rows
                self%col_ptr(col + 1) = used
            end do
            self%row_index = all_rows(1:used)
            self%nnz = used
        end block

        ! Slot of each element entry: search the row in its column.
        allocate(self%element_slot(6, 6, n_elements), source=0)
        do e = 1, n_elements
            do b = 1, 6
                j = element_unknowns(b, e)
                if (j == 0) cycle
                first = int(self%col_ptr(j)) + 1
                last = int(self%col_ptr(j + 1))
                do a = 1, 6
                    i = element_unknowns(a, e)
                    if (i == 0) cycle
                    self%element_slot(a, b, e) = find_row(self%row_index(first:last), i - 1) &
                        + first - 1
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
    end subroutine new_pattern

    pure subroutine insertion_sort(values)
        integer, intent(inout) :: values(:)
        integer :: i, j, v
        do i = 2, size(values)
            v = values(i)
            j = i - 1
            do while (j >= 1)
                if (values(j) <= v) exit
                values(j + 1) = values(j)
                j = j - 1
            end do
            values(j + 1) = v
        end do
    end subroutine insertion_sort

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
