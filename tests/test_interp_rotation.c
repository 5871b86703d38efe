/* test_interp_rotation.c: G10 L2 R, the rotation of a coordinate system, in the machine frame
 * the interpreter hands to motion (the program frame is compared with rs274 in
 * tests/interp_expected/g10_rotation*.ngc). */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "interp/printer.h"
#include "test_interp_util.h"

#define TOL 1e-9

/* Moves are turned about the work offset's origin; G91 steps along the turned axes. */
START_TEST(rotated_moves)
{
    struct canon_prog p;
    interp_ok("G21 G10 L2 P1 X10 Y5 R90\nG0 X1 Y0\nG91 G0 X1\nG90 G1 Y2 F100\nM2\n", &p);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 0)->end, 10, 6, 0, 0, 0, 0, TOL);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 1)->end, 10, 7, 0, 0, 0, 0, TOL);
    ck_assert_pose(nth(&p, CANON_FEED, 0)->end, 8, 7, 0, 0, 0, 0, TOL);
    ck_assert_double_eq_tol(nth(&p, CANON_OFFSETS, 0)->value, 90, TOL);
    canon_prog_free(&p);
}
END_TEST

/* An arc's centre turns with the system, and so does the plane of a G18 arc. */
START_TEST(rotated_arcs)
{
    struct canon_prog p;
    interp_ok("G21 G10 L2 P1 R90\nG0 X1 Y0\nG3 X-1 Y0 I-1 J0 F100\n"
              "G18 G2 X-3 Z0 I-1 K0\nM2\n", &p);
    const struct canon_cmd *a = nth(&p, CANON_ARC, 0);
    ck_assert_pose(a->end, 0, -1, 0, 0, 0, 0, TOL);
    ck_assert_double_eq_tol(a->arc.center[0], 0, TOL);
    ck_assert_double_eq_tol(a->arc.center[1], 0, TOL);
    a = nth(&p, CANON_ARC, 1);
    ck_assert_pose(a->end, 0, -3, 0, 0, 0, 0, TOL);
    ck_assert_double_eq_tol(a->arc.center[1], -2, TOL);
    ck_assert_double_eq_tol(a->arc.normal[0], -1, TOL);  /* Y turned by 90 degrees */
    ck_assert_double_eq_tol(a->arc.normal[1], 0, TOL);
    canon_prog_free(&p);
}
END_TEST

/* G92 is measured in the turned frame; #5420.. and #<_x> tell the point in it. */
START_TEST(rotated_g92_and_position)
{
    struct canon_prog p;
    interp_ok("G21 G10 L2 P1 R90\nG0 X1 Y0\nG92 X0 Y0\nG0 X0 Y1\n"
              "G0 X[#5420 + 2] Y[#<_y> + #5421]\nM2\n", &p);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 1)->end, -1, 1, 0, 0, 0, 0, TOL);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 2)->end, -2, 3, 0, 0, 0, 0, TOL);
    canon_prog_free(&p);
}
END_TEST

/* L20 sets the offset so the current point reads as given in the turned frame. */
START_TEST(rotated_l20)
{
    struct canon_prog p;
    interp_ok("G21 G10 L2 P1 R90\nG0 X1 Y0\nG10 L20 P1 X0 Y0\nG0 X1\nM2\n", &p);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 1)->end, 0, 2, 0, 0, 0, 0, TOL);
    canon_prog_free(&p);
}
END_TEST

/* The rotation is parameter #5210 + 20 n, kept in the parameter file and read back. */
START_TEST(rotation_parameter_kept)
{
    struct interp *in = interp_create();
    struct canon_prog p;
    ck_assert_int_eq(run_on(in, "G10 L2 P2 R30\nG55\nM2\n", &p), INTERP_OK);
    ck_assert_double_eq(interp_param(in, 5250), 30);
    const struct canon_cmd *s = nth(&p, CANON_SETTING, 0);
    int found = 0;
    for (size_t i = 0; i < s->setting->nparams; i++)
        found |= s->setting->params[i].number == 5250 && s->setting->params[i].value == 30;
    ck_assert_msg(found, "the setting does not carry #5250");
    canon_prog_free(&p);
    interp_destroy(in);

    char path[] = "/tmp/hexcnc_rotXXXXXX";
    int fd = mkstemp(path);
    ck_assert_int_ge(fd, 0);
    const char *text = "5220\t1.000000\n5230\t90.000000\n";
    ck_assert_int_eq(write(fd, text, strlen(text)), (int)strlen(text));
    close(fd);
    in = interp_create();
    ck_assert_int_eq(interp_load_param_file(in, path), INTERP_OK);
    ck_assert_int_eq(run_on(in, "G0 X1\nM2\n", &p), INTERP_OK);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 0)->end, 0, 1, 0, 0, 0, 0, TOL);
    canon_prog_free(&p);
    interp_destroy(in);
    unlink(path);
}
END_TEST

/* The printer turns the machine frame back into the program's, as rs274 prints it. */
static int to_buf(void *ctx, const char *buf, size_t len)
{
    strncat(ctx, buf, len);
    return 0;
}

START_TEST(rotation_printed)
{
    static struct interp_printer pr;
    static char out[8192];
    struct interp *in = interp_create();
    out[0] = 0;
    interp_printer_init(&pr, in, 4, to_buf, out);
    const char *text = "G21 G10 L2 P1 X1 R45\nG0 X2 Y3\nM2\n";
    ck_assert_int_eq(interp_run_text(in, "t.ngc", text, strlen(text), interp_printer_sink, &pr),
                     INTERP_OK);
    interp_printer_flush(&pr);
    ck_assert_ptr_nonnull(strstr(out, "SET_XY_ROTATION(45.0000)"));
    ck_assert_ptr_nonnull(strstr(out, "STRAIGHT_TRAVERSE(2.0000, 3.0000, 0.0000,"));
    interp_destroy(in);
}
END_TEST

static Suite *rotation_suite(void)
{
    Suite *s = suite_create("interp_rotation");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, rotated_moves);
    tcase_add_test(tc, rotated_arcs);
    tcase_add_test(tc, rotated_g92_and_position);
    tcase_add_test(tc, rotated_l20);
    tcase_add_test(tc, rotation_parameter_kept);
    tcase_add_test(tc, rotation_printed);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(rotation_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
