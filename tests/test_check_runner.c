/* test_check_runner.c: hexcnc check and hexcnc run (HAL graph, stepgens) agree on the same program. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check/check.h"
#include "task/runner.h"
#include "tests/test_check_util.h"

/* The check on the library path, the run on the machine's HAL graph: the same motion, so the
 * same machining time, leg ranges and peak leg rates. */
static void compare(const char *ini_rel, const char *prog_rel)
{
    char ini[1024], prog[1024], err[1024];
    if (ini_rel[0] == '/')   /* absolute paths are taken as they are */
        snprintf(ini, sizeof ini, "%s", ini_rel);
    else
        tc_path(ini_rel, ini, sizeof ini);
    if (prog_rel[0] == '/')
        snprintf(prog, sizeof prog, "%s", prog_rel);
    else
        tc_path(prog_rel, prog, sizeof prog);
    struct check_machine *mc;
    struct check_result c;
    ck_assert_msg(check_machine_open(ini, &mc, err, sizeof err) == 0, "%s", err);
    check_result_init(&c);
    ck_assert_int_eq(check_program(mc, prog, NULL, &c), CHECK_OK);
    check_machine_close(mc);

    struct runner_opts o = { ini, RUNNER_CLOCK_SIM };
    struct runner *r;
    struct runner_summary s;
    ck_assert_msg(runner_create(&o, &r, err, sizeof err) == RUNNER_OK, "%s", err);
    ck_assert_msg(runner_load_program(r, prog, err, sizeof err) == RUNNER_OK, "%s", err);
    ck_assert_msg(runner_start(r, err, sizeof err) == RUNNER_OK, "%s", err);
    ck_assert_msg(runner_run(r, NULL, NULL, NULL, err, sizeof err) == RUNNER_OK, "%s", err);
    runner_summary(r, &s);
    runner_destroy(r);

    ck_assert_msg(fabs(s.machine_time_s - c.machining_time_s) <= 2 * c.servo_period_s,
                  "run %.4f s, check %.4f s", s.machine_time_s, c.machining_time_s);
    ck_assert(fabs(s.planned_time_s - c.planned_time_s) < 1e-9);
    for (int i = 0; i < 6; i++) {
        /* the run's rates are motion's commanded (Jacobian) rates, the check's come from
         * successive set points: equal to within the change of rate over one period */
        ck_assert_msg(fabs(s.peak_rate_mm_s[i] - c.leg[i].peak_vel_mm_s) < 0.01 *
                      c.leg[i].peak_vel_mm_s, "leg %d: run %.4f, check %.4f", i + 1,
                      s.peak_rate_mm_s[i], c.leg[i].peak_vel_mm_s);
        ck_assert(fabs(s.leg_min_mm[i] - c.leg[i].min_mm) < 1e-6);
        ck_assert(fabs(s.leg_max_mm[i] - c.leg[i].max_mm) < 1e-6);
    }
    check_result_free(&c);
}

START_TEST(test_check_agrees_with_run)
{
    compare("examples/paper/experiment/tmu-path1.ini", "examples/paper/path1_tooltable.ngc");
    compare("examples/paper/experiment/tmu-path2.ini", "examples/paper/experiment/run4_g141.ngc");
}
END_TEST

/* Writes text to dir/name; out receives the path. */
static void put_file(const char *dir, const char *name, const char *text, char *out, size_t len)
{
    snprintf(out, len, "%s/%s", dir, name);
    FILE *f = fopen(out, "w");
    ck_assert_ptr_nonnull(f);
    fputs(text, f);
    fclose(f);
}

/* Copies the simulated TMU's INI into dir with its files made absolute (they stay in
 * configs/sim), adding [RS274NGC] PARAMETER_FILE = params.var (relative: beside the copy). */
static void copy_ini_with_params(const char *dir, char *ini, size_t len)
{
    char src[1024], simdir[1024], line[1024];
    tc_path("configs/sim/tmu-hexapod.ini", src, sizeof src);
    tc_path("configs/sim", simdir, sizeof simdir);
    FILE *in = fopen(src, "r");
    ck_assert_ptr_nonnull(in);
    snprintf(ini, len, "%s/machine.ini", dir);
    FILE *out = fopen(ini, "w");
    ck_assert_ptr_nonnull(out);
    while (fgets(line, sizeof line, in)) {
        char key[64], value[512];
        if (sscanf(line, " %63[A-Z_] = %511s", key, value) == 2 &&
            (!strcmp(key, "HALFILE") || !strcmp(key, "TOOL_TABLE")))
            fprintf(out, "%s = %s/%s\n", key, simdir, value);
        else if (strncmp(line, "OPEN_FILE", 9) != 0)
            fputs(line, out);
        if (!strncmp(line, "[RS274NGC]", 10))
            fputs("PARAMETER_FILE = params.var\n", out);
    }
    fclose(in);
    fclose(out);
}

/* A G54 work offset stored in the parameter file moves the check's path exactly as it moves
 * the run's: the check reads [RS274NGC] PARAMETER_FILE as the runner does, never writing it. */
START_TEST(test_check_uses_the_parameter_file)
{
    char dir[] = "/tmp/hexcnc-params-XXXXXX", ini[1024], params[1024], prog[1024], err[1024];
    ck_assert_ptr_nonnull(mkdtemp(dir));
    copy_ini_with_params(dir, ini, sizeof ini);
    /* G54 (parameters 5221..5223): X +40, Y -30, Z -12 mm */
    const char *param_text = "5220\t1.000000\n5221\t40.000000\n5222\t-30.000000\n"
                             "5223\t-12.000000\n";
    put_file(dir, "params.var", param_text, params, sizeof params);
    put_file(dir, "g54.ngc", "G21 G90 G54\nG1 X10 Y5 Z640 A0 B0 C0 F1000\nG1 X-10 Y-5 Z635\n"
             "M2\n", prog, sizeof prog);

    struct check_machine *mc;
    ck_assert_msg(check_machine_open(ini, &mc, err, sizeof err) == 0, "%s", err);
    struct canon_prog cp;
    struct check_problem pb;
    canon_prog_init(&cp);
    ck_assert_msg(check_machine_interpret(mc, prog, &cp, &pb) == CHECK_OK, "%s", pb.message);
    const struct canon_cmd *first = NULL;
    for (size_t i = 0; i < cp.count && !first; i++)
        if (cp.cmds[i].type == CANON_FEED)
            first = &cp.cmds[i];
    ck_assert_ptr_nonnull(first);
    ck_assert_double_eq_tol(first->end[0], 50.0, 1e-9);   /* 10 + 40 */
    ck_assert_double_eq_tol(first->end[1], -25.0, 1e-9);  /* 5 - 30 */
    ck_assert_double_eq_tol(first->end[2], 628.0, 1e-9);  /* 640 - 12 */
    canon_prog_free(&cp);
    check_machine_close(mc);

    compare(ini, prog);   /* the same leg ranges, time and rates as the run */

    char names[3][1024];
    snprintf(names[0], sizeof names[0], "%s", prog);
    snprintf(names[1], sizeof names[1], "%s", params);
    snprintf(names[2], sizeof names[2], "%s", ini);
    for (int i = 0; i < 3; i++)
        unlink(names[i]);
    rmdir(dir);
}
END_TEST

/* The test case. */
static Suite *suite(void)
{
    Suite *s = suite_create("check_runner");
    TCase *tc = tcase_create("check_runner");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_check_agrees_with_run);
    tcase_add_test(tc, test_check_uses_the_parameter_file);
    suite_add_tcase(s, tc);
    return s;
}

/* Runs the suite; non-zero when a test failed. */
int main(void)
{
    SRunner *sr = srunner_create(suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
