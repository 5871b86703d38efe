/* test_motion.c: planner and interpolator: trapezoids, arcs, dwell, rejection at load, config. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_priv.h"
#include "tests/test_motion_same.h"
#include "tests/test_motion_util.h"

#define DT 0.001

/* Opens the trivial machine or fails the test. */
static void open_trivial(struct tm_machine *mc)
{
    ck_assert_int_eq(tm_open(mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
}

/* Opens the TMU hexapod or fails the test. */
static void open_hexapod(struct tm_machine *mc)
{
    struct tk_cfg *c = tm_hexapod_cfg();
    ck_assert_msg(c != NULL, "cannot read configs/sim/tmu-hexapod.ini (HEXCNC_ROOT?)");
    ck_assert_int_eq(tm_open(mc, c, &kins_hexapod_ops), 0);
}

/* One 100 mm feed move at 50 mm/s, 1000 mm/s^2 on the trivial machine: a trapezoid with
 * 0.05 s ramps: 2.05 s. The run ends exactly on the end point, in the planned time, and
 * never exceeds the feed or the acceleration. */
START_TEST(test_trapezoid_trivial)
{
    struct tm_machine mc;
    open_trivial(&mc);
    struct canon_prog p;
    canon_prog_init(&p);
    double end[6] = {100, 0, 0, 0, 0, 0};
    tm_add(&p, CANON_FEED, 3, end, 3000, 0);
    tm_load_start(mc.m, &p);
    struct motion_plan_info info;
    ck_assert_int_eq(motion_plan_info(mc.m, &info), MOTION_OK);
    ck_assert_msg(fabs(info.time_s - 2.05) < 0.01, "planned %.4f s, ideal 2.05 s", info.time_s);
    struct tm_stats s;
    tm_run(mc.m, DT, 10000, &s, NULL, NULL);
    ck_assert_int_eq(s.last.state, MOTION_DONE);
    ck_assert_double_eq_tol(s.last.pose[0], 100, 1e-9);
    ck_assert_double_eq_tol(s.last.joint_pos[0], 100, 1e-9);
    ck_assert_msg(fabs(s.t_s - info.time_s) <= DT + 1e-9, "ran %.4f s, planned %.4f s", s.t_s,
                  info.time_s);
    ck_assert_msg(s.max_v_mm_s <= 50 * (1 + 1e-9), "speed %.6f > 50", s.max_v_mm_s);
    ck_assert_msg(s.max_v_mm_s > 49.99, "never reached the feed: %.4f", s.max_v_mm_s);
    ck_assert_msg(s.max_a_mm_s2 <= 1000 * (1 + 1e-6), "acceleration %.3f > 1000", s.max_a_mm_s2);
    ck_assert_int_eq(s.last.line, 3);
    ck_assert_double_eq_tol(s.last.distance_done_mm, 100, 1e-9);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* A short move never reaches the feed: a triangle, 2 sqrt(d / a) long. Rapids use the
 * machine's MAX_LINEAR_VELOCITY. */
START_TEST(test_triangle_and_rapid)
{
    struct tm_machine mc;
    open_trivial(&mc);
    struct canon_prog p;
    canon_prog_init(&p);
    p.start_path_mode = 610;                         /* exact stop: the ideal below */
    double a[6] = {0, 2, 0, 0, 0, 0}, b[6] = {0, 2, 300, 0, 0, 0};
    tm_add(&p, CANON_FEED, 1, a, 6000, 0);           /* 2 mm at up to 100 mm/s */
    tm_add(&p, CANON_TRAVERSE, 2, b, 0, 0);          /* 300 mm rapid at 100 mm/s */
    tm_load_start(mc.m, &p);
    struct motion_plan_info info;
    motion_plan_info(mc.m, &info);
    double tri = 2 * sqrt(2 / 1000.0), rapid = 300 / 100.0 + 100 / 1000.0;
    ck_assert_msg(fabs(info.time_s - (tri + rapid)) < 0.01 * (tri + rapid),
                  "planned %.4f s, ideal %.4f s", info.time_s, tri + rapid);
    struct tm_stats s;
    tm_run(mc.m, DT, 10000, &s, NULL, NULL);
    ck_assert_int_eq(s.last.state, MOTION_DONE);
    ck_assert_double_eq_tol(s.last.pose[2], 300, 1e-9);
    ck_assert(s.max_v_mm_s <= 100 * (1 + 1e-9) && s.max_v_mm_s > 99.9);
    ck_assert(s.max_a_mm_s2 <= 1000 * (1 + 1e-6));
    /* the same in G64 (a program's default): the square corner G1 -> G0 is planned as a
     * stop, so it takes no longer than in G61 (3.234 s when it was passed at 0.35 mm/s with
     * the moves beside it giving up half their acceleration) */
    double g61 = info.time_s;
    p.start_path_mode = 0;
    tm_load_start(mc.m, &p);
    motion_plan_info(mc.m, &info);
    ck_assert_msg(info.time_s <= g61 + 1e-9, "G64 %.6f s, G61 %.6f s", info.time_s, g61);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* A five-axis move on the TMU hexapod: ends exactly, in the planned time, within the path
 * feed and acceleration, the leg speeds within [JOINT_n] MAX_VELOCITY. */
START_TEST(test_trapezoid_hexapod)
{
    struct tm_machine mc;
    open_hexapod(&mc);
    struct canon_prog p;
    canon_prog_init(&p);
    double s0[6] = {0, 0, 645, 0, 0, 0}, e[6] = {60, -40, 660, 5, -4, 10};
    memcpy(p.start, s0, sizeof s0);
    tm_add(&p, CANON_FEED, 7, e, 1200, 0);
    tm_load_start(mc.m, &p);
    struct motion_plan_info info;
    motion_plan_info(mc.m, &info);
    struct tm_stats s;
    tm_run(mc.m, DT, 100000, &s, NULL, NULL);
    ck_assert_int_eq(s.last.state, MOTION_DONE);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(s.last.pose[i], e[i], 1e-9);
    double legs[6];
    kins_inverse(mc.kins, e, legs);
    for (int i = 0; i < 6; i++) {
        ck_assert_double_eq_tol(s.last.joint_pos[i], legs[i], 1e-9);
        ck_assert(s.max_leg_v[i] <= mc.mc.joint[i].max_vel_mm_s);
        ck_assert(s.max_leg_a[i] <= mc.mc.joint[i].max_acc_mm_s2 * (1 + 1e-6));
    }
    ck_assert(fabs(s.t_s - info.time_s) <= DT + 1e-9);
    ck_assert(s.max_v_mm_s <= 20 * (1 + 1e-9));
    ck_assert(s.max_a_mm_s2 <= mc.mc.max_lin_acc_mm_s2 * (1 + 1e-6));
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* Two TMU hexapods side by side and an empty program for both, starting at s0. */
static void two_machines(struct tm_machine *a, struct tm_machine *b, struct canon_prog *p,
                         const double s0[6])
{
    open_hexapod(a);
    open_hexapod(b);
    canon_prog_init(p);
    memcpy(p->start, s0, 6 * sizeof *s0);
}

/* motion_set_brief: the record's brief part is the same, bit for bit, as with the whole record
 * (two machines run the same five-axis program side by side), the rest is left as it was,
 * and the executor's own course does not change: both end together in the same place. */
START_TEST(test_brief_record)
{
    struct tm_machine a, b;
    struct canon_prog p;
    double s0[6] = {0, 0, 645, 0, 0, 0}, e1[6] = {30, -20, 650, 3, -2, 5},
           e2[6] = {-10, 15, 640, -2, 4, -6};
    two_machines(&a, &b, &p, s0);
    tm_add(&p, CANON_FEED, 3, e1, 1500, 0);
    tm_add(&p, CANON_FEED, 4, e2, 2000, 0);
    tm_load_start(a.m, &p);
    tm_load_start(b.m, &p);
    motion_set_brief(b.m, true);
    struct motion_out oa, ob;
    memset(&oa, 0, sizeof oa);
    memset(&ob, 0xff, sizeof ob);           /* (a NaN in every double the brief leaves) */
    long n = 0;
    do {
        ck_assert_int_eq(motion_step(a.m, DT, &oa), MOTION_OK);
        ck_assert_int_eq(motion_step(b.m, DT, &ob), MOTION_OK);
        same_brief(&oa, &ob);
        ck_assert(isnan(ob.time_remaining_s) && isnan(ob.pose_vel[0]) &&
                  isnan(ob.joint_vel[0]) && isnan(ob.motor_pos[0]) && isnan(ob.path_vel));
    } while (oa.state == MOTION_RUNNING && ++n < 100000);
    ck_assert_int_eq(oa.state, MOTION_DONE);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(ob.pose[i], e2[i], 1e-9);
    motion_set_brief(b.m, false);            /* off again: the whole record */
    ck_assert_int_eq(motion_step(b.m, DT, &ob), MOTION_OK);
    ck_assert(ob.time_remaining_s == 0 && ob.path_vel == 0);
    canon_prog_free(&p);
    tm_close(&a);
    tm_close(&b);
}
END_TEST

/* n feeds along a wandering five-axis curve from `from` (chords of about 0.5 mm at t step
 * 0.02, A B C turning), the end pose into at: dense CAM code, blended by a G64 before. */
static void add_curve(struct canon_prog *p, const double from[6], int n, double step, int line,
                      double at[6])
{
    for (int i = 0; i < n; i++) {
        double t = i * step;
        at[0] = from[0] + 20 * sin(t), at[1] = from[1] + 15 * sin(1.7 * t);
        at[2] = from[2] + 2 * sin(0.5 * t), at[3] = from[3] + 3 * sin(t);
        at[4] = from[4] + 2 * cos(0.8 * t) - 2, at[5] = from[5] + 4 * sin(0.3 * t);
        tm_add(p, CANON_FEED, line, at, 2000, 0);
    }
}

/* A look-ahead's entries were taken: more than twice as often as it filled, by at least
 * `least` periods or knots. */
static void ahead_taken(long taken, long fills, long least)
{
    ck_assert_msg(taken > 2 * fills && taken > least, "%ld fills, %ld taken (at least %ld)",
                  fills, taken, least);
}

/* The program the look-ahead's tests run on two TMU hexapods, a and b, loaded and started
 * with rates off in both, and b with the look-ahead and the brief record a check has:
 * blended and exact-stop five-axis feeds, an arc, dense code whose blend arcs turn A B C, a
 * dwell, an M0 and a last feed to e4; with spindle set, S1200 M3 at the start and M5 after
 * the arc. */
static void same_bits_program(struct tm_machine *a, struct tm_machine *b, struct canon_prog *p,
                              int spindle, double e4[6])
{
    double s0[6] = {0, 0, 645, 0, 0, 0}, e1[6] = {30, -20, 650, 3, -2, 5},
           e2[6] = {-10, 15, 640, -2, 4, -6}, e3[6] = {-10, 35, 640, -2, 4, -6},
           c3[3] = {-10, 25, 640}, n3[3] = {0, 0, 1}, end[6] = {5, 5, 645, 0, 0, 0};
    memcpy(e4, end, sizeof end);
    two_machines(a, b, p, s0);
    struct canon_cmd pm = {.type = CANON_PATH_MODE, .line = 2, .file = "test.ngc",
                           .value = 0.01, .ivalue = 640};
    ck_assert_int_eq(canon_prog_sink(p, &pm), 0);
    struct canon_cmd sp[3] = {{.type = CANON_SPINDLE_SPEED, .line = 2, .file = "test.ngc",
                               .value = 1200},
                              {.type = CANON_SPINDLE_ON, .line = 2, .file = "test.ngc",
                               .value = 1},
                              {.type = CANON_SPINDLE_STOP, .line = 5, .file = "test.ngc"}};
    if (spindle)
        ck_assert(canon_prog_sink(p, &sp[0]) == 0 && canon_prog_sink(p, &sp[1]) == 0);
    tm_add(p, CANON_FEED, 3, e1, 1500, 0);
    tm_add(p, CANON_FEED, 4, e2, 2000, 0);
    tm_arc(p, 5, e3, c3, n3, 1, 1800);
    if (spindle)
        ck_assert_int_eq(canon_prog_sink(p, &sp[2]), 0);
    double at[6];
    add_curve(p, e3, 120, 0.05, 5, at);         /* dense code: blend arcs turning A B C */
    tm_add(p, CANON_DWELL, 6, NULL, 0, 0.25);
    tm_add(p, CANON_PAUSE, 7, NULL, 0, 0);
    tm_add(p, CANON_FEED, 8, end, 2400, 0);
    tm_load_start(a->m, p);
    tm_load_start(b->m, p);
    motion_set_rates(a->m, false);
    motion_set_rates(b->m, false);
    motion_set_ahead(b->m, true);
    motion_set_brief(b->m, true);
}

/* The check's look-ahead (motion_set_ahead: eight periods' poses and legs ahead) and its
 * short period (motion_step's calm_period, with the brief record a check reads) change
 * nothing a period gives: two machines side by side, rates off in both, the look-ahead and
 * the brief record on in one, through blended and exact-stop five-axis feeds, an arc, dense
 * code whose blend arcs turn A B C (four periods' poses on one segment as vectors), a dwell
 * and an M0, with the feed override raised and lowered again and a pause and a resume on
 * the way: the record's brief part, the executor's clock, place, speeds and legs equal bit
 * for bit in every period; at the plan's pace the periods took the entries filled before
 * them, and most took the short way. */
START_TEST(test_ahead_same_bits)
{
    struct tm_machine a, b;
    struct canon_prog p;
    double e4[6];
    same_bits_program(&a, &b, &p, 0, e4);
    struct motion_out oa, ob;
    memset(&oa, 0, sizeof oa);
    long n = 0, paused = 0;
    do {
        if (n == 700 || n == 1100)
            ck_assert(motion_set_feed_override(a.m, n == 700 ? 1.5 : 1.0) == MOTION_OK &&
                      motion_set_feed_override(b.m, n == 700 ? 1.5 : 1.0) == MOTION_OK);
        if (n == 1500)
            ck_assert(motion_pause(a.m) == MOTION_OK && motion_pause(b.m) == MOTION_OK);
        if (oa.state == MOTION_PAUSED && n > 1500) {       /* the pause, and then the M0 */
            paused++;
            ck_assert(motion_resume(a.m) == MOTION_OK && motion_resume(b.m) == MOTION_OK);
        }
        ck_assert_int_eq(motion_step(a.m, DT, &oa), MOTION_OK);
        ck_assert_int_eq(motion_step(b.m, DT, &ob), MOTION_OK);
        same_executor(a.m, b.m);
        same_brief(&oa, &ob);
    } while ((oa.state == MOTION_RUNNING || oa.state == MOTION_PAUSING ||
              oa.state == MOTION_PAUSED) && ++n < 200000);
    ck_assert_int_eq(oa.state, MOTION_DONE);
    ck_assert_int_ge(paused, 2);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(ob.pose[i], e4[i], 1e-9);
    /* at the plan's pace seven periods in eight take an entry filled before them */
    ahead_taken(b.m->ahead.taken, b.m->ahead.fills, n / 2);
    ck_assert_msg(b.m->ahead.calm > n / 2, "%ld of %ld periods the short way", b.m->ahead.calm, n);
    ck_assert_int_eq(a.m->ahead.fills, 0);
    ck_assert_int_eq(a.m->ahead.calm, 0);
    canon_prog_free(&p);
    tm_close(&a);
    tm_close(&b);
}
END_TEST

/* A check's calm periods taken several at a time (motion_step_calm) are the periods
 * motion_step gives one by one: the program of test_ahead_same_bits, with the ideal spindle
 * a check has started by S1200 M3 and stopped by M5 on the way, on two machines, one
 * stepping period by period, the other taking runs of calm periods wherever it can; every
 * period's record equals the other's bit for bit (its brief part), and at the end of every
 * run the executors stand at the same place with the same values, the spindle's turns
 * among them. The feed override is raised and lowered and a pause and a resume given where
 * the second machine stands at a period (between runs); most periods were taken in runs. */
START_TEST(test_calm_same_bits)
{
    struct tm_machine a, b;
    struct canon_prog p;
    double e4[6];
    same_bits_program(&a, &b, &p, 1, e4);
    motion_set_spindle_ideal(a.m, true);
    motion_set_spindle_ideal(b.m, true);
    motion_set_brief(a.m, true);
    struct calm_feed f = { .on = 1 };
    struct motion_out oa, ob;
    long n = 0, paused = 0;
    memset(&oa, 0, sizeof oa);
    int step = 0, in_step = 1;
    double revs = 0;
    do {
        /* (the operator's commands where the second machine stands at the period) */
        if (in_step && step < 3 && n >= (long[]){ 700, 1100, 1500 }[step]) {
            if (step < 2)
                ck_assert(motion_set_feed_override(a.m, step == 0 ? 1.5 : 1.0) == MOTION_OK &&
                          motion_set_feed_override(b.m, step == 0 ? 1.5 : 1.0) == MOTION_OK);
            else
                ck_assert(motion_pause(a.m) == MOTION_OK && motion_pause(b.m) == MOTION_OK);
            step++;
        }
        if (oa.state == MOTION_PAUSED && step == 3) {      /* the pause, and then the M0 */
            ck_assert(in_step);
            paused++;
            ck_assert(motion_resume(a.m) == MOTION_OK && motion_resume(b.m) == MOTION_OK);
        }
        ck_assert_int_eq(motion_step(a.m, DT, &oa), MOTION_OK);
        ck_assert_int_eq(calm_next(b.m, DT, &f, &ob, &in_step), MOTION_OK);
        same_brief(&oa, &ob);
        if (in_step) {
            same_executor(a.m, b.m);
            ck_assert(a.m->spindle_revs == b.m->spindle_revs &&
                      a.m->ideal_rps == b.m->ideal_rps && a.m->sync.phase == b.m->sync.phase);
            revs = a.m->spindle_revs;
        }
    } while ((oa.state == MOTION_RUNNING || oa.state == MOTION_PAUSING ||
              oa.state == MOTION_PAUSED) && ++n < 200000);
    ck_assert_int_eq(oa.state, MOTION_DONE);
    ck_assert(in_step);
    ck_assert_int_eq(step, 3);
    ck_assert_int_ge(paused, 2);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(ob.pose[i], e4[i], 1e-9);
    /* most periods in runs, of more than two periods on average */
    ck_assert_msg(f.periods > n / 2 && f.periods > 2 * f.runs, "%ld periods in %ld runs of "
                  "%ld", f.periods, f.runs, n);
    ck_assert_int_eq(b.m->ahead.calm, f.periods);
    ck_assert_msg(revs > 10 && a.m->ideal_rps == 0, "%.3f turns, %.3f rev/s at the end", revs,
                  a.m->ideal_rps);
    canon_prog_free(&p);
    tm_close(&a);
    tm_close(&b);
}
END_TEST

/* The planner's look-ahead over knots (four knots' kinematics at once) changes no plan: two
 * machines plan the same program, dense blended five-axis feeds, an arc, a dwell and exact
 * stops, the look-ahead off in one; every knot's place, speeds, caps and every interval's
 * acceleration are equal bit for bit, and the look-ahead's entries were taken. */
START_TEST(test_knot_ahead_same_plan)
{
    struct tm_machine a, b;
    struct canon_prog p;
    double s0[6] = {0, 0, 645, 0, 0, 0}, at[6], c3[3], n3[3] = {0, 0, 1};
    two_machines(&a, &b, &p, s0);
    b.m->kahead.off = 1;
    struct canon_cmd pm = {.type = CANON_PATH_MODE, .line = 2, .file = "test.ngc",
                           .value = 0.01, .ivalue = 640};
    ck_assert_int_eq(canon_prog_sink(&p, &pm), 0);
    double c6[6] = {0, 0, 645, 0, 8, 0};
    add_curve(&p, c6, 300, 0.02, 3, at);        /* a curve of 0.5 mm chords, turning */
    memcpy(c3, at, sizeof c3);
    c3[1] += 5;
    double e3[6];
    memcpy(e3, at, sizeof e3);
    e3[1] += 10;
    tm_arc(&p, 400, e3, c3, n3, 1, 1800);
    tm_add(&p, CANON_DWELL, 401, NULL, 0, 0.1);
    e3[0] += 8, e3[5] += 2;
    tm_add(&p, CANON_FEED, 402, e3, 1500, 0);
    tm_load_start(a.m, &p);
    tm_load_start(b.m, &p);
    const struct motion_plan *pa = &a.m->plan, *pb = &b.m->plan;
    ck_assert_uint_eq(pa->nknot, pb->nknot);
    size_t nk = pa->nknot;
    ck_assert(!memcmp(pa->ks, pb->ks, nk * sizeof *pa->ks));
    ck_assert(!memcmp(pa->kv, pb->kv, nk * sizeof *pa->kv));
    ck_assert(!memcmp(pa->kt, pb->kt, nk * sizeof *pa->kt));
    ck_assert(!memcmp(pa->krho, pb->krho, nk * sizeof *pa->krho));
    ck_assert(!memcmp(pa->iacc, pb->iacc, nk * sizeof *pa->iacc));
    ck_assert(!memcmp(pa->irho, pb->irho, nk * sizeof *pa->irho));
    ck_assert(!memcmp(pa->ivp, pb->ivp, nk * sizeof *pa->ivp));
    ck_assert(pa->total_time_s == pb->total_time_s);
    ahead_taken(a.m->kahead.taken, a.m->kahead.fills, (long)nk / 2);
    ck_assert_int_eq(b.m->kahead.fills, 0);
    canon_prog_free(&p);
    tm_close(&a);
    tm_close(&b);
}
END_TEST

/* The status's segment values (line, the move's ends, its kind) are taken once per segment:
 * a second program loaded into the same instance, whose plan may lie where the first's did,
 * reports its own from its first period on. */
START_TEST(test_segment_values_per_program)
{
    struct tm_machine a;
    open_hexapod(&a);
    double s0[6] = {0, 0, 645, 0, 0, 0}, e1[6] = {20, 0, 645, 0, 0, 0},
           e2[6] = {0, 20, 645, 0, 0, 0};
    struct motion_out o;
    for (int run = 0; run < 2; run++) {
        struct canon_prog p;
        canon_prog_init(&p);
        memcpy(p.start, s0, sizeof s0);
        tm_add(&p, CANON_FEED, run ? 7 : 3, run ? e2 : e1, 1500, 0);
        tm_load_start(a.m, &p);
        long n = 0;
        do {
            ck_assert_int_eq(motion_step(a.m, DT, &o), MOTION_OK);
            ck_assert_int_eq(o.line, run ? 7 : 3);
            ck_assert(!memcmp(o.seg_to, run ? e2 : e1, sizeof o.seg_to));
            ck_assert_int_eq(o.seg_kind, 1);
        } while (o.state == MOTION_RUNNING && ++n < 100000);
        ck_assert_int_eq(o.state, MOTION_DONE);
        canon_prog_free(&p);
    }
    tm_close(&a);
}
END_TEST

/* Largest distance of the run's XYZ from a circle of radius r about c in the plane normal n,
 * and largest distance from that plane (for a planar arc). */
struct arc_check { double c[3], n[3], r, max_rad_err, max_plane_err; };
static int arc_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    struct arc_check *a = ctx;
    double d[3], h = 0, q = 0;
    for (int i = 0; i < 3; i++)
        d[i] = o->pose[i] - a->c[i], h += d[i] * a->n[i];
    for (int i = 0; i < 3; i++)
        q += (d[i] - h * a->n[i]) * (d[i] - h * a->n[i]);
    a->max_rad_err = fmax(a->max_rad_err, fabs(sqrt(q) - a->r));
    a->max_plane_err = fmax(a->max_plane_err, fabs(h));
    return 0;
}

/* G17 arc: a half circle of radius 20 stays on its radius and ends at its end point, in
 * about pi r / v; a 3-D arc about a tilted normal (as G141/G142 corners) does too. */
START_TEST(test_arcs)
{
    struct tm_machine mc;
    open_trivial(&mc);
    struct canon_prog p;
    canon_prog_init(&p);
    double e1[6] = {40, 0, 0, 0, 0, 0}, c1[3] = {20, 0, 0}, n1[3] = {0, 0, 1};
    tm_arc(&p, 5, e1, c1, n1, -1, 1200);     /* G2 from (0,0) over the top to (40,0) */
    tm_load_start(mc.m, &p);
    struct arc_check ac = {{20, 0, 0}, {0, 0, 1}, 20, 0, 0};
    struct tm_stats s;
    tm_run(mc.m, DT, 100000, &s, arc_hook, &ac);
    ck_assert_int_eq(s.last.state, MOTION_DONE);
    ck_assert_double_eq_tol(s.last.pose[0], 40, 1e-9);
    ck_assert_double_eq_tol(s.last.pose[1], 0, 1e-9);
    ck_assert_msg(ac.max_rad_err < 1e-9 && ac.max_plane_err < 1e-9, "off the arc by %g",
                  ac.max_rad_err);
    ck_assert_msg(fabs(s.t_s - M_PI * 20 / 20.0) < 0.1, "half circle took %.3f s", s.t_s);
    canon_prog_free(&p);
    /* clockwise about +Z from (0,0): passes y > 0 */
    canon_prog_init(&p);
    double nt[3] = {0, sin(0.3), cos(0.3)}, ct[3] = {10, 0, 0}, et[6] = {20, 0, 0, 0, 0, 0};
    tm_arc(&p, 6, et, ct, nt, 1, 600);       /* a plane-0 arc with a tilted normal */
    tm_load_start(mc.m, &p);
    struct arc_check at = {{10, 0, 0}, {0, sin(0.3), cos(0.3)}, 10, 0, 0};
    tm_run(mc.m, DT, 100000, &s, arc_hook, &at);
    ck_assert_int_eq(s.last.state, MOTION_DONE);
    ck_assert_double_eq_tol(s.last.pose[0], 20, 1e-9);
    ck_assert(at.max_rad_err < 1e-9 && at.max_plane_err < 1e-9);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* Helix: two full turns of radius 5 rising 4 mm: ends on its end point, the height rises in
 * proportion to the angle, the radius holds. */
static int helix_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    double *worst = ctx, x = o->pose[0], y = o->pose[1];
    worst[0] = fmax(worst[0], fabs(sqrt(x * x + y * y) - 5));
    if (o->pose[2] < worst[1] - 1e-12)
        worst[2] = 1;                          /* Z went down: not a rising helix */
    worst[1] = o->pose[2];
    return 0;
}
START_TEST(test_helix)
{
    struct tm_machine mc;
    open_trivial(&mc);
    struct canon_prog p;
    canon_prog_init(&p);
    p.start[0] = 5;
    double e[6] = {5, 0, 4, 0, 0, 0}, c[3] = {0, 0, 0}, n[3] = {0, 0, 1};
    tm_arc(&p, 9, e, c, n, 2, 600);           /* G3 with P2: two turns */
    tm_load_start(mc.m, &p);
    struct motion_plan_info info;
    motion_plan_info(mc.m, &info);
    double len = sqrt(pow(4 * M_PI * 5, 2) + 16);
    ck_assert_double_eq_tol(info.length_mm, len, 1e-6);
    double worst[3] = {0, 0, 0};
    struct tm_stats s;
    tm_run(mc.m, DT, 100000, &s, helix_hook, worst);
    ck_assert_int_eq(s.last.state, MOTION_DONE);
    ck_assert_double_eq_tol(s.last.pose[0], 5, 1e-9);
    ck_assert_double_eq_tol(s.last.pose[2], 4, 1e-9);
    ck_assert(worst[0] < 1e-9);
    ck_assert(worst[2] == 0);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* G4 P1.5 between two moves: the machine holds still for 1.5 s, and the plan counts it. */
static int dwell_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    double *still = ctx;
    if (o->line == 2 && o->path_vel == 0)
        *still += DT;
    return 0;
}
START_TEST(test_dwell)
{
    struct tm_machine mc;
    open_trivial(&mc);
    struct canon_prog p;
    canon_prog_init(&p);
    double a[6] = {10, 0, 0, 0, 0, 0}, b[6] = {20, 0, 0, 0, 0, 0};
    tm_add(&p, CANON_FEED, 1, a, 600, 0);
    tm_add(&p, CANON_DWELL, 2, NULL, 0, 1.5);
    tm_add(&p, CANON_FEED, 3, b, 600, 0);
    tm_add(&p, CANON_PROGRAM_END, 4, NULL, 0, 0);
    tm_load_start(mc.m, &p);
    struct motion_plan_info info;
    motion_plan_info(mc.m, &info);
    double move = 10 / 10.0 + 10 / 1000.0;   /* each: 1 s cruise + one ramp's worth */
    ck_assert_double_eq_tol(info.time_s, 2 * move + 1.5, 0.01);
    double still = 0;
    struct tm_stats s;
    tm_run(mc.m, DT, 100000, &s, dwell_hook, &still);
    ck_assert_int_eq(s.last.state, MOTION_DONE);
    ck_assert_msg(fabs(still - 1.5) <= 2 * DT, "held %.4f s at the dwell", still);
    ck_assert_double_eq_tol(s.last.pose[0], 20, 1e-9);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* A move that leaves the workspace in its middle (both ends reachable) is refused at load,
 * naming the line, before any motion; so is a line to an unreachable end. At Z 645 the legs
 * are 725 mm; a full circle in the XZ plane about (10, 0, 795) rises to Z 945, where they
 * would be over 1000 mm, beyond the 980 mm limit. */
START_TEST(test_unreachable_mid_move)
{
    struct tm_machine mc;
    open_hexapod(&mc);
    struct canon_prog p;
    canon_prog_init(&p);
    double s0[6] = {0, 0, 645, 0, 0, 0}, a[6] = {10, 0, 645, 0, 0, 0}, L[6];
    memcpy(p.start, s0, sizeof s0);
    tm_add(&p, CANON_FEED, 11, a, 600, 0);
    double c[3] = {10, 0, 795}, n[3] = {0, 1, 0};
    tm_arc(&p, 12, a, c, n, 1, 600);          /* G18 full circle back to its start */
    ck_assert_int_eq(kins_inverse(mc.kins, a, L), KINS_OK);
    char err[512] = "";
    int st = motion_load(mc.m, &p, err, sizeof err);
    ck_assert_int_eq(st, MOTION_ERR_UNREACHABLE);
    ck_assert_msg(strstr(err, "test.ngc:12:") && strstr(err, "beyond its maximum of 980"),
                  "message: %s", err);
    ck_assert_int_eq(motion_start(mc.m), MOTION_ERR_STATE);
    struct motion_out o;
    motion_step(mc.m, DT, &o);
    ck_assert_int_eq(o.state, MOTION_IDLE);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(o.pose[i], mc.kins->home[i], 1e-12);   /* never moved */
    canon_prog_free(&p);
    canon_prog_init(&p);
    memcpy(p.start, s0, sizeof s0);
    double up[6] = {0, 0, 1000, 0, 0, 0};
    tm_add(&p, CANON_TRAVERSE, 20, a, 0, 0);
    tm_add(&p, CANON_FEED, 21, up, 600, 0);
    st = motion_load(mc.m, &p, err, sizeof err);
    ck_assert_int_eq(st, MOTION_ERR_UNREACHABLE);
    ck_assert_msg(strstr(err, "test.ngc:21:"), "message: %s", err);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* Lowest path speed seen while the line number is `line` or `line + 1` (around a joint). */
struct joint_watch { int line; double min_v; double t_started; };
static int joint_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    struct joint_watch *w = ctx;
    if ((o->line == w->line && o->distance_done_mm > 5) ||
        (o->line == w->line + 1 && o->distance_done_mm < 15))
        w->min_v = fmin(w->min_v, o->path_vel);
    return 0;
}

/* Runs X0 -> X10 -> second end at 1200 mm/min (20 mm/s) in path mode `blend` (0 = G61);
 * returns the lowest speed around the joint. */
static double joint_speed(double blend, int gcode, const double *second)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
    struct canon_prog p;
    canon_prog_init(&p);
    double a[6] = {10, 0, 0, 0, 0, 0};
    struct canon_cmd pm = {.type = CANON_PATH_MODE, .line = 1, .file = "test.ngc",
                           .value = blend, .ivalue = gcode};
    canon_prog_sink(&p, &pm);
    tm_add(&p, CANON_FEED, 2, a, 1200, 0);
    tm_add(&p, CANON_FEED, 3, second, 1200, 0);
    tm_load_start(mc.m, &p);
    struct joint_watch w = {2, 1e9, 0};
    struct tm_stats s;
    tm_run(mc.m, DT, 100000, &s, joint_hook, &w);
    ck_assert_int_eq(s.last.state, MOTION_DONE);
    ck_assert_double_eq_tol(s.last.pose[0], second[0], 1e-9);
    ck_assert_double_eq_tol(s.last.pose[1], second[1], 1e-9);
    ck_assert(s.max_a_mm_s2 <= 1000 * (1 + 1e-6));
    canon_prog_free(&p);
    tm_close(&mc);
    return w.min_v;
}

/* G61 stops at every joint; G64 (with P, or without: [TRAJ]BLEND_TOLERANCE) passes a
 * collinear joint at the feed and rounds a square corner (motion_blend.c) with an arc of
 * radius P / (sqrt 2 - 1), run at its centripetal limit sqrt(a r / 2). */
START_TEST(test_blend)
{
    double straight[6] = {20, 0, 0, 0, 0, 0}, corner[6] = {10, 10, 0, 0, 0, 0};
    ck_assert_double_eq_tol(joint_speed(0, 610, straight), 0, 1e-9);
    ck_assert_msg(joint_speed(0.01, 640, straight) > 20 * (1 - 1e-9), "collinear joint slowed");
    ck_assert_msg(joint_speed(0, 640, straight) > 20 * (1 - 1e-9), "G64 without P stopped");
    double v = joint_speed(0.01, 640, corner), r = 0.01 / (sqrt(2) - 1);
    ck_assert_msg(fabs(v - sqrt(0.5 * 1000 * r)) < 0.01, "corner passed at %.3f mm/s", v);
}
END_TEST

/* G93 inverse time: a 10 mm move in 0.01 min runs at 16.7 mm/s; a rotary-only move runs at
 * its feed in deg/min (600 deg/min: 30 deg in about 3 s). */
START_TEST(test_inverse_time_and_rotary)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
    struct canon_prog p;
    canon_prog_init(&p);
    struct canon_cmd c = {.type = CANON_FEED, .line = 1, .file = "t.ngc", .feed_mm_min = 99,
                          .inverse_time_min = 0.01, .end = {10, 0, 0, 0, 0, 0}};
    canon_prog_sink(&p, &c);
    tm_load_start(mc.m, &p);
    struct tm_stats s;
    tm_run(mc.m, DT, 100000, &s, NULL, NULL);
    ck_assert_double_eq_tol(s.max_v_mm_s, 10 / 0.6, 1e-6);
    ck_assert_double_eq_tol(s.t_s, 0.6 + 10 / 0.6 / 1000, 0.005);
    canon_prog_free(&p);
    canon_prog_init(&p);
    double r[6] = {0, 0, 0, 30, 0, 0};
    tm_add(&p, CANON_FEED, 2, r, 600, 0);
    tm_load_start(mc.m, &p);
    tm_run(mc.m, DT, 100000, &s, NULL, NULL);
    ck_assert_double_eq_tol(s.last.pose[3], 30, 1e-9);
    ck_assert_double_eq_tol(s.t_s, 3 + 10 / 900.0, 0.005);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* Configuration: keys read, a bad value named with its section and key. */
START_TEST(test_config)
{
    struct tk_cfg *c = tm_trivial_cfg();
    struct kins_config kc = tk_config(c);
    struct motion_config mcfg;
    char err[256] = "";
    motion_config_default(&mcfg);
    tk_set(c, "EMCMOT", "SERVO_PERIOD", "250000");
    tk_set(c, "TRAJ", "SETPOINT_PERIOD", "10000000");
    tk_set(c, "JOINT_3", "FERROR", "0.5");
    ck_assert_int_eq(motion_config_read(&mcfg, &kc, 6, err, sizeof err), MOTION_OK);
    ck_assert_double_eq_tol(mcfg.servo_period_s, 0.00025, 1e-15);
    ck_assert_double_eq_tol(mcfg.setpoint_period_s, 0.01, 1e-15);
    ck_assert_double_eq_tol(mcfg.joint[3].ferror_mm, 0.5, 1e-15);
    ck_assert_double_eq_tol(mcfg.max_lin_vel_mm_s, 100, 1e-15);
    ck_assert_double_eq_tol(mcfg.kin_tol_mm, 0.001, 1e-15);
    tk_set(c, "TRAJ", "MAX_LINEAR_ACCELERATION", "fast");
    ck_assert_int_eq(motion_config_read(&mcfg, &kc, 6, err, sizeof err), MOTION_ERR_CONFIG);
    ck_assert_str_eq(err, "[TRAJ] MAX_LINEAR_ACCELERATION = fast: not a number");
    tk_set(c, "TRAJ", "MAX_LINEAR_ACCELERATION", "-5");
    ck_assert_int_eq(motion_config_read(&mcfg, &kc, 6, err, sizeof err), MOTION_ERR_CONFIG);
    ck_assert_str_eq(err, "[TRAJ] MAX_LINEAR_ACCELERATION = -5: must be > 0");
    ck_assert_str_eq(motion_strerror(MOTION_ERR_FERROR), "following error too large");
    ck_assert_str_eq(motion_state_name(MOTION_PAUSED), "paused");
    free(c);
}
END_TEST

/* The limits that protect the machine have no built-in default: each one missing is an
 * error naming it (it used to leave the leg at 100 mm/s, 1000 mm/s^2, 1 mm). */
START_TEST(test_config_limits_required)
{
    static const char *const joint_keys[] = { "MAX_VELOCITY", "MAX_ACCELERATION", "FERROR" };
    static const char *const traj_keys[] = { "MAX_LINEAR_VELOCITY", "MAX_LINEAR_ACCELERATION",
                                             "MAX_ANGULAR_VELOCITY",
                                             "MAX_ANGULAR_ACCELERATION" };
    for (int drop = 0; drop < 7; drop++) {
        struct tk_cfg *full = tm_trivial_cfg(), *c = calloc(1, sizeof *c);
        ck_assert_ptr_nonnull(c);
        for (int i = 0; i < full->n; i++) {
            int is_j3 = !strcmp(full->sec[i], "JOINT_3");
            if ((drop < 3 && is_j3 && !strcmp(full->key[i], joint_keys[drop])) ||
                (drop >= 3 && !strcmp(full->sec[i], "TRAJ") &&
                 !strcmp(full->key[i], traj_keys[drop - 3])))
                continue;
            tk_set(c, full->sec[i], full->key[i], full->val[i]);
        }
        struct kins_config kc = tk_config(c);
        struct motion_config mcfg;
        char err[256] = "", want[128];
        motion_config_default(&mcfg);
        ck_assert_int_eq(motion_config_read(&mcfg, &kc, 6, err, sizeof err), MOTION_ERR_CONFIG);
        snprintf(want, sizeof want, "[%s] %s: missing;", drop < 3 ? "JOINT_3" : "TRAJ",
                 drop < 3 ? joint_keys[drop] : traj_keys[drop - 3]);
        ck_assert_msg(!strncmp(err, want, strlen(want)), "want '%s', got '%s'", want, err);
        free(full);
        free(c);
    }
}
END_TEST

static Suite *motion_suite(void)
{
    Suite *s = suite_create("motion");
    TCase *tc = tcase_create("plan");
    tcase_add_test(tc, test_trapezoid_trivial);
    tcase_add_test(tc, test_triangle_and_rapid);
    tcase_add_test(tc, test_trapezoid_hexapod);
    tcase_add_test(tc, test_brief_record);
    tcase_add_test(tc, test_segment_values_per_program);
    tcase_add_test(tc, test_ahead_same_bits);
    tcase_add_test(tc, test_calm_same_bits);
    tcase_add_test(tc, test_knot_ahead_same_plan);
    tcase_add_test(tc, test_arcs);
    tcase_add_test(tc, test_helix);
    tcase_add_test(tc, test_dwell);
    tcase_add_test(tc, test_unreachable_mid_move);
    tcase_add_test(tc, test_blend);
    tcase_add_test(tc, test_inverse_time_and_rotary);
    tcase_add_test(tc, test_config);
    tcase_add_test(tc, test_config_limits_required);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(motion_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
