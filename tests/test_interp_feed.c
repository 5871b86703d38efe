/* test_interp_feed.c: G95, feed per revolution: the feed moves carry F x S (mm/min), what
 * this machine runs them at (G95 does not follow the encoder: only G33, G33.1 do); rs274's
 * printed form is compared in tests/interp_expected/g95_per_rev.ngc. */
#include <check.h>
#include <stdlib.h>
#include <string.h>

#include "test_interp_util.h"

/* F0.1 mm/rev at S1000: 100 mm/min; S2000: 200; F0.004 in/rev at S2000: 203.2 mm/min; G94
 * back to F as written; the mode is 2 in the stream. */
START_TEST(per_rev_feed)
{
    struct canon_prog p;
    interp_ok("G21 S1000 M3\nG95 F0.1\nG1 X10\nG2 X20 I5\nS2000\nG1 Y5\n"
              "G20 F0.004\nG1 X1\nG21 G94 F300\nG1 X0\nM2\n", &p);
    ck_assert_double_eq(nth(&p, CANON_FEED_MODE, 0)->value, 2);
    ck_assert_double_eq_tol(nth(&p, CANON_FEED, 0)->feed_mm_min, 100, 1e-9);
    ck_assert_double_eq_tol(nth(&p, CANON_ARC, 0)->feed_mm_min, 100, 1e-9);
    ck_assert_double_eq_tol(nth(&p, CANON_FEED, 1)->feed_mm_min, 200, 1e-9);
    ck_assert_double_eq_tol(nth(&p, CANON_FEED, 2)->feed_mm_min, 0.004 * 25.4 * 2000, 1e-9);
    ck_assert_double_eq_tol(nth(&p, CANON_FEED, 3)->feed_mm_min, 300, 1e-9);
    ck_assert_double_eq(nth(&p, CANON_FEED_MODE, 1)->value, 0);
    ck_assert_double_eq(nth(&p, CANON_FEED, 0)->inverse_time_min, 0);
    canon_prog_free(&p);
    /* #<_units_per_rev> and #<_units_per_minute> tell the mode */
    interp_ok("G21 S500 M3 G95 F0.2\nG1 X[#<_units_per_rev> * 10 + #<_units_per_minute>]\nM2\n",
              &p);
    ck_assert_double_eq_tol(last_move(&p)->end[0], 10, 1e-12);
    canon_prog_free(&p);
}
END_TEST

/* G95 needs a spindle speed (LinuxCNC) and, on this machine, a turning spindle. */
START_TEST(per_rev_errors)
{
    struct canon_prog p;
    struct interp_error err;
    ck_assert_int_ne(run_text("G21 M3\nG95 F0.1\nG1 X10\nM2\n", &p, &err), INTERP_OK);
    ck_assert_ptr_nonnull(strstr(err.message, "spindle speed 0"));
    ck_assert_int_eq(err.line, 3);
    canon_prog_free(&p);
    ck_assert_int_ne(run_text("G21 S1000 M3\nG95 F0.1\nM5\nG2 X10 I5\nM2\n", &p, &err),
                     INTERP_OK);
    ck_assert_ptr_nonnull(strstr(err.message, "spindle stopped"));
    ck_assert_int_eq(err.line, 4);
    canon_prog_free(&p);
    ck_assert_int_ne(run_text("G21 S1000\nG95 F0.1\nG1 X10\nM2\n", &p, &err), INTERP_OK);
    canon_prog_free(&p);
}
END_TEST

static Suite *feed_suite(void)
{
    Suite *s = suite_create("interp_feed");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, per_rev_feed);
    tcase_add_test(tc, per_rev_errors);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(feed_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
