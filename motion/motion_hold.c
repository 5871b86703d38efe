/* motion_hold.c: where the path holds at a segment's start: an M0/M1 pause, a wait for the
 * spindle to reach its speed, for a tool change or for an input (M66), and with jerk limits
 * the settling of the moving average before any of them. */
#include <stdatomic.h>

#include "motion/motion_priv.h"

/* Periods a spindle command must have been out before an at-speed report counts: one for
 * the spindle's drive to see it, one for its report to come back. */
#define MOTION_AT_SPEED_LAG 2

/* Whether every spindle or tool command before the present segment has been applied (the
 * commands are in path order: the next one not applied lies further on). */
static bool ios_reached(const struct motion *m)
{
    return m->ios_done == m->run->nios || m->run->ios[m->ios_done].at > m->cs;
}

/* An M66 wait at sg: whether it is answered (the answer in *v). It begins the first period
 * the path is there; a rise or fall must happen after that. */
static bool input_answered(struct motion *m, const struct motion_seg *sg, double *v)
{
    bool cur = m->din[sg->input];
    if (!m->in_waiting) {
        m->in_waiting = 1;
        m->in_since_s = m->elapsed_s;
        m->in_prev = cur;
    }
    bool prev = m->in_prev, done;
    m->in_prev = cur;
    *v = cur;
    switch (sg->input_mode) {
    case 1: done = !prev && cur; break;    /* rise */
    case 2: done = prev && !cur; break;    /* fall */
    case 3: done = cur; break;             /* high */
    case 4: done = !cur; break;            /* low */
    default:                               /* at once: the value now */
        done = true;
        if (sg->input_analog)
            *v = m->ain[sg->input];
        break;
    }
    if (!done && m->elapsed_s - m->in_since_s >= sg->timeout_s - 1e-9) {
        *v = -1;                           /* LinuxCNC's time-out answer */
        done = true;
    }
    return done;
}

/* Holds the path at the present knot (a segment's start) this period: 1. */
static int hold(struct motion *m)
{
    m->tau_s = m->run->kt[m->ci];
    m->rate = 0;
    return 1;
}

/* At the start of a wait segment sg: hold there until the spindle is at speed, the tool
 * changed or the input answered. */
static int wait_here(struct motion *m, const struct motion_seg *sg)
{
    m->waiting = 0;
    if (sg->kind != SEG_WAIT || m->ci != sg->k0 || m->waited_at_seg == m->cs + 1)
        return 0;
    if (sg->wait_input) {
        double v;
        if (ios_reached(m) && input_answered(m, sg, &v)) {
            m->in_waiting = 0;
            m->waited_at_seg = m->cs + 1;
            atomic_store_explicit(&m->input_result, v, memory_order_relaxed);
            atomic_fetch_add_explicit(&m->input_seq, 1, memory_order_release);
            return 0;
        }
        m->waiting = 3;
        return hold(m);
    }
    /* the report counts once the spindle has had the command for MOTION_AT_SPEED_LAG
     * periods: an at-speed that was true for the old speed says nothing of the new */
    bool done = sg->wait_tool ? m->tool_done_seq == m->tool.seq
                              : m->at_speed && m->io_age >= MOTION_AT_SPEED_LAG;
    if (done && ios_reached(m)) {
        m->waited_at_seg = m->cs + 1;
        return 0;
    }
    m->waiting = sg->wait_tool ? 2 : 1;
    return hold(m);
}

/* At the start of a pause or a wait not yet honoured, with jerk limits: held there until the
 * moving average has come to rest on it (motion_jerk.c), so that the machine stands still
 * when the pause or the wait begins. */
static int settle_here(struct motion *m, const struct motion_seg *sg)
{
    bool stop = (sg->kind == SEG_PAUSE && m->paused_at_seg != m->cs + 1) ||
                (sg->kind == SEG_WAIT && m->waited_at_seg != m->cs + 1 && !m->waiting);
    if (!stop || m->ci != sg->k0 || motion_jerk_settled(m))
        return 0;
    return hold(m);
}

/* See motion_priv.h. */
int motion_pause_or_wait_here(struct motion *m, const struct motion_seg *sg)
{
    if (settle_here(m, sg) || wait_here(m, sg))
        return 1;
    if (sg->kind != SEG_PAUSE || m->ci != sg->k0 || m->paused_at_seg == m->cs + 1)
        return 0;
    m->paused_at_seg = m->cs + 1;
    if (m->state == MOTION_RUNNING || m->state == MOTION_PAUSING)
        m->state = MOTION_PAUSED;
    return hold(m);
}
