/* sync.c: G33 (spindle-synchronised motion) and G33.1 (rigid tapping): LinuxCNC's checks
 * and the canonical moves; the machine makes the path follow the spindle (motion_sync.c). */
#include <math.h>
#include <string.h>

#include "interp/interp_int.h"

#define W(c) (in->blk.col[(c) - 'a'])    /* column of word c, 0 if absent */
#define V(c) (in->blk.val[(c) - 'a'])    /* value of word c */

/* LinuxCNC's refusals ("All axes missing with motion code", "K word missing with
 * g33/g33.1", "F word used with a g33/g33.1", "Spindle not turning in G33"), and those of
 * this machine, whose synchronised move is a straight line of the tool along X Y Z. */
static int sync_checks(struct interp *in, const char *name, int col, int axis)
{
    if (!axis)
        return interp_fail(in, INTERP_ERR_WORD, col, "%s needs axis words: the end of the "
                           "move", name);
    if (!W('k'))
        return interp_fail(in, INTERP_ERR_WORD, col, "%s needs a K word: the distance the "
                           "tool goes per spindle revolution (the thread's pitch)", name);
    if (!(V('k') > 0))
        return interp_fail(in, INTERP_ERR_WORD, W('k'), "%s K%g: the distance per revolution "
                           "must be more than 0", name, V('k'));
    if (W('i') && !(V('i') > 0))
        return interp_fail(in, INTERP_ERR_WORD, W('i'), "%s I%g: the spindle speed's multiple "
                           "for the way out must be more than 0", name, V('i'));
    if (W('f'))
        return interp_fail(in, INTERP_ERR_WORD, W('f'), "F word with %s: a synchronised move's "
                           "speed is the spindle's speed times K, not a feed", name);
    if (in->spindle_dir == 0)
        return interp_fail(in, INTERP_ERR_MODAL, col, "%s with the spindle not turning: start "
                           "it with M3 or M4 first", name);
    if (!(in->spindle_rpm > 0))
        return interp_fail(in, INTERP_ERR_WORD, col, "%s with spindle speed 0: give an S word "
                           "first", name);
    if (ccomp_active(in))    /* rs274 fails here too ("Bug code not g0 or g1") */
        return interp_fail(in, INTERP_ERR_MODAL, col, "%s cannot be used while cutter radius "
                           "compensation (%s) is on: G40 first", name, in->cc.name);
    if (in->tcp_on)
        return interp_fail(in, INTERP_ERR_MODAL, col, "%s cannot be used under tool centre "
                           "point control (G43.4): cancel it with G49 first", name);
    return 0;
}

/* The move's shape: X Y Z only (a rotation would turn the thread), and some length. */
static int sync_shape(struct interp *in, const char *name, int col, const double end[6])
{
    for (int i = 3; i < 6; i++)
        if (fabs(end[i] - in->pos[i]) > 1e-9)
            return interp_fail(in, INTERP_ERR_UNSUPPORTED, col, "%s turns the platform (%c "
                               "from %.4f to %.4f deg): a synchronised move here is a straight "
                               "line along X Y Z", name, "ABC"[i - 3], in->pos[i], end[i]);
    if (hypot(hypot(end[0] - in->pos[0], end[1] - in->pos[1]), end[2] - in->pos[2]) < 1e-9)
        return interp_fail(in, INTERP_ERR_WORD, col, "%s: the move has zero length: the end "
                           "is where the tool already is", name);
    return 0;
}

/* One synchronised canonical move from the current pose to end. */
static int sync_emit(struct interp *in, enum canon_sync kind, const double end[6])
{
    struct canon_cmd c;
    interp_cmd_init(in, &c, CANON_FEED);
    memcpy(c.end, end, sizeof c.end);
    c.sync = kind;
    c.pitch_word = V('k');
    c.pitch_mm_rev = in->inch ? V('k') * MM_PER_INCH : V('k');
    c.retract_factor = W('i') ? V('i') : 1.0;
    /* the speed the move has at the commanded spindle speed: what consumers that plan by
     * feed (previews, time estimates) take it to run at */
    c.feed_mm_min = c.pitch_mm_rev * in->spindle_rpm *
                    (kind == CANON_SYNC_TAP_OUT ? c.retract_factor : 1.0);
    memcpy(in->pos, end, sizeof in->pos);
    return interp_emit(in, &c);
}

int interp_sync_move(struct interp *in, int g, int axis)
{
    const char *name = g == 330 ? "G33" : "G33.1";
    int col = in->blk.g[1] >= 0 ? in->blk.gcol[1] : 0;
    if (!axis && in->blk.g[1] < 0 && !W('k') && !W('i'))
        return 0;               /* a block without G33's words: no move (modal G33) */
    CHP(sync_checks(in, name, col, axis));
    double start[6], end[6];
    memcpy(start, in->pos, sizeof start);
    interp_target(in, 0, end);
    CHP(sync_shape(in, name, col, end));
    if (g == 330)
        return sync_emit(in, CANON_SYNC_THREAD, end);
    /* G33.1: in, and back out to where it started (rs274 goes on from there too) */
    CHP(sync_emit(in, CANON_SYNC_TAP_IN, end));
    return sync_emit(in, CANON_SYNC_TAP_OUT, start);
}
