! SPDX-License-Identifier: MIT
!> The order that sorts a short list (insertion sort: stable, no work space beyond the
!> order itself).
module yarnfort_sort
    use yarnfort_kinds, only: wp
    implicit none
    private

    public :: sort_index

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

end module yarnfort_sort
