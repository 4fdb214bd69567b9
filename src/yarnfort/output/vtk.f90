! SPDX-License-Identifier: MIT
!> Network states as VTK XML unstructured grids (.vtu, one per step) for ParaView, and a
!> states.pvd collection listing them with their pseudo-time.
module yarnfort_output_vtk
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_continuation, only: step_state_type
    implicit none
    private

    public :: vtk_writer_type

    type :: vtk_writer_type
        character(len=:), allocatable :: folder
        !> Files written so far and their times, for the collection file.
        character(len=32), allocatable :: files(:)
        real(wp), allocatable :: times(:)
    contains
        procedure :: write_state
        !> Delete the states a previous run listed in folder/states.pvd.
        procedure :: remove_previous
        !> Keep the states of folder/states.pvd up to a step, delete the later ones.
        procedure :: resume => resume_states
    end type vtk_writer_type

    integer, parameter :: vtk_line = 3

contains

    !> Write state_<step>.vtu with node positions and, per element, tension (N),
    !> stretch and reference length L0; then rewrite states.pvd.
    subroutine write_state(self, scene, state, error)
        class(vtk_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        type(error_type), allocatable, intent(out) :: error
        character(len=32) :: name
        integer :: unit, status, n_nodes, n_elements, e

        write(name, '("state_", i5.5, ".vtu")') state%step
        open(newunit=unit, file=self%folder // '/' // trim(name), status='replace', &
            action='write', iostat=status)
        if (status /= 0) then
            call fatal_error(error, "cannot write '" // self%folder // '/' // trim(name) // "'")
            return
        end if
        n_nodes = size(state%position, 2)
        n_elements = size(state%tension)
        write(unit, '(a)') '<?xml version="1.0"?>'
        write(unit, '(a)') '<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">'
        write(unit, '(a)') '<UnstructuredGrid>'
        write(unit, '(a, i0, a, i0, a)') '<Piece NumberOfPoints="', n_nodes, &
            '" NumberOfCells="', n_elements, '">'
        write(unit, '(a)') '<Points><DataArray type="Float64" NumberOfComponents="3" format="ascii">'
        write(unit, '(3(1x, es24.16e3))') state%position
        write(unit, '(a)') '</DataArray></Points>'
        write(unit, '(a)') '<Cells><DataArray type="Int64" Name="connectivity" format="ascii">'
        write(unit, '(2(i0, 1x))') (scene%network%element_nodes(:, e) - 1, e = 1, n_elements)
        write(unit, '(a)') '</DataArray><DataArray type="Int64" Name="offsets" format="ascii">'
        write(unit, '(10(i0, 1x))') (2 * e, e = 1, n_elements)
        write(unit, '(a)') '</DataArray><DataArray type="UInt8" Name="types" format="ascii">'
        write(unit, '(20(i0, 1x))') (vtk_line, e = 1, n_elements)
        write(unit, '(a)') '</DataArray></Cells>'
        write(unit, '(a)') '<CellData Scalars="tension">'
        call write_cell_array('tension', state%tension)
        call write_cell_array('stretch', state%stretch)
        call write_cell_array('L0', state%length0)
        write(unit, '(a)') '</CellData>'
        write(unit, '(a)') '</Piece></UnstructuredGrid></VTKFile>'
        close(unit)

        if (.not. allocated(self%files)) allocate(self%files(0), self%times(0))
        self%files = [self%files, name]
        self%times = [self%times, state%time]
        call write_collection(self, error)
    contains
        subroutine write_cell_array(label, values)
            character(len=*), intent(in) :: label
            real(wp), intent(in) :: values(:)
            write(unit, '(a)') '<DataArray type="Float64" Name="' // label // '" format="ascii">'
            write(unit, '(4(1x, es24.16e3))') values
            write(unit, '(a)') '</DataArray>'
        end subroutine write_cell_array
    end subroutine write_state

    subroutine remove_previous(self)
        class(vtk_writer_type), intent(in) :: self
        character(len=1024) :: line
        character(len=:), allocatable :: name
        integer :: unit, status, old

        open(newunit=unit, file=self%folder // '/states.pvd', status='old', action='read', &
            iostat=status)
        if (status /= 0) return
        do
            read(unit, '(a)', iostat=status) line
            if (status /= 0) exit
            name = get_attribute(line, 'file')
            ! Only plain file names written by this writer (no paths).
            if (len(name) == 0 .or. index(name, '/') > 0) cycle
            open(newunit=old, file=self%folder // '/' // name, status='old', iostat=status)
            if (status == 0) close(old, status='delete')
        end do
        close(unit, status='delete')
    end subroutine remove_previous

    !> Continue the states of folder/states.pvd after `step` (a restart): keep the
    !> listed states of steps up to `step`, delete the files of later ones, and rewrite
    !> the collection with the kept ones. No states.pvd: no states to keep.
    subroutine resume_states(self, step, error)
        class(vtk_writer_type), intent(inout) :: self
        integer, intent(in) :: step
        type(error_type), allocatable, intent(out) :: error
        character(len=1024) :: line
        character(len=:), allocatable :: name, value
        integer :: unit, status, old, state_step
        real(wp) :: time

        allocate(self%files(0), self%times(0))
        open(newunit=unit, file=self%folder // '/states.pvd', status='old', action='read', &
            iostat=status)
        if (status /= 0) return
        do
            read(unit, '(a)', iostat=status) line
            if (status /= 0) exit
            name = get_attribute(line, 'file')
            ! Only the plain state_NNNNN.vtu names written by this writer.
            if (len(name) /= len('state_00000.vtu') .or. name(1:6) /= 'state_' .or. &
                    name(12:) /= '.vtu') cycle
            read(name(7:11), '(i5)', iostat=status) state_step
            if (status /= 0) cycle
            if (state_step <= step) then
                value = get_attribute(line, 'timestep')
                read(value, *, iostat=status) time
                if (status /= 0) cycle
                self%files = [self%files, [character(len=32) :: name]]
                self%times = [self%times, time]
            else
                open(newunit=old, file=self%folder // '/' // name, status='old', iostat=status)
                if (status == 0) close(old, status='delete')
            end if
        end do
        close(unit)
        call write_collection(self, error)
    end subroutine resume_states

    !> The value of attribute `key="..."` in a line of states.pvd ('' if absent or empty).
    pure function get_attribute(line, key) result(value)
        character(len=*), intent(in) :: line, key
        character(len=:), allocatable :: value
        integer :: first, last

        value = ''
        first = index(line, key // '="')
        if (first == 0) return
        first = first + len(key) + 2
        last = index(line(first:), '"') + first - 2
        if (last >= first) value = line(first:last)
    end function get_attribute

    subroutine write_collection(self, error)
        type(vtk_writer_type), intent(in) :: self
        type(error_type), allocatable, intent(out) :: error
        integer :: unit, status, i

        open(newunit=unit, file=self%folder // '/states.pvd', status='replace', &
            action='write', iostat=status)
        if (status /= 0) then
            call fatal_error(error, "cannot write '" // self%folder // "/states.pvd'")
            return
        end if
        write(unit, '(a)') '<?xml version="1.0"?>'
        write(unit, '(a)') '<VTKFile type="Collection" version="0.1">'
        write(unit, '(a)') '<Collection>'
        do i = 1, size(self%files)
            write(unit, '(a, es24.16e3, a)') '<DataSet timestep="', self%times(i), &
                '" file="' // trim(self%files(i)) // '"/>'
        end do
        write(unit, '(a)') '</Collection></VTKFile>'
        close(unit)
    end subroutine write_collection

end module yarnfort_output_vtk
