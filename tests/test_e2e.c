/* test_e2e.c: end to end on the simulated clock: the paper's programs on the simulated TMU
 * hexapod (INI + HAL files -> interpreter -> planner -> stepgens -> forward kinematics). */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "hal/hal.h"
#include "task/runner.h"

/* What the per-period observer checks against, and what it found. */
struct watch {
    struct runner *r;
    double leg_min_mm[KINS_MAX_JOINTS], leg_max_mm[KINS_MAX_JOINTS];
    double max_vel_mm_s[KINS_MAX_JOINTS], max_acc_mm_s2[KINS_MAX_JOINTS];
    double step_mm;                 /* one step of the stepgens (1 / SCALE) */
    double prev_rate[KINS_MAX_JOINTS];
    int have_prev;
    long periods, moving, bad_length, bad_rate, bad_accel, bad_ferror;
    double worst_rate_ratio;        /* max |rate| / limit seen */
    double worst_ferror_mm;
    char first_problem[256];
};

static char tmp_dir[256];

/* Path of the simulated machine's INI in the source tree. */
static const char *sim_ini(void)
{
    static char path[1024];
    const char *root = getenv("HEXCNC_ROOT");
    snprintf(path, sizeof path, "%s/configs/sim/tmu-hexapod.ini", root ? root : ".");
    return path;
}

/* Writes text to a file in the test's temporary folder; returns its path (static per slot). */
static const char *write_file(const char *name, const char *text)
{
    static char paths[8][512];
    static int slot;
    char *p = paths[slot++ % 8];
    snprintf(p, 512, "%s/%s", tmp_dir, name);
    FILE *f = fopen(p, "w");
    ck_assert_ptr_nonnull(f);
    fputs(text, f);
    fclose(f);
    return p;
}

/* The INI lookup motion_config_read() wants, over the runner's HAL runtime. */
static const char *ini_get(void *ctx, const char *section, const char *key)
{
    return hal_ini_get(ctx, section, key);
}

/* Records a problem (the first one verbatim) in the watch. */
static void problem(struct watch *w, long *counter, const char *what, int leg, double v)
{
    if (!w->first_problem[0])
        snprintf(w->first_problem, sizeof w->first_problem, "period %ld leg %d: %s (%g)",
                 w->periods, leg, what, v);
    (*counter)++;
}

/* Every servo period: leg lengths within limits, rates within MAX_VELOCITY, rate changes
 * within MAX_ACCELERATION, following error within one step. */
static void observe(void *ctx, const struct runner_sample *s)
{
    struct watch *w = ctx;
    w->periods++;
    for (int i = 0; i < s->njoints; i++) {
        if (s->joint_rate_mm_s[i] != 0) {
            w->moving++;
            break;
        }
    }
    for (int i = 0; i < s->njoints; i++) {
        double len = s->joint_cmd_mm[i], rate = s->joint_rate_mm_s[i];
        if (len < w->leg_min_mm[i] || len > w->leg_max_mm[i])
            problem(w, &w->bad_length, "leg length out of range", i, len);
        w->worst_rate_ratio = fmax(w->worst_rate_ratio, fabs(rate) / w->max_vel_mm_s[i]);
        if (fabs(rate) > w->max_vel_mm_s[i] * (1.0 + 1e-6))
            problem(w, &w->bad_rate, "leg rate above MAX_VELOCITY", i, rate);
        if (w->have_prev && fabs(rate - w->prev_rate[i]) * 1000.0 > w->max_acc_mm_s2[i] * 1.01)
            problem(w, &w->bad_accel, "leg acceleration above MAX_ACCELERATION", i,
                    (rate - w->prev_rate[i]) * 1000.0);
        w->prev_rate[i] = rate;
        double fe = fabs(s->joint_cmd_mm[i] - s->joint_fb_mm[i]);
        w->worst_ferror_mm = fmax(w->worst_ferror_mm, fe);
        if (fe > w->step_mm * (0.5 + 1e-6))
            problem(w, &w->bad_ferror, "following error above half a step", i, fe);
    }
    w->have_prev = 1;
}

/* The paper's machine for path 1 (F in m/min, as the paper's programs and these tests write
 * it; the head tilted at B-4), on the HAL files of configs/sim. */
static const char *paper_ini(void)
{
    static char path[1024];
    const char *root = getenv("HEXCNC_ROOT");
    snprintf(path, sizeof path, "%s/examples/paper/experiment/tmu-path1.ini", root ? root : ".");
    return path;
}

/* A runner on the simulated machine with the observer set up from its configuration. */
static struct runner *make_runner(struct watch *w)
{
    struct runner_opts o = { paper_ini(), RUNNER_CLOCK_SIM };
    struct runner *r;
    char err[1024];
    int st = runner_create(&o, &r, err, sizeof err);
    ck_assert_msg(st == RUNNER_OK, "runner_create: %s", err);
    memset(w, 0, sizeof *w);
    w->r = r;
    struct kins *k = runner_kins(r);
    struct motion_config mc;
    motion_config_default(&mc);
    struct kins_config kc = { ini_get, runner_hal(r) };
    ck_assert_int_eq(motion_config_read(&mc, &kc, k->njoints, err, sizeof err), MOTION_OK);
    for (int i = 0; i < k->njoints; i++) {
        w->leg_min_mm[i] = k->joint_min[i];
        w->leg_max_mm[i] = k->joint_max[i];
        w->max_vel_mm_s[i] = mc.joint[i].max_vel_mm_s;
        w->max_acc_mm_s2[i] = mc.joint[i].max_acc_mm_s2;
    }
    double scale = 0.0;
    ck_assert_int_eq(hal_ini_double(runner_hal(r), "JOINT_0", "SCALE", 0.0, &scale), HAL_OK);
    w->step_mm = 1.0 / scale;
    runner_set_observer(r, observe, w);
    return r;
}

/* Loads, runs to the end and checks the run against the plan and the limits. */
static void run_program(struct watch *w, const char *path, struct runner_summary *s)
{
    char err[1024];
    int st = runner_load_program(w->r, path, err, sizeof err);
    ck_assert_msg(st == RUNNER_OK, "load %s: %s", path, err);
    ck_assert_int_eq(runner_start(w->r, err, sizeof err), RUNNER_OK);
    w->have_prev = 0;
    st = runner_run(w->r, NULL, NULL, NULL, err, sizeof err);
    ck_assert_msg(st == RUNNER_OK, "run %s: %s", path, err);
    runner_summary(w->r, s);
    ck_assert_msg(!w->bad_length && !w->bad_rate && !w->bad_accel && !w->bad_ferror,
                  "%s: %ld length, %ld rate, %ld accel, %ld ferror problems; first: %s", path,
                  w->bad_length, w->bad_rate, w->bad_accel, w->bad_ferror, w->first_problem);
    ck_assert_int_eq(s->state, MOTION_DONE);
    ck_assert_int_ge(w->periods, (long)(s->planned_time_s * 1000.0));
    ck_assert_msg(fabs(s->machine_time_s - s->planned_time_s) <= 0.003,
                  "ran %.4f s, planned %.4f s", s->machine_time_s, s->planned_time_s);
}

/* The final pose is `want` (to the stepgens' quantisation) and the legs are its inverse. */
static void check_final(struct watch *w, const struct runner_summary *s, const double *want)
{
    double legs[KINS_MAX_JOINTS];
    struct kins *k = runner_kins(w->r);
    ck_assert_int_eq(kins_inverse(k, want, legs), KINS_OK);
    for (int i = 0; i < k->njoints; i++)
        ck_assert_msg(fabs(s->final_legs_mm[i] - legs[i]) <= w->step_mm * 0.5 + 1e-9,
                      "leg %d: %.6f, inverse of the end point %.6f", i, s->final_legs_mm[i],
                      legs[i]);
    ck_assert(s->final_pose_ok);
    for (int j = 0; j < KINS_POSE_DIM; j++)
        ck_assert_msg(fabs(s->final_pose[j] - want[j]) <= 0.005, "pose[%d] %.6f, want %.6f",
                      j, s->final_pose[j], want[j]);
}

/* A program of examples/paper/ in the source tree. */
static const char *paper(const char *name)
{
    static char paths[4][1024];
    static int slot;
    char *p = paths[slot++ % 4];
    const char *root = getenv("HEXCNC_ROOT");
    snprintf(p, 1024, "%s/examples/paper/%s", root ? root : ".", name);
    return p;
}

/* Program (10) with the 20 mm tool, then program (11) with the 10 mm tool, G141, on one
 * machine: the compensated end points of paper.md's table. */
START_TEST(test_paper_g141_both_tools)
{
    struct watch w;
    struct runner_summary s;
    struct runner *r = make_runner(&w);
    run_program(&w, paper("prog10_g141_d20.ngc"), &s);
    const double end10[6] = { 59.975641, -20, 630.697565, 0, -4, 0 };
    check_final(&w, &s, end10);
    ck_assert(s.distance_mm > 60.0);
    run_program(&w, paper("prog11_g141_d10.ngc"), &s);
    const double end11[6] = { 54.987820, 20, 630.348782, 0, -4, 0 };
    check_final(&w, &s, end11);
    runner_destroy(r);
}
END_TEST

/* The same path compensated on the left (G142), both tools. */
START_TEST(test_paper_g142_both_tools)
{
    struct watch w;
    struct runner_summary s;
    struct runner *r = make_runner(&w);
    run_program(&w, paper("prog10_g142_d20.ngc"), &s);
    const double end10[6] = { 40.024359, -20, 629.302435, 0, -4, 0 };
    check_final(&w, &s, end10);
    run_program(&w, paper("prog11_g142_d10.ngc"), &s);
    const double end11[6] = { 45.012180, 20, 629.651218, 0, -4, 0 };
    check_final(&w, &s, end11);
    runner_destroy(r);
}
END_TEST

/* Path 1 with both tools in one program, radii from the machine's tool table (D3, D1). */
START_TEST(test_paper_tool_table)
{
    struct watch w;
    struct runner_summary s;
    struct runner *r = make_runner(&w);
    run_program(&w, paper("path1_tooltable.ngc"), &s);
    const double end[6] = { 54.987820, 20, 630.348782, 0, -4, 0 };
    check_final(&w, &s, end);
    runner_destroy(r);
}
END_TEST

/* Path 2 of the experiment (B-8) with the 20 mm tool. */
START_TEST(test_paper_path2)
{
    struct watch w;
    struct runner_summary s;
    struct runner *r = make_runner(&w);
    run_program(&w, paper("path2_g141_d20.ngc"), &s);
    const double end[6] = { 39.902681, 50, 659.391731, 0, -8, 0 };
    check_final(&w, &s, end);
    runner_destroy(r);
}
END_TEST

/* A point out of reach is refused before any motion, naming its line. */
START_TEST(test_unreachable_refused)
{
    struct watch w;
    struct runner *r = make_runner(&w);
    char err[1024];
    const char *p = write_file("far.ngc", "G1 X0 Y0 Z645 F2\nG1 X10\nG1 X600\nM2\n");
    int st = runner_load_program(r, p, err, sizeof err);
    ck_assert_int_eq(st, RUNNER_ERR_PLAN);
    ck_assert_msg(strstr(err, ":3") != NULL, "message does not name line 3: %s", err);
    ck_assert_int_eq(runner_start(r, err, sizeof err), RUNNER_ERR_STATE);
    /* the threads ran a few periods with the machine off, to plan from where the legs are;
     * nothing moved */
    ck_assert_int_le(w.periods, 10);
    ck_assert_int_eq(w.moving, 0);
    runner_destroy(r);
}
END_TEST

/* A malformed program gives the interpreter's file:line message and no motion. */
START_TEST(test_malformed_refused)
{
    struct watch w;
    struct runner *r = make_runner(&w);
    char err[1024];
    const char *p = write_file("bad.ngc", "G1 X10 Y0 Z640 F2\nG1 X1 Y=\nM2\n");
    ck_assert_int_eq(runner_load_program(r, p, err, sizeof err), RUNNER_ERR_PROGRAM);
    ck_assert_msg(strstr(err, "bad.ngc:2") != NULL, "no file:line in: %s", err);
    ck_assert_int_eq(runner_start(r, err, sizeof err), RUNNER_ERR_STATE);
    runner_destroy(r);
}
END_TEST

/* An error in a HAL file names the file and the line. */
START_TEST(test_hal_error_named)
{
    FILE *f = fopen(sim_ini(), "r");
    ck_assert_ptr_nonnull(f);
    static char text[65536];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = 0;
    const char *bad = write_file("broken.hal", "# a wiring mistake on line 3\n"
                                 "loadrt stepgen count=6\nnet leg-0-cmd nosuch.pin\n");
    char *at = strstr(text, "HALFILE = tmu-hexapod.hal");
    ck_assert_ptr_nonnull(at);
    static char ini[70000];
    snprintf(ini, sizeof ini, "%.*sHALFILE = %s%s", (int)(at - text), text, bad,
             at + strlen("HALFILE = tmu-hexapod.hal"));
    struct runner_opts o = { write_file("broken.ini", ini), RUNNER_CLOCK_SIM };
    struct runner *r;
    char err[1024];
    ck_assert_int_eq(runner_create(&o, &r, err, sizeof err), RUNNER_ERR_HAL);
    ck_assert_msg(strstr(err, "broken.hal") && strstr(err, "3"), "message: %s", err);
}
END_TEST

/* Ctrl-C's path: the abort decelerates along the path within the limits and stops on it. */
START_TEST(test_abort_controlled)
{
    struct watch w;
    struct runner *r = make_runner(&w);
    char err[1024];
    const char *p = write_file("long.ngc", "G1 X0 Y0 Z645 F2\nG1 X100 Y0 Z645\nM2\n");
    ck_assert_int_eq(runner_load_program(r, p, err, sizeof err), RUNNER_OK);
    ck_assert_int_eq(runner_start(r, err, sizeof err), RUNNER_OK);
    ck_assert_int_eq(runner_advance(r, 1.0), RUNNER_OK);
    ck_assert(!runner_finished(r));
    volatile sig_atomic_t stop = 1;
    ck_assert_int_eq(runner_run(r, &stop, NULL, NULL, err, sizeof err), RUNNER_ERR_ABORTED);
    struct runner_summary s;
    runner_summary(r, &s);
    ck_assert_int_eq(s.state, MOTION_IDLE);
    ck_assert_msg(!w.bad_length && !w.bad_rate && !w.bad_accel && !w.bad_ferror, "%s",
                  w.first_problem);
    ck_assert(s.final_pose_ok);
    ck_assert(s.final_pose[0] > 1.0 && s.final_pose[0] < 99.0);
    ck_assert(fabs(s.final_pose[1]) < 0.005 && fabs(s.final_pose[2] - 645.0) < 0.005);
    ck_assert(s.machine_time_s < s.planned_time_s);
    runner_destroy(r);
}
END_TEST

/* A leg that cannot keep up (its stepgen limited to 5 mm/s) trips the following-error
 * check: the run ends in a fault that names the leg, the amount and the program line. */
START_TEST(test_following_error_fault)
{
    struct watch w;
    struct runner *r = make_runner(&w);
    char err[1024];
    ck_assert_int_eq(runner_load_program(r, paper("prog10_g141_d20.ngc"), err, sizeof err),
                     RUNNER_OK);
    ck_assert_int_eq(hal_setp(runner_hal(r), "stepgen.3.maxvel", "5"), HAL_OK);
    ck_assert_int_eq(runner_start(r, err, sizeof err), RUNNER_OK);
    ck_assert_int_eq(runner_run(r, NULL, NULL, NULL, err, sizeof err), RUNNER_ERR_FAULT);
    ck_assert_msg(strstr(err, "following error") && strstr(err, "[JOINT_3]") &&
                  strstr(err, "prog10_g141_d20.ngc:"), "message: %s", err);
    struct runner_summary s;
    runner_summary(r, &s);
    ck_assert_int_eq(s.state, MOTION_FAULT);
    ck_assert(s.machine_time_s < s.planned_time_s);
    runner_destroy(r);
}
END_TEST

/* The e-stop chain: a fault on the latch stops motion and the stepgens at once. */
START_TEST(test_estop_fault)
{
    struct watch w;
    struct runner *r = make_runner(&w);
    char err[1024];
    ck_assert_int_eq(runner_load_program(r, paper("prog10_g141_d20.ngc"), err, sizeof err),
                     RUNNER_OK);
    ck_assert_int_eq(runner_start(r, err, sizeof err), RUNNER_OK);
    ck_assert_int_eq(runner_advance(r, 1.0), RUNNER_OK);
    ck_assert_int_eq(hal_setp(runner_hal(r), "estop-latch.0.fault-in", "1"), HAL_OK);
    ck_assert_int_eq(runner_run(r, NULL, NULL, NULL, err, sizeof err), RUNNER_ERR_FAULT);
    ck_assert_msg(strstr(err, "emergency stop") != NULL, "message: %s", err);
    struct runner_summary a, b;
    runner_summary(r, &a);
    ck_assert_int_eq(runner_advance(r, 0.5), RUNNER_OK);
    runner_summary(r, &b);
    for (int i = 0; i < a.njoints; i++)
        ck_assert(a.final_legs_mm[i] == b.final_legs_mm[i]);  /* the legs stand still */
    runner_destroy(r);
}
END_TEST

/* The suite: the paper's programs, refusals before motion, stop and faults. */
static Suite *e2e_suite(void)
{
    Suite *s = suite_create("e2e");
    TCase *tc = tcase_create("sim");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_paper_g141_both_tools);
    tcase_add_test(tc, test_paper_g142_both_tools);
    tcase_add_test(tc, test_paper_tool_table);
    tcase_add_test(tc, test_paper_path2);
    tcase_add_test(tc, test_unreachable_refused);
    tcase_add_test(tc, test_malformed_refused);
    tcase_add_test(tc, test_hal_error_named);
    tcase_add_test(tc, test_abort_controlled);
    tcase_add_test(tc, test_following_error_fault);
    tcase_add_test(tc, test_estop_fault);
    suite_add_tcase(s, tc);
    return s;
}

/* Runs the suite in a fresh temporary folder for its programs. */
int main(void)
{
    snprintf(tmp_dir, sizeof tmp_dir, "/tmp/hexcnc-e2e-XXXXXX");
    if (!mkdtemp(tmp_dir))
        return EXIT_FAILURE;
    SRunner *sr = srunner_create(e2e_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
