/* comp5_gouge.c: the gouge check of a G141/G142 run: tool axis against the whole programmed contour. */
#include "interp/comp5_gouge.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "interp/comp5.h"
#include "interp/comp5_join.h"

#define GOUGE_SAMPLES_MIN 8    /* samples along a curved or tilting move, at least */
#define GOUGE_SAMPLES_MAX 4096 /* ... and at most */
#define GOUGE_REFINE_ITER 32   /* golden-section steps around the closest sample */

/* One contour segment's extent across the reference plane, for the sweep. */
struct gouge_box {
    double lo, hi;            /* along e1, mm */
    double lo2, hi2;          /* along e2, mm */
    double q0[2], q1[2];      /* its ends in (e1, e2), mm */
    size_t k;                 /* the segment pts[k - 1] -> pts[k] */
};

/* The closest approach of one move to one segment. */
struct gouge_near {
    double dist_mm;           /* tool axis to contour, in the plane normal to the axis */
    double t;                 /* where on the move (0..1) */
    double u;                 /* where on the segment (0..1) */
};

/* How moves find the segments near them: sorted along e1 of the plane normal to the run's
 * first tool axis n. When the axis changes along the run, a contour point whose distance
 * from some tool axis N is d lies within d + D sin(a) of that tool position seen along n (D
 * the run's extent, a the largest angle between N and n): the margin widens the search by
 * that. Past 60 degrees of tilt there is no sweep: every pair is compared. */
struct gouge_sweep {
    int sweep;                /* the boxes below are in use */
    int flat;                 /* the tool axis is n all along the run: exact 2-D pairs */
    double n[3], e1[3], e2[3];
    double margin_mm;         /* D sin(a), 0 when flat */
    struct gouge_box *box;    /* the segments, sorted by lo */
    size_t nbox;
    double max_w;             /* the widest box along e1, mm */
};

/* The tolerance for a tool of radius W: 1e-6 relative, never below 1e-6 mm. */
static double gouge_tol(double radius_mm)
{
    return COMP5_GOUGE_REL * fmax(radius_mm, 1.0);
}

void comp5_gouge_clear(struct comp5_gouge *g)
{
    g->npts = 0;
    g->nmoves = 0;
}

void comp5_gouge_free(struct comp5_gouge *g)
{
    free(g->pts);
    free(g->moves);
    memset(g, 0, sizeof *g);
}

/* Makes room for one more element of size sz in *arr (count n, capacity *cap). */
static int gouge_grow(void **arr, size_t n, size_t *cap, size_t sz)
{
    if (n < *cap)
        return 0;
    size_t ncap = *cap ? 2 * *cap : 64;
    void *p = realloc(*arr, ncap * sz);
    if (!p)
        return -1;
    *arr = p;
    *cap = ncap;
    return 0;
}

int comp5_gouge_add_point(struct comp5_gouge *g, const struct comp5_gpt *pt)
{
    if (gouge_grow((void **)&g->pts, g->npts, &g->cap_pts, sizeof *g->pts))
        return -1;
    g->pts[g->npts++] = *pt;
    return 0;
}

int comp5_gouge_add_move(struct comp5_gouge *g, const struct comp5_gmove *m)
{
    if (gouge_grow((void **)&g->moves, g->nmoves, &g->cap_moves, sizeof *g->moves))
        return -1;
    g->moves[g->nmoves++] = *m;
    return 0;
}

/* True when two poses have the same orientation (A B C within COMP5_EPS_DEG). */
static int gouge_same_abc(const double a[6], const double b[6])
{
    for (int i = 3; i < 6; i++)
        if (fabs(a[i] - b[i]) >= COMP5_EPS_DEG)
            return 0;
    return 1;
}

/* The angle (rad, in (0, 2 pi]) an arc turns counter-clockwise about its normal. */
static double gouge_arc_angle(const struct comp5_gmove *m)
{
    double r0[3], r1[3], x[3];
    comp5_sub(m->p0, m->center, r0);
    comp5_sub(m->p1, m->center, r1);
    comp5_cross(r0, r1, x);
    double a = atan2(comp5_dot(x, m->normal), comp5_dot(r0, r1));
    return a <= 0.0 ? a + 2.0 * M_PI : a;
}

/* The tool pose at fraction t of a move: straight (linear in all six), or the arc's
 * rotation about its normal with the along-normal part and A B C linear. */
static void gouge_pose(const struct comp5_gmove *m, double angle, double t, double out[6])
{
    for (int i = 0; i < 6; i++)
        out[i] = m->p0[i] + t * (m->p1[i] - m->p0[i]);
    if (!m->arc)
        return;
    double r0[3], nxr[3];
    comp5_sub(m->p0, m->center, r0);
    double h0 = comp5_dot(r0, m->normal);
    for (int i = 0; i < 3; i++)
        r0[i] -= h0 * m->normal[i];
    comp5_cross(m->normal, r0, nxr);
    double c = cos(t * angle), s = sin(t * angle), d[3];
    comp5_sub(m->p1, m->p0, d);
    double h = h0 + t * comp5_dot(d, m->normal);
    for (int i = 0; i < 3; i++)
        out[i] = m->center[i] + c * r0[i] + s * nxr[i] + h * m->normal[i];
}

/* v without its component along unit n. */
static void gouge_flat(const double v[3], const double n[3], double out[3])
{
    double d = comp5_dot(v, n);
    for (int i = 0; i < 3; i++)
        out[i] = v[i] - d * n[i];
}

/* Distance from the line through x along unit n to segment a..b, measured in the plane
 * normal to n; *u the closest point's place on a..b. */
static double gouge_point_seg(const double x[3], const double n[3], const double a[3],
                              const double b[3], double *u)
{
    double d[3], e[3], dp[3], ep[3];
    comp5_sub(a, x, d);
    comp5_sub(b, a, e);
    gouge_flat(d, n, dp);
    gouge_flat(e, n, ep);
    double ee = comp5_dot(ep, ep), t = 0.0;
    if (ee > 0.0)
        t = -comp5_dot(dp, ep) / ee;
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    *u = t;
    for (int i = 0; i < 3; i++)
        dp[i] += t * ep[i];
    return comp5_len(dp);
}

/* 2-D helpers for the straight case. */
static double cross2(const double a[2], const double b[2])
{
    return a[0] * b[1] - a[1] * b[0];
}

/* Squared distance from 2-D point p to segment a..b, and the place s on a..b. */
static double seg2_point2(const double p[2], const double a[2], const double b[2], double *s)
{
    double e[2] = {b[0] - a[0], b[1] - a[1]}, d[2] = {p[0] - a[0], p[1] - a[1]};
    double ee = e[0] * e[0] + e[1] * e[1], t = 0.0;
    if (ee > 0.0)
        t = (d[0] * e[0] + d[1] * e[1]) / ee;
    t = t < 0.0 ? 0.0 : t > 1.0 ? 1.0 : t;
    *s = t;
    double x = d[0] - t * e[0], y = d[1] - t * e[1];
    return x * x + y * y;
}

/* The exact distance between two 2-D segments p0..p1 (the tool) and q0..q1 (the contour):
 * zero where they cross, else the closest of the four end-to-segment distances. */
static void gouge_near_2d(const double p0[2], const double p1[2], const double q0[2],
                          const double q1[2], struct gouge_near *r)
{
    double rv[2] = {p1[0] - p0[0], p1[1] - p0[1]}, sv[2] = {q1[0] - q0[0], q1[1] - q0[1]};
    double w[2] = {q0[0] - p0[0], q0[1] - p0[1]}, den = cross2(rv, sv), s;
    if (fabs(den) > 1e-300) {
        double t = cross2(w, sv) / den, u = cross2(w, rv) / den;
        if (t >= 0.0 && t <= 1.0 && u >= 0.0 && u <= 1.0) {
            r->dist_mm = 0.0, r->t = t, r->u = u;
            return;
        }
    }
    double best = seg2_point2(p0, q0, q1, &s);
    r->t = 0.0, r->u = s;
    double d = seg2_point2(p1, q0, q1, &s);
    if (d < best)
        best = d, r->t = 1.0, r->u = s;
    d = seg2_point2(q0, p0, p1, &s);
    if (d < best)
        best = d, r->t = s, r->u = 0.0;
    d = seg2_point2(q1, p0, p1, &s);
    if (d < best)
        best = d, r->t = s, r->u = 1.0;
    r->dist_mm = sqrt(best);
}

/* Straight move with a constant tool axis: both segments seen along the axis (e1, e2 span
 * the plane normal to it), then the exact 2-D distance. */
static void gouge_near_line(const struct comp5_gmove *m, const double e1[3], const double e2[3],
                            const double a[3], const double b[3], struct gouge_near *r)
{
    double p0[2] = {comp5_dot(m->p0, e1), comp5_dot(m->p0, e2)};
    double p1[2] = {comp5_dot(m->p1, e1), comp5_dot(m->p1, e2)};
    double q0[2] = {comp5_dot(a, e1), comp5_dot(a, e2)};
    double q1[2] = {comp5_dot(b, e1), comp5_dot(b, e2)};
    gouge_near_2d(p0, p1, q0, q1, r);
}

/* The distance at fraction t of a curved or tilting move (the axis from the pose's A B C). */
static double gouge_dist_at(const struct comp5_gmove *m, double angle, double t,
                            const double a[3], const double b[3], double *u)
{
    double pose[6], n[3];
    gouge_pose(m, angle, t, pose);
    comp5_axis(m->tf, pose + 3, n);
    return gouge_point_seg(pose, n, a, b, u);
}

/* Curved or tilting move: sampled finely (at least every W/4 of travel, every degree of
 * tilt and every 1/16 rad of arc), then the closest sample refined by golden section. */
static void gouge_near_sampled(const struct comp5_gmove *m, const double a[3],
                               const double b[3], struct gouge_near *r)
{
    double angle = m->arc ? gouge_arc_angle(m) : 0.0, tilt_deg = 0.0, u;
    for (int i = 3; i < 6; i++)
        tilt_deg = fmax(tilt_deg, fabs(m->p1[i] - m->p0[i]));
    double len_mm = m->arc ? angle * comp5_dist(m->p0, m->center) : comp5_dist(m->p0, m->p1);
    double ns = GOUGE_SAMPLES_MIN + ceil(4.0 * len_mm / m->radius_mm) + ceil(tilt_deg) +
                ceil(16.0 * angle);
    int n = ns > GOUGE_SAMPLES_MAX ? GOUGE_SAMPLES_MAX : (int)ns, best = 0;
    r->dist_mm = INFINITY;
    for (int i = 0; i <= n; i++) {
        double d = gouge_dist_at(m, angle, (double)i / n, a, b, &u);
        if (d < r->dist_mm)
            r->dist_mm = d, r->t = (double)i / n, r->u = u, best = i;
    }
    double lo = best > 0 ? (double)(best - 1) / n : 0.0;
    double hi = best < n ? (double)(best + 1) / n : 1.0;
    const double g = 0.5 * (sqrt(5.0) - 1.0);
    for (int it = 0; it < GOUGE_REFINE_ITER; it++) {
        double t1 = hi - g * (hi - lo), t2 = lo + g * (hi - lo), u1, u2;
        double d1 = gouge_dist_at(m, angle, t1, a, b, &u1);
        double d2 = gouge_dist_at(m, angle, t2, a, b, &u2);
        if (d1 < r->dist_mm)
            r->dist_mm = d1, r->t = t1, r->u = u1;
        if (d2 < r->dist_mm)
            r->dist_mm = d2, r->t = t2, r->u = u2;
        if (d1 < d2)
            hi = t2;
        else
            lo = t1;
    }
}

/* Two unit vectors e1, e2 spanning the plane normal to unit n. */
static void gouge_plane(const double n[3], double e1[3], double e2[3])
{
    double x[3] = {1, 0, 0}, y[3] = {0, 1, 0};
    comp5_cross(n, fabs(n[0]) < 0.9 ? x : y, e1);
    double l = comp5_len(e1);
    for (int i = 0; i < 3; i++)
        e1[i] /= l;
    comp5_cross(n, e1, e2);
}

/* Grows the box lo..hi (3 axes) by the point p with margin r. */
static void gouge_extend(double lo[3], double hi[3], const double p[3], double r)
{
    for (int i = 0; i < 3; i++)
        lo[i] = fmin(lo[i], p[i] - r), hi[i] = fmax(hi[i], p[i] + r);
}

/* How far the tool axis can turn along move m, rad: N = Rz(C) Ry(B) Rx(A) z turns no
 * faster than |dA| + |dB| + s |dC| (rad per unit of t), s = |z x N| <= sqrt(1 - (cos A
 * cos B)^2) the sine of the axis's tilt from Z (C turns about Z), with the largest |A|, |B|
 * of the move; so it stays within half of that from the middle. */
static double gouge_turn_rad(const struct comp5_gmove *m)
{
    double d2r = M_PI / 180.0;
    double a_max = fmax(fabs(m->p0[3]), fabs(m->p1[3])) * d2r;
    double b_max = fmax(fabs(m->p0[4]), fabs(m->p1[4])) * d2r;
    double cz = a_max < 0.5 * M_PI && b_max < 0.5 * M_PI ? cos(a_max) * cos(b_max) : 0.0;
    return (fabs(m->p1[3] - m->p0[3]) + fabs(m->p1[4] - m->p0[4]) +
            sqrt(fmax(0.0, 1.0 - cz * cz)) * fabs(m->p1[5] - m->p0[5])) * d2r;
}

/* The run's reference frame (its first tool axis n), whether the axis stays n (flat), and
 * the sweep's margin D sin(a) for a run whose axis changes; no sweep past 60 degrees. */
static void gouge_frame(const struct comp5_gouge *g, struct gouge_sweep *sw)
{
    const double *ref = g->pts[0].p;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double min_cos = 1.0, nn[3], max_turn = 0.0;
    sw->flat = 1;
    const struct kins_tool_frame *tf = g->nmoves ? g->moves[0].tf : NULL;
    comp5_axis(tf, ref + 3, sw->n);
    gouge_plane(sw->n, sw->e1, sw->e2);
    for (size_t k = 0; k < g->npts + 2 * g->nmoves; k++) {
        const struct comp5_gmove *m = k < g->npts ? NULL : &g->moves[(k - g->npts) / 2];
        const double *p = !m ? g->pts[k].p : (k - g->npts) % 2 ? m->p1 : m->p0;
        gouge_extend(lo, hi, p, m && m->arc ? comp5_dist(m->p0, m->center) : 0.0);
        if (m && !m->arc && (k - g->npts) % 2 == 0)
            max_turn = fmax(max_turn, gouge_turn_rad(m));
        if (gouge_same_abc(p, ref))
            continue;
        sw->flat = 0;
        comp5_axis(tf, p + 3, nn);
        min_cos = fmin(min_cos, comp5_dot(nn, sw->n));
    }
    double d[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
    /* a: the largest angle at the ends of the moves, plus half a move's turn between them */
    double a_rad = acos(fmin(1.0, min_cos)) + 0.5 * max_turn;
    double sin_a = sin(fmin(a_rad, 0.5 * M_PI));
    sw->sweep = a_rad < M_PI / 3.0;
    sw->margin_mm = sw->flat ? 0.0 : comp5_len(d) * sin_a + COMP5_EPS_MM;
}

/* Sweep order: by the low end along e1. */
static int gouge_box_cmp(const void *pa, const void *pb)
{
    const struct gouge_box *a = pa, *b = pb;
    return (a->lo > b->lo) - (a->lo < b->lo);
}

/* What one move needs for its pairs, computed once: the frame of its middle tool axis, how
 * far the axis turns from it along the move (sin beta), and for an arc its centre and
 * radius. */
struct gouge_movectx {
    double f1[3], f2[3];      /* the plane normal to the axis at the middle of the move */
    double nm[3];             /* that axis */
    double beta_rad;          /* the axis never turns further than this from nm */
    double arc_r_mm;          /* arc: distance of the start from the centre */
};

/* The context of move m. */
static void gouge_move_ctx(const struct comp5_gmove *m, struct gouge_movectx *x)
{
    double mid[6];
    for (int i = 0; i < 6; i++)
        mid[i] = 0.5 * (m->p0[i] + m->p1[i]);
    comp5_axis(m->tf, mid + 3, x->nm);
    gouge_plane(x->nm, x->f1, x->f2);
    x->beta_rad = 0.5 * gouge_turn_rad(m);
    x->arc_r_mm = m->arc ? comp5_dist(m->p0, m->center) : 0.0;
}

/* max |q - p| and max |(q - p) . n| over p in {p0, p1}, q in {a, b} (both are largest at
 * the ends, the first being convex and the second affine in the places on both segments). */
static void gouge_span(const double p0[3], const double p1[3], const double a[3],
                       const double b[3], const double n[3], double *v_mm, double *h_mm)
{
    const double *ps[2] = {p0, p1}, *qs[2] = {a, b};
    double d[3];
    *v_mm = 0.0, *h_mm = 0.0;
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) {
            comp5_sub(qs[j], ps[i], d);
            *v_mm = fmax(*v_mm, comp5_len(d));
            *h_mm = fmax(*h_mm, fabs(comp5_dot(d, n)));
        }
}

/* The closest approach of move m to segment k in the move's own frame: exact for a straight
 * move with a constant axis; otherwise a lower bound first, and sampling only when the bound
 * does not already show the pair clear (>= `clear_mm`). The bounds: an arc (constant axis)
 * is no nearer than its centre less its radius; a straight tilting move, seen along its axis
 * N instead of the middle axis nm: d_N^2 = |v|^2 - (v.N)^2 = d_nm^2 - (v.(N - nm)) (v.(N +
 * nm)) >= d_nm^2 - |v| beta (2 h + |v| beta), v from tool to contour, h = max |v.nm|. */
static void gouge_near_pair(const struct comp5_gouge *g, const struct comp5_gmove *m, size_t k,
                            const struct gouge_movectx *x, double clear_mm,
                            struct gouge_near *r)
{
    const double *a = g->pts[k - 1].p, *b = g->pts[k].p;
    double lb, u;
    if (!m->arc) {
        gouge_near_line(m, x->f1, x->f2, a, b, r);
        if (x->beta_rad == 0.0)
            return;
        double v, h;
        gouge_span(m->p0, m->p1, a, b, x->nm, &v, &h);
        double vb = v * x->beta_rad, d = r->dist_mm;
        lb = sqrt(fmax(0.0, d * d - vb * (2.0 * h + vb)));
    } else {
        lb = gouge_point_seg(m->center, x->nm, a, b, &u) - x->arc_r_mm;
    }
    if (lb >= clear_mm) {
        r->dist_mm = lb, r->t = 0.0, r->u = 0.0;
        return;
    }
    gouge_near_sampled(m, a, b, r);
}

/* Fills the report for move m cutting into segment k at r. */
static void gouge_report(const struct comp5_gouge *g, const struct comp5_gmove *m, size_t k,
                         const struct gouge_near *r, struct comp5_gouge_hit *hit)
{
    const struct comp5_gpt *pa = &g->pts[k - 1], *pb = &g->pts[k];
    double unit = pb->unit_mm > 0.0 ? pb->unit_mm : 1.0, tool[6];
    gouge_pose(m, m->arc ? gouge_arc_angle(m) : 0.0, r->t, tool);
    hit->depth_mm = m->radius_mm - r->dist_mm;
    hit->dist_mm = r->dist_mm;
    hit->radius_mm = m->radius_mm;
    hit->move_line = m->line;
    hit->positioning = m->positioning && r->t < 1.0 - 1e-9;
    hit->tilt = m->line == pb->line && !gouge_same_abc(m->p0, m->p1);
    hit->seg_line0 = pa->line;
    hit->seg_line1 = pb->line;
    for (int i = 0; i < 3; i++) {
        double c = pa->p[i] + r->u * (pb->p[i] - pa->p[i]);
        hit->point_prog[i] = (c - pb->prog_off[i]) / unit;
        hit->tool_prog[i] = (tool[i] - pb->prog_off[i]) / unit;
    }
}

/* The deepest cut of move m into any candidate segment; 1 (and *hit) when beyond the
 * tolerance. Candidates: every segment, or those the sweep finds near the move. */
static int gouge_move(const struct comp5_gouge *g, const struct comp5_gmove *m,
                      const struct gouge_sweep *sw, struct comp5_gouge_hit *hit)
{
    double reach = m->radius_mm + gouge_tol(m->radius_mm), worst = gouge_tol(m->radius_mm);
    double lo = 0, hi = 0, lo2 = 0, hi2 = 0;
    const double *e1 = sw->e1, *e2 = sw->e2;
    const struct gouge_box *box = sw->box;
    size_t first = 0, best_k = 0;
    struct gouge_near r, best;
    if (sw->sweep) {
        double ext = (m->arc ? comp5_dist(m->p0, m->center) : 0.0) + reach + sw->margin_mm;
        const double *c0 = m->arc ? m->center : m->p0, *c1 = m->arc ? m->center : m->p1;
        lo = fmin(comp5_dot(c0, e1), comp5_dot(c1, e1)) - ext;
        hi = fmax(comp5_dot(c0, e1), comp5_dot(c1, e1)) + ext;
        lo2 = fmin(comp5_dot(c0, e2), comp5_dot(c1, e2)) - ext;
        hi2 = fmax(comp5_dot(c0, e2), comp5_dot(c1, e2)) + ext;
        size_t l = 0, h = sw->nbox; /* first box whose lo may reach: lo >= query lo - max_w */
        while (l < h) {
            size_t mid = l + (h - l) / 2;
            if (box[mid].lo < lo - sw->max_w)
                l = mid + 1;
            else
                h = mid;
        }
        first = l;
    }
    size_t count = sw->sweep ? sw->nbox : g->npts - 1;
    double p0[2] = {comp5_dot(m->p0, e1), comp5_dot(m->p0, e2)};
    double p1[2] = {comp5_dot(m->p1, e1), comp5_dot(m->p1, e2)};
    double mid[2] = {0.5 * (p0[0] + p1[0]), 0.5 * (p0[1] + p1[1])};
    double half_mm = 0.5 * hypot(p1[0] - p0[0], p1[1] - p0[1]);
    struct gouge_movectx x;
    if (!sw->flat || m->arc)
        gouge_move_ctx(m, &x);
    for (size_t i = first; i < count; i++) {
        size_t k = i + 1;
        if (sw->sweep) {
            if (box[i].lo > hi)
                break;
            if (box[i].hi < lo || box[i].hi2 < lo2 || box[i].lo2 > hi2)
                continue;
            k = box[i].k;
        }
        if (sw->flat && !m->arc) {
            /* lower bound first: no move point is nearer than its middle's distance less
             * half its length */
            double us, dm = sqrt(seg2_point2(mid, box[i].q0, box[i].q1, &us));
            if (dm - half_mm >= reach)
                continue;
            gouge_near_2d(p0, p1, box[i].q0, box[i].q1, &r);
        } else {
            gouge_near_pair(g, m, k, &x, m->radius_mm - gouge_tol(m->radius_mm), &r);
        }
        double depth = m->radius_mm - r.dist_mm;
        if (depth > worst)
            worst = depth, best = r, best_k = k;
    }
    if (!best_k)
        return 0;
    gouge_report(g, m, best_k, &best, hit);
    return 1;
}

/* The positioning move counts only when level: it starts at the cutting depth. */
static int gouge_counts(const struct comp5_gmove *m)
{
    if (!m->positioning)
        return 1;
    double n[3], d[3];
    comp5_axis(m->tf, m->p1 + 3, n);
    comp5_sub(m->p0, m->p1, d);
    return fabs(comp5_dot(d, n)) <= gouge_tol(m->radius_mm);
}

int comp5_gouge_check(const struct comp5_gouge *g, struct comp5_gouge_hit *hit)
{
    struct gouge_sweep sw;
    int found = 0;
    memset(hit, 0, sizeof *hit);
    memset(&sw, 0, sizeof sw);
    if (g->npts < 2)
        return 0;
    gouge_frame(g, &sw);
    if (sw.sweep) {
        sw.nbox = g->npts - 1;
        sw.box = malloc(sw.nbox * sizeof *sw.box);
        if (!sw.box)
            return -1;
        for (size_t k = 1; k < g->npts; k++) {
            const double *a = g->pts[k - 1].p, *b = g->pts[k].p;
            struct gouge_box *x = &sw.box[k - 1];
            double a1 = comp5_dot(a, sw.e1), b1 = comp5_dot(b, sw.e1);
            double a2 = comp5_dot(a, sw.e2), b2 = comp5_dot(b, sw.e2);
            x->lo = fmin(a1, b1), x->hi = fmax(a1, b1);
            x->q0[0] = a1, x->q0[1] = a2, x->q1[0] = b1, x->q1[1] = b2;
            x->lo2 = fmin(a2, b2), x->hi2 = fmax(a2, b2);
            x->k = k;
            sw.max_w = fmax(sw.max_w, x->hi - x->lo);
        }
        qsort(sw.box, sw.nbox, sizeof *sw.box, gouge_box_cmp);
    }
    for (size_t i = 0; i < g->nmoves && !found; i++)
        if (gouge_counts(&g->moves[i]))
            found = gouge_move(g, &g->moves[i], &sw, hit);
    free(sw.box);
    return found;
}
