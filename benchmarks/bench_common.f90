! SPDX-License-Identifier: MIT
!> What the benchmark programs share: peak memory and failing with a message.
module bench_common
    use, intrinsic :: iso_fortran_env, only: error_unit
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    implicit none
    private

    public :: peak_memory_mib, fail

contains

    !> Peak resident memory of this process (VmHWM of /proc/self/status), MiB; -1 if
    !> unknown.
    real(wp) function peak_memory_mib()
        character(len=256) :: line
        integer :: unit, status, kib
        peak_memory_mib = -1.0_wp
        open(newunit=unit, file='/proc/self/status', action='read', iostat=status)
        if (status /= 0) return
        do
            read(unit, '(a)', iostat=status) line
            if (status /= 0) exit
            if (line(1:6) == 'VmHWM:') then
                read(line(7:), *) kib
                peak_memory_mib = kib / 1024.0_wp
            end if
        end do
        close(unit)
    end function peak_memory_mib

    !> Print the error after the program's name and stop with exit code 1.
    subroutine fail(program_name, error)
        character(len=*), intent(in) :: program_name
        type(error_type), intent(in) :: error
        write(error_unit, '(a)') program_name // ': ' // error%message
        error stop 1
    end subroutine fail

end module bench_common
