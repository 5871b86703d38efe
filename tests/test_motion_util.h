/* test_motion_util.h: machines, programs and run loops for the motion tests and bench. */
#ifndef HEXCNC_TEST_MOTION_UTIL_H
#define HEXCNC_TEST_MOTION_UTIL_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "interp/canon.h"
#include "kins/kins.h"
#include "motion/motion.h"
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

/* What a run measured. */
struct tm_stats {
    int steps;
    double t_s;                       /* simulated time until done (or the step limit) */
    double max_v_mm_s;                /* XYZ speed from successive poses */
    double max_a_mm_s2;               /* XYZ acceleration from successive speeds */
    double max_leg_v[KINS_MAX_JOINTS];/* leg speed from successive leg commands */
    double max_leg_a[KINS_MAX_JOINTS];/* leg acceleration from successive leg speeds */
    double max_cmd_leg_v[KINS_MAX_JOINTS]; /* leg rate commands (joint_vel) */
    struct motion_out last;
};

/* Per-step hook: may command the machine; returns non-zero to stop the run. */
typedef int (*tm_hook)(struct motion *m, const struct motion_out *o, int step, void *ctx);

/* Runs until done, idle, fault or max_steps; measures speeds and accelerations. */
static inline void tm_run(struct motion *m, double dt, int max_steps, struct tm_stats *s,
                          tm_hook hook, void *ctx)
{
    struct motion_out o, prev;
    double pv[3] = {0, 0, 0}, plv[KINS_MAX_JOINTS] = {0};
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
        memcpy(pv, v, sizeof pv);
        for (int j = 0; j < o.njoints; j++) {
            double lv = (o.joint_pos[j] - prev.joint_pos[j]) / dt;
            s->max_leg_v[j] = fmax(s->max_leg_v[j], fabs(lv));
            if (k > 1)
                s->max_leg_a[j] = fmax(s->max_leg_a[j], fabs(lv - plv[j]) / dt);
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
    for (int i = 0; i < 6; i++) {
        char sec[24];
        snprintf(sec, sizeof sec, "JOINT_%d", i);
        tk_set(c, sec, "MAX_VELOCITY", "1000");
        tk_set(c, sec, "MAX_ACCELERATION", "20000");
    }
    return c;
}

#endif
