! SPDX-License-Identifier: MIT
!> A growing list of nodes, yarns, supports and links that the fabric generators fill
!> and then hand over to the input configuration, as if the user had listed them.
module yarnfort_generate_net_builder
    use yarnfort_kinds, only: wp
    use yarnfort_input_config, only: config_type, yarn_config_type, support_config_type, &
        link_config_type
    implicit none
    private

    public :: net_builder_type

    type :: net_builder_type
        integer :: n_nodes = 0
        real(wp), allocatable :: position(:, :)
        type(yarn_config_type), allocatable :: yarns(:)
        type(support_config_type), allocatable :: supports(:)
        integer :: n_links = 0
        type(link_config_type), allocatable :: links(:)
    contains
        procedure :: add_node
        procedure :: add_yarn
        procedure :: add_support
        procedure :: add_link
        !> Move everything into the configuration (nodes, yarns, supports, links).
        procedure :: hand_over
    end type net_builder_type

contains

    !> A new node at x; returns its id.
    integer function add_node(self, x) result(id)
        class(net_builder_type), intent(inout) :: self
        real(wp), intent(in) :: x(3)
        real(wp), allocatable :: grown(:, :)

        if (.not. allocated(self%position)) allocate(self%position(3, 256))
        if (self%n_nodes == size(self%position, 2)) then
            allocate(grown(3, 2 * size(self%position, 2)))
            grown(:, 1:self%n_nodes) = self%position(:, 1:self%n_nodes)
            call move_alloc(grown, self%position)
        end if
        self%n_nodes = self%n_nodes + 1
        id = self%n_nodes
        self%position(:, id) = x
    end function add_node

    subroutine add_yarn(self, material, nodes, elements_per_segment)
        class(net_builder_type), intent(inout) :: self
        character(len=*), intent(in) :: material
        integer, intent(in) :: nodes(:), elements_per_segment
        type(yarn_config_type) :: yarn

        if (.not. allocated(self%yarns)) allocate(self%yarns(0))
        yarn%material = material
        yarn%nodes = nodes
        yarn%elements_per_segment = elements_per_segment
        self%yarns = [self%yarns, yarn]
    end subroutine add_yarn

    subroutine add_support(self, name, nodes, fix, displacement)
        class(net_builder_type), intent(inout) :: self
        character(len=*), intent(in) :: name, fix
        integer, intent(in) :: nodes(:)
        real(wp), intent(in) :: displacement(3)
        type(support_config_type) :: support

        if (.not. allocated(self%supports)) allocate(self%supports(0))
        support%name = name
        support%nodes = nodes
        support%fix = fix
        support%displacement = displacement
        self%supports = [self%supports, support]
    end subroutine add_support

    !> Node `follower` follows `leader`: a periodic image (strain: macroscopic strain at
    !> p_disp = 1) or a gap-holder partner (gap = .true.); a gap-holder between a node
    !> and a periodic image of its partner also takes the lattice vector `period`;
    !> `bonded`: the two nodes are sewn together, not one contact.
    subroutine add_link(self, follower, leader, strain, gap, period, bonded)
        class(net_builder_type), intent(inout) :: self
        integer, intent(in) :: follower, leader
        real(wp), intent(in) :: strain(3)
        logical, intent(in) :: gap
        real(wp), intent(in), optional :: period(3)
        logical, intent(in), optional :: bonded
        type(link_config_type), allocatable :: grown(:)

        if (.not. allocated(self%links)) allocate(self%links(64))
        if (self%n_links == size(self%links)) then
            allocate(grown(2 * size(self%links)))
            grown(1:self%n_links) = self%links(1:self%n_links)
            call move_alloc(grown, self%links)
        end if
        self%n_links = self%n_links + 1
        self%links(self%n_links)%follower = follower
        self%links(self%n_links)%leader = leader
        self%links(self%n_links)%strain = strain
        self%links(self%n_links)%gap = gap
        self%links(self%n_links)%period = 0.0_wp
        if (present(period)) self%links(self%n_links)%period = period
        self%links(self%n_links)%bonded = .false.
        if (present(bonded)) self%links(self%n_links)%bonded = bonded
    end subroutine add_link

    subroutine hand_over(self, config)
        class(net_builder_type), intent(inout) :: self
        type(config_type), intent(inout) :: config

        config%node_positions = self%position(:, 1:self%n_nodes)
        if (.not. allocated(self%yarns)) allocate(self%yarns(0))
        if (.not. allocated(self%supports)) allocate(self%supports(0))
        call move_alloc(self%yarns, config%yarns)
        call move_alloc(self%supports, config%supports)
        if (allocated(config%links)) deallocate(config%links)
        if (allocated(self%links)) then
            config%links = self%links(1:self%n_links)
        else
            allocate(config%links(0))
        end if
    end subroutine hand_over

end module yarnfort_generate_net_builder
