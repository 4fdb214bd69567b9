! SPDX-License-Identifier: MIT
!> Folder creation through the C library (Fortran has no portable mkdir).
module yarnfort_output_filesystem
    use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char
    use yarnfort_error, only: error_type, fatal_error
    implicit none
    private

    public :: make_folder

    interface
        function c_mkdir(path, mode) result(status) bind(C, name='mkdir')
            import :: c_int, c_char
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int), value :: mode
            integer(c_int) :: status
        end function c_mkdir
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

end module yarnfort_output_filesystem
