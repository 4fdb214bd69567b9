! SPDX-License-Identifier: MIT
!> The curve file: one CSV row per converged step, flushed as soon as it is written.
!> `curve_writer_type` is also the writer of the other per-step CSV files of a run (a
!> header, then the rows of each step appended and flushed together, resumed on restart):
!> `open_table`, `resume_table` and `put_line` with the file's own name and header.
module yarnfort_output_curve
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_scene_scene, only: scene_type
    use yarnfort_solver_continuation, only: step_state_type
    use yarnfort_text, only: read_line
    use yarnfort_output_csv_rows, only: csv_rows_type, format_csv_real
    use yarnfort_scene_channels, only: get_curve_columns, curve_column_length
    use yarnfort_output_filesystem, only: rename_file, remove_file, close_checked, open_append, &
        flush_checked, truncate_file, open_new_file, close_new_file
    implicit none
    private

    public :: curve_writer_type, curve_file_name, get_support_displacement
    public :: get_load_displacement

    character(len=*), parameter :: curve_file_name = 'curve.csv'

    type :: curve_writer_type
        integer :: unit = -1
        character(len=:), allocatable :: path
    contains
        procedure :: open => open_curve
        !> Keep the rows up to a step of an existing curve file and append after them.
        procedure :: resume => resume_curve
        !> The same for any per-step CSV file of the folder, by name and header.
        procedure :: open_table
        procedure :: resume_table
        procedure :: write_step
        procedure :: put_line
        procedure :: close => close_curve
    end type curve_writer_type

contains

    !> Create folder/curve.csv and write its header. Columns: step, time, the factor of
    !> each load channel (p_force, p_disp without &path channels), then rx, ry, rz (N,
    !> force applied by the support on the net) for each support set, then ux, uy, uz (m,
    !> the mean displacement of the set's prescribed coordinates, per component; 0 for a
    !> component it does not prescribe) for each support set, then load_<k>_ux, _uy, _uz
    !> (m, the mean displacement of the nodes of &load #k) for each &load, then for a
    !> fabric strain and force_per_width, then direction (1 loading, -1 unloading, 0
    !> neither: sign of the change of the sum of the channels' factors), passages
    !> slipping, passages held in stick by chatter damping, 1 if the step ended in a jump
    !> after a slip instability (else 0), and sliding passages in all,
    !> Newton iterations of the step (all solves), final scaled residual, step cuts and
    !> wall time (s) of the step.
    subroutine open_curve(self, folder, scene, error)
        class(curve_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: folder
        type(scene_type), intent(in) :: scene
        type(error_type), allocatable, intent(out) :: error

        call self%open_table(folder, curve_file_name, get_header(scene), error)
    end subroutine open_curve

    !> Create folder/name and write its header line.
    subroutine open_table(self, folder, name, header, error)
        class(curve_writer_type), intent(inout) :: self
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
        class(curve_writer_type), intent(inout) :: self
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

    !> Continue folder/curve.csv after `step` (a restart): keep its header and its rows
    !> up to that step, drop the later ones (written after the restart snapshot), and
    !> append from there. The kept rows go to a temporary file renamed over the old one,
    !> so an interruption leaves the old file. Fails if the file is missing, has other
    !> columns than `scene` writes, or has no row for `step`.
    !> The row of `step` must have the pseudo-time `time` (that of the restart file), and
    !> the row of step - 1 (when step > 0 and the file has it) `previous_time`.
    subroutine resume_curve(self, folder, scene, step, error, time, previous_time)
        class(curve_writer_type), intent(inout) :: self
        character(len=*), intent(in) :: folder
        type(scene_type), intent(in) :: scene
        integer, intent(in) :: step
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in), optional :: time, previous_time

        call self%resume_table(folder, curve_file_name, get_header(scene), step, error, time, &
            previous_time=previous_time)
    end subroutine resume_curve

    !> Continue folder/name (header `header`) after `step` as resume_curve does: rows are
    !> lines whose first field is their step; a step may have several rows (long format).
    !> With `row_required` false (default true), a step without rows is accepted (a
    !> file that has none for any step, e.g. of a scene with nothing to report).
    subroutine resume_table(self, folder, name, header, step, error, time, row_required, &
            previous_time)
        class(curve_writer_type), intent(inout) :: self
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

    !> The header line of the curve file for `scene` (columns: see open_curve; the
    !> names of get_curve_columns, which the input check found unique).
    function get_header(scene) result(header)
        type(scene_type), intent(in) :: scene
        character(len=:), allocatable :: header
        character(len=curve_column_length), allocatable :: names(:)
        integer, allocatable :: kind(:), item(:)
        integer :: n_loads, j

        n_loads = 0
        if (allocated(scene%loads)) n_loads = size(scene%loads)
        call get_curve_columns(scene%path%channel, scene%supports%name, n_loads, &
            scene%fabric_set > 0, names, kind, item)
        header = trim(names(1))
        do j = 2, size(names)
            header = header // ',' // trim(names(j))
        end do
    end function get_header

    subroutine write_step(self, scene, state, error)
        class(curve_writer_type), intent(inout) :: self
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        type(error_type), allocatable, intent(out) :: error
        type(csv_rows_type) :: row
        integer :: s

        call row%add(state%step)
        call row%add(state%time)
        call row%add(state%factors)
        do s = 1, size(state%reaction, 2)
            call row%add(state%reaction(:, s))
        end do
        do s = 1, size(scene%supports)
            call row%add(get_support_displacement(scene, state, s))
        end do
        if (allocated(scene%loads)) then
            do s = 1, size(scene%loads)
                call row%add(get_load_displacement(scene, state, s))
            end do
        end if
        if (scene%fabric_set > 0) then
            ! A fabric has the two default channels: p_disp is channel 2.
            call row%add(state%factors(2) * scene%fabric_strain)
            call row%add(state%reaction(1, scene%fabric_set) / scene%fabric_width)
        end if
        call row%add(state%direction)
        call row%add(state%n_slipping)
        call row%add(state%n_held)
        call row%add(merge(1, 0, state%jump_steps > 0))
        call row%add(state%n_passages)
        call row%add(state%newton_iterations)
        call row%add(state%newton%residual_norm)
        call row%add(state%step_cuts)
        call row%add(state%wall_time)
        if (self%unit == -1) then
            call fatal_error(error, "cannot write '" // self%path // "': it is not open")
            return
        end if
        call self%put_line(row%get(), error)
    end subroutine write_step

    !> Mean displacement (m, from the initial position) of the coordinates support set s
    !> prescribes, per component (0 for a component it prescribes nowhere).
    pure function get_support_displacement(scene, state, s) result(displacement)
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        integer, intent(in) :: s
        real(wp) :: displacement(3)
        integer :: i, c, k, node, n(3)

        displacement = 0.0_wp
        n = 0
        do i = 1, size(scene%supports(s)%coordinates)
            c = scene%supports(s)%coordinates(i)
            node = (c - 1) / 3 + 1
            k = c - 3 * (node - 1)
            displacement(k) = displacement(k) + (state%position(k, node) &
                - scene%network%position(k, node))
            n(k) = n(k) + 1
        end do
        where (n > 0) displacement = displacement / n
    end function get_support_displacement

    !> Mean displacement (m) of the nodes of &load #l.
    pure function get_load_displacement(scene, state, l) result(displacement)
        type(scene_type), intent(in) :: scene
        type(step_state_type), intent(in) :: state
        integer, intent(in) :: l
        real(wp) :: displacement(3)
        integer :: i, node

        displacement = 0.0_wp
        associate(nodes => scene%loads(l)%nodes)
            do i = 1, size(nodes)
                node = nodes(i)
                displacement = displacement + (state%position(:, node) &
                    - scene%network%position(:, node))
            end do
            if (size(nodes) > 0) displacement = displacement / size(nodes)
        end associate
    end function get_load_displacement

    !> Close the file; `error` says if the last data could not be written.
    subroutine close_curve(self, error)
        class(curve_writer_type), intent(inout) :: self
        type(error_type), allocatable, intent(out), optional :: error
        type(error_type), allocatable :: close_error

        if (self%unit == -1) return
        call close_checked(self%unit, self%path, close_error)
        self%unit = -1
        if (present(error) .and. allocated(close_error)) call move_alloc(close_error, error)
    end subroutine close_curve

end module yarnfort_output_curve
