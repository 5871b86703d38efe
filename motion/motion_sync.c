/* motion_sync.c: spindle-synchronised moves (G33, G33.1): what the planner checks, and the
 * executor's follower that keeps the path position at pitch x spindle revolutions. */
#include <math.h>
#include <stdio.h>

#include "motion/motion_priv.h"

/*
 * A synchronised move is a straight line whose path position d the spindle drives:
 *
 *     d_target = K x (revs - revs0),  revs0 = the whole revolution (the spindle's index)
 *                                      the spindle passed first once the move began
 *
 * so every pass of a thread starts at the same spindle angle, as LinuxCNC's index does. The
 * path starts at rest while the spindle already turns, so the follower chases the target
 * within the move's acceleration and the speed the planner checked (pitch x speed x (1 +
 * [SPINDLE_SYNC] SPEED_MARGIN)), then stays on it: each period it moves at the spindle's
 * speed times K plus a correction of the remaining error over SYNC_FOLLOW_PERIODS.
 *
 * G33.1 (rigid tap), LinuxCNC's sequence:
 *
 *     start --FOLLOW--> bottom: spindle told to reverse (speed x I)
 *        run-on past the bottom while the spindle stops --OUT--> back up, following it
 *     start reached: spindle told its own direction and speed again
 *        run-on above the start while it stops --RESTORING--> it turns forward again
 *     --PLACE--> not synchronised, back to the start; rest.
 *
 * A G33 move ends at rest at its end; a G33 that follows at once goes on from the same
 * revolutions (no new index), so a thread leaving at an angle stays in phase.
 * Pause and feed override wait until the synchronised run is over (a tool in the thread
 * cannot stop while the spindle turns); an abort brakes the path where it is.
 */

#define SYNC_SAMPLES 16          /* caps sampled along a synchronised move at plan time */
#define SYNC_FOLLOW_PERIODS 4.0  /* the follower's position error decays over this many */
#define SYNC_BRAKE_SHARE 0.9     /* share of the acceleration used to stop on a point */
#define SYNC_RUN_ON_SHARE 1.2    /* a tap's run-on checked for reach: the spindle's stop
                                  * distance, and a fifth more for the follower's lag */

void motion_set_spindle_revs(struct motion *m, double revs, bool wired)
{
    if (!m)
        return;
    m->spindle_revs = revs;
    atomic_store_explicit(&m->spindle_wired, wired, memory_order_relaxed);
}

void motion_set_spindle_index(struct motion *m, bool enabled, bool wired)
{
    if (!m)
        return;
    m->index_enabled = enabled;
    m->index_wired = wired;
}

void motion_set_spindle_ideal(struct motion *m, bool on)
{
    if (m)
        m->spindle_ideal = on;
}

bool motion_sync_direct(const struct motion *m)
{
    return m->sync.phase != SYNC_IDLE && m->sync.phase != SYNC_INDEX &&
           m->sync.phase != SYNC_LEFT;
}

bool motion_sync_running(const struct motion *m)
{
    return m && m->sync.phase != SYNC_IDLE && m->sync.phase != SYNC_CHAIN &&
           m->sync.phase != SYNC_LEFT;
}

static const char *sync_name(const struct motion_seg *sg)
{
    return sg->sync == CANON_SYNC_THREAD ? "G33" : "G33.1";
}

/* The spindle's speed on sg, rev/s: commanded, times I on a tap's way out. */
static double sync_rps(const struct motion_seg *sg)
{
    return sg->sync_rpm / 60.0 * (sg->sync == CANON_SYNC_TAP_OUT ? sg->retract_factor : 1.0);
}

/* The path speed sg needs with the spindle SPEED_MARGIN fast, mm/s. */
static double sync_speed_need(const struct motion_config *c, const struct motion_seg *sg)
{
    return sg->pitch_mm_rev * sync_rps(sg) * (1.0 + c->spindle_speed_margin);
}

/* How far past a tap's end the spindle takes the tool while it stops to reverse, mm. */
static double sync_run_on_mm(const struct motion_config *c, const struct motion_seg *sg)
{
    double rps = sync_rps(sg) * (1.0 + c->spindle_speed_margin);
    return SYNC_RUN_ON_SHARE * sg->pitch_mm_rev * rps * rps / (2.0 * c->spindle_acc_rpm_s / 60.0);
}

/* The poses a tap's run-on passes past its end (and past a way out's end: above the
 * start) must be reachable; -2 with err if not. */
static int sync_check_run_on(struct motion *m, const struct motion_seg *sg, char *err,
                             size_t errlen)
{
    double run_on = sync_run_on_mm(&m->cfg, sg), L[KINS_MAX_JOINTS], P[KINS_POSE_DIM];
    int n = (int)ceil(run_on / 0.25) + 1;
    for (int i = 1; i <= n; i++) {
        double s = sg->len + run_on * i / n;
        motion_seg_pose(&m->plan, sg, s, P);
        int st = motion_path_inverse(m, sg->tcp, sg->tool_len_mm, P, L);
        if (st != KINS_OK) {
            snprintf(err, errlen, "%s:%d: %s: the tap may run on %.3f mm past %s while the "
                     "spindle stops to reverse ([SPINDLE_SYNC] ACCELERATION %g rpm/s); "
                     "X%.3f Y%.3f Z%.3f on the way is out of reach (%s)",
                     sg->file ? sg->file : "program", sg->line, sync_name(sg), run_on,
                     sg->sync == CANON_SYNC_TAP_IN ? "the bottom" : "the start",
                     m->cfg.spindle_acc_rpm_s, P[0], P[1], P[2], kins_strerror(st));
            return -2;
        }
    }
    return 0;
}

int motion_sync_check(struct motion *m, const struct motion_seg *sg, char *err,
                      size_t errlen)
{
    const struct motion_config *c = &m->cfg;
    const char *file = sg->file ? sg->file : "program", *name = sync_name(sg);
    if (!atomic_load_explicit(&m->spindle_wired, memory_order_relaxed) && !m->spindle_ideal) {
        snprintf(err, errlen, "%s:%d: %s follows the spindle, and this machine's spindle has "
                 "no position feedback (spindle.0.revs is not connected)", file, sg->line,
                 name);
        return -2;
    }
    if (isnan(c->spindle_speed_margin) || isnan(c->spindle_acc_rpm_s)) {
        snprintf(err, errlen, "%s:%d: %s needs [SPINDLE_SYNC] %s in the INI: %s", file,
                 sg->line, name, isnan(c->spindle_speed_margin) ? "SPEED_MARGIN" :
                 "ACCELERATION", isnan(c->spindle_speed_margin) ? "how much faster than "
                 "commanded the spindle may turn, which the path must keep up with" :
                 "how fast the spindle changes speed, which the path must follow");
        return -2;
    }
    double need = sync_speed_need(c, sg);
    double acc_need = sg->pitch_mm_rev * c->spindle_acc_rpm_s / 60.0;
    for (int i = 0; i <= SYNC_SAMPLES; i++) {
        struct motion_sample S;
        double hard, cap, acc, s = sg->len * i / SYNC_SAMPLES;
        if (motion_knot_caps(m, sg, s, sg->len / SYNC_SAMPLES, &S, &hard, &cap, &acc, NULL,
                             err, errlen))
            return -2;
        if (hard < need || acc < acc_need) {
            snprintf(err, errlen, "%s:%d: %s at S%g with K%g needs %.2f mm/s (the spindle "
                     "%g %% fast, [SPINDLE_SYNC] SPEED_MARGIN) and %.1f mm/s^2 (its "
                     "ACCELERATION): at X%.3f Y%.3f Z%.3f the machine can follow %.2f mm/s "
                     "and %.1f mm/s^2 (path and leg limits); lower S or K", file, sg->line,
                     name, sync_rps(sg) * 60.0, sg->pitch_mm_rev, need,
                     100.0 * c->spindle_speed_margin, acc_need, S.pose[0], S.pose[1],
                     S.pose[2], hard, acc);
            return -2;
        }
    }
    return sg->sync == CANON_SYNC_THREAD ? 0 : sync_check_run_on(m, sg, err, errlen);
}

/* The path acceleration a synchronised move sg of p keeps to: the least its intervals were
 * planned with (the machine's linear limit on a move without intervals). */
static double sync_acc(const struct motion_config *c, const struct motion_plan *p,
                       const struct motion_seg *sg)
{
    double a = HUGE_VAL;
    for (size_t k = sg->k0; k + 1 < sg->k0 + sg->nk; k++)
        a = fmin(a, p->iacc[k]);
    return a < HUGE_VAL ? a : c->max_lin_acc_mm_s2;
}

/* Time to travel d mm at pitch k while the spindle speeds up from rest at acc (rev/s^2) to
 * w (rev/s), then turns at w. */
static double climb_s(double d, double k, double acc, double w)
{
    if (!(d > 0) || !(k > 0) || !(acc > 0) || !(w > 0))
        return 0;
    double d_ramp = k * w * w / (2 * acc);
    return d <= d_ramp ? sqrt(2 * d / (k * acc)) : w / acc + (d - d_ramp) / (k * w);
}

double motion_sync_extra_s(const struct motion *m, const struct motion_plan *p, size_t j)
{
    const struct motion_seg *sg = &p->segs[j];
    double rps = sg->sync_rpm / 60.0, acc = m->cfg.spindle_acc_rpm_s / 60.0;
    double k = sg->pitch_mm_rev, out = rps * sg->retract_factor, t = 0;
    if (!sg->sync || !(rps > 0) || !(acc > 0))
        return 0;
    if (!(j > 0 && p->segs[j - 1].sync))
        t += 0.5 / rps;         /* the index comes within a turn: half of one on average */
    if (sg->sync == CANON_SYNC_TAP_IN) {        /* the spindle stops at the bottom, and the */
        t += rps / acc + climb_s(k * rps * rps / (2 * acc), k, acc, out); /* run-on back */
    } else if (sg->sync == CANON_SYNC_TAP_OUT) {
        /* it stops above the start; the tool comes back unsynchronised, from rest to rest at
         * the share of the move's acceleration the follower brakes with */
        double a = SYNC_BRAKE_SHARE * sync_acc(&m->cfg, p, sg);
        t += out / acc + 2 * sqrt(k * out * out / (2 * acc) / a);
    }
    return t;
}

/* The ideal spindle of a check: it reaches the commanded speed at [SPINDLE_SYNC]
 * ACCELERATION (at once when that is not given) and turns. */
void motion_sync_spindle(struct motion *m, double dt)
{
    if (!m->spindle_ideal || atomic_load_explicit(&m->spindle_wired, memory_order_relaxed))
        return;
    double want = m->io.dir * m->io.rpm / 60.0, step = m->cfg.spindle_acc_rpm_s / 60.0 * dt;
    double r0 = m->ideal_rps, diff = want - r0;
    if (want == 0 && r0 == 0)
        return;                        /* at rest, and told to stay there */
    m->ideal_rps = isnan(step) || fabs(diff) <= step ? want : r0 + copysign(step, diff);
    m->spindle_revs += 0.5 * (r0 + m->ideal_rps) * dt;
}

/* One period of the follower: d chases d_t (moving at v_t) within vmax and the move's
 * acceleration; with stop set it also keeps able to stop at *stop going forward, and rests
 * there once reached. Returns whether it is at rest on *stop. */
static bool follow(struct motion_sync *y, double d_t, double v_t, double dt,
                   const double *stop)
{
    double a = y->acc_mm_s2, e = d_t - y->d_mm;
    double corr = e / (SYNC_FOLLOW_PERIODS * dt), reach = sqrt(2.0 * SYNC_BRAKE_SHARE * a *
                                                                fabs(e));
    double v = v_t + (fabs(corr) > reach ? copysign(reach, e) : corr);
    if (stop) {
        /* the speed at the end of this period that puts d exactly on the stop: once it is
         * within one period's change of the speed now and of rest, land there */
        double rem = *stop - y->d_mm, land = 2.0 * rem / dt - y->v_mm_s;
        if (fabs(rem) < 1e-12 && fabs(y->v_mm_s) <= a * dt) {
            y->v_mm_s = 0;            /* landed last period: at rest */
            return true;
        }
        if (land <= a * dt && land >= -a * dt && fabs(land - y->v_mm_s) <= a * dt) {
            y->d_mm = *stop;
            y->v_mm_s = land;         /* at rest next period: within a again */
            return false;
        }
        /* the fastest next speed from which braking at the brake share, period by period,
         * still stops on it: v^2 / 2a' = rem - (v_now + v) dt / 2 (back when past it) */
        double ab = SYNC_BRAKE_SHARE * a, r = rem - 0.5 * y->v_mm_s * dt;
        double vb = r >= 0 ? ab * (sqrt(0.25 * dt * dt + 2.0 * r / ab) - 0.5 * dt)
                           : -sqrt(2.0 * ab * -r);
        v = fmin(v, vb);
    }
    v = fmax(-y->vmax_mm_s, fmin(y->vmax_mm_s, v));
    double vn = y->v_mm_s + fmax(-a * dt, fmin(a * dt, v - y->v_mm_s));
    y->d_mm += 0.5 * (y->v_mm_s + vn) * dt;
    y->v_mm_s = vn;
    return false;
}

/* The follower's limits on sg: the checked speed and the planned path acceleration. */
static void sync_limits(struct motion *m, const struct motion_seg *sg)
{
    struct motion_sync *y = &m->sync;
    y->vmax_mm_s = sync_speed_need(&m->cfg, sg);
    y->acc_mm_s2 = sync_acc(&m->cfg, m->run, sg);
}

/* The path came onto synchronised segment sg: a tap's way out goes on in the way in's
 * frame, a G33 after a G33 from the same revolutions, anything else waits for the index. */
static void sync_enter(struct motion *m, const struct motion_seg *sg)
{
    struct motion_sync *y = &m->sync;
    y->run = m->run;
    y->seg = m->cs;
    m->tau_s = m->run->kt[sg->k0];    /* the plan's clock waits at the start */
    sync_limits(m, sg);
    if (sg->sync == CANON_SYNC_TAP_OUT && y->phase == SYNC_OUT)
        return;
    int dir = m->io.dir ? m->io.dir : sg->sync_dir;
    if (y->phase == SYNC_CHAIN && sg->sync == CANON_SYNC_THREAD) {
        y->revs0 += y->len_mm / y->k_mm_rev;  /* where the last one's target reached its end */
        y->k_mm_rev = sg->pitch_mm_rev * dir;
        y->d_mm -= y->len_mm;
        y->len_mm = sg->len;
        y->phase = SYNC_FOLLOW;
        return;
    }
    y->k_mm_rev = sg->pitch_mm_rev * dir;
    y->d_mm = y->v_mm_s = 0;
    y->len_mm = sg->len;
    y->dir0 = m->io.dir;
    y->rpm0 = m->io.rpm;
    y->revs_prev = m->spindle_revs;
    y->phase = SYNC_INDEX;
}

/* Whether the spindle passed a whole revolution turning the move's way since last period;
 * if so, that revolution is where d is 0. */
static bool sync_index(struct motion_sync *y, double revs)
{
    double n0 = floor(y->revs_prev), n1 = floor(revs);
    if (n0 == n1 || (revs - y->revs_prev) * y->k_mm_rev <= 0)
        return false;
    y->revs0 = fmax(n0, n1);
    return true;
}

void motion_sync_index_withdraw(struct motion *m)
{
    if (m->sync.index_asked)
        m->index_out = -1;
    m->sync.index_asked = 0;
}

/* The index has not come while the spindle turned MOTION_INDEX_WAIT_REVS: the request is
 * withdrawn and the machine, at rest at the move's start, faults and says why. */
static void index_missing(struct motion *m, const struct motion_seg *sg, double turned)
{
    motion_sync_index_withdraw(m);
    motion_set_msg(m, "%s:%d: the spindle turned %.1f revolutions with spindle.0.index-enable "
                   "set and the encoder never cleared it: no index pulse came (check the "
                   "encoder's index signal and its wiring; with the pin left unconnected, "
                   "each pass starts at a whole revolution of the count instead); the %s did "
                   "not start, machine stopped",
                   sg->file ? sg->file : "program", sg->line, turned,
                   sg->sync == CANON_SYNC_THREAD ? "G33 move" : "tap (G33.1)");
    m->rate = 0;
    m->state = MOTION_FAULT;
    m->fault_status = MOTION_ERR_INDEX;
}

/* With the encoder's index wired: asks for the index once the move may start, and whether
 * the encoder has met it since (it clears the pin, its count reset to 0 there). A pause or an
 * abort meanwhile withdraws the request; a resume asks again. An index comes once a
 * revolution: when the spindle has turned MOTION_INDEX_WAIT_REVS since the request without
 * one, the index is missing and the machine faults (index_missing). */
static bool sync_index_pin(struct motion *m, const struct motion_seg *sg, bool ready,
                           double revs)
{
    struct motion_sync *y = &m->sync;
    if (!ready) {
        motion_sync_index_withdraw(m);
        return false;
    }
    if (!y->index_asked) {
        y->index_asked = 1;
        y->index_revs0 = revs;
        m->index_out = 1;             /* set this period; the encoder sees it from the next */
        return false;
    }
    if (m->index_enabled) {
        double turned = fabs(revs - y->index_revs0);
        if (turned > MOTION_INDEX_WAIT_REVS)
            index_missing(m, sg, turned);
        return false;
    }
    y->index_asked = 0;
    y->revs0 = 0;                     /* the count starts at the index */
    return true;
}

/* Leaves segment sg: the plan's clock goes to the next segment's start (past the hold the
 * plan keeps where the path turns back: the executor has turned already), or to the end. */
static void sync_leave(struct motion *m, const struct motion_seg *sg, enum motion_sync_phase ph)
{
    size_t k = sg->k0 + sg->nk;
    m->tau_s = m->run->kt[k < m->run->nknot ? k : k - 1];
    m->sync.phase = ph;
    /* at rest with nothing synchronised to follow at once: a pause asked for meanwhile
     * holds here (between G33s that follow each other it would let the spindle run ahead
     * of the thread) */
    const struct motion_plan *p = m->run;
    bool chained = ph == SYNC_CHAIN && m->cs + 1 < p->nseg &&
                   p->segs[m->cs + 1].sync == CANON_SYNC_THREAD;
    if (ph != SYNC_OUT && !chained)
        m->rate = 0;
}

/* An abort on a synchronised move: the path brakes where it is; at rest, stopped. */
static void sync_abort(struct motion *m, double dt)
{
    struct motion_sync *y = &m->sync;
    double dv = fmin(fabs(y->v_mm_s), y->acc_mm_s2 * dt);
    double vn = y->v_mm_s - copysign(dv, y->v_mm_s);
    y->d_mm += 0.5 * (y->v_mm_s + vn) * dt;
    y->v_mm_s = vn;
    m->rate = vn != 0 ? 1 : 0;        /* at rest: motion_step's abort ends it (the phase
                                       * stays, so the pose stays where it stopped) */
}

/* The tap's phases after the way in (see the top of the file). */
static void sync_tap(struct motion *m, const struct motion_seg *sg, double d_t, double v_t,
                     double dt)
{
    struct motion_sync *y = &m->sync;
    switch (y->phase) {
    case SYNC_FOLLOW:                 /* into the hole */
        follow(y, d_t, v_t, dt, NULL);
        if (y->d_mm >= y->len_mm) {
            m->io.dir = -y->dir0;     /* reverse, at I times the speed, and go on out */
            m->io.rpm = y->rpm0 * sg->retract_factor;
            m->io_age = 0;
            sync_leave(m, sg, SYNC_OUT);
        }
        break;
    case SYNC_OUT:                    /* run-on, then out following the reversed spindle */
        follow(y, d_t, v_t, dt, NULL);
        if (y->d_mm <= 0 && y->v_mm_s < 0) {
            m->io.dir = y->dir0;      /* back at the start: the spindle's own direction */
            m->io.rpm = y->rpm0;
            m->io_age = 0;
            y->phase = SYNC_RESTORING;
        }
        break;
    case SYNC_RESTORING:              /* run-on above the start until it turns forward */
        follow(y, d_t, v_t, dt, NULL);
        if (v_t > 0 || y->v_mm_s >= 0)  /* (v_t > 0: turning the way in again) */
            y->phase = SYNC_PLACE;
        break;
    case SYNC_PLACE: {                /* not synchronised: back to the start, then rest */
        double zero = 0;
        if (follow(y, 0, 0, dt, &zero))
            sync_leave(m, sg, SYNC_LEFT);
        break;
    }
    default: break;
    }
}

bool motion_sync_advance_line(struct motion *m, const struct motion_seg *sg, double dt)
{
    struct motion_sync *y = &m->sync;
    bool here = y->run == m->run && y->seg == m->cs;
    if (here && (y->phase == SYNC_CHAIN || y->phase == SYNC_LEFT))
        return false;                 /* left at its end: the plan's clock goes on */
    if (!here || y->phase == SYNC_IDLE)
        sync_enter(m, sg);
    double revs = m->spindle_revs, rps = (revs - y->revs_prev) / dt;
    if (y->phase == SYNC_INDEX) {
        /* (with jerk limits, once the moving average has come to rest here: the move then
         * follows the spindle without it, motion_jerk.c) */
        bool ready = m->state == MOTION_RUNNING && motion_jerk_settled(m);
        bool go = m->index_wired ? sync_index_pin(m, sg, ready, revs)
                                 : ready && sync_index(y, revs);
        y->revs_prev = revs;
        if (!go) {
            m->rate = 0;              /* at rest: a pause or an abort may take it here */
            return true;
        }
        y->phase = SYNC_FOLLOW;
    }
    y->revs_prev = revs;
    if (m->state == MOTION_STOPPING) {
        sync_abort(m, dt);
        return true;
    }
    m->rate = 1;
    /* the target a period ago: the step lands on where these revolutions put the path */
    double v_t = y->k_mm_rev * rps, d_t = y->k_mm_rev * (revs - y->revs0) - v_t * dt;
    if (sg->sync == CANON_SYNC_THREAD) {
        if (follow(y, d_t, v_t, dt, &y->len_mm))
            sync_leave(m, sg, SYNC_CHAIN);
    } else {
        sync_tap(m, sg, d_t, v_t, dt);
    }
    return true;
}

bool motion_sync_position(const struct motion *m, const struct motion_seg *sg, double *s,
                          double *v)
{
    const struct motion_sync *y = &m->sync;
    if (sg->kind != SEG_LINE || y->phase == SYNC_IDLE)
        return false;
    bool here = y->run == m->run && y->seg == m->cs;
    if (here && (y->phase == SYNC_CHAIN || y->phase == SYNC_LEFT))
        return false;                 /* left at its end: the plan has it there */
    if (sg->sync == CANON_SYNC_TAP_OUT && (here || y->phase == SYNC_OUT)) {
        *s = sg->len - y->d_mm;       /* the way out runs back along the way in */
        *v = -y->v_mm_s;
    } else if (here) {
        *s = y->d_mm;
        *v = y->v_mm_s;
    } else {
        *s = 0;                       /* at its start, not entered yet */
        *v = 0;
    }
    return true;
}
