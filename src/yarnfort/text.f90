! SPDX-License-Identifier: MIT
!> The one text-utility module: records of any length (read in linear time, bounded),
!> case folding, numbers written so that they read back exactly, words, strict number
!> parsing, file names, and the "did you mean" suggestions of error messages.
module yarnfort_text
    use, intrinsic :: ieee_arithmetic, only: ieee_is_nan, ieee_is_finite
    use, intrinsic :: iso_fortran_env, only: int64
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    implicit none
    private

    public :: string_type, read_line, to_lower, format_integer, format_real, quote_string
    public :: format_short
    public :: split_words, parse_integer, parse_real, edit_distance, closest_name
    public :: join_names, folder_of, resolve_path, is_folder, max_line_length
    public :: drop_byte_order_mark, remove_characters, read_file_text, open_to_read

    interface format_integer
        module procedure format_default_integer, format_long_integer
    end interface format_integer

    !> One string of an array of strings of different lengths.
    type :: string_type
        character(len=:), allocatable :: text
    end type string_type

    !> Characters read per non-advancing read of a record.
    integer, parameter :: chunk_length = 4096
    !> Longest record read_line accepts: far above the longest documented line (100 000
    !> node ids of a &yarn on one line, about 7 MB); a longer one is an error, so that a
    !> device like /dev/zero or a binary file ends with a message instead of never.
    integer, parameter :: max_line_length = 2**26
    !> Largest edit distance at which a known name is suggested for a mistyped one.
    integer, parameter :: max_suggestion_distance = 2
    character(len=1), parameter :: tab = achar(9)
    !> The UTF-8 byte order mark some editors put at the start of a file.
    character(len=*), parameter :: byte_order_mark = achar(239) // achar(187) // achar(191)

contains

    !> Read one whole record from a formatted sequential unit, in time linear in its
    !> length. `stat` is 0, or iostat_end at the end of the file, or another nonzero
    !> value with `message` set (also for a record longer than max_line_length).
    subroutine read_line(unit, line, stat, message)
        integer, intent(in) :: unit
        character(len=:), allocatable, intent(out) :: line
        integer, intent(out) :: stat
        character(len=*), intent(out) :: message
        character(len=:), allocatable :: buffer, grown
        integer :: size_read, n

        line = ''
        allocate(character(len=chunk_length) :: buffer)
        n = 0
        message = ''
        do
            if (n + chunk_length > len(buffer)) then
                if (len(buffer) >= max_line_length) then
                    stat = -huge(1)
                    message = 'a line is longer than ' // format_integer(max_line_length) &
                        // ' characters (is this a binary file or a device?)'
                    return
                end if
                allocate(character(len=2 * len(buffer)) :: grown)
                grown(:n) = buffer(:n)
                call move_alloc(grown, buffer)
            end if
            read(unit, '(a)', advance='no', iostat=stat, iomsg=message, size=size_read) &
                buffer(n + 1:n + chunk_length)
            if (stat > 0) return
            n = n + size_read
            if (is_iostat_eor(stat)) then
                stat = 0
                exit
            end if
            if (is_iostat_end(stat)) then
                ! A last record without a newline is still a record.
                if (n > 0) stat = 0
                exit
            end if
        end do
        line = buffer(:n)
    end subroutine read_line

    !> The string in lower case (ASCII letters only).
    pure function to_lower(text) result(lower)
        character(len=*), intent(in) :: text
        character(len=len(text)) :: lower
        integer :: i, code

        lower = text
        do i = 1, len(text)
            code = iachar(text(i:i))
            if (code >= iachar('A') .and. code <= iachar('Z')) then
                lower(i:i) = achar(code + iachar('a') - iachar('A'))
            end if
        end do
    end function to_lower

    !> An integer (default or 64-bit) as text without blanks.
    pure function format_default_integer(value) result(text)
        integer, intent(in) :: value
        character(len=:), allocatable :: text

        text = format_long_integer(int(value, int64))
    end function format_default_integer

    pure function format_long_integer(value) result(text)
        integer(int64), intent(in) :: value
        character(len=:), allocatable :: text
        character(len=24) :: buffer

        write(buffer, '(i0)') value
        text = trim(buffer)
    end function format_long_integer

    !> A real as the shortest decimal text that reads back to exactly the same value
    !> ('0.25', '150.0', '1.0e-6', '-3.0e12'); 'NaN', 'Infinity' and '-Infinity' as such.
    pure function format_real(value) result(text)
        real(wp), intent(in) :: value
        character(len=:), allocatable :: text
        integer, parameter :: max_digits = 17
        character(len=48) :: buffer
        character(len=24) :: form
        character(len=:), allocatable :: digits, minus, suffix
        real(wp) :: back
        integer :: decimals, first_decimals, stat, exponent, mark, point

        if (ieee_is_nan(value)) then
            text = 'NaN'
            return
        end if
        minus = trim(merge('-', ' ', sign(1.0_wp, value) < 0.0_wp))
        if (.not. ieee_is_finite(value)) then
            text = minus // 'Infinity'
            return
        else if (value == 0.0_wp) then
            text = minus // '0.0'
            return
        end if
        ! Near the overflow threshold a rounded-up candidate would overflow when read
        ! back: use the full 17 significant digits there.
        first_decimals = 0
        if (abs(value) > huge(value) / 10) first_decimals = max_digits - 1
        do decimals = first_decimals, max_digits
            write(form, '("(es48.", i0, "e4)")') decimals
            write(buffer, form) value
            read(buffer, *, iostat=stat) back
            if (stat == 0 .and. back == value) exit
        end do
        ! buffer is like '  -2.5E-0001': sign, digits and a decimal exponent.
        buffer = adjustl(buffer)
        mark = index(buffer, 'E')
        read(buffer(mark + 1:), *) exponent
        digits = remove_characters(buffer(len(minus) + 1:mark - 1), '.')
        do while (len(digits) > 1 .and. digits(len(digits):len(digits)) == '0')
            digits = digits(:len(digits) - 1)
        end do
        ! The decimal point after digit `point`, with at least one digit after it.
        point = 1
        suffix = ''
        if (exponent < -4 .or. exponent > 6) then
            suffix = 'e' // format_integer(exponent)
        else if (exponent < 0) then
            digits = repeat('0', -exponent) // digits
        else
            point = exponent + 1
        end if
        digits = digits // repeat('0', max(point + 1 - len(digits), 0))
        text = minus // digits(:point) // '.' // digits(point + 1:) // suffix
    end function format_real

    !> A real for a message, rounded to `digits` significant digits (default 3), always
    !> with its exponent: '1.80e308', '4.94e-324', '-2.50e-3', '1.00e0'; 'NaN', 'Infinity'
    !> and '-Infinity' as such. (An ES edit descriptor without an exponent width drops
    !> the 'E' of a three-digit exponent: 1.80+308.)
    pure function format_short(value, digits) result(text)
        real(wp), intent(in) :: value
        integer, intent(in), optional :: digits
        character(len=:), allocatable :: text
        character(len=40) :: buffer, form
        integer :: shown, mark, exponent

        if (ieee_is_nan(value)) then
            text = 'NaN'
            return
        else if (.not. ieee_is_finite(value)) then
            text = trim(merge('-', ' ', value < 0.0_wp)) // 'Infinity'
            return
        end if
        shown = 3
        if (present(digits)) shown = min(max(digits, 1), 17)
        ! Four exponent digits hold every double's exponent, subnormals included.
        write(form, '("(es40.", i0, "e4)")') shown - 1
        write(buffer, form) value
        buffer = adjustl(buffer)
        mark = index(buffer, 'E')
        read(buffer(mark + 1:), *) exponent
        ! ES with no decimals writes '2.E+0308': no point without digits after it.
        if (buffer(mark - 1:mark - 1) == '.') mark = mark - 1
        text = buffer(:mark - 1) // 'e' // format_integer(exponent)
    end function format_short

    !> Drop the UTF-8 byte order mark some editors put at the start of a file: it is not
    !> text of the file.
    pure subroutine drop_byte_order_mark(text)
        character(len=:), allocatable, intent(inout) :: text

        if (index(text, byte_order_mark) == 1) text = text(len(byte_order_mark) + 1:)
    end subroutine drop_byte_order_mark

    !> `text` without the characters of `set`.
    pure function remove_characters(text, set) result(cleaned)
        character(len=*), intent(in) :: text, set
        character(len=:), allocatable :: cleaned
        integer :: i

        cleaned = ''
        do i = 1, len(text)
            if (index(set, text(i:i)) == 0) cleaned = cleaned // text(i:i)
        end do
    end function remove_characters

    !> A character value as a namelist literal: in apostrophes, inner apostrophes doubled,
    !> trailing blanks dropped.
    pure function quote_string(text) result(quoted)
        character(len=*), intent(in) :: text
        character(len=:), allocatable :: quoted
        integer :: i

        quoted = "'"
        do i = 1, len_trim(text)
            if (text(i:i) == "'") then
                quoted = quoted // "''"
            else
                quoted = quoted // text(i:i)
            end if
        end do
        quoted = quoted // "'"
    end function quote_string

    !> The blank-separated (spaces, tabs) words of a line.
    pure subroutine split_words(line, words)
        character(len=*), intent(in) :: line
        type(string_type), allocatable, intent(out) :: words(:)
        integer :: first, last, n
        type(string_type), allocatable :: grown(:)

        allocate(words(8))
        n = 0
        last = 0
        do
            ! The next word: from its first character to the one before the next blank.
            first = verify(line(last + 1:), ' ' // tab)
            if (first == 0) exit
            first = last + first
            last = scan(line(first:), ' ' // tab)
            last = merge(len(line), first + last - 2, last == 0)
            if (n == size(words)) then
                allocate(grown(2 * n))
                grown(:n) = words
                call move_alloc(grown, words)
            end if
            n = n + 1
            words(n)%text = line(first:last)
        end do
        words = words(:n)
    end subroutine split_words

    !> Read a whole word as an integer (optional sign, digits); `ok` is false otherwise,
    !> also when the value does not fit the integer kind.
    pure subroutine parse_integer(word, value, ok)
        character(len=*), intent(in) :: word
        integer, intent(out) :: value
        logical, intent(out) :: ok
        integer :: i, first, digit
        logical :: negative

        value = 0
        ok = .false.
        first = 1
        negative = .false.
        if (len(word) > 0) then
            if (word(1:1) == '+' .or. word(1:1) == '-') first = 2
            negative = word(1:1) == '-'
        end if
        if (first > len(word)) return
        ! Accumulate as a negative number: -huge(1) - 1 fits, +huge(1) + 1 does not.
        do i = first, len(word)
            digit = index('0123456789', word(i:i)) - 1
            if (digit < 0) return
            if (value < (-huge(value) - 1 + digit) / 10) return
            value = 10 * value - digit
        end do
        if (.not. negative) then
            if (value < -huge(value)) return
            value = -value
        end if
        ok = .true.
    end subroutine parse_integer

    !> Read a whole word as a real (Fortran syntax, also NaN and Infinity); `ok` is false
    !> unless the whole word is a number.
    subroutine parse_real(word, value, ok)
        character(len=*), intent(in) :: word
        real(wp), intent(out) :: value
        logical, intent(out) :: ok
        integer :: stat

        call parse_short_decimal(word, value, ok)
        if (ok) return
        value = 0.0_wp
        ! Without separators, quotes and repeat counts, a list-directed read takes the
        ! whole word or fails.
        if (len(word) == 0 .or. scan(word, " ,;/*()'""" // tab) > 0) return
        read(word, *, iostat=stat) value
        ok = stat == 0
    end subroutine parse_real

    !> Fast path of parse_real for the usual coordinates: [sign] digits [. digits]
    !> [e|d [sign] digits] with a mantissa below 2**53 and a power of ten up to 22. Both
    !> are then exact doubles and one multiplication or division rounds correctly
    !> (Clinger's fast path); `ok` is false for anything else.
    pure subroutine parse_short_decimal(word, value, ok)
        character(len=*), intent(in) :: word
        real(wp), intent(out) :: value
        logical, intent(out) :: ok
        integer, parameter :: max_exact_power = 22
        integer(int64), parameter :: max_exact_mantissa = 2_int64**53
        integer :: i, digit, exponent, exponent_part, n_digits
        integer(int64) :: mantissa
        logical :: negative, in_fraction, fits

        value = 0.0_wp
        ok = .false.
        i = 1
        negative = .false.
        if (len(word) == 0) return
        if (word(1:1) == '+' .or. word(1:1) == '-') then
            negative = word(1:1) == '-'
            i = 2
        end if
        mantissa = 0
        exponent = 0
        n_digits = 0
        in_fraction = .false.
        do while (i <= len(word))
            if (word(i:i) == '.') then
                if (in_fraction) return
                in_fraction = .true.
            else
                digit = index('0123456789', word(i:i)) - 1
                if (digit < 0) exit
                if (mantissa > (max_exact_mantissa - digit) / 10) return
                mantissa = 10 * mantissa + digit
                n_digits = n_digits + 1
                if (in_fraction) exponent = exponent - 1
            end if
            i = i + 1
        end do
        if (n_digits == 0) return
        if (i <= len(word)) then
            if (index('eEdD', word(i:i)) == 0) return
            call parse_integer(word(i + 1:), exponent_part, fits)
            if (.not. fits .or. exponent_part < -1000 .or. exponent_part > 1000) return
            exponent = exponent + exponent_part
        end if
        if (abs(exponent) > max_exact_power) return
        value = real(mantissa, wp)
        if (exponent >= 0) then
            value = value * 10.0_wp**exponent
        else
            value = value / 10.0_wp**(-exponent)
        end if
        if (negative) value = -value
        ok = .true.
    end subroutine parse_short_decimal

    !> Levenshtein distance between two strings (insertions, deletions, substitutions).
    pure function edit_distance(a, b) result(distance)
        character(len=*), intent(in) :: a, b
        integer :: distance
        integer :: previous(0:len(b)), current(0:len(b)), i, j, cost

        do j = 0, len(b)
            previous(j) = j
        end do
        do i = 1, len(a)
            current(0) = i
            do j = 1, len(b)
                cost = merge(0, 1, a(i:i) == b(j:j))
                current(j) = min(previous(j) + 1, current(j - 1) + 1, previous(j - 1) + cost)
            end do
            previous = current
        end do
        distance = previous(len(b))
    end function edit_distance

    !> The known name closest to `name` if it is close enough to be a typing error, else ''.
    pure function closest_name(name, names) result(closest)
        character(len=*), intent(in) :: name
        character(len=*), intent(in) :: names(:)
        character(len=:), allocatable :: closest
        integer :: i, distance, best

        closest = ''
        best = max_suggestion_distance + 1
        do i = 1, size(names)
            distance = edit_distance(to_lower(name), to_lower(trim(names(i))))
            if (distance < best .and. distance < len(name)) then
                best = distance
                closest = trim(names(i))
            end if
        end do
    end function closest_name

    !> Names joined as 'a, b, c', each with an optional prefix (e.g. '&'); with `last`
    !> (e.g. ' or '), that joins the last two: 'a, b or c'.
    pure function join_names(names, prefix, last) result(joined)
        character(len=*), intent(in) :: names(:)
        character(len=*), intent(in) :: prefix
        character(len=*), intent(in), optional :: last
        character(len=:), allocatable :: joined
        integer :: i

        joined = ''
        do i = 1, size(names)
            if (i > 1 .and. i == size(names) .and. present(last)) then
                joined = joined // last
            else if (i > 1) then
                joined = joined // ', '
            end if
            joined = joined // prefix // trim(names(i))
        end do
    end function join_names

    !> The folder part of a file name ('' for a bare file name, '/' for a file in '/').
    pure function folder_of(path) result(folder)
        character(len=*), intent(in) :: path
        character(len=:), allocatable :: folder
        integer :: slash

        slash = index(trim(path), '/', back=.true.)
        if (slash == 0) then
            folder = ''
        else if (slash == 1) then
            folder = '/'
        else
            folder = path(:slash - 1)
        end if
    end function folder_of

    !> A file name resolved against a folder: absolute names and names with an empty
    !> folder are returned as they are.
    pure function resolve_path(file, folder) result(path)
        character(len=*), intent(in) :: file, folder
        character(len=:), allocatable :: path

        if (len_trim(folder) == 0 .or. file(1:min(1, len(file))) == '/') then
            path = trim(file)
        else if (folder(len_trim(folder):len_trim(folder)) == '/') then
            path = trim(folder) // trim(file)
        else
            path = trim(folder) // '/' // trim(file)
        end if
    end function resolve_path

    !> Whether `path` names an existing folder (then opening it as a file must not be
    !> mistaken for an empty file).
    function is_folder(path) result(folder)
        character(len=*), intent(in) :: path
        logical :: folder
        integer :: stat

        folder = .false.
        if (len_trim(path) == 0) return
        inquire(file=trim(path) // '/.', exist=folder, iostat=stat)
        if (stat /= 0) folder = .false.
    end function is_folder

    !> Open file `path` to read, formatted and sequential or, with `stream`, as a stream
    !> of bytes. `what` names the file in the messages: what is a folder, cannot be opened.
    subroutine open_to_read(path, what, unit, error, stream)
        character(len=*), intent(in) :: path, what
        integer, intent(out) :: unit
        type(error_type), allocatable, intent(out) :: error
        logical, intent(in), optional :: stream
        character(len=512) :: message
        integer :: stat
        logical :: bytes

        unit = -1
        bytes = .false.
        if (present(stream)) bytes = stream
        if (is_folder(path)) then
            call fatal_error(error, what // ' is a folder, not a file')
            return
        end if
        if (bytes) then
            open(newunit=unit, file=path, status='old', action='read', access='stream', &
                form='unformatted', iostat=stat, iomsg=message)
        else
            open(newunit=unit, file=path, status='old', action='read', form='formatted', &
                access='sequential', iostat=stat, iomsg=message)
        end if
        if (stat /= 0) call fatal_error(error, 'cannot open ' // what // ': ' // trim(message))
    end subroutine open_to_read

    !> The whole content of file `path`, read as a stream (much faster than record by
    !> record). `what` names the file in the messages ("file 'a.geo'", "it"): what is
    !> a folder, cannot be opened, read, sized or held in memory.
    subroutine read_file_text(path, what, content, error)
        character(len=*), intent(in) :: path, what
        character(len=:), allocatable, intent(out) :: content
        type(error_type), allocatable, intent(out) :: error
        character(len=512) :: message
        integer :: unit, stat
        integer(int64) :: file_size

        call open_to_read(path, what, unit, error, stream=.true.)
        if (allocated(error)) return
        inquire(unit=unit, size=file_size)
        if (file_size < 0) then
            call fatal_error(error, 'cannot get the size of ' // what)
            close(unit)
            return
        end if
        allocate(character(len=file_size) :: content, stat=stat, errmsg=message)
        if (stat /= 0) then
            close(unit)
            call fatal_error(error, what // ' (' // format_integer(file_size) &
                // ' bytes) does not fit in memory: ' // trim(message))
            return
        end if
        stat = 0
        if (file_size > 0) read(unit, iostat=stat, iomsg=message) content
        close(unit)
        if (stat /= 0) call fatal_error(error, 'cannot read ' // what // ': ' // trim(message))
    end subroutine read_file_text

end module yarnfort_text
