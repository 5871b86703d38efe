/* motion_ahead.c: a check's executor evaluates the path four periods at a time. */
#include <string.h>

#include "motion/motion_priv.h"

/*
 * motion_set_ahead(m, true) (the check's servo-rate pass, with rates off): where evaluate()
 * has no entry for the period, it computes the path's position, pose and legs of this period
 * and of the next three as the plan's own pace would reach them (the clock one period on
 * each, the knots followed as follow_knots does), the legs of all four in one
 * kins_inverse4 call: the inverse kinematics of four poses at once take under half the time
 * of four single ones (bench_kins). Each entry is keyed by what it is a function of, the
 * plan run, its interval and segment, and the plan clock; a period whose state has that key
 * takes the entry, any other (an override, a pause, a chunk switched, a stop) computes its
 * own and four more. Position, pose and legs are pure functions of the key, so an entry is
 * the very bits the period would compute (test_ahead_same_bits): the look-ahead changes
 * how much is computed at once, never what. The machine's own servo thread does not use it
 * (a period there must not take four periods' work).
 */

/* Fills the entries from the present state on: returns the first, or NULL when the present
 * segment is one it leaves to evaluate() (synchronised, under G43.4). */
static const struct motion_ahead_at *fill(struct motion *m, double dt)
{
    struct motion_ahead *a = &m->ahead;
    const struct motion_plan *p = m->run;
    size_t ci = m->ci, cs = m->cs;
    double tau = m->tau_s;
    int n = 0;
    for (;;) {
        const struct motion_seg *sg = &p->segs[cs];
        if (sg->sync || sg->tcp)
            break;
        struct motion_ahead_at *e = &a->at[n];
        double ap;
        e->ci = ci, e->cs = cs, e->tau_s = tau;
        motion_plan_at(p, ci, tau, &e->s, &e->vp, &ap, &m->phases);
        motion_seg_pose(p, sg, e->s, a->pose[n]);
        if (++n == MOTION_AHEAD)
            break;
        tau += dt;                     /* advance() at the plan's pace */
        if (tau >= p->total_time_s)
            break;
        while (ci + 2 < p->nknot && tau >= p->kt[ci + 1]) {   /* follow_knots */
            ci++;
            while (ci >= p->segs[cs].k0 + p->segs[cs].nk)
                cs++;
        }
    }
    a->n = n;
    a->next = 0;
    if (n == 0)
        return NULL;
    for (int j = n; j < MOTION_AHEAD; j++)      /* (lanes without a period: a pose the */
        memcpy(a->pose[j], a->pose[0], sizeof a->pose[j]);   /* kinematics can take) */
    a->run = p;
    a->fills++;
    kins_inverse4(m->kins, (const double(*)[KINS_POSE_DIM])a->pose, a->joints, a->status);
    return &a->at[a->next++];
}

const struct motion_ahead_at *motion_ahead(struct motion *m, double dt)
{
    struct motion_ahead *a = &m->ahead;
    if (a->next < a->n && a->run == m->run) {
        const struct motion_ahead_at *e = &a->at[a->next];
        if (e->ci == m->ci && e->cs == m->cs && e->tau_s == m->tau_s) {
            a->next++;
            a->taken++;
            return e;
        }
    }
    /* the next periods are foreseen at the plan's own pace only (anywhere else the clock
     * follows the override's ramp, and four periods' work would be done for one) */
    if (m->state != MOTION_RUNNING || m->rate != 1 || m->override_cmd != 1 ||
        m->rapid_cmd != 1 || m->waiting || m->probe_halt == PROBE_HALTING ||
        m->probe_halt == PROBE_PARKED) {
        a->n = a->next = 0;
        return NULL;
    }
    return fill(m, dt);
}

void motion_set_ahead(struct motion *m, bool on)
{
    if (!m)
        return;
    m->ahead_on = on;
    m->ahead.n = m->ahead.next = 0;
    m->ahead.run = NULL;
}
