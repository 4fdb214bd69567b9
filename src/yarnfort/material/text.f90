! SPDX-License-Identifier: MIT
!> Text helpers for the messages of the material laws.
module yarnfort_material_text
    use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
    use yarnfort_kinds, only: wp
    implicit none
    private

    public :: format_real

    !> Significant digits that always round-trip a real(wp).
    integer, parameter :: max_digits = 17
    !> Decimal exponents written in fixed notation.
    integer, parameter :: min_fixed_exponent = -4, max_fixed_exponent = 9

contains

    !> Shortest decimal text that reads back as `value`: fixed notation for moderate
    !> magnitudes ('0.31', '-2', '500'), scientific otherwise ('1E-20'); 'NaN', 'Infinity'.
    pure function format_real(value) result(text)
        real(wp), intent(in) :: value
        character(len=:), allocatable :: text
        character(len=60) :: buffer, fmt
        real(wp) :: readback
        integer :: digits, stat, exponent, mark

        if (ieee_is_nan(value)) then
            text = 'NaN'
            return
        else if (.not. ieee_is_finite(value)) then
            text = merge('Infinity ', '-Infinity', value > 0.0_wp)
            text = trim(text)
            return
        else if (.not. abs(value) > 0.0_wp) then
            text = '0'
            return
        end if
        ! Fewest significant digits (digits + 1, at least 2: gfortran writes all digits
        ! for es0.0) that round-trip.
        do digits = 1, max_digits - 1
            write(fmt, '("(es0.", i0, ")")') digits
            write(buffer, fmt) value
            read(buffer, *, iostat=stat) readback
            ! Exact round trip (written as a difference to keep -Wcompare-reals quiet).
            if (stat == 0 .and. .not. abs(readback - value) > 0.0_wp) exit
        end do
        digits = min(digits, max_digits - 1)
        ! gfortran leaves out a zero exponent ('2.0' for 2).
        mark = index(buffer, 'E')
        exponent = 0
        if (mark > 0) read(buffer(mark + 1:), *, iostat=stat) exponent
        if (mark > 0 .and. stat /= 0) exponent = 0
        if (exponent >= min_fixed_exponent .and. exponent <= max_fixed_exponent) then
            write(fmt, '("(f0.", i0, ")")') max(0, digits - exponent)
            write(buffer, fmt) value
            text = strip_zeros(trim(adjustl(buffer)))
            ! gfortran writes '.31' for 0.31.
            if (index(text, '.') == 1) text = '0' // text
            if (index(text, '-.') == 1) text = '-0' // text(2:)
        else
            text = trim(adjustl(buffer))
            mark = index(text, 'E')
            if (mark > 0) text = strip_zeros(text(:mark - 1)) // text(mark:)
        end if
    end function format_real

    !> Drop trailing zeros after a decimal point, and the point if nothing follows it.
    pure function strip_zeros(number) result(text)
        character(len=*), intent(in) :: number
        character(len=:), allocatable :: text
        integer :: last

        text = number
        if (index(text, '.') == 0) return
        last = len_trim(text)
        do while (last > 1 .and. text(last:last) == '0')
            last = last - 1
        end do
        if (text(last:last) == '.') last = last - 1
        text = text(:last)
    end function strip_zeros

end module yarnfort_material_text
