/* test_interp_sync.c: G33 and G33.1 as canonical moves: the pitch in mm (G20 K in inch), a
 * rigid tap as its way in and its way out back to the start, G33.1's I, and the feed that
 * consumers which plan by feed see (K x S). rs274's printed form: tests/interp_expected/
 * sync_*.ngc; its refusals: tests/interp_errors/g33*.ngc. */
#include <check.h>
#include <stdlib.h>

#include "tests/test_interp_util.h"

START_TEST(tap_in_and_out)
{
    struct canon_prog p;
    ck_assert_int_eq(run_text("G21 G90\nG0 X1 Y2 Z5\nS600 M4\nG33.1 Z-10 K1.25 I2\n"
                              "G1 X3 F100\nM2\n", &p, NULL), INTERP_OK);
    const struct canon_cmd *in = nth(&p, CANON_FEED, 0), *out = nth(&p, CANON_FEED, 1);
    ck_assert_int_eq(in->sync, CANON_SYNC_TAP_IN);
    ck_assert_int_eq(out->sync, CANON_SYNC_TAP_OUT);
    ck_assert_int_eq(in->line, 4);
    ck_assert_int_eq(out->line, 4);
    ck_assert_double_eq_tol(in->end[2], -10, 1e-12);
    ck_assert_double_eq_tol(out->end[0], 1, 1e-12);     /* back where it started */
    ck_assert_double_eq_tol(out->end[1], 2, 1e-12);
    ck_assert_double_eq_tol(out->end[2], 5, 1e-12);
    ck_assert_double_eq_tol(in->pitch_mm_rev, 1.25, 1e-12);
    ck_assert_double_eq_tol(in->retract_factor, 2, 1e-12);
    ck_assert_double_eq_tol(in->feed_mm_min, 1.25 * 600, 1e-9);
    ck_assert_double_eq_tol(out->feed_mm_min, 1.25 * 600 * 2, 1e-9);
    /* the program goes on from the tap's start, as rs274's does */
    const struct canon_cmd *g1 = nth(&p, CANON_FEED, 2);
    ck_assert_int_eq(g1->sync, 0);
    ck_assert_double_eq_tol(g1->end[2], 5, 1e-12);
    ck_assert_double_eq_tol(g1->end[0], 3, 1e-12);
    canon_prog_free(&p);
}
END_TEST

START_TEST(thread_inch)
{
    struct canon_prog p;
    ck_assert_int_eq(run_text("G20 G90\nG0 X0 Y0 Z1\nS500 M3\nG33 Z-0.5 K0.05\nM2\n", &p,
                              NULL), INTERP_OK);
    ck_assert_int_eq(count_type(&p, CANON_FEED), 1);
    const struct canon_cmd *c = nth(&p, CANON_FEED, 0);
    ck_assert_int_eq(c->sync, CANON_SYNC_THREAD);
    ck_assert_double_eq_tol(c->pitch_mm_rev, 1.27, 1e-12);
    ck_assert_double_eq_tol(c->pitch_word, 0.05, 1e-12);
    ck_assert_double_eq_tol(c->retract_factor, 1, 1e-12);
    ck_assert_double_eq_tol(c->end[2], -0.5 * 25.4, 1e-9);
    canon_prog_free(&p);
}
END_TEST

START_TEST(refusals)
{
    static const struct { const char *text; const char *says; int line; } cases[] = {
        { "G21 S500 M3\nG33 Z-1 K-1\nM2\n", "must be more than 0", 2 },
        { "G21 S500 M3\nG33.1 Z-1 K1 I0\nM2\n", "way out must be more than 0", 2 },
        { "G21 M3\nG33 Z-1 K1\nM2\n", "spindle speed 0", 2 },
        { "G21 S500 M3\nG0 Z1\nG33 Z1 K1\nM2\n", "zero length", 3 },
        { "G21 S500 M3\nG33 Z-1 B5 K1\nM2\n", "turns the platform", 2 },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        struct canon_prog p;
        struct interp_error err;
        ck_assert_int_ne(run_text(cases[i].text, &p, &err), INTERP_OK);
        ck_assert_msg(strstr(err.message, cases[i].says), "%s", err.message);
        ck_assert_int_eq(err.line, cases[i].line);
        canon_prog_free(&p);
    }
}
END_TEST

static Suite *sync_suite(void)
{
    Suite *s = suite_create("interp_sync");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, tap_in_and_out);
    tcase_add_test(tc, thread_inch);
    tcase_add_test(tc, refusals);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(sync_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
