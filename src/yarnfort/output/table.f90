! SPDX-License-Identifier: MIT
!> A per-step CSV file of a run (curve.csv, reactions.csv, contacts.csv): a header, then
!> the rows of each converged step appended and flushed together, whole rows only, and
!> on a restart the rows up to the restart's step kept and appended after.
module yarnfort_output_table
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: read_line
    use yarnfort_output_csv_rows, only: format_csv_real
    use yarnfort_output_filesystem, only: rename_file, remove_file, close_checked, open_append, &
        flush_checked, truncate_file, open_new_file, close_new_file
    implicit none
    private

    public :: table_writer_type

    !> The writer of one CSV file; each file's own writer extends it with its header and
    !> rows (yarnfort_output_curve, _reactions, _contacts).
    type :: table_writer_type
        integer :: unit = -1
        character(len=:), allocatable :: path
    contains
        !> Create the file with its header.
        procedure :: open_table
        !> Keep the rows up to a step of an existing file and append after them.
        procedure :: resume_table
        procedure :: put_line
        procedure :: close => close_table
    end type table_writer_type

contains

    !> Create folder/name and write its header line.
    subroutine open_table(self, folder, name, header, error)
        class(table_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: folder, name, header
        type(error_type), allocatable, intent(out) :: error

        self%path = folder // '/' // name
        call open_new_file(self%unit, self%path, error)
        if (allocated(error)) return
        call self%put_line(header, error)
    end subroutine open_table

    !> Write a line and flush it to the file. A failure closes the file, cuts off what
    !> reached it of the line (so the file keeps whole rows only) and says why.
    subroutine put_line(self, line, error)
        class(table_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: line
        type(error_type), allocatable, intent(out) :: error
        type(error_type), allocatable :: ignored
        character(len=256) :: message
        integer :: status
        integer(8) :: whole

        inquire(unit=self%unit, size=whole)
        message = ''
        write(self%unit, '(a)', iostat=status, iomsg=message) line
        if (status /= 0) then
            call fatal_error(error, "cannot write '" // self%path // "': " // trim(message))
        else
            call flush_checked(self%unit, self%path, error)
        end if
        if (allocated(error)) then
            close(self%unit, iostat=status)
            self%unit = -1
            if (whole >= 0) call truncate_file(self%path, whole, ignored)
        end if
    end subroutine put_line

    !> Continue folder/name (header `header`) after `step` (a restart): keep its header
    !> and its rows up to that step, drop the later ones (written after the restart
    !> snapshot), and append from there. The kept rows go to a temporary file renamed over
    !> the old one, so an interruption leaves the old file. Fails if the file is missing,
    !> has another header, or has no row for `step`. Rows are lines whose first field is
    !> their step; a step may have several rows (long format). With `row_required` false
    !> (default true), a step without rows is accepted (a file that has none for any step,
    !> e.g. of a scene with nothing to report).
    !> The row of `step` must have the pseudo-time `time` (its second field: that of the
    !> restart file), and the row of step - 1 (when step > 0 and the file has it)
    !> `previous_time`.
    subroutine resume_table(self, folder, name, header, step, error, time, row_required, &
            previous_time)
        class(table_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: folder, name, header
        integer, intent(in) :: step
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: time, previous_time
        logical, intent(in), optional :: row_required
        type(error_type), allocatable :: ignored
        character(len=:), allocatable :: path, temporary, line
        character(len=32) :: text
        character(len=256) :: message
        integer :: old, new, status, row_step, comma, last_kept, write_status
        character(len=256) :: read_message
        real(wp) :: row_time, row_time_previous

        path = folder // '/' // name
        temporary = path // '.tmp'
        open(newunit=old, file=path, status='old', action='read', iostat=status)
        if (status /= 0) then
            call fatal_error(error, "&control restart: cannot read '" // path // "'")
            return
        end if
        call read_line(old, line, status, read_message)
        if (status /= 0 .or. line /= header) then
            close(old)
            call fatal_error(error, "&control restart: '" // path // "' has other columns " &
                // 'than this scene writes')
            return
        end if
        call open_new_file(new, temporary, error)
        if (allocated(error)) then
            close(old)
            return
        end if
        message = ''
        write(new, '(a)', iostat=write_status, iomsg=message) header
        last_kept = -1
        row_time = -huge(row_time)
        row_time_previous = -huge(row_time)
        do
            call read_line(old, line, status, read_message)
            if (status /= 0) exit
            ! A complete row has as many fields as the header (a row cut short by a kill
            ! has fewer) and starts with its step number.
            if (count_commas(line) /= count_commas(header)) cycle
            comma = index(line, ',')
            read(line(:comma - 1), *, iostat=status) row_step
            if (status /= 0) cycle
            if (row_step > step) cycle
            if (write_status == 0) write(new, '(a)', iostat=write_status, iomsg=message) line
            last_kept = row_step
            if (row_step == step) then
                ! The time field is the second one (list-directed: up to the comma).
                read(line(comma + 1:), *, iostat=status) row_time
                if (status /= 0) row_time = -huge(row_time)
            else if (row_step == step - 1) then
                read(line(comma + 1:), *, iostat=status) row_time_previous
                if (status /= 0) row_time_previous = -huge(row_time)
            end if
        end do
        close(old)
        call close_new_file(new, temporary, error, write_status, message)
        if (allocated(error)) return
        if (present(row_required)) then
            if (.not. row_required) last_kept = step
        end if
        if (last_kept /= step) then
            call remove_file(temporary, ignored)
            write(text, '(i0)') step
            call fatal_error(error, "&control restart: '" // path // "' has no row for step " &
                // trim(text) // ', the step of the restart file')
            return
        end if
        if (present(time)) call check_time('time', time, row_time, step)
        ! (A folder whose rows were renumbered may lack the row before: then unchecked.)
        if (present(previous_time) .and. step > 0 .and. row_time_previous > -huge(row_time)) &
            call check_time('previous time', previous_time, row_time_previous, step - 1)
        if (allocated(error)) then
            call remove_file(temporary, ignored)
            return
        end if
        call rename_file(temporary, path, error)
        if (allocated(error)) return
        self%path = path
        call open_append(self%unit, path, error)
    contains
        !> The restart file's `what` (`expected`) must be the time `found` in the row of
        !> `row_step`: written from the same double with 17 significant digits, it reads
        !> back to within a unit in the last place. Nothing to do after an error.
        subroutine check_time(what, expected, found, row_step)
            character(len=*), intent(in) :: what
            real(wp), intent(in) :: expected, found
            integer, intent(in) :: row_step

            if (allocated(error)) return
            if (abs(found - expected) <= 2 * spacing(max(abs(expected), tiny(expected)))) return
            write(text, '(i0)') row_step
            call fatal_error(error, "&control restart: the restart file's " // what // ' ' &
                // format_csv_real(expected) // ' is not that of step ' // trim(text) // " in '" &
                // path // "' (" // format_csv_real(found) // '): the two files are not of ' &
                // 'the same run')
        end subroutine check_time

        pure integer function count_commas(text)
            character(len=*), intent(in) :: text
            integer :: i
            count_commas = 0
            do i = 1, len(text)
                if (text(i:i) == ',') count_commas = count_commas + 1
            end do
        end function count_commas
    end subroutine resume_table

    !> Close the file; `error` says if the last data could not be written.
    subroutine close_table(self, error)
        class(table_writer_type), intent(inout) :: self
        type(error_type), allocatable, intent(out), optional :: error
        type(error_type), allocatable :: close_error

        if (self%unit == -1) return
        call close_checked(self%unit, self%path, close_error)
        self%unit = -1
        if (present(error) .and. allocated(close_error)) call move_alloc(close_error, error)
    end subroutine close_table

end module yarnfort_output_table
