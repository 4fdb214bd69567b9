! SPDX-License-Identifier: MIT
!> Threads of the libraries under the linear solvers: their own OpenMP regions (Debian's
!> CHOLMOD asks for 4 threads whatever OMP_NUM_THREADS says) and OpenBLAS run on one
!> thread, which is faster on the factorisations measured and never competes with other
!> processes for the cores (docs/decisions.md, 'Process settings: ...'). Applied once
!> per process by the program and the Python entry point (yarnfort_linalg_process);
!> OMP_THREAD_LIMIT and OPENBLAS_NUM_THREADS set by the user take precedence (threads.c).
module yarnfort_linalg_process_threads
    use, intrinsic :: iso_c_binding, only: c_int, c_long
    implicit none
    private

    public :: apply_thread_policy, library_openmp, blas_threads, count_serial_regions

    !> Let the libraries' own OpenMP regions run in parallel.
    logical, parameter :: library_openmp = .false.
    !> OpenBLAS threads.
    integer, parameter :: blas_threads = 1

    interface
        function yarnfort_serial_regions() result(count) bind(C, name='yarnfort_serial_regions')
            import :: c_long
            integer(c_long) :: count
        end function yarnfort_serial_regions
        function yarnfort_apply_thread_policy(openmp, threads) result(applied) &
                bind(C, name='yarnfort_apply_thread_policy')
            import :: c_int
            integer(c_int), value :: openmp, threads
            integer(c_int) :: applied
        end function yarnfort_apply_thread_policy
    end interface

contains

    !> Apply the policy (only the first call does anything). `openmp_limited` and
    !> `blas_set`: what it changed (false where the user's environment decides, or the
    !> library is not there).
    subroutine apply_thread_policy(openmp_limited, blas_set)
        logical, intent(out), optional :: openmp_limited, blas_set
        integer(c_int) :: applied

        applied = yarnfort_apply_thread_policy(merge(1_c_int, 0_c_int, library_openmp), &
            int(blas_threads, c_int))
        if (present(openmp_limited)) openmp_limited = iand(applied, 1_c_int) /= 0
        if (present(blas_set)) blas_set = iand(applied, 2_c_int) /= 0
    end subroutine apply_thread_policy

    !> OpenMP regions of the libraries run on the calling thread so far (threads.c).
    integer function count_serial_regions()
        count_serial_regions = int(yarnfort_serial_regions())
    end function count_serial_regions

end module yarnfort_linalg_process_threads
