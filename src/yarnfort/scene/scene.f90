! SPDX-License-Identifier: MIT
!> A scene: everything a run needs, built from the input (see yarnfort_scene_builder).
module yarnfort_scene_scene
    use yarnfort_kinds, only: wp
    use yarnfort_material_force_law, only: force_law_type
    use yarnfort_network_network, only: network_type
    use yarnfort_network_dof_map, only: dof_map_type
    use yarnfort_contact_passages, only: passage_set_type, friction_holder_type
    use yarnfort_input_config, only: solver_config_type, output_config_type, name_length
    implicit none
    private

    public :: scene_type, law_holder_type, support_set_type, load_set_type, load_path_type
    public :: get_applied_force, get_loaded_nodes, get_force_scale, lateral_channel_name
    public :: axial_channel_name, get_fabric_strain

    !> The channels of a force-controlled x and y period (their factors, and columns,
    !> are e11 and e22).
    character(len=*), parameter :: axial_channel_name = 'axial'
    character(len=*), parameter :: lateral_channel_name = 'lateral'

    !> One yarn type's force law.
    type :: law_holder_type
        character(len=name_length) :: name = ''
        class(force_law_type), allocatable :: law
    end type law_holder_type

    !> A named set of prescribed coordinates; its reaction is reported per step.
    type :: support_set_type
        character(len=name_length) :: name = ''
        !> Coordinates 3*(node-1)+k of the set.
        integer, allocatable :: coordinates(:)
        !> Coordinates that follow coordinates(follows(j)) (images of a periodic cell,
        !> gap-holders): prescribed with it, their forces add to its reaction.
        integer, allocatable :: followers(:), follows(:)
    end type support_set_type

    !> The nodes of one &load group (their mean displacement is reported per step).
    type :: load_set_type
        integer, allocatable :: nodes(:)
    end type load_set_type

    !> Load path knots: the factor of every load channel over pseudo-time, linear in
    !> between. Without &path channels the channels are 'p_force' (every &load) and
    !> 'p_disp' (every &support).
    type :: load_path_type
        real(wp), allocatable :: time(:)
        !> Channel names, and the factor of each at each knot (n_knots, n_channels).
        character(len=name_length), allocatable :: channel(:)
        real(wp), allocatable :: factor(:, :)
    contains
        procedure :: get_factors
        procedure :: n_channels
    end type load_path_type

    type :: scene_type
        character(len=256) :: title = ''
        type(network_type) :: network
        type(law_holder_type), allocatable :: laws(:)
        type(dof_map_type) :: dofs
        !> External nodal forces at factor 1 of each load channel, (3 * n_nodes, n_channels):
        !> the applied force is sum_c factor_c(t) * external_force(:, c).
        real(wp), allocatable :: external_force(:, :)
        type(support_set_type), allocatable :: supports(:)
        type(load_set_type), allocatable :: loads(:)
        type(load_path_type) :: path
        !> Sliding contact: passages and the friction laws they use (none: no sliding).
        type(passage_set_type) :: passages
        type(friction_holder_type), allocatable :: friction(:)
        type(solver_config_type) :: solver
        type(output_config_type) :: output
        !> Length scale of the solver's unknowns (mean element length). Forces are
        !> judged against the forces present (yarnfort_assembly_scales), never against a
        !> material stiffness.
        real(wp) :: length_scale = 1.0_wp
        !> Generated fabrics (&fabric): the width (m) across which the fabric carries its
        !> x force, the macroscopic strain at p_disp = 1 (channel 2), and the set of
        !> `supports` whose x reaction is that force (fabric_set = 0: not a fabric).
        real(wp) :: fabric_width = 0.0_wp
        real(wp) :: fabric_strain = 0.0_wp
        integer :: fabric_set = 0
        !> Links (gap-holders and periodic images), for the output: (leader, follower)
        !> node pairs (2, n_links), and whether each is a gap-holder.
        integer, allocatable :: link_nodes(:, :)
        logical, allocatable :: link_is_gap(:)
        !> The lattice vector each link spans at p_disp = 0 (3, n_links): a periodic link's
        !> initial offset, a gap-holder's period (zero inside the cell); at factor p of
        !> dofs%gap_channel it is link_period * (1 + p * link_strain), componentwise.
        real(wp), allocatable :: link_period(:, :), link_strain(:, :)
        !> A periodic cell (&fabric boundary = 'periodic'): each node's lattice vector at
        !> p_disp = 0 (3, n_nodes; zero for a node that follows no periodic image), the
        !> reference periods along x and y (m), their engineering strains and the simple
        !> shear at p_disp = 1. A node's position is its root's plus lattice * (1 + p_disp *
        !> cell_strain), componentwise, plus p_disp * cell_shear * lattice_y along x
        !> (yarnfort_output_membrane).
        logical :: periodic_cell = .false.
        real(wp), allocatable :: cell_lattice(:, :)
        real(wp) :: cell_period(2) = 0.0_wp, cell_strain(2) = 0.0_wp, cell_shear = 0.0_wp
        !> A periodic cell whose y period follows a force (&fabric lateral_control 'force'
        !> or 'ratio'): the load channel (appended to the path's, factor 0 at every knot)
        !> whose factor is e22, set by yarnfort_solver_force_control; 0 otherwise. The
        !> n22 held, or the ratio n22 / n11 held.
        integer :: lateral_channel = 0
        character(len=16) :: lateral_control = 'strain'
        real(wp) :: lateral_force = 0.0_wp, force_ratio = 0.0_wp
        !> A periodic cell whose x period follows a force (&fabric axial_control 'force'):
        !> the load channel (appended to the path's before the lateral one, factor 0 at
        !> every knot) whose factor is e11, set by yarnfort_solver_force_control; 0
        !> otherwise. n11 is held at p_disp * axial_force.
        integer :: axial_channel = 0
        real(wp) :: axial_force = 0.0_wp
    end type scene_type

contains

    !> Factors of every channel at pseudo-time t (clamped to the path's ends).
    pure subroutine get_factors(self, t, factors)
        class(load_path_type), intent(in) :: self
        real(wp), intent(in) :: t
        real(wp), intent(out) :: factors(:)
        integer :: i, n
        real(wp) :: w

        n = size(self%time)
        if (t <= self%time(1)) then
            factors = self%factor(1, :)
            return
        end if
        if (t >= self%time(n)) then
            factors = self%factor(n, :)
            return
        end if
        do i = 1, n - 1
            if (t <= self%time(i + 1)) exit
        end do
        w = (t - self%time(i)) / (self%time(i + 1) - self%time(i))
        factors = (1.0_wp - w) * self%factor(i, :) + w * self%factor(i + 1, :)
    end subroutine get_factors

    !> The applied nodal forces (3 * n_nodes) at the channels' factors.
    pure subroutine get_applied_force(scene, factors, force)
        type(scene_type), intent(in) :: scene
        real(wp), intent(in) :: factors(:)
        real(wp), intent(out) :: force(:)
        integer :: c

        force = 0.0_wp
        do c = 1, size(scene%external_force, 2)
            force = force + factors(c) * scene%external_force(:, c)
        end do
    end subroutine get_applied_force

    !> An upper bound of the applied force's magnitude at a node: the sum over channels of
    !> |factor| * magnitude (the magnitudes of the channels' forces at the node; with one
    !> loaded channel, exactly its magnitude).
    pure real(wp) function get_force_scale(factors, magnitude) result(scale)
        real(wp), intent(in) :: factors(:), magnitude(:)
        integer :: c

        scale = 0.0_wp
        do c = 1, size(magnitude)
            scale = scale + abs(factors(c)) * magnitude(c)
        end do
    end function get_force_scale

    !> The nodes where some channel applies a force, and each channel's magnitude there
    !> (n_channels, n_loaded). Elsewhere get_force_scale is 0 at any factors, so a
    !> caller that asks at every iterate (the row levels) need only visit these.
    pure subroutine get_loaded_nodes(scene, nodes, magnitude)
        type(scene_type), intent(in) :: scene
        integer, allocatable, intent(out) :: nodes(:)
        real(wp), allocatable, intent(out) :: magnitude(:, :)
        integer :: n, c

        nodes = pack([(n, n = 1, size(scene%external_force, 1) / 3)], &
            [(any(scene%external_force(3 * n - 2:3 * n, :) /= 0.0_wp), &
            n = 1, size(scene%external_force, 1) / 3)])
        allocate(magnitude(size(scene%external_force, 2), size(nodes)))
        do n = 1, size(nodes)
            do c = 1, size(scene%external_force, 2)
                magnitude(c, n) = norm2(scene%external_force(3 * nodes(n) - 2:3 * nodes(n), c))
            end do
        end do
    end subroutine get_loaded_nodes

    !> The fabric's x strain at load `factors`: p_disp * strain, or the e11 found under
    !> axial force control.
    pure real(wp) function get_fabric_strain(scene, factors) result(strain)
        type(scene_type), intent(in) :: scene
        real(wp), intent(in) :: factors(:)

        if (scene%axial_channel > 0) then
            strain = factors(scene%axial_channel)
        else
            ! A fabric has the two default channels: p_disp is channel 2.
            strain = factors(2) * scene%fabric_strain
        end if
    end function get_fabric_strain

    pure integer function n_channels(self)
        class(load_path_type), intent(in) :: self
        n_channels = 0
        if (allocated(self%factor)) n_channels = size(self%factor, 2)
    end function n_channels

end module yarnfort_scene_scene
