/* test_check_stream.c: hexcnc check of long programs, streamed: the same figures as with the
 * whole program in memory, a fraction of its memory, and errors found late in the program. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench/bench_dense.h"
#include "check/check.h"
#include "check/plot.h"
#include "tests/test_check_util.h"

#define TMU_INI "configs/sim/tmu-hexapod.ini"

#ifdef __SANITIZE_ADDRESS__
/* AddressSanitizer holds freed memory back (its quarantine, 256 MB): a streamed check frees
 * each window as it goes, so with the quarantine its peak would count every window. Without
 * it the two peaks compare as in a plain build (the shadow memory adds an eighth to both). */
const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "quarantine_size_mb=0";
}
#endif

/* Dense five-axis code as CAM writes it: n blocks of 0.5 mm with X Y Z A B C on each, a
 * wandering direction inside the TMU's region, G64 P0.01 at F2000; then `last` (a line of
 * its own, or NULL) and M2. Returns the file's path (static buffer). */
static const char *dense_program(int n, const char *last)
{
    static char path[64];
    snprintf(path, sizeof path, "/tmp/hexcnc_dense_%d.ngc", (int)getpid());
    ck_assert_int_eq(bench_dense_write_seed(path, n, 7, last), 0);
    return path;
}

/* The check of prog on the TMU machine: streamed, or (whole) with the program in memory (a
 * trace asks for that: its samples are spread over the planned time). */
static int run(const char *prog, int whole, struct check_result *r)
{
    char ip[1024], err[1024];
    struct check_machine *mc;
    ck_assert_msg(check_machine_open(tc_path(TMU_INI, ip, sizeof ip), &mc, err, sizeof err) == 0,
                  "%s", err);
    struct check_opts o;
    struct check_trace trace;
    check_opts_default(&o);
    check_trace_init(&trace);
    if (whole)
        o.trace = &trace;
    check_result_init(r);
    int st = check_program(mc, prog, &o, r);
    check_trace_free(&trace);
    check_machine_close(mc);
    return st;
}

/* Streamed windows hand over at full speed: the run is the whole program's, to the period. */
START_TEST(test_stream_same_figures)
{
    const char *prog = dense_program(12000, NULL);
    struct check_result s, w;
    ck_assert_int_eq(run(prog, 0, &s), CHECK_OK);
    ck_assert_int_eq(run(prog, 1, &w), CHECK_OK);
    unlink(prog);
    printf("12000 dense blocks: streamed %ld periods, whole %ld; condition %.6f / %.6f\n",
           s.periods, w.periods, s.max_condition, w.max_condition);
    ck_assert(s.simulated && w.simulated);
    ck_assert(s.machining_time_s > 150);           /* 6 km... 6000 mm at <= 33 mm/s */
    ck_assert(labs(s.periods - w.periods) <= 2);
    ck_assert(fabs(s.length_mm - w.length_mm) < 1e-6);
    ck_assert(fabs(s.planned_time_s - w.planned_time_s) < 0.01);
    ck_assert(fabs(s.max_deviation_mm - w.max_deviation_mm) < 1e-7);
    ck_assert(fabs(s.max_condition - w.max_condition) < 1e-6 * w.max_condition);
    ck_assert_uint_eq(s.nwarnings, w.nwarnings);
    for (int i = 0; i < 6; i++) {
        ck_assert(fabs(s.leg[i].min_mm - w.leg[i].min_mm) < 1e-6);
        ck_assert(fabs(s.leg[i].max_mm - w.leg[i].max_mm) < 1e-6);
        ck_assert(fabs(s.leg[i].peak_vel_mm_s / w.leg[i].peak_vel_mm_s - 1) < 1e-3);
        ck_assert(fabs(s.leg[i].peak_acc_mm_s2 / w.leg[i].peak_acc_mm_s2 - 1) < 0.02);
        ck_assert(s.leg[i].peak_vel_mm_s <= s.leg[i].limit_vel_mm_s);
        ck_assert(s.leg[i].peak_acc_mm_s2 <= s.leg[i].limit_acc_mm_s2);
    }
    check_result_free(&s);
    check_result_free(&w);
}
END_TEST

/* Peak memory of one check in a child process, kB (the children's largest so far). */
static long child_peak_kb(const char *prog, int whole)
{
    pid_t pid = fork();
    ck_assert(pid >= 0);
    if (pid == 0) {
        struct check_result r;
        _exit(run(prog, whole, &r) == CHECK_OK ? 0 : 1);
    }
    int status;
    ck_assert(waitpid(pid, &status, 0) == pid);
    ck_assert_msg(WIFEXITED(status) && WEXITSTATUS(status) == 0, "the check failed");
    struct rusage ru;
    getrusage(RUSAGE_CHILDREN, &ru);
    return ru.ru_maxrss;
}

/* Memory stays bounded: a long program checked in a fraction of what it takes whole. */
START_TEST(test_stream_bounded_memory)
{
    const char *prog = dense_program(100000, NULL);
    long streamed = child_peak_kb(prog, 0);        /* first: the children's peak so far */
    long whole = child_peak_kb(prog, 1);
    unlink(prog);
    printf("100000 dense blocks: peak memory streamed %ld kB, whole %ld kB\n", streamed, whole);
    ck_assert_msg(streamed * 3 < whole, "streamed %ld kB, whole %ld kB", streamed, whole);
}
END_TEST

/* A fault far into the program, after windows have run: its problem alone, no figures. */
START_TEST(test_stream_late_errors)
{
    struct check_result r;
    const char *prog = dense_program(9000, "G1 X0 Y0 Z1200");   /* far above the reach */
    ck_assert_int_eq(run(prog, 0, &r), CHECK_ERR_VIOLATION);
    ck_assert_uint_eq(r.nproblems, 1);
    ck_assert_int_eq(r.problems[0].kind, CHECK_UNREACHABLE);
    ck_assert_int_eq(r.problems[0].line, 9003);
    ck_assert(!r.simulated);
    check_result_free(&r);
    prog = dense_program(9000, "G1 X0 Y0 Z645 Q#");               /* a syntax error */
    ck_assert_int_eq(run(prog, 0, &r), CHECK_ERR_VIOLATION);
    ck_assert_uint_eq(r.nproblems, 1);
    ck_assert_int_eq(r.problems[0].kind, CHECK_INTERP);
    ck_assert_int_eq(r.problems[0].line, 9003);
    ck_assert(!r.simulated);
    check_result_free(&r);
    unlink(prog);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("check_stream");
    TCase *tc = tcase_create("stream");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_stream_same_figures);
    tcase_add_test(tc, test_stream_bounded_memory);
    tcase_add_test(tc, test_stream_late_errors);
    suite_add_tcase(s, tc);
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
