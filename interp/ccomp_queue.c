/* ccomp_queue.c: the G41/G42 queue: the move waiting for its corner, moved and sent on. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "interp/ccomp_priv.h"

void ccomp_name(char name[8], int g)
{
    if (g % 10)
        snprintf(name, 8, "G%d.%d", g / 10 % 100, g % 10);
    else
        snprintf(name, 8, "G%d", g / 10 % 100);
}

void ccomp_free(struct ccomp *cc)
{
    free(cc->q);
    memset(cc, 0, sizeof *cc);
}

void ccomp_reset(struct ccomp *cc)
{
    struct ccomp_item *q = cc->q;
    int cap = cc->cap;
    memset(cc, 0, sizeof *cc);
    cc->q = q;
    cc->cap = cap;
    cc->first = 1;
}

int ccomp_active(const struct interp *in)
{
    return in->cc.side != CCOMP_OFF && in->cc.radius > 0.0;
}

/* rs274 queues these behind a waiting move; the rest (settings, messages) go at once. */
int ccomp_holds(const struct interp *in, enum canon_type t)
{
    if (in->cc.n == 0)
        return 0;
    switch (t) {
    case CANON_FEED_RATE: case CANON_FEED_MODE: case CANON_DWELL: case CANON_SPINDLE_SPEED:
    case CANON_SPINDLE_ON: case CANON_SPINDLE_STOP: case CANON_COOLANT: case CANON_COMMENT:
        return 1;
    default:
        return 0;
    }
}

/* A free slot at the end of the queue, or NULL (out of memory, error recorded). */
static struct ccomp_item *push(struct interp *in)
{
    struct ccomp *cc = &in->cc;
    if (cc->n == cc->cap) {
        int cap = cc->cap ? 2 * cc->cap : 8;
        struct ccomp_item *q = realloc(cc->q, (size_t)cap * sizeof *q);
        if (!q) {
            interp_fail(in, INTERP_ERR_NOMEM, 0, "out of memory for the cutter compensation "
                        "queue");
            return NULL;
        }
        cc->q = q;
        cc->cap = cap;
    }
    struct ccomp_item *it = &cc->q[cc->n++];
    memset(it, 0, sizeof *it);
    return it;
}

int ccomp_hold(struct interp *in, const struct canon_cmd *c)
{
    struct ccomp_item *it = push(in);
    if (!it)
        return INTERP_ERR_NOMEM;
    it->cmd = *c;
    if (c->type == CANON_COMMENT && c->text) {
        snprintf(it->text, sizeof it->text, "%s", c->text);
        it->cmd.text = it->text;
    }
    return 0;
}

/* The plane's axes in LinuxCNC's order: (X, Y, Z) under G17, (Z, X, Y) under G18. */
void ccomp_axes(const struct interp *in, int ax[3])
{
    if (in->plane == 18) {
        ax[0] = AX_Z, ax[1] = AX_X, ax[2] = AX_Y;
    } else {
        ax[0] = AX_X, ax[1] = AX_Y, ax[2] = AX_Z;
    }
}

/* A program coordinate (program units, offsets removed) of axis i to the machine frame. */
double ccomp_machine(const struct interp *in, int i, double v)
{
    return interp_len_mm(in, v) + in->g5x[i] + in->g92[i] + in->tool[i];
}

/* Sets the plane end point (first, second) of a queued move's command. */
static void set_cmd_end(const struct interp *in, struct ccomp_item *it, double x, double y)
{
    int ax[3];
    ccomp_axes(in, ax);
    it->end[0] = x, it->end[1] = y;
    it->cmd.end[ax[0]] = ccomp_machine(in, ax[0], x);
    it->cmd.end[ax[1]] = ccomp_machine(in, ax[1], y);
}

/* Queues a straight move (traverse or feed) to (x, y, z) in plane order; the axes beyond the
 * plane (A B C) are taken from end6 (machine frame). dir: its programmed direction. */
int ccomp_push_line(struct interp *in, int move, double dx, double dy, double x, double y,
                    double z, const double end6[6])
{
    int ax[3];
    struct ccomp_item *it = push(in);
    if (!it)
        return INTERP_ERR_NOMEM;
    ccomp_axes(in, ax);
    interp_cmd_init(in, &it->cmd, move == 0 ? CANON_TRAVERSE : CANON_FEED);
    memcpy(it->cmd.end, end6, sizeof it->cmd.end);
    it->cmd.end[ax[2]] = ccomp_machine(in, ax[2], z);
    it->cmd.feed_mm_min = in->feed_mm_min;
    if (move != 0 && in->inverse_time)
        it->cmd.inverse_time_min = 1.0 / in->f_word;
    it->move = 1;
    it->dir[0] = dx, it->dir[1] = dy;
    set_cmd_end(in, it, x, y);
    return 0;
}

/* Queues an arc to (x, y, z) about centre (cx, cy) (plane order), `turn` turns. */
int ccomp_push_arc(struct interp *in, double sweep_rad, double x, double y, double cx, double cy,
                   int turn, double z, const double end6[6])
{
    int ax[3];
    struct ccomp_item *it = push(in);
    if (!it)
        return INTERP_ERR_NOMEM;
    ccomp_axes(in, ax);
    interp_cmd_init(in, &it->cmd, CANON_ARC);
    memcpy(it->cmd.end, end6, sizeof it->cmd.end);
    it->cmd.end[ax[2]] = ccomp_machine(in, ax[2], z);
    it->cmd.arc.center[ax[0]] = ccomp_machine(in, ax[0], cx);
    it->cmd.arc.center[ax[1]] = ccomp_machine(in, ax[1], cy);
    it->cmd.arc.center[ax[2]] = ccomp_machine(in, ax[2], in->cc.cur[2]);
    it->cmd.arc.normal[ax[2]] = 1.0;
    it->cmd.arc.rotation = turn;
    it->cmd.arc.plane = in->plane;
    it->cmd.feed_mm_min = in->feed_mm_min;
    if (in->inverse_time)
        it->cmd.inverse_time_min = 1.0 / in->f_word;
    it->move = 2;
    it->center[0] = cx, it->center[1] = cy;
    it->turn = turn;
    it->sweep_rad = sweep_rad;
    set_cmd_end(in, it, x, y);
    return 0;
}

/* The angle an arc sweeps from (x1, y1) to (x2, y2) about (cx, cy), signed as turn (LinuxCNC's
 * find_turn: |turn| - 1 whole turns more). */
double ccomp_sweep(double x1, double y1, double cx, double cy, int turn, double x2, double y2)
{
    if (turn == 0)
        return 0.0;
    double a = atan2(y1 - cy, x1 - cx), b = atan2(y2 - cy, x2 - cx);
    if (turn > 0) {
        if (b <= a)
            b = (double)(b + 2 * CC_PI_L);
        return (double)((b - a) + (turn - 1) * (2 * CC_PI_L));
    }
    if (a <= b)
        a = (double)(a + 2 * CC_PI_L);
    return (double)((b - a) + (turn + 1) * (2 * CC_PI_L));
}

/* Sends every queued command on, in order; the N column is the block's now (rs274's); under
 * G43.4 the moves carry the tool centre point state, as every command does. */
int ccomp_dequeue(struct interp *in)
{
    struct ccomp *cc = &in->cc;
    cc->endpoint_valid = 0;
    for (int i = 0; i < cc->n; i++) {
        struct canon_cmd c = cc->q[i].cmd;
        c.has_n = in->blk.n_present;
        c.n_number = in->blk.n_number;
        c.n_digits = in->blk.n_digits;
        if (interp_comp_sink(in, &c)) {  /* stamps the tool centre point state */
            cc->n = 0;
            return interp_fail(in, INTERP_ERR_SINK, 0, "the command consumer stopped the "
                               "program");
        }
        if (c.type == CANON_TRAVERSE || c.type == CANON_FEED || c.type == CANON_ARC) {
            memcpy(cc->sent_end, c.end, sizeof cc->sent_end);
            cc->sent_valid = 1;
        }
    }
    cc->n = 0;
    return 0;
}

void ccomp_set_endpoint(struct interp *in, double x, double y)
{
    in->cc.endpoint[0] = x, in->cc.endpoint[1] = y;
    in->cc.endpoint_valid = 1;
}

/* A queued arc ends at (x, y) now: it must keep its radius and not sweep further than it was
 * programmed to (else the tool went past the corner: a gouge). */
static int move_arc_end(struct interp *in, struct ccomp_item *it, double x, double y)
{
    struct ccomp *cc = &in->cc;
    double r1 = hypot(it->end[0] - it->center[0], it->end[1] - it->center[1]);
    double r2 = hypot(x - it->center[0], y - it->center[1]);
    double l2 = ccomp_sweep(cc->endpoint[0], cc->endpoint[1], it->center[0], it->center[1],
                            it->turn, x, y);
    if (fabs(r1 - r2) > .01)
        return interp_fail(in, INTERP_ERR_CCOMP, 0, "cutter compensation made an arc whose "
                           "radius changes from %.4f to %.4f (line %d): an interpreter fault",
                           r1, r2, it->cmd.line);
    if (it->sweep_rad != 0.0 && cc->endpoint_valid &&
        fabs(l2) > fabs(it->sweep_rad) + (in->inch ? .001 : .0254))
        return interp_fail(in, INTERP_ERR_CCOMP, 0, "%s: the arc of line %d ends in an inside "
                           "corner the tool cannot reach without gouging (tool radius %.4f %s)",
                           cc->name, it->cmd.line, cc->radius,
                           in->inch ? "in" : "mm");
    set_cmd_end(in, it, x, y);
    return 0;
}

/* The queued moves end at (x, y) instead (the corner is known now), then go to the sink. A
 * straight move that would then run backwards is a gouge. */
int ccomp_move_endpoint_and_flush(struct interp *in, double x, double y)
{
    struct ccomp *cc = &in->cc;
    if (cc->n == 0)
        return 0;
    for (int i = 0; i < cc->n; i++) {
        struct ccomp_item *it = &cc->q[i];
        if (it->move == 2) {
            CHP(move_arc_end(in, it, x, y));
        } else if (it->move == 1) {
            double dot = it->dir[0] * (x - cc->endpoint[0]) + it->dir[1] * (y - cc->endpoint[1]);
            if (cc->endpoint_valid && dot < 0)
                return interp_fail(in, INTERP_ERR_CCOMP, 0, "%s: the %s of line %d is too "
                                   "short for the inside corner after it: the tool (radius "
                                   "%.4f %s) would gouge", cc->name,
                                   it->cmd.type == CANON_TRAVERSE ? "rapid move" : "move",
                                   it->cmd.line, cc->radius, in->inch ? "in" : "mm");
            set_cmd_end(in, it, x, y);
        }
    }
    CHP(ccomp_dequeue(in));
    ccomp_set_endpoint(in, x, y);
    return 0;
}

int ccomp_flush(struct interp *in)
{
    CHP(ccomp_move_endpoint_and_flush(in, in->cc.cur[0], in->cc.cur[1]));
    return ccomp_dequeue(in);
}

void ccomp_scale(struct interp *in, double k)
{
    struct ccomp *cc = &in->cc;
    cc->radius *= k;
    for (int i = 0; i < 3; i++)
        cc->cur[i] *= k, cc->prog[i] *= k;
    cc->endpoint[0] *= k, cc->endpoint[1] *= k;
    for (int i = 0; i < cc->n; i++) {
        struct ccomp_item *it = &cc->q[i];
        it->end[0] *= k, it->end[1] *= k;
        it->center[0] *= k, it->center[1] *= k;
    }
}
