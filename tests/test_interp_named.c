/* test_interp_named.c: named parameters #<name> and #<_name>, the predefined ones, EXISTS. */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/test_interp_util.h"

#define TOL 1e-9

/* Runs a program on in that must succeed, and frees its commands. */
static void ok_on(struct interp *in, const char *text)
{
    struct canon_prog p;
    int rc = run_on(in, text, &p);
    canon_prog_free(&p);
    const struct interp_error *e = interp_last_error(in);
    ck_assert_msg(rc == INTERP_OK, "failed: %d:%d: %s", e->line, e->column, e->message);
}

/* The error of a program that must fail. */
static struct interp_error fail_of(const char *text)
{
    struct canon_prog p;
    struct interp_error e;
    ck_assert_int_ne(run_text(text, &p, &e), INTERP_OK);
    canon_prog_free(&p);
    return e;
}

/* Local and global names, any case and spacing, in words and expressions. */
START_TEST(set_and_use)
{
    struct canon_prog p;
    interp_ok("#<Safe Z>=10\n#<_G>=[2*3]\nG0 Z#<safez> X[#<_g> + #<SAFE z>]\nM2\n", &p);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 0)->end, 16, 0, 10, 0, 0, 0, TOL);
    canon_prog_free(&p);
    /* settings land after the line; a new name reads 0 until then, as in LinuxCNC */
    interp_ok("#<a>=1\n#<a>=2 G0 X#<a>\nG0 Y#<a>\n#<b>=3 G0 Z[#<b>+1]\nG0 A#<b>\nM2\n", &p);
    ck_assert_double_eq_tol(nth(&p, CANON_TRAVERSE, 0)->end[0], 1, TOL);
    ck_assert_double_eq_tol(nth(&p, CANON_TRAVERSE, 1)->end[1], 2, TOL);
    ck_assert_double_eq_tol(nth(&p, CANON_TRAVERSE, 2)->end[2], 1, TOL);
    ck_assert_double_eq_tol(nth(&p, CANON_TRAVERSE, 3)->end[3], 3, TOL);
    canon_prog_free(&p);
    /* ##<p> reads the numbered parameter whose number #<p> holds */
    interp_ok("#2=7 #<p>=2\nG0 X##<p>\nM2\n", &p);
    ck_assert_double_eq_tol(nth(&p, CANON_TRAVERSE, 0)->end[0], 7, TOL);
    canon_prog_free(&p);
}
END_TEST

/* Names set in one line all land, also while the table grows, and keep apart. */
START_TEST(many_names)
{
    struct interp *in = interp_create();
    ck_assert_ptr_nonnull(in);
    char *text = malloc(64 * 1024);
    ck_assert_ptr_nonnull(text);
    size_t n = 0;
    for (int i = 0; i < 60; i++) /* one line, the table grows from 16 entries while it is read */
        n += (size_t)sprintf(text + n, "#<n%d>=%d ", i, i * 3);
    text[n++] = '\n';
    for (int i = 0; i < 400; i++)
        n += (size_t)sprintf(text + n, "#<_m%d>=[%d+0.5]\n", i, i);
    n += (size_t)sprintf(text + n, "#1=[#<n0>+#<n17>+#<n59>] #2=[#<_m0>+#<_m255>+#<_m399>]\nM2\n");
    ck_assert_uint_lt(n, 64 * 1024);
    ok_on(in, text);
    ck_assert_double_eq_tol(interp_param(in, 1), 0 + 51 + 177, TOL);
    ck_assert_double_eq_tol(interp_param(in, 2), 0.5 + 255.5 + 399.5, TOL);
    free(text);
    interp_destroy(in);
}
END_TEST

/* A program's own names go when the next program starts; #<_name> ones stay. */
START_TEST(scope_between_programs)
{
    struct interp *in = interp_create();
    ck_assert_ptr_nonnull(in);
    struct canon_prog p;
    ok_on(in, "#<local>=1\n#<_global>=2\nM2\n");
    ok_on(in, "#1=#<_global>\nM2\n");
    ck_assert_double_eq(interp_param(in, 1), 2);
    ck_assert_int_eq(run_on(in, "#1=#<local>\nM2\n", &p), INTERP_ERR_PARAM);
    ck_assert_ptr_nonnull(strstr(interp_last_error(in)->message, "#<local> is not defined"));
    canon_prog_free(&p);
    interp_destroy(in);
}
END_TEST

/* The read-only state parameters, checked against the state the program set. */
START_TEST(predefined)
{
    struct interp *in = interp_create();
    ck_assert_ptr_nonnull(in);
    ok_on(in, "G10 L2 P1 X5\nG0 X7 Y2 B30\nG92 Y0\n"
              "#1=#<_x> #2=#<_y> #3=#<_abs_x> #4=#<_plane> #5=#<_b> #6=#<_coord_system>\n"
              "G20 G91 G18 G98 G59.1 M8 F12 S500 M3\n"
              "#7=#<_x> #8=#<_metric> #9=#<_imperial> #10=#<_incremental> #11=#<_plane>\n"
              "#12=#<_retract_old_z> #13=#<_coord_system> #14=#<_flood> #15=#<_mist>\n"
              "#16=#<_feed> #17=#<_rpm> #18=#<_spindle_cw> #19=#<_line> #20=#<_motion_mode>\n"
              "M7\n#21=#<_mist> #22=#<_flood>\nM9\n#23=#<_flood>\nM2\n");
    /* #7: machine X 12 under G59.1 (no offset) in inch; #19: the line number */
    const double want[24] = {0, 7, 0, 12, 170, 30, 540, 12 / 25.4, 0, 1, 1, 180, 1, 591, 1, 0,
                             12, 500, 1, 8, 0, 1, 1, 0};
    for (int i = 1; i <= 23; i++)
        ck_assert_msg(fabs(interp_param(in, i) - want[i]) < TOL, "#%d is %g, not %g", i,
                      interp_param(in, i), want[i]);
    interp_destroy(in);
}
END_TEST

/* EXISTS: set names and predefined ones exist, others not; a number is no parameter. */
START_TEST(exists)
{
    struct interp *in = interp_create();
    ck_assert_ptr_nonnull(in);
    ok_on(in, "#<a>=1\n#1=EXISTS[#<a>] #2=EXISTS[#<b>] #3=EXISTS[ #<_Z> ] #4=EXISTS[#5]\nM2\n");
    ck_assert_double_eq(interp_param(in, 1), 1);
    ck_assert_double_eq(interp_param(in, 2), 0);
    ck_assert_double_eq(interp_param(in, 3), 1);
    ck_assert_double_eq(interp_param(in, 4), 1);
    interp_destroy(in);
    struct interp_error e = fail_of("G0 X[EXISTS[5]]\nM2\n");
    ck_assert_int_eq(e.status, INTERP_ERR_SYNTAX);
    ck_assert_int_eq(e.column, 13);
    e = fail_of("G0 X[EXISTS[#<a>\nM2\n");
    ck_assert_int_eq(e.status, INTERP_ERR_SYNTAX);
}
END_TEST

/* Bad names are named with their column; an undefined read names the parameter. */
START_TEST(errors)
{
    struct interp_error e = fail_of("G0 X1\nG1 Y2 Z#<Depth> F5\nM2\n");
    ck_assert_int_eq(e.status, INTERP_ERR_PARAM);
    ck_assert_int_eq(e.line, 2);
    ck_assert_int_eq(e.column, 8);  /* the # */
    ck_assert_ptr_nonnull(strstr(e.message, "#<depth> is not defined"));
    e = fail_of("#<depth = 3\nM2\n");
    ck_assert_int_eq(e.status, INTERP_ERR_SYNTAX);
    ck_assert_int_eq(e.column, 1);
    ck_assert_ptr_nonnull(strstr(e.message, "'>' missing"));
    e = fail_of("G0 X #<>\nM2\n");
    ck_assert_int_eq(e.column, 6);
    ck_assert_ptr_nonnull(strstr(e.message, "without a name"));
    e = fail_of("#<_z>=1\nM2\n");
    ck_assert_int_eq(e.status, INTERP_ERR_PARAM);
    ck_assert_ptr_nonnull(strstr(e.message, "#<_z> is read-only"));
    e = fail_of("#<a> 5\nM2\n");
    ck_assert_int_eq(e.column, 6);
    char longname[300] = "#<";
    memset(longname + 2, 'n', 256);
    strcpy(longname + 258, ">=1\nM2\n");
    e = fail_of(longname);
    ck_assert_ptr_nonnull(strstr(e.message, "longer than 255"));
}
END_TEST

/* #<_ini[SECTION]KEY> through the INI lookup (upper-cased, numbers only, errors naming the
 * key) and #<_hal[name]> through the machine's (0 without one; an unknown pin an error). */
static const char *fake_ini(void *ctx, const char *sec, const char *key)
{
    (void)ctx;
    if (!strcmp(sec, "TRAJ") && !strcmp(key, "MAX_LINEAR_VELOCITY"))
        return "33.5";
    if (!strcmp(sec, "TRAJ") && !strcmp(key, "COORDINATES"))
        return "X Y Z";
    return NULL;
}

static int fake_hal(void *ctx, const char *name, double *v)
{
    (void)ctx;
    if (strcmp(name, "motion.in-position"))
        return -1;
    *v = 1;
    return 0;
}

START_TEST(ini_and_hal)
{
    struct canon_prog p;
    struct interp *in = interp_create();
    const char *prog = "G21\nG0 X#<_ini[traj]max_linear_velocity> Y#<_hal[motion.in-position]>\n"
                       "G0 Z[EXISTS[#<_ini[TRAJ]MAX_LINEAR_VELOCITY>] + "
                       "EXISTS[#<_ini[traj]nope>]]\nM2\n";
    const char *pin = "G21\nG0 Y5\nG0 Y#<_hal[motion.in-position]>\nM2\n";
    ck_assert_int_eq(run_on(in, pin, &p), INTERP_OK);   /* no machine: a pin reads 0 */
    ck_assert(last_move(&p)->end[1] == 0);
    canon_prog_free(&p);
    interp_destroy(in);
    in = interp_create();
    const char *noini = "G21\nG0 X#<_ini[traj]max_linear_velocity>\nM2\n";
    ck_assert_int_ne(run_on(in, noini, &p), INTERP_OK);
    ck_assert_msg(strstr(interp_last_error(in)->message, "no INI file is given"), "%s",
                  interp_last_error(in)->message);
    canon_prog_free(&p);
    interp_set_ini(in, fake_ini, NULL);
    interp_set_hal_fn(in, fake_hal, NULL);
    ck_assert_int_eq(run_on(in, prog, &p), INTERP_OK);
    const struct canon_cmd *a = nth(&p, CANON_TRAVERSE, 0), *b = nth(&p, CANON_TRAVERSE, 1);
    ck_assert(a->end[0] == 33.5 && a->end[1] == 1);
    ck_assert(b->end[2] == 1);                       /* one exists, the other does not */
    canon_prog_free(&p);
    static const struct { const char *prog, *msg; } bad[] = {
        { "G0 X#<_ini[traj]nope>\n", "the INI file has no [TRAJ] NOPE" },
        { "G0 X#<_ini[traj]coordinates>\n", "[TRAJ] COORDINATES = X Y Z is not a number" },
        { "G0 X#<_hal[no.such-pin]>\n", "no HAL pin or parameter 'no.such-pin'" },
        { "#<_ini[traj]max_linear_velocity>=3\n", "is read-only" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ck_assert_int_ne(run_on(in, bad[i].prog, &p), INTERP_OK);
        ck_assert_msg(strstr(interp_last_error(in)->message, bad[i].msg), "%s",
                      interp_last_error(in)->message);
        ck_assert_int_eq(interp_last_error(in)->line, 1);
        canon_prog_free(&p);
    }
    interp_destroy(in);
}
END_TEST

static Suite *named_suite(void)
{
    Suite *s = suite_create("interp_named");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, set_and_use);
    tcase_add_test(tc, many_names);
    tcase_add_test(tc, scope_between_programs);
    tcase_add_test(tc, predefined);
    tcase_add_test(tc, exists);
    tcase_add_test(tc, errors);
    tcase_add_test(tc, ini_and_hal);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(named_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
