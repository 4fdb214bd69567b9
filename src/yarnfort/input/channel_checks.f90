! SPDX-License-Identifier: MIT
!> Load channels: the independent load factors of the path (`&path channels`, `factors`;
!> without them the two channels 'p_force' and 'p_disp' with their columns `p_force` and
!> `p_disp`), the channel of each &load and &support, and the checks that tie them
!> together: names defined, unique, one word and no clash with another column of
!> curve.csv; one factor per channel and knot; a nonzero load or displacement names its
!> channel when channels are given.
module yarnfort_input_channel_checks
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type, path_config_type, name_length
    use yarnfort_input_fields, only: check_name, quoted_list
    use yarnfort_input_network_checks, only: check_defined
    use yarnfort_text, only: format_integer
    use yarnfort_sort, only: sort_text_index
    implicit none
    private

    public :: get_channel_names, get_channel_factors, find_channel, check_channels
    public :: default_force_channel, default_displacement_channel, fixed_curve_columns
    public :: load_column_prefix, get_curve_columns, curve_column_length
    public :: column_fixed, column_channel, column_set, column_load

    character(len=*), parameter :: default_force_channel = 'p_force'
    character(len=*), parameter :: default_displacement_channel = 'p_disp'

    !> The columns of curve.csv that are not named after a channel, support or load.
    character(len=*), parameter :: fixed_curve_columns(13) = [character(len=17) :: &
        'step', 'time', 'strain', 'force_per_width', 'direction', 'slipping', 'held', &
        'jumped', 'passages', &
        'newton_iterations', 'residual', 'step_cuts', 'wall_time']

    !> Longest name of a curve.csv column: a support set's name and a suffix ('_rx').
    integer, parameter :: curve_column_length = name_length + 3
    !> What makes a column of curve.csv (get_curve_columns).
    integer, parameter :: column_fixed = 1, column_channel = 2, column_set = 3, column_load = 4

contains

    !> The channels of the path: the given `channels` (up to the first empty entry), or
    !> 'p_force' and 'p_disp'.
    pure function get_channel_names(path) result(names)
        type(path_config_type), intent(in) :: path
        character(len=name_length), allocatable :: names(:)
        integer :: n

        n = count_given(path)
        if (n == 0) then
            names = [character(len=name_length) :: default_force_channel, &
                default_displacement_channel]
        else
            names = path%channels(:n)
        end if
    end function get_channel_names

    !> The factor of each channel at each knot, (n_knots, n_channels).
    pure function get_channel_factors(path) result(factor)
        type(path_config_type), intent(in) :: path
        real(wp), allocatable :: factor(:, :)
        integer :: n

        n = count_given(path)
        if (n == 0) then
            factor = reshape([path%p_force, path%p_disp], [size(path%time), 2])
        else
            ! factors is one row per knot: the channels' values, in order.
            factor = transpose(reshape(path%factors, [n, size(path%time)]))
        end if
    end function get_channel_factors

    !> Index in `names` of channel `name`, or of `default_name` when `name` is empty (only
    !> without &path channels; with them an empty name has no channel); 0: not found.
    pure integer function find_channel(names, name, default_name, given) result(found)
        character(len=*), intent(in) :: names(:), name, default_name
        logical, intent(in) :: given

        if (len_trim(name) > 0) then
            found = findloc(names, name, dim=1)
        else if (given) then
            found = 0
        else
            found = findloc(names, default_name, dim=1)
        end if
    end function find_channel

    !> Number of values of &path factors (0 when unallocated).
    pure integer function n_factors(path)
        type(path_config_type), intent(in) :: path
        n_factors = 0
        if (allocated(path%factors)) n_factors = size(path%factors)
    end function n_factors

    !> Number of given channel names (entries before the first empty one).
    pure integer function count_given(path) result(n)
        type(path_config_type), intent(in) :: path

        n = findloc(path%channels == '', .true., dim=1) - 1
        if (n < 0) n = size(path%channels)
    end function count_given

    !> The prefix of the displacement columns of &load #k in curve.csv.
    pure function load_column_prefix(k) result(prefix)
        integer, intent(in) :: k
        character(len=:), allocatable :: prefix
        prefix = 'load_' // format_integer(k)
    end function load_column_prefix

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

    !> The columns of curve.csv, in order: step, time, the factor of each channel, rx, ry,
    !> rz of each support set (the &support groups, then the &obstacle groups that hold
    !> a coordinate), ux, uy, uz of each set, load_<k>_ux, _uy, _uz of each of n_loads
    !> &load groups, strain and force_per_width for a fabric, then the step's counters.
    !> What makes column j: `kind(j)` = column_fixed, column_channel (channel item(j)),
    !> column_set (set item(j)) or column_load (&load #item(j)). The one list of names:
    !> the header of the curve file is these names, and the input check finds clashes in it.
    subroutine get_curve_columns(channels, sets, n_loads, fabric, names, kind, item)
        character(len=*), intent(in) :: channels(:), sets(:)
        integer, intent(in) :: n_loads
        logical, intent(in) :: fabric
        character(len=curve_column_length), allocatable, intent(out) :: names(:)
        integer, allocatable, intent(out) :: kind(:), item(:)
        character(len=3), parameter :: suffixes(6) = ['_rx', '_ry', '_rz', '_ux', '_uy', '_uz']
        integer :: n, k, j, half

        n = size(channels) + 6 * size(sets) + 3 * n_loads + size(fixed_curve_columns)
        allocate(names(n), kind(n), item(n))
        n = 0
        call add_fixed(1, 2)
        do k = 1, size(channels)
            call add(trim(channels(k)), column_channel, k)
        end do
        do half = 0, 1
            do k = 1, size(sets)
                do j = 1, 3
                    call add(trim(sets(k)) // suffixes(3 * half + j), column_set, k)
                end do
            end do
        end do
        do k = 1, n_loads
            do j = 4, 6
                call add(load_column_prefix(k) // suffixes(j), column_load, k)
            end do
        end do
        ! fixed_curve_columns(3:4) are the fabric's.
        if (fabric) call add_fixed(3, 4)
        call add_fixed(5, size(fixed_curve_columns))
        names = names(:n)
        kind = kind(:n)
        item = item(:n)

    contains

        subroutine add(name, what, which)
            character(len=*), intent(in) :: name
            integer, intent(in) :: what, which
            n = n + 1
            names(n) = name
            kind(n) = what
            item(n) = which
        end subroutine add

        subroutine add_fixed(first, last)
            integer, intent(in) :: first, last
            integer :: i
            do i = first, last
                call add(trim(fixed_curve_columns(i)), column_fixed, 0)
            end do
        end subroutine add_fixed

    end subroutine get_curve_columns

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
