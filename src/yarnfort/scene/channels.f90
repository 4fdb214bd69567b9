! SPDX-License-Identifier: MIT
!> Load channels: the independent load factors of the path (`&path channels`, `factors`;
!> without them the two channels 'p_force' and 'p_disp' with their columns `p_force` and
!> `p_disp`), the channel of each &load and &support, and the columns of curve.csv. The
!> rules that the input checks (yarnfort_input_channel_checks), the scene builder and the
!> curve writer share.
module yarnfort_scene_channels
    use yarnfort_kinds, only: wp
    use yarnfort_input_config, only: path_config_type, name_length
    use yarnfort_text, only: format_integer
    implicit none
    private

    public :: get_channel_names, get_channel_factors, find_channel, count_given
    public :: default_force_channel, default_displacement_channel, fixed_curve_columns
    public :: load_column_prefix, get_curve_columns, curve_column_length
    public :: column_fixed, column_channel, column_set, column_load

    character(len=*), parameter :: default_force_channel = 'p_force'
    character(len=*), parameter :: default_displacement_channel = 'p_disp'

    !> The columns of curve.csv that are not named after a channel, support or load.
    character(len=*), parameter :: fixed_curve_columns(19) = [character(len=17) :: &
        'step', 'time', 'strain', 'force_per_width', &
        'e11', 'e22', 'gamma12', 'n11', 'n22', 'n12', 'direction', 'slipping', 'held', &
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

    !> The columns of curve.csv, in order: step, time, the factor of each channel, rx, ry,
    !> rz of each support set (the &support groups, then the &obstacle groups that hold
    !> a coordinate), ux, uy, uz of each set, load_<k>_ux, _uy, _uz of each of n_loads
    !> &load groups, strain and force_per_width for a fabric, e11 ... n12 for a periodic cell, then the step's counters.
    !> What makes column j: `kind(j)` = column_fixed, column_channel (channel item(j)),
    !> column_set (set item(j)) or column_load (&load #item(j)). The one list of names:
    !> the header of the curve file is these names, and the input check finds clashes in it.
    subroutine get_curve_columns(channels, sets, n_loads, fabric, periodic, names, kind, item)
        character(len=*), intent(in) :: channels(:), sets(:)
        integer, intent(in) :: n_loads
        logical, intent(in) :: fabric, periodic
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
        ! fixed_curve_columns(3:4) are the fabric's, (5:10) a periodic cell's membrane.
        if (fabric) call add_fixed(3, 4)
        if (periodic) call add_fixed(5, 10)
        call add_fixed(11, size(fixed_curve_columns))
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

end module yarnfort_scene_channels
