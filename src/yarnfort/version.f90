! SPDX-License-Identifier: MIT
!> Version of the library and program.
module yarnfort_version
    implicit none
    private

    public :: yarnfort_version_string

    !> Semantic version, kept equal to the version in meson.build.
    character(len=*), parameter :: yarnfort_version_string = '0.1.0'

end module yarnfort_version
