/* test_interp_params.c: the parameter file: strict loading (nan, inf, out of range, trailing
 * text refused with file and line), and saving through common/atomicfile (no fixed temporary
 * name, concurrent savers, read-only refused, write errors). */
#include <check.h>
#include <dirent.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "interp/interp_int.h"
#include "test_file_util.h"
#include "test_interp_util.h"

/* Runs a program on in, then saves the persistent parameters as the machine does once the
 * program's settings have executed (interpreting alone writes nothing); returns the status. */
static int run_and_save(struct interp *in, const char *text)
{
    struct canon_prog p;
    int rc = run_on(in, text, &p);
    canon_prog_free(&p);
    return rc ? rc : interp_params_save(in);
}

/* Loading `text` fails with INTERP_ERR_PARAM on `line`, naming `word`; nothing is changed. */
static void expect_load_error(const char *text, int line, const char *word)
{
    char dir[64], path[128];
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/bad.var", dir);
    write_file(path, text);
    struct interp *in = interp_create();
    ck_assert_msg(interp_set_param_file(in, path) == INTERP_ERR_PARAM, "'%s' was accepted",
                  text);
    const struct interp_error *e = interp_last_error(in);
    ck_assert_str_eq(e->file, path);
    ck_assert_int_eq(e->line, line);
    ck_assert_msg(strstr(e->message, word), "'%s' lacks '%s'", e->message, word);
    ck_assert_double_eq(interp_param(in, 5161), 0.0);   /* all or nothing */
    interp_destroy(in);
    rm_dir(dir);
}

START_TEST(load_refuses_bad_numbers)
{
    expect_load_error("5161 1.5\n5162 nan\n", 2, "nan");
    expect_load_error("5161 1.5\n5162 inf\n", 2, "inf");
    expect_load_error("5161 1.5\n5162 -INF\n", 2, "INF");
    expect_load_error("5161 1.5\n5162 1e999\n", 2, "1e999");
    expect_load_error("5161 1.5\n5162 0x10\n", 2, "0x10");
    expect_load_error("5161 1.5\n5162 1.0abc\n", 2, "abc");
    expect_load_error("5161 1.5\n5162 1.0 2.0\n", 2, "2.0");
    expect_load_error("5161 1.5\n\n5162\n", 3, "value");
    expect_load_error("5161 1.5\n99999999999999999999 1\n", 2, "out of range");
    expect_load_error("5161 1.5\n6000 1\n", 2, "out of range");
    expect_load_error("5161 1.5\n5162x 1\n", 2, "blank");
    /* what LinuxCNC writes, comments and blank lines, still load */
    char dir[64], path[128];
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/ok.var", dir);
    write_file(path, "# comment\n5161\t1.500000\n\n5162 -2e-3  \r\n; comment\n");
    struct interp *in = interp_create();
    ck_assert_int_eq(interp_set_param_file(in, path), 0);
    ck_assert_double_eq(interp_param(in, 5161), 1.5);
    ck_assert_double_eq(interp_param(in, 5162), -0.002);
    interp_destroy(in);
    rm_dir(dir);
}
END_TEST

/* A symlink planted at the old fixed temporary name (PARAMETER_FILE.tmp) is not followed:
 * the file it points at stays as it was. */
START_TEST(planted_symlink_not_followed)
{
    char dir[64], path[128], tmp[140], victim[128], text[64];
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/hexcnc.var", dir);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    snprintf(victim, sizeof victim, "%s/victim", dir);
    write_file(victim, "precious\n");
    ck_assert_int_eq(symlink(victim, tmp), 0);
    struct interp *in = interp_create();
    ck_assert_int_eq(interp_set_param_file(in, path), 0);
    ck_assert_int_eq(run_and_save(in, "G10 L2 P1 X5\nM2\n"), 0);
    interp_destroy(in);
    read_file(victim, text, sizeof text);
    ck_assert_str_eq(text, "precious\n");
    read_file(path, text, sizeof text);
    ck_assert_ptr_nonnull(strstr(text, "5161\t"));
    ck_assert_int_eq(count_entries(dir, ""), 3);              /* var, the planted link, victim */
    rm_dir(dir);
}
END_TEST

/* Two processes sharing one parameter file, 300 runs each: every save succeeds and the
 * file is always one complete version. */
START_TEST(concurrent_saves)
{
    char dir[64], path[128], full[8192];
    enum { RUNS = 300 };
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/shared.var", dir);
    struct interp *in = interp_create();
    ck_assert_int_eq(interp_set_param_file(in, path), 0);
    ck_assert_int_eq(run_and_save(in, "M2\n"), 0);
    interp_destroy(in);
    read_file(path, full, sizeof full);
    int want_lines = 0;
    for (char *c = full; *c; c++)
        want_lines += *c == '\n';
    ck_assert_int_gt(want_lines, 50);
    pid_t kids[2];
    for (int k = 0; k < 2; k++) {
        kids[k] = fork();
        ck_assert_int_ge(kids[k], 0);
        if (kids[k] == 0) {
            struct interp *mine = interp_create();
            int failed = interp_set_param_file(mine, path) != 0;
            char prog[64];
            for (int r = 0; r < RUNS; r++) {
                snprintf(prog, sizeof prog, "G10 L2 P1 X%d Y%d\nM2\n", r, k);
                failed += run_and_save(mine, prog) != 0;
            }
            interp_destroy(mine);
            _exit(failed > 255 ? 255 : failed);
        }
    }
    int done = 0, incomplete = 0;
    while (done < 2) {
        read_file(path, full, sizeof full);
        int lines = 0;
        for (char *c = full; *c; c++)
            lines += *c == '\n';
        incomplete += lines != want_lines;
        for (int k = 0; k < 2; k++) {
            int status;
            if (kids[k] > 0 && waitpid(kids[k], &status, WNOHANG) == kids[k]) {
                ck_assert_msg(WIFEXITED(status) && WEXITSTATUS(status) == 0,
                              "process %d: %d saves failed", k, WEXITSTATUS(status));
                kids[k] = -1;
                done++;
            }
        }
    }
    ck_assert_int_eq(incomplete, 0);
    ck_assert_int_eq(count_entries(dir, ""), 1);
    rm_dir(dir);
}
END_TEST

/* A read-only parameter file: the run reports it, the file stays as it was. */
START_TEST(read_only_refused)
{
    char dir[64], path[128], text[64];
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/ro.var", dir);
    write_file(path, "5161 1.5\n");
    ck_assert_int_eq(chmod(path, 0444), 0);
    struct interp *in = interp_create();
    ck_assert_int_eq(interp_set_param_file(in, path), 0);
    ck_assert_int_eq(run_and_save(in, "G10 L2 P1 X5\nM2\n"), INTERP_ERR_IO);
    const char *m = interp_last_error(in)->message;
    ck_assert_msg(strstr(m, path) && strstr(m, "read-only"), "%s", m);
    interp_destroy(in);
    read_file(path, text, sizeof text);
    ck_assert_str_eq(text, "5161 1.5\n");
    ck_assert_int_eq(count_entries(dir, ""), 1);
    rm_dir(dir);
}
END_TEST

/* A write error (file size limit, as a full disk) fails the run; the file stays. */
START_TEST(write_error_reported)
{
    char dir[64], path[128], text[64];
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/p.var", dir);
    write_file(path, "5161 1.5\n");
    pid_t pid = fork();
    ck_assert_int_ge(pid, 0);
    if (pid == 0) {
        struct rlimit rl = { 200, 200 };
        struct interp *in = interp_create();
        if (interp_set_param_file(in, path) != 0)
            _exit(3);
        signal(SIGXFSZ, SIG_IGN);
        if (setrlimit(RLIMIT_FSIZE, &rl) != 0)
            _exit(2);
        int rc = run_and_save(in, "G10 L2 P1 X5\nM2\n");
        int ok = rc == INTERP_ERR_IO && strstr(interp_last_error(in)->message, path);
        _exit(ok ? 0 : 1);
    }
    int status;
    ck_assert_int_eq(waitpid(pid, &status, 0), pid);
    ck_assert(WIFEXITED(status));
    ck_assert_int_eq(WEXITSTATUS(status), 0);
    read_file(path, text, sizeof text);
    ck_assert_str_eq(text, "5161 1.5\n");
    ck_assert_int_eq(count_entries(dir, ""), 1);
    rm_dir(dir);
}
END_TEST

static Suite *params_suite(void)
{
    Suite *s = suite_create("interp_params");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, load_refuses_bad_numbers);
    tcase_add_test(tc, planted_symlink_not_followed);
    tcase_add_test(tc, concurrent_saves);
    tcase_add_test(tc, read_only_refused);
    tcase_add_test(tc, write_error_reported);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(params_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
