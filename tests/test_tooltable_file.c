/* test_tooltable_file.c: saving a tool table: only changed lines rewritten, read-only refused,
 * mode kept, long paths, write errors, stale temporaries removed at load. */
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

#include "interp/tooltable.h"
#include "test_file_util.h"

/* Lines of a and b that differ (same line count expected); *which gets the last one. */
static int lines_changed(const char *a, const char *b, int *which)
{
    int n = 0, line = 1;
    while (*a || *b) {
        size_t la = strcspn(a, "\n"), lb = strcspn(b, "\n");
        if (la != lb || memcmp(a, b, la))
            n++, *which = line;
        a += la + (a[la] == '\n');
        b += lb + (b[lb] == '\n');
        line++;
    }
    return n;
}

/* A LinuxCNC-style table as people write them: comments, blank lines, tools out of order,
 * lower case, '+' signs, six decimals, CR LF on one line, a wear entry with every field. */
static const char lcnc_table[] =
    ";Tool table of the hexapod: keep this header\n"
    "\n"
    "T12 P3 Z+12.500000 D6.000000 ;6 mm end mill\n"
    "t2   p2  d.25   z-1.5 ;lower case, D before Z\n"
    "   ; indented comment\n"
    "T1 P1 X0.10000 Y0 Z0 D10.0000 I95.0 J155.0 Q1 ;face \r\n"
    "T10001 P0 X0.00100 Y0 Z0.00100 D-0.0200 ;Wear Offset 1\n"
    "\n"
    "T5 P5 D3 ; the last line has no comment after it";

/* One G10 L1 on one entry changes that line and nothing else. */
START_TEST(rewrite_changes_one_line)
{
    char dir[64], path[128], err[256] = "", after[2048];
    struct tooltable t;
    int which = 0;
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/tool.tbl", dir);
    write_file(path, lcnc_table);
    ck_assert_msg(tooltable_load(&t, path, err, sizeof err) == TOOLTABLE_OK, "%s", err);
    ck_assert_int_eq(tooltable_g10_l1(&t, 12, 1, 3.5, 1, 12.75), TOOLTABLE_OK);
    ck_assert_msg(tooltable_save(&t, path, err, sizeof err) == TOOLTABLE_OK, "%s", err);
    read_file(path, after, sizeof after);
    ck_assert_int_eq(lines_changed(lcnc_table, after, &which), 1);
    ck_assert_int_eq(which, 3);
    ck_assert_ptr_nonnull(strstr(after, "\nT12 P3 Z+12.750000 D7.000000 ;6 mm end mill\n"));
    /* the wear of tool 1: only the D of the wear entry changes, in its style */
    ck_assert_int_eq(tooltable_g10_l1(&t, 10001, 1, -0.02, 0, 0), TOOLTABLE_OK);
    ck_assert_int_eq(tooltable_save(&t, path, err, sizeof err), TOOLTABLE_OK);
    char again[2048];
    read_file(path, again, sizeof again);
    ck_assert_int_eq(lines_changed(after, again, &which), 1);
    ck_assert_int_eq(which, 7);
    ck_assert_ptr_nonnull(strstr(again, "T10001 P0 X0.00100 Y0 Z0.00100 D-0.0400 ;Wear Offset 1\n"));
    /* a new tool and a new wear go at the end; what was there stays */
    ck_assert_int_eq(tooltable_g10_l1(&t, 7, 1, 2.0, 0, 0), TOOLTABLE_OK);
    ck_assert_int_eq(tooltable_set_wear(&t, 2, -0.01), TOOLTABLE_OK);
    ck_assert_int_eq(tooltable_save(&t, path, err, sizeof err), TOOLTABLE_OK);
    read_file(path, after, sizeof after);
    ck_assert_int_eq(strncmp(after, again, strlen(again)), 0);
    ck_assert_str_eq(after + strlen(again), "\nT10002 P0 D-0.01 ;wear of T2\nT7 P7 D4\n");
    struct tooltable u;
    ck_assert_msg(tooltable_load(&u, path, err, sizeof err) == TOOLTABLE_OK, "%s", err);
    ck_assert_int_eq(u.count, t.count);
    ck_assert_double_eq(tooltable_find(&u, 2)->wear_mm, -0.01);
    ck_assert_double_eq(tooltable_find(&u, 1)->wear_mm, -0.04);
    ck_assert_double_eq(tooltable_find(&u, 12)->diameter_mm, 7);
    ck_assert_int_eq(count_entries(dir, ""), 1);
    rm_dir(dir);
}
END_TEST

/* A 0444 table is refused with a message naming it, and stays as it was (mode too); a
 * writable one keeps its mode. */
START_TEST(read_only_refused_mode_kept)
{
    char dir[64], path[128], err[256] = "", text[1024];
    struct tooltable t;
    struct stat st;
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/tool.tbl", dir);
    write_file(path, lcnc_table);
    ck_assert_int_eq(chmod(path, 0444), 0);
    ck_assert_int_eq(tooltable_load(&t, path, err, sizeof err), TOOLTABLE_OK);
    ck_assert_int_eq(tooltable_g10_l1(&t, 12, 1, 3.5, 0, 0), TOOLTABLE_OK);
    ck_assert_int_eq(tooltable_save(&t, path, err, sizeof err), TOOLTABLE_ERR_IO);
    ck_assert_msg(strstr(err, path) && strstr(err, "read-only"), "%s", err);
    read_file(path, text, sizeof text);
    ck_assert_str_eq(text, lcnc_table);
    ck_assert_int_eq(stat(path, &st), 0);
    ck_assert_uint_eq(st.st_mode & 07777, 0444);
    ck_assert_int_eq(chmod(path, 0640), 0);
    ck_assert_int_eq(tooltable_save(&t, path, err, sizeof err), TOOLTABLE_OK);
    ck_assert_int_eq(stat(path, &st), 0);
    ck_assert_uint_eq(st.st_mode & 07777, 0640);
    ck_assert_int_eq(count_entries(dir, ""), 1);
    rm_dir(dir);
}
END_TEST

/* A path of more than 511 characters is loaded and saved under exactly its name. */
START_TEST(long_path_not_cut)
{
    char dir[64], path[1024], err[512] = "";
    struct tooltable t;
    make_dir(dir, sizeof dir);
    size_t n = (size_t)snprintf(path, sizeof path, "%s", dir);
    for (int k = 0; k < 5; k++) {
        n += (size_t)snprintf(path + n, sizeof path - n, "/%0100d", k);
        ck_assert_int_eq(mkdir(path, 0755), 0);
    }
    snprintf(path + n, sizeof path - n, "/tool.tbl");
    ck_assert_uint_gt(strlen(path), 511);
    write_file(path, "T1 P1 D10\n");
    ck_assert_msg(tooltable_load(&t, path, err, sizeof err) == TOOLTABLE_OK, "%s", err);
    ck_assert_str_eq(t.path, path);
    ck_assert_int_eq(tooltable_g10_l1(&t, 1, 1, 4.0, 0, 0), TOOLTABLE_OK);
    ck_assert_int_eq(tooltable_save(&t, t.path, err, sizeof err), TOOLTABLE_OK);
    char text[64];
    read_file(path, text, sizeof text);
    ck_assert_str_eq(text, "T1 P1 D8\n");
    path[n] = '\0';
    ck_assert_int_eq(count_entries(path, ""), 1);
    for (int k = 0; k < 5; k++) {
        rm_dir(path);
        path[strlen(path) - strlen(strrchr(path, '/'))] = '\0';
    }
    rm_dir(dir);
}
END_TEST

/* A write error (the file size limit, as a full disk) fails the save; the table stays. */
START_TEST(write_error_keeps_table)
{
    char dir[64], path[128], err[256] = "", text[1024];
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/tool.tbl", dir);
    write_file(path, lcnc_table);
    pid_t pid = fork();
    ck_assert_int_ge(pid, 0);
    if (pid == 0) {
        static struct tooltable t;
        struct rlimit rl = { 512, 512 };
        if (tooltable_load(&t, path, err, sizeof err) != TOOLTABLE_OK)
            _exit(3);
        for (int k = 20; k < 60; k++)
            tooltable_g10_l1(&t, k, 1, 1.0, 1, 2.0);
        signal(SIGXFSZ, SIG_IGN);
        if (setrlimit(RLIMIT_FSIZE, &rl) != 0)
            _exit(2);
        int st = tooltable_save(&t, path, err, sizeof err);
        _exit(st == TOOLTABLE_ERR_IO && strstr(err, path) ? 0 : 1);
    }
    int status;
    ck_assert_int_eq(waitpid(pid, &status, 0), pid);
    ck_assert(WIFEXITED(status));
    ck_assert_int_eq(WEXITSTATUS(status), 0);
    read_file(path, text, sizeof text);
    ck_assert_str_eq(text, lcnc_table);
    ck_assert_int_eq(count_entries(dir, ""), 1);
    rm_dir(dir);
}
END_TEST

/* Loading removes the temporary a killed save left (its process is gone). */
START_TEST(load_removes_stale_temporary)
{
    char dir[64], path[128], stale[200], err[256] = "";
    struct tooltable t;
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/tool.tbl", dir);
    write_file(path, "T1 P1 D10\n");
    pid_t pid = fork();                     /* a process id that is surely gone */
    ck_assert_int_ge(pid, 0);
    if (pid == 0)
        _exit(0);
    ck_assert_int_eq(waitpid(pid, NULL, 0), pid);
    snprintf(stale, sizeof stale, "%s/.tool.tbl.hexcnc-%ld-AbC123", dir, (long)pid);
    write_file(stale, "T1 P1 D");
    ck_assert_int_eq(count_entries(dir, ""), 2);
    ck_assert_int_eq(tooltable_load(&t, path, err, sizeof err), TOOLTABLE_OK);
    ck_assert_int_eq(count_entries(dir, ""), 1);
    rm_dir(dir);
}
END_TEST

static Suite *tooltable_file_suite(void)
{
    Suite *s = suite_create("tooltable_file");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, rewrite_changes_one_line);
    tcase_add_test(tc, read_only_refused_mode_kept);
    tcase_add_test(tc, long_path_not_cut);
    tcase_add_test(tc, write_error_keeps_table);
    tcase_add_test(tc, load_removes_stale_temporary);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(tooltable_file_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
