/* test_motion_blend.c: G64 P corner blending: arc geometry, the executed path, speed, G61, the
 * legs (the tool between set points: test_motion_chords.c). */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_blend.h"
#include "tests/test_motion_util.h"

#define DT 0.001
#define TOL 0.05               /* G64 P, mm */

/* The executed path: every period's pose. */
struct run_log {
    double (*pose)[6];
    size_t n, cap;
    double t_s;
    enum motion_state state;
};

/* Runs the started program to its end, logging every period's commanded pose. */
static void run_log(struct motion *m, double dt, struct run_log *r)
{
    struct motion_out o;
    memset(r, 0, sizeof *r);
    for (int k = 0; k < 2000000; k++) {
        motion_step(m, dt, &o);
        if (r->n == r->cap) {
            r->cap = r->cap ? 2 * r->cap : 4096;
            r->pose = realloc(r->pose, r->cap * sizeof *r->pose);
            ck_assert_ptr_nonnull(r->pose);
        }
        memcpy(r->pose[r->n++], o.pose, sizeof o.pose);
        if (o.state == MOTION_DONE || o.state == MOTION_FAULT)
            break;
    }
    r->t_s = o.time_elapsed_s;
    r->state = o.state;
}

static double dist3(const double *a, const double *b)
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

/* Distance from p to the segment a-b (X Y Z). */
static double dist_seg(const double *p, const double *a, const double *b)
{
    double d[3], w[3], dd = 0, u = 0;
    for (int i = 0; i < 3; i++)
        d[i] = b[i] - a[i], w[i] = p[i] - a[i], dd += d[i] * d[i], u += w[i] * d[i];
    u = dd > 0 ? fmin(1, fmax(0, u / dd)) : 0;
    double q[3] = {a[0] + u * d[0], a[1] + u * d[1], a[2] + u * d[2]};
    return dist3(p, q);
}

/* Distance from p to the polyline pts[0..n-1]. */
static double dist_poly(const double *p, const double (*pts)[6], int n)
{
    double best = HUGE_VAL;
    for (int i = 0; i + 1 < n; i++)
        best = fmin(best, dist_seg(p, pts[i], pts[i + 1]));
    return best;
}

/* Lowest XYZ speed (from successive poses) while the path is within `near` mm of c. */
static double min_speed_near(const struct run_log *r, const double *c, double near)
{
    double v = HUGE_VAL;
    for (size_t k = 1; k < r->n; k++)
        if (dist3(r->pose[k], c) < near)
            v = fmin(v, dist3(r->pose[k], r->pose[k - 1]) / DT);
    return v;
}

/* Runs a square corner X0 -> X20 -> X20 Y20 at 600 mm/min in G64 P0.05 or G61. */
static void square_corner(int gcode, struct run_log *r, size_t *blends)
{
    static const double pts[3][6] = {{0, 0, 0, 0, 0, 0}, {20, 0, 0, 0, 0, 0}, {20, 20, 0, 0, 0, 0}};
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
    struct canon_prog p;
    tm_polyline_prog(&p, pts, 3, gcode, gcode == 640 ? TOL : 0, 600);
    tm_load_start(mc.m, &p);
    struct motion_plan_info info;
    motion_plan_info(mc.m, &info);
    *blends = info.blends;
    run_log(mc.m, DT, r);
    ck_assert_int_eq(r->state, MOTION_DONE);
    const double *end = r->pose[r->n - 1];
    ck_assert_double_eq_tol(end[0], 20, 1e-9);
    ck_assert_double_eq_tol(end[1], 20, 1e-9);
    canon_prog_free(&p);
    tm_close(&mc);
}

/* G64 P0.05 on a square corner: the executed path stays within P of the programmed lines,
 * comes within P (not closer than 0.9 P, not further than P) of the corner point, keeps
 * moving through the corner at over half the feed and finishes sooner than G61, which stops
 * at the corner and passes exactly through it. */
START_TEST(test_square_corner)
{
    static const double pts[3][6] = {{0, 0, 0, 0, 0, 0}, {20, 0, 0, 0, 0, 0}, {20, 20, 0, 0, 0, 0}};
    struct run_log g64, g61;
    size_t b64, b61;
    square_corner(640, &g64, &b64);
    square_corner(610, &g61, &b61);
    ck_assert_int_eq(b64, 1);
    ck_assert_int_eq(b61, 0);
    double off = 0, closest = HUGE_VAL, off61 = 0, closest61 = HUGE_VAL;
    for (size_t k = 0; k < g64.n; k++) {
        off = fmax(off, dist_poly(g64.pose[k], pts, 3));
        closest = fmin(closest, dist3(g64.pose[k], pts[1]));
    }
    for (size_t k = 0; k < g61.n; k++) {
        off61 = fmax(off61, dist_poly(g61.pose[k], pts, 3));
        closest61 = fmin(closest61, dist3(g61.pose[k], pts[1]));
    }
    ck_assert_msg(off <= TOL + 1e-9, "G64 P0.05 left the lines by %.9f mm", off);
    /* the arc's midpoint is exactly P from the corner; samples 1 ms apart land near it */
    ck_assert_msg(closest >= TOL - 1e-9 && closest <= 1.01 * TOL, "corner passed at %.9f mm",
                  closest);
    ck_assert_msg(off >= 0.9 * TOL * sqrt(0.5), "lines left by only %.9f mm", off);
    ck_assert_msg(off61 <= 1e-9 && closest61 <= 1e-9, "G61: %.3g mm off, corner at %.3g mm",
                  off61, closest61);
    double v64 = min_speed_near(&g64, pts[1], 0.5), v61 = min_speed_near(&g61, pts[1], 0.5);
    ck_assert_msg(v64 > 0.5 * 10, "G64 P0.05 corner at %.3f mm/s (feed 10)", v64);
    ck_assert_msg(v61 < 0.1 * 10, "G61 did not stop at the corner (%.3f mm/s)", v61);
    ck_assert_msg(g64.t_s < g61.t_s - 0.005, "G64 %.3f s, G61 %.3f s", g64.t_s, g61.t_s);
    printf("square corner, P0.05, 600 mm/min: G64 %.6f mm from the corner, slowest %.3f mm/s, "
           "%.3f s; G61 %.3g mm, slowest %.3f mm/s, %.3f s\n", closest, v64, g64.t_s,
           closest61, v61, g61.t_s);
    free(g64.pose);
    free(g61.pose);
}
END_TEST

/* Two lines turning by turn_deg in a plane tilted out of every axis plane, from P0 through
 * the corner at (5, -3, 2); fills pts. */
static void tilted_corner(double turn_deg, double len_mm, double pts[3][6])
{
    double u[3] = {0.6, 0.48, 0.64}, w[3] = {-0.8, 0.36, 0.48};   /* orthonormal */
    double t = turn_deg * M_PI / 180, c0[3] = {5, -3, 2};
    memset(pts, 0, 3 * sizeof pts[0]);
    for (int i = 0; i < 3; i++) {
        pts[1][i] = c0[i];
        pts[0][i] = c0[i] - len_mm * u[i];
        pts[2][i] = c0[i] + len_mm * (cos(t) * u[i] + sin(t) * w[i]);
    }
}

/* The arc that replaces 30, 90 and 150 degree turns in a tilted plane: tangent to both lines
 * (its direction equals theirs at both ends to 1e-6), radius as derived, its midpoint at P
 * from the corner, start and end P-trimmed line ends; then executed, the direction of motion
 * never turns by more than one period's arc angle between periods (no kink). */
START_TEST(test_arc_geometry)
{
    static const double turns[3] = {30, 90, 150};
    for (int k = 0; k < 3; k++) {
        double pts[3][6];
        tilted_corner(turns[k], 10, pts);
        struct canon_prog p, out;
        tm_polyline_prog(&p, (const double (*)[6])pts, 3, 640, TOL, 600);
        struct motion_config cfg;
        motion_config_default(&cfg);
        size_t nb = 0;
        ck_assert_int_eq(motion_blend_program(&cfg, &p, &out, &nb, NULL), MOTION_OK);
        ck_assert_int_eq(nb, 1);
        ck_assert_int_eq((int)out.count, 4);      /* path mode, line, arc, line */
        const struct canon_cmd *l1 = &out.cmds[1], *a = &out.cmds[2], *l2 = &out.cmds[3];
        ck_assert_int_eq(a->type, CANON_ARC);
        ck_assert_int_eq(a->arc.plane, 0);
        ck_assert_int_eq(a->line, 11);             /* the move it enters */
        double th = turns[k] * M_PI / 180, half = th / 2;
        double r = TOL * cos(half) / (1 - cos(half)), t = r * tan(half);
        double rs[3], re[3], d1[3], d2[3], ts[3], te[3], mid[3], rm = 0;
        for (int i = 0; i < 3; i++) {
            rs[i] = l1->end[i] - a->arc.center[i];
            re[i] = a->end[i] - a->arc.center[i];
            d1[i] = (pts[1][i] - pts[0][i]) / 10;
            d2[i] = (pts[2][i] - pts[1][i]) / 10;
            mid[i] = rs[i] + re[i];
            rm += mid[i] * mid[i];
        }
        ck_assert_double_eq_tol(dist3(l1->end, pts[1]), t, 1e-9);
        ck_assert_double_eq_tol(dist3(a->end, pts[1]), t, 1e-9);
        ck_assert_double_eq_tol(dist3(l2->end, pts[2]), 0, 1e-12);
        ck_assert_double_eq_tol(sqrt(rs[0] * rs[0] + rs[1] * rs[1] + rs[2] * rs[2]), r, 1e-9);
        ck_assert_double_eq_tol(sqrt(re[0] * re[0] + re[1] * re[1] + re[2] * re[2]), r, 1e-9);
        /* tangents of a counter-clockwise arc about n: n x (radius vector) / r */
        const double *n = a->arc.normal;
        ts[0] = n[1] * rs[2] - n[2] * rs[1], ts[1] = n[2] * rs[0] - n[0] * rs[2];
        ts[2] = n[0] * rs[1] - n[1] * rs[0];
        te[0] = n[1] * re[2] - n[2] * re[1], te[1] = n[2] * re[0] - n[0] * re[2];
        te[2] = n[0] * re[1] - n[1] * re[0];
        for (int i = 0; i < 3; i++) {
            ck_assert_double_eq_tol(ts[i] / r, d1[i], 1e-6);
            ck_assert_double_eq_tol(te[i] / r, d2[i], 1e-6);
            mid[i] = a->arc.center[i] + r * mid[i] / sqrt(rm);   /* the arc's midpoint */
        }
        ck_assert_double_eq_tol(dist3(mid, pts[1]), TOL, 1e-9);
        canon_prog_free(&out);

        /* executed: successive chords turn by at most the arc angle of one chord */
        struct tm_machine mc;
        ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
        tm_load_start(mc.m, &p);
        struct run_log rl;
        run_log(mc.m, DT, &rl);
        ck_assert_int_eq(rl.state, MOTION_DONE);
        double kink = 0, prev[3] = {0, 0, 0};
        int have = 0;
        for (size_t s = 1; s < rl.n; s++) {
            double d[3], len = dist3(rl.pose[s], rl.pose[s - 1]);
            if (len < 1e-9)
                continue;
            for (int i = 0; i < 3; i++)
                d[i] = (rl.pose[s][i] - rl.pose[s - 1][i]) / len;
            if (have) {
                double c = fmin(1, prev[0] * d[0] + prev[1] * d[1] + prev[2] * d[2]);
                kink = fmax(kink, acos(c) - len / r);
            }
            memcpy(prev, d, sizeof prev);
            have = 1;
        }
        ck_assert_msg(kink < 1e-3, "%g deg turn: the direction jumps by %.6f rad", turns[k],
                      kink);
        free(rl.pose);
        tm_close(&mc);
        canon_prog_free(&p);
    }
}
END_TEST

/* A zigzag of 0.1 mm steps at 90 degrees: the blends would need 0.12 mm of each line, so
 * they are limited to half a line (0.05 mm): the trims never overlap, the corner is passed
 * closer than P, and the executed path stays within P of the programmed zigzag. */
START_TEST(test_short_segments)
{
    double pts[9][6];
    memset(pts, 0, sizeof pts);
    for (int i = 0; i < 9; i++)
        pts[i][0] = 0.1 * ((i + 1) / 2), pts[i][1] = 0.1 * (i / 2);
    struct canon_prog p, out;
    tm_polyline_prog(&p, (const double (*)[6])pts, 9, 640, TOL, 300);
    struct motion_config cfg;
    motion_config_default(&cfg);
    size_t nb = 0;
    ck_assert_int_eq(motion_blend_program(&cfg, &p, &out, &nb, NULL), MOTION_OK);
    ck_assert_int_eq(nb, 7);
    double at[6];
    memcpy(at, out.start, sizeof at);
    for (size_t i = 1; i < out.count; i++) {
        const struct canon_cmd *c = &out.cmds[i];
        double len = dist3(at, c->end);
        if (c->type == CANON_ARC) {
            double r = dist3(at, c->arc.center);
            ck_assert_double_eq_tol(r, 0.05, 1e-9);            /* t = r at 90 degrees */
            ck_assert_double_eq_tol(dist3(c->end, c->arc.center), r, 1e-9);
        } else {
            ck_assert_msg(len <= 0.1 - 0.05 + 1e-9, "line %zu keeps %.9f mm", i, len);
        }
        memcpy(at, c->end, sizeof at);
    }
    canon_prog_free(&out);
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
    tm_load_start(mc.m, &p);
    struct run_log rl;
    run_log(mc.m, DT, &rl);
    ck_assert_int_eq(rl.state, MOTION_DONE);
    double off = 0, closest = HUGE_VAL;
    for (size_t k = 0; k < rl.n; k++) {
        off = fmax(off, dist_poly(rl.pose[k], (const double (*)[6])pts, 9));
        closest = fmin(closest, dist3(rl.pose[k], pts[4]));
    }
    double dev = 0.05 * (sqrt(2) - 1);          /* r (1 / cos 45 - 1) */
    ck_assert_msg(off < TOL, "left the zigzag by %.6f mm", off);
    ck_assert_msg(closest >= dev - 1e-9 && closest < TOL, "corner passed at %.6f mm", closest);
    ck_assert_double_eq_tol(rl.pose[rl.n - 1][0], 0.4, 1e-9);
    ck_assert_double_eq_tol(rl.pose[rl.n - 1][1], 0.4, 1e-9);
    free(rl.pose);
    tm_close(&mc);
    canon_prog_free(&p);
}
END_TEST

/* A B C change on both lines: along the arc they follow the cubic (in the arc's angle) from
 * the first line's pose at its trim point to the second's whose rates at both ends are the
 * lines' rates, so orientation and its rate per mm of path are continuous: every sample on
 * the arc carries the cubic's A B C, and the rate measured between samples never steps by
 * more than a quarter of the step a corner without the cubic would make. */
START_TEST(test_orientation)
{
    static const double pts[3][6] = {{0, 0, 0, 0, 0, 0}, {10, 0, 0, 10, -4, 2},
                                     {10, 10, 0, 10, 16, -3}};
    struct canon_prog p, out;
    tm_polyline_prog(&p, pts, 3, 640, TOL, 600);
    struct motion_config cfg;
    motion_config_default(&cfg);
    size_t nb = 0;
    struct motion_blend_abc *abc;
    ck_assert_int_eq(motion_blend_program(&cfg, &p, &out, &nb, &abc), MOTION_OK);
    ck_assert_int_eq(nb, 1);
    ck_assert(abc[2].blend && !abc[1].blend && !abc[3].blend);
    double T1[6], T2[6], C[3], r, g1[3], g2[3], step = 0;
    memcpy(T1, out.cmds[1].end, sizeof T1);
    memcpy(T2, out.cmds[2].end, sizeof T2);
    memcpy(C, out.cmds[2].arc.center, sizeof C);
    r = dist3(T1, C);
    double t = 10 - T1[0], L = r * M_PI / 2;   /* trim length; arc length */
    ck_assert_double_eq_tol(T1[3], 10 * (1 - t / 10), 1e-9);   /* first line's pose there */
    ck_assert_double_eq_tol(T2[4], -4 + 20 * t / 10, 1e-9);    /* second line's */
    for (int i = 0; i < 3; i++) {
        g1[i] = pts[1][3 + i] / 10, g2[i] = (pts[2][3 + i] - pts[1][3 + i]) / 10;
        ck_assert_double_eq_tol(abc[2].rate0[i], g1[i], 1e-12);
        ck_assert_double_eq_tol(abc[2].rate1[i], g2[i], 1e-12);
        step = fmax(step, fabs(g2[i] - g1[i]));
    }
    free(abc);
    canon_prog_free(&out);

    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
    tm_load_start(mc.m, &p);
    struct run_log rl;
    run_log(mc.m, DT, &rl);
    ck_assert_int_eq(rl.state, MOTION_DONE);
    int on_arc = 0;
    double jump = 0, prate[3] = {0, 0, 0}, rstep = 0;
    for (size_t k = 1; k < rl.n; k++) {
        const double *q = rl.pose[k], *q0 = rl.pose[k - 1];
        double ds = dist3(q, q0);
        for (int i = 3; i < 6; i++)
            jump = fmax(jump, fabs(q[i] - q0[i]));
        if (ds > 1e-4) {                     /* rate per mm between samples */
            for (int i = 0; i < 3; i++) {
                double rate = (q[3 + i] - q0[3 + i]) / ds;
                if (k > 1)
                    rstep = fmax(rstep, fabs(rate - prate[i]));
                prate[i] = rate;
            }
        }
        if (q[0] <= T1[0] + 1e-12 || q[1] <= 1e-12 || q[1] >= T2[1] - 1e-12)
            continue;                            /* on a line */
        double a0 = atan2(T1[1] - C[1], T1[0] - C[0]), a = atan2(q[1] - C[1], q[0] - C[0]);
        double u = (a - a0) / (M_PI / 2), u2 = u * u, u3 = u2 * u;
        ck_assert_double_eq_tol(hypot(q[0] - C[0], q[1] - C[1]), r, 1e-9);
        for (int i = 0; i < 3; i++) {
            double want = (2 * u3 - 3 * u2 + 1) * T1[3 + i] + (u3 - 2 * u2 + u) * g1[i] * L +
                          (3 * u2 - 2 * u3) * T2[3 + i] + (u3 - u2) * g2[i] * L;
            ck_assert_double_eq_tol(q[3 + i], want, 1e-6);
        }
        on_arc++;
    }
    ck_assert_int_gt(on_arc, 3);
    ck_assert_msg(rstep < 0.25 * step, "A B C rate stepped by %.4f deg/mm (corner: %.4f)",
                  rstep, step);
    /* no step in A B C: within one period at the angular speed limit (90 deg/s) */
    ck_assert_msg(jump <= 90 * DT * (1 + 1e-6), "A B C stepped by %.6f deg", jump);
    free(rl.pose);
    tm_close(&mc);
    canon_prog_free(&p);
}
END_TEST

/* G61 and G64 P0 with a zero BLEND_TOLERANCE make no blend; a G0 corner and a corner after
 * M0 are left sharp even under G64 P. */
START_TEST(test_no_blend)
{
    static const double pts[3][6] = {{0, 0, 0, 0, 0, 0}, {10, 0, 0, 0, 0, 0}, {10, 10, 0, 0, 0, 0}};
    struct motion_config cfg;
    motion_config_default(&cfg);
    struct canon_prog p, out;
    size_t nb = 9;
    tm_polyline_prog(&p, pts, 3, 610, 0, 600);
    ck_assert_int_eq(motion_blend_program(&cfg, &p, &out, &nb, NULL), MOTION_OK);
    ck_assert_int_eq(nb, 0);
    ck_assert_int_eq((int)out.count, 0);
    canon_prog_free(&p);
    tm_polyline_prog(&p, pts, 3, 640, 0, 600);     /* G64 without P: BLEND_TOLERANCE */
    ck_assert_int_eq(motion_blend_program(&cfg, &p, &out, &nb, NULL), MOTION_OK);
    ck_assert_int_eq(nb, 1);
    ck_assert_double_eq_tol(dist3(out.cmds[1].end, pts[1]) * (sqrt(2) - 1), 0.01, 1e-9);
    canon_prog_free(&out);
    cfg.blend_tol_mm = 0;
    ck_assert_int_eq(motion_blend_program(&cfg, &p, &out, &nb, NULL), MOTION_OK);
    ck_assert_int_eq(nb, 0);
    canon_prog_free(&p);
    cfg.blend_tol_mm = 0.01;
    canon_prog_init(&p);
    struct canon_cmd pm = {.type = CANON_PATH_MODE, .line = 1, .value = TOL, .ivalue = 640};
    canon_prog_sink(&p, &pm);
    tm_add(&p, CANON_TRAVERSE, 2, pts[1], 0, 0);
    tm_add(&p, CANON_TRAVERSE, 3, pts[2], 0, 0);
    tm_add(&p, CANON_FEED, 4, pts[0], 600, 0);
    tm_add(&p, CANON_PAUSE, 5, NULL, 0, 0);
    tm_add(&p, CANON_FEED, 6, pts[1], 600, 0);
    ck_assert_int_eq(motion_blend_program(&cfg, &p, &out, &nb, NULL), MOTION_OK);
    ck_assert_int_eq(nb, 0);
    canon_prog_free(&p);
}
END_TEST

/* With jerk limits and half of P below the rounding's share of KINEMATIC_TOLERANCE, a
 * corner whose blend arc would be shorter than the moving average's window is left sharp
 * (motion_blend.c, shorter_than_window: the junction rule passes it); without jerk limits,
 * or with P large enough, the same corner is rounded. A 90-degree corner under P0.001 has
 * an arc of 1.9 um, the window at the arc's fastest (0.26 mm/s, 20 ms) 5 um. */
START_TEST(test_jerk_leaves_short_arcs)
{
    static const double pts[3][6] = {{0, 0, 0, 0, 0, 0}, {10, 0, 0, 0, 0, 0}, {10, 10, 0, 0, 0, 0}};
    struct motion_config cfg;
    motion_config_default(&cfg);
    cfg.kin_tol_mm = 0.001;
    cfg.max_lin_acc_mm_s2 = 500;
    struct canon_prog p, out;
    size_t nb = 9;
    tm_polyline_prog(&p, pts, 3, 640, 0.001, 600);
    ck_assert_int_eq(motion_blend_program(&cfg, &p, &out, &nb, NULL), MOTION_OK);
    ck_assert_int_eq(nb, 1);                      /* no jerk limits: rounded */
    canon_prog_free(&out);
    cfg.max_lin_jerk_mm_s3 = 50000;               /* a 20 ms average */
    ck_assert_double_eq_tol(motion_jerk_window_s(&cfg), 0.02, 1e-12);
    ck_assert_int_eq(motion_blend_program(&cfg, &p, &out, &nb, NULL), MOTION_OK);
    ck_assert_int_eq(nb, 0);                      /* left sharp */
    canon_prog_free(&p);
    tm_polyline_prog(&p, pts, 3, 640, 0.01, 600);    /* P0.01: half of it is the rounding's */
    ck_assert_int_eq(motion_blend_program(&cfg, &p, &out, &nb, NULL), MOTION_OK);
    ck_assert_int_eq(nb, 1);
    canon_prog_free(&out);
    canon_prog_free(&p);
}
END_TEST

/* G93: the trimmed lines and the arc keep the speed of the moves they come from (10 mm in
 * 0.01 min: 16.67 mm/s), measured on the run. */
START_TEST(test_inverse_time)
{
    static const double pts[3][6] = {{0, 0, 0, 0, 0, 0}, {10, 0, 0, 0, 0, 0}, {10, 10, 0, 0, 0, 0}};
    struct canon_prog p;
    tm_polyline_prog(&p, pts, 3, 640, 1.0, 0);
    p.cmds[1].inverse_time_min = p.cmds[2].inverse_time_min = 0.01;
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
    tm_load_start(mc.m, &p);
    struct run_log rl;
    run_log(mc.m, DT, &rl);
    ck_assert_int_eq(rl.state, MOTION_DONE);
    double vmax = 0, vcorner = HUGE_VAL;
    for (size_t k = 1; k < rl.n; k++) {
        double v = dist3(rl.pose[k], rl.pose[k - 1]) / DT;
        vmax = fmax(vmax, v);
        if (dist3(rl.pose[k], pts[1]) < 2.5)    /* on the arc (r 2.41 mm) or next to it */
            vcorner = fmin(vcorner, v);
    }
    ck_assert_double_eq_tol(vmax, 10 / 0.6, 1e-6);
    ck_assert_msg(vcorner > 10 / 0.6 * (1 - 1e-4), "corner at %.4f mm/s", vcorner);
    free(rl.pose);
    tm_close(&mc);
    canon_prog_free(&p);
}
END_TEST

/* The TMU hexapod where the legs bind (bench_topp_blend's machine): legs 40 mm/s and
 * 200 mm/s^2, path 500 mm/s and 5000 mm/s^2, no kinematic-error bound. */
static struct tk_cfg *leg_bound_cfg(void)
{
    struct tk_cfg *c = tm_leg_bound_hexapod_cfg();
    ck_assert_ptr_nonnull(c);
    tk_set(c, "TRAJ", "KINEMATIC_TOLERANCE", "0");
    return c;
}

/* Plans a polygon of n chords (pts: n + 1 poses) at feed F under G64 P tol_mm and runs it
 * at override 1 and 2: the planned time is returned; every leg's speed and acceleration,
 * differenced every servo period, stay within their limits in both runs, and override 2
 * is faster where the feed, not the legs, holds the speed (faster). */
static double polygon_run(const double (*pts)[6], int n, double tol_mm, double F, int faster)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, leg_bound_cfg(), &kins_hexapod_ops), 0);
    struct canon_prog p;
    canon_prog_init(&p);
    p.start_path_mode = 640;
    p.start_path_tol_mm = tol_mm;
    memcpy(p.start, pts[0], sizeof p.start);
    for (int i = 1; i <= n; i++)
        tm_add(&p, CANON_FEED, i + 1, pts[i], F, 0);
    char err[512];
    struct motion_plan_info info;
    double t[2];
    for (int k = 0; k < 2; k++) {
        ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
        motion_plan_info(mc.m, &info);
        ck_assert_int_eq(motion_set_feed_override(mc.m, k ? 2.0 : 1.0), MOTION_OK);
        ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
        struct tm_stats st;
        tm_run(mc.m, DT, (int)(2 * info.time_s / DT) + 1000, &st, NULL, NULL);
        ck_assert_int_eq(st.last.state, MOTION_DONE);
        for (int j = 0; j < 6; j++) {
            ck_assert_msg(st.max_leg_v[j] <= 40 * (1 + 1e-9), "override %d: leg %d at %.4f mm/s",
                          k + 1, j + 1, st.max_leg_v[j]);
            ck_assert_msg(st.max_leg_a[j] <= 200 * (1 + 1e-9),
                          "override %d: leg %d at %.3f mm/s^2", k + 1, j + 1, st.max_leg_a[j]);
        }
        t[k] = st.t_s;
    }
    ck_assert_msg(!faster || t[1] < 0.9 * t[0], "override 2: %.4f s, override 1: %.4f s",
                  t[1], t[0]);
    canon_prog_free(&p);
    tm_close(&mc);
    return info.time_s;
}

/* Blend arcs are crossed at nearly the speed their curvature allows the legs. 24 chords
 * round a tilted circle (bench_topp_blend's polygon, kinks of 15 deg) with P0.01 at F30000:
 * blend arcs of 1.16 mm radius, which the legs' curvature term bounds. The time-optimal
 * parameterisation of the same blended path takes 6.9079 s (bench_topp_blend); with 40 % of
 * the legs' acceleration for the curvature on every arc the planner took 8.620 s (1.248x),
 * now 7.180 s: within 5 % of it. The polygon at F30000 and F600 and a 12-gon of 30 mm radius
 * (P0.01 F3000, P0.1 F1200) keep every leg within its limits at override 1 and 2, where the
 * feed leaves override 2 room to speed up as much as where it does not: before the
 * executor followed the override ceiling a period ahead, override 2 took a leg 5 % over its
 * acceleration limit on the 12-gon with 40 % on the blend arcs' curvature, and 8 % in these
 * runs with the blend arcs' shares. */
START_TEST(test_blend_legs_time_optimal)
{
    enum { NQ = 24 };
    double quad[NQ + 1][6];
    for (int i = 0; i <= NQ; i++) {
        double a = 2 * M_PI * i / NQ;
        double q[6] = { 20 * cos(a) - 20, 20 * sin(a), 645 + 2 * sin(a), 6 * sin(a),
                        6 * cos(a) - 6, 0 };
        memcpy(quad[i], q, sizeof q);
    }
    double t = polygon_run((const double (*)[6])quad, NQ, 0.01, 30000, 0);
    ck_assert_msg(t <= 1.05 * 6.9079, "planned %.4f s, time-optimal 6.9079 s", t);
    polygon_run((const double (*)[6])quad, NQ, 0.01, 600, 1);
    double gon[13][6];
    for (int i = 0; i <= 12; i++) {
        double a = 2 * M_PI * i / 12;
        double q[6] = { 30 * cos(a) - 30, 30 * sin(a), 645, 4 * sin(a), 0, 0 };
        memcpy(gon[i], q, sizeof q);
    }
    polygon_run((const double (*)[6])gon, 12, 0.01, 3000, 0);
    polygon_run((const double (*)[6])gon, 12, 0.1, 1200, 1);
}
END_TEST

static Suite *blend_suite(void)
{
    Suite *s = suite_create("motion_blend");
    TCase *tc = tcase_create("blend");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_square_corner);
    tcase_add_test(tc, test_arc_geometry);
    tcase_add_test(tc, test_short_segments);
    tcase_add_test(tc, test_orientation);
    tcase_add_test(tc, test_no_blend);
    tcase_add_test(tc, test_jerk_leaves_short_arcs);
    tcase_add_test(tc, test_inverse_time);
    tcase_add_test(tc, test_blend_legs_time_optimal);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(blend_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
