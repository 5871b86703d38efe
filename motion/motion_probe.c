/* motion_probe.c: G38 probe moves on the executor: watching the probe input, coming to rest
 * on the path where it changes, and the result the interpreter reads on with. */
#include <string.h>

#include "motion/motion_priv.h"

/*
 * A probe move is a straight feed segment with a stop before and after it (motion_path.c).
 * While the path is on it, each period the probe input is compared with what the move
 * seeks (G38.2/G38.3 contact: the input true; G38.4/G38.5 loss of contact: false):
 *
 *   watching --input as sought--> halting --rate 0--> parked (result published)
 *       |                           (the feed override's target is 0: the path decelerates
 *       |                            within its acceleration limits, as for a pause)
 *       +--end of the segment, no change--> done (result published, the path goes on)
 *
 * A streamed program is planned to a stop at the probe move's end (motion_stream_sync); once
 * parked, the executor waits for the next part, which the planner starts where it stopped.
 */

void motion_set_probe_input(struct motion *m, bool on)
{
    if (m) {
        m->probe_in = on;
        m->probe_wired = true;
    }
}

unsigned motion_probe_result(const struct motion *m, struct motion_probe_result *out)
{
    struct motion *w = (struct motion *)m;
    unsigned seq = atomic_load_explicit(&w->probe_seq, memory_order_acquire);
    if (out)
        *out = w->probe_res;
    return seq;
}

/* Makes the result visible to other threads (it is written before the counter moves). */
static void publish(struct motion *m)
{
    atomic_fetch_add_explicit(&m->probe_seq, 1, memory_order_release);
}

/* Where the probe is: the path pose commanded last period. */
static void take_pose(const struct motion *m, double pose[KINS_POSE_DIM])
{
    memcpy(pose, m->prog_pose, sizeof m->prog_pose);
}

bool motion_probe_watch_wired(struct motion *m)
{
    /* the stop before a probe move counts as its start: nothing moves before the input is
     * first looked at */
    size_t k = m->cs;
    const struct motion_plan *p = m->run;
    if (!p->segs[k].probe && p->segs[k].kind == SEG_DWELL && k + 1 < p->nseg &&
        p->segs[k + 1].probe)
        k++;
    const struct motion_seg *sg = &p->segs[k];
    if (!sg->probe)
        return false;
    bool sought = m->probe_in != ((sg->probe_type & 2) != 0);
    if (m->probe_seg != k + 1) {               /* the move begins, at rest */
        m->probe_seg = k + 1;
        m->probe_halt = PROBE_WATCHING;
        memset(&m->probe_res, 0, sizeof m->probe_res);
        if (sought && !(sg->probe_type & 1))
            m->probe_res.already = 1;           /* G38.2/G38.4: LinuxCNC refuses to start */
    } else if (m->probe_halt != PROBE_WATCHING) {
        return false;                           /* done without a trip: the path goes on */
    }
    if (!sought)
        return false;
    m->probe_res.tripped = !m->probe_res.already;
    take_pose(m, m->probe_res.trip);
    m->probe_halt = PROBE_HALTING;
    return true;
}

void motion_probe_arm_wired(struct motion *m)
{
    const struct motion_plan *p = m->run;
    const struct motion_seg *sg = &p->segs[m->cs];
    if (!sg->probe || m->probe_seg == m->cs + 1 || m->probe_halt != PROBE_WATCHING)
        return;
    /* the path came onto the move within this period, without a look at the input at its
     * start: look now, and if it is already as sought, back to the start (at rest there) */
    m->probe_seg = m->cs + 1;
    memset(&m->probe_res, 0, sizeof m->probe_res);
    if (m->probe_in == ((sg->probe_type & 2) != 0))
        return;
    m->probe_res.already = !(sg->probe_type & 1);
    m->probe_res.tripped = !m->probe_res.already;
    memcpy(m->probe_res.trip, sg->start, sizeof sg->start);
    m->ci = sg->k0;
    m->tau_s = p->kt[sg->k0];
    m->rate = 0;
    m->probe_halt = PROBE_HALTING;
}

void motion_probe_settle_move(struct motion *m)
{
    if (!m->run || m->probe_seg > m->run->nseg)
        return;
    const struct motion_seg *sg = &m->run->segs[m->probe_seg - 1];
    if (m->probe_halt == PROBE_HALTING && m->rate == 0 && motion_jerk_settled(m)) {
        take_pose(m, m->probe_res.stop);
        m->probe_halt = PROBE_PARKED;
        publish(m);
        return;
    }
    if (m->probe_halt != PROBE_WATCHING)
        return;
    bool past = m->cs + 1 > m->probe_seg ||
                m->tau_s >= m->run->kt[sg->k0 + sg->nk - 1] || m->state == MOTION_DONE;
    if (!past)
        return;
    memcpy(m->probe_res.trip, sg->end, sizeof sg->end);   /* the whole move, no trip */
    memcpy(m->probe_res.stop, sg->end, sizeof sg->end);
    m->probe_halt = PROBE_DONE;
    publish(m);
}

void motion_probe_reset(struct motion *m)
{
    m->probe_seg = 0;
    m->probe_halt = PROBE_WATCHING;
}
