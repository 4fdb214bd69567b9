! SPDX-License-Identifier: MIT
!> Checks of the load channels (yarnfort_scene_channels): names defined, unique, one word
!> and no clash with another column of curve.csv; one factor per channel and knot; a
!> nonzero load or displacement names its channel when channels are given.
module yarnfort_input_channel_checks
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type, path_config_type, name_length
    use yarnfort_input_fields, only: check_name, quoted_list
    use yarnfort_input_network_checks, only: check_defined
    use yarnfort_text, only: format_integer
    use yarnfort_sort, only: sort_text_index
    use yarnfort_scene_channels, only: get_channel_names, find_channel, count_given, &
        default_force_channel, default_displacement_channel, fixed_curve_columns, &
        get_curve_columns, curve_column_length, column_channel, column_set, column_load
    implicit none
    private

    public :: check_channels

contains

    !> Number of values of &path factors (0 when unallocated).
    pure integer function n_factors(path)
        type(path_config_type), intent(in) :: path
        n_factors = 0
        if (allocated(path%factors)) n_factors = size(path%factors)
    end function n_factors

    !> Channels of the path and of every &load and &support (after check_path: the times
    !> are known good; p_force and p_disp have one value per knot).
    subroutine check_channels(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        character(len=name_length), allocatable :: names(:)
        integer :: n, k, j, n_knots
        logical :: given

        associate(path => config%path)
            n = count_given(path)
            given = n > 0
            n_knots = size(path%time)
            k = findloc(path%channels(n + 2:) /= '', .true., dim=1)
            if (k > 0) then
                k = n + 1 + k
                call fatal_error(error, '&path: channels(' // format_integer(k) // ") = '" &
                    // trim(path%channels(k)) // "' follows the empty channels(" &
                    // format_integer(n + 1) // ') (give the names one after another)')
                return
            end if
            ! A config built in code (tests, benchmarks) may leave factors unallocated.
            if (.not. given) then
                if (n_factors(path) > 0) call fatal_error(error, '&path: factors is given ' &
                    // 'but channels is not (factors are the columns of the channels that ' &
                    // 'channels names; without channels give p_force and p_disp)')
            else if (len_trim(config%fabric%kind) > 0) then
                call fatal_error(error, '&path: channels is given with &fabric (a generated ' &
                    // "fabric is driven by the channels 'p_force' and 'p_disp': give " &
                    // 'p_force and p_disp instead)')
            else if (any(path%p_force /= 0.0_wp) .or. any(path%p_disp /= 0.0_wp)) then
                call fatal_error(error, '&path: p_force or p_disp is set together with ' &
                    // 'channels (with channels every factor comes from factors: give ' &
                    // "'p_force' / 'p_disp' as channel names if you want them)")
            else if (n_factors(path) /= n * n_knots) then
                call fatal_error(error, '&path: factors has ' // format_integer(n_factors(path)) &
                    // ' values but the ' // format_integer(n) // ' channels (' &
                    // quoted_list(path%channels(:n)) // ') at ' // format_integer(n_knots) &
                    // ' knots need ' // format_integer(n * n_knots) // ' (one row per ' &
                    // 'knot, one value per channel)')
            end if
            if (allocated(error)) return
            do k = 1, n
                call check_name(error, '&path channels(' // format_integer(k) // ')', &
                    path%channels(k))
                if (allocated(error)) return
                j = findloc(path%channels(:k - 1), path%channels(k), dim=1)
                if (j > 0) then
                    call fatal_error(error, "&path: channel '" // trim(path%channels(k)) &
                        // "' is named twice (channels(" // format_integer(j) &
                        // ') and channels(' // format_integer(k) // '))')
                    return
                end if
                if (any(fixed_curve_columns == path%channels(k))) then
                    call fatal_error(error, '&path: channels(' // format_integer(k) // ") = '" &
                        // trim(path%channels(k)) // "' is the name of another column of " &
                        // 'curve.csv (' // quoted_list(fixed_curve_columns) // '): choose ' &
                        // 'another name')
                    return
                end if
            end do
        end associate
        names = get_channel_names(config%path)
        if (allocated(config%loads)) then
            do k = 1, size(config%loads)
                call check_one('&load #' // format_integer(k), config%loads(k)%channel, &
                    default_force_channel, any(config%loads(k)%force /= 0.0_wp), 'force')
                if (allocated(error)) return
            end do
        end if
        if (allocated(config%supports)) then
            do k = 1, size(config%supports)
                call check_one("&support '" // trim(config%supports(k)%name) // "'", &
                    config%supports(k)%channel, default_displacement_channel, &
                    any(config%supports(k)%displacement /= 0.0_wp), 'displacement')
                if (allocated(error)) return
            end do
        end if
        call check_curve_columns(config, names, error)

    contains

        subroutine check_one(label, name, default_name, used, what)
            character(len=*), intent(in) :: label, name, default_name, what
            logical, intent(in) :: used

            if (len_trim(name) > 0) then
                call check_defined(error, label, 'channel', name, names, 'a channel of &path', &
                    'channels')
            else if (used .and. find_channel(names, name, default_name, given) == 0) then
                call fatal_error(error, label // ': channel is not set, and &path names its ' &
                    // 'channels (' // quoted_list(names) // '): give the channel whose ' &
                    // 'factor scales its ' // what)
            end if
        end subroutine check_one

    end subroutine check_channels

    !> No two columns of curve.csv with one name, whatever makes them (a channel named
    !> like a support's or an obstacle's column, 'a_rx' with a support 'a'; a support or
    !> obstacle named like a load's columns, 'load_2' with two loads): the columns of
    !> get_curve_columns, sorted (n log n); the message names both makers.
    subroutine check_curve_columns(config, names, error)
        type(config_type), intent(in) :: config
        character(len=*), intent(in) :: names(:)
        type(error_type), allocatable, intent(out) :: error
        character(len=curve_column_length), allocatable :: columns(:)
        character(len=name_length), allocatable :: sets(:)
        character(len=:), allocatable :: rename
        integer, allocatable :: kind(:), item(:), order(:)
        integer :: n_loads, i, first, second

        n_loads = 0
        if (allocated(config%loads)) n_loads = size(config%loads)
        sets = get_support_set_names(config)
        call get_curve_columns(names, sets, n_loads, config%fabric_support > 0, &
            config%fabric_width > 0.0_wp .and. config%fabric%boundary == 'periodic', &
            columns, kind, item)
        order = sort_text_index(columns)
        ! Of all clashes, the one whose later column comes first in the file.
        second = 0
        do i = 2, size(order)
            if (columns(order(i)) /= columns(order(i - 1))) cycle
            if (second == 0 .or. order(i) < second) then
                first = order(i - 1)
                second = order(i)
            end if
        end do
        if (second == 0) return
        ! The one to rename: a channel, else a support or obstacle (load columns are numbered).
        rename = 'one'
        if (kind(first) == column_channel .or. kind(second) == column_channel) then
            if (kind(first) /= kind(second)) rename = 'the channel'
        else if (kind(second) == column_load .and. kind(first) == column_set) then
            rename = 'the ' // trim(set_group(item(first)))
        end if
        call fatal_error(error, "curve.csv would have two columns '" // trim(columns(first)) &
            // "' (" // maker(first) // ' and ' // maker(second) // '): rename ' // rename)

    contains

        !> What makes column j of `columns`.
        function maker(j) result(text)
            integer, intent(in) :: j
            character(len=:), allocatable :: text

            select case (kind(j))
            case (column_channel)
                text = 'the factor of channel ' // trim(names(item(j)))
            case (column_set)
                text = '&' // trim(set_group(item(j))) // " '" // trim(sets(item(j))) // "'"
            case (column_load)
                text = '&load #' // format_integer(item(j))
            case default
                text = 'a column of every curve.csv'
            end select
        end function maker

        !> 'support' or 'obstacle': the group of support set s.
        function set_group(s) result(group)
            integer, intent(in) :: s
            character(len=8) :: group

            group = 'obstacle'
            if (allocated(config%supports)) then
                if (s <= size(config%supports)) group = 'support'
            end if
        end function set_group

    end subroutine check_curve_columns

    !> The names of the support sets of the scene that `config` describes: every &support,
    !> then every &obstacle with a coordinate that no &support prescribes (the scene
    !> builder holds those; the node ids must be checked).
    function get_support_set_names(config) result(sets)
        type(config_type), intent(in) :: config
        character(len=name_length), allocatable :: sets(:)
        logical, allocatable :: prescribed(:, :), held(:)
        character(len=1), parameter :: axis(3) = ['x', 'y', 'z']
        integer :: s, k

        allocate(sets(0))
        allocate(prescribed(3, size(config%node_positions, 2)), source=.false.)
        if (allocated(config%supports)) then
            sets = config%supports%name
            do s = 1, size(config%supports)
                do k = 1, 3
                    if (index(config%supports(s)%fix, axis(k)) > 0) &
                        prescribed(k, config%supports(s)%nodes) = .true.
                end do
            end do
        end if
        if (.not. allocated(config%obstacles)) return
        held = [(.not. all(prescribed(:, config%obstacles(s)%nodes)), &
            s = 1, size(config%obstacles))]
        sets = [character(len=name_length) :: sets, pack(config%obstacles%name, held)]
    end function get_support_set_names

end module yarnfort_input_channel_checks
