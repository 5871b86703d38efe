/* test_motion_run.c: pause, resume, abort, M0, feed override, e-stop and following error. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/test_motion_util.h"

#define DT 0.001

static const double S0[6] = {0, 0, 645, 0, 0, 0};
static const double E5[6] = {80, -30, 655, 4, -6, 10};  /* a five-axis move from S0 */

/* The TMU hexapod loaded with S0 -> E5 at `feed` (mm/min) on line 5, started. */
static void hex_move(struct tm_machine *mc, struct canon_prog *p, double feed)
{
    struct tk_cfg *c = tm_hexapod_cfg();
    ck_assert_msg(c != NULL, "cannot read configs/sim/tmu-hexapod.ini (HEXCNC_ROOT?)");
    ck_assert_int_eq(tm_open(mc, c, &kins_hexapod_ops), 0);
    canon_prog_init(p);
    memcpy(p->start, S0, sizeof S0);
    tm_add(p, CANON_FEED, 5, E5, feed, 0);
    char err[512] = "";
    ck_assert_msg(motion_load(mc->m, p, err, sizeof err) == MOTION_OK, "load: %s", err);
    ck_assert_int_eq(motion_start(mc->m), MOTION_OK);
}

/* Distance of a pose from the S0 -> E5 line in all six coordinates (the programmed path
 * interpolates X Y Z A B C together), after projecting on the XYZ direction. */
static double off_line(const double *pose)
{
    double d[3], u = 0, n2 = 0, worst = 0;
    for (int i = 0; i < 3; i++)
        d[i] = E5[i] - S0[i], u += (pose[i] - S0[i]) * d[i], n2 += d[i] * d[i];
    u /= n2;
    for (int i = 0; i < 6; i++)
        worst = fmax(worst, fabs(pose[i] - (S0[i] + u * (E5[i] - S0[i]))));
    return worst;
}

/* Records a stop requested at step `at`: the speed must fall at no more than the path
 * acceleration, the pose stay on the line. */
struct stop_watch {
    int at;                   /* step at which to pause / abort */
    int abort;                /* 1: abort instead of pause */
    int resume_after;         /* steps to stay paused before resuming (0: stop the run) */
    int paused_steps;
    double pose_at_pause[6];
    double max_off_line;
    double max_decel;
    double prev_v;
    int seen_pausing, seen_stopping;
};

static int stop_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    struct stop_watch *w = ctx;
    if (step == w->at)
        ck_assert_int_eq(w->abort ? motion_abort(m) : motion_pause(m), MOTION_OK);
    if (step > w->at && o->state != MOTION_RUNNING && o->state != MOTION_DONE) {
        w->max_off_line = fmax(w->max_off_line, off_line(o->pose));
        w->max_decel = fmax(w->max_decel, (w->prev_v - o->path_vel) / DT);
    }
    w->seen_pausing |= o->state == MOTION_PAUSING;
    w->seen_stopping |= o->state == MOTION_STOPPING;
    if (o->state == MOTION_PAUSED) {
        if (w->paused_steps++ == 0)
            memcpy(w->pose_at_pause, o->pose, sizeof w->pose_at_pause);
        for (int i = 0; i < 6; i++)
            ck_assert_double_eq(o->pose[i], w->pose_at_pause[i]);   /* holds still */
        if (w->paused_steps >= w->resume_after && w->resume_after > 0)
            ck_assert_int_eq(motion_resume(m), MOTION_OK);
        if (w->resume_after == 0)
            return 1;
    }
    w->prev_v = o->path_vel;
    return 0;
}

/* Pause mid-move: decelerates along the path, holds, resumes and ends exactly at E5; the
 * whole run takes longer by at least the time spent paused. */
START_TEST(test_pause_resume)
{
    struct tm_machine mc;
    struct canon_prog p;
    hex_move(&mc, &p, 2400);
    struct motion_plan_info info;
    motion_plan_info(mc.m, &info);
    struct stop_watch w = {.at = 1500, .resume_after = 500};
    struct tm_stats s;
    tm_run(mc.m, DT, 200000, &s, stop_hook, &w);
    ck_assert_int_eq(s.last.state, MOTION_DONE);
    ck_assert(w.seen_pausing);
    ck_assert_int_ge(w.paused_steps, 500);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(s.last.pose[i], E5[i], 1e-9);
    ck_assert_msg(w.max_off_line < 1e-9, "left the line by %g while stopping", w.max_off_line);
    ck_assert_msg(w.max_decel <= mc.mc.max_lin_acc_mm_s2 * 1.001, "decel %.1f", w.max_decel);
    ck_assert(s.t_s > info.time_s + 0.5);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* Abort mid-move: decelerates along the path to a stop and drops the program (IDLE, the
 * program cannot be started again without loading). */
START_TEST(test_abort)
{
    struct tm_machine mc;
    struct canon_prog p;
    hex_move(&mc, &p, 2400);
    struct stop_watch w = {.at = 1500, .abort = 1};
    struct tm_stats s;
    tm_run(mc.m, DT, 200000, &s, stop_hook, &w);
    ck_assert_int_eq(s.last.state, MOTION_IDLE);
    ck_assert(w.seen_stopping);
    ck_assert(w.max_off_line < 1e-9);
    ck_assert(w.max_decel <= mc.mc.max_lin_acc_mm_s2 * 1.001);
    ck_assert(off_line(s.last.pose) < 1e-9);
    ck_assert(fabs(s.last.pose[0] - E5[0]) > 1);            /* stopped short of the end */
    ck_assert_int_eq(motion_start(mc.m), MOTION_ERR_STATE);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* M0 stops at its line until resumed; M1 too (optional stop on by default). */
static int m0_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    int *paused = ctx;
    if (o->state == MOTION_PAUSED) {
        ck_assert_int_eq(o->line, 2);
        ck_assert_double_eq_tol(o->pose[0], 10, 1e-9);
        if (++*paused == 300)
            motion_resume(m);
    }
    return 0;
}
START_TEST(test_program_pause)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
    struct canon_prog p;
    canon_prog_init(&p);
    double a[6] = {10, 0, 0, 0, 0, 0}, b[6] = {20, 0, 0, 0, 0, 0};
    tm_add(&p, CANON_FEED, 1, a, 1200, 0);
    struct canon_cmd c = {.type = CANON_PAUSE, .line = 2, .file = "test.ngc"};
    canon_prog_sink(&p, &c);
    tm_add(&p, CANON_FEED, 3, b, 1200, 0);
    char err[256];
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_OK);
    motion_start(mc.m);
    int paused = 0;
    struct tm_stats s;
    tm_run(mc.m, DT, 100000, &s, m0_hook, &paused);
    ck_assert_int_eq(paused, 300);
    ck_assert_int_eq(s.last.state, MOTION_DONE);
    ck_assert_double_eq_tol(s.last.pose[0], 20, 1e-9);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* What the settings hook saw: settings_done when X first passed 10 and at each state. */
struct settings_watch {
    size_t max_before_10;     /* largest count while X < 10 - 1e-9 (still on line 1) */
    size_t min_after_10;      /* smallest count once X > 10 + 1e-9 (on line 3) */
    double min_vel_mid;       /* slowest path speed between X 9 and X 11 */
};

static int settings_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    (void)m, (void)step;
    struct settings_watch *w = ctx;
    if (o->pose[0] < 10 - 1e-9 && o->settings_done > w->max_before_10)
        w->max_before_10 = o->settings_done;
    if (o->pose[0] > 10 + 1e-9 && o->settings_done < w->min_after_10)
        w->min_after_10 = o->settings_done;
    if (o->pose[0] > 9 && o->pose[0] < 11)
        w->min_vel_mid = fmin(w->min_vel_mid, o->path_vel);
    return 0;
}

/* A setting (CANON_SETTING) is a point of zero length: counted as passed once the path is
 * beyond it, never before; the machine does not stop there (G64: the blend goes on); the
 * one before PROGRAM_END counts when the program is done. */
START_TEST(test_settings_passed)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
    struct canon_prog p;
    canon_prog_init(&p);
    double a[6] = {10, 0, 0, 0, 0, 0}, b[6] = {20, 0, 0, 0, 0, 0};
    struct canon_param prm = {5221, 1.5};
    struct canon_setting set = {.tool = NULL, .nparams = 1, .params = &prm};
    struct canon_cmd c = {.type = CANON_SETTING, .line = 2, .file = "test.ngc", .setting = &set};
    tm_add(&p, CANON_PATH_MODE, 1, NULL, 0, 0.01);
    p.cmds[0].ivalue = 640;
    tm_add(&p, CANON_FEED, 1, a, 1200, 0);
    ck_assert_int_eq(canon_prog_sink(&p, &c), 0);
    tm_add(&p, CANON_FEED, 3, b, 1200, 0);
    c.line = 4;
    ck_assert_int_eq(canon_prog_sink(&p, &c), 0);
    ck_assert_ptr_ne(p.cmds[4].setting, &set);             /* the program owns a copy */
    ck_assert_double_eq(p.cmds[4].setting->params[0].value, 1.5);
    tm_add(&p, CANON_PROGRAM_END, 5, NULL, 0, 0);
    char err[256];
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_OK);
    motion_start(mc.m);
    struct settings_watch w = {.min_after_10 = 99, .min_vel_mid = 1e9};
    struct tm_stats s;
    tm_run(mc.m, DT, 100000, &s, settings_hook, &w);
    ck_assert_int_eq(s.last.state, MOTION_DONE);
    ck_assert_int_eq((int)w.max_before_10, 0);
    ck_assert_int_eq((int)w.min_after_10, 1);
    ck_assert_int_eq((int)s.last.settings_done, 2);
    ck_assert_msg(w.min_vel_mid > 1200 / 60.0 * 0.5, "slowed to %g mm/s at the setting",
                  w.min_vel_mid);                            /* straight on: no stop */
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* Feed override 0.5 from the start: the cruise takes twice as long. Override 2 on a feed of
 * half the machine's limit: twice as fast, the acceleration still within its limit; override
 * 2 on a feed near the limit: held at MAX_LINEAR_VELOCITY. */
START_TEST(test_feed_override)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
    struct canon_prog p;
    canon_prog_init(&p);
    double a[6] = {200, 0, 0, 0, 0, 0};
    tm_add(&p, CANON_FEED, 1, a, 2400, 0);               /* 40 mm/s: 5 s */
    char err[256];
    struct tm_stats s1, s2, s3, s4;
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_OK);
    motion_start(mc.m);
    tm_run(mc.m, DT, 100000, &s1, NULL, NULL);
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_OK);
    motion_set_feed_override(mc.m, 0.5);
    motion_start(mc.m);
    tm_run(mc.m, DT, 100000, &s2, NULL, NULL);
    ck_assert_msg(fabs(s2.t_s - 2 * s1.t_s) < 0.1, "override 0.5: %.3f s vs %.3f s", s2.t_s,
                  s1.t_s);
    ck_assert(s2.max_v_mm_s <= 20 * (1 + 1e-9));
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_OK);
    motion_set_feed_override(mc.m, 2);
    motion_start(mc.m);
    tm_run(mc.m, DT, 100000, &s3, NULL, NULL);
    ck_assert_msg(fabs(s3.t_s - 0.5 * s1.t_s) < 0.1, "override 2: %.3f s vs %.3f s", s3.t_s,
                  s1.t_s);
    ck_assert(s3.max_v_mm_s <= 80 * (1 + 1e-9) && s3.max_v_mm_s > 79.9);
    ck_assert_msg(s3.max_a_mm_s2 <= 1000 * 1.001, "accel %.1f", s3.max_a_mm_s2);
    ck_assert_double_eq_tol(s3.last.pose[0], 200, 1e-9);
    canon_prog_free(&p);
    canon_prog_init(&p);
    tm_add(&p, CANON_FEED, 1, a, 4800, 0);               /* 80 mm/s, machine 100 */
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_OK);
    motion_start(mc.m);
    tm_run(mc.m, DT, 100000, &s4, NULL, NULL);
    ck_assert(s4.max_v_mm_s <= 100 * (1 + 1e-9) && s4.max_v_mm_s > 99.9);
    ck_assert(s4.max_a_mm_s2 <= 1000 * 1.001);
    ck_assert_double_eq_tol(s4.last.pose[0], 200, 1e-9);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* Override changed in the middle of a move, up and down: applied smoothly (acceleration
 * within the limit), the move still ends exactly. */
static int ovr_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    if (step == 800)
        motion_set_feed_override(m, 1.8);
    if (step == 1600)
        motion_set_feed_override(m, 0.3);
    if (step == 2400)
        motion_set_feed_override(m, 1);
    return 0;
}
START_TEST(test_feed_override_live)
{
    struct tm_machine mc;
    struct canon_prog p;
    hex_move(&mc, &p, 1800);
    struct tm_stats s;
    tm_run(mc.m, DT, 200000, &s, ovr_hook, NULL);
    ck_assert_int_eq(s.last.state, MOTION_DONE);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(s.last.pose[i], E5[i], 1e-9);
    ck_assert_msg(s.max_a_mm_s2 <= mc.mc.max_lin_acc_mm_s2 * 1.001, "accel %.1f", s.max_a_mm_s2);
    ck_assert(s.max_v_mm_s <= 1.8 * 30 * (1 + 1e-6));
    for (int i = 0; i < 6; i++) {
        ck_assert(s.max_leg_v[i] <= mc.mc.joint[i].max_vel_mm_s);
        ck_assert(s.max_leg_a[i] <= mc.mc.joint[i].max_acc_mm_s2 * 1.001);
    }
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* E-stop: the very next period's command is where the machine was, the state is FAULT with
 * MOTION_ERR_ESTOP, the message names the line. */
static int estop_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    double *held = ctx;
    if (step == 1000) {
        memcpy(held, o->pose, 6 * sizeof *held);
        motion_estop(m);
    }
    return 0;
}
START_TEST(test_estop)
{
    struct tm_machine mc;
    struct canon_prog p;
    hex_move(&mc, &p, 2400);
    double held[6];
    struct tm_stats s;
    tm_run(mc.m, DT, 200000, &s, estop_hook, held);
    ck_assert_int_eq(s.steps, 1002);
    ck_assert_int_eq(s.last.state, MOTION_FAULT);
    ck_assert_int_eq(s.last.status, MOTION_ERR_ESTOP);
    for (int i = 0; i < 6; i++) {
        ck_assert_double_eq(s.last.pose[i], held[i]);
        ck_assert_double_eq(s.last.joint_vel[i], 0);
    }
    ck_assert_msg(strstr(motion_last_error(mc.m), "test.ngc:5") &&
                  strstr(motion_last_error(mc.m), "emergency stop"), "%s",
                  motion_last_error(mc.m));
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* Following error: once a leg runs faster than 40 mm/s its feedback starts lagging 0.3 mm.
 * That is fine while the leg is fast enough for the limit (MIN_FERROR 0.1 growing to FERROR 1
 * at 100 mm/s) to exceed 0.3 mm, and a fault once the leg slows below 30 mm/s: the fault
 * names leg, amount and line, and stops the machine at once. */
struct fe_ctx { int leg; int lag_step; int fault_step; double leg_speed_at_fault; };
static int fe_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    struct fe_ctx *c = ctx;
    double fb[KINS_MAX_JOINTS];
    memcpy(fb, o->joint_pos, sizeof fb);
    for (int i = 0; i < 6 && c->leg < 0; i++)
        if (fabs(o->joint_vel[i]) > 40)
            c->leg = i, c->lag_step = step;
    if (c->leg >= 0)
        fb[c->leg] -= 0.3;
    if (motion_feedback(m, fb) == MOTION_ERR_FERROR && !c->fault_step) {
        c->fault_step = step;
        c->leg_speed_at_fault = fabs(o->joint_vel[c->leg]);
    }
    return 0;
}
START_TEST(test_following_error)
{
    struct tm_machine mc;
    struct canon_prog p;
    hex_move(&mc, &p, 6000);
    struct fe_ctx c = {-1, 0, 0, 0};
    struct tm_stats s;
    tm_run(mc.m, DT, 200000, &s, fe_hook, &c);
    ck_assert_msg(c.leg >= 0, "no leg reached 40 mm/s");
    ck_assert_int_eq(s.last.state, MOTION_FAULT);
    ck_assert_int_eq(s.last.status, MOTION_ERR_FERROR);
    ck_assert_msg(c.fault_step > c.lag_step + 10, "faulted at once (step %d, lag from %d)",
                  c.fault_step, c.lag_step);
    /* the limit at the fault was below 0.3 mm: the leg was slower than 0.3 / 1 * 100 */
    ck_assert_msg(c.leg_speed_at_fault < 30, "faulted at %.2f mm/s", c.leg_speed_at_fault);
    const char *msg = motion_last_error(mc.m);
    char leg[32];
    snprintf(leg, sizeof leg, "leg %d ", c.leg + 1);
    ck_assert_msg(strstr(msg, "test.ngc:5") && strstr(msg, leg) && strstr(msg, "0.3000 mm"),
                  "%s", msg);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq(s.last.joint_vel[i], 0);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

static Suite *run_suite(void)
{
    Suite *s = suite_create("motion_run");
    TCase *tc = tcase_create("run");
    tcase_add_test(tc, test_pause_resume);
    tcase_add_test(tc, test_abort);
    tcase_add_test(tc, test_program_pause);
    tcase_add_test(tc, test_settings_passed);
    tcase_add_test(tc, test_feed_override);
    tcase_add_test(tc, test_feed_override_live);
    tcase_add_test(tc, test_estop);
    tcase_add_test(tc, test_following_error);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(run_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
