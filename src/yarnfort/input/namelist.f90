! SPDX-License-Identifier: MIT
!> Reading the namelist input into a `config_type`. Groups may come in any order; each
!> is read by its own `read_<group>` with a local namelist whose variables start from
!> the defaults of the config types. Singletons (&control, &solver, &nodes, &geometry,
!> &path, &output) may appear at most once; &material, &contact, &yarn, &support and
!> &load once per item. A structural scan of the text first rejects unknown group names, text
!> outside groups, unclosed groups and variables set twice (see yarnfort_input_scan);
!> the namelist reads then run on a scratch copy of the text without its comments.
!> Lists are read into buffers of `max_list` (+1 guard) entries prefilled with a marker:
!> the count is the last set entry, a set guard is an overflow, an unset entry before
!> the last set one is an empty value.
!>
!> Reading checks form only (names, types, list lengths); `check_config` (re-exported
!> here from yarnfort_input_validate) checks meaning.
module yarnfort_input_namelist
    use, intrinsic :: iso_fortran_env, only: input_unit
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type, control_config_type, solver_config_type, &
        material_config_type, yarn_config_type, support_config_type, load_config_type, &
        output_config_type, geometry_config_type, contact_config_type, path_length, &
        fabric_config_type, get_solver_preset
    use yarnfort_input_scan, only: namelist_scan_type, scan_namelist, explain_read_error
    use yarnfort_input_geometry, only: read_geometry_file
    use yarnfort_input_text, only: read_line, to_lower, format_integer, folder_of, &
        resolve_path
    use yarnfort_input_validate, only: check_config
    use yarnfort_generate_fabric, only: generate_fabric
    implicit none
    private

    public :: read_config, read_config_from_file, read_config_from_stdin, check_config
    public :: max_list, max_coordinates, group_names

    !> Most node ids in one &yarn, &support or &load group, and most knots in &path.
    integer, parameter :: max_list = 100000
    !> Most values of &nodes xyz (3 per node); larger scenes use &geometry.
    integer, parameter :: max_coordinates = 3 * max_list

    !> All group names, in the order they are read and echoed.
    character(len=*), parameter :: group_names(*) = [character(len=8) :: 'control', &
        'solver', 'material', 'contact', 'fabric', 'nodes', 'geometry', 'yarn', 'support', &
        'load', 'path', 'output']
    !> Groups that may appear at most once.
    character(len=*), parameter :: singleton_names(*) = [character(len=8) :: 'control', &
        'solver', 'fabric', 'nodes', 'geometry', 'path', 'output']
    !> Groups a generated fabric replaces.
    character(len=*), parameter :: generated_names(*) = [character(len=8) :: 'nodes', &
        'geometry', 'yarn', 'support', 'load']

    !> Marks list entries the input did not set.
    integer, parameter :: unset_integer = -huge(1)
    real(wp), parameter :: unset_real = -huge(1.0_wp)
    !> Marks a character variable the input did not set (&solver: preset defaults).
    character(len=*), parameter :: unset_character = achar(0)
    !> Length of the character buffers the namelists read into (longer than any config
    !> field, so that a value too long for its field is detected, not cut).
    integer, parameter :: buffer_length = 4 * path_length
    integer, parameter :: message_length = 512

contains

    !> Read all groups from an open, rewindable formatted sequential unit. Relative file
    !> names in the input are resolved against `folder` (default: working directory).
    subroutine read_config(unit, config, error, folder)
        integer, intent(in) :: unit
        type(config_type), intent(out) :: config
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in), optional :: folder
        type(namelist_scan_type) :: scan
        character(len=:), allocatable :: name
        character(len=message_length) :: message
        integer :: k, text, stat

        if (present(folder)) then
            if (len_trim(folder) > len(config%input_folder)) then
                call fatal_error(error, "input folder '" // trim(folder) &
                    // "' is longer than " // format_integer(len(config%input_folder)) &
                    // ' characters')
                return
            end if
            config%input_folder = folder
        end if
        call scan_namelist(unit, group_names, scan, error)
        if (allocated(error)) return
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

        open(newunit=text, status='scratch', action='readwrite', form='formatted', &
            access='sequential', iostat=stat, iomsg=message)
        if (stat /= 0) then
            call fatal_error(error, 'cannot open a scratch file for the input: ' // trim(message))
            return
        end if
        call scan%write_without_comments(text, error)
        if (.not. allocated(error)) call read_groups(text, scan, config, error)
        close(text)
        rewind(unit)
        if (allocated(error)) return

        if (len_trim(config%geometry%file) > 0) then
            if (scan%count_group('nodes') > 0) then
                call fatal_error(error, '&nodes: not allowed together with &geometry file = ' &
                    // "'" // trim(config%geometry%file) // "' (the file gives the nodes)")
                return
            end if
            if (scan%count_group('yarn') > 0) then
                call fatal_error(error, '&yarn: not allowed together with &geometry file = ' &
                    // "'" // trim(config%geometry%file) // "' (the file gives the yarns)")
                return
            end if
            call read_geometry_file(resolve_path(config%geometry%file, config%input_folder), &
                config%node_positions, config%yarns, error)
            if (allocated(error)) return
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
            call generate_fabric(config, error)
            if (allocated(error)) return
        end if
        if (.not. allocated(config%links)) allocate(config%links(0))
    end subroutine read_config

    !> Each group from the comment-free text, in a fixed order.
    subroutine read_groups(unit, scan, config, error)
        integer, intent(in) :: unit
        type(namelist_scan_type), intent(in) :: scan
        type(config_type), intent(inout) :: config
        type(error_type), allocatable, intent(out) :: error

        call read_control(unit, scan, config, error)
        if (allocated(error)) return
        call read_solver(unit, scan, config, error)
        if (allocated(error)) return
        call read_material(unit, scan, config, error)
        if (allocated(error)) return
        call read_contact(unit, scan, config, error)
        if (allocated(error)) return
        call read_fabric(unit, scan, config, error)
        if (allocated(error)) return
        call read_nodes(unit, scan, config, error)
        if (allocated(error)) return
        call read_geometry(unit, scan, config, error)
        if (allocated(error)) return
        call read_yarn(unit, scan, config, error)
        if (allocated(error)) return
        call read_support(unit, scan, config, error)
        if (allocated(error)) return
        call read_load(unit, scan, config, error)
        if (allocated(error)) return
        call read_path(unit, scan, config, error)
        if (allocated(error)) return
        call read_output(unit, scan, config, error)
    end subroutine read_groups

    !> Read the namelist input from the file `path`; relative file names in it are
    !> resolved against the folder of `path`.
    subroutine read_config_from_file(path, config, error)
        character(len=*), intent(in) :: path
        type(config_type), intent(out) :: config
        type(error_type), allocatable, intent(out) :: error
        character(len=message_length) :: message
        integer :: unit, stat

        open(newunit=unit, file=path, status='old', action='read', form='formatted', &
            access='sequential', iostat=stat, iomsg=message)
        if (stat /= 0) then
            call fatal_error(error, "cannot open input file '" // path // "': " // trim(message))
            return
        end if
        call read_config(unit, config, error, folder_of(path))
        close(unit)
    end subroutine read_config_from_file

    !> Read the namelist input from standard input (copied to a scratch file first, so
    !> that groups can be read in any order); relative file names in it are resolved
    !> against the working directory.
    subroutine read_config_from_stdin(config, error)
        type(config_type), intent(out) :: config
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: line
        character(len=message_length) :: message
        integer :: scratch, stat, line_number

        open(newunit=scratch, status='scratch', action='readwrite', form='formatted', &
            access='sequential', iostat=stat, iomsg=message)
        if (stat /= 0) then
            call fatal_error(error, 'cannot open a scratch file for the input: ' // trim(message))
            return
        end if
        line_number = 0
        do
            call read_line(input_unit, line, stat, message)
            if (is_iostat_end(stat)) exit
            if (stat /= 0) then
                call fatal_error(error, 'standard input, line ' &
                    // format_integer(line_number + 1) // ': ' // trim(message))
                close(scratch)
                return
            end if
            line_number = line_number + 1
            write(scratch, '(a)', iostat=stat, iomsg=message) line
            if (stat /= 0) then
                call fatal_error(error, 'cannot copy the input to a scratch file: ' &
                    // trim(message))
                close(scratch)
                return
            end if
        end do
        call read_config(scratch, config, error)
        close(scratch)
    end subroutine read_config_from_stdin

    !> &control: title, check_only, restart, max_steps.
    subroutine read_control(unit, scan, cfg, error)
        integer, intent(in) :: unit
        type(namelist_scan_type), intent(in) :: scan
        type(config_type), intent(inout) :: cfg
        type(error_type), allocatable, intent(out) :: error
        type(control_config_type) :: defaults
        character(len=buffer_length) :: title
        logical :: check_only, restart
        integer :: max_steps
        namelist /control/ title, check_only, restart, max_steps
        character(len=message_length) :: message
        integer :: stat

        if (scan%count_group('control') == 0) return
        title = defaults%title
        check_only = defaults%check_only
        restart = defaults%restart
        max_steps = defaults%max_steps
        rewind(unit)
        message = ''
        read(unit, nml=control, iostat=stat, iomsg=message)
        if (stat /= 0) then
            call read_failed(error, scan, 'control', 0, stat, message, &
                [character(len=16) :: 'title', 'check_only', 'restart', 'max_steps'])
            return
        end if
        call check_length(error, scan, 'control', 0, 'title', title, len(cfg%control%title))
        if (allocated(error)) return
        cfg%control%title = title(:len(cfg%control%title))
        cfg%control%check_only = check_only
        cfg%control%restart = restart
        cfg%control%max_steps = max_steps
    end subroutine read_control

    !> &solver: linear solver, Newton, continuation and friction settings. The variables a
    !> preset sets start unset; those the input leaves unset take the preset's values.
    subroutine read_solver(unit, scan, cfg, error)
        integer, intent(in) :: unit
        type(namelist_scan_type), intent(in) :: scan
        type(config_type), intent(inout) :: cfg
        type(error_type), allocatable, intent(out) :: error
        type(solver_config_type) :: defaults, preset_defaults
        character(len=buffer_length) :: linear_solver, scheme, preset
        real(wp) :: residual_tolerance, step_tolerance, slack_stiffness, initial_step, &
            min_step, max_step, step_growth, step_cut, min_length_ratio, friction_tolerance
        integer :: max_iterations, max_setup_calls, easy_iterations, max_step_cuts, &
            max_friction_iterations
        logical :: line_search
        namelist /solver/ linear_solver, residual_tolerance, step_tolerance, max_iterations, &
            max_setup_calls, line_search, slack_stiffness, initial_step, min_step, max_step, &
            step_growth, step_cut, easy_iterations, max_step_cuts, scheme, &
            max_friction_iterations, min_length_ratio, friction_tolerance, preset
        character(len=message_length) :: message
        integer :: stat
        logical :: known_preset

        if (scan%count_group('solver') == 0) return
        preset = defaults%preset
        linear_solver = defaults%linear_solver
        residual_tolerance = unset_real
        step_tolerance = defaults%step_tolerance
        max_iterations = defaults%max_iterations
        max_setup_calls = defaults%max_setup_calls
        line_search = defaults%line_search
        slack_stiffness = defaults%slack_stiffness
        initial_step = unset_real
        min_step = defaults%min_step
        max_step = unset_real
        step_growth = defaults%step_growth
        step_cut = defaults%step_cut
        easy_iterations = defaults%easy_iterations
        max_step_cuts = defaults%max_step_cuts
        scheme = unset_character
        max_friction_iterations = defaults%max_friction_iterations
        min_length_ratio = defaults%min_length_ratio
        friction_tolerance = defaults%friction_tolerance
        rewind(unit)
        message = ''
        read(unit, nml=solver, iostat=stat, iomsg=message)
        if (stat /= 0) then
            call read_failed(error, scan, 'solver', 0, stat, message, &
                [character(len=24) :: 'linear_solver', 'residual_tolerance', &
                'step_tolerance', 'max_iterations', 'max_setup_calls', 'line_search', &
                'slack_stiffness', 'initial_step', 'min_step', 'max_step', 'step_growth', &
                'step_cut', 'easy_iterations', 'max_step_cuts', 'scheme', &
                'max_friction_iterations', 'min_length_ratio', 'friction_tolerance', &
                'preset'])
            return
        end if
        call check_length(error, scan, 'solver', 0, 'preset', adjustl(preset), &
            len(cfg%solver%preset))
        if (allocated(error)) return
        ! An unknown preset gives the plain defaults here; check_config rejects its name.
        preset = to_lower(adjustl(preset))
        call get_solver_preset(trim(preset), preset_defaults, known_preset)
        if (residual_tolerance == unset_real) &
            residual_tolerance = preset_defaults%residual_tolerance
        if (initial_step == unset_real) initial_step = preset_defaults%initial_step
        if (max_step == unset_real) max_step = preset_defaults%max_step
        if (scheme == unset_character) scheme = preset_defaults%scheme
        cfg%solver%preset = preset_defaults%preset
        call check_length(error, scan, 'solver', 0, 'linear_solver', linear_solver, &
            len(cfg%solver%linear_solver))
        if (allocated(error)) return
        call check_length(error, scan, 'solver', 0, 'scheme', adjustl(scheme), &
            len(cfg%solver%scheme))
        if (allocated(error)) return
        linear_solver = to_lower(adjustl(linear_solver))
        cfg%solver%linear_solver = linear_solver(:len(cfg%solver%linear_solver))
        cfg%solver%residual_tolerance = residual_tolerance
        cfg%solver%step_tolerance = step_tolerance
        cfg%solver%max_iterations = max_iterations
        cfg%solver%max_setup_calls = max_setup_calls
        cfg%solver%line_search = line_search
        cfg%solver%slack_stiffness = slack_stiffness
        cfg%solver%initial_step = initial_step
        cfg%solver%min_step = min_step
        cfg%solver%max_step = max_step
        cfg%solver%step_growth = step_growth
        cfg%solver%step_cut = step_cut
        cfg%solver%easy_iterations = easy_iterations
        cfg%solver%max_step_cuts = max_step_cuts
        scheme = to_lower(adjustl(scheme))
        cfg%solver%scheme = scheme(:len(cfg%solver%scheme))
        cfg%solver%max_friction_iterations = max_friction_iterations
        cfg%solver%min_length_ratio = min_length_ratio
        cfg%solver%friction_tolerance = friction_tolerance
    end subroutine read_solver

    !> &material, once per yarn type.
    subroutine read_material(unit, scan, cfg, error)
        integer, intent(in) :: unit
        type(namelist_scan_type), intent(in) :: scan
        type(config_type), intent(inout) :: cfg
        type(error_type), allocatable, intent(out) :: error
        type(material_config_type) :: defaults
        character(len=buffer_length) :: name, law, table_file
        real(wp) :: stiffness, modulus, area, prestress
        namelist /material/ name, law, stiffness, modulus, area, table_file, prestress
        character(len=message_length) :: message
        integer :: stat, k, n_expected

        n_expected = scan%count_group('material')
        allocate(cfg%materials(n_expected))
        rewind(unit)
        k = 0
        do
            name = defaults%name
            law = defaults%law
            stiffness = defaults%stiffness
            modulus = defaults%modulus
            area = defaults%area
            table_file = defaults%table_file
            prestress = defaults%prestress
            message = ''
            read(unit, nml=material, iostat=stat, iomsg=message)
            if (is_iostat_end(stat)) exit
            k = k + 1
            if (k > n_expected) then
                call too_many_found(error, 'material', n_expected)
                return
            end if
            if (stat /= 0) then
                call read_failed(error, scan, 'material', k, stat, message, &
                    [character(len=16) :: 'name', 'law', 'stiffness', 'modulus', 'area', &
                    'table_file', 'prestress'])
                return
            end if
            associate(material => cfg%materials(k))
                call check_length(error, scan, 'material', k, 'name', adjustl(name), &
                    len(material%name))
                if (allocated(error)) return
                call check_length(error, scan, 'material', k, 'law', adjustl(law), &
                    len(material%law))
                if (allocated(error)) return
                call check_length(error, scan, 'material', k, 'table_file', table_file, &
                    len(material%table_file))
                if (allocated(error)) return
                name = adjustl(name)
                material%name = name(:len(material%name))
                law = to_lower(adjustl(law))
                material%law = law(:len(material%law))
                material%stiffness = stiffness
                material%modulus = modulus
                material%area = area
                material%table_file = table_file(:len(material%table_file))
                material%prestress = prestress
            end associate
        end do
        if (k < n_expected) then
            call read_failed(error, scan, 'material', k + 1, stat, message, [character :: ])
        end if
    end subroutine read_material

    !> &contact, once per pair of yarn types that touch.
    subroutine read_contact(unit, scan, cfg, error)
        integer, intent(in) :: unit
        type(namelist_scan_type), intent(in) :: scan
        type(config_type), intent(inout) :: cfg
        type(error_type), allocatable, intent(out) :: error
        type(contact_config_type) :: defaults
        character(len=buffer_length) :: materials(2), law
        real(wp) :: friction_coefficient, adhesion, decay_start, decay_end
        namelist /contact/ materials, law, friction_coefficient, adhesion, decay_start, &
            decay_end
        character(len=message_length) :: message
        integer :: stat, k, i, n_expected

        n_expected = scan%count_group('contact')
        allocate(cfg%contacts(n_expected))
        rewind(unit)
        k = 0
        do
            materials = defaults%materials
            law = defaults%law
            friction_coefficient = defaults%friction_coefficient
            adhesion = defaults%adhesion
            decay_start = defaults%decay_start
            decay_end = defaults%decay_end
            message = ''
            read(unit, nml=contact, iostat=stat, iomsg=message)
            if (is_iostat_end(stat)) exit
            k = k + 1
            if (k > n_expected) then
                call too_many_found(error, 'contact', n_expected)
                return
            end if
            if (stat /= 0) then
                call read_failed(error, scan, 'contact', k, stat, message, &
                    [character(len=24) :: 'materials', 'law', 'friction_coefficient', &
                    'adhesion', 'decay_start', 'decay_end'])
                return
            end if
            associate(contact => cfg%contacts(k))
                do i = 1, size(materials)
                    call check_length(error, scan, 'contact', k, 'materials(' &
                        // format_integer(i) // ')', adjustl(materials(i)), &
                        len(contact%materials(i)))
                    if (allocated(error)) return
                end do
                call check_length(error, scan, 'contact', k, 'law', adjustl(law), &
                    len(contact%law))
                if (allocated(error)) return
                do i = 1, size(materials)
                    materials(i) = adjustl(materials(i))
                    contact%materials(i) = materials(i)(:len(contact%materials(i)))
                end do
                law = to_lower(adjustl(law))
                contact%law = law(:len(contact%law))
                contact%friction_coefficient = friction_coefficient
                contact%adhesion = adhesion
                contact%decay_start = decay_start
                contact%decay_end = decay_end
            end associate
        end do
        if (k < n_expected) then
            call read_failed(error, scan, 'contact', k + 1, stat, message, [character :: ])
        end if
    end subroutine read_contact

    !> &nodes: xyz = x1, y1, z1, x2, ... (node ids 1..n in this order).
    subroutine read_nodes(unit, scan, cfg, error)
        integer, intent(in) :: unit
        type(namelist_scan_type), intent(in) :: scan
        type(config_type), intent(inout) :: cfg
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: xyz(:)
        namelist /nodes/ xyz
        character(len=message_length) :: message
        integer :: stat, n

        if (scan%count_group('nodes') == 0) return
        allocate(xyz(max_coordinates + 1))
        xyz = unset_real
        rewind(unit)
        message = ''
        read(unit, nml=nodes, iostat=stat, iomsg=message)
        if (stat /= 0) then
            call read_failed(error, scan, 'nodes', 0, stat, message, [character(len=8) :: 'xyz'])
            return
        end if
        call get_real_list_length(error, scan, 'nodes', 0, 'xyz', xyz, n)
        if (allocated(error)) return
        if (mod(n, 3) /= 0) then
            call post_read_error(error, scan, 'nodes', 0, 'xyz has ' // format_integer(n) &
                // ' values, not a multiple of 3 (x, y, z of each node)')
            return
        end if
        cfg%node_positions = reshape(xyz(:n), [3, n / 3])
    end subroutine read_nodes

    !> &geometry: file.
    subroutine read_geometry(unit, scan, cfg, error)
        integer, intent(in) :: unit
        type(namelist_scan_type), intent(in) :: scan
        type(config_type), intent(inout) :: cfg
        type(error_type), allocatable, intent(out) :: error
        type(geometry_config_type) :: defaults
        character(len=buffer_length) :: file
        namelist /geometry/ file
        character(len=message_length) :: message
        integer :: stat

        if (scan%count_group('geometry') == 0) return
        file = defaults%file
        rewind(unit)
        message = ''
        read(unit, nml=geometry, iostat=stat, iomsg=message)
        if (stat /= 0) then
            call read_failed(error, scan, 'geometry', 0, stat, message, &
                [character(len=8) :: 'file'])
            return
        end if
        call check_length(error, scan, 'geometry', 0, 'file', file, len(cfg%geometry%file))
        if (allocated(error)) return
        cfg%geometry%file = file(:len(cfg%geometry%file))
    end subroutine read_geometry

    !> &yarn, once per yarn.
    subroutine read_yarn(unit, scan, cfg, error)
        integer, intent(in) :: unit
        type(namelist_scan_type), intent(in) :: scan
        type(config_type), intent(inout) :: cfg
        type(error_type), allocatable, intent(out) :: error
        type(yarn_config_type) :: defaults
        character(len=buffer_length) :: material
        integer, allocatable :: nodes(:)
        integer :: elements_per_segment
        namelist /yarn/ material, nodes, elements_per_segment
        character(len=message_length) :: message
        integer :: stat, k, n, n_expected

        n_expected = scan%count_group('yarn')
        allocate(cfg%yarns(n_expected))
        allocate(nodes(max_list + 1))
        rewind(unit)
        k = 0
        do
            material = defaults%material
            nodes = unset_integer
            elements_per_segment = defaults%elements_per_segment
            message = ''
            read(unit, nml=yarn, iostat=stat, iomsg=message)
            if (is_iostat_end(stat)) exit
            k = k + 1
            if (k > n_expected) then
                call too_many_found(error, 'yarn', n_expected)
                return
            end if
            if (stat /= 0) then
                call read_failed(error, scan, 'yarn', k, stat, message, &
                    [character(len=24) :: 'material', 'nodes', 'elements_per_segment'])
                return
            end if
            call check_length(error, scan, 'yarn', k, 'material', adjustl(material), &
                len(cfg%yarns(k)%material))
            if (allocated(error)) return
            call get_integer_list_length(error, scan, 'yarn', k, 'nodes', nodes, n)
            if (allocated(error)) return
            material = adjustl(material)
            cfg%yarns(k)%material = material(:len(cfg%yarns(k)%material))
            cfg%yarns(k)%nodes = nodes(:n)
            cfg%yarns(k)%elements_per_segment = elements_per_segment
        end do
        if (k < n_expected) then
            call read_failed(error, scan, 'yarn', k + 1, stat, message, [character :: ])
        end if
    end subroutine read_yarn

    !> &support, once per set of prescribed nodes.
    subroutine read_support(unit, scan, cfg, error)
        integer, intent(in) :: unit
        type(namelist_scan_type), intent(in) :: scan
        type(config_type), intent(inout) :: cfg
        type(error_type), allocatable, intent(out) :: error
        type(support_config_type) :: defaults
        character(len=buffer_length) :: name, fix
        integer, allocatable :: nodes(:)
        real(wp) :: displacement(3)
        namelist /support/ name, nodes, fix, displacement
        character(len=message_length) :: message
        integer :: stat, k, n, n_expected

        n_expected = scan%count_group('support')
        allocate(cfg%supports(n_expected))
        allocate(nodes(max_list + 1))
        rewind(unit)
        k = 0
        do
            name = defaults%name
            nodes = unset_integer
            fix = defaults%fix
            displacement = defaults%displacement
            message = ''
            read(unit, nml=support, iostat=stat, iomsg=message)
            if (is_iostat_end(stat)) exit
            k = k + 1
            if (k > n_expected) then
                call too_many_found(error, 'support', n_expected)
                return
            end if
            if (stat /= 0) then
                call read_failed(error, scan, 'support', k, stat, message, &
                    [character(len=16) :: 'name', 'nodes', 'fix', 'displacement'])
                return
            end if
            call check_length(error, scan, 'support', k, 'name', adjustl(name), &
                len(cfg%supports(k)%name))
            if (allocated(error)) return
            call check_length(error, scan, 'support', k, 'fix', adjustl(fix), &
                len(cfg%supports(k)%fix))
            if (allocated(error)) return
            call get_integer_list_length(error, scan, 'support', k, 'nodes', nodes, n)
            if (allocated(error)) return
            name = adjustl(name)
            cfg%supports(k)%name = name(:len(cfg%supports(k)%name))
            cfg%supports(k)%nodes = nodes(:n)
            fix = to_lower(adjustl(fix))
            cfg%supports(k)%fix = fix(:len(cfg%supports(k)%fix))
            cfg%supports(k)%displacement = displacement
        end do
        if (k < n_expected) then
            call read_failed(error, scan, 'support', k + 1, stat, message, [character :: ])
        end if
    end subroutine read_support

    !> &load, once per set of loaded nodes.
    subroutine read_load(unit, scan, cfg, error)
        integer, intent(in) :: unit
        type(namelist_scan_type), intent(in) :: scan
        type(config_type), intent(inout) :: cfg
        type(error_type), allocatable, intent(out) :: error
        type(load_config_type) :: defaults
        integer, allocatable :: nodes(:)
        real(wp) :: force(3)
        namelist /load/ nodes, force
        character(len=message_length) :: message
        integer :: stat, k, n, n_expected

        n_expected = scan%count_group('load')
        allocate(cfg%loads(n_expected))
        allocate(nodes(max_list + 1))
        rewind(unit)
        k = 0
        do
            nodes = unset_integer
            force = defaults%force
            message = ''
            read(unit, nml=load, iostat=stat, iomsg=message)
            if (is_iostat_end(stat)) exit
            k = k + 1
            if (k > n_expected) then
                call too_many_found(error, 'load', n_expected)
                return
            end if
            if (stat /= 0) then
                call read_failed(error, scan, 'load', k, stat, message, &
                    [character(len=8) :: 'nodes', 'force'])
                return
            end if
            call get_integer_list_length(error, scan, 'load', k, 'nodes', nodes, n)
            if (allocated(error)) return
            cfg%loads(k)%nodes = nodes(:n)
            cfg%loads(k)%force = force
        end do
        if (k < n_expected) then
            call read_failed(error, scan, 'load', k + 1, stat, message, [character :: ])
        end if
    end subroutine read_load

    !> &path: knots time, p_force, p_disp; an omitted p_force or p_disp is all zeros.
    subroutine read_path(unit, scan, cfg, error)
        integer, intent(in) :: unit
        type(namelist_scan_type), intent(in) :: scan
        type(config_type), intent(inout) :: cfg
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable :: time(:), p_force(:), p_disp(:)
        namelist /path/ time, p_force, p_disp
        character(len=message_length) :: message
        integer :: stat, n_time, n_force, n_disp

        if (scan%count_group('path') == 0) return
        allocate(time(max_list + 1), p_force(max_list + 1), p_disp(max_list + 1))
        time = unset_real
        p_force = unset_real
        p_disp = unset_real
        rewind(unit)
        message = ''
        read(unit, nml=path, iostat=stat, iomsg=message)
        if (stat /= 0) then
            call read_failed(error, scan, 'path', 0, stat, message, &
                [character(len=8) :: 'time', 'p_force', 'p_disp'])
            return
        end if
        call get_real_list_length(error, scan, 'path', 0, 'time', time, n_time)
        if (allocated(error)) return
        call get_real_list_length(error, scan, 'path', 0, 'p_force', p_force, n_force)
        if (allocated(error)) return
        call get_real_list_length(error, scan, 'path', 0, 'p_disp', p_disp, n_disp)
        if (allocated(error)) return
        cfg%path%time = time(:n_time)
        if (n_force == 0) then
            allocate(cfg%path%p_force(n_time), source=0.0_wp)
        else
            cfg%path%p_force = p_force(:n_force)
        end if
        if (n_disp == 0) then
            allocate(cfg%path%p_disp(n_time), source=0.0_wp)
        else
            cfg%path%p_disp = p_disp(:n_disp)
        end if
    end subroutine read_path

    !> &fabric: a generated knitted or woven fabric (see yarnfort_generate_fabric).
    subroutine read_fabric(unit, scan, cfg, error)
        integer, intent(in) :: unit
        type(namelist_scan_type), intent(in) :: scan
        type(config_type), intent(inout) :: cfg
        type(error_type), allocatable, intent(out) :: error
        type(fabric_config_type) :: defaults
        character(len=buffer_length) :: kind, boundary, sides, knit_material, inlay_material, &
            warp_material, weft_material
        integer :: cells(2), elements_per_segment, inlay_every, n_p, n_f
        real(wp) :: spacing(2), strain, lateral_strain, head_width, inlay_offset, gap
        real(wp), allocatable :: gap_factor_p_disp(:), gap_factor(:)
        namelist /fabric/ kind, cells, spacing, boundary, strain, lateral_strain, sides, &
            elements_per_segment, knit_material, inlay_material, head_width, inlay_offset, &
            inlay_every, warp_material, weft_material, gap, &
            gap_factor_p_disp, gap_factor
        character(len=message_length) :: message
        integer :: stat

        allocate(cfg%fabric%gap_factor_p_disp(0), cfg%fabric%gap_factor(0))
        if (scan%count_group('fabric') == 0) return
        kind = defaults%kind
        cells = defaults%cells
        spacing = defaults%spacing
        boundary = defaults%boundary
        strain = defaults%strain
        lateral_strain = defaults%lateral_strain
        sides = defaults%sides
        elements_per_segment = defaults%elements_per_segment
        knit_material = defaults%knit_material
        inlay_material = defaults%inlay_material
        head_width = defaults%head_width
        inlay_offset = defaults%inlay_offset
        inlay_every = defaults%inlay_every
        warp_material = defaults%warp_material
        weft_material = defaults%weft_material
        gap = defaults%gap
        allocate(gap_factor_p_disp(max_list + 1), gap_factor(max_list + 1))
        gap_factor_p_disp = unset_real
        gap_factor = unset_real
        rewind(unit)
        message = ''
        read(unit, nml=fabric, iostat=stat, iomsg=message)
        if (stat /= 0) then
            call read_failed(error, scan, 'fabric', 0, stat, message, &
                [character(len=20) :: 'kind', 'cells', 'spacing', 'boundary', 'strain', &
                'lateral_strain', 'sides', 'elements_per_segment', 'knit_material', &
                'inlay_material', 'head_width', 'inlay_offset', 'inlay_every', &
                'warp_material', 'weft_material', 'gap', 'gap_factor_p_disp', 'gap_factor'])
            return
        end if
        call get_real_list_length(error, scan, 'fabric', 0, 'gap_factor_p_disp', &
            gap_factor_p_disp, n_p)
        if (allocated(error)) return
        call get_real_list_length(error, scan, 'fabric', 0, 'gap_factor', gap_factor, n_f)
        if (allocated(error)) return
        call take_name(kind, 'kind', cfg%fabric%kind, .true.)
        if (allocated(error)) return
        call take_name(boundary, 'boundary', cfg%fabric%boundary, .true.)
        if (allocated(error)) return
        call take_name(sides, 'sides', cfg%fabric%sides, .true.)
        if (allocated(error)) return
        call take_name(knit_material, 'knit_material', cfg%fabric%knit_material, .false.)
        if (allocated(error)) return
        call take_name(inlay_material, 'inlay_material', cfg%fabric%inlay_material, .false.)
        if (allocated(error)) return
        call take_name(warp_material, 'warp_material', cfg%fabric%warp_material, .false.)
        if (allocated(error)) return
        call take_name(weft_material, 'weft_material', cfg%fabric%weft_material, .false.)
        if (allocated(error)) return
        if (len_trim(cfg%fabric%kind) == 0) then
            call post_read_error(error, scan, 'fabric', 0, &
                "kind is required (knit, plain or twill)")
            return
        end if
        cfg%fabric%cells = cells
        cfg%fabric%spacing = spacing
        cfg%fabric%strain = strain
        cfg%fabric%lateral_strain = lateral_strain
        cfg%fabric%elements_per_segment = elements_per_segment
        cfg%fabric%head_width = head_width
        cfg%fabric%inlay_offset = inlay_offset
        cfg%fabric%inlay_every = inlay_every
        cfg%fabric%gap = gap
        cfg%fabric%gap_factor_p_disp = gap_factor_p_disp(:n_p)
        cfg%fabric%gap_factor = gap_factor(:n_f)
    contains
        subroutine take_name(buffer, variable, field, lower)
            character(len=*), intent(inout) :: buffer
            character(len=*), intent(in) :: variable
            character(len=*), intent(out) :: field
            logical, intent(in) :: lower
            call check_length(error, scan, 'fabric', 0, variable, adjustl(buffer), len(field))
            if (allocated(error)) return
            buffer = adjustl(buffer)
            if (lower) buffer = to_lower(buffer)
            field = buffer(:len(field))
        end subroutine take_name
    end subroutine read_fabric

    !> &output: folder, vtk_every, vtk_format, progress, residual_history.
    subroutine read_output(unit, scan, cfg, error)
        integer, intent(in) :: unit
        type(namelist_scan_type), intent(in) :: scan
        type(config_type), intent(inout) :: cfg
        type(error_type), allocatable, intent(out) :: error
        type(output_config_type) :: defaults
        character(len=buffer_length) :: folder
        integer :: vtk_every
        character(len=buffer_length) :: vtk_format
        logical :: progress, residual_history
        namelist /output/ folder, vtk_every, vtk_format, progress, residual_history
        character(len=message_length) :: message
        integer :: stat

        if (scan%count_group('output') == 0) return
        folder = defaults%folder
        vtk_every = defaults%vtk_every
        vtk_format = defaults%vtk_format
        progress = defaults%progress
        residual_history = defaults%residual_history
        rewind(unit)
        message = ''
        read(unit, nml=output, iostat=stat, iomsg=message)
        if (stat /= 0) then
            call read_failed(error, scan, 'output', 0, stat, message, &
                [character(len=16) :: 'folder', 'vtk_every', 'vtk_format', 'progress', &
                'residual_history'])
            return
        end if
        call check_length(error, scan, 'output', 0, 'folder', folder, len(cfg%output%folder))
        if (allocated(error)) return
        cfg%output%folder = folder(:len(cfg%output%folder))
        call check_length(error, scan, 'output', 0, 'vtk_format', vtk_format, &
            len(cfg%output%vtk_format))
        if (allocated(error)) return
        cfg%output%vtk_format = vtk_format(:len(cfg%output%vtk_format))
        cfg%output%vtk_every = vtk_every
        cfg%output%progress = progress
        cfg%output%residual_history = residual_history
    end subroutine read_output

    !> '&name' for a singleton (occurrence 0), '&name #k' for the k-th of a repeatable.
    pure function group_label(name, occurrence) result(label)
        character(len=*), intent(in) :: name
        integer, intent(in) :: occurrence
        character(len=:), allocatable :: label

        label = '&' // name
        if (occurrence > 0) label = label // ' #' // format_integer(occurrence)
    end function group_label

    !> Turn a failed namelist READ into an error naming the group, with the reader's
    !> message and where possible the variable, the line and a suggestion.
    subroutine read_failed(error, scan, name, occurrence, stat, message, variables)
        type(error_type), allocatable, intent(out) :: error
        type(namelist_scan_type), intent(in) :: scan
        character(len=*), intent(in) :: name
        integer, intent(in) :: occurrence, stat
        character(len=*), intent(in) :: message
        character(len=*), intent(in) :: variables(:)
        integer :: g

        if (is_iostat_end(stat)) then
            g = scan%find_group(name, max(occurrence, 1))
            call fatal_error(error, group_label(name, occurrence) // ' (line ' &
                // format_integer(scan%groups(g)%first_line) // ') was not found by the ' &
                // "Fortran namelist reader: is there a '!' inside a character value " &
                // 'earlier on that line? (it hides the rest of the line)')
            return
        end if
        call fatal_error(error, group_label(name, occurrence) // ': ' &
            // explain_read_error(scan, name, max(occurrence, 1), trim(message), variables))
    end subroutine read_failed

    !> An error found after a successful READ, with the group's line.
    subroutine post_read_error(error, scan, name, occurrence, text)
        type(error_type), allocatable, intent(out) :: error
        type(namelist_scan_type), intent(in) :: scan
        character(len=*), intent(in) :: name
        integer, intent(in) :: occurrence
        character(len=*), intent(in) :: text

        call fatal_error(error, group_label(name, occurrence) // ': ' // text &
            // ' (group on line ' &
            // format_integer(scan%groups(scan%find_group(name, max(occurrence, 1)))%first_line) &
            // ')')
    end subroutine post_read_error

    !> The namelist reader found more occurrences than the structural scan.
    subroutine too_many_found(error, name, n_expected)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: name
        integer, intent(in) :: n_expected

        call fatal_error(error, '&' // name // ': the Fortran namelist reader found more ' &
            // 'than the ' // format_integer(n_expected) // ' &' // name // ' groups of ' &
            // "the text; is '&" // name // "' inside a comment after a character value " &
            // "with '!'?")
    end subroutine too_many_found

    !> A character value must fit its config field.
    subroutine check_length(error, scan, name, occurrence, variable, value, max_length)
        type(error_type), allocatable, intent(out) :: error
        type(namelist_scan_type), intent(in) :: scan
        character(len=*), intent(in) :: name, variable, value
        integer, intent(in) :: occurrence, max_length

        if (len_trim(value) > max_length) then
            call post_read_error(error, scan, name, occurrence, variable // " = '" &
                // value(:min(len_trim(value), 40)) // "...' is longer than " &
                // format_integer(max_length) // ' characters')
        end if
    end subroutine check_length

    !> Number of values of a list read into a buffer prefilled with `unset_integer`:
    !> the buffer's last entry is a guard against overflow, and gaps are errors.
    subroutine get_integer_list_length(error, scan, name, occurrence, variable, values, n)
        type(error_type), allocatable, intent(out) :: error
        type(namelist_scan_type), intent(in) :: scan
        character(len=*), intent(in) :: name, variable
        integer, intent(in) :: occurrence
        integer, intent(in) :: values(:)
        integer, intent(out) :: n
        integer :: i

        n = 0
        do i = size(values), 1, -1
            if (values(i) /= unset_integer) then
                n = i
                exit
            end if
        end do
        if (n == size(values)) then
            call post_read_error(error, scan, name, occurrence, variable // ' has more than ' &
                // format_integer(size(values) - 1) // ' values (the most it can hold)')
            return
        end if
        do i = 1, n
            if (values(i) == unset_integer) then
                call post_read_error(error, scan, name, occurrence, variable // '(' &
                    // format_integer(i) // ') has no value, but later entries have (an ' &
                    // 'empty entry between commas?)')
                return
            end if
        end do
    end subroutine get_integer_list_length

    !> As get_integer_list_length for reals prefilled with `unset_real`.
    subroutine get_real_list_length(error, scan, name, occurrence, variable, values, n)
        type(error_type), allocatable, intent(out) :: error
        type(namelist_scan_type), intent(in) :: scan
        character(len=*), intent(in) :: name, variable
        integer, intent(in) :: occurrence
        real(wp), intent(in) :: values(:)
        integer, intent(out) :: n
        integer :: i

        n = 0
        do i = size(values), 1, -1
            if (values(i) /= unset_real) then
                n = i
                exit
            end if
        end do
        if (n == size(values)) then
            call post_read_error(error, scan, name, occurrence, variable // ' has more than ' &
                // format_integer(size(values) - 1) // ' values (the most it can hold)')
            return
        end if
        do i = 1, n
            if (values(i) == unset_real) then
                call post_read_error(error, scan, name, occurrence, variable // '(' &
                    // format_integer(i) // ') has no value, but later entries have (an ' &
                    // 'empty entry between commas?)')
                return
            end if
        end do
    end subroutine get_real_list_length

end module yarnfort_input_namelist
