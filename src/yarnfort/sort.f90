! SPDX-License-Identifier: MIT
!> The order that sorts a short list (insertion sort: stable, no work space beyond the
!> order itself), or a list of names of any length (merge sort).
module yarnfort_sort
    use yarnfort_kinds, only: wp
    implicit none
    private

    public :: sort_index, sort_text_index

    !> Indices that sort `values` ascending, equal values in their order.
    interface sort_index
        module procedure sort_index_real
        module procedure sort_index_integer
    end interface sort_index

contains

    pure function sort_index_real(values) result(order)
        real(wp), intent(in) :: values(:)
        integer :: order(size(values)), i, j, item

        order = [(i, i = 1, size(values))]
        do i = 2, size(values)
            item = order(i)
            j = i - 1
            do while (j >= 1)
                if (values(order(j)) <= values(item)) exit
                order(j + 1) = order(j)
                j = j - 1
            end do
            order(j + 1) = item
        end do
    end function sort_index_real

    !> (Integers of up to 53 bits are exact in real(wp).)
    pure function sort_index_integer(values) result(order)
        integer, intent(in) :: values(:)
        integer :: order(size(values))

        order = sort_index_real(real(values, wp))
    end function sort_index_integer

    !> Indices that sort `values` ascending (character order), equal values in their
    !> order: a merge sort, n log n comparisons for lists of any length.
    pure function sort_text_index(values) result(order)
        character(len=*), intent(in) :: values(:)
        integer :: order(size(values)), work(size(values))
        integer :: width, first, middle, last, i, j, k, n

        n = size(values)
        order = [(i, i = 1, n)]
        width = 1
        do while (width < n)
            do first = 1, n, 2 * width
                middle = min(first + width, n + 1)
                last = min(first + 2 * width, n + 1)
                i = first
                j = middle
                do k = first, last - 1
                    ! From the left run on ties: stable.
                    if (i < middle .and. (j >= last)) then
                        work(k) = order(i)
                        i = i + 1
                    else if (i < middle) then
                        if (values(order(i)) <= values(order(j))) then
                            work(k) = order(i)
                            i = i + 1
                        else
                            work(k) = order(j)
                            j = j + 1
                        end if
                    else
                        work(k) = order(j)
                        j = j + 1
                    end if
                end do
            end do
            order = work
            width = 2 * width
        end do
    end function sort_text_index

end module yarnfort_sort
