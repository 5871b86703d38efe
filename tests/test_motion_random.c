/* test_motion_random.c: random dense programs, made the way CAM code comes, against what the
 * planner and the executor promise.
 *
 * The dense code's way through motion has many shortcuts (merged feeds, blend arcs, the
 * knots' look-ahead, a check's eight-period look-ahead and its calm periods), each tested on
 * programs written for it. Here each case is a program of 150 to 500 moves of 0.002 to 1 mm
 * (now and then a zero-length one, a longer one, a turn of A B C in place, a small arc either
 * way), collinear, gently or sharply turning, with A B C still, drifting or jumping, under
 * G61 or G64 P (0.001 to 0.05 mm, with or without Q), at feeds from 0.3 to 12 m/min, on the
 * TMU hexapod and on one whose legs bind (40 mm/s, 200 mm/s^2), every other case of each with
 * jerk limits. Every case must:
 *   - plan, run to its end and stop there (within 1e-9 mm and deg);
 *   - keep every leg within its speed, acceleration (and jerk) limit in every servo period,
 *     measured by differencing the commanded legs;
 *   - keep the commanded tool within the path tolerance of the programmed moves (G64 P, the
 *     merge's Q, the jerk average's rounding) in every period;
 *   - never pass the largest programmed feed;
 *   - give, run the way a check runs it (rates off, the brief record, the eight-period
 *     look-ahead and, where no operator acts, runs of calm periods taken at once), the same
 *     record in every period and the same executor state wherever both stand at a period.
 * In every third case an operator moves the feed override (0 to 2, every 3 to 800 periods)
 * and pauses and resumes now and then, the same on both machines; there a leg may pass its
 * acceleration by 0.1 % (test_motion_override) and the feed is bounded by twice the
 * largest.
 * The seeds are fixed: a failure names its case, which reruns alone with
 * HEXCNC_RANDOM_CASE=N; HEXCNC_RANDOM_CASES=N runs N cases instead of CASES, and the
 * sanitizer's run (HEXCNC_SANITIZED=1, some ten times slower) the first SANITIZED_CASES,
 * every kind of case among them; HARD_CASES run as well. HEXCNC_RANDOM_EACH=1 prints each
 * case's time and path figure; HEXCNC_RANDOM_KIND=N runs only the cases k with k % 4 == N (0
 * and 1 the TMU's, 2 and 3 the leg-bound machine's, the odd ones with jerk limits);
 * HEXCNC_RANDOM_TMU=abc-fast or slow-path changes the TMU's limits (A B C at 1500 deg/s^2 and
 * 150,000 deg/s^3; the path at 200 mm/s^2), to compare jerk windows on more than one machine
 * (docs/motion.md). */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_priv.h"
#include "tests/test_motion_dense.h"
#include "tests/test_motion_same.h"
#include "tests/test_motion_util.h"

#define DT 0.001
#define CASES 48
#define SANITIZED_CASES 12

/* Cases beyond the first CASES that found a defect, run every time: 321 (G64 P0.001 with
 * jerk limits) took the tool 1.34 times its tolerance from the path through blend arcs
 * shorter than the moving average's window (motion_blend.c, shorter_than_window). */
static const int HARD_CASES[] = { 321 };

/* The operator (tm_operate) of every third case, given to both machines alike. */
static void operate(struct tm_operator *op, long n, const struct motion_out *o,
                    struct motion *a, struct motion *b)
{
    struct tm_act act = tm_operate(op, n, o->state);
    if (act.resume)
        ck_assert(motion_resume(a) == MOTION_OK && motion_resume(b) == MOTION_OK);
    if (act.pause)
        ck_assert(motion_pause(a) == MOTION_OK && motion_pause(b) == MOTION_OK);
    else if (act.ovr >= 0)
        ck_assert(motion_set_feed_override(a, act.ovr) == MOTION_OK &&
                  motion_set_feed_override(b, act.ovr) == MOTION_OK);
}

/* The machine of case k: the TMU hexapod or the leg-bound one, with jerk limits on odd
 * cases (the default 20 ms average on both, the TMU's legs lowered to 500 mm/s^2 by it; with
 * HEXCNC_RANDOM_WINDOW=1 each machine's full window as [TRAJ] JERK_WINDOW, 40 ms on the TMU,
 * 20 ms on the other, every acceleration in full). */
static struct tk_cfg *case_cfg(int k)
{
    int legs = (k / 2) % 2, jerk = k % 2;
    struct tk_cfg *c = legs ? tm_leg_bound_hexapod_cfg() : tm_hexapod_cfg();
    ck_assert_ptr_nonnull(c);
    if (jerk && legs)
        tm_set_jerk(c, 500000, 200000, 20000);
    else if (jerk)
        tm_set_jerk(c, 50000, 30000, 50000);
    const char *tmu = getenv("HEXCNC_RANDOM_TMU");
    if (!legs && tmu && !strcmp(tmu, "abc-fast")) {
        tk_setf(c, "TRAJ", "MAX_ANGULAR_ACCELERATION", 1500);
        if (jerk)
            tk_setf(c, "TRAJ", "MAX_ANGULAR_JERK", 150000);
    } else if (!legs && tmu && !strcmp(tmu, "slow-path")) {
        tk_setf(c, "TRAJ", "MAX_LINEAR_ACCELERATION", 200);
    } else if (!legs && tmu) {
        ck_abort_msg("HEXCNC_RANDOM_TMU=%s: abc-fast or slow-path", tmu);
    }
    if (jerk && getenv("HEXCNC_RANDOM_WINDOW"))
        tk_setf(c, "TRAJ", "JERK_WINDOW", legs ? 0.020 : 0.040);
    return c;
}

/* The worst of all cases, as shares of the limits. */
struct worst {
    double leg_v, leg_a, leg_j, path, feed;
    double case_path;        /* the last case's: its path figure, of its tolerance */
    int case_jerk;           /* ... whether it ran with jerk limits */
    long periods, calm;
    int ran, merged, pauses;
};

/* Runs case k; 0 when it ran, 1 when it was refused at load as it must be. */
static int run_case(int k, struct worst *wr)
{
    unsigned long long seed = 0x2545f4914f6cdd1dULL * (unsigned long long)(k + 1);
    struct tm_machine a, b;
    ck_assert_int_eq(tm_open(&a, case_cfg(k), &kins_hexapod_ops), 0);
    ck_assert_int_eq(tm_open(&b, case_cfg(k), &kins_hexapod_ops), 0);
    struct dense d;
    dense_prog(&d, &seed, 150, 500);
    char err[512] = "";
    int st = motion_load(a.m, &d.p, err, sizeof err);
    if (st != MOTION_OK) {
        /* (a move near the box's corners may leave the legs' reach: refused before any
         * motion, with the words for it) */
        ck_assert_msg(strstr(err, "reach"), "case %d: %s", k, err);
        dense_free(&d);
        tm_close(&a);
        tm_close(&b);
        return 1;
    }
    ck_assert_msg(motion_load(b.m, &d.p, err, sizeof err) == MOTION_OK, "case %d: %s", k, err);
    ck_assert(motion_start(a.m) == MOTION_OK && motion_start(b.m) == MOTION_OK);
    motion_set_rates(a.m, false);
    motion_set_rates(b.m, false);
    motion_set_ahead(b.m, true);
    motion_set_brief(b.m, true);
    struct motion_plan_info info;
    motion_plan_info(a.m, &info);
    const struct motion_config *mc = &a.mc;
    int jerk = mc->max_lin_jerk_mm_s3 > 0;
    double allowed = dense_allowed(&d, mc, jerk);
    double v0[6] = { 0 }, a0[6] = { 0 }, worst_path = 0;
    struct motion_out oa, ob, prev;
    memset(&oa, 0, sizeof oa);
    ck_assert_int_eq(motion_step(a.m, DT, &prev), MOTION_OK);
    ck_assert_int_eq(motion_step(b.m, DT, &ob), MOTION_OK);
    same_brief(&prev, &ob);
    struct tm_operator op = { .seed = seed ^ 0x5bd1e995ULL, .next = 1 };
    int operated = k % 3 == 2;
    double acc_slack = operated ? 1e-3 : 1e-6, feed_bound = operated ? 2 : 1;
    long n = 1, bound = (long)((operated ? 8 : 2) * info.time_s / DT) + 2000;
    /* (where no operator acts between periods, the second machine takes runs of calm
     * periods as a check does: motion_step_calm, the same periods) */
    struct calm_feed cf = { .on = !operated };
    int in_step = 1;
    int reach = jerk ? 400 : 8;               /* the average's line lags by T/2 */
    do {
        if (operated)
            operate(&op, n, &prev, a.m, b.m);
        ck_assert_int_eq(motion_step(a.m, DT, &oa), MOTION_OK);
        ck_assert_int_eq(calm_next(b.m, DT, &cf, &ob, &in_step), MOTION_OK);
        if (in_step)
            same_executor(a.m, b.m);
        same_brief(&oa, &ob);
        double sp = 0;
        for (int i = 0; i < 3; i++)
            sp += (oa.pose[i] - prev.pose[i]) * (oa.pose[i] - prev.pose[i]);
        wr->feed = fmax(wr->feed, sqrt(sp) / DT / (feed_bound * d.max_feed_mm_s));
        double off = off_path(&d, oa.pose, oa.line, reach);
        worst_path = fmax(worst_path, off);
        ck_assert_msg(off <= allowed, "case %d: %.6f mm off the path at line %d (allowed "
                      "%.6f)", k, off, oa.line, allowed);
        for (int j = 0; j < 6; j++) {
            const struct motion_joint_config *jc = &mc->joint[j];
            double v = (oa.joint_pos[j] - prev.joint_pos[j]) / DT, acc = (v - v0[j]) / DT;
            ck_assert_msg(fabs(v) <= jc->max_vel_mm_s * (1 + 1e-9), "case %d: leg %d at "
                          "%.6f mm/s, period %ld", k, j + 1, fabs(v), n);
            wr->leg_v = fmax(wr->leg_v, fabs(v) / jc->max_vel_mm_s);
            if (n > 1) {
                ck_assert_msg(fabs(acc) <= jc->max_acc_mm_s2 * (1 + acc_slack), "case %d: "
                              "leg %d at %.4f mm/s^2, period %ld", k, j + 1, fabs(acc), n);
                wr->leg_a = fmax(wr->leg_a, fabs(acc) / jc->max_acc_mm_s2);
            }
            if (n > 2 && jerk) {
                double jk = fabs(acc - a0[j]) / DT;
                ck_assert_msg(jk <= jc->max_jerk_mm_s3 * (1 + 1e-9), "case %d: leg %d at "
                              "%.0f mm/s^3, period %ld", k, j + 1, jk, n);
                wr->leg_j = fmax(wr->leg_j, jk / jc->max_jerk_mm_s3);
            }
            v0[j] = v, a0[j] = acc;
        }
        prev = oa;
    } while ((oa.state == MOTION_RUNNING || oa.state == MOTION_PAUSING ||
              oa.state == MOTION_PAUSED) && ++n < bound);
    ck_assert_msg(oa.state == MOTION_DONE, "case %d: state %d after %ld periods (%s)", k,
                  oa.state, n, motion_last_error(a.m));
    for (int i = 0; i < 6; i++)
        ck_assert_msg(fabs(oa.pose[i] - d.end[i]) <= 1e-9, "case %d: ends %g from its end "
                      "on axis %d", k, oa.pose[i] - d.end[i], i);
    wr->path = fmax(wr->path, worst_path / allowed);
    wr->case_path = worst_path / allowed, wr->case_jerk = jerk;
    wr->periods += n;
    wr->calm += b.m->ahead.calm;
    wr->merged += (int)info.merged;
    wr->pauses += op.pauses;
    dense_free(&d);
    tm_close(&a);
    tm_close(&b);
    return 0;
}

/* Runs case k and counts it as run or refused at load. */
static void tally(int k, struct worst *wr, int *refused)
{
    long periods = wr->periods;
    if (run_case(k, wr)) {
        (*refused)++;
        return;
    }
    wr->ran++;
    if (getenv("HEXCNC_RANDOM_EACH"))       /* one line a case, to compare planners by */
        printf("case %d: %s, %.3f s, %.4f of the path tolerance\n", k,
               wr->case_jerk ? "jerk-limited" : "trapezoidal",
               (double)(wr->periods - periods) * DT, wr->case_path);
}

START_TEST(test_random_dense)
{
    const char *only = getenv("HEXCNC_RANDOM_CASE"), *many = getenv("HEXCNC_RANDOM_CASES");
    const char *san = getenv("HEXCNC_SANITIZED"), *kind = getenv("HEXCNC_RANDOM_KIND");
    int cases = many && atoi(many) > 0 ? atoi(many)
              : san && !strcmp(san, "1") ? SANITIZED_CASES : CASES, refused = 0;
    if (only && atoi(only) >= cases)
        cases = atoi(only) + 1;
    struct worst wr;
    memset(&wr, 0, sizeof wr);
    for (int k = 0; k < cases; k++) {
        if ((!only || atoi(only) == k) && (!kind || k % 4 == atoi(kind)))
            tally(k, &wr, &refused);
    }
    for (size_t h = 0; !only && h < sizeof HARD_CASES / sizeof *HARD_CASES; h++)
        if (HARD_CASES[h] >= cases && (!kind || HARD_CASES[h] % 4 == atoi(kind)))
            tally(HARD_CASES[h], &wr, &refused);
    printf("random dense programs: %d run (%d refused at load), %.0f s of motion, %d feeds "
           "merged, %d pauses, %.0f %% of the look-ahead machine's periods calm; at most %.4f "
           "of a leg's speed, %.4f of its acceleration, %.4f of its jerk limit, %.4f of the path "
           "tolerance, %.4f of the largest feed (twice it under the override)\n", wr.ran,
           refused, (double)wr.periods * DT, wr.merged, wr.pauses,
           wr.periods ? 100.0 * (double)wr.calm / (double)wr.periods : 0, wr.leg_v, wr.leg_a,
           wr.leg_j, wr.path, wr.feed);
    ck_assert_int_gt(wr.ran, (only ? 0 : kind ? cases / 4 * 3 / 4 : cases * 3 / 4));
    ck_assert(wr.feed <= 1 + 1e-9);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("motion_random");
    TCase *tc = tcase_create("dense");
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, test_random_dense);
    suite_add_tcase(s, tc);
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
