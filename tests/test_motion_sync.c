/* test_motion_sync.c: G33 and G33.1 on the executor: the path position follows pitch x
 * spindle revolutions from a whole revolution on, a rigid tap reverses the spindle at the
 * bottom, follows it out and comes back to its start; and what the planner refuses. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/test_motion_util.h"

#define DT 0.001                 /* servo period, s */
#define ACC 1000.0               /* the trivial machine's path acceleration, mm/s^2 */
#define SPINDLE_ACC 2000.0       /* rpm/s, the simulated spindle's and [SPINDLE_SYNC]'s */

/* Appends a synchronised move (enum canon_sync kind) to end with pitch k_mm. */
static void add_sync(struct canon_prog *p, int line, const double *end, int kind, double k_mm,
                     double i_factor)
{
    struct canon_cmd c;
    memset(&c, 0, sizeof c);
    c.type = CANON_FEED;
    c.line = line;
    c.file = "test.ngc";
    memcpy(c.end, end, sizeof c.end);
    c.sync = kind;
    c.pitch_mm_rev = c.pitch_word = k_mm;
    c.retract_factor = i_factor;
    c.feed_mm_min = 600;
    if (canon_prog_sink(p, &c))
        abort();
}

/* A program starting at top with M3 S rpm. */
static void spindle_prog(struct canon_prog *p, const double *top, double rpm)
{
    canon_prog_init(p);
    memcpy(p->start, top, sizeof p->start);
    tm_add(p, CANON_SPINDLE_SPEED, 1, NULL, 0, rpm);
    tm_add(p, CANON_SPINDLE_ON, 1, NULL, 0, 1);
}

/* M3 S rpm, then a tap from top to bottom and back (as the interpreter makes G33.1). */
static void tap_prog(struct canon_prog *p, const double *top, const double *bottom,
                     double rpm, double k_mm, double i_factor)
{
    spindle_prog(p, top, rpm);
    add_sync(p, 2, bottom, CANON_SYNC_TAP_IN, k_mm, i_factor);
    add_sync(p, 2, top, CANON_SYNC_TAP_OUT, k_mm, i_factor);
    tm_add(p, CANON_PROGRAM_END, 3, NULL, 0, 2);
}

/* The simulated spindle (as sim-spindle): ramps to the commanded speed, integrates it to
 * revolutions, which it gives motion as spindle.0.revs. Records what the run did. */
struct spindle {
    double rpm, revs;
    int reversed, restored;      /* the command went to reverse, then forward again */
    double z_min, z_end;
    /* following: z + K revs is constant while the tool follows the spindle into the hole */
    double k_mm, z_top, lo, hi, c_min, c_max;
    int n_follow;
};

static int spindle_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    struct spindle *s = ctx;
    (void)step;
    double want = o->spindle.dir * o->spindle.rpm, diff = want - s->rpm, st = SPINDLE_ACC * DT;
    double r0 = s->rpm;
    s->rpm += fabs(diff) <= st ? diff : copysign(st, diff);
    s->revs += 0.5 * (r0 + s->rpm) / 60.0 * DT;
    motion_set_spindle_revs(m, s->revs, true);
    if (o->spindle.dir < 0)
        s->reversed = 1;
    if (s->reversed && o->spindle.dir > 0)
        s->restored = 1;
    double z = o->pose[2];
    s->z_min = fmin(s->z_min, z);
    s->z_end = z;
    /* into the hole, between lo and hi (past the catch-up, before the bottom): the pose is
     * that of the revolutions of the period before (motion reads them, then steps) */
    if (!s->reversed && z <= s->hi && z >= s->lo) {
        double c = z + s->k_mm * (s->revs - (r0 + s->rpm) / 120.0 * DT);
        s->c_min = fmin(s->c_min, c);
        s->c_max = fmax(s->c_max, c);
        s->n_follow++;
    }
    return 0;
}

static void open_trivial(struct tm_machine *mc)
{
    struct tk_cfg *c = tm_trivial_cfg();
    tk_set(c, "SPINDLE_SYNC", "ACCELERATION", "2000");
    tk_set(c, "SPINDLE_SYNC", "SPEED_MARGIN", "0.1");
    ck_assert_int_eq(tm_open(mc, c, &kins_trivial_ops), 0);
}

/* A tap from Z10 to Z0 at K1.25, S600 on the spindle already at speed: into the hole the
 * tool is where 1.25 mm x the revolutions since a whole one put it (within 1 um), the
 * spindle is reversed at the bottom, the tool runs on while it stops (K x rps^2 / 2a: 1.25
 * mm here) and no further, comes out, the spindle is set forward again, and the tool ends
 * at rest at Z10, never over the path's acceleration; the plan's time is within 3 % of the
 * tap's. */
START_TEST(test_tap_follows_spindle)
{
    struct tm_machine mc;
    open_trivial(&mc);
    const double top[6] = { 0, 0, 10, 0, 0, 0 }, bottom[6] = { 0, 0, 0, 0, 0, 0 };
    struct canon_prog p;
    tap_prog(&p, top, bottom, 600, 1.25, 1.0);
    struct spindle s = { .rpm = 600, .revs = 0.37, .z_min = 1e9, .k_mm = 1.25, .lo = 0.2,
                         .hi = 8, .c_min = 1e9, .c_max = -1e9 };
    motion_set_spindle_revs(mc.m, s.revs, true);
    char err[400];
    ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    struct motion_plan_info info;
    motion_plan_info(mc.m, &info);
    motion_start(mc.m);
    struct tm_stats st;
    tm_run(mc.m, DT, 20000, &st, spindle_hook, &s);
    ck_assert_int_eq(st.last.state, MOTION_DONE);
    /* the plan's time (progress and time remaining count on it) holds the wait for the
     * index and the spindle's reversals with the run-on travelled back (about 1.2 s) */
    printf("a tap: planned %.3f s, took %.3f s\n", info.time_s, st.t_s);
    ck_assert_msg(fabs(info.time_s - st.t_s) < 0.03 * st.t_s, "planned %.3f s, took %.3f s",
                  info.time_s, st.t_s);
    ck_assert_int_gt(s.n_follow, 500);
    ck_assert_msg(s.c_max - s.c_min < 0.001, "z + K revs spread %.6f mm", s.c_max - s.c_min);
    /* the thread starts at a whole revolution: z = 10 - K (revs - n) */
    double n = (10.0 - s.c_min) / -1.25;
    ck_assert_msg(fabs(n - round(n)) < 0.002, "index at %.4f revolutions", n);
    ck_assert(s.reversed && s.restored);
    double run_on = 1.25 * 10.0 * 10.0 / (2 * SPINDLE_ACC / 60.0);
    ck_assert_msg(s.z_min < -0.9 * run_on && s.z_min > -run_on - 0.05, "z min %.4f, run-on "
                  "%.4f", s.z_min, run_on);
    ck_assert_double_eq_tol(s.z_end, 10.0, 1e-9);
    ck_assert_double_eq_tol(st.last.pose[2], 10.0, 1e-9);
    ck_assert_int_eq(st.last.spindle.dir, 1);
    ck_assert_double_eq_tol(st.last.spindle.rpm, 600, 1e-9);
    ck_assert_msg(st.max_a_mm_s2 <= ACC * 1.001, "acceleration %.1f", st.max_a_mm_s2);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* Under M4 the same: the revolutions count down, the tap follows them, reverses the spindle
 * to M3 at the bottom, and at the top sets M4 again, running on above the start while the
 * spindle stops (as far as below the bottom: I is 1) before it goes back to the start. */
static int z_max_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    struct spindle *s = ctx;
    spindle_hook(m, o, step, s);
    s->hi = fmax(s->hi, o->pose[2]);
    return 0;
}

START_TEST(test_tap_m4)
{
    struct tm_machine mc;
    open_trivial(&mc);
    const double top[6] = { 0, 0, 10, 0, 0, 0 }, bottom[6] = { 0, 0, 0, 0, 0, 0 };
    struct canon_prog p;
    tap_prog(&p, top, bottom, 600, 1.25, 1.0);
    p.cmds[1].value = -1;              /* M4 */
    struct spindle s = { .rpm = -600, .revs = 0.37, .z_min = 1e9, .lo = 100, .hi = -100 };
    motion_set_spindle_revs(mc.m, s.revs, true);
    char err[400];
    ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    motion_start(mc.m);
    struct tm_stats st;
    tm_run(mc.m, DT, 20000, &st, z_max_hook, &s);
    ck_assert_int_eq(st.last.state, MOTION_DONE);
    double run_on = 1.25 * 10.0 * 10.0 / (2 * SPINDLE_ACC / 60.0);
    ck_assert_msg(s.z_min < -run_on + 0.001 && s.z_min > -run_on - 0.02, "z min %.4f",
                  s.z_min);
    ck_assert_msg(s.hi > 10 + run_on - 0.001 && s.hi < 10 + run_on + 0.02, "z max %.4f", s.hi);
    ck_assert_double_eq_tol(st.last.pose[2], 10, 1e-9);
    ck_assert_int_eq(st.last.spindle.dir, -1);
    ck_assert_msg(st.max_a_mm_s2 <= ACC * 1.001, "acceleration %.1f", st.max_a_mm_s2);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* Without spindle.0.revs connected a program with G33.1 is refused before anything moves,
 * naming the line and why. */
START_TEST(test_no_feedback_refused)
{
    struct tm_machine mc;
    open_trivial(&mc);
    const double top[6] = { 0, 0, 10, 0, 0, 0 }, bottom[6] = { 0, 0, 0, 0, 0, 0 };
    struct canon_prog p;
    tap_prog(&p, top, bottom, 600, 1.25, 1.0);
    char err[400] = "";
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_ERR_PROGRAM);
    ck_assert_msg(strstr(err, "test.ngc:2: G33.1") && strstr(err, "no position feedback"),
                  "%s", err);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* S6000 x K1.25 = 125 mm/s (137.5 with the 10 % margin): more than the machine's 100 mm/s,
 * refused at plan time naming the line and the speeds. */
START_TEST(test_too_fast_refused)
{
    struct tm_machine mc;
    open_trivial(&mc);
    const double top[6] = { 0, 0, 10, 0, 0, 0 }, bottom[6] = { 0, 0, 0, 0, 0, 0 };
    struct canon_prog p;
    tap_prog(&p, top, bottom, 6000, 1.25, 1.0);
    motion_set_spindle_revs(mc.m, 0, true);
    char err[400] = "";
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_ERR_PROGRAM);
    ck_assert_msg(strstr(err, "test.ngc:2: G33.1 at S6000 with K1.25 needs 137.50 mm/s") &&
                  strstr(err, "can follow 100.00 mm/s"), "%s", err);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* A tap whose run-on past the bottom (1.875 mm at S600 K1.25, checked with the margin and a
 * fifth more) would leave the machine's reach (the trivial machine's Z stops at -1000) is
 * refused at plan time, naming the line. */
START_TEST(test_run_on_out_of_reach_refused)
{
    struct tm_machine mc;
    open_trivial(&mc);
    const double top[6] = { 0, 0, -990, 0, 0, 0 }, bottom[6] = { 0, 0, -999, 0, 0, 0 };
    struct canon_prog p;
    tap_prog(&p, top, bottom, 600, 1.25, 1.0);
    motion_set_spindle_revs(mc.m, 0, true);
    char err[400] = "";
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_ERR_PROGRAM);
    ck_assert_msg(strstr(err, "test.ngc:2: G33.1: the tap may run on 2.722 mm past the bottom")
                  && strstr(err, "out of reach"), "%s", err);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* Two G33 passes of one thread start at the same spindle angle: each waits for a whole
 * revolution, so the spindle's revolutions at Z5 differ by a whole number between them. */
struct pass_rec {
    struct spindle sp;
    double revs_at_5[2];
    int pass;
    double zprev;
};

static int pass_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    struct pass_rec *r = ctx;
    spindle_hook(m, o, step, &r->sp);
    double z = o->pose[2];
    if (r->zprev > 5 && z <= 5 && r->pass < 2)
        r->revs_at_5[r->pass++] = r->sp.revs - (5 - z) / (r->zprev - z) * (r->sp.rpm / 60 * DT);
    r->zprev = z;
    return 0;
}

START_TEST(test_passes_in_phase)
{
    struct tm_machine mc;
    open_trivial(&mc);
    const double top[6] = { 0, 0, 10, 0, 0, 0 }, bottom[6] = { 0, 0, 0, 0, 0, 0 };
    struct canon_prog p;
    spindle_prog(&p, top, 600);
    add_sync(&p, 2, bottom, CANON_SYNC_THREAD, 1.5, 1);
    tm_add(&p, CANON_TRAVERSE, 3, top, 0, 0);
    tm_add(&p, CANON_DWELL, 4, NULL, 0, 0.123);  /* the spindle goes on meanwhile */
    add_sync(&p, 5, bottom, CANON_SYNC_THREAD, 1.5, 1);
    tm_add(&p, CANON_PROGRAM_END, 6, NULL, 0, 2);
    struct pass_rec r = { .sp = { .rpm = 600, .revs = 0.61, .z_min = 1e9, .k_mm = 1.5,
                                  .lo = 100, .hi = -100 }, .zprev = 10 };
    motion_set_spindle_revs(mc.m, r.sp.revs, true);
    char err[400];
    ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    motion_start(mc.m);
    struct tm_stats st;
    tm_run(mc.m, DT, 20000, &st, pass_hook, &r);
    ck_assert_int_eq(st.last.state, MOTION_DONE);
    ck_assert_int_eq(r.pass, 2);
    double dn = r.revs_at_5[1] - r.revs_at_5[0];
    ck_assert_msg(dn > 1 && fabs(dn - round(dn)) < 0.002, "revolutions between passes %.4f",
                  dn);
    ck_assert_double_eq_tol(st.last.pose[2], 0, 1e-9);
    ck_assert_msg(st.max_a_mm_s2 <= ACC * 1.001, "acceleration %.1f", st.max_a_mm_s2);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* An abort in the middle of the way in: the path brakes on its line within the path's
 * acceleration (no longer following the spindle), the machine goes idle and the spindle is
 * stopped. */
struct abort_rec {
    struct spindle sp;
    int aborted;
    double z_abort;
};

static int abort_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    struct abort_rec *r = ctx;
    spindle_hook(m, o, step, &r->sp);
    if (!r->aborted && o->pose[2] < 5) {
        r->aborted = 1;
        r->z_abort = o->pose[2];
        motion_abort(m);
    }
    return 0;
}

START_TEST(test_abort_mid_tap)
{
    struct tm_machine mc;
    open_trivial(&mc);
    const double top[6] = { 0, 0, 10, 0, 0, 0 }, bottom[6] = { 0, 0, 0, 0, 0, 0 };
    struct canon_prog p;
    tap_prog(&p, top, bottom, 600, 1.25, 1.0);
    struct abort_rec r = { .sp = { .rpm = 600, .z_min = 1e9, .lo = 100, .hi = -100 } };
    motion_set_spindle_revs(mc.m, 0, true);
    char err[400];
    ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    motion_start(mc.m);
    struct tm_stats st;
    tm_run(mc.m, DT, 20000, &st, abort_hook, &r);
    ck_assert(r.aborted);
    ck_assert_int_eq(st.last.state, MOTION_IDLE);
    /* 12.5 mm/s braked at 1000 mm/s^2: 0.078 mm further, one period's travel of slack */
    double z = st.last.pose[2];
    ck_assert_msg(z < r.z_abort && z > r.z_abort - 0.078 - 0.02, "stopped at %.4f after the "
                  "abort at %.4f", z, r.z_abort);
    ck_assert_msg(st.max_a_mm_s2 <= ACC * 1.001, "acceleration %.1f", st.max_a_mm_s2);
    struct motion_out o;
    motion_step(mc.m, DT, &o);         /* idle after the abort: the spindle is stopped */
    ck_assert_int_eq(o.spindle.dir, 0);
    ck_assert_double_eq_tol(o.pose[2], z, 1e-12);
    ck_assert(!r.sp.reversed);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* hexcnc check's ideal spindle: no encoder, the commanded speed reached at [SPINDLE_SYNC]
 * ACCELERATION (from rest here): the tap runs to its end, runs on K rps^2 / 2a past the
 * bottom, and ends at its start with the spindle forward again. */
START_TEST(test_ideal_spindle)
{
    struct tm_machine mc;
    open_trivial(&mc);
    motion_set_spindle_ideal(mc.m, true);
    const double top[6] = { 0, 0, 10, 0, 0, 0 }, bottom[6] = { 0, 0, 0, 0, 0, 0 };
    struct canon_prog p;
    tap_prog(&p, top, bottom, 600, 1.25, 2.0);
    char err[400];
    ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    motion_start(mc.m);
    struct tm_stats st;
    double z_min = 1e9;
    motion_step(mc.m, DT, &st.last);
    for (int k = 0; k < 20000 && st.last.state == MOTION_RUNNING; k++) {
        motion_step(mc.m, DT, &st.last);
        z_min = fmin(z_min, st.last.pose[2]);
    }
    ck_assert_int_eq(st.last.state, MOTION_DONE);
    double run_on = 1.25 * 10.0 * 10.0 / (2 * SPINDLE_ACC / 60.0);
    ck_assert_msg(-z_min > run_on - 0.001 && -z_min < run_on + 0.02, "z min %.4f", z_min);
    ck_assert_double_eq_tol(st.last.pose[2], 10, 1e-9);
    ck_assert_int_eq(st.last.spindle.dir, 1);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* A pause in the middle of the way in waits until the tap is over (a tap cannot stop in the
 * hole while the spindle turns): the tool comes out to its start and the machine pauses
 * there, before the move after the tap. */
static int pause_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    struct abort_rec *r = ctx;
    spindle_hook(m, o, step, &r->sp);
    if (!r->aborted && o->pose[2] < (r->z_abort != 0 ? r->z_abort : 5)) {
        r->aborted = 1;
        motion_pause(m);
    }
    return o->state == MOTION_PAUSED;
}

START_TEST(test_pause_waits_for_tap)
{
    struct tm_machine mc;
    open_trivial(&mc);
    const double top[6] = { 0, 0, 10, 0, 0, 0 }, bottom[6] = { 0, 0, 0, 0, 0, 0 };
    const double aside[6] = { 5, 0, 10, 0, 0, 0 };
    struct canon_prog p;
    tap_prog(&p, top, bottom, 600, 1.25, 1.0);
    p.count--;                         /* the program's end goes after one more move */
    tm_add(&p, CANON_TRAVERSE, 3, aside, 0, 0);
    tm_add(&p, CANON_PROGRAM_END, 4, NULL, 0, 2);
    struct abort_rec r = { .sp = { .rpm = 600, .z_min = 1e9, .lo = 100, .hi = -100 } };
    motion_set_spindle_revs(mc.m, 0, true);
    char err[400];
    ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    motion_start(mc.m);
    struct tm_stats st;
    tm_run(mc.m, DT, 20000, &st, pause_hook, &r);
    ck_assert(r.aborted);
    ck_assert_int_eq(st.last.state, MOTION_PAUSED);
    ck_assert(r.sp.reversed && r.sp.restored);
    ck_assert_msg(r.sp.z_min < -1.8, "the tap went to its bottom and beyond: %.4f", r.sp.z_min);
    ck_assert_double_eq_tol(st.last.pose[2], 10, 1e-9);
    ck_assert_double_eq_tol(st.last.pose[0], 0, 1e-9);
    motion_resume(mc.m);
    tm_run(mc.m, DT, 20000, &st, spindle_hook, &r.sp);
    ck_assert_int_eq(st.last.state, MOTION_DONE);
    ck_assert_double_eq_tol(st.last.pose[0], 5, 1e-9);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* Streamed (the machine session): 4,000 taps in one place, their ways in and out, cut into
 * windows of about 2,048 commands wherever the planner likes: after a way in (then the way
 * out is the next window's: so it was at all three cuts when this was written) or after a
 * way out. Every tap reverses the
 * spindle, none runs on deeper than its spindle's stop, and the program ends at the top. */
struct stream_rec {
    struct spindle sp;
    struct motion_stream *s;
    const struct canon_prog *p;
    size_t next;
    int reversals, last_dir;
};

static int stream_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    struct stream_rec *r = ctx;
    spindle_hook(m, o, step, &r->sp);
    if (o->spindle.dir < 0 && r->last_dir > 0)
        r->reversals++;
    r->last_dir = o->spindle.dir;
    while (r->next < r->p->count && motion_stream_backlog(r->s) < 2) {
        ck_assert_int_eq(motion_stream_add(r->s, &r->p->cmds[r->next++]), MOTION_OK);
        if (r->next == r->p->count)
            ck_assert_int_eq(motion_stream_finish(r->s), MOTION_OK);
    }
    return 0;
}

START_TEST(test_streamed_taps)
{
    struct tm_machine mc;
    open_trivial(&mc);
    const double top[6] = { 0, 0, 10, 0, 0, 0 }, bottom[6] = { 0, 0, 9, 0, 0, 0 };
    struct canon_prog p;
    spindle_prog(&p, top, 600);
    enum { TAPS = 4000 };
    for (int i = 0; i < TAPS; i++) {
        add_sync(&p, 2 + i, bottom, CANON_SYNC_TAP_IN, 0.5, 1.0);
        add_sync(&p, 2 + i, top, CANON_SYNC_TAP_OUT, 0.5, 1.0);
    }
    tm_add(&p, CANON_PROGRAM_END, 2 + TAPS, NULL, 0, 2);
    motion_set_spindle_revs(mc.m, 0, true);
    struct stream_rec r = { .sp = { .rpm = 600, .z_min = 1e9, .lo = 100, .hi = -100 },
                            .p = &p, .last_dir = 1 };
    char err[400] = "";
    ck_assert_msg(motion_stream_create(mc.m, p.start, NULL, &r.s, err, sizeof err) ==
                  MOTION_OK, "%s", err);
    ck_assert_int_eq(motion_stream_attach(mc.m, r.s, NULL), MOTION_OK);
    stream_hook(mc.m, &(struct motion_out){ .pose = { 0, 0, 10 }, .spindle = { .dir = 1,
                                                                        .rpm = 600 } }, 1, &r);
    ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
    struct tm_stats st;
    tm_run(mc.m, DT, 8000000, &st, stream_hook, &r);
    ck_assert_msg(st.last.state == MOTION_DONE, "state %d: %s", st.last.state,
                  motion_last_error(mc.m));
    struct motion_stream_info si;
    motion_stream_info(r.s, &si);
    printf("streamed taps: %zu windows, %d reversals, %.1f s, deepest %.4f\n", si.windows,
           r.reversals, st.t_s, r.sp.z_min);
    ck_assert_uint_gt(si.windows, 2);
    ck_assert_int_eq(r.reversals, TAPS);
    double run_on = 0.5 * 10.0 * 10.0 / (2 * SPINDLE_ACC / 60.0);
    ck_assert_msg(r.sp.z_min > 9 - run_on - 0.02 && r.sp.z_min < 9 - run_on + 0.001,
                  "deepest %.4f", r.sp.z_min);
    ck_assert_double_eq_tol(st.last.pose[2], 10, 1e-9);
    ck_assert_msg(st.max_a_mm_s2 <= ACC * 1.001, "acceleration %.1f", st.max_a_mm_s2);
    motion_stream_detach(mc.m);
    motion_stream_destroy(r.s);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* A pause during a G33 that another follows at once waits until the last of them has
 * ended (at the corner between them the spindle would run ahead of the thread). */
START_TEST(test_pause_after_chain)
{
    struct tm_machine mc;
    open_trivial(&mc);
    const double top[6] = { 0, 0, 10, 0, 0, 0 }, mid[6] = { 0, 0, 5, 0, 0, 0 };
    const double out[6] = { 2, 0, 3, 0, 0, 0 }, aside[6] = { 5, 0, 10, 0, 0, 0 };
    struct canon_prog p;
    spindle_prog(&p, top, 600);
    add_sync(&p, 2, mid, CANON_SYNC_THREAD, 1.5, 1);
    add_sync(&p, 3, out, CANON_SYNC_THREAD, 1.5 * sqrt(2), 1);
    tm_add(&p, CANON_TRAVERSE, 4, aside, 0, 0);
    tm_add(&p, CANON_PROGRAM_END, 5, NULL, 0, 2);
    struct abort_rec r = { .sp = { .rpm = 600, .z_min = 1e9, .lo = 100, .hi = -100 },
                           .z_abort = 8 };
    motion_set_spindle_revs(mc.m, 0, true);
    char err[400];
    ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    motion_start(mc.m);
    struct tm_stats st;
    tm_run(mc.m, DT, 20000, &st, pause_hook, &r);    /* pauses once z < 8: on line 2 */
    ck_assert(r.aborted);
    ck_assert_int_eq(st.last.state, MOTION_PAUSED);
    ck_assert_double_eq_tol(st.last.pose[0], 2, 1e-9);
    ck_assert_double_eq_tol(st.last.pose[2], 3, 1e-9);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* The spindle with an encoder that has an index (as sim-spindle with index-enable connected):
 * a set spindle.0.index-enable resets the count to 0 at the next whole revolution and clears
 * itself, unless the index is broken (it never comes). */
struct indexed {
    double rpm, revs;
    bool pin, broken;
    int sets, clears, cancels;
    double k_mm, c_min, c_max;   /* z + K revs while following (between Z8 and Z0.2) */
    double z_min;
};

static int indexed_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    struct indexed *s = ctx;
    (void)step;
    if (o->spindle_index > 0)
        s->pin = true, s->sets++;
    if (o->spindle_index < 0)
        s->pin = false, s->cancels++;
    double want = o->spindle.dir * o->spindle.rpm, diff = want - s->rpm, st = SPINDLE_ACC * DT;
    double r0 = s->revs, rpm0 = s->rpm;
    s->rpm += fabs(diff) <= st ? diff : copysign(st, diff);
    s->revs += 0.5 * (rpm0 + s->rpm) / 60.0 * DT;
    if (s->pin && !s->broken && floor(r0) != floor(s->revs)) {
        s->revs -= fmax(floor(r0), floor(s->revs));
        s->pin = false;
        s->clears++;
    }
    motion_set_spindle_revs(m, s->revs, true);
    motion_set_spindle_index(m, s->pin, true);
    double z = o->pose[2];
    s->z_min = fmin(s->z_min, z);
    if (z <= 8 && z >= 0.2 && o->spindle.dir > 0) {
        double c = z + s->k_mm * (s->revs - (rpm0 + s->rpm) / 120.0 * DT); /* the count read */
        s->c_min = fmin(s->c_min, c);
        s->c_max = fmax(s->c_max, c);
    }
    return o->state == MOTION_IDLE;
}

/* With the index handshake wired: the tap sets index-enable once, waits while it stays set,
 * and starts when the encoder clears it, from its count of 0 (z + K revs = the start, within
 * 1 um); with a broken index it waits at the start while the spindle turns two revolutions
 * (0.2 s at 600 rpm), then withdraws the pin and faults there with a message that says so.
 * Before the index time-out a broken index kept the machine waiting, pin set, until an abort:
 * the fault's assertions fail on that code. */
START_TEST(test_index_handshake)
{
    const double top[6] = { 0, 0, 10, 0, 0, 0 }, bottom[6] = { 0, 0, 0, 0, 0, 0 };
    for (int broken = 0; broken < 2; broken++) {
        struct tm_machine mc;
        open_trivial(&mc);
        struct canon_prog p;
        tap_prog(&p, top, bottom, 600, 1.25, 1.0);
        struct indexed s = { .rpm = 600, .revs = 0.37, .broken = broken, .k_mm = 1.25,
                             .c_min = 1e9, .c_max = -1e9, .z_min = 1e9 };
        motion_set_spindle_revs(mc.m, s.revs, true);
        motion_set_spindle_index(mc.m, false, true);
        char err[400];
        ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
        motion_start(mc.m);
        struct tm_stats st;
        if (!broken) {
            tm_run(mc.m, DT, 20000, &st, indexed_hook, &s);
            ck_assert_int_eq(st.last.state, MOTION_DONE);
            ck_assert_int_eq(s.sets, 1);
            ck_assert_int_eq(s.clears, 1);
            ck_assert_int_eq(s.cancels, 0);
            ck_assert_msg(s.c_max - s.c_min < 0.001 && fabs(s.c_min - 10) < 0.001,
                          "z + K revs from %.6f to %.6f", s.c_min, s.c_max);
        } else {
            tm_run(mc.m, DT, 3000, &st, indexed_hook, &s);
            ck_assert_int_eq(st.last.state, MOTION_FAULT);
            ck_assert_int_eq(st.last.status, MOTION_ERR_INDEX);
            ck_assert_double_eq_tol(s.z_min, 10, 1e-12);
            ck_assert(!s.pin && s.sets == 1 && s.clears == 0 && s.cancels == 1);
            /* two revolutions after the request: 10 rev/s, so 0.2 s and a period or two */
            ck_assert_msg(s.revs > 0.37 + MOTION_INDEX_WAIT_REVS &&
                          s.revs < 0.37 + MOTION_INDEX_WAIT_REVS + 0.5 && st.steps < 400,
                          "faulted at %.3f revolutions, after %d periods", s.revs, st.steps);
            const char *msg = motion_last_error(mc.m);
            ck_assert_msg(strstr(msg, "index-enable") && strstr(msg, "no index pulse") &&
                          strstr(msg, ":2:") && strstr(msg, "tap (G33.1)"), "%s", msg);
            struct motion_out o;        /* it stays there, the spindle stopped */
            for (int k = 0; k < 100; k++) {
                motion_step(mc.m, DT, &o);
                indexed_hook(mc.m, &o, k, &s);
            }
            ck_assert_int_eq(o.state, MOTION_FAULT);
            ck_assert_int_eq(o.spindle.dir, 0);
            ck_assert_double_eq_tol(o.pose[2], 10, 1e-12);
            ck_assert(!s.pin && s.sets == 1);
        }
        canon_prog_free(&p);
        tm_close(&mc);
    }
}
END_TEST

static Suite *sync_suite(void)
{
    Suite *s = suite_create("motion_sync");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_tap_follows_spindle);
    tcase_add_test(tc, test_index_handshake);
    tcase_add_test(tc, test_tap_m4);
    tcase_add_test(tc, test_no_feedback_refused);
    tcase_add_test(tc, test_too_fast_refused);
    tcase_add_test(tc, test_run_on_out_of_reach_refused);
    tcase_add_test(tc, test_passes_in_phase);
    tcase_add_test(tc, test_abort_mid_tap);
    tcase_add_test(tc, test_ideal_spindle);
    tcase_add_test(tc, test_pause_waits_for_tap);
    tcase_add_test(tc, test_pause_after_chain);
    tcase_add_test(tc, test_streamed_taps);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(sync_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
