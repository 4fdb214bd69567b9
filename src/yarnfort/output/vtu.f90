! SPDX-License-Identifier: MIT
!> One VTK XML unstructured-grid file (.vtu) built in memory and written whole: the XML
!> text with its DataArrays, appended base64-encoded binary (VTK XML 1.0, UInt64 headers)
!> or inline ASCII. What goes in it is the caller's (yarnfort_output_vtk).
module yarnfort_output_vtu
    use, intrinsic :: iso_fortran_env, only: int8, int32, int64
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    use yarnfort_output_filesystem, only: rename_file, remove_file, open_new_file, &
        close_new_file
    use yarnfort_text, only: format_integer
    implicit none
    private

    public :: vtu_builder_type, start_vtu, finish_vtu, write_text_file
    public :: add_text, add_reals, add_int32
    public :: vtk_vertex, vtk_line

    !> VTK cell types.
    integer(int8), parameter :: vtk_vertex = 1_int8, vtk_line = 3_int8

    character(len=64), parameter :: base64_alphabet = &
        'ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/'

    !> The XML text and appended data of one file being built.
    type :: vtu_builder_type
        logical :: ascii = .false.
        character(len=:), allocatable :: xml, appended
    end type vtu_builder_type

contains

    !> Begin a file: the XML header up to the grid's element.
    subroutine start_vtu(vtu, ascii)
        type(vtu_builder_type), intent(out) :: vtu
        logical, intent(in) :: ascii

        vtu%ascii = ascii
        vtu%xml = '<?xml version="1.0"?>' // new_line('a') &
            // '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="' &
            // get_byte_order() // '" header_type="UInt64">' // new_line('a') &
            // '<UnstructuredGrid>' // new_line('a')
        vtu%appended = ''
    end subroutine start_vtu

    !> End a file with its points and cells (all of type `cell_type`, `per_cell`
    !> points each: `connectivity`, from 0) and write it to `path`.
    subroutine finish_vtu(vtu, points, connectivity, cell_type, per_cell, path, error)
        type(vtu_builder_type), intent(inout) :: vtu
        real(wp), intent(in) :: points(:, :)
        integer(int64), intent(in) :: connectivity(:)
        integer(int8), intent(in) :: cell_type
        integer, intent(in) :: per_cell
        character(len=*), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        integer :: n_cells, c

        n_cells = size(connectivity) / per_cell
        call add_text(vtu, '<Points>')
        call add_reals(vtu, 'Points', reshape(points, [size(points)]), 3)
        call add_text(vtu, '</Points>')
        call add_text(vtu, '<Cells>')
        call add_int64(vtu, 'connectivity', connectivity)
        call add_int64(vtu, 'offsets', [(int(per_cell, int64) * c, c = 1, n_cells)])
        call add_uint8(vtu, 'types', spread(cell_type, 1, n_cells))
        call add_text(vtu, '</Cells>')
        call add_text(vtu, '</Piece>')
        call add_text(vtu, '</UnstructuredGrid>')
        if (.not. vtu%ascii) then
            call add_text(vtu, '<AppendedData encoding="base64">')
            vtu%xml = vtu%xml // '_' // vtu%appended // new_line('a')
            call add_text(vtu, '</AppendedData>')
        end if
        call add_text(vtu, '</VTKFile>')
        call write_text_file(path, vtu%xml, error)
    end subroutine finish_vtu

    !> Write `text` to `path` (a stream, so lines of any length), checking every write
    !> and the close; with `atomic`, through path.tmp renamed over path. On failure the
    !> incomplete file is removed.
    subroutine write_text_file(path, text, error, atomic)
        character(len=*), intent(in) :: path, text
        type(error_type), allocatable, intent(out) :: error
        logical, intent(in), optional :: atomic
        type(error_type), allocatable :: ignored
        character(len=:), allocatable :: target
        character(len=256) :: message
        integer :: unit, status
        logical :: through_temporary

        through_temporary = .false.
        if (present(atomic)) through_temporary = atomic
        target = path
        if (through_temporary) target = path // '.tmp'
        call open_new_file(unit, target, error, stream=.true.)
        if (allocated(error)) then
            call remove_file(target, ignored)
            return
        end if
        message = ''
        write(unit, iostat=status, iomsg=message) text
        call close_new_file(unit, target, error, status, message)
        if (allocated(error) .or. .not. through_temporary) return
        call rename_file(target, path, error)
        if (allocated(error)) call remove_file(target, ignored)
    end subroutine write_text_file

    subroutine add_text(vtu, text)
        type(vtu_builder_type), intent(inout) :: vtu
        character(len=*), intent(in) :: text
        vtu%xml = vtu%xml // text // new_line('a')
    end subroutine add_text

    !> The DataArray element of an array: `values` inline as ASCII, or an offset into the
    !> appended data (where the byte count and `bytes`, their binary form, go, each
    !> base64-encoded).
    subroutine add_array(vtu, type_name, label, components, n_tuples, field, bytes, values)
        type(vtu_builder_type), intent(inout) :: vtu
        character(len=*), intent(in) :: type_name, label
        integer, intent(in) :: components, n_tuples
        logical, intent(in) :: field
        integer(int8), intent(in) :: bytes(:)
        class(*), intent(in) :: values(:)
        character(len=:), allocatable :: attributes

        attributes = '<DataArray type="' // type_name // '" Name="' // label // '"'
        if (components > 1) attributes = attributes // ' NumberOfComponents="' &
            // format_integer(components) // '"'
        if (field) attributes = attributes // ' NumberOfTuples="' &
            // format_integer(n_tuples) // '"'
        if (vtu%ascii) then
            call add_text(vtu, attributes // ' format="ascii">' // format_values(values) &
                // '</DataArray>')
        else
            call add_text(vtu, attributes // ' format="appended" offset="' &
                // format_integer(len(vtu%appended)) // '"/>')
            vtu%appended = vtu%appended &
                // encode_base64(transfer(int(size(bytes), int64), [0_int8])) &
                // encode_base64(bytes)
        end if
    end subroutine add_array

    subroutine add_reals(vtu, label, values, components, field)
        type(vtu_builder_type), intent(inout) :: vtu
        character(len=*), intent(in) :: label
        real(wp), intent(in) :: values(:)
        integer, intent(in) :: components
        logical, intent(in), optional :: field

        call add_array(vtu, 'Float64', label, components, size(values) / components, &
            is_field(field), transfer(values, [0_int8], 8 * size(values)), values)
    end subroutine add_reals

    subroutine add_int32(vtu, label, values, field)
        type(vtu_builder_type), intent(inout) :: vtu
        character(len=*), intent(in) :: label
        integer(int32), intent(in) :: values(:)
        logical, intent(in), optional :: field

        call add_integers(vtu, 'Int32', label, int(values, int64), &
            transfer(values, [0_int8], 4 * size(values)), field)
    end subroutine add_int32

    subroutine add_int64(vtu, label, values)
        type(vtu_builder_type), intent(inout) :: vtu
        character(len=*), intent(in) :: label
        integer(int64), intent(in) :: values(:)

        call add_integers(vtu, 'Int64', label, values, transfer(values, [0_int8], 8 * size(values)))
    end subroutine add_int64

    subroutine add_uint8(vtu, label, values)
        type(vtu_builder_type), intent(inout) :: vtu
        character(len=*), intent(in) :: label
        integer(int8), intent(in) :: values(:)

        call add_integers(vtu, 'UInt8', label, int(values, int64), values)
    end subroutine add_uint8

    !> An integer array of VTK type `type_name`: `values` in ASCII, or `bytes`, their
    !> binary form in that type, appended.
    subroutine add_integers(vtu, type_name, label, values, bytes, field)
        type(vtu_builder_type), intent(inout) :: vtu
        character(len=*), intent(in) :: type_name, label
        integer(int64), intent(in) :: values(:)
        integer(int8), intent(in) :: bytes(:)
        logical, intent(in), optional :: field

        call add_array(vtu, type_name, label, 1, size(values), is_field(field), bytes, values)
    end subroutine add_integers

    !> The ASCII form of a DataArray: ' v1 v2 ...', reals as es24.16e3, integers as i0.
    function format_values(values) result(text)
        class(*), intent(in) :: values(:)
        character(len=:), allocatable :: text
        integer :: status

        select type (values)
        type is (real(wp))
            allocate(character(len=25 * size(values) + 1) :: text)
            write(text, '(*(1x, es24.16e3))', iostat=status) values
        type is (integer(int64))
            allocate(character(len=21 * size(values) + 1) :: text)
            write(text, '(*(1x, i0))', iostat=status) values
        end select
        text = trim(text)
    end function format_values

    pure logical function is_field(field)
        logical, intent(in), optional :: field
        is_field = .false.
        if (present(field)) is_field = field
    end function is_field

    !> Base64 (RFC 4648, with '=' padding) of `bytes`.
    pure function encode_base64(bytes) result(text)
        integer(int8), intent(in) :: bytes(:)
        character(len=:), allocatable :: text
        integer :: i, j, n, b1, b2, b3, group

        n = size(bytes)
        allocate(character(len=4 * ((n + 2) / 3)) :: text)
        j = 0
        do i = 1, n, 3
            b1 = iand(int(bytes(i)), 255)
            b2 = 0
            b3 = 0
            if (i + 1 <= n) b2 = iand(int(bytes(i + 1)), 255)
            if (i + 2 <= n) b3 = iand(int(bytes(i + 2)), 255)
            group = ior(ior(ishft(b1, 16), ishft(b2, 8)), b3)
            text(j + 1:j + 1) = base64_alphabet(ishft(group, -18) + 1:ishft(group, -18) + 1)
            text(j + 2:j + 2) = base64_alphabet(iand(ishft(group, -12), 63) + 1: &
                iand(ishft(group, -12), 63) + 1)
            text(j + 3:j + 3) = base64_alphabet(iand(ishft(group, -6), 63) + 1: &
                iand(ishft(group, -6), 63) + 1)
            text(j + 4:j + 4) = base64_alphabet(iand(group, 63) + 1:iand(group, 63) + 1)
            if (i + 1 > n) text(j + 3:j + 3) = '='
            if (i + 2 > n) text(j + 4:j + 4) = '='
            j = j + 4
        end do
    end function encode_base64

    !> 'LittleEndian' or 'BigEndian': the byte order of this machine.
    pure function get_byte_order() result(order)
        character(len=:), allocatable :: order
        integer(int8) :: bytes(4)
        bytes = transfer(1_int32, bytes)
        if (bytes(1) == 1_int8) then
            order = 'LittleEndian'
        else
            order = 'BigEndian'
        end if
    end function get_byte_order

end module yarnfort_output_vtu
