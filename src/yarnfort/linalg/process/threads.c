/* SPDX-License-Identifier: MIT */
/*
 * The thread policy for the libraries under the linear solvers, applied once per process
 * (docs/decisions.md, 'Process settings: ...'):
 * - OpenMP regions inside the libraries (Debian's CHOLMOD asks for a fixed 4 threads in
 *   its supernodal factorisation, a num_threads clause that OMP_NUM_THREADS does not
 *   override) run on one thread: max-active-levels is set to 0, unless the user set
 *   OMP_THREAD_LIMIT; once limited, they run on the calling thread without libgomp's
 *   team machinery (GOMP_parallel below);
 * - OpenBLAS, when it is the BLAS in use, gets the given number of threads, unless the
 *   user set OPENBLAS_NUM_THREADS.
 * The OpenMP and OpenBLAS entry points are looked up in the running process (dlsym), so
 * nothing here needs them at link time and a reference BLAS is left alone.
 *
 * OpenBLAS (pthreads build) starts its worker threads when it is loaded, one per core
 * but the caller's, and each spins (sched_yield) for 2^28 TSC cycles, about 0.1 s, before
 * it sleeps; openblas_set_num_threads starts them again if they were stopped: a second
 * core burnt at the start of every process, whatever the number of threads. Unless the
 * user set OPENBLAS_NUM_THREADS, the workers are stopped when this library is loaded (a
 * constructor: it runs after those of the libraries it depends on) and again right
 * after the policy sets one thread, with OpenBLAS's own blas_thread_shutdown_ (the call
 * its fork handler makes). OpenBLAS starts them again at its first multithreaded call,
 * which with one thread never comes.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdlib.h>

typedef void (*set_int_function)(int);
typedef void (*region_body)(void *);
typedef void (*parallel_function)(region_body, void *, unsigned, unsigned);

/* Bits of the result: OpenMP regions limited, OpenBLAS threads set. */
#define YARNFORT_THREADS_OPENMP 1
#define YARNFORT_THREADS_OPENBLAS 2

static int applied = -1;

/* Regions run here on the calling thread (a count for the tests). */
static long serial_regions = 0;

/* The user's OPENBLAS_NUM_THREADS decides OpenBLAS's threads. */
static int blas_left_to_user(void)
{
    return getenv("OPENBLAS_NUM_THREADS") != NULL;
}

/* Stop OpenBLAS's worker threads if OpenBLAS is loaded. */
static void stop_blas_workers(void)
{
    typedef int (*shutdown_function)(void);
    shutdown_function shutdown;
    shutdown = (shutdown_function) dlsym(RTLD_DEFAULT, "blas_thread_shutdown_");
    if (shutdown) shutdown();
}

__attribute__((constructor)) static void stop_blas_workers_at_load(void)
{
    if (!blas_left_to_user()) stop_blas_workers();
}

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
    if (blas_threads > 0 && !blas_left_to_user()) {
        set = (set_int_function) dlsym(RTLD_DEFAULT, "openblas_set_num_threads");
        if (set) {
            set(blas_threads);
            if (blas_threads == 1) stop_blas_workers();
            applied |= YARNFORT_THREADS_OPENBLAS;
        }
    }
    return applied;
}

/*
 * libgomp's entry point for `#pragma omp parallel` (GCC 4.9 on), defined here so that
 * the libraries bind to it: the dynamic linker looks in the executable (or in the module
 * that holds this library) before libgomp. Debian's CHOLMOD (the only user: it imports
 * GOMP_parallel, omp_get_num_threads and omp_get_thread_num and nothing else) enters a
 * region two or three times per supernode, `if` clause or not, and libgomp makes a team
 * of one for each, ending with a futex wake (a system call per region). With the regions
 * limited (the policy above) the body runs here on the calling thread, where
 * omp_get_num_threads() is 1 and omp_get_thread_num() 0, as in a team of one: the same
 * work, in the same order (docs/decisions.md, 'Process settings: limited OpenMP regions
 * run on the calling thread').
 * Otherwise (the user's OMP_THREAD_LIMIT, or before the policy) libgomp's own runs.
 */
void GOMP_parallel(region_body body, void *data, unsigned num_threads, unsigned flags)
{
    static parallel_function next = NULL;
    if (applied >= 0 && (applied & YARNFORT_THREADS_OPENMP)) {
        serial_regions++;
        body(data);
        return;
    }
    if (!next) next = (parallel_function) dlsym(RTLD_NEXT, "GOMP_parallel");
    if (!next) {
        body(data);
        return;
    }
    next(body, data, num_threads, flags);
}

long yarnfort_serial_regions(void)
{
    return serial_regions;
}
