/* spline.c: G5.1, LinuxCNC's quadratic B-spline in the XY plane, as chords within a bound. */
#include <math.h>
#include <string.h>

#include "interp/interp_int.h"

#define W(c) (in->blk.col[(c) - 'a'])    /* column of word c, 0 if absent */
#define V(c) (in->blk.val[(c) - 'a'])    /* value of word c */

/* Largest distance of a chord from the curve, mm: the planner follows the chords exactly,
 * so the tool leaves the programmed spline by at most this (plus the planner's own bound). */
#define SPLINE_TOL_MM 1e-4
#define SPLINE_MAX_CHORDS 100000

/*
 * G5.1 X Y I J: from the present point P0 through the pull of the control point
 * P1 = P0 + (I, J) to P2 = (X, Y): B(t) = (1-t)^2 P0 + 2t(1-t) P1 + t^2 P2, t in [0, 1].
 * B'' = 2 (P0 - 2 P1 + P2) is the same everywhere, so a chord over dt leaves the curve by
 * exactly |P0 - 2 P1 + P2| dt^2 / 4 at its middle: n equal steps of t keep every chord
 * within SPLINE_TOL_MM. The chords are straight feeds of the block (spline = 1 on the
 * first, 2 on the rest: printers show rs274's one NURBS_FEED line); under G93 the block's
 * time is shared by length.
 */
int interp_spline(struct interp *in)
{
    const struct interp_block *b = &in->blk;
    if (in->plane != 17)
        return interp_fail(in, INTERP_ERR_MODAL, b->gcol[1] ? b->gcol[1] : 0, "G5.1: splines "
                           "must be in the XY plane (G17); G%d is in force", in->plane);
    if (!W('i') || !W('j'))
        return interp_fail(in, INTERP_ERR_WORD, W('i') ? W('i') : W('j'), "G5.1 needs both I "
                           "and J: the control point's offset from the start");
    static const char others[] = "zabc";
    for (int k = 0; k < 4; k++)
        if (W(others[k]))
            return interp_fail(in, INTERP_ERR_WORD, W(others[k]), "G5.1 may not move Z, A, B or "
                               "C: a quadratic spline lies in the XY plane");
    double end[6], p0[2] = { in->pos[0], in->pos[1] };
    interp_target(in, 0, end);
    double d[2] = { interp_len_mm(in, V('i')), interp_len_mm(in, V('j')) };
    if (in->rot_deg != 0.0)
        interp_rotate_xy(&d[0], &d[1], in->rot_deg);   /* I J turn with the system */
    double p1[2] = { p0[0] + d[0], p0[1] + d[1] };
    double q[2] = { p0[0] - 2 * p1[0] + end[0], p0[1] - 2 * p1[1] + end[1] };
    double n = ceil(sqrt(hypot(q[0], q[1]) / (4 * SPLINE_TOL_MM)));
    int pieces = n < 1 ? 1 : n > SPLINE_MAX_CHORDS ? SPLINE_MAX_CHORDS : (int)n;
    double total = 0, prev[2] = { p0[0], p0[1] };
    for (int k = 1; k <= pieces; k++) {     /* the curve's length along the chords */
        double t = (double)k / pieces, a = (1 - t) * (1 - t), m = 2 * t * (1 - t), c = t * t;
        double x = a * p0[0] + m * p1[0] + c * end[0], y = a * p0[1] + m * p1[1] + c * end[1];
        total += hypot(x - prev[0], y - prev[1]);
        prev[0] = x, prev[1] = y;
    }
    prev[0] = p0[0], prev[1] = p0[1];
    for (int k = 1; k <= pieces; k++) {
        double t = (double)k / pieces, a = (1 - t) * (1 - t), m = 2 * t * (1 - t), c = t * t;
        struct canon_cmd cmd;
        interp_cmd_init(in, &cmd, CANON_FEED);
        memcpy(cmd.end, in->pos, sizeof cmd.end);
        if (k < pieces) {
            cmd.end[0] = a * p0[0] + m * p1[0] + c * end[0];
            cmd.end[1] = a * p0[1] + m * p1[1] + c * end[1];
        } else {
            cmd.end[0] = end[0], cmd.end[1] = end[1];   /* the end exactly */
        }
        cmd.feed_mm_min = in->feed_mm_min;
        if (in->inverse_time)
            cmd.inverse_time_min = total > 0 ? hypot(cmd.end[0] - prev[0], cmd.end[1] - prev[1])
                                               / total / in->f_word : 1.0 / in->f_word / pieces;
        cmd.spline = k == 1 ? 1 : 2;
        prev[0] = cmd.end[0], prev[1] = cmd.end[1];
        memcpy(in->pos, cmd.end, sizeof in->pos);
        CHP(interp_emit(in, &cmd));
    }
    return 0;
}
