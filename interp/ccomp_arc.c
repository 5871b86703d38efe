/* ccomp_arc.c: G2/G3 under G41/G42: the offset arc and its corner with the move before. */
#include <math.h>
#include <string.h>

#include "interp/ccomp_priv.h"

/* LinuxCNC's centre-arc radius tolerance (CENTER_ARC_RADIUS_TOLERANCE_*). */
#define CC_ARC_TOL_MM (2 * 0.01 * M_SQRT2)
#define CC_ARC_TOL_IN (2 * 0.001 * M_SQRT2)

/* Column of the block's motion word, for errors. */
static int motion_col(const struct interp *in)
{
    return in->blk.g[1] >= 0 ? in->blk.gcol[1] : 0;
}

static const char *unit(const struct interp *in)
{
    return in->inch ? "in" : "mm";
}

/* The tool cannot run inside an arc of radius not more than its own. */
static int check_fits(struct interp *in, double arc_radius)
{
    if (arc_radius > in->cc.radius)
        return 0;
    return interp_fail(in, INTERP_ERR_CCOMP, motion_col(in), "%s: the tool radius %.4f %s is "
                       "not less than the radius %.4f %s of the arc it runs inside",
                       in->cc.name, in->cc.radius, unit(in), arc_radius, unit(in));
}

/* The entry move is an arc: the tool goes on an arc from where it is to a radius beside
 * the programmed end, about a centre found again (LinuxCNC's convert_arc_comp1). */
static int arc_first(struct interp *in, int turn, const double e[2], const double c[2],
                     const double s[2], double z, const double end6[6])
{
    struct ccomp *cc = &in->cc;
    double cx = cc->cur[0], cy = cc->cur[1], r = cc->radius, ex = e[0], ey = e[1];
    double d = hypot(ex - cx, ey - cy);
    if (d <= r)
        return interp_fail(in, INTERP_ERR_CCOMP, motion_col(in), "%s entry arc: its end is "
                           "%.4f %s from the start, not more than the tool radius %.4f %s",
                           cc->name, d, unit(in), r, unit(in));
    int inside = CC_INSIDE(cc->side, turn);
    if (inside)
        CHP(check_fits(in, hypot(c[0] - s[0], c[1] - s[1])));
    double gamma = inside ? atan2(c[1] - ey, c[0] - ex) : atan2(ey - c[1], ex - c[0]);
    ex += r * cos(gamma);
    ey += r * sin(gamma);
    /* the new centre: on the line from the end to the old centre, as far from the start
     * as from the end */
    double b_len = hypot(cy - ey, cx - ex) / 2.0;
    double ab = atan2(c[1] - ey, c[0] - ex);
    double a_ang = atan2(cy - ey, cx - ex) - ab;
    if (fabs(cos(a_ang)) < CC_EQUAL)
        return interp_fail(in, INTERP_ERR_CCOMP, motion_col(in), "%s entry arc: no arc "
                           "through its start reaches a radius beside its end (tool radius "
                           "%.4f %s too large for it)", cc->name, r, unit(in));
    double c_len = b_len / cos(a_ang);
    double nx = ex + c_len * cos(ab), ny = ey + c_len * sin(ab);
    if (fabs(hypot(nx - ex, ny - ey) - hypot(nx - cx, ny - cy)) >
        (in->inch ? CC_ARC_TOL_IN : CC_ARC_TOL_MM))
        return interp_fail(in, INTERP_ERR_CCOMP, motion_col(in), "%s entry arc: the offset "
                           "arc does not close (an interpreter fault)", cc->name);
    CHP(ccomp_push_arc(in, ccomp_sweep(cx, cy, nx, ny, turn, ex, ey), ex, ey, nx, ny, turn, z,
                       end6));
    cc->first = 0;
    cc->cur[0] = ex, cc->cur[1] = ey, cc->cur[2] = z;
    return 0;
}

/* Inside corner, a queued line then this arc (centre c, radius ar): where the offset line
 * meets the offset arc. theta: the normal of the line's tool side, beta: the turn. */
static int line_arc_corner(struct interp *in, int turn, const double c[2], double ar,
                           double theta, double beta, double *mx, double *my)
{
    struct ccomp *cc = &in->cc;
    double r = cc->radius, dist, l, ang;
    double h = (double)(ar * sinl(beta - CC_PI_2L));
    if (CC_INSIDE(cc->side, turn)) {
        dist = ar - r;
        l = (h + r) / dist;
    } else {
        dist = ar + r;
        l = (h - r) / dist;
    }
    if (l > 1.0 || l < -1.0)
        return interp_fail(in, INTERP_ERR_CCOMP, motion_col(in), "%s: this arc makes an "
                           "inside corner the tool (radius %.4f %s) cannot reach without "
                           "gouging", cc->name, r, unit(in));
    if (CC_INSIDE(cc->side, turn))
        ang = turn > 0 ? theta + asin(l) : theta - asin(l);
    else
        ang = turn > 0 ? (double)(theta + CC_PI_L - asin(l)) : (double)(theta + CC_PI_L + asin(l));
    *mx = c[0] + dist * cos(ang);
    *my = c[1] + dist * sin(ang);
    return 0;
}

/* Inside corner, a queued arc then this arc: where the two offset circles cross. */
static int arc_arc_corner(struct interp *in, int turn, const double c[2], double ar,
                          double *mx, double *my)
{
    struct ccomp *cc = &in->cc;
    const struct ccomp_item *prev = &cc->q[0];
    double r = cc->radius;
    double oldrad = hypot(prev->center[1] - prev->end[1], prev->center[0] - prev->end[0]);
    double newrad = CC_INSIDE(cc->side, turn) ? ar - r : ar + r;
    double arc_cc = hypot(prev->center[1] - c[1], prev->center[0] - c[0]);
    if (oldrad == 0 || arc_cc == 0)
        return interp_fail(in, INTERP_ERR_CCOMP, motion_col(in), "%s: this arc and the arc "
                           "of line %d have the same centre: no corner to place", cc->name,
                           prev->cmd.line);
    double a = (oldrad * oldrad + arc_cc * arc_cc - newrad * newrad) / (2 * oldrad * arc_cc);
    if (a > 1.0 || a < -1.0)
        return interp_fail(in, INTERP_ERR_CCOMP, motion_col(in), "%s: this arc and the arc "
                           "of line %d make an inside corner the tool (radius %.4f %s) cannot "
                           "fit in without gouging", cc->name, prev->cmd.line, r, unit(in));
    double pull = acos(a), dir = atan2(c[1] - prev->center[1], c[0] - prev->center[0]);
    if (CC_INSIDE(cc->side, prev->turn) == (turn > 0))
        dir = dir + pull;
    else
        dir = dir - pull;
    *mx = prev->center[0] + oldrad * cos(dir);
    *my = prev->center[1] + oldrad * sin(dir);
    return 0;
}

/* A compensated arc after the entry move (LinuxCNC's convert_arc_comp2). */
static int arc_next(struct interp *in, int move, int turn, const double e[2], const double c[2],
                    double z, const double end6[6])
{
    struct ccomp *cc = &in->cc;
    double op0 = cc->prog[0], op1 = cc->prog[1], cx = cc->cur[0], cy = cc->cur[1];
    double r = cc->radius, ar = hypot(c[0] - e[0], c[1] - e[1]), gamma, mx = 0, my = 0;
    int left = cc->side == CCOMP_LEFT, inside = CC_INSIDE(cc->side, turn);
    double theta = atan2(cy - op1, cx - op0);
    theta = left ? (double)(theta - CC_PI_2L) : (double)(theta + CC_PI_2L);
    double delta = atan2(c[1] - op1, c[0] - op0);
    double alpha = move == 30 ? (double)(delta - CC_PI_2L) : (double)(delta + CC_PI_2L);
    double beta = left ? theta - alpha : alpha - theta;
    if (beta > 1.5 * CC_PI_L)  /* into -90 .. 270 degrees */
        beta = (double)(beta - 2 * CC_PI_L);
    else if (beta < -CC_PI_2L)
        beta = (double)(beta + 2 * CC_PI_L);
    if (inside) {
        gamma = atan2(c[1] - e[1], c[0] - e[0]);
        CHP(check_fits(in, ar));
    } else {
        gamma = atan2(e[1] - c[1], e[0] - c[0]);
        delta = (double)(delta + CC_PI_L);
    }
    double nx = e[0] + r * cos(gamma), ny = e[1] + r * sin(gamma);
    double sweep = ccomp_sweep(op0, op1, c[0], c[1], turn, e[0], e[1]);
    /* tangent arcs over the top of an "m" or an "h" make an inside corner too */
    if (beta < -CC_SMALL_RAD || beta > CC_PI_L + CC_SMALL_RAD ||
        (fabsl(beta - CC_PI_L) < CC_SMALL_RAD && !inside)) {
        if (cc->n == 0 || cc->q[0].move != 2)
            CHP(line_arc_corner(in, turn, c, ar, theta, beta, &mx, &my));
        else
            CHP(arc_arc_corner(in, turn, c, ar, &mx, &my));
        CHP(ccomp_move_endpoint_and_flush(in, mx, my));
    } else if (beta > CC_SMALL_RAD) {  /* outside corner: an arc around it first */
        mx = op0 + r * cos(delta);
        my = op1 + r * sin(delta);
        CHP(ccomp_dequeue(in));
        CHP(ccomp_push_arc(in, 0.0, mx, my, op0, op1, left ? -1 : 1, cc->cur[2], end6));
        CHP(ccomp_dequeue(in));
        ccomp_set_endpoint(in, mx, my);
    } else {                           /* tangent: on it goes */
        CHP(ccomp_dequeue(in));
        ccomp_set_endpoint(in, cx, cy);
    }
    CHP(ccomp_push_arc(in, sweep, nx, ny, c[0], c[1], turn, z, end6));
    cc->cur[0] = nx, cc->cur[1] = ny, cc->cur[2] = z;
    return 0;
}

int ccomp_arc(struct interp *in, int move, const double s[2], const double e[2],
              const double c[2], int turns, const double end6[6])
{
    struct ccomp *cc = &in->cc;
    double p[3];
    ccomp_prog_point(in, p);
    if (cc->first) {
        ccomp_take_position(in);
        CHP(arc_first(in, turns, e, c, s, p[2], end6));
    } else {
        CHP(arc_next(in, move, turns, e, c, p[2], end6));
    }
    cc->prog[0] = e[0], cc->prog[1] = e[1], cc->prog[2] = p[2];
    memcpy(in->pos, end6, sizeof in->pos);
    return 0;
}
