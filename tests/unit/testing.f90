! SPDX-License-Identifier: MIT
!> A small unit-test harness in the test-drive style: each suite exports
!> `collect_<suite>(testsuite)` returning named tests; a test sets `error` to fail.
module yarnfort_testing
    use yarnfort_kinds, only: wp
    use yarnfort_error, only: error_type, fatal_error
    implicit none
    private

    public :: unittest_type, new_unittest, test_interface, collect_interface
    public :: check, check_close, run_testsuite

    abstract interface
        subroutine test_interface(error)
            import :: error_type
            type(error_type), allocatable, intent(out) :: error
        end subroutine test_interface
    end interface

    !> One named test.
    type :: unittest_type
        character(len=:), allocatable :: name
        procedure(test_interface), pointer, nopass :: test => null()
    end type unittest_type

    abstract interface
        subroutine collect_interface(testsuite)
            import :: unittest_type
            type(unittest_type), allocatable, intent(out) :: testsuite(:)
        end subroutine collect_interface
    end interface

    interface check_close
        module procedure check_close_scalar
        module procedure check_close_array
    end interface check_close

contains

    function new_unittest(name, test) result(self)
        character(len=*), intent(in) :: name
        procedure(test_interface) :: test
        type(unittest_type) :: self

        self%name = name
        self%test => test
    end function new_unittest

    !> Fail with `message` unless `condition` holds.
    subroutine check(error, condition, message)
        type(error_type), allocatable, intent(out) :: error
        logical, intent(in) :: condition
        character(len=*), intent(in) :: message

        if (.not. condition) call fatal_error(error, message)
    end subroutine check

    !> Fail unless |actual - expected| <= max(abs_tol, rel_tol*|expected|).
    subroutine check_close_scalar(error, actual, expected, rel_tol, what, abs_tol)
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in) :: actual, expected, rel_tol
        character(len=*), intent(in) :: what
        real(wp), intent(in), optional :: abs_tol
        real(wp) :: tol
        character(len=200) :: buffer

        tol = rel_tol * abs(expected)
        if (present(abs_tol)) tol = max(tol, abs_tol)
        if (.not. (abs(actual - expected) <= tol)) then
            write(buffer, '(a, ": got ", es24.16, " expected ", es24.16, " (tol ", es9.2, ")")') &
                what, actual, expected, tol
            call fatal_error(error, trim(buffer))
        end if
    end subroutine check_close_scalar

    subroutine check_close_array(error, actual, expected, rel_tol, what, abs_tol)
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in) :: actual(:), expected(:), rel_tol
        character(len=*), intent(in) :: what
        real(wp), intent(in), optional :: abs_tol
        integer :: i
        character(len=20) :: index

        if (size(actual) /= size(expected)) then
            call fatal_error(error, what // ': sizes differ')
            return
        end if
        do i = 1, size(actual)
            write(index, '("(", i0, ")")') i
            call check_close_scalar(error, actual(i), expected(i), rel_tol, &
                what // trim(index), abs_tol)
            if (allocated(error)) return
        end do
    end subroutine check_close_array

    !> Run every test of a suite, print one line per test and a closing count line.
    subroutine run_testsuite(suite, collect, nfail)
        use, intrinsic :: iso_fortran_env, only: output_unit
        character(len=*), intent(in) :: suite
        procedure(collect_interface) :: collect
        integer, intent(out) :: nfail
        type(unittest_type), allocatable :: tests(:)
        type(error_type), allocatable :: error
        integer :: i, npass

        call collect(tests)
        nfail = 0
        npass = 0
        do i = 1, size(tests)
            call tests(i)%test(error)
            if (allocated(error)) then
                nfail = nfail + 1
                write(output_unit, '(a)') '  FAIL ' // suite // '/' // tests(i)%name // ': ' &
                    // error%message
                deallocate(error)
            else
                npass = npass + 1
                write(output_unit, '(a)') '  ok   ' // suite // '/' // tests(i)%name
            end if
        end do
        write(output_unit, '(i0, " passed, ", i0, " failed")') npass, nfail
    end subroutine run_testsuite

end module yarnfort_testing
