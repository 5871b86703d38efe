/* test_motion_chords.c: the tool between set points on the hexapod. Drives move their legs
 * linearly from one set point to the next, so the tool leaves the planned path between them:
 * along blend arcs and programmed arcs (the chord caps and their reach, motion_chord.c), at
 * G61 corners (held for a set point) and where two arcs' reaches meet, measured through the
 * forward kinematics of the interpolated legs at 100 Hz to 1 kHz set points. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/test_motion_util.h"

#define DT 0.001
#define TOL 0.05               /* G64 P, mm */

/* Measures p's chords on the fast hexapod with set points every T_s (tm_chord_deviation);
 * fails the test when the run or a forward solve fails. */
static void chord_deviation(const struct canon_prog *p, double T_s, double tol_mm,
                            struct tm_chord *d)
{
    ck_assert_msg(tm_chord_deviation(p, T_s, tol_mm, d) == 0, "chord measurement failed");
}

/* A five-axis zigzag on the TMU hexapod under G64 P0.05 */
static const double ZIG[6][6] = {
    {-30, -20, 640, -4, 3, -5}, {-15, 20, 645, 4, -3, 5}, {0, -20, 650, -4, 3, -5},
    {15, 20, 645, 4, -3, 5}, {30, -20, 640, -4, 3, -5}, {30, 20, 635, 0, 0, 0},
};

/* On the hexapod with tight legs (20 mm/s, 200 mm/s^2) the blended zigzag keeps every leg
 * within its limits (measured from successive leg commands); programmed at 500 mm/s with
 * fast limits, the tool point, through the forward kinematics of legs interpolated linearly
 * between 1 kHz set points, stays within KINEMATIC_TOLERANCE of the blended path, hence
 * within P + that of the programmed zigzag. */
START_TEST(test_hexapod_zigzag)
{
    double t_g[2];
    for (int g = 0; g < 2; g++) {
        struct tk_cfg *c = tm_hexapod_cfg();
        ck_assert_ptr_nonnull(c);
        tm_set_legs(c, "20", "200");
        struct tm_machine mc;
        ck_assert_int_eq(tm_open(&mc, c, &kins_hexapod_ops), 0);
        struct canon_prog p;
        tm_polyline_prog(&p, ZIG, 6, g ? 610 : 640, g ? 0 : TOL, 3000);
        tm_load_start(mc.m, &p);
        struct motion_plan_info info;
        motion_plan_info(mc.m, &info);
        ck_assert_int_eq(info.blends, g ? 0 : 4);
        struct tm_stats s;
        tm_run(mc.m, DT, 1000000, &s, NULL, NULL);
        ck_assert_int_eq(s.last.state, MOTION_DONE);
        for (int i = 0; i < 6; i++) {
            ck_assert_msg(s.max_leg_v[i] <= 20 * (1 + 1e-9), "leg %d at %.4f mm/s", i + 1,
                          s.max_leg_v[i]);
            ck_assert_msg(s.max_leg_a[i] <= 200 * 1.001, "leg %d at %.2f mm/s^2", i + 1,
                          s.max_leg_a[i]);
            ck_assert_double_eq_tol(s.last.pose[i], ZIG[5][i], 1e-9);
        }
        t_g[g] = s.t_s;
        canon_prog_free(&p);
        tm_close(&mc);
    }
    printf("hexapod zigzag, legs 20 mm/s: G64 P0.05 %.3f s, G61 %.3f s\n", t_g[0], t_g[1]);

    struct canon_prog p;
    tm_polyline_prog(&p, ZIG, 6, 640, TOL, 30000);
    struct tm_chord d;
    chord_deviation(&p, DT, 0.001, &d);
    ck_assert_int_eq(d.blends, 4);
    ck_assert_msg(d.path_mm <= 0.001, "off the blended path by %.6f mm", d.path_mm);
    ck_assert_msg(d.prog_mm <= TOL + 0.001, "off the zigzag by %.6f mm", d.prog_mm);
    printf("hexapod zigzag at 500 mm/s, 1 kHz set points: %.6f mm off the blended path, %.6f mm off "
           "the programmed zigzag\n", d.path_mm, d.prog_mm);
    canon_prog_free(&p);
}
END_TEST

/* Set points at 100 Hz, 250 Hz (the Modbus drives), 500 Hz (the CAN drives) and 1 kHz with
 * 2000 mm/s^2: a set-point chord that starts on a blend arc (0.03 mm radius here) and ends on
 * the line accelerating away from it must not cut the arc by more than KINEMATIC_TOLERANCE:
 * the arcs and the line ends within one chord of them are capped by the arc's curvature
 * (without that cap the chord left the blended path by 0.0011 mm at 100 Hz). In G61 every
 * corner is held for one set-point period, so a set point lands on it and no chord cuts it
 * (without the hold: 0.004046 mm at 100 Hz); the planned time counts the holds and the run
 * takes it. */
START_TEST(test_setpoint_chords)
{
    static const double periods_s[4] = {0.01, 0.004, 0.002, 0.001};
    for (int k = 0; k < 4; k++) {
        struct canon_prog p;
        tm_polyline_prog(&p, ZIG, 6, 640, TOL, 30000);
        struct tm_chord d, d61;
        chord_deviation(&p, periods_s[k], 0.001, &d);
        ck_assert_int_eq(d.blends, 4);
        canon_prog_free(&p);
        tm_polyline_prog(&p, ZIG, 6, 610, 0, 30000);
        chord_deviation(&p, periods_s[k], 0.001, &d61);
        printf("hexapod zigzag G64 P0.05 at 500 mm/s, %.0f Hz set points: %.6f mm off the blended "
               "path, %.3f s; G61 %.6f mm, %.3f s (%zu corners held)\n", 1 / periods_s[k],
               d.path_mm, d.time_s, d61.path_mm, d61.time_s, d61.stops_held);
        ck_assert_msg(d.path_mm <= 0.001, "%.0f Hz: off the blended path by %.6f mm",
                      1 / periods_s[k], d.path_mm);
        ck_assert_msg(d.prog_mm <= TOL + 0.001, "off the zigzag by %.6f mm", d.prog_mm);
        ck_assert_msg(d61.path_mm <= 0.001, "%.0f Hz: G61 off the zigzag by %.6f mm",
                      1 / periods_s[k], d61.path_mm);
        ck_assert_int_eq(d61.stops_held, 4);
        ck_assert_msg(fabs(d61.time_s - d61.plan_s) <= periods_s[k] + 1e-9,
                      "G61 ran %.4f s, planned %.4f s", d61.time_s, d61.plan_s);
        canon_prog_free(&p);
    }
}
END_TEST

/* The hold does not depend on the drive's phase: with a 1 ms servo period and drives taking a
 * set point every 10 ms, 4 ms or 2 ms, whichever servo period the drive samples first, the
 * G61 zigzag stays within KINEMATIC_TOLERANCE (without the hold, at 100 Hz: 0.003579 to
 * 0.008009 mm depending on the phase; at 250 Hz up to 0.001250 mm). */
START_TEST(test_stop_phases)
{
    static const double periods_s[3] = {0.01, 0.004, 0.002};
    struct canon_prog p;
    tm_polyline_prog(&p, ZIG, 6, 610, 0, 30000);
    for (int k = 0; k < 3; k++) {
        int every = (int)lround(periods_s[k] / DT);
        double worst = 0;
        for (int phase = 0; phase < every; phase++) {
            struct tm_chord d;
            ck_assert_msg(tm_chord_deviation_at(&p, periods_s[k], DT, phase, 0.001, &d) == 0,
                          "chord measurement failed");
            ck_assert_msg(d.path_mm <= 0.001, "%.0f Hz set points, phase %d ms: %.6f mm off",
                          1 / periods_s[k], phase, d.path_mm);
            ck_assert_msg(fabs(d.time_s - d.plan_s) <= DT + 1e-9, "ran %.4f s, planned %.4f s",
                          d.time_s, d.plan_s);
            worst = fmax(worst, d.path_mm);
        }
        printf("G61 zigzag, %.0f Hz set points on a 1 kHz servo, every phase: at most %.6f mm "
               "off\n", 1 / periods_s[k], worst);
    }
    canon_prog_free(&p);
}
END_TEST

/* A programmed arc as G141/G142 make at an outside corner: a plane-0 arc of 0.3 mm (a small tool's
 * radius) in a tilted plane, tangent to the lines before and after it, at 500 mm/s with
 * 100 Hz set points: the chords that reach onto the arc from the lines stay within
 * KINEMATIC_TOLERANCE of the path. */
START_TEST(test_arc_chords)
{
    const double r = 0.3, c0[3] = {0, 0, 640};
    double e1[3] = {0.8, 0, 0.6}, e2[3] = {0, 1, 0}, n[3], A[6] = {0}, B[6] = {0}, S[6] = {0},
           E[6] = {0}, C[3];
    n[0] = e1[1] * e2[2] - e1[2] * e2[1], n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    for (int i = 0; i < 3; i++) {
        C[i] = c0[i];
        A[i] = C[i] + r * e1[i], B[i] = C[i] + r * e2[i];
        S[i] = A[i] - 20 * e2[i], E[i] = B[i] - 20 * e1[i];
    }
    struct canon_prog p;
    canon_prog_init(&p);
    memcpy(p.start, S, sizeof p.start);
    tm_add(&p, CANON_FEED, 10, A, 30000, 0);
    tm_arc(&p, 11, B, C, n, 1, 30000);
    tm_add(&p, CANON_FEED, 12, E, 30000, 0);
    struct tm_chord d;
    chord_deviation(&p, 0.01, 0.001, &d);
    printf("tilted 0.3 mm arc between tangent lines at 500 mm/s, 100 Hz set points: %.6f mm off "
           "the path, %.3f s\n", d.path_mm, d.time_s);
    ck_assert_msg(d.path_mm <= 0.001, "off the path by %.6f mm", d.path_mm);
    canon_prog_free(&p);
}
END_TEST

/* Two arcs close together, all tangent: a 3 mm arc, a line of 0.1 mm, a 0.03 mm arc, at
 * 500 mm/s with 100 Hz set points. The line lies within reach of both arcs' chords (all of
 * it of the large one's, its last 0.016 mm of the small one's), and its two knots are capped
 * by the large arc and by both: the speed must come down to the small arc's cap where that
 * arc's reach begins, not at the line's end only. (Without a knot there it ran 6.9 mm/s where
 * the small arc allows 1.47 mm/s, decelerating between the line's two knots.) */
START_TEST(test_meeting_reaches)
{
    const double z = 640, r1 = 3, r2 = 0.03, gap = 0.1, nz[3] = {0, 0, 1}, Ts = 0.01;
    /* up the y axis to (0,0); left round (-r1,0) to (-r1,r1), heading -x; the gap to
     * (-r1-gap, r1); left round (-r1-gap, r1-r2) to (-r1-gap-r2, r1-r2), heading -y */
    double S[6] = {0, -20, z}, A[6] = {0, 0, z}, C1[3] = {-r1, 0, z}, B[6] = {-r1, r1, z},
           G[6] = {-r1 - gap, r1, z}, C2[3] = {-r1 - gap, r1 - r2, z},
           H[6] = {-r1 - gap - r2, r1 - r2, z}, E[6] = {-r1 - gap - r2, r1 - r2 - 20, z};
    const double *ends[5] = {A, B, G, H, E}, *centres[5] = {NULL, C1, NULL, C2, NULL};
    struct canon_prog p;
    canon_prog_init(&p);
    memcpy(p.start, S, sizeof p.start);
    for (int i = 0; i < 5; i++) {
        if (centres[i])
            tm_arc(&p, 10 + i, ends[i], centres[i], nz, 1, 30000);
        else
            tm_add(&p, CANON_FEED, 10 + i, ends[i], 30000, 0);
    }
    struct tk_cfg *c = tm_fast_hexapod_cfg(DT, 0.001);
    ck_assert_ptr_nonnull(c);
    tk_setf(c, "TRAJ", "SETPOINT_PERIOD", Ts * 1e9);
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, c, &kins_hexapod_ops), 0);
    tm_load_start(mc.m, &p);
    /* the small arc's cap (the longest chord its curvature allows, over one set-point
     * period) and its reach, motion_chord.c */
    double chord = sqrt(8 * 0.9 * 0.001 * r2), cap = chord / Ts, reach = 1.1 * chord;
    struct motion_out o, prev;
    ck_assert_int_eq(motion_step(mc.m, DT, &prev), MOTION_OK);
    double fastest = 0;
    int seen = 0;
    for (int n = 0; n < 100000 && prev.state != MOTION_DONE; n++) {
        ck_assert_int_eq(motion_step(mc.m, DT, &o), MOTION_OK);
        double v = hypot(o.pose[0] - prev.pose[0], o.pose[1] - prev.pose[1]) / DT;
        int in = fabs(o.pose[1] - r1) < 1e-9 && o.pose[0] <= G[0] + reach &&
                 o.pose[0] >= G[0];       /* the period's both ends within the reach */
        if (in && fabs(prev.pose[1] - r1) < 1e-9 && prev.pose[0] <= G[0] + reach)
            fastest = fmax(fastest, v), seen++;
        prev = o;
    }
    ck_assert_int_eq(prev.state, MOTION_DONE);
    printf("arcs of 3 and 0.03 mm 0.1 mm apart, 100 Hz set points: %d periods within reach of "
           "the small arc's chords, at most %.3f mm/s (its cap %.3f mm/s)\n", seen, fastest,
           cap);
    ck_assert_int_gt(seen, 0);
    ck_assert_msg(fastest <= cap * (1 + 1e-6), "%.4f mm/s within reach of the 0.03 mm arc, "
                  "cap %.4f mm/s", fastest, cap);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

static Suite *chords_suite(void)
{
    Suite *s = suite_create("motion_chords");
    TCase *tc = tcase_create("chords");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_hexapod_zigzag);
    tcase_add_test(tc, test_setpoint_chords);
    tcase_add_test(tc, test_stop_phases);
    tcase_add_test(tc, test_arc_chords);
    tcase_add_test(tc, test_meeting_reaches);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(chords_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
