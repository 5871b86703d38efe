/* test_interp_cycles.c: the drilling cycles in G17, G18 (along Y) and G19 (along X). */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/test_interp_util.h"

#define TOL 1e-9

/* The moves of one G81 hole, then G83 pecks, G98 against G99, L with G91. */
START_TEST(cycles_g17)
{
    struct canon_prog p;
    interp_ok("G0 X0 Y0 Z-1\nG81 X5 Y5 Z-2 R1 F50\nG80\nM2\n", &p);
    ck_assert_int_eq(count_type(&p, CANON_TRAVERSE) + count_type(&p, CANON_FEED), 5);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 1)->end, 0, 0, 1, 0, 0, 0, TOL); /* up to R */
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 2)->end, 5, 5, 1, 0, 0, 0, TOL);
    ck_assert_pose(nth(&p, CANON_FEED, 0)->end, 5, 5, -2, 0, 0, 0, TOL);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 3)->end, 5, 5, 1, 0, 0, 0, TOL);
    canon_prog_free(&p);
    interp_ok("G0 Z10\nG98 G83 X1 Z-5 R1 Q2 F50\nM2\n", &p);
    ck_assert_int_eq(count_type(&p, CANON_FEED), 3);   /* pecks to -1, -3, then -5 */
    ck_assert_double_eq_tol(nth(&p, CANON_FEED, 0)->end[2], -1, TOL);
    ck_assert_double_eq_tol(nth(&p, CANON_TRAVERSE, 4)->end[2], -0.746, TOL);
    ck_assert_double_eq_tol(last_move(&p)->end[2], 10, TOL); /* G98: back to old Z */
    canon_prog_free(&p);
    interp_ok("G0 Z10\nG91 G99 G82 X5 Z-4 R-2 P0.5 L3 F50\nM2\n", &p);
    ck_assert_int_eq(count_type(&p, CANON_DWELL), 3);
    ck_assert_double_eq(nth(&p, CANON_DWELL, 0)->value, 0.5);
    ck_assert_pose(nth(&p, CANON_FEED, 2)->end, 15, 0, 4, 0, 0, 0, TOL);
    ck_assert_double_eq_tol(last_move(&p)->end[2], 8, TOL); /* G99: R plane */
    canon_prog_free(&p);
    interp_ok("G0 Z5\nG85 X1 Z-3 R2 F50\nG89 X2 Z-3 R2 P1\nG73 X3 Z-1 R2 Q1\nM2\n", &p);
    ck_assert_int_eq(count_type(&p, CANON_DWELL), 1);
    canon_prog_free(&p);
    ck_assert_int_eq(interp_status_of("G0 Z5\nG81 X1 Z-3 F50\nM2\n"), INTERP_ERR_CYCLE);
    ck_assert_int_eq(interp_status_of("G0 Z5\nG83 X1 Z-3 R1 F50\nM2\n"), INTERP_ERR_CYCLE);
    ck_assert_int_eq(interp_status_of("G0 Z5\nG81 X1 Z3 R1 F50\nM2\n"), INTERP_ERR_CYCLE);
}
END_TEST

/* G18 holes sit in Z X and drill along Y: R and the depth are Y levels. */
START_TEST(cycles_g18)
{
    struct canon_prog p;
    interp_ok("G0 X0 Y20 Z0\nG18 G99 G81 X10 Z5 Y-5 R2 F100\nG80\nM2\n", &p);
    ck_assert_int_eq(count_type(&p, CANON_TRAVERSE) + count_type(&p, CANON_FEED), 5);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 1)->end, 10, 20, 5, 0, 0, 0, TOL); /* over the hole */
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 2)->end, 10, 2, 5, 0, 0, 0, TOL);  /* down to R */
    ck_assert_pose(nth(&p, CANON_FEED, 0)->end, 10, -5, 5, 0, 0, 0, TOL);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 3)->end, 10, 2, 5, 0, 0, 0, TOL);  /* G99: to R */
    canon_prog_free(&p);
    /* below R on Y: straight out to R first; Y sticky for the second hole */
    interp_ok("G0 Y-10\nG18 G81 X1 Z1 Y-12 R2 F10\nX3\nM2\n", &p);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 1)->end, 0, 2, 0, 0, 0, 0, TOL);
    ck_assert_pose(nth(&p, CANON_FEED, 0)->end, 1, -12, 1, 0, 0, 0, TOL);
    ck_assert_pose(nth(&p, CANON_FEED, 1)->end, 3, -12, 1, 0, 0, 0, TOL);
    canon_prog_free(&p);
    /* inch: the G83 rapid stops 0.010 in above the last peck, along Y */
    interp_ok("G20 G18 G0 Y1\nG99 G83 X0.5 Z0.5 Y-0.5 R0.1 Q0.2 F10\nM2\n", &p);
    ck_assert_int_eq(count_type(&p, CANON_FEED), 3);  /* pecks to -0.1, -0.3, then -0.5 */
    ck_assert_double_eq_tol(nth(&p, CANON_FEED, 1)->end[1], -0.3 * 25.4, TOL);
    ck_assert_double_eq_tol(nth(&p, CANON_TRAVERSE, 4)->end[1], -0.09 * 25.4, TOL);
    ck_assert_double_eq_tol(last_move(&p)->end[1], 0.1 * 25.4, TOL);
    canon_prog_free(&p);
}
END_TEST

/* G19 holes sit in Y Z and drill along X; G98 returns to the X the series started from. */
START_TEST(cycles_g19)
{
    struct canon_prog p;
    interp_ok("G0 X10\nG19 G98 G83 Y1 Z2 X-5 R1 Q2 F50\nM2\n", &p);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 1)->end, 10, 1, 2, 0, 0, 0, TOL);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 2)->end, 1, 1, 2, 0, 0, 0, TOL);
    ck_assert_int_eq(count_type(&p, CANON_FEED), 3);  /* pecks to -1, -3, then -5 */
    ck_assert_double_eq_tol(nth(&p, CANON_FEED, 0)->end[0], -1, TOL);
    ck_assert_double_eq_tol(nth(&p, CANON_TRAVERSE, 4)->end[0], -0.746, TOL);
    ck_assert_double_eq_tol(nth(&p, CANON_FEED, 2)->end[0], -5, TOL);
    ck_assert_pose(last_move(&p)->end, 10, 1, 2, 0, 0, 0, TOL);
    canon_prog_free(&p);
    /* G91: Y Z step per repeat, R from the start X, the depth from R */
    interp_ok("G0 X10\nG19 G91 G99 G82 Y5 Z1 X-4 R-2 P0.5 L3 F50\nM2\n", &p);
    ck_assert_int_eq(count_type(&p, CANON_DWELL), 3);
    ck_assert_pose(nth(&p, CANON_FEED, 0)->end, 4, 5, 1, 0, 0, 0, TOL);
    ck_assert_pose(nth(&p, CANON_FEED, 2)->end, 4, 15, 3, 0, 0, 0, TOL);
    ck_assert_pose(last_move(&p)->end, 8, 15, 3, 0, 0, 0, TOL);
    canon_prog_free(&p);
    /* G85 feeds back out to R, G89 dwells and feeds out to the clear level */
    interp_ok("G0 X5\nG19 G99 G85 Y1 Z1 X-3 R2 F50\nG89 Y2 X-3 R2 P1\nM2\n", &p);
    ck_assert_pose(nth(&p, CANON_FEED, 1)->end, 2, 1, 1, 0, 0, 0, TOL);
    ck_assert_int_eq(count_type(&p, CANON_DWELL), 1);
    ck_assert_pose(last_move(&p)->end, 2, 2, 1, 0, 0, 0, TOL);
    ck_assert_int_eq(nth(&p, CANON_FEED, 3)->type, CANON_FEED);
    canon_prog_free(&p);
}
END_TEST

/* The drilling axis word is the one a first block must give, and R must be above it. */
START_TEST(cycle_plane_errors)
{
    struct canon_prog p;
    struct interp_error e;
    ck_assert_int_eq(run_text("G18 G81 X1 Z-3 R1 F50\nM2\n", &p, &e), INTERP_ERR_CYCLE);
    ck_assert_ptr_nonnull(strstr(e.message, "needs Y (hole depth: G18 drills along Y)"));
    canon_prog_free(&p);
    ck_assert_int_eq(run_text("G19 G81 Y1 Z-3 R1 F50\nM2\n", &p, &e), INTERP_ERR_CYCLE);
    ck_assert_ptr_nonnull(strstr(e.message, "needs X (hole depth: G19 drills along X)"));
    canon_prog_free(&p);
    ck_assert_int_eq(run_text("G19 G81 Y1 X3 R1 F50\nM2\n", &p, &e), INTERP_ERR_CYCLE);
    ck_assert_ptr_nonnull(strstr(e.message, "is below X (hole bottom, 3)"));
    ck_assert_int_eq(e.column, 15);  /* the R word */
    canon_prog_free(&p);
    ck_assert_int_eq(interp_status_of("G18 G81 X1 Y-3 R1 A2 F50\nM2\n"), INTERP_ERR_CYCLE);
    ck_assert_int_eq(interp_status_of("G17 G0 Z5\nG18 G81 X1 Y-3 R1 F50\nM2\n"), INTERP_OK);
}
END_TEST

static Suite *cycles_suite(void)
{
    Suite *s = suite_create("interp_cycles");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, cycles_g17);
    tcase_add_test(tc, cycles_g18);
    tcase_add_test(tc, cycles_g19);
    tcase_add_test(tc, cycle_plane_errors);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(cycles_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
