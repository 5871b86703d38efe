/* test_inifile.c: the INI reader: entries in order with their lines, repeated keys, long and
 * bad lines named by number, and messages pointed at the key's line. */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "common/inifile.h"

/* Writes text to a fresh temporary file; path receives its name. */
static void write_tmp(char *path, size_t len, const char *text)
{
    snprintf(path, len, "/tmp/hexcnc-inifile-XXXXXX");
    int fd = mkstemp(path);
    ck_assert_int_ge(fd, 0);
    FILE *f = fdopen(fd, "w");
    ck_assert_ptr_nonnull(f);
    fputs(text, f);
    fclose(f);
}

START_TEST(entries_lines_and_repeats)
{
    char path[64], err[256];
    write_tmp(path, sizeof path, "# machine\n[KINS]\nKINEMATICS = hexapod\n\n[HAL]\n"
              "HALFILE = a.hal ; first\nHALFILE = b.hal\n[KINS]\nJOINTS = 6\nBASE_X = 1\n  2\n");
    struct inifile ini = { 0 };
    ck_assert_int_eq(inifile_load(&ini, path, err, sizeof err), INIFILE_OK);
    ck_assert_str_eq(inifile_path(&ini), path);
    ck_assert_str_eq(inifile_dir(&ini), "/tmp");
    ck_assert_str_eq(inifile_get(&ini, "KINS", "KINEMATICS"), "hexapod");
    ck_assert_int_eq(inifile_line(&ini, "KINS", "KINEMATICS"), 3);
    ck_assert_str_eq(inifile_get_n(&ini, "HAL", "HALFILE", 0), "a.hal");
    ck_assert_str_eq(inifile_get_n(&ini, "HAL", "HALFILE", 1), "b.hal");
    ck_assert_ptr_null(inifile_get_n(&ini, "HAL", "HALFILE", 2));
    ck_assert_int_eq(inifile_line(&ini, "HAL", "HALFILE"), 6);
    ck_assert_int_eq(inifile_line(&ini, "KINS", "JOINTS"), 9);   /* a section may reopen */
    ck_assert_str_eq(inifile_get_n(&ini, "KINS", "BASE_X", 1), "2");
    ck_assert_int_eq(inifile_line(&ini, "KINS", "MISSING"), 0);
    ck_assert_ptr_null(inifile_get(&ini, "kins", "JOINTS"));      /* names are exact */
    ck_assert_str_eq(inifile_config_get(&ini, "KINS", "JOINTS"), "6");
    ck_assert_uint_eq(ini.n, 6);
    ck_assert_str_eq(ini.items[0].key, "KINEMATICS");             /* file order */
    ck_assert_str_eq(ini.items[5].key, "BASE_X");
    ck_assert_int_eq(ini.items[5].line, 11);
    inifile_free(&ini);
    ck_assert_ptr_null(inifile_get(&ini, "KINS", "KINEMATICS"));
    unlink(path);
}
END_TEST

START_TEST(bad_lines_are_named)
{
    char path[64], err[256], want[256], text[1024];
    struct inifile ini = { 0 };
    write_tmp(path, sizeof path, "[A]\nX = 1\nthis is not ini\n");
    ck_assert_int_eq(inifile_load(&ini, path, err, sizeof err), INIFILE_ERR_SYNTAX);
    snprintf(want, sizeof want, "%s:3: this line is not a [SECTION] header, a KEY = VALUE "
             "line or a comment", path);
    ck_assert_str_eq(err, want);
    ck_assert_ptr_null(inifile_path(&ini));                       /* nothing half-read */
    ck_assert_ptr_null(inifile_get(&ini, "A", "X"));
    unlink(path);

    /* 198 characters fit libinih's buffer, also with a CR LF ending; 199 do not. */
    snprintf(text, sizeof text, "[A]\nK = %0194d\r\nL = %0194d\nM = %0195d\nN = 1\n", 0, 0, 0);
    write_tmp(path, sizeof path, text);
    ck_assert_int_eq(inifile_load(&ini, path, err, sizeof err), INIFILE_ERR_SYNTAX);
    snprintf(want, sizeof want, "%s:4: line longer than 198 characters (the INI reader's "
             "limit)", path);
    ck_assert_str_eq(err, want);
    unlink(path);

    snprintf(text, sizeof text, "[A]\nK = %0194d\r\nL = %0194d\n", 0, 0);
    write_tmp(path, sizeof path, text);
    ck_assert_int_eq(inifile_load(&ini, path, err, sizeof err), INIFILE_OK);
    ck_assert_int_eq(inifile_line(&ini, "A", "L"), 3);
    ck_assert_uint_eq(strlen(inifile_get(&ini, "A", "L")), 194);
    inifile_free(&ini);
    unlink(path);

    ck_assert_int_eq(inifile_load(&ini, "/nonexistent/m.ini", err, sizeof err),
                     INIFILE_ERR_IO);
    ck_assert_str_eq(err, "cannot open INI file '/nonexistent/m.ini': No such file or "
                     "directory");
}
END_TEST

START_TEST(messages_point_at_the_key)
{
    char path[64], err[256], out[512], want[512];
    struct inifile ini = { 0 };
    char msg[] = "[JOINT_3] MAX_LIMIT: 'abc' is not a number";
    ck_assert_str_eq(inifile_locate_msg(&ini, msg, out, sizeof out), msg);  /* no file */
    write_tmp(path, sizeof path, "[JOINT_3]\nMIN_LIMIT = 1\nMAX_LIMIT = abc\n"
              "[RS274NGC]\nFEED_UNITS = furlongs\n");
    ck_assert_int_eq(inifile_load(&ini, path, err, sizeof err), INIFILE_OK);
    snprintf(want, sizeof want, "%s:3: %s", path, msg);
    ck_assert_str_eq(inifile_locate_msg(&ini, msg, out, sizeof out), want);
    snprintf(want, sizeof want, "%s:5: [RS274NGC] FEED_UNITS = furlongs: use mm/min", path);
    ck_assert_str_eq(inifile_locate_msg(&ini, "[RS274NGC] FEED_UNITS = furlongs: use mm/min",
                                        out, sizeof out), want);
    snprintf(want, sizeof want, "%s: [KINS] BASE_RADIUS: missing", path);   /* no [KINS] */
    ck_assert_str_eq(inifile_locate_msg(&ini, "[KINS] BASE_RADIUS: missing", out, sizeof out),
                     want);
    /* a key missing from a section the file has: the section's first line */
    snprintf(want, sizeof want, "%s:2: [JOINT_3] MAX_JERK: missing", path);
    ck_assert_str_eq(inifile_locate_msg(&ini, "[JOINT_3] MAX_JERK: missing", out, sizeof out),
                     want);
    snprintf(want, sizeof want, "%s: no kinematics", path);
    ck_assert_str_eq(inifile_locate_msg(&ini, "no kinematics", out, sizeof out), want);
    inifile_free(&ini);
    unlink(path);
}
END_TEST

static Suite *inifile_suite(void)
{
    Suite *s = suite_create("inifile");
    TCase *tc = tcase_create("inifile");
    tcase_add_test(tc, entries_lines_and_repeats);
    tcase_add_test(tc, bad_lines_are_named);
    tcase_add_test(tc, messages_point_at_the_key);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(inifile_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
