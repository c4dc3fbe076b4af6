/* The general slicer's generic level in C: a polytope with star faces or non-convex cells cut by
 * w = c0 where no vertex lies on the hyperplane (rot4d_widget.geometry.starslice's `_cut` with no
 * vertex on H, one pass over the geometry instead of ~250 numpy steps).
 *
 * The same slice as the numpy slicer, by the same rules (see starslice.py and starfill.py, whose
 * docstrings are the specification): points where edges cross H; each face's crossings sorted
 * along its line and paired even-odd; the winding-weighted volume; each cell's cycles chained
 * through the faces at its edges and run the way the boundary runs them; fills: a convex cell's
 * cycle fanned, star-shaped sections fanned from their centroids, crossing sections by their
 * arrangement's odd faces, anything else by even-odd slabs.  Whatever is not generic (a tie along
 * a face's line, a check that fails) returns a status and the numpy slicer does the level.
 *
 * Plain C, no Python API: loaded with ctypes (rot4d_widget/geometry/_cstar.py).  Indices int64,
 * coordinates float64, row-major.  Thread-safe: every call owns its memory (a `Result`, freed by
 * starcut_take; a declined level frees its own). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <stdatomic.h>
#include <string.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

/* Two threads for the crossing sections' fills where there is enough work (PARALLEL_WORK: the
 * sum over those cells of their records squared); none in the timing build, whose clock marks are
 * one thread's, nor on Windows. */
#if !defined(STARCUT_TIMING) && !defined(_WIN32)
#define STARCUT_THREADS
#include <pthread.h>
#include <time.h>
#include <unistd.h>
#endif
#define PARALLEL_WORK 20000.0

typedef int64_t I;

#ifndef STARCUT_SOURCE
#define STARCUT_SOURCE "unknown"
#endif
/* the sha256 of this file when it was built (hatch_build.py): the package uses no stale build */
const char *starcut_source(void) { return STARCUT_SOURCE; }

enum { OK = 0, NO_CROSSING = 1, INCONSISTENT = 2, NOT_GENERIC = 3, NO_MEMORY = 4 };

/* Built with -DSTARCUT_TIMING (benchmarks/star_stages.py only): seconds spent in each stage, summed
 * over calls, in starcut_times[]; otherwise the marks compile to nothing. */
#ifdef STARCUT_TIMING
#include <time.h>
double starcut_times[16];
long starcut_counts[4];  /* cells tried by the arrangement fill, cells it filled */
#define COUNT(k) (starcut_counts[k]++)
static double stage_clock(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }
#define MARK_START double mark_t_ = stage_clock()
#define MARK(k) do { double t_ = stage_clock(); starcut_times[k] += t_ - mark_t_; mark_t_ = t_; } while (0)
#else
#define MARK_START do { } while (0)
#define MARK(k) do { } while (0)
#define COUNT(k) do { } while (0)
#endif
/* the stages starcut_times counts: */
enum { T_EDGES, T_FACES, T_CYCLES, T_FANS, T_ARR_PAIRS, T_ARR_ORDER, T_ARR_PARITY, T_ARR_NEXT, T_ARR_FACES,
       T_ARR_OUTPUT, T_SLABS };
enum { C_ARR_TRIED, C_ARR_FILLED };

typedef struct { I *a; I n, cap; } ivec;
typedef struct { double *a; I n, cap; } dvec;

/* Room for `extra` more elements of `size` bytes after the `n` in *a (capacity *cap, doubled as
 * needed); 0 when memory runs out (*a unchanged). */
static int grow(void **a, I *cap, I n, I extra, size_t size) {
    if (n + extra <= *cap) return 1;
    I c = *cap ? *cap : 64;
    while (c < n + extra) c *= 2;
    void *b = realloc(*a, (size_t)c * size);
    if (!b) return 0;
    *a = b; *cap = c; return 1;
}
#define GROW(v, extra) grow((void **)&(v)->a, &(v)->cap, (v)->n, (extra), sizeof *(v)->a)
#define PUSH(v, x) do { if (!GROW(&(v), 1)) { st = NO_MEMORY; goto done; } (v).a[(v).n++] = (x); } while (0)

typedef struct Result_ {
    int status, pooled;          /* pooled: its arrays belong to a Pool, kept for the next level */
    double volume;
    I n_points, n_extra;
    dvec verts;                  /* 3 per vertex: the points, then the extra fill corners */
    ivec edges;                  /* 2 per segment */
    ivec flat, offsets, cells;   /* the polygons */
    ivec tri, tcell;             /* 3 per triangle, its cell */
    /* where a second thread filled some cells (`more`, its result): what the fills before the
     * cells' own took (pre_extra corners, pre_tri triangles, all here), and each cell's corners and
     * triangles, [5c .. 5c + 5) of `cell_out`: whose (0 here, 1 `more`, -1 none), its corners'
     * [from, to) and its triangles' [from, to) there; starcut_take joins them in cell order */
    struct Result_ *more;
    I pre_extra, pre_tri;
    ivec cell_out;
} Result;

static void result_free_arrays(Result *r) {
    free(r->verts.a); free(r->edges.a); free(r->flat.a); free(r->offsets.a); free(r->cells.a);
    free(r->tri.a); free(r->tcell.a); free(r->cell_out.a);
}

static void result_free(Result *r) {
    if (!r || r->pooled) return;
    result_free_arrays(r);
    free(r);
}

#ifdef STARCUT_THREADS
/* A pool's second thread, started with its first two-thread level and then waiting for the next
 * (starting a thread costs tens of microseconds a level).  Waking a sleeping thread costs as much
 * again or far more (an idle virtual processor), so a level after a two-thread one pings it first
 * (W_PINGED): it wakes while this thread does the stages before the fills, and waits for the cells
 * spinning (at most SPIN_S).  Both threads then take cells as they go (`Range.next`): a thread
 * that wakes late takes few or none, and one that has not taken the job when the cells are all
 * done is not waited for (W_JOB taken back).  `pid`: a forked child has no such thread. */
enum { W_IDLE, W_PINGED, W_JOB, W_RUNNING, W_DONE };
#define SPIN_S 0.002
/* Two threads only for a level that follows the last within `batch_gap` seconds (starcut's
 * argument, _cstar.BATCH_GAP: a batch, a stack of levels, a benchmark): between levels further
 * apart (a key's steps) the second processor goes to sleep, and waking it can cost more than it
 * saves (docs/meshes.md, benchmarks/star_threads.py). */
typedef struct {
    pthread_t th;
    pthread_mutex_t mu;
    pthread_cond_t go, fin;
    int up, quit, two_last;  /* two_last: the last level took two threads */
    double last_end;         /* when the last level ended (wall(), s) */
    _Atomic int state;
    pid_t pid;
    void *job;  /* the Range to fill */
} Worker;
#endif

/* Two results' arrays kept from one level to the next (a polytope's; starcut_pool_new), so that a
 * level reuses memory it has touched instead of growing fresh pages: R[0] the level's, R[1] the
 * second thread's, and that thread.  One level at a time (the caller holds a lock). */
typedef struct {
    Result R[2];
#ifdef STARCUT_THREADS
    Worker w;
#endif
} Pool;

void *starcut_pool_new(void) {
    Pool *p = calloc(1, sizeof(Pool));
    if (p) p->R[0].pooled = p->R[1].pooled = 1;
    return p;
}

void starcut_pool_free(void *p) {
    if (!p) return;
#ifdef STARCUT_THREADS
    Worker *w = &((Pool *)p)->w;
    if (w->up && w->pid == getpid()) {
        pthread_mutex_lock(&w->mu); w->quit = 1; pthread_cond_broadcast(&w->go); pthread_mutex_unlock(&w->mu);
        pthread_join(w->th, NULL);
        pthread_mutex_destroy(&w->mu); pthread_cond_destroy(&w->go); pthread_cond_destroy(&w->fin);
    }
#endif
    result_free_arrays(&((Pool *)p)->R[0]); result_free_arrays(&((Pool *)p)->R[1]);
    free(p);
}

static Result *result_reset(Result *r) {  /* empty, its arrays' room kept */
    r->status = 0; r->volume = 0; r->n_points = r->n_extra = 0;
    r->verts.n = r->edges.n = r->flat.n = r->offsets.n = r->cells.n = r->tri.n = r->tcell.n = 0;
    r->more = NULL; r->pre_extra = r->pre_tri = 0; r->cell_out.n = 0;
    return r;
}

/* u, v of rot4d_widget.geometry.slicetables._inplane_axes for one normal n */
static void inplane(const double *n, double *uv) {
    double nx = n[0], ny = n[1], nz = n[2];
    int use_x = nx * nx < 0.5 * (ny * ny + nz * nz + nx * nx);
    uv[0] = use_x ? 0.0 : -nz;
    uv[1] = use_x ? nz : 0.0;
    uv[2] = use_x ? -ny : nx;
    uv[3] = use_x ? -(ny * ny + nz * nz) : nx * ny;
    uv[4] = use_x ? nx * ny : -(nx * nx + nz * nz);
    uv[5] = use_x ? nx * nz : ny * nz;
}

static void cross3(const double *a, const double *b, double *o) {
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

#define EPS_ARR 1e-9   /* starfill._EPS */
#define EPS_IN 1e-12   /* a crossing inside both segments */
#define PARALLEL 1e-12 /* starfill._PARALLEL */

/* one cell's records in its plane */
typedef struct {
    I m;            /* records */
    I *g;           /* global record ids */
    I *p0, *p1;     /* their end points (point ids) */
    double *X0, *Y0, *dX, *dY;  /* (and a zero record after the m: fill_cells) */
    double *X1, *Y1;  /* the far ends as computed from them (X0 + dX may round otherwise) */
} Cell2D;

/* Even-odd slab fill of one cell's records (starslice._slabs).  xs: heights where its segments
 * cross (nx of them).  Returns a status. */
static int slab_fill(const Cell2D *c, const double *xs, I nx, I cell, Result *R) {
    int st = OK;
    I m = c->m;
    I *lo_p = NULL, *hi_p = NULL, *keep = NULL, *ylo = NULL, *yhi = NULL, *pstart = NULL, *pid = NULL;
    double *Xl = NULL, *Yl = NULL, *Xh = NULL, *Yh = NULL, *uy = NULL, *key = NULL, *slope = NULL;
    I *bylo = NULL, *act = NULL;
    I *order = NULL, *openL = NULL, *openR = NULL, *openY = NULL, *nopenL = NULL, *nopenR = NULL, *nopenY = NULL;
    lo_p = malloc(m * sizeof(I)); hi_p = malloc(m * sizeof(I)); keep = malloc(m * sizeof(I));
    Xl = malloc(m * sizeof(double)); Yl = malloc(m * sizeof(double));
    Xh = malloc(m * sizeof(double)); Yh = malloc(m * sizeof(double));
    uy = malloc((2 * m + nx + 1) * sizeof(double));
    if (!lo_p || !hi_p || !keep || !Xl || !Yl || !Xh || !Yh || !uy) { st = NO_MEMORY; goto done; }
    I nk = 0, nu = 0;
    for (I a = 0; a < m; a++) {
        double x0 = c->X0[a], y0 = c->Y0[a], x1 = c->X1[a], y1 = c->Y1[a];
        int up = y1 > y0;
        if (!(up ? y1 > y0 : y0 > y1)) continue; /* level: bounds no slab */
        lo_p[nk] = up ? c->p0[a] : c->p1[a];
        hi_p[nk] = up ? c->p1[a] : c->p0[a];
        Xl[nk] = up ? x0 : x1; Yl[nk] = up ? y0 : y1; Xh[nk] = up ? x1 : x0; Yh[nk] = up ? y1 : y0;
        uy[nu++] = Yl[nk]; uy[nu++] = Yh[nk];
        nk++;
    }
    for (I k = 0; k < nx; k++) uy[nu++] = xs[k];
    /* sort and unique the slab lines (insertion sort: a cell has a few dozen) */
    for (I i = 1; i < nu; i++) {
        double v = uy[i]; I j = i - 1;
        while (j >= 0 && uy[j] > v) { uy[j + 1] = uy[j]; j--; }
        uy[j + 1] = v;
    }
    I nl = 0;
    for (I i = 0; i < nu; i++) if (nl == 0 || uy[i] != uy[nl - 1]) uy[nl++] = uy[i];
    ylo = malloc((nk + 1) * sizeof(I)); yhi = malloc((nk + 1) * sizeof(I)); pstart = malloc((nk + 1) * sizeof(I));
    if (!ylo || !yhi || !pstart) { st = NO_MEMORY; goto done; }
    I npieces = 0;
    for (I a = 0; a < nk; a++) {  /* (exact members of uy: binary search) */
        I lo = 0, hi = nl - 1;
        while (lo < hi) { I mid = (lo + hi) / 2; if (uy[mid] < Yl[a]) lo = mid + 1; else hi = mid; }
        ylo[a] = lo;
        lo = 0; hi = nl - 1;
        while (lo < hi) { I mid = (lo + hi) / 2; if (uy[mid] < Yh[a]) lo = mid + 1; else hi = mid; }
        yhi[a] = lo; pstart[a] = npieces; npieces += yhi[a] - ylo[a];
        if (yhi[a] <= ylo[a] || uy[ylo[a]] != Yl[a] || uy[yhi[a]] != Yh[a]) { st = INCONSISTENT; goto done; }
    }
    pid = malloc((npieces + 1) * sizeof(I));  /* the extra corner on segment a at line y, -1 none yet */
    order = malloc((nk + 1) * sizeof(I)); key = malloc((nk + 1) * sizeof(double));
    openL = malloc((nk + 1) * sizeof(I)); openR = malloc((nk + 1) * sizeof(I)); openY = malloc((nk + 1) * sizeof(I));
    nopenL = malloc((nk + 1) * sizeof(I)); nopenR = malloc((nk + 1) * sizeof(I)); nopenY = malloc((nk + 1) * sizeof(I));
    slope = malloc((nk + 1) * sizeof(double)); bylo = malloc((nk + 1) * sizeof(I)); act = malloc((nk + 1) * sizeof(I));
    if (!pid || !order || !key || !openL || !openR || !openY || !nopenL || !nopenR || !nopenY || !slope || !bylo || !act) {
        st = NO_MEMORY; goto done;
    }
    for (I q = 0; q < npieces; q++) pid[q] = -1;
    for (I a = 0; a < nk; a++) {  /* slopes; the segments by their lowest slab (insertion: a few dozen) */
        slope[a] = (Xh[a] - Xl[a]) / (Yh[a] - Yl[a]);
        I j = a - 1;
        while (j >= 0 && ylo[bylo[j]] > ylo[a]) { bylo[j + 1] = bylo[j]; j--; }
        bylo[j + 1] = a;
    }
    I nact = 0, next_in = 0;
    I nopen = 0;
#define CORNER(seg, line, out) do { \
        I s_ = (seg), l_ = (line); \
        if (l_ == ylo[s_]) (out) = lo_p[s_]; \
        else if (l_ == yhi[s_]) (out) = hi_p[s_]; \
        else { I q_ = pstart[s_] + l_ - ylo[s_]; \
            if (pid[q_] < 0) { \
                double lam_ = (uy[l_] - Yl[s_]) / (Yh[s_] - Yl[s_]); \
                if (!GROW(&R->verts, 3)) { st = NO_MEMORY; goto done; } \
                const double *A_ = R->verts.a + 3 * lo_p[s_], *B_ = R->verts.a + 3 * hi_p[s_]; \
                for (int k_ = 0; k_ < 3; k_++) R->verts.a[R->verts.n++] = A_[k_] + lam_ * (B_[k_] - A_[k_]); \
                pid[q_] = R->n_points + R->n_extra++; } \
            (out) = pid[q_]; } \
    } while (0)
#define TRAP(L, Rr, y0, y1) do { \
        I a_, b_, c_, d_; \
        CORNER(L, y0, a_); CORNER(Rr, y0, b_); CORNER(Rr, y1, c_); CORNER(L, y1, d_); \
        if (a_ != b_ && b_ != c_ && a_ != c_) { PUSH(R->tri, a_); PUSH(R->tri, b_); PUSH(R->tri, c_); PUSH(R->tcell, cell); } \
        if (a_ != c_ && c_ != d_ && a_ != d_) { PUSH(R->tri, a_); PUSH(R->tri, c_); PUSH(R->tri, d_); PUSH(R->tcell, cell); } \
    } while (0)
    for (I k = 0; k + 1 < nl; k++) {
        I n = 0, keepn = 0;
        for (I i = 0; i < nact; i++) if (yhi[act[i]] > k) act[keepn++] = act[i];  /* the segments across slab k */
        nact = keepn;
        while (next_in < nk && ylo[bylo[next_in]] == k) act[nact++] = bylo[next_in++];
        for (I i = 0; i < nact; i++) {
            I a = act[i];
            {
                double xa = Xl[a] + (uy[k] - Yl[a]) * slope[a], xb = Xl[a] + (uy[k + 1] - Yl[a]) * slope[a];
                double kv = xa + xb;
                I j = n - 1;
                while (j >= 0 && key[j] > kv) { key[j + 1] = key[j]; order[j + 1] = order[j]; j--; }
                key[j + 1] = kv; order[j + 1] = a; n++;
            }
        }
        if (n & 1) { st = INCONSISTENT; goto done; }
        /* trapezoids: those open below with the same two segments go on; the others close at k */
        I nn = 0;
        for (I i = 0; i < n; i += 2) {
            I L = order[i], Rr = order[i + 1], y0 = k;
            for (I o = 0; o < nopen; o++)
                if (openL[o] == L && openR[o] == Rr) { y0 = openY[o]; openL[o] = -1; break; }
            nopenL[nn] = L; nopenR[nn] = Rr; nopenY[nn] = y0; nn++;
        }
        for (I o = 0; o < nopen; o++) if (openL[o] >= 0) TRAP(openL[o], openR[o], openY[o], k);
        memcpy(openL, nopenL, nn * sizeof(I)); memcpy(openR, nopenR, nn * sizeof(I)); memcpy(openY, nopenY, nn * sizeof(I));
        nopen = nn;
    }
    for (I o = 0; o < nopen; o++) TRAP(openL[o], openR[o], openY[o], nl - 1);
#undef TRAP
#undef CORNER
done:
    free(lo_p); free(hi_p); free(keep); free(Xl); free(Yl); free(Xh); free(Yh); free(uy); free(ylo); free(yhi);
    free(pstart); free(pid); free(order); free(key); free(openL); free(openR); free(openY);
    free(nopenL); free(nopenR); free(nopenY); free(slope); free(bylo); free(act);
    return st;
}

/* the index of the lowest set bit of v != 0 */
static inline I lowest_bit(uint64_t v) {
#if defined(__GNUC__) || defined(__clang__)
    return __builtin_ctzll(v);
#else
    I i = 0;
    while (!(v & 1)) { v >>= 1; i++; }
    return i;
#endif
}

typedef struct { char *buf; size_t cap; } Work;  /* scratch memory, grown as needed, freed by the caller */

/* Where records a and b of a cell cross, as parameters s along a and u along b (cross(e, d_b) / den
 * and cross(e, d_a) / den, den = cross(d_a, d_b), e = P_b - P_a: starfill's, to the bit); 0 when
 * they are parallel to rounding (a star face's line holds several segments: no crossing, no
 * contact) or the crossing is far outside both (neither parameter in [-0.5, 1.5]). */
static int pair_params(const Cell2D *c, I a, I b, double L2a, double L2b, double *s, double *u) {
    double ex = c->X0[b] - c->X0[a], ey = c->Y0[b] - c->Y0[a], dxa = c->dX[a], dya = c->dY[a], dxb = c->dX[b], dyb = c->dY[b];
    double den = dxa * dyb - dya * dxb;
    if (!(den * den > PARALLEL * PARALLEL * L2a * L2b)) return 0;
    double cb = ex * dyb - ey * dxb, ca = ex * dya - ey * dxa, ad = fabs(den);
    if (den < 0) { cb = -cb; ca = -ca; }
    if (cb < -0.5 * ad || cb > 1.5 * ad || ca < -0.5 * ad || ca > 1.5 * ad) return 0;
    *s = cb / ad; *u = ca / ad;  /* (negation is exact) */
    return 1;
}

/* The heights where a cell's segments cross inside both (the slab fill's extra slab lines), as
 * the arrangement computes them. */
static int inner_crossings(const Cell2D *c, dvec *xs) {
    xs->n = 0;
    for (I a = 0; a < c->m; a++) {
        double L2a = c->dX[a] * c->dX[a] + c->dY[a] * c->dY[a], s, u;
        for (I b = a + 1; b < c->m; b++) {
            if (!pair_params(c, a, b, L2a, c->dX[b] * c->dX[b] + c->dY[b] * c->dY[b], &s, &u)) continue;
            double lo = s < u ? s : u, hi = s < u ? u : s;
            if (lo > EPS_IN && hi < 1 - EPS_IN) {
                if (!GROW(xs, 1)) return NO_MEMORY;
                xs->a[xs->n++] = c->Y0[a] + s * c->dY[a];
            }
        }
    }
    return OK;
}

/* Even-odd fill of one cell's section by its segments' arrangement (starfill.arrangement_fill).
 * Returns OK with the triangles added, NOT_GENERIC when the cell is left to the slab fill (its
 * crossings by `inner_crossings`; the caller drops what was added), or NO_MEMORY.
 *
 * Loops are written without data-dependent branches where the data are random (which pairs cross,
 * the order of crossings along a segment): a mispredicted branch costs more than the arithmetic. */
static int arrangement(const Cell2D *c, const I *loc, const I *partner, I cell, Result *R, Work *ws) {
    int st = OK, bad = 0;
    I m = c->m;
    I nxmax = m * (m - 1) / 2 + 1, nsmax = m + 2 * nxmax + 1;
    /* one block for the cell: its crossings, occurrences and pieces at their most */
    size_t need = (size_t)(2 * nxmax + 4 * (m + 1) + 6 * nxmax + 4 * nsmax) * sizeof(I)
                + (size_t)(4 * nxmax + 2 * nxmax + (m + 1)) * sizeof(double) + 8 * (size_t)(nsmax / 64 + 1);
    if (ws->cap < need) {
        char *b = realloc(ws->buf, need);
        if (!b) return NO_MEMORY;
        ws->buf = b; ws->cap = need;
    }
    double *xsp = (double *)ws->buf, *xup = xsp + nxmax, *occ_t = xup + nxmax, *ut = occ_t + 2 * nxmax;
    double *L2 = ut + 2 * nxmax;
    I *xa = (I *)(L2 + (m + 1)), *xb = xa + nxmax;
    I *k = xb + nxmax, *optr = k + (m + 1), *base = optr + (m + 1), *cnt = base + (m + 1);
    I *occ_x = cnt + (m + 1), *ux = occ_x + 2 * nxmax, *pos = ux + 2 * nxmax;
    I *nxt = pos + 2 * nxmax, *tail = nxt + nsmax, *fillp = tail + nsmax, *up = fillp + nsmax;
    uint64_t *seen = (uint64_t *)(up + nsmax);  /* a bit a piece */
    const double *restrict X0 = c->X0, *restrict Y0 = c->Y0, *restrict DX = c->dX, *restrict DY = c->dY;
    MARK_START;
    I nx = 0, nn = 0;
    I *na = occ_x, *nb = ux;  /* pairs near but not inside (nn), for the shared-end check (free until the order stage) */
    for (I a = 0; a < m; a++) L2[a] = DX[a] * DX[a] + DY[a] * DY[a];
    L2[m] = 0;  /* (as the zero record after the m: see fill_cells) */
    /* every pair: s along a, u along b (starfill's, to the bit: cb / den equals the sign-corrected
     * quotient exactly); a crossing inside both is kept (nx counts it), one at an end must be where
     * the two share that end (consecutive in a cycle, checked below), a parallel pair (den ~ 0)
     * neither.  Kept pairs and near ones are stored at nx, nn and the count moved on by the test
     * (the next pair overwrites a dropped one): no branch on which */
    for (I a = 0; a + 1 < m; a++) {
        const double x0 = X0[a], y0 = Y0[a], dxa = DX[a], dya = DY[a], lim = PARALLEL * PARALLEL * L2[a];
        I b = a + 1;
#ifdef __SSE2__
        /* two pairs at a time: the same IEEE operations as the loop below (min/max as its ?:); an
         * odd last one beside the zero record (den = 0: not okd, neither kept nor near) */
        const __m128d vx0 = _mm_set1_pd(x0), vy0 = _mm_set1_pd(y0), vdxa = _mm_set1_pd(dxa), vdya = _mm_set1_pd(dya);
        const __m128d vlim = _mm_set1_pd(lim), e_lo = _mm_set1_pd(EPS_ARR), e_hi = _mm_set1_pd(1 - EPS_ARR);
        const __m128d n_lo = _mm_set1_pd(-EPS_ARR), n_hi = _mm_set1_pd(1 + EPS_ARR);
        const __m128i va = _mm_set1_epi64x(a);
        for (; b < m; b += 2) {
            __m128d ex = _mm_sub_pd(_mm_loadu_pd(X0 + b), vx0), ey = _mm_sub_pd(_mm_loadu_pd(Y0 + b), vy0);
            __m128d dxb = _mm_loadu_pd(DX + b), dyb = _mm_loadu_pd(DY + b);
            __m128d den = _mm_sub_pd(_mm_mul_pd(vdxa, dyb), _mm_mul_pd(vdya, dxb));
            __m128d sv = _mm_div_pd(_mm_sub_pd(_mm_mul_pd(ex, dyb), _mm_mul_pd(ey, dxb)), den);
            __m128d uv = _mm_div_pd(_mm_sub_pd(_mm_mul_pd(ex, vdya), _mm_mul_pd(ey, vdxa)), den);
            __m128d lo = _mm_min_pd(sv, uv), hi = _mm_max_pd(sv, uv);
            __m128d okd = _mm_cmpgt_pd(_mm_mul_pd(den, den), _mm_mul_pd(vlim, _mm_loadu_pd(L2 + b)));
            int in = _mm_movemask_pd(_mm_and_pd(okd, _mm_and_pd(_mm_cmpgt_pd(lo, e_lo), _mm_cmplt_pd(hi, e_hi))));
            int near = _mm_movemask_pd(_mm_and_pd(okd, _mm_and_pd(_mm_cmpgt_pd(lo, n_lo), _mm_cmplt_pd(hi, n_hi)))) & ~in;
            /* pair b at [n], pair b + 1 at [n + (b's kept)]: over b where b was dropped */
            I i0 = in & 1, j0 = near & 1;
            _mm_storeu_si128((__m128i *)(xa + nx), va);
            xb[nx] = b; xb[nx + i0] = b + 1;
            _mm_storel_pd(xsp + nx, sv); _mm_storeh_pd(xsp + nx + i0, sv);
            _mm_storel_pd(xup + nx, uv); _mm_storeh_pd(xup + nx + i0, uv);
            nx += i0 + (in >> 1);
            _mm_storeu_si128((__m128i *)(na + nn), va);
            nb[nn] = b; nb[nn + j0] = b + 1;
            nn += j0 + (near >> 1);
        }
#endif
        for (; b < m; b++) {
            double ex = X0[b] - x0, ey = Y0[b] - y0, dxb = DX[b], dyb = DY[b];
            double den = dxa * dyb - dya * dxb;
            double s = (ex * dyb - ey * dxb) / den, u = (ex * dya - ey * dxa) / den;
            double lo = s < u ? s : u, hi = s < u ? u : s;
            int okd = den * den > lim * L2[b];
            int in = okd & (lo > EPS_ARR) & (hi < 1 - EPS_ARR);
            int near = okd & (lo > -EPS_ARR) & (hi < 1 + EPS_ARR);
            xa[nx] = a; xb[nx] = b; xsp[nx] = s; xup[nx] = u;  /* (a slot to spare: nx < nxmax) */
            nx += in;
            na[nn] = a; nb[nn] = b;
            nn += near & !in;
        }
    }
    for (I i = 0; i < nn; i++) {
        const I *p0 = c->p0, *p1 = c->p1, a = na[i], b = nb[i];
        bad |= !((p0[a] == p0[b]) | (p0[a] == p1[b]) | (p1[a] == p0[b]) | (p1[a] == p1[b]));
    }
    MARK(T_ARR_PAIRS);
    COUNT(C_ARR_TRIED);
    if (!nx || bad) { st = NOT_GENERIC; goto done; }
    /* occurrences: each record's crossings in order along it (by rank; equal parameters: not
     * generic); occurrence 2x + j of crossing x is its place on xa[x] (j = 0) or xb[x] (j = 1),
     * at index pos[2x + j] of occ_x, occ_t */
    memset(k, 0, (m + 1) * sizeof(I));
    for (I x = 0; x < nx; x++) { k[xa[x]]++; k[xb[x]]++; }
    optr[0] = 0; base[0] = 0;
    for (I a = 0; a < m; a++) { optr[a + 1] = optr[a] + k[a]; base[a + 1] = base[a] + k[a] + 1; }
    I nsub = base[m];
    memset(fillp, 0, m * sizeof(I));
    for (I x = 0; x < nx; x++) {
        I ia = optr[xa[x]] + fillp[xa[x]]++, ib = optr[xb[x]] + fillp[xb[x]]++;
        ut[ia] = xsp[x]; ux[ia] = 2 * x;
        ut[ib] = xup[x]; ux[ib] = 2 * x + 1;
    }
    for (I a = 0; a < m; a++) {
        I s0 = optr[a], s1 = optr[a + 1];
        I rsum = 0, kk = s1 - s0, i = s0;
#ifdef __SSE2__
        for (; i + 1 < s1; i += 2) {  /* two at a time: each load compared twice */
            const double ti = ut[i], ti1 = ut[i + 1];
            const __m128d vt = _mm_set1_pd(ti), vt1 = _mm_set1_pd(ti1);
            __m128i cnt2 = _mm_setzero_si128(), cnt3 = _mm_setzero_si128();
            I j = s0;
            for (; j + 1 < s1; j += 2) {
                __m128d v = _mm_loadu_pd(ut + j);
                cnt2 = _mm_add_epi64(cnt2, _mm_castpd_si128(_mm_cmplt_pd(v, vt)));
                cnt3 = _mm_add_epi64(cnt3, _mm_castpd_si128(_mm_cmplt_pd(v, vt1)));
            }
            int64_t c2[2], c3[2];
            _mm_storeu_si128((__m128i *)c2, cnt2);
            _mm_storeu_si128((__m128i *)c3, cnt3);
            I r = -(c2[0] + c2[1]), r1 = -(c3[0] + c3[1]);
            for (; j < s1; j++) { r += ut[j] < ti; r1 += ut[j] < ti1; }
            rsum += r + r1; r += s0; r1 += s0;
            occ_t[r] = ti; occ_x[r] = ux[i] >> 1; pos[ux[i]] = r;
            occ_t[r1] = ti1; occ_x[r1] = ux[i + 1] >> 1; pos[ux[i + 1]] = r1;
        }
#endif
        for (; i < s1; i++) {
            double ti = ut[i];
            I r = 0, j = s0;
#ifdef __SSE2__
            __m128i cnt2 = _mm_setzero_si128();  /* each lane: minus its count of smaller (true is -1) */
            const __m128d vt = _mm_set1_pd(ti);
            for (; j + 1 < s1; j += 2) cnt2 = _mm_add_epi64(cnt2, _mm_castpd_si128(_mm_cmplt_pd(_mm_loadu_pd(ut + j), vt)));
            int64_t c2[2];
            _mm_storeu_si128((__m128i *)c2, cnt2);
            r = -(c2[0] + c2[1]);
#endif
            for (; j < s1; j++) r += ut[j] < ti;
            rsum += r; r += s0;
            occ_t[r] = ti; occ_x[r] = ux[i] >> 1; pos[ux[i]] = r;
        }
        if (2 * rsum != kk * (kk - 1)) { st = NOT_GENERIC; goto done; }  /* equal parameters share a rank */
    }
    MARK(T_ARR_ORDER);
    /* parity left of each record's first piece: a ray square to it, leftwards from that piece's
     * middle, for the first record of a cycle; the others along it: left of the way walked into a
     * corner is left of the way walked out (the corner is generic, no other segment through it;
     * the next pointers check every parity against its neighbours') */
    for (I a = 0; a < m; a++) cnt[a] = -1;
    for (I a0 = 0; a0 < m; a0++) {
        if (cnt[a0] >= 0) continue;
        double f = k[a0] ? occ_t[optr[a0]] : 1.0;
        double ox = c->X0[a0] + 0.5 * f * c->dX[a0], oy = c->Y0[a0] + 0.5 * f * c->dY[a0];
        double dx = c->dX[a0], dy = c->dY[a0], nx_ = -dy, ny_ = dx;
        I n = 0;
        for (I b = 0; b < m; b++) {
            double Ax = c->X0[b] - ox, Ay = c->Y0[b] - oy, Bx = Ax + c->dX[b], By = Ay + c->dY[b];
            double a0_ = Ax * dx + Ay * dy, a1 = Bx * dx + By * dy;
            double n0 = Ax * nx_ + Ay * ny_, n1 = Bx * nx_ + By * ny_;
            n += ((a0_ > 0) != (a1 > 0)) & ((a0_ * n1 - a1 * n0) * (a0_ - a1) > 0) & (b != a0);
        }
        cnt[a0] = n & 1;
        for (I a = a0, q = 1;;) {  /* leaving a at its end q: the parity left of the way walked there */
            I w = q ? cnt[a] + k[a] : cnt[a] + 1;
            I pe = partner[2 * c->g[a] + q], b = loc[pe >> 1];
            if (b < 0 || cnt[b] >= 0) break;
            cnt[b] = (pe & 1 ? w + k[b] + 1 : w) & 1;  /* entered at b's end: walking it backwards */
            a = b; q = 1 - (pe & 1);
        }
    }
    MARK(T_ARR_PARITY);
    /* the odd halves (the pieces walked with the odd side on their left): piece t of record a is
     * walked backwards, p1 to p0, where cnt[a] + t is even (base[a] + t = optr[a] + a + t); each
     * one's next odd half round its face and that one's tail (where it starts: crossing x becomes
     * fill corner x0 + x, as the crossings are output below), and up[e] where the heading passes
     * +u (once round a face).  Every piece is the next of one: every tail is set. */
    if (!GROW(&R->verts, 3 * nx) || !GROW(&R->tri, 3 * nsub) || !GROW(&R->tcell, nsub)) { st = NO_MEMORY; goto done; }
    const I x0 = R->n_points + R->n_extra;
    /* at a crossing of a and b, the two pieces of one record end there and turn left onto the
     * other's, which start there (the turns are left by construction; the parities must differ,
     * else the rays disagree: not generic), without a branch on which record's */
    for (I x = 0; x < nx; x++) {
        const I a = xa[x], b = xb[x], oa = pos[2 * x], ob = pos[2 * x + 1];
        const double dya = DY[a], dyb = DY[b];
        const int bka = ((cnt[a] + oa - optr[a]) & 1) == 0, bkb = ((cnt[b] + ob - optr[b]) & 1) == 0;
        const int turn = DX[a] * dyb - dya * DX[b] > 0;
        bad |= bka == bkb;
        /* the record whose piece before x is walked forwards (src) ends at x; dst's pieces leave
         * (selected by masks: the compiler would branch on ?:, and bka is random) */
        const I ea = oa + a, eb = ob + b, flip = (ea ^ eb) & -(I)bka;
        const I src = ea ^ flip, dst = eb ^ flip;
        const int tsel = turn ^ bka;
        /* up: the heading's y goes from < 0 to >= 0; src walked +d_src, src + 1 -d_src; the next
         * is dst + 1 (+d_dst) where tsel, else dst (-d_dst); -h < 0 is h > 0, -h >= 0 is h <= 0 */
        const int neg_a = dya < 0, pos_a = dya > 0, ge_a = dya >= 0, le_a = dya <= 0;
        const int neg_b = dyb < 0, pos_b = dyb > 0, ge_b = dyb >= 0, le_b = dyb <= 0;
        const int fa = !bka, nt = !tsel;  /* fa: a's piece before x walked forwards (src is a) */
        const int hs_neg = (bka & neg_b) | (fa & neg_a), hs_pos = (bka & pos_b) | (fa & pos_a);
        const int hd_ge = (bka & ge_a) | (fa & ge_b), hd_le = (bka & le_a) | (fa & le_b);
        nxt[src] = dst + tsel; nxt[src + 1] = dst + nt;
        tail[dst] = tail[dst + 1] = x0 + x;
        up[src] = hs_neg & ((tsel & hd_ge) | (nt & hd_le));
        up[src + 1] = hs_pos & ((tsel & hd_le) | (nt & hd_ge));
    }
    if (bad) { st = NOT_GENERIC; goto done; }
    /* at a segment's end, onto the piece of the cell's next segment there: that piece's parity
     * checked, and the turn (left for a convex face) */
    for (I a = 0; a < m; a++) {
        const I ka = k[a];
        for (int bk = 0; bk < 2; bk++) {  /* the last piece walked forwards, the first backwards */
            if (((cnt[a] + (bk ? 0 : ka)) & 1) != (bk ? 0 : 1)) continue;
            I e = bk ? base[a] : base[a] + ka;
            I pe = partner[2 * c->g[a] + 1 - bk], b = loc[pe >> 1];
            if (b < 0) { st = NOT_GENERIC; goto done; }
            int start = (pe & 1) == 0, expect = !start;
            I nx2 = start ? base[b] : base[b + 1] - 1;
            if ((((cnt[b] + nx2 - base[b]) & 1) == 0) != expect) { st = NOT_GENERIC; goto done; }
            const double hx = bk ? -c->dX[a] : c->dX[a], hy = bk ? -c->dY[a] : c->dY[a];
            const double hx2 = expect ? -c->dX[b] : c->dX[b], hy2 = expect ? -c->dY[b] : c->dY[b];
            if (!(hx * hy2 - hy * hx2 > 0)) { st = NOT_GENERIC; goto done; }
            up[e] = (hy < 0) & (hy2 >= 0);
            nxt[e] = nx2;
            tail[nx2] = start ? c->p0[b] : c->p1[b];
        }
    }
    MARK(T_ARR_NEXT);
    /* the crossings become corners */
    for (I x = 0; x < nx; x++) {
        const double *A = R->verts.a + 3 * c->p0[xa[x]], *B = R->verts.a + 3 * c->p1[xa[x]];
        double *o = R->verts.a + R->verts.n;
        for (int q = 0; q < 3; q++) o[q] = A[q] + xsp[x] * (B[q] - A[q]);
        R->verts.n += 3;
    }
    R->n_extra += nx;
    MARK(T_ARR_OUTPUT);
    /* faces, each from its least piece (its turns checked above; the heading must pass +u once),
     * fanned from that piece's tail as it is walked (a face that fails leaves the cell to the slabs) */
    const I nw = (nsub + 63) >> 6;  /* the least piece not seen found a word at a time (a branch a
                                      * piece on whether it was seen mispredicts often) */
    memset(seen, 0, nw * sizeof(uint64_t));
    if (nsub & 63) seen[nw - 1] = ~(uint64_t)0 << (nsub & 63);  /* no pieces there */
    I *tri = R->tri.a + R->tri.n, *tc = R->tcell.a + R->tcell.n, ntri = 0;  /* (room: fewer triangles than pieces) */
    for (I w = 0; w < nw;) {
        if (!~seen[w]) { w++; continue; }
        I e0 = (w << 6) + lowest_bit(~seen[w]);
        I e = e0, ups = 0, t0 = tail[e0], te = t0;
        do {  /* (a triangle written at every piece, kept where neither end is e0: room for it) */
            uint64_t bit = (uint64_t)1 << (e & 63);
            if (seen[e >> 6] & bit) { st = NOT_GENERIC; goto done; }
            seen[e >> 6] |= bit;
            I e2 = nxt[e], te2 = tail[e2];
            ups += up[e];
            tri[3 * ntri] = t0; tri[3 * ntri + 1] = te; tri[3 * ntri + 2] = te2;
            tc[ntri] = cell;
            ntri += (e != e0) & (e2 != e0);
            e = e2; te = te2;
        } while (e != e0);
        if (ups != 1) { st = NOT_GENERIC; goto done; }
    }
    R->tri.n += 3 * ntri; R->tcell.n += ntri;
    MARK(T_ARR_FACES);
    COUNT(C_ARR_FILLED);
done:
    return st;
}

/* What one level holds while it is cut: the inputs (see `starcut`) and what each stage leaves
 * for the next.  Segment r joins points seg_pt[2r], seg_pt[2r + 1] (crossings of the face sides
 * seg_side[2r], seg_side[2r + 1]) of face seg_face[r], the face winding W0[r] times round it;
 * record g = 2r + j is segment r in cell j of its face, and end q is end q & 1 of record q >> 1,
 * partner[q] the other end at that point in that cell. */
typedef struct {
    I V, E, F, S, C;
    const double *x, *face_basis, *mrot, *face_rho, *cell_normals;
    const I *ea, *eb, *fe_face, *fe_edge, *fv_vert, *fv_next, *face_cells, *slot_mate;
    const unsigned char *cell_convex;
    double c0, tol;
    int slabs_only;           /* every non-star-shaped section by slabs (tests of the slab fill) */
    int threads;              /* 2: the crossing sections' fills split between this thread and one more */
    int used;                 /* threads the fills took */
    Result *spare;            /* the second thread's result (a pool's), or NULL: one thread */
    void *worker;             /* the pool's second thread (a Worker), or NULL: one thread */
    int recent;               /* this level follows the last closely (two threads may pay) */
    unsigned char *above;     /* (V,) each vertex above H */
    I *cid;                   /* (E,) each edge's point, -1 if it does not cross */
    double centre[3];         /* the points' mean: coordinates about it keep the volume's sums small */
    I ns, *seg_pt, *seg_side, *seg_face, *W0;
    double *anchor;           /* (C, 3) a point of each cell's section plane, less `centre` */
    double *normals;          /* (C, 3) each cell's outward normal in H */
    I *partner, *rec_cell;
    Result *R;
} Level;

static void level_free(Level *L) {
    free(L->above); free(L->cid); free(L->seg_pt); free(L->seg_side); free(L->seg_face); free(L->W0);
    free(L->anchor); free(L->normals); free(L->partner); free(L->rec_cell);
}

#define PTS (L->R->verts.a) /* the points, then the fill corners (grows: re-read after every push) */

/* The points where edges cross H, in edge order; NOT_GENERIC for a vertex on H (or a coordinate
 * that is not a number), NO_CROSSING when no edge crosses. */
static int cut_edges(Level *L) {
    Result *R = L->R;
    L->above = malloc(L->V + 1); L->cid = malloc((L->E + 1) * sizeof(I));
    if (!L->above || !L->cid) return NO_MEMORY;
    if (!isfinite(L->c0) || !isfinite(L->tol)) return NOT_GENERIC;
    for (I v = 0; v < L->V; v++) {
        const double *X = L->x + 4 * v;
        double h = X[3] - L->c0;
        if (fabs(h) <= L->tol || !isfinite(h) || !isfinite(X[0]) || !isfinite(X[1]) || !isfinite(X[2]))
            return NOT_GENERIC;  /* on H (or not a number: the numpy slicer says what) */
        L->above[v] = h > 0;
    }
    I np = 0;
    for (I e = 0; e < L->E; e++) {
        if (L->above[L->ea[e]] != L->above[L->eb[e]]) {
            const double *A = L->x + 4 * L->ea[e], *B = L->x + 4 * L->eb[e];
            double ha = A[3] - L->c0, hb = B[3] - L->c0, s = ha / (ha - hb);
            if (!GROW(&R->verts, 3)) return NO_MEMORY;
            for (int k = 0; k < 3; k++) R->verts.a[R->verts.n++] = A[k] + s * (B[k] - A[k]);
            L->cid[e] = np++;
        } else L->cid[e] = -1;
    }
    if (!np) return NO_CROSSING;
    R->n_points = np;
    for (int k = 0; k < 3; k++) L->centre[k] = 0;
    for (I i = 0; i < np; i++) for (int k = 0; k < 3; k++) L->centre[k] += R->verts.a[3 * i + k];
    for (int k = 0; k < 3; k++) L->centre[k] /= (double)np;
    return OK;
}

/* Each crossing face's points sorted along its line and paired even-odd into segments; the
 * winding-weighted volume of its stretches; the cells' anchors and normals. */
static int pair_faces(Level *L) {
    int st = OK;
    Result *R = L->R;
    const I S = L->S, *cid = L->cid;
    I *sortk = malloc((S + 1) * sizeof(I)), *str_f = malloc((S + 1) * sizeof(I)), *str_p = malloc((S + 1) * sizeof(I));
    I *str_q = malloc((S + 1) * sizeof(I)), *str_w = malloc((S + 1) * sizeof(I));
    double *tpos = malloc((S + 1) * sizeof(double));
    L->seg_pt = malloc((S + 1) * sizeof(I)); L->seg_side = malloc((S + 1) * sizeof(I));
    L->seg_face = malloc((S / 2 + 1) * sizeof(I)); L->W0 = malloc((S / 2 + 1) * sizeof(I));
    L->anchor = calloc(3 * (L->C + 1), sizeof(double)); L->normals = malloc(3 * (L->C + 1) * sizeof(double));
    if (!sortk || !str_f || !str_p || !str_q || !str_w || !tpos || !L->seg_pt || !L->seg_side || !L->seg_face ||
        !L->W0 || !L->anchor || !L->normals) { st = NO_MEMORY; goto done; }
    I ns = 0, nstr = 0;
    for (I s0 = 0; s0 < S;) {
        I f = L->fe_face[s0], s1 = s0;
        while (s1 < S && L->fe_face[s1] == f) s1++;
        I n = 0;
        for (I s = s0; s < s1; s++) if (cid[L->fe_edge[s]] >= 0) sortk[n++] = s;
        if (n) {
            if (n & 1) { st = INCONSISTENT; goto done; }
            /* the line's direction in H: J grad w of the face's plane, turned */
            const double *b0 = L->face_basis + 8 * f, *b1 = b0 + 4, *m = L->mrot;
            double r0[4], r1[4], d[3];
            for (int i = 0; i < 4; i++) {
                r0[i] = m[4 * i] * b0[0] + m[4 * i + 1] * b0[1] + m[4 * i + 2] * b0[2] + m[4 * i + 3] * b0[3];
                r1[i] = m[4 * i] * b1[0] + m[4 * i + 1] * b1[1] + m[4 * i + 2] * b1[2] + m[4 * i + 3] * b1[3];
            }
            for (int i = 0; i < 3; i++) d[i] = r1[i] * r0[3] - r0[i] * r1[3];
            for (I i = 0; i < n; i++) {
                const double *P = PTS + 3 * cid[L->fe_edge[sortk[i]]];
                double tv = P[0] * d[0] + P[1] * d[1] + P[2] * d[2];
                I sv = sortk[i], j = i - 1;
                while (j >= 0 && tpos[j] > tv) { tpos[j + 1] = tpos[j]; sortk[j + 1] = sortk[j]; j--; }
                tpos[j + 1] = tv; sortk[j + 1] = sv;
            }
            for (I i = 1; i < n; i++) if (tpos[i] == tpos[i - 1]) { st = NOT_GENERIC; goto done; }
            I W = 0;
            for (I i = 0; i < n; i++) {
                I s = sortk[i];
                W += L->above[L->fv_vert[L->fv_next[s]]] ? 1 : -1;  /* +1 where the side rises through H */
                if (!(i & 1)) {
                    L->seg_face[ns] = f; L->W0[ns] = W; L->seg_pt[2 * ns] = cid[L->fe_edge[s]]; L->seg_side[2 * ns] = s;
                } else { L->seg_pt[2 * ns + 1] = cid[L->fe_edge[s]]; L->seg_side[2 * ns + 1] = s; ns++; }
                if (i + 1 < n && W != 0) {
                    str_f[nstr] = f; str_w[nstr] = W;
                    str_p[nstr] = cid[L->fe_edge[s]]; str_q[nstr] = cid[L->fe_edge[sortk[i + 1]]]; nstr++;
                }
            }
        }
        s0 = s1;
    }
    L->ns = ns;
    const double *c = L->centre;
    for (I r = 0; r < ns; r++)
        for (int j = 0; j < 2; j++) {
            I cc = L->face_cells[2 * L->seg_face[r] + j];
            for (int k = 0; k < 3; k++) L->anchor[3 * cc + k] = PTS[3 * L->seg_pt[2 * r] + k] - c[k];
        }
    double vol = 0.0;
    for (I i = 0; i < nstr; i++) {
        double P[3], Q[3], PxQ[3];
        for (int k = 0; k < 3; k++) { P[k] = PTS[3 * str_p[i] + k] - c[k]; Q[k] = PTS[3 * str_q[i] + k] - c[k]; }
        cross3(P, Q, PxQ);
        for (int j = 0; j < 2; j++) {
            const double *A = L->anchor + 3 * L->face_cells[2 * str_f[i] + j];
            vol += (double)str_w[i] * L->face_rho[2 * str_f[i] + j] * (A[0] * PxQ[0] + A[1] * PxQ[1] + A[2] * PxQ[2]);
        }
    }
    R->volume = vol / 6.0;
    for (I cc = 0; cc < L->C; cc++) {
        const double *n = L->cell_normals + 4 * cc, *m = L->mrot;
        for (int i = 0; i < 3; i++)
            L->normals[3 * cc + i] = m[4 * i] * n[0] + m[4 * i + 1] * n[1] + m[4 * i + 2] * n[2] + m[4 * i + 3] * n[3];
    }
    for (I r = 0; r < ns; r++) { PUSH(R->edges, L->seg_pt[2 * r]); PUSH(R->edges, L->seg_pt[2 * r + 1]); }
done:
    free(sortk); free(str_f); free(str_p); free(str_q); free(str_w); free(tpos);
    return st;
}

/* Each cell's cycles: the segments' ends chained through the other face of the cell at each
 * crossing edge, each cycle run the way the boundary runs its segments (the votes of its faces'
 * windings, else its signed area), corners from its least end; NO_CROSSING when none is left. */
static int chain_cycles(Level *L) {
    int st = OK;
    Result *R = L->R;
    const I ns = L->ns, n_end = 4 * ns, *seg_pt = L->seg_pt;
    I *at = malloc((L->S + 1) * sizeof(I));
    ivec ends = {0};  /* a tie's orbit's ends and its reverse's */
    unsigned char *visited = calloc(n_end + 1, 1);
    L->partner = malloc((n_end + 1) * sizeof(I)); L->rec_cell = malloc((2 * ns + 1) * sizeof(I));
    if (!at || !visited || !L->partner || !L->rec_cell) { st = NO_MEMORY; goto done; }
    I *partner = L->partner, *rec_cell = L->rec_cell;
    for (I s = 0; s < L->S; s++) at[s] = -1;
    for (I k = 0; k < 2 * ns; k++) at[L->seg_side[k]] = k;
    for (I r = 0; r < 2 * ns; r++) rec_cell[r] = L->face_cells[2 * L->seg_face[r >> 1] + (r & 1)];
    for (I q = 0; q < n_end; q++) {
        I side = L->seg_side[2 * (q >> 2) + (q & 1)];
        I mate = L->slot_mate[2 * side + ((q >> 1) & 1)];  /* the cell's other face at that edge */
        if (mate < 0) { st = INCONSISTENT; goto done; }
        I q2 = at[mate >> 1];
        if (q2 < 0) { st = INCONSISTENT; goto done; }
        partner[q] = 4 * (q2 >> 1) + 2 * (mate & 1) + (q2 & 1);
    }
    for (I q = 0; q < n_end; q++)
        if (partner[q] == q || partner[partner[q]] != q) { st = INCONSISTENT; goto done; }
    PUSH(R->offsets, 0);
    for (I q0 = 0; q0 < n_end; q0++) {
        if (visited[q0]) continue;
        I cc = rec_cell[q0 >> 1], score = 0, rev = n_end, len = 0;
        const double *A = L->anchor + 3 * cc, *N = L->normals + 3 * cc, *c = L->centre;
        I q = q0;
        do {
            visited[q] = 1; len++;
            I r = q >> 1;
            double nat = L->face_rho[2 * L->seg_face[r >> 1] + (r & 1)] * (double)((L->W0[r >> 1] > 0) - (L->W0[r >> 1] < 0));
            score += (((q & 1) == 1) == (nat > 0)) ? 1 : -1;
            if ((q ^ 1) < rev) rev = q ^ 1;
            q = partner[q] ^ 1;
            if (len > n_end) { st = INCONSISTENT; goto done; }
        } while (q != q0);
        int keep = score > 0;
        if (score == 0 && rev != q0) {
            /* the orbit's signed area against its reverse's, each summed over its ends in ascending
             * order (as the numpy slicer sums them): exactly one of the two is kept, even where the
             * area is zero to rounding (a bowtie's two halves) and the two sums differ in sign by it */
            if (!GROW(&ends, 2 * len)) { st = NO_MEMORY; goto done; }
            I *fe = ends.a, *re = ends.a + len, n = 0;
            q = q0;
            do { fe[n] = q; re[n] = q ^ 1; n++; q = partner[q] ^ 1; } while (q != q0);
            double area[2] = {0.0, 0.0};
            for (int w = 0; w < 2; w++) {
                I *o = w ? re : fe;
                for (I i = 1; i < n; i++) {  /* (insertion sort: a tie's orbit is short) */
                    I v = o[i], j = i - 1;
                    while (j >= 0 && o[j] > v) { o[j + 1] = o[j]; j--; }
                    o[j + 1] = v;
                }
                for (I i = 0; i < n; i++) {
                    I qa = o[i], qb = partner[qa] ^ 1;
                    double a[3], b[3], ab[3];
                    I ia = seg_pt[2 * (qa >> 2) + (qa & 1)], ib = seg_pt[2 * (qb >> 2) + (qb & 1)];
                    for (int k = 0; k < 3; k++) { a[k] = PTS[3 * ia + k] - c[k] - A[k]; b[k] = PTS[3 * ib + k] - c[k] - A[k]; }
                    cross3(a, b, ab);
                    area[w] += N[0] * ab[0] + N[1] * ab[1] + N[2] * ab[2];
                }
            }
            keep = area[0] > area[1] || (area[0] == area[1] && q0 < rev);
        }
        if (!keep || rev == q0) continue;  /* (rev == q0: an orbit that is its own reverse) */
        /* its corners from its least end; repeats dropped, fewer than 3 corners: none */
        I n0 = R->flat.n;
        q = q0;
        do {
            I pid = seg_pt[2 * (q >> 2) + (q & 1)];
            if (R->flat.n == n0 || R->flat.a[R->flat.n - 1] != pid) PUSH(R->flat, pid);
            q = partner[q] ^ 1;
        } while (q != q0);
        if (R->flat.n - n0 > 1 && R->flat.a[R->flat.n - 1] == R->flat.a[n0]) R->flat.n--;
        if (R->flat.n - n0 < 3) { R->flat.n = n0; continue; }
        PUSH(R->offsets, R->flat.n);
        PUSH(R->cells, cc);
    }
    if (!R->cells.n) st = NO_CROSSING;
done:
    free(at); free(visited); free(ends.a);
    return st;
}

/* The section of cell cc, polygons cI[p0 .. p1): if every one winds once round its corners'
 * centroid, always the same way, and their boxes are apart, fanned from the centroids (1); else
 * nothing done (0); NO_MEMORY as -1. */
static int star_shaped_fan(Level *L, const I *cI, I p0, I p1, I cc) {
    int st = OK;
    Result *R = L->R;
    const double *Nr = L->normals + 3 * cc;
    double nl = sqrt(Nr[0] * Nr[0] + Nr[1] * Nr[1] + Nr[2] * Nr[2]), n[3] = {Nr[0] / nl, Nr[1] / nl, Nr[2] / nl};
    for (I i = p0; i < p1; i++) {
        I o0 = R->offsets.a[cI[i]], o1 = R->offsets.a[cI[i] + 1], kk = o1 - o0;
        double cen[3] = {0, 0, 0}, ang = 0.0;
        for (I j = o0; j < o1; j++) for (int q = 0; q < 3; q++) cen[q] += PTS[3 * R->flat.a[j] + q];
        for (int q = 0; q < 3; q++) cen[q] /= (double)kk;
        I left = 0, right = 0;
        for (int pass = 0; pass < 2; pass++) {  /* every turn one way first; then the angle */
            for (I j = o0; j < o1; j++) {
                I jn = j + 1 < o1 ? j + 1 : o0;
                double a[3], b[3], ab[3];
                for (int q = 0; q < 3; q++) { a[q] = PTS[3 * R->flat.a[j] + q] - cen[q]; b[q] = PTS[3 * R->flat.a[jn] + q] - cen[q]; }
                cross3(a, b, ab);
                double y = ab[0] * n[0] + ab[1] * n[1] + ab[2] * n[2];
                if (pass) ang += atan2(y, a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
                else { left += y > 0; right += y < 0; }
            }
            if (!pass && left != kk && right != kk) return 0;
        }
        if (!(fabs(fabs(ang) - 2 * M_PI) < 1e-6)) return 0;
    }
    for (I i = p0; i < p1; i++)
        for (I j = i + 1; j < p1; j++) {
            double lo1[3], hi1[3], lo2[3], hi2[3];
            for (int w = 0; w < 2; w++) {
                I pp = cI[w ? j : i];
                double *lo = w ? lo2 : lo1, *hi = w ? hi2 : hi1;
                for (int q = 0; q < 3; q++) { lo[q] = INFINITY; hi[q] = -INFINITY; }
                for (I z = R->offsets.a[pp]; z < R->offsets.a[pp + 1]; z++)
                    for (int q = 0; q < 3; q++) {
                        double v = PTS[3 * R->flat.a[z] + q];
                        if (v < lo[q]) lo[q] = v;
                        if (v > hi[q]) hi[q] = v;
                    }
            }
            if (lo1[0] <= hi2[0] && lo2[0] <= hi1[0] && lo1[1] <= hi2[1] && lo2[1] <= hi1[1] &&
                lo1[2] <= hi2[2] && lo2[2] <= hi1[2]) return 0;
        }
    for (I i = p0; i < p1; i++) {
        I o0 = R->offsets.a[cI[i]], o1 = R->offsets.a[cI[i] + 1], kk = o1 - o0;
        double cen[3] = {0, 0, 0}, y0 = 0;
        for (I j = o0; j < o1; j++) for (int q = 0; q < 3; q++) cen[q] += PTS[3 * R->flat.a[j] + q];
        for (int q = 0; q < 3; q++) cen[q] /= (double)kk;
        {   /* the way it winds (every turn agrees): the first corner's */
            double a[3], b[3], ab[3];
            for (int q = 0; q < 3; q++) { a[q] = PTS[3 * R->flat.a[o0] + q] - cen[q]; b[q] = PTS[3 * R->flat.a[o0 + 1] + q] - cen[q]; }
            cross3(a, b, ab);
            y0 = ab[0] * n[0] + ab[1] * n[1] + ab[2] * n[2];
        }
        if (!GROW(&R->verts, 3)) return -1;
        for (int q = 0; q < 3; q++) R->verts.a[R->verts.n++] = cen[q];
        I centroid = R->n_points + R->n_extra++;
        for (I j = o0; j < o1; j++) {
            I jn = j + 1 < o1 ? j + 1 : o0;
            PUSH(R->tri, centroid);
            PUSH(R->tri, y0 > 0 ? R->flat.a[j] : R->flat.a[jn]);
            PUSH(R->tri, y0 > 0 ? R->flat.a[jn] : R->flat.a[j]);
            PUSH(R->tcell, cc);
        }
    }
done:
    return st == OK ? 1 : -1;
}

/* The cells whose sections neither a convex cycle nor a star-shaped fan filled, by their
 * arrangement, else by slabs: each thread (`Filler`) takes the next CHUNK cells (`Range.next`)
 * until none is left, into its result R (its points read, its fill corners, triangles grown),
 * noting each cell's parts in `cell_out`.  Each thread owns its scratch and R; `loc` is shared,
 * each cell writing only its own records'. */
#define CHUNK 2
typedef struct {
    Level *L;
    I C, mmax;
    const I *crec_ptr, *crec;
    const unsigned char *cdone;
    I *loc, *cell_out;      /* (5C,) see Result */
    _Atomic I next;         /* the next cell not yet taken */
    _Atomic int took2;      /* the second thread took cells */
} Range;

typedef struct {
    Range *g;
    Result *R;
    int who, st;
} Filler;

static void fill_cells(Filler *f) {
    Range *g = f->g;
    Level *L = g->L;
    Result *R = f->R;
    const I *crec_ptr = g->crec_ptr, *crec = g->crec, mmax = g->mmax;
    I *loc = g->loc, *cg = NULL;
    double *cd = NULL;
    dvec xs = {0};
    Work ws = {0};
    int st = OK;
    cg = malloc((3 * mmax + 1) * sizeof(I));
    cd = malloc(6 * (mmax + 1) * sizeof(double));  /* a cell's plane coordinates (heap: a cell may hold thousands) */
    if (!cg || !cd) { st = NO_MEMORY; goto done; }
    for (I c_lo; st == OK && (c_lo = atomic_fetch_add(&g->next, CHUNK)) < g->C;)
    for (I cc = c_lo; cc < c_lo + CHUNK && cc < g->C && st == OK; cc++) {
        I r0 = crec_ptr[cc], m = crec_ptr[cc + 1] - r0;
        if (!m || g->cdone[cc]) continue;
        if (f->who) atomic_store(&g->took2, 1);
        I *co = g->cell_out + 5 * cc, e_before = R->n_extra, t_before = R->tcell.n;
        const I ms = mmax + 1;  /* (room for a zero record after the m) */
        double *X0 = cd, *Y0 = cd + ms, *dX = cd + 2 * ms, *dY = cd + 3 * ms, *X1 = cd + 4 * ms, *Y1 = cd + 5 * ms;
        Cell2D c2 = {m, cg, cg + mmax, cg + 2 * mmax, X0, Y0, dX, dY, X1, Y1};
        double uv[6], org[3];
        const double *pts = R->verts.a;  /* (the points: not moved until this cell adds its corners) */
        inplane(L->normals + 3 * cc, uv);
        for (int q = 0; q < 3; q++) org[q] = L->anchor[3 * cc + q] + L->centre[q];
        for (I i = 0; i < m; i++) {
            I gi = crec[r0 + i], seg = gi >> 1;
            c2.g[i] = gi; c2.p0[i] = L->seg_pt[2 * seg]; c2.p1[i] = L->seg_pt[2 * seg + 1];
            loc[gi] = i;
            double a[3], b[3];
            for (int q = 0; q < 3; q++) { a[q] = pts[3 * c2.p0[i] + q] - org[q]; b[q] = pts[3 * c2.p1[i] + q] - org[q]; }
            X0[i] = a[0] * uv[0] + a[1] * uv[1] + a[2] * uv[2];
            Y0[i] = a[0] * uv[3] + a[1] * uv[4] + a[2] * uv[5];
            X1[i] = b[0] * uv[0] + b[1] * uv[1] + b[2] * uv[2];
            Y1[i] = b[0] * uv[3] + b[1] * uv[4] + b[2] * uv[5];
            dX[i] = X1[i] - X0[i];
            dY[i] = Y1[i] - Y0[i];
        }
        X0[m] = Y0[m] = dX[m] = dY[m] = 0;  /* the zero record: the arrangement's pair tests read records two at a time */
        I nv0 = R->verts.n, ne0 = R->n_extra, nt0 = R->tri.n, nc0 = R->tcell.n;
        int s2 = L->slabs_only ? NOT_GENERIC : arrangement(&c2, loc, L->partner, cc, R, &ws);
        if (s2 == NOT_GENERIC) {  /* left to the slabs: what the arrangement added is dropped */
            R->verts.n = nv0; R->n_extra = ne0; R->tri.n = nt0; R->tcell.n = nc0;
            MARK_START;
            s2 = inner_crossings(&c2, &xs);
            if (s2 == OK) s2 = slab_fill(&c2, xs.a, xs.n, cc, R);
            MARK(T_SLABS);
        }
        for (I i = 0; i < m; i++) loc[c2.g[i]] = -1;
        if (s2 != OK) st = s2;
        co[0] = f->who; co[1] = e_before; co[2] = R->n_extra; co[3] = t_before; co[4] = R->tcell.n;
    }
done:
    free(cg); free(cd); free(xs.a); free(ws.buf);
    f->st = st;
}

#ifdef STARCUT_THREADS
static double wall(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t); return t.tv_sec + 1e-9 * t.tv_nsec; }

static void *worker_loop(void *p) {
    Worker *w = (Worker *)p;
    for (;;) {
        int s;
        pthread_mutex_lock(&w->mu);
        while (((s = atomic_load(&w->state)) == W_IDLE || s == W_DONE) && !w->quit) pthread_cond_wait(&w->go, &w->mu);
        pthread_mutex_unlock(&w->mu);
        if (w->quit) break;
        double t0 = wall();
        for (long i = 1; (s = atomic_load(&w->state)) == W_PINGED; i++) {  /* the range is on its way */
#if defined(__x86_64__) || defined(__i386__)
            __builtin_ia32_pause();
#endif
            if (!(i & 1023) && wall() - t0 > SPIN_S) break;
        }
        if (s == W_PINGED) {
            pthread_mutex_lock(&w->mu);
            while ((s = atomic_load(&w->state)) == W_PINGED && !w->quit) pthread_cond_wait(&w->go, &w->mu);
            pthread_mutex_unlock(&w->mu);
        }
        int job = W_JOB;
        if (s != W_JOB || !atomic_compare_exchange_strong(&w->state, &job, W_RUNNING))
            continue;  /* not pinged for cells after all, or the cells were all done before it came */
        fill_cells((Filler *)w->job);
        pthread_mutex_lock(&w->mu);
        atomic_store(&w->state, W_DONE);
        pthread_cond_signal(&w->fin);
        pthread_mutex_unlock(&w->mu);
    }
    return NULL;
}

/* The pool's thread, started if it is not up in this process; 0 if it cannot be. */
static int worker_up(Worker *w) {
    if (w->up && w->pid == getpid()) return 1;
    w->up = 0;
    if (pthread_mutex_init(&w->mu, NULL) || pthread_cond_init(&w->go, NULL) || pthread_cond_init(&w->fin, NULL))
        return 0;
    w->quit = 0;
    atomic_store(&w->state, W_IDLE);
    if (pthread_create(&w->th, NULL, worker_loop, w) != 0) return 0;
    w->up = 1; w->pid = getpid();
    return 1;
}

static void worker_set(Worker *w, int from, int to) {  /* from < 0: any */
    pthread_mutex_lock(&w->mu);
    if (from < 0 || atomic_load(&w->state) == from) { atomic_store(&w->state, to); pthread_cond_signal(&w->go); }
    pthread_mutex_unlock(&w->mu);
}

/* At a level's start: whether it follows the last closely enough for two threads; if so, and the
 * last took two, wake the thread now (it will likely be wanted). */
static int worker_ping(Worker *w, int threads, double batch_gap) {
    int recent = threads > 1 && wall() - w->last_end < batch_gap;
    if (recent && w->two_last && worker_up(w)) worker_set(w, W_IDLE, W_PINGED);
    return recent;
}

/* At a level's end: a ping that got no cells is taken back; the time noted. */
static void worker_unping(Worker *w) {
    if (w->up && w->pid == getpid()) worker_set(w, W_PINGED, W_IDLE);
    w->last_end = wall();
}

/* Hand f to the pool's thread; 0 if it cannot be. */
static int worker_start(Worker *w, Filler *f) {
    if (!worker_up(w)) return 0;
    w->job = f;
    worker_set(w, -1, W_JOB);
    return 1;
}

/* After this thread's cells: take the job back if the other has not started it (it will not
 * touch the cells), else wait until it is done.  1 if it ran. */
static int worker_wait(Worker *w) {
    int job = W_JOB;
    pthread_mutex_lock(&w->mu);
    if (atomic_compare_exchange_strong(&w->state, &job, W_IDLE)) { pthread_mutex_unlock(&w->mu); return 0; }
    while (atomic_load(&w->state) != W_DONE) pthread_cond_wait(&w->fin, &w->mu);
    atomic_store(&w->state, W_IDLE);
    pthread_mutex_unlock(&w->mu);
    return 1;
}

#endif

/* Triangles: a convex cell's cycle fanned from its first corner; a non-convex cell's section fanned
 * from its polygons' centroids where it is star-shaped (`star_shaped_fan`), else filled even-odd by
 * its arrangement, else by slabs. */
static int fill_sections(Level *L) {
    int st = OK;
    Result *R = L->R;
    const I C = L->C, ns = L->ns, npoly = R->cells.n, *rec_cell = L->rec_cell;
    I *crec_ptr = NULL, *crec = NULL, *pstart_c = NULL, *cI = NULL, *loc = NULL, *fill = NULL;
    unsigned char *cdone = NULL;
    for (I p = 0; p < npoly; p++) {
        if (!L->cell_convex[R->cells.a[p]]) continue;
        I o0 = R->offsets.a[p], o1 = R->offsets.a[p + 1];
        for (I j = o0 + 1; j + 1 < o1; j++) {
            PUSH(R->tri, R->flat.a[o0]); PUSH(R->tri, R->flat.a[j]); PUSH(R->tri, R->flat.a[j + 1]);
            PUSH(R->tcell, R->cells.a[p]);
        }
    }
    /* a non-convex cell's records, by cell (crec), and its polygons (cI) */
    crec_ptr = calloc(C + 2, sizeof(I)); crec = malloc((2 * ns + 1) * sizeof(I)); pstart_c = calloc(C + 2, sizeof(I));
    cI = malloc((npoly + 1) * sizeof(I)); loc = malloc((2 * ns + 1) * sizeof(I)); fill = calloc(C + 1, sizeof(I));
    cdone = calloc(C + 1, 1);
    if (!crec_ptr || !crec || !pstart_c || !cI || !loc || !fill || !cdone) { st = NO_MEMORY; goto done; }
    for (I r = 0; r < 2 * ns; r++) if (!L->cell_convex[rec_cell[r]]) crec_ptr[rec_cell[r] + 1]++;
    for (I cc = 0; cc < C; cc++) crec_ptr[cc + 1] += crec_ptr[cc];
    for (I r = 0; r < 2 * ns; r++)
        if (!L->cell_convex[rec_cell[r]]) crec[crec_ptr[rec_cell[r]] + fill[rec_cell[r]]++] = r;
    for (I p = 0; p < npoly; p++) pstart_c[R->cells.a[p] + 1]++;
    for (I cc = 0; cc < C; cc++) pstart_c[cc + 1] += pstart_c[cc];
    memset(fill, 0, (C + 1) * sizeof(I));
    for (I p = 0; p < npoly; p++) cI[pstart_c[R->cells.a[p]] + fill[R->cells.a[p]]++] = p;
    MARK_START;
    for (I cc = 0; cc < C; cc++) {  /* star-shaped: only where the polygons hold all the cell's records */
        I nrec = crec_ptr[cc + 1] - crec_ptr[cc], p0 = pstart_c[cc], p1 = pstart_c[cc + 1], corners = 0;
        if (!nrec || p1 == p0) continue;
        for (I i = p0; i < p1; i++) corners += R->offsets.a[cI[i] + 1] - R->offsets.a[cI[i]];
        if (corners != nrec) continue;
        int done_ = star_shaped_fan(L, cI, p0, p1, cc);
        if (done_ < 0) { st = NO_MEMORY; goto done; }
        cdone[cc] = (unsigned char)done_;
    }
    MARK(T_FANS);
    for (I r = 0; r < 2 * ns; r++) loc[r] = -1;
    /* the rest by arrangement or slabs, cell by cell in order; with two threads, each takes the next
     * cells as it goes (a level with little such work stays on one: PARALLEL_WORK, ~ m^2 a cell) */
    if (!GROW(&R->cell_out, 5 * C)) { st = NO_MEMORY; goto done; }
    R->cell_out.n = 5 * C;
    Range g = {.L = L, .C = C, .crec_ptr = crec_ptr, .crec = crec, .cdone = cdone, .loc = loc,
               .cell_out = R->cell_out.a};
    double work = 0;
    for (I cc = 0; cc < C; cc++) {
        I mc = crec_ptr[cc + 1] - crec_ptr[cc];
        g.cell_out[5 * cc] = -1;
        if (mc > g.mmax) g.mmax = mc;
        if (!cdone[cc]) work += (double)mc * (double)mc;
    }
    atomic_store(&g.next, 0);
    atomic_store(&g.took2, 0);
    Filler f0 = {&g, R, 0, OK};
    R->pre_extra = R->n_extra; R->pre_tri = R->tcell.n;
#ifdef STARCUT_THREADS
    Worker *wk = (Worker *)L->worker;  /* (NULL without a pool: one thread) */
    Result *W = L->spare;
    Filler f1 = {&g, W, 1, OK};
    int two = wk && W && L->recent && work >= PARALLEL_WORK;  /* (recent: threads > 1) */
    if (two) {
        result_reset(W);
        W->n_points = R->n_points;
        if (!GROW(&W->verts, 3 * R->n_points)) two = 0;  /* the points, for the other thread to read */
        else { memcpy(W->verts.a, R->verts.a, 3 * R->n_points * sizeof(double)); W->verts.n = 3 * R->n_points; }
        if (two && !worker_start(wk, &f1)) two = 0;
    }
    fill_cells(&f0);
    int ran = two && worker_wait(wk);
    if (wk) wk->two_last = two;
    if (ran && f1.st != OK && f0.st == OK) f0.st = f1.st;
    if (ran && atomic_load(&g.took2)) { R->more = W; R->n_extra += W->n_extra; }  /* joined in starcut_take */
    L->used = 1 + (ran && atomic_load(&g.took2));
#else
    fill_cells(&f0);
    L->used = 1;
#endif
    st = f0.st;
done:
    free(crec_ptr); free(crec); free(pstart_c); free(cI); free(loc); free(fill); free(cdone);
    return st;
}

#undef PTS

/* The level; see the file's comment.  Arguments: x (V, 4) the rotated unit vertices; c0, tol the
 * level and the on-H tolerance; ea, eb (E,) edges; fe_face, fe_edge, fv_vert, fv_next (S,) the face
 * sides (faces ascending); face_basis (F, 2, 4); m (4, 4) the rotation; face_cells (F, 2),
 * face_rho (F, 2); slot_mate (2S,); cell_convex (C,) bytes; cell_normals (C, 4); slabs_only: no
 * arrangement fill (every section it would take goes to the slabs: for tests); threads: 2 lets a
 * second thread fill some of the crossing sections (the same result as 1) when the level follows the
 * pool's last within batch_gap seconds; pool: a `starcut_pool_new`
 * (its memory reused; the result is the pool's until starcut_take), or NULL.  counts (out):
 * points, extra corners, segments, polygon corners, polygons, triangles, threads the fills took;
 * volume, status (out).
 * Returns the result for `starcut_take`, or NULL (the status says why: the numpy slicer's level). */
void *starcut(I V, const double *x, double c0, double tol, I E, const I *ea, const I *eb, I F, I S,
              const I *fe_face, const I *fe_edge, const I *fv_vert, const I *fv_next, const double *face_basis,
              const double *mrot, const I *face_cells, const double *face_rho, const I *slot_mate, I C,
              const unsigned char *cell_convex, const double *cell_normals, int slabs_only, int threads, double batch_gap,
              void *pool, I *counts, double *volume, int *status) {
    Level L = {.V = V, .E = E, .F = F, .S = S, .C = C, .x = x, .face_basis = face_basis, .mrot = mrot,
               .face_rho = face_rho, .cell_normals = cell_normals, .ea = ea, .eb = eb, .fe_face = fe_face,
               .fe_edge = fe_edge, .fv_vert = fv_vert, .fv_next = fv_next, .face_cells = face_cells,
               .slot_mate = slot_mate, .cell_convex = cell_convex, .c0 = c0, .tol = tol, .slabs_only = slabs_only,
               .threads = threads};
    Pool *P = (Pool *)pool;
    L.R = P ? result_reset(&P->R[0]) : calloc(1, sizeof(Result));
    L.spare = P ? &P->R[1] : NULL;
#ifdef STARCUT_THREADS
    L.worker = P ? &P->w : NULL;
    if (P) L.recent = worker_ping(&P->w, threads, batch_gap);
#endif
    MARK_START;
    int st = L.R ? cut_edges(&L) : NO_MEMORY;
    MARK(T_EDGES);
    if (st == OK) st = pair_faces(&L);
    MARK(T_FACES);
    if (st == OK) st = chain_cycles(&L);
    MARK(T_CYCLES);
    if (st == OK) st = fill_sections(&L);
#ifdef STARCUT_THREADS
    if (P) worker_unping(&P->w);
#endif
    level_free(&L);
    *status = st;
    if (st != OK) { result_free(L.R); return NULL; }
    Result *R = L.R;
    counts[0] = R->n_points; counts[1] = R->n_extra; counts[2] = R->edges.n / 2; counts[3] = R->flat.n;
    counts[4] = R->cells.n; counts[5] = R->tcell.n + (R->more ? R->more->tcell.n : 0); counts[6] = L.used;
    *volume = R->volume;
    return R;
}

/* Copy a result into the caller's arrays (sized by its counts) and free it (a pool's: keep its room). */
void starcut_take(void *p, double *verts, I *edges, I *flat, I *offsets, I *cells, I *tri, I *tcell) {
    Result *R = (Result *)p, *M = R->more;
    memcpy(edges, R->edges.a, (size_t)R->edges.n * sizeof(I));
    memcpy(flat, R->flat.a, (size_t)R->flat.n * sizeof(I));
    memcpy(offsets, R->offsets.a, (size_t)R->offsets.n * sizeof(I));
    memcpy(cells, R->cells.a, (size_t)R->cells.n * sizeof(I));
    if (!M) {  /* one thread: already in cell order */
        memcpy(verts, R->verts.a, (size_t)R->verts.n * sizeof(double));
        memcpy(tri, R->tri.a, (size_t)R->tri.n * sizeof(I));
        memcpy(tcell, R->tcell.a, (size_t)R->tcell.n * sizeof(I));
    } else {  /* what came before the cells' own fills, then cell by cell, its corners renumbered */
        I np = R->n_points, ne = R->pre_extra, nt = R->pre_tri, C = R->cell_out.n / 5;
        memcpy(verts, R->verts.a, (size_t)(3 * (np + ne)) * sizeof(double));
        memcpy(tri, R->tri.a, (size_t)(3 * nt) * sizeof(I));
        memcpy(tcell, R->tcell.a, (size_t)nt * sizeof(I));
        for (I cc = 0; cc < C; cc++) {
            const I *co = R->cell_out.a + 5 * cc;
            if (co[0] < 0) continue;
            const Result *S = co[0] ? M : R;
            I e0 = co[1], e1 = co[2], t0 = co[3], t1 = co[4], shift = (np + ne) - (np + e0);
            memcpy(verts + 3 * (np + ne), S->verts.a + 3 * (np + e0), (size_t)(3 * (e1 - e0)) * sizeof(double));
            for (I i = 3 * t0; i < 3 * t1; i++) { I v = S->tri.a[i]; tri[3 * nt + i - 3 * t0] = v >= np ? v + shift : v; }
            memcpy(tcell + nt, S->tcell.a + t0, (size_t)(t1 - t0) * sizeof(I));
            ne += e1 - e0; nt += t1 - t0;
        }
    }
    result_free(R);
}
