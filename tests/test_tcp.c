/* test_tcp.c: tool centre point control (G43.4): the tip-to-platform map, the interpreter's
 * G43.4/G49, the tip kept on the programmed path on both machine types (forward kinematics
 * of the legs interpolated between set points), and check's report of the tip's swing
 * when the same moves are interpolated as platform poses. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check/check.h"
#include "interp/interp.h"
#include "kins/kins.h"
#include "motion/motion.h"
#include "tests/test_check_util.h"
#include "tests/test_kins_util.h"
#include "tests/test_motion_util.h"

#define TMU_INI "configs/sim/tmu-hexapod.ini"
#define SPINDLE_INI "examples/tcp/spindle-hexapod.ini"

/* A path of the source tree, or an absolute one as it is. */
static const char *tree_path(const char *p, char *buf, size_t len)
{
    if (p[0] == '/') {
        snprintf(buf, len, "%s", p);
        return buf;
    }
    return tc_path(p, buf, len);
}

static struct check_machine *open_machine(const char *ini)
{
    char ip[1024], err[1024];
    struct check_machine *mc;
    ck_assert_msg(check_machine_open(tree_path(ini, ip, sizeof ip), &mc, err, sizeof err) == 0,
                  "%s", err);
    return mc;
}

/* The tool frame of a machine (it must have one). */
static struct kins_tool_frame frame_of(struct check_machine *mc)
{
    struct kins_tool_frame f;
    ck_assert_int_eq(kins_get_tool_frame(check_machine_kins(mc), &f), KINS_OK);
    return f;
}

/* ---- the map ---- */

/* Round trip, the velocity against finite differences, the tip against kins_tool_point and
 * the tool direction against R's columns, on random poses of both machine types. */
static void map_checks(const char *ini, int on_platform)
{
    struct check_machine *mc = open_machine(ini);
    struct kins *k = check_machine_kins(mc);
    struct kins_tool_frame f = frame_of(mc);
    ck_assert_int_eq(f.on_platform, on_platform);
    uint64_t seed = 42;
    for (int n = 0; n < 200; n++) {
        double P[6], Q[6], back[6], V[6], Pp[6], Pm[6], Qp[6], Qm[6], Qv[6], Q2[6];
        for (int i = 0; i < 6; i++) {
            P[i] = k->home[i] + tk_rand(&seed, i < 3 ? -50 : -15, i < 3 ? 50 : 15);
            V[i] = tk_rand(&seed, -20, 20);
        }
        double len = tk_rand(&seed, 0, 150);
        kins_tcp_from_pose(&f, len, P, Q);          /* a platform pose's tip ... */
        kins_tcp_to_pose(&f, len, Q, back);         /* ... and back */
        for (int i = 0; i < 6; i++)
            ck_assert_msg(fabs(back[i] - P[i]) < 1e-9, "round trip axis %d: %.12f vs %.12f",
                          i, back[i], P[i]);
        /* the tip with the configured tool is where kins_tool_point puts it */
        double tb[3], tp[3], Qt[6];
        ck_assert_int_eq(kins_tool_point(k, P, tb, tp), KINS_OK);
        kins_tcp_from_pose(&f, f.length_mm, P, Qt);
        for (int i = 0; i < 3; i++)
            ck_assert(fabs(Qt[i] - (on_platform ? tb[i] : tp[i])) < 1e-9);
        /* velocity: central differences of the map along Q + t V */
        double h = 1e-5;
        for (int i = 0; i < 6; i++)
            Pp[i] = Q[i] + h * V[i], Pm[i] = Q[i] - h * V[i];
        kins_tcp_to_pose(&f, len, Pp, Qp);
        kins_tcp_to_pose(&f, len, Pm, Qm);
        kins_tcp_to_pose_vel(&f, len, Q, V, Q2, Qv);
        for (int i = 0; i < 6; i++) {
            double fd = (Qp[i] - Qm[i]) / (2 * h);
            ck_assert_msg(fabs(Qv[i] - fd) < 1e-5 * (1 + fabs(fd)), "velocity axis %d: %.9f "
                          "vs %.9f", i, Qv[i], fd);
            ck_assert(fabs(Q2[i] - back[i]) < 1e-9);
        }
        /* the tool's direction (tip to spindle) in the program's frame: -axis turned by R
         * (spindle on the platform) or by R^T (tool on the frame), with axis (0 0 -1) */
        double nd[3], ca = cos(P[3] * M_PI / 180), sa = sin(P[3] * M_PI / 180);
        double cb = cos(P[4] * M_PI / 180), sb = sin(P[4] * M_PI / 180);
        double cc = cos(P[5] * M_PI / 180), sc = sin(P[5] * M_PI / 180);
        double Rz[3] = { cc * sb * ca + sc * sa, sc * sb * ca - cc * sa, cb * ca }; /* R e3 */
        double RTz[3] = { -sb, cb * sa, cb * ca };                                /* R^T e3 */
        kins_tcp_tool_dir(&f, P + 3, nd);
        for (int i = 0; i < 3; i++)
            ck_assert(fabs(nd[i] - (on_platform ? Rz[i] : RTz[i])) < 1e-12);
    }
    check_machine_close(mc);
}

START_TEST(test_map_workpiece) { map_checks(TMU_INI, 0); }
END_TEST
START_TEST(test_map_spindle) { map_checks(SPINDLE_INI, 1); }
END_TEST

/* ---- the interpreter ---- */

static void interpret(struct check_machine *mc, const char *text, struct canon_prog *p)
{
    struct check_problem pb;
    memset(&pb, 0, sizeof pb);
    canon_prog_init(p);
    int st = check_machine_interpret_text(mc, "t.ngc", text, strlen(text), p, &pb);
    ck_assert_msg(st == CHECK_OK, "%s", pb.message);
}

/* The n-th move of a program. */
static const struct canon_cmd *move(const struct canon_prog *p, int n)
{
    for (size_t i = 0; i < p->count; i++)
        if ((p->cmds[i].type == CANON_FEED || p->cmds[i].type == CANON_TRAVERSE ||
             p->cmds[i].type == CANON_ARC) && n-- == 0)
            return &p->cmds[i];
    ck_abort_msg("no such move");
    return NULL;
}

/* On the TMU machine (tool on the frame, tip 75 mm above the platform at HOME Z645):
 * G43.4 H1 makes X Y Z the tip in the platform's frame; G49 gives back the platform pose,
 * the machine not moving at either switch. */
START_TEST(test_interp_switches)
{
    struct check_machine *mc = open_machine(TMU_INI);
    struct canon_prog p;
    interpret(mc, "G21 G90\nG43.4 H1\nG1 X10 F600\nG1 B5\nG49\nG1 X5\nM2\n", &p);
    const struct canon_cmd *a = move(&p, 0), *b = move(&p, 1), *c = move(&p, 2);
    ck_assert_int_eq(a->tcp, 1);
    ck_assert(fabs(a->tool_len_mm - 60) < 1e-12);   /* TOOL_LENGTH + T1's Z (0) */
    double want_a[6] = { 10, 0, 75, 0, 0, 0 };       /* the tip kept its Y Z (0, 75) */
    for (int i = 0; i < 6; i++)
        ck_assert_msg(fabs(a->end[i] - want_a[i]) < 1e-9, "axis %d %.9f", i, a->end[i]);
    ck_assert_int_eq(b->tcp, 1);
    ck_assert(fabs(b->end[0] - 10) < 1e-9 && fabs(b->end[4] - 5) < 1e-12);
    /* after G49: the platform pose of tip (10, 0, 75) at B5, X then set to 5 */
    struct kins_tool_frame f = frame_of(mc);
    double plat[6];
    kins_tcp_to_pose(&f, 60, b->end, plat);
    ck_assert_int_eq(c->tcp, 0);
    ck_assert(fabs(c->end[0] - 5) < 1e-9);
    for (int i = 1; i < 6; i++)
        ck_assert_msg(fabs(c->end[i] - plat[i]) < 1e-9, "axis %d %.9f vs %.9f", i, c->end[i],
                      plat[i]);
    /* by hand: tip at base (0 0 720); platform = tip - R (10 0 75), R = Ry(5 deg) */
    double s5 = sin(5 * M_PI / 180), c5 = cos(5 * M_PI / 180);
    ck_assert(fabs(plat[0] - (0 - (10 * c5 + 75 * s5))) < 1e-9);
    ck_assert(fabs(plat[2] - (720 - (-10 * s5 + 75 * c5))) < 1e-9);
    canon_prog_free(&p);
    check_machine_close(mc);
}
END_TEST

/* The spindle machine programs the tip from the start (PROGRAM_POINT = TOOL_TIP); G43.4 H2
 * takes tool 2's length (TOOL_LENGTH 100 + its Z 25). */
START_TEST(test_interp_program_point_and_length)
{
    struct check_machine *mc = open_machine(SPINDLE_INI);
    struct canon_prog p;
    interpret(mc, "G21 G90\nG1 X10 F600\nG43.4 H2\nG1 Y5\nM2\n", &p);
    const struct canon_cmd *a = move(&p, 0), *b = move(&p, 1);
    ck_assert_int_eq(a->tcp, 1);
    ck_assert(fabs(a->tool_len_mm - 100) < 1e-12);
    ck_assert(fabs(a->end[2] - 650) < 1e-9);         /* HOME Z950 less 300: the tip */
    ck_assert_int_eq(b->tcp, 1);
    ck_assert(fabs(b->tool_len_mm - 125) < 1e-12);
    ck_assert(fabs(b->end[2] - 625) < 1e-9);         /* the longer tool's tip, 25 lower */
    ck_assert(fabs(b->end[0] - 10) < 1e-9 && fabs(b->end[1] - 5) < 1e-9);
    canon_prog_free(&p);
    check_machine_close(mc);
}
END_TEST

/* G43.4 with a tool the table lacks, and without the machine's kinematics. */
START_TEST(test_interp_errors)
{
    struct check_machine *mc = open_machine(TMU_INI);
    struct canon_prog p;
    struct check_problem pb;
    canon_prog_init(&p);
    const char *t = "G21\nG43.4 H9\nM2\n";
    ck_assert_int_eq(check_machine_interpret_text(mc, "t.ngc", t, strlen(t), &p, &pb),
                     CHECK_ERR_VIOLATION);
    ck_assert_int_eq(pb.line, 2);
    ck_assert_msg(strstr(pb.message, "G43.4 H9: tool 9 is not in the tool table"), "%s",
                  pb.message);
    canon_prog_free(&p);
    check_machine_close(mc);
    struct interp *in = interp_create();
    canon_prog_init(&p);
    ck_assert_int_eq(interp_run_text(in, "n.ngc", t, strlen(t), canon_prog_sink, &p),
                     INTERP_ERR_CONFIG);
    ck_assert_msg(strstr(interp_last_error(in)->message, "G43.4 (tool centre point control) "
                         "needs the machine's kinematics"), "%s", interp_last_error(in)->message);
    canon_prog_free(&p);
    interp_destroy(in);
}
END_TEST

/* ---- the tip on the path ---- */

/* What a drive does between two set points a and b it takes: each leg moves linearly, through
 * La + (Lb - La) j / 10 for j = 1..9. Runs the loaded program to its end, the drives taking
 * every `every`-th set point ([TRAJ] SETPOINT_PERIOD), and hands each of those poses (the
 * forward kinematics of the legs, warm-started) to measure with the two set points; returns
 * how many poses were measured. */
typedef void (*pose_fn)(void *ctx, const struct motion_out *a, const struct motion_out *b,
                        const double P[6]);
static long drive_walk(struct check_machine *mc, pose_fn measure, void *ctx)
{
    struct kins *k = check_machine_kins(mc);
    struct motion *m = check_machine_motion(mc);
    const struct motion_config *cfg = check_machine_motion_config(mc);
    double T = cfg->servo_period_s;
    int every = cfg->setpoint_period_s > 0 ? (int)lround(cfg->setpoint_period_s / T) : 1;
    ck_assert_int_eq(motion_start(m), MOTION_OK);
    struct motion_out a, b;
    long n = 0;
    motion_step(m, T, &a);
    for (long step = 0; step < 10000000 && a.state != MOTION_DONE; step++) {
        for (int e = 0; e < every; e++) {
            ck_assert_int_ne(motion_step(m, T, &b), MOTION_ERR_UNREACHABLE);
            if (b.state == MOTION_DONE)
                break;
        }
        ck_assert(b.state != MOTION_FAULT);
        double guess[6];
        memcpy(guess, a.pose, sizeof guess);
        for (int j = 1; j < 10; j++) {
            double L[KINS_MAX_JOINTS], P[6];
            for (int i = 0; i < 6; i++)
                L[i] = a.joint_pos[i] + (b.joint_pos[i] - a.joint_pos[i]) * j / 10.0;
            memcpy(P, guess, sizeof P);
            ck_assert_int_eq(kins_forward(k, L, P, NULL), KINS_OK);
            memcpy(guess, P, sizeof guess);
            measure(ctx, &a, &b, P);
            n++;
        }
        a = b;
    }
    ck_assert_int_eq(a.state, MOTION_DONE);
    return n;
}

/* The programmed tip path of a G43.4 program of straight moves, per line. */
enum { MAXL = 64 };
struct tip_path {
    struct kins_tool_frame f;
    double from[MAXL][3], to[MAXL][3], len_mm[MAXL];
    int tcp[MAXL], have[MAXL];
    double worst;
    long samples;
};

/* A pose between set points of two G43.4 lines: its tip against their programmed lines. */
static void tip_on_lines(void *ctx, const struct motion_out *a, const struct motion_out *b,
                         const double P[6])
{
    struct tip_path *t = ctx;
    int la = a->line, lb = b->line;
    if (la <= 0 || la >= MAXL || !t->have[la] || !t->tcp[la] || lb <= 0 || lb >= MAXL ||
        !t->have[lb] || !t->tcp[lb])
        return;
    double tip[6];
    kins_tcp_from_pose(&t->f, t->len_mm[lb], P, tip);
    double d = fmin(tm_dist_seg(tip, t->from[la], t->to[la]), tm_dist_seg(tip, t->from[lb], t->to[lb]));
    t->worst = fmax(t->worst, d);
    t->samples++;
}

/* Runs a G43.4 program of straight moves through motion at the servo period. Between
 * successive set points the legs pass La + (Lb - La) j / 10, j = 1..9, as a drive moves
 * them; the forward kinematics of those legs gives the pose, and the tip of that pose (with
 * the program's tool) is measured against the programmed tip path: the segments of the
 * lines the two set points belong to. Returns the largest distance, mm. */
static double tip_path_deviation(const char *ini, const char *prog_rel, double *tol_mm)
{
    struct check_machine *mc = open_machine(ini);
    struct motion *m = check_machine_motion(mc);
    static struct tip_path t;
    memset(&t, 0, sizeof t);
    t.f = frame_of(mc);
    *tol_mm = check_machine_motion_config(mc)->kin_tol_mm;
    char pp[1024];
    struct canon_prog p;
    struct check_problem pb;
    canon_prog_init(&p);
    ck_assert_msg(check_machine_interpret(mc, tree_path(prog_rel, pp, sizeof pp), &p, &pb) ==
                  CHECK_OK, "%s", pb.message);
    double at[6];
    int at_tcp = 0;
    double at_len = 0;
    memcpy(at, p.start, sizeof at);
    for (size_t i = 0; i < p.count; i++) {
        const struct canon_cmd *c = &p.cmds[i];
        if (c->type != CANON_FEED && c->type != CANON_TRAVERSE)
            continue;
        ck_assert(c->line < MAXL);
        if (c->tcp != at_tcp || c->tool_len_mm != at_len) {   /* re-express the start */
            double plat[6];
            if (at_tcp)
                kins_tcp_to_pose(&t.f, at_len, at, plat);
            else
                memcpy(plat, at, sizeof plat);
            if (c->tcp)
                kins_tcp_from_pose(&t.f, c->tool_len_mm, plat, at);
            else
                memcpy(at, plat, sizeof at);
            at_tcp = c->tcp, at_len = c->tool_len_mm;
        }
        memcpy(t.from[c->line], at, sizeof t.from[0]);
        memcpy(t.to[c->line], c->end, sizeof t.to[0]);
        t.tcp[c->line] = c->tcp, t.len_mm[c->line] = c->tool_len_mm, t.have[c->line] = 1;
        memcpy(at, c->end, sizeof at);
    }
    char err[512] = "";
    ck_assert_msg(motion_load(m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    drive_walk(mc, tip_on_lines, &t);
    ck_assert(t.samples > 1000);
    canon_prog_free(&p);
    check_machine_close(mc);
    return t.worst;
}

START_TEST(test_tip_on_path)
{
    static const struct { const char *ini, *prog; } runs[] = {
        { SPINDLE_INI, "examples/tcp/pivot.ngc" },
        { SPINDLE_INI, "examples/tcp/chamfer.ngc" },
        { TMU_INI, "examples/tcp/tmu-pivot.ngc" },
        { TMU_INI, "examples/tcp/tmu-chamfer.ngc" },
    };
    double tol;
    double d = tip_path_deviation(runs[_i].ini, runs[_i].prog, &tol);
    printf("%s on %s: the tip stays within %.3g um of the programmed path (tolerance %.3g um)\n",
           runs[_i].prog, runs[_i].ini, d * 1e3, tol * 1e3);
    ck_assert_msg(d <= tol, "%s: the tip strays %.6f mm from its path", runs[_i].prog, d);
}
END_TEST

struct tip_arc {
    struct kins_tool_frame f;
    double len_mm, c[3], r, worst;
    int line;
    long samples;
};

/* A pose between set points on the arc's line: its tip's distance from the circle. */
static void tip_on_circle(void *ctx, const struct motion_out *a, const struct motion_out *b,
                          const double P[6])
{
    struct tip_arc *t = ctx;
    if (a->line != t->line || b->line != t->line)
        return;
    double tip[6];
    kins_tcp_from_pose(&t->f, t->len_mm, P, tip);
    double rho = hypot(tip[0] - t->c[0], tip[1] - t->c[1]);
    t->worst = fmax(t->worst, hypot(rho - t->r, tip[2] - t->c[2]));
    t->samples++;
}

/* An arc under G43.4: the tip on the circle (centre c, radius r, in the plane z = c[2],
 * normal Z) while the tool tilts along it. Forward kinematics of the legs interpolated
 * between set points, as above, while the program is on the arc's line; returns the
 * largest distance from the circle, mm. */
static double tip_arc_deviation(const char *ini, const char *text, int arc_line,
                                const double c[3], double r, double *tol_mm)
{
    struct check_machine *mc = open_machine(ini);
    struct motion *m = check_machine_motion(mc);
    struct tip_arc t = { .f = frame_of(mc), .r = r, .line = arc_line };
    memcpy(t.c, c, sizeof t.c);
    *tol_mm = check_machine_motion_config(mc)->kin_tol_mm;
    struct canon_prog p;
    interpret(mc, text, &p);
    for (size_t i = 0; i < p.count; i++)
        if (p.cmds[i].type == CANON_ARC) {
            ck_assert_int_eq(p.cmds[i].tcp, 1);
            t.len_mm = p.cmds[i].tool_len_mm;
        }
    char err[512] = "";
    ck_assert_msg(motion_load(m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    drive_walk(mc, tip_on_circle, &t);
    ck_assert(t.samples > 1000);
    canon_prog_free(&p);
    check_machine_close(mc);
    return t.worst;
}

START_TEST(test_tip_on_arc)
{
    double tol;
    /* spindle machine: a half circle of radius 30 about X0 Y0 at Z700, the tool tilting
     * A0 -> A10 and C0 -> C20 along it */
    static const double c1[3] = { 0, 0, 700 };
    double d1 = tip_arc_deviation(SPINDLE_INI, "G21 G90 G17\nG43.4 H1\nG0 X30 Y0 Z700\n"
                                  "G3 X-30 Y0 I-30 J0 A10 C20 F1200\nM2\n", 4, c1, 30, &tol);
    /* the TMU: a full circle of radius 20 about X5 Y5 on the table at Z80, the table
     * tilting B0 -> B6 */
    static const double c2[3] = { 5, 5, 80 };
    double d2 = tip_arc_deviation(TMU_INI, "G21 G90 G17\nG43.4 H1\nG1 X25 Y5 Z80 F600\n"
                                  "G2 X25 Y5 I-20 J0 B6 F600\nM2\n", 4, c2, 20, &tol);
    printf("arcs under G43.4: the tip stays within %.3g um (spindle machine) and %.3g um "
           "(TMU) of the programmed circle (tolerance %.3g um)\n", d1 * 1e3, d2 * 1e3,
           tol * 1e3);
    ck_assert_msg(d1 <= tol && d2 <= tol, "%.6f %.6f mm", d1, d2);
}
END_TEST

/* The bound binds: drives that take a set point every 10 ms, a machine five times faster
 * and the chamfer at 500 mm/s. The tip stays within KINEMATIC_TOLERANCE; with the bound
 * off (KINEMATIC_TOLERANCE = 0) the same moves leave it by more, so the measure can fail. */
static double fast_chamfer(const char *tol)
{
    char src[1024], line[512];
    char dir[] = "/tmp/hexcnc-tcp-XXXXXX";
    ck_assert_ptr_nonnull(mkdtemp(dir));
    char ini[600], tbl[600], prog[600];
    snprintf(ini, sizeof ini, "%s/fast.ini", dir);
    snprintf(tbl, sizeof tbl, "%s/spindle-hexapod.tbl", dir);
    snprintf(prog, sizeof prog, "%s/chamfer.ngc", dir);
    FILE *in = fopen(tc_path(SPINDLE_INI, src, sizeof src), "r"), *out = fopen(ini, "w");
    ck_assert(in && out);
    while (fgets(line, sizeof line, in)) {
        double v;
        if (!strncmp(line, "KINEMATIC_TOLERANCE", 19))
            fprintf(out, "KINEMATIC_TOLERANCE = %s\nSETPOINT_PERIOD = 10000000\n", tol);
        else if (sscanf(line, "MAX_LINEAR_VELOCITY = %lf", &v) == 1)
            fputs("MAX_LINEAR_VELOCITY = 500\n", out);
        else if (sscanf(line, "MAX_LINEAR_ACCELERATION = %lf", &v) == 1)
            fputs("MAX_LINEAR_ACCELERATION = 5000\n", out);
        else if (sscanf(line, "MAX_ANGULAR_VELOCITY = %lf", &v) == 1)
            fputs("MAX_ANGULAR_VELOCITY = 300\n", out);
        else if (sscanf(line, "MAX_ANGULAR_ACCELERATION = %lf", &v) == 1)
            fputs("MAX_ANGULAR_ACCELERATION = 3000\n", out);
        else if (sscanf(line, "MAX_VELOCITY = %lf", &v) == 1)
            fputs("MAX_VELOCITY = 1000\n", out);
        else if (sscanf(line, "MAX_ACCELERATION = %lf", &v) == 1)
            fputs("MAX_ACCELERATION = 50000\n", out);
        else
            fputs(line, out);
    }
    fclose(in);
    fclose(out);
    in = fopen(tc_path("examples/tcp/spindle-hexapod.tbl", src, sizeof src), "r");
    out = fopen(tbl, "w");
    ck_assert(in && out);
    while (fgets(line, sizeof line, in))
        fputs(line, out);
    fclose(in);
    fclose(out);
    in = fopen(tc_path("examples/tcp/chamfer.ngc", src, sizeof src), "r");
    out = fopen(prog, "w");
    ck_assert(in && out);
    while (fgets(line, sizeof line, in)) {
        char *f = strstr(line, "F1200");
        if (f) {                    /* 30 m/min */
            *f = 0;
            fprintf(out, "%sF30000%s", line, f + 5);
        } else {
            fputs(line, out);
        }
    }
    fclose(in);
    fclose(out);
    double t;
    double d = tip_path_deviation(ini, prog, &t);
    unlink(ini), unlink(tbl), unlink(prog), rmdir(dir);
    return d;
}

START_TEST(test_tip_bound_binds)
{
    double with = fast_chamfer("0.001"), without = fast_chamfer("0");
    printf("chamfer at 500 mm/s, 10 ms set points: the tip strays %.3f um with the bound "
           "(tolerance 1 um), %.3f um without\n", with * 1e3, without * 1e3);
    ck_assert_msg(with <= 0.001, "%.6f mm", with);
    ck_assert_msg(without > 0.002, "%.6f mm: the moves do not test the bound", without);
}
END_TEST

/* The same tip positions at the ends of every move, but the moves interpolated as platform
 * poses (G49): check warns of the tip's swing by line. Turning by th about the tip, a tip
 * at distance r from the axis of the turn swings r (1 - cos th/2) off its point at
 * mid-move: on the spindle machine A15 (line 6) with the tip 300 mm below the platform,
 * 2.5665 mm; on the TMU B8 (line 6) about the tip at X10 Z80 on the table, r = sqrt(10^2 +
 * 80^2), 0.1964 mm. Under G43.4 the same programs have no warning. */
static const struct { const char *ini, *prog; double r_mm, turn_deg; } swings[] = {
    { SPINDLE_INI, "examples/tcp/pivot.ngc", 300, 15 },
    { TMU_INI, "examples/tcp/tmu-pivot.ngc", 80.62257748, 8 },
};

START_TEST(test_check_reports_swing)
{
    struct check_machine *mc = open_machine(swings[_i].ini);
    struct kins_tool_frame f = frame_of(mc);
    char pp[1024], text[4096], *w = text;
    struct canon_prog p;
    struct check_problem pb;
    canon_prog_init(&p);
    ck_assert(check_machine_interpret(mc, tc_path(swings[_i].prog, pp, sizeof pp), &p, &pb) ==
              CHECK_OK);
    /* line by line, the platform poses of the programmed tips: lines 1..4 as in the file */
    w += sprintf(w, "(platform poses)\n(of the tips)\nG21 G90 G94 G61\nG49\n");
    for (size_t i = 0; i < p.count; i++) {
        const struct canon_cmd *c = &p.cmds[i];
        if (c->type != CANON_FEED && c->type != CANON_TRAVERSE)
            continue;
        double q[6];
        kins_tcp_to_pose(&f, c->tool_len_mm, c->end, q);
        w += sprintf(w, "G%d X%.9f Y%.9f Z%.9f A%.9f B%.9f C%.9f F600\n",
                     c->type == CANON_TRAVERSE ? 0 : 1, q[0], q[1], q[2], q[3], q[4], q[5]);
    }
    w += sprintf(w, "M2\n");
    canon_prog_free(&p);
    char path[] = "/tmp/hexcnc-tcp-XXXXXX";
    int fd = mkstemp(path);
    ck_assert(fd >= 0);
    FILE *fp = fdopen(fd, "w");
    fputs(text, fp);
    fclose(fp);
    struct check_result r;
    check_result_init(&r);
    ck_assert_int_eq(check_program(mc, path, NULL, &r), CHECK_OK);   /* warnings only */
    unlink(path);
    int found = 0;
    double seen = 0;
    ck_assert_uint_eq(r.nproblems, 0);
    ck_assert_uint_gt(r.nwarnings, 0);
    for (size_t i = 0; i < r.nwarnings; i++) {
        const struct check_problem *q = &r.warnings[i];
        ck_assert_int_eq(q->kind, CHECK_TIP_DEVIATION);
        if (q->line == 6) {
            double want = swings[_i].r_mm * (1 - cos(swings[_i].turn_deg / 2 * M_PI / 180));
            printf("%s without G43.4, line 6 (%g deg about the tip): the tip swings %.4f mm "
                   "(by hand %.4f mm)\n", swings[_i].prog, swings[_i].turn_deg, q->value, want);
            ck_assert_msg(fabs(q->value - want) < 0.01 * want, "%.6f vs %.6f", q->value, want);
            ck_assert(strstr(q->message, "G43.4"));
            found = 1;
            seen = q->value;
        }
    }
    ck_assert(found);
    ck_assert(r.max_tip_deviation_mm >= seen);   /* the figure covers the warned line */
    check_result_free(&r);
    check_result_init(&r);
    ck_assert_int_eq(check_program(mc, tc_path(swings[_i].prog, pp, sizeof pp), NULL, &r),
                     CHECK_OK);
    ck_assert(r.tip_measured && r.max_tip_deviation_mm <= r.kin_tol_mm);
    ck_assert_uint_eq(r.nwarnings, 0);
    check_result_free(&r);
    check_machine_close(mc);
}
END_TEST

static Suite *tcp_suite(void)
{
    Suite *s = suite_create("tcp");
    TCase *tc = tcase_create("tcp");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_map_workpiece);
    tcase_add_test(tc, test_map_spindle);
    tcase_add_test(tc, test_interp_switches);
    tcase_add_test(tc, test_interp_program_point_and_length);
    tcase_add_test(tc, test_interp_errors);
    tcase_add_loop_test(tc, test_tip_on_path, 0, 4);
    tcase_add_test(tc, test_tip_on_arc);
    tcase_add_test(tc, test_tip_bound_binds);
    tcase_add_loop_test(tc, test_check_reports_swing, 0, 2);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(tcp_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
