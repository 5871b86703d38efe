/* test_motion_util.h: machines, programs and run loops for the motion tests and bench. */
#ifndef HEXCNC_TEST_MOTION_UTIL_H
#define HEXCNC_TEST_MOTION_UTIL_H

#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "interp/canon.h"
#include "kins/kins.h"
#include "motion/motion.h"
#include "motion/motion_blend.h"
#include "tests/test_kins_util.h"

/* A machine: configuration table, kinematics and motion. */
struct tm_machine {
    struct tk_cfg *cfg;
    struct kins *kins;
    struct motion *m;
    struct motion_config mc;
};

/* The trivial machine: 6 joints = X Y Z A B C, wide limits. */
static inline struct tk_cfg *tm_trivial_cfg(void)
{
    struct tk_cfg *c = calloc(1, sizeof *c);
    if (!c)
        abort();
    tk_set(c, "KINS", "KINEMATICS", "trivial");
    tk_set(c, "KINS", "JOINTS", "6");
    for (int i = 0; i < 6; i++) {
        char sec[24];
        snprintf(sec, sizeof sec, "JOINT_%d", i);
        tk_set(c, sec, "MIN_LIMIT", "-1000");
        tk_set(c, sec, "MAX_LIMIT", "1000");
        tk_set(c, sec, "MAX_VELOCITY", "1000");
        tk_set(c, sec, "MAX_ACCELERATION", "10000");
        tk_set(c, sec, "FERROR", "1");
    }
    tk_set(c, "TRAJ", "MAX_LINEAR_VELOCITY", "100");
    tk_set(c, "TRAJ", "MAX_LINEAR_ACCELERATION", "1000");
    tk_set(c, "TRAJ", "MAX_ANGULAR_VELOCITY", "90");
    tk_set(c, "TRAJ", "MAX_ANGULAR_ACCELERATION", "900");
    return c;
}

/* The TMU hexapod from configs/sim/tmu-hexapod.ini (NULL when not readable). */
static inline struct tk_cfg *tm_hexapod_cfg(void)
{
    return tk_ini("configs/sim/tmu-hexapod.ini");
}

/* The six legs' MAX_VELOCITY and MAX_ACCELERATION, the same on every leg. */
static inline void tm_set_legs(struct tk_cfg *c, const char *vel, const char *acc)
{
    for (int i = 0; i < 6; i++) {
        char sec[24];
        snprintf(sec, sizeof sec, "JOINT_%d", i);
        tk_set(c, sec, "MAX_VELOCITY", vel);
        tk_set(c, sec, "MAX_ACCELERATION", acc);
    }
}

/* Jerk limits: [TRAJ] MAX_LINEAR_JERK lin (mm/s^3), MAX_ANGULAR_JERK ang (deg/s^3), and
 * every leg's MAX_JERK leg (mm/s^3). */
static inline void tm_set_jerk(struct tk_cfg *c, double lin, double ang, double leg)
{
    tk_setf(c, "TRAJ", "MAX_LINEAR_JERK", lin);
    tk_setf(c, "TRAJ", "MAX_ANGULAR_JERK", ang);
    tk_setf_joints(c, "MAX_JERK", leg);
}

/* Builds kinematics and motion from a table; returns 0 or prints why not. */
static inline int tm_open(struct tm_machine *mc, struct tk_cfg *c, const struct kins_ops *ops)
{
    char err[512] = "";
    memset(mc, 0, sizeof *mc);
    mc->cfg = c;
    struct kins_config kc = tk_config(c);
    if (kins_create(ops, &kc, &mc->kins, err, sizeof err)) {
        fprintf(stderr, "kins: %s\n", err);
        return -1;
    }
    motion_config_default(&mc->mc);
    if (motion_config_read(&mc->mc, &kc, mc->kins->njoints, err, sizeof err) ||
        motion_create(&mc->mc, mc->kins, &mc->m, err, sizeof err)) {
        fprintf(stderr, "motion: %s\n", err);
        return -1;
    }
    return 0;
}

static inline void tm_close(struct tm_machine *mc)
{
    motion_destroy(mc->m);
    kins_free(mc->kins);
    free(mc->cfg);
}

/* Appends one command to a program. */
static inline void tm_add(struct canon_prog *p, enum canon_type type, int line,
                          const double *end, double feed_mm_min, double value)
{
    struct canon_cmd c;
    memset(&c, 0, sizeof c);
    c.type = type;
    c.line = line;
    c.file = "test.ngc";
    if (end)
        memcpy(c.end, end, sizeof c.end);
    c.feed_mm_min = feed_mm_min;
    c.value = value;
    if (canon_prog_sink(p, &c))
        abort();
}

/* A program: path mode (gcode 640 with P = tol, or 610), then feed moves through pts[1..n-1]
 * from pts[0], lines 10, 11, ... */
static inline void tm_polyline_prog(struct canon_prog *p, const double (*pts)[6], int n,
                                    int gcode, double tol, double feed_mm_min)
{
    canon_prog_init(p);
    memcpy(p->start, pts[0], sizeof p->start);
    struct canon_cmd pm = {.type = CANON_PATH_MODE, .line = 1, .file = "test.ngc",
                           .value = tol, .ivalue = gcode};
    if (canon_prog_sink(p, &pm))
        abort();
    for (int i = 1; i < n; i++)
        tm_add(p, CANON_FEED, 9 + i, pts[i], feed_mm_min, 0);
}

/* With Check (the tests, not the bench): */
#ifdef ck_assert_msg
/* Loads and starts a program; fails the test with the planner's message. */
static inline void tm_load_start(struct motion *m, const struct canon_prog *p)
{
    char err[512] = "";
    ck_assert_msg(motion_load(m, p, err, sizeof err) == MOTION_OK, "load: %s", err);
    ck_assert_int_eq(motion_start(m), MOTION_OK);
}
#endif

/* Appends an arc (plane 17/18/19 or 0 with any normal). */
static inline void tm_arc(struct canon_prog *p, int line, const double *end, const double *center,
                          const double *normal, int rotation, double feed_mm_min)
{
    struct canon_cmd c;
    memset(&c, 0, sizeof c);
    c.type = CANON_ARC;
    c.line = line;
    c.file = "test.ngc";
    memcpy(c.end, end, sizeof c.end);
    memcpy(c.arc.center, center, sizeof c.arc.center);
    memcpy(c.arc.normal, normal, sizeof c.arc.normal);
    c.arc.rotation = rotation;
    c.feed_mm_min = feed_mm_min;
    if (canon_prog_sink(p, &c))
        abort();
}

/* n small arcs of radius r mm, each sweeping sweep_deg, in the XY plane at height z: two
 * counter-clockwise (G3), two clockwise (G2), and so on, each joined to the last at its
 * tangent turned by kink_deg (0: tangent joints where the curvature changes sign), after a
 * G64 P tol_mm. The path of LinuxCNC's issue 3773 (small G3 segments of radius about 4 mm). */
static inline void tm_small_arcs(struct canon_prog *p, int n, double r, double sweep_deg,
                                 double kink_deg, double feed_mm_min, double z, double tol_mm)
{
    const double rad = M_PI / 180, nz[3] = { 0, 0, 1 };
    double at[6] = { 0, 0, z, 0, 0, 0 }, head = 0;
    canon_prog_init(p);
    memcpy(p->start, at, sizeof at);
    struct canon_cmd pm;
    memset(&pm, 0, sizeof pm);
    pm.type = CANON_PATH_MODE, pm.line = 1, pm.file = "test.ngc", pm.ivalue = 640;
    pm.value = tol_mm;
    if (canon_prog_sink(p, &pm))
        abort();
    for (int i = 0; i < n; i++) {
        int ccw = (i / 2) % 2 == 0;
        double side = ccw ? 1 : -1, c[3], e[6];
        c[0] = at[0] - side * r * sin(head), c[1] = at[1] + side * r * cos(head), c[2] = z;
        double a0 = atan2(at[1] - c[1], at[0] - c[0]), a1 = a0 + side * sweep_deg * rad;
        memcpy(e, at, sizeof e);
        e[0] = c[0] + r * cos(a1), e[1] = c[1] + r * sin(a1);
        tm_arc(p, i + 2, e, c, nz, ccw ? 1 : -1, feed_mm_min);
        head += side * sweep_deg * rad + kink_deg * rad;
        memcpy(at, e, sizeof at);
    }
}

/* A small deterministic generator for the random tests (the C library's rand differs
 * between systems): uniform in [0, 1). */
static inline double tm_uniform(unsigned long long *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 9007199254740992.0;
}

/* An operator at random: moves the feed override (0 to 2, every 3 to 800 periods) and now
 * and then pauses, to resume 50 to 550 periods later. Start with next = 1. */
struct tm_operator {
    unsigned long long seed;
    long next;                 /* period of the next change */
    long resume_at;            /* period to resume a pause at (0: none) */
    int pauses;
};

/* What the operator does at period n, the machine in state st: resume (first), pause, or
 * set the override to *ovr (>= 0; -1: leave it). */
struct tm_act { int resume, pause; double ovr; };

static inline struct tm_act tm_operate(struct tm_operator *op, long n, enum motion_state st)
{
    struct tm_act act = { 0, 0, -1 };
    if (op->resume_at && n >= op->resume_at && st == MOTION_PAUSED) {
        act.resume = 1;
        op->resume_at = 0;
    }
    if (n < op->next)
        return act;
    double u = tm_uniform(&op->seed);
    if (u < 0.04 && st == MOTION_RUNNING && !op->resume_at) {
        act.pause = 1;
        op->resume_at = n + 50 + (long)(tm_uniform(&op->seed) * 500);
        op->pauses++;
    } else {
        act.ovr = u < 0.1 ? 0 : u < 0.3 ? 2 : 2 * tm_uniform(&op->seed);
    }
    op->next = n + 3 + (long)(tm_uniform(&op->seed) * 800);
    return act;
}

/* What a run measured. */
struct tm_stats {
    int steps;
    double t_s;                       /* simulated time until done (or the step limit) */
    double max_v_mm_s;                /* XYZ speed from successive poses */
    double max_a_mm_s2;               /* XYZ acceleration from successive speeds */
    double max_leg_v[KINS_MAX_JOINTS];/* leg speed from successive leg commands */
    double max_leg_a[KINS_MAX_JOINTS];/* leg acceleration from successive leg speeds */
    double max_cmd_leg_v[KINS_MAX_JOINTS]; /* leg rate commands (joint_vel) */
    double max_j_mm_s3;               /* XYZ jerk from successive accelerations */
    double max_leg_j[KINS_MAX_JOINTS];/* leg jerk from successive leg accelerations */
    struct motion_out last;
};

/* Per-step hook: may command the machine; returns non-zero to stop the run. */
typedef int (*tm_hook)(struct motion *m, const struct motion_out *o, int step, void *ctx);

/* Runs until done, idle, fault or max_steps; measures speeds and accelerations. */
static inline void tm_run(struct motion *m, double dt, int max_steps, struct tm_stats *s,
                          tm_hook hook, void *ctx)
{
    struct motion_out o, prev;
    double pv[3] = {0, 0, 0}, plv[KINS_MAX_JOINTS] = {0}, pa[3] = {0, 0, 0};
    double pla[KINS_MAX_JOINTS] = {0};
    memset(s, 0, sizeof *s);
    motion_step(m, dt, &prev);          /* the first period leaves the start */
    s->steps = 1;
    for (int k = 1; k < max_steps; k++) {
        motion_step(m, dt, &o);
        s->steps++;
        double v[3];
        for (int i = 0; i < 3; i++)
            v[i] = (o.pose[i] - prev.pose[i]) / dt;
        double vn = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        double an = sqrt((v[0] - pv[0]) * (v[0] - pv[0]) + (v[1] - pv[1]) * (v[1] - pv[1]) +
                         (v[2] - pv[2]) * (v[2] - pv[2])) / dt;
        s->max_v_mm_s = fmax(s->max_v_mm_s, vn);
        if (k > 1)
            s->max_a_mm_s2 = fmax(s->max_a_mm_s2, an);
        double a[3], jn = 0;
        for (int i = 0; i < 3; i++)
            a[i] = (v[i] - pv[i]) / dt, jn += (a[i] - pa[i]) * (a[i] - pa[i]);
        if (k > 2)
            s->max_j_mm_s3 = fmax(s->max_j_mm_s3, sqrt(jn) / dt);
        memcpy(pa, a, sizeof pa);
        memcpy(pv, v, sizeof pv);
        for (int j = 0; j < o.njoints; j++) {
            double lv = (o.joint_pos[j] - prev.joint_pos[j]) / dt;
            s->max_leg_v[j] = fmax(s->max_leg_v[j], fabs(lv));
            double la = (lv - plv[j]) / dt;
            if (k > 1)
                s->max_leg_a[j] = fmax(s->max_leg_a[j], fabs(la));
            if (k > 2)
                s->max_leg_j[j] = fmax(s->max_leg_j[j], fabs(la - pla[j]) / dt);
            pla[j] = la;
            s->max_cmd_leg_v[j] = fmax(s->max_cmd_leg_v[j], fabs(o.joint_vel[j]));
            plv[j] = lv;
        }
        prev = o;
        if (hook && hook(m, &o, k, ctx))
            break;
        if (o.state == MOTION_DONE || o.state == MOTION_IDLE || o.state == MOTION_FAULT)
            break;
    }
    s->t_s = prev.time_elapsed_s;
    s->last = prev;
}

/* The kinematic deviation a drive produces: it gets a set point every T and moves each leg
 * linearly between set points. Between successive set points (legs La, Lb) the legs pass
 * La + (Lb - La) j / 10, j = 1..9; the forward kinematics of those gives the pose really
 * reached. Its distance from the programmed line S -> E (X Y Z) and its orientation's
 * deviation from the programmed A B C at the same place along the line are the errors.
 * Runs the loaded, started program to its end; returns -1 if a forward solve failed. */
struct tm_dev { double pos_mm, ang_deg, time_s; int setpoints; };
static inline int tm_deviation(struct motion *m, struct kins *k, const double *S,
                               const double *E, double T, struct tm_dev *out)
{
    struct motion_out a, b;
    double d[3], n2 = 0;
    for (int i = 0; i < 3; i++)
        d[i] = E[i] - S[i], n2 += d[i] * d[i];
    memset(out, 0, sizeof *out);
    motion_step(m, T, &a);
    for (int step = 0; step < 10000000 && a.state != MOTION_DONE; step++) {
        motion_step(m, T, &b);
        double guess[6];
        memcpy(guess, a.pose, sizeof guess);
        for (int j = 1; j < 10; j++) {
            double L[KINS_MAX_JOINTS], P[6], u = 0, e2 = 0;
            for (int i = 0; i < 6; i++)
                L[i] = a.joint_pos[i] + (b.joint_pos[i] - a.joint_pos[i]) * j / 10.0;
            memcpy(P, guess, sizeof P);
            if (kins_forward(k, L, P, NULL) != KINS_OK)
                return -1;
            memcpy(guess, P, sizeof guess);
            for (int i = 0; i < 3; i++)
                u += (P[i] - S[i]) * d[i];
            u /= n2;
            for (int i = 0; i < 3; i++)
                e2 += (P[i] - S[i] - u * d[i]) * (P[i] - S[i] - u * d[i]);
            out->pos_mm = fmax(out->pos_mm, sqrt(e2));
            for (int i = 3; i < 6; i++)
                out->ang_deg = fmax(out->ang_deg, fabs(P[i] - S[i] - u * (E[i] - S[i])));
        }
        out->setpoints++;
        a = b;
    }
    out->time_s = a.time_elapsed_s;
    return 0;
}

/* The TMU hexapod with generous path and leg limits, so that only the kinematic-error bound
 * holds a fast five-axis move back; set points every period_s; tol_mm 0 turns the bound off. */
static inline struct tk_cfg *tm_fast_hexapod_cfg(double period_s, double tol_mm)
{
    struct tk_cfg *c = tm_hexapod_cfg();
    if (!c)
        return NULL;
    tk_set(c, "TRAJ", "MAX_LINEAR_VELOCITY", "1000");
    tk_set(c, "TRAJ", "MAX_LINEAR_ACCELERATION", "2000");
    tk_set(c, "TRAJ", "MAX_ANGULAR_VELOCITY", "1000");
    tk_set(c, "TRAJ", "MAX_ANGULAR_ACCELERATION", "20000");
    tk_setf(c, "TRAJ", "KINEMATIC_TOLERANCE", tol_mm);
    tk_setf(c, "EMCMOT", "SERVO_PERIOD", period_s * 1e9);
    tm_set_legs(c, "1000", "20000");
    return c;
}

/* The TMU hexapod where the legs bind (bench_topp and test_motion_legs): legs 40 mm/s and
 * 200 mm/s^2 under path limits of 500 mm/s, 5000 mm/s^2, 200 deg/s and 2000 deg/s^2. */
static inline struct tk_cfg *tm_leg_bound_hexapod_cfg(void)
{
    struct tk_cfg *c = tm_hexapod_cfg();
    if (!c)
        return NULL;
    tk_set(c, "TRAJ", "MAX_LINEAR_VELOCITY", "500");
    tk_set(c, "TRAJ", "MAX_LINEAR_ACCELERATION", "5000");
    tk_set(c, "TRAJ", "MAX_ANGULAR_VELOCITY", "200");
    tk_set(c, "TRAJ", "MAX_ANGULAR_ACCELERATION", "2000");
    tm_set_legs(c, "40", "200");
    return c;
}

/* bench_topp's two G61 programs for that machine, as X Y Z A B C points (the first the
 * start): 0, five moves through the workspace; 1, turns in place, then a short move. Returns
 * the number of points. */
static inline int tm_leg_bound_points(int which, const double (**pts)[6])
{
    static const double five[][6] = {
        { 0, 0, 645, 0, 0, 0 }, { 100, 0, 645, 0, 0, 0 }, { 100, 80, 660, 5, -5, 10 },
        { -60, 40, 630, -8, 6, -12 }, { -60, -90, 640, 0, 0, 0 }, { 0, 0, 645, 0, 0, 0 },
    };
    static const double turns[][6] = {
        { 0, 0, 645, 0, 0, 0 }, { 0, 0, 645, 10, 0, 0 }, { 0, 0, 645, 0, 10, 15 },
        { 20, 10, 650, 0, 0, 0 },
    };
    *pts = which ? turns : five;
    return which ? 4 : 6;
}

/* The G61 program of straight feeds through pts[1..n-1] from pts[0] at feed_mm_min. */
static inline void tm_g61_points(struct canon_prog *p, const double (*pts)[6], int n,
                                 double feed_mm_min)
{
    canon_prog_init(p);
    p->start_path_mode = 610;
    memcpy(p->start, pts[0], sizeof pts[0]);
    for (int i = 1; i < n; i++)
        tm_add(p, CANON_FEED, i + 1, pts[i], feed_mm_min, 0);
}

/* Feed overrides asked for mid-program: every `every` periods the override switches between
 * 2 and `low` (every 0: held at `low` from the start), so the rate rises to the plan's
 * ceiling and falls again on every part of the profile (ramps, cruises, knots, moves leaving
 * rest). A tm_hook. */
struct tm_override_walk { int every; double low; };

static inline int tm_override_hook(struct motion *m, const struct motion_out *o, int step,
                                   void *ctx)
{
    const struct tm_override_walk *w = ctx;
    (void)o;
    if (w->every && step % w->every == 0)
        motion_set_feed_override(m, step % (2 * w->every) ? 2 : w->low);
    return 0;
}

/* Program p run on m at the servo rate at overrides 1 and 2 and under override walks, the
 * legs differenced every period: the peak leg speed and acceleration over all legs and runs
 * as ratios to their limits into pk[0], pk[1]; -1 (a message on stderr) unless every run
 * ends. */
static inline int tm_run_peaks(struct tm_machine *m, const struct canon_prog *p, double pk[2])
{
    static const struct tm_override_walk walks[] = {
        { 0, 1 }, { 0, 2 }, { 37, 0 }, { 250, 0.3 }, { 700, 0.6 }, { 1009, 0.95 },
    };
    char err[512];
    pk[0] = pk[1] = 0;
    for (size_t r = 0; r < sizeof walks / sizeof walks[0]; r++) {
        struct tm_stats s;
        if (motion_load(m->m, p, err, sizeof err)) {
            fprintf(stderr, "%s\n", err);
            return -1;
        }
        motion_set_feed_override(m->m, walks[r].every ? 1 : walks[r].low);
        motion_start(m->m);
        tm_run(m->m, m->mc.servo_period_s, 10000000, &s, tm_override_hook, (void *)&walks[r]);
        if (s.last.state != MOTION_DONE) {
            fprintf(stderr, "a run did not end (state %d after %.3f s)\n", s.last.state,
                    s.t_s);
            return -1;
        }
        for (int j = 0; j < m->kins->njoints; j++) {
            pk[0] = fmax(pk[0], s.max_leg_v[j] / m->mc.joint[j].max_vel_mm_s);
            pk[1] = fmax(pk[1], s.max_leg_a[j] / m->mc.joint[j].max_acc_mm_s2);
        }
    }
    motion_set_feed_override(m->m, 1);
    return 0;
}

/* Distance from p to the segment a-b (X Y Z). */
static inline double tm_dist_seg(const double *p, const double *a, const double *b)
{
    double d[3], w[3], dd = 0, u = 0, e2 = 0;
    for (int i = 0; i < 3; i++)
        d[i] = b[i] - a[i], w[i] = p[i] - a[i], dd += d[i] * d[i], u += w[i] * d[i];
    u = dd > 0 ? fmin(1, fmax(0, u / dd)) : 0;
    for (int i = 0; i < 3; i++)
        e2 += (w[i] - u * d[i]) * (w[i] - u * d[i]);
    return sqrt(e2);
}

/* Distance from q (X Y Z) to an arc of prog from `at` (any normal, sweep under a half turn
 * counter-clockwise about the normal, as the blend arcs and the tests' arcs are). */
static inline double tm_dist_arc(const double *q, const double *at, const struct canon_cmd *c)
{
    const double *n = c->arc.normal, *o = c->arc.center;
    double v[3] = {q[0] - o[0], q[1] - o[1], q[2] - o[2]}, w[3], e1[3], e2[3], r = 0;
    double h = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
    for (int k = 0; k < 3; k++)
        r += (at[k] - o[k]) * (at[k] - o[k]);
    r = sqrt(r);
    for (int k = 0; k < 3; k++)
        w[k] = v[k] - h * n[k], e1[k] = (at[k] - o[k]) / r;
    e2[0] = n[1] * e1[2] - n[2] * e1[1], e2[1] = n[2] * e1[0] - n[0] * e1[2];
    e2[2] = n[0] * e1[1] - n[1] * e1[0];
    double ang = atan2(w[0] * e2[0] + w[1] * e2[1] + w[2] * e2[2],
                       w[0] * e1[0] + w[1] * e1[1] + w[2] * e1[2]);
    double ee[3] = {c->end[0] - o[0], c->end[1] - o[1], c->end[2] - o[2]};
    double sw = atan2(ee[0] * e2[0] + ee[1] * e2[1] + ee[2] * e2[2],
                      ee[0] * e1[0] + ee[1] * e1[1] + ee[2] * e1[2]);
    double best = fmin(tm_dist_seg(q, at, at), tm_dist_seg(q, c->end, c->end));
    if (ang >= 0 && ang <= sw)
        best = fmin(best, hypot(h, sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) - r));
    return best;
}

/* Distance from q (X Y Z) to the path of prog: its lines and arcs. */
static inline double tm_dist_path(const double *q, const struct canon_prog *p)
{
    double at[6], best = HUGE_VAL;
    memcpy(at, p->start, sizeof at);
    for (size_t i = 0; i < p->count; i++) {
        const struct canon_cmd *c = &p->cmds[i];
        if (c->type == CANON_FEED || c->type == CANON_TRAVERSE)
            best = fmin(best, tm_dist_seg(q, at, c->end));
        else if (c->type == CANON_ARC)
            best = fmin(best, tm_dist_arc(q, at, c));
        if (c->type == CANON_FEED || c->type == CANON_TRAVERSE || c->type == CANON_ARC)
            memcpy(at, c->end, sizeof at);
    }
    return best;
}

/* What tm_chord_deviation measured: largest distance from the path followed (the blended
 * program, or p when nothing is blended) and from p's own lines, the run time, the planned
 * time, the blends and the stops held for a set point (motion_plan_info). */
struct tm_chord {
    double path_mm, prog_mm, time_s, plan_s;
    size_t blends, stops_held;
};

/* Largest distance from the path (p, or the blended program when blended) and from lines of
 * the poses through the forward kinematics of legs interpolated at 9 inner points between
 * the set points La and Lb (guess: the pose at La); -1 when a forward solve fails. */
static inline int tm_chord_check(struct kins *k, const double *La, const double *Lb,
                                 const double *guess0, const struct canon_prog *path,
                                 const struct canon_prog *lines, struct tm_chord *d)
{
    double guess[6];
    memcpy(guess, guess0, sizeof guess);
    for (int j = 1; j < 10; j++) {
        double L[KINS_MAX_JOINTS], P[6];
        for (int i = 0; i < 6; i++)
            L[i] = La[i] + (Lb[i] - La[i]) * j / 10.0;
        memcpy(P, guess, sizeof P);
        if (kins_forward(k, L, P, NULL) != KINS_OK)
            return -1;
        memcpy(guess, P, sizeof guess);
        d->path_mm = fmax(d->path_mm, tm_dist_path(P, path));
        d->prog_mm = fmax(d->prog_mm, tm_dist_path(P, lines));
    }
    return 0;
}

/* Runs p on the fast hexapod (2000 mm/s^2, tm_fast_hexapod_cfg) with KINEMATIC_TOLERANCE
 * tol_mm, a servo period servo_s and drives taking a set point every T_s ([TRAJ]
 * SETPOINT_PERIOD), at the servo outputs phase, phase + T_s / servo_s, ... (the drive's phase
 * against the program's start): legs interpolated linearly between successive set points at
 * 9 inner points, the tool point through the forward kinematics, its distances. 0 or -1. */
static inline int tm_chord_deviation_at(const struct canon_prog *p, double T_s, double servo_s,
                                        int phase, double tol_mm, struct tm_chord *d)
{
    struct tm_machine mc;
    struct tk_cfg *c = tm_fast_hexapod_cfg(servo_s, tol_mm);
    memset(d, 0, sizeof *d);
    if (!c)
        return -1;
    tk_setf(c, "TRAJ", "SETPOINT_PERIOD", T_s * 1e9);
    if (tm_open(&mc, c, &kins_hexapod_ops))
        return -1;
    struct canon_prog out, lines;
    struct motion_plan_info info;
    char err[512];
    int every = (int)lround(T_s / servo_s);
    int st = motion_blend_program(&mc.mc, p, &out, &d->blends, NULL) ||
             motion_load(mc.m, p, err, sizeof err) || motion_start(mc.m);
    motion_plan_info(mc.m, &info);
    d->plan_s = info.time_s;
    d->stops_held = info.stops_held;
    canon_prog_init(&lines);
    memcpy(lines.start, p->start, sizeof lines.start);
    for (size_t i = 0; i < p->count && !st; i++)
        if (p->cmds[i].type == CANON_FEED)
            st = canon_prog_sink(&lines, &p->cmds[i]);
    struct motion_out a, b;
    motion_step(mc.m, servo_s, &a);    /* the first set point: output phase */
    for (int n = 0; n < phase; n++)
        motion_step(mc.m, servo_s, &a);
    for (int n = 0; !st && a.state != MOTION_DONE && n < 10000000; n++) {
        for (int k = 0; k < every; k++) {
            motion_step(mc.m, servo_s, &b);
            if (b.state == MOTION_DONE)
                break;
        }
        st = tm_chord_check(mc.kins, a.joint_pos, b.joint_pos, a.pose,
                            d->blends ? &out : p, &lines, d);
        a = b;
    }
    d->time_s = a.time_elapsed_s;
    canon_prog_free(&lines);
    canon_prog_free(&out);
    tm_close(&mc);
    return st || a.state != MOTION_DONE ? -1 : 0;
}

/* A thread that takes shares of a planner's work, take(arg) (a wrapper of
 * motion_stream_help or motion_caps_help), until tm_helper_stop, which gives their count. */
struct tm_helper {
    bool (*take)(void *arg);
    void *arg;
    _Atomic int stop;
    long taken;
    pthread_t thread;
};

static inline void *tm_helper_loop(void *arg)
{
    struct tm_helper *h = arg;
    while (!atomic_load(&h->stop))
        if (h->take(h->arg))
            h->taken++;
        else
            sched_yield();
    return NULL;
}

static inline int tm_helper_start(struct tm_helper *h, bool (*take)(void *), void *arg)
{
    h->take = take, h->arg = arg, h->taken = 0;
    atomic_store(&h->stop, 0);
    return pthread_create(&h->thread, NULL, tm_helper_loop, h);
}

static inline long tm_helper_stop(struct tm_helper *h)
{
    atomic_store(&h->stop, 1);
    pthread_join(h->thread, NULL);
    return h->taken;
}

/* tm_chord_deviation_at with the servo period equal to the set-point period T_s. */
static inline int tm_chord_deviation(const struct canon_prog *p, double T_s, double tol_mm,
                                     struct tm_chord *d)
{
    return tm_chord_deviation_at(p, T_s, T_s, 0, tol_mm, d);
}

#endif
