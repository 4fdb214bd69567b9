! SPDX-License-Identifier: MIT
!> Checks of a read `config_type` before any network is built: each group's variables
!> (ranges, choices, law parameters, from their description), and what crosses them,
!> by concern: solver steps, materials and the path here; the network in
!> yarnfort_input_network_checks, contacts in yarnfort_input_contact_checks, numbers
!> the solver cannot compute with in yarnfort_input_magnitudes. Each message names the
!> group, the variable and the value.
module yarnfort_input_validate
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type, solver_config_type, output_config_type, &
        material_config_type, path_config_type
    use yarnfort_input_groups, only: check_control_variables, check_solver_variables, &
        check_material_variables, check_path_variables, check_output_variables
    use yarnfort_input_fields, only: check_item_name, group_label
    use yarnfort_input_magnitudes, only: check_scene_size, check_prescribed_reach
    use yarnfort_input_network_checks, only: check_nodes, check_yarns, &
        check_duplicate_segments, check_supports, check_loads, coincidence_tolerance
    use yarnfort_input_contact_checks, only: check_contacts
    use yarnfort_input_contact_node_checks, only: check_contact_nodes, check_contact_node_laws
    use yarnfort_input_channel_checks, only: check_channels
    use yarnfort_text, only: format_integer, format_real, format_short
    implicit none
    private

    public :: check_config, coincidence_tolerance

    !> Smallest &solver min_step as a fraction of the largest |&path time|: a shorter
    !> step would not (or barely) change the pseudo-time, and the continuation would stall.
    real(wp), parameter :: time_resolution = 100 * epsilon(1.0_wp)

contains

    !> Check everything that can be checked before the network is built.
    subroutine check_config(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        integer, allocatable :: owner(:, :)

        ! Each check runs only while all before it have passed.
        call check_control_variables(config%control, '&control', error)
        if (.not. allocated(error)) call check_solver(config%solver, error)
        if (.not. allocated(error)) call check_output(config%output, error)
        if (.not. allocated(error)) call check_materials(config%materials, error)
        if (.not. allocated(error)) call check_nodes(config, error)
        if (.not. allocated(error)) call check_scene_size(config, error)
        ! Before check_yarns, whose "node on no yarn" would hide a ring with no yarn.
        if (.not. allocated(error)) call check_contact_nodes(config, error)
        if (.not. allocated(error)) call check_yarns(config, error)
        if (.not. allocated(error)) call check_duplicate_segments(config, error)
        if (.not. allocated(error)) call check_contacts(config, error)
        if (.not. allocated(error)) call check_contact_node_laws(config, error)
        if (.not. allocated(error)) call check_supports(config, owner, error)
        if (.not. allocated(error)) call check_loads(config, owner, error)
        if (allocated(error)) return
        ! New nodes inside segments, sliding at contacts and generated fabrics are unknowns.
        if (all(owner > 0) .and. all(config%yarns%elements_per_segment == 1) &
            .and. size(config%contacts) == 0 .and. len_trim(config%fabric%kind) == 0) then
            call fatal_error(error, 'every coordinate of every node is prescribed by a ' &
                // '&support: the scene has no unknowns (nothing to solve)')
            return
        end if
        call check_path(config%path, error)
        if (.not. allocated(error)) call check_channels(config, error)
        if (.not. allocated(error)) call check_prescribed_reach(config, error)
        if (.not. allocated(error)) call check_step_resolution(config%solver, config%path, error)
    end subroutine check_config

    !> &solver: its variables, and min_step <= initial_step (larger ones are capped at
    !> max_step by the continuation), min_step <= max_step.
    subroutine check_solver(solver, error)
        type(solver_config_type), intent(in) :: solver
        type(error_type), allocatable, intent(out) :: error

        call check_solver_variables(solver, '&solver', error)
        if (allocated(error)) return
        if (solver%min_step > solver%max_step) then
            call fatal_error(error, '&solver: min_step = ' // format_real(solver%min_step) &
                // ' is larger than max_step = ' // format_real(solver%max_step))
        else if (solver%initial_step < solver%min_step) then
            call fatal_error(error, '&solver: initial_step = ' &
                // format_real(solver%initial_step) // ' is smaller than min_step = ' &
                // format_real(solver%min_step))
        end if
    end subroutine check_solver

    subroutine check_output(output, error)
        type(output_config_type), intent(in) :: output
        type(error_type), allocatable, intent(out) :: error

        if (len_trim(output%folder) == 0) then
            call fatal_error(error, "&output: folder = '' is empty (give a folder name)")
            return
        end if
        call check_output_variables(output, '&output', error)
    end subroutine check_output

    subroutine check_materials(materials, error)
        type(material_config_type), intent(in), allocatable :: materials(:)
        type(error_type), allocatable, intent(out) :: error
        character(len=24), allocatable :: labels(:)
        integer :: m
        logical :: none

        none = .not. allocated(materials)
        if (.not. none) none = size(materials) == 0
        if (none) then
            call fatal_error(error, 'no &material group: at least one material is needed')
            return
        end if
        labels = [character(len=24) :: (group_label('material', m), m = 1, size(materials))]
        do m = 1, size(materials)
            call check_item_name(error, materials%name, labels, m, '', 'defined', '')
            if (allocated(error)) return
            call check_material_variables(materials(m), "&material '" &
                // trim(materials(m)%name) // "'", error)
            if (allocated(error)) return
        end do
    end subroutine check_materials

    subroutine check_path(path, error)
        type(path_config_type), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        integer :: n, i, m

        if (.not. allocated(path%time)) then
            call fatal_error(error, '&path: group missing (give the load path, e.g. ' &
                // '&path time = 0, 1, p_disp = 0, 1 /)')
            return
        end if
        n = size(path%time)
        if (n < 2) then
            call fatal_error(error, '&path: time has ' // format_integer(n) &
                // ' knot(s); at least 2 are needed')
            return
        end if
        do i = 1, 2
            m = merge(size(path%p_force), size(path%p_disp), i == 1)
            if (m /= n) then
                call fatal_error(error, '&path: ' // trim(merge('p_force', 'p_disp ', i == 1)) &
                    // ' has ' // format_integer(m) // ' values but time has ' &
                    // format_integer(n))
                return
            end if
        end do
        call check_path_variables(path, '&path', error)
        if (allocated(error)) return
        do i = 2, n
            if (.not. (path%time(i) > path%time(i - 1))) then
                call fatal_error(error, '&path: time(' // format_integer(i) // ') = ' &
                    // format_real(path%time(i)) // ' is not greater than time(' &
                    // format_integer(i - 1) // ') = ' // format_real(path%time(i - 1)) &
                    // ' (time must be strictly increasing)')
                return
            end if
        end do
        if (.not. ieee_is_finite(path%time(n) - path%time(1))) then
            call fatal_error(error, '&path: time(' // format_integer(n) // ') - time(1) = ' &
                // format_real(path%time(n)) // ' - ' // format_real(path%time(1)) &
                // ' overflows: the path is too long to step through')
            return
        end if
    end subroutine check_path

    !> Every continuation step (at least min_step times the shortest knot interval) must
    !> advance the pseudo-time: it must not be below the floating-point resolution of the
    !> path's times.
    subroutine check_step_resolution(solver, path, error)
        type(solver_config_type), intent(in) :: solver
        type(path_config_type), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: largest, interval

        largest = maxval(abs(path%time))
        interval = minval(path%time(2:) - path%time(:size(path%time) - 1))
        if (solver%min_step * interval < time_resolution * largest) then
            call fatal_error(error, '&solver: min_step = ' // format_real(solver%min_step) &
                // ' is below the resolution of &path time (up to ' // format_real(largest) &
                // ' in magnitude, shortest knot interval ' // format_real(interval) &
                // '): a step shorter than ' // format_short(time_resolution * largest) &
                // ' would not advance the pseudo-time; raise min_step (a fraction of the ' &
                // 'knot interval) or move the path times closer to 0')
        end if
    end subroutine check_step_resolution

end module yarnfort_input_validate
