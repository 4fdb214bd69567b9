/* SPDX-License-Identifier: MIT */
/*
 * Minimal C shim between yarnfort_linalg_backend_cholmod and CHOLMOD's 64-bit API (cholmod_l_*).
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
 * permuted triangle by one or two transposes per factorisation, which cost as much as a
 * simplicial factorisation itself (docs/decisions.md, 'CHOLMOD factorises the
 * pre-permuted triangle'). Here each factorisation gathers the values through a map made
 * once per pattern, and each solve permutes its right-hand sides (O(n)). */
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
    h->perm = h->p_col_ptr = h->p_row_index = h->source = NULL;
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

/* Row and column in the stored triangle of PAP' of entry (i, j) of A. */
static void place(const yarnfort_cholmod *h, const SuiteSparse_long *inverse,
                  SuiteSparse_long i, SuiteSparse_long j, SuiteSparse_long *row,
                  SuiteSparse_long *column)
{
    SuiteSparse_long low = inverse[i], high = inverse[j];
    if (low > high) {
        SuiteSparse_long swap = low;
        low = high;
        high = swap;
    }
    *row = h->stype > 0 ? low : high;
    *column = h->stype > 0 ? high : low;
}

/* The stored triangle of PAP' (h->stype) from the upper triangle of A (col_ptr,
 * row_index), rows sorted within each column, and for each entry the entry of A it
 * takes. 0 or CHOLMOD_OUT_OF_MEMORY. */
static int permute_pattern(yarnfort_cholmod *h, const SuiteSparse_long *col_ptr,
                           const SuiteSparse_long *row_index)
{
    SuiteSparse_long n = h->n, most = col_ptr[n] > 0 ? col_ptr[n] : 1;
    SuiteSparse_long j, e, k, nnz = 0;
    SuiteSparse_long *inverse = malloc((size_t) (n > 0 ? n : 1) * sizeof(*inverse));
    SuiteSparse_long *row = malloc((size_t) most * sizeof(*row));
    SuiteSparse_long *column = malloc((size_t) most * sizeof(*column));
    SuiteSparse_long *entry = malloc((size_t) most * sizeof(*entry));
    SuiteSparse_long *row_ptr = calloc((size_t) n + 1, sizeof(*row_ptr));
    SuiteSparse_long *by_row = malloc((size_t) most * sizeof(*by_row));
    int status = CHOLMOD_OUT_OF_MEMORY;

    h->p_col_ptr = calloc((size_t) n + 1, sizeof(*h->p_col_ptr));
    h->p_row_index = malloc((size_t) most * sizeof(*h->p_row_index));
    h->source = malloc((size_t) most * sizeof(*h->source));
    if (!inverse || !row || !column || !entry || !row_ptr || !by_row || !h->p_col_ptr
        || !h->p_row_index || !h->source) goto done;
    for (k = 0; k < n; k++) inverse[h->perm[k]] = k;
    /* The upper triangle's entries, placed, and the counts per row and per column. */
    for (j = 0; j < n; j++) {
        for (e = col_ptr[j]; e < col_ptr[j + 1]; e++) {
            if (row_index[e] > j) continue;
            place(h, inverse, row_index[e], j, &row[nnz], &column[nnz]);
            entry[nnz] = e;
            row_ptr[row[nnz] + 1]++;
            h->p_col_ptr[column[nnz] + 1]++;
            nnz++;
        }
    }
    for (k = 0; k < n; k++) {
        row_ptr[k + 1] += row_ptr[k];
        h->p_col_ptr[k + 1] += h->p_col_ptr[k];
    }
    /* Sorted rows: the entries bucketed by row (a counting sort), then dealt out to their
     * columns in row order. */
    for (k = 0; k < nnz; k++) by_row[row_ptr[row[k]]++] = k;
    memcpy(row_ptr, h->p_col_ptr, (size_t) (n + 1) * sizeof(*row_ptr));
    for (e = 0; e < nnz; e++) {
        k = by_row[e];
        h->p_row_index[row_ptr[column[k]]] = row[k];
        h->source[row_ptr[column[k]]++] = entry[k];
    }
    status = 0;
done:
    free(inverse);
    free(row);
    free(column);
    free(entry);
    free(row_ptr);
    free(by_row);
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

/* Numeric LL' factorisation of A (its values in the order of the analysed pattern); on
 * CHOLMOD_NOT_POSDEF *minor is the failed column of PAP' (0-based), else n. */
int yarnfort_cholmod_factorize(void *handle, SuiteSparse_long n, double *values,
                               SuiteSparse_long *minor)
{
    yarnfort_cholmod *h = handle;
    cholmod_sparse a;
    double *permuted;
    SuiteSparse_long k, nnz;
    int status;
    *minor = n;
    if (!h) return YARNFORT_CHOLMOD_NO_HANDLE;
    if (!h->factor || n != h->n) return CHOLMOD_INVALID;
    /* The values of PAP' for this factorisation only (as CHOLMOD's own transposes were). */
    nnz = h->p_col_ptr[n];
    permuted = malloc((size_t) (nnz > 0 ? nnz : 1) * sizeof(*permuted));
    if (!permuted) return CHOLMOD_OUT_OF_MEMORY;
    for (k = 0; k < nnz; k++) permuted[k] = values[h->source[k]];
    a = wrap_sparse(n, h->p_col_ptr, h->p_row_index, permuted, h->stype);
    h->common.status = CHOLMOD_OK;
    if (!cholmod_l_factorize(&a, h->factor, &h->common) && h->common.status == CHOLMOD_OK) {
        h->common.status = CHOLMOD_INVALID;
    }
    free(permuted);
    status = h->common.status;
    *minor = (SuiteSparse_long) h->factor->minor;
    if (status == CHOLMOD_OK && h->factor->minor < (size_t) n) return CHOLMOD_NOT_POSDEF;
    return status;
}

/* Solve A X = RHS for ncol columns (RHS column-major, n x ncol) and overwrite RHS; the
 * solution and workspaces are allocated by the first call and reused while ncol stays the
 * same (several columns go through the supernodes' dense blocks together). */
int yarnfort_cholmod_solve(void *handle, SuiteSparse_long n, SuiteSparse_long ncol,
                           double *rhs)
{
    yarnfort_cholmod *h = handle;
    cholmod_dense b;
    double *permuted;
    SuiteSparse_long c, k;
    int status;
    if (!h) return YARNFORT_CHOLMOD_NO_HANDLE;
    if (!h->factor || ncol < 1 || n != h->n) return CHOLMOD_INVALID;
    /* P rhs, solved with the factor of PAP', then P' x; P rhs for this solve only (n x
     * ncol: kept, 16 columns at 963,600 unknowns would hold 123 MB for the run). */
    permuted = malloc((size_t) (n > 0 ? n : 1) * (size_t) ncol * sizeof(*permuted));
    if (!permuted) return CHOLMOD_OUT_OF_MEMORY;
    for (c = 0; c < ncol; c++) {
        for (k = 0; k < n; k++) permuted[c * n + k] = rhs[c * n + h->perm[k]];
    }
    memset(&b, 0, sizeof(b));
    b.nrow = (size_t) n;
    b.ncol = (size_t) ncol;
    b.nzmax = (size_t) n * (size_t) ncol;
    b.d = (size_t) n;
    b.x = permuted;
    b.xtype = CHOLMOD_REAL;
    b.dtype = CHOLMOD_DOUBLE;
    h->common.status = CHOLMOD_OK;
    if (!cholmod_l_solve2(CHOLMOD_A, h->factor, &b, NULL, &h->x, NULL, &h->y, &h->e,
                          &h->common)) {
        status = h->common.status == CHOLMOD_OK ? CHOLMOD_INVALID : h->common.status;
        free(permuted);
        return status;
    }
    free(permuted);
    for (c = 0; c < ncol; c++) {
        const double *x = (const double *) h->x->x + c * n;
        for (k = 0; k < n; k++) rhs[c * n + h->perm[k]] = x[k];
    }
    return h->common.status;
}

/* METIS' nested dissection of the pattern of A + A^T (n x n, 0-based CSC, any pattern),
 * postordered, into perm (size n: the k-th pivot is perm[k]), and the nonzeros of the
 * Cholesky factor of A + A^T in that order (diagonal included) into lnz: the order and
 * the fill an LU factorisation with diagonal pivots gets from it. Its own CHOLMOD
 * workspace. 0 or a CHOLMOD status. */
int yarnfort_cholmod_metis_order(SuiteSparse_long n, SuiteSparse_long *col_ptr,
                                 SuiteSparse_long *row_index, SuiteSparse_long *perm,
                                 double *lnz)
{
    cholmod_common common;
    cholmod_sparse a, *at = NULL, *sum = NULL;
    cholmod_factor *factor = NULL;
    double one[2] = {1.0, 0.0};
    int status;

    if (!cholmod_l_start(&common)) return YARNFORT_CHOLMOD_NO_HANDLE;
    common.print = 0;
    common.nmethods = 1;
    common.method[0].ordering = CHOLMOD_METIS;
    common.postorder = 1;
    a = wrap_sparse(n, col_ptr, row_index, NULL, 0);
    a.sorted = 0;
    at = cholmod_l_transpose(&a, 0, &common);
    if (at) sum = cholmod_l_add(&a, at, one, one, 0, 0, &common);
    if (sum) {
        sum->stype = 1;
        factor = cholmod_l_analyze(sum, &common);
    }
    if (factor && common.status == CHOLMOD_OK) {
        memcpy(perm, factor->Perm, (size_t) n * sizeof(*perm));
        *lnz = common.lnz;
    }
    status = factor ? common.status : (common.status != CHOLMOD_OK ? common.status
                                                                    : CHOLMOD_INVALID);
    cholmod_l_free_factor(&factor, &common);
    cholmod_l_free_sparse(&sum, &common);
    cholmod_l_free_sparse(&at, &common);
    cholmod_l_finish(&common);
    return status;
}
