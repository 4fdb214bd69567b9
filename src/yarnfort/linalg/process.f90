! SPDX-License-Identifier: MIT
!> The process-wide settings of the libraries under the linear solvers: threads of the
!> libraries' OpenMP regions and of OpenBLAS (process/threads.f90), and how malloc serves
!> the factorisations' large blocks (process/heap.f90). Made once, explicitly, by each
!> program and by the Python entry point before any solve, never by a solver's
!> constructor; a setting the user made in the environment takes precedence.
module yarnfort_linalg_process
    use yarnfort_linalg_process_threads, only: apply_thread_policy, count_serial_regions
    use yarnfort_linalg_process_heap, only: apply_heap_policy
    implicit none
    private

    public :: apply_process_settings, apply_thread_policy, apply_heap_policy
    public :: count_serial_regions

contains

    !> Apply the thread and the heap policy (only the first call does anything).
    subroutine apply_process_settings()
        call apply_thread_policy()
        call apply_heap_policy()
    end subroutine apply_process_settings

end module yarnfort_linalg_process
