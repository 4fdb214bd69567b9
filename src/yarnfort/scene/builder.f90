! SPDX-License-Identifier: MIT
!> Build a scene (network, force laws, constraints, loads, load path) from the input.
!> Proxy module over scene/builder/: the force and friction laws (laws.f90), the
!> network and its reference lengths (network.f90), supports, obstacles and loads
!> (supports.f90), links of periodic images and gap-holders (links.f90), and the
!> passages at contact nodes (passages.f90); new_scene puts them together in order.
module yarnfort_scene_builder
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error, prefix_error
    use yarnfort_input_config, only: config_type, name_length
    use yarnfort_scene_scene, only: scene_type, lateral_channel_name, axial_channel_name
    use yarnfort_scene_channels, only: get_channel_names, get_channel_factors
    use yarnfort_scene_builder_laws, only: new_force_law, new_friction_law
    use yarnfort_scene_builder_network, only: build_network, apply_prestress, &
        apply_element_lengths
    use yarnfort_scene_builder_supports, only: build_constraints, build_loads
    use yarnfort_scene_builder_links, only: build_links
    use yarnfort_scene_builder_passages, only: build_passages
    implicit none
    private

    public :: new_scene, new_force_law, new_friction_law

contains

    !> Build `scene` from a checked `config`. Relative table paths are taken relative to
    !> the input file's folder (the working directory for standard input).
    subroutine new_scene(scene, config, error)
        type(scene_type), intent(out) :: scene
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer :: m

        scene%title = config%control%title
        scene%solver = config%solver
        scene%output = config%output
        allocate(scene%laws(size(config%materials)))
        do m = 1, size(config%materials)
            scene%laws(m)%name = config%materials(m)%name
            call new_force_law(scene%laws(m)%law, config%materials(m), error, &
                config%input_folder)
            if (allocated(error)) then
                call prefix_error(error, "&material '" // trim(config%materials(m)%name) // "'")
                return
            end if
        end do
        scene%path%channel = get_channel_names(config%path)
        ! A force-controlled x or y period of a periodic cell: e11 or e22 is the factor of
        ! a channel of its own (the path leaves it at 0; the outer iteration sets it).
        if (len_trim(config%fabric%kind) > 0 .and. config%fabric%boundary == 'periodic') then
            if (config%fabric%axial_control /= 'strain') then
                scene%axial_channel = size(scene%path%channel) + 1
                scene%axial_force = config%fabric%axial_force
            end if
            if (config%fabric%lateral_control /= 'strain') then
                scene%lateral_channel = size(scene%path%channel) + 1 &
                    + merge(1, 0, scene%axial_channel > 0)
                scene%lateral_control = config%fabric%lateral_control
                scene%lateral_force = config%fabric%lateral_force
                scene%force_ratio = config%fabric%force_ratio
            end if
        end if
        call append_control_channels()
        call build_network(scene, config, error)
        if (allocated(error)) return
        call apply_prestress(scene, config, error)
        if (allocated(error)) return
        call apply_element_lengths(scene, config)
        call build_constraints(scene, config, error)
        if (allocated(error)) return
        call build_links(scene, config, error)
        if (allocated(error)) return
        call build_loads(scene, config)
        call build_passages(scene, config, error)
        if (allocated(error)) return
        ! Something to solve: a free coordinate or a passage that slides (an input error
        ! here, before anything is written; yarnfort_input_validate finds the plain case).
        if (scene%dofs%n_unknowns == 0 .and. scene%passages%size() == 0) then
            call fatal_error(error, 'every coordinate of every node is prescribed (by ' &
                // '&support, &obstacle or the links of a generated fabric) and no yarn ' &
                // 'slides at a contact: the scene has no unknowns (nothing to solve)')
            return
        end if
        if (config%fabric_width > 0.0_wp) then
            scene%fabric_width = config%fabric_width
            scene%fabric_strain = config%fabric%strain
            if (config%fabric_support > 0) scene%fabric_set = config%fabric_support
            ! A periodic cell's periods are its longest lattice vectors along x and y
            ! (images lie one period away; a corner image both).
            scene%periodic_cell = config%fabric%boundary == 'periodic'
            if (scene%periodic_cell) then
                scene%cell_period = maxval(abs(scene%cell_lattice(1:2, :)), dim=2)
                scene%cell_strain = [config%fabric%strain, config%fabric%lateral_strain]
                scene%cell_shear = config%fabric%shear
            end if
        end if
        scene%path%time = config%path%time
        scene%path%channel = get_channel_names(config%path)
        scene%path%factor = get_channel_factors(config%path)
        call append_control_channels()
        scene%length_scale = sum(scene%network%length0) / size(scene%network%length0)
    contains
        !> The channels of force-controlled periods after the path's (axial, then
        !> lateral), with factor 0 at every knot where the path's factors are set.
        subroutine append_control_channels()
            real(wp), allocatable :: factor(:, :)
            integer :: n

            n = size(scene%path%channel)
            if (scene%axial_channel > 0) scene%path%channel = &
                [character(len=name_length) :: scene%path%channel, axial_channel_name]
            if (scene%lateral_channel > 0) scene%path%channel = &
                [character(len=name_length) :: scene%path%channel, lateral_channel_name]
            if (.not. allocated(scene%path%factor)) return
            if (size(scene%path%channel) == n) return
            allocate(factor(size(scene%path%time), size(scene%path%channel)), source=0.0_wp)
            factor(:, :n) = scene%path%factor
            call move_alloc(factor, scene%path%factor)
        end subroutine append_control_channels
    end subroutine new_scene

end module yarnfort_scene_builder
