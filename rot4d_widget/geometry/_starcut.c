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
 * coordinates float64, row-major.  Thread-safe: every call owns its memory (a `Result` freed by
 * starcut_take or starcut_free). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef int64_t I;

#ifndef STARCUT_SOURCE
#define STARCUT_SOURCE "unknown"
#endif
/* the sha256 of this file when it was built (hatch_build.py): the package uses no stale build */
const char *starcut_source(void) { return STARCUT_SOURCE; }

enum { OK = 0, NO_CROSSING = 1, INCONSISTENT = 2, NOT_GENERIC = 3, NO_MEMORY = 4 };

typedef struct { I *a; I n, cap; } ivec;
typedef struct { double *a; I n, cap; } dvec;

static int igrow(ivec *v, I extra) {
    if (v->n + extra <= v->cap) return 1;
    I cap = v->cap ? v->cap : 64;
    while (cap < v->n + extra) cap *= 2;
    I *a = (I *)realloc(v->a, (size_t)cap * sizeof(I));
    if (!a) return 0;
    v->a = a; v->cap = cap; return 1;
}
static int dgrow(dvec *v, I extra) {
    if (v->n + extra <= v->cap) return 1;
    I cap = v->cap ? v->cap : 64;
    while (cap < v->n + extra) cap *= 2;
    double *a = (double *)realloc(v->a, (size_t)cap * sizeof(double));
    if (!a) return 0;
    v->a = a; v->cap = cap; return 1;
}
#define IPUSH(v, x) do { if (!igrow(&(v), 1)) { st = NO_MEMORY; goto done; } (v).a[(v).n++] = (x); } while (0)
#define DPUSH(v, x) do { if (!dgrow(&(v), 1)) { st = NO_MEMORY; goto done; } (v).a[(v).n++] = (x); } while (0)

typedef struct {
    int status;
    double volume;
    I n_points, n_extra;
    dvec verts;                  /* 3 per vertex: the points, then the extra fill corners */
    ivec edges;                  /* 2 per segment */
    ivec flat, offsets, cells;   /* the polygons */
    ivec tri, tcell;             /* 3 per triangle, its cell */
} Result;

static void result_free(Result *r) {
    if (!r) return;
    free(r->verts.a); free(r->edges.a); free(r->flat.a); free(r->offsets.a); free(r->cells.a);
    free(r->tri.a); free(r->tcell.a); free(r);
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
    double *X0, *Y0, *dX, *dY;
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
                if (!dgrow(&R->verts, 3)) { st = NO_MEMORY; goto done; } \
                const double *A_ = R->verts.a + 3 * lo_p[s_], *B_ = R->verts.a + 3 * hi_p[s_]; \
                for (int k_ = 0; k_ < 3; k_++) R->verts.a[R->verts.n++] = A_[k_] + lam_ * (B_[k_] - A_[k_]); \
                pid[q_] = R->n_points + R->n_extra++; } \
            (out) = pid[q_]; } \
    } while (0)
#define TRAP(L, Rr, y0, y1) do { \
        I a_, b_, c_, d_; \
        CORNER(L, y0, a_); CORNER(Rr, y0, b_); CORNER(Rr, y1, c_); CORNER(L, y1, d_); \
        if (a_ != b_ && b_ != c_ && a_ != c_) { IPUSH(R->tri, a_); IPUSH(R->tri, b_); IPUSH(R->tri, c_); IPUSH(R->tcell, cell); } \
        if (a_ != c_ && c_ != d_ && a_ != d_) { IPUSH(R->tri, a_); IPUSH(R->tri, c_); IPUSH(R->tri, d_); IPUSH(R->tcell, cell); } \
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

typedef struct { char *buf; size_t cap; } Work;  /* scratch memory, grown as needed, freed by the caller */

/* The heights where a cell's segments cross inside both (the slab fill's extra slab lines), as
 * the arrangement computes them. */
static int inner_crossings(const Cell2D *c, dvec *xs) {
    xs->n = 0;
    for (I a = 0; a < c->m; a++) {
        double L2a = c->dX[a] * c->dX[a] + c->dY[a] * c->dY[a];
        for (I b = a + 1; b < c->m; b++) {
            double ex = c->X0[b] - c->X0[a], ey = c->Y0[b] - c->Y0[a];
            double den = c->dX[a] * c->dY[b] - c->dY[a] * c->dX[b];
            if (!(den * den > PARALLEL * PARALLEL * L2a * (c->dX[b] * c->dX[b] + c->dY[b] * c->dY[b]))) continue;
            double cb = ex * c->dY[b] - ey * c->dX[b], ca = ex * c->dY[a] - ey * c->dX[a], ad = fabs(den);
            if (den < 0) { cb = -cb; ca = -ca; }
            double s = cb / ad, u = ca / ad, lo = s < u ? s : u, hi = s < u ? u : s;
            if (lo > EPS_IN && hi < 1 - EPS_IN) {
                if (!dgrow(xs, 1)) return NO_MEMORY;
                xs->a[xs->n++] = c->Y0[a] + s * c->dY[a];
            }
        }
    }
    return OK;
}

/* Even-odd fill of one cell's section by its segments' arrangement (starfill.arrangement_fill).
 * Returns OK with the triangles added, NOT_GENERIC when the cell is left to the slab fill (its
 * crossings by `inner_crossings`), or NO_MEMORY. */

static int arrangement(const Cell2D *c, const I *loc, const I *partner, I cell, Result *R, Work *ws) {
    int st = OK, bad = 0;
    I m = c->m;
    I nxmax = m * (m - 1) / 2 + 1, nsmax = m + 2 * nxmax + 1;
    /* one block for the cell: its crossings, occurrences and pieces at their most */
    size_t need = (size_t)(8 * nxmax + 4 * (m + 1) + 4 * nsmax) * sizeof(I)
                + (size_t)(4 * nxmax + (m + 1) + 2 * nsmax) * sizeof(double) + (size_t)nsmax;
    if (ws->cap < need) {
        char *b = realloc(ws->buf, need);
        if (!b) return NO_MEMORY;
        ws->buf = b; ws->cap = need;
    }
    double *xsp = (double *)ws->buf, *xup = xsp + nxmax, *occ_t = xup + nxmax;
    double *L2 = occ_t + 2 * nxmax, *hx = L2 + (m + 1), *hy = hx + nsmax;
    I *xa = (I *)(hy + nsmax), *xb = xa + nxmax, *xid = xb + nxmax, *xsp_at = xid + nxmax;
    I *k = xsp_at + nxmax, *optr = k + (m + 1), *base = optr + (m + 1), *cnt = base + (m + 1);
    I *occ_x = cnt + (m + 1), *occ_other = occ_x + nxmax * 2;
    I *nxt = occ_other + nxmax * 2, *lab = nxt + nsmax, *tail = lab + nsmax, *fillp = tail + nsmax;
    unsigned char *back = (unsigned char *)(fillp + m + 1);
    memset(k, 0, (m + 1) * sizeof(I));
    I nx = 0;
    for (I a = 0; a < m; a++) L2[a] = c->dX[a] * c->dX[a] + c->dY[a] * c->dY[a];
    for (I a = 0; a < m; a++) {
        double xa0 = c->X0[a], ya0 = c->Y0[a], dxa = c->dX[a], dya = c->dY[a];
        for (I b = a + 1; b < m; b++) {
            double ex = c->X0[b] - xa0, ey = c->Y0[b] - ya0, dxb = c->dX[b], dyb = c->dY[b];
            double den = dxa * dyb - dya * dxb;
            /* parallel to rounding (a star face's line holds several segments): no crossing, no contact */
            if (!(den * den > PARALLEL * PARALLEL * L2[a] * L2[b])) continue;
            double cb = ex * dyb - ey * dxb, ca = ex * dya - ey * dxa, ad = fabs(den);
            if (den < 0) { cb = -cb; ca = -ca; }
            if (cb < -0.5 * ad || cb > 1.5 * ad || ca < -0.5 * ad || ca > 1.5 * ad) continue;  /* far from both */
            double s = cb / ad, u = ca / ad;  /* (= cej / den, cei / den exactly: negation is exact) */
            double lo = s < u ? s : u, hi = s < u ? u : s;
            if (lo > EPS_ARR && hi < 1 - EPS_ARR) { xa[nx] = a; xb[nx] = b; xsp[nx] = s; xup[nx] = u; nx++; }
            else if (lo > -EPS_ARR && hi < 1 + EPS_ARR) {
                /* at (or near) an end: only where the two share that end (consecutive in a cycle) */
                if (c->p0[a] != c->p0[b] && c->p0[a] != c->p1[b] && c->p1[a] != c->p0[b] && c->p1[a] != c->p1[b]) bad = 1;
            }
        }
    }
    if (!nx || bad) { st = NOT_GENERIC; goto done; }
    /* occurrences: each record's crossings in order along it */
    for (I x = 0; x < nx; x++) { k[xa[x]]++; k[xb[x]]++; }
    optr[0] = 0; base[0] = 0;
    for (I a = 0; a < m; a++) { optr[a + 1] = optr[a] + k[a]; base[a + 1] = base[a] + k[a] + 1; }
    I nocc = optr[m], nsub = base[m];
    (void)nocc;
    memset(fillp, 0, m * sizeof(I));
    for (I x = 0; x < nx; x++) {
        I ia = optr[xa[x]] + fillp[xa[x]]++, ib = optr[xb[x]] + fillp[xb[x]]++;
        occ_x[ia] = x; occ_t[ia] = xsp[x];
        occ_x[ib] = x; occ_t[ib] = xup[x];
    }
    for (I a = 0; a < m; a++) {  /* sort each record's occurrences by parameter; equal ones: not generic */
        I s0 = optr[a], s1 = optr[a + 1];
        for (I i = s0 + 1; i < s1; i++) {
            double tv = occ_t[i]; I xv = occ_x[i]; I j = i - 1;
            while (j >= s0 && occ_t[j] > tv) { occ_t[j + 1] = occ_t[j]; occ_x[j + 1] = occ_x[j]; j--; }
            occ_t[j + 1] = tv; occ_x[j + 1] = xv;
        }
        for (I i = s0 + 1; i < s1; i++) if (occ_t[i] == occ_t[i - 1]) { st = NOT_GENERIC; goto done; }
    }
    for (I x = 0; x < nx; x++) xsp_at[x] = -1;  /* each crossing's two occurrences, each the other's */
    for (I i = 0; i < optr[m]; i++) {
        I x = occ_x[i];
        if (xsp_at[x] < 0) xsp_at[x] = i;
        else { occ_other[i] = xsp_at[x]; occ_other[xsp_at[x]] = i; }
    }
    /* parity left of each record's first piece: a ray square to it, leftwards from that piece's middle */
    memset(cnt, 0, m * sizeof(I));
    for (I a = 0; a < m; a++) {
        double f = k[a] ? occ_t[optr[a]] : 1.0;
        double ox = c->X0[a] + 0.5 * f * c->dX[a], oy = c->Y0[a] + 0.5 * f * c->dY[a];
        double dx = c->dX[a], dy = c->dY[a], nx_ = -dy, ny_ = dx;
        I n = 0;
        for (I b = 0; b < m; b++) {
            double Ax = c->X0[b] - ox, Ay = c->Y0[b] - oy, Bx = Ax + c->dX[b], By = Ay + c->dY[b];
            double a0 = Ax * dx + Ay * dy, a1 = Bx * dx + By * dy;
            double n0 = Ax * nx_ + Ay * ny_, n1 = Bx * nx_ + By * ny_;
            n += ((a0 > 0) != (a1 > 0)) & ((a0 * n1 - a1 * n0) * (a0 - a1) > 0) & (b != a);
        }
        cnt[a] = n;
    }
    for (I a = 0; a < m; a++)
        for (I t = 0; t <= k[a]; t++) {
            I e = base[a] + t;
            back[e] = ((cnt[a] + t) & 1) == 0;
            hx[e] = back[e] ? -c->dX[a] : c->dX[a];
            hy[e] = back[e] ? -c->dY[a] : c->dY[a];
        }
    /* the next odd half round its face */
    for (I a = 0; a < m; a++) {
        for (I t = 0; t <= k[a]; t++) {
            I e = base[a] + t, nx2;
            int bk = back[e], expect;
            int at_x = bk ? t > 0 : t < k[a];
            if (at_x) {
                I oc = optr[a] + (bk ? t - 1 : t), o2 = occ_other[oc];
                I b = xa[occ_x[oc]] == a ? xb[occ_x[oc]] : xa[occ_x[oc]];
                I t2 = o2 - optr[b];
                int turn = c->dX[a] * c->dY[b] - c->dY[a] * c->dX[b] > 0;
                nx2 = base[b] + t2 + (turn != bk);
                expect = turn == bk;
            } else {
                I pe = partner[2 * c->g[a] + 1 - bk];
                I b = loc[pe >> 1];
                if (b < 0) { st = NOT_GENERIC; goto done; }
                int start = (pe & 1) == 0;
                nx2 = start ? base[b] : base[b + 1] - 1;
                expect = !start;
            }
            if (back[nx2] != expect) { st = NOT_GENERIC; goto done; }
            nxt[e] = nx2;
        }
    }
    /* faces: each by its least piece; convex (every turn left, the heading passing +u once) */
    for (I e = 0; e < nsub; e++) lab[e] = -1;
    for (I e0 = 0; e0 < nsub; e0++) {
        if (lab[e0] >= 0) continue;
        I e = e0, steps = 0, ups = 0;
        do {
            if (lab[e] >= 0 || ++steps > nsub) { st = NOT_GENERIC; goto done; }
            lab[e] = e0;
            I e2 = nxt[e];
            if (!(hx[e] * hy[e2] - hy[e] * hx[e2] > 0)) { st = NOT_GENERIC; goto done; }
            ups += hy[e] < 0 && hy[e2] >= 0;
            e = e2;
        } while (e != e0);
        if (ups != 1) { st = NOT_GENERIC; goto done; }
    }
    /* generic: the crossings become corners; each odd half's tail; fans from each face's first */
    if (!dgrow(&R->verts, 3 * nx) || !igrow(&R->tri, 3 * nsub) || !igrow(&R->tcell, nsub)) { st = NO_MEMORY; goto done; }
    for (I x = 0; x < nx; x++) {
        const double *A = R->verts.a + 3 * c->p0[xa[x]], *B = R->verts.a + 3 * c->p1[xa[x]];
        double *o = R->verts.a + R->verts.n;
        for (int q = 0; q < 3; q++) o[q] = A[q] + xsp[x] * (B[q] - A[q]);
        R->verts.n += 3;
        xid[x] = R->n_points + R->n_extra++;
    }
    for (I a = 0; a < m; a++)
        for (I t = 0; t <= k[a]; t++) {
            I e = base[a] + t;
            if (!back[e]) tail[e] = t > 0 ? xid[occ_x[optr[a] + t - 1]] : c->p0[a];
            else tail[e] = t < k[a] ? xid[occ_x[optr[a] + t]] : c->p1[a];
        }
    for (I e0 = 0; e0 < nsub; e0++) {
        if (lab[e0] != e0) continue;
        for (I e = nxt[e0]; nxt[e] != e0; e = nxt[e]) {  /* (room reserved: fewer triangles than pieces) */
            I *o = R->tri.a + R->tri.n;
            o[0] = tail[e0]; o[1] = tail[e]; o[2] = tail[nxt[e]];
            R->tri.n += 3;
            R->tcell.a[R->tcell.n++] = cell;
        }
    }
done:
    return st;
}

/* The level; see the file's comment.  Arguments: x (V, 4) the rotated unit vertices; c0, tol the
 * level and the on-H tolerance; ea, eb (E,) edges; fe_face, fe_edge, fv_vert, fv_next (S,) the face
 * sides (faces ascending); face_basis (F, 2, 4); m (4, 4) the rotation; face_cells (F, 2),
 * face_rho (F, 2); slot_mate (2S,); cell_convex (C,) bytes; cell_normals (C, 4).  counts (out):
 * points, extra corners, segments, polygon corners, polygons, triangles; status (out). */
void *starcut(I V, const double *x, double c0, double tol, I E, const I *ea, const I *eb, I F, I S,
              const I *fe_face, const I *fe_edge, const I *fv_vert, const I *fv_next, const double *face_basis,
              const double *mrot, const I *face_cells, const double *face_rho, const I *slot_mate, I C,
              const unsigned char *cell_convex, const double *cell_normals, I *counts, double *volume, int *status) {
    int st = OK;
    Result *R = calloc(1, sizeof(Result));
    unsigned char *above = NULL, *cdone = NULL;
    I *cid = NULL, *sortk = NULL, *seg_pt = NULL, *seg_side = NULL, *seg_face = NULL, *at = NULL, *partner = NULL;
    I *rec_cell = NULL, *W0 = NULL, *str_f = NULL, *str_p = NULL, *str_q = NULL, *str_w = NULL;
    I *loc = NULL, *crec_ptr = NULL, *crec = NULL, *pstart_c = NULL;
    double *anchor = NULL, *normals = NULL, *tpos = NULL;
    I *cI = NULL;
    unsigned char *visited = NULL;
    dvec xs = {0};
    Work ws = {0};
    if (!R) { *status = NO_MEMORY; return NULL; }
    above = malloc(V + 1); cid = malloc((E + 1) * sizeof(I));
    if (!above || !cid) { st = NO_MEMORY; goto done; }
    if (!isfinite(c0) || !isfinite(tol)) { st = NOT_GENERIC; goto done; }
    for (I v = 0; v < V; v++) {
        double h = x[4 * v + 3] - c0;
        if (fabs(h) <= tol || !isfinite(h) || !isfinite(x[4 * v]) || !isfinite(x[4 * v + 1]) || !isfinite(x[4 * v + 2])) {
            st = NOT_GENERIC; goto done;  /* on H (or not a number: the numpy slicer says what) */
        }
        above[v] = h > 0;
    }
    /* points: where edges cross H, in edge order */
    I np = 0;
    for (I e = 0; e < E; e++) {
        if (above[ea[e]] != above[eb[e]]) {
            const double *A = x + 4 * ea[e], *B = x + 4 * eb[e];
            double ha = A[3] - c0, hb = B[3] - c0, s = ha / (ha - hb);
            if (!dgrow(&R->verts, 3)) { st = NO_MEMORY; goto done; }
            for (int k = 0; k < 3; k++) R->verts.a[R->verts.n++] = A[k] + s * (B[k] - A[k]);
            cid[e] = np++;
        } else cid[e] = -1;
    }
    if (!np) { st = NO_CROSSING; goto done; }
    R->n_points = np;
    double centre[3] = {0, 0, 0};
    for (I i = 0; i < np; i++) for (int k = 0; k < 3; k++) centre[k] += R->verts.a[3 * i + k];
    for (int k = 0; k < 3; k++) centre[k] /= (double)np;
#define PTS (R->verts.a) /* (grows: re-read after every push) */

    /* each crossing face's points along its line, sorted, paired even-odd; its winding stretches */
    sortk = malloc((S + 1) * sizeof(I)); tpos = malloc((S + 1) * sizeof(double));
    seg_pt = malloc((S + 1) * sizeof(I)); seg_side = malloc((S + 1) * sizeof(I)); seg_face = malloc((S / 2 + 1) * sizeof(I));
    W0 = malloc((S / 2 + 1) * sizeof(I));
    str_f = malloc((S + 1) * sizeof(I)); str_p = malloc((S + 1) * sizeof(I)); str_q = malloc((S + 1) * sizeof(I));
    str_w = malloc((S + 1) * sizeof(I));
    if (!sortk || !tpos || !seg_pt || !seg_side || !seg_face || !W0 || !str_f || !str_p || !str_q || !str_w) { st = NO_MEMORY; goto done; }
    I ns = 0, nstr = 0;
    for (I s0 = 0; s0 < S;) {
        I f = fe_face[s0], s1 = s0;
        while (s1 < S && fe_face[s1] == f) s1++;
        I n = 0;
        for (I s = s0; s < s1; s++) if (cid[fe_edge[s]] >= 0) sortk[n++] = s;
        if (n) {
            if (n & 1) { st = INCONSISTENT; goto done; }
            const double *b0 = face_basis + 8 * f, *b1 = b0 + 4;
            double r0[4], r1[4], d[3];
            for (int i = 0; i < 4; i++) {
                r0[i] = mrot[4 * i] * b0[0] + mrot[4 * i + 1] * b0[1] + mrot[4 * i + 2] * b0[2] + mrot[4 * i + 3] * b0[3];
                r1[i] = mrot[4 * i] * b1[0] + mrot[4 * i + 1] * b1[1] + mrot[4 * i + 2] * b1[2] + mrot[4 * i + 3] * b1[3];
            }
            for (int i = 0; i < 3; i++) d[i] = r1[i] * r0[3] - r0[i] * r1[3];
            for (I i = 0; i < n; i++) {
                const double *P = PTS + 3 * cid[fe_edge[sortk[i]]];
                double tv = P[0] * d[0] + P[1] * d[1] + P[2] * d[2];
                I sv = sortk[i], j = i - 1;
                while (j >= 0 && tpos[j] > tv) { tpos[j + 1] = tpos[j]; sortk[j + 1] = sortk[j]; j--; }
                tpos[j + 1] = tv; sortk[j + 1] = sv;
            }
            for (I i = 1; i < n; i++) if (tpos[i] == tpos[i - 1]) { st = NOT_GENERIC; goto done; }
            I W = 0;
            for (I i = 0; i < n; i++) {
                I s = sortk[i];
                W += above[fv_vert[fv_next[s]]] ? 1 : -1;  /* +1 where the side rises through H */
                if (!(i & 1)) { seg_face[ns] = f; W0[ns] = W; seg_pt[2 * ns] = cid[fe_edge[s]]; seg_side[2 * ns] = s; }
                else { seg_pt[2 * ns + 1] = cid[fe_edge[s]]; seg_side[2 * ns + 1] = s; ns++; }
                if (i + 1 < n && W != 0) {
                    str_f[nstr] = f; str_w[nstr] = W;
                    str_p[nstr] = cid[fe_edge[s]]; str_q[nstr] = cid[fe_edge[sortk[i + 1]]]; nstr++;
                }
            }
        }
        s0 = s1;
    }
    /* volume: winding-weighted stretches in both cells of each face, about a point of each cell's plane */
    anchor = calloc(3 * (C + 1), sizeof(double));
    normals = malloc(3 * (C + 1) * sizeof(double));
    if (!anchor || !normals) { st = NO_MEMORY; goto done; }
    for (I r = 0; r < ns; r++)
        for (int j = 0; j < 2; j++) {
            I cc = face_cells[2 * seg_face[r] + j];
            for (int k = 0; k < 3; k++) anchor[3 * cc + k] = PTS[3 * seg_pt[2 * r] + k] - centre[k];
        }
    double vol = 0.0;
    for (I i = 0; i < nstr; i++) {
        double P[3], Q[3], PxQ[3];
        for (int k = 0; k < 3; k++) { P[k] = PTS[3 * str_p[i] + k] - centre[k]; Q[k] = PTS[3 * str_q[i] + k] - centre[k]; }
        cross3(P, Q, PxQ);
        for (int j = 0; j < 2; j++) {
            const double *A = anchor + 3 * face_cells[2 * str_f[i] + j];
            vol += (double)str_w[i] * face_rho[2 * str_f[i] + j] * (A[0] * PxQ[0] + A[1] * PxQ[1] + A[2] * PxQ[2]);
        }
    }
    R->volume = vol / 6.0;
    for (I cc = 0; cc < C; cc++)
        for (int i = 0; i < 3; i++)
            normals[3 * cc + i] = mrot[4 * i] * cell_normals[4 * cc] + mrot[4 * i + 1] * cell_normals[4 * cc + 1]
                                + mrot[4 * i + 2] * cell_normals[4 * cc + 2] + mrot[4 * i + 3] * cell_normals[4 * cc + 3];
    for (I r = 0; r < ns; r++) {
        IPUSH(R->edges, seg_pt[2 * r]); IPUSH(R->edges, seg_pt[2 * r + 1]);
    }

    /* cycles: end q is end q & 1 of record q >> 1 (segment q >> 2 in its face's cell (q >> 1) & 1) */
    I n_end = 4 * ns;
    at = malloc((S + 1) * sizeof(I)); partner = malloc((n_end + 1) * sizeof(I)); rec_cell = malloc((2 * ns + 1) * sizeof(I));
    visited = calloc(n_end + 1, 1);
    if (!at || !partner || !rec_cell || !visited) { st = NO_MEMORY; goto done; }
    for (I s = 0; s < S; s++) at[s] = -1;
    for (I k = 0; k < 2 * ns; k++) at[seg_side[k]] = k;
    for (I r = 0; r < 2 * ns; r++) rec_cell[r] = face_cells[2 * seg_face[r >> 1] + (r & 1)];
    for (I q = 0; q < n_end; q++) {
        I side = seg_side[2 * (q >> 2) + (q & 1)];
        I mate = slot_mate[2 * side + ((q >> 1) & 1)];
        if (mate < 0) { st = INCONSISTENT; goto done; }
        I q2 = at[mate >> 1];
        if (q2 < 0) { st = INCONSISTENT; goto done; }
        partner[q] = 4 * (q2 >> 1) + 2 * (mate & 1) + (q2 & 1);
    }
    for (I q = 0; q < n_end; q++)
        if (partner[q] == q || partner[partner[q]] != q) { st = INCONSISTENT; goto done; }
    IPUSH(R->offsets, 0);
    for (I q0 = 0; q0 < n_end; q0++) {
        if (visited[q0]) continue;
        I cc = rec_cell[q0 >> 1], score = 0, rev = n_end, len = 0;
        double area = 0.0;
        const double *A = anchor + 3 * cc, *N = normals + 3 * cc;
        I q = q0;
        do {
            visited[q] = 1; len++;
            I r = q >> 1;
            double nat = face_rho[2 * seg_face[r >> 1] + (r & 1)] * (double)((W0[r >> 1] > 0) - (W0[r >> 1] < 0));
            score += (((q & 1) == 1) == (nat > 0)) ? 1 : -1;
            if ((q ^ 1) < rev) rev = q ^ 1;
            q = partner[q] ^ 1;
            if (len > n_end) { st = INCONSISTENT; goto done; }
        } while (q != q0);
        int keep = score > 0;
        if (score == 0 && rev != q0) {
            q = q0;
            do {
                I q1 = partner[q] ^ 1;
                double a[3], b[3], ab[3];
                I ia = seg_pt[2 * (q >> 2) + (q & 1)], ib = seg_pt[2 * (q1 >> 2) + (q1 & 1)];
                for (int k = 0; k < 3; k++) { a[k] = PTS[3 * ia + k] - centre[k] - A[k]; b[k] = PTS[3 * ib + k] - centre[k] - A[k]; }
                cross3(a, b, ab);
                area += N[0] * ab[0] + N[1] * ab[1] + N[2] * ab[2];
                q = q1;
            } while (q != q0);
            keep = area > 0 || (area == 0 && q0 < rev);
        }
        if (!keep || rev == q0) continue;
        /* its corners from its least end; repeats dropped, fewer than 3 corners: none */
        I n0 = R->flat.n;
        q = q0;
        do {
            I pid = seg_pt[2 * (q >> 2) + (q & 1)];
            if (R->flat.n == n0 || R->flat.a[R->flat.n - 1] != pid) IPUSH(R->flat, pid);
            q = partner[q] ^ 1;
        } while (q != q0);
        if (R->flat.n - n0 > 1 && R->flat.a[R->flat.n - 1] == R->flat.a[n0]) R->flat.n--;
        if (R->flat.n - n0 < 3) { R->flat.n = n0; continue; }
        IPUSH(R->offsets, R->flat.n);
        IPUSH(R->cells, cc);
    }
    I npoly = R->cells.n;
    if (!npoly) { st = NO_CROSSING; goto done; }

    /* triangles: a convex cell's cycle fanned from its first corner */
    for (I p = 0; p < npoly; p++) {
        if (!cell_convex[R->cells.a[p]]) continue;
        I o0 = R->offsets.a[p], o1 = R->offsets.a[p + 1];
        for (I j = o0 + 1; j + 1 < o1; j++) {
            IPUSH(R->tri, R->flat.a[o0]); IPUSH(R->tri, R->flat.a[j]); IPUSH(R->tri, R->flat.a[j + 1]);
            IPUSH(R->tcell, R->cells.a[p]);
        }
    }
    /* a non-convex cell's records, by cell; its polygons */
    crec_ptr = calloc(C + 2, sizeof(I)); crec = malloc((2 * ns + 1) * sizeof(I));
    pstart_c = calloc(C + 2, sizeof(I)); cI = malloc((npoly + 1) * sizeof(I));
    cdone = calloc(C + 1, 1); loc = malloc((2 * ns + 1) * sizeof(I));
    if (!crec_ptr || !crec || !pstart_c || !cI || !cdone || !loc) { st = NO_MEMORY; goto done; }
    for (I r = 0; r < 2 * ns; r++) if (!cell_convex[rec_cell[r]]) crec_ptr[rec_cell[r] + 1]++;
    for (I cc = 0; cc < C; cc++) crec_ptr[cc + 1] += crec_ptr[cc];
    {
        I *fill = calloc(C + 1, sizeof(I));
        if (!fill) { st = NO_MEMORY; goto done; }
        for (I r = 0; r < 2 * ns; r++)
            if (!cell_convex[rec_cell[r]]) crec[crec_ptr[rec_cell[r]] + fill[rec_cell[r]]++] = r;
        free(fill);
        for (I p = 0; p < npoly; p++) pstart_c[R->cells.a[p] + 1]++;
        for (I cc = 0; cc < C; cc++) pstart_c[cc + 1] += pstart_c[cc];
        fill = calloc(C + 1, sizeof(I));
        if (!fill) { st = NO_MEMORY; goto done; }
        for (I p = 0; p < npoly; p++) cI[pstart_c[R->cells.a[p]] + fill[R->cells.a[p]]++] = p;
        free(fill);
    }
    /* star-shaped sections: every polygon of the cell winds once round its centroid, always the
     * same way, the cell's polygons' boxes apart and holding all its records: fanned from centroids */
    for (I cc = 0; cc < C; cc++) {
        I nrec = crec_ptr[cc + 1] - crec_ptr[cc];
        if (!nrec) continue;
        I p0 = pstart_c[cc], p1 = pstart_c[cc + 1], corners = 0;
        for (I i = p0; i < p1; i++) corners += R->offsets.a[cI[i] + 1] - R->offsets.a[cI[i]];
        if (corners != nrec || p1 == p0) continue;
        const double *Nr = normals + 3 * cc;
        double nl = sqrt(Nr[0] * Nr[0] + Nr[1] * Nr[1] + Nr[2] * Nr[2]), n[3] = {Nr[0] / nl, Nr[1] / nl, Nr[2] / nl};
        int ok = 1;
        for (I i = p0; i < p1 && ok; i++) {
            I o0 = R->offsets.a[cI[i]], o1 = R->offsets.a[cI[i] + 1], kk = o1 - o0;
            double cen[3] = {0, 0, 0}, ang = 0.0;
            for (I j = o0; j < o1; j++) for (int q = 0; q < 3; q++) cen[q] += PTS[3 * R->flat.a[j] + q];
            for (int q = 0; q < 3; q++) cen[q] /= (double)kk;
            I left = 0, right = 0;
            for (int pass = 0; pass < 2 && ok; pass++) {  /* every turn one way first; then the angle */
                for (I j = o0; j < o1; j++) {
                    I jn = j + 1 < o1 ? j + 1 : o0;
                    double a[3], b[3], ab[3];
                    for (int q = 0; q < 3; q++) { a[q] = PTS[3 * R->flat.a[j] + q] - cen[q]; b[q] = PTS[3 * R->flat.a[jn] + q] - cen[q]; }
                    cross3(a, b, ab);
                    double y = ab[0] * n[0] + ab[1] * n[1] + ab[2] * n[2];
                    if (pass) ang += atan2(y, a[0] * b[0] + a[1] * b[1] + a[2] * b[2]);
                    else { left += y > 0; right += y < 0; }
                }
                if (!pass && left != kk && right != kk) ok = 0;
            }
            if (ok && !(fabs(fabs(ang) - 2 * M_PI) < 1e-6)) ok = 0;
        }
        for (I i = p0; i < p1 && ok; i++)
            for (I j = i + 1; j < p1 && ok; j++) {
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
                    lo1[2] <= hi2[2] && lo2[2] <= hi1[2]) ok = 0;
            }
        if (!ok) continue;
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
            if (!dgrow(&R->verts, 3)) { st = NO_MEMORY; goto done; }
            for (int q = 0; q < 3; q++) R->verts.a[R->verts.n++] = cen[q];
            I cid_ = R->n_points + R->n_extra++;
            for (I j = o0; j < o1; j++) {
                I jn = j + 1 < o1 ? j + 1 : o0;
                IPUSH(R->tri, cid_);
                IPUSH(R->tri, y0 > 0 ? R->flat.a[j] : R->flat.a[jn]);
                IPUSH(R->tri, y0 > 0 ? R->flat.a[jn] : R->flat.a[j]);
                IPUSH(R->tcell, cc);
            }
        }
        cdone[cc] = 1;
    }
    /* the others: by their arrangement, else by slabs */
    for (I r = 0; r < 2 * ns; r++) loc[r] = -1;
    I mmax = 0;
    for (I cc = 0; cc < C; cc++) if (crec_ptr[cc + 1] - crec_ptr[cc] > mmax) mmax = crec_ptr[cc + 1] - crec_ptr[cc];
    I *cg = malloc((3 * mmax + 1) * sizeof(I));
    double *cd = malloc((6 * mmax + 1) * sizeof(double));  /* a cell's plane coordinates (heap: a cell may hold thousands) */
    if (!cg || !cd) { free(cg); free(cd); st = NO_MEMORY; goto done; }
    for (I cc = 0; cc < C && st == OK; cc++) {
        I r0 = crec_ptr[cc], m = crec_ptr[cc + 1] - r0;
        if (!m || cdone[cc]) continue;
        double *X0 = cd, *Y0 = cd + mmax, *dX = cd + 2 * mmax, *dY = cd + 3 * mmax, *X1 = cd + 4 * mmax, *Y1 = cd + 5 * mmax;
        Cell2D c2 = {m, cg, cg + mmax, cg + 2 * mmax, X0, Y0, dX, dY, X1, Y1};
        double uv[6], org[3];
        inplane(normals + 3 * cc, uv);
        for (int q = 0; q < 3; q++) org[q] = anchor[3 * cc + q] + centre[q];
        for (I i = 0; i < m; i++) {
            I g = crec[r0 + i], seg = g >> 1;
            c2.g[i] = g; c2.p0[i] = seg_pt[2 * seg]; c2.p1[i] = seg_pt[2 * seg + 1];
            loc[g] = i;
            double a[3], b[3];
            for (int q = 0; q < 3; q++) { a[q] = PTS[3 * c2.p0[i] + q] - org[q]; b[q] = PTS[3 * c2.p1[i] + q] - org[q]; }
            X0[i] = a[0] * uv[0] + a[1] * uv[1] + a[2] * uv[2];
            Y0[i] = a[0] * uv[3] + a[1] * uv[4] + a[2] * uv[5];
            X1[i] = b[0] * uv[0] + b[1] * uv[1] + b[2] * uv[2];
            Y1[i] = b[0] * uv[3] + b[1] * uv[4] + b[2] * uv[5];
            dX[i] = X1[i] - X0[i];
            dY[i] = Y1[i] - Y0[i];
        }
        /* the record ends' partners are global end numbers: the end 2g + n of record g */
        I nv0 = R->verts.n, ne0 = R->n_extra, nt0 = R->tri.n, nc0 = R->tcell.n;
        int s2 = arrangement(&c2, loc, partner, cc, R, &ws);
        if (s2 == NOT_GENERIC) {
            R->verts.n = nv0; R->n_extra = ne0; R->tri.n = nt0; R->tcell.n = nc0;
            s2 = inner_crossings(&c2, &xs);
            if (s2 == OK) s2 = slab_fill(&c2, xs.a, xs.n, cc, R);
        }
        for (I i = 0; i < m; i++) loc[c2.g[i]] = -1;
        if (s2 != OK) st = s2;
    }
    free(cg); free(cd);
    if (st != OK) goto done;

done:
    if (st == OK) {
        counts[0] = R->n_points; counts[1] = R->n_extra; counts[2] = R->edges.n / 2; counts[3] = R->flat.n;
        counts[4] = R->cells.n; counts[5] = R->tcell.n;
        *volume = R->volume;
    }
#undef PTS
    free(above); free(cdone); free(cid); free(sortk); free(seg_pt); free(seg_side); free(seg_face); free(at);
    free(partner); free(rec_cell); free(W0); free(str_f); free(str_p); free(str_q); free(str_w); free(loc);
    free(crec_ptr); free(crec); free(pstart_c); free(anchor); free(normals); free(tpos);
    free(cI); free(visited); free(xs.a); free(ws.buf);
    *status = st;
    if (st != OK) { result_free(R); return NULL; }
    return R;
}

/* Copy a result into the caller's arrays (sized by its counts) and free it. */
void starcut_take(void *p, double *verts, I *edges, I *flat, I *offsets, I *cells, I *tri, I *tcell) {
    Result *R = (Result *)p;
    memcpy(verts, R->verts.a, (size_t)R->verts.n * sizeof(double));
    memcpy(edges, R->edges.a, (size_t)R->edges.n * sizeof(I));
    memcpy(flat, R->flat.a, (size_t)R->flat.n * sizeof(I));
    memcpy(offsets, R->offsets.a, (size_t)R->offsets.n * sizeof(I));
    memcpy(cells, R->cells.a, (size_t)R->cells.n * sizeof(I));
    memcpy(tri, R->tri.a, (size_t)R->tri.n * sizeof(I));
    memcpy(tcell, R->tcell.a, (size_t)R->tcell.n * sizeof(I));
    result_free(R);
}
