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

/* Everything one CHOLMOD solver owns.
 *
 * The matrix is handed to CHOLMOD already permuted to the fill-reducing order, as the
 * one triangle its factorisation reads without copying (the upper for a simplicial
 * factor, the lower for a supernodal one), and factorised in the natural order. Given
 * the caller's matrix and its ordering, cholmod_l_factorize would instead build the
 * permuted triangle by one or two transposes per factorisation: on the woven nets'
 * simplicial factors (7-23 flops per nonzero of L) those cost as much as the
 * factorisation itself (perf, 10,120 unknowns). Here each factorisation gathers the
 * values through a map made once per pattern, and each solve permutes its right-hand
 * sides (O(n)). */
typedef struct {
    cholmod_common common;
    cholmod_factor *factor;    /* of the permuted matrix, natural order */
    cholmod_dense *x;          /* solution, reused by cholmod_l_solve2 */
    cholmod_dense *y;          /* workspace of cholmod_l_solve2 */
    cholmod_dense *e;          /* workspace of cholmod_l_solve2 */
    SuiteSparse_long n;
    SuiteSparse_long *perm;    /* fill-reducing order: row k of PAP' is row perm[k] of A */
    int stype;                 /* triangle of PAP' that is stored: 1 upper, -1 lower */
    SuiteSparse_long *p_col_ptr, *p_row_index;  /* that triangle's pattern */
    SuiteSparse_long *source;  /* for each of its entries, the entry of A it takes */
    double *p_values;          /* its values at the last factorisation */
    double *work;              /* permuted right-hand sides (n x work_columns) */
    SuiteSparse_long work_columns;
} yarnfort_cholmod;

/* Status returned when the handle itself is missing or cannot be allocated. */
#define YARNFORT_CHOLMOD_NO_HANDLE (-100)

/* A cholmod_sparse header over existing arrays; stype > 0: only the upper triangle is
 * used, stype < 0: only the lower. */
static cholmod_sparse wrap_sparse(SuiteSparse_long n, SuiteSparse_long *col_ptr,
                                  SuiteSparse_long *row_index, double *values, int stype)
{
    cholmod_sparse a;
    memset(&a, 0, sizeof(a));
    a.nrow = (size_t) n;
    a.ncol = (size_t) n;
    a.nzmax = (size_t) col_ptr[n];
    a.p = col_ptr;
    a.i = row_index;
    a.x = values;
    a.stype = stype;
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

/* Free what an analysis made: the factor, the permuted pattern and the workspaces. */
static void free_analysis(yarnfort_cholmod *h)
{
    cholmod_l_free_factor(&h->factor, &h->common);
    cholmod_l_free_dense(&h->x, &h->common);
    cholmod_l_free_dense(&h->y, &h->common);
    cholmod_l_free_dense(&h->e, &h->common);
    free(h->perm);
    free(h->p_col_ptr);
    free(h->p_row_index);
    free(h->source);
    free(h->p_values);
    free(h->work);
    h->perm = h->p_col_ptr = h->p_row_index = h->source = NULL;
    h->p_values = h->work = NULL;
    h->work_columns = 0;
    h->n = 0;
}

/* Free the factor and workspaces, finish CHOLMOD and free the handle (NULL is ignored). */
void yarnfort_cholmod_free(void *handle)
{
    yarnfort_cholmod *h = handle;
    if (!h) return;
    free_analysis(h);
    cholmod_l_finish(&h->common);
    free(h);
}

/* The stored triangle of PAP' (h->stype) from the upper triangle of A (col_ptr,
 * row_index), rows sorted within each column, and for each entry the entry of A it
 * takes. 0 or CHOLMOD_OUT_OF_MEMORY. */
static int permute_pattern(yarnfort_cholmod *h, const SuiteSparse_long *col_ptr,
                           const SuiteSparse_long *row_index)
{
    SuiteSparse_long n = h->n, j, e, k, nnz = 0;
    SuiteSparse_long *inverse = malloc((size_t) n * sizeof(*inverse));
    SuiteSparse_long *next = malloc((size_t) (n + 1) * sizeof(*next));
    SuiteSparse_long *by_row_ptr = NULL, *by_row = NULL, *by_row_column = NULL;
    int status = CHOLMOD_OUT_OF_MEMORY;

    h->p_col_ptr = calloc((size_t) n + 1, sizeof(*h->p_col_ptr));
    if (!inverse || !next || !h->p_col_ptr) goto done;
    for (k = 0; k < n; k++) inverse[h->perm[k]] = k;
    /* Count the entries of each column of the triangle. */
    for (j = 0; j < n; j++) {
        for (e = col_ptr[j]; e < col_ptr[j + 1]; e++) {
            SuiteSparse_long i = row_index[e], pi, pj;
            if (i > j) continue;
            pi = inverse[i];
            pj = inverse[j];
            h->p_col_ptr[(h->stype > 0 ? (pi > pj ? pi : pj) : (pi < pj ? pi : pj)) + 1]++;
            nnz++;
        }
    }
    for (k = 0; k < n; k++) h->p_col_ptr[k + 1] += h->p_col_ptr[k];
    h->p_row_index = malloc((size_t) (nnz > 0 ? nnz : 1) * sizeof(*h->p_row_index));
    h->source = malloc((size_t) (nnz > 0 ? nnz : 1) * sizeof(*h->source));
    h->p_values = malloc((size_t) (nnz > 0 ? nnz : 1) * sizeof(*h->p_values));
    /* Sorted rows: first bucket the entries by their row in the triangle (a counting
     * sort), then deal them out to their columns in row order. */
    by_row_ptr = calloc((size_t) n + 1, sizeof(*by_row_ptr));
    by_row = malloc((size_t) (nnz > 0 ? nnz : 1) * sizeof(*by_row));
    by_row_column = malloc((size_t) (nnz > 0 ? nnz : 1) * sizeof(*by_row_column));
    if (!h->p_row_index || !h->source || !h->p_values || !by_row_ptr || !by_row
        || !by_row_column) goto done;
    for (j = 0; j < n; j++) {
        for (e = col_ptr[j]; e < col_ptr[j + 1]; e++) {
            SuiteSparse_long i = row_index[e], pi, pj;
            if (i > j) continue;
            pi = inverse[i];
            pj = inverse[j];
            by_row_ptr[(h->stype > 0 ? (pi < pj ? pi : pj) : (pi > pj ? pi : pj)) + 1]++;
        }
    }
    for (k = 0; k < n; k++) by_row_ptr[k + 1] += by_row_ptr[k];
    memcpy(next, by_row_ptr, (size_t) (n + 1) * sizeof(*next));
    for (j = 0; j < n; j++) {
        for (e = col_ptr[j]; e < col_ptr[j + 1]; e++) {
            SuiteSparse_long i = row_index[e], pi, pj;
            if (i > j) continue;
            pi = inverse[i];
            pj = inverse[j];
            k = next[h->stype > 0 ? (pi < pj ? pi : pj) : (pi > pj ? pi : pj)]++;
            by_row[k] = e;
            by_row_column[k] = h->stype > 0 ? (pi > pj ? pi : pj) : (pi < pj ? pi : pj);
        }
    }
    memcpy(next, h->p_col_ptr, (size_t) (n + 1) * sizeof(*next));
    for (k = 0; k < n; k++) {
        for (e = by_row_ptr[k]; e < by_row_ptr[k + 1]; e++) {
            SuiteSparse_long column = by_row_column[e];
            h->p_row_index[next[column]] = k;
            h->source[next[column]] = by_row[e];
            next[column]++;
        }
    }
    status = 0;
done:
    free(inverse);
    free(next);
    free(by_row_ptr);
    free(by_row);
    free(by_row_column);
    return status;
}

/* Fill-reducing ordering of the upper triangle, then the permuted triangle's pattern
 * and its symbolic factorisation in the natural order. */
int yarnfort_cholmod_analyze(void *handle, SuiteSparse_long n, SuiteSparse_long *col_ptr,
                             SuiteSparse_long *row_index)
{
    yarnfort_cholmod *h = handle;
    cholmod_sparse a;
    cholmod_factor *ordering;
    int status, nmethods, postorder, ordering_method;
    if (!h) return YARNFORT_CHOLMOD_NO_HANDLE;
    free_analysis(h);
    a = wrap_sparse(n, col_ptr, row_index, NULL, 1);
    h->common.status = CHOLMOD_OK;
    ordering = cholmod_l_analyze(&a, &h->common);
    if (!ordering) return h->common.status == CHOLMOD_OK ? CHOLMOD_INVALID : h->common.status;
    h->n = n;
    h->perm = malloc((size_t) (n > 0 ? n : 1) * sizeof(*h->perm));
    if (!h->perm) {
        cholmod_l_free_factor(&ordering, &h->common);
        return CHOLMOD_OUT_OF_MEMORY;
    }
    memcpy(h->perm, ordering->Perm, (size_t) n * sizeof(*h->perm));
    /* The triangle that the factorisation reads as it is (cholmod_factorize.c). */
    h->stype = ordering->is_super ? -1 : 1;
    cholmod_l_free_factor(&ordering, &h->common);
    status = permute_pattern(h, col_ptr, row_index);
    if (status != 0) {
        free_analysis(h);
        return status;
    }
    /* The permutation is CHOLMOD's own (ordering and postorder), so the natural order
     * of PAP' gives the same factor. */
    nmethods = h->common.nmethods;
    ordering_method = h->common.method[0].ordering;
    postorder = h->common.postorder;
    h->common.nmethods = 1;
    h->common.method[0].ordering = CHOLMOD_NATURAL;
    h->common.postorder = 0;
    a = wrap_sparse(n, h->p_col_ptr, h->p_row_index, NULL, h->stype);
    h->common.status = CHOLMOD_OK;
    h->factor = cholmod_l_analyze(&a, &h->common);
    h->common.nmethods = nmethods;
    h->common.method[0].ordering = ordering_method;
    h->common.postorder = postorder;
    if (!h->factor) {
        status = h->common.status == CHOLMOD_OK ? CHOLMOD_INVALID : h->common.status;
        free_analysis(h);
        return status;
    }
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
    if (!h->factor || n != h->n) return CHOLMOD_INVALID;
    (void) col_ptr;
    (void) row_index;
    for (SuiteSparse_long k = 0; k < h->p_col_ptr[n]; k++) h->p_values[k] = values[h->source[k]];
    a = wrap_sparse(n, h->p_col_ptr, h->p_row_index, h->p_values, h->stype);
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
    SuiteSparse_long c, k;
    if (!h) return YARNFORT_CHOLMOD_NO_HANDLE;
    if (!h->factor || ncol < 1 || n != h->n) return CHOLMOD_INVALID;
    if (ncol != h->work_columns) {
        free(h->work);
        h->work = malloc((size_t) (n > 0 ? n : 1) * (size_t) ncol * sizeof(*h->work));
        h->work_columns = h->work ? ncol : 0;
        if (!h->work) return CHOLMOD_OUT_OF_MEMORY;
    }
    /* P rhs, solved with the factor of PAP', then P' x. */
    for (c = 0; c < ncol; c++) {
        for (k = 0; k < n; k++) h->work[c * n + k] = rhs[c * n + h->perm[k]];
    }
    memset(&b, 0, sizeof(b));
    b.nrow = (size_t) n;
    b.ncol = (size_t) ncol;
    b.nzmax = (size_t) n * (size_t) ncol;
    b.d = (size_t) n;
    b.x = h->work;
    b.xtype = CHOLMOD_REAL;
    b.dtype = CHOLMOD_DOUBLE;
    h->common.status = CHOLMOD_OK;
    if (!cholmod_l_solve2(CHOLMOD_A, h->factor, &b, NULL, &h->x, NULL, &h->y, &h->e,
                          &h->common)) {
        return h->common.status == CHOLMOD_OK ? CHOLMOD_INVALID : h->common.status;
    }
    for (c = 0; c < ncol; c++) {
        const double *x = (const double *) h->x->x + c * n;
        for (k = 0; k < n; k++) rhs[c * n + h->perm[k]] = x[k];
    }
    return h->common.status;
}
