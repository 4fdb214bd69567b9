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
    use yarnfort_text, only: format_integer, parse_integer
    implicit none
    private

    public :: get_channel_names, get_channel_factors, find_channel, check_channels
    public :: default_force_channel, default_displacement_channel, fixed_curve_columns
    public :: load_column_prefix

    character(len=*), parameter :: default_force_channel = 'p_force'
    character(len=*), parameter :: default_displacement_channel = 'p_disp'

    !> The columns of curve.csv that are not named after a channel, support or load.
    character(len=*), parameter :: fixed_curve_columns(13) = [character(len=17) :: &
        'step', 'time', 'strain', 'force_per_width', 'direction', 'slipping', 'held', &
        'jumped', 'passages', &
        'newton_iterations', 'residual', 'step_cuts', 'wall_time']

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

    !> No two columns of curve.csv with one name. Support names are unique and the fixed
    !> columns end in no support suffix, so a clash needs a channel named like a fixed,
    !> support or load column (e.g. 'a_rx' with a support 'a'), or a support named like a
    !> load's columns ('load_2' with two loads): linear in the number of columns.
    subroutine check_curve_columns(config, names, error)
        type(config_type), intent(in) :: config
        character(len=*), intent(in) :: names(:)
        type(error_type), allocatable, intent(out) :: error
        character(len=3), parameter :: suffixes(6) = ['_rx', '_ry', '_rz', '_ux', '_uy', '_uz']
        integer :: k, j, n_loads, length
        character(len=:), allocatable :: name, stem

        n_loads = 0
        if (allocated(config%loads)) n_loads = size(config%loads)
        do k = 1, size(names)
            name = trim(names(k))
            length = len(name)
            if (length <= 3) cycle
            if (.not. any(suffixes == name(length - 2:))) cycle
            stem = name(:length - 3)
            if (allocated(config%supports)) then
                if (any(config%supports%name == stem)) then
                    call fatal_error(error, "curve.csv would have two columns '" // name &
                        // "' (the factor of channel " // name // " and &support '" // stem &
                        // "'): rename one")
                    return
                end if
            end if
            j = load_number(stem, n_loads)
            if (j > 0 .and. any(suffixes(4:) == name(length - 2:))) then
                call fatal_error(error, "curve.csv would have two columns '" // name &
                    // "' (the factor of channel " // name // ' and &load #' &
                    // format_integer(j) // '): rename the channel')
                return
            end if
        end do
        if (allocated(config%supports)) then
            do k = 1, size(config%supports)
                j = load_number(trim(config%supports(k)%name), n_loads)
                if (j > 0) then
                    call fatal_error(error, "curve.csv would have two columns '" &
                        // trim(config%supports(k)%name) // "_ux' (&support '" &
                        // trim(config%supports(k)%name) // "' and &load #" &
                        // format_integer(j) // '): rename the support')
                    return
                end if
            end do
        end if
    end subroutine check_curve_columns

    !> k if `text` is load_column_prefix(k) of one of n_loads loads, else 0. (A module
    !> procedure: as an internal one it needed a trampoline, so an executable stack.)
    integer function load_number(text, n_loads)
        character(len=*), intent(in) :: text
        integer, intent(in) :: n_loads
        logical :: ok

        load_number = 0
        if (index(text, 'load_') /= 1) return
        call parse_integer(text(6:), load_number, ok)
        if (.not. ok .or. load_number < 1 .or. load_number > n_loads) then
            load_number = 0
        else if (load_column_prefix(load_number) /= text) then
            load_number = 0          ! 'load_01' or 'load_+1' is no column name
        end if
    end function load_number

end module yarnfort_input_channel_checks
