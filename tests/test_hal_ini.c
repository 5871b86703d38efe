/* test_hal_ini.c: the INI reader: LinuxCNC conventions, repeated keys, comments as Debian's
 * libinih reads them, typed readers and the messages for bad files. */
#include <check.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "hal/hal.h"

/* A runtime working in tests/hal/ini. */
static struct hal *new_hal(void)
{
    const char *root = getenv("HEXCNC_ROOT");
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/tests/hal/ini", root ? root : ".");
    ck_assert_msg(chdir(dir) == 0, "cannot enter %s", dir);
    struct hal *h = hal_create();
    ck_assert_ptr_nonnull(h);
    return h;
}

START_TEST(values_comments_and_repeated_keys)
{
    struct hal *h = new_hal();
    ck_assert_ptr_null(hal_ini_path(h));
    ck_assert_ptr_null(hal_ini_get(h, "KINS", "JOINTS"));
    ck_assert_int_eq(hal_load_ini(h, "good.ini"), HAL_OK);
    ck_assert_str_eq(hal_ini_path(h), "good.ini");
    ck_assert_str_eq(hal_ini_dir(h), ".");
    ck_assert_str_eq(hal_ini_get(h, "EMCMOT", "SERVO_PERIOD"), "1000000");
    ck_assert_str_eq(hal_ini_get(h, "TRAJ", "MAX_LINEAR_VELOCITY"), "25.5");
    ck_assert_str_eq(hal_ini_get(h, "TRAJ", "MAX_LINEAR_ACCELERATION"),
                     "100 # an inline '#' is NOT a comment: it stays in the value");
    ck_assert_str_eq(hal_ini_get(h, "TRAJ", "RATIO"), "5;7");    /* ';' needs a blank */
    ck_assert_str_eq(hal_ini_get(h, "TRAJ", "LABEL"), "colon separated");
    ck_assert_str_eq(hal_ini_get(h, "TRAJ", "EMPTY"), "");
    ck_assert_ptr_null(hal_ini_get(h, "traj", "LABEL"));           /* names are exact */
    ck_assert_str_eq(hal_ini_get_n(h, "HAL", "HALFILE", 0), "core.hal");
    ck_assert_str_eq(hal_ini_get_n(h, "HAL", "HALFILE", 1), "io.hal");
    ck_assert_str_eq(hal_ini_get_n(h, "HAL", "HALFILE", 2), "ui.hal");
    ck_assert_ptr_null(hal_ini_get_n(h, "HAL", "HALFILE", 3));
    ck_assert_str_eq(hal_ini_get_n(h, "KINS", "BASE_X", 0), "1");
    ck_assert_str_eq(hal_ini_get_n(h, "KINS", "BASE_X", 1), "2");
    hal_destroy(h);
}
END_TEST

START_TEST(typed_readers)
{
    struct hal *h = new_hal();
    ck_assert_int_eq(hal_load_ini(h, "good.ini"), HAL_OK);
    double d;
    long n;
    ck_assert_int_eq(hal_ini_double(h, "TRAJ", "MAX_LINEAR_VELOCITY", 1.0, &d), HAL_OK);
    ck_assert(d == 25.5);
    ck_assert_int_eq(hal_ini_double(h, "TRAJ", "MISSING", 7.5, &d), HAL_ERR_NOT_FOUND);
    ck_assert(d == 7.5);
    ck_assert_int_eq(hal_ini_double(h, "TRAJ", "NOT_A_NUMBER", 7.5, &d), HAL_ERR_SYNTAX);
    ck_assert_str_eq(hal_last_error(h), "good.ini:12: [TRAJ]NOT_A_NUMBER = 'fast' is not a "
                     "number");
    ck_assert(d == 7.5);
    ck_assert_int_eq(hal_ini_double(h, "TRAJ", "MAX_LINEAR_ACCELERATION", 0, &d),
                     HAL_ERR_SYNTAX);
    ck_assert_int_eq(hal_ini_int(h, "TRAJ", "COUNT", 0, &n), HAL_OK);
    ck_assert_int_eq(n, 12);
    ck_assert_int_eq(hal_ini_int(h, "TRAJ", "MAX_LINEAR_VELOCITY", 3, &n), HAL_ERR_SYNTAX);
    ck_assert_str_eq(hal_last_error(h), "good.ini:7: [TRAJ]MAX_LINEAR_VELOCITY = '25.5' is not "
                     "a whole number");
    ck_assert_int_eq(n, 3);
    ck_assert_int_eq(hal_ini_int(h, "NOSECTION", "COUNT", 4, &n), HAL_ERR_NOT_FOUND);
    ck_assert_int_eq(n, 4);
    hal_destroy(h);
}
END_TEST

START_TEST(bad_files_name_file_and_line)
{
    struct hal *h = new_hal();
    ck_assert_int_eq(hal_load_ini(h, "bad_syntax.ini"), HAL_ERR_SYNTAX);
    ck_assert_str_eq(hal_last_error(h), "bad_syntax.ini:3: this line is not a [SECTION] "
                     "header, a KEY = VALUE line or a comment");
    ck_assert_ptr_null(hal_ini_path(h));          /* nothing half-read is kept */
    ck_assert_ptr_null(hal_ini_get(h, "KINS", "KINEMATICS"));
    ck_assert_int_eq(hal_load_ini(h, "bad_section.ini"), HAL_ERR_SYNTAX);
    ck_assert_str_eq(hal_last_error(h), "bad_section.ini:2: this line is not a [SECTION] "
                     "header, a KEY = VALUE line or a comment");
    ck_assert_int_eq(hal_load_ini(h, "long_line.ini"), HAL_ERR_SYNTAX);
    ck_assert_str_eq(hal_last_error(h), "long_line.ini:3: line longer than 198 characters "
                     "(the INI reader's limit)");
    ck_assert_int_eq(hal_load_ini(h, "no_such.ini"), HAL_ERR_IO);
    ck_assert_str_eq(hal_last_error(h), "cannot open INI file 'no_such.ini': No such file or "
                     "directory");
    ck_assert_int_eq(hal_load_ini(h, "../ini/good.ini"), HAL_OK);
    ck_assert_str_eq(hal_ini_dir(h), "../ini");
    hal_destroy(h);
}
END_TEST

static Suite *hal_ini_suite(void)
{
    Suite *s = suite_create("hal_ini");
    TCase *tc = tcase_create("ini");
    tcase_add_test(tc, values_comments_and_repeated_keys);
    tcase_add_test(tc, typed_readers);
    tcase_add_test(tc, bad_files_name_file_and_line);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(hal_ini_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
