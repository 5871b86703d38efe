/* test_motion_probe.c: G38 probe moves on the executor: it stops on the path where the probe
 * input changes, within the acceleration limit, records where, and (streamed) the program
 * goes on from where the machine came to rest. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/test_motion_util.h"

#define ck_assert_pose(pose, x, y, z, a, b, c, tol) do {                              \
        const double *p_ = (pose);                                                    \
        const double e_[6] = {x, y, z, a, b, c};                                      \
        for (int i_ = 0; i_ < 6; i_++)                                                \
            ck_assert_double_eq_tol(p_[i_], e_[i_], tol);                             \
    } while (0)

#define DT 0.001                 /* servo period, s */
#define ACC 1000.0               /* the trivial machine's path acceleration, mm/s^2 */

/* Appends a probe move of type t (0 G38.2 .. 3 G38.5) to end, planned to its end. */
static void add_probe(struct canon_prog *p, int line, const double *end, double feed_mm_min,
                      int t)
{
    struct canon_cmd c;
    memset(&c, 0, sizeof c);
    c.type = CANON_PROBE;
    c.line = line;
    c.file = "test.ngc";
    memcpy(c.end, end, sizeof c.end);
    memcpy(c.probe_stop, end, sizeof c.probe_stop);
    c.feed_mm_min = feed_mm_min;
    c.ivalue = t;
    if (canon_prog_sink(p, &c))
        abort();
}

/* The simulated workpiece: material at and below z = surface; the probe input is contact
 * (as sim-probe drives motion.probe-input). */
struct surface {
    double z_mm;
    int on_from_start;           /* the input is true whatever the pose (a stuck probe) */
};

static int probe_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    const struct surface *s = ctx;
    (void)step;
    motion_set_probe_input(m, s->on_from_start || o->pose[2] <= s->z_mm);
    return 0;
}

static void open_trivial(struct tm_machine *mc)
{
    ck_assert_int_eq(tm_open(mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
}

/* From Z10 a G38.2 to Z-10 at 50 mm/s: the surface at Z0 trips it. The trip is recorded
 * within one period's travel of the surface; the machine stops v^2 / 2a = 1.25 mm further,
 * never braking harder than the path's limit, and stays there (the move's end is dropped). */
START_TEST(test_stops_on_trip)
{
    struct tm_machine mc;
    open_trivial(&mc);
    struct canon_prog p;
    canon_prog_init(&p);
    const double top[6] = { 0, 0, 10, 0, 0, 0 }, bottom[6] = { 0, 0, -10, 0, 0, 0 };
    memcpy(p.start, top, sizeof top);
    add_probe(&p, 5, bottom, 3000, 0);
    tm_add(&p, CANON_PROGRAM_END, 6, NULL, 0, 0);
    char err[400];
    ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    motion_start(mc.m);
    struct surface s = { 0, 0 };
    motion_set_probe_input(mc.m, false);
    struct tm_stats st;
    tm_run(mc.m, DT, 100000, &st, probe_hook, &s);
    struct motion_probe_result r;
    ck_assert_uint_eq(motion_probe_result(mc.m, &r), 1);
    ck_assert_int_eq(r.tripped, 1);
    ck_assert_int_eq(r.already, 0);
    ck_assert_msg(r.trip[2] <= 0 && r.trip[2] > -50 * DT - 1e-9, "trip z %g", r.trip[2]);
    double stop_z = r.trip[2] - 50.0 * 50.0 / (2 * ACC);
    ck_assert_msg(fabs(r.stop[2] - stop_z) < 0.06, "stop z %g, expected about %g",
                  r.stop[2], stop_z);
    ck_assert_int_eq(st.last.state, MOTION_DONE);
    ck_assert_double_eq_tol(st.last.pose[2], r.stop[2], 1e-12);
    ck_assert_msg(st.max_a_mm_s2 <= ACC * 1.001, "braked at %g mm/s^2", st.max_a_mm_s2);
    ck_assert_msg(st.max_v_mm_s <= 50 * 1.001, "%g mm/s", st.max_v_mm_s);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* G38.3 that touches nothing runs to its end and the program goes on; the result says no
 * trip, at the end point. */
START_TEST(test_no_trip_goes_on)
{
    struct tm_machine mc;
    open_trivial(&mc);
    struct canon_prog p;
    canon_prog_init(&p);
    const double top[6] = { 0, 0, 10, 0, 0, 0 }, low[6] = { 0, 0, 2, 0, 0, 0 },
                 side[6] = { 5, 0, 2, 0, 0, 0 };
    memcpy(p.start, top, sizeof top);
    add_probe(&p, 5, low, 3000, 1);
    tm_add(&p, CANON_FEED, 6, side, 3000, 0);
    tm_add(&p, CANON_PROGRAM_END, 7, NULL, 0, 0);
    char err[400];
    ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    motion_start(mc.m);
    struct surface s = { 0, 0 };
    struct tm_stats st;
    tm_run(mc.m, DT, 100000, &st, probe_hook, &s);
    struct motion_probe_result r;
    ck_assert_uint_eq(motion_probe_result(mc.m, &r), 1);
    ck_assert_int_eq(r.tripped, 0);
    ck_assert_pose(r.trip, 0, 0, 2, 0, 0, 0, 1e-12);
    ck_assert_int_eq(st.last.state, MOTION_DONE);
    ck_assert_pose(st.last.pose, 5, 0, 2, 0, 0, 0, 1e-9);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* A G38.2 whose probe is already in contact where it starts does not move (LinuxCNC's
 * error, which the interpreter reports); a G38.3 there trips at once. */
START_TEST(test_already_tripped)
{
    for (int t = 0; t < 2; t++) {
        struct tm_machine mc;
        open_trivial(&mc);
        struct canon_prog p;
        canon_prog_init(&p);
        const double top[6] = { 0, 0, 10, 0, 0, 0 }, bottom[6] = { 0, 0, -10, 0, 0, 0 };
        memcpy(p.start, top, sizeof top);
        add_probe(&p, 5, bottom, 3000, t);
        tm_add(&p, CANON_PROGRAM_END, 6, NULL, 0, 0);
        char err[400];
        ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
        motion_start(mc.m);
        struct surface s = { 0, 1 };
        motion_set_probe_input(mc.m, true);
        struct tm_stats st;
        tm_run(mc.m, DT, 100000, &st, probe_hook, &s);
        struct motion_probe_result r;
        ck_assert_uint_eq(motion_probe_result(mc.m, &r), 1);
        ck_assert_int_eq(r.already, t == 0);
        ck_assert_int_eq(r.tripped, t == 1);
        ck_assert_msg(st.last.pose[2] == 10, "moved to z %.9g", st.last.pose[2]);
        canon_prog_free(&p);
        tm_close(&mc);
    }
}
END_TEST

/* G93: the whole move to its end takes 1/F minutes, wherever the planner is told it stops
 * (the interpreter's model stopped it halfway): 20 mm in 0.6 s is 33.3 mm/s. */
START_TEST(test_inverse_time)
{
    struct tm_machine mc;
    open_trivial(&mc);
    struct canon_prog p;
    canon_prog_init(&p);
    const double top[6] = { 0, 0, 10, 0, 0, 0 }, bottom[6] = { 0, 0, -10, 0, 0, 0 },
                 half[6] = { 0, 0, 0, 0, 0, 0 };
    memcpy(p.start, top, sizeof top);
    add_probe(&p, 5, bottom, 0, 1);
    p.cmds[0].inverse_time_min = 0.01;
    memcpy(p.cmds[0].probe_stop, half, sizeof half);
    tm_add(&p, CANON_PROGRAM_END, 6, NULL, 0, 0);
    char err[400];
    ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    motion_start(mc.m);
    struct surface s = { -100, 0 };
    struct tm_stats st;
    tm_run(mc.m, DT, 100000, &st, probe_hook, &s);
    ck_assert_msg(fabs(st.max_v_mm_s - 20 / 0.6) < 0.05, "%g mm/s", st.max_v_mm_s);
    ck_assert_double_eq_tol(st.last.pose[2], 0, 1e-9);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* Without anyone giving the probe input (hexcnc check's servo pass), a probe move is a
 * plain feed: a G38.4, whose input would read false, runs to its end and reports nothing. */
START_TEST(test_unwired)
{
    struct tm_machine mc;
    open_trivial(&mc);
    struct canon_prog p;
    canon_prog_init(&p);
    const double low[6] = { 0, 0, 0, 0, 0, 0 }, high[6] = { 0, 0, 5, 0, 0, 0 },
                 side[6] = { 3, 0, 5, 0, 0, 0 };
    memcpy(p.start, low, sizeof low);
    add_probe(&p, 5, high, 1200, 2);
    tm_add(&p, CANON_FEED, 6, side, 1200, 0);
    tm_add(&p, CANON_PROGRAM_END, 7, NULL, 0, 0);
    char err[400];
    ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    motion_start(mc.m);
    struct tm_stats st;
    tm_run(mc.m, DT, 100000, &st, NULL, NULL);
    ck_assert_uint_eq(motion_probe_result(mc.m, NULL), 0);
    ck_assert_int_eq(st.last.state, MOTION_DONE);
    ck_assert_pose(st.last.pose, 3, 0, 5, 0, 0, 0, 1e-9);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* G38.4 from inside the material: stops once the probe leaves it (above z = 5). */
START_TEST(test_away)
{
    struct tm_machine mc;
    open_trivial(&mc);
    struct canon_prog p;
    canon_prog_init(&p);
    const double low[6] = { 0, 0, 0, 0, 0, 0 }, high[6] = { 0, 0, 20, 0, 0, 0 };
    memcpy(p.start, low, sizeof low);
    add_probe(&p, 5, high, 1200, 2);
    tm_add(&p, CANON_PROGRAM_END, 6, NULL, 0, 0);
    char err[400];
    ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    motion_start(mc.m);
    struct surface s = { 5, 0 };
    motion_set_probe_input(mc.m, true);
    struct tm_stats st;
    tm_run(mc.m, DT, 100000, &st, probe_hook, &s);
    struct motion_probe_result r;
    ck_assert_uint_eq(motion_probe_result(mc.m, &r), 1);
    ck_assert_int_eq(r.tripped, 1);
    ck_assert_msg(r.trip[2] > 5 && r.trip[2] < 5 + 20 * DT + 1e-9, "trip z %g", r.trip[2]);
    ck_assert_msg(r.stop[2] > r.trip[2] && r.stop[2] < 6, "stop z %g", r.stop[2]);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* Streamed: the window is synced at the probe move; once the machine has stopped on the
 * trip, the next window starts there (motion_stream_restart_at) and the machine goes on from
 * where it stands, without a jump, within the acceleration limit. */
START_TEST(test_stream_goes_on_from_stop)
{
    struct tm_machine mc;
    open_trivial(&mc);
    const double top[6] = { 0, 0, 10, 0, 0, 0 }, bottom[6] = { 0, 0, -10, 0, 0, 0 },
                 side[6] = { 10, 0, 3, 0, 0, 0 };
    struct motion_stream *s;
    char err[400];
    ck_assert_int_eq(motion_stream_create(mc.m, top, NULL, &s, err, sizeof err), MOTION_OK);
    ck_assert_int_eq(motion_stream_attach(mc.m, s, NULL), MOTION_OK);
    ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
    struct canon_prog p;
    canon_prog_init(&p);
    add_probe(&p, 5, bottom, 3000, 0);
    ck_assert_int_eq(motion_stream_add(s, &p.cmds[0]), MOTION_OK);
    ck_assert_int_eq(motion_stream_sync(s), MOTION_OK);
    struct surface surf = { 0, 0 };
    motion_set_probe_input(mc.m, false);
    struct motion_out o, prev;
    motion_step(mc.m, DT, &prev);
    double max_a = 0, pv[3] = { 0, 0, 0 };
    struct motion_probe_result r;
    int k, added = 0;
    for (k = 0; k < 100000; k++) {
        if (!added && motion_probe_result(mc.m, &r) == 1) {
            motion_stream_restart_at(s, r.stop);
            struct canon_prog q;
            canon_prog_init(&q);
            tm_add(&q, CANON_FEED, 6, side, 3000, 0);
            tm_add(&q, CANON_PROGRAM_END, 7, NULL, 0, 0);
            ck_assert_int_eq(motion_stream_add(s, &q.cmds[0]), MOTION_OK);
            ck_assert_int_eq(motion_stream_add(s, &q.cmds[1]), MOTION_OK);
            ck_assert_int_eq(motion_stream_finish(s), MOTION_OK);
            canon_prog_free(&q);
            added = 1;
        }
        motion_step(mc.m, DT, &o);
        probe_hook(mc.m, &o, k, &surf);
        double v[3], a2 = 0;
        for (int i = 0; i < 3; i++) {
            v[i] = (o.pose[i] - prev.pose[i]) / DT;
            a2 += (v[i] - pv[i]) * (v[i] - pv[i]);
        }
        if (k > 0)
            max_a = fmax(max_a, sqrt(a2) / DT);
        memcpy(pv, v, sizeof pv);
        prev = o;
        if (o.state == MOTION_DONE || o.state == MOTION_FAULT)
            break;
    }
    ck_assert_int_eq(added, 1);
    ck_assert_msg(o.state == MOTION_DONE, "state %d: %s", o.state, motion_last_error(mc.m));
    ck_assert_int_eq(r.tripped, 1);
    ck_assert_msg(r.stop[2] < 0 && r.stop[2] > -1.4, "stop z %g", r.stop[2]);
    ck_assert_pose(o.pose, 10, 0, 3, 0, 0, 0, 1e-9);
    ck_assert_msg(max_a <= ACC * 1.001, "%g mm/s^2", max_a);
    motion_stream_detach(mc.m);
    motion_stream_destroy(s);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

static Suite *probe_suite(void)
{
    Suite *s = suite_create("motion_probe");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_stops_on_trip);
    tcase_add_test(tc, test_no_trip_goes_on);
    tcase_add_test(tc, test_already_tripped);
    tcase_add_test(tc, test_away);
    tcase_add_test(tc, test_unwired);
    tcase_add_test(tc, test_inverse_time);
    tcase_add_test(tc, test_stream_goes_on_from_stop);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(probe_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
