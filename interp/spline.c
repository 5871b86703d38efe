/* spline.c: G5 (cubic) and G5.1 (quadratic), LinuxCNC's Bezier splines in the XY plane, as
 * chords within a bound; the chords of a G5.2/G5.3 NURBS (nurbs.c) go out the same way. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "interp/interp_int.h"

#define W(c) (in->blk.col[(c) - 'a'])    /* column of word c, 0 if absent */
#define V(c) (in->blk.val[(c) - 'a'])    /* value of word c */

/*
 * Emits the chords pts[1..n] (machine X Y, mm; pts[0] is the present point) as straight
 * feeds of the block: spline = 1 on the first, with ivalue = the control points rs274
 * counts in its one NURBS_FEED line (printers show that line), 2 on the rest. Under G93
 * the block's time is shared by length. Z A B C stay.
 */
int interp_spline_emit(struct interp *in, const double (*pts)[2], int n, int ncp)
{
    double total = 0;
    for (int k = 1; k <= n; k++)     /* the curve's length along the chords */
        total += hypot(pts[k][0] - pts[k - 1][0], pts[k][1] - pts[k - 1][1]);
    if (!isfinite(total))
        return interp_fail(in, INTERP_ERR_WORD, in->blk.g[1] >= 0 ? in->blk.gcol[1]
                           : in->blk.g[0] >= 0 ? in->blk.gcol[0] : 0, "the curve's points are "
                           "out of range (its length overflows)");
    for (int k = 1; k <= n; k++) {
        struct canon_cmd cmd;
        interp_cmd_init(in, &cmd, CANON_FEED);
        memcpy(cmd.end, in->pos, sizeof cmd.end);
        cmd.end[0] = pts[k][0];
        cmd.end[1] = pts[k][1];
        cmd.feed_mm_min = in->feed_mm_min;
        if (in->inverse_time)
            cmd.inverse_time_min = total > 0 ? hypot(pts[k][0] - pts[k - 1][0],
                                                     pts[k][1] - pts[k - 1][1])
                                               / total / in->f_word : 1.0 / in->f_word / n;
        cmd.spline = k == 1 ? 1 : 2;
        cmd.ivalue = k == 1 ? ncp : 0;
        memcpy(in->pos, cmd.end, sizeof in->pos);
        CHP(interp_emit(in, &cmd));
    }
    return 0;
}

/*
 * A Bezier curve of degree 2 or 3 through control points p[0..deg] (machine X Y, mm) as n
 * chords over equal steps of its parameter t. A chord over dt leaves a curve by at most
 * dt^2 / 8 max|B''|, and |B''| <= deg (deg - 1) max_i |p[i] - 2 p[i+1] + p[i+2]| (B'' is a
 * weighted mean of those second differences): n = sqrt(deg (deg - 1) M / (8 tol)) keeps
 * every chord within SPLINE_TOL_MM. For a quadratic B'' is constant and the bound exact.
 */
static int bezier(struct interp *in, const double p[4][2], int deg)
{
    double m = 0;
    for (int i = 0; i + 2 <= deg; i++)
        m = fmax(m, hypot(p[i][0] - 2 * p[i + 1][0] + p[i + 2][0],
                          p[i][1] - 2 * p[i + 1][1] + p[i + 2][1]));
    double n = ceil(sqrt((deg == 2 ? 1.0 : 3.0) * m / (4 * SPLINE_TOL_MM)));
    int pieces = !(n >= 1) ? 1 : n > SPLINE_MAX_CHORDS ? SPLINE_MAX_CHORDS : (int)n;
    double (*pts)[2] = malloc((size_t)(pieces + 1) * sizeof *pts);
    if (!pts)
        return interp_fail(in, INTERP_ERR_NOMEM, 0, "out of memory");
    pts[0][0] = p[0][0], pts[0][1] = p[0][1];
    for (int k = 1; k < pieces; k++) {
        double t = (double)k / pieces, s = 1 - t;
        for (int i = 0; i < 2; i++)
            pts[k][i] = deg == 2 ? s * s * p[0][i] + 2 * t * s * p[1][i] + t * t * p[2][i]
                                 : s * s * s * p[0][i] + 3 * t * s * s * p[1][i] +
                                   3 * t * t * s * p[2][i] + t * t * t * p[3][i];
    }
    pts[pieces][0] = p[deg][0], pts[pieces][1] = p[deg][1];   /* the end exactly */
    int rc = interp_spline_emit(in, (const double (*)[2])pts, pieces, deg + 1);
    free(pts);
    return rc;
}

/* LinuxCNC's rules for both: the XY plane, no Z A B C. */
static int spline_check(struct interp *in, const char *name)
{
    const struct interp_block *b = &in->blk;
    if (in->plane != 17)
        return interp_fail(in, INTERP_ERR_MODAL, b->g[1] >= 0 ? b->gcol[1] : 0, "%s: splines "
                           "must be in the XY plane (G17); G%d is in force", name, in->plane);
    static const char others[] = "zabc";
    for (int k = 0; k < 4; k++)
        if (W(others[k]))
            return interp_fail(in, INTERP_ERR_WORD, W(others[k]), "%s may not move Z, A, B or "
                               "C: a spline lies in the XY plane", name);
    return 0;
}

/* An offset (program units) from a machine X Y point, turned with the coordinate system. */
static void offset_point(const struct interp *in, const double from[2], double di, double dj,
                         double out[2])
{
    double d[2] = { interp_len_mm(in, di), interp_len_mm(in, dj) };
    if (in->rot_deg != 0.0)
        interp_rotate_xy(&d[0], &d[1], in->rot_deg);   /* I J turn with the system */
    out[0] = from[0] + d[0];
    out[1] = from[1] + d[1];
}

/*
 * G5.1 X Y I J: from the present point P0 through the pull of the control point
 * P1 = P0 + (I, J) to P2 = (X, Y): B(t) = (1-t)^2 P0 + 2t(1-t) P1 + t^2 P2, t in [0, 1].
 */
int interp_spline(struct interp *in)
{
    CHP(spline_check(in, "G5.1"));
    if (!W('i') || !W('j'))
        return interp_fail(in, INTERP_ERR_WORD, W('i') ? W('i') : W('j'), "G5.1 needs both I "
                           "and J: the control point's offset from the start");
    double end[6], p[4][2] = { { in->pos[0], in->pos[1] } };
    interp_target(in, 0, end);
    offset_point(in, p[0], V('i'), V('j'), p[1]);
    p[2][0] = end[0], p[2][1] = end[1];
    return bezier(in, (const double (*)[2])p, 2);
}

/*
 * G5 X Y I J P Q: LinuxCNC's cubic, from the present point P0 to P3 = (X, Y), leaving towards
 * P1 = P0 + (I, J) and arriving from P2 = P3 + (P, Q). Without I J (both or neither) it leaves
 * along the direction the previous G5 arrived in: I J = -P -Q of that block (LinuxCNC keeps
 * them from block to block; 0 0 before the first G5). P and Q are needed.
 */
int interp_spline_cubic(struct interp *in)
{
    CHP(spline_check(in, "G5"));
    if (!W('i') != !W('j'))
        return interp_fail(in, INTERP_ERR_WORD, W('i') ? W('i') : W('j'), "G5 needs both I and "
                           "J (the start's pull), or neither (to go on from the last G5)");
    if (!W('p') || !W('q'))
        return interp_fail(in, INTERP_ERR_WORD, W('p') ? W('p') : W('q') ? W('q') :
                           in->blk.gcol[1], "G5 needs both P and Q: the end's pull, from the "
                           "end point");
    double end[6], p[4][2] = { { in->pos[0], in->pos[1] } };
    interp_target(in, 0, end);
    double i = W('i') ? V('i') : in->g5_ij[0], j = W('j') ? V('j') : in->g5_ij[1];
    offset_point(in, p[0], i, j, p[1]);
    p[3][0] = end[0], p[3][1] = end[1];
    offset_point(in, p[3], V('p'), V('q'), p[2]);
    in->g5_ij[0] = -V('p');
    in->g5_ij[1] = -V('q');
    return bezier(in, (const double (*)[2])p, 3);
}
