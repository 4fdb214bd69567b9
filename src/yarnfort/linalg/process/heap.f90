! SPDX-License-Identifier: MIT
!> How the process's heap serves the factorisations' large blocks, chosen by
!> measurement (benchmarks/results-issue16-run9.md; woven load cycle of 963,600 unknowns,
!> `steps_trace --woven 219`, 60 steps, idle machine): with glibc's defaults every
!> UMFPACK numeric factorisation maps its working memory afresh and the kernel
!> zero-fills it page by page, 35.6 million page faults and 98 s of system time against
!> 260 s user; served from a heap that keeps what is freed, 0.85 million faults, 7.6 s
!> system, the same user time, 5,848 -> 4,344 CPU ms per load step (peak RSS 2.98 ->
!> 3.40 GB). At 96,600 unknowns (KLU, blocks under 32 MiB) 0.43 -> 0.24 s system.
!> The policy (heap.c): no memory mapped by malloc while the heap can grow, and no freed
!> memory returned to the system before the process ends, so the resident size stays at
!> its peak. Applied once per process, at the first linear solver; a user's own malloc
!> tuning (GLIBC_TUNABLES, MALLOC_*_) takes precedence.
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
