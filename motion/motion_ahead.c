/* motion_ahead.c: a check's executor evaluates the path eight periods ahead, four at a time. */
#include <stdbool.h>
#include <string.h>

#include "common/simd.h"
#include "common/sincos4.h"
#include "motion/motion_priv.h"

/*
 * motion_set_ahead(m, true) (the check's servo-rate pass, with rates off): where evaluate()
 * has no entry for the period, it computes the path's position, pose and legs of this period
 * and of the next seven (MOTION_AHEAD) as the plan's own pace would reach them (the clock
 * one period on each, the knots followed as follow_knots does), four at a time
 * (MOTION_LANES): the legs of four in one kins_inverse4 call, as the inverse kinematics of
 * four poses at once take under half the time of four single ones (bench_kins). Four periods
 * in one interval of the plan take their positions as vectors (plan_at4), four on one
 * segment their poses (seg_pose4), lane by lane the scalar functions' operations, where the
 * processor has AVX2 (common/simd.h; else the scalar functions, the same bits). Each entry
 * is keyed by what it is a function of, the plan run, its interval and segment, and the plan
 * clock; a period whose state has that key takes the entry, any other (an override, a
 * pause, a chunk switched, a stop) computes its own and seven more. Position, pose and legs
 * are pure functions of the key, so an entry is the very bits the period would compute
 * (test_ahead_same_bits): the look-ahead changes how much is computed at once, never what.
 * motion_step_calm (motion_step.c) fills it from the next period's key, before the clock
 * gets there (motion_ahead_next), and takes its entries as a run of periods. The machine's
 * own servo thread does not use it (a period there must not take eight periods' work).
 */

/* motion_seg_pose at the four places s[] of segment sg, on vectors: its operations in its
 * order, so the same bits; false (nothing written) when an arc's angle lies beyond the
 * series' range, where motion_seg_pose calls the C library. */
HEXCNC_AVX2
static bool seg_pose4(const struct motion_plan *p, const struct motion_seg *sg, const double *s,
                      double (*pose)[KINS_POSE_DIM])
{
    v4d sv = { s[0], s[1], s[2], s[3] }, q[KINS_POSE_DIM];
    v4d u = sg->len > 0 ? sv / sg->len : SPLAT(0.0);
    for (int i = 0; i < KINS_POSE_DIM; i++)
        q[i] = sg->start[i] + u * (sg->end[i] - sg->start[i]);
    if (sg->kind == SEG_ARC) {
        const struct motion_arc *a = &p->arcs[sg->arc];
        v4d ang = a->sweep_rad * u, r = a->r0_mm + a->dr_mm * u, h = a->h0_mm + a->dh_mm * u;
        v4d sn, c;
        v4l bad = { 0, 0, 0, 0 };
        SINCOS_LANES(ang, sn, c, bad);
        if (bad[0] | bad[1] | bad[2] | bad[3])
            return false;
        for (int i = 0; i < 3; i++)
            q[i] = a->center[i] + r * (c * a->e1[i] + sn * a->e2[i]) + h * a->n[i];
        if (a->abc_cubic) {            /* (abc_cubic's d = 0) */
            v4d u2 = u * u, u3 = u2 * u;
            v4d h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = 3 * u2 - 2 * u3;
            v4d h11 = u3 - u2;
            for (int k = 0; k < 3; k++)
                q[3 + k] = h00 * sg->start[3 + k] + h10 * a->abc_m0[k] +
                           h01 * sg->end[3 + k] + h11 * a->abc_m1[k];
        }
    }
    for (int l = 0; l < 4; l++)
        for (int i = 0; i < KINS_POSE_DIM; i++)
            pose[l][i] = q[i][l];
    return true;
}

/* motion_plan_at at the four plan times tau[] of interval ci (position into s[], speed
 * into v[]), on vectors: each lane's phase taken as motion_plan_at takes it, by the same
 * operations in the same order, so the same bits. */
HEXCNC_AVX2
static void plan_at4(const struct motion_plan *p, size_t ci, const double *tau, double *s,
                     double *v, struct motion_phase_memo *mp)
{
    double ds = p->ks[ci + 1] - p->ks[ci];
    double v0 = p->kv[ci], v1 = p->kv[ci + 1], vp = p->ivp[ci], acc = p->iacc[ci];
    if (!(ds > 0) || !(p->kt[ci + 1] > p->kt[ci])) {
        for (int l = 0; l < 4; l++)
            s[l] = p->ks[ci], v[l] = v0;
        return;
    }
    motion_phase_memo_take(mp, v0, v1, vp, acc, ds);
    double ta = mp->ta, tc = mp->tc, td = mp->td, sa = mp->sa;
    v4d d = (v4d){ tau[0], tau[1], tau[2], tau[3] } - p->kt[ci];
    v4d dc = SELECT(d > ta + tc + td, SPLAT(ta + tc + td), d);
    d = SELECT(d < 0, SPLAT(0.0), dc);
    v4l ramp_up = d < ta, cruise = d < ta + tc;
    v4d e = d - ta - tc;
    v4d vv = SELECT(ramp_up, v0 + acc * d, SELECT(cruise, SPLAT(vp), vp - acc * e));
    v4d sv = SELECT(ramp_up, v0 * d + 0.5 * acc * d * d,
                    SELECT(cruise, sa + vp * (d - ta),
                           sa + vp * tc + vp * e - 0.5 * acc * e * e));
    sv = p->ks[ci] + SELECT(sv > ds, SPLAT(ds), sv);
    for (int l = 0; l < 4; l++)
        s[l] = sv[l], v[l] = vv[l];
}

/* Entries g to g + n - 1 (n up to MOTION_LANES) of the look-ahead, their keys set: the
 * path's position, pose and legs. */
static void fill_lanes(struct motion *m, int g, int n, bool vec)
{
    struct motion_ahead *a = &m->ahead;
    const struct motion_plan *p = m->run;
    struct motion_ahead_at *at = &a->at[g];
    double (*pose)[KINS_POSE_DIM] = &a->pose[g];
    double sv[MOTION_LANES], vv[MOTION_LANES], tv[MOTION_LANES];
    if (vec && n == MOTION_LANES) {
        /* the four lanes on vectors, interval by interval (the entries are in order: the
         * lanes of an interval lie together, and most groups have one, some two) */
        for (int j = 0; j < n; j++)
            tv[j] = at[j].tau_s;
        for (int j0 = 0; j0 < n;) {
            int j1 = j0 + 1;
            while (j1 < n && at[j1].ci == at[j0].ci)
                j1++;
            plan_at4(p, at[j0].ci, tv, sv, vv, &m->phases);
            for (int j = j0; j < j1; j++)
                at[j].s = sv[j], at[j].vp = vv[j];
            j0 = j1;
        }
        for (int j = 0; j < n; j++)
            sv[j] = at[j].s;
    } else {
        for (int j = 0; j < n; j++) {
            struct motion_ahead_at *e = &at[j];
            double ap;
            motion_plan_at(p, e->ci, e->tau_s, &e->s, &e->vp, &ap, &m->phases);
            sv[j] = e->s;
        }
    }
    if (vec && n == MOTION_LANES) {
        /* segment by segment as the intervals (a segment whose arc lies beyond seg_pose4's
         * series: its lanes one by one) */
        double q[MOTION_LANES][KINS_POSE_DIM];
        for (int j0 = 0; j0 < n;) {
            int j1 = j0 + 1;
            while (j1 < n && at[j1].cs == at[j0].cs)
                j1++;
            const struct motion_seg *sg = &p->segs[at[j0].cs];
            if (j0 == 0 && j1 == n) {
                if (!seg_pose4(p, sg, sv, pose))
                    for (int j = 0; j < n; j++)
                        motion_seg_pose(p, sg, at[j].s, pose[j]);
            } else if (seg_pose4(p, sg, sv, q)) {
                for (int j = j0; j < j1; j++)
                    memcpy(pose[j], q[j], sizeof pose[j]);
            } else {
                for (int j = j0; j < j1; j++)
                    motion_seg_pose(p, sg, at[j].s, pose[j]);
            }
            j0 = j1;
        }
    } else {
        for (int j = 0; j < n; j++)
            motion_seg_pose(p, &p->segs[at[j].cs], at[j].s, pose[j]);
    }
    if (n == MOTION_LANES) {
        kins_inverse4(m->kins, (const double(*)[KINS_POSE_DIM])pose, &a->joints[g],
                      &a->status[g]);
        return;
    }
    double lanes[MOTION_LANES][KINS_POSE_DIM], joints[MOTION_LANES][KINS_MAX_JOINTS];
    int status[MOTION_LANES];
    for (int j = 0; j < MOTION_LANES; j++)    /* (lanes without a period: a pose the */
        memcpy(lanes[j], pose[j < n ? j : 0], sizeof lanes[j]);   /* kinematics can take) */
    kins_inverse4(m->kins, (const double(*)[KINS_POSE_DIM])lanes, joints, status);
    memcpy(&a->joints[g], joints, (size_t)n * sizeof joints[0]);
    memcpy(&a->status[g], status, (size_t)n * sizeof status[0]);
}

/* Fills the entries from plan time tau in interval ci of segment cs on: returns the first's
 * index (0), or -1 when that segment is one it leaves to evaluate() (synchronised, under
 * G43.4). */
static int fill(struct motion *m, double dt, size_t ci, size_t cs, double tau)
{
    struct motion_ahead *a = &m->ahead;
    const struct motion_plan *p = m->run;
    int n = 0;
    for (;;) {
        const struct motion_seg *sg = &p->segs[cs];
        if (sg->sync || sg->tcp)
            break;
        struct motion_ahead_at *e = &a->at[n];
        e->ci = ci, e->cs = cs, e->tau_s = tau;
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
        return -1;
    bool vec = hexcnc_avx2();          /* (else the scalar functions: common/simd.h) */
    for (int g = 0; g < n; g += MOTION_LANES)
        fill_lanes(m, g, n - g < MOTION_LANES ? n - g : MOTION_LANES, vec);
    a->run = p;
    a->fills++;
    return a->next++;
}

int motion_ahead(struct motion *m, double dt)
{
    struct motion_ahead *a = &m->ahead;
    if (a->next < a->n && a->run == m->run) {
        const struct motion_ahead_at *e = &a->at[a->next];
        if (e->ci == m->ci && e->cs == m->cs && e->tau_s == m->tau_s) {
            a->taken++;
            return a->next++;
        }
    }
    if (!motion_at_plan_pace(m)) {      /* (else eight periods' work would be done for one) */
        a->n = a->next = 0;
        return -1;
    }
    return fill(m, dt, m->ci, m->cs, m->tau_s);
}

int motion_ahead_next(struct motion *m, double dt)
{
    struct motion_ahead *a = &m->ahead;
    const struct motion_plan *p = m->run;
    size_t ci = m->ci, cs = m->cs;
    double tau = m->tau_s + dt;        /* advance() at the plan's pace */
    a->n = a->next = 0;
    if (!(tau < p->total_time_s))
        return 0;
    while (ci + 2 < p->nknot && tau >= p->kt[ci + 1]) {   /* follow_knots */
        ci++;
        while (ci >= p->segs[cs].k0 + p->segs[cs].nk)
            cs++;
    }
    if (fill(m, dt, ci, cs, tau) < 0)
        return 0;
    a->next = 0;                       /* (fill counts its first entry taken) */
    return a->n;
}

void motion_set_ahead(struct motion *m, bool on)
{
    if (!m)
        return;
    m->ahead_on = on;
    m->ahead.n = m->ahead.next = 0;
    m->ahead.run = NULL;
}
