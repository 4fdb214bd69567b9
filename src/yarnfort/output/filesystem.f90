! SPDX-License-Identifier: MIT
!> File-system calls Fortran has no portable statement for, through the C library and a
!> small C shim (filesystem_shim.c): folder creation, atomic rename, hard links, removal,
!> fsync, and the exclusive lock of an output folder. No routine here writes, truncates or
!> removes through a symbolic link: a link at a name the program writes is refused, so
!> nothing outside the output folder is ever changed through one.
module yarnfort_output_filesystem
    use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char, c_long_long
    use yarnfort_error, only: error_type, fatal_error
    implicit none
    private

    public :: make_folder, rename_file, link_file, remove_file, sync_file, sync_folder
    public :: folder_lock_type, get_links, refuse_link
    public :: close_checked, flush_checked, truncate_file, ignore_file_size_signal
    public :: open_append, open_new_file, close_new_file
    public :: lock_file_name, probe_file_name

    !> The lock file of an output folder (kept; the lock is the kernel's, not the file).
    character(len=*), parameter :: lock_file_name = '.yarnfort-lock'
    !> The file created and removed again to tell whether a folder can be written.
    character(len=*), parameter :: probe_file_name = '.yarnfort-write-test'

    !> What yarnfort_file_kind, yarnfort_create_file and yarnfort_lock_file tell of a
    !> name: a symbolic link, or something else than a regular file of its own.
    integer(c_int), parameter :: kind_link = 2, kind_other = 3

    !> An exclusive lock on an output folder, held from `acquire` to `release` (or the end
    !> of the process, however it ends: a killed run leaves no stale lock).
    type :: folder_lock_type
        integer(c_int) :: fd = -1
    contains
        procedure :: acquire => acquire_lock
        procedure :: release => release_lock
        procedure :: held => is_held
        final :: finalize_lock
    end type folder_lock_type

    interface
        function c_mkdir(path, mode) result(status) bind(C, name='mkdir')
            import :: c_int, c_char
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int), value :: mode
            integer(c_int) :: status
        end function c_mkdir

        function c_rmdir(path) result(status) bind(C, name='rmdir')
            import :: c_int, c_char
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int) :: status
        end function c_rmdir

        function c_list_links(folder, names, length) result(needed) &
                bind(C, name='yarnfort_list_links')
            import :: c_char, c_long_long
            character(kind=c_char), intent(in) :: folder(*)
            character(kind=c_char), intent(out) :: names(*)
            integer(c_long_long), value :: length
            integer(c_long_long) :: needed
        end function c_list_links

        function c_rename(old, new) result(status) bind(C, name='rename')
            import :: c_int, c_char
            character(kind=c_char), intent(in) :: old(*), new(*)
            integer(c_int) :: status
        end function c_rename

        function c_link(old, new) result(status) bind(C, name='yarnfort_link_file')
            import :: c_int, c_char
            character(kind=c_char), intent(in) :: old(*), new(*)
            integer(c_int) :: status
        end function c_link

        function c_lock_file(path, fd, holder, holder_length) result(status) &
                bind(C, name='yarnfort_lock_file')
            import :: c_int, c_char
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int), intent(out) :: fd
            character(kind=c_char), intent(out) :: holder(*)
            integer(c_int), value :: holder_length
            integer(c_int) :: status
        end function c_lock_file

        function c_unlock_file(fd) result(status) bind(C, name='yarnfort_unlock_file')
            import :: c_int
            integer(c_int), value :: fd
            integer(c_int) :: status
        end function c_unlock_file

        subroutine ignore_file_size_signal() bind(C, name='yarnfort_ignore_file_size_signal')
        end subroutine ignore_file_size_signal

        function c_truncate_file(path, bytes) result(status) &
                bind(C, name='yarnfort_truncate_file')
            import :: c_int, c_char, c_long_long
            character(kind=c_char), intent(in) :: path(*)
            integer(c_long_long), value :: bytes
            integer(c_int) :: status
        end function c_truncate_file

        function c_file_size_limit() result(bytes) bind(C, name='yarnfort_file_size_limit')
            import :: c_long_long
            integer(c_long_long) :: bytes
        end function c_file_size_limit

        subroutine c_last_error(text, length) bind(C, name='yarnfort_last_error')
            import :: c_int, c_char
            character(kind=c_char), intent(out) :: text(*)
            integer(c_int), value :: length
        end subroutine c_last_error
    end interface

    abstract interface
        !> yarnfort_sync_file, yarnfort_sync_folder, yarnfort_remove_file: 0 on success, -1
        !> on failure (the reason: c_last_error); yarnfort_file_kind, yarnfort_create_file,
        !> yarnfort_remove_regular_file: see filesystem_shim.c.
        function path_status_interface(path) result(status) bind(C)
            import :: c_int, c_char
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int) :: status
        end function path_status_interface

        !> yarnfort_file_size, yarnfort_free_space: bytes of the file, or free on its
        !> device; -1 if it cannot be told.
        function path_bytes_interface(path) result(bytes) bind(C)
            import :: c_char, c_long_long
            character(kind=c_char), intent(in) :: path(*)
            integer(c_long_long) :: bytes
        end function path_bytes_interface
    end interface

    procedure(path_status_interface), bind(C, name='yarnfort_sync_file') :: c_sync_file
    procedure(path_status_interface), bind(C, name='yarnfort_sync_folder') :: c_sync_folder
    procedure(path_status_interface), bind(C, name='yarnfort_remove_file') :: c_remove_file
    procedure(path_status_interface), bind(C, name='yarnfort_file_kind') :: c_file_kind
    procedure(path_status_interface), bind(C, name='yarnfort_create_file') :: c_create_file
    procedure(path_status_interface), bind(C, name='yarnfort_remove_regular_file') :: &
        c_remove_regular_file
    procedure(path_bytes_interface), bind(C, name='yarnfort_file_size') :: c_file_size
    procedure(path_bytes_interface), bind(C, name='yarnfort_free_space') :: c_free_space

    !> Permissions of new folders (rwxr-xr-x before the umask).
    integer(c_int), parameter :: folder_mode = int(o'755', c_int)

    !> Longest text kept from a C call (the reason, the lock holder).
    integer, parameter :: text_length = 512

contains

    !> Create `path` and its missing parents; an existing folder is fine. The error
    !> names the folder that could not be created or written; the folders this call
    !> created are then removed again (a refused folder leaves nothing behind).
    subroutine make_folder(path, error)
        character(len=*), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        character(len=:), allocatable :: folder, probe
        integer, allocatable :: created(:)
        integer(c_int) :: status
        integer :: i

        folder = trim(path)
        ! The lengths of the prefixes of `folder` that mkdir created, shortest first.
        allocate(created(0))
        do i = 2, len(folder) + 1
            if (i <= len(folder)) then
                if (folder(i:i) /= '/') cycle
            end if
            if (c_mkdir(folder(:i - 1) // c_null_char, folder_mode) == 0) &
                created = [created, i - 1]
        end do
        ! Whatever mkdir said, the folder is usable if a file can be created in it.
        probe = folder // '/' // probe_file_name
        status = c_create_file(probe // c_null_char)
        if (status == 0) then
            status = c_remove_file(probe // c_null_char)
            return
        end if
        if (status == -1) then
            call fatal_error(error, "&output: folder '" // folder &
                // "' cannot be created or written: " // get_reason())
        else
            call refuse_link(probe, status == kind_link, error)
        end if
        do i = size(created), 1, -1
            status = c_rmdir(folder(:created(i)) // c_null_char)
        end do
    end subroutine make_folder

    !> The error for `path`, a name the program writes in its output folder, when a
    !> symbolic link (`link`) or something else than a regular file is found there.
    subroutine refuse_link(path, link, error)
        character(len=*), intent(in) :: path
        logical, intent(in) :: link
        type(error_type), allocatable, intent(out) :: error

        if (link) then
            call fatal_error(error, "&output: '" // path // "' is a symbolic link; yarnfort " &
                // 'writes no file through a link (remove it or choose another &output folder)')
        else
            call fatal_error(error, "&output: '" // path // "' is not a regular file of its " &
                // 'own (a folder, a pipe or a file with other names); remove it or choose ' &
                // 'another &output folder')
        end if
    end subroutine refuse_link

    !> The names of the symbolic links in `folder`.
    subroutine get_links(folder, names, error)
        character(len=*), intent(in) :: folder
        character(len=:), allocatable, intent(out) :: names(:)
        type(error_type), allocatable, intent(out) :: error
        character(kind=c_char, len=:), allocatable :: buffer
        integer(c_long_long) :: needed
        integer :: first, last, longest, n

        allocate(character(len=1) :: names(0))
        allocate(character(kind=c_char, len=256) :: buffer)
        do
            needed = c_list_links(folder // c_null_char, buffer, int(len(buffer), c_long_long))
            if (needed < 0) then
                call fatal_error(error, "&output: cannot read folder '" // folder // "': " &
                    // get_reason())
                return
            end if
            if (needed <= len(buffer)) exit
            ! Links made while it was read may need more room still: read it again.
            deallocate(buffer)
            allocate(character(kind=c_char, len=needed + 256) :: buffer)
        end do
        ! NUL-ended names, one after the other.
        n = 0
        longest = 1
        first = 1
        do while (first <= needed)
            last = first + index(buffer(first:needed), c_null_char) - 2
            if (last < first - 1) exit
            n = n + 1
            longest = max(longest, last - first + 1)
            first = last + 2
        end do
        deallocate(names)
        allocate(character(len=longest) :: names(n))
        first = 1
        do n = 1, size(names)
            last = first + index(buffer(first:needed), c_null_char) - 2
            names(n) = buffer(first:last)
            first = last + 2
        end do
    end subroutine get_links

    !> Rename `old` to `new`, replacing `new` if it exists. On POSIX systems this is
    !> atomic: `new` is always either the old file or the complete new one.
    subroutine rename_file(old, new, error)
        character(len=*), intent(in) :: old, new
        type(error_type), allocatable, intent(out) :: error

        call check_call(c_rename(old // c_null_char, new // c_null_char), &
            "cannot rename '" // old // "' to '" // new // "'", error)
    end subroutine rename_file

    !> Give the file `old` the second name `new` (a hard link: one file, two names;
    !> renaming another file over `old` later leaves `new` as it is). `new` must not exist.
    !> `linked` is false, and no error, on a file system without hard links.
    subroutine link_file(old, new, error, linked)
        character(len=*), intent(in) :: old, new
        type(error_type), allocatable, intent(out) :: error
        logical, intent(out) :: linked
        integer(c_int) :: status

        status = c_link(old // c_null_char, new // c_null_char)
        linked = status == 0
        if (status /= 1) call check_call(status, "cannot link '" // old // "' to '" // new &
            // "'", error)
    end subroutine link_file

    !> Remove `path` if it is a regular file; a symbolic link, a folder or anything else
    !> of that name is left alone (no file the program writes is ever one), and a
    !> missing file is fine.
    subroutine remove_file(path, error)
        character(len=*), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error

        if (c_remove_regular_file(path // c_null_char) == -1) &
            call fatal_error(error, "cannot remove '" // path // "': " // get_reason())
    end subroutine remove_file

    !> Flush the closed file `path` to its device (fsync), so that a rename after it
    !> cannot leave an empty file after a power cut.
    subroutine sync_file(path, error)
        character(len=*), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error

        call check_call(c_sync_file(path // c_null_char), &
            "cannot write '" // path // "' to disk", error)
    end subroutine sync_file

    !> Flush the entries of the folder `path` (a rename in it) to its device.
    subroutine sync_folder(path, error)
        character(len=*), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error

        call check_call(c_sync_folder(path // c_null_char), &
            "cannot write the entries of folder '" // path // "' to disk", error)
    end subroutine sync_folder

    !> Cut the (closed) file `path` back to `bytes` bytes, e.g. to drop a line that could
    !> be written only in part.
    subroutine truncate_file(path, bytes, error)
        character(len=*), intent(in) :: path
        integer(8), intent(in) :: bytes
        type(error_type), allocatable, intent(out) :: error

        call check_call(c_truncate_file(path // c_null_char, int(bytes, c_long_long)), &
            "cannot cut '" // path // "' back to its last whole line", error)
    end subroutine truncate_file

    !> Fail with '<what>: <reason of the failed C call>' unless `status` (of a call
    !> returning 0 on success) is 0.
    subroutine check_call(status, what, error)
        integer(c_int), intent(in) :: status
        character(len=*), intent(in) :: what
        type(error_type), allocatable, intent(out) :: error

        if (status /= 0) call fatal_error(error, what // ': ' // get_reason())
    end subroutine check_call

    !> Open the existing file `path` to append lines to it (`unit` = -1 on failure; a
    !> symbolic link is refused, not followed).
    subroutine open_append(unit, path, error)
        integer, intent(out) :: unit
        character(len=*), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        character(len=text_length) :: message
        integer(c_int) :: kind
        integer :: status

        unit = -1
        kind = c_file_kind(path // c_null_char)
        if (kind == kind_link .or. kind == kind_other) then
            call refuse_link(path, kind == kind_link, error)
            return
        end if
        message = ''
        open(newunit=unit, file=path, status='old', position='append', action='write', &
            iostat=status, iomsg=message)
        call check_open(unit, path, status, message, error)
    end subroutine open_append

    !> Open `path` to write it anew: formatted lines, or bytes with `stream` (`unit` = -1
    !> on failure). A regular file of that name is replaced by a new one (so another name
    !> of the old file, a hard link, keeps its content); a symbolic link or anything else
    !> of that name is refused (yarnfort_create_file).
    subroutine open_new_file(unit, path, error, stream)
        integer, intent(out) :: unit
        character(len=*), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        logical, intent(in), optional :: stream
        character(len=256) :: message
        integer :: status
        logical :: bytes

        bytes = .false.
        if (present(stream)) bytes = stream
        unit = -1
        status = c_create_file(path // c_null_char)
        if (status == kind_link .or. status == kind_other) then
            call refuse_link(path, status == kind_link, error)
            return
        else if (status /= 0) then
            call fatal_error(error, "cannot write '" // path // "': " // get_reason())
            return
        end if
        message = ''
        open(newunit=unit, file=path, access=merge('stream    ', 'sequential', bytes), &
            form=merge('unformatted', 'formatted  ', bytes), status='old', action='write', &
            iostat=status, iomsg=message)
        call check_open(unit, path, status, message, error)
    end subroutine open_new_file

    !> After an OPEN of `path` for writing with iostat `status` and iomsg `message`: on
    !> failure `unit` = -1 and the error says why.
    subroutine check_open(unit, path, status, message, error)
        integer, intent(inout) :: unit
        character(len=*), intent(in) :: path, message
        integer, intent(in) :: status
        type(error_type), allocatable, intent(out) :: error

        if (status /= 0) then
            unit = -1
            call fatal_error(error, "cannot write '" // path // "': " // trim(message))
        end if
    end subroutine check_open

    !> Close `unit`, on which the file `path` was written anew, after its last write
    !> (`status`, 0 if absent, and its iomsg `message`), checking that every byte reached
    !> the file (close_checked). On failure the file is removed and the error says why.
    subroutine close_new_file(unit, path, error, status, message)
        integer, intent(in) :: unit
        character(len=*), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        integer, intent(in), optional :: status
        character(len=*), intent(in), optional :: message
        type(error_type), allocatable :: ignored
        logical :: failed

        failed = .false.
        if (present(status)) failed = status /= 0
        if (failed) then
            close(unit)
            call fatal_error(error, "cannot write '" // path // "': " // trim(message))
        else
            call close_checked(unit, path, error)
        end if
        if (allocated(error)) call remove_file(path, ignored)
    end subroutine close_new_file

    !> Close `unit`, connected to the file `path`, and check that every byte written
    !> reached the file. (gfortran's CLOSE and FLUSH report no error when the buffered
    !> data cannot be written, e.g. on a full disk: the file's size tells.)
    subroutine close_checked(unit, path, error)
        integer, intent(in) :: unit
        character(len=*), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        character(len=256) :: message
        integer :: status

        call flush_checked(unit, path, error)
        message = ''
        close(unit, iostat=status, iomsg=message)
        if (status /= 0 .and. .not. allocated(error)) &
            call fatal_error(error, "cannot write '" // path // "': " // trim(message))
    end subroutine close_checked

    !> Flush `unit`, connected to the file `path`, and check that every byte written so
    !> far reached the file (see close_checked).
    subroutine flush_checked(unit, path, error)
        integer, intent(in) :: unit
        character(len=*), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        character(len=256) :: message
        integer(8) :: expected
        integer :: status

        message = ''
        flush(unit, iostat=status, iomsg=message)
        if (status /= 0) then
            call fatal_error(error, "cannot write '" // path // "': " // trim(message))
            return
        end if
        inquire(unit=unit, size=expected)
        call check_size(path, expected, error)
    end subroutine flush_checked

    !> Fail unless the file `path` has `expected` bytes; the error says whether its
    !> device is full.
    subroutine check_size(path, expected, error)
        character(len=*), intent(in) :: path
        integer(8), intent(in) :: expected
        type(error_type), allocatable, intent(out) :: error
        integer(c_long_long) :: actual, free, limit
        character(len=64) :: counts, limit_text

        if (expected < 0) return
        actual = c_file_size(path // c_null_char)
        if (actual == expected) return
        write(counts, '(i0, " of its ", i0)') max(actual, 0_c_long_long), expected
        free = c_free_space(path // c_null_char)
        limit = c_file_size_limit()
        if (limit >= 0 .and. expected > limit) then
            write(limit_text, '(i0)') limit
            call fatal_error(error, "cannot write '" // path // "': File too large (the " &
                // 'file size limit, ulimit -f, is ' // trim(limit_text) // ' bytes; the ' &
                // 'file got ' // trim(counts) // ' bytes)')
        else if (free == 0) then
            call fatal_error(error, "cannot write '" // path // "': No space left on " &
                // 'device (the file got ' // trim(counts) // ' bytes)')
        else
            call fatal_error(error, "cannot write '" // path // "': the file got " &
                // trim(counts) // ' bytes (the device failed or is full)')
        end if
    end subroutine check_size

    !> Take the lock of `folder` (its file .yarnfort-lock). If another process holds it
    !> the error says who (pid, host, since when); the lock then stays theirs. A lock
    !> file that is a link or has other names is refused (the run's line is written
    !> into it).
    subroutine acquire_lock(self, folder, error)
        class(folder_lock_type), intent(inout) :: self
        character(len=*), intent(in) :: folder
        type(error_type), allocatable, intent(out) :: error
        character(kind=c_char, len=text_length) :: holder
        integer(c_int) :: status, fd
        integer :: n

        if (self%fd >= 0) return
        holder = ''
        status = c_lock_file(folder // '/' // lock_file_name // c_null_char, fd, holder, &
            int(text_length, c_int))
        select case (status)
        case (0)
            self%fd = fd
        case (kind_link, kind_other)
            call refuse_link(folder // '/' // lock_file_name, status == kind_link, error)
        case (1)
            n = index(holder, c_null_char) - 1
            if (n < 0) n = len_trim(holder)
            if (n == 0) holder = 'a process that has not written its name yet'
            if (n == 0) n = len_trim(holder)
            call fatal_error(error, "&output: folder '" // folder // "' is in use by another " &
                // 'yarnfort run (' // holder(:n) // '); wait for it to end or choose ' &
                // 'another &output folder')
        case default
            call fatal_error(error, "&output: cannot lock folder '" // folder // "' (file " &
                // lock_file_name // '): ' // get_reason())
        end select
    end subroutine acquire_lock

    subroutine release_lock(self)
        class(folder_lock_type), intent(inout) :: self
        integer(c_int) :: status

        if (self%fd < 0) return
        status = c_unlock_file(self%fd)
        self%fd = -1
    end subroutine release_lock

    pure logical function is_held(self)
        class(folder_lock_type), intent(in) :: self
        is_held = self%fd >= 0
    end function is_held

    subroutine finalize_lock(self)
        type(folder_lock_type), intent(inout) :: self
        call self%release()
    end subroutine finalize_lock

    !> The C library's text for the reason of the last failed call.
    function get_reason() result(reason)
        character(len=:), allocatable :: reason
        character(kind=c_char, len=text_length) :: text
        integer :: n

        text = ''
        call c_last_error(text, int(text_length, c_int))
        n = index(text, c_null_char) - 1
        if (n < 0) n = len_trim(text)
        reason = text(:n)
    end function get_reason

end module yarnfort_output_filesystem
