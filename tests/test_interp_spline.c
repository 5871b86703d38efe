/* test_interp_spline.c: G5 (cubic) and G5.2/G5.3 (NURBS) as the chords motion follows: on
 * the curve, within 0.1 um of it, ending on the end point (rs274's printed form is compared
 * in tests/interp_expected/splines.ngc). */
#include <check.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "test_interp_util.h"

#define TOL_MM 1e-4

/* The chords of a program's only curve: their ends, [0] the start. Returns how many. */
static int chords(const struct canon_prog *p, const double start[2], double (*pt)[2], int max)
{
    int n = 0;
    pt[n][0] = start[0], pt[n][1] = start[1];
    for (size_t i = 0; i < p->count && n + 1 < max; i++)
        if (p->cmds[i].type == CANON_FEED && p->cmds[i].spline) {
            n++;
            pt[n][0] = p->cmds[i].end[0], pt[n][1] = p->cmds[i].end[1];
        }
    return n;
}

/* Distance from q to the polyline pt[0..n]. */
static double polyline_dist(const double (*pt)[2], int n, const double q[2])
{
    double best = 1e30;
    for (int k = 1; k <= n; k++) {
        double dx = pt[k][0] - pt[k - 1][0], dy = pt[k][1] - pt[k - 1][1];
        double l2 = dx * dx + dy * dy, t = 0;
        if (l2 > 0)
            t = fmin(1, fmax(0, ((q[0] - pt[k - 1][0]) * dx + (q[1] - pt[k - 1][1]) * dy) / l2));
        best = fmin(best, hypot(q[0] - pt[k - 1][0] - t * dx, q[1] - pt[k - 1][1] - t * dy));
    }
    return best;
}

/* G5 X30 Y0 I10 J20 P-10 Q-5 from (0, 0): control points (0,0) (10,20) (20,-5) (30,0), so
 * x = 30 t exactly and y(t) = 60 t (1-t)^2 - 15 t^2 (1-t). Every chord end is on it, no
 * point of it is more than 0.1 um from the chords, and the next G5 without I J leaves along
 * the direction this one arrived in. */
START_TEST(cubic_on_the_curve)
{
    struct canon_prog p;
    interp_ok("G21 G17 G90 F100\nG0 X0 Y0 Z2\nG5 X30 Y0 I10 J20 P-10 Q-5\nM2\n", &p);
    static double pt[100001][2];
    int n = chords(&p, (double[2]){ 0, 0 }, pt, 100001);
    ck_assert_int_gt(n, 100);
    ck_assert_int_eq(nth(&p, CANON_FEED, 0)->spline, 1);
    ck_assert_int_eq(nth(&p, CANON_FEED, 0)->ivalue, 4);   /* rs274's NURBS_FEED(4, ...) */
    for (int k = 0; k <= n; k++) {
        double t = pt[k][0] / 30;
        ck_assert_double_eq_tol(pt[k][1], 60 * t * (1 - t) * (1 - t) - 15 * t * t * (1 - t),
                                1e-9);
    }
    ck_assert(pt[n][0] == 30 && pt[n][1] == 0);
    ck_assert(last_move(&p)->end[2] == 2);
    double worst = 0;
    for (int s = 0; s <= 200000; s++) {
        double t = s / 200000.0;
        double q[2] = { 30 * t, 60 * t * (1 - t) * (1 - t) - 15 * t * t * (1 - t) };
        worst = fmax(worst, polyline_dist((const double (*)[2])pt, n, q));
    }
    ck_assert_msg(worst <= TOL_MM && worst > TOL_MM / 10, "worst %g", worst);
    canon_prog_free(&p);

    /* the second G5 starts with I J = 10 5 (-P -Q of the first): control points (30,0)
     * (40,5) (50,5) (60,0), so x = 30 + 30 t and y = 15 t (1-t) */
    interp_ok("G21 G17 G90 F100\nG0 X0 Y0\nG5 X30 Y0 I10 J20 P-10 Q-5\n"
              "G5 X60 Y0 P-10 Q5\nG1 X61\nM2\n", &p);
    int second = 0;
    for (int k = 0; k < count_type(&p, CANON_FEED); k++) {
        const struct canon_cmd *c = nth(&p, CANON_FEED, k);
        second += c->spline == 1;
        if (second == 2 && c->spline) {
            double u = (c->end[0] - 30) / 30;
            ck_assert_double_eq_tol(c->end[1], 15 * u * (1 - u), 1e-9);
        }
    }
    ck_assert_int_eq(second, 2);
    ck_assert_int_eq(last_move(&p)->spline, 0);   /* G1 after it, as written */
    canon_prog_free(&p);
}
END_TEST

/* A quadratic NURBS with weights 1, sqrt(2)/2, 1 is an exact quarter circle: from (10, 0)
 * over (10, 10) to (0, 10), radius 10 about the origin. Every chord end is on the circle and
 * every chord's sagitta (its distance from the arc) is within 0.1 um. */
START_TEST(nurbs_quarter_circle)
{
    struct canon_prog p;
    interp_ok("G21 G17 G90 F100\nG0 X10 Y0\nG5.2 X10 Y10 P0.7071067811865476 L3\n"
              "X0 Y10 P1\nG5.3\nM2\n", &p);
    static double pt[100001][2];
    int n = chords(&p, (double[2]){ 10, 0 }, pt, 100001);
    ck_assert_int_gt(n, 10);
    ck_assert_int_eq(nth(&p, CANON_FEED, 0)->ivalue, 3);
    ck_assert_int_eq(nth(&p, CANON_FEED, 0)->line, 5);   /* the G5.3 block */
    double worst = 0;
    for (int k = 0; k <= n; k++)
        ck_assert_double_eq_tol(hypot(pt[k][0], pt[k][1]), 10, 1e-9);
    for (int k = 1; k <= n; k++)
        worst = fmax(worst, 10 - hypot(0.5 * (pt[k][0] + pt[k - 1][0]),
                                       0.5 * (pt[k][1] + pt[k - 1][1])));
    ck_assert_msg(worst <= TOL_MM && worst > TOL_MM / 10, "worst %g", worst);
    ck_assert(pt[n][0] == 0 && pt[n][1] == 10);
    canon_prog_free(&p);
}
END_TEST

/* The test's own NURBS, from the definition (Cox-de Boor recursion on LinuxCNC's knots:
 * order k zeros, 1 .. n-k+1, order k times n-k+2). */
static double basis(int i, int k, double u, const double *t, double umax)
{
    if (k == 1)
        return (t[i] <= u && u < t[i + 1]) || (u == umax && t[i] < u && t[i + 1] == u);
    double a = t[i + k - 1] > t[i] ? (u - t[i]) / (t[i + k - 1] - t[i]) : 0;
    double b = t[i + k] > t[i + 1] ? (t[i + k] - u) / (t[i + k] - t[i + 1]) : 0;
    return a * basis(i, k - 1, u, t, umax) + b * basis(i + 1, k - 1, u, t, umax);
}

/* Order 4 with unequal weights: the curve from the definition, sampled densely, lies within
 * 0.1 um of the chords, which end on the last control point. */
START_TEST(nurbs_order4_weights)
{
    static const double cp[6][3] = { { 0, 0, 1 }, { 5, 10, 2 }, { 12, 9, 0.5 },
                                     { 18, -4, 1 }, { 25, 3, 3 }, { 30, 0, 1 } };
    struct canon_prog p;
    interp_ok("G21 G17 G90 F100\nG0 X0 Y0\nG5.2 X5 Y10 P2 L4\nX12 Y9 P0.5\nX18 Y-4 P1\n"
              "X25 Y3 P3\nX30 Y0 P1\nG5.3\nM2\n", &p);
    static double pt[100001][2];
    int n = chords(&p, (double[2]){ 0, 0 }, pt, 100001);
    ck_assert_int_eq(nth(&p, CANON_FEED, 0)->ivalue, 6);
    ck_assert(pt[n][0] == 30 && pt[n][1] == 0);
    int k = 4, nn = 5;
    double t[10], umax = nn - k + 2, worst = 0;
    for (int i = 0; i <= nn + k; i++)
        t[i] = i < k ? 0 : i <= nn ? i - k + 1 : umax;
    for (int s = 0; s <= 30000; s++) {
        double u = umax * s / 30000, q[2] = { 0, 0 }, den = 0;
        for (int i = 0; i <= nn; i++) {
            double b = basis(i, k, u, t, umax) * cp[i][2];
            q[0] += b * cp[i][0], q[1] += b * cp[i][1], den += b;
        }
        q[0] /= den, q[1] /= den;
        worst = fmax(worst, polyline_dist((const double (*)[2])pt, n, q));
    }
    ck_assert_msg(worst <= TOL_MM && worst > TOL_MM / 20, "worst %g over %d chords", worst, n);
    canon_prog_free(&p);
}
END_TEST

/* Under G93 the chords share the block's time by length (G5 F2: half a minute in all). */
START_TEST(cubic_inverse_time)
{
    struct canon_prog p;
    interp_ok("G21 G17\nG0 X0 Y0\nG93 G5 X30 Y0 I10 J20 P-10 Q-5 F2\nM2\n", &p);
    double total = 0;
    for (int k = 0; k < count_type(&p, CANON_FEED); k++)
        total += nth(&p, CANON_FEED, k)->inverse_time_min;
    ck_assert_double_eq_tol(total, 0.5, 1e-12);
    canon_prog_free(&p);
}
END_TEST

/* LinuxCNC's errors (and hexcnc's where it refuses what LinuxCNC lets through), on line 3. */
START_TEST(spline_errors)
{
    static const struct { const char *prog, *msg; int line; } bad[] = {
        { "G21 F100\nG0 X0 Y0\nG5 X10 Y0 I1 P1 Q1\nM2\n", "G5 needs both I and J", 3 },
        { "G21 F100\nG0 X0 Y0\nG5 X10 Y0 I1 J1 P1\nM2\n", "G5 needs both P and Q", 3 },
        { "G21 F100\nG18\nG5 X10 Y0 I1 J1 P1 Q1\nM2\n", "XY plane (G17)", 3 },
        { "G21 F100\nG0 X0\nG5 X10 Z1 I1 J1 P1 Q1\nM2\n", "may not move Z", 3 },
        { "G21 F100\nG0 X0\nG5.3\nM2\n", "G5.3 without G5.2 first", 3 },
        { "G21 F100\nG5.2 X1 Y1 P1\nX2 Y2\nM2\n", "positive weight P", 3 },
        { "G21 F100\nG5.2 X1 Y1 P1\nX2 Y2 P0\nM2\n", "positive weight P", 3 },
        { "G21 F100\nG5.2 X1 Y1 P1\nX2 P1\nM2\n", "both X and Y", 3 },
        { "G21 F100\nG5.2 X1 Y1 P1 L4\nG5.3\nM2\n", "order L = 4 needs at least 4", 3 },
        { "G21 F100\nG18\nG5.2 X1 Y1 P1\nM2\n", "XY plane (G17)", 3 },
        { "G21 F100\nG93\nG5.2 X1 Y1 P1 F1\nM2\n", "inverse time", 3 },
        { "G21 F100\nG5.2 X1 Y1 P1\nX2 Y0 Z1 P1\nM2\n", "no Z, A, B or C", 3 },
        { "G21 F100\nG5.2 X1 Y1 P1\nG5.3 X3 Y3\nM2\n", "block of its own", 3 },
        { "G21 F100\nG5.2 X1 Y1 P1\nX2 Y0 P1\nG5.3\nX3 Y3\nM2\n", "no motion mode", 5 },
    };
    struct canon_prog p;
    struct interp_error err;
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        int rc = run_text(bad[i].prog, &p, &err);
        ck_assert_msg(rc != INTERP_OK, "accepted: %s", bad[i].prog);
        ck_assert_msg(strstr(err.message, bad[i].msg), "%s: %s", bad[i].prog, err.message);
        ck_assert_int_eq(err.line, bad[i].line);
        canon_prog_free(&p);
    }
}
END_TEST

static Suite *spline_suite(void)
{
    Suite *s = suite_create("interp_spline");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, cubic_on_the_curve);
    tcase_add_test(tc, nurbs_quarter_circle);
    tcase_add_test(tc, nurbs_order4_weights);
    tcase_add_test(tc, cubic_inverse_time);
    tcase_add_test(tc, spline_errors);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(spline_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
