! SPDX-License-Identifier: MIT
!> Passages: a yarn passing through a contact node (a node it shares with another yarn
!> or with another pass of itself). Each passage has one flow variable s: the reference
!> length moved from the yarn segment before the node to the segment after it (paper
!> eq. 22). A segment is the run of elements between two listed nodes of a yarn (split
!> by elements_per_segment); material moves along it freely, so each of its elements
!> takes its initial share of the change:
!>     L0(e) = L0_initial(e) + share(e) * (s(passage at the segment's start)
!>                                         - s(passage at the segment's end)),
!> share(e) = L0_initial(e) / (segment's initial length). Every yarn's total reference
!> length is conserved exactly, and a segment shortens evenly rather than draining the
!> one element next to the node.
module yarnfort_contact_passages
    use yarnfort_kinds, only: wp
    use yarnfort_friction_law, only: friction_law_type
    implicit none
    private

    public :: passage_set_type, friction_holder_type, is_at_minimum_length

    !> One pair-of-yarn-types friction law.
    type :: friction_holder_type
        class(friction_law_type), allocatable :: law
    end type friction_holder_type

    type :: passage_set_type
        !> Yarn, contact node, element before and after the node (along the yarn), and
        !> the friction law (index into the scene's friction laws) of each passage.
        integer, allocatable :: yarn(:), node(:), element_before(:), element_after(:)
        integer, allocatable :: law(:)
        !> Passage at the start and at the end of each element's segment (0: none), and
        !> the element's share of its segment's initial reference length.
        integer, allocatable :: at_start(:), at_end(:)
        real(wp), allocatable :: share(:)
    contains
        procedure :: size => get_size
        !> Current reference lengths from initial ones and the flows.
        procedure :: get_length0
    end type passage_set_type

contains

    !> A reference length `length0` (initial length `initial`, share `share` of its
    !> segment) is at its minimum, `min_ratio` times `initial`: within rounding, and
    !> within the solve's accuracy of the flows that set it (`flow_accuracy`, a stick
    !> row's tolerance: residual_tolerance * length_scale). A lock's flow is solved to
    !> that; an element left that much above its minimum must not slide on towards it.
    pure logical function is_at_minimum_length(length0, initial, share, min_ratio, &
            flow_accuracy)
        real(wp), intent(in) :: length0, initial, share, min_ratio, flow_accuracy
        !> Round-off of a reference length locked at its minimum, relative to its initial
        !> length (the lock sets L0 = initial length - flow to the minimum).
        real(wp), parameter :: length_round_off = 64 * epsilon(1.0_wp)
        is_at_minimum_length = length0 <= min_ratio * initial &
            + max(length_round_off * initial, flow_accuracy * share)
    end function is_at_minimum_length

    pure integer function get_size(self)
        class(passage_set_type), intent(in) :: self
        get_size = 0
        if (allocated(self%node)) get_size = size(self%node)
    end function get_size

    pure subroutine get_length0(self, initial, flow, length0)
        class(passage_set_type), intent(in) :: self
        real(wp), intent(in) :: initial(:), flow(:)
        real(wp), intent(out) :: length0(:)
        integer :: e

        length0 = initial
        if (self%size() == 0) return
        do e = 1, size(initial)
            if (self%at_start(e) > 0) length0(e) = length0(e) + self%share(e) &
                * flow(self%at_start(e))
            if (self%at_end(e) > 0) length0(e) = length0(e) - self%share(e) &
                * flow(self%at_end(e))
        end do
    end subroutine get_length0

end module yarnfort_contact_passages
