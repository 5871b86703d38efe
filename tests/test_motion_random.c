/* test_motion_random.c: random dense programs, made the way CAM code comes, against what the
 * planner and the executor promise.
 *
 * The dense code's way through motion has many shortcuts (merged feeds, blend arcs, the
 * knots' look-ahead, a check's four-period look-ahead and its calm period), each tested on
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
 *   - give, run the way a check runs it (rates off, the brief record, the four-period
 *     look-ahead), the same record and executor state bit for bit in every period.
 * The seeds are fixed: a failure names its case, which reruns alone with
 * HEXCNC_RANDOM_CASE=N; HEXCNC_RANDOM_CASES=N runs N cases instead of CASES. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_merge.h"
#include "motion/motion_priv.h"
#include "tests/test_motion_same.h"
#include "tests/test_motion_util.h"

#define DT 0.001
#define CASES 48
#define FIRST_LINE 3           /* the first move's line (the path mode is on line 2) */

/* A small deterministic generator (the C library's rand differs between systems). */
static double uniform(unsigned long long *s)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 9007199254740992.0;
}

/* What a case's program is: its path mode and the moves' start points (move i on line
 * FIRST_LINE + i is command cmd[i] of the program). */
struct dense {
    struct canon_prog p;
    int g61;
    double tol_p, tol_q, max_feed_mm_s;
    int n;
    double (*from)[6];
    size_t *cmd;
    double end[6];
};

/* A turn of the heading h (unit, X Y Z) by ang rad about Z, its Z part nudged by dz. */
static void turn(double h[3], double ang, double dz)
{
    double x = h[0] * cos(ang) - h[1] * sin(ang), y = h[0] * sin(ang) + h[1] * cos(ang);
    double z = fmax(-0.3, fmin(0.3, h[2] + dz)), n = sqrt(x * x + y * y + z * z);
    h[0] = x / n, h[1] = y / n, h[2] = z / n;
}

/* Whether a pose is inside the box the cases stay in. */
static int inside(const double q[6])
{
    int ok = fabs(q[0]) <= 55 && fabs(q[1]) <= 55 && q[2] >= 632 && q[2] <= 658;
    for (int i = 3; i < 6; i++)
        ok = ok && fabs(q[i]) <= 7;
    return ok;
}

static void add_move(struct dense *d, int i, const double at[6])
{
    memcpy(d->from[i], at, sizeof d->from[i]);
    d->cmd[i] = d->p.count;
}

/* A random dense program (see the top of the file). */
static void dense_prog(struct dense *d, unsigned long long *s)
{
    static const double tols[] = { 0.001, 0.005, 0.01, 0.05 };
    memset(d, 0, sizeof *d);
    canon_prog_init(&d->p);
    double at[6] = { 0, 0, 645, 0, 0, 0 };
    memcpy(d->p.start, at, sizeof at);
    d->g61 = uniform(s) < 0.2;
    d->tol_p = d->g61 ? 0 : tols[(int)(uniform(s) * 4)];
    double q = uniform(s);
    d->tol_q = d->g61 || q < 0.4 ? 0 : q < 0.7 ? d->tol_p : 0.5 * d->tol_p;
    struct canon_cmd pm = { .type = CANON_PATH_MODE, .line = 2, .file = "test.ngc",
                            .value = d->tol_p, .ivalue = d->g61 ? 610 : 640,
                            .naive_tol_mm = d->tol_q };
    if (canon_prog_sink(&d->p, &pm))
        abort();
    d->n = 150 + (int)(uniform(s) * 350);
    d->from = calloc((size_t)d->n, sizeof *d->from);
    d->cmd = calloc((size_t)d->n, sizeof *d->cmd);
    if (!d->from || !d->cmd)
        abort();
    int abc_style = (int)(uniform(s) * 3);     /* still, drifting, drifting with jumps */
    double feed = 300 + uniform(s) * 11700, h[3] = { 1, 0, 0 }, rate[3] = { 0, 0, 0 };
    d->max_feed_mm_s = feed / 60;
    turn(h, uniform(s) * 2 * M_PI, 0);
    for (int i = 0; i < d->n; i++) {
        int line = FIRST_LINE + i;
        double to[6], u = uniform(s);
        if (uniform(s) < 0.05) {               /* a new feed */
            feed = 300 + uniform(s) * 11700;
            d->max_feed_mm_s = fmax(d->max_feed_mm_s, feed / 60);
        }
        if (abc_style && uniform(s) < 0.1)     /* A B C turn at a new rate (deg per mm) */
            for (int k = 0; k < 3; k++)
                rate[k] = -0.5 + uniform(s);
        add_move(d, i, at);
        if (u < 0.05) {                        /* a small arc in XY, either way, tangent */
            double r = 0.2 + uniform(s) * 4.8, sweep = (10 + uniform(s) * 160) * M_PI / 180;
            int ccw = uniform(s) < 0.5;
            double side = ccw ? 1 : -1, c[3], n[3] = { 0, 0, side }, hn = hypot(h[0], h[1]);
            c[0] = at[0] - side * r * h[1] / hn, c[1] = at[1] + side * r * h[0] / hn;
            c[2] = at[2];
            double a0 = atan2(at[1] - c[1], at[0] - c[0]), a1 = a0 + side * sweep;
            memcpy(to, at, sizeof to);
            to[0] = c[0] + r * cos(a1), to[1] = c[1] + r * sin(a1);
            if (inside(to)) {
                /* (about the normal n the arc turns counter-clockwise: n is -Z for G2) */
                tm_arc(&d->p, line, to, c, n, 1, feed);
                double hz = h[2];
                h[0] = -side * sin(a1), h[1] = side * cos(a1), h[2] = 0;
                turn(h, 0, hz);
                memcpy(at, to, sizeof at);
                continue;
            }
        }
        double len = exp(log(0.002) + uniform(s) * (log(1.0) - log(0.002)));
        double v = uniform(s);
        if (v < 0.03)
            len = 0;                           /* the same point again */
        else if (v < 0.05)
            len = 2 + uniform(s) * 8;          /* a longer move */
        double w = uniform(s), ang = 0;
        if (w < 0.3)
            ang = 0;                           /* collinear */
        else if (w < 0.8)
            ang = uniform(s) * 3 * M_PI / 180;
        else if (w < 0.95)
            ang = (3 + uniform(s) * 27) * M_PI / 180;
        else
            ang = (30 + uniform(s) * 145) * M_PI / 180;
        turn(h, uniform(s) < 0.5 ? ang : -ang, 0.02 * (uniform(s) - 0.5));
        memcpy(to, at, sizeof to);
        for (int k = 0; k < 3; k++)
            to[k] += len * h[k], to[3 + k] += len * rate[k];
        if (abc_style == 2 && uniform(s) < 0.03)   /* a turn of A B C in place, or nearly */
            for (int k = 0; k < 3; k++)
                to[k] = at[k] + (uniform(s) < 0.5 ? 0 : 0.002 * h[k]),
                to[3 + k] = at[3 + k] + (uniform(s) - 0.5);
        if (!inside(to)) {                     /* back towards the middle: a sharp corner */
            double c[3] = { -at[0], -at[1], 645 - at[2] }, n = 0;
            for (int k = 0; k < 3; k++)
                n += c[k] * c[k];
            n = sqrt(n);
            for (int k = 0; k < 3; k++)
                h[k] = c[k] / n, to[k] = at[k] + len * h[k];
            for (int k = 3; k < 6; k++)
                rate[k - 3] = -0.1 * at[k], to[k] = at[k] + len * rate[k - 3];
        }
        tm_add(&d->p, CANON_FEED, line, to, feed, 0);
        memcpy(at, to, sizeof at);
    }
    memcpy(d->end, at, sizeof at);
}

static void dense_free(struct dense *d)
{
    canon_prog_free(&d->p);
    free(d->from);
    free(d->cmd);
}

/* Distance of the commanded X Y Z q from the programmed moves within `reach` moves of the
 * one on `line`, and the MOTION_MERGE_MAX before those (a merged run of feeds carries its
 * last feed's line). */
static double off_path(const struct dense *d, const double q[3], int line, int reach)
{
    int j = line - FIRST_LINE, back = reach + MOTION_MERGE_MAX;
    int lo = j - back < 0 ? 0 : j - back;
    int hi = j + reach >= d->n ? d->n - 1 : j + reach;
    double best = HUGE_VAL;
    if (j < 0)                                 /* (before the first move: at the start) */
        return tm_dist_seg(q, d->p.start, d->p.start);
    for (int i = lo; i <= hi; i++) {
        const struct canon_cmd *c = &d->p.cmds[d->cmd[i]];
        best = fmin(best, c->type == CANON_ARC ? tm_dist_arc(q, d->from[i], c)
                                                : tm_dist_seg(q, d->from[i], c->end));
    }
    return best;
}

/* The machine of case k: the TMU hexapod or the leg-bound one, with jerk limits on odd
 * cases (a 20 ms average on the leg-bound machine, 40 ms on the TMU's). */
static struct tk_cfg *case_cfg(int k)
{
    int legs = (k / 2) % 2, jerk = k % 2;
    struct tk_cfg *c = legs ? tm_leg_bound_hexapod_cfg() : tm_hexapod_cfg();
    ck_assert_ptr_nonnull(c);
    if (jerk && legs)
        tm_set_jerk(c, 500000, 200000, 20000);
    else if (jerk)
        tm_set_jerk(c, 50000, 30000, 50000);
    return c;
}

/* The worst of all cases, as shares of the limits. */
struct worst {
    double leg_v, leg_a, leg_j, path, feed;
    double path_small;         /* (with jerk limits where half of P is below the rounding's
                                * share of KINEMATIC_TOLERANCE: see run_case) */
    long periods, calm;
    int ran, merged;
};

/* Runs case k; 0 when it ran, 1 when it was refused at load as it must be. */
static int run_case(int k, struct worst *wr)
{
    unsigned long long seed = 0x2545f4914f6cdd1dULL * (unsigned long long)(k + 1);
    struct tm_machine a, b;
    ck_assert_int_eq(tm_open(&a, case_cfg(k), &kins_hexapod_ops), 0);
    ck_assert_int_eq(tm_open(&b, case_cfg(k), &kins_hexapod_ops), 0);
    struct dense d;
    dense_prog(&d, &seed);
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
    /* G64 P: blends within P; with jerk limits half of it, and the average's rounding the
     * other half or its share of KINEMATIC_TOLERANCE; the merge's Q on top. Where half of P
     * is below that share (P 0.001 on the TMU machine) the blend arcs of sharp corners are so
     * small that the average's window reaches past them and the rounding's bound does not
     * hold (docs/motion.md, "Jerk limiting"): 400 cases took the tool up to 1.34 times as
     * far; there the test holds it to 1.5 times, so that it grows no worse unseen. */
    double allowed = d.tol_q + (jerk ? fmax(d.tol_p, 0.5 * d.tol_p + mc->kin_tol_mm)
                                     : d.tol_p) + 1e-6;
    int small_p = jerk && !d.g61 && 0.5 * d.tol_p < KIN_TOL_SHARE * mc->kin_tol_mm;
    double held = small_p ? 1.5 * allowed : allowed;
    double v0[6] = { 0 }, a0[6] = { 0 }, worst_path = 0;
    struct motion_out oa, ob, prev;
    memset(&oa, 0, sizeof oa);
    ck_assert_int_eq(motion_step(a.m, DT, &prev), MOTION_OK);
    ck_assert_int_eq(motion_step(b.m, DT, &ob), MOTION_OK);
    same_brief(&prev, &ob);
    long n = 1, bound = (long)(2 * info.time_s / DT) + 2000;
    int reach = jerk ? 400 : 8;               /* the average's line lags by T/2 */
    do {
        ck_assert_int_eq(motion_step(a.m, DT, &oa), MOTION_OK);
        ck_assert_int_eq(motion_step(b.m, DT, &ob), MOTION_OK);
        same_executor(a.m, b.m);
        same_brief(&oa, &ob);
        double sp = 0;
        for (int i = 0; i < 3; i++)
            sp += (oa.pose[i] - prev.pose[i]) * (oa.pose[i] - prev.pose[i]);
        wr->feed = fmax(wr->feed, sqrt(sp) / DT / d.max_feed_mm_s);
        double off = off_path(&d, oa.pose, oa.line, reach);
        worst_path = fmax(worst_path, off);
        ck_assert_msg(off <= held, "case %d: %.6f mm off the path at line %d (held to "
                      "%.6f)", k, off, oa.line, held);
        for (int j = 0; j < 6; j++) {
            const struct motion_joint_config *jc = &mc->joint[j];
            double v = (oa.joint_pos[j] - prev.joint_pos[j]) / DT, acc = (v - v0[j]) / DT;
            ck_assert_msg(fabs(v) <= jc->max_vel_mm_s * (1 + 1e-9), "case %d: leg %d at "
                          "%.6f mm/s, period %ld", k, j + 1, fabs(v), n);
            wr->leg_v = fmax(wr->leg_v, fabs(v) / jc->max_vel_mm_s);
            if (n > 1) {
                ck_assert_msg(fabs(acc) <= jc->max_acc_mm_s2 * (1 + 1e-6), "case %d: leg %d "
                              "at %.4f mm/s^2, period %ld", k, j + 1, fabs(acc), n);
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
    } while (oa.state == MOTION_RUNNING && ++n < bound);
    ck_assert_msg(oa.state == MOTION_DONE, "case %d: state %d after %ld periods (%s)", k,
                  oa.state, n, motion_last_error(a.m));
    for (int i = 0; i < 6; i++)
        ck_assert_msg(fabs(oa.pose[i] - d.end[i]) <= 1e-9, "case %d: ends %g from its end "
                      "on axis %d", k, oa.pose[i] - d.end[i], i);
    if (small_p)
        wr->path_small = fmax(wr->path_small, worst_path / allowed);
    else
        wr->path = fmax(wr->path, worst_path / allowed);
    wr->periods += n;
    wr->calm += b.m->ahead.calm;
    wr->merged += (int)info.merged;
    dense_free(&d);
    tm_close(&a);
    tm_close(&b);
    return 0;
}

START_TEST(test_random_dense)
{
    const char *only = getenv("HEXCNC_RANDOM_CASE"), *many = getenv("HEXCNC_RANDOM_CASES");
    int cases = many && atoi(many) > 0 ? atoi(many) : CASES, refused = 0;
    if (only && atoi(only) >= cases)
        cases = atoi(only) + 1;
    struct worst wr;
    memset(&wr, 0, sizeof wr);
    for (int k = 0; k < cases; k++) {
        if (only && atoi(only) != k)
            continue;
        if (run_case(k, &wr))
            refused++;
        else
            wr.ran++;
    }
    printf("random dense programs: %d run (%d refused at load), %.0f s of motion, %d feeds "
           "merged, %.0f %% of the look-ahead machine's periods calm; at most %.4f of a leg's "
           "speed, %.4f of its acceleration, %.4f of its jerk limit, %.4f of the path "
           "tolerance (%.4f with jerk limits and P below the kinematic tolerance), %.4f of the "
           "largest feed\n", wr.ran, refused, (double)wr.periods * DT, wr.merged,
           wr.periods ? 100.0 * (double)wr.calm / (double)wr.periods : 0, wr.leg_v, wr.leg_a,
           wr.leg_j, wr.path, wr.path_small, wr.feed);
    ck_assert_int_gt(wr.ran, (only ? 0 : cases * 3 / 4));
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
