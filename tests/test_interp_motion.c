/* test_interp_motion.c: moves, arcs, offsets, units, tool length, machine words, G141/G142 hand-off
 * (canned cycles: test_interp_cycles.c). */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "interp/tooltable.h"
#include "tests/test_interp_util.h"

#define TOL 1e-9

START_TEST(straight_moves_and_feed)
{
    struct canon_prog p;
    interp_ok("G0 X1 Y2 Z3 A4 B5 C6\nG1 X-1 F250\nG91 G1 Y1 C-6\nM2\n", &p);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 0)->end, 1, 2, 3, 4, 5, 6, TOL);
    const struct canon_cmd *f = nth(&p, CANON_FEED, 0);
    ck_assert_pose(f->end, -1, 2, 3, 4, 5, 6, TOL);
    ck_assert_double_eq(f->feed_mm_min, 250);
    ck_assert_double_eq(nth(&p, CANON_FEED_RATE, 0)->feed_mm_min, 250);
    ck_assert_pose(nth(&p, CANON_FEED, 1)->end, -1, 3, 3, 4, 5, 0, TOL);
    ck_assert_int_eq(nth(&p, CANON_PROGRAM_END, 0)->ivalue, 2);
    canon_prog_free(&p);
    ck_assert_int_eq(interp_status_of("G1 X1\nM2\n"), INTERP_ERR_WORD); /* no feed */
}
END_TEST

START_TEST(units_and_feed_factor)
{
    struct canon_prog p;
    interp_ok("G20 G1 X1 Y-0.5 A10 F10\nG21 G1 X1\nM2\n", &p);
    ck_assert_pose(nth(&p, CANON_FEED, 0)->end, 25.4, -12.7, 0, 10, 0, 0, TOL);
    ck_assert_double_eq_tol(nth(&p, CANON_FEED, 0)->feed_mm_min, 254.0, TOL);
    ck_assert_pose(nth(&p, CANON_FEED, 1)->end, 1, -12.7, 0, 10, 0, 0, TOL);
    canon_prog_free(&p);
    /* FEED_UNITS = m/min: the paper's F2 is 2000 mm/min */
    struct interp *in = interp_create();
    double factor = 0;
    ck_assert_int_eq(interp_feed_units_parse("m/min", &factor), 0);
    ck_assert_int_eq(interp_feed_units_parse("furlongs", &factor), -1);
    interp_set_feed_factor(in, factor);
    ck_assert_int_eq(run_on(in, "G1 X1 F2\nM2\n", &p), 0);
    ck_assert_double_eq(nth(&p, CANON_FEED, 0)->feed_mm_min, 2000);
    canon_prog_free(&p);
    interp_destroy(in);
    /* G93: every feed move carries its own time */
    interp_ok("G93 G1 X10 F2\nG1 X20 F4\nM2\n", &p);
    ck_assert_double_eq(nth(&p, CANON_FEED, 0)->inverse_time_min, 0.5);
    ck_assert_double_eq(nth(&p, CANON_FEED, 1)->inverse_time_min, 0.25);
    ck_assert_double_eq(nth(&p, CANON_FEED_MODE, 0)->value, 1);
    canon_prog_free(&p);
    ck_assert_int_eq(interp_status_of("G93 G1 X10 F2\nG1 X20\nM2\n"), INTERP_ERR_WORD);
}
END_TEST

START_TEST(arc_centre_form_planes)
{
    struct canon_prog p;
    interp_ok("G1 X10 F100\nG2 X20 Y10 I10 J0\nG3 X20 Y10 I-5 J0 Z-2\n"
       "G18 G2 X30 Z-2 I5 K0\nG19 G3 Y20 Z-2 J5 K0\nM2\n", &p);
    const struct canon_cmd *a = nth(&p, CANON_ARC, 0);
    ck_assert_pose(a->end, 20, 10, 0, 0, 0, 0, TOL);
    ck_assert_double_eq(a->arc.center[0], 20);
    ck_assert_double_eq(a->arc.center[1], 0);
    ck_assert_double_eq(a->arc.normal[2], 1);
    ck_assert_int_eq(a->arc.rotation, -1);   /* G2: clockwise about +Z */
    ck_assert_int_eq(a->arc.plane, 17);
    a = nth(&p, CANON_ARC, 1);               /* full circle with a helix */
    ck_assert_int_eq(a->arc.rotation, 1);
    ck_assert_pose(a->end, 20, 10, -2, 0, 0, 0, TOL);
    a = nth(&p, CANON_ARC, 2);
    ck_assert_int_eq(a->arc.plane, 18);
    ck_assert_double_eq(a->arc.normal[1], 1);
    ck_assert_double_eq(a->arc.center[0], 25);
    ck_assert_double_eq(a->arc.center[2], -2);
    a = nth(&p, CANON_ARC, 3);
    ck_assert_int_eq(a->arc.plane, 19);
    ck_assert_double_eq(a->arc.normal[0], 1);
    ck_assert_double_eq(a->arc.center[1], 15);
    ck_assert_int_eq(a->arc.rotation, 1);
    canon_prog_free(&p);
}
END_TEST

START_TEST(arc_radius_form_and_turns)
{
    struct canon_prog p;
    /* from (0,0) to (10,0), R5: the centre is the midpoint; R-8 vs R8 choose opposite sides */
    interp_ok("G1 X0 Y0 F100\nG2 X10 Y0 R5\nG2 X0 Y0 R8\nG2 X10 Y0 R-8\nG3 I-5 P3 Z-3\nM2\n", &p);
    ck_assert_double_eq_tol(nth(&p, CANON_ARC, 0)->arc.center[0], 5, TOL);
    ck_assert_double_eq_tol(nth(&p, CANON_ARC, 0)->arc.center[1], 0, 1e-6);
    double yc_short = nth(&p, CANON_ARC, 1)->arc.center[1];
    double yc_long = nth(&p, CANON_ARC, 2)->arc.center[1];
    /* G2 from (10,0) to (0,0), short arc: the centre right of the travel (-X), so +Y; G2 from
     * (0,0) to (10,0), long arc (R < 0): right of +X is -Y, the long arc flips it to +Y */
    ck_assert_double_eq_tol(yc_short, sqrt(64 - 25), TOL);
    ck_assert_double_eq_tol(yc_long, sqrt(64 - 25), TOL);
    ck_assert_double_eq_tol(nth(&p, CANON_ARC, 2)->arc.center[0], 5, TOL);
    const struct canon_cmd *h = nth(&p, CANON_ARC, 3);
    ck_assert_int_eq(h->arc.rotation, 3);
    ck_assert_double_eq(h->end[2], -3);
    canon_prog_free(&p);
    ck_assert_int_eq(interp_status_of("G1 F1\nG2 X20 R5\nM2\n"), INTERP_ERR_ARC);  /* too small */
    ck_assert_int_eq(interp_status_of("G1 F1\nG2 X0 Y0 R5\nM2\n"), INTERP_ERR_ARC); /* full circle */
    ck_assert_int_eq(interp_status_of("G1 F1\nG2 X10 I5 P0\nM2\n"), INTERP_ERR_WORD);
}
END_TEST

/* LinuxCNC's tolerance: 0.0283 mm (0.00283 in) absolute and 0.1 %, or 100 times the
 * absolute one; more is an error. Each case was checked against rs274 -g. */
START_TEST(arc_radius_mismatch)
{
    ck_assert_int_eq(interp_status_of("G1 X10 F1\nG2 X0 I-5.01 J0\nM2\n"), INTERP_OK);   /* 0.02 */
    ck_assert_int_eq(interp_status_of("G1 X10 F1\nG2 X0 I-5.02 J0\nM2\n"), INTERP_ERR_ARC); /* 0.04 */
    /* large radius: under 0.1 %, so only the 100 x 0.0283 = 2.83 mm bound applies */
    ck_assert_int_eq(interp_status_of("G1 X20000 F1\nG2 X0 I-10001.01 J0\nM2\n"), INTERP_OK);
    ck_assert_int_eq(interp_status_of("G1 X20000 F1\nG2 X0 I-10001.5 J0\nM2\n"), INTERP_ERR_ARC);
    ck_assert_int_eq(interp_status_of("G20 G1 X1 F1\nG2 X0 I-0.5011 J0\nM2\n"), INTERP_OK);
    ck_assert_int_eq(interp_status_of("G20 G1 X1 F1\nG2 X0 I-0.502 J0\nM2\n"), INTERP_ERR_ARC);
    ck_assert_int_eq(interp_status_of("G1 X10 F1\nG2 X0 I-10 J0\nM2\n"), INTERP_ERR_ARC); /* r2 = 0 */
}
END_TEST

START_TEST(offsets_work_and_g92)
{
    struct canon_prog p;
    interp_ok("G10 L2 P1 X100 Y50\nG10 L2 P6 Z-20 B3\nG0 X1 Y1\nG59 G0 Z1 B1\n"
       "G54 G92 X0 Y0\nG0 X1 Y1\nG92.2\nG0 X1 Y1\nG92.3\nG0 X2\nG92.1\nG0 X2\n"
       "G53 G0 X0\nM2\n", &p);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 0)->end, 101, 51, 0, 0, 0, 0, TOL);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 1)->end, 101, 51, -19, 0, 4, 0, TOL);
    /* G92 X0 Y0 at machine (101, 51) under G54 (100, 50): G92 offset (1, 1) */
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 2)->end, 102, 52, -19, 0, 4, 0, TOL);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 3)->end, 101, 51, -19, 0, 4, 0, TOL);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 4)->end, 103, 51, -19, 0, 4, 0, TOL);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 5)->end, 102, 51, -19, 0, 4, 0, TOL);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 6)->end, 0, 51, -19, 0, 4, 0, TOL);
    const struct canon_cmd *o = nth(&p, CANON_OFFSETS, 0);
    ck_assert_double_eq(o->offset[0], 100);
    canon_prog_free(&p);
    ck_assert_int_eq(interp_status_of("G91 G53 G0 X1\nM2\n"), INTERP_ERR_MODAL);
    ck_assert_int_eq(interp_status_of("G53 G2 X1 I1\nM2\n"), INTERP_ERR_MODAL);
}
END_TEST

START_TEST(offsets_g10_l20_and_homes)
{
    struct canon_prog p;
    interp_ok("G0 X10 Y20 Z30\nG10 L20 P1 X0 Y0\nG0 X1 Y1\nG28.1\nG0 X50 Y50 Z50\nG28 Z40\n"
       "G28\nG30.1\nG0 X0\nG30\nM2\n", &p);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 1)->end, 11, 21, 30, 0, 0, 0, TOL);
    /* G28 Z40: through program Z40, then only Z to the stored home (machine 30) */
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 3)->end, 60, 70, 40, 0, 0, 0, TOL);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 4)->end, 60, 70, 30, 0, 0, 0, TOL);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 6)->end, 11, 21, 30, 0, 0, 0, TOL);
    ck_assert_pose(last_move(&p)->end, 11, 21, 30, 0, 0, 0, TOL);
    canon_prog_free(&p);
}
END_TEST

/* G43 H takes Z from the tool table; G43.1 from the block; G49 cancels. */
START_TEST(tool_length)
{
    struct tooltable *tt = calloc(1, sizeof *tt);
    tooltable_init(tt);
    struct tool_entry e = {.tool = 3, .pocket = 3, .z_offset_mm = 12.5, .diameter_mm = 6};
    ck_assert_int_eq(tooltable_set(tt, &e), 0);
    struct interp *in = interp_create();
    interp_set_tooltable(in, tt);
    struct canon_prog p;
    ck_assert_int_eq(run_on(in, "T3 M6\nG43 H3\nG0 Z0\nG43.1 Z-1\nG0 Z0\nG49\nG0 Z0\n"
                                "G43\nG0 Z1\nM2\n", &p), 0);
    ck_assert_int_eq(nth(&p, CANON_TOOL_CHANGE, 0)->ivalue, 3);
    ck_assert_double_eq(nth(&p, CANON_TRAVERSE, 0)->end[2], 12.5);
    ck_assert_double_eq(nth(&p, CANON_TRAVERSE, 1)->end[2], -1);
    ck_assert_double_eq(nth(&p, CANON_TRAVERSE, 2)->end[2], 0);
    ck_assert_double_eq(nth(&p, CANON_TRAVERSE, 3)->end[2], 13.5); /* G43 alone: tool 3 */
    canon_prog_free(&p);
    /* G10 L1 writes the table in memory: radius R (diameter 2R) and length Z; the entry goes
     * out as a CANON_SETTING at its line, for the machine to save when it gets there */
    snprintf(tt->path, sizeof tt->path, "/nonexistent-dir/never-written.tbl");
    ck_assert_int_eq(run_on(in, "G0 Z1\nG10 L1 P5 R3 Z7\nG43 H5\nG0 Z0\nG49\nM2\n", &p), 0);
    ck_assert_double_eq(tooltable_find(tt, 5)->diameter_mm, 6);
    ck_assert_double_eq(nth(&p, CANON_TRAVERSE, 1)->end[2], 7);
    ck_assert_int_eq(count_type(&p, CANON_SETTING), 1);
    const struct canon_cmd *set = nth(&p, CANON_SETTING, 0);
    ck_assert_int_eq(set->line, 2);
    ck_assert(set > nth(&p, CANON_TRAVERSE, 0));  /* after line 1's move, */
    ck_assert(set < nth(&p, CANON_OFFSETS, 0));   /* before line 3's G43 */
    ck_assert_int_eq(set->setting->tool->tool, 5);
    ck_assert_double_eq(set->setting->tool->diameter_mm, 6);
    ck_assert_double_eq(set->setting->tool->z_offset_mm, 7);
    canon_prog_free(&p);
    tt->path[0] = '\0';
    ck_assert_int_eq(interp_status_of("G10 L1 P5 R3\nM2\n"), INTERP_ERR_TOOL); /* no table */
    ck_assert_int_eq(run_on(in, "G43 H4\nM2\n", &p), INTERP_ERR_TOOL);
    canon_prog_free(&p);
    ck_assert_int_eq(run_on(in, "T9 M6\nM2\n", &p), INTERP_ERR_TOOL);
    canon_prog_free(&p);
    interp_destroy(in);
    free(tt);
}
END_TEST

START_TEST(machine_words)
{
    struct canon_prog p;
    interp_ok("S1200 M3\nM4\nM5\nM7\nM8\nM9\nG4 P1.5\nM1\nM0\nG64 P0.05\nG61\nM30\n", &p);
    ck_assert_double_eq(nth(&p, CANON_SPINDLE_SPEED, 0)->value, 1200);
    ck_assert_double_eq(nth(&p, CANON_SPINDLE_ON, 0)->value, 1);
    ck_assert_double_eq(nth(&p, CANON_SPINDLE_ON, 1)->value, -1);
    ck_assert_int_eq(nth(&p, CANON_COOLANT, 1)->ivalue, 8);
    ck_assert_double_eq(nth(&p, CANON_DWELL, 0)->value, 1.5);
    ck_assert_int_eq(nth(&p, CANON_PAUSE, 0)->ivalue, 1);
    ck_assert_double_eq(nth(&p, CANON_PATH_MODE, 0)->value, 0.05);
    ck_assert_int_eq(nth(&p, CANON_PATH_MODE, 1)->ivalue, 610);
    ck_assert_int_eq(nth(&p, CANON_PROGRAM_END, 0)->ivalue, 30);
    canon_prog_free(&p);
}
END_TEST

/* G64's Q (the naive CAM tolerance) as rs274 prints it: Q absent takes P's value, G64 alone
 * and G61 have none, inches are converted, M72 puts back the Q it saved. */
START_TEST(naive_cam_tolerance)
{
    struct canon_prog p;
    interp_ok("G21\nG64 P0.02\nG64 P0.02 Q0.005\nG64\nG64 Q0.03\nG61\nG20 G64 P0.001 Q0.002\n"
              "G21 G64 P0.01 Q0.004\nM70\nG64 P0.05 Q0.05\nM72\nM30\n", &p);
    const double q[] = { 0.02, 0.005, 0, 0.03, 0, 0.0508, 0.004, 0.05, 0.004 };
    for (int k = 0; k < (int)(sizeof q / sizeof q[0]); k++)
        ck_assert_msg(fabs(nth(&p, CANON_PATH_MODE, k)->naive_tol_mm - q[k]) < 1e-12,
                      "PATH_MODE %d: Q %.6f, expected %.6f", k,
                      nth(&p, CANON_PATH_MODE, k)->naive_tol_mm, q[k]);
    ck_assert_int_eq(nth(&p, CANON_PATH_MODE, 8)->ivalue, 640);
    ck_assert_double_eq_tol(nth(&p, CANON_PATH_MODE, 8)->value, 0.01, 1e-12);
    canon_prog_free(&p);
}
END_TEST

/* G141 blocks are resolved like G1 (offsets, units) and handed to the compensation. The
 * tool comes in along the compensated line, 10 mm before its start (from the contour line
 * itself it would cut the wall's start: the gouge check refuses that). */
START_TEST(g141_hand_off)
{
    struct canon_prog p;
    struct interp *in = interp_create();
    interp_set_feed_factor(in, 1000);
    ck_assert_int_eq(run_on(in, "G0 X59.975641 Y-90 Z630.697565 B-4\n"
                                "G141 X50 Y-80 Z630 A0 B-4 W10 F2\n"
                                "G141 X50 Y-20 Z630 A0 B-4\nG0 Z700\nM2\n", &p), 0);
    const struct canon_cmd *last = NULL;
    for (size_t i = 0; i < p.count; i++)
        if (p.cmds[i].type == CANON_FEED) {
            ck_assert_int_eq(p.cmds[i].compensated, 141);
            ck_assert_double_eq(p.cmds[i].feed_mm_min, 2000);
            last = &p.cmds[i];
        }
    ck_assert_ptr_nonnull(last);
    ck_assert_pose(last->end, 59.975641, -20, 630.697565, 0, -4, 0, 1e-6);
    ck_assert_int_eq(last->line, 3);
    /* the rapid after the run starts where the compensated path ended */
    ck_assert_pose(last_move(&p)->end, 59.975641, -20, 700, 0, -4, 0, 1e-6);
    canon_prog_free(&p);
    /* a lone G141 block: the compensation's error, on its line */
    ck_assert_int_eq(run_on(in, "G0 X0 Y0 Z0\nG141 X10 W5 F1\nG0 Z5\nM2\n", &p), INTERP_ERR_COMP5);
    ck_assert_int_eq(interp_last_error(in)->line, 2);
    canon_prog_free(&p);
    ck_assert_int_eq(run_on(in, "G0 X0 Y0 Z0\nG141 X10 F1\nG141 X20\nM2\n", &p), INTERP_ERR_COMP5);
    ck_assert_ptr_nonnull(strstr(interp_last_error(in)->message, "radius"));
    canon_prog_free(&p);
    ck_assert_int_eq(run_on(in, "G141 X10 D1 F1\nM2\n", &p), INTERP_ERR_TOOL);
    canon_prog_free(&p);
    interp_destroy(in);
}
END_TEST

/* G5.1 from (0, 0) through the pull of (5, 5) to (10, 0): the parabola y = x (10 - x) / 10,
 * top (5, 2.5). Every chord end lies on it, the chords stay within 0.1 um of it, the last
 * ends exactly on the end point; under G93 the chords share the block's time; the errors
 * are LinuxCNC's. */
START_TEST(g5_1_quadratic_spline)
{
    struct canon_prog p;
    struct interp_error err;
    ck_assert_int_eq(run_text("G21 G17 G90\nG0 X0 Y0 Z1\nG5.1 X10 Y0 I5 J5 F100\nM2\n", &p,
                              &err), INTERP_OK);
    int n = count_type(&p, CANON_FEED);
    /* |P0 - 2 P1 + P2| = 10: chords over dt leave it by 10 dt^2 / 4 <= 1e-4: 159 of them */
    ck_assert_int_eq(n, 159);
    double prev[2] = { 0, 0 }, worst = 0, top = 0;
    for (int k = 0; k < n; k++) {
        const struct canon_cmd *c = nth(&p, CANON_FEED, k);
        ck_assert_int_eq(c->spline, k == 0 ? 1 : 2);
        ck_assert_int_eq(c->line, 3);
        double x = c->end[0], y = c->end[1];
        ck_assert_double_eq_tol(y, x * (10 - x) / 10, 1e-12);
        ck_assert(c->end[2] == 1);
        /* the parabola's farthest point from the chord: where its slope is the chord's */
        double xm = 0.5 * (prev[0] + x), ym = xm * (10 - xm) / 10;
        double cy = prev[1] + (y - prev[1]) * (xm - prev[0]) / (x - prev[0]);
        worst = fmax(worst, fabs(ym - cy));
        top = fmax(top, y);
        prev[0] = x, prev[1] = y;
    }
    ck_assert(worst <= 1e-4 && worst > 0.5e-4);
    ck_assert_double_eq_tol(top, 2.5, 1e-3);
    ck_assert(last_move(&p)->end[0] == 10 && last_move(&p)->end[1] == 0);
    canon_prog_free(&p);
    ck_assert_int_eq(run_text("G21 G17\nG0 X0 Y0\nG93 G5.1 X10 Y0 I5 J5 F2\nM2\n", &p, &err),
                     INTERP_OK);
    double total = 0;
    for (int k = 0; k < count_type(&p, CANON_FEED); k++)
        total += nth(&p, CANON_FEED, k)->inverse_time_min;
    ck_assert_double_eq_tol(total, 0.5, 1e-12);   /* F2 under G93: the block in 1/2 min */
    canon_prog_free(&p);
    static const struct { const char *prog, *msg; } bad[] = {
        { "G21 G17\nG0 X0 Y0\nG5.1 X10 Y0 I5 F100\nM2\n", "G5.1 needs both I and J" },
        { "G21 G18\nG0 X0 Y0\nG5.1 X10 Y0 I5 J5 F100\nM2\n", "XY plane (G17)" },
        { "G21 G17\nG0 X0 Y0\nG5.1 X10 Y0 Z3 I5 J5 F100\nM2\n", "may not move Z, A, B or C" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ck_assert_int_ne(run_text(bad[i].prog, &p, &err), INTERP_OK);
        ck_assert_int_eq(err.line, 3);
        ck_assert_msg(strstr(err.message, bad[i].msg), "%s", err.message);
        canon_prog_free(&p);
    }
}
END_TEST

static Suite *motion_suite(void)
{
    Suite *s = suite_create("interp_motion");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, straight_moves_and_feed);
    tcase_add_test(tc, units_and_feed_factor);
    tcase_add_test(tc, arc_centre_form_planes);
    tcase_add_test(tc, arc_radius_form_and_turns);
    tcase_add_test(tc, arc_radius_mismatch);
    tcase_add_test(tc, offsets_work_and_g92);
    tcase_add_test(tc, offsets_g10_l20_and_homes);
    tcase_add_test(tc, tool_length);
    tcase_add_test(tc, machine_words);
    tcase_add_test(tc, naive_cam_tolerance);
    tcase_add_test(tc, g141_hand_off);
    tcase_add_test(tc, g5_1_quadratic_spline);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(motion_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
