/* cycles.c: the drilling cycles G73 G81 G82 G83 G85 G89 in G17, G18 and G19, with G98/G99,
 * as LinuxCNC. */
#include <math.h>
#include <string.h>

#include "interp/interp_int.h"

#define W(c) (in->blk.col[(c) - 'a'])
#define V(c) (in->blk.val[(c) - 'a'])

#define PECK_CLEAR_MM 0.254      /* G83 rapid stop above the last depth, G73 chip-break lift */
#define PECK_CLEAR_IN 0.010
#define CYCLE_MAX_REPEATS 100000 /* L: more would only be a typing error */
#define CYCLE_MAX_PECKS 1000000  /* depth / Q, all repeats together */

/* The axes of a plane's cycles, as LinuxCNC maps them: two in the plane (the hole position)
 * and the drilling axis along which R, the depth, the pecks and the retract are measured. */
struct cycle_axes {
    int u, v, w;                 /* AX_X/Y/Z: first and second in the plane, drilling axis */
};

/* G17 drills along Z, G18 along Y (holes in Z X), G19 along X (holes in Y Z). */
static struct cycle_axes plane_axes(int plane)
{
    if (plane == 18)
        return (struct cycle_axes){AX_Z, AX_X, AX_Y};
    if (plane == 19)
        return (struct cycle_axes){AX_Y, AX_Z, AX_X};
    return (struct cycle_axes){AX_X, AX_Y, AX_Z};
}

/* One cycle in program units, in the plane's axes, with the words it uses. */
struct cycle {
    int g;
    struct cycle_axes ax;
    double x, y;                 /* hole position on the plane's axes u, v */
    double r;                    /* retract (R) plane, on the drilling axis */
    double bottom;               /* hole depth on the drilling axis */
    double clear;                /* where the tool goes between holes: R (G99) or old level (G98) */
    double q;                    /* peck depth */
    double p_s;                  /* dwell, seconds */
};

/* A move to (x, y) in the plane at level z on the drilling axis, A B C unchanged. */
static int cyc_move(struct interp *in, const struct cycle *c, enum canon_type t, double x,
                    double y, double z)
{
    double p[3], m[6];
    p[c->ax.u] = x;
    p[c->ax.v] = y;
    p[c->ax.w] = z;
    for (int i = 0; i < 3; i++)
        m[i] = interp_len_mm(in, p[i]) + in->g5x[i] + in->g92[i] + in->tool[i];
    if (in->rot_deg != 0.0)
        interp_xy_to_machine(in, p[AX_X], p[AX_Y], m);
    for (int i = 3; i < 6; i++)
        m[i] = in->pos[i];
    return interp_straight(in, t, m);
}

/* A dwell of s seconds inside a cycle. */
static int dwell(struct interp *in, double s)
{
    struct canon_cmd c;
    interp_cmd_init(in, &c, CANON_DWELL);
    c.value = s;
    return interp_emit(in, &c);
}

/* The moves of one hole, from above it at the R plane. */
static int cycle_hole(struct interp *in, const struct cycle *c)
{
    double lift = in->inch ? PECK_CLEAR_IN : PECK_CLEAR_MM;
    switch (c->g) {
    case 830:
    case 730:
        for (double d = c->r - c->q; d > c->bottom; d -= c->q) {
            CHP(cyc_move(in, c, CANON_FEED, c->x, c->y, d));
            if (c->g == 830) {
                CHP(cyc_move(in, c, CANON_TRAVERSE, c->x, c->y, c->r));
                CHP(cyc_move(in, c, CANON_TRAVERSE, c->x, c->y, d + lift));
            } else {
                CHP(cyc_move(in, c, CANON_TRAVERSE, c->x, c->y, d + lift));
            }
        }
        CHP(cyc_move(in, c, CANON_FEED, c->x, c->y, c->bottom));
        return cyc_move(in, c, CANON_TRAVERSE, c->x, c->y, c->clear);
    case 850:
        CHP(cyc_move(in, c, CANON_FEED, c->x, c->y, c->bottom));
        CHP(cyc_move(in, c, CANON_FEED, c->x, c->y, c->r));
        return cyc_move(in, c, CANON_TRAVERSE, c->x, c->y, c->clear);
    case 890:
        CHP(cyc_move(in, c, CANON_FEED, c->x, c->y, c->bottom));
        CHP(dwell(in, c->p_s));
        return cyc_move(in, c, CANON_FEED, c->x, c->y, c->clear);
    default: /* G81, G82 */
        CHP(cyc_move(in, c, CANON_FEED, c->x, c->y, c->bottom));
        if (c->g == 820)
            CHP(dwell(in, c->p_s));
        return cyc_move(in, c, CANON_TRAVERSE, c->x, c->y, c->clear);
    }
}

/* R, the depth, P and Q are sticky while the same cycle repeats; the first block must give
 * them. The depth is the word of the drilling axis: Z in G17, Y in G18, X in G19. */
static int cycle_words(struct interp *in, int g, int first, char depth)
{
    if (first && !W('r'))
        return interp_fail(in, INTERP_ERR_CYCLE, in->blk.gcol[1], "G%d needs R (retract plane) "
                           "in its first block", g / 10);
    if (first && !W(depth))
        return interp_fail(in, INTERP_ERR_CYCLE, in->blk.gcol[1], "G%d needs %c (hole depth%s) "
                           "in its first block", g / 10, depth - 32,
                           in->plane == 18 ? ": G18 drills along Y"
                           : in->plane == 19 ? ": G19 drills along X" : "");
    if (W('r'))
        in->cycle_r = V('r');
    if (W(depth))
        in->cycle_depth = V(depth);
    if (g == 820 || g == 890) {
        if (W('p'))
            in->cycle_p = V('p');
        else if (first)
            return interp_fail(in, INTERP_ERR_CYCLE, in->blk.gcol[1], "G%d needs P (dwell "
                               "time, seconds)", g / 10);
        if (in->cycle_p < 0)
            return interp_fail(in, INTERP_ERR_CYCLE, W('p'), "negative dwell time P%g", in->cycle_p);
    }
    if (g == 730 || g == 830) {
        if (W('q'))
            in->cycle_q = V('q');
        else if (first)
            return interp_fail(in, INTERP_ERR_CYCLE, in->blk.gcol[1], "G%d needs Q (peck "
                               "depth)", g / 10);
        if (!(in->cycle_q > 0))
            return interp_fail(in, INTERP_ERR_CYCLE, W('q'), "G%d Q (peck depth) must be "
                               "positive, not %g", g / 10, in->cycle_q);
    }
    return 0;
}

/* R above the bottom, and a bounded number of pecks. */
static int cycle_check(struct interp *in, const struct cycle *c, int reps)
{
    if (c->r < c->bottom)
        return interp_fail(in, INTERP_ERR_CYCLE, W('r') ? W('r') : in->blk.gcol[1], "R (retract "
                           "plane, %g) is below %c (hole bottom, %g)", c->r,
                           'X' + c->ax.w, c->bottom);
    if ((c->g == 730 || c->g == 830) && (c->r - c->bottom) / c->q * reps > CYCLE_MAX_PECKS)
        return interp_fail(in, INTERP_ERR_CYCLE, W('q'), "Q (peck depth) %g is too small for "
                           "%d hole(s) %g deep (more than %d pecks)", c->q, reps,
                           c->r - c->bottom, CYCLE_MAX_PECKS);
    return 0;
}

/* Exact path during the cycle (its corners must be sharp), and back after it. */
static int path_mode(struct interp *in, int mode, double tol_mm)
{
    struct canon_cmd pm;
    interp_cmd_init(in, &pm, CANON_PATH_MODE);
    pm.ivalue = mode;
    pm.value = tol_mm;
    return interp_emit(in, &pm);
}

/* The hole position, R and depth of this block in the plane's axes: G90 takes the words
 * (an absent plane word keeps the current position), G91 steps from the current position
 * once per repeat with R counted from the series' start level and the depth from R. */
static void cycle_place(struct interp *in, struct cycle *c, const double cur[6], double step[2])
{
    static const char letter[3] = {'x', 'y', 'z'};
    char u = letter[c->ax.u], v = letter[c->ax.v];
    step[0] = step[1] = 0;
    if (in->incremental) {
        step[0] = W(u) ? V(u) : 0;
        step[1] = W(v) ? V(v) : 0;
        c->x = cur[c->ax.u];
        c->y = cur[c->ax.v];
        c->r = in->cycle_r + in->cycle_il;
        c->bottom = c->r + in->cycle_depth;
    } else {
        c->x = W(u) ? V(u) : cur[c->ax.u];
        c->y = W(v) ? V(v) : cur[c->ax.v];
        c->r = in->cycle_r;
        c->bottom = in->cycle_depth;
    }
}

/* A drilling cycle block: LinuxCNC's CYCLE_MACRO, one hole per repeat. */
int interp_cycle(struct interp *in, int g)
{
    if (W('a') || W('b') || W('c'))
        return interp_fail(in, INTERP_ERR_CYCLE, W('a') ? W('a') : W('b') ? W('b') : W('c'),
                           "A, B or C words in a canned cycle block");
    CHP(interp_need_feed(in, "a canned cycle"));
    struct cycle c = {.g = g, .ax = plane_axes(in->plane)};
    int first = in->cycle_mode != g, reps = 1;
    CHP(cycle_words(in, g, first, (char)('x' + c.ax.w)));
    if (W('l')) {
        CHP(interp_to_int(in, V('l'), W('l'), "L (repeats)", &reps));
        if (reps < 1 || reps > CYCLE_MAX_REPEATS)
            return interp_fail(in, INTERP_ERR_CYCLE, W('l'), "L (repeats) must be 1 to %d, not "
                               "%d", CYCLE_MAX_REPEATS, reps);
    }
    if (in->blk.polar_inc && !(c.ax.u == 0 && c.ax.v == 1))
        return interp_fail(in, INTERP_ERR_CYCLE, in->blk.col[26] ? in->blk.col[26]
                           : in->blk.col[27], "G91 polar coordinates (@ ^) in a canned cycle "
                           "need the XY plane (G17)");
    double cur[6], step[2];
    interp_prog_pos(in, cur);
    /* The level a series of cycle blocks started from on the drilling axis (LinuxCNC's
     * "initial level"): G98 returns there and G91 R counts from it, until a motion that is
     * not a cycle ends the series. */
    if (!in->cycle_il_on) {
        in->cycle_il = cur[c.ax.w];
        in->cycle_il_on = 1;
    }
    double old_z = in->cycle_il, cur_z = cur[c.ax.w];
    c.q = in->cycle_q;
    c.p_s = in->cycle_p;
    cycle_place(in, &c, cur, step);
    /* cur comes back from machine coordinates: within rounding of R is at R */
    if (fabs(cur_z - c.r) <= 1e-9 * fmax(1.0, fabs(c.r)))
        cur_z = c.r;
    CHP(cycle_check(in, &c, reps));
    in->cycle_mode = g;
    if (old_z < c.r) { /* below R: straight up to it first */
        CHP(cyc_move(in, &c, CANON_TRAVERSE, cur[c.ax.u], cur[c.ax.v], c.r));
        old_z = cur_z = c.r;
    }
    c.clear = in->retract_old_z ? old_z : c.r;
    int restore = in->path_mode != 610;
    if (restore)
        CHP(path_mode(in, 610, 0.0));
    for (int i = 0; i < reps; i++) {
        if (in->blk.polar_inc && c.ax.u == 0 && c.ax.v == 1) {
            interp_polar_step(in, &c.x, &c.y);  /* G91 polar: each repeat turns about */
        } else {                               /* the origin (LinuxCNC) */
            c.x += step[0];
            c.y += step[1];
        }
        double over = i == 0 && cur_z > c.r ? cur_z : c.clear; /* level of the rapid over */
        CHP(cyc_move(in, &c, CANON_TRAVERSE, c.x, c.y, over));
        if (over > c.r)
            CHP(cyc_move(in, &c, CANON_TRAVERSE, c.x, c.y, c.r));
        CHP(cycle_hole(in, &c));
    }
    if (restore)
        CHP(interp_emit_path_mode(in));
    return 0;
}
