/* test_check.c: hexcnc check on good and faulty programs: problems, lines, figures, JSON, plots, exit status. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "check/check.h"
#include "check/plot.h"
#include "tests/test_check_util.h"

#define TMU_INI "configs/sim/tmu-hexapod.ini"
/* The paper's programs run on the paper's machine: F in m/min, the head tilted at B-4. */
#define PAPER_INI "examples/paper/experiment/tmu-path1.ini"
#define PAPER_PROG "examples/paper/prog10_g141_d20.ngc"

/* Runs the check of program on ini; returns the status, res filled (caller frees). */
static int run(const char *ini, const char *prog, const struct check_opts *o,
               struct check_result *res)
{
    char ip[1024], pp[1024], err[1024];
    struct check_machine *mc;
    ck_assert_msg(check_machine_open(tc_path(ini, ip, sizeof ip), &mc, err, sizeof err) == 0,
                  "%s", err);
    check_result_init(res);
    int st = check_program(mc, tc_path(prog, pp, sizeof pp), o, res);
    check_machine_close(mc);
    return st;
}

/* The one problem of a kind (fails when there is none). */
static const struct check_problem *find(const struct check_result *r, enum check_kind k)
{
    for (size_t i = 0; i < r->nproblems; i++)
        if (r->problems[i].kind == k)
            return &r->problems[i];
    ck_abort_msg("no problem of kind %s", check_kind_name(k));
    return NULL;
}

START_TEST(test_good_program)
{
    struct check_result r;
    ck_assert_int_eq(run(PAPER_INI, PAPER_PROG, NULL, &r), CHECK_OK);
    ck_assert_uint_eq(r.nproblems, 0);
    ck_assert(r.simulated);
    ck_assert_int_eq(r.njoints, 6);
    /* home to the start (~100 mm) and the 60 mm cut at 2 m/min: a few seconds */
    ck_assert(r.machining_time_s > 3 && r.machining_time_s < 10);
    ck_assert(fabs(r.machining_time_s - r.planned_time_s) < 0.01);
    ck_assert(fabs(r.periods * r.servo_period_s - r.machining_time_s) < 1e-6);
    for (int i = 0; i < 6; i++) {
        const struct check_leg *l = &r.leg[i];
        ck_assert(l->min_mm >= l->limit_min_mm && l->max_mm <= l->limit_max_mm);
        ck_assert(l->min_mm < l->max_mm);
        ck_assert(l->peak_vel_mm_s > 1 && l->peak_vel_mm_s <= l->limit_vel_mm_s);
        ck_assert(l->peak_acc_mm_s2 > 1 && l->peak_acc_mm_s2 <= l->limit_acc_mm_s2);
    }
    ck_assert(r.max_deviation_mm >= 0 && r.max_deviation_mm <= r.kin_tol_mm);
    ck_assert(r.max_condition > 2 && r.max_condition < r.condition_limit);
    ck_assert(r.deviation_evals > 50 && r.condition_evals > 5);
    check_result_free(&r);
}
END_TEST

START_TEST(test_planner_keeps_tight_leg_limit)
{
    struct check_result r;   /* MAX_VELOCITY 5 mm/s: the planner slows, the check agrees */
    ck_assert_int_eq(run("tests/check/tmu-slow-legs.ini", PAPER_PROG, NULL, &r), CHECK_OK);
    for (int i = 0; i < 6; i++)
        ck_assert(r.leg[i].peak_vel_mm_s <= 5.0 + 1e-9);
    check_result_free(&r);
}
END_TEST

START_TEST(test_unreachable_point)
{
    struct check_result r;
    ck_assert_int_eq(run(TMU_INI, "tests/check/unreachable.ngc", NULL, &r), CHECK_ERR_VIOLATION);
    const struct check_problem *p = find(&r, CHECK_UNREACHABLE);
    ck_assert_int_eq(p->line, 4);
    ck_assert(strstr(p->file, "unreachable.ngc"));
    ck_assert(p->value > p->limit && fabs(p->value - 1024.611) < 0.01);
    ck_assert(strstr(p->message, "MAX_LIMIT"));
    ck_assert(!r.simulated);
    check_result_free(&r);
}
END_TEST

START_TEST(test_leg_too_long_along_move)
{
    struct check_result r;
    ck_assert_int_eq(run("tests/check/tmu-short-legs.ini", "tests/check/leg_range.ngc", NULL, &r),
                     CHECK_ERR_VIOLATION);
    const struct check_problem *p = find(&r, CHECK_LEG_RANGE);
    ck_assert_int_eq(p->line, 5);
    ck_assert(p->value > 830 && p->limit == 830);
    for (size_t i = 0; i < r.nproblems; i++)   /* both ends are reachable */
        ck_assert_int_ne(r.problems[i].kind, CHECK_UNREACHABLE);
    check_result_free(&r);
}
END_TEST

START_TEST(test_leg_speed_over_drive_limit)
{
    struct check_result r;
    ck_assert_int_eq(run("tests/check/tmu-slow-drive.ini", PAPER_PROG, NULL, &r),
                     CHECK_ERR_VIOLATION);
    const struct check_problem *p = find(&r, CHECK_LEG_VELOCITY);
    ck_assert(p->line == 10 || p->line == 11);
    ck_assert(p->value > 5.0 && p->limit == 5.0);
    ck_assert(strstr(p->message, "STEPGEN_MAXVEL"));
    int lines[12] = { 0 };
    for (size_t i = 0; i < r.nproblems; i++)
        if (r.problems[i].kind == CHECK_LEG_VELOCITY && r.problems[i].line < 12)
            lines[r.problems[i].line]++;
    ck_assert(lines[10] > 0 && lines[11] > 0);   /* positioning (line 10) and cut (line 11) */
    check_result_free(&r);
}
END_TEST

START_TEST(test_leg_acceleration_over_drive_limit)
{
    struct check_result r;
    ck_assert_int_eq(run("tests/check/tmu-weak-drive.ini", PAPER_PROG, NULL, &r),
                     CHECK_ERR_VIOLATION);
    const struct check_problem *p = find(&r, CHECK_LEG_ACCELERATION);
    ck_assert(p->line == 10 || p->line == 11);
    ck_assert(p->value > 50.0 && p->limit == 50.0);
    ck_assert(strstr(p->message, "STEPGEN_MAXACCEL"));
    for (size_t i = 0; i < r.nproblems; i++)   /* speeds are within every limit */
        ck_assert_int_ne(r.problems[i].kind, CHECK_LEG_VELOCITY);
    check_result_free(&r);
}
END_TEST

START_TEST(test_near_singular_pose)
{
    struct check_result r;
    ck_assert_int_eq(run("tests/check/tmu-singular.ini", PAPER_PROG, NULL, &r),
                     CHECK_ERR_VIOLATION);
    const struct check_problem *p = find(&r, CHECK_SINGULAR);
    ck_assert(p->line == 10 || p->line == 11);
    ck_assert(p->value > 2.5 && p->limit == 2.5);
    check_result_free(&r);
}
END_TEST

/* A wandering five-axis program of n short blocks (X Y Z A B C on each), run twice over,
 * written to a new file in /tmp whose name goes into path (unlink it when done). */
static void write_wander(char path[32], int n)
{
    snprintf(path, 32, "/tmp/hexcnc_wanderXXXXXX");
    int fd = mkstemp(path);
    ck_assert(fd >= 0);
    close(fd);
    FILE *f = fopen(path, "w");
    ck_assert(f != NULL);
    fprintf(f, "G21 G90 G64 P0.01\nG1 X0 Y0 Z645 A0 B0 C0 F2000\n");
    for (int j = 0; j <= 2 * n; j++) {
        int i = j <= n ? j : 2 * n - j;  /* out and back along the same poses */
        double t = 0.004 * i;
        fprintf(f, "X%.4f Y%.4f Z%.4f A%.4f B%.4f C%.4f\n", 60 * sin(t), 45 * sin(1.7 * t),
                645 + 15 * sin(0.9 * t), 9 * sin(1.3 * t), 8 * cos(1.1 * t) - 8,
                12 * sin(0.7 * t));
    }
    fprintf(f, "M2\n");
    fclose(f);
}

/* The condition number between poses: a bound from the last one solved (Weyl) answers most
 * measures, and the check finds exactly what solving every one finds: the largest, its
 * line, and on a machine whose limit the path crosses, every problem with its value. */
START_TEST(test_condition_bound)
{
    char path[32];
    write_wander(path, 2000);
    static const char *inis[] = { TMU_INI, "tests/check/tmu-singular.ini" };
    for (int k = 0; k < 2; k++) {
        struct check_opts o;
        struct check_result a, b;
        check_opts_default(&o);
        int sa = run(inis[k], path, &o, &a);
        o.solve_every_condition = 1;
        int sb = run(inis[k], path, &o, &b);
        ck_assert_int_eq(sa, sb);
        ck_assert_int_eq(b.condition_bounded, 0);
        ck_assert_int_eq(a.condition_evals, b.condition_evals);
        ck_assert_msg(a.condition_evals > 200, "%ld measures", a.condition_evals);
        ck_assert(a.max_condition == b.max_condition);
        ck_assert_int_eq(a.max_condition_line, b.max_condition_line);
        ck_assert_uint_eq(a.nproblems, b.nproblems);
        size_t singular = 0;
        for (size_t i = 0; i < a.nproblems; i++) {
            const struct check_problem *p = &a.problems[i], *q = &b.problems[i];
            ck_assert_int_eq(p->kind, q->kind);
            ck_assert_int_eq(p->line, q->line);
            ck_assert_int_eq(p->count, q->count);
            ck_assert(p->value == q->value);
            singular += p->kind == CHECK_SINGULAR;
        }
        printf("condition bound on %s: %ld of %ld measures bounded, largest %.4f at line %d, "
               "%zu singular problems\n", inis[k], a.condition_bounded, a.condition_evals,
               a.max_condition, a.max_condition_line, singular);
        if (k == 0) {            /* well within the limit: most measures need no solving
                                  * (on the way back, none) */
            ck_assert_uint_eq(singular, 0);
            ck_assert_msg(a.condition_bounded > a.condition_evals / 2, "%ld of %ld",
                          a.condition_bounded, a.condition_evals);
        } else {                 /* the limit is crossed: those are solved and reported */
            ck_assert(singular > 10);
        }
        check_result_free(&a);
        check_result_free(&b);
    }
    unlink(path);
}
END_TEST

/* The legs tested in batches of periods find what period by period finds: every problem
 * in the same order (leg rates over a drive's limit interleaved with condition numbers over
 * the threshold), with the same values, times and counts, and the same figures. */
START_TEST(test_legs_in_batches)
{
    char path[32];
    write_wander(path, 800);
    struct check_opts o;
    struct check_result a, b;
    check_opts_default(&o);
    int sa = run("tests/check/tmu-slow-singular.ini", path, &o, &a);
    o.legs_every_period = 1;
    int sb = run("tests/check/tmu-slow-singular.ini", path, &o, &b);
    ck_assert_int_eq(sa, CHECK_ERR_VIOLATION);
    ck_assert_int_eq(sa, sb);
    ck_assert_uint_eq(a.nproblems, b.nproblems);
    size_t legs = 0, singular = 0, changes = 0;
    for (size_t i = 0; i < a.nproblems; i++) {
        const struct check_problem *p = &a.problems[i], *q = &b.problems[i];
        ck_assert_int_eq(p->kind, q->kind);
        ck_assert_int_eq(p->line, q->line);
        ck_assert_int_eq(p->leg, q->leg);
        ck_assert_int_eq(p->count, q->count);
        ck_assert(p->value == q->value && p->time_s == q->time_s);
        ck_assert_str_eq(p->message, q->message);
        legs += p->kind == CHECK_LEG_VELOCITY;
        singular += p->kind == CHECK_SINGULAR;
        changes += i > 0 && p->kind != a.problems[i - 1].kind;
    }
    printf("legs in batches: %zu problems (%zu leg rates, %zu condition numbers, the kind "
           "changing %zu times in order)\n", a.nproblems, legs, singular, changes);
    ck_assert(legs > 100 && singular > 10 && changes > 20);
    for (int i = 0; i < 6; i++) {
        ck_assert(a.leg[i].min_mm == b.leg[i].min_mm && a.leg[i].max_mm == b.leg[i].max_mm);
        ck_assert(a.leg[i].peak_vel_mm_s == b.leg[i].peak_vel_mm_s);
        ck_assert(a.leg[i].peak_acc_mm_s2 == b.leg[i].peak_acc_mm_s2);
        ck_assert(a.leg[i].peak_jerk_mm_s3 == b.leg[i].peak_jerk_mm_s3);
    }
    check_result_free(&a);
    check_result_free(&b);
    unlink(path);
}
END_TEST

START_TEST(test_interpreter_error)
{
    struct check_result r;
    ck_assert_int_eq(run(TMU_INI, "tests/check/interp_error.ngc", NULL, &r),
                     CHECK_ERR_VIOLATION);
    const struct check_problem *p = find(&r, CHECK_INTERP);
    ck_assert_int_eq(p->line, 4);
    ck_assert_int_eq(p->column, 16);
    ck_assert(strstr(p->message, "interp_error.ngc:4:16:"));
    check_result_free(&r);
}
END_TEST

/* Runs bin/hexcnc check and returns its exit status (output to out_path). */
static int run_binary(const char *args, const char *out_path)
{
    const char *bin = getenv("HEXCNC_BIN");
    char cmd[2048], root[1024];
    if (!bin)
        bin = "bin/hexcnc";
    int n = snprintf(cmd, sizeof cmd, "cd %s && %s check %s > %s 2>&1",
                     tc_path("", root, sizeof root), bin, args, out_path);
    ck_assert_msg(n > 0 && (size_t)n < sizeof cmd, "the command line is too long");
    int st = system(cmd);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

START_TEST(test_json_and_exit_status)
{
    char out[] = "/tmp/hexcnc_check_jsonXXXXXX";
    int fd = mkstemp(out);
    ck_assert(fd >= 0);
    close(fd);
    ck_assert_int_eq(run_binary("--json " PAPER_INI " " PAPER_PROG, out), 0);
    char *j = tc_read(out);
    ck_assert(j && tj_valid(j));
    const char *keys[] = { "\"ok\":true", "\"machining_time_s\":", "\"deviation\":{",
                           "\"max_mm\":", "\"condition\":{", "\"legs\":[{\"leg\":1",
                           "\"peak_vel_mm_s\":", "\"peak_acc_mm_s2\":", "\"problems\":[]" };
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
        ck_assert_msg(strstr(j, keys[i]), "missing %s", keys[i]);
    free(j);
    ck_assert_int_eq(run_binary("--json " TMU_INI " tests/check/unreachable.ngc", out), 1);
    j = tc_read(out);
    ck_assert(j && tj_valid(j));
    ck_assert(strstr(j, "\"kind\":\"unreachable\"") && strstr(j, "\"line\":4"));
    free(j);
    ck_assert_int_eq(run_binary(TMU_INI " tests/check/interp_error.ngc", out), 1);
    ck_assert_int_eq(run_binary("missing.ini " PAPER_PROG, out), 2);
    unlink(out);
}
END_TEST

/* Largest distance from the line S -> E of the platform when the legs move linearly between
 * set points, 9 points per chord, each solved from scratch (an independent measure). */
static double deviation_9(const char *ini, const char *prog, const double S[6], const double E[6])
{
    char ip[1024], pp[1024], err[1024];
    struct check_machine *mc;
    struct canon_prog cp;
    struct check_problem pb;
    ck_assert(check_machine_open(tc_path(ini, ip, sizeof ip), &mc, err, sizeof err) == 0);
    canon_prog_init(&cp);
    ck_assert(check_machine_interpret(mc, tc_path(prog, pp, sizeof pp), &cp, &pb) == 0);
    struct motion *m = check_machine_motion(mc);
    struct kins *k = check_machine_kins(mc);
    double T = check_machine_motion_config(mc)->servo_period_s, L0[6], d[3], n2 = 0, worst = 0;
    ck_assert(motion_load(m, &cp, err, sizeof err) == 0 && motion_start(m) == 0);
    ck_assert(kins_inverse(k, S, L0) == 0);
    for (int i = 0; i < 3; i++)
        d[i] = E[i] - S[i], n2 += d[i] * d[i];
    struct motion_out o;
    do {
        motion_step(m, T, &o);
        for (int j = 1; j < 10; j++) {
            double L[6], P[6], u = 0, e2 = 0;
            for (int i = 0; i < 6; i++)
                L[i] = L0[i] + (o.joint_pos[i] - L0[i]) * j / 10.0, P[i] = k->home[i];
            ck_assert(kins_forward(k, L, P, NULL) == 0);
            for (int i = 0; i < 3; i++)
                u += (P[i] - S[i]) * d[i] / n2;
            for (int i = 0; i < 3; i++)
                e2 += (P[i] - S[i] - u * d[i]) * (P[i] - S[i] - u * d[i]);
            worst = fmax(worst, sqrt(e2));
        }
        memcpy(L0, o.joint_pos, sizeof L0);
    } while (o.state == MOTION_RUNNING);
    canon_prog_free(&cp);
    check_machine_close(mc);
    return worst;
}

START_TEST(test_deviation_measure)
{   /* 100 Hz set points at 500 mm/s: without the bound the platform leaves the line by
     * micrometres; the check's mid-chord measure agrees with a 9-point measure from scratch */
    static const double S[6] = { 0, 0, 645, 0, 0, 0 }, E[6] = { 60, 40, 660, 8, -6, 12 };
    struct check_opts o;
    struct check_result r;
    check_opts_default(&o);
    o.deviation_every_s = 0;
    ck_assert_int_eq(run("tests/check/tmu-fast-nobound.ini", "tests/check/fast_move.ngc", &o,
                         &r), CHECK_OK);
    double ref = deviation_9("tests/check/tmu-fast-nobound.ini", "tests/check/fast_move.ngc",
                             S, E);
    ck_assert_msg(ref > 0.002, "%.6f", ref);
    ck_assert_msg(fabs(r.max_deviation_mm - ref) < 0.02 * ref, "check %.6f, 9-point %.6f",
                  r.max_deviation_mm, ref);
    ck_assert_int_eq(r.max_deviation_line, 3);
    check_result_free(&r);
    /* with KINEMATIC_TOLERANCE = 0.001 mm the planner keeps it, and the check sees that */
    ck_assert_int_eq(run("tests/check/tmu-fast-bound.ini", "tests/check/fast_move.ngc", &o, &r),
                     CHECK_OK);
    ck_assert(r.max_deviation_mm <= 0.001 && r.max_deviation_mm > 0.0002);
    check_result_free(&r);
}
END_TEST

START_TEST(test_json_reader_rejects_bad_text)
{   /* the reader the test above relies on does tell good from bad */
    ck_assert(tj_valid("{\"a\":[1,2.5e-3,null,true,\"x\\n\"]}"));
    ck_assert(!tj_valid("{\"a\":[1,2,]}"));
    ck_assert(!tj_valid("{\"a\":nan}"));
    ck_assert(!tj_valid("{\"a\":1} x"));
    ck_assert(tx_balanced("<svg><g><line/></g><text>a</text></svg>"));
    ck_assert(!tx_balanced("<svg><g></svg></g>"));
}
END_TEST

START_TEST(test_plots_written)
{
    char dir[] = "/tmp/hexcnc_check_plotXXXXXX", out[] = "/tmp/hexcnc_check_outXXXXXX";
    ck_assert(mkdtemp(dir));
    int fd = mkstemp(out);
    close(fd);
    char args[1200];
    snprintf(args, sizeof args, "--plot %s " PAPER_INI " " PAPER_PROG, dir);
    ck_assert_int_eq(run_binary(args, out), 0);
    const char *files[] = { "toolpath_top.svg", "toolpath_3d.svg", "legs.svg", "leg_rates.svg",
                            "deviation.svg" };
    const char *expect[] = { "programmed contour", "compensated tool path", "leg 6", "leg 1",
                             "mid-chord deviation" };
    for (int i = 0; i < 5; i++) {
        char p[1300];
        snprintf(p, sizeof p, "%s/%s", dir, files[i]);
        char *s = tc_read(p);
        ck_assert_msg(s, "%s not written", p);
        ck_assert_msg(tx_balanced(s), "%s: unbalanced tags", p);
        ck_assert(strstr(s, "<polyline") || strstr(s, "<circle"));
        ck_assert_msg(strstr(s, expect[i]), "%s: no series '%s'", p, expect[i]);
        ck_assert(strstr(s, "(mm)") || strstr(s, "(um)") || strstr(s, "(mm/s)"));
        free(s);
        unlink(p);
    }
    rmdir(dir);
    unlink(out);
}
END_TEST

/* A plot replaces its file atomically: the mode is kept, a read-only plot is refused with
 * a message naming it and left as it was. */
START_TEST(test_plot_file_replaced_atomically)
{
    char dir[] = "/tmp/hexcnc_check_svgXXXXXX", path[128], err[512] = "";
    ck_assert(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/legs.svg", dir);
    FILE *f = fopen(path, "w");
    fputs("old plot\n", f);
    fclose(f);
    ck_assert_int_eq(chmod(path, 0600), 0);
    double x[3] = { 0, 1, 2 }, y[3] = { 1, 3, 2 };
    struct svg_series s = { "leg 1", x, y, 3, 0, "#000", 0, 0 };
    struct svg_chart c = { "Leg lengths", "machine time (s)", "leg length (mm)", 0 };
    ck_assert_msg(svg_write_chart(path, &c, &s, 1, err, sizeof err) == 0, "%s", err);
    struct stat st;
    ck_assert_int_eq(stat(path, &st), 0);
    ck_assert_uint_eq(st.st_mode & 07777, 0600);
    char *text = tc_read(path);
    ck_assert(text && tx_balanced(text) && strstr(text, "leg 1"));
    free(text);
    ck_assert_int_eq(chmod(path, 0444), 0);
    ck_assert_int_eq(svg_write_chart(path, &c, &s, 1, err, sizeof err), -1);
    ck_assert_msg(strstr(err, path) && strstr(err, "read-only"), "%s", err);
    text = tc_read(path);
    ck_assert(text && strstr(text, "leg 1"));        /* the earlier plot, unchanged */
    free(text);
    unlink(path);
    ck_assert_int_eq(rmdir(dir), 0);                  /* nothing else was left there */
}
END_TEST

/* A bad value in the INI: the check at load names the file and the key's line. */
START_TEST(test_config_error_names_the_ini_line)
{
    char path[] = "/tmp/hexcnc-check-ini-XXXXXX", err[1024], want[256];
    int fd = mkstemp(path);
    ck_assert_int_ge(fd, 0);
    FILE *f = fdopen(fd, "w");
    fprintf(f, "[KINS]\nKINEMATICS = hexapod\nBASE_RADIUS = 500\nPLATFORM_RADIUS = 300\n"
               "BASE_HALF_ANGLE = 10\nPLATFORM_HALF_ANGLE = 10\n");
    for (int i = 0; i < 6; i++)
        fprintf(f, "[JOINT_%d]\nMIN_LIMIT = 520\nMAX_LIMIT = %s\nMAX_VELOCITY = 100\n"
                   "MAX_ACCELERATION = 1000\nFERROR = 1\n", i, i == 3 ? "abc" : "980");
    fclose(f);
    struct check_machine *mc = NULL;
    ck_assert_int_eq(check_machine_open(path, &mc, err, sizeof err), CHECK_ERR_CONFIG);
    snprintf(want, sizeof want, "%s:27: [JOINT_3] MAX_LIMIT = abc: not a number (mm)", path);
    ck_assert_str_eq(err, want);
    ck_assert_ptr_null(mc);
    unlink(path);
}
END_TEST

/* Problems merge by kind, file, line and leg, the worst value kept and the periods counted;
 * distinct ones keep their order. 60,000 lines with a warning each (dense code under jerk
 * limits has one on most lines) merge through the index, not a scan of the list. */
START_TEST(test_problem_merging)
{
    struct check_result r;
    check_result_init(&r);
    struct check_problem p = { .kind = CHECK_TIP_DEVIATION, .leg = -1, .count = 1 };
    snprintf(p.file, sizeof p.file, "a.ngc");
    for (int pass = 0; pass < 2; pass++)
        for (int line = 1; line <= 60000; line++) {
            p.line = line;
            p.value = pass ? 2.0 * line : line;
            ck_assert_int_eq(check_add_warning(&r, &p), CHECK_OK);
        }
    snprintf(p.file, sizeof p.file, "b.ngc");       /* another file, the same line */
    p.line = 7, p.value = 1;
    ck_assert_int_eq(check_add_warning(&r, &p), CHECK_OK);
    p.kind = CHECK_LEG_JERK, p.leg = 2;               /* a problem: its own list */
    ck_assert_int_eq(check_add_problem(&r, &p), CHECK_OK);
    ck_assert_int_eq(check_add_problem(&r, &p), CHECK_OK);
    ck_assert_uint_eq(r.nwarnings, 60001);
    for (int line = 1; line <= 60000; line += 997) {
        ck_assert_int_eq(r.warnings[line - 1].line, line);
        ck_assert_int_eq(r.warnings[line - 1].count, 2);
        ck_assert_double_eq(r.warnings[line - 1].value, 2.0 * line);
    }
    ck_assert_str_eq(r.warnings[60000].file, "b.ngc");
    ck_assert_int_eq(r.warnings[60000].count, 1);
    ck_assert_uint_eq(r.nproblems, 1);
    ck_assert_int_eq(r.problems[0].count, 2);
    check_result_free(&r);
}
END_TEST

START_TEST(test_strip_compensation)
{
    const char in[] = "G141 X50 Y-80 Z630 A0 B-4 W10 F2;\ng142 x1 D3\nG1 X1 (G1410)\n";
    char *o = check_strip_compensation(in, strlen(in));
    ck_assert_str_eq(o, "G1   X50 Y-80 Z630 A0 B-4     F2;\ng1   x1   \nG1 X1 (G1410)\n");
    free(o);
}
END_TEST

/* The simulated TMU's INI with jerk limits (50,000 mm/s^3 on the path and the legs, 30,000
 * deg/s^3 on A B C: a 20 ms average by default, 40 ms for every acceleration in full) and,
 * when window is given, [TRAJ] JERK_WINDOW window, in
 * dir (made here) beside a copy of its tool table; the INI's path into ini. */
static void jerk_ini(char *dir, const char *window, char *ini, size_t len)
{
    char path[1024];
    ck_assert(mkdtemp(dir));
    char *text = tc_read(tc_path("configs/sim/tmu-hexapod.ini", path, sizeof path));
    char *tbl = tc_read(tc_path("configs/sim/tmu-hexapod.tbl", path, sizeof path));
    ck_assert(text && tbl);
    snprintf(path, sizeof path, "%s/tmu-hexapod.tbl", dir);
    FILE *f = fopen(path, "w");
    ck_assert(f && fputs(tbl, f) >= 0 && fclose(f) == 0);
    snprintf(ini, len, "%s/tmu-hexapod-jerk.ini", dir);
    ck_assert((f = fopen(ini, "w")) != NULL);
    int added = 0;
    for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
        fprintf(f, "%s\n", line);
        if (!strncmp(line, "MAX_ANGULAR_ACCELERATION", 24)) {
            fputs("MAX_LINEAR_JERK = 50000\nMAX_ANGULAR_JERK = 30000\n", f), added++;
            if (window)
                fprintf(f, "JERK_WINDOW = %s\n", window);
        } else if (!strncmp(line, "MAX_ACCELERATION", 16)) {
            fputs("MAX_JERK = 50000\n", f), added++;
        }
    }
    ck_assert(fclose(f) == 0);
    ck_assert_int_eq(added, 7);                     /* [TRAJ] and six legs */
    free(text);
    free(tbl);
}

/* Removes what jerk_ini wrote. */
static void jerk_ini_remove(const char *dir, const char *ini)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/tmu-hexapod.tbl", dir);
    ck_assert(unlink(ini) == 0 && unlink(path) == 0 && rmdir(dir) == 0);
}

/* The check with the default window and with [TRAJ] JERK_WINDOW the full one: the demo's
 * legs, which reach their full 1000 mm/s^2 with the 40 ms average, keep to the 500 the
 * default 20 ms one plans them to; the report names the window, where it comes from, the
 * full one and the lowered accelerations, and compares the legs with the machine's own
 * limits. */
START_TEST(test_jerk_window_reported)
{
    char d20[] = "/tmp/hexcnc_check_jerk20XXXXXX", d40[] = "/tmp/hexcnc_check_jerk40XXXXXX";
    char i20[1100], i40[1100];
    jerk_ini(d20, NULL, i20, sizeof i20);
    jerk_ini(d40, "0.040", i40, sizeof i40);
    struct check_result w, full;
    ck_assert_int_eq(run(i20, "configs/sim/tmu-hexapod-demo.ngc", NULL, &w), CHECK_OK);
    ck_assert_int_eq(run(i40, "configs/sim/tmu-hexapod-demo.ngc", NULL, &full), CHECK_OK);
    ck_assert_uint_eq(w.nproblems, 0);
    ck_assert_double_eq_tol(w.jerk_window_s, 0.020, 1e-12);
    ck_assert_double_eq_tol(full.jerk_window_s, 0.040, 1e-12);
    ck_assert(!w.jerk_window_set && full.jerk_window_set);
    ck_assert_double_eq_tol(w.jerk_full_window_s, 0.040, 1e-12);
    double pw = 0, pf = 0;
    for (int i = 0; i < 6; i++) {
        ck_assert_double_eq(w.leg[i].limit_acc_mm_s2, 1000);       /* the machine's */
        ck_assert_double_eq_tol(w.leg[i].planned_acc_mm_s2, 500, 1e-9);
        ck_assert_double_eq(full.leg[i].planned_acc_mm_s2, 1000);
        ck_assert(w.leg[i].peak_jerk_mm_s3 <= 50000 * (1 + 1e-6));
        pw = fmax(pw, w.leg[i].peak_acc_mm_s2), pf = fmax(pf, full.leg[i].peak_acc_mm_s2);
    }
    ck_assert_msg(pw <= 500 * (1 + 1e-6) && pf > 900, "peak leg acceleration %.3f with the "
                  "default window, %.3f with the full one", pw, pf);
    ck_assert_msg(w.machining_time_s < full.machining_time_s, "%.3f s against %.3f s",
                  w.machining_time_s, full.machining_time_s);
    char *txt = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&txt, &n);
    ck_assert(f);
    check_print_table(&w, f);
    check_print_table(&full, f);
    check_print_json(&w, f);
    ck_assert(fclose(f) == 0);
    ck_assert_msg(strstr(txt, "\"jerk_window_s\":0.02,\"jerk_full_window_s\":0.04,") &&
                  strstr(txt, "\"limit_acc_mm_s2\":1000,\"planned_acc_mm_s2\":500,"), "%s",
                  txt);
    ck_assert_msg(strstr(txt, "jerk            a 20 ms moving average of the set points (the "
                              "default; 40 ms with every acceleration in full): accelerations "
                              "planned to MAX_JERK x window / 2 at most, the legs' to 500 "
                              "mm/s^2\n") &&
                  strstr(txt, "jerk            a 40 ms moving average of the set points ([TRAJ] "
                              "JERK_WINDOW; every acceleration in full)\n"), "%s", txt);
    free(txt);
    check_result_free(&w);
    check_result_free(&full);
    jerk_ini_remove(d20, i20);
    jerk_ini_remove(d40, i40);
}
END_TEST

/* The test cases. */
static Suite *suite(void)
{
    Suite *s = suite_create("check");
    TCase *tc = tcase_create("check");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_good_program);
    tcase_add_test(tc, test_planner_keeps_tight_leg_limit);
    tcase_add_test(tc, test_unreachable_point);
    tcase_add_test(tc, test_leg_too_long_along_move);
    tcase_add_test(tc, test_leg_speed_over_drive_limit);
    tcase_add_test(tc, test_leg_acceleration_over_drive_limit);
    tcase_add_test(tc, test_near_singular_pose);
    tcase_add_test(tc, test_condition_bound);
    tcase_add_test(tc, test_legs_in_batches);
    tcase_add_test(tc, test_interpreter_error);
    tcase_add_test(tc, test_deviation_measure);
    tcase_add_test(tc, test_json_and_exit_status);
    tcase_add_test(tc, test_json_reader_rejects_bad_text);
    tcase_add_test(tc, test_plots_written);
    tcase_add_test(tc, test_plot_file_replaced_atomically);
    tcase_add_test(tc, test_strip_compensation);
    tcase_add_test(tc, test_problem_merging);
    tcase_add_test(tc, test_config_error_names_the_ini_line);
    tcase_add_test(tc, test_jerk_window_reported);
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
