/* motion_plan.c: samples every move through the kinematics and plans the velocity profile. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_priv.h"

/*
 * The profile is computed on knots (samples every <= 1 mm / 0.5 deg / 0.05 rad of arc):
 *
 *   speed  ^           cap(s) = min(feed, machine, legs, kinematic error)
 *          |      ____________________
 *          |     /                    \          each knot: v <= cap; between knots the
 *          |    /                      \         acceleration is constant and <= acc(s),
 *          |   /                        \___     so v^2 changes at most 2 acc ds:
 *          |  /                             \       forward pass: v[i+1] <= sqrt(v[i]^2 + 2 a ds)
 *          | /                               \      backward pass: v[i] <= sqrt(v[i+1]^2 + 2 a ds)
 *        0 +-------------------------------------> s
 *          start (v = 0)                 exact stop or blend junction
 *
 * The result is trapezoidal (triangular on short moves), slowed wherever a cap says so.
 */

#define FD_H 0.05              /* finite-difference step along the path, mm (deg) */
#define LEG_ACC_SPLIT 0.5      /* share of a leg's acceleration for the path acceleration term */
#define ARC_NORMAL_SHARE 0.5   /* share of the linear acceleration spent on centripetal */
#define JUMP_SHARE 0.5         /* share of a period's acceleration for a G64 corner's jump */
#define KIN_TOL_SHARE 0.9      /* the d^2 estimate is first order: keep 10 % in hand */

/* One path sample through the kinematics: pose, its s-derivative, legs and their
 * first and second s-derivatives. */
struct sample {
    double pose[KINS_POSE_DIM], dp[KINS_POSE_DIM];
    double L[KINS_MAX_JOINTS], dL[KINS_MAX_JOINTS], d2L[KINS_MAX_JOINTS];
};

/* Samples segment sg at s; returns the inverse kinematics status at s itself. */
static int sample_at(struct motion *m, const struct motion_seg *sg, double s, struct sample *o)
{
    double h = FD_H, pm[KINS_POSE_DIM], pp[KINS_POSE_DIM];
    double Lm[KINS_MAX_JOINTS], Lp[KINS_MAX_JOINTS];
    if (sg->kind == SEG_ARC)
        h = fmin(h, 0.01 * m->plan.arcs[sg->arc].r0_mm);
    motion_seg_pose(&m->plan, sg, s, o->pose);
    motion_seg_pose(&m->plan, sg, s - h, pm);
    motion_seg_pose(&m->plan, sg, s + h, pp);
    int st = kins_inverse(m->kins, o->pose, o->L);
    kins_inverse(m->kins, pm, Lm);     /* legs are written even when out of range */
    kins_inverse(m->kins, pp, Lp);
    for (int i = 0; i < KINS_POSE_DIM; i++)
        o->dp[i] = (pp[i] - pm[i]) / (2 * h);
    for (int i = 0; i < m->nj; i++) {
        o->dL[i] = (Lp[i] - Lm[i]) / (2 * h);
        o->d2L[i] = (Lp[i] - 2 * o->L[i] + Lm[i]) / (h * h);
    }
    return st;
}

/* Solves a x = b in place (b becomes x) for 6x6 a, partial pivoting; -1 when singular. */
int motion_solve6(double a[6][6], double b[6])
{
    for (int c = 0; c < 6; c++) {
        int p = c;
        for (int r = c + 1; r < 6; r++)
            if (fabs(a[r][c]) > fabs(a[p][c]))
                p = r;
        if (!(fabs(a[p][c]) > 1e-12))
            return -1;
        if (p != c) {
            for (int k = 0; k < 6; k++) {
                double t = a[c][k]; a[c][k] = a[p][k]; a[p][k] = t;
            }
            double t = b[c]; b[c] = b[p]; b[p] = t;
        }
        for (int r = c + 1; r < 6; r++) {
            double f = a[r][c] / a[c][c];
            for (int k = c; k < 6; k++)
                a[r][k] -= f * a[c][k];
            b[r] -= f * b[c];
        }
    }
    for (int c = 5; c >= 0; c--) {
        for (int k = c + 1; k < 6; k++)
            b[c] -= a[c][k] * b[k];
        b[c] /= a[c][c];
    }
    return 0;
}

/* The Jacobian dL/dpose (mm/mm, mm/deg) at S's pose by finite differences of the inverse,
 * or the cached one when S lies within 2 mm and 1 deg of where that was taken. */
static void jacobian_near(struct motion *m, const struct sample *S, double J[6][6])
{
    int near = m->jc_valid;
    for (int i = 0; i < 6 && near; i++)
        near = fabs(S->pose[i] - m->jc_pose[i]) <= (i < 3 ? 2.0 : 1.0);
    if (!near) {
        double L1[KINS_MAX_JOINTS], p1[KINS_POSE_DIM], d = 1e-4;
        for (int j = 0; j < 6; j++) {
            memcpy(p1, S->pose, sizeof p1);
            p1[j] += d;
            kins_inverse(m->kins, p1, L1);
            for (int i = 0; i < 6; i++)
                m->jc_J[i][j] = (L1[i] - S->L[i]) / d;
        }
        memcpy(m->jc_pose, S->pose, sizeof m->jc_pose);
        m->jc_valid = 1;
    }
    memcpy(J, m->jc_J, sizeof m->jc_J);
}

/* The kinematic-error speed cap at a sample (the paper's interpolator). Drives move legs
 * linearly between set points T apart, so over a chord of path length d the legs sit off the
 * leg-space curve by d2L d^2 / 8 at mid-chord; through the inverse Jacobian that is a pose
 * deviation q d^2 / 8 with J q = d2L. Its part across the path (the part along the path is
 * only a timing shift) must stay within KINEMATIC_TOLERANCE: d <= sqrt(8 tol / |q_perp|),
 * v <= d / T. Returns HUGE_VAL when no cap applies, -1 when J is singular. */
static double kin_tol_cap(struct motion *m, const struct motion_seg *sg, const struct sample *S)
{
    const struct motion_config *c = &m->cfg;
    if (c->kin_tol_mm <= 0 || m->nj != 6)
        return HUGE_VAL;
    double J[6][6], q[6];
    jacobian_near(m, S, J);
    for (int j = 0; j < 6; j++)
        q[j] = S->d2L[j];
    if (motion_solve6(J, q) < 0)
        return -1;
    double shift, w2 = 0;      /* shift: the along-path part of q, in s units */
    int base = sg->rotary ? 3 : 0;
    for (int i = base; i < base + 3; i++)
        w2 += S->dp[i] * S->dp[i];
    shift = 0;
    for (int i = base; i < base + 3; i++)
        shift += q[i] * S->dp[i];
    shift = w2 > 0 ? shift / w2 : 0;
    double perp2 = 0, ang = 0;
    for (int i = 0; i < 3; i++)
        perp2 += (q[i] - shift * S->dp[i]) * (q[i] - shift * S->dp[i]);
    for (int i = 3; i < 6; i++)
        ang = fmax(ang, fabs(q[i] - shift * S->dp[i]));
    double dmax = HUGE_VAL;
    if (perp2 > 1e-30)
        dmax = sqrt(8 * KIN_TOL_SHARE * c->kin_tol_mm / sqrt(perp2));
    if (ang > 1e-30 && c->kin_tol_deg > 0)
        dmax = fmin(dmax, sqrt(8 * KIN_TOL_SHARE * c->kin_tol_deg / ang));
    double T = c->setpoint_period_s > 0 ? c->setpoint_period_s : c->servo_period_s;
    return dmax / T;
}

/* Reports a leg out of range at a sample, naming file, line, leg, amount and pose. */
static int unreachable(struct motion *m, const struct motion_seg *sg, const struct sample *S,
                       int st, char *err, size_t errlen)
{
    const struct kins *k = m->kins;
    const char *f = sg->file ? sg->file : "program";
    const double *P = S->pose;
    for (int i = 0; i < m->nj; i++) {
        double over = S->L[i] - k->joint_max[i], under = k->joint_min[i] - S->L[i];
        if (over > 0 || under > 0) {
            snprintf(err, errlen, "%s:%d: the move leaves the machine's reach: leg %d "
                     "([JOINT_%d]) would be %.3f mm long, %.3f mm %s its %s of %.3f mm, at X%.3f "
                     "Y%.3f Z%.3f A%.3f B%.3f C%.3f", f, sg->line, i + 1, i, S->L[i], over > 0 ? over : under,
                     over > 0 ? "beyond" : "below", over > 0 ? "maximum" : "minimum",
                     over > 0 ? k->joint_max[i] : k->joint_min[i], P[0], P[1], P[2], P[3], P[4], P[5]);
            return MOTION_ERR_UNREACHABLE;
        }
    }
    snprintf(err, errlen, "%s:%d: the kinematics cannot follow the move (%s) at X%.3f Y%.3f "
             "Z%.3f A%.3f B%.3f C%.3f", f, sg->line, kins_strerror(st), P[0], P[1], P[2], P[3],
             P[4], P[5]);
    return st == KINS_ERR_UNREACHABLE || st == KINS_ERR_LEG_RANGE ? MOTION_ERR_UNREACHABLE
                                                                  : MOTION_ERR_KINS;
}

/* Speed caps of one knot: hard (machine, legs, kinematic error) into *hard, with the feed
 * into *cap, and the path acceleration limit into *acc. */
static int knot_caps(struct motion *m, const struct motion_seg *sg, double s, double hs,
                     struct sample *Sp, double *hard, double *cap, double *acc, char *err,
                     size_t errlen)
{
    const struct motion_config *c = &m->cfg;
    const struct kins *k = m->kins;
    struct sample S;
    int st = sample_at(m, sg, s, &S);
    *Sp = S;
    for (int i = 0; i < m->nj && st == KINS_OK; i++)  /* catches a leg peaking between knots */
        if (S.L[i] + fabs(S.d2L[i]) * hs * hs / 8 > k->joint_max[i] ||
            S.L[i] - fabs(S.d2L[i]) * hs * hs / 8 < k->joint_min[i])
            st = KINS_ERR_UNREACHABLE, S.L[i] += S.L[i] > 0.5 * (k->joint_max[i] + k->joint_min[i])
                                       ? fabs(S.d2L[i]) * hs * hs / 8 : -fabs(S.d2L[i]) * hs * hs / 8;
    if (st != KINS_OK)
        return unreachable(m, sg, &S, st, err, errlen);
    double vm = HUGE_VAL, am = HUGE_VAL, w = 0;
    if (!sg->rotary) {
        vm = c->max_lin_vel_mm_s;
        am = c->max_lin_acc_mm_s2;
    }
    for (int i = 3; i < 6; i++)
        w = fmax(w, fabs(S.dp[i]));
    if (w > 1e-12) {
        vm = fmin(vm, c->max_ang_vel_deg_s / w);
        am = fmin(am, c->max_ang_acc_deg_s2 / w);
    }
    if (sg->kind == SEG_ARC) {
        const struct motion_arc *a = &m->plan.arcs[sg->arc];
        double r = fmin(a->r0_mm, a->r0_mm + a->dr_mm);
        vm = fmin(vm, sqrt(ARC_NORMAL_SHARE * c->max_lin_acc_mm_s2 * r));
        am *= sqrt(1 - ARC_NORMAL_SHARE * ARC_NORMAL_SHARE);
    }
    double vl = HUGE_VAL;
    for (int i = 0; i < m->nj; i++) {
        double d1 = fabs(S.dL[i]) + fabs(S.d2L[i]) * hs, d2 = fabs(S.d2L[i]);
        if (d1 > 1e-12) {
            vl = fmin(vl, c->joint[i].max_vel_mm_s / d1);
            am = fmin(am, LEG_ACC_SPLIT * c->joint[i].max_acc_mm_s2 / d1);
        }
        if (d2 > 1e-12)
            vl = fmin(vl, sqrt((1 - LEG_ACC_SPLIT) * c->joint[i].max_acc_mm_s2 / (1.2 * d2)));
    }
    double vk = kin_tol_cap(m, sg, &S);
    if (vk < 0) {
        snprintf(err, errlen, "%s:%d: the move passes through a singular pose of the machine "
                 "at X%.3f Y%.3f Z%.3f A%.3f B%.3f C%.3f", sg->file ? sg->file : "program",
                 sg->line, S.pose[0], S.pose[1], S.pose[2], S.pose[3], S.pose[4], S.pose[5]);
        return MOTION_ERR_KINS;
    }
    double feed = sg->feed > 0 ? sg->feed : HUGE_VAL;
    double soft = fmin(feed, vm);
    if (vl < soft)
        m->plan.info.limited_by_legs++;
    if (vk < fmin(soft, vl))
        m->plan.info.limited_by_kin_tol++;
    *hard = fmin(fmin(vm, vl), vk);
    *cap = fmin(*hard, feed);
    *acc = am;
    return MOTION_OK;
}

/* The speed at which the joint from segment a into b may be passed (G64): the velocity
 * changes direction within one servo period there, so its jump may use JUMP_SHARE of one
 * period's acceleration on every axis (a quarter on every leg) while the moves on either
 * side give up that share of their path acceleration (all_caps); and the corner cut by the
 * set-point chord stays within the blend tolerance. 0 when the moves must stop between. */
static double junction_speed(struct motion *m, const struct motion_seg *a,
                             const struct motion_seg *b, const struct sample *Ap,
                             const struct sample *Bp)
{
    const struct motion_config *c = &m->cfg;
    if (a->blend_tol_mm <= 0 || a->rotary != b->rotary || a->kind > SEG_ARC || b->kind > SEG_ARC)
        return 0;
    const struct sample A = *Ap, B = *Bp;
    double T = c->servo_period_s, Ts = c->setpoint_period_s > 0 ? c->setpoint_period_s : T;
    double dx = 0, da = 0, v = HUGE_VAL;
    for (int i = 0; i < 3; i++)
        dx += (B.dp[i] - A.dp[i]) * (B.dp[i] - A.dp[i]);
    dx = sqrt(dx);
    for (int i = 3; i < 6; i++)
        da = fmax(da, fabs(B.dp[i] - A.dp[i]));
    if (dx > 1e-12) {
        v = fmin(v, JUMP_SHARE * c->max_lin_acc_mm_s2 * T / dx);
        v = fmin(v, 4 * a->blend_tol_mm / (Ts * dx));
    }
    if (da > 1e-12)
        v = fmin(v, JUMP_SHARE * c->max_ang_acc_deg_s2 * T / da);
    for (int i = 0; i < m->nj; i++) {
        double dl = fabs(B.dL[i] - A.dL[i]);
        if (dl > 1e-12)
            v = fmin(v, 0.5 * JUMP_SHARE * c->joint[i].max_acc_mm_s2 * T / dl);
    }
    return v;
}

/* Caps of the knots of one segment: hard caps into kt, caps into kv, acceleration into iacc
 * (per knot here, per interval after passes()); each knot's leg gains |dL/ds| into gain.
 * first/last receive the samples at the segment's ends (for the joints between segments). */
static int segment_caps(struct motion *m, const struct motion_seg *sg, double *gain,
                        struct sample *first, struct sample *last, char *err, size_t errlen)
{
    struct motion_plan *p = &m->plan;
    double hs = sg->len / (double)(sg->nk - 1);
    for (size_t i = 0; i < sg->nk; i++) {
        size_t k = sg->k0 + i;
        double hard = 0, cap = 0, acc = HUGE_VAL;
        if (sg->kind <= SEG_ARC) {
            struct sample S;
            int st = knot_caps(m, sg, p->ks[k], hs, &S, &hard, &cap, &acc, err, errlen);
            if (st)
                return st;
            for (int l = 0; l < m->nj; l++)
                gain[k * (size_t)m->nj + l] = fabs(S.dL[l]);
            if (i == 0)
                *first = S;
            if (i + 1 == sg->nk)
                *last = S;
        } else {
            memset(&gain[k * (size_t)m->nj], 0, (size_t)m->nj * sizeof *gain);
        }
        p->kt[k] = hard, p->kv[k] = cap, p->iacc[k] = fmin(acc, 1e30);
    }
    return MOTION_OK;
}

/* Caps at every knot (see segment_caps); interval caps into ivp and irho (hard); a knot's
 * speed suits both neighbouring intervals; joints between segments get their speed. */
static int all_caps(struct motion *m, double *gain, char *err, size_t errlen)
{
    struct motion_plan *p = &m->plan;
    struct sample prev_end, first, last;
    for (size_t j = 0; j < p->nseg; j++) {
        struct motion_seg *sg = &p->segs[j];
        int st = segment_caps(m, sg, gain, &first, &last, err, errlen);
        if (st)
            return st;
        size_t lk = sg->k0 + sg->nk - 1;
        for (size_t k = sg->k0; k < lk; k++) {
            p->ivp[k] = fmin(p->kv[k], p->kv[k + 1]);
            p->irho[k] = fmin(p->kt[k], p->kt[k + 1]);
        }
        p->ivp[lk] = p->irho[lk] = 0;
        for (size_t k = sg->k0; k <= lk; k++) {
            double c = k > sg->k0 ? p->ivp[k - 1] : p->ivp[k];
            double h = k > sg->k0 ? p->irho[k - 1] : p->irho[k];
            if (k < lk)
                c = fmin(c, p->ivp[k]), h = fmin(h, p->irho[k]);
            p->kv[k] = c, p->kt[k] = h;
        }
        double vin = j > 0 ? junction_speed(m, &p->segs[j - 1], sg, &prev_end, &first) : 0;
        size_t pk = j > 0 ? p->segs[j - 1].k0 + p->segs[j - 1].nk - 1 : 0;
        p->kv[sg->k0] = fmin(p->kv[sg->k0], vin);
        if (j > 0)
            p->kv[pk] = fmin(p->kv[pk], vin);
        if (vin > 0) {                 /* the jump's share of the acceleration, both sides */
            p->iacc[sg->k0] *= 1 - JUMP_SHARE;
            p->iacc[pk] *= 1 - JUMP_SHARE;
        }
        p->kv[lk] = j + 1 < p->nseg ? p->kv[lk] : 0;
        prev_end = last;
        p->info.samples += sg->nk;
    }
    return MOTION_OK;
}

/* Length of interval i (0 across a joint between segments). */
static double interval_ds(const struct motion_plan *p, size_t i, const struct motion_seg *sg)
{
    return i + 1 < sg->k0 + sg->nk && i >= sg->k0 ? p->ks[i + 1] - p->ks[i] : 0;
}

/* Forward and backward passes over the knots: the fastest speeds that every cap and the
 * acceleration allow, starting and ending at rest. */
static void speed_passes(struct motion_plan *p)
{
    size_t n = p->nknot, j = 0;
    for (size_t i = 0; i + 1 < n; i++) {              /* interval acceleration: both ends */
        while (i >= p->segs[j].k0 + p->segs[j].nk) j++;
        p->iacc[i] = i + 1 < p->segs[j].k0 + p->segs[j].nk ? fmin(p->iacc[i], p->iacc[i + 1])
                                                            : 1e30;
    }
    p->kv[0] = 0, p->kv[n - 1] = 0;
    j = 0;
    for (size_t i = 0; i + 1 < n; i++) {
        while (i >= p->segs[j].k0 + p->segs[j].nk) j++;
        double ds = interval_ds(p, i, &p->segs[j]);
        p->kv[i + 1] = fmin(p->kv[i + 1], sqrt(p->kv[i] * p->kv[i] + 2 * p->iacc[i] * ds));
    }
    j = p->nseg - 1;
    for (size_t i = n - 1; i-- > 0;) {
        while (i < p->segs[j].k0) j--;
        double ds = interval_ds(p, i, &p->segs[j]);
        p->kv[i] = fmin(p->kv[i], sqrt(p->kv[i + 1] * p->kv[i + 1] + 2 * p->iacc[i] * ds));
    }
}

/* Per interval: cruise speed, duration, override ceiling; then knot times and ceilings. */
static void passes(struct motion *m)
{
    struct motion_plan *p = &m->plan;
    size_t n = p->nknot, j = 0;
    speed_passes(p);
    double t = 0;
    p->kt[0] = 0;
    for (size_t i = 0; i + 1 < n; i++) {
        while (i >= p->segs[j].k0 + p->segs[j].nk) j++;
        const struct motion_seg *sg = &p->segs[j];
        double ds = interval_ds(p, i, sg), v0 = p->kv[i], v1 = p->kv[i + 1], a = p->iacc[i];
        double rho = 2, dt = 0;
        if (ds > 0) {
            double peak = sqrt(fmax(0, (2 * a * ds + v0 * v0 + v1 * v1) / 2));
            double vp = fmax(fmax(v0, v1), fmin(p->ivp[i], peak)), ta, tc, td;
            p->ivp[i] = vp;
            motion_phases(v0, v1, vp, a, ds, &ta, &tc, &td);
            dt = ta + tc + td;
            if (vp > 0)
                rho = fmin(rho, p->irho[i] / vp);
            if (ta > 1e-12 || td > 1e-12)
                rho = 1;                 /* a ramp already uses the whole acceleration */
        } else {
            p->ivp[i] = v0;
            if (sg->kind == SEG_DWELL && i == sg->k0)
                dt = sg->dwell_s;
        }
        p->irho[i] = fmax(rho, 1.0);
        t += dt;
        p->kt[i + 1] = t;
    }
    p->total_time_s = t;
    /* knot ceilings: the override must come down ahead of a lower ceiling; while cruising
     * it can fall by acc * t_cruise / (2 v) (the rate never exceeds 2) */
    p->krho[n - 1] = 1;
    j = p->nseg - 1;
    for (size_t i = n - 1; i-- > 0;) {
        while (i < p->segs[j].k0) j--;
        double ds = interval_ds(p, i, &p->segs[j]), credit = 0;
        if (ds > 0 && p->irho[i] > 1) {
            double ta, tc, td;
            motion_phases(p->kv[i], p->kv[i + 1], p->ivp[i], p->iacc[i], ds, &ta, &tc, &td);
            credit = p->iacc[i] * tc / (2 * p->ivp[i]);
        }
        p->krho[i] = fmin(p->irho[i], p->krho[i + 1] + credit);
    }
}

/* The largest planned leg rate per leg: |dL/ds| at the knots times the fastest speed of
 * the intervals on either side. */
static void leg_rate_report(struct motion *m, const double *gain)
{
    struct motion_plan *p = &m->plan;
    for (size_t k = 0; k < p->nknot; k++) {
        double v = p->kv[k];
        if (k > 0)
            v = fmax(v, p->ivp[k - 1]);
        if (k + 1 < p->nknot)
            v = fmax(v, p->ivp[k]);
        for (int l = 0; l < m->nj; l++)
            p->info.max_leg_vel_mm_s[l] = fmax(p->info.max_leg_vel_mm_s[l],
                                               gain[k * (size_t)m->nj + l] * v);
    }
}

/* Plans the speeds of the segments made by motion_path_build. */
int motion_plan_profile(struct motion *m, char *err, size_t errlen)
{
    struct motion_plan *p = &m->plan;
    memset(&p->info, 0, sizeof p->info);
    m->jc_valid = 0;
    if (p->nseg == 0) {
        p->total_time_s = 0;
        return MOTION_OK;
    }
    double *gain = malloc(p->nknot * (size_t)m->nj * sizeof *gain);
    if (!gain) {
        snprintf(err, errlen, "out of memory planning the program");
        return MOTION_ERR_NOMEM;
    }
    int st = all_caps(m, gain, err, errlen);
    if (!st) {
        passes(m);
        leg_rate_report(m, gain);
        p->info.time_s = p->total_time_s;
        p->info.length_mm = p->total_len_mm;
        p->info.segments = p->nseg;
    }
    free(gain);
    return st;
}
