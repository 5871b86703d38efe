/* probe.c: G38.2..G38.5 straight probing: LinuxCNC's checks, the CANON_PROBE command, and
 * its answer (the machine's, the probe model's, or rs274's) in #5061..#5066, #5070 and the
 * position the program goes on from. */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

#include "interp/interp_int.h"

/* rs274's simulated back-off after a probe move: 0.01 inch (0.254 mm) towards the start. */
#define PROBE_RS274_BACKOFF_MM 0.254

void interp_set_probe_fn(struct interp *in, interp_probe_fn fn, void *ctx)
{
    in->probe_fn = fn;
    in->probe_ctx = ctx;
}

void interp_set_probe_model(struct interp *in, const struct probe_model *m)
{
    if (m)
        in->probe_model = *m;
    else
        memset(&in->probe_model, 0, sizeof in->probe_model);
}

/* "G38.2" for the probe type t (0..3). */
static const char *probe_name(int t)
{
    static const char *const names[] = { "G38.2", "G38.3", "G38.4", "G38.5" };
    return names[t & 3];
}

/* Without a workpiece, rs274's answer: no trip, the probe position is the end point, and
 * the machine stands 0.254 mm short of it (along X Y Z) towards the start. */
static void rs274_answer(const double from[6], const double end[6],
                         struct interp_probe_result *r)
{
    double d[3], len = 0;
    for (int i = 0; i < 3; i++) {
        d[i] = from[i] - end[i];
        len += d[i] * d[i];
    }
    len = sqrt(len);
    r->tripped = 0;
    memcpy(r->trip, end, sizeof r->trip);
    memcpy(r->stop, end, sizeof r->stop);
    for (int i = 0; i < 3 && len != 0; i++)
        r->stop[i] = end[i] + PROBE_RS274_BACKOFF_MM * (d[i] / len);
}

/* The probe model's answer: where along the move the contact changes as the type seeks
 * (towards: touches; away: leaves). The interpreter's model stops where it trips. With a
 * machine to ask (strict 0) it is only the plan's guess: the machine's answer counts. */
static int model_answer(struct interp *in, int type, int col, const double from[6],
                        const double end[6], bool strict, struct interp_probe_result *r)
{
    int away = (type & 2) != 0;
    bool already = probe_model_contact(&in->probe_model, from) != away;
    if (already && !(type & 1) && strict)
        return interp_fail(in, INTERP_ERR_PROBE, col, "%s: the probe %s where the move starts "
                           "(the probe model, [PROBE] in the INI)", probe_name(type), away
                           ? "is already clear of the workpiece" : "already touches the "
                           "workpiece");
    /* (s = 0 without `already`: on the surface, leaving it at once) */
    double s = already ? 0 : probe_model_find(&in->probe_model, from, end, !away);
    r->tripped = s >= 0;
    for (int i = 0; i < 6; i++)
        r->trip[i] = s >= 0 ? from[i] + s * (end[i] - from[i]) : end[i];
    memcpy(r->stop, r->trip, sizeof r->stop);
    return 0;
}

/* LinuxCNC's refusals, before anything is emitted. */
static int probe_checks(struct interp *in, int type, int col, const double from[6],
                        const double end[6])
{
    const char *name = probe_name(type);
    if (in->tcp_on)
        return interp_fail(in, INTERP_ERR_MODAL, col, "%s cannot be used under tool centre "
                           "point control (G43.4): cancel it with G49 first", name);
    if (in->cc.side != CCOMP_OFF)      /* LinuxCNC: "Cannot probe with cutter radius comp on" */
        return interp_fail(in, INTERP_ERR_MODAL, col, "%s cannot be used while cutter radius "
                           "compensation (%s) is on: G40 first", name, in->cc.name);
    CHP(interp_need_feed(in, name));     /* under G93: F in the block, the whole move's time */
    if (!(type & 1) && !memcmp(from, end, 6 * sizeof *from))
        return interp_fail(in, INTERP_ERR_WORD, col, "%s: the probe move has zero length: the "
                           "end point is where the probe already is", name);
    return 0;
}

/* G38.2..G38.5 (g x10) with the block's axis words: the probe move, then its answer. */
int interp_probe(struct interp *in, int g)
{
    int type = g - 382;
    int col = in->blk.g[1] >= 0 ? in->blk.gcol[1] : 0;
    const char *name = probe_name(type);
    double from[6], end[6];
    memcpy(from, in->pos, sizeof from);
    interp_target(in, 0, end);
    CHP(probe_checks(in, type, col, from, end));
    struct interp_probe_result r;
    if (in->probe_model.kind != PROBE_MODEL_NONE)
        CHP(model_answer(in, type, col, from, end, !in->probe_fn, &r));
    else
        rs274_answer(from, end, &r);
    struct canon_cmd c;
    interp_cmd_init(in, &c, CANON_PROBE);
    memcpy(c.end, end, sizeof c.end);
    memcpy(c.probe_stop, r.stop, sizeof c.probe_stop);
    c.feed_mm_min = in->feed_mm_min;
    if (in->inverse_time)                /* the whole move, to end, would take this long */
        c.inverse_time_min = 1.0 / in->f_word;
    c.ivalue = type;
    CHP(interp_emit(in, &c));
    /* a zero-length G38.3/G38.5 moves nothing: no machine to ask, no trip (as rs274) */
    if (in->probe_fn && memcmp(from, end, sizeof from)) {
        char why[256] = "";
        if (in->probe_fn(in->probe_ctx, &c, &r, why, sizeof why))
            return interp_fail(in, INTERP_ERR_PROBE, col, "%s: %s", name, why);
    }
    /* rs274 (no machine, no model) never trips and never complains */
    bool simulated = !in->probe_fn && in->probe_model.kind == PROBE_MODEL_NONE;
    if (!r.tripped && !(type & 1) && !simulated)
        return interp_fail(in, INTERP_ERR_PROBE, col, "%s: the move ended without the probe %s",
                           name, type & 2 ? "losing contact" : "touching anything");
    double prog[6];
    interp_machine_to_program(in, r.trip, prog);
    for (int i = 0; i < 6; i++)
        in->params[5061 + i] = prog[i];
    in->params[5070] = r.tripped;
    memcpy(in->pos, r.stop, sizeof in->pos);
    return 0;
}
