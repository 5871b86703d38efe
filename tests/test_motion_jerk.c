/* test_motion_jerk.c: jerk limiting ([TRAJ] MAX_LINEAR_JERK, MAX_ANGULAR_JERK, [JOINT_n]
 * MAX_JERK): the configuration (all or none, named when missing), and on the TMU hexapod no
 * leg over its speed, acceleration or jerk in any servo period (differencing the commanded
 * legs) through exact stops, small arcs, feed holds, overrides and aborts, the tool within
 * KINEMATIC_TOLERANCE of the programmed path, and what it costs in time. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kins/hexapod.h"
#include "tests/test_motion_util.h"

#define DT 0.001
#define LEG_JERK 50000.0       /* mm/s^3: 2 x 1000 / 50000 = 40 ms for the legs in full */
#define LIN_JERK 50000.0       /* mm/s^3: 2 x 500 / 50000 = 20 ms, the default window */
#define ANG_JERK 30000.0       /* deg/s^3: 2 x 300 / 30000 = 20 ms */

#define WINDOW 0.020           /* s, the default window: the legs to 50000 x 0.02 / 2 = 500 */
#define FULL_WINDOW 0.040      /* s, every acceleration in full ([TRAJ] JERK_WINDOW) */

/* The TMU hexapod, with jerk limits (1: the default window; 2: [TRAJ] JERK_WINDOW =
 * FULL_WINDOW) or without. */
static struct tk_cfg *jerk_cfg(int jerk)
{
    struct tk_cfg *c = tm_hexapod_cfg();
    ck_assert_ptr_nonnull(c);
    if (!jerk)
        return c;
    tm_set_jerk(c, LIN_JERK, ANG_JERK, LEG_JERK);
    if (jerk == 2)
        tk_setf(c, "TRAJ", "JERK_WINDOW", FULL_WINDOW);
    return c;
}

/* A G61 program of five-axis feeds at F6000 round a 60 mm square at Z645 (the legs bind). */
static void square(struct canon_prog *p)
{
    static const double pts[][6] = {
        { 60, 0, 645, 0, 0, 0 }, { 60, 60, 650, 5, -5, 10 }, { 0, 60, 645, 0, 0, 0 },
        { 0, 0, 645, 0, 0, 0 }, { 30, 30, 648, -4, 3, -8 },
    };
    canon_prog_init(p);
    double start[6] = { 0, 0, 645, 0, 0, 0 };
    memcpy(p->start, start, sizeof start);
    p->start_path_mode = 610;
    for (size_t i = 0; i < sizeof pts / sizeof pts[0]; i++)
        tm_add(p, CANON_FEED, (int)i + 1, pts[i], 6000, 0);
}

/* Distance from q (X Y Z) to the program's path of lines and XY arcs turning either way
 * (tm_dist_path takes arcs counter-clockwise only). */
static double path_dist(const double *q, const struct canon_prog *p)
{
    double at[6], best = HUGE_VAL;
    memcpy(at, p->start, sizeof at);
    for (size_t i = 0; i < p->count; i++) {
        const struct canon_cmd *c = &p->cmds[i];
        if (c->type == CANON_FEED || c->type == CANON_TRAVERSE) {
            best = fmin(best, tm_dist_seg(q, at, c->end));
        } else if (c->type == CANON_ARC) {
            const double *o = c->arc.center;
            double r = hypot(at[0] - o[0], at[1] - o[1]), dir = c->arc.rotation > 0 ? 1 : -1;
            double a0 = atan2(at[1] - o[1], at[0] - o[0]);
            double sweep = dir * (atan2(c->end[1] - o[1], c->end[0] - o[0]) - a0);
            sweep -= 2 * M_PI * floor(sweep / (2 * M_PI));      /* 0 .. 2 pi, turning dir */
            double aq = dir * (atan2(q[1] - o[1], q[0] - o[0]) - a0);
            aq -= 2 * M_PI * floor(aq / (2 * M_PI));
            double d = aq <= sweep ? hypot(hypot(q[0] - o[0], q[1] - o[1]) - r, q[2] - at[2])
                                   : fmin(tm_dist_seg(q, at, at), tm_dist_seg(q, c->end, c->end));
            best = fmin(best, d);
        }
        if (c->type == CANON_FEED || c->type == CANON_TRAVERSE || c->type == CANON_ARC)
            memcpy(at, c->end, sizeof at);
    }
    return best;
}

/* What a hook watches: the farthest the tool (forward kinematics of the commanded legs)
 * strays from the program's path, commands at given periods, and that a stopped state is
 * reported only once the legs stand still. */
struct watch {
    const struct canon_prog *prog;
    struct kins *kins;
    double guess[6];
    double dev_mm;
    int pause_at, resume_at, abort_at, ovr_at[2];
    double ovr[2];
    double prev_L[KINS_MAX_JOINTS];
    int moved_when_stopped;
    int paused_periods;
};

static int watch_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    struct watch *w = ctx;
    double P[6];
    memcpy(P, w->guess, sizeof P);
    ck_assert_int_eq(kins_forward(w->kins, o->joint_pos, P, NULL), KINS_OK);
    memcpy(w->guess, P, sizeof P);
    if (w->prog)
        w->dev_mm = fmax(w->dev_mm, path_dist(P, w->prog));
    if (o->state == MOTION_PAUSED || o->state == MOTION_DONE || o->state == MOTION_IDLE) {
        for (int j = 0; j < o->njoints; j++)
            if (o->joint_pos[j] != w->prev_L[j])
                w->moved_when_stopped++;
    }
    w->paused_periods += o->state == MOTION_PAUSED;
    memcpy(w->prev_L, o->joint_pos, sizeof w->prev_L);
    if (step == w->pause_at)
        ck_assert_int_eq(motion_pause(m), MOTION_OK);
    if (step == w->resume_at)
        ck_assert_int_eq(motion_resume(m), MOTION_OK);
    if (step == w->abort_at)
        ck_assert_int_eq(motion_abort(m), MOTION_OK);
    for (int i = 0; i < 2; i++)
        if (step == w->ovr_at[i])
            ck_assert_int_eq(motion_set_feed_override(m, w->ovr[i]), MOTION_OK);
    return 0;
}

/* Runs prog on the machine (jerk limits or not) with the watch; returns the figures. */
static struct tm_stats run(int jerk, const struct canon_prog *prog, struct watch *w,
                           int deviation)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, jerk_cfg(jerk), &kins_hexapod_ops), 0);
    char err[400];
    ck_assert_msg(motion_load(mc.m, prog, err, sizeof err) == MOTION_OK, "%s", err);
    ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
    w->prog = deviation ? prog : NULL;
    w->kins = mc.kins;
    memcpy(w->guess, prog->start, sizeof w->guess);
    struct tm_stats st;
    tm_run(mc.m, DT, 400000, &st, watch_hook, w);
    tm_close(&mc);
    return st;
}

/* Every leg within speed, acceleration and jerk in every period; the worst jerk ratio. */
static double assert_limits(const struct tm_stats *st, const char *what)
{
    double worst = 0;
    for (int j = 0; j < 6; j++) {
        ck_assert_msg(st->max_leg_v[j] <= 100 * (1 + 1e-9), "%s: leg %d at %.3f mm/s", what, j,
                      st->max_leg_v[j]);
        ck_assert_msg(st->max_leg_a[j] <= 1000 * (1 + 1e-9), "%s: leg %d at %.3f mm/s^2",
                      what, j, st->max_leg_a[j]);
        ck_assert_msg(st->max_leg_j[j] <= LEG_JERK * (1 + 1e-9), "%s: leg %d at %.0f mm/s^3",
                      what, j, st->max_leg_j[j]);
        worst = fmax(worst, st->max_leg_j[j] / LEG_JERK);
    }
    return worst;
}

/* The motion configuration of table t into c: MOTION_OK or the error, said in err. */
static int read_cfg(struct tk_cfg *t, struct motion_config *c, char *err, size_t errlen)
{
    struct kins_config kc = tk_config(t);
    motion_config_default(c);
    return motion_config_read(c, &kc, 6, err, errlen);
}

START_TEST(test_config)
{
    struct kins *k;
    struct motion_config c;
    char err[400];
    struct tk_cfg *t = jerk_cfg(1);
    struct kins_config kc = tk_config(t);
    ck_assert_int_eq(kins_create(&kins_hexapod_ops, &kc, &k, err, sizeof err), 0);
    ck_assert_int_eq(read_cfg(t, &c, err, sizeof err), MOTION_OK);
    /* the default: the path's 2 x 500 / 50000 and A B C's 2 x 300 / 30000, the legs' with
     * their acceleration taken as the path's 500; the full window is the legs' 2 x 1000 /
     * 50000 */
    ck_assert_double_eq_tol(motion_jerk_window_s(&c), WINDOW, 1e-12);
    ck_assert_double_eq_tol(motion_jerk_default_window_s(&c), WINDOW, 1e-12);
    ck_assert_double_eq_tol(motion_jerk_full_window_s(&c), FULL_WINDOW, 1e-12);
    tk_set(t, "JOINT_4", "MAX_JERK", NULL);     /* JOINT_4's MAX_JERK gone */
    ck_assert_int_eq(read_cfg(t, &c, err, sizeof err), MOTION_ERR_CONFIG);
    ck_assert_msg(strstr(err, "[JOINT_4] MAX_JERK: missing"), "%s", err);
    free(t);
    /* a jerk so low that the average would be longer than a second */
    t = jerk_cfg(1);
    tk_set(t, "JOINT_2", "MAX_JERK", "500");        /* 2 x min(1000, 500) / 500 = 2 s */
    ck_assert_int_eq(read_cfg(t, &c, err, sizeof err), MOTION_ERR_CONFIG);
    ck_assert_msg(strstr(err, "2.000 s moving average"), "%s", err);
    free(t);
    /* none: trapezoidal, no average */
    t = jerk_cfg(0);
    ck_assert_int_eq(read_cfg(t, &c, err, sizeof err), MOTION_OK);
    ck_assert_double_eq(motion_jerk_window_s(&c), 0);
    /* a window without jerk limits is refused, not ignored */
    tk_setf(t, "TRAJ", "JERK_WINDOW", 0.02);
    ck_assert_int_eq(read_cfg(t, &c, err, sizeof err), MOTION_ERR_CONFIG);
    ck_assert_msg(strstr(err, "[TRAJ] JERK_WINDOW = 0.02 s: only with jerk limits"), "%s", err);
    free(t);
    /* the default window, shorter than the full one: every acceleration lowered to jerk x
     * window / 2 where it is above, the window kept in the lowered copy */
    t = jerk_cfg(1);
    ck_assert_int_eq(read_cfg(t, &c, err, sizeof err), MOTION_OK);
    struct motion_config shared = c;
    motion_jerk_share(&shared);
    for (int i = 0; i < 6; i++) {
        ck_assert_double_eq_tol(shared.joint[i].max_acc_mm_s2, 500, 1e-9);  /* from 1000 */
        ck_assert_double_eq(shared.joint[i].max_vel_mm_s, c.joint[i].max_vel_mm_s);
    }
    ck_assert_double_eq(shared.max_lin_acc_mm_s2, c.max_lin_acc_mm_s2);   /* 500: within */
    ck_assert_double_eq(shared.max_ang_acc_deg_s2, c.max_ang_acc_deg_s2); /* 300: within */
    ck_assert_double_eq_tol(shared.jerk_window_s, WINDOW, 1e-12);
    ck_assert_double_eq_tol(motion_jerk_window_s(&shared), WINDOW, 1e-12);
    struct motion *mo;
    ck_assert_int_eq(motion_create(&c, k, &mo, err, sizeof err), MOTION_OK);
    motion_destroy(mo);
    free(t);
    /* [TRAJ] JERK_WINDOW the full window: nothing lowered */
    t = jerk_cfg(2);
    ck_assert_int_eq(read_cfg(t, &c, err, sizeof err), MOTION_OK);
    ck_assert_double_eq_tol(motion_jerk_window_s(&c), FULL_WINDOW, 1e-12);
    shared = c;
    motion_jerk_share(&shared);
    ck_assert(!memcmp(&shared, &c, sizeof c));
    /* legs slower than the path (their 2 x 400 / 50000 = 16 ms within the path's 20): the
     * default is the full window, nothing lowered */
    struct tk_cfg *alt = jerk_cfg(1);
    tk_setf_joints(alt, "MAX_ACCELERATION", 400);
    ck_assert_int_eq(read_cfg(alt, &c, err, sizeof err), MOTION_OK);
    ck_assert_double_eq_tol(motion_jerk_window_s(&c), WINDOW, 1e-12);
    ck_assert_double_eq_tol(motion_jerk_full_window_s(&c), WINDOW, 1e-12);
    free(alt);
    /* ... and the path's acceleration above the legs' 1000: the legs' own 40 ms */
    alt = jerk_cfg(1);
    tk_setf(alt, "TRAJ", "MAX_LINEAR_ACCELERATION", 2000);
    tk_setf(alt, "TRAJ", "MAX_LINEAR_JERK", 200000);       /* (its own 20 ms) */
    ck_assert_int_eq(read_cfg(alt, &c, err, sizeof err), MOTION_OK);
    ck_assert_double_eq_tol(motion_jerk_window_s(&c), FULL_WINDOW, 1e-12);
    /* ... and between (the path's 700): the legs lowered to the path's acceleration, 28 ms */
    tk_setf(alt, "TRAJ", "MAX_LINEAR_ACCELERATION", 700);
    tk_setf(alt, "TRAJ", "MAX_LINEAR_JERK", 70000);        /* (its own 20 ms) */
    ck_assert_int_eq(read_cfg(alt, &c, err, sizeof err), MOTION_OK);
    ck_assert_double_eq_tol(motion_jerk_window_s(&c), 0.028, 1e-12);
    free(alt);
    /* four times the jerk: the path's 5 ms, the full window 10 ms, which the default keeps
     * (it shortens to no less than 20 ms) */
    alt = jerk_cfg(0);
    tm_set_jerk(alt, 4 * LIN_JERK, 4 * ANG_JERK, 4 * LEG_JERK);
    ck_assert_int_eq(read_cfg(alt, &c, err, sizeof err), MOTION_OK);
    ck_assert_double_eq_tol(motion_jerk_window_s(&c), 0.010, 1e-12);
    ck_assert_double_eq_tol(motion_jerk_full_window_s(&c), 0.010, 1e-12);
    /* ... and legs of 2000 mm/s^2 with it: the full window 20 ms, the path's 5 ms; the
     * default 20 ms */
    tk_setf_joints(alt, "MAX_ACCELERATION", 2000);
    ck_assert_int_eq(read_cfg(alt, &c, err, sizeof err), MOTION_OK);
    ck_assert_double_eq_tol(motion_jerk_window_s(&c), 0.020, 1e-12);
    /* ... of 4000: the full window 40 ms; the default 20 ms, the legs lowered to 2000 */
    tk_setf_joints(alt, "MAX_ACCELERATION", 4000);
    ck_assert_int_eq(read_cfg(alt, &c, err, sizeof err), MOTION_OK);
    ck_assert_double_eq_tol(motion_jerk_window_s(&c), 0.020, 1e-12);
    ck_assert_double_eq_tol(motion_jerk_full_window_s(&c), 0.040, 1e-12);
    shared = c;
    motion_jerk_share(&shared);
    ck_assert_double_eq_tol(shared.joint[0].max_acc_mm_s2, 2000, 1e-9);
    free(alt);
    /* rounded up to whole servo periods, never shorter than asked */
    tk_setf(t, "TRAJ", "JERK_WINDOW", 0.0205);
    ck_assert_int_eq(read_cfg(t, &c, err, sizeof err), MOTION_OK);
    ck_assert_double_eq_tol(motion_jerk_window_s(&c), 0.021, 1e-12);
    /* longer than the full acceleration needs, or shorter than two periods: refused */
    static const struct { const char *v, *msg; } bad[] = {
        { "0.05", "[TRAJ] JERK_WINDOW = 0.05 s: longer than the 0.0400 s" },
        { "0.0015", "[TRAJ] JERK_WINDOW = 0.0015 s: shorter than two servo periods" },
        { "0", "[TRAJ] JERK_WINDOW = 0: " },
        { "-0.01", "[TRAJ] JERK_WINDOW = -0.01: " },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        tk_set(t, "TRAJ", "JERK_WINDOW", bad[i].v);
        ck_assert_int_eq(read_cfg(t, &c, err, sizeof err), MOTION_ERR_CONFIG);
        ck_assert_msg(strstr(err, bad[i].msg), "%s: %s", bad[i].v, err);
    }
    free(t);
    kins_free(k);
}
END_TEST

/* Exact stops where the legs bind: every limit kept, the corners reached at rest, and the
 * trapezoidal profile's leg jerk shown to be far over the limit (what the test measures). */
START_TEST(test_exact_stops)
{
    struct canon_prog p;
    square(&p);
    struct watch wj = { .pause_at = -1, .resume_at = -1, .abort_at = -1, .ovr_at = { -1, -1 } };
    struct watch wt = wj;
    struct tm_stats sj = run(1, &p, &wj, 1), st = run(0, &p, &wt, 1);
    ck_assert_int_eq(sj.last.state, MOTION_DONE);
    double r = assert_limits(&sj, "jerk-limited");
    double rt = 0;
    for (int j = 0; j < 6; j++)
        rt = fmax(rt, st.max_leg_j[j] / LEG_JERK);
    ck_assert_msg(rt > 5, "the trapezoidal profile's leg jerk is only %.2f of the limit", rt);
    ck_assert_msg(wj.dev_mm <= 0.001, "the tool strays %.5f mm from the path", wj.dev_mm);
    ck_assert_int_eq(wj.moved_when_stopped, 0);
    printf("G61 square, TMU hexapod: jerk-limited %.3f s (peak leg jerk %.3f of the limit, "
           "path %.5f mm) against trapezoidal %.3f s (peak leg jerk %.1f x the limit, path "
           "%.5f mm): %.3f x the time\n", sj.t_s, r, wj.dev_mm, st.t_s, rt, wt.dev_mm,
           sj.t_s / st.t_s);
    canon_prog_free(&p);
}
END_TEST

/* A feed hold, a resume, overrides up and down, and an abort mid-move: jerk-limited on the
 * path; paused and idle only once the legs stand still. */
START_TEST(test_hold_override_abort)
{
    struct canon_prog p;
    square(&p);
    struct watch w = { .pause_at = 400, .resume_at = 900, .abort_at = -1,
                       .ovr_at = { 1100, 1500 }, .ovr = { 2.0, 0.3 } };
    struct tm_stats s = run(1, &p, &w, 1);
    ck_assert_int_eq(s.last.state, MOTION_DONE);
    ck_assert_int_gt(w.paused_periods, 100);
    double r1 = assert_limits(&s, "hold and overrides");
    ck_assert_int_eq(w.moved_when_stopped, 0);
    ck_assert_msg(w.dev_mm <= 0.001, "the tool strays %.5f mm from the path", w.dev_mm);
    struct watch wa = { .pause_at = -1, .resume_at = -1, .abort_at = 700,
                        .ovr_at = { -1, -1 } };
    s = run(1, &p, &wa, 1);
    ck_assert_int_eq(s.last.state, MOTION_IDLE);
    double r2 = assert_limits(&s, "abort");
    ck_assert_int_eq(wa.moved_when_stopped, 0);
    printf("hold, overrides 2.0 and 0.3, abort: peak leg jerk %.3f and %.3f of the limit\n",
           r1, r2);
    canon_prog_free(&p);
}
END_TEST

/* LinuxCNC's issue 3773: small arcs of radius 4 mm under G64, tangent joints and 5 degree
 * kinks: every limit kept in every period, the tool within the tolerance of the path. */
START_TEST(test_small_arcs)
{
    static const struct { double kink_deg, tol_mm; } cases[] = {
        { 0, 0.01 }, { 5, 0.01 }, { 5, 0.1 },
    };
    struct canon_prog p;
    tm_small_arcs(&p, 40, 4.0, 30, cases[_i].kink_deg, 6000, 645, cases[_i].tol_mm);
    struct watch wj = { .pause_at = -1, .resume_at = -1, .abort_at = -1, .ovr_at = { -1, -1 } };
    struct watch wt = wj;
    struct tm_stats sj = run(1, &p, &wj, 1), st = run(0, &p, &wt, 1);
    ck_assert_int_eq(sj.last.state, MOTION_DONE);
    double r = assert_limits(&sj, "small arcs");
    double rt = 0;
    for (int j = 0; j < 6; j++)
        rt = fmax(rt, st.max_leg_j[j] / LEG_JERK);
    /* blend arcs within half of P, the chords' and the average's rounding within the other
     * half: the tool stays within P of the programmed arcs */
    ck_assert_msg(wj.dev_mm <= cases[_i].tol_mm, "the tool strays %.5f mm from the path",
                  wj.dev_mm);
    printf("small arcs, kinks %.0f deg, G64 P%.2f: jerk-limited %.3f s (peak leg jerk %.3f of "
           "the limit, %.4f mm from the path) against trapezoidal %.3f s (%.1f x the limit, "
           "%.4f mm): %.3f x the time\n", cases[_i].kink_deg, cases[_i].tol_mm, sj.t_s, r,
           wj.dev_mm, st.t_s, rt, wt.dev_mm, sj.t_s / st.t_s);
    canon_prog_free(&p);
}
END_TEST

/* A G64 P tol zigzag of ten 10 mm feeds at F6000 turning 60 and 120 degrees. */
static void zigzag(struct canon_prog *p, double tol)
{
    canon_prog_init(p);
    double at[6] = { -40, 0, 645, 0, 0, 0 };
    memcpy(p->start, at, sizeof at);
    p->start_path_mode = 640;
    p->start_path_tol_mm = tol;
    for (int i = 0; i < 10; i++) {
        double a = (i % 2 ? -1 : 1) * (i % 4 < 2 ? 60 : 30) * M_PI / 180;
        at[0] += 10 * cos(a), at[1] += 10 * sin(a);
        tm_add(p, CANON_FEED, i + 1, at, 6000, 0);
    }
}

/* G64 corners between straight feeds (a zigzag of 10 mm lines turning 60 and 120 degrees):
 * the blend arcs take half of P, the rounding the other half; the tool stays within P of the
 * programmed corners, every limit kept. */
START_TEST(test_blended_corners)
{
    static const double tols[] = { 0.01, 0.05 };
    struct canon_prog p;
    zigzag(&p, tols[_i]);
    struct watch wj = { .pause_at = -1, .resume_at = -1, .abort_at = -1, .ovr_at = { -1, -1 } };
    struct watch wt = wj;
    struct tm_stats sj = run(1, &p, &wj, 1), st = run(0, &p, &wt, 1);
    ck_assert_int_eq(sj.last.state, MOTION_DONE);
    double r = assert_limits(&sj, "blended corners");
    ck_assert_msg(wj.dev_mm <= tols[_i], "the tool strays %.5f mm from the corners",
                  wj.dev_mm);
    printf("zigzag, G64 P%.2f: jerk-limited %.3f s (peak leg jerk %.3f of the limit, %.4f mm "
           "from the programmed corners) against trapezoidal %.3f s (%.4f mm): %.3f x the "
           "time\n", tols[_i], sj.t_s, r, wj.dev_mm, st.t_s, wt.dev_mm, sj.t_s / st.t_s);
    canon_prog_free(&p);
}
END_TEST

/* The default window, half the full one on this machine: the legs' acceleration lowered to
 * 500 mm/s^2, every jerk still kept in every period (differenced), the tool within P of the
 * blended zigzag and within KINEMATIC_TOLERANCE of the G61 square. The shorter average rounds
 * the corners less, so the zigzag runs faster than with the full window ([TRAJ] JERK_WINDOW
 * = 0.040, asserted); the square, where the legs now bind at 500, is printed beside it (it
 * ends sooner too on this machine: each of its stops rests 20 ms less). */
START_TEST(test_jerk_window)
{
    struct canon_prog z, q;
    zigzag(&z, 0.01);
    square(&q);
    struct watch w0 = { .pause_at = -1, .resume_at = -1, .abort_at = -1, .ovr_at = { -1, -1 } };
    struct watch wz = w0, wz1 = w0, wq = w0, wq1 = w0;
    struct tm_stats sz = run(1, &z, &wz, 1), sz1 = run(2, &z, &wz1, 0);
    struct tm_stats sq = run(1, &q, &wq, 1), sq1 = run(2, &q, &wq1, 0);
    ck_assert_int_eq(sz.last.state, MOTION_DONE);
    ck_assert_int_eq(sq.last.state, MOTION_DONE);
    double rz = assert_limits(&sz, "zigzag, window"), rq = assert_limits(&sq, "square, window");
    double az = 0, aq = 0, af = 0;
    for (int j = 0; j < 6; j++) {
        az = fmax(az, sz.max_leg_a[j]), aq = fmax(aq, sq.max_leg_a[j]);
        af = fmax(af, sq1.max_leg_a[j]);
        ck_assert_msg(sz.max_leg_a[j] <= 500 * (1 + 1e-9) && sq.max_leg_a[j] <= 500 * (1 + 1e-9),
                      "leg %d at %.3f and %.3f mm/s^2 with its acceleration lowered to 500", j + 1,
                      sz.max_leg_a[j], sq.max_leg_a[j]);
    }
    assert_limits(&sq1, "square, full window");
    ck_assert_msg(af > 550, "the square's legs reach only %.3f mm/s^2 with every acceleration "
                  "in full", af);      /* (what the default gives up there) */
    ck_assert_msg(wz.dev_mm <= 0.01, "the tool strays %.5f mm from the zigzag", wz.dev_mm);
    ck_assert_msg(wq.dev_mm <= 0.001, "the tool strays %.5f mm from the square", wq.dev_mm);
    ck_assert_msg(sz.t_s < sz1.t_s, "the zigzag took %.3f s with the 20 ms window, %.3f s with "
                  "the 40 ms one", sz.t_s, sz1.t_s);
    printf("the default 20 ms window: zigzag G64 P0.01 %.3f s against %.3f s with the full 40 ms "
           "window (peak leg acceleration %.1f mm/s^2, jerk %.3f of the limit, %.4f mm from the "
           "corners); G61 square %.3f s against %.3f s (%.1f mm/s^2, %.3f, %.5f mm; %.1f mm/s^2 "
           "with the full window)\n", sz.t_s, sz1.t_s, az, rz, wz.dev_mm, sq.t_s, sq1.t_s, aq,
           rq, wq.dev_mm, af);
    canon_prog_free(&z);
    canon_prog_free(&q);
}
END_TEST

/* Arcs joined to lines at a kink (G64 passes such a joint with a velocity jump, no blend
 * arc): the jump's cut takes the blend arcs' half of P, the average's rounding of the arcs
 * the other half, and its cut grows while the path slows into the corner and speeds up out
 * of it (motion_junction_speed); the tool stays within P of the programmed path, every
 * limit kept. Found by test_motion_random: the jump took all of P on top of the rounding,
 * at constant speed, and under P0.002 the tool strayed 2.26 um here. */
START_TEST(test_arc_line_corners)
{
    static const double tols[] = { 0.002, 0.01 };
    const double nz[3] = { 0, 0, 1 }, rad = M_PI / 180;
    struct canon_prog p;
    canon_prog_init(&p);
    double at[6] = { -40, 0, 645, 0, 0, 0 }, head = 0;
    memcpy(p.start, at, sizeof at);
    p.start_path_mode = 640;
    p.start_path_tol_mm = tols[_i];
    for (int i = 0; i < 8; i++) {
        double r = 2 + i % 3, sweep = 40 * rad, c[3], e[6];
        c[0] = at[0] - r * sin(head), c[1] = at[1] + r * cos(head), c[2] = at[2];
        double a1 = atan2(at[1] - c[1], at[0] - c[0]) + sweep;
        memcpy(e, at, sizeof e);
        e[0] = c[0] + r * cos(a1), e[1] = c[1] + r * sin(a1);
        tm_arc(&p, 2 * i + 1, e, c, nz, 1, 6000);
        head += sweep + (i % 2 ? 6 : -3) * rad;       /* the line kinks off the arc's end */
        memcpy(at, e, sizeof at);
        at[0] += 8 * cos(head), at[1] += 8 * sin(head);
        tm_add(&p, CANON_FEED, 2 * i + 2, at, 6000, 0);
        head -= 50 * rad;                             /* and the next arc starts kinked */
    }
    struct watch wj = { .pause_at = -1, .resume_at = -1, .abort_at = -1, .ovr_at = { -1, -1 } };
    struct watch wt = wj;
    struct tm_stats sj = run(1, &p, &wj, 1), st = run(0, &p, &wt, 1);
    ck_assert_int_eq(sj.last.state, MOTION_DONE);
    double r = assert_limits(&sj, "arcs and lines");
    ck_assert_msg(wj.dev_mm <= tols[_i], "the tool strays %.5f mm from the path", wj.dev_mm);
    ck_assert_msg(wt.dev_mm <= tols[_i], "without jerk limits %.5f mm", wt.dev_mm);
    printf("arcs kinked into lines, G64 P%.3f: jerk-limited %.3f s (peak leg jerk %.3f of the "
           "limit, %.5f mm from the path) against trapezoidal %.3f s (%.4f mm): %.3f x the "
           "time\n", tols[_i], sj.t_s, r, wj.dev_mm, st.t_s, wt.dev_mm, sj.t_s / st.t_s);
    canon_prog_free(&p);
}
END_TEST

/* Two tangent arcs close together (G64 P0.01, F6000): a line, an arc of rA turning 90
 * degrees left, a gap, an arc of rB turning 90 degrees left or right, a line. The arcs'
 * caps differ up to 30 times, so the average's window may hold samples of the sharper arc
 * and of the gentler one run faster beyond the sharper one's reach, the case the rounding's
 * bound does not cover (docs/motion.md): measured here against the rounding's share of P
 * (the other half is the blend arcs', and there are none), the tool through the forward
 * kinematics of the commanded legs: at most 0.995 of it. Without the knot where the sharper
 * arc's chord reach ends (motion_chord.c), arcs of 0.05 and 1.5 mm turning back took 1.014
 * of it. The sanitizer's run takes a quarter of the grid. */
START_TEST(test_two_arcs)
{
    static const double ra[] = { 0.05, 0.2, 1 }, ratio[] = { 0.1, 0.5, 4, 30 },
                        gaps[] = { 0.05, 0.2 };
    const double P = 0.01, z = 645, up[3] = { 0, 0, 1 };
    const char *san = getenv("HEXCNC_SANITIZED");
    int step = san && !strcmp(san, "1") ? 4 : 1, n = 0;
    double worst = 0, worst_t = 0;
    for (int k = 0; k < 3 * 4 * 2 * 2; k += step) {
        double rA = ra[k / 16], rB = rA * ratio[k / 4 % 4], gap = gaps[k / 2 % 2];
        int left = k % 2;       /* the second arc turns the same way (left) or back */
        /* up the Y axis to (0,0); left round (-rA,0) to (-rA,rA), heading -X; the gap;
         * round (-rA-gap, rA -+ rB) to (-rA-gap-rB, rA -+ rB), heading -Y or +Y */
        double s = left ? -1 : 1, S[6] = { 0, -30, z }, A[6] = { 0, 0, z },
               CA[3] = { -rA, 0, z }, B[6] = { -rA, rA, z }, G[6] = { -rA - gap, rA, z },
               CB[3] = { -rA - gap, rA + s * rB, z },
               H[6] = { -rA - gap - rB, rA + s * rB, z },
               E[6] = { -rA - gap - rB, rA + s * rB + s * 30, z };
        struct canon_prog p;
        canon_prog_init(&p);
        memcpy(p.start, S, sizeof p.start);
        p.start_path_mode = 640;
        p.start_path_tol_mm = P;
        tm_add(&p, CANON_FEED, 1, A, 6000, 0);
        tm_arc(&p, 2, B, CA, up, 1, 6000);
        tm_add(&p, CANON_FEED, 3, G, 6000, 0);
        tm_arc(&p, 4, H, CB, up, left ? 1 : -1, 6000);
        tm_add(&p, CANON_FEED, 5, E, 6000, 0);
        struct watch w = { .pause_at = -1, .resume_at = -1, .abort_at = -1,
                           .ovr_at = { -1, -1 } };
        struct tm_stats st = run(1, &p, &w, 1);
        ck_assert_int_eq(st.last.state, MOTION_DONE);
        assert_limits(&st, "two arcs");
        ck_assert_msg(w.dev_mm <= P / 2, "arcs of %.2f and %.2f mm %.2f mm apart, turning %s: "
                      "the tool %.5f mm from the path, the rounding's share %.4f mm", rA, rB,
                      gap, left ? "alike" : "back", w.dev_mm, P / 2);
        worst = fmax(worst, w.dev_mm), worst_t += st.t_s, n++;
        canon_prog_free(&p);
    }
    printf("two tangent arcs (radii 0.05 to 30 mm, up to 30 times apart), G64 P0.01, jerk "
           "limits: %d programs, %.1f s, the tool at most %.5f mm from the path (%.3f of the "
           "rounding's share)\n", n, worst_t, worst, worst / (P / 2));
}
END_TEST

/* Where an output switches on the path (M62/M63 between moves): the X of the commanded
 * pose in the period it switches. */
struct switches { double on_x, off_x; int was_on; };

static int switch_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    struct switches *w = ctx;
    int on = (int)(o->outputs.dout & 1);
    if (on && !w->was_on)
        w->on_x = o->pose[0];
    if (!on && w->was_on)
        w->off_x = o->pose[0];
    w->was_on = on;
    return 0;
}

/* Three straight feeds of 20 mm along X at 50 mm/s from X-30, G64 P0.01 (the path blends
 * on through the block ends at X-10 and X10); between(p, line, i) adds what stands after
 * the i-th (1, 2); S900 first when speed is set. */
static void feeds_between(struct canon_prog *p, int speed,
                          void (*between)(struct canon_prog *, int, int))
{
    canon_prog_init(p);
    double at[6] = { -30, 0, 645, 0, 0, 0 };
    memcpy(p->start, at, sizeof at);
    p->start_path_mode = 640;
    p->start_path_tol_mm = 0.01;
    if (speed)
        tm_add(p, CANON_SPINDLE_SPEED, 1, NULL, 0, 900);
    for (int i = 1; i <= 3; i++) {
        at[0] += 20;
        tm_add(p, CANON_FEED, 2 * i, at, 3000, 0);
        if (i < 3)
            between(p, 2 * i + 1, i);
    }
}

/* Runs p on the TMU hexapod (with jerk limits or without) to its end, hook watching. */
static void run_to_end(int jerk, const struct canon_prog *p, tm_hook hook, void *ctx)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, jerk_cfg(jerk), &kins_hexapod_ops), 0);
    char err[400];
    ck_assert_msg(motion_load(mc.m, p, err, sizeof err) == MOTION_OK, "%s", err);
    ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
    struct tm_stats st;
    tm_run(mc.m, DT, 100000, &st, hook, ctx);
    ck_assert_int_eq(st.last.state, MOTION_DONE);
    tm_close(&mc);
}

/* M62 after the first feed, M63 after the second. */
static void add_dout(struct canon_prog *p, int line, int i)
{
    tm_add(p, CANON_DIGITAL_OUT, line, NULL, 0, i == 1 ? 1 : 0);
}

/* M62 and M63 between straight feeds at 50 mm/s blended on through them: the output switches
 * where the tool is at the blocks' ends, with jerk limits as without (the executor reaches
 * those ends T/2 = 20 ms, 1 mm, ahead of the tool). */
START_TEST(test_synced_outputs)
{
    for (int jerk = 0; jerk < 2; jerk++) {
        struct canon_prog p;
        feeds_between(&p, 0, add_dout);
        struct switches w = { .on_x = NAN, .off_x = NAN };
        run_to_end(jerk, &p, switch_hook, &w);
        printf("M62 at X-10, M63 at X10, %s: switched at X%.3f and X%.3f\n",
               jerk ? "jerk-limited" : "trapezoidal", w.on_x, w.off_x);
        /* within a period's travel (0.05 mm) of the blocks' ends */
        ck_assert_msg(fabs(w.on_x + 10) <= 0.06 && fabs(w.off_x - 10) <= 0.06,
                      "switched at X%.3f and X%.3f", w.on_x, w.off_x);
        canon_prog_free(&p);
    }
}
END_TEST

/* Where coolant and spindle speed change on the path: the X of the commanded pose in the
 * period motion's output changes. */
struct coolant { double on_x, off_x, up_x, down_x; int mist; double rpm; };

static int coolant_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    struct coolant *w = ctx;
    if (o->spindle.mist && !w->mist)
        w->on_x = o->pose[0];
    if (!o->spindle.mist && w->mist)
        w->off_x = o->pose[0];
    if (o->spindle.rpm > w->rpm)
        w->up_x = o->pose[0];
    if (o->spindle.rpm < w->rpm)
        w->down_x = o->pose[0];
    w->mist = o->spindle.mist;
    w->rpm = o->spindle.rpm;
    return 0;
}

/* M7 and S1200 after the first feed, M9 and S600 after the second. */
static void add_coolant_speed(struct canon_prog *p, int line, int i)
{
    struct canon_cmd c;
    memset(&c, 0, sizeof c);
    c.type = CANON_COOLANT;
    c.line = line;
    c.file = "test.ngc";
    c.ivalue = i == 1 ? 7 : 9;
    ck_assert_int_eq(canon_prog_sink(p, &c), 0);
    tm_add(p, CANON_SPINDLE_SPEED, line, NULL, 0, i == 1 ? 1200 : 600);
}

/* M7 with S1200 and M9 with S600 between straight feeds at 50 mm/s blended on through them:
 * coolant and spindle speed change where the tool is at the blocks' ends, with jerk limits as
 * without. Before they went out with the mean, they changed T/2 = 20 ms (1 mm) ahead of the
 * tool with jerk limits: at and X9.025. */
START_TEST(test_synced_spindle_coolant)
{
    for (int jerk = 0; jerk < 2; jerk++) {
        struct canon_prog p;
        feeds_between(&p, 1, add_coolant_speed);
        struct coolant w = { .on_x = NAN, .off_x = NAN, .up_x = NAN, .down_x = NAN };
        run_to_end(jerk, &p, coolant_hook, &w);
        printf("M7 S1200 at X-10, M9 S600 at X10, %s: coolant at X%.3f and X%.3f, speed at "
               "X%.3f and X%.3f\n", jerk ? "jerk-limited" : "trapezoidal", w.on_x, w.off_x,
               w.up_x, w.down_x);
        /* within a period's travel (0.05 mm) of the blocks' ends */
        ck_assert_msg(fabs(w.on_x + 10) <= 0.06 && fabs(w.off_x - 10) <= 0.06 &&
                      fabs(w.up_x + 10) <= 0.06 && fabs(w.down_x - 10) <= 0.06,
                      "coolant at X%.3f and X%.3f, speed at X%.3f and X%.3f", w.on_x,
                      w.off_x, w.up_x, w.down_x);
        canon_prog_free(&p);
    }
}
END_TEST

int main(void)
{
    Suite *s = suite_create("motion_jerk");
    TCase *tc = tcase_create("jerk");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_config);
    tcase_add_test(tc, test_exact_stops);
    tcase_add_test(tc, test_hold_override_abort);
    tcase_add_loop_test(tc, test_small_arcs, 0, 3);
    tcase_add_loop_test(tc, test_blended_corners, 0, 2);
    tcase_add_loop_test(tc, test_arc_line_corners, 0, 2);
    tcase_add_test(tc, test_two_arcs);
    tcase_add_test(tc, test_jerk_window);
    tcase_add_test(tc, test_synced_outputs);
    tcase_add_test(tc, test_synced_spindle_coolant);
    suite_add_tcase(s, tc);
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
