/* comp5_join.c: how two G141/G142 offset segments meet at a corner (inside point, outside arc). */
#include "interp/comp5_join.h"

#include <string.h>

/* v without its component along unit n. */
static void comp5_join_flat(const double v[3], const double n[3], double out[3])
{
    double d = comp5_dot(v, n);
    for (int i = 0; i < 3; i++)
        out[i] = v[i] - d * n[i];
}

/* Inside corner: the point where the two offset lines meet, seen along the corner's tool
 * axis N. When they are skew (the orientation changes, or the contour does not lie in a
 * plane normal to N, e.g. a horizontal contour on a tilted table) they still cross in that
 * view: pa on line a and pb on line b differ only along N, and the join is their midpoint.
 * Its tool axis is then exactly W from both walls (what the gouge check measures); the
 * depth difference |pa - pb| is shared. Closest points of two lines in the metric that
 * ignores N: minimise |flat(w0 + t Da - u Db)|^2. Parallel in that view: a straight join. */
static void comp5_join_inside(const struct comp5_seg *a, const struct comp5_seg *b,
                              const double corner[6], const struct kins_tool_frame *tf,
                              struct comp5_join *j)
{
    double da[3], db[3], w0[3], pa[3], pb[3], n[3], fa[3], fb[3], fw[3];
    comp5_sub(a->a1, a->a0, da);
    comp5_sub(b->a1, b->a0, db);
    comp5_sub(a->a0, b->a0, w0);
    comp5_axis(tf, corner + 3, n);
    comp5_join_flat(da, n, fa);
    comp5_join_flat(db, n, fb);
    comp5_join_flat(w0, n, fw);
    double aa = comp5_dot(fa, fa), ab = comp5_dot(fa, fb), bb = comp5_dot(fb, fb);
    double d = comp5_dot(fa, fw), e = comp5_dot(fb, fw);
    double denom = aa * bb - ab * ab; /* |Da|^2 |Db|^2 sin^2(angle between the lines) */
    if (!(denom > COMP5_EPS_SIN_PARALLEL * COMP5_EPS_SIN_PARALLEL * aa * bb)) {
        j->kind = COMP5_JOIN_LINE;
        return;
    }
    j->kind = COMP5_JOIN_INSIDE;
    j->t_a = (ab * e - bb * d) / denom;
    j->u_b = (aa * e - ab * d) / denom;
    for (int i = 0; i < 3; i++) {
        pa[i] = a->a0[i] + j->t_a * da[i];
        pb[i] = b->a0[i] + j->u_b * db[i];
        j->point[i] = 0.5 * (pa[i] + pb[i]);
        j->point[3 + i] = corner[3 + i];
    }
    j->gap_mm = comp5_dist(pa, pb);
}

/* Outside corner: an arc about the corner from a1 to b0 (both at distance W, both taken with
 * the corner's orientation), counter-clockwise about unit(ua x ub), i.e. the short way, which
 * is the way round the outside. A U-turn (ua = -ub) has no such plane: its normal is
 * ua x T_a, so the arc starts off forward along the direction of travel. */
static void comp5_join_outside(const struct comp5_seg *a, const double ua[3],
                               const double ub[3], struct comp5_join *j)
{
    double n[3];
    comp5_cross(ua, ub, n);
    double sin_mag = comp5_len(n);
    if (!(sin_mag > COMP5_EPS_SIN_PARALLEL)) {
        if (comp5_dot(ua, ub) > 0.0) {
            j->kind = COMP5_JOIN_LINE; /* a vanishing arc: its chord is as good */
            return;
        }
        comp5_cross(ua, a->dir, n); /* |ua x T| = 1: ua is perpendicular to T */
        sin_mag = comp5_len(n);
        if (!(sin_mag > COMP5_EPS_SIN_PARALLEL)) {
            j->kind = COMP5_JOIN_LINE;
            return;
        }
    }
    j->kind = COMP5_JOIN_OUTSIDE;
    for (int i = 0; i < 3; i++)
        j->normal[i] = n[i] / sin_mag + 0.0; /* + 0.0 turns -0 into 0 for the printout */
}

/* Classifies the corner: inside when the next segment turns towards the compensation side
 * (T_b . ua - T_a . ub > 0, ua and ub the unit offset directions at the corner). */
void comp5_join_corner(const struct comp5_seg *a, const struct comp5_seg *b,
                       const double corner[6], const struct kins_tool_frame *tf,
                       struct comp5_join *j)
{
    double ua[3], ub[3];
    memset(j, 0, sizeof *j);
    if (comp5_dist(a->a1, b->a0) < COMP5_EPS_MM) {
        j->kind = COMP5_JOIN_NONE;
        return;
    }
    comp5_sub(a->a1, corner, ua);
    comp5_sub(b->a0, corner, ub);
    double ra = comp5_len(ua), rb = comp5_len(ub); /* the corner's radius W, > EPS_MM */
    if (!(ra > COMP5_EPS_MM && rb > COMP5_EPS_MM)) {
        j->kind = COMP5_JOIN_LINE;
        return;
    }
    for (int i = 0; i < 3; i++)
        ua[i] /= ra, ub[i] /= rb;
    double turn = comp5_dot(b->dir, ua) - comp5_dot(a->dir, ub);
    if (turn > 0.0)
        comp5_join_inside(a, b, corner, tf, j);
    else
        comp5_join_outside(a, ua, ub, j);
}
