/* cycles.c: the drilling cycles G73 G81 G82 G83 G85 G89 in G17, with G98/G99, as LinuxCNC. */
#include <math.h>
#include <string.h>

#include "interp/interp_int.h"

#define W(c) (in->blk.col[(c) - 'a'])
#define V(c) (in->blk.val[(c) - 'a'])

#define PECK_CLEAR_MM 0.254      /* G83 rapid stop above the last depth, G73 chip-break lift */
#define PECK_CLEAR_IN 0.010
#define CYCLE_MAX_REPEATS 100000 /* L: more would only be a typing error */
#define CYCLE_MAX_PECKS 1000000  /* depth / Q, all repeats together */

/* One cycle in program units (X Y Z only), with the words it uses. */
struct cycle {
    int g;
    double x, y;                 /* hole position */
    double r;                    /* retract (R) plane */
    double bottom;               /* Z depth */
    double clear;                /* where the tool goes between holes: R (G99) or old Z (G98) */
    double q;                    /* peck depth */
    double p_s;                  /* dwell, seconds */
};

/* A move to program point (x, y, z), A B C unchanged. */
static int cyc_move(struct interp *in, enum canon_type t, double x, double y, double z)
{
    double p[3] = {x, y, z}, m[6];
    for (int i = 0; i < 3; i++)
        m[i] = interp_len_mm(in, p[i]) + in->g5x[i] + in->g92[i] + in->tool[i];
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
            CHP(cyc_move(in, CANON_FEED, c->x, c->y, d));
            if (c->g == 830) {
                CHP(cyc_move(in, CANON_TRAVERSE, c->x, c->y, c->r));
                CHP(cyc_move(in, CANON_TRAVERSE, c->x, c->y, d + lift));
            } else {
                CHP(cyc_move(in, CANON_TRAVERSE, c->x, c->y, d + lift));
            }
        }
        CHP(cyc_move(in, CANON_FEED, c->x, c->y, c->bottom));
        return cyc_move(in, CANON_TRAVERSE, c->x, c->y, c->clear);
    case 850:
        CHP(cyc_move(in, CANON_FEED, c->x, c->y, c->bottom));
        CHP(cyc_move(in, CANON_FEED, c->x, c->y, c->r));
        return cyc_move(in, CANON_TRAVERSE, c->x, c->y, c->clear);
    case 890:
        CHP(cyc_move(in, CANON_FEED, c->x, c->y, c->bottom));
        CHP(dwell(in, c->p_s));
        return cyc_move(in, CANON_FEED, c->x, c->y, c->clear);
    default: /* G81, G82 */
        CHP(cyc_move(in, CANON_FEED, c->x, c->y, c->bottom));
        if (c->g == 820)
            CHP(dwell(in, c->p_s));
        return cyc_move(in, CANON_TRAVERSE, c->x, c->y, c->clear);
    }
}

/* R, Z, P and Q are sticky while the same cycle repeats; the first block must give them. */
static int cycle_words(struct interp *in, int g, int first)
{
    static const struct { char w; const char *what; } need[] = {
        {'r', "R (retract plane)"}, {'z', "Z (hole depth)"}};
    for (int i = 0; i < 2; i++)
        if (first && !W(need[i].w))
            return interp_fail(in, INTERP_ERR_CYCLE, in->blk.gcol[1], "G%d needs %s in its first "
                               "block", g / 10, need[i].what);
    if (W('r'))
        in->cycle_r = V('r');
    if (W('z'))
        in->cycle_z = V('z');
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
                           "plane, %g) is below Z (hole bottom, %g)", c->r, c->bottom);
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

/* A drilling cycle block: LinuxCNC's CYCLE_MACRO, one hole per repeat. */
int interp_cycle(struct interp *in, int g)
{
    if (in->plane != 17)
        return interp_fail(in, INTERP_ERR_UNSUPPORTED, in->blk.gcol[1], "canned cycles in G%d "
                           "are not supported yet (only G17)", in->plane);
    if (W('a') || W('b') || W('c'))
        return interp_fail(in, INTERP_ERR_CYCLE, W('a') ? W('a') : W('b') ? W('b') : W('c'),
                           "A, B or C words in a canned cycle block");
    CHP(interp_need_feed(in, "a canned cycle"));
    int first = in->cycle_mode != g, reps = 1;
    CHP(cycle_words(in, g, first));
    if (W('l')) {
        CHP(interp_to_int(in, V('l'), W('l'), "L (repeats)", &reps));
        if (reps < 1 || reps > CYCLE_MAX_REPEATS)
            return interp_fail(in, INTERP_ERR_CYCLE, W('l'), "L (repeats) must be 1 to %d, not "
                               "%d", CYCLE_MAX_REPEATS, reps);
    }
    double cur[6], ai = 0, bi = 0;
    interp_prog_pos(in, cur);
    /* The Z a series of cycle blocks started from (LinuxCNC's "initial level"): G98 returns
     * there and G91 R counts from it, until a motion that is not a cycle ends the series. */
    if (!in->cycle_il_on) {
        in->cycle_il = cur[AX_Z];
        in->cycle_il_on = 1;
    }
    double old_z = in->cycle_il, cur_z = cur[AX_Z];
    struct cycle c = {.g = g, .q = in->cycle_q, .p_s = in->cycle_p};
    if (in->incremental) {
        ai = W('x') ? V('x') : 0;
        bi = W('y') ? V('y') : 0;
        c.x = cur[AX_X];
        c.y = cur[AX_Y];
        c.r = in->cycle_r + old_z;
        c.bottom = c.r + in->cycle_z;
    } else {
        c.x = W('x') ? V('x') : cur[AX_X];
        c.y = W('y') ? V('y') : cur[AX_Y];
        c.r = in->cycle_r;
        c.bottom = in->cycle_z;
    }
    /* cur comes back from machine coordinates: within rounding of R is at R */
    if (fabs(cur_z - c.r) <= 1e-9 * fmax(1.0, fabs(c.r)))
        cur_z = c.r;
    CHP(cycle_check(in, &c, reps));
    in->cycle_mode = g;
    if (old_z < c.r) { /* below R: straight up to it first */
        CHP(cyc_move(in, CANON_TRAVERSE, cur[AX_X], cur[AX_Y], c.r));
        old_z = cur_z = c.r;
    }
    c.clear = in->retract_old_z ? old_z : c.r;
    int restore = in->path_mode != 610;
    if (restore)
        CHP(path_mode(in, 610, 0.0));
    for (int i = 0; i < reps; i++) {
        c.x += ai;
        c.y += bi;
        double over = i == 0 && cur_z > c.r ? cur_z : c.clear; /* level of the rapid over */
        CHP(cyc_move(in, CANON_TRAVERSE, c.x, c.y, over));
        if (over > c.r)
            CHP(cyc_move(in, CANON_TRAVERSE, c.x, c.y, c.r));
        CHP(cycle_hole(in, &c));
    }
    if (restore)
        CHP(path_mode(in, in->path_mode, in->path_tol_mm));
    return 0;
}
