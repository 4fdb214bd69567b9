! SPDX-License-Identifier: MIT
!> Checks that the numbers of a scene stay in the range the solver can compute with:
!> lengths, squared lengths and force scales must be finite normal numbers. Values
!> outside it are input errors here, not NaN residuals in the solve.
module yarnfort_input_magnitudes
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type, name_length
    use yarnfort_scene_channels, only: get_channel_names, get_channel_factors, &
        find_channel, default_displacement_channel
    use yarnfort_text, only: format_real, format_integer
    implicit none
    private

    public :: check_scene_size, check_prescribed_reach, max_coordinate, min_scene_size

    !> Largest coordinate of a node, initial or prescribed (m): lengths and stretches are
    !> squared by the force laws, which overflows above this.
    real(wp), parameter :: max_coordinate = sqrt(huge(1.0_wp))
    !> Smallest extent of the nodes (m): below it squared lengths are no normal numbers.
    real(wp), parameter :: min_scene_size = sqrt(tiny(1.0_wp))

contains

    !> The extent and coordinates of the nodes and the force scales of the laws.
    subroutine check_scene_size(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: source
        real(wp) :: extent, reach
        integer :: m

        source = '&nodes'
        if (len_trim(config%geometry%file) > 0) source = "&geometry file '" &
            // trim(config%geometry%file) // "'"
        if (len_trim(config%fabric%kind) > 0) source = '&fabric'
        extent = maxval(maxval(config%node_positions, dim=2) &
            - minval(config%node_positions, dim=2))
        if (extent < min_scene_size) then
            call fatal_error(error, source // ': the nodes span at most ' // format_real(extent) &
                // ' m along x, y and z, below ' // format_real(min_scene_size) // ' m (lengths ' &
                // 'are squared, and their squares would not be normal numbers); give ' &
                // 'the coordinates in a unit that makes the scene larger')
            return
        end if
        reach = maxval(abs(config%node_positions))
        if (reach > max_coordinate) then
            call fatal_error(error, source // ': a coordinate of ' // format_real(reach) &
                // ' m is above ' // format_real(max_coordinate) // ' m, where squared ' &
                // 'lengths overflow')
            return
        end if
        do m = 1, size(config%materials)
            associate(material => config%materials(m))
                if (material%law /= 'neo_hookean') cycle
                ! Not set: the law's checks name the missing parameter.
                if (.not. (allocated(material%modulus) .and. allocated(material%area))) cycle
                ! The law's force scale is modulus * area, its stiffness 3 times that.
                if (.not. (3 * material%modulus * material%area <= huge(1.0_wp) &
                        .and. material%modulus * material%area >= tiny(1.0_wp))) then
                    call fatal_error(error, "&material '" // trim(material%name) &
                        // "': modulus * area = " // format_real(material%modulus) // ' * ' &
                        // format_real(material%area) // ' is not a normal number (its ' &
                        // 'force scale, in N, must lie between ' // format_real(tiny(1.0_wp)) &
                        // ' and ' // format_real(huge(1.0_wp) / 3) // ')')
                    return
                end if
            end associate
        end do
    end subroutine check_scene_size

    !> The prescribed positions: initial ones plus the factors of their channels times the
    !> displacements (after check_channels: every channel is defined).
    subroutine check_prescribed_reach(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        character(len=name_length), allocatable :: names(:)
        real(wp), allocatable :: factors(:, :)
        real(wp) :: reach, factor
        integer :: s, k, c

        if (.not. allocated(config%supports)) return
        reach = maxval(abs(config%node_positions))
        names = get_channel_names(config%path)
        factors = get_channel_factors(config%path)
        do s = 1, size(config%supports)
            associate(support => config%supports(s))
                c = find_channel(names, support%channel, default_displacement_channel, &
                    len_trim(config%path%channels(1)) > 0)
                factor = 0.0_wp
                if (c > 0) factor = maxval(abs(factors(:, c)))
                k = findloc(.not. (abs(support%displacement) * factor + reach <= max_coordinate), &
                    .true., dim=1)
                if (k > 0) then
                    call fatal_error(error, "&support '" // trim(support%name) &
                        // "': displacement(" // format_integer(k) // ') = ' &
                        // format_real(support%displacement(k)) // ' times ' &
                        // trim(names(max(c, 1))) // ' up to ' // format_real(factor) &
                        // ' moves nodes beyond ' // format_real(max_coordinate) &
                        // ' m, where squared lengths overflow')
                    return
                end if
            end associate
        end do
    end subroutine check_prescribed_reach

end module yarnfort_input_magnitudes
