/* test_motion_small_arcs.c: small arcs (LinuxCNC's issue 3773: G3 segments of radius about
 * 4 mm, measured there at 1.9-8.1x the acceleration limit): no joint exceeds its speed or
 * acceleration in any servo period, whether the arcs meet at their tangents (the curvature
 * changing sign) or at kinks, with G64 P0.01 and P0.1, on a Cartesian machine and on the
 * TMU hexapod. Rates come from differencing the commanded joints at the servo rate. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kins/hexapod.h"
#include "tests/test_motion_util.h"

#define DT 0.001

static const struct { double kink_deg, tol_mm; } cases[] = {
    { 0, 0.01 }, { 0, 0.1 }, { 5, 0.01 }, { 5, 0.1 },
};

/* Runs 40 arcs of radius 4 mm (30 degrees each) at F6000; asserts every joint within its
 * limits in every period and returns the largest ratio of joint acceleration to its limit. */
static double run_arcs(struct tk_cfg *cfg, const struct kins_ops *ops, double z, int c,
                       double *time_s)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, cfg, ops), 0);
    struct canon_prog p;
    tm_small_arcs(&p, 40, 4.0, 30, cases[c].kink_deg, 6000, z, cases[c].tol_mm);
    char err[400];
    ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
    struct tm_stats st;
    tm_run(mc.m, DT, 200000, &st, NULL, NULL);
    ck_assert_int_eq(st.last.state, MOTION_DONE);
    double worst = 0;
    for (int j = 0; j < mc.kins->njoints; j++) {
        double vl = mc.mc.joint[j].max_vel_mm_s, al = mc.mc.joint[j].max_acc_mm_s2;
        ck_assert_msg(st.max_leg_v[j] <= vl * (1 + 1e-9), "joint %d: %.3f mm/s over %.3f", j,
                      st.max_leg_v[j], vl);
        ck_assert_msg(st.max_leg_a[j] <= al * (1 + 1e-9), "joint %d: %.3f mm/s^2 over %.3f", j,
                      st.max_leg_a[j], al);
        worst = fmax(worst, st.max_leg_a[j] / al);
    }
    *time_s = st.t_s;
    canon_prog_free(&p);
    tm_close(&mc);
    return worst;
}

START_TEST(test_cartesian)
{
    struct tk_cfg *c = tm_trivial_cfg();
    for (int j = 0; j < 6; j++) {            /* joints as limited as the path */
        char sec[24];
        snprintf(sec, sizeof sec, "JOINT_%d", j);
        tk_set(c, sec, "MAX_ACCELERATION", "1000");
        tk_set(c, sec, "MAX_VELOCITY", "100");
    }
    double t, r = run_arcs(c, &kins_trivial_ops, 0, _i, &t);
    printf("small arcs, Cartesian, kinks %.0f deg, G64 P%.2f: %.3f s, peak joint "
           "acceleration %.3f of its limit\n", cases[_i].kink_deg, cases[_i].tol_mm, t, r);
}
END_TEST

START_TEST(test_hexapod)
{
    double t, r = run_arcs(tm_hexapod_cfg(), &kins_hexapod_ops, 645, _i, &t);
    printf("small arcs, TMU hexapod, kinks %.0f deg, G64 P%.2f: %.3f s, peak leg "
           "acceleration %.3f of its limit\n", cases[_i].kink_deg, cases[_i].tol_mm, t, r);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("motion_small_arcs");
    TCase *tc = tcase_create("arcs");
    tcase_set_timeout(tc, 60);
    int n = (int)(sizeof cases / sizeof cases[0]);
    tcase_add_loop_test(tc, test_cartesian, 0, n);
    tcase_add_loop_test(tc, test_hexapod, 0, n);
    suite_add_tcase(s, tc);
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
