! SPDX-License-Identifier: MIT
!> Passages: a yarn passing through a contact node (a node it shares with another yarn
!> or with another pass of itself). Each passage has one flow variable s: the reference
!> length moved from the element before the node to the element after it (paper eq. 22),
!>     L0(e) = L0_initial(e) + s(passage at the start of e) - s(passage at the end of e),
!> so every yarn's total reference length is conserved exactly.
module yarnfort_contact_passages
    use yarnfort_kinds, only: wp
    use yarnfort_friction_law, only: friction_law_type
    implicit none
    private

    public :: passage_set_type, friction_holder_type

    !> One pair-of-yarn-types friction law.
    type :: friction_holder_type
        class(friction_law_type), allocatable :: law
    end type friction_holder_type

    type :: passage_set_type
        !> Yarn, contact node, element before and after the node (along the yarn), and
        !> the friction law (index into the scene's friction laws) of each passage.
        integer, allocatable :: yarn(:), node(:), element_before(:), element_after(:)
        integer, allocatable :: law(:)
        !> Passage at the start and at the end of each element (0: none).
        integer, allocatable :: at_start(:), at_end(:)
    contains
        procedure :: size => get_size
        !> Current reference lengths from initial ones and the flows.
        procedure :: get_length0
    end type passage_set_type

contains

    pure integer function get_size(self)
        class(passage_set_type), intent(in) :: self
        get_size = 0
        if (allocated(self%node)) get_size = size(self%node)
    end function get_size

    pure subroutine get_length0(self, initial, flow, length0)
        class(passage_set_type), intent(in) :: self
        real(wp), intent(in) :: initial(:), flow(:)
        real(wp), intent(out) :: length0(:)
        integer :: p

        length0 = initial
        do p = 1, self%size()
            length0(self%element_before(p)) = length0(self%element_before(p)) - flow(p)
            length0(self%element_after(p)) = length0(self%element_after(p)) + flow(p)
        end do
    end subroutine get_length0

end module yarnfort_contact_passages
