! SPDX-License-Identifier: MIT
!> The string network: nodes, two-node truss elements and the yarns they form.
module yarnfort_network_network
    use yarnfort_kinds, only: wp
    implicit none
    private

    public :: network_type

    !> Nodes and elements of a yarn network. The elements of yarn y are
    !> yarn_first_element(y) .. yarn_first_element(y+1)-1, in order along the yarn, and
    !> consecutive elements of a yarn share a node.
    type :: network_type
        !> Initial node positions, (3, n_nodes).
        real(wp), allocatable :: position(:, :)
        !> Node ids of each element, (2, n_elements); node 2 of element e is node 1 of e+1
        !> inside a yarn.
        integer, allocatable :: element_nodes(:, :)
        !> Reference (undeformed) length L0 of each element.
        real(wp), allocatable :: length0(:)
        !> Yarn type (index of its force law) of each element.
        integer, allocatable :: element_material(:)
        !> Offsets of each yarn's elements, (n_yarns + 1).
        integer, allocatable :: yarn_first_element(:)
    contains
        procedure :: n_nodes => get_n_nodes
        procedure :: n_elements => get_n_elements
        procedure :: n_yarns => get_n_yarns
    end type network_type

contains

    pure integer function get_n_nodes(self)
        class(network_type), intent(in) :: self
        get_n_nodes = size(self%position, 2)
    end function get_n_nodes

    pure integer function get_n_elements(self)
        class(network_type), intent(in) :: self
        get_n_elements = size(self%element_nodes, 2)
    end function get_n_elements

    pure integer function get_n_yarns(self)
        class(network_type), intent(in) :: self
        get_n_yarns = size(self%yarn_first_element) - 1
    end function get_n_yarns

end module yarnfort_network_network
