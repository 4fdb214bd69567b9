! SPDX-License-Identifier: MIT
!> Reader of the two-column numeric CSV tables of the input (a material's (strain, force),
!> a friction law's (T, g)): one routine for every such file, so that they all accept the
!> same text and their messages name the file, the line and the value alike.
!>
!> Rows are "a,b" (spaces and tabs allowed). Lines before the first row that start with a
!> non-numeric character and do not read as two numbers are headers; blank lines and lines
!> starting with '#' are skipped anywhere; a UTF-8 byte order mark is dropped. The lines
!> before the first row other than the last header (comments, earlier headers) are notes,
!> which a reader checks for units that its header does not state.
module yarnfort_csv
    use, intrinsic :: iso_fortran_env, only: iostat_end
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    use yarnfort_text, only: format_integer, read_line, is_folder, drop_byte_order_mark, &
        string_type
    implicit none
    private

    public :: csv_row_type, read_csv_pairs, row_check_interface

    !> Rows allocated before the first growth while reading a file.
    integer, parameter :: initial_rows = 16

    !> Lines before the first row kept as notes (a tester's export has a few dozen).
    integer, parameter :: max_notes = 1000

    !> Longest piece of an input line quoted in a message.
    integer, parameter :: max_quote = 60

    !> Characters that may start a data row of a CSV table.
    character(len=*), parameter :: numeric_start = '0123456789+-.'

    !> Outcomes of parsing one CSV line.
    integer, parameter :: line_row = 0, line_skip = 1, line_bad = 2

    !> One row while it is checked: values, their text, and where it came from.
    type :: csv_row_type
        real(wp) :: value(2) = 0.0_wp
        character(len=:), allocatable :: first_text, second_text
        !> 'row 3' or 'line 7'.
        character(len=:), allocatable :: place
    end type csv_row_type

    abstract interface
        !> Check one row on its own (`previous` absent: the first row) or after the
        !> previous one; the message need not name the file or the line.
        subroutine row_check_interface(row, previous, error)
            import :: csv_row_type, error_type
            type(csv_row_type), intent(in) :: row
            type(csv_row_type), intent(in), optional :: previous
            type(error_type), allocatable, intent(out) :: error
        end subroutine row_check_interface
    end interface

contains

    !> Read the rows of a two-column CSV file, checking each with `check` as it is read.
    !> `names` are the columns (for messages: 'expected "strain,force"'); `first`, `second`
    !> the values, `lines` the line of each row. Messages start with `context` (e.g.
    !> "table 'cotton.csv'") and name the line. `header` is the last header line before
    !> the first row (the column names; '' if none) and `header_line` its line (0 if none);
    !> `notes` the other lines before the first row (comments without their '#', earlier
    !> header lines) and `note_lines` their lines.
    subroutine read_csv_pairs(path, context, names, check, first, second, lines, error, &
            header, header_line, notes, note_lines)
        character(len=*), intent(in) :: path, context
        character(len=*), intent(in) :: names(2)
        procedure(row_check_interface) :: check
        real(wp), allocatable, intent(out) :: first(:), second(:)
        integer, allocatable, intent(out) :: lines(:)
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable, intent(out), optional :: header
        integer, intent(out), optional :: header_line
        type(string_type), allocatable, intent(out), optional :: notes(:)
        integer, allocatable, intent(out), optional :: note_lines(:)
        type(string_type), allocatable :: before(:)
        integer, allocatable :: before_lines(:)
        character(len=:), allocatable :: line, message, comment
        character(len=512) :: iomsg
        type(csv_row_type) :: row, previous
        integer :: unit, stat, line_number, nrow, outcome, header_at, n_before

        if (present(header)) header = ''
        if (present(header_line)) header_line = 0
        allocate(before(0), before_lines(0))
        n_before = 0
        header_at = 0
        if (is_folder(path)) then
            call fatal_error(error, context // ': is a folder, not a file')
            return
        end if
        open(newunit=unit, file=path, status='old', action='read', form='formatted', &
            access='sequential', iostat=stat, iomsg=iomsg)
        if (stat /= 0) then
            call fatal_error(error, context // ': cannot open the file (' // trim(iomsg) // ')')
            return
        end if

        allocate(first(initial_rows), second(initial_rows), lines(initial_rows))
        nrow = 0
        line_number = 0
        do
            call read_line(unit, line, stat, iomsg)
            if (stat == iostat_end) exit
            line_number = line_number + 1
            if (stat /= 0) then
                call fatal_error(error, context // ', line ' // format_integer(line_number) &
                    // ': cannot read the line (' // trim(iomsg) // ')')
                exit
            end if
            if (line_number == 1) call drop_byte_order_mark(line)
            call parse_line(line, names, row, outcome, message)
            if (outcome == line_skip) then
                comment = clean_line(line)
                if (nrow == 0 .and. len(comment) > 0) call append_note(before, before_lines, &
                    n_before, trim(adjustl(comment(2:))), line_number)
                cycle
            end if
            if (outcome == line_bad) then
                if (nrow == 0 .and. is_header(line)) then
                    if (present(header)) header = clean_line(line)
                    if (present(header_line)) header_line = line_number
                    header_at = line_number
                    call append_note(before, before_lines, n_before, clean_line(line), &
                        line_number)
                    cycle
                end if
                call fatal_error(error, context // ', line ' // format_integer(line_number) &
                    // ': ' // message)
                exit
            end if
            row%place = 'line ' // format_integer(line_number)
            if (nrow == 0) then
                call check(row, error=error)
            else
                call check(row, previous, error)
            end if
            if (allocated(error)) then
                error%message = context // ', ' // row%place // ': ' // error%message
                exit
            end if
            call append_row(first, second, lines, nrow, row%value, line_number)
            previous = row
        end do
        close(unit)
        if (allocated(error)) return
        ! Notes: the lines before the first row but the last header.
        if (present(notes)) notes = pack(before(:n_before), before_lines(:n_before) /= header_at)
        if (present(note_lines)) note_lines = pack(before_lines(:n_before), &
            before_lines(:n_before) /= header_at)
        first = first(:nrow)
        second = second(:nrow)
        lines = lines(:nrow)
    end subroutine read_csv_pairs

    !> Parse one CSV line into a row, or report it as skipped (blank, '#') or bad.
    pure subroutine parse_line(line, names, row, outcome, message)
        character(len=*), intent(in) :: line
        character(len=*), intent(in) :: names(2)
        type(csv_row_type), intent(out) :: row
        integer, intent(out) :: outcome
        character(len=:), allocatable, intent(out) :: message
        character(len=:), allocatable :: text, expected
        integer :: comma
        logical :: ok

        text = clean_line(line)
        outcome = line_skip
        if (len(text) == 0) return
        if (text(1:1) == '#') return

        outcome = line_bad
        expected = '"' // trim(names(1)) // ',' // trim(names(2)) // '"'
        comma = index(text, ',')
        if (comma == 0) then
            message = 'expected ' // expected // ', found ' // quote(text)
            return
        end if
        if (index(text(comma + 1:), ',') /= 0) then
            message = 'expected 2 comma-separated values ' // expected // ', found ' &
                // quote(text)
            return
        end if
        call read_value(text(:comma - 1), row%value(1), row%first_text, ok)
        if (.not. ok) then
            message = trim(names(1)) // ' ' // quote(row%first_text) // ' is not a number'
            return
        end if
        call read_value(text(comma + 1:), row%value(2), row%second_text, ok)
        if (.not. ok) then
            message = trim(names(2)) // ' ' // quote(row%second_text) // ' is not a number'
            return
        end if
        outcome = line_row
    end subroutine parse_line

    !> Read one real from a CSV field (surrounding blanks allowed).
    pure subroutine read_value(field, value, text, ok)
        character(len=*), intent(in) :: field
        real(wp), intent(out) :: value
        character(len=:), allocatable, intent(out) :: text
        logical, intent(out) :: ok
        integer :: stat

        text = trim(adjustl(field))
        value = 0.0_wp
        ! Characters list-directed input would treat specially (separators, repeat counts).
        ok = len(text) > 0 .and. scan(text, ' */;"''') == 0
        if (.not. ok) return
        read(text, *, iostat=stat) value
        ok = stat == 0
    end subroutine read_value

    !> A line with tabs and carriage returns turned into blanks, leading and trailing
    !> blanks removed.
    pure function clean_line(line) result(text)
        character(len=*), intent(in) :: line
        character(len=:), allocatable :: text
        character(len=len(line)) :: buffer
        integer :: i

        buffer = line
        do i = 1, len(buffer)
            if (buffer(i:i) == achar(9) .or. buffer(i:i) == achar(13)) buffer(i:i) = ' '
        end do
        text = trim(adjustl(buffer))
    end function clean_line

    !> Whether a line that is not a data row may be a header: its first character is not
    !> one that starts a number.
    pure function is_header(line) result(header)
        character(len=*), intent(in) :: line
        logical :: header
        character(len=:), allocatable :: text

        text = clean_line(line)
        header = len(text) > 0
        if (header) header = verify(text(1:1), numeric_start) /= 0
    end function is_header

    !> Text in single quotes, shortened to `max_quote` characters.
    pure function quote(text) result(quoted)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: quoted

        if (len(text) > max_quote) then
            quoted = "'" // text(:max_quote) // "...'"
        else
            quoted = "'" // text // "'"
        end if
    end function quote

    !> Keep a line before the first row as a note (the first `max_notes` of them).
    pure subroutine append_note(notes, lines, n, text, line)
        type(string_type), allocatable, intent(inout) :: notes(:)
        integer, allocatable, intent(inout) :: lines(:)
        integer, intent(inout) :: n
        character(len=*), intent(in) :: text
        integer, intent(in) :: line
        type(string_type), allocatable :: grown(:)
        integer, allocatable :: grown_lines(:)

        if (n == max_notes) return
        if (n == size(notes)) then
            allocate(grown(max(2 * n, initial_rows)), grown_lines(max(2 * n, initial_rows)))
            grown(:n) = notes(:n)
            grown_lines(:n) = lines(:n)
            call move_alloc(grown, notes)
            call move_alloc(grown_lines, lines)
        end if
        n = n + 1
        notes(n)%text = text
        lines(n) = line
    end subroutine append_note

    !> Append one row, growing the arrays geometrically.
    pure subroutine append_row(first, second, lines, nrow, value, new_line)
        real(wp), allocatable, intent(inout) :: first(:), second(:)
        integer, allocatable, intent(inout) :: lines(:)
        integer, intent(inout) :: nrow
        real(wp), intent(in) :: value(2)
        integer, intent(in) :: new_line
        real(wp), allocatable :: real_buffer(:)
        integer, allocatable :: int_buffer(:)

        if (nrow == size(first)) then
            allocate(real_buffer(2 * nrow))
            real_buffer(:nrow) = first(:nrow)
            call move_alloc(real_buffer, first)
            allocate(real_buffer(2 * nrow))
            real_buffer(:nrow) = second(:nrow)
            call move_alloc(real_buffer, second)
            allocate(int_buffer(2 * nrow))
            int_buffer(:nrow) = lines(:nrow)
            call move_alloc(int_buffer, lines)
        end if
        nrow = nrow + 1
        first(nrow) = value(1)
        second(nrow) = value(2)
        lines(nrow) = new_line
    end subroutine append_row

end module yarnfort_csv
