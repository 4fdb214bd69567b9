/* SPDX-License-Identifier: MIT */
/*
 * Bare CHOLMOD for bench_floor: cholmod_l_analyze once, then cholmod_l_factorize +
 * cholmod_l_solve repeated on the same matrix with CHOLMOD's defaults (no yarnfort shim),
 * timed in process CPU time like the rest of the floor. The matrix is the caller's CSC
 * arrays (0-based, both triangles stored; CHOLMOD reads the upper one, stype = 1).
 * Returns 0 and sets *ms (CPU ms per factorize + solve) and *lnz (nonzeros of L as
 * CHOLMOD counts them after the analysis), or CHOLMOD's status (< 0 or not positive
 * definite: 1) without timing.
 */
#include <string.h>
#include <time.h>

#include "cholmod.h"

static double cpu_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double) t.tv_sec + 1e-9 * (double) t.tv_nsec;
}

int bench_cholmod_time(SuiteSparse_long n, SuiteSparse_long *col_ptr,
                       SuiteSparse_long *row_index, double *values, double target_seconds,
                       int max_repetitions, double supernodal_switch, double *ms,
                       double *lnz)
{
    cholmod_common common;
    cholmod_sparse a;
    cholmod_factor *factor;
    cholmod_dense *b, *x;
    double start, first;
    int k, repetitions, status = 0;

    *ms = -1.0;
    *lnz = 0.0;
    if (!cholmod_l_start(&common)) return -1;
    common.print = 0;
    common.supernodal_switch = supernodal_switch;
    memset(&a, 0, sizeof(a));
    a.nrow = a.ncol = (size_t) n;
    a.nzmax = (size_t) col_ptr[n];
    a.p = col_ptr;
    a.i = row_index;
    a.x = values;
    a.stype = 1;
    a.itype = CHOLMOD_LONG;
    a.xtype = CHOLMOD_REAL;
    a.dtype = CHOLMOD_DOUBLE;
    a.sorted = 1;
    a.packed = 1;
    b = cholmod_l_ones((size_t) n, 1, CHOLMOD_REAL, &common);
    factor = cholmod_l_analyze(&a, &common);
    if (!factor || !b) {
        status = common.status < 0 ? common.status : -1;
        goto done;
    }
    *lnz = common.lnz;
    start = cpu_seconds();
    cholmod_l_factorize(&a, factor, &common);
    if (common.status != CHOLMOD_OK) {
        status = common.status < 0 ? common.status : 1;
        goto done;
    }
    x = cholmod_l_solve(CHOLMOD_A, factor, b, &common);
    cholmod_l_free_dense(&x, &common);
    first = cpu_seconds() - start;
    repetitions = (int) (target_seconds / (first > 1e-6 ? first : 1e-6));
    if (repetitions < 1) repetitions = 1;
    if (repetitions > max_repetitions) repetitions = max_repetitions;
    start = cpu_seconds();
    for (k = 0; k < repetitions; k++) {
        cholmod_l_factorize(&a, factor, &common);
        x = cholmod_l_solve(CHOLMOD_A, factor, b, &common);
        cholmod_l_free_dense(&x, &common);
    }
    *ms = 1e3 * (cpu_seconds() - start) / repetitions;
done:
    cholmod_l_free_factor(&factor, &common);
    cholmod_l_free_dense(&b, &common);
    cholmod_l_finish(&common);
    return status;
}
