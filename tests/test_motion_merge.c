/* test_motion_merge.c: G64 Q, LinuxCNC's naive CAM detector: which straight feeds run as one
 * line, the path they give, their time, and the same through a stream. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kins/hexapod.h"
#include "motion/motion_merge.h"
#include "tests/test_motion_util.h"

#define DT 0.001

/* G64 P p Q q (path mode 640), as the interpreter sends it. */
static void g64(struct canon_prog *p, int line, double tol_p, double tol_q)
{
    struct canon_cmd c;
    memset(&c, 0, sizeof c);
    c.type = CANON_PATH_MODE;
    c.line = line;
    c.file = "test.ngc";
    c.ivalue = 640;
    c.value = tol_p;
    c.naive_tol_mm = tol_q;
    ck_assert_int_eq(canon_prog_sink(p, &c), 0);
}

/* n feeds of step mm along +X from x0 at height z, each end off the line by jitter (mm,
 * alternating in Y), A B C fixed at abc; lines from line0. */
static void noisy_line(struct canon_prog *p, int line0, int n, double x0, double z, double step,
                       double jitter, const double abc[3], double feed)
{
    for (int i = 1; i <= n; i++) {
        double e[6] = { x0 + i * step, (i % 2 ? jitter : -jitter) * (i < n), z, abc[0], abc[1],
                        abc[2] };
        tm_add(p, CANON_FEED, line0 + i - 1, e, feed, 0);
    }
}

/* The program through the filter: how many commands went out and how many feeds merged. */
static size_t merged_count(const struct canon_prog *p, size_t *out_count, struct canon_prog *out)
{
    size_t merged = 0;
    ck_assert_int_eq(motion_merge_program(p, out, &merged), 0);
    *out_count = out->count;
    return merged;
}

START_TEST(test_runs_within_q)
{
    const double abc[3] = { 0, 0, 0 };
    struct canon_prog p, o;
    size_t n;
    canon_prog_init(&p);
    memcpy(p.start, (double[6]){ 0, 0, 10, 0, 0, 0 }, sizeof p.start);
    g64(&p, 1, 0.01, 0.005);
    noisy_line(&p, 2, 50, 0, 10, 0.5, 0.002, abc, 1200);    /* within Q: one line */
    ck_assert_uint_eq(merged_count(&p, &n, &o), 49);
    ck_assert_uint_eq(n, 2);                                  /* PATH_MODE, the line */
    ck_assert_int_eq(o.cmds[1].type, CANON_FEED);
    ck_assert_int_eq(o.cmds[1].line, 51);                     /* the run's last line */
    ck_assert_double_eq_tol(o.cmds[1].end[0], 25.0, 1e-12);
    ck_assert_double_eq_tol(o.cmds[1].end[1], 0.0, 1e-12);
    canon_prog_free(&o);
    canon_prog_free(&p);

    canon_prog_init(&p);                                      /* jitter past Q: none merge */
    memcpy(p.start, (double[6]){ 0, 0, 10, 0, 0, 0 }, sizeof p.start);
    g64(&p, 1, 0.01, 0.001);
    noisy_line(&p, 2, 50, 0, 10, 0.5, 0.002, abc, 1200);
    ck_assert_uint_eq(merged_count(&p, &n, &o), 0);
    ck_assert_uint_eq(n, 51);
    canon_prog_free(&o);
    canon_prog_free(&p);

    canon_prog_init(&p);                                      /* 250 feeds: runs of 101 */
    memcpy(p.start, (double[6]){ 0, 0, 10, 0, 0, 0 }, sizeof p.start);
    g64(&p, 1, 0.01, 0.005);
    noisy_line(&p, 2, 250, 0, 10, 0.1, 0, abc, 1200);
    ck_assert_uint_eq(merged_count(&p, &n, &o), 247);
    ck_assert_uint_eq(n, 1 + 3);
    canon_prog_free(&o);
    canon_prog_free(&p);
}
END_TEST

/* What ends a run: a turn past Q, A B C moving, a new feed, any other command, G61; and no
 * Q (G64 P0 Q0) merges nothing. */
START_TEST(test_what_ends_a_run)
{
    const double abc[3] = { 0, 0, 0 };
    struct canon_prog p, o;
    size_t n;
    canon_prog_init(&p);
    memcpy(p.start, (double[6]){ 0, 0, 10, 0, 0, 0 }, sizeof p.start);
    g64(&p, 1, 0.01, 0.005);
    noisy_line(&p, 2, 10, 0, 10, 0.5, 0, abc, 1200);          /* run 1 (10 feeds) */
    double turn[6] = { 5, 1, 10, 0, 0, 0 };                   /* a corner: ends it */
    tm_add(&p, CANON_FEED, 12, turn, 1200, 0);
    double rot[6] = { 5, 2, 10, 0, 1, 0 };                    /* turns B: alone */
    tm_add(&p, CANON_FEED, 13, rot, 1200, 0);
    double a1[6] = { 5, 3, 10, 0, 1, 0 }, a2[6] = { 5, 4, 10, 0, 1, 0 };
    tm_add(&p, CANON_FEED, 14, a1, 1200, 0);                  /* run 2 ... */
    tm_add(&p, CANON_FEED, 15, a2, 900, 0);                   /* a new feed: run 3 */
    tm_add(&p, CANON_DWELL, 16, NULL, 0, 0.5);                /* ends run 3 */
    double b1[6] = { 5, 5, 10, 0, 1, 0 }, b2[6] = { 5, 6, 10, 0, 1, 0 };
    tm_add(&p, CANON_FEED, 17, b1, 900, 0);
    tm_add(&p, CANON_FEED, 18, b2, 900, 0);                   /* run 4: two feeds */
    struct canon_cmd g61;
    memset(&g61, 0, sizeof g61);
    g61.type = CANON_PATH_MODE, g61.ivalue = 610, g61.line = 19, g61.file = "test.ngc";
    canon_prog_sink(&p, &g61);
    double c1[6] = { 5, 7, 10, 0, 1, 0 }, c2[6] = { 5, 8, 10, 0, 1, 0 };
    tm_add(&p, CANON_FEED, 20, c1, 900, 0);                   /* G61: no runs */
    tm_add(&p, CANON_FEED, 21, c2, 900, 0);
    g64(&p, 22, 0, 0);
    double d1[6] = { 5, 9, 10, 0, 1, 0 }, d2[6] = { 5, 10, 10, 0, 1, 0 };
    tm_add(&p, CANON_FEED, 23, d1, 900, 0);                   /* G64 Q0: none */
    tm_add(&p, CANON_FEED, 24, d2, 900, 0);
    ck_assert_uint_eq(merged_count(&p, &n, &o), 9 + 1);
    int lines[] = { 1, 11, 12, 13, 14, 15, 16, 18, 19, 20, 21, 22, 23, 24 };
    ck_assert_uint_eq(n, sizeof lines / sizeof lines[0]);
    for (size_t i = 0; i < n; i++)
        ck_assert_int_eq(o.cmds[i].line, lines[i]);
    canon_prog_free(&o);
    canon_prog_free(&p);
}
END_TEST

/* A CAM program's straight stretch, points jittered by 1 um as CAM output rounds them: with
 * Q the planner sees one line and runs it at the feed; without, it follows every kink. The
 * path stays within Q of the programmed points. */
START_TEST(test_merged_path_and_time)
{
    const double abc[3] = { 0, 0, 0 };
    double t[2], dev[2];
    size_t segs[2];
    for (int q = 0; q < 2; q++) {
        struct tm_machine mc;
        ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
        struct canon_prog p;
        canon_prog_init(&p);
        memcpy(p.start, (double[6]){ 0, 0, 10, 0, 0, 0 }, sizeof p.start);
        g64(&p, 1, 0.01, q ? 0.005 : 0);
        noisy_line(&p, 2, 800, 0, 10, 0.1, 0.001, abc, 6000);   /* 80 mm at 100 mm/s */
        char err[400];
        ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_OK);
        struct motion_plan_info info;
        motion_plan_info(mc.m, &info);
        segs[q] = info.segments;
        ck_assert_uint_eq(info.merged, q ? 792 : 0);
        ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
        struct motion_out o;
        dev[q] = 0;
        do {
            motion_step(mc.m, DT, &o);
            dev[q] = fmax(dev[q], fabs(o.pose[1]));             /* the line is Y = 0 */
        } while (o.state == MOTION_RUNNING);
        ck_assert_int_eq(o.state, MOTION_DONE);
        t[q] = o.time_elapsed_s;
        canon_prog_free(&p);
        tm_close(&mc);
    }
    printf("800 feeds of 0.1 mm with 1 um kinks at 100 mm/s: G64 P0.01 %.3f s (%zu segments), "
           "with Q0.005 %.3f s (%zu segments); off the line %.4f / %.4f mm\n", t[0], segs[0],
           t[1], segs[1], dev[0], dev[1]);
    ck_assert_msg(t[1] < t[0], "merged %.3f s, not %.3f s", t[1], t[0]);
    ck_assert(segs[1] * 20 < segs[0]);
    ck_assert(dev[1] <= 0.005 + 1e-9);
}
END_TEST

/* The same program planned whole and streamed: runs held across the stream's windows give the
 * same moves, so the same plan. */
START_TEST(test_stream_same_runs)
{
    const double abc[3] = { 0, 0, 0 };
    struct canon_prog p;
    canon_prog_init(&p);
    memcpy(p.start, (double[6]){ 0, 0, 10, 0, 0, 0 }, sizeof p.start);
    g64(&p, 1, 0.01, 0.005);
    for (int leg = 0; leg < 3000; leg++) { /* short noisy lines, each from a rapid to its */
        double x0 = leg % 2 ? 0.3 : 0, z = 10 + leg * 0.01;   /* start: more than a window */
        tm_add(&p, CANON_TRAVERSE, 2 + leg * 4, (double[6]){ x0, 0, z, 0, 0, 0 }, 0, 0);
        noisy_line(&p, 3 + leg * 4, 3, x0, z, leg % 2 ? -0.1 : 0.1, 0.001, abc, 3000);
    }
    struct tm_machine a, b;
    ck_assert_int_eq(tm_open(&a, tm_trivial_cfg(), &kins_trivial_ops), 0);
    ck_assert_int_eq(tm_open(&b, tm_trivial_cfg(), &kins_trivial_ops), 0);
    char err[400];
    ck_assert_int_eq(motion_load(a.m, &p, err, sizeof err), MOTION_OK);
    struct motion_plan_info whole;
    motion_plan_info(a.m, &whole);
    struct motion_stream *s;
    ck_assert_int_eq(motion_stream_create(b.m, p.start, NULL, &s, err, sizeof err), MOTION_OK);
    for (size_t i = 0; i < p.count; i++)
        ck_assert_int_eq(motion_stream_add(s, &p.cmds[i]), MOTION_OK);
    ck_assert_int_eq(motion_stream_finish(s), MOTION_OK);
    struct motion_stream_info si;
    motion_stream_info(s, &si);
    printf("9000 feeds in 3000 short noisy lines: whole plan %.4f s, %zu merged; streamed %.4f s, %zu "
           "merged, %zu windows\n", whole.time_s, whole.merged, si.plan.time_s, si.plan.merged,
           si.windows);
    ck_assert_uint_eq(si.plan.merged, whole.merged);
    ck_assert_uint_eq(whole.merged, 6000);
    ck_assert(si.windows > 1);
    ck_assert(fabs(si.plan.time_s - whole.time_s) < 1e-6 * whole.time_s);
    motion_stream_destroy(s);
    canon_prog_free(&p);
    tm_close(&a);
    tm_close(&b);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("motion_merge");
    TCase *tc = tcase_create("merge");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_runs_within_q);
    tcase_add_test(tc, test_what_ends_a_run);
    tcase_add_test(tc, test_merged_path_and_time);
    tcase_add_test(tc, test_stream_same_runs);
    suite_add_tcase(s, tc);
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
