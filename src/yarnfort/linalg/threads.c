/* SPDX-License-Identifier: MIT */
/*
 * The thread policy for the libraries under the linear solvers, applied once per process
 * (see yarnfort_linalg_threads for the measurements that chose it):
 * - OpenMP regions inside the libraries (Debian's CHOLMOD asks for a fixed 4 threads in
 *   its supernodal factorisation, a num_threads clause that OMP_NUM_THREADS does not
 *   override) run on one thread: max-active-levels is set to 0, unless the user set
 *   OMP_THREAD_LIMIT;
 * - OpenBLAS, when it is the BLAS in use, gets the given number of threads, unless the
 *   user set OPENBLAS_NUM_THREADS.
 * The OpenMP and OpenBLAS entry points are looked up in the running process (dlsym), so
 * nothing here needs them at link time and a reference BLAS is left alone.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdlib.h>

typedef void (*set_int_function)(int);

/* Bits of the result: OpenMP regions limited, OpenBLAS threads set. */
#define YARNFORT_THREADS_OPENMP 1
#define YARNFORT_THREADS_OPENBLAS 2

static int applied = -1;

int yarnfort_apply_thread_policy(int library_openmp, int blas_threads)
{
    set_int_function set;
    if (applied >= 0) return applied;
    applied = 0;
    if (!library_openmp && !getenv("OMP_THREAD_LIMIT")) {
        set = (set_int_function) dlsym(RTLD_DEFAULT, "omp_set_max_active_levels");
        if (set) {
            set(0);
            applied |= YARNFORT_THREADS_OPENMP;
        }
    }
    if (blas_threads > 0 && !getenv("OPENBLAS_NUM_THREADS")) {
        set = (set_int_function) dlsym(RTLD_DEFAULT, "openblas_set_num_threads");
        if (set) {
            set(blas_threads);
            applied |= YARNFORT_THREADS_OPENBLAS;
        }
    }
    return applied;
}
