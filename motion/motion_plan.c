/* motion_plan.c: the velocity profile over the knots of the whole program. */
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
 *          |    /                      \         speed accelerates, cruises (<= cap) and
 *          |   /                        \___     decelerates at acc, so v^2 changes at
 *          |  /                             \    most 2 acc ds from knot to knot:
 *          | /                               \      forward pass: v[i+1] <= sqrt(v[i]^2 + 2 a ds)
 *          |/                                 \     backward pass: v[i] <= sqrt(v[i+1]^2 + 2 a ds)
 *        0 +-------------------------------------> s
 *          start (v = 0)                 exact stop or blend junction
 *
 * The result is trapezoidal (triangular on short moves), slowed wherever a cap says so.
 */

/* The largest distance between neighbouring knots of sg (evenly spaced but where a chord's
 * reach of an arc ends, motion_chord.c). */
static double knot_spacing(const struct motion_plan *p, const struct motion_seg *sg)
{
    double h = 0;
    for (size_t k = sg->k0; k + 1 < sg->k0 + sg->nk; k++)
        h = motion_max2(h, p->ks[k + 1] - p->ks[k]);
    return h;
}

/* The chord cap of knot k at s of sg when a set-point chord touching an arc can reach it
 * (motion_chord.c), else HUGE_VAL; -1 when the pose is singular. */
static double chord_cap(struct motion *m, const struct motion_seg *sg, double s,
                        const struct motion_sample *S)
{
    double eps = 1e-9 * (1 + sg->len), k = 0, kabc = 0, tol = HUGE_VAL;
    for (int e = 0; e < 2; e++) {
        double from_end = e ? sg->len - s : s;
        if (sg->chord_mm[e] > 0 && from_end <= sg->chord_mm[e] + eps) {
            k = motion_max2(k, sg->chord_k[e]), kabc = motion_max2(kabc, sg->chord_kabc[e]);
            tol = motion_min2(tol, sg->chord_tol[e]);
        }
    }
    return k > 0 || kabc > 0 ? motion_chord_cap(m, sg, S, k, kabc, tol) : HUGE_VAL;
}

/* Caps of the knots of one segment: hard caps into kt, caps into kv, acceleration into iacc
 * (per knot here, per interval after passes()), chord caps near arcs into zcap; each knot's
 * leg gains |dL/ds| into gain. first/last receive the samples at the segment's ends (for the
 * joints between segments). */
static int segment_caps(struct motion *m, const struct motion_seg *sg, double *gain,
                        double *zcap, struct motion_sample *first, struct motion_sample *last,
                        char *err, size_t errlen)
{
    struct motion_plan *p = &m->plan;
    double hs = knot_spacing(p, sg);
    for (size_t i = 0; i < sg->nk; i++) {
        size_t k = sg->k0 + i;
        double hard = 0, cap = 0, acc = HUGE_VAL;
        zcap[k] = HUGE_VAL;
        if (motion_cancelled(m, sg->file, sg->line, err, errlen))
            return MOTION_ERR_CANCELLED;
        if (sg->kind <= SEG_ARC) {
            /* the end samples straight into first and last, not copied there (dense code
             * has two knots a move, both ends) */
            struct motion_sample mid, *S = i == 0 ? first : i + 1 == sg->nk ? last : &mid;
            int st = motion_knot_caps(m, sg, p->ks[k], hs, S, &hard, &cap, &acc, err, errlen);
            if (st)
                return st;
            zcap[k] = chord_cap(m, sg, p->ks[k], S);
            if (zcap[k] < 0) {
                snprintf(err, errlen, "%s:%d: the move passes through a singular pose of the "
                         "machine", sg->file ? sg->file : "program", sg->line);
                return MOTION_ERR_KINS;
            }
            if (zcap[k] < cap)
                p->info.limited_by_kin_tol++;
            for (int l = 0; l < m->nj; l++)
                gain[k * (size_t)m->nj + l] = fabs(S->dL[l]);
            if (sg->nk == 1)
                *last = *first;
        } else {
            memset(&gain[k * (size_t)m->nj], 0, (size_t)m->nj * sizeof *gain);
        }
        p->kt[k] = hard, p->kv[k] = cap, p->iacc[k] = motion_min2(acc, 1e30);
    }
    return MOTION_OK;
}

/* The chord caps of sg's knots (zcap) on its knots and on the intervals between two capped
 * knots. They come after a knot took its neighbours' caps: an interval from the last capped
 * knot out of the reach is not capped, so the speed may rise from there on. */
static void apply_chord_caps(struct motion_plan *p, const struct motion_seg *sg,
                             const double *zcap)
{
    size_t lk = sg->k0 + sg->nk - 1;
    for (size_t k = sg->k0; k <= lk; k++) {
        p->kv[k] = motion_min2(p->kv[k], zcap[k]);
        p->kt[k] = motion_min2(p->kt[k], zcap[k]);
        if (k < lk && zcap[k] < HUGE_VAL && zcap[k + 1] < HUGE_VAL) {
            double z = motion_min2(zcap[k], zcap[k + 1]);
            p->ivp[k] = motion_min2(p->ivp[k], z);
            p->irho[k] = motion_min2(p->irho[k], z);
        }
    }
}

/* Caps at every knot (see segment_caps); interval caps into ivp and irho (hard); a knot's
 * speed suits both neighbouring intervals; joints between segments get their speed. */
static int all_caps(struct motion *m, double *gain, double *zcap, char *err, size_t errlen)
{
    struct motion_plan *p = &m->plan;
    struct motion_sample ends[3], *prev_end = &ends[0], *first = &ends[1], *last = &ends[2];
    for (size_t j = 0; j < p->nseg; j++) {
        struct motion_seg *sg = &p->segs[j];
        int st = segment_caps(m, sg, gain, zcap, first, last, err, errlen);
        if (st)
            return st;
        size_t lk = sg->k0 + sg->nk - 1;
        for (size_t k = sg->k0; k < lk; k++) {
            p->ivp[k] = motion_min2(p->kv[k], p->kv[k + 1]);
            p->irho[k] = motion_min2(p->kt[k], p->kt[k + 1]);
        }
        p->ivp[lk] = p->irho[lk] = 0;
        for (size_t k = sg->k0; k <= lk; k++) {
            double c = k > sg->k0 ? p->ivp[k - 1] : p->ivp[k];
            double h = k > sg->k0 ? p->irho[k - 1] : p->irho[k];
            if (k < lk)
                c = motion_min2(c, p->ivp[k]), h = motion_min2(h, p->irho[k]);
            p->kv[k] = c, p->kt[k] = h;
        }
        apply_chord_caps(p, sg, zcap);
        double vin = j > 0 ? motion_junction_speed(m, &p->segs[j - 1], sg, prev_end, first) : 0;
        size_t pk = j > 0 ? p->segs[j - 1].k0 + p->segs[j - 1].nk - 1 : 0;
        /* a joint passed no faster than full acceleration reaches in STOP_EQUIV_PERIODS
         * servo periods (a sharp corner) is a stop in all but name, while the jump would
         * take a share of the moves' acceleration on both sides: stop there instead */
        if (vin > 0 && j > 0 && vin < STOP_EQUIV_PERIODS * m->cfg.servo_period_s *
                                      motion_min2(p->iacc[sg->k0], p->iacc[pk]))
            vin = 0;
        p->kv[sg->k0] = motion_min2(p->kv[sg->k0], vin);
        if (j > 0)
            p->kv[pk] = motion_min2(p->kv[pk], vin);
        if (vin > 0) {                 /* the jump's share of the acceleration, both sides,
                                        * at the fastest the joint may be passed (hard caps) */
            double vmax = motion_min2(vin, motion_min2(p->kt[sg->k0], p->kt[pk]));
            double share = motion_junction_share(m, prev_end, first, vmax);
            p->iacc[sg->k0] *= 1 - share;
            p->iacc[pk] *= 1 - share;
        }
        p->kv[lk] = j + 1 < p->nseg ? p->kv[lk] : 0;
        if (sg->kind <= SEG_ARC) {     /* (a dwell's neighbours never pass it blended) */
            struct motion_sample *t = prev_end;
            prev_end = last, last = t;
        }
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
        p->iacc[i] = i + 1 < p->segs[j].k0 + p->segs[j].nk
                         ? motion_min2(p->iacc[i], p->iacc[i + 1]) : 1e30;
    }
    /* a streamed window starts at k_enter at the speed the previous window left there;
     * the context knots before it are never followed and keep that speed */
    size_t k0 = p->k_enter < n ? p->k_enter : 0;
    double cap0 = p->kv[k0];
    for (size_t i = 0; i <= k0; i++)
        p->kv[i] = p->v_enter;
    p->kv[n - 1] = 0;
    j = 0;
    for (size_t i = k0; i + 1 < n; i++) {
        while (i >= p->segs[j].k0 + p->segs[j].nk) j++;
        double ds = interval_ds(p, i, &p->segs[j]);
        p->kv[i + 1] = motion_min2(p->kv[i + 1], sqrt(p->kv[i] * p->kv[i] + 2 * p->iacc[i] * ds));
    }
    j = p->nseg - 1;
    for (size_t i = n - 1; i-- > k0;) {
        while (i < p->segs[j].k0) j--;
        double ds = interval_ds(p, i, &p->segs[j]);
        p->kv[i] = motion_min2(p->kv[i], sqrt(p->kv[i + 1] * p->kv[i + 1] + 2 * p->iacc[i] * ds));
    }
    /* The previous window planned v_enter able to stop within its own tail, which this
     * window holds and extends under the same caps: the backward pass cannot ask for less
     * but by rounding. The entry keeps its speed; the shortfall is recorded. */
    p->enter_deficit = 0;
    if (p->v_enter > 0 && motion_min2(cap0, p->kv[k0]) < p->v_enter) {
        p->enter_deficit = (p->v_enter - motion_min2(cap0, p->kv[k0])) / p->v_enter;
        p->kv[k0] = p->v_enter;
    }
}

/* Whether drives with this set-point period need direction-changing stops held: a stop that
 * falls between two set points lets the drive's chord across it cut the corner by up to
 * a T^2 / 8 (a: the path acceleration into and out of the stop). Held unless that fits, for
 * both position and orientation, in the tenth of the tolerances the bound keeps in hand. */
static int stops_need_rest(const struct motion_config *c)
{
    double T = c->setpoint_period_s > 0 ? c->setpoint_period_s : c->servo_period_s;
    if (c->kin_tol_mm <= 0)
        return 0;                      /* the kinematic-error bound is off */
    return c->max_lin_acc_mm_s2 * T * T / 8 > (1 - KIN_TOL_SHARE) * c->kin_tol_mm ||
           (c->kin_tol_deg > 0 &&
            c->max_ang_acc_deg_s2 * T * T / 8 > (1 - KIN_TOL_SHARE) * c->kin_tol_deg);
}

/* Unit direction of the pose's motion (mm and deg together) at s of a move. */
static void pose_direction(const struct motion_plan *p, const struct motion_seg *sg, double s,
                           double u[KINS_POSE_DIM])
{
    double n = 0;
    motion_seg_tangent(p, sg, s, u);
    for (int i = 0; i < KINS_POSE_DIM; i++)
        n += u[i] * u[i];
    n = sqrt(n);
    for (int i = 0; i < KINS_POSE_DIM; i++)
        u[i] = n > 0 ? u[i] / n : 0;
}

/* Rest to add where move j stops (s), less the dwells already there, when the next move
 * leaves in another direction: one set-point period, so that the drive has a set point on
 * the corner whatever its phase; and with jerk limits the moving average's window, so that
 * the average comes to rest on the corner (motion_jerk.c). 0 before a pause or a wait (the
 * machine waits there until the average has settled), at the program's end and where the
 * path goes on straight. */
static double stop_rest_s(const struct motion *m, size_t j)
{
    const struct motion_plan *p = &m->plan;
    const struct motion_config *c = &m->cfg;
    double T = (stops_need_rest(c) ? c->setpoint_period_s > 0 ? c->setpoint_period_s
                                                               : c->servo_period_s : 0) +
               motion_jerk_window_s(c);
    double rested = 0, u0[KINS_POSE_DIM], u1[KINS_POSE_DIM], du = 0;
    size_t k = j + 1;
    for (; k < p->nseg && p->segs[k].kind > SEG_ARC; k++) {
        if (p->segs[k].kind == SEG_PAUSE || p->segs[k].kind == SEG_WAIT)
            return 0;
        rested += p->segs[k].dwell_s;
    }
    if (k >= p->nseg || rested >= T)
        return 0;
    pose_direction(p, &p->segs[j], p->segs[j].len, u0);
    pose_direction(p, &p->segs[k], 0, u1);
    for (int i = 0; i < KINS_POSE_DIM; i++)
        du = motion_max2(du, fabs(u1[i] - u0[i]));
    return du > 1e-9 ? T - rested : 0;
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
            double peak = sqrt(motion_max2(0, (2 * a * ds + v0 * v0 + v1 * v1) / 2));
            double vp = motion_max2(motion_max2(v0, v1), motion_min2(p->ivp[i], peak)), ta, tc, td;
            p->ivp[i] = vp;
            motion_phases(v0, v1, vp, a, ds, &ta, &tc, &td);
            dt = ta + tc + td;
            if (vp > 0)
                rho = motion_min2(rho, p->irho[i] / vp);
            if (ta > 1e-12 || td > 1e-12)
                rho = 1;                 /* a ramp already uses the whole acceleration */
        } else {
            p->ivp[i] = v0;
            if (sg->kind == SEG_DWELL && i == sg->k0)
                dt = sg->dwell_s;
            else if (sg->kind <= SEG_ARC && v0 == 0 && i + 1 == sg->k0 + sg->nk)
                dt = stop_rest_s(m, j);  /* a stop between moves: held (motion_step.c) */
            if (sg->sync && i + 1 == sg->k0 + sg->nk)
                dt += motion_sync_extra_s(m, p, j);  /* (the executor's clock skips it) */
            p->info.stops_held += dt > 0 && sg->kind <= SEG_ARC;
        }
        p->irho[i] = motion_max2(rho, 1.0);
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
        p->krho[i] = motion_min2(p->irho[i], p->krho[i + 1] + credit);
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
            v = motion_max2(v, p->ivp[k - 1]);
        if (k + 1 < p->nknot)
            v = motion_max2(v, p->ivp[k]);
        for (int l = 0; l < m->nj; l++)
            p->info.max_leg_vel_mm_s[l] = motion_max2(p->info.max_leg_vel_mm_s[l],
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
    double *zcap = malloc(p->nknot * sizeof *zcap);
    if (!gain || !zcap) {
        free(gain);
        free(zcap);
        snprintf(err, errlen, "out of memory planning the program");
        return MOTION_ERR_NOMEM;
    }
    int st = all_caps(m, gain, zcap, err, errlen);
    if (!st) {
        passes(m);
        leg_rate_report(m, gain);
        p->info.time_s = p->total_time_s;
        p->info.length_mm = p->total_len_mm;
        p->info.segments = p->nseg;
    }
    free(gain);
    free(zcap);
    return st;
}
