! SPDX-License-Identifier: MIT
!> Unit tests of the numbers in messages (format_short, issue 42): every finite double
!> with its exponent letter, three-digit exponents and subnormals included, rounded to
!> the digits asked for; NaN and infinities by name.
module test_text
    use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, &
        ieee_positive_inf, ieee_negative_inf
    use, intrinsic :: iso_fortran_env, only: int64
    use yarnfort_kinds, only: wp
    use yarnfort_testing, only: unittest_type, new_unittest, check
    use yarnfort_error, only: error_type
    use yarnfort_text, only: format_short
    implicit none
    private

    public :: collect_text

contains

    subroutine collect_text(testsuite)
        type(unittest_type), allocatable, intent(out) :: testsuite(:)

        testsuite = [ &
            new_unittest('short_numbers', test_short_numbers), &
            new_unittest('short_special_values', test_short_special_values), &
            new_unittest('short_reads_back', test_short_reads_back)]
    end subroutine collect_text

    !> Values written out by hand: 3 significant digits unless asked otherwise.
    subroutine test_short_numbers(error)
        type(error_type), allocatable, intent(out) :: error

        ! The largest double, 1.7976931348623157e308, and the smallest subnormal,
        ! 2**-1074 = 4.9406564584124654e-324 (bits 1): three-digit exponents.
        call expect(error, huge(1.0_wp), 3, '1.80e308')
        if (allocated(error)) return
        call expect(error, -huge(1.0_wp), 3, '-1.80e308')
        if (allocated(error)) return
        call expect(error, 1.79e308_wp, 3, '1.79e308')
        if (allocated(error)) return
        call expect(error, transfer(1_int64, 1.0_wp), 3, '4.94e-324')
        if (allocated(error)) return
        call expect(error, tiny(1.0_wp), 4, '2.225e-308')
        if (allocated(error)) return
        call expect(error, 1.0e100_wp, 3, '1.00e100')
        if (allocated(error)) return
        call expect(error, 9.999e99_wp, 3, '1.00e100')
        if (allocated(error)) return
        call expect(error, -2.5e-3_wp, 3, '-2.50e-3')
        if (allocated(error)) return
        call expect(error, 1.0_wp, 3, '1.00e0')
        if (allocated(error)) return
        call expect(error, 0.0_wp, 3, '0.00e0')
        if (allocated(error)) return
        call expect(error, 2.0_wp, 1, '2e0')
        if (allocated(error)) return
        call expect(error, huge(1.0_wp), 17, '1.7976931348623157e308')
    end subroutine test_short_numbers

    subroutine test_short_special_values(error)
        type(error_type), allocatable, intent(out) :: error

        call expect(error, ieee_value(1.0_wp, ieee_quiet_nan), 3, 'NaN')
        if (allocated(error)) return
        call expect(error, ieee_value(1.0_wp, ieee_positive_inf), 3, 'Infinity')
        if (allocated(error)) return
        call expect(error, ieee_value(1.0_wp, ieee_negative_inf), 3, '-Infinity')
    end subroutine test_short_special_values

    !> With 17 digits every double, from the smallest subnormal to the largest, reads back
    !> exactly, and every text holds its exponent letter.
    subroutine test_short_reads_back(error)
        type(error_type), allocatable, intent(out) :: error
        real(wp) :: value, back
        integer :: k, stat
        character(len=:), allocatable :: text

        do k = -1074, 1023, 7
            value = (1.0_wp + 0.1_wp * modulo(k, 9)) * 2.0_wp**k
            text = format_short(value, 17)
            read(text, *, iostat=stat) back
            call check(error, stat == 0 .and. back == value .and. index(text, 'e') > 1, &
                'format_short(2**' // format_short(real(k, wp), 4) // ' * ...) = ' // text &
                // ' does not read back')
            if (allocated(error)) return
            text = format_short(-value)
            call check(error, text(1:1) == '-' .and. index(text, 'e') == 6, &
                'format_short(-value) = ' // text // ': not -d.dde<exponent>')
            if (allocated(error)) return
        end do
    end subroutine test_short_reads_back

    subroutine expect(error, value, digits, text)
        type(error_type), allocatable, intent(out) :: error
        real(wp), intent(in) :: value
        integer, intent(in) :: digits
        character(len=*), intent(in) :: text

        call check(error, format_short(value, digits) == text, 'format_short: ' &
            // format_short(value, digits) // ' instead of ' // text)
    end subroutine expect

end module test_text
