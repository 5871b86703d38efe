/* test_motion_legs.c: leg speed and acceleration limits, and the kinematic-error bound. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_priv.h"
#include "tests/test_motion_util.h"

#define DT 0.001

static const double S0[6] = {-60, -40, 630, -8, 6, -12};
static const double E0[6] = {60, 40, 660, 8, -6, 12};

/* Loads S0 -> E0 at feed_mm_min and starts it. */
static void load_move(struct tm_machine *mc, const double *S, const double *E,
                      double feed_mm_min)
{
    struct canon_prog p;
    canon_prog_init(&p);
    memcpy(p.start, S, 6 * sizeof *S);
    tm_add(&p, CANON_FEED, 8, E, feed_mm_min, 0);
    char err[512] = "";
    ck_assert_msg(motion_load(mc->m, &p, err, sizeof err) == MOTION_OK, "load: %s", err);
    ck_assert_int_eq(motion_start(mc->m), MOTION_OK);
    canon_prog_free(&p);
}

/* Tight legs (20 mm/s, 200 mm/s^2) and a feed of 100 mm/s that would drive some leg far
 * beyond 20 mm/s: no leg ever exceeds its limits, and the busiest leg still gets close to
 * its speed limit (the feed is lowered only as far as needed). */
START_TEST(test_leg_limits_hold)
{
    struct tk_cfg *c = tm_hexapod_cfg();
    ck_assert_ptr_nonnull(c);
    tm_set_legs(c, "20", "200");
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, c, &kins_hexapod_ops), 0);
    /* what the programmed feed would ask of the legs at the middle of the move */
    double mid[6], vel[6], rates[6], worst = 0, len = 0;
    for (int i = 0; i < 3; i++)
        len += (E0[i] - S0[i]) * (E0[i] - S0[i]);
    len = sqrt(len);
    for (int i = 0; i < 6; i++)
        mid[i] = 0.5 * (S0[i] + E0[i]), vel[i] = (E0[i] - S0[i]) / len * 100;
    ck_assert_int_eq(kins_leg_rates(mc.kins, mid, vel, rates), KINS_OK);
    for (int i = 0; i < 6; i++)
        worst = fmax(worst, fabs(rates[i]));
    ck_assert_msg(worst > 40, "the test move is not demanding enough: %.1f mm/s", worst);
    load_move(&mc, S0, E0, 6000);
    struct motion_plan_info info;
    motion_plan_info(mc.m, &info);
    ck_assert_int_gt(info.limited_by_legs, 0);
    struct tm_stats s;
    tm_run(mc.m, DT, 1000000, &s, NULL, NULL);
    ck_assert_int_eq(s.last.state, MOTION_DONE);
    double busiest = 0;
    for (int i = 0; i < 6; i++) {
        ck_assert_msg(s.max_leg_v[i] <= 20, "leg %d at %.4f mm/s", i + 1, s.max_leg_v[i]);
        ck_assert_msg(s.max_cmd_leg_v[i] <= 20, "leg %d rate %.4f", i + 1, s.max_cmd_leg_v[i]);
        ck_assert_msg(s.max_leg_a[i] <= 200 * 1.001, "leg %d at %.2f mm/s^2", i + 1,
                      s.max_leg_a[i]);
        busiest = fmax(busiest, s.max_leg_v[i]);
        ck_assert_double_eq_tol(s.last.pose[i], E0[i], 1e-9);
    }
    ck_assert_msg(busiest > 0.9 * 20, "legs held far below their limit: %.2f mm/s", busiest);
    tm_close(&mc);
}
END_TEST

/* The machine's own legs (100 mm/s) on a move that keeps them well within: the path runs at
 * the programmed feed, not lower. */
START_TEST(test_leg_limits_not_needless)
{
    struct tk_cfg *c = tm_hexapod_cfg();
    ck_assert_ptr_nonnull(c);
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, c, &kins_hexapod_ops), 0);
    load_move(&mc, S0, E0, 1200);
    struct motion_plan_info info;
    motion_plan_info(mc.m, &info);
    ck_assert_int_eq(info.limited_by_legs, 0);
    struct tm_stats s;
    tm_run(mc.m, DT, 1000000, &s, NULL, NULL);
    ck_assert_int_eq(s.last.state, MOTION_DONE);
    ck_assert_msg(s.max_v_mm_s > 20 * (1 - 1e-9) && s.max_v_mm_s <= 20 * (1 + 1e-9),
                  "path speed %.6f, feed 20", s.max_v_mm_s);
    tm_close(&mc);
}
END_TEST

/* The TMU hexapod where the legs bind, with leg-bound G61 program k (tm_leg_bound_points)
 * at F30000 loaded; its points into *pts, their number returned. */
static int load_leg_bound(struct tm_machine *mc, struct canon_prog *p, int k,
                          const double (**pts)[6])
{
    ck_assert_int_eq(tm_open(mc, tm_leg_bound_hexapod_cfg(), &kins_hexapod_ops), 0);
    int n = tm_leg_bound_points(k, pts);
    tm_g61_points(p, *pts, n, 30000);
    char err[512] = "";
    ck_assert_msg(motion_load(mc->m, p, err, sizeof err) == MOTION_OK, "load: %s", err);
    return n;
}

/* Where the legs bind (bench_topp's machine and G61 programs), the planned time is within
 * 4.5 % of the time-optimal one: the TOPP-RA reference bench_topp computes for the same
 * path and limits, 11.5910 s and 6.0341 s (4000 grid intervals per move). Run at the
 * servo rate, no leg passes its limits and the busiest leg uses its acceleration. With
 * the legs lending the path only their fixed 60 % share of acceleration (not what the
 * curvature term leaves at the knot's speed cap, motion_caps.c) the first takes 1.062x. */
START_TEST(test_leg_bound_time_near_optimal)
{
    static const double topp_s[2] = { 11.5910, 6.0341 };
    for (int k = 0; k < 2; k++) {
        struct tm_machine mc;
        struct canon_prog p;
        const double (*pts)[6];
        int n = load_leg_bound(&mc, &p, k, &pts);
        struct motion_plan_info info;
        motion_plan_info(mc.m, &info);
        printf("leg-bound G61 program %d: planned %.4f s, %.4fx the time-optimal %.4f s\n",
               k + 1, info.time_s, info.time_s / topp_s[k], topp_s[k]);
        ck_assert_msg(info.time_s <= 1.045 * topp_s[k], "program %d: %.4f s, %.4fx", k + 1,
                      info.time_s, info.time_s / topp_s[k]);
        ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
        struct tm_stats s;
        tm_run(mc.m, DT, 1000000, &s, NULL, NULL);
        ck_assert_int_eq(s.last.state, MOTION_DONE);
        double busiest = 0;
        for (int i = 0; i < 6; i++) {
            ck_assert_msg(s.max_leg_v[i] <= 40, "leg %d at %.4f mm/s", i + 1, s.max_leg_v[i]);
            ck_assert_msg(s.max_leg_a[i] <= 200 * 1.001, "leg %d at %.2f mm/s^2", i + 1,
                          s.max_leg_a[i]);
            busiest = fmax(busiest, s.max_leg_a[i]);
            ck_assert_double_eq_tol(s.last.pose[i], pts[n - 1][i], 1e-9);
        }
        ck_assert_msg(busiest > 0.95 * 200, "legs held below their acceleration: %.2f mm/s^2",
                      busiest);
        canon_prog_free(&p);
        tm_close(&mc);
    }
}
END_TEST

/* The feed override switched up and down while the legs bind: the rate rises to the plan's
 * ceiling and falls again on ramps, cruises, across knots and on moves leaving rest, and no
 * leg passes its limits in any servo period. The rate was set from the plan at each period's
 * start: a ramp beginning within the period added to a rate change that had already taken
 * the whole acceleration, and on a slow plan the rate moved so far within one period that
 * r^2 a_plan left its start value behind (up to 1.48x the legs' acceleration). */
START_TEST(test_leg_limits_under_changing_override)
{
    static const struct tm_override_walk walks[] = { { 700, 0.6 }, { 37, 0 }, { 250, 0.3 } };
    for (int k = 0; k < 2; k++)
        for (size_t w = 0; w < sizeof walks / sizeof walks[0]; w++) {
            struct tm_machine mc;
            struct canon_prog p;
            const double (*pts)[6];
            int n = load_leg_bound(&mc, &p, k, &pts);
            ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
            struct tm_stats s;
            tm_run(mc.m, DT, 1000000, &s, tm_override_hook, (void *)&walks[w]);
            ck_assert_int_eq(s.last.state, MOTION_DONE);
            for (int i = 0; i < 6; i++) {
                ck_assert_msg(s.max_leg_v[i] <= 40, "program %d, walk %zu: leg %d at %.4f mm/s",
                              k + 1, w, i + 1, s.max_leg_v[i]);
                ck_assert_msg(s.max_leg_a[i] <= 200 * 1.001,
                              "program %d, walk %zu: leg %d at %.2f mm/s^2", k + 1, w, i + 1,
                              s.max_leg_a[i]);
                ck_assert_double_eq_tol(s.last.pose[i], pts[n - 1][i], 1e-9);
            }
            canon_prog_free(&p);
            tm_close(&mc);
        }
}
END_TEST

/* bench_topp_blend's programmed arcs: four half circles of 10 mm radius in a row along X
 * (a G2, a G3, ...), A and B turning to 6 and -4 deg on the first and third and back on the
 * others, G61, at feed F. */
static void four_arcs(struct canon_prog *p, double F)
{
    double at[6] = { -40, 0, 645, 0, 0, 0 };
    static const double up[3] = { 0, 0, 1 };
    canon_prog_init(p);
    p->start_path_mode = 610;
    memcpy(p->start, at, sizeof at);
    for (int i = 0; i < 4; i++) {
        double c3[3] = { at[0] + 10, at[1], at[2] }, to[6];
        memcpy(to, at, sizeof to);
        to[0] += 20;
        to[3] = i % 2 ? 0 : 6, to[4] = i % 2 ? 0 : -4;
        tm_arc(p, i + 2, to, c3, up, i % 2 ? 1 : -1, F);
        memcpy(at, to, sizeof at);
    }
}

/* Programmed arcs where the legs bind (bench_topp_blend's four arcs, no kinematic-error
 * bound): at F30000 the planned time is within 5 % of the time-optimal parameterisation of
 * the same path, 5.0062 s (bench_topp_blend). The planner took 5.3144 s (1.062x) while every
 * ramp had only the acceleration the legs leave at the knot's hard speed cap, not at the
 * ramp's own speed (motion_plan.c). Run at the servo rate at overrides 1 and 2 and with the
 * override switched up and down, at F30000 and at F1200 (where override 2 has room to speed
 * up, so ramps meet cruises that override 2 raises), no leg passes its limits. */
START_TEST(test_leg_bound_arcs_near_optimal)
{
    static const struct tm_override_walk walks[] = { { 0, 1 }, { 0, 2 }, { 37, 0 }, { 700, 0.6 } };
    static const double feeds[2] = { 30000, 1200 };
    for (int f = 0; f < 2; f++) {
        struct tk_cfg *c = tm_leg_bound_hexapod_cfg();
        ck_assert_ptr_nonnull(c);
        tk_set(c, "TRAJ", "KINEMATIC_TOLERANCE", "0");
        struct tm_machine mc;
        ck_assert_int_eq(tm_open(&mc, c, &kins_hexapod_ops), 0);
        struct canon_prog p;
        four_arcs(&p, feeds[f]);
        char err[512] = "";
        for (size_t w = 0; w < sizeof walks / sizeof walks[0]; w++) {
            ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "load: %s",
                          err);
            if (f == 0 && w == 0) {
                struct motion_plan_info info;
                motion_plan_info(mc.m, &info);
                printf("leg-bound arcs: planned %.4f s, %.4fx the time-optimal 5.0062 s\n",
                       info.time_s, info.time_s / 5.0062);
                ck_assert_msg(info.time_s <= 1.05 * 5.0062, "planned %.4f s, %.4fx",
                              info.time_s, info.time_s / 5.0062);
            }
            motion_set_feed_override(mc.m, walks[w].every ? 1 : walks[w].low);
            ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
            struct tm_stats s;
            tm_run(mc.m, DT, 1000000, &s, walks[w].every ? tm_override_hook : NULL,
                   (void *)&walks[w]);
            ck_assert_int_eq(s.last.state, MOTION_DONE);
            for (int i = 0; i < 6; i++) {
                ck_assert_msg(s.max_leg_v[i] <= 40 * (1 + 1e-9),
                              "F%g, run %zu: leg %d at %.4f mm/s", feeds[f], w, i + 1,
                              s.max_leg_v[i]);
                ck_assert_msg(s.max_leg_a[i] <= 200 * (1 + 1e-9),
                              "F%g, run %zu: leg %d at %.3f mm/s^2", feeds[f], w, i + 1,
                              s.max_leg_a[i]);
            }
        }
        canon_prog_free(&p);
        tm_close(&mc);
    }
}
END_TEST

/* Runs S -> E at a fast feed with set points every T; returns the measured deviation. */
static struct tm_dev deviation(const double *S, const double *E, double T, double tol_mm)
{
    struct tk_cfg *c = tm_fast_hexapod_cfg(T, tol_mm);
    ck_assert_ptr_nonnull(c);
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, c, &kins_hexapod_ops), 0);
    load_move(&mc, S, E, 30000);              /* 500 mm/s programmed */
    struct tm_dev d;
    ck_assert_int_eq(tm_deviation(mc.m, mc.kins, S, E, T, &d), 0);
    tm_close(&mc);
    return d;
}

/* The paper's interpolator: with set points at 1 kHz and at 100 Hz, the tool point leaves the
 * programmed line by at most KINEMATIC_TOLERANCE (0.001 mm) and the orientation by at most
 * KINEMATIC_ANGULAR_TOLERANCE (0.001 deg), measured through the forward kinematics of the
 * legs as the drives interpolate them. Without the bound, 100 Hz set points on the same move
 * leave the line by far more. */
START_TEST(test_kinematic_deviation)
{
    static const double moves[2][2][6] = {
        {{-60, -40, 630, -8, 6, -12}, {60, 40, 660, 8, -6, 12}},
        {{80, -90, 660, 10, 0, 15}, {-80, 90, 625, -10, 8, -15}},
    };
    for (int k = 0; k < 2; k++) {
        const double *S = moves[k][0], *E = moves[k][1];
        struct tm_dev fast = deviation(S, E, 0.001, 0.001);
        struct tm_dev slow = deviation(S, E, 0.01, 0.001);
        struct tm_dev off = deviation(S, E, 0.01, 0);
        ck_assert_msg(fast.pos_mm <= 0.001 && fast.ang_deg <= 0.001,
                      "1 kHz: %.6f mm %.6f deg", fast.pos_mm, fast.ang_deg);
        ck_assert_msg(slow.pos_mm <= 0.001 && slow.ang_deg <= 0.001,
                      "100 Hz: %.6f mm %.6f deg", slow.pos_mm, slow.ang_deg);
        ck_assert_msg(off.pos_mm > 0.003, "100 Hz without the bound: only %.6f mm", off.pos_mm);
        ck_assert(slow.time_s > off.time_s);          /* the bound costs time */
        ck_assert_int_gt(fast.setpoints, 100);
    }
}
END_TEST

/* Largest distance of the platform from the helix r = 50 about the Z axis rising 5 mm per
 * half turn, measured as in tm_deviation (forward kinematics of interpolated legs). */
static double helix_deviation(double T, double tol_mm)
{
    struct tk_cfg *c = tm_fast_hexapod_cfg(T, tol_mm);
    ck_assert_ptr_nonnull(c);
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, c, &kins_hexapod_ops), 0);
    struct canon_prog p;
    canon_prog_init(&p);
    double S[6] = {50, 0, 645, 0, 0, 0}, E[6] = {-50, 0, 650, 6, -6, 10};
    double C[3] = {0, 0, 645}, N[3] = {0, 0, 1};
    memcpy(p.start, S, sizeof S);
    tm_arc(&p, 3, E, C, N, 1, 30000);
    char err[512] = "";
    ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "%s", err);
    motion_start(mc.m);
    struct motion_out a, b;
    double worst = 0;
    motion_step(mc.m, T, &a);
    while (a.state != MOTION_DONE) {
        motion_step(mc.m, T, &b);
        double g[6];
        memcpy(g, a.pose, sizeof g);
        for (int j = 1; j < 10; j++) {
            double L[6], P[6];
            for (int i = 0; i < 6; i++)
                L[i] = a.joint_pos[i] + (b.joint_pos[i] - a.joint_pos[i]) * j / 10.0;
            memcpy(P, g, sizeof P);
            ck_assert_int_eq(kins_forward(mc.kins, L, P, NULL), KINS_OK);
            memcpy(g, P, sizeof g);
            double ang = atan2(P[1], P[0]);
            ang = ang < 0 ? ang + 2 * M_PI : ang;
            worst = fmax(worst, hypot(hypot(P[0], P[1]) - 50, P[2] - (645 + 5 * ang / M_PI)));
        }
        a = b;
    }
    canon_prog_free(&p);
    tm_close(&mc);
    return worst;
}

/* The bound holds on a helix turning A B C too (100 Hz set points); without it, no. */
START_TEST(test_kinematic_deviation_helix)
{
    double on = helix_deviation(0.01, 0.001), off = helix_deviation(0.01, 0);
    ck_assert_msg(on <= 0.001, "100 Hz helix: %.6f mm", on);
    ck_assert_msg(off > 0.003, "100 Hz helix without the bound: only %.6f mm", off);
}
END_TEST

/* Plans a helix of `turns` turns about a centre `r_mm` to -X of start (XY plane, 1 mm of Z
 * over all turns); returns motion_load's status with its message in err. */
static int load_helix(struct tm_machine *mc, const double *start, double r_mm, int turns,
                      char *err, size_t errlen)
{
    struct canon_prog p;
    canon_prog_init(&p);
    memcpy(p.start, start, 6 * sizeof *start);
    struct canon_cmd c;
    memset(&c, 0, sizeof c);
    c.type = CANON_ARC;
    c.line = 3;
    c.file = "helix.ngc";
    memcpy(c.end, start, sizeof c.end);
    c.end[2] -= 1.0;
    c.arc.center[0] = start[0] - r_mm;
    c.arc.center[1] = start[1];
    c.arc.center[2] = start[2];
    c.arc.normal[2] = 1;
    c.arc.rotation = -turns;   /* G2 ... P<turns> */
    c.feed_mm_min = 1000;
    ck_assert_int_eq(canon_prog_sink(&p, &c), 0);
    int st = motion_load(mc->m, &p, err, errlen);
    canon_prog_free(&p);
    return st;
}

/* A helix of 20000 turns (G2 I-10 P20000, 1257 m of path) is within reach all along: it is
 * planned, not refused with an impossible leg length. Its knots are capped (4000 per move),
 * so they lie 314 mm apart; the reach check's error term used that spacing and refused the
 * move with leg 1 "1231.725 mm long". */
START_TEST(test_long_helix_is_reachable)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_hexapod_cfg(), &kins_hexapod_ops), 0);
    const double start[6] = {10, 0, 640, 0, 0, 0};
    char err[512] = "";
    ck_assert_msg(load_helix(&mc, start, 10, 20000, err, sizeof err) == MOTION_OK, "%s", err);
    struct motion_plan_info info;
    ck_assert_int_eq(motion_plan_info(mc.m, &info), MOTION_OK);
    ck_assert_double_eq_tol(info.length_mm, 20000 * 2 * M_PI * 10, 1.0);
    tm_close(&mc);
}
END_TEST

/* The other way round: 4000 turns in 4000 intervals put every knot on the same side of the
 * circle, near X-400 where every leg is in range; the far side is out of reach.
 * The samples between the knots find it, with a true leg length. */
START_TEST(test_long_helix_out_of_reach_between_knots)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_hexapod_cfg(), &kins_hexapod_ops), 0);
    const double start[6] = {-400, 0, 640, 0, 0, 0};
    double L[6];
    ck_assert_int_eq(kins_inverse(mc.kins, start, L), KINS_OK);
    char err[512] = "";
    ck_assert_int_eq(load_helix(&mc, start, 50, 4000, err, sizeof err), MOTION_ERR_UNREACHABLE);
    ck_assert_msg(strstr(err, "helix.ngc:3: the move leaves the machine's reach: leg ") != NULL,
                  "%s", err);
    double len = 0;
    const char *at = strstr(err, "would be ");
    ck_assert_ptr_nonnull(at);
    ck_assert_int_eq(sscanf(at, "would be %lf", &len), 1);
    ck_assert_msg(len > 980 && len < 1000, "a leg length the machine could have: %s", err);
    tm_close(&mc);
}
END_TEST

/* The cancel flag (Ctrl-C) stops planning at once: the 20000-turn helix, 2.5 million
 * samples, is dropped with MOTION_ERR_CANCELLED and the file:line; nothing stays loaded. */
START_TEST(test_cancel_stops_planning)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_hexapod_cfg(), &kins_hexapod_ops), 0);
    volatile sig_atomic_t stop = 1;
    motion_set_cancel(mc.m, &stop);
    const double start[6] = {10, 0, 640, 0, 0, 0};
    char err[512] = "";
    ck_assert_int_eq(load_helix(&mc, start, 10, 20000, err, sizeof err), MOTION_ERR_CANCELLED);
    ck_assert_str_eq(err, "helix.ngc:3: planning stopped by the operator");
    struct motion_plan_info info;
    ck_assert_int_ne(motion_plan_info(mc.m, &info), MOTION_OK);
    stop = 0;
    ck_assert_int_eq(load_helix(&mc, start, 10, 2, err, sizeof err), MOTION_OK);
    tm_close(&mc);
}
END_TEST

static bool take_caps_job(void *m)
{
    return motion_caps_help(m);
}

/* The knot caps come in batches of jobs (motion_plan.c): a move out of reach far into a
 * long program (past the first batch, 64 jobs of 128 segments) is refused naming its own
 * line, and of two such moves the first, with or without a thread taking jobs meanwhile. */
START_TEST(test_unreachable_in_a_later_job)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_hexapod_cfg(), &kins_hexapod_ops), 0);
    for (int run = 0; run < 4; run++) {
        struct canon_prog p;
        canon_prog_init(&p);
        double s0[6] = {0, 0, 645, 0, 0, 0}, up[6] = {0, 0, 1000, 0, 0, 0};
        memcpy(p.start, s0, sizeof s0);
        for (int i = 1; i <= 10000; i++) {      /* G61 (no path mode): a segment a move */
            double q[6] = {10 * sin(i * 0.01), 10 * cos(i * 0.01) - 10, 645, 0, 0, 0};
            int bad = i == 9500 || (run % 2 && i == 9900);
            tm_add(&p, CANON_FEED, 10 + i, bad ? up : q, 3000, 0);
        }
        struct tm_helper h;
        if (run >= 2)
            ck_assert_int_eq(tm_helper_start(&h, take_caps_job, mc.m), 0);
        char err[512] = "";
        int st = motion_load(mc.m, &p, err, sizeof err);
        if (run >= 2)
            tm_helper_stop(&h);
        ck_assert_int_eq(st, MOTION_ERR_UNREACHABLE);
        ck_assert_msg(strstr(err, "test.ngc:9510: the move leaves the machine's reach"),
                      "message: %s", err);
        canon_prog_free(&p);
    }
    tm_close(&mc);
}
END_TEST

/* Blend arcs carry few knots (one interval for a turn under 0.25 rad on an arc under 1 mm,
 * motion_path.c): the caps taken at the knots must hold at every point between them. A
 * zigzag of five-axis moves with turns from 0.05 to 1.3 rad, rounded by G64 P of 0.005 to
 * 0.05 mm, on legs of 10 mm/s and 1000 mm/s^2 (so that they, not the path's limits, bind on
 * the arcs): on every interval of every blend arc, sampled at 200 points, the interval's
 * speed (the lower hard cap of its two knots) keeps every leg within its speed and within
 * the curvature's share of its acceleration (on blend arcs 95 %, without the 5 % kept in
 * hand, motion_caps.c), and
 * A B C within their speed. Without the spacing term of the leg caps (|L''| h) a leg runs
 * 0.2 % over its speed here. */
START_TEST(test_blend_arc_knots_conservative)
{
    struct tk_cfg *c = tm_hexapod_cfg();
    ck_assert_ptr_nonnull(c);
    tm_set_legs(c, "10", "1000");
    tk_set(c, "TRAJ", "MAX_LINEAR_VELOCITY", "500");
    tk_set(c, "TRAJ", "MAX_LINEAR_ACCELERATION", "20000");
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, c, &kins_hexapod_ops), 0);
    static const double tols[4] = {0.005, 0.01, 0.02, 0.05};
    int arcs = 0, multi = 0, wide_single = 0, binding = 0, bending = 0;
    for (int t = 0; t < 4; t++) {
        struct canon_prog p;
        canon_prog_init(&p);
        double at[6] = {-20, -10, 640, -3, 2, -4}, dir = 0.3;
        memcpy(p.start, at, sizeof at);
        tm_add(&p, CANON_PATH_MODE, 1, NULL, 0, tols[t]);
        p.cmds[p.count - 1].ivalue = 640;
        for (int k = 0; k < 24; k++) {
            static const double turns[8] = {0.05, 0.12, 0.2, 0.24, 0.4, 0.7, 1.0, 1.3};
            double turn = turns[k % 8] * (k % 2 ? 1 : -1);
            dir += turn;
            at[0] += 4 * cos(dir), at[1] += 4 * sin(dir), at[2] += 0.3 * (k % 3 - 1);
            at[3] += 0.08 * (k % 5 - 2), at[4] -= 0.06 * (k % 3 - 1);
            at[5] += 0.05 * (k % 4 - 1.5);
            tm_add(&p, CANON_FEED, 2 + k, at, 6000, 0);
        }
        char err[512] = "";
        ck_assert_msg(motion_load(mc.m, &p, err, sizeof err) == MOTION_OK, "load: %s", err);
        canon_prog_free(&p);
        struct motion *m = mc.m;
        struct motion_plan *pl = &m->plan;
        for (size_t j = 0; j < pl->nseg; j++) {
            const struct motion_seg *sg = &pl->segs[j];
            if (sg->kind != SEG_ARC || !pl->arcs[sg->arc].abc_cubic)
                continue;
            arcs++;
            multi += sg->nk > 2;
            wide_single += sg->nk == 2 && fabs(pl->arcs[sg->arc].sweep_rad) > 0.2;
            double hs = 0, hard[8] = {0}, cap, acc, acc0;
            ck_assert_uint_le(sg->nk, 8);
            for (size_t k = sg->k0; k + 1 < sg->k0 + sg->nk; k++)
                hs = fmax(hs, pl->ks[k + 1] - pl->ks[k]);
            for (size_t i = 0; i < sg->nk; i++) {
                struct motion_sample S;
                ck_assert_int_eq(motion_knot_caps(m, sg, pl->ks[sg->k0 + i], hs, &S, &hard[i],
                                                  &cap, &acc, &acc0, err, sizeof err),
                                 MOTION_OK);
            }
            for (size_t i = 0; i + 1 < sg->nk; i++) {
                double v = fmin(hard[i], hard[i + 1]), s0 = pl->ks[sg->k0 + i];
                double s1 = pl->ks[sg->k0 + i + 1], worst_v = 0, worst_a = 0;
                for (int q = 0; q <= 200; q++) {
                    double pose[6], dp[6], d2p[6], L[6], dL[6], d2L[6], w = 0;
                    motion_seg_derivs(pl, sg, s0 + (s1 - s0) * q / 200.0, pose, dp, d2p);
                    ck_assert_int_eq(m->kins->ops->inverse_path(m->kins, pose, dp, d2p, L, dL,
                                                                d2L), KINS_OK);
                    for (int l = 0; l < 6; l++) {
                        worst_v = fmax(worst_v, fabs(dL[l]) * v / 10);
                        worst_a = fmax(worst_a, fabs(d2L[l]) * v * v / (0.95 * 1000));
                    }
                    for (int a = 3; a < 6; a++)
                        w = fmax(w, fabs(dp[a]));
                    ck_assert_msg(w * v <= m->cfg.max_ang_vel_deg_s * (1 + 1e-12),
                                  "A B C at %.4f deg/s", w * v);
                }
                ck_assert_msg(worst_v <= 1 + 1e-12 && worst_a <= 1 + 1e-12, "P%.2f line %d "
                              "interval %zu of %zu: leg speed %.5f, curvature acceleration %.5f "
                              "of the limit", tols[t], sg->line, i, sg->nk - 1, worst_v, worst_a);
                binding += worst_v > 0.95;
                bending += worst_a > 0.7;
            }
        }
    }
    /* the test means something: many arcs, some wide ones on one interval, some on several,
     * and the legs' caps bind on many intervals */
    ck_assert_int_ge(arcs, 80);
    ck_assert_int_gt(multi, 10);
    ck_assert_int_gt(wide_single, 5);
    ck_assert_int_gt(binding, 10);
    ck_assert_int_gt(bending, 20);
    tm_close(&mc);
}
END_TEST

static Suite *legs_suite(void)
{
    Suite *s = suite_create("motion_legs");
    TCase *tc = tcase_create("legs");
    tcase_add_test(tc, test_leg_limits_hold);
    tcase_add_test(tc, test_leg_limits_not_needless);
    tcase_add_test(tc, test_leg_bound_time_near_optimal);
    tcase_add_test(tc, test_leg_limits_under_changing_override);
    tcase_add_test(tc, test_leg_bound_arcs_near_optimal);
    tcase_add_test(tc, test_kinematic_deviation);
    tcase_add_test(tc, test_kinematic_deviation_helix);
    tcase_add_test(tc, test_long_helix_is_reachable);
    tcase_add_test(tc, test_long_helix_out_of_reach_between_knots);
    tcase_add_test(tc, test_cancel_stops_planning);
    tcase_add_test(tc, test_unreachable_in_a_later_job);
    tcase_add_test(tc, test_blend_arc_knots_conservative);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(legs_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
