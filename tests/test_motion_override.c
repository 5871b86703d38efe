/* test_motion_override.c: the feed override against the legs' limits on random programs.
 *
 * Two defects of the override's rate logic were found one program at a time (a ramp
 * beginning within a period, the ceiling followed a period late): each let a leg pass its
 * acceleration limit by 5 to 48 % while the override moved. Here random five-axis programs
 * (straight feeds and arcs, G61 and G64 with several P, feeds from 10 to 500 mm/s) run on the
 * TMU hexapod with slow legs (40 mm/s, 200 mm/s^2: they bind) while the override is moved at
 * random (0 to 2, every 3 to 800 periods) and the program is paused and resumed now and then,
 * every other case with jerk limits (a 20 ms moving average). Every leg must keep within its
 * speed, acceleration (and jerk) in every servo period (differencing the commanded legs), and
 * every program must end where it should. The seeds are fixed: a
 * failure names its case, which reruns alone with HEXCNC_OVERRIDE_CASE=N;
 * HEXCNC_OVERRIDE_CASES=N runs N cases instead of CASES. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/test_motion_util.h"

#define DT 0.001
#define CASES 60
#define LEG_VEL 40.0
#define LEG_ACC 200.0
#define LEG_JERK 20000.0       /* 2 x 200 / 20000: a 20 ms average */

/* The leg-bound machine; with jerk limits, all at a 20 ms average. */
static struct tk_cfg *machine_cfg(int jerk)
{
    struct tk_cfg *c = tm_leg_bound_hexapod_cfg();
    ck_assert_ptr_nonnull(c);
    if (!jerk)
        return c;
    tm_set_jerk(c, 500000, 200000, LEG_JERK);   /* 2 x 5000 / 0.02, 2 x 2000 / 0.02 */
    return c;
}

/* A random program of n moves from the workspace's middle: mostly straight five-axis feeds,
 * some XY arcs. Its end into end. */
static void random_prog(struct canon_prog *p, unsigned long long *s, double end[6])
{
    static const double tols[] = { 0.01, 0.1, 1.0 };
    canon_prog_init(p);
    double at[6] = { 0, 0, 645, 0, 0, 0 };
    memcpy(p->start, at, sizeof at);
    int mode = (int)(tm_uniform(s) * 4);
    p->start_path_mode = mode == 0 ? 610 : 640;
    p->start_path_tol_mm = mode == 0 ? 0 : tols[mode - 1];
    int n = 3 + (int)(tm_uniform(s) * 6);
    double feed = 600 + tm_uniform(s) * 29400;
    for (int i = 0; i < n; i++) {
        double to[6];
        if (tm_uniform(s) < 0.25) {                    /* an XY arc, either way */
            double r = 5 + tm_uniform(s) * 30, a0 = tm_uniform(s) * 2 * M_PI;
            double sweep = (tm_uniform(s) < 0.5 ? -1 : 1) * (0.3 + tm_uniform(s) * 2.5);
            double c[3] = { at[0] - r * cos(a0), at[1] - r * sin(a0), at[2] };
            memcpy(to, at, sizeof to);
            to[0] = c[0] + r * cos(a0 + sweep), to[1] = c[1] + r * sin(a0 + sweep);
            if (fabs(to[0]) > 70 || fabs(to[1]) > 70) {
                i--;
                continue;
            }
            static const double up[3] = { 0, 0, 1 };
            tm_arc(p, i + 2, to, c, up, sweep > 0 ? 1 : -1, feed);
        } else {
            to[0] = -60 + 120 * tm_uniform(s), to[1] = -60 + 120 * tm_uniform(s);
            to[2] = 630 + 30 * tm_uniform(s);
            for (int k = 3; k < 6; k++)
                to[k] = -8 + 16 * tm_uniform(s);
            tm_add(p, CANON_FEED, i + 2, to, feed, 0);
        }
        memcpy(at, to, sizeof at);
    }
    memcpy(end, at, sizeof at);
}

/* The operator (tm_operate), as a run's hook. */
static int operator_hook(struct motion *m, const struct motion_out *o, int step, void *ctx)
{
    struct tm_act act = tm_operate(ctx, step, o->state);
    if (act.resume)
        ck_assert_int_eq(motion_resume(m), MOTION_OK);
    if (act.pause)
        ck_assert_int_eq(motion_pause(m), MOTION_OK);
    else if (act.ovr >= 0)
        ck_assert_int_eq(motion_set_feed_override(m, act.ovr), MOTION_OK);
    return 0;
}

START_TEST(test_random_override)
{
    const char *only = getenv("HEXCNC_OVERRIDE_CASE"), *many = getenv("HEXCNC_OVERRIDE_CASES");
    int cases = many && atoi(many) > 0 ? atoi(many) : CASES, ran = 0, pauses = 0;
    long periods = 0;
    double worst_v = 0, worst_a = 0, worst_j = 0;
    for (int k = 0; k < cases; k++) {
        if (only && atoi(only) != k)
            continue;
        unsigned long long seed = 0x9e3779b97f4a7c15ULL * (unsigned long long)(k + 1);
        struct tm_machine mc;
        int jerk = k % 2;
        ck_assert_int_eq(tm_open(&mc, machine_cfg(jerk), &kins_hexapod_ops), 0);
        struct canon_prog p;
        double end[6];
        random_prog(&p, &seed, end);
        char err[512] = "";
        if (motion_load(mc.m, &p, err, sizeof err) != MOTION_OK) {
            /* (a random arc may leave the reach: refused at plan time, as it must be) */
            ck_assert_msg(strstr(err, "reach") || strstr(err, "limit"), "case %d: %s", k, err);
            canon_prog_free(&p);
            tm_close(&mc);
            continue;
        }
        ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
        struct tm_operator w = { .seed = seed ^ 0x5bd1e995ULL, .next = 1 };
        struct tm_stats s;
        tm_run(mc.m, DT, 4000000, &s, operator_hook, &w);
        if (s.last.state == MOTION_PAUSED) {  /* paused at the very end: let it finish */
            ck_assert_int_eq(motion_resume(mc.m), MOTION_OK);
            struct tm_stats s2;
            tm_run(mc.m, DT, 100000, &s2, NULL, NULL);
            s.last = s2.last;
        }
        ck_assert_msg(s.last.state == MOTION_DONE, "case %d: state %d after %d periods", k,
                      s.last.state, s.steps);
        for (int i = 0; i < 6; i++) {
            ck_assert_msg(s.max_leg_v[i] <= LEG_VEL * (1 + 1e-9),
                          "case %d: leg %d at %.4f mm/s", k, i + 1, s.max_leg_v[i]);
            ck_assert_msg(s.max_leg_a[i] <= LEG_ACC * 1.001,
                          "case %d: leg %d at %.2f mm/s^2", k, i + 1, s.max_leg_a[i]);
            if (jerk) {
                ck_assert_msg(s.max_leg_j[i] <= LEG_JERK * (1 + 1e-9),
                              "case %d: leg %d at %.0f mm/s^3", k, i + 1, s.max_leg_j[i]);
                worst_j = fmax(worst_j, s.max_leg_j[i] / LEG_JERK);
            }
            ck_assert_msg(fabs(s.last.pose[i] - end[i]) < 1e-6, "case %d: ends %g from its "
                          "end on axis %d", k, s.last.pose[i] - end[i], i);
            worst_v = fmax(worst_v, s.max_leg_v[i] / LEG_VEL);
            worst_a = fmax(worst_a, s.max_leg_a[i] / LEG_ACC);
        }
        ran++;
        pauses += w.pauses;
        periods += s.steps;
        canon_prog_free(&p);
        tm_close(&mc);
    }
    printf("random programs under a moving override: %d run, %.0f s of motion, %d pauses; legs "
           "at most %.4f of their speed, %.4f of their acceleration, %.4f of their jerk limit "
           "(every other case)\n", ran, (double)periods * DT, pauses, worst_v, worst_a,
           worst_j);
    ck_assert_int_gt(ran, only ? 0 : cases / 2);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("motion_override");
    TCase *tc = tcase_create("random");
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, test_random_override);
    suite_add_tcase(s, tc);
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
