! SPDX-License-Identifier: MIT
!> Reading the namelist input into a `config_type`. Groups may come in any order; each
!> is read by the reader generated from its description (yarnfort_input_groups, from
!> variables.py). Singletons may appear at most once, repeatable groups once per item.
!> The tokenizer (yarnfort_input_scan) rejects unknown group names, text outside groups,
!> unclosed groups and entries set twice; the readers convert and store the values.
!>
!> Reading checks form only (names, types, list lengths); `check_config` (re-exported
!> here from yarnfort_input_validate) checks meaning.
module yarnfort_input_namelist
    use, intrinsic :: iso_fortran_env, only: input_unit
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type
    use yarnfort_input_groups, only: group_names, singleton_names, nodes_config_type, &
        read_control_groups, read_solver_groups, read_material_groups, read_contact_groups, &
        read_fabric_groups, read_nodes_groups, read_geometry_groups, read_yarn_groups, &
        read_support_groups, read_load_groups, read_path_groups, read_output_groups, &
        read_obstacle_groups, read_ring_groups, fabric_kind_choices
    use yarnfort_input_fields, only: max_list, max_coordinates
    use yarnfort_input_scan, only: namelist_scan_type, scan_namelist
    use yarnfort_input_geometry_file, only: read_geometry_file
    use yarnfort_text, only: format_integer, folder_of, resolve_path, open_to_read, join_names
    use yarnfort_input_validate, only: check_config
    implicit none
    private

    public :: read_config, read_config_from_file, read_config_from_stdin, check_config
    public :: max_list, max_coordinates, group_names

    !> Groups a generated fabric replaces.
    character(len=*), parameter :: generated_names(*) = [character(len=8) :: 'nodes', &
        'geometry', 'yarn', 'support', 'load', 'obstacle', 'ring']

contains

    !> Read all groups from an open formatted sequential unit (from its start, unless it
    !> is standard input). Relative file names in the input are resolved against `folder`
    !> (default: working directory).
    subroutine read_config(unit, config, error, folder)
        integer, intent(in) :: unit
        type(config_type), intent(out) :: config
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in), optional :: folder
        type(namelist_scan_type) :: scan
        character(len=:), allocatable :: name
        integer :: k

        if (present(folder)) then
            if (len_trim(folder) > len(config%input_folder)) then
                call fatal_error(error, "input folder '" // trim(folder) &
                    // "' is longer than " // format_integer(len(config%input_folder)) &
                    // ' characters')
                return
            end if
            config%input_folder = folder
        end if
        if (unit /= input_unit) rewind(unit)
        call scan_namelist(unit, merge('standard input, line ', 'input line           ', &
            unit == input_unit), group_names, scan, error)
        if (unit /= input_unit) rewind(unit)
        if (allocated(error)) return
        if (unit == input_unit .and. size(scan%lines) == 0) then
            ! A folder or a closed standard input reads as an empty one in gfortran.
            call fatal_error(error, 'standard input is empty: no input was given (is it ' &
                // 'closed or a folder?); run as: yarnfort < scene.nml')
            return
        end if
        do k = 1, size(singleton_names)
            name = trim(singleton_names(k))
            if (scan%count_group(name) > 1) then
                call fatal_error(error, '&' // name // ' appears more than once (lines ' &
                    // format_integer(scan%groups(scan%find_group(name, 1))%first_line) &
                    // ' and ' &
                    // format_integer(scan%groups(scan%find_group(name, 2))%first_line) &
                    // '); it may appear at most once')
                return
            end if
        end do

        call read_groups(scan, config, error)
        if (allocated(error)) return

        if (len_trim(config%geometry%file) > 0) then
            do k = 1, 2
                name = trim(merge('nodes', 'yarn ', k == 1))
                if (scan%count_group(name) > 0) then
                    call fatal_error(error, '&' // name // ': not allowed together with ' &
                        // "&geometry file = '" // trim(config%geometry%file) &
                        // "' (the file gives the " // trim(merge('nodes', 'yarns', k == 1)) &
                        // ')')
                    return
                end if
            end do
            call read_geometry_file(resolve_path(config%geometry%file, config%input_folder), &
                config%node_positions, config%yarns, error, config%geometry%unit)
            if (allocated(error)) return
        else if (len_trim(config%geometry%unit) > 0) then
            call fatal_error(error, "&geometry: unit = '" // trim(config%geometry%unit) &
                // "' is set but no file (it is the unit of the geometry file)")
            return
        end if
        if (len_trim(config%fabric%kind) > 0) then
            do k = 1, size(generated_names)
                name = trim(generated_names(k))
                if (scan%count_group(name) > 0) then
                    call fatal_error(error, '&' // name // ': not allowed together with ' &
                        // '&fabric (the fabric generator makes the nodes, yarns and supports)')
                    return
                end if
            end do
        end if
        if (.not. allocated(config%links)) allocate(config%links(0))
    end subroutine read_config

    !> Each group, in a fixed order, with what is not one variable's business: the
    !> fabric kind and the node triplets; then the defaults of lists.
    subroutine read_groups(scan, config, error)
        type(namelist_scan_type), intent(in) :: scan
        type(config_type), intent(inout) :: config
        type(error_type), allocatable, intent(out) :: error
        type(nodes_config_type) :: nodes
        integer :: n

        ! Each group is read only while all before it were read without error.
        call read_control_groups(scan, config%control, error)
        if (.not. allocated(error)) call read_solver_groups(scan, config%solver, error)
        if (.not. allocated(error)) call read_material_groups(scan, config%materials, error)
        if (.not. allocated(error)) call read_contact_groups(scan, config%contacts, error)
        if (.not. allocated(error)) call read_fabric_groups(scan, config%fabric, error)
        if (allocated(error)) return
        if (scan%count_group('fabric') > 0 .and. len_trim(config%fabric%kind) == 0) then
            call post_read_error(error, scan, 'fabric', 'kind is required (' &
                // join_names(fabric_kind_choices, '', ' or ') // ')')
            return
        end if
        call read_nodes_groups(scan, nodes, error)
        if (allocated(error)) return
        if (allocated(nodes%xyz)) then
            n = size(nodes%xyz)
            if (mod(n, 3) /= 0) then
                call post_read_error(error, scan, 'nodes', 'xyz has ' // format_integer(n) &
                    // ' values, not a multiple of 3 (x, y, z of each node)')
                return
            end if
            config%node_positions = reshape(nodes%xyz, [3, n / 3])
        end if
        call read_geometry_groups(scan, config%geometry, error)
        if (.not. allocated(error)) call read_yarn_groups(scan, config%yarns, error)
        if (.not. allocated(error)) call read_support_groups(scan, config%supports, error)
        if (.not. allocated(error)) call read_load_groups(scan, config%loads, error)
        if (.not. allocated(error)) call read_path_groups(scan, config%path, error)
        if (.not. allocated(error)) call read_output_groups(scan, config%output, error)
        if (.not. allocated(error)) call read_obstacle_groups(scan, config%obstacles, error)
        if (.not. allocated(error)) call read_ring_groups(scan, config%rings, error)
        if (allocated(error)) return
        if (.not. allocated(config%fabric%gap_factor)) allocate(config%fabric%gap_factor(0))
        if (.not. allocated(config%fabric%gap_factor_p_disp)) &
            allocate(config%fabric%gap_factor_p_disp(0))
        ! An omitted p_force or p_disp is all zeros.
        if (allocated(config%path%time)) then
            n = size(config%path%time)
            if (size(config%path%p_force) == 0) config%path%p_force = spread(0.0_wp, 1, n)
            if (size(config%path%p_disp) == 0) config%path%p_disp = spread(0.0_wp, 1, n)
        end if
    end subroutine read_groups

    !> An error of singleton group `name` found after reading it, with the group's line.
    subroutine post_read_error(error, scan, name, text)
        type(error_type), allocatable, intent(out) :: error
        type(namelist_scan_type), intent(in) :: scan
        character(len=*), intent(in) :: name, text

        call fatal_error(error, '&' // name // ': ' // text // ' (group on line ' &
            // format_integer(scan%groups(scan%find_group(name, 1))%first_line) // ')')
    end subroutine post_read_error

    !> Read the namelist input from the file `path`; relative file names in it are
    !> resolved against the folder of `path`, or with `from_working_directory` against
    !> the working directory (as for standard input).
    subroutine read_config_from_file(path, config, error, from_working_directory)
        character(len=*), intent(in) :: path
        type(config_type), intent(out) :: config
        type(error_type), allocatable, intent(out) :: error
        logical, intent(in), optional :: from_working_directory
        character(len=:), allocatable :: folder
        integer :: unit

        call open_to_read(path, "input file '" // path // "'", unit, error)
        if (allocated(error)) return
        ! '' is the working directory.
        folder = folder_of(path)
        if (present(from_working_directory)) then
            if (from_working_directory) folder = ''
        end if
        call read_config(unit, config, error, folder)
        close(unit)
    end subroutine read_config_from_file

    !> Read the namelist input from standard input (read whole first, so that groups can
    !> be read in any order); relative file names in it are resolved against the working
    !> directory.
    subroutine read_config_from_stdin(config, error)
        type(config_type), intent(out) :: config
        type(error_type), allocatable, intent(out) :: error

        call read_config(input_unit, config, error)
    end subroutine read_config_from_stdin

end module yarnfort_input_namelist
