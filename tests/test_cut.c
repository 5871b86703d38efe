/* test_cut.c: the cutting simulation: a straight cut's wall, the paper's walls with and without compensation. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check/cut.h"
#include "check/experiment.h"
#include "tests/test_check_util.h"

/* Cuts program on ini into path. */
static void cut(const char *ini, const char *prog, struct check_machine **mc, struct cut_path *p)
{
    char ip[1024], pp[1024], err[1024];
    struct canon_prog cp;
    struct check_problem pb;
    ck_assert_msg(check_machine_open(tc_path(ini, ip, sizeof ip), mc, err, sizeof err) == 0,
                  "%s", err);
    canon_prog_init(&cp);
    ck_assert_int_eq(check_machine_interpret(*mc, tc_path(prog, pp, sizeof pp), &cp, &pb), 0);
    cut_path_init(p);
    ck_assert_msg(cut_simulate(*mc, &cp, p, err, sizeof err) == 0, "%s", err);
    canon_prog_free(&cp);
}

START_TEST(test_straight_cut_wall)
{
    struct check_machine *mc;
    struct cut_path p;
    cut("configs/sim/tmu-hexapod.ini", "tests/check/straight_cut.ngc", &mc, &p);
    double a[3], pose[6] = { 0, -40, 645, 0, 0, 0 };
    ck_assert_int_eq(cut_tip_in_workpiece(mc, pose, a), 0);
    /* the tool runs along -y in the workpiece frame (the platform moves +Y) */
    struct cut_wall w = { { a[0], a[1], a[2] }, { 0, -1, 0 }, { 1, 0, 0 }, a[2] + 5, 100 };
    for (double s = 20; s <= 60; s += 10) {
        double wall = cut_wall_at(&p, &w, s);   /* the tool's side: 10 mm from its centre */
        ck_assert_msg(fabs(wall - 10) <= 2 * p.max_step_mm, "s %g: wall %.6f", s, wall);
        struct cut_wall o = w;                  /* the other side, seen the other way */
        o.n[0] = -1;
        ck_assert(fabs(cut_wall_at(&p, &o, s) - 10) <= 2 * p.max_step_mm);
    }
    ck_assert(p.max_step_mm == 1 / 400.0);
    ck_assert(isnan(cut_wall_at(&p, &w, 200)));   /* no tool passes there */
    w.top_z_mm = a[2] - 1;                         /* a top face below the tool: nothing cut */
    ck_assert(isnan(cut_wall_at(&p, &w, 40)));
    cut_path_free(&p);
    check_machine_close(mc);
}
END_TEST

/* Runs experiment run i, optionally on another machine. */
static struct exp_result run_exp(int i, const char *ini)
{
    int n;
    struct exp_run_def d = exp_runs(&n)[i];
    struct exp_result r;
    char err[512], root[1024];
    if (ini)
        d.ini = ini;
    tc_path("", root, sizeof root);
    ck_assert_msg(exp_run(root, &d, NULL, &r, err, sizeof err) == 0, "%s", err);
    return r;
}

START_TEST(test_compensated_walls_coincide)
{
    int n;
    exp_runs(&n);
    ck_assert_int_eq(n, 7);   /* Table 1's four, the G142 run, run 1 under G43.4 (twice) */
    for (int i = 0; i < n; i++) {
        struct exp_result r = run_exp(i, NULL);
        ck_assert_msg(r.spread_um < 1.0, "run %d: walls %.3f um apart", i, r.spread_um);
        ck_assert(fabs(r.part_diff_um) < 1.0);
        /* on the programmed contour, within the step size; the G43.4 run on the machine with
         * its head vertical cuts a wall drafted 4 deg, 5 tan 4 deg into the material on the
         * top face 5 mm above the contour */
        double want = strcmp(exp_runs(&n)[i].name, "1tcpv") ? 8.0
                                                           : 8.0 - 5 * tan(4 * M_PI / 180);
        for (int k = 0; k < 4; k++)
            ck_assert_msg(fabs(r.d_mm[k] - want) < r.max_step_mm, "run %d d%d %.6f", i, k + 1,
                          r.d_mm[k]);
    }
}
END_TEST

START_TEST(test_without_compensation_walls_differ_by_radii)
{
    for (int i = 0; i < 5; i += 3) {   /* run 1 (radii 10, 5) and run 4 (10, 6) */
        struct exp_result r = run_exp(i, NULL);
        double dr = r.radius_mm[1] - r.radius_mm[0];
        ck_assert(fabs(dr) >= 4);
        ck_assert_msg(fabs(r.nocomp_step_mm - dr) < 0.003, "step %.6f", r.nocomp_step_mm);
        /* the tool centre on the contour: the wall a radius into the material */
        ck_assert(fabs(r.nocomp_d_mm[0] - (8.0 - r.radius_mm[0])) < 0.003);
        ck_assert(fabs(r.nocomp_d_mm[3] - (8.0 - r.radius_mm[1])) < 0.003);
    }
}
END_TEST

START_TEST(test_quantisation_is_the_residue)
{   /* with 0.25 nm drive steps the compensated walls agree to a nanometre */
    struct exp_result r = run_exp(0, "tests/check/tmu-path1-fine.ini");
    ck_assert_msg(r.point_spread_um < 0.005, "%.6f um", r.point_spread_um);
    for (int k = 0; k < 4; k++)
        ck_assert(fabs(r.d_mm[k] - 8.0) < 1e-5);
}
END_TEST

START_TEST(test_untilted_head_breaks_coincidence)
{   /* the tool left vertical on the tilted table: the compensation's V is in the table plane,
     * the tool's radius is not, and the two tools' walls part by W2 - W1 times (1/cos B - 1)
     * and more at the top face */
    struct exp_result r = run_exp(0, "tests/check/tmu-path1-vertical.ini");
    ck_assert_msg(fabs(r.part_diff_um) > 5, "%.3f um", r.part_diff_um);
}
END_TEST

/* The test cases. */
static Suite *suite(void)
{
    Suite *s = suite_create("cut");
    TCase *tc = tcase_create("cut");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_straight_cut_wall);
    tcase_add_test(tc, test_compensated_walls_coincide);
    tcase_add_test(tc, test_without_compensation_walls_differ_by_radii);
    tcase_add_test(tc, test_quantisation_is_the_residue);
    tcase_add_test(tc, test_untilted_head_breaks_coincidence);
    suite_add_tcase(s, tc);
    return s;
}

/* Runs the suite; non-zero when a test failed. */
int main(void)
{
    SRunner *sr = srunner_create(suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
