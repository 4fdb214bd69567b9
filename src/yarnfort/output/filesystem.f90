! SPDX-License-Identifier: MIT
!> Folder creation and file renaming through the C library (Fortran has no portable
!> mkdir or rename).
module yarnfort_output_filesystem
    use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char
    use yarnfort_error, only: error_type, fatal_error
    implicit none
    private

    public :: make_folder, rename_file

    interface
        function c_mkdir(path, mode) result(status) bind(C, name='mkdir')
            import :: c_int, c_char
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int), value :: mode
            integer(c_int) :: status
        end function c_mkdir

        function c_rename(old, new) result(status) bind(C, name='rename')
            import :: c_int, c_char
            character(kind=c_char), intent(in) :: old(*), new(*)
            integer(c_int) :: status
        end function c_rename
    end interface

    !> Permissions of new folders (rwxr-xr-x before the umask).
    integer(c_int), parameter :: folder_mode = int(o'755', c_int)

contains

    !> Create `path` and its missing parents; an existing folder is fine. The error
    !> names the folder that could not be created or written.
    subroutine make_folder(path, error)
        character(len=*), intent(in) :: path
        type(error_type), allocatable, intent(out) :: error
        integer :: i, status, unit
        character(len=:), allocatable :: probe

        do i = 2, len_trim(path)
            if (path(i:i) == '/') status = c_mkdir(path(1:i - 1) // c_null_char, folder_mode)
        end do
        status = c_mkdir(trim(path) // c_null_char, folder_mode)
        ! Whatever mkdir said, the folder is usable if a file can be created in it.
        probe = trim(path) // '/.yarnfort-write-test'
        open(newunit=unit, file=probe, status='replace', action='write', iostat=status)
        if (status /= 0) then
            call fatal_error(error, "&output: folder '" // trim(path) &
                // "' cannot be created or written")
            return
        end if
        close(unit, status='delete')
    end subroutine make_folder

    !> Rename `old` to `new`, replacing `new` if it exists. On POSIX systems this is
    !> atomic: `new` is always either the old file or the complete new one.
    subroutine rename_file(old, new, error)
        character(len=*), intent(in) :: old, new
        type(error_type), allocatable, intent(out) :: error

        if (c_rename(old // c_null_char, new // c_null_char) /= 0) &
            call fatal_error(error, "cannot rename '" // old // "' to '" // new // "'")
    end subroutine rename_file

end module yarnfort_output_filesystem
