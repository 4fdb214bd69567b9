! SPDX-License-Identifier: MIT
!> The &fabric group: check its parameters and generate the fabric's nodes, yarns,
!> supports and links into the configuration (knitted: yarnfort_generate_knit; woven:
!> yarnfort_generate_woven; TexGen: yarnfort_generate_texgen). Called by the program and
!> the Python entry between reading the input and checking it; the input layer never
!> calls it.
module yarnfort_generate_fabric
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type
    use yarnfort_input_groups, only: fabric_kind_choices, fabric_boundary_choices, &
        fabric_sides_choices, fabric_lateral_control_choices, fabric_axial_control_choices, &
        fabric_config_type
    use yarnfort_input_fields, only: check_range
    use yarnfort_input_network_checks, only: coincidence_tolerance
    use yarnfort_generate_net_builder, only: net_builder_type
    use yarnfort_generate_knit, only: generate_knit
    use yarnfort_generate_woven, only: generate_woven
    use yarnfort_generate_texgen, only: generate_texgen
    use yarnfort_text, only: resolve_path, join_names, format_real, format_integer
    implicit none
    private

    public :: generate_fabric

    !> Most generated nodes (a guard against a typo such as cells = 40000, 40000).
    integer, parameter :: max_generated_cells = 1000000

contains

    subroutine generate_fabric(config, error)
        type(config_type), intent(inout) :: config
        type(error_type), allocatable, intent(out) :: error
        type(net_builder_type) :: net
        real(wp) :: width
        integer :: pulled

        if (len_trim(config%fabric%kind) == 0) return
        call check_fabric(config, error)
        if (allocated(error)) return
        select case (trim(config%fabric%kind))
        case ('knit')
            call generate_knit(config%fabric, net, width, pulled)
        case ('texgen')
            call generate_texgen(config%fabric, resolve_path(trim(config%fabric%texgen_file), &
                trim(config%input_folder)), net, width, pulled, config%texgen_yarns, &
                config%texgen_contacts, error)
            if (allocated(error)) then
                error%message = '&fabric: ' // error%message
                return
            end if
        case default
            call generate_woven(config%fabric, net, width, pulled)
        end select
        call net%hand_over(config)
        config%fabric_width = width
        config%fabric_support = pulled
    end subroutine generate_fabric

    subroutine check_fabric(config, error)
        type(config_type), intent(in) :: config
        type(error_type), allocatable, intent(out) :: error
        character(len=*), parameter :: label = '&fabric: '
        character(len=200) :: buffer
        integer :: k

        associate(fabric => config%fabric)
            call require_choice(error, 'kind', fabric%kind, fabric_kind_choices)
            if (allocated(error)) return
            call require_choice(error, 'boundary', fabric%boundary, fabric_boundary_choices)
            if (allocated(error)) return
            call require_choice(error, 'sides', fabric%sides, fabric_sides_choices)
            if (allocated(error)) return
            call check_lateral_control(error)
            if (allocated(error)) return
            call check_axial_control(error)
            if (allocated(error)) return
            call require_range(error, 'shear', fabric%shear, -10.0_wp, 10.0_wp)
            if (allocated(error)) return
            ! Only a periodic cell has a y period to tilt; a clamped sample's shear would
            ! need its edges moved, which no support set here does.
            if (fabric%shear /= 0.0_wp .and. fabric%boundary /= 'periodic') then
                call fatal_error(error, label // 'shear = ' // format_real(fabric%shear) &
                    // " needs boundary = 'periodic' (it tilts the y period of a periodic " &
                    // 'cell; a clamped sample cannot be sheared)')
                return
            end if
            ! The shear follows p_disp, which under a held x force scales that force.
            if (fabric%shear /= 0.0_wp .and. fabric%axial_control == 'force') then
                call fatal_error(error, label // 'shear = ' // format_real(fabric%shear) &
                    // " needs axial_control = 'strain' (under 'force' p_disp scales the " &
                    // 'force n11 held, not a deformation)')
                return
            end if
            if (fabric%kind == 'texgen') then
                call require_range(error, 'strain', fabric%strain, -0.9_wp, 100.0_wp)
                if (allocated(error)) return
                call require_range(error, 'lateral_strain', fabric%lateral_strain, -0.9_wp, &
                    100.0_wp)
                if (allocated(error)) return
                call require_count(error, 'elements_per_segment', fabric%elements_per_segment, &
                    1, 1000)
                if (allocated(error)) return
                call forbid_depth(error)
                if (allocated(error)) return
                call check_texgen(error)
                return
            end if
            call check_cells(error)
            if (allocated(error)) return
            if (.not. all(fabric%spacing > 0.0_wp .and. fabric%spacing < huge(1.0_wp))) then
                write(buffer, '(a, "spacing = ", g0, ", ", g0, " must be two positive lengths (m)")') &
                    label, fabric%spacing
                call fatal_error(error, trim(buffer))
                return
            end if
            call require_range(error, 'strain', fabric%strain, -0.9_wp, 100.0_wp)
            if (allocated(error)) return
            call require_range(error, 'lateral_strain', fabric%lateral_strain, -0.9_wp, 100.0_wp)
            if (allocated(error)) return
            if (real(fabric%cells(1), wp) * fabric%cells(2) * fabric%elements_per_segment &
                    > max_generated_cells) then
                write(buffer, '(a, "cells = ", i0, ", ", i0, " with elements_per_segment = ", &
                    & i0, " makes too large a network (cells times elements_per_segment at ", &
                    & "most ", i0, ")")') label, fabric%cells, fabric%elements_per_segment, &
                    max_generated_cells
                call fatal_error(error, trim(buffer))
                return
            end if
            call require_count(error, 'elements_per_segment', fabric%elements_per_segment, 1)
            if (allocated(error)) return

            call forbid_name(error, 'texgen_file', fabric%texgen_file)
            if (allocated(error)) return
            call forbid_name(error, 'texgen_materials', fabric%texgen_materials(1))
            if (allocated(error)) return
            if (fabric%kind == 'knit') then
                call require_material(error, 'knit_material', fabric%knit_material, .true.)
                if (allocated(error)) return
                call require_material(error, 'inlay_material', fabric%inlay_material, .false.)
                if (allocated(error)) return
                call require_material(error, 'edge_material', fabric%edge_material, .false.)
                if (allocated(error)) return
                if (len_trim(fabric%edge_material) > 0 .and. .not. (fabric%boundary == &
                        'clamped' .and. fabric%sides == 'free')) then
                    call fatal_error(error, label // "edge_material applies to a clamped " &
                        // "knit with sides = 'free' (the threads that close its edge courses)")
                    return
                end if
                call require_range(error, 'head_width', fabric%head_width, 0.05_wp, 0.95_wp)
                if (allocated(error)) return
                if (.not. (fabric%knit_depth >= 0.0_wp .and. &
                        fabric%knit_depth < minval(fabric%spacing))) then
                    write(buffer, '(a, "knit_depth = ", g0, " must be 0 (a planar knit) or ", &
                        & "positive and smaller than the spacing (m)")') label, fabric%knit_depth
                    call fatal_error(error, trim(buffer))
                    return
                end if
                if (len_trim(fabric%inlay_material) > 0) then
                    call require_range(error, 'inlay_offset', fabric%inlay_offset, 0.05_wp, &
                        0.95_wp)
                    if (allocated(error)) return
                    call require_count(error, 'inlay_every', fabric%inlay_every, 1)
                    if (allocated(error)) return
                end if
                call forbid_woven_materials(error)
                if (allocated(error)) return
                if (len_trim(fabric%inlay_material) > 0) then
                    call check_gap(error)
                    if (allocated(error)) return
                else if (allocated(fabric%gap)) then
                    call fatal_error(error, label // 'gap applies to woven fabrics and to ' &
                        // 'the inlay of a knit; this knit has no inlay_material')
                    return
                else if (fabric%knit_depth > 0.0_wp) then
                    ! The loop contacts' gap-holders take the gap factor.
                    call check_gap_table(error, below_spacing=.false.)
                    if (allocated(error)) return
                else if (size(fabric%gap_factor) > 0) then
                    call fatal_error(error, label // 'gap and gap_factor apply to woven ' &
                        // 'fabrics, to the inlay of a knit and to a three-dimensional knit ' &
                        // '(knit_depth > 0); this planar knit has no inlay_material')
                    return
                end if
                if (fabric%knit_depth > 0.0_wp .and. any(fabric%gap_factor * fabric%knit_depth &
                        >= minval(fabric%spacing))) then
                    call fatal_error(error, label // 'gap_factor must keep knit_depth * ' &
                        // 'factor below the spacing')
                    return
                end if
            else
                call require_material(error, 'warp_material', fabric%warp_material, .true.)
                if (allocated(error)) return
                call require_material(error, 'weft_material', fabric%weft_material, .true.)
                if (allocated(error)) return
                call forbid_knit_materials(error)
                if (allocated(error)) return
                call forbid_depth(error)
                if (allocated(error)) return
                call check_gap(error)
                if (allocated(error)) return
                if (fabric%boundary == 'periodic') call check_repeat(error)
                if (allocated(error)) return
            end if
        end associate
    contains

        !> A held lateral force or force ratio replaces the lateral strain of a periodic cell.
        subroutine check_lateral_control(error)
            type(error_type), allocatable, intent(out) :: error

            associate(fabric => config%fabric)
                call require_choice(error, 'lateral_control', fabric%lateral_control, &
                    fabric_lateral_control_choices)
                if (allocated(error)) return
                call require_range(error, 'lateral_force', fabric%lateral_force, 0.0_wp, &
                    huge(1.0_wp))
                if (allocated(error)) return
                call require_range(error, 'force_ratio', fabric%force_ratio, 0.0_wp, 100.0_wp)
                if (allocated(error)) return
                if (fabric%lateral_control == 'strain') return
                if (fabric%boundary /= 'periodic') then
                    call fatal_error(error, label // "lateral_control = '" &
                        // trim(fabric%lateral_control) // "' needs boundary = 'periodic' " &
                        // '(it holds the y period of a periodic cell)')
                else if (fabric%lateral_strain /= 0.0_wp) then
                    call fatal_error(error, label // 'lateral_strain = ' &
                        // format_real(fabric%lateral_strain) // " is given with " &
                        // "lateral_control = '" // trim(fabric%lateral_control) &
                        // "' (the y period then follows the force: leave lateral_strain out)")
                end if
            end associate
        end subroutine check_lateral_control

        !> A held x force replaces the x strain of a periodic cell.
        subroutine check_axial_control(error)
            type(error_type), allocatable, intent(out) :: error
            type(fabric_config_type) :: defaults

            associate(fabric => config%fabric)
                call require_choice(error, 'axial_control', fabric%axial_control, &
                    fabric_axial_control_choices)
                if (allocated(error)) return
                if (fabric%axial_control == 'strain') then
                    if (fabric%axial_force /= defaults%axial_force) &
                        call fatal_error(error, label // 'axial_force = ' &
                        // format_real(fabric%axial_force) // " is given with axial_control = " &
                        // "'strain' (it is the x force held under axial_control = 'force')")
                    return
                end if
                if (fabric%boundary /= 'periodic') then
                    call fatal_error(error, label // "axial_control = 'force' needs boundary " &
                        // "= 'periodic' (it holds the x period of a periodic cell)")
                else if (fabric%strain /= defaults%strain) then
                    call fatal_error(error, label // 'strain = ' // format_real(fabric%strain) &
                        // " is given with axial_control = 'force' (the x period then follows " &
                        // 'the force: leave strain out)')
                else
                    call check_range(error, '&fabric', 'axial_force', fabric%axial_force, &
                        fabric%axial_force > 0.0_wp .and. fabric%axial_force <= huge(1.0_wp), &
                        "must be a positive force (N/m): axial_control = 'force' holds n11 at " &
                        // 'p_disp * axial_force, and a string network carries no compression; ' &
                        // 'at n11 = 0 the cell collapses along x')
                end if
            end associate
        end subroutine check_axial_control
        !> A finite real in [low, high] (the message by the input's generic range check).
        subroutine require_range(error, variable, value, low, high)
            type(error_type), allocatable, intent(out) :: error
            character(len=*), intent(in) :: variable
            real(wp), intent(in) :: value, low, high
            call check_range(error, '&fabric', variable, value, value >= low .and. &
                value <= high, 'must lie in [' // format_real(low) // ', ' &
                // format_real(high) // ']')
        end subroutine require_range

        !> An integer in [low, high], or at least `low` without `high`.
        subroutine require_count(error, variable, value, low, high)
            type(error_type), allocatable, intent(out) :: error
            character(len=*), intent(in) :: variable
            integer, intent(in) :: value, low
            integer, intent(in), optional :: high
            if (present(high)) then
                call check_range(error, '&fabric', variable, value, value >= low .and. &
                    value <= high, 'must lie in [' // format_integer(low) // ', ' &
                    // format_integer(high) // ']')
            else
                call check_range(error, '&fabric', variable, value, value >= low, &
                    'must be at least ' // format_integer(low))
            end if
        end subroutine require_count

        subroutine require_material(error, variable, name, required)
            type(error_type), allocatable, intent(out) :: error
            character(len=*), intent(in) :: variable, name
            logical, intent(in) :: required
            if (len_trim(name) == 0) then
                if (required) call fatal_error(error, label // variable // ' is required for ' &
                    // "kind = '" // trim(config%fabric%kind) // "'")
                return
            end if
            do k = 1, size(config%materials)
                if (trim(config%materials(k)%name) == trim(name)) return
            end do
            call fatal_error(error, label // variable // " = '" // trim(name) &
                // "' is not the name of any &material")
        end subroutine require_material

        !> The TexGen route: a file, materials by yarn index, the search settings; the
        !> pattern variables of the built-in generators do not apply.
        subroutine check_texgen(error)
            type(error_type), allocatable, intent(out) :: error
            integer :: given, m
            associate(fabric => config%fabric)
                if (len_trim(fabric%texgen_file) == 0) then
                    call fatal_error(error, label // "texgen_file is required for kind = 'texgen'")
                    return
                end if
                if (fabric%boundary == 'clamped') call check_cells(error)
                if (allocated(error)) return
                given = 0
                do m = 1, size(fabric%texgen_materials)
                    if (len_trim(fabric%texgen_materials(m)) == 0) cycle
                    if (m > given + 1) then
                        write(buffer, '(a, "texgen_materials(", i0, ") is given but ", &
                            & "texgen_materials(", i0, ") is not: give them in yarn order")') &
                            label, m, given + 1
                        call fatal_error(error, trim(buffer))
                        return
                    end if
                    given = m
                    write(buffer, '("texgen_materials(", i0, ")")') m
                    call require_material(error, trim(buffer), fabric%texgen_materials(m), &
                        .true.)
                    if (allocated(error)) return
                end do
                if (given == 0) then
                    call fatal_error(error, label // "texgen_materials is required for kind " &
                        // "= 'texgen' (the &material of each TexGen yarn, by index)")
                    return
                end if
                call require_range(error, 'texgen_contact_tolerance', &
                    fabric%texgen_contact_tolerance, 0.0_wp, 1.0_wp)
                if (allocated(error)) return
                call require_count(error, 'texgen_samples', fabric%texgen_samples, 2, 1000)
                if (allocated(error)) return
                call forbid_knit_materials(error)
                if (allocated(error)) return
                call forbid_woven_materials(error)
                if (allocated(error)) return
                if (allocated(fabric%gap)) then
                    call fatal_error(error, label // "gap does not apply to kind = 'texgen' " &
                        // '(the holders take the distances of the model; gap_factor scales ' &
                        // 'them)')
                    return
                end if
                call check_gap_table(error, below_spacing=.false.)
            end associate
        end subroutine check_texgen


        subroutine forbid_depth(error)
            type(error_type), allocatable, intent(out) :: error
            if (config%fabric%knit_depth == 0.0_wp) return
            call fatal_error(error, label // "knit_depth does not apply to kind = '" &
                // trim(config%fabric%kind) // "'")
        end subroutine forbid_depth

        subroutine forbid_name(error, variable, name)
            type(error_type), allocatable, intent(out) :: error
            character(len=*), intent(in) :: variable, name
            if (len_trim(name) == 0) return
            call fatal_error(error, label // variable // " does not apply to kind = '" &
                // trim(config%fabric%kind) // "'")
        end subroutine forbid_name

        !> None of the knit's materials (outside kind = 'knit').
        subroutine forbid_knit_materials(error)
            type(error_type), allocatable, intent(out) :: error
            call forbid_name(error, 'knit_material', config%fabric%knit_material)
            if (allocated(error)) return
            call forbid_name(error, 'inlay_material', config%fabric%inlay_material)
            if (allocated(error)) return
            call forbid_name(error, 'edge_material', config%fabric%edge_material)
        end subroutine forbid_knit_materials

        !> None of the weave's materials (outside the woven kinds).
        subroutine forbid_woven_materials(error)
            type(error_type), allocatable, intent(out) :: error
            call forbid_name(error, 'warp_material', config%fabric%warp_material)
            if (allocated(error)) return
            call forbid_name(error, 'weft_material', config%fabric%weft_material)
        end subroutine forbid_woven_materials

        !> `value` must be one of `choices` (named in the message as "a, b or c").
        subroutine require_choice(error, variable, value, choices)
            type(error_type), allocatable, intent(out) :: error
            character(len=*), intent(in) :: variable, value, choices(:)
            if (any(choices == value)) return
            call fatal_error(error, label // variable // " = '" // trim(value) &
                // "' is unknown (use " // join_names(choices, '', ' or ') // ')')
        end subroutine require_choice

        !> At least one cell each way, and not too many in all.
        subroutine check_cells(error)
            type(error_type), allocatable, intent(out) :: error
            associate(cells => config%fabric%cells)
                if (all(cells >= 1) .and. real(cells(1), wp) * cells(2) <= max_generated_cells) &
                    return
                write(buffer, '(a, "cells = ", i0, ", ", i0, " must be at least 1 and at most ", &
                    & i0, " in all")') label, cells, max_generated_cells
            end associate
            call fatal_error(error, trim(buffer))
        end subroutine check_cells

        subroutine check_gap(error)
            type(error_type), allocatable, intent(out) :: error
            if (.not. allocated(config%fabric%gap)) then
                call fatal_error(error, label // 'gap is required (the distance between the ' &
                    // 'axes of two crossing yarns, m)')
                return
            end if
            if (.not. (config%fabric%gap > 0.0_wp .and. &
                    config%fabric%gap < minval(config%fabric%spacing))) then
                write(buffer, '(a, "gap = ", g0, " must be positive and smaller than the ", &
                    & "yarn spacing (m)")') label, config%fabric%gap
                call fatal_error(error, trim(buffer))
                return
            end if
            call check_gap_table(error, below_spacing=.true.)
        end subroutine check_gap

        !> A periodic weave must hold whole repeats of its pattern.
        subroutine check_repeat(error)
            type(error_type), allocatable, intent(out) :: error
            integer :: repeat
            repeat = merge(4, 2, config%fabric%kind == 'twill')
            if (all(mod(config%fabric%cells, repeat) == 0)) return
            write(buffer, '(a, "cells = ", i0, ", ", i0, " must be multiples of ", i0, &
                & " for a periodic ", a, " cell")') label, config%fabric%cells, repeat, &
                trim(config%fabric%kind)
            call fatal_error(error, trim(buffer))
        end subroutine check_repeat

        !> The gap-factor table: knots increasing and finite, factors positive (and, where
        !> a gap is given, keeping it below the yarn spacing).
        subroutine check_gap_table(error, below_spacing)
            type(error_type), allocatable, intent(out) :: error
            logical, intent(in) :: below_spacing
            associate(p => config%fabric%gap_factor_p_disp, f => config%fabric%gap_factor)
                if (size(p) /= size(f)) then
                    write(buffer, '(a, "gap_factor_p_disp has ", i0, " values but gap_factor ", &
                        & "has ", i0)') label, size(p), size(f)
                    call fatal_error(error, trim(buffer))
                    return
                end if
                do k = 2, size(p)
                    if (.not. (p(k) > p(k - 1))) then
                        write(buffer, '(a, "gap_factor_p_disp must increase strictly: value ", &
                            & i0, " (", g0, ") follows ", g0)') label, k, p(k), p(k - 1)
                        call fatal_error(error, trim(buffer))
                        return
                    end if
                end do
                ! A holder gap * factor shorter than coincidence_tolerance * gap is a zero
                ! length by the rule for elements (the gap is below the scene's size): the
                ! holder collapses its two nodes (docs/decisions.md, Smallest gap factor).
                k = findloc(f > 0.0_wp .and. f < coincidence_tolerance, .true., dim=1)
                if (k > 0) then
                    call fatal_error(error, label // 'gap_factor(' // format_integer(k) &
                        // ') = ' // format_real(f(k)) // ' is below ' &
                        // format_real(coincidence_tolerance) // ' (100 * epsilon): it ' &
                        // 'collapses the gap-holders to zero length (give a factor that ' &
                        // 'keeps a gap)')
                    return
                end if
                if (.not. below_spacing) then
                    if (any(.not. (f > 0.0_wp .and. f < huge(1.0_wp)))) then
                        call fatal_error(error, label // 'gap_factor values must be positive ' &
                            // 'and finite')
                        return
                    end if
                end if
                do k = 1, merge(size(f), 0, below_spacing)
                    if (.not. (f(k) > 0.0_wp .and. f(k) * config%fabric%gap &
                            < minval(config%fabric%spacing))) then
                        write(buffer, '(a, "gap_factor value ", i0, " (", g0, ") must be ", &
                            & "positive and keep the gap below the yarn spacing")') &
                            label, k, f(k)
                        call fatal_error(error, trim(buffer))
                        return
                    end if
                end do
                if (any(p /= p) .or. any(abs(p) > huge(1.0_wp))) then
                    call fatal_error(error, label // 'gap_factor_p_disp must be finite')
                end if
            end associate
        end subroutine check_gap_table
    end subroutine check_fabric

end module yarnfort_generate_fabric
