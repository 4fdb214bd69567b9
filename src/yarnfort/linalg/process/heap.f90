! SPDX-License-Identifier: MIT
!> How the process's heap serves the factorisations' large blocks (heap.c): no memory
!> mapped by malloc while the heap can grow, and no freed memory returned to the system
!> before the process ends, so that UMFPACK's working memory is not zero-filled by the
!> kernel page by page at every factorisation; the resident size stays at its peak
!> (docs/decisions.md, 'Process settings: malloc keeps its heap'). Applied once per
!> process by the program and the Python entry point (yarnfort_linalg_process); a user's
!> own malloc tuning (GLIBC_TUNABLES, MALLOC_*_) takes precedence.
module yarnfort_linalg_process_heap
    use, intrinsic :: iso_c_binding, only: c_int
    implicit none
    private

    public :: apply_heap_policy

    interface
        function yarnfort_apply_heap_policy() result(applied) &
                bind(C, name='yarnfort_apply_heap_policy')
            import :: c_int
            integer(c_int) :: applied
        end function yarnfort_apply_heap_policy
    end interface

contains

    !> Apply the policy (only the first call does anything); `applied`: whether the
    !> process runs with it (false where the user's environment decides, or without glibc).
    subroutine apply_heap_policy(applied)
        logical, intent(out), optional :: applied
        integer(c_int) :: status

        status = yarnfort_apply_heap_policy()
        if (present(applied)) applied = status == 1_c_int
    end subroutine apply_heap_policy

end module yarnfort_linalg_process_heap
