/* test_atomicfile.c: common/atomicfile: private temporaries, mode kept, read-only refused,
 * concurrent savers, stale temporaries of killed runs, long paths, write errors. */
#include <check.h>
#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "common/atomicfile.h"
#include "test_file_util.h"

/* Mode kept, new file from the umask, the temporary's name, nothing left behind. */
START_TEST(mode_kept_and_temporary_named)
{
    char dir[64], path[128], err[512] = "", text[64];
    struct stat st;
    struct atomicfile a;
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/t.txt", dir);
    write_file(path, "old\n");
    ck_assert_int_eq(chmod(path, 0640), 0);
    ck_assert_int_eq(atomicfile_open(&a, path, err, sizeof err), ATOMICFILE_OK);
    char want[160];
    snprintf(want, sizeof want, "%s/.t.txt.hexcnc-%ld-", dir, (long)getpid());
    ck_assert_msg(!strncmp(a.tmp, want, strlen(want)), "%s", a.tmp);
    fputs("new\n", a.f);
    read_file(path, text, sizeof text);
    ck_assert_str_eq(text, "old\n");                 /* nothing visible before the commit */
    ck_assert_int_eq(atomicfile_commit(&a, err, sizeof err), ATOMICFILE_OK);
    read_file(path, text, sizeof text);
    ck_assert_str_eq(text, "new\n");
    ck_assert_int_eq(stat(path, &st), 0);
    ck_assert_uint_eq(st.st_mode & 07777, 0640);
    ck_assert_int_eq(count_entries(dir, ""), 1);
    /* a new file: 0666 less the umask */
    mode_t old = umask(027);
    snprintf(path, sizeof path, "%s/new.txt", dir);
    ck_assert_int_eq(atomicfile_write(path, "x", 1, err, sizeof err), ATOMICFILE_OK);
    umask(old);
    ck_assert_int_eq(stat(path, &st), 0);
    ck_assert_uint_eq(st.st_mode & 07777, 0640);
    rm_dir(dir);
}
END_TEST

/* A read-only target (0444; root may write it, so the mode itself decides) is refused and
 * left as it was; a FIFO is not a file to replace; abort leaves nothing. */
START_TEST(read_only_and_special_refused)
{
    char dir[64], path[128], fifo[128], err[512] = "", text[64];
    struct stat st;
    struct atomicfile a;
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/ro.tbl", dir);
    write_file(path, "keep\n");
    ck_assert_int_eq(chmod(path, 0444), 0);
    ck_assert_int_eq(atomicfile_write(path, "x", 1, err, sizeof err), ATOMICFILE_ERR_READ_ONLY);
    ck_assert_msg(strstr(err, path) && strstr(err, "read-only") && strstr(err, "0444"), "%s",
                  err);
    read_file(path, text, sizeof text);
    ck_assert_str_eq(text, "keep\n");
    ck_assert_int_eq(stat(path, &st), 0);
    ck_assert_uint_eq(st.st_mode & 07777, 0444);
    snprintf(fifo, sizeof fifo, "%s/fifo", dir);
    ck_assert_int_eq(mkfifo(fifo, 0644), 0);
    ck_assert_int_eq(atomicfile_write(fifo, "x", 1, err, sizeof err), ATOMICFILE_ERR_NOT_FILE);
    ck_assert_ptr_nonnull(strstr(err, fifo));
    ck_assert_int_eq(chmod(path, 0644), 0);
    ck_assert_int_eq(atomicfile_open(&a, path, err, sizeof err), ATOMICFILE_OK);
    fputs("half", a.f);
    atomicfile_abort(&a);
    read_file(path, text, sizeof text);
    ck_assert_str_eq(text, "keep\n");
    ck_assert_int_eq(count_entries(dir, ".hexcnc-"), 0);
    rm_dir(dir);
}
END_TEST

/* A symbolic link: the file it names is replaced, the link stays a link. */
START_TEST(symlink_target_replaced)
{
    char dir[64], path[128], link_path[128], err[512] = "", text[64];
    struct stat st;
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/real.var", dir);
    snprintf(link_path, sizeof link_path, "%s/link.var", dir);
    write_file(path, "old\n");
    ck_assert_int_eq(symlink("real.var", link_path), 0);
    ck_assert_int_eq(atomicfile_write(link_path, "new\n", 4, err, sizeof err), ATOMICFILE_OK);
    ck_assert_int_eq(lstat(link_path, &st), 0);
    ck_assert(S_ISLNK(st.st_mode));
    read_file(path, text, sizeof text);
    ck_assert_str_eq(text, "new\n");
    rm_dir(dir);
}
END_TEST

/* Two processes saving one file 300 times each: every save succeeds, and a reader always
 * finds one complete version (a header, 200 lines, the end mark). */
START_TEST(concurrent_savers)
{
    char dir[64], path[128], err[512];
    enum { SAVES = 300, LINES = 200 };
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/shared.var", dir);
    write_file(path, "start\n");
    pid_t kids[2];
    for (int k = 0; k < 2; k++) {
        kids[k] = fork();
        ck_assert_int_ge(kids[k], 0);
        if (kids[k] == 0) {
            static char text[LINES * 16 + 64];
            int failed = 0;
            for (int s = 0; s < SAVES; s++) {
                size_t n = (size_t)snprintf(text, sizeof text, "writer %d save %d\n", k, s);
                for (int i = 0; i < LINES; i++)
                    n += (size_t)snprintf(text + n, sizeof text - n, "%d\t%d.000000\n", i, s);
                n += (size_t)snprintf(text + n, sizeof text - n, "end\n");
                failed += atomicfile_write(path, text, n, err, sizeof err) != ATOMICFILE_OK;
            }
            _exit(failed > 255 ? 255 : failed);
        }
    }
    int incomplete = 0, reads = 0, done = 0;
    while (done < 2) {
        static char buf[LINES * 16 + 64];
        FILE *f = fopen(path, "r");
        ck_assert_ptr_nonnull(f);
        size_t n = fread(buf, 1, sizeof buf - 1, f);
        fclose(f);
        buf[n] = '\0';
        reads++;
        int lines = 0;
        for (char *c = buf; *c; c++)
            lines += *c == '\n';
        if (strcmp(buf, "start\n") && (lines != LINES + 2 || strcmp(buf + n - 4, "end\n")))
            incomplete++;
        for (int k = 0; k < 2; k++) {
            int status;
            if (kids[k] > 0 && waitpid(kids[k], &status, WNOHANG) == kids[k]) {
                ck_assert_msg(WIFEXITED(status) && WEXITSTATUS(status) == 0,
                              "writer %d: %d saves failed", k, WEXITSTATUS(status));
                kids[k] = -1;
                done++;
            }
        }
    }
    ck_assert_int_eq(incomplete, 0);
    ck_assert_int_gt(reads, 0);
    ck_assert_int_eq(count_entries(dir, ""), 1);     /* no temporary left */
    rm_dir(dir);
}
END_TEST

/* 200 runs killed in the middle of a save: each new save removes the temporaries of the
 * dead ones, so at most the last is left, and the next save removes it too; the temporary
 * of a process that is still alive is left alone. */
START_TEST(stale_temporaries_removed)
{
    char dir[64], path[128], err[512];
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/tool.tbl", dir);
    write_file(path, "T1 P1 D1\n");
    for (int k = 0; k < 200; k++) {
        pid_t pid = fork();
        ck_assert_int_ge(pid, 0);
        if (pid == 0) {
            struct atomicfile a;
            if (atomicfile_open(&a, path, err, sizeof err) == ATOMICFILE_OK)
                fputs("half a table", a.f), fflush(a.f);
            raise(SIGKILL);
            _exit(1);
        }
        int status;
        ck_assert_int_eq(waitpid(pid, &status, 0), pid);
        ck_assert(WIFSIGNALED(status));
    }
    ck_assert_int_eq(count_entries(dir, ".hexcnc-"), 1);   /* the last killed run's */
    int sync_pipe[2];
    ck_assert_int_eq(pipe(sync_pipe), 0);
    pid_t alive = fork();                   /* holds a temporary while we clean */
    ck_assert_int_ge(alive, 0);
    if (alive == 0) {
        struct atomicfile a;
        char c = atomicfile_open(&a, path, err, sizeof err) == ATOMICFILE_OK ? 'y' : 'n';
        if (write(sync_pipe[1], &c, 1) != 1)
            _exit(1);
        pause();
        _exit(0);
    }
    char c = 0;
    ck_assert_int_eq(read(sync_pipe[0], &c, 1), 1);
    ck_assert_int_eq(c, 'y');
    ck_assert_int_eq(atomicfile_write(path, "T1 P1 D2\n", 9, err, sizeof err), ATOMICFILE_OK);
    ck_assert_int_eq(count_entries(dir, ".hexcnc-"), 1);   /* the live one only */
    kill(alive, SIGKILL);
    waitpid(alive, NULL, 0);
    close(sync_pipe[0]);
    close(sync_pipe[1]);
    ck_assert_int_eq(atomicfile_clean_stale(path), 1);
    ck_assert_int_eq(count_entries(dir, ""), 1);
    rm_dir(dir);
}
END_TEST

/* A path far over 511 characters, with a name over 200: saved under exactly that name. */
START_TEST(long_path)
{
    char dir[64], path[4096], err[512] = "", text[64];
    make_dir(dir, sizeof dir);
    size_t n = (size_t)snprintf(path, sizeof path, "%s", dir);
    char sub[4][120];
    for (int k = 0; k < 4; k++) {
        memset(sub[k], 'a' + k, 100);
        sub[k][100] = '\0';
        n += (size_t)snprintf(path + n, sizeof path - n, "/%s", sub[k]);
        ck_assert_int_eq(mkdir(path, 0755), 0);
    }
    char name[240];
    memset(name, 'n', 230);
    strcpy(name + 230, ".tbl");
    snprintf(path + n, sizeof path - n, "/%s", name);
    ck_assert_uint_gt(strlen(path), 511);
    ck_assert_int_eq(atomicfile_write(path, "v1\n", 3, err, sizeof err), ATOMICFILE_OK);
    ck_assert_int_eq(atomicfile_write(path, "v2\n", 3, err, sizeof err), ATOMICFILE_OK);
    read_file(path, text, sizeof text);
    ck_assert_str_eq(text, "v2\n");
    path[n] = '\0';
    ck_assert_int_eq(count_entries(path, ""), 1);
    ck_assert_int_eq(unlink(strcat(strcat(path, "/"), name)), 0);
    for (int k = 3; k >= 0; k--) {
        path[strlen(path) - strlen(strrchr(path, '/'))] = '\0';
        ck_assert_int_eq(rmdir(path), 0);
    }
    rm_dir(dir);
}
END_TEST

/* A write error (the file size limit, as a full disk would): the save fails naming the
 * file, the target keeps its old text, the temporary is gone. Run in a child so that the
 * limit stays there. */
START_TEST(write_error_fails_cleanly)
{
    char dir[64], path[128], err[512] = "", text[64];
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/p.var", dir);
    write_file(path, "old\n");
    pid_t pid = fork();
    ck_assert_int_ge(pid, 0);
    if (pid == 0) {
        static char big[64 * 1024];
        struct rlimit rl = { 4096, 4096 };
        memset(big, 'x', sizeof big);
        signal(SIGXFSZ, SIG_IGN);
        if (setrlimit(RLIMIT_FSIZE, &rl) != 0)
            _exit(2);
        int st = atomicfile_write(path, big, sizeof big, err, sizeof err);
        _exit(st == ATOMICFILE_ERR_IO && strstr(err, path) ? 0 : 1);
    }
    int status;
    ck_assert_int_eq(waitpid(pid, &status, 0), pid);
    ck_assert(WIFEXITED(status));
    ck_assert_int_eq(WEXITSTATUS(status), 0);
    read_file(path, text, sizeof text);
    ck_assert_str_eq(text, "old\n");
    ck_assert_int_eq(count_entries(dir, ""), 1);
    rm_dir(dir);
}
END_TEST

/* A missing folder: an error naming the file. */
START_TEST(missing_folder)
{
    char err[512] = "";
    ck_assert_int_eq(atomicfile_write("/nonexistent-dir/x.var", "x", 1, err, sizeof err),
                     ATOMICFILE_ERR_IO);
    ck_assert_ptr_nonnull(strstr(err, "/nonexistent-dir/x.var"));
}
END_TEST

static Suite *atomicfile_suite(void)
{
    Suite *s = suite_create("atomicfile");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, mode_kept_and_temporary_named);
    tcase_add_test(tc, read_only_and_special_refused);
    tcase_add_test(tc, symlink_target_replaced);
    tcase_add_test(tc, concurrent_savers);
    tcase_add_test(tc, stale_temporaries_removed);
    tcase_add_test(tc, long_path);
    tcase_add_test(tc, write_error_fails_cleanly);
    tcase_add_test(tc, missing_folder);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(atomicfile_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
