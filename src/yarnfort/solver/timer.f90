! SPDX-License-Identifier: MIT
!> Wall-clock time for measurements (solver statistics and benchmarks).
module yarnfort_solver_timer
    use yarnfort_kinds, only: wp
    use, intrinsic :: iso_fortran_env, only: int64
    implicit none
    private

    public :: wall_time

contains

    !> Seconds since an arbitrary fixed origin.
    function wall_time() result(seconds)
        real(wp) :: seconds
        integer(int64) :: count, rate
        call system_clock(count, rate)
        seconds = real(count, wp) / real(rate, wp)
    end function wall_time

end module yarnfort_solver_timer
