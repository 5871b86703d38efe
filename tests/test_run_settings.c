/* test_run_settings.c: settings a program writes (G10 L1 tool entries, G10 L2 work offsets,
 * i.e. the tool table and the parameter file) are saved when the simulated machine executes
 * their line: a refused program saves nothing, an aborted or faulted run saves the lines
 * it executed and no later one, a full run saves all; an unwritable parameter file refuses
 * only the programs that would need it. */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "hal/hal.h"
#include "task/runner.h"

/* A machine (the simulated TMU hexapod) whose tool table and parameter file live in a
 * temporary folder. */
struct machine {
    char dir[64];
    char ini[128], tbl[128], var[128], prog[128];
};

/* The whole of a small file (at most 16 KiB), for byte-for-byte comparisons. */
static char *slurp(const char *path)
{
    static char buf[2][16384];
    static int slot;
    char *b = buf[slot++ % 2];
    FILE *f = fopen(path, "r");
    ck_assert_msg(f != NULL, "cannot open %s", path);
    size_t n = fread(b, 1, sizeof buf[0] - 1, f);
    b[n] = '\0';
    fclose(f);
    return b;
}

static void spit(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    ck_assert_ptr_nonnull(f);
    fputs(text, f);
    fclose(f);
}

/* The sim INI with absolute HAL files, TOOL_TABLE in dir and PARAMETER_FILE = var_path. */
static void machine_init(struct machine *m, const char *var_path)
{
    const char *root = getenv("HEXCNC_ROOT") ? getenv("HEXCNC_ROOT") : ".";
    snprintf(m->dir, sizeof m->dir, "/tmp/hexcnc-settings-XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(m->dir));
    snprintf(m->ini, sizeof m->ini, "%s/m.ini", m->dir);
    snprintf(m->tbl, sizeof m->tbl, "%s/tool.tbl", m->dir);
    snprintf(m->prog, sizeof m->prog, "%s/p.ngc", m->dir);
    snprintf(m->var, sizeof m->var, "%s", var_path ? var_path : "");
    if (!var_path)
        snprintf(m->var, sizeof m->var, "%s/hexcnc.var", m->dir);
    char src[1024], line[1024];
    snprintf(src, sizeof src, "%s/configs/sim/tmu-hexapod.ini", root);
    FILE *in = fopen(src, "r"), *out = fopen(m->ini, "w");
    ck_assert(in && out);
    while (fgets(line, sizeof line, in)) {
        if (strncmp(line, "HALFILE = ", 10) == 0)
            fprintf(out, "HALFILE = %s/configs/sim/%s", root, line + 10);
        else if (strncmp(line, "TOOL_TABLE = ", 13) == 0)
            fprintf(out, "TOOL_TABLE = %s\nPARAMETER_FILE = %s\n", m->tbl, m->var);
        else
            fputs(line, out);
    }
    fclose(in);
    fclose(out);
    spit(m->tbl, "T1 P1 D10 ;ten\nT2 P2 D12 ;twelve\n");
    if (!var_path)
        spit(m->var, "5221\t0.000000\n5222\t0.000000\n");
}

static void machine_free(struct machine *m)
{
    unlink(m->ini);
    unlink(m->tbl);
    unlink(m->prog);
    if (strncmp(m->var, m->dir, strlen(m->dir)) == 0)
        unlink(m->var);
    rmdir(m->dir);
}

/* Parameter n as the parameter file has it (-999 when absent). */
static double saved_param(const struct machine *m, int n)
{
    FILE *f = fopen(m->var, "r");
    ck_assert_ptr_nonnull(f);
    int k;
    double v, found = -999;
    while (fscanf(f, "%d %lf", &k, &v) == 2)
        if (k == n)
            found = v;
    fclose(f);
    return found;
}

/* G10 L2 and G10 L1 early (lines 3, 4), a few moves, G10 L2 and L1 late (lines 10, 11). At
 * F2 m/min each 20 mm move takes about 0.6 s. */
static const char two_settings[] =
    "G21 G90\n"
    "G0 X0 Y0 Z645\n"
    "G10 L2 P1 X0.5 (early)\n"
    "G10 L1 P1 R6 (early: T1 D12)\n"
    "G1 X20 F2\n"
    "G1 X0\n"
    "G1 X20\n"
    "G1 X0\n"
    "G1 X20\n"
    "G10 L2 P1 Y0.25 (late)\n"
    "G10 L1 P2 R7 (late: T2 D14)\n"
    "G1 X0\n"
    "M2\n";

/* What the progress callback does at a program line: abort, or fault the machine. */
struct stop_at {
    struct runner *r;
    int line;                /* first line at which to act */
    int fault;               /* 1: e-stop fault, 0: the operator's abort */
    int done;
    char tbl_then[16384];    /* the tool table when it acted */
};

static void stop_when_there(void *ctx, const struct runner_progress *p)
{
    struct stop_at *s = ctx;
    if (s->done || p->line < s->line)
        return;
    s->done = 1;
    if (s->fault)
        ck_assert_int_eq(hal_setp(runner_hal(s->r), "estop-latch.0.fault-in", "1"), HAL_OK);
    else
        ck_assert_int_eq(runner_abort(s->r), RUNNER_OK);
}

static struct runner *machine_runner(const struct machine *m)
{
    struct runner_opts o = { m->ini, RUNNER_CLOCK_SIM };
    struct runner *r;
    char err[1024];
    ck_assert_msg(runner_create(&o, &r, err, sizeof err) == RUNNER_OK, "%s", err);
    return r;
}

/* Loads and runs prog (stopping at stop->line when stop is given); returns runner_run's
 * status. Loading alone must leave both files as they were. */
static int run(const struct machine *m, const char *prog, struct stop_at *stop)
{
    char err[1024], var0[16384], tbl0[16384];
    spit(m->prog, prog);
    snprintf(var0, sizeof var0, "%s", slurp(m->var));
    snprintf(tbl0, sizeof tbl0, "%s", slurp(m->tbl));
    struct runner *r = machine_runner(m);
    ck_assert_msg(runner_load_program(r, m->prog, err, sizeof err) == RUNNER_OK, "%s", err);
    ck_assert_str_eq(slurp(m->var), var0);
    ck_assert_str_eq(slurp(m->tbl), tbl0);
    ck_assert_msg(runner_start(r, err, sizeof err) == RUNNER_OK, "%s", err);
    if (stop)
        stop->r = r;
    int st = runner_run(r, NULL, stop ? stop_when_there : NULL, stop, err, sizeof err);
    runner_destroy(r);
    return st;
}

/* A full run saves the early and the late settings. */
START_TEST(full_run_saves_all)
{
    struct machine m;
    machine_init(&m, NULL);
    ck_assert_int_eq(run(&m, two_settings, NULL), RUNNER_OK);
    ck_assert_double_eq(saved_param(&m, 5221), 0.5);
    ck_assert_double_eq(saved_param(&m, 5222), 0.25);
    const char *t = slurp(m.tbl);
    ck_assert_msg(strstr(t, "T1 P1 D12 ;ten\n") && strstr(t, "T2 P2 D14 ;twelve\n"), "%s", t);
    machine_free(&m);
}
END_TEST

/* Stopped at line 6 (Ctrl-C's controlled stop, or an e-stop fault): lines 3 and 4 are saved,
 * lines 10 and 11 are not. */
static void stopped_run(int fault)
{
    struct machine m;
    machine_init(&m, NULL);
    struct stop_at s = { .line = 6, .fault = fault };
    int st = run(&m, two_settings, &s);
    ck_assert_int_eq(s.done, 1);
    ck_assert_int_eq(st, fault ? RUNNER_ERR_FAULT : RUNNER_ERR_ABORTED);
    ck_assert_double_eq(saved_param(&m, 5221), 0.5);
    ck_assert_double_eq(saved_param(&m, 5222), 0);
    const char *t = slurp(m.tbl);
    ck_assert_msg(strstr(t, "T1 P1 D12 ;ten\n") && strstr(t, "T2 P2 D12 ;twelve\n"), "%s", t);
    machine_free(&m);
}

START_TEST(aborted_run_saves_executed_lines_only)
{
    stopped_run(0);
}
END_TEST

START_TEST(faulted_run_saves_executed_lines_only)
{
    stopped_run(1);
}
END_TEST

/* A program refused at load (a point out of reach after its G10s) saves nothing. */
START_TEST(refused_program_saves_nothing)
{
    struct machine m;
    machine_init(&m, NULL);
    char var0[16384], tbl0[16384], err[1024];
    snprintf(var0, sizeof var0, "%s", slurp(m.var));
    snprintf(tbl0, sizeof tbl0, "%s", slurp(m.tbl));
    spit(m.prog, "G0 X0 Y0 Z645\nG10 L2 P1 X0.5\nG10 L1 P1 R6\nG1 X600 F2\nM2\n");
    struct runner *r = machine_runner(&m);
    ck_assert_int_eq(runner_load_program(r, m.prog, err, sizeof err), RUNNER_ERR_PLAN);
    runner_destroy(r);
    ck_assert_str_eq(slurp(m.var), var0);
    ck_assert_str_eq(slurp(m.tbl), tbl0);
    machine_free(&m);
}
END_TEST

/* The parameter file cannot be written (its folder does not exist): a program that changes
 * no persistent parameter runs; one that does is refused at load, naming file and line. */
START_TEST(unwritable_param_file)
{
    struct machine m;
    machine_init(&m, "/nonexistent-hexcnc-dir/hexcnc.var");
    char err[1024];
    spit(m.prog, "G0 X0 Y0 Z645\nG1 X10 F2\nG10 L1 P1 R6\nG1 X0\nM2\n");
    struct runner *r = machine_runner(&m);
    ck_assert_msg(runner_load_program(r, m.prog, err, sizeof err) == RUNNER_OK, "%s", err);
    ck_assert_msg(runner_start(r, err, sizeof err) == RUNNER_OK, "%s", err);
    ck_assert_msg(runner_run(r, NULL, NULL, NULL, err, sizeof err) == RUNNER_OK, "%s", err);
    ck_assert(strstr(slurp(m.tbl), "T1 P1 D12 ;ten\n") != NULL); /* the tool table is fine */
    spit(m.prog, "G0 X0 Y0 Z645\nG1 X10 F2\nG10 L2 P1 X0.5\nG1 X0\nM2\n");
    ck_assert_int_eq(runner_load_program(r, m.prog, err, sizeof err), RUNNER_ERR_CONFIG);
    ck_assert_msg(strstr(err, "p.ngc:3:") && strstr(err, "/nonexistent-hexcnc-dir/hexcnc.var"),
                  "%s", err);
    runner_destroy(r);
    machine_free(&m);
}
END_TEST

/* (LOGOPEN,) is written when its line executes, like a setting: into a folder that does
 * not exist, the program is refused at load naming the line; loading writes nothing, the
 * run writes its lines, relative paths from the program's folder. */
START_TEST(log_file_as_lines_execute)
{
    struct machine m;
    machine_init(&m, NULL);
    char err[1024], log[160];
    spit(m.prog, "G0 X0 Y0 Z645\n(LOGOPEN,/nonexistent-hexcnc-dir/p.log)\nG1 X10 F2\nM2\n");
    struct runner *r = machine_runner(&m);
    ck_assert_int_eq(runner_load_program(r, m.prog, err, sizeof err), RUNNER_ERR_CONFIG);
    ck_assert_msg(strstr(err, "p.ngc:2:") && strstr(err, "opens a log file") &&
                  strstr(err, "/nonexistent-hexcnc-dir"), "%s", err);
    snprintf(log, sizeof log, "%s/p.log", m.dir);
    spit(m.prog, "G0 X0 Y0 Z645\n#1=7\n(LOGOPEN,p.log)\n(LOG,one #1)\nG1 X10 F2\n"
                 "(LOG,two)\nM2\n");
    ck_assert_msg(runner_load_program(r, m.prog, err, sizeof err) == RUNNER_OK, "%s", err);
    ck_assert(access(log, F_OK) != 0);                  /* loading writes nothing */
    ck_assert_msg(runner_start(r, err, sizeof err) == RUNNER_OK, "%s", err);
    ck_assert_msg(runner_run(r, NULL, NULL, NULL, err, sizeof err) == RUNNER_OK, "%s", err);
    ck_assert_str_eq(slurp(log), "one 7.000000\ntwo\n");
    runner_destroy(r);
    unlink(log);
    machine_free(&m);
}
END_TEST

static Suite *run_settings_suite(void)
{
    Suite *s = suite_create("run_settings");
    TCase *tc = tcase_create("save");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, full_run_saves_all);
    tcase_add_test(tc, aborted_run_saves_executed_lines_only);
    tcase_add_test(tc, faulted_run_saves_executed_lines_only);
    tcase_add_test(tc, refused_program_saves_nothing);
    tcase_add_test(tc, unwritable_param_file);
    tcase_add_test(tc, log_file_as_lines_execute);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(run_settings_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
