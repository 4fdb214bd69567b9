/* SPDX-License-Identifier: MIT */
/*
 * Minimal C shim between yarnfort_linalg_cholmod and CHOLMOD's 64-bit API (cholmod_l_*).
 *
 * Why it exists: cholmod_common is a ~2.7 kB struct whose layout changes between
 * CHOLMOD versions (and with build options such as GPU support), and cholmod_sparse,
 * cholmod_dense and cholmod_factor are likewise version-dependent. Mirroring them in
 * Fortran would be fragile, so this file keeps them behind one opaque handle and exposes
 * only thin calls with plain arguments. No policy lives here; errors are returned as
 * CHOLMOD status codes (plus the column of a failed pivot) for Fortran to turn into
 * messages.
 */
#include <stdlib.h>
#include <string.h>

#include "cholmod.h"

/* Everything one CHOLMOD solver owns. */
typedef struct {
    cholmod_common common;
    cholmod_factor *factor;    /* symbolic after analyse, numeric after factorize */
    cholmod_dense *x;          /* solution, reused by cholmod_l_solve2 */
    cholmod_dense *y;          /* workspace of cholmod_l_solve2 */
    cholmod_dense *e;          /* workspace of cholmod_l_solve2 */
} yarnfort_cholmod;

/* Status returned when the handle itself is missing or cannot be allocated. */
#define YARNFORT_CHOLMOD_NO_HANDLE (-100)

/* A cholmod_sparse header over caller-owned arrays; stype > 0: only the upper triangle
 * is used, entries below the diagonal are ignored. */
static cholmod_sparse wrap_sparse(SuiteSparse_long n, SuiteSparse_long *col_ptr,
                                  SuiteSparse_long *row_index, double *values)
{
    cholmod_sparse a;
    memset(&a, 0, sizeof(a));
    a.nrow = (size_t) n;
    a.ncol = (size_t) n;
    a.nzmax = (size_t) col_ptr[n];
    a.p = col_ptr;
    a.i = row_index;
    a.x = values;
    a.stype = 1;
    a.itype = CHOLMOD_LONG;
    a.xtype = values ? CHOLMOD_REAL : CHOLMOD_PATTERN;
    a.dtype = CHOLMOD_DOUBLE;
    a.sorted = 1;
    a.packed = 1;
    return a;
}

/* New handle with CHOLMOD started, silent, and set to compute LL' (LDL', the simplicial
 * default, would factorise indefinite matrices without reporting them); the factor is
 * supernodal where the analysis predicts at least `supernodal_switch` flops per nonzero
 * of L, else simplicial. NULL on failure. */
void *yarnfort_cholmod_create(double supernodal_switch)
{
    yarnfort_cholmod *h = calloc(1, sizeof(*h));
    if (!h) return NULL;
    if (!cholmod_l_start(&h->common)) {
        free(h);
        return NULL;
    }
    h->common.print = 0;
    h->common.final_ll = 1;
    h->common.supernodal_switch = supernodal_switch;
    return h;
}

/* Free the factor and workspaces, finish CHOLMOD and free the handle (NULL is ignored). */
void yarnfort_cholmod_free(void *handle)
{
    yarnfort_cholmod *h = handle;
    if (!h) return;
    cholmod_l_free_factor(&h->factor, &h->common);
    cholmod_l_free_dense(&h->x, &h->common);
    cholmod_l_free_dense(&h->y, &h->common);
    cholmod_l_free_dense(&h->e, &h->common);
    cholmod_l_finish(&h->common);
    free(h);
}

/* Fill-reducing ordering and symbolic factorisation of the upper triangle. */
int yarnfort_cholmod_analyze(void *handle, SuiteSparse_long n, SuiteSparse_long *col_ptr,
                             SuiteSparse_long *row_index)
{
    yarnfort_cholmod *h = handle;
    cholmod_sparse a;
    if (!h) return YARNFORT_CHOLMOD_NO_HANDLE;
    cholmod_l_free_factor(&h->factor, &h->common);
    cholmod_l_free_dense(&h->x, &h->common);
    cholmod_l_free_dense(&h->y, &h->common);
    cholmod_l_free_dense(&h->e, &h->common);
    a = wrap_sparse(n, col_ptr, row_index, NULL);
    h->common.status = CHOLMOD_OK;
    h->factor = cholmod_l_analyze(&a, &h->common);
    if (!h->factor && h->common.status == CHOLMOD_OK) return CHOLMOD_INVALID;
    return h->common.status;
}

/* Numeric LL' factorisation; on CHOLMOD_NOT_POSDEF *minor is the failed column
 * (0-based), else n. */
int yarnfort_cholmod_factorize(void *handle, SuiteSparse_long n, SuiteSparse_long *col_ptr,
                               SuiteSparse_long *row_index, double *values,
                               SuiteSparse_long *minor)
{
    yarnfort_cholmod *h = handle;
    cholmod_sparse a;
    *minor = n;
    if (!h) return YARNFORT_CHOLMOD_NO_HANDLE;
    if (!h->factor) return CHOLMOD_INVALID;
    a = wrap_sparse(n, col_ptr, row_index, values);
    h->common.status = CHOLMOD_OK;
    if (!cholmod_l_factorize(&a, h->factor, &h->common) && h->common.status == CHOLMOD_OK) {
        return CHOLMOD_INVALID;
    }
    *minor = (SuiteSparse_long) h->factor->minor;
    if (h->common.status == CHOLMOD_OK && h->factor->minor < (size_t) n) {
        return CHOLMOD_NOT_POSDEF;
    }
    return h->common.status;
}

/* Solve A X = RHS for ncol columns (RHS column-major, n x ncol) and overwrite RHS; the
 * solution and workspaces are allocated by the first call and reused while ncol stays the
 * same (several columns go through the supernodes' dense blocks together). */
int yarnfort_cholmod_solve(void *handle, SuiteSparse_long n, SuiteSparse_long ncol,
                           double *rhs)
{
    yarnfort_cholmod *h = handle;
    cholmod_dense b;
    if (!h) return YARNFORT_CHOLMOD_NO_HANDLE;
    if (!h->factor || ncol < 1) return CHOLMOD_INVALID;
    memset(&b, 0, sizeof(b));
    b.nrow = (size_t) n;
    b.ncol = (size_t) ncol;
    b.nzmax = (size_t) n * (size_t) ncol;
    b.d = (size_t) n;
    b.x = rhs;
    b.xtype = CHOLMOD_REAL;
    b.dtype = CHOLMOD_DOUBLE;
    h->common.status = CHOLMOD_OK;
    if (!cholmod_l_solve2(CHOLMOD_A, h->factor, &b, NULL, &h->x, NULL, &h->y, &h->e,
                          &h->common)) {
        return h->common.status == CHOLMOD_OK ? CHOLMOD_INVALID : h->common.status;
    }
    memcpy(rhs, h->x->x, (size_t) n * (size_t) ncol * sizeof(double));
    return h->common.status;
}
