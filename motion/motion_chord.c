/* motion_chord.c: where a set-point chord can touch an arc, and knots where that reach ends. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_priv.h"

/*
 * A drive moves its leg linearly between set points T apart, so the tool goes along the chord
 * of the path between two set points rather than along the path. Where a chord touches an arc
 * (a blend arc of G64, a programmed G2/G3, a G141/G142 corner arc), it cuts the arc by up to
 * the arc's sagitta, about k d^2 / 8 for a chord of length d and curvature k, even when the
 * chord's other end lies well along a straight line accelerating away. So every knot within
 * reach of such a chord gets the chord cap (motion_chord_cap), and a knot is put exactly where
 * the reach ends: the speed is at or below the cap everywhere a chord could touch the arc.
 *
 *      line ─────────●──────●═══arc═══●──────●───────── line
 *                    |<-D ->|         |<-D ->|          D = margin · sqrt(8 · 0.9 tol / k)
 *                  new knot                new knot     (the longest chord the cap allows)
 *
 * A chord that starts or ends on the arc moves at or below the cap while inside the reach, so
 * it covers at most cap · T < D: it never leaves the reach, and its length is within the cap.
 */

#define CHORD_MARGIN 1.1       /* the reach is this much longer than the longest chord */

/* See motion_priv.h. A circle of radius r has curvature 1/r; the small spiral of an arc whose
 * end radius differs (dr over the sweep) has at most (1 + 2 (r'/r)^2) / r, r' = dr per
 * radian; a helix bends less than its circle. */
double motion_arc_curvature(const struct motion_plan *p, const struct motion_seg *sg,
                            double *kabc)
{
    const struct motion_arc *a = &p->arcs[sg->arc];
    double r = motion_min2(a->r0_mm, a->r0_mm + a->dr_mm);
    double rp = fabs(a->sweep_rad) > 1e-12 ? a->dr_mm / a->sweep_rad : 0;
    /* the cubic's A B C curvature is linear in u: largest at an end */
    *kabc = motion_max2(motion_seg_abc_curvature(p, sg, 0),
                        motion_seg_abc_curvature(p, sg, sg->len));
    return (1 + 2 * (rp / r) * (rp / r)) / r;
}

/* Marks the first (end 0) or last (end 1) len_mm of o as within reach of an arc (curvatures
 * k, kabc; rounding budget tol, mm). */
static void mark(struct motion_seg *o, int end, double len_mm, double k, double kabc,
                 double tol)
{
    o->chord_mm[end] = motion_max2(o->chord_mm[end], len_mm);
    o->chord_k[end] = motion_max2(o->chord_k[end], k);
    o->chord_kabc[end] = motion_max2(o->chord_kabc[end], kabc);
    o->chord_tol[end] = motion_min2(o->chord_tol[end], tol);
}

/* Marks the segments before (dir -1) or after (dir +1) arc segment j within d_mm of path.
 * Dwells, pauses and rotary-only moves have no X Y Z travel: the reach goes on past them. */
static void reach(struct motion_plan *p, size_t j, int dir, double d_mm, double k, double kabc,
                  double tol)
{
    size_t i = j;
    while (d_mm > 0) {
        if (dir < 0 ? i == 0 : i + 1 >= p->nseg)
            break;
        i = dir < 0 ? i - 1 : i + 1;
        struct motion_seg *o = &p->segs[i];
        if (o->kind > SEG_ARC || o->rotary)
            continue;
        mark(o, dir < 0 ? 1 : 0, motion_min2(d_mm, o->len), k, kabc, tol);
        d_mm -= o->len;
    }
}

/* How fast a chord may run near end `end` of sg: the bound on its squared length (over 8)
 * of the arcs reaching sg from there, the lower of the linear and the angular one; the
 * lower the bound, the slower the cap. */
static double end_bound(const struct motion_config *c, const struct motion_seg *sg, int end)
{
    double b = HUGE_VAL;
    if (sg->chord_k[end] > 0)
        b = sg->chord_tol[end] / sg->chord_k[end];
    if (sg->chord_kabc[end] > 0 && c->kin_tol_deg > 0)
        b = motion_min2(b, KIN_TOL_SHARE * c->kin_tol_deg / sg->chord_kabc[end]);
    return b;
}

/* The places inside sg (0 < s < len) where a reach ends and no knot lies yet, ascending;
 * returns how many (0 to 2). */
static int new_knots(const struct motion_config *c, const struct motion_plan *p,
                     const struct motion_seg *sg, double s[2])
{
    int n = 0, only = -1;
    double cand[2] = {sg->chord_mm[0], sg->len - sg->chord_mm[1]};
    if (sg->kind > SEG_ARC || sg->rotary)
        return 0;
    double eps = 1e-9 * (1 + sg->len), h = sg->len / (double)(sg->nk - 1);
    /* Reaches from both ends that meet: every point of sg lies in one. The speed between
     * two knots is at most the faster one's (v^2 is linear in s there), so the reach of the
     * slower end (the sharper arc's) needs a knot where it ends: then every interval lies
     * either within it, between two of its knots, or within the other reach alone. The other
     * reach's end lies inside the slower one's and needs none: short moves between blends
     * (dense CAM code) get one knot more, not two. */
    if (sg->chord_mm[0] > 0 && sg->chord_mm[1] > 0 &&
        sg->chord_mm[0] + sg->chord_mm[1] >= sg->len - eps)
        only = end_bound(c, sg, 0) <= end_bound(c, sg, 1) ? 0 : 1;
    for (int e = 0; e < 2; e++) {
        double x = cand[e];
        if (!(x > eps && x < sg->len - eps) || sg->chord_mm[e] <= 0 ||
            (only >= 0 && e != only))
            continue;
        double nearest = p->ks[sg->k0] + h * round((x - p->ks[sg->k0]) / h);
        if (fabs(nearest - x) <= eps || (n == 1 && fabs(s[0] - x) <= eps))
            continue;
        s[n++] = x;
    }
    if (n == 2 && s[1] < s[0]) {
        double t = s[0];
        s[0] = s[1], s[1] = t;
    }
    return n;
}

/* Resizes every per-knot array to cap entries; the plan stays consistent on failure. */
static int resize_knots(struct motion_plan *p, size_t cap)
{
    double **arr[7] = {&p->ks, &p->kv, &p->kt, &p->krho, &p->iacc, &p->irho, &p->ivp};
    for (int i = 0; i < 7; i++) {
        double *n = realloc(*arr[i], cap * sizeof *n);
        if (!n)
            return -1;
        *arr[i] = n;
    }
    p->capknot = cap;
    return 0;
}

/* Puts the knots where the reaches end into the (evenly spaced) knots of every segment. */
static int insert_knots(const struct motion_config *c, struct motion_plan *p)
{
    size_t extra = 0;
    double s[2];
    for (size_t j = 0; j < p->nseg; j++)
        extra += (size_t)new_knots(c, p, &p->segs[j], s);
    if (extra == 0)
        return 0;
    size_t n = p->nknot + extra;
    double *ks = malloc(n * sizeof *ks);
    if (!ks)
        return -1;
    size_t w = 0;
    for (size_t j = 0; j < p->nseg; j++) {
        struct motion_seg *sg = &p->segs[j];
        int m = new_knots(c, p, sg, s), used = 0;
        size_t k0 = w;
        for (size_t i = 0; i < sg->nk; i++) {
            double x = p->ks[sg->k0 + i];
            while (used < m && s[used] < x)
                ks[w++] = s[used++];
            ks[w++] = x;
        }
        sg->k0 = k0;
        sg->nk += (size_t)m;
    }
    if (n > p->capknot && resize_knots(p, n) < 0) {
        free(ks);
        return -1;
    }
    memcpy(p->ks, ks, n * sizeof *ks);
    p->nknot = n;
    free(ks);
    return 0;
}

/* See motion_priv.h. The reach of an arc is the longest chord its cap allows (with q_kin = 0
 * and f = 1 it is longest), times CHORD_MARGIN. */
int motion_chord_zones(struct motion *m)
{
    struct motion_plan *p = &m->plan;
    const struct motion_config *c = &m->cfg;
    for (size_t j = 0; j < p->nseg; j++) {
        struct motion_seg *sg = &p->segs[j];
        memset(sg->chord_mm, 0, sizeof sg->chord_mm);
        memset(sg->chord_k, 0, sizeof sg->chord_k);
        memset(sg->chord_kabc, 0, sizeof sg->chord_kabc);
        sg->chord_tol[0] = sg->chord_tol[1] = HUGE_VAL;
    }
    if (c->kin_tol_mm <= 0)
        return 0;
    for (size_t j = 0; j < p->nseg; j++) {
        struct motion_seg *sg = &p->segs[j];
        if (sg->kind != SEG_ARC || !(sg->len > 0))
            continue;
        double kabc, k = motion_arc_curvature(p, sg, &kabc), tol = motion_round_tol_mm(m, sg);
        double d = sqrt(8 * tol / k);
        if (kabc > 1e-30 && c->kin_tol_deg > 0)
            d = motion_min2(d, sqrt(8 * KIN_TOL_SHARE * c->kin_tol_deg / kabc));
        d *= CHORD_MARGIN;
        mark(sg, 0, sg->len, k, kabc, tol);
        mark(sg, 1, sg->len, k, kabc, tol);
        reach(p, j, -1, d, k, kabc, tol);
        reach(p, j, +1, d, k, kabc, tol);
    }
    return insert_knots(c, p);
}
