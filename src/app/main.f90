! SPDX-License-Identifier: MIT
program yarnfort_main
    implicit none
end program yarnfort_main
