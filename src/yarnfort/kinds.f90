! SPDX-License-Identifier: MIT
!> Working precision and the few kind parameters the library uses.
module yarnfort_kinds
    use, intrinsic :: iso_fortran_env, only: real64, int64
    implicit none
    private

    public :: wp, ik

    !> Working precision for all real quantities.
    integer, parameter :: wp = real64
    !> Index kind for sparse matrices (SUNDIALS' 64-bit sunindextype, UMFPACK's dl interface).
    integer, parameter :: ik = int64

end module yarnfort_kinds
