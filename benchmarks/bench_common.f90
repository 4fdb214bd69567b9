! SPDX-License-Identifier: MIT
!> What the benchmark programs share: peak memory, failing with a message (or with their
!> usage, for a bad command line), and the node numbering of their square nets.
module bench_common
    use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type
    implicit none
    private

    public :: peak_memory_mib, fail, number_grid_nodes, fail_usage, stop_if_help, &
        read_integer_argument

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

    !> Node ids 1..n of a (side + 2) x (side + 2) grid without its four corners, row by
    !> row (0 at the corners): interior nodes plus one anchor on each edge.
    pure subroutine number_grid_nodes(side, id, n)
        integer, intent(in) :: side
        integer, allocatable, intent(out) :: id(:, :)
        integer, intent(out) :: n
        integer :: i, j

        allocate(id(0:side + 1, 0:side + 1), source=0)
        n = 0
        do j = 0, side + 1
            do i = 0, side + 1
                if ((i == 0 .or. i == side + 1) .and. (j == 0 .or. j == side + 1)) cycle
                n = n + 1
                id(i, j) = n
            end do
        end do
    end subroutine number_grid_nodes

    !> Print the error after the program's name and stop with exit code 1.
    subroutine fail(program_name, error)
        character(len=*), intent(in) :: program_name
        type(error_type), intent(in) :: error
        write(error_unit, '(a)') program_name // ': ' // error%message
        stop 1, quiet=.true.
    end subroutine fail

    !> A bad command line: print the problem and the usage, stop with exit code 2.
    subroutine fail_usage(program_name, problem, usage)
        character(len=*), intent(in) :: program_name, problem, usage
        write(error_unit, '(a)') program_name // ': ' // problem
        write(error_unit, '(a)') usage
        stop 2, quiet=.true.
    end subroutine fail_usage

    !> With -h or --help anywhere on the command line: print the usage, stop with 0.
    subroutine stop_if_help(usage)
        character(len=*), intent(in) :: usage
        character(len=16) :: argument
        integer :: k
        do k = 1, command_argument_count()
            call get_command_argument(k, argument)
            if (argument == '-h' .or. argument == '--help') then
                write(output_unit, '(a)') usage
                stop 0, quiet=.true.
            end if
        end do
    end subroutine stop_if_help

    !> The integer `text` given for `what`, or fail_usage.
    integer function read_integer_argument(program_name, what, text, usage) result(value)
        character(len=*), intent(in) :: program_name, what, text, usage
        integer :: status
        read(text, *, iostat=status) value
        if (status /= 0) call fail_usage(program_name, what // " must be an integer, not '" &
            // trim(text) // "'", usage)
    end function read_integer_argument

end module bench_common
