! SPDX-License-Identifier: MIT
!> A scene: everything a run needs, built from the input (see yarnfort_scene_builder).
module yarnfort_scene_scene
    use yarnfort_kinds, only: wp
    use yarnfort_material_law, only: force_law_type
    use yarnfort_network_network, only: network_type
    use yarnfort_network_dof_map, only: dof_map_type
    use yarnfort_contact_passages, only: passage_set_type, friction_holder_type
    use yarnfort_input_config, only: solver_config_type, output_config_type, name_length
    implicit none
    private

    public :: scene_type, law_holder_type, support_set_type, load_path_type

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
    end type support_set_type

    !> Load path knots: load factors over pseudo-time, linear in between.
    type :: load_path_type
        real(wp), allocatable :: time(:), p_force(:), p_disp(:)
    contains
        procedure :: get_factors
    end type load_path_type

    type :: scene_type
        character(len=256) :: title = ''
        type(network_type) :: network
        type(law_holder_type), allocatable :: laws(:)
        type(dof_map_type) :: dofs
        !> External nodal forces at p_force = 1, (3 * n_nodes).
        real(wp), allocatable :: external_force(:)
        type(support_set_type), allocatable :: supports(:)
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
        !> x force, the macroscopic strain at p_disp = 1, and the set of `supports` whose
        !> x reaction is that force (fabric_set = 0: not a fabric).
        real(wp) :: fabric_width = 0.0_wp
        real(wp) :: fabric_strain = 0.0_wp
        integer :: fabric_set = 0
        !> Links (gap-holders and periodic images), for the output: (leader, follower)
        !> node pairs (2, n_links), and whether each is a gap-holder.
        integer, allocatable :: link_nodes(:, :)
        logical, allocatable :: link_is_gap(:)
    end type scene_type

contains

    !> Load factors at pseudo-time t (clamped to the path's ends).
    pure subroutine get_factors(self, t, p_force, p_disp)
        class(load_path_type), intent(in) :: self
        real(wp), intent(in) :: t
        real(wp), intent(out) :: p_force, p_disp
        integer :: i, n
        real(wp) :: w

        n = size(self%time)
        if (t <= self%time(1)) then
            p_force = self%p_force(1)
            p_disp = self%p_disp(1)
            return
        end if
        if (t >= self%time(n)) then
            p_force = self%p_force(n)
            p_disp = self%p_disp(n)
            return
        end if
        do i = 1, n - 1
            if (t <= self%time(i + 1)) exit
        end do
        w = (t - self%time(i)) / (self%time(i + 1) - self%time(i))
        p_force = (1.0_wp - w) * self%p_force(i) + w * self%p_force(i + 1)
        p_disp = (1.0_wp - w) * self%p_disp(i) + w * self%p_disp(i + 1)
    end subroutine get_factors

end module yarnfort_scene_scene
