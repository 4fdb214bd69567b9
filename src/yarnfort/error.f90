! SPDX-License-Identifier: MIT
!> Error values that travel up the call chain instead of stopping the program.
module yarnfort_error
    implicit none
    private

    public :: error_type, fatal_error, prefix_error

    !> An error: a status code and a message that names what was wrong.
    type :: error_type
        integer :: stat = 1
        character(len=:), allocatable :: message
    end type error_type

contains

    !> Allocate `error` and set its message.
    pure subroutine fatal_error(error, message, stat)
        type(error_type), allocatable, intent(out) :: error
        character(len=*), intent(in) :: message
        integer, intent(in), optional :: stat

        allocate(error)
        error%message = message
        if (present(stat)) error%stat = stat
    end subroutine fatal_error

    !> Put context in front of an existing error message ("context: message").
    pure subroutine prefix_error(error, context)
        type(error_type), intent(inout) :: error
        character(len=*), intent(in) :: context

        error%message = context // ': ' // error%message
    end subroutine prefix_error

end module yarnfort_error
