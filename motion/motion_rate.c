/* motion_rate.c: the plan's own clock under the feed override: where the plan is at a time,
 * and how fast the override's rate may change. */
#include <math.h>

#include "motion/motion_priv.h"

/*
 * The plan gives the path position s(tau) for the plan's own clock tau (override 1). Each
 * period tau advances by rate * dt: rate is the feed override in effect. Pausing or aborting
 * ramps rate to 0, so the machine slows down ON the planned path. The path acceleration is
 *     d2s/dt2 = rate^2 * a_plan(tau) + v_plan(tau) * d(rate)/dt,
 * so the rate may change only as fast as keeps that within the interval's acceleration
 * limit; above 1 it is also held under the plan's ceiling (speed caps of legs and machine).
 */

/* Plan position, speed and acceleration at tau within interval ci (the interval's phases
 * memoised in *mp: a pure function of its inputs, recomputed when they change). */
void motion_plan_at(const struct motion_plan *p, size_t ci, double tau, double *s, double *v,
                    double *a, struct motion_phase_memo *mp)
{
    double d = tau - p->kt[ci], ds = p->ks[ci + 1] - p->ks[ci];
    double v0 = p->kv[ci], v1 = p->kv[ci + 1], vp = p->ivp[ci], acc = p->iacc[ci];
    if (!(ds > 0) || !(p->kt[ci + 1] > p->kt[ci])) {
        *s = p->ks[ci];
        *v = v0;
        *a = 0;
        return;
    }
    motion_phase_memo_take(mp, v0, v1, vp, acc, ds);
    double ta = mp->ta, tc = mp->tc, td = mp->td;
    d = d < 0 ? 0 : d > ta + tc + td ? ta + tc + td : d;
    if (d < ta) {
        *v = v0 + acc * d, *a = acc;
        *s = v0 * d + 0.5 * acc * d * d;
    } else if (d < ta + tc) {
        *v = vp, *a = 0;
        *s = mp->sa + vp * (d - ta);
    } else {
        double e = d - ta - tc;
        *v = vp - acc * e, *a = -acc;
        *s = mp->sa + vp * tc + vp * e - 0.5 * acc * e * e;
    }
    *s = p->ks[ci] + (*s > ds ? ds : *s);
}

/* The override ceiling at tau in interval ci (>= 1). */
static double ceiling_at(const struct motion_plan *p, size_t ci, double tau)
{
    double dt = p->kt[ci + 1] - p->kt[ci];
    double f = dt > 0 ? (p->kt[ci + 1] - tau) / dt : 0;
    f = f < 0 ? 0 : f > 1 ? 1 : f;
    double r = p->krho[ci + 1] + (p->krho[ci] - p->krho[ci + 1]) * f;
    return fmin(r, p->irho[ci]);
}

/* The override ceiling at tau, which may lie past interval ci (a period ahead): the
 * ceiling is continuous along the plan's clock, so the rate that follows it a period ahead
 * changes no faster than it does. */
double motion_ceiling_ahead(const struct motion_plan *p, size_t ci, double tau)
{
    while (ci + 2 < p->nknot && tau > p->kt[ci + 1])
        ci++;
    return ceiling_at(p, ci, tau);
}

/* The phases of interval i that plan time [t0, t1] passes: each ramp's or cruise's path
 * acceleration (+-iacc or 0) into a[] (returns how many, at most 3). Joints and rests, where
 * the path does not move, have none. */
static int interval_phases(const struct motion_plan *p, size_t i, double t0, double t1,
                           double a[3])
{
    double ds = p->ks[i + 1] - p->ks[i], a0 = fmax(t0, p->kt[i]) - p->kt[i];
    double a1 = fmin(t1, p->kt[i + 1]) - p->kt[i], ta, tc, td;
    int n = 0;
    if (!(ds > 0) || !(p->kt[i + 1] > p->kt[i]) || a1 < a0)
        return 0;
    motion_phases(p->kv[i], p->kv[i + 1], p->ivp[i], p->iacc[i], ds, &ta, &tc, &td);
    if (ta > 0 && a0 <= ta)
        a[n++] = p->iacc[i];
    if (tc > 0 && a0 <= ta + tc && a1 >= ta)
        a[n++] = 0;
    if (td > 0 && a1 >= ta + tc)
        a[n++] = -p->iacc[i];
    return n;
}

/* The last interval plan time t1 reaches from interval ci on, within the current chunk of a
 * streamed program. */
static size_t interval_at(const struct motion_plan *p, size_t ci, double t1)
{
    size_t i = ci;
    while (i + 2 < p->nknot && p->kt[i + 1] < t1)
        i++;
    return i;
}

/* The rate within [lo, hi] nearest the target, at most the ceiling, at least 0. */
static double clamp_rate(double target, double lo, double hi, double ceiling)
{
    double rn = target < lo ? lo : target > hi ? hi : target;
    if (rn > ceiling)
        rn = ceiling;
    if (rn < 0)
        rn = 0;
    if (fabs(rn - target) < 1e-9)
        rn = target;
    return rn;
}

/* The positive root of a x^2 + K x = C (a > 0, K > 0): the rate at which the path
 * acceleration a x^2 + K (x - r) reaches its bound; C / K (<= 0) when there is none. */
static double rate_root(double a, double K, double C)
{
    return C > 0 ? 2 * C / (K + sqrt(K * K + 4 * a * C)) : C / K;
}

/* New rate after dt: toward the target, within the acceleration budget and the ceiling. The
 * path acceleration r^2 a_plan + v_plan dr/dt must stay within the limit all through the
 * period, not only at its start: for every phase of the plan the period passes (the plan
 * time advances by at most max(r, ceiling) dt) against its own interval's limit, with r
 * anywhere between the old rate and the new (r^2 a_plan is worst at the new rate where the
 * two pull apart: a quadratic), and v_plan as fast (or as slow) as it gets within the
 * period. Taken at the period's start alone, a ramp beginning within the period passed the
 * legs' limit by half for a period, and a rate moving fast on a slow plan (a move leaving
 * rest) by 4 % while it moved (bench_topp, under a changing override). */
double motion_next_rate(const struct motion *m, double target, double vp, double ceiling,
                        double dt)
{
    const struct motion_plan *p = m->run;
    double r = m->rate, t0 = m->tau_s, span = fmax(r, ceiling) * dt, a[3];
    double amin = 0, amax = 0, lo = -HUGE_VAL, hi = HUGE_VAL;
    size_t last = interval_at(p, m->ci, t0 + span);
    if (target > ceiling)
        target = ceiling;
    if (!(vp > 1e-9))
        return clamp_rate(target, 0, 2, ceiling);
    for (size_t i = m->ci; i <= last; i++)      /* how fast v_plan may change */
        for (int k = interval_phases(p, i, t0, t0 + span, a); k-- > 0;)
            amin = fmin(amin, a[k]), amax = fmax(amax, a[k]);
    double vhi = vp + amax * span, vlo = fmax(vp + amin * span, 1e-9);
    for (size_t i = m->ci; i <= last; i++)
        for (int k = interval_phases(p, i, t0, t0 + span, a); k-- > 0;) {
            double acc = p->iacc[i], c = acc - r * r * a[k];
            if (c < 0)         /* faster than the plan's ramp allows: the rate must fall */
                hi = fmin(hi, r + dt * c / vlo);
            else if (a[k] > 0) /* rising: r^2 a grows with it */
                hi = fmin(hi, rate_root(a[k], vhi / dt, acc + vhi * r / dt));
            else
                hi = fmin(hi, r + dt * c / vhi);
            c = -acc - r * r * a[k];
            if (c > 0)         /* above 1 on a braking plan: the rate must rise */
                lo = fmax(lo, r + dt * c / vlo);
            else if (a[k] > 0) /* falling on an accelerating plan: r^2 a shrinks with it */
                lo = fmax(lo, rate_root(a[k], vhi / dt, vhi * r / dt - acc));
            else
                lo = fmax(lo, r + dt * c / vhi);
        }
    if (lo == -HUGE_VAL)       /* no phase: the plan holds still (a joint, a rest) */
        lo = 0, hi = 2;
    return clamp_rate(target, lo, hi, ceiling);
}
