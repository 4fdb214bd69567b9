! SPDX-License-Identifier: MIT
!> The curve file: one CSV row per converged step, flushed as soon as it is written.
module yarnfort_output_curve
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_continuation, only: step_state_type
    use yarnfort_output_filesystem, only: rename_file
    implicit none
    private

    public :: curve_writer_type, curve_file_name

    character(len=*), parameter :: curve_file_name = 'curve.csv'

    type :: curve_writer_type
        integer :: unit = -1
    contains
        procedure :: open => open_curve
        !> Keep the rows up to a step of an existing curve file and append after them.
        procedure :: resume => resume_curve
        procedure :: write_step
        procedure :: close => close_curve
    end type curve_writer_type

contains

    !> Create folder/curve.csv and write its header. Columns: step, time, p_force,
    !> p_disp, then rx, ry, rz (N, force applied by the support on the net) for each
    !> support set, then direction (1 loading, -1 unloading, 0 neither: sign of the
    !> change of p_force + p_disp), passages slipping and sliding passages in all,
    !> Newton iterations of the step (all solves), final scaled residual, step cuts and
    !> wall time (s) of the step.
    subroutine open_curve(self, folder, scene, error)
        class(curve_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: folder
        type(scene_type), intent(in) :: scene
        type(error_type), allocatable, intent(out) :: error
        integer :: status

        open(newunit=self%unit, file=folder // '/' // curve_file_name, status='replace', &
            action='write', iostat=status)
        if (status /= 0) then
            call fatal_error(error, "cannot write '" // folder // '/' // curve_file_name // "'")
            return
        end if
        write(self%unit, '(a)') get_header(scene)
        flush(self%unit)
    end subroutine open_curve

    !> Continue folder/curve.csv after `step` (a restart): keep its header and its rows
    !> up to that step, drop the later ones (written after the restart snapshot), and
    !> append from there. The kept rows go to a temporary file renamed over the old one,
    !> so an interruption leaves the old file. Fails if the file is missing, has other
    !> columns than `scene` writes, or has no row for `step`.
    subroutine resume_curve(self, folder, scene, step, error)
        class(curve_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: folder
        type(scene_type), intent(in) :: scene
        integer, intent(in) :: step
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: path, temporary, line, header
        character(len=32) :: text
        integer :: old, new, status, row_step, comma, last_kept

        path = folder // '/' // curve_file_name
        temporary = path // '.tmp'
        open(newunit=old, file=path, status='old', action='read', iostat=status)
        if (status /= 0) then
            call fatal_error(error, "&control restart: cannot read '" // path // "'")
            return
        end if
        header = get_header(scene)
        call read_line(old, line, status)
        if (status /= 0 .or. line /= header) then
            close(old)
            call fatal_error(error, "&control restart: '" // path // "' has other columns " &
                // 'than this scene writes')
            return
        end if
        open(newunit=new, file=temporary, status='replace', action='write', iostat=status)
        if (status /= 0) then
            close(old)
            call fatal_error(error, "cannot write '" // temporary // "'")
            return
        end if
        write(new, '(a)') header
        last_kept = -1
        do
            call read_line(old, line, status)
            if (status /= 0) exit
            ! A complete row has as many fields as the header (a row cut short by a kill
            ! has fewer) and starts with its step number.
            if (count_commas(line) /= count_commas(header)) cycle
            comma = index(line, ',')
            read(line(:comma - 1), *, iostat=status) row_step
            if (status /= 0) cycle
            if (row_step > step) cycle
            write(new, '(a)') line
            last_kept = row_step
        end do
        close(old)
        close(new)
        if (last_kept /= step) then
            open(newunit=new, file=temporary, status='old', iostat=status)
            if (status == 0) close(new, status='delete')
            write(text, '(i0)') step
            call fatal_error(error, "&control restart: '" // path // "' has no row for step " &
                // trim(text) // ', the step of the restart file')
            return
        end if
        call rename_file(temporary, path, error)
        if (allocated(error)) return
        open(newunit=self%unit, file=path, status='old', position='append', action='write', &
            iostat=status)
        if (status /= 0) call fatal_error(error, "cannot write '" // path // "'")
    contains
        pure integer function count_commas(text)
            character(len=*), intent(in) :: text
            integer :: i
            count_commas = 0
            do i = 1, len(text)
                if (text(i:i) == ',') count_commas = count_commas + 1
            end do
        end function count_commas
    end subroutine resume_curve

    !> One whole line of a formatted sequential unit, however long; status /= 0 at the
    !> end of the file.
    subroutine read_line(unit, line, status)
        integer, intent(in) :: unit
        character(len=:), allocatable, intent(out) :: line
        integer, intent(out) :: status
        character(len=1024) :: chunk
        integer :: n

        line = ''
        do
            read(unit, '(a)', advance='no', size=n, iostat=status) chunk
            line = line // chunk(:n)
            if (status /= 0) exit
        end do
        if (is_iostat_eor(status)) status = 0
    end subroutine read_line

    !> The header line of the curve file for `scene` (columns: see open_curve).
    function get_header(scene) result(header)
        type(scene_type), intent(in) :: scene
        character(len=:), allocatable :: header
        character(len=:), allocatable :: name
        integer :: s

        header = 'step,time,p_force,p_disp'
        do s = 1, size(scene%supports)
            name = trim(scene%supports(s)%name)
            header = header // ',' // name // '_rx,' // name // '_ry,' // name // '_rz'
        end do
        if (scene%fabric_set > 0) header = header // ',strain,force_per_width'
        header = header // ',direction,slipping,passages,newton_iterations,residual,step_cuts,wall_time'
    end function get_header

    subroutine write_step(self, scene, state)
        class(curve_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        character(len=32) :: field
        character(len=:), allocatable :: row
        integer :: s, k

        write(field, '(i0)') state%step
        row = trim(field)
        call append(state%time)
        call append(state%p_force)
        call append(state%p_disp)
        do s = 1, size(state%reaction, 2)
            do k = 1, 3
                call append(state%reaction(k, s))
            end do
        end do
        if (scene%fabric_set > 0) then
            call append(state%p_disp * scene%fabric_strain)
            call append(state%reaction(1, scene%fabric_set) / scene%fabric_width)
        end if
        write(field, '(i0, ",", i0, ",", i0, ",", i0)') state%direction, state%n_slipping, &
            state%n_passages, state%newton_iterations
        row = row // ',' // trim(field)
        call append(state%newton%residual_norm)
        write(field, '(i0)') state%step_cuts
        row = row // ',' // trim(field)
        call append(state%wall_time)
        write(self%unit, '(a)') row
        flush(self%unit)
    contains
        subroutine append(value)
            real(wp), intent(in) :: value
            write(field, '(es24.16e3)') value
            row = row // ',' // trim(adjustl(field))
        end subroutine append
    end subroutine write_step

    subroutine close_curve(self)
        class(curve_writer_type), intent(inout) :: self
        if (self%unit /= -1) close(self%unit)
        self%unit = -1
    end subroutine close_curve

end module yarnfort_output_curve
