/*
 * Thin C layer between the Fortran module core_sparse (src/core/sparse.f90) and SuiteSparse
 * CHOLMOD. CHOLMOD's API passes structs (cholmod_common, cholmod_sparse, cholmod_factor,
 * cholmod_dense) whose layout changes between releases; describing them in Fortran would tie
 * the code to one release. Here the structs stay in C: Fortran holds an opaque handle and
 * passes plain arrays. Every numerical operation is CHOLMOD's; this file only builds headers
 * around the caller's arrays, sets options and copies results out.
 *
 * Conventions: matrices are symmetric, n x n, in compressed sparse column form holding the
 * lower triangle (CHOLMOD stype = -1), 0-based 64-bit indices (the cholmod_l_* interface),
 * columns sorted, no duplicates. Return values are CHOLMOD status codes (CHOLMOD_OK = 0,
 * errors < 0, warnings > 0, e.g. CHOLMOD_NOT_POSDEF = 1).
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cholmod.h>

_Static_assert(sizeof(SuiteSparse_long) == sizeof(int64_t),
               "core_sparse passes 64-bit indices: SuiteSparse_long must be 64 bits");

/* Factorisation kinds and orderings; the same values are named in core_sparse. */
enum { MC_CHOLESKY = 1, MC_LDLT = 2 };
enum { MC_ORDER_AUTO = 0, MC_ORDER_AMD = 1, MC_ORDER_METIS = 2, MC_ORDER_NATURAL = 3 };

/* Status returned when a handle is missing (not a CHOLMOD code: those stop at -5). */
#define MC_NO_HANDLE (-100)

/* One solver: CHOLMOD's settings and workspace, the factor and the solve workspace. */
typedef struct {
    cholmod_common c;
    cholmod_factor *L;
    cholmod_dense *X, *Y, *E; /* reused by cholmod_l_solve2 from one solve to the next */
    int kind, ordering;
} mc_solver;

/* A header around the caller's arrays (no copy): lower triangle, sorted, packed. */
static cholmod_sparse lower_header(int64_t n, int64_t *p, int64_t *i, double *x)
{
    cholmod_sparse a;
    memset(&a, 0, sizeof(a));
    a.nrow = (size_t)n;
    a.ncol = (size_t)n;
    a.nzmax = (size_t)p[n];
    a.p = p;
    a.i = i;
    a.x = x;
    a.stype = -1;
    a.itype = CHOLMOD_LONG;
    a.xtype = CHOLMOD_REAL;
    a.dtype = CHOLMOD_DOUBLE;
    a.sorted = 1;
    a.packed = 1;
    return a;
}

/* A dense n x ncol column-major header around the caller's array (no copy). */
static cholmod_dense dense_header(int64_t n, int64_t ncol, double *x)
{
    cholmod_dense d;
    memset(&d, 0, sizeof(d));
    d.nrow = (size_t)n;
    d.ncol = (size_t)ncol;
    d.nzmax = (size_t)(n * ncol);
    d.d = (size_t)n;
    d.x = x;
    d.xtype = CHOLMOD_REAL;
    d.dtype = CHOLMOD_DOUBLE;
    return d;
}

/* Options of a solver: silent, LL' (supernodal or simplicial, chosen by CHOLMOD from the
 * flop count) for MC_CHOLESKY, simplicial LDL' for MC_LDLT; the requested ordering. */
static void configure(cholmod_common *c, int kind, int ordering)
{
    c->print = 0; /* no output from a library: errors come back as status values */
    if (kind == MC_LDLT) {
        c->supernodal = CHOLMOD_SIMPLICIAL;
        c->final_ll = 0;
    } else {
        c->supernodal = CHOLMOD_AUTO;
        c->final_ll = 1; /* simplicial factors are LL' too: a pivot <= 0 is an error */
    }
    switch (ordering) {
    case MC_ORDER_AMD:
        c->nmethods = 1;
        c->method[0].ordering = CHOLMOD_AMD;
        break;
    case MC_ORDER_METIS:
        c->nmethods = 1;
        c->method[0].ordering = CHOLMOD_METIS;
        break;
    case MC_ORDER_NATURAL:
        c->nmethods = 1;
        c->method[0].ordering = CHOLMOD_NATURAL;
        c->postorder = 0;
        break;
    default:
        break; /* CHOLMOD's default: AMD, and METIS as well when AMD gives much fill */
    }
}

void *mc_sparse_create(int kind, int ordering)
{
    mc_solver *s = calloc(1, sizeof(mc_solver));
    if (s == NULL) return NULL;
    if (!cholmod_l_start(&s->c)) {
        free(s);
        return NULL;
    }
    s->kind = kind;
    s->ordering = ordering;
    configure(&s->c, kind, ordering);
    return s;
}

void mc_sparse_destroy(void *handle)
{
    mc_solver *s = handle;
    if (s == NULL) return;
    cholmod_l_free_factor(&s->L, &s->c);
    cholmod_l_free_dense(&s->X, &s->c);
    cholmod_l_free_dense(&s->Y, &s->c);
    cholmod_l_free_dense(&s->E, &s->c);
    cholmod_l_finish(&s->c);
    free(s);
}

/* A new solver with the same options and a copy of the factor (NULL when out of memory). */
void *mc_sparse_copy(void *handle)
{
    mc_solver *s = handle, *t;
    if (s == NULL) return NULL;
    t = mc_sparse_create(s->kind, s->ordering);
    if (t == NULL) return NULL;
    if (s->L != NULL) {
        t->L = cholmod_l_copy_factor(s->L, &t->c);
        if (t->L == NULL) {
            mc_sparse_destroy(t);
            return NULL;
        }
    }
    return t;
}

/* Symbolic analysis: fill-reducing ordering, elimination tree, pattern of L. */
int mc_sparse_analyse(void *handle, int64_t n, int64_t *p, int64_t *i, double *x)
{
    mc_solver *s = handle;
    cholmod_sparse a;
    if (s == NULL) return MC_NO_HANDLE;
    cholmod_l_free_factor(&s->L, &s->c);
    a = lower_header(n, p, i, x);
    s->L = cholmod_l_analyze(&a, &s->c);
    if (s->L == NULL && s->c.status >= CHOLMOD_OK) return CHOLMOD_INVALID;
    return s->c.status;
}

/* Numerical factorisation with the analysis kept in the factor. On CHOLMOD_NOT_POSDEF
 * (LL': pivot <= 0; LDL': pivot = 0) *failed_column is the failing column of the original
 * matrix, 1-based (CHOLMOD reports it in the permuted order, L->minor). */
int mc_sparse_factor(void *handle, int64_t n, int64_t *p, int64_t *i, double *x,
                     int64_t *failed_column)
{
    mc_solver *s = handle;
    cholmod_sparse a;
    *failed_column = 0;
    if (s == NULL || s->L == NULL) return MC_NO_HANDLE;
    a = lower_header(n, p, i, x);
    cholmod_l_factorize(&a, s->L, &s->c);
    if (s->c.status == CHOLMOD_NOT_POSDEF) {
        int64_t k = (int64_t)s->L->minor;
        const int64_t *perm = s->L->Perm;
        *failed_column = (perm != NULL && k < n) ? perm[k] + 1 : k + 1;
    }
    return s->c.status;
}

/* Solve A X = B for nrhs right-hand sides (n x nrhs, column-major); X is copied to x. */
int mc_sparse_solve(void *handle, int64_t n, int64_t nrhs, double *b, double *x)
{
    mc_solver *s = handle;
    cholmod_dense bh;
    if (s == NULL || s->L == NULL) return MC_NO_HANDLE;
    bh = dense_header(n, nrhs, b);
    if (!cholmod_l_solve2(CHOLMOD_A, s->L, &bh, NULL, &s->X, NULL, &s->Y, &s->E, &s->c)) {
        return s->c.status < CHOLMOD_OK ? s->c.status : CHOLMOD_INVALID;
    }
    memcpy(x, s->X->x, sizeof(double) * (size_t)(n * nrhs));
    return s->c.status;
}

/* Replace rows and columns rows[0..nrows-1] (0-based, original numbering) of the factored
 * matrix by those of the identity: cholmod_l_rowdel on each, in the given order, with the
 * row's position in the factor (L holds the factor of P A P'). CHOLMOD modifies only a
 * simplicial LDL' factor and converts any other (supernodal, or LL') to one first. */
int mc_sparse_delete(void *handle, int64_t nrows, int64_t *rows)
{
    mc_solver *s = handle;
    int64_t n, *where;
    const int64_t *perm;
    if (s == NULL || s->L == NULL) return MC_NO_HANDLE;
    if (s->L->xtype == CHOLMOD_PATTERN) return MC_NO_HANDLE;
    n = (int64_t)s->L->n;
    where = malloc(sizeof(int64_t) * (size_t)(n > 0 ? n : 1));
    if (where == NULL) return CHOLMOD_OUT_OF_MEMORY;
    perm = s->L->Perm;
    for (int64_t j = 0; j < n; j++) where[perm != NULL ? perm[j] : j] = j;
    for (int64_t r = 0; r < nrows; r++) {
        if (rows[r] < 0 || rows[r] >= n) {
            free(where);
            return CHOLMOD_INVALID;
        }
        if (!cholmod_l_rowdel((size_t)where[rows[r]], NULL, s->L, &s->c)) {
            free(where);
            return s->c.status < CHOLMOD_OK ? s->c.status : CHOLMOD_INVALID;
        }
    }
    free(where);
    return s->c.status;
}

/* Figures of the last analysis and factorisation. lnz and flops come from the analysis
 * (nonzeros of L including the diagonal; floating-point operations of the factorisation);
 * negative_pivots counts D(j,j) < 0 of a simplicial LDL' factor (0 otherwise); rcond is
 * CHOLMOD's cheap estimate (min/max of the diagonal of L, squared for LL'), 0 when there is
 * no numerical factor; memory_peak is CHOLMOD's peak memory use in bytes. */
void mc_sparse_info(void *handle, double *lnz, double *flops, int *ordering, int *supernodal,
                    int *is_ll, int64_t *negative_pivots, double *rcond, double *memory_peak)
{
    mc_solver *s = handle;
    *lnz = 0;
    *flops = 0;
    *ordering = -1;
    *supernodal = 0;
    *is_ll = 0;
    *negative_pivots = 0;
    *rcond = 0;
    *memory_peak = 0;
    if (s == NULL || s->L == NULL) return;
    *lnz = s->c.lnz;
    *flops = s->c.fl;
    *ordering = s->L->ordering;
    *supernodal = s->L->is_super;
    *is_ll = s->L->is_ll;
    *memory_peak = (double)s->c.memory_usage;
    if (s->L->xtype == CHOLMOD_PATTERN || s->L->minor < s->L->n) return;
    *rcond = cholmod_l_rcond(s->L, &s->c);
    if (!s->L->is_super && !s->L->is_ll) {
        const int64_t *lp = s->L->p;
        const double *lx = s->L->x;
        for (size_t j = 0; j < s->L->n; j++) {
            if (lx[lp[j]] < 0) (*negative_pivots)++;
        }
    }
}

/* Triplets to compressed columns (cholmod_l_triplet_to_sparse: duplicates summed, entries
 * of the upper triangle transposed into the lower one, columns sorted). Two steps because
 * the caller allocates the arrays once the number of entries is known: mc_sparse_compress
 * returns a handle and *nnz; mc_sparse_compress_take copies the arrays and frees it. */
typedef struct {
    cholmod_common c;
    cholmod_sparse *a;
} mc_compressed;

void *mc_sparse_compress(int64_t n, int64_t nt, int64_t *ti, int64_t *tj, double *tv,
                         int64_t *nnz, int *status)
{
    mc_compressed *h = calloc(1, sizeof(mc_compressed));
    cholmod_triplet t;
    *nnz = 0;
    if (h == NULL) {
        *status = CHOLMOD_OUT_OF_MEMORY;
        return NULL;
    }
    cholmod_l_start(&h->c);
    h->c.print = 0;
    memset(&t, 0, sizeof(t));
    t.nrow = (size_t)n;
    t.ncol = (size_t)n;
    t.nzmax = (size_t)(nt > 0 ? nt : 1);
    t.nnz = (size_t)nt;
    t.i = ti;
    t.j = tj;
    t.x = tv;
    t.stype = -1;
    t.itype = CHOLMOD_LONG;
    t.xtype = CHOLMOD_REAL;
    t.dtype = CHOLMOD_DOUBLE;
    h->a = cholmod_l_triplet_to_sparse(&t, 0, &h->c);
    *status = h->c.status;
    if (h->a == NULL) {
        if (*status >= CHOLMOD_OK) *status = CHOLMOD_INVALID;
        cholmod_l_finish(&h->c);
        free(h);
        return NULL;
    }
    *nnz = ((int64_t *)h->a->p)[n];
    return h;
}

void mc_sparse_compress_take(void *handle, int64_t *p, int64_t *i, double *x)
{
    mc_compressed *h = handle;
    int64_t n, nnz;
    if (h == NULL) return;
    n = (int64_t)h->a->ncol;
    nnz = ((int64_t *)h->a->p)[n];
    memcpy(p, h->a->p, sizeof(int64_t) * (size_t)(n + 1));
    memcpy(i, h->a->i, sizeof(int64_t) * (size_t)nnz);
    memcpy(x, h->a->x, sizeof(double) * (size_t)nnz);
    cholmod_l_free_sparse(&h->a, &h->c);
    cholmod_l_finish(&h->c);
    free(h);
}

/* Y = alpha*A*X + beta*Y for a symmetric A stored as its lower triangle (cholmod_l_sdmult);
 * X and Y are n x ncol, column-major. */
int mc_sparse_matvec(int64_t n, int64_t *p, int64_t *i, double *x, int64_t ncol, double *xin,
                     double *yout, double alpha, double beta)
{
    cholmod_common c;
    cholmod_sparse a = lower_header(n, p, i, x);
    cholmod_dense xd = dense_header(n, ncol, xin), yd = dense_header(n, ncol, yout);
    double al[2] = {alpha, 0}, be[2] = {beta, 0};
    int status;
    cholmod_l_start(&c);
    c.print = 0;
    cholmod_l_sdmult(&a, 0, al, be, &xd, &yd, &c);
    status = c.status;
    cholmod_l_finish(&c);
    return status;
}
