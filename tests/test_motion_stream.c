/* test_motion_stream.c: a program planned window by window while it runs (motion_stream.c)
 * against the same program planned whole (motion_load), trapezoidal (loop 0) and with jerk
 * limits (loop 1: every leg's jerk within MAX_JERK, streamed as whole; the first test also
 * loop 2, with [TRAJ] JERK_WINDOW). */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tests/test_motion_dense.h"
#include "tests/test_motion_util.h"

#define DT 0.001
#define LEG_JERK 200000.0      /* mm/s^3, loop 1: a 10 ms moving average, the full window,
                                * which the default keeps as it is under 20 ms
                                * (test_motion_jerk has 20 ms; this keeps the sanitizer run
                                * short) */

/* The TMU hexapod, with jerk limits when jerk (the test's loop index) is 1 or 2; 2 adds
 * [TRAJ] JERK_WINDOW 0.005 s, half the legs' 10 ms, their acceleration lowered to 500. */
static struct tk_cfg *stream_cfg(int jerk)
{
    struct tk_cfg *c = tm_hexapod_cfg();
    if (!c || !jerk)
        return c;
    tm_set_jerk(c, LEG_JERK, 120000, LEG_JERK);
    if (jerk == 2)
        tk_setf(c, "TRAJ", "JERK_WINDOW", 0.005);
    return c;
}

/* A long program on the TMU hexapod: short G64 P0.01 moves around a 20 mm circle while A
 * rocks by 2 deg, with spindle commands, settings and a dwell along the way. */
static void long_program(struct canon_prog *p, int nmoves)
{
    canon_prog_init(p);
    double home[6] = {0, 0, 645, 0, 0, 0};
    memcpy(p->start, home, sizeof home);
    tm_add(p, CANON_PATH_MODE, 1, NULL, 0, 0.01);
    double e[6] = {20, 0, 645, 0, 0, 0};
    tm_add(p, CANON_TRAVERSE, 2, e, 0, 0);
    tm_add(p, CANON_SPINDLE_SPEED, 3, NULL, 0, 8000);
    tm_add(p, CANON_SPINDLE_ON, 3, NULL, 0, 1);
    for (int i = 1; i <= nmoves; i++) {
        double a = i * 0.025;
        double q[6] = {20 * cos(a), 20 * sin(a), 645 - 0.002 * i, 2 * sin(a * 3), 0, 0};
        tm_add(p, CANON_FEED, 10 + i, q, 3000, 0);
        if (i % 1500 == 0)
            tm_add(p, CANON_SETTING, 10 + i, NULL, 0, 0);
        if (i % 2500 == 0)
            tm_add(p, CANON_SPINDLE_SPEED, 10 + i, NULL, 0, 8000 + i);
        if (i == nmoves / 2)
            tm_add(p, CANON_DWELL, 10 + i, NULL, 0, 0.05);
    }
    tm_add(p, CANON_SPINDLE_STOP, 20 + nmoves, NULL, 0, 0);
    tm_add(p, CANON_PROGRAM_END, 21 + nmoves, NULL, 0, 0);
}

/* The producer, run from the executor's loop: keeps at most `ahead` chunks queued. */
struct feed {
    struct motion_stream *s;
    const struct canon_prog *p;
    size_t next;
    size_t ahead;
    size_t stop_at;          /* stop feeding there (SIZE_MAX: never) */
    double max_off_path;     /* largest distance of the commanded XYZ from the programmed
                              * path, mm */
    size_t max_backlog;
};

static void feed_some(struct feed *f)
{
    while (f->next < f->p->count && f->next < f->stop_at &&
           motion_stream_backlog(f->s) < f->ahead) {
        ck_assert_int_eq(motion_stream_add(f->s, &f->p->cmds[f->next++]), MOTION_OK);
        if (f->next == f->p->count)
            ck_assert_int_eq(motion_stream_finish(f->s), MOTION_OK);
    }
    f->max_backlog = fmax(f->max_backlog, motion_stream_backlog(f->s));
}

static int feed_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    (void)m, (void)step;
    struct feed *f = ctx;
    feed_some(f);
    f->max_off_path = fmax(f->max_off_path, tm_dist_path(o->pose, f->p));
    return 0;
}

static struct motion_stream *stream_open(struct tm_machine *mc, const struct canon_prog *p,
                                         struct feed *f, size_t ahead)
{
    struct motion_stream *s = NULL;
    char err[400] = "";
    ck_assert_msg(motion_stream_create(mc->m, p->start, NULL, &s, err, sizeof err) ==
                  MOTION_OK, "%s", err);
    ck_assert_int_eq(motion_stream_attach(mc->m, s, NULL), MOTION_OK);
    memset(f, 0, sizeof *f);
    f->s = s;
    f->p = p;
    f->ahead = ahead;
    f->stop_at = SIZE_MAX;
    feed_some(f);
    ck_assert_int_eq(motion_start(mc->m), MOTION_OK);
    return s;
}

/* Streamed, the program takes the time the whole plan takes, stays on its path and within
 * every leg's limits, and passes every setting and spindle command. */
START_TEST(stream_matches_whole_plan)
{
    struct tm_machine whole, st;
    struct tk_cfg *c1 = stream_cfg(_i), *c2 = stream_cfg(_i);
    ck_assert_ptr_nonnull(c1);
    ck_assert_int_eq(tm_open(&whole, c1, &kins_hexapod_ops), 0);
    ck_assert_int_eq(tm_open(&st, c2, &kins_hexapod_ops), 0);
    struct canon_prog p;
    long_program(&p, 9000);
    char err[400];
    ck_assert_msg(motion_load(whole.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    ck_assert_int_eq(motion_start(whole.m), MOTION_OK);
    struct tm_stats sw, ss;
    tm_run(whole.m, DT, 2000000, &sw, NULL, NULL);
    ck_assert_int_eq(sw.last.state, MOTION_DONE);

    struct feed f;
    struct motion_stream *s = stream_open(&st, &p, &f, 2);
    tm_run(st.m, DT, 2000000, &ss, feed_hook, &f);
    ck_assert_msg(ss.last.state == MOTION_DONE, "state %d: %s", ss.last.state,
                  motion_last_error(st.m));
    struct motion_stream_info si;
    motion_stream_info(s, &si);
    printf("stream: %zu windows, time %.4f s (whole plan %.4f s), run %.4f s (whole %.4f s), "
           "entry shortfall %.2e, off path %.5f mm, backlog <= %zu\n", si.windows,
           si.plan.time_s, sw.last.time_elapsed_s, ss.t_s, sw.t_s, si.entry_shortfall,
           f.max_off_path, f.max_backlog);
    ck_assert_uint_gt(si.windows, 4);                     /* it did stream */
    ck_assert_uint_le(f.max_backlog, 2);
    ck_assert_double_lt(fabs(ss.t_s - sw.t_s), 0.002 * sw.t_s);
    ck_assert_double_lt(si.entry_shortfall, 1e-6);
    ck_assert_double_lt(f.max_off_path, 0.01 + 1e-3);     /* G64 P0.01 */
    for (int j = 0; j < 6; j++) {
        ck_assert_double_le(ss.max_leg_v[j], 100 * 1.001);
        ck_assert_double_le(ss.max_leg_a[j], fmax(1000, sw.max_leg_a[j]) * 1.01);
        if (_i)
            ck_assert_double_le(ss.max_leg_j[j], LEG_JERK * (1 + 1e-9));
        if (_i == 2) {           /* the window's lowered acceleration, streamed and whole */
            ck_assert_double_le(ss.max_leg_a[j], 500 * (1 + 1e-9));
            ck_assert_double_le(sw.max_leg_a[j], 500 * (1 + 1e-9));
        }
    }
    ck_assert_uint_eq(ss.last.settings_done, 6);           /* 9000 / 1500 */
    ck_assert_uint_eq(sw.last.settings_done, 6);
    ck_assert_int_eq(ss.last.spindle.dir, 0);
    ck_assert_double_eq(ss.last.spindle.rpm, sw.last.spindle.rpm);
    for (int k = 0; k < 6; k++)
        ck_assert_double_lt(fabs(ss.last.pose[k] - sw.last.pose[k]), 1e-9);
    motion_stream_detach(st.m);
    motion_stream_destroy(s);
    canon_prog_free(&p);
    tm_close(&whole);
    tm_close(&st);
}
END_TEST

/* A producer that stops: the executor runs into the last chunk's tail and stops there on the
 * path, saying why; nothing can be attached after that. */
START_TEST(stream_starved_stops_on_path)
{
    struct tm_machine mc;
    struct tk_cfg *c = stream_cfg(_i);
    ck_assert_int_eq(tm_open(&mc, c, &kins_hexapod_ops), 0);
    struct canon_prog p;
    long_program(&p, 9000);
    struct feed f;
    struct motion_stream *s = stream_open(&mc, &p, &f, 2);
    f.stop_at = 4000;
    struct tm_stats ss;
    tm_run(mc.m, DT, 2000000, &ss, feed_hook, &f);
    ck_assert_int_eq(ss.last.state, MOTION_FAULT);
    ck_assert_int_eq(ss.last.status, MOTION_ERR_STARVED);
    ck_assert_ptr_nonnull(strstr(motion_last_error(mc.m), "not planned in time"));
    ck_assert_double_eq(ss.last.path_vel, 0);
    ck_assert_double_lt(f.max_off_path, 0.011);
    for (int j = 0; j < 6; j++)
        ck_assert_double_le(ss.max_leg_a[j], 1000 * 1.01);
    /* the producer comes back: refused, the machine has left the stream */
    int st = MOTION_OK;
    for (size_t i = f.next; i < p.count && st == MOTION_OK; i++)
        st = motion_stream_add(s, &p.cmds[i]);
    if (st == MOTION_OK)
        st = motion_stream_finish(s);
    ck_assert_int_eq(st, MOTION_ERR_STARVED);
    motion_stream_detach(mc.m);
    motion_stream_destroy(s);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* Abort, pause and resume work across chunks: the stop stays on the path. */
static int pause_then_abort(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    feed_hook(m, o, step, ctx);
    if (step == 20000)
        motion_pause(m);
    if (step == 21500) {
        ck_assert_int_eq(o->state, MOTION_PAUSED);
        motion_resume(m);
    }
    if (step == 40000)
        motion_abort(m);
    return 0;
}

START_TEST(stream_pause_resume_abort)
{
    struct tm_machine mc;
    struct tk_cfg *c = stream_cfg(_i);
    ck_assert_int_eq(tm_open(&mc, c, &kins_hexapod_ops), 0);
    struct canon_prog p;
    long_program(&p, 9000);
    struct feed f;
    struct motion_stream *s = stream_open(&mc, &p, &f, 2);
    struct tm_stats ss;
    tm_run(mc.m, DT, 2000000, &ss, pause_then_abort, &f);
    ck_assert_int_eq(ss.last.state, MOTION_IDLE);
    ck_assert_int_gt(ss.steps, 40000);
    ck_assert_int_lt(ss.steps, 41000);
    ck_assert_double_lt(f.max_off_path, 0.011);
    for (int j = 0; j < 6; j++)
        ck_assert_double_le(ss.max_leg_a[j], 1000 * 1.01);
    motion_stream_detach(mc.m);
    motion_stream_destroy(s);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* Without an executor the stream checks: an unreachable move far into the program is
 * reported by its line, as motion_load reports it. */
START_TEST(stream_check_reports_line)
{
    struct tm_machine mc;
    struct tk_cfg *c = stream_cfg(_i);
    ck_assert_int_eq(tm_open(&mc, c, &kins_hexapod_ops), 0);
    struct canon_prog p;
    long_program(&p, 9000);
    p.cmds[7000].end[2] = 2000;           /* out of reach */
    int line = p.cmds[7000].line;
    struct motion_stream *s = NULL;
    char err[400] = "", whole[400] = "";
    ck_assert_int_eq(motion_stream_create(mc.m, p.start, NULL, &s, err, sizeof err), MOTION_OK);
    int st = MOTION_OK;
    for (size_t i = 0; i < p.count && st == MOTION_OK; i++)
        st = motion_stream_add(s, &p.cmds[i]);
    if (st == MOTION_OK)
        st = motion_stream_finish(s);
    ck_assert_int_eq(st, MOTION_ERR_UNREACHABLE);
    ck_assert_int_eq(motion_load(mc.m, &p, whole, sizeof whole), MOTION_ERR_UNREACHABLE);
    char at[64];
    snprintf(at, sizeof at, "test.ngc:%d:", line);
    ck_assert_msg(strstr(motion_stream_error(s), at), "%s", motion_stream_error(s));
    ck_assert_msg(strstr(whole, at), "%s", whole);
    struct motion_stream_info si;
    motion_stream_info(s, &si);
    ck_assert_uint_le(si.window_capacity, 16384);    /* bounded: never the whole program */
    motion_stream_destroy(s);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* M66 streamed: the window up to the wait goes out (sync), the machine waits on the input
 * until its time-out, answers -1, and the next window starts at rest there; the time is the
 * whole plan's. */
START_TEST(stream_sync_on_input_wait)
{
    struct tm_machine whole, st;
    ck_assert_int_eq(tm_open(&whole, stream_cfg(_i), &kins_hexapod_ops), 0);
    ck_assert_int_eq(tm_open(&st, stream_cfg(_i), &kins_hexapod_ops), 0);
    struct canon_prog p;
    canon_prog_init(&p);
    double home[6] = {0, 0, 645, 0, 0, 0}, a[6] = {5, 0, 645, 0, 0, 0}, b[6] = {5, 5, 645, 0, 0, 0};
    memcpy(p.start, home, sizeof home);
    tm_add(&p, CANON_FEED, 1, a, 3000, 0);
    tm_add(&p, CANON_WAIT_INPUT, 2, NULL, 0, 0.5);
    p.cmds[1].wait_mode = 3;                 /* high, input 0: never comes */
    tm_add(&p, CANON_FEED, 3, b, 3000, 0);
    tm_add(&p, CANON_PROGRAM_END, 4, NULL, 0, 0);
    char err[400];
    ck_assert_msg(motion_load(whole.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    ck_assert_int_eq(motion_start(whole.m), MOTION_OK);
    struct tm_stats sw;
    tm_run(whole.m, DT, 100000, &sw, NULL, NULL);
    ck_assert_int_eq(sw.last.state, MOTION_DONE);

    struct motion_stream *s = NULL;
    ck_assert_int_eq(motion_stream_create(st.m, p.start, NULL, &s, err, sizeof err), MOTION_OK);
    ck_assert_int_eq(motion_stream_attach(st.m, s, NULL), MOTION_OK);
    ck_assert_int_eq(motion_stream_add(s, &p.cmds[0]), MOTION_OK);
    ck_assert_int_eq(motion_stream_add(s, &p.cmds[1]), MOTION_OK);
    ck_assert_int_eq(motion_stream_sync(s), MOTION_OK);
    ck_assert_int_eq(motion_start(st.m), MOTION_OK);
    struct motion_out o;
    unsigned seq = 0;
    int k = 0;
    for (; k < 100000 && seq == 0; k++) {
        motion_step(st.m, DT, &o);
        motion_input_result(st.m, &seq);
    }
    ck_assert_uint_eq(seq, 1);
    ck_assert_double_eq(motion_input_result(st.m, NULL), -1);
    for (int j = 0; j < 50; j++) {           /* at rest there until the next part comes */
        motion_step(st.m, DT, &o);
        ck_assert_double_eq(o.path_vel, 0);
        ck_assert(motion_stream_starving(st.m));
    }
    ck_assert_int_eq(motion_stream_add(s, &p.cmds[2]), MOTION_OK);
    ck_assert_int_eq(motion_stream_add(s, &p.cmds[3]), MOTION_OK);
    ck_assert_int_eq(motion_stream_finish(s), MOTION_OK);
    struct tm_stats ss;
    tm_run(st.m, DT, 100000, &ss, NULL, NULL);
    ck_assert_int_eq(ss.last.state, MOTION_DONE);
    for (int i = 0; i < 6; i++)
        ck_assert_double_lt(fabs(ss.last.pose[i] - b[i]), 1e-9);
    /* the whole plan's time, plus the 50 periods it was held for the next part */
    printf("M66 streamed: %.3f s (whole plan %.3f s)\n", ss.last.time_elapsed_s,
           sw.last.time_elapsed_s);
    ck_assert_double_lt(fabs(ss.last.time_elapsed_s - 0.050 - sw.last.time_elapsed_s), 0.003);
    ck_assert_double_gt(sw.last.time_elapsed_s, 0.5);
    motion_stream_detach(st.m);
    motion_stream_destroy(s);
    canon_prog_free(&p);
    tm_close(&whole);
    tm_close(&st);
}
END_TEST

/* The streamed run of a random dense program (test_motion_dense.h): where it is and how
 * far from the programmed moves it strays. */
struct dense_watch {
    struct feed f;
    const struct dense *d;
    double off_mm;
};

static int dense_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    (void)m, (void)step;
    struct dense_watch *w = ctx;
    feed_some(&w->f);
    w->off_mm = fmax(w->off_mm, off_path(w->d, o->pose, o->line, 400));
    return 0;
}

/* Random dense programs of 5000 to 6000 moves, streamed across windows (merged runs, blends
 * and the knots' look-ahead meet the windows' ends wherever they fall) and planned whole:
 * the streamed run ends where the whole one does, in its time within 0.2 %, on its path
 * (dense_allowed), every leg within
 * its limits as in stream_matches_whole_plan. Loop 0 trapezoidal, 1 with jerk limits. */
START_TEST(stream_random_dense)
{
    unsigned long long seed = 0x7f4a7c159e3779b9ULL * (unsigned long long)(_i + 1);
    int jerk = _i % 2;
    struct dense d;
    dense_prog(&d, &seed, 5000, 6000);
    struct tm_machine whole, st;
    ck_assert_int_eq(tm_open(&whole, stream_cfg(jerk), &kins_hexapod_ops), 0);
    ck_assert_int_eq(tm_open(&st, stream_cfg(jerk), &kins_hexapod_ops), 0);
    char err[400];
    ck_assert_msg(motion_load(whole.m, &d.p, err, sizeof err) == MOTION_OK, "%s", err);
    ck_assert_int_eq(motion_start(whole.m), MOTION_OK);
    struct tm_stats sw, ss;
    tm_run(whole.m, DT, 4000000, &sw, NULL, NULL);
    ck_assert_int_eq(sw.last.state, MOTION_DONE);
    struct dense_watch w = { .d = &d };
    struct motion_stream *s = stream_open(&st, &d.p, &w.f, 2);
    tm_run(st.m, DT, 4000000, &ss, dense_hook, &w);
    ck_assert_msg(ss.last.state == MOTION_DONE, "state %d: %s", ss.last.state,
                  motion_last_error(st.m));
    struct motion_stream_info si;
    motion_stream_info(s, &si);
    const struct motion_config *mc = &st.mc;
    double allowed = dense_allowed(&d, mc, jerk);
    printf("random dense, %d moves, %s P%g Q%g%s: %zu windows, run %.3f s (whole %.3f s), "
           "%.5f mm off the path\n", d.n, d.g61 ? "G61" : "G64", d.tol_p, d.tol_q,
           jerk ? ", jerk limits" : "", si.windows, ss.t_s, sw.t_s, w.off_mm);
    ck_assert_uint_gt(si.windows, 1);
    ck_assert_double_lt(fabs(ss.t_s - sw.t_s), 0.002 * sw.t_s);
    ck_assert_double_le(w.off_mm, allowed);
    for (int j = 0; j < 6; j++) {
        ck_assert_double_le(ss.max_leg_v[j], mc->joint[j].max_vel_mm_s * (1 + 1e-9));
        ck_assert_double_le(ss.max_leg_a[j],
                            fmax(mc->joint[j].max_acc_mm_s2, sw.max_leg_a[j]) * 1.01);
        if (jerk)
            ck_assert_double_le(ss.max_leg_j[j], LEG_JERK * (1 + 1e-9));
        ck_assert_double_lt(fabs(ss.last.pose[j] - d.end[j]), 1e-9);
        ck_assert_double_lt(fabs(sw.last.pose[j] - d.end[j]), 1e-9);
    }
    motion_stream_detach(st.m);
    motion_stream_destroy(s);
    dense_free(&d);
    tm_close(&whole);
    tm_close(&st);
}
END_TEST

static bool take_stream_share(void *s)
{
    return motion_stream_help(s);
}

/* Every period's leg commands, kept (the run with and the run without a helper). */
struct legs_log {
    struct feed f;
    double (*L)[6];
    size_t n, cap;
};

static int legs_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    (void)m, (void)step;
    struct legs_log *g = ctx;
    feed_some(&g->f);
    if (g->n == g->cap) {
        g->cap = g->cap ? 2 * g->cap : 65536;
        g->L = realloc(g->L, g->cap * sizeof *g->L);
        ck_assert_ptr_nonnull(g->L);
    }
    memcpy(g->L[g->n++], o->joint_pos, sizeof g->L[0]);
    return 0;
}

/* The knot caps of each window come in jobs that any thread may take (motion_stream_help):
 * a random dense program streamed while a second thread takes what it can of them gives
 * every leg command of every period bit for bit as the same program streamed alone. Loop 0
 * trapezoidal, 1 with jerk limits. */
START_TEST(stream_helped_same_bits)
{
    unsigned long long seed = 0x2545f4914f6cdd1dULL * (unsigned long long)(_i + 3);
    struct dense d;
    dense_prog(&d, &seed, 5000, 6000);
    struct legs_log g[2];
    long shares = 0;
    for (int run = 0; run < 2; run++) {
        struct tm_machine mc;
        ck_assert_int_eq(tm_open(&mc, stream_cfg(_i), &kins_hexapod_ops), 0);
        memset(&g[run], 0, sizeof g[run]);
        struct motion_stream *s = stream_open(&mc, &d.p, &g[run].f, 2);
        struct tm_helper h;
        if (run == 1)
            ck_assert_int_eq(tm_helper_start(&h, take_stream_share, s), 0);
        struct tm_stats st;
        tm_run(mc.m, DT, 4000000, &st, legs_hook, &g[run]);
        if (run == 1)
            shares = tm_helper_stop(&h);
        ck_assert_msg(st.last.state == MOTION_DONE, "state %d: %s", st.last.state,
                      motion_last_error(mc.m));
        motion_stream_detach(mc.m);
        motion_stream_destroy(s);
        tm_close(&mc);
    }
    printf("helped stream, %d moves%s: %zu periods, %ld shares taken by the helper\n", d.n,
           _i ? ", jerk limits" : "", g[1].n, shares);
    ck_assert_uint_eq(g[0].n, g[1].n);
    ck_assert_int_gt(shares, 0);
    for (size_t k = 0; k < g[0].n; k++)
        ck_assert_msg(!memcmp(g[0].L[k], g[1].L[k], sizeof g[0].L[k]),
                      "period %zu: leg commands differ", k);
    free(g[0].L);
    free(g[1].L);
    dense_free(&d);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("motion_stream");
    TCase *tc = tcase_create("stream");
    tcase_set_timeout(tc, 300);
    tcase_add_loop_test(tc, stream_matches_whole_plan, 0, 3);
    tcase_add_loop_test(tc, stream_starved_stops_on_path, 0, 2);
    tcase_add_loop_test(tc, stream_pause_resume_abort, 0, 2);
    tcase_add_loop_test(tc, stream_check_reports_line, 0, 2);
    tcase_add_loop_test(tc, stream_sync_on_input_wait, 0, 2);
    tcase_add_loop_test(tc, stream_random_dense, 0, 2);
    tcase_add_loop_test(tc, stream_helped_same_bits, 0, 2);
    suite_add_tcase(s, tc);
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
