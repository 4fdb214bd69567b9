! SPDX-License-Identifier: MIT
!> The force law of a &material and the friction law of a &contact group, and the
!> index of a &material by name (laws are built from the input groups one by one).
module yarnfort_scene_builder_laws
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_input_config, only: config_type, material_config_type, contact_config_type
    use yarnfort_text, only: format_real, resolve_path, quote_string
    use yarnfort_material_force_law, only: force_law_type
    use yarnfort_material_linear, only: linear_law_type, new_linear_law
    use yarnfort_material_neo_hookean, only: neo_hookean_law_type, new_neo_hookean_law
    use yarnfort_material_table, only: table_law_type, read_table_law
    use yarnfort_friction_law, only: friction_law_type
    use yarnfort_friction_coulomb, only: coulomb_law_type, new_coulomb_law
    use yarnfort_friction_adhesion, only: adhesion_law_type, new_adhesion_law
    use yarnfort_friction_decaying_adhesion, only: decaying_adhesion_law_type, &
        new_decaying_adhesion_law
    use yarnfort_friction_general, only: rate_table_law_type => table_law_type, &
        read_rate_table
    implicit none
    private

    public :: new_force_law, new_friction_law, find_material

contains

    !> The force law a &material group describes. A relative table_file is taken
    !> relative to `folder` (the input file's folder; the working directory if empty).
    subroutine new_force_law(law, material, error, folder)
        class(force_law_type), allocatable, intent(out) :: law
        type(material_config_type), intent(in) :: material
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in), optional :: folder
        type(linear_law_type) :: linear
        type(neo_hookean_law_type) :: neo
        type(table_law_type) :: table
        character(len=:), allocatable :: path

        if (trim(material%law) /= 'table') then
            call check_table_units_unset(material, error)
            if (allocated(error)) return
        end if
        select case (trim(material%law))
        case ('linear')
            call new_linear_law(linear, material%stiffness, error)
            allocate(law, source=linear)
        case ('neo_hookean')
            call new_neo_hookean_law(neo, material%modulus, material%area, error)
            allocate(law, source=neo)
        case ('table')
            path = trim(material%table_file)
            if (present(folder)) path = resolve_path(path, folder)
            if (.not. allocated(material%gauge_length)) then
                call read_table_law(table, path, error, strain_unit=trim(material%strain_unit), &
                    force_unit=trim(material%force_unit))
            else
                call read_table_law(table, path, error, strain_unit=trim(material%strain_unit), &
                    force_unit=trim(material%force_unit), gauge_length=material%gauge_length)
            end if
            allocate(law, source=table)
        case default
            call fatal_error(error, "law '" // trim(material%law) &
                // "' is unknown (use linear, neo_hookean or table)")
        end select
    end subroutine new_force_law

    !> The units of a table file are not set for another law (they would be ignored).
    subroutine check_table_units_unset(material, error)
        type(material_config_type), intent(in) :: material
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: name, text

        if (len_trim(material%strain_unit) > 0) then
            name = 'strain_unit'
            text = quote_string(trim(material%strain_unit))
        else if (len_trim(material%force_unit) > 0) then
            name = 'force_unit'
            text = quote_string(trim(material%force_unit))
        else if (allocated(material%gauge_length)) then
            name = 'gauge_length'
            text = format_real(material%gauge_length)
        else
            return
        end if
        call fatal_error(error, name // ' = ' // text // " is not used by law '" &
            // trim(material%law) // "' (only by 'table'; remove it)")
    end subroutine check_table_units_unset

    !> The friction law of a &contact group ('bonded' gets none: it never slides). A
    !> relative rate_table is taken relative to `folder` (as a &material table_file).
    subroutine new_friction_law(law, contact, error, folder)
        class(friction_law_type), allocatable, intent(out) :: law
        type(contact_config_type), intent(in) :: contact
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: folder
        type(coulomb_law_type) :: coulomb
        type(adhesion_law_type) :: adhesion
        type(decaying_adhesion_law_type) :: decaying
        type(rate_table_law_type) :: general

        select case (trim(contact%law))
        case ('bonded')
        case ('coulomb')
            call new_coulomb_law(coulomb, contact%friction_coefficient, error)
            allocate(law, source=coulomb)
        case ('adhesion')
            call new_adhesion_law(adhesion, contact%friction_coefficient, contact%adhesion, &
                error)
            allocate(law, source=adhesion)
        case ('decaying_adhesion')
            call new_decaying_adhesion_law(decaying, contact%friction_coefficient, &
                contact%adhesion, contact%decay_start, contact%decay_end, error)
            allocate(law, source=decaying)
        case ('general')
            call read_rate_table(general, resolve_path(contact%rate_table, folder), error)
            allocate(law, source=general)
        case default
            call fatal_error(error, "law '" // trim(contact%law) // "' is unknown")
        end select
    end subroutine new_friction_law

    !> The index of the &material named `name` (0 if none).
    integer function find_material(config, name) result(index)
        type(config_type), intent(in) :: config
        character(len=*), intent(in) :: name
        do index = 1, size(config%materials)
            if (trim(config%materials(index)%name) == trim(name)) return
        end do
        index = 0
    end function find_material

end module yarnfort_scene_builder_laws
