! SPDX-License-Identifier: MIT
!> Unit tests of the namelist input: reading a valid scene (values and defaults), groups
!> in any order, friction contacts, the round trip read -> write_config -> read, the
!> geometry file, and bad
!> inputs that must fail with a message naming what is wrong (tests/data/input/bad_*.nml).
module test_input
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_is_nan
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_testing, only: unittest_type, new_unittest, check, check_close
    use yarnfort_input_config, only: config_type, solver_config_type
    use yarnfort_input_namelist, only: read_config, read_config_from_file, check_config, &
        max_list
    use yarnfort_input_echo, only: write_config
    use yarnfort_text, only: format_real, format_integer, read_line
    use test_input_paths, only: data_folder
    implicit none
    private

    public :: collect_input

    !> Values read from text, and written and read again, must be exact.
    real(wp), parameter :: exact = 0.0_wp

contains

    !> All tests of the input suite.
    subroutine collect_input(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)

        testsuite = [ &
            new_unittest('valid_scene', test_valid_scene), &
            new_unittest('defaults', test_defaults), &
            new_unittest('any_order', test_any_order), &
            new_unittest('round_trip', test_round_trip), &
            new_unittest('round_trip_special_values', test_round_trip_special_values), &
            new_unittest('valid_contact', test_valid_contact), &
            new_unittest('contact_round_trip', test_contact_round_trip), &
            new_unittest('geometry_file', test_geometry_file), &
            new_unittest('geometry_round_trip', test_geometry_round_trip), &
            new_unittest('format_real', test_format_real), &
            new_unittest('list_overflow', test_list_overflow), &
            new_unittest('list_beyond_buffer', test_list_beyond_buffer), &
            new_unittest('missing_input_file', test_missing_input_file), &
            new_unittest('input_file_is_a_folder', test_input_file_is_a_folder), &
            new_unittest('long_record', test_long_record), &
            new_unittest('bad_unknown_group', test_bad_unknown_group), &
            new_unittest('bad_unknown_variable', test_bad_unknown_variable), &
            new_unittest('bad_wrong_type', test_bad_wrong_type), &
            new_unittest('bad_wrong_type_unquoted', test_bad_wrong_type_unquoted), &
            new_unittest('bad_wrong_type_integer', test_bad_wrong_type_integer), &
            new_unittest('bad_duplicate_singleton', test_bad_duplicate_singleton), &
            new_unittest('bad_missing_path', test_bad_missing_path), &
            new_unittest('bad_dangling_yarn_node', test_bad_dangling_yarn_node), &
            new_unittest('bad_dangling_support_node', test_bad_dangling_support_node), &
            new_unittest('bad_dangling_load_node', test_bad_dangling_load_node), &
            new_unittest('bad_zero_length_segment', test_bad_zero_length_segment), &
            new_unittest('bad_zero_length_element', test_bad_zero_length_element), &
            new_unittest('bad_unknown_material', test_bad_unknown_material), &
            new_unittest('bad_duplicate_material', test_bad_duplicate_material), &
            new_unittest('bad_path_time', test_bad_path_time), &
            new_unittest('bad_nan', test_bad_nan), &
            new_unittest('bad_nan_node', test_bad_nan_node), &
            new_unittest('bad_negative_stiffness', test_bad_negative_stiffness), &
            new_unittest('bad_unknown_law', test_bad_unknown_law), &
            new_unittest('bad_linear_solver', test_bad_linear_solver), &
            new_unittest('bad_fix', test_bad_fix), &
            new_unittest('bad_min_step', test_bad_min_step), &
            new_unittest('bad_step_cut', test_bad_step_cut), &
            new_unittest('bad_unclosed_group', test_bad_unclosed_group), &
            new_unittest('bad_text_outside', test_bad_text_outside), &
            new_unittest('bad_variable_twice', test_bad_variable_twice), &
            new_unittest('group_in_string', test_group_in_string), &
            new_unittest('bad_string_not_closed', test_bad_string_not_closed), &
            new_unittest('bad_nodes_not_triplets', test_bad_nodes_not_triplets), &
            new_unittest('bad_nodes_and_geometry', test_bad_nodes_and_geometry), &
            new_unittest('bad_unused_parameter', test_bad_unused_parameter), &
            new_unittest('bad_missing_parameter', test_bad_missing_parameter), &
            new_unittest('bad_support_conflict', test_bad_support_conflict), &
            new_unittest('bad_duplicate_support', test_bad_duplicate_support), &
            new_unittest('bad_load_on_support', test_bad_load_on_support), &
            new_unittest('bad_free_node', test_bad_free_node), &
            new_unittest('bad_path_lengths', test_bad_path_lengths), &
            new_unittest('bad_list_gap', test_bad_list_gap), &
            new_unittest('bad_long_name', test_bad_long_name), &
            new_unittest('bad_short_yarn', test_bad_short_yarn), &
            new_unittest('bad_elements_per_segment', test_bad_elements_per_segment), &
            new_unittest('bad_no_material', test_bad_no_material), &
            new_unittest('bad_group_not_closed', test_bad_group_not_closed), &
            new_unittest('bad_support_name', test_bad_support_name), &
            new_unittest('bad_geometry_missing_node', test_bad_geometry_missing_node), &
            new_unittest('bad_geometry_keyword', test_bad_geometry_keyword), &
            new_unittest('bad_geometry_duplicate_node', test_bad_geometry_duplicate_node), &
            new_unittest('bad_geometry_dangling_node', test_bad_geometry_dangling_node), &
            new_unittest('bad_geometry_missing_file', test_bad_geometry_missing_file), &
            new_unittest('bad_contact_law', test_bad_contact_law), &
            new_unittest('bad_contact_material', test_bad_contact_material), &
            new_unittest('bad_contact_one_material', test_bad_contact_one_material), &
            new_unittest('bad_contact_duplicate', test_bad_contact_duplicate), &
            new_unittest('bad_contact_duplicate_reversed', test_bad_contact_duplicate_reversed), &
            new_unittest('bad_contact_missing_friction', test_bad_contact_missing_friction), &
            new_unittest('bad_contact_unused_adhesion', test_bad_contact_unused_adhesion), &
            new_unittest('bad_contact_decay', test_bad_contact_decay), &
            new_unittest('bad_contact_negative_friction', test_bad_contact_negative_friction), &
            new_unittest('bad_contact_missing_pair', test_bad_contact_missing_pair), &
            new_unittest('bad_scheme', test_bad_scheme), &
            new_unittest('bad_min_length_ratio', test_bad_min_length_ratio), &
            new_unittest('bad_duplicate_segment', test_bad_duplicate_segment), &
            new_unittest('bad_duplicate_segment_back', test_bad_duplicate_segment_back), &
            new_unittest('bad_path_time_resolution', test_bad_path_time_resolution), &
            new_unittest('bad_elements_per_segment_huge', test_bad_elements_per_segment_huge) &
            ]
    end subroutine collect_input

    !> Read a file of tests/data/input.
    subroutine read_data(name, config, error)
        character(len=*), intent(in) :: name
        type(config_type), intent(out) :: config
        type(error_type), allocatable, intent(out) :: error

        call read_config_from_file(data_folder // '/' // name, config, error)
    end subroutine read_data

    !> Reading and checking `name` must fail with a message containing every word.
    subroutine check_bad_input(error, name, words)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: name
        character(len=*), intent(in) :: words(:)
        type(config_type) :: config
        type(error_type), allocatable :: input_error
        integer :: i

        call read_data(name, config, input_error)
        if (.not. allocated(input_error)) call check_config(config, input_error)
        if (.not. allocated(input_error)) then
            call fatal_error(error, name // ': no error reported')
            return
        end if
        do i = 1, size(words)
            if (index(input_error%message, trim(words(i))) == 0) then
                call fatal_error(error, name // ": message '" // input_error%message &
                    // "' lacks '" // trim(words(i)) // "'")
                return
            end if
        end do
    end subroutine check_bad_input

    subroutine test_valid_scene(error)
        type(error_type), allocatable, intent(out) :: error
        type(config_type) :: config

        call read_data('valid_scene.nml', config, error)
        if (allocated(error)) return
        call check_config(config, error)
        if (allocated(error)) return
        call check(error, config%control%title == 'two yarns', 'title')
        if (allocated(error)) return
        call check(error, .not. config%control%check_only, 'check_only default')
        if (allocated(error)) return
        call check(error, config%solver%linear_solver == 'dense', 'linear_solver')
        if (allocated(error)) return
        call check(error, config%solver%max_iterations == 20, 'max_iterations')
        if (allocated(error)) return
        call check_close(error, config%solver%max_step, 0.2_wp, exact, 'max_step')
        if (allocated(error)) return
        call check(error, size(config%materials) == 2, 'number of materials')
        if (allocated(error)) return
        call check(error, config%materials(1)%name == 'cotton' &
            .and. config%materials(1)%law == 'linear', 'material 1')
        if (allocated(error)) return
        call check_close(error, config%materials(1)%stiffness, 150.0_wp, exact, 'stiffness')
        if (allocated(error)) return
        call check(error, config%materials(2)%name == 'wool' &
            .and. config%materials(2)%law == 'neo_hookean', 'material 2')
        if (allocated(error)) return
        call check_close(error, [config%materials(2)%modulus, config%materials(2)%area], &
            [2.0e9_wp, 1.0e-8_wp], exact, 'modulus, area')
        if (allocated(error)) return
        call check(error, all(shape(config%node_positions) == [3, 5]), 'shape of nodes')
        if (allocated(error)) return
        call check_close(error, reshape(config%node_positions, [15]), [0.0_wp, 0.0_wp, &
            0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 2.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, -1.0_wp, &
            0.0_wp, 1.0_wp, 1.0_wp, 0.0_wp], exact, 'xyz')
        if (allocated(error)) return
        call check(error, size(config%yarns) == 2, 'number of yarns')
        if (allocated(error)) return
        call check(error, config%yarns(1)%material == 'cotton' &
            .and. config%yarns(1)%elements_per_segment == 4, 'yarn 1')
        if (allocated(error)) return
        call check(error, size(config%yarns(1)%nodes) == 3, 'yarn 1 length')
        if (allocated(error)) return
        call check(error, all(config%yarns(1)%nodes == [1, 2, 3]), 'yarn 1 nodes')
        if (allocated(error)) return
        call check(error, config%yarns(2)%elements_per_segment == 1, 'yarn 2 default')
        if (allocated(error)) return
        call check(error, size(config%supports) == 2, 'number of supports')
        if (allocated(error)) return
        call check(error, config%supports(2)%name == 'pull' .and. config%supports(2)%fix == 'x' &
            .and. size(config%supports(2)%nodes) == 1, 'support 2')
        if (allocated(error)) return
        call check_close(error, config%supports(2)%displacement, [0.1_wp, 0.0_wp, 0.0_wp], &
            exact, 'displacement')
        if (allocated(error)) return
        call check_close(error, config%supports(1)%displacement, [0.0_wp, 0.0_wp, 0.0_wp], &
            exact, 'default displacement')
        if (allocated(error)) return
        call check(error, size(config%loads) == 1, 'number of loads')
        if (allocated(error)) return
        call check_close(error, config%loads(1)%force, [0.0_wp, 0.5_wp, 0.0_wp], exact, 'force')
        if (allocated(error)) return
        call check_close(error, config%path%time, [0.0_wp, 1.0_wp], exact, 'time')
        if (allocated(error)) return
        call check_close(error, config%path%p_disp, [0.0_wp, 1.0_wp], exact, 'p_disp')
        if (allocated(error)) return
        call check_close(error, config%path%p_force, [0.0_wp, 0.0_wp], exact, &
            'omitted p_force is zeros')
        if (allocated(error)) return
        call check(error, config%output%folder == 'out/two_yarns' &
            .and. config%output%vtk_every == 2 .and. config%output%progress, 'output')
        if (allocated(error)) return
        call check(error, config%input_folder == data_folder, 'input folder')
    end subroutine test_valid_scene

    !> Variables not in the input keep the defaults of the config types.
    subroutine test_defaults(error)
        type(error_type), allocatable, intent(out) :: error
        type(config_type) :: config
        type(solver_config_type) :: defaults

        call read_data('valid_scene.nml', config, error)
        if (allocated(error)) return
        call check_close(error, [config%solver%residual_tolerance, &
            config%solver%step_tolerance, config%solver%slack_stiffness, &
            config%solver%initial_step, config%solver%min_step, config%solver%step_growth, &
            config%solver%step_cut], [defaults%residual_tolerance, defaults%step_tolerance, &
            defaults%slack_stiffness, defaults%initial_step, defaults%min_step, &
            defaults%step_growth, defaults%step_cut], exact, 'solver defaults')
        if (allocated(error)) return
        call check(error, config%solver%max_setup_calls == defaults%max_setup_calls &
            .and. config%solver%easy_iterations == defaults%easy_iterations &
            .and. config%solver%max_step_cuts == defaults%max_step_cuts &
            .and. (config%solver%line_search .eqv. defaults%line_search), &
            'solver integer and logical defaults')
        if (allocated(error)) return
        call check(error, config%solver%scheme == defaults%scheme &
            .and. config%solver%max_friction_iterations == defaults%max_friction_iterations, &
            'friction scheme and iteration defaults')
        if (allocated(error)) return
        call check_close(error, [config%solver%min_length_ratio, &
            config%solver%friction_tolerance], [defaults%min_length_ratio, &
            defaults%friction_tolerance], exact, 'friction solver defaults')
        if (allocated(error)) return
        call check(error, allocated(config%contacts), 'contacts allocated without &contact')
        if (allocated(error)) return
        call check(error, size(config%contacts) == 0, 'no contacts without &contact')
        if (allocated(error)) return
        call check(error, config%geometry%file == '', 'no geometry file')
        if (allocated(error)) return
        call check(error, .not. (allocated(config%materials(1)%modulus) &
            .or. allocated(config%materials(1)%area)), 'unset material parameters not set')
    end subroutine test_defaults

    subroutine test_any_order(error)
        type(error_type), allocatable, intent(out) :: error
        type(config_type) :: expected, actual

        call read_data('valid_scene.nml', expected, error)
        if (allocated(error)) return
        call read_data('valid_shuffled.nml', actual, error)
        if (allocated(error)) return
        call check_configs_equal(error, actual, expected)
    end subroutine test_any_order

    !> write_config, then read_config from a scratch file, gives the same config.
    subroutine round_trip(error, config)
        type(error_type), allocatable, intent(out) :: error
        type(config_type), intent(in) :: config
        type(config_type) :: again
        integer :: unit

        open(newunit=unit, status='scratch', action='readwrite', form='formatted')
        call write_config(unit, config)
        call read_config(unit, again, error, config%input_folder)
        close(unit)
        if (allocated(error)) then
            error%message = 'reading the echo: ' // error%message
            return
        end if
        call check_configs_equal(error, again, config)
    end subroutine round_trip

    subroutine test_round_trip(error)
        type(error_type), allocatable, intent(out) :: error
        type(config_type) :: config

        call read_data('valid_scene.nml', config, error)
        if (allocated(error)) return
        call round_trip(error, config)
    end subroutine test_round_trip

    !> Values that are awkward to write: quotes, long lists, non-decimal fractions.
    subroutine test_round_trip_special_values(error)
        type(error_type), allocatable, intent(out) :: error
        type(config_type) :: config
        integer :: i

        call read_data('valid_scene.nml', config, error)
        if (allocated(error)) return
        config%control%title = "it's a ""quoted"" title, with / and ! and &"
        config%solver%residual_tolerance = 1.0_wp / 3.0_wp
        config%solver%step_tolerance = tiny(1.0_wp)
        config%materials(1)%stiffness = huge(1.0_wp)
        config%materials(2)%area = 0.1_wp + 0.2_wp
        config%node_positions(2, 3) = -epsilon(1.0_wp)
        config%yarns(1)%nodes = [(i, i = 1, 5), (i, i = 4, 1, -1), (i, i = 2, 5)]
        config%path%time = [(real(i, wp) / 7.0_wp, i = 0, 22)]
        config%path%p_force = config%path%time**2
        config%path%p_disp = -config%path%time
        call round_trip(error, config)
    end subroutine test_round_trip_special_values

    !> Two &contact groups (one with its pair in reversed order) and friction settings.
    subroutine test_valid_contact(error)
        type(error_type), allocatable, intent(out) :: error
        type(config_type) :: config
        type(solver_config_type) :: defaults

        call read_data('valid_contact.nml', config, error)
        if (allocated(error)) return
        call check_config(config, error)
        if (allocated(error)) return
        call check(error, config%solver%scheme == 'staggered', 'scheme (lower case)')
        if (allocated(error)) return
        call check(error, config%solver%max_friction_iterations == 20, &
            'max_friction_iterations')
        if (allocated(error)) return
        call check_close(error, [config%solver%min_length_ratio, &
            config%solver%friction_tolerance], [defaults%min_length_ratio, &
            defaults%friction_tolerance], exact, 'friction solver defaults')
        if (allocated(error)) return
        call check(error, size(config%contacts) == 2, 'number of contacts')
        if (allocated(error)) return
        associate(contact => config%contacts(1))
            call check(error, contact%materials(1) == 'wool' &
                .and. contact%materials(2) == 'cotton', 'contact 1 materials')
            if (allocated(error)) return
            call check(error, contact%law == 'coulomb', 'contact 1 law (lower case)')
            if (allocated(error)) return
            call check_close(error, contact%friction_coefficient, 0.3_wp, exact, &
                'contact 1 friction_coefficient')
            if (allocated(error)) return
            call check(error, .not. (allocated(contact%adhesion) .or. &
                allocated(contact%decay_start) .or. allocated(contact%decay_end)), &
                'contact 1: the parameters it does not give are not set')
            if (allocated(error)) return
        end associate
        associate(contact => config%contacts(2))
            call check(error, all(contact%materials == 'wool') &
                .and. contact%law == 'decaying_adhesion', 'contact 2')
            if (allocated(error)) return
            call check_close(error, [contact%friction_coefficient, contact%adhesion, &
                contact%decay_start, contact%decay_end], [0.2_wp, 0.05_wp, 1.0_wp, 2.5_wp], &
                exact, 'contact 2 parameters')
            if (allocated(error)) return
        end associate
        call check(error, size(config%yarns) == 3, 'number of yarns')
    end subroutine test_valid_contact

    !> Contacts and friction settings survive write_config -> read_config exactly.
    subroutine test_contact_round_trip(error)
        type(error_type), allocatable, intent(out) :: error
        type(config_type) :: config

        call read_data('valid_contact.nml', config, error)
        if (allocated(error)) return
        call round_trip(error, config)
        if (allocated(error)) return
        config%contacts(1)%friction_coefficient = 0.1_wp + 0.2_wp
        config%contacts(2)%adhesion = 1.0_wp / 3.0_wp
        config%contacts(2)%decay_end = huge(1.0_wp)
        config%contacts(2)%materials(2) = "it's"
        config%solver%min_length_ratio = tiny(1.0_wp)
        config%solver%friction_tolerance = 1.0_wp / 7.0_wp
        config%solver%max_friction_iterations = 1
        call round_trip(error, config)
    end subroutine test_contact_round_trip

    subroutine test_geometry_file(error)
        type(error_type), allocatable, intent(out) :: error
        type(config_type) :: expected, actual

        call read_data('valid_scene.nml', expected, error)
        if (allocated(error)) return
        call read_data('valid_geometry.nml', actual, error)
        if (allocated(error)) return
        call check_config(actual, error)
        if (allocated(error)) return
        call check(error, actual%geometry%file == 'grid.geo', 'geometry file name')
        if (allocated(error)) return
        ! The same scene apart from where its geometry comes from.
        actual%geometry%file = ''
        call check_configs_equal(error, actual, expected)
    end subroutine test_geometry_file

    subroutine test_geometry_round_trip(error)
        type(error_type), allocatable, intent(out) :: error
        type(config_type) :: config

        call read_data('valid_geometry.nml', config, error)
        if (allocated(error)) return
        call round_trip(error, config)
    end subroutine test_geometry_round_trip

    !> format_real writes the shortest text that reads back exactly.
    subroutine test_format_real(error)
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: values(12), back
        character(len=32) :: text
        integer :: i

        values = [0.25_wp, 1.0e-6_wp, -3.0e12_wp, 0.1_wp + 0.2_wp, 1.0_wp / 3.0_wp, &
            huge(1.0_wp), tiny(1.0_wp), -tiny(1.0_wp) / 4, 150.0_wp, 1.0e15_wp, &
            1.0e16_wp, 123456.789_wp]
        do i = 1, size(values)
            text = format_real(values(i))
            read(text, *) back
            call check(error, back == values(i), 'format_real(' // format_real(values(i)) &
                // ') does not read back')
            if (allocated(error)) return
        end do
        call check(error, format_real(0.25_wp) == '0.25', '0.25: ' // format_real(0.25_wp))
        if (allocated(error)) return
        call check(error, format_real(1.0e-6_wp) == '1.0e-6', '1e-6: ' // format_real(1.0e-6_wp))
        if (allocated(error)) return
        call check(error, format_real(150.0_wp) == '150.0', '150: ' // format_real(150.0_wp))
        if (allocated(error)) return
        call check(error, format_real(-5.0_wp) == '-5.0', '-5: ' // format_real(-5.0_wp))
        if (allocated(error)) return
        call check(error, format_real(ieee_value(1.0_wp, ieee_quiet_nan)) == 'NaN', 'NaN')
    end subroutine test_format_real

    !> A &yarn with `n` node ids, written to a scratch unit and read.
    subroutine read_long_yarn(n, error)
        integer, intent(in) :: n
        type(error_type), allocatable, intent(out) :: error
        type(config_type) :: config
        integer :: unit, i, k
        integer, parameter :: per_line = 20

        open(newunit=unit, status='scratch', action='readwrite', form='formatted')
        write(unit, '(a)') "&yarn material = 'cotton'"
        write(unit, '(a)') '    nodes ='
        do i = 1, n, per_line
            write(unit, '(4x, *(i0, :, 1x))') (mod(i + k, 2) + 1, k = 0, &
                min(per_line, n - i + 1) - 1)
        end do
        write(unit, '(a)') '/'
        call read_config(unit, config, error)
        close(unit)
    end subroutine read_long_yarn

    !> One value more than the list holds is detected by the buffer's guard entry.
    subroutine test_list_overflow(error)
        type(error_type), allocatable, intent(out) :: error
        type(error_type), allocatable :: input_error

        call read_long_yarn(max_list, input_error)
        call check(error, .not. allocated(input_error), 'a list of max_list values is read')
        if (allocated(error)) return
        call read_long_yarn(max_list + 1, input_error)
        call check(error, allocated(input_error), 'no error for max_list + 1 values')
        if (allocated(error)) return
        call check(error, index(input_error%message, '&yarn #1: nodes has more than ') == 1, &
            input_error%message)
    end subroutine test_list_overflow

    !> Several values more than the list holds: the message says so.
    subroutine test_list_beyond_buffer(error)
        type(error_type), allocatable, intent(out) :: error
        type(error_type), allocatable :: input_error

        call read_long_yarn(max_list + 5, input_error)
        call check(error, allocated(input_error), 'no error for max_list + 5 values')
        if (allocated(error)) return
        call check(error, index(input_error%message, '&yarn #1:') == 1 &
            .and. index(input_error%message, 'more values than nodes holds') > 0, &
            input_error%message)
    end subroutine test_list_beyond_buffer

    subroutine test_missing_input_file(error)
        type(error_type), allocatable, intent(out) :: error
        type(config_type) :: config
        type(error_type), allocatable :: input_error

        call read_data('no_such_input.nml', config, input_error)
        call check(error, allocated(input_error), 'no error for a missing file')
        if (allocated(error)) return
        call check(error, index(input_error%message, 'cannot open input file') == 1, &
            input_error%message)
    end subroutine test_missing_input_file

    subroutine test_input_file_is_a_folder(error)
        type(error_type), allocatable, intent(out) :: error
        type(config_type) :: config
        type(error_type), allocatable :: input_error

        call read_config_from_file('.', config, input_error)
        call check(error, allocated(input_error), 'no error for a folder')
        if (allocated(error)) return
        call check(error, input_error%message == "input file '.' is a folder, not a file", &
            input_error%message)
    end subroutine test_input_file_is_a_folder

    !> read_line returns a record of several buffer growths whole, and the next one.
    subroutine test_long_record(error)
        type(error_type), allocatable, intent(out) :: error
        integer, parameter :: n = 100003
        character(len=:), allocatable :: line, record
        character(len=512) :: message
        integer :: unit, stat, i

        allocate(character(len=n) :: record)
        do i = 1, n
            record(i:i) = achar(iachar('a') + mod(i, 26))
        end do
        open(newunit=unit, status='scratch', action='readwrite', form='formatted')
        write(unit, '(a)') record
        write(unit, '(a)') 'next'
        rewind(unit)
        call read_line(unit, line, stat, message)
        call check(error, stat == 0 .and. line == record, 'long record not read whole')
        if (allocated(error)) return
        call read_line(unit, line, stat, message)
        call check(error, stat == 0 .and. line == 'next', 'record after it: ' // line)
        close(unit)
    end subroutine test_long_record

    !> Every variable of two configs is equal (reals exactly, NaN equal to NaN).
    subroutine check_configs_equal(error, actual, expected)
        type(error_type), allocatable, intent(out) :: error
        type(config_type), intent(in) :: actual, expected
        integer :: k
        character(len=:), allocatable :: what

        associate(a => actual%control, e => expected%control)
            if (a%title /= e%title .or. (a%check_only .neqv. e%check_only)) then
                call fatal_error(error, '&control differs')
                return
            end if
        end associate
        associate(a => actual%solver, e => expected%solver)
            if (a%linear_solver /= e%linear_solver .or. a%max_iterations /= e%max_iterations &
                .or. a%max_setup_calls /= e%max_setup_calls &
                .or. (a%line_search .neqv. e%line_search) &
                .or. a%easy_iterations /= e%easy_iterations &
                .or. a%max_step_cuts /= e%max_step_cuts .or. a%scheme /= e%scheme &
                .or. a%max_friction_iterations /= e%max_friction_iterations) then
                call fatal_error(error, '&solver differs (text, integer or logical)')
                return
            end if
            call check_reals(error, [a%residual_tolerance, a%step_tolerance, &
                a%slack_stiffness, a%initial_step, a%min_step, a%max_step, a%step_growth, &
                a%step_cut, a%min_length_ratio, a%friction_tolerance], [e%residual_tolerance, &
                e%step_tolerance, e%slack_stiffness, e%initial_step, e%min_step, e%max_step, &
                e%step_growth, e%step_cut, e%min_length_ratio, e%friction_tolerance], &
                '&solver')
            if (allocated(error)) return
        end associate
        if (size(actual%materials) /= size(expected%materials)) then
            call fatal_error(error, 'number of materials differs')
            return
        end if
        do k = 1, size(expected%materials)
            associate(a => actual%materials(k), e => expected%materials(k))
                what = '&material #' // format_integer(k)
                if (a%name /= e%name .or. a%law /= e%law .or. a%table_file /= e%table_file) then
                    call fatal_error(error, what // ' differs (text)')
                    return
                end if
                call check_optional(error, a%stiffness, e%stiffness, what // ' stiffness')
                if (allocated(error)) return
                call check_optional(error, a%modulus, e%modulus, what // ' modulus')
                if (allocated(error)) return
                call check_optional(error, a%area, e%area, what // ' area')
                if (allocated(error)) return
                call check_optional(error, a%gauge_length, e%gauge_length, &
                    what // ' gauge_length')
                if (allocated(error)) return
            end associate
        end do
        if (size(actual%contacts) /= size(expected%contacts)) then
            call fatal_error(error, 'number of contacts differs')
            return
        end if
        do k = 1, size(expected%contacts)
            associate(a => actual%contacts(k), e => expected%contacts(k))
                what = '&contact #' // format_integer(k)
                if (any(a%materials /= e%materials) .or. a%law /= e%law) then
                    call fatal_error(error, what // ' differs (text)')
                    return
                end if
                call check_optional(error, a%friction_coefficient, e%friction_coefficient, &
                    what // ' friction_coefficient')
                if (allocated(error)) return
                call check_optional(error, a%adhesion, e%adhesion, what // ' adhesion')
                if (allocated(error)) return
                call check_optional(error, a%decay_start, e%decay_start, what // ' decay_start')
                if (allocated(error)) return
                call check_optional(error, a%decay_end, e%decay_end, what // ' decay_end')
                if (allocated(error)) return
            end associate
        end do
        if (actual%geometry%file /= expected%geometry%file) then
            call fatal_error(error, '&geometry file differs')
            return
        end if
        if (.not. all(shape(actual%node_positions) == shape(expected%node_positions))) then
            call fatal_error(error, 'number of nodes differs')
            return
        end if
        call check_reals(error, reshape(actual%node_positions, [size(actual%node_positions)]), &
            reshape(expected%node_positions, [size(expected%node_positions)]), '&nodes xyz')
        if (allocated(error)) return
        if (size(actual%yarns) /= size(expected%yarns)) then
            call fatal_error(error, 'number of yarns differs')
            return
        end if
        do k = 1, size(expected%yarns)
            associate(a => actual%yarns(k), e => expected%yarns(k))
                if (a%material /= e%material .or. a%elements_per_segment &
                    /= e%elements_per_segment .or. size(a%nodes) /= size(e%nodes)) then
                    call fatal_error(error, 'yarn differs')
                    return
                end if
                if (any(a%nodes /= e%nodes)) then
                    call fatal_error(error, 'yarn nodes differ')
                    return
                end if
            end associate
        end do
        if (size(actual%supports) /= size(expected%supports)) then
            call fatal_error(error, 'number of supports differs')
            return
        end if
        do k = 1, size(expected%supports)
            associate(a => actual%supports(k), e => expected%supports(k))
                if (a%name /= e%name .or. a%fix /= e%fix .or. size(a%nodes) /= size(e%nodes)) then
                    call fatal_error(error, 'support differs')
                    return
                end if
                if (any(a%nodes /= e%nodes)) then
                    call fatal_error(error, 'support nodes differ')
                    return
                end if
                call check_reals(error, a%displacement, e%displacement, 'displacement')
                if (allocated(error)) return
            end associate
        end do
        if (size(actual%loads) /= size(expected%loads)) then
            call fatal_error(error, 'number of loads differs')
            return
        end if
        do k = 1, size(expected%loads)
            associate(a => actual%loads(k), e => expected%loads(k))
                if (size(a%nodes) /= size(e%nodes)) then
                    call fatal_error(error, 'load differs')
                    return
                end if
                if (any(a%nodes /= e%nodes)) then
                    call fatal_error(error, 'load nodes differ')
                    return
                end if
                call check_reals(error, a%force, e%force, 'force')
                if (allocated(error)) return
            end associate
        end do
        call check_reals(error, actual%path%time, expected%path%time, '&path time')
        if (allocated(error)) return
        call check_reals(error, actual%path%p_force, expected%path%p_force, '&path p_force')
        if (allocated(error)) return
        call check_reals(error, actual%path%p_disp, expected%path%p_disp, '&path p_disp')
        if (allocated(error)) return
        associate(a => actual%output, e => expected%output)
            if (a%folder /= e%folder .or. a%vtk_every /= e%vtk_every &
                .or. (a%progress .neqv. e%progress)) then
                call fatal_error(error, '&output differs')
                return
            end if
        end associate
    end subroutine check_configs_equal

    !> Optional reals both not set, or both set to the same value (check_reals).
    subroutine check_optional(error, actual, expected, what)
        type(error_type), allocatable, intent(out) :: error
        real(wp), allocatable, intent(in) :: actual, expected
        character(len=*), intent(in) :: what

        if (allocated(actual) .neqv. allocated(expected)) then
            call fatal_error(error, what // ': set in one, not set in the other')
        else if (allocated(actual)) then
            call check_reals(error, [actual], [expected], what)
        end if
    end subroutine check_optional

    !> Equal reals, bit for bit apart from NaN payloads.
    subroutine check_reals(error, actual, expected, what)
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in) :: actual(:), expected(:)
        character(len=*), intent(in) :: what
        integer :: i

        if (size(actual) /= size(expected)) then
            call fatal_error(error, what // ': sizes differ')
            return
        end if
        do i = 1, size(actual)
            if (ieee_is_nan(actual(i)) .and. ieee_is_nan(expected(i))) cycle
            if (actual(i) /= expected(i)) then
                call fatal_error(error, what // ': ' // format_real(actual(i)) // ' /= ' &
                    // format_real(expected(i)))
                return
            end if
        end do
    end subroutine check_reals

    subroutine test_bad_unknown_group(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_unknown_group.nml', [character(len=28) :: &
            'unknown group &solvr on line', &
            'did you mean &solver?'])
    end subroutine test_bad_unknown_group

    subroutine test_bad_unknown_variable(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_unknown_variable.nml', [character(len=53) :: &
            '&solver: unknown variable line_serch (line 10)', &
            'did you mean line_search?'])
    end subroutine test_bad_unknown_variable

    subroutine test_bad_wrong_type(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_wrong_type.nml', [character(len=41) :: &
            '&material #1:', &
            '''stiff'' is not a valid value of stiffness'])
    end subroutine test_bad_wrong_type

    subroutine test_bad_wrong_type_unquoted(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_wrong_type_unquoted.nml', [character(len=43) :: &
            '&solver:', &
            'many is not a valid value of max_iterations'])
    end subroutine test_bad_wrong_type_unquoted

    subroutine test_bad_wrong_type_integer(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_wrong_type_integer.nml', [character(len=48) :: &
            '&yarn #1:', &
            '2.5 is not a valid value of elements_per_segment'])
    end subroutine test_bad_wrong_type_integer

    subroutine test_bad_duplicate_singleton(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_duplicate_singleton.nml', [character(len=47) :: &
            '&solver appears more than once (lines 6 and 36)'])
    end subroutine test_bad_duplicate_singleton

    subroutine test_bad_missing_path(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_missing_path.nml', [character(len=20) :: &
            '&path: group missing'])
    end subroutine test_bad_missing_path

    subroutine test_bad_dangling_yarn_node(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_dangling_yarn_node.nml', [character(len=56) :: &
            '&yarn #1: nodes(3) = 9 is not a node (node ids are 1..5)'])
    end subroutine test_bad_dangling_yarn_node

    subroutine test_bad_dangling_support_node(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_dangling_support_node.nml', [character(len=43) :: &
            '&support ''left'': nodes(2) = 7 is not a node'])
    end subroutine test_bad_dangling_support_node

    subroutine test_bad_dangling_load_node(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_dangling_load_node.nml', [character(len=36) :: &
            '&load #1: nodes(1) = 0 is not a node'])
    end subroutine test_bad_dangling_load_node

    subroutine test_bad_zero_length_segment(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_zero_length_segment.nml', [character(len=54) :: &
            '&yarn #1: nodes(2) = nodes(3) = 2: zero-length segment'])
    end subroutine test_bad_zero_length_segment

    subroutine test_bad_zero_length_element(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_zero_length_element.nml', [character(len=23) :: &
            '&yarn #1: nodes 2 and 3', &
            'zero-length element'])
    end subroutine test_bad_zero_length_element

    subroutine test_bad_unknown_material(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_unknown_material.nml', [character(len=43) :: &
            '&yarn #1: material = ''cottn'' is not defined', &
            '''cotton'', ''wool''', &
            'did you mean ''cotton''?'])
    end subroutine test_bad_unknown_material

    subroutine test_bad_duplicate_material(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_duplicate_material.nml', [character(len=43) :: &
            '&material: name = ''cotton'' is defined twice'])
    end subroutine test_bad_duplicate_material

    subroutine test_bad_path_time(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_path_time.nml', [character(len=54) :: &
            '&path: time(3) = 1.0 is not greater than time(2) = 1.0', &
            'strictly increasing'])
    end subroutine test_bad_path_time

    subroutine test_bad_nan(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_nan.nml', [character(len=49) :: &
            '&material ''cotton'': stiffness = NaN is not finite'])
    end subroutine test_bad_nan

    subroutine test_bad_nan_node(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_nan_node.nml', [character(len=46) :: &
            '&nodes: xyz(14) = NaN (node 5 y) is not finite'])
    end subroutine test_bad_nan_node

    subroutine test_bad_negative_stiffness(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_negative_stiffness.nml', [character(len=53) :: &
            '&material ''cotton'': stiffness = -5.0 must be positive'])
    end subroutine test_bad_negative_stiffness

    subroutine test_bad_unknown_law(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_unknown_law.nml', [character(len=77) :: &
            '&material ''cotton'': law = ''hooke'' is unknown (use linear, neo_hookean, table)'])
    end subroutine test_bad_unknown_law

    subroutine test_bad_linear_solver(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_linear_solver.nml', [character(len=45) :: &
            '&solver: linear_solver = ''superlu'' is unknown'])
    end subroutine test_bad_linear_solver

    subroutine test_bad_fix(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_fix.nml', [character(len=56) :: &
            '&support ''pull'': fix = ''xw'' has ''w'' (use any of x, y, z)'])
    end subroutine test_bad_fix

    subroutine test_bad_min_step(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_min_step.nml', [character(len=53) :: &
            '&solver: min_step = 0.5 is larger than max_step = 0.2'])
    end subroutine test_bad_min_step

    subroutine test_bad_step_cut(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_step_cut.nml', [character(len=57) :: &
            '&solver: step_cut = 1.0 must lie strictly between 0 and 1'])
    end subroutine test_bad_step_cut

    subroutine test_bad_unclosed_group(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_unclosed_group.nml', [character(len=40) :: &
            '&output (line 35) is not closed with ''/'''])
    end subroutine test_bad_unclosed_group

    subroutine test_bad_text_outside(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_text_outside.nml', [character(len=39) :: &
            'line 3: text outside a group: ''control'''])
    end subroutine test_bad_text_outside

    subroutine test_bad_variable_twice(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_variable_twice.nml', [character(len=46) :: &
            '&solver: max_step is set twice (lines 9 and 10)'])
    end subroutine test_bad_variable_twice

    !> '&yarn' and '!' inside a character value are text (the reader knows the quotes).
    subroutine test_group_in_string(error)
        type(error_type), allocatable, intent(out) :: error
        type(config_type) :: config

        call read_data('group_in_string.nml', config, error)
        if (allocated(error)) return
        call check(error, config%control%title == 'see &yarn below! and &path', &
            'title: ' // trim(config%control%title))
    end subroutine test_group_in_string

    subroutine test_bad_string_not_closed(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_string_not_closed.nml', [character(len=53) :: &
            'line 4: character value not closed with '' on its line'])
    end subroutine test_bad_string_not_closed

    subroutine test_bad_nodes_not_triplets(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_nodes_not_triplets.nml', [character(len=46) :: &
            '&nodes: xyz has 13 values, not a multiple of 3'])
    end subroutine test_bad_nodes_not_triplets

    subroutine test_bad_nodes_and_geometry(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_nodes_and_geometry.nml', [character(len=61) :: &
            '&nodes: not allowed together with &geometry file = ''grid.geo'''])
    end subroutine test_bad_nodes_and_geometry

    subroutine test_bad_unused_parameter(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_unused_parameter.nml', [character(len=63) :: &
            '&material ''cotton'': modulus = 1.0e9 is not used by law ''linear'''])
    end subroutine test_bad_unused_parameter

    subroutine test_bad_missing_parameter(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_missing_parameter.nml', [character(len=62) :: &
            '&material ''wool'': area is not set (law ''neo_hookean'' needs it)'])
    end subroutine test_bad_missing_parameter

    subroutine test_bad_support_conflict(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_support_conflict.nml', [character(len=66) :: &
            '&support ''pull'': node 3 x is already prescribed by &support ''left'''])
    end subroutine test_bad_support_conflict

    subroutine test_bad_duplicate_support(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_duplicate_support.nml', [character(len=37) :: &
            '&support: name = ''left'' is used twice'])
    end subroutine test_bad_duplicate_support

    subroutine test_bad_load_on_support(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_load_on_support.nml', [character(len=35) :: &
            '&load #1: node 4 has force(2) = 0.5', &
            'prescribed by &support ''left'''])
    end subroutine test_bad_load_on_support

    subroutine test_bad_free_node(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_free_node.nml', [character(len=28) :: &
            '&nodes: node 6 is on no yarn'])
    end subroutine test_bad_free_node

    subroutine test_bad_path_lengths(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_path_lengths.nml', [character(len=41) :: &
            '&path: p_disp has 3 values but time has 2'])
    end subroutine test_bad_path_lengths

    subroutine test_bad_list_gap(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_list_gap.nml', [character(len=31) :: &
            '&yarn #2: nodes(2) has no value'])
    end subroutine test_bad_list_gap

    subroutine test_bad_long_name(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_long_name.nml', [character(len=28) :: &
            '&material #2: name =', &
            'is longer than 64 characters'])
    end subroutine test_bad_long_name

    subroutine test_bad_short_yarn(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_short_yarn.nml', [character(len=57) :: &
            '&yarn #2: nodes has 1 node id(s); a yarn needs at least 2'])
    end subroutine test_bad_short_yarn

    subroutine test_bad_elements_per_segment(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_elements_per_segment.nml', [character(len=47) :: &
            '&yarn #1: elements_per_segment = 0 must be >= 1'])
    end subroutine test_bad_elements_per_segment

    subroutine test_bad_no_material(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_no_material.nml', [character(len=18) :: &
            'no &material group'])
    end subroutine test_bad_no_material

    subroutine test_bad_group_not_closed(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_group_not_closed.nml', [character(len=71) :: &
            'line 15: &material starts before &material (line 11) is closed with ''/'''])
    end subroutine test_bad_group_not_closed

    subroutine test_bad_support_name(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_support_name.nml', [character(len=66) :: &
            '&support #1: name = ''left clamp'' may contain only letters, digits'])
    end subroutine test_bad_support_name

    subroutine test_bad_geometry_missing_node(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_geometry_missing_node.nml', [character(len=40) :: &
            'bad_missing_node.geo'': node 3 is missing'])
    end subroutine test_bad_geometry_missing_node

    subroutine test_bad_geometry_keyword(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_geometry_keyword.nml', [character(len=47) :: &
            'bad_keyword.geo'', line 3: unknown keyword ''nod'''])
    end subroutine test_bad_geometry_keyword

    subroutine test_bad_geometry_duplicate_node(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_geometry_duplicate_node.nml', [character(len=72) :: &
            'bad_duplicate_node.geo'', line 4: node 2 is defined twice (lines 3 and 4)'])
    end subroutine test_bad_geometry_duplicate_node

    subroutine test_bad_geometry_dangling_node(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_geometry_dangling_node.nml', [character(len=75) :: &
            'bad_dangling_node.geo'', line 7: yarn node id 8 is not a node (ids are 1..5)'])
    end subroutine test_bad_geometry_dangling_node

    subroutine test_bad_geometry_missing_file(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_geometry_missing_file.nml', [character(len=27) :: &
            '&geometry: cannot open file', &
            'no_such_file.geo'])
    end subroutine test_bad_geometry_missing_file

    subroutine test_bad_contact_law(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_contact_law.nml', [character(len=78) :: &
            '&contact #1 (''wool'', ''cotton''): law = ''colomb'' is unknown', &
            '(use bonded, coulomb, adhesion, decaying_adhesion, general)', &
            'did you mean ''coulomb''?'])
    end subroutine test_bad_contact_law

    subroutine test_bad_contact_material(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_contact_material.nml', [character(len=64) :: &
            '&contact #1: materials(2) = ''coton'' is not defined by any &material', &
            '''cotton'', ''wool''', &
            'did you mean ''cotton''?'])
    end subroutine test_bad_contact_material

    subroutine test_bad_contact_one_material(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_contact_one_material.nml', [character(len=38) :: &
            '&contact #1: materials(2) is not set'])
    end subroutine test_bad_contact_one_material

    subroutine test_bad_contact_duplicate(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_contact_duplicate.nml', [character(len=64) :: &
            '&contact #2: materials = ''wool'', ''cotton'' is the same pair as', &
            '&contact #1 (materials = ''wool'', ''cotton''', &
            'one &contact per pair'])
    end subroutine test_bad_contact_duplicate

    subroutine test_bad_contact_duplicate_reversed(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_contact_duplicate_reversed.nml', &
            [character(len=64) :: &
            '&contact #2: materials = ''cotton'', ''wool'' is the same pair as', &
            '&contact #1 (materials = ''wool'', ''cotton''', &
            'the order does not matter'])
    end subroutine test_bad_contact_duplicate_reversed

    subroutine test_bad_contact_missing_friction(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_contact_missing_friction.nml', [character(len=90) :: &
            '&contact #1 (''wool'', ''cotton''): friction_coefficient is not set ' &
            // '(law ''coulomb'' needs it)'])
    end subroutine test_bad_contact_missing_friction

    subroutine test_bad_contact_unused_adhesion(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_contact_unused_adhesion.nml', [character(len=90) :: &
            '&contact #1 (''wool'', ''cotton''): adhesion = 0.05 is not used by law ' &
            // '''coulomb'' (remove it)'])
    end subroutine test_bad_contact_unused_adhesion

    subroutine test_bad_contact_decay(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_contact_decay.nml', [character(len=90) :: &
            '&contact #2 (''wool'', ''wool''): decay_start = 2.5 must be less than ' &
            // 'decay_end = 2.5'])
    end subroutine test_bad_contact_decay

    subroutine test_bad_contact_negative_friction(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_contact_negative_friction.nml', &
            [character(len=90) :: &
            '&contact #1 (''wool'', ''cotton''): friction_coefficient = -0.3 must be >= 0'])
    end subroutine test_bad_contact_negative_friction

    subroutine test_bad_contact_missing_pair(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_contact_missing_pair.nml', [character(len=80) :: &
            'no &contact for yarn types ''cotton'' and ''wool'' (they meet at node 2)', &
            '&yarn #1 and &yarn #2'])
    end subroutine test_bad_contact_missing_pair

    subroutine test_bad_scheme(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_scheme.nml', [character(len=72) :: &
            '&solver: scheme = ''implicit'' is unknown (use monolithic, staggered)'])
    end subroutine test_bad_scheme

    subroutine test_bad_min_length_ratio(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_min_length_ratio.nml', [character(len=72) :: &
            '&solver: min_length_ratio = 1.0 must lie strictly between 0 and 1'])
    end subroutine test_bad_min_length_ratio

    subroutine test_bad_duplicate_segment(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_duplicate_segment.nml', [character(len=72) :: &
            '&yarn #2: nodes(2), nodes(3) = 2, 3 join the same two nodes as &yarn #1:', &
            'duplicate segment'])
    end subroutine test_bad_duplicate_segment

    subroutine test_bad_duplicate_segment_back(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_duplicate_segment_back.nml', [character(len=72) :: &
            '&yarn #2: nodes(3), nodes(4) = 5, 2 join the same two nodes as &yarn #2:', &
            'nodes(2), nodes(3) = 2, 5: duplicate segment'])
    end subroutine test_bad_duplicate_segment_back

    subroutine test_bad_path_time_resolution(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_path_time_resolution.nml', [character(len=72) :: &
            '&solver: min_step = 1.0e-6 is below the resolution of &path time', &
            '(up to 1.0000000001e20 in magnitude, shortest knot interval'])
    end subroutine test_bad_path_time_resolution

    subroutine test_bad_elements_per_segment_huge(error)
        type(error_type), allocatable, intent(out) :: error

        call check_bad_input(error, 'bad_elements_per_segment_huge.nml', [character(len=72) :: &
            '&yarn #1: elements_per_segment = 2147483647 makes the network 4294967294', &
            'at most 59652323 elements and 715827882 nodes fit the solver'])
    end subroutine test_bad_elements_per_segment_huge

end module test_input
