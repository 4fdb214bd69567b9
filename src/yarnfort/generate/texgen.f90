! SPDX-License-Identifier: MIT
!> A periodic cell from a TexGen model file (.tg3, XML; read without TexGen), or a
!> clamped sample of copies of it.
!>
!> Proxy module over generate/texgen/: model.f90 (the file read into yarns and the
!> cell), curves.f90 (centre lines), contacts.f90 (contacts of the yarns), cell.f90
!> (the periodic cell's network) and tiling.f90 (a clamped sample of copies).
module yarnfort_generate_texgen
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: format_integer
    use yarnfort_input_config, only: fabric_config_type
    use yarnfort_generate_net_builder, only: net_builder_type
    use yarnfort_generate_xml_subset, only: xml_document_type, read_xml_file
    use yarnfort_generate_texgen_curves, only: texgen_yarn_type
    use yarnfort_generate_texgen_model, only: read_model, textile_hint, &
        check_weft_knit
    use yarnfort_generate_texgen_contacts, only: contact_type, find_contacts, &
        check_meetings
    use yarnfort_generate_texgen_cell, only: build_cell
    use yarnfort_generate_texgen_tiling, only: tile_sample
    implicit none
    private

    public :: generate_texgen

contains

    !> Fill `net` from fabric%texgen_file (relative to `folder` unless absolute); also the
    !> width across which the x force is carried (the cell's y period, or the sample's
    !> height), the support pulled along x (0 for a periodic cell), and the counts of
    !> yarns and contacts found (in the cell).
    subroutine generate_texgen(fabric, path, net, width, pulled, n_yarns, n_contacts, error)
        type(fabric_config_type), intent(in) :: fabric
        character(len=*), intent(in) :: path
        type(net_builder_type), intent(inout) :: net
        real(wp), intent(out) :: width
        integer, intent(out) :: pulled, n_yarns, n_contacts
        type(error_type), allocatable, intent(out) :: error
        type(xml_document_type) :: document
        type(texgen_yarn_type), allocatable :: yarns(:)
        type(contact_type), allocatable :: contacts(:)
        type(net_builder_type) :: unit_cell
        real(wp) :: cell(2), scale

        width = 0.0_wp
        pulled = 0
        n_yarns = 0
        n_contacts = 0
        call read_xml_file(path, document, error)
        if (allocated(error)) goto 100
        call read_model(document, fabric%texgen_samples, yarns, cell, scale, error)
        if (allocated(error)) goto 100
        call check_material_count(fabric, size(yarns), error)
        if (allocated(error)) goto 100
        n_yarns = size(yarns)
        call find_contacts(yarns, cell, fabric%texgen_contact_tolerance, contacts)
        n_contacts = size(contacts)
        if (fabric%boundary == 'clamped') then
            call build_cell(fabric, yarns, cell, scale, contacts, unit_cell, error)
            if (allocated(error)) goto 100
            call check_meetings(yarns, contacts, textile_hint(document), error)
            if (allocated(error)) goto 100
            call check_weft_knit(document, size(contacts), error)
            if (allocated(error)) goto 100
            call tile_sample(fabric, unit_cell, cell * scale, net, error)
            if (allocated(error)) goto 100
            width = fabric%cells(2) * cell(2) * scale
            pulled = 2
            return
        end if
        call build_cell(fabric, yarns, cell, scale, contacts, net, error)
        if (allocated(error)) goto 100
        ! After the cell: a yarn over several cells meets its own image, which the cell
        ! refuses in its own terms first.
        call check_meetings(yarns, contacts, textile_hint(document), error)
        if (allocated(error)) goto 100
        call check_weft_knit(document, size(contacts), error)
        if (allocated(error)) goto 100
        width = cell(2) * scale
        return
100     error%message = "texgen_file '" // trim(path) // "': " // error%message
    end subroutine generate_texgen

    !> `texgen_materials` names one material (for every yarn) or one per TexGen yarn: a
    !> shorter list gave the yarns after it the last name ('warp', 'weft' for a weave of
    !> 2 + 2 yarns made yarn 1, along x, of weft), a longer one names yarns the file lacks.
    subroutine check_material_count(fabric, n_yarns, error)
        type(fabric_config_type), intent(in) :: fabric
        integer, intent(in) :: n_yarns
        type(error_type), allocatable, intent(out) :: error
        integer :: given

        given = count(len_trim(fabric%texgen_materials) > 0)
        if (given == 1 .or. given == n_yarns) return
        call fatal_error(error, 'texgen_materials names ' // format_integer(given) &
            // ' materials for the ' // format_integer(n_yarns) // ' TexGen yarns of the ' &
            // 'file: give one name (for every yarn) or one per yarn, in TexGen''s order ' &
            // '(yarn 0, 1, ...)')
    end subroutine check_material_count

end module yarnfort_generate_texgen
