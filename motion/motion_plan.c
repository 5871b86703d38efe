/* motion_plan.c: the velocity profile over the knots of the whole program. */
#include <math.h>
#include <sched.h>
#include <stdint.h>
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

/* A knot's path acceleration limit as a function of the speed v: at least a0 - b v^2 up to
 * the knot's hard cap (motion_knot_caps: the chord from rest to the hard cap under the legs'
 * limit; b = 0 where the limit does not depend on the speed). Every pass takes the
 * acceleration at the fastest the interval is passed, not at the hard cap: a ramp out of a
 * stop on a leg-bound arc had the acceleration the legs leave at the cap, 0.72 of what they
 * allow at rest, and the arcs took 1.062x the time-optimal time (bench_topp_blend). The
 * override cannot raise the speed on a ramp (passes(); acc_line_of's pad, and
 * keep_hard_after_fast for the ramps it may enter above 1), so the acceleration holds at every
 * speed the executor reaches there. */
struct acc_line { double a0, b; };

#define ACC_PAD_E 0.05      /* see acc_line_of */

/* The line under the chord through the knot's limit at rest (a0) and at its hard cap vh (a),
 * for a ramp's speeds; flat where the two agree, where vh bounds nothing, and on
 * spindle-synchronised moves (the spindle sets their speed, and motion_sync.c takes their
 * iacc as the limit up to the checked speed). The override holds the rate at 1 on a ramp
 * (passes()), but in the period before a cruise whose ceiling lets it rise (the executor
 * follows the ceiling a period ahead, motion_step.c), where the speed may pass the plan's
 * by (1 + r^2) a T (T the servo period), at most d = 4 a0 T: so the line is the chord's
 * value d faster, a0 - b (v + d)^2, which is at least a0 - b d^2 (1 + 1/e) - b (1 + e) v^2
 * for any e > 0 (ACC_PAD_E). Where it falls below a, a holds (up to vh, passes()). */
static struct acc_line acc_line_of(double a, double a0, double vh, int sync, double T)
{
    if (sync || !(a0 > a) || !(vh > 0) || !(vh < HUGE_VAL) || !(a0 < 1e30))
        return (struct acc_line){ a, 0 };
    double b = (a0 - a) / (vh * vh), d = 4 * a0 * T;
    return (struct acc_line){ a0 - b * d * d * (1 + 1 / ACC_PAD_E), b * (1 + ACC_PAD_E) };
}

/* The largest x = v^2 with x <= w + c a(v), a the smaller of knot k's and k + 1's lines:
 * w + c a falls as x grows, so the fixed point is the smaller of the two lines' own. With
 * c = 2 ds it is the speed at the end of a ramp of length ds from sqrt(w); with c = ds and
 * w the mean of the ends' squares, the interval's peak. */
static double ramp_sq(const struct acc_line *ln, size_t k, double w, double c)
{
    return fmin((w + c * ln[k].a0) / (1 + c * ln[k].b),
                (w + c * ln[k + 1].a0) / (1 + c * ln[k + 1].b));
}

/* The acceleration the lines of knots k and k + 1 allow at speed v. */
static double line_acc(const struct acc_line *ln, size_t k, double v)
{
    return fmin(ln[k].a0 - ln[k].b * v * v, ln[k + 1].a0 - ln[k + 1].b * v * v);
}

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
 * (per knot here, per interval after passes()) and its line into ln, chord caps near arcs
 * into zcap; each knot's leg gains |dL/ds| into gain. first/last receive the samples at the
 * segment's ends (for the joints between segments). */
static int segment_caps(struct motion *m, const struct motion_seg *sg, double *gain,
                        double *zcap, struct acc_line *ln, struct motion_sample *first,
                        struct motion_sample *last, char *err, size_t errlen)
{
    struct motion_plan *p = &m->plan;
    double hs = knot_spacing(p, sg);
    for (size_t i = 0; i < sg->nk; i++) {
        size_t k = sg->k0 + i;
        double hard = 0, cap = 0, acc = HUGE_VAL, acc0 = HUGE_VAL;
        zcap[k] = HUGE_VAL;
        if (motion_cancelled(m, sg->file, sg->line, err, errlen))
            return MOTION_ERR_CANCELLED;
        if (sg->kind <= SEG_ARC) {
            /* the end samples straight into first and last, not copied there (dense code
             * has two knots a move, both ends) */
            struct motion_sample mid, *S = i == 0 ? first : i + 1 == sg->nk ? last : &mid;
            int st = motion_knot_caps(m, sg, p->ks[k], hs, S, &hard, &cap, &acc, &acc0,
                                      err, errlen);
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
        ln[k] = acc_line_of(p->iacc[k], acc0, hard, sg->sync, m->cfg.servo_period_s);
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

/* The joint from segment j - 1 into j (j > 0): its speed, the caps of the knots beside it,
 * and the share of their acceleration its jump takes. prev_end: the end sample of the last
 * line or arc before j, first: j's first sample (read only where both moves are lines or
 * arcs). */
static void joint_caps(struct motion *m, size_t j, const struct motion_sample *prev_end,
                       const struct motion_sample *first, struct acc_line *ln)
{
    struct motion_plan *p = &m->plan;
    struct motion_seg *sg = &p->segs[j];
    size_t pk = p->segs[j - 1].k0 + p->segs[j - 1].nk - 1;
    double vin = motion_junction_speed(m, &p->segs[j - 1], sg, prev_end, first,
                                       motion_max2(p->iacc[pk], p->iacc[sg->k0]));
    /* a joint passed no faster than full acceleration reaches in STOP_EQUIV_PERIODS servo
     * periods (a sharp corner) is a stop in all but name, while the jump would take a share
     * of the moves' acceleration on both sides: stop there instead */
    if (vin > 0 && vin < STOP_EQUIV_PERIODS * m->cfg.servo_period_s *
                             motion_min2(p->iacc[sg->k0], p->iacc[pk]))
        vin = 0;
    p->kv[sg->k0] = motion_min2(p->kv[sg->k0], vin);
    p->kv[pk] = motion_min2(p->kv[pk], vin);
    if (vin > 0) {                 /* the jump's share of the acceleration, both sides, at
                                    * the fastest the joint may be passed (hard caps) */
        double vmax = motion_min2(vin, motion_min2(p->kt[sg->k0], p->kt[pk]));
        double share = motion_junction_share(m, prev_end, first, vmax);
        p->iacc[sg->k0] *= 1 - share;
        p->iacc[pk] *= 1 - share;
        ln[sg->k0].a0 *= 1 - share, ln[sg->k0].b *= 1 - share;
        ln[pk].a0 *= 1 - share, ln[pk].b *= 1 - share;
    }
}

/* One job of the knot caps (struct motion_caps_work): segments [j0, j1) in order, from the
 * planner m's copy. Caps at every knot (see segment_caps); interval caps into ivp and irho
 * (hard); a knot's speed suits both neighbouring intervals; the joints between the job's
 * segments get their speed, all but the one into j0 (j0 > 0), which all_caps gives once
 * every job is done: first and end keep the samples it needs. */
struct motion_caps_job {
    size_t j0, j1;
    int status;
    int has_end;                 /* a line or arc among them: end is the last one's end */
    struct motion_sample first;  /* segment j0's first sample */
    struct motion_sample end;
    size_t samples;
    int limited_by_legs, limited_by_kin_tol;
    long fills, taken;           /* the look-ahead's counts */
    char err[400];
};

static int caps_in_order(struct motion *m, struct motion_caps_job *J, double *gain,
                         double *zcap, struct acc_line *ln, char *err, size_t errlen)
{
    struct motion_plan *p = &m->plan;
    struct motion_sample ends[3], *prev_end = &ends[0], *first = &ends[1], *last = &ends[2];
    for (size_t j = J->j0; j < J->j1; j++) {
        struct motion_seg *sg = &p->segs[j];
        int st = segment_caps(m, sg, gain, zcap, ln, first, last, err, errlen);
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
        if (j == 0)
            p->kv[sg->k0] = motion_min2(p->kv[sg->k0], 0);   /* from rest */
        else if (j > J->j0)
            joint_caps(m, j, prev_end, first, ln);
        else
            J->first = *first;             /* (the joint into j0: all_caps) */
        p->kv[lk] = j + 1 < p->nseg ? p->kv[lk] : 0;
        if (sg->kind <= SEG_ARC) {     /* (a dwell's neighbours never pass it blended) */
            struct motion_sample *t = prev_end;
            prev_end = last, last = t;
            J->has_end = 1;
        }
        p->info.samples += sg->nk;
    }
    if (J->has_end)
        J->end = *prev_end;
    return MOTION_OK;
}

#define CAPS_JOB_SEGS 128   /* segments a job of the knot caps takes, at least */
#define CAPS_BATCH 64       /* jobs offered at a time (a window of dense code has about 40; a
                             * whole program is done batch by batch, in bounded memory) */

/* The knot caps of a plan in jobs of consecutive segments. Each job starts from the same
 * copy of the planner (tmpl: a Jacobian cache and look-ahead of its own), so the plan is the
 * same whichever thread computes which job. The planner offers the jobs while it takes them
 * itself, and a thread waiting for its plan (the check's servo pass, motion_stream_help) may
 * take one with motion_caps_help. */
struct motion_caps_work {
    _Atomic uint64_t offer;  /* (jobs << 32) | the next job to take: none left when equal */
    _Atomic size_t done;     /* jobs finished */
    struct motion_caps_job jobs[CAPS_BATCH]; /* the jobs on offer: a batch of the plan's */
    struct motion tmpl;      /* the planner as every job starts from */
    double *gain, *zcap;     /* the arrays all_caps fills */
    struct acc_line *ln;
};

/* Job i of w, from w's copy of the planner. */
static void run_job(struct motion_caps_work *w, size_t i)
{
    struct motion_caps_job *J = &w->jobs[i];
    struct motion mj;
    memcpy(&mj, &w->tmpl, sizeof mj);
    memset(&mj.plan.info, 0, sizeof mj.plan.info);
    motion_knot_ahead(&mj, true);
    J->status = caps_in_order(&mj, J, w->gain, w->zcap, w->ln, J->err, sizeof J->err);
    J->samples = mj.plan.info.samples;
    J->limited_by_legs = mj.plan.info.limited_by_legs;
    J->limited_by_kin_tol = mj.plan.info.limited_by_kin_tol;
    J->fills = mj.kahead.fills - w->tmpl.kahead.fills;
    J->taken = mj.kahead.taken - w->tmpl.kahead.taken;
    atomic_fetch_add_explicit(&w->done, 1, memory_order_release);
}

/* Takes the next job on offer, if any: its number, or -1. */
static long take_job(struct motion_caps_work *w)
{
    uint64_t o = atomic_load_explicit(&w->offer, memory_order_acquire);
    while ((o & 0xffffffffu) < (o >> 32))
        if (atomic_compare_exchange_weak_explicit(&w->offer, &o, o + 1, memory_order_acq_rel,
                                                  memory_order_acquire))
            return (long)(o & 0xffffffffu);
    return -1;
}

bool motion_caps_help(struct motion *m)
{
    struct motion_caps_work *w = atomic_load_explicit(&m->caps, memory_order_acquire);
    long i = w ? take_job(w) : -1;
    if (i < 0)
        return false;
    run_job(w, (size_t)i);
    return true;
}

void motion_caps_free(struct motion *m)
{
    struct motion_caps_work *w = atomic_load(&m->caps);
    free(w);
    atomic_store(&m->caps, NULL);
}

/* Up to CAPS_BATCH jobs into w->jobs from segment j0 on (each ends before a line or arc of
 * two knots or more, or at the plan's end: the joint into it then changes no knot a later
 * segment of its job reads); their count. */
static size_t make_jobs(struct motion_caps_work *w, const struct motion_plan *p, size_t j0)
{
    size_t n = 0;
    while (j0 < p->nseg && n < CAPS_BATCH) {
        size_t j1 = p->nseg - j0 > CAPS_JOB_SEGS ? j0 + CAPS_JOB_SEGS : p->nseg;
        while (j1 < p->nseg && (p->segs[j1].kind > SEG_ARC || p->segs[j1].nk < 2))
            j1++;
        w->jobs[n].j0 = j0, w->jobs[n].j1 = j1, w->jobs[n].has_end = 0;
        n++;
        j0 = j1;
    }
    return n;
}

/* Caps at every knot, in batches of jobs (struct motion_caps_work) that the planner offers
 * to helpers while it takes them itself; then the joints between the jobs. */
static int all_caps(struct motion *m, double *gain, double *zcap, struct acc_line *ln,
                    char *err, size_t errlen)
{
    struct motion_plan *p = &m->plan;
    struct motion_caps_work *w = atomic_load_explicit(&m->caps, memory_order_relaxed);
    if (!w) {
        w = calloc(1, sizeof *w);
        if (!w) {
            snprintf(err, errlen, "out of memory planning the program");
            return MOTION_ERR_NOMEM;
        }
        atomic_store_explicit(&m->caps, w, memory_order_release);
    }
    memcpy(&w->tmpl, m, sizeof w->tmpl);
    w->gain = gain, w->zcap = zcap, w->ln = ln;
    struct motion_sample end;  /* the last batch's last line or arc: its end sample */
    int has_end = 0;
    for (size_t j0 = 0; j0 < p->nseg;) {
        size_t n = make_jobs(w, p, j0);
        atomic_store_explicit(&w->done, 0, memory_order_relaxed);
        atomic_store_explicit(&w->offer, (uint64_t)n << 32, memory_order_release);
        for (long i; (i = take_job(w)) >= 0;)
            run_job(w, (size_t)i);
        while (atomic_load_explicit(&w->done, memory_order_acquire) < n)
            sched_yield();                 /* a helper's last job: a fraction of a ms */
        atomic_store_explicit(&w->offer, 0, memory_order_relaxed);
        for (size_t i = 0; i < n; i++) {
            struct motion_caps_job *J = &w->jobs[i];
            if (J->status) {
                snprintf(err, errlen, "%s", J->err);
                return J->status;
            }
            p->info.samples += J->samples;
            p->info.limited_by_legs += J->limited_by_legs;
            p->info.limited_by_kin_tol += J->limited_by_kin_tol;
            m->kahead.fills += J->fills, m->kahead.taken += J->taken;
            /* the joint into the job (the last line or arc before it: where the segment
             * before it is none, the joint is a stop whatever the samples) */
            if (J->j0 > 0)
                joint_caps(m, J->j0, has_end ? &end : &J->first, &J->first, ln);
            if (J->has_end)
                end = J->end, has_end = 1;
        }
        j0 = w->jobs[n - 1].j1;
    }
    return MOTION_OK;
}

/* Whether the override may run the interval from knot a to b above 1: it moves (both knots'
 * caps above 0) and a soft cap (the feed, a joint's speed) lies below the hard one at either
 * knot, so the profile may cruise there below the hard caps. */
static int may_cruise_fast(const struct motion_plan *p, size_t a, size_t b)
{
    return p->kv[a] > 0 && p->kv[b] > 0 &&
           (p->kv[a] < p->kt[a] * (1 - 1e-9) || p->kv[b] < p->kt[b] * (1 - 1e-9));
}

/* Where the interval before knot k may run above 1, the executor brings the rate down to 1
 * as the knot is reached, and the last step down overlaps the first servo period of a ramp
 * that begins there: the legs passed their limit by up to 1.55 % (test_motion_override, 10000
 * cases) once such ramps took the acceleration at their own speed. The acceleration at the
 * hard cap leaves room for it (none passed in those cases), so ramps from there keep it: the
 * lines of knots k and k + 1 are flat. */
static void keep_hard_after_fast(const struct motion_plan *p, struct acc_line *ln)
{
    for (size_t j = 0; j < p->nseg; j++) {
        const struct motion_seg *sg = &p->segs[j];
        if (sg->kind > SEG_ARC)
            continue;
        size_t lk = sg->k0 + sg->nk - 1;
        for (size_t k = sg->k0; k <= lk; k++) {
            int fast = 0;
            if (k > sg->k0) {
                fast = may_cruise_fast(p, k - 1, k);
            } else if (j > 0 && p->segs[j - 1].kind <= SEG_ARC && p->segs[j - 1].nk > 1) {
                size_t pk = p->segs[j - 1].k0 + p->segs[j - 1].nk - 1;
                fast = may_cruise_fast(p, pk - 1, pk);
            }
            if (!fast)
                continue;
            ln[k] = (struct acc_line){ p->iacc[k], 0 };
            if (k < lk)
                ln[k + 1] = (struct acc_line){ p->iacc[k + 1], 0 };
        }
    }
}

/* Length of interval i (0 across a joint between segments). */
static double interval_ds(const struct motion_plan *p, size_t i, const struct motion_seg *sg)
{
    return i + 1 < sg->k0 + sg->nk && i >= sg->k0 ? p->ks[i + 1] - p->ks[i] : 0;
}

/* motion_min2(cap, sqrt(w)), without the square root where the cap is certainly the
 * smaller (cap^2 below w by a margin far beyond rounding: then cap < sqrt(w) exactly). Where
 * caps bind, each knot of a pass then waits on no square root of the knot before it. (A
 * cap is a speed, never a NaN; nor is a pass's w, a sum of squares and ramps: the passes
 * take motion_lower and motion_raise, one instruction each on the chain from knot to
 * knot.) */
static inline double cap_or_root(double cap, double w)
{
    if (cap * cap < w * (1 - 1e-12))
        return cap;
    return motion_lower(cap, sqrt(w));
}

/* Forward and backward passes over the knots: the fastest speeds that every cap and the
 * acceleration allow, starting and ending at rest; a ramp's acceleration is taken at its
 * faster end (ln), at least the interval's iacc (the limit at its hard caps). */
static void speed_passes(struct motion_plan *p, const struct acc_line *ln)
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
        double ds = interval_ds(p, i, &p->segs[j]), w = p->kv[i] * p->kv[i];
        w = ds > 0 ? motion_raise(w + 2 * p->iacc[i] * ds, ramp_sq(ln, i, w, 2 * ds)) : w;
        p->kv[i + 1] = cap_or_root(p->kv[i + 1], w);
    }
    j = p->nseg - 1;
    for (size_t i = n - 1; i-- > k0;) {
        while (i < p->segs[j].k0) j--;
        double ds = interval_ds(p, i, &p->segs[j]), w = p->kv[i + 1] * p->kv[i + 1];
        w = ds > 0 ? motion_raise(w + 2 * p->iacc[i] * ds, ramp_sq(ln, i, w, 2 * ds)) : w;
        p->kv[i] = cap_or_root(p->kv[i], w);
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
               m->jerk_window_s;
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
static void passes(struct motion *m, const struct acc_line *ln)
{
    struct motion_plan *p = &m->plan;
    size_t n = p->nknot, j = 0;
    speed_passes(p, ln);
    double t = 0;
    p->kt[0] = 0;
    for (size_t i = 0; i + 1 < n; i++) {
        while (i >= p->segs[j].k0 + p->segs[j].nk) j++;
        const struct motion_seg *sg = &p->segs[j];
        double ds = interval_ds(p, i, sg), v0 = p->kv[i], v1 = p->kv[i + 1], a = p->iacc[i];
        double rho = 2, dt = 0;
        if (ds > 0) {
            double w = (v0 * v0 + v1 * v1) / 2;
            double peak = sqrt(motion_max2(0, motion_max2(w + a * ds, ramp_sq(ln, i, w, ds))));
            double vp = motion_max2(motion_max2(v0, v1), motion_min2(p->ivp[i], peak)), ta, tc, td;
            p->ivp[i] = vp;
            if (fmax(vp - v0, vp - v1) > 1e-12 * a) {
                /* a ramp already uses the whole acceleration: the override holds at most
                 * the plan's speed here (but for acc_line_of's pad), so the acceleration
                 * at the fastest holds */
                rho = 1;
                a = p->iacc[i] = fmax(a, line_acc(ln, i, vp));
            }
            motion_phases(v0, v1, vp, a, ds, &ta, &tc, &td);
            dt = ta + tc + td;
            if (vp > 0 && rho > 1)
                rho = motion_min2(rho, p->irho[i] / vp);
        } else {
            p->ivp[i] = v0;
            if (sg->kind == SEG_DWELL && i == sg->k0)
                dt = sg->dwell_s;
            else if (sg->kind <= SEG_ARC && v0 == 0 && i + 1 == sg->k0 + sg->nk)
                dt = stop_rest_s(m, j);  /* a stop between moves: held (motion_step.c) */
            p->info.stops_held += dt > 0 && sg->kind <= SEG_ARC;
            if (sg->sync && i + 1 == sg->k0 + sg->nk)
                dt += motion_sync_extra_s(m, p, j);  /* (the executor's clock skips it) */
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
    struct acc_line *ln = malloc(p->nknot * sizeof *ln);
    if (!gain || !zcap || !ln) {
        free(gain);
        free(zcap);
        free(ln);
        snprintf(err, errlen, "out of memory planning the program");
        return MOTION_ERR_NOMEM;
    }
    int st = all_caps(m, gain, zcap, ln, err, errlen);
    if (!st) {
        keep_hard_after_fast(p, ln);
        passes(m, ln);
        leg_rate_report(m, gain);
        p->info.time_s = p->total_time_s;
        p->info.length_mm = p->total_len_mm;
        p->info.segments = p->nseg;
    }
    free(gain);
    free(zcap);
    free(ln);
    return st;
}
