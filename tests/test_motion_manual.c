/* test_motion_manual.c: jogs and homing on the motion core, period by period: every leg
 * within its speed, acceleration and length limits (measured by differencing the leg
 * commands), a jog that runs into the workspace edge stopping short of it with a note, an
 * incremental jog landing exactly, and homing on home switches finding an offset the
 * controller cannot see; with jerk limits, all of it within every leg's MAX_JERK too. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/test_motion_util.h"

#define DT 0.001

/* A perfect drive: the feedback is the last motor command; the true leg is that plus a
 * hidden offset, and each leg's switch closes at a true length of SW_AT and beyond. */
struct rig {
    struct tm_machine mc;
    struct motion_out o, prev;
    double hidden[KINS_MAX_JOINTS];
    double sw_at;
    int use_switches;
    /* measured over the run: motor speed, acceleration and jerk, leg lengths */
    double max_v[KINS_MAX_JOINTS], max_a[KINS_MAX_JOINTS], max_j[KINS_MAX_JOINTS];
    double pla[KINS_MAX_JOINTS];         /* last period's acceleration, for the jerk */
    double min_len[KINS_MAX_JOINTS], max_len[KINS_MAX_JOINTS];
    int steps;
};

static void rig_step(struct rig *r, double plv[KINS_MAX_JOINTS])
{
    int nj = r->mc.kins->njoints;
    if (r->use_switches) {
        bool sw[KINS_MAX_JOINTS];
        for (int i = 0; i < nj; i++)
            sw[i] = r->prev.motor_pos[i] + r->hidden[i] >= r->sw_at;
        motion_set_home_switches(r->mc.m, sw);
    }
    motion_feedback(r->mc.m, r->prev.motor_pos);
    motion_step(r->mc.m, DT, &r->o);
    for (int j = 0; j < nj; j++) {
        /* the motor's command is the physical motion (a latch redefines the leg's length,
         * not the motor's position) */
        double lv = (r->o.motor_pos[j] - r->prev.motor_pos[j]) / DT;
        r->max_v[j] = fmax(r->max_v[j], fabs(lv));
        double la = (lv - plv[j]) / DT;
        if (r->steps > 0)
            r->max_a[j] = fmax(r->max_a[j], fabs(la));
        if (r->steps > 1)
            r->max_j[j] = fmax(r->max_j[j], fabs(la - r->pla[j]) / DT);
        r->pla[j] = la;
        r->min_len[j] = fmin(r->min_len[j], r->o.joint_pos[j]);
        r->max_len[j] = fmax(r->max_len[j], r->o.joint_pos[j]);
        plv[j] = lv;
    }
    r->prev = r->o;
    r->steps++;
}

/* Runs until manual motion ends (or max_s of machine time); stop_after_s > 0 sends a
 * jog stop then. Returns the machine time taken. */
static double rig_run(struct rig *r, double max_s, double stop_after_s)
{
    double plv[KINS_MAX_JOINTS] = {0};
    int nj = r->mc.kins->njoints;
    for (int j = 0; j < nj; j++) {
        r->max_v[j] = r->max_a[j] = r->max_j[j] = 0;
        r->min_len[j] = r->max_len[j] = r->prev.joint_pos[j];
    }
    r->steps = 0;
    int n = (int)(max_s / DT);
    for (int k = 0; k < n; k++) {
        if (stop_after_s > 0 && k == (int)(stop_after_s / DT))
            motion_jog_stop(r->mc.m);
        rig_step(r, plv);
        if (motion_get_state(r->mc.m) != MOTION_MANUAL)
            return (k + 1) * DT;
    }
    return max_s;
}

/* Jerk limits for the rig's machine: legs and path (0: none, trapezoidal). */
#define RIG_LEG_JERK 50000.0    /* mm/s^3: the default 20 ms average (the path's 2 x 500 /
                                 * 50000), the motors lowered to 500; 40 ms for their 1000 */
static double rig_jerk;
static double rig_window;      /* s, [TRAJ] JERK_WINDOW with rig_jerk (0: none) */
static double rig_amax = 1000; /* mm/s^2 the motors must keep: 1000, or 500 in a 20 ms window */

/* The TMU hexapod with legs of vmax mm/s and amax mm/s^2 (and rig_jerk); joints homed at
 * once (no switches) unless switches is set, and at its home pose. */
static void rig_open_with(struct rig *r, double vmax, double amax, int switches,
                          const char *sec_, const char *key, const char *val)
{
    memset(r, 0, sizeof *r);
    struct tk_cfg *c = tm_hexapod_cfg();
    ck_assert_ptr_nonnull(c);
    if (sec_)
        tk_set(c, sec_, key, val);
    if (rig_jerk > 0)
        tm_set_jerk(c, rig_jerk, rig_jerk, rig_jerk);
    if (rig_jerk > 0 && rig_window > 0)
        tk_setf(c, "TRAJ", "JERK_WINDOW", rig_window);
    for (int i = 0; i < 6; i++) {
        char sec[24], v[32], a[32];
        snprintf(sec, sizeof sec, "JOINT_%d", i);
        snprintf(v, sizeof v, "%g", vmax);
        snprintf(a, sizeof a, "%g", amax);
        tk_set(c, sec, "MAX_VELOCITY", v);
        tk_set(c, sec, "MAX_ACCELERATION", a);
        if (switches) {
            char seq[16];
            snprintf(seq, sizeof seq, "%d", i / 3);
            tk_set(c, sec, "HOME_SEARCH_VEL", "20");
            tk_set(c, sec, "HOME_LATCH_VEL", "-2");
            tk_set(c, sec, "HOME_OFFSET", "760");
            tk_set(c, sec, "HOME_SEQUENCE", seq);
        }
    }
    ck_assert_int_eq(tm_open(&r->mc, c, &kins_hexapod_ops), 0);
    r->use_switches = switches;
    r->sw_at = 760;
    motion_step(r->mc.m, DT, &r->prev);
}

static void rig_open(struct rig *r, double vmax, double amax, int switches)
{
    rig_open_with(r, vmax, amax, switches, NULL, NULL, NULL);
}

/* Homes every leg; without switches that takes no motion beyond the move to HOME. */
static void rig_home(struct rig *r)
{
    ck_assert_int_eq(motion_home(r->mc.m, -1), MOTION_OK);
    rig_run(r, 120, 0);
    ck_assert_msg(motion_all_homed(r->mc.m), "not homed: %s",
                  motion_manual_note(r->mc.m, NULL));
}

static void assert_legs_within(const struct rig *r, double vmax, double amax, int lengths)
{
    for (int j = 0; j < r->mc.kins->njoints; j++) {
        ck_assert_msg(r->max_v[j] <= vmax * (1 + 1e-6), "leg %d at %.5f mm/s (limit %g)",
                      j + 1, r->max_v[j], vmax);
        ck_assert_msg(r->max_a[j] <= amax * 1.001, "leg %d at %.3f mm/s^2 (limit %g)", j + 1,
                      r->max_a[j], amax);
        ck_assert_msg(!lengths || (r->min_len[j] >= r->mc.kins->joint_min[j] &&
                      r->max_len[j] <= r->mc.kins->joint_max[j]),
                      "leg %d went to %.4f..%.4f, limits %g..%g", j + 1, r->min_len[j],
                      r->max_len[j], r->mc.kins->joint_min[j], r->mc.kins->joint_max[j]);
    }
}

/* Every leg homed, knowing its true length (motor + hidden offset) to within the latch
 * pass's travel in two periods, and the platform at [KINS] HOME. */
static void assert_homed_exactly(const struct rig *r, const double *hidden)
{
    ck_assert_msg(motion_all_homed(r->mc.m), "not homed: %s",
                  motion_manual_note(r->mc.m, NULL));
    for (int j = 0; j < 6; j++) {
        double true_len = r->o.motor_pos[j] + hidden[j];
        ck_assert_msg(fabs(true_len - r->o.joint_pos[j]) <= 2 * DT + 1e-9,
                      "leg %d: thinks %.5f, is %.5f", j + 1, r->o.joint_pos[j], true_len);
    }
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(r->o.pose[i], r->mc.kins->home[i], 1e-9);
}

/* A world X jog asked for 100 mm/s with legs of 20 mm/s and 200 mm/s^2: every leg stays
 * within its limits in every period, and the busiest one gets near its speed limit (the jog
 * is slowed only as far as the legs need). */
START_TEST(test_world_jog_within_leg_limits)
{
    struct rig r;
    rig_open(&r, 20, 200, 0);
    rig_home(&r);
    ck_assert_int_eq(motion_jog(r.mc.m, MOTION_JOG_WORLD, 0, 100, 0), MOTION_OK);
    rig_run(&r, 10, 1.5);
    ck_assert_int_eq(motion_get_state(r.mc.m), MOTION_IDLE);
    assert_legs_within(&r, 20, 200, 1);
    double busiest = 0;
    for (int j = 0; j < 6; j++)
        busiest = fmax(busiest, r.max_v[j]);
    ck_assert_msg(busiest > 0.9 * 20, "legs held far below their limit: %.3f mm/s", busiest);
    ck_assert_msg(r.o.pose[0] > 5, "the jog went nowhere: X %.3f", r.o.pose[0]);
    for (int i = 1; i < 6; i++)
        ck_assert_msg(fabs(r.o.pose[i] - r.mc.kins->home[i]) < 1e-9,
                      "axis %d moved on an X jog: %.12f", i, r.o.pose[i]);
    tm_close(&r.mc);
}
END_TEST

/* An A (rotary) jog and a tool-frame jog keep the same limits. */
START_TEST(test_rotary_and_tool_jog_within_leg_limits)
{
    struct rig r;
    rig_open(&r, 20, 200, 0);
    rig_home(&r);
    ck_assert_int_eq(motion_jog(r.mc.m, MOTION_JOG_WORLD, 3, 30, 8), MOTION_OK);
    rig_run(&r, 20, 0);
    assert_legs_within(&r, 20, 200, 1);
    ck_assert_double_eq_tol(r.o.pose[3], r.mc.kins->home[3] + 8, 1e-9);
    ck_assert_int_eq(motion_jog(r.mc.m, MOTION_JOG_TOOL, 2, -50, 20), MOTION_OK);
    rig_run(&r, 20, 0);
    assert_legs_within(&r, 20, 200, 1);
    /* 20 mm along the tool's axis, which A+8 tilted out of Z */
    double dz = r.o.pose[2] - r.mc.kins->home[2], dy = r.o.pose[1] - r.mc.kins->home[1];
    ck_assert_double_eq_tol(sqrt(dz * dz + dy * dy), 20, 1e-6);
    ck_assert_msg(fabs(dy) > 1, "a tool jog along a tilted tool went straight down (dy %g)",
                  dy);
    tm_close(&r.mc);
}
END_TEST

/* An incremental jog lands exactly where it was sent. */
START_TEST(test_incremental_jog_exact)
{
    struct rig r;
    rig_open(&r, 100, 1000, 0);
    rig_home(&r);
    double y0 = r.o.pose[1];
    ck_assert_int_eq(motion_jog(r.mc.m, MOTION_JOG_WORLD, 1, -25, 12.5), MOTION_OK);
    rig_run(&r, 10, 0);
    ck_assert_int_eq(motion_get_state(r.mc.m), MOTION_IDLE);
    ck_assert_double_eq_tol(r.o.pose[1], y0 - 12.5, 1e-9);
    tm_close(&r.mc);
}
END_TEST

/* A continuous Z jog up runs into the workspace edge: it stops by itself, no leg ever
 * passes its limit, it stops close to the edge (a leg within 1 mm of its limit), and the
 * note says why. */
START_TEST(test_jog_stops_at_workspace_edge)
{
    struct rig r;
    rig_open(&r, 100, 1000, 0);
    rig_home(&r);
    unsigned seq0, seq1;
    motion_manual_note(r.mc.m, &seq0);
    ck_assert_int_eq(motion_jog(r.mc.m, MOTION_JOG_WORLD, 2, 80, 0), MOTION_OK);
    double t = rig_run(&r, 60, 0);
    ck_assert_msg(t < 60, "the jog never stopped");
    ck_assert_int_eq(motion_get_state(r.mc.m), MOTION_IDLE);
    assert_legs_within(&r, 100, 1000, 1);
    double closest = 1e9;
    for (int j = 0; j < 6; j++)
        closest = fmin(closest, fmin(r.max_len[j] - r.mc.kins->joint_min[j],
                                     r.mc.kins->joint_max[j] - r.max_len[j]));
    ck_assert_msg(closest < 1.0, "stopped %.3f mm short of the nearest limit", closest);
    const char *note = motion_manual_note(r.mc.m, &seq1);
    ck_assert_uint_ne(seq0, seq1);
    ck_assert_msg(strstr(note, "edge of the reachable workspace"), "note: %s", note);
    /* the way back is open */
    ck_assert_int_eq(motion_jog(r.mc.m, MOTION_JOG_WORLD, 2, -80, 10), MOTION_OK);
    rig_run(&r, 10, 0);
    ck_assert_int_eq(motion_get_state(r.mc.m), MOTION_IDLE);
    tm_close(&r.mc);
}
END_TEST

/* A jog into a soft limit of the pose ([AXIS_X] MAX_LIMIT) stops at it, and the note names
 * the limit as kins_describe() words it. */
START_TEST(test_jog_stops_at_soft_limit)
{
    struct rig r;
    rig_open_with(&r, 100, 1000, 0, "AXIS_X", "MAX_LIMIT", "50");
    rig_home(&r);
    ck_assert_int_eq(motion_jog(r.mc.m, MOTION_JOG_WORLD, 0, 20, 0), MOTION_OK);
    double t = rig_run(&r, 60, 0);
    ck_assert_msg(t < 60, "the jog never stopped");
    const double *pose = r.o.pose;   /* the last commanded pose */
    ck_assert_msg(pose[0] <= 50.0 && pose[0] > 49.0, "stopped at X%.4f", pose[0]);
    const char *note = motion_manual_note(r.mc.m, NULL);
    ck_assert_msg(strstr(note, "jog stopped at the workspace edge: X50.0") &&
                  strstr(note, "above [AXIS_X] MAX_LIMIT = 50"), "note: %s", note);
    tm_close(&r.mc);
}
END_TEST

/* World jogs need homed legs; a leg jog does not. */
START_TEST(test_world_jog_needs_homing)
{
    struct rig r;
    rig_open(&r, 100, 1000, 1);
    ck_assert_int_ne(motion_jog(r.mc.m, MOTION_JOG_WORLD, 0, 10, 0), MOTION_OK);
    double l0 = r.prev.joint_pos[4];
    ck_assert_int_eq(motion_jog(r.mc.m, MOTION_JOG_JOINT, 4, -10, 5), MOTION_OK);
    rig_run(&r, 10, 0);
    ck_assert_double_eq_tol(r.o.joint_pos[4], l0 - 5, 1e-9);
    tm_close(&r.mc);
}
END_TEST

/* Homing on switches: the legs' true lengths are their motor positions plus offsets the
 * controller cannot see; after homing each leg's length is its true length to within the
 * distance the latch moves in one period, two groups of three legs moved in turn, and the
 * platform ends at the kinematics' home pose, the legs within their limits throughout. */
START_TEST(test_homing_with_switches_finds_offsets)
{
    static const double hidden[6] = {3.7, -5.2, 1.1, -0.4, 6.3, -2.9};
    struct rig r;
    rig_open(&r, 100, 1000, 1);
    memcpy(r.hidden, hidden, sizeof hidden);
    ck_assert(!motion_all_homed(r.mc.m));
    ck_assert_int_eq(motion_home(r.mc.m, -1), MOTION_OK);
    /* the second group waits while the first homes */
    double plv[KINS_MAX_JOINTS] = {0};
    for (int k = 0; k < 200; k++)
        rig_step(&r, plv);
    for (int j = 3; j < 6; j++)
        ck_assert_msg(fabs(r.o.joint_pos[j] - r.prev.joint_pos[j]) < 1e-12 &&
                      r.max_v[j] == 0, "leg %d of group 1 moved with group 0", j + 1);
    ck_assert_msg(r.max_v[0] > 1, "group 0 did not start");
    rig_run(&r, 200, 0);
    /* speeds and accelerations of the motors; lengths are unknown until each latch */
    assert_legs_within(&r, 100, 1000, 0);
    assert_homed_exactly(&r, hidden);
    tm_close(&r.mc);
}
END_TEST

/* The largest motor jerk of the last run, over the legs. */
static double rig_peak_jerk(const struct rig *r)
{
    double j = 0;
    for (int i = 0; i < r->mc.kins->njoints; i++)
        j = fmax(j, r->max_j[i]);
    return j;
}

/* Runs manual motion to its end and asserts every motor within 100 mm/s, rig_amax mm/s^2
 * and (with jerk limits) RIG_LEG_JERK in every period; returns the run's peak jerk. */
static double rig_run_limited(struct rig *r, const char *what)
{
    double t = rig_run(r, 200, 0);
    ck_assert_msg(motion_get_state(r->mc.m) == MOTION_IDLE, "%s: not over in %.3f s", what, t);
    assert_legs_within(r, 100, rig_amax, 0);
    double pj = rig_peak_jerk(r);
    ck_assert_msg(rig_jerk == 0 || pj <= RIG_LEG_JERK * (1 + 1e-6),
                  "%s: a motor at %.1f mm/s^3 (MAX_JERK %g)", what, pj, RIG_LEG_JERK);
    return pj;
}

/* With jerk limits, homing on switches and every kind of jog keep each motor within its
 * MAX_JERK in every period (manual motion follows the same moving average as a program);
 * each still ends exactly where it was sent, the latch still finds the hidden offsets, and
 * the machine is idle only once the average has settled there. Without jerk limits the same
 * moves reach 20 times MAX_JERK (a trapezoid's acceleration steps in one period):
 * the measurement sees it. Manual motion was trapezoidal under jerk limits before. Run 1
 * has the default 20 ms window: the motors within 500 mm/s^2 as well; run 2 [TRAJ]
 * JERK_WINDOW 0.040, the full window. */
START_TEST(test_manual_jerk_limited)
{
    static const double hidden[6] = {3.7, -5.2, 1.1, -0.4, 6.3, -2.9};
    double peak[3] = {0, 0, 0};
    for (int jerk = 0; jerk < 3; jerk++) {
        rig_jerk = jerk ? RIG_LEG_JERK : 0;
        rig_window = jerk == 2 ? 0.040 : 0;
        rig_amax = jerk == 1 ? 500 : 1000;
        struct rig r;
        rig_open(&r, 100, 1000, 1);
        memcpy(r.hidden, hidden, sizeof hidden);
        ck_assert_int_eq(motion_home(r.mc.m, -1), MOTION_OK);
        peak[jerk] = fmax(peak[jerk], rig_run_limited(&r, "homing"));
        assert_homed_exactly(&r, hidden);
        /* incremental world jog: exact, in the period the machine becomes idle */
        double y0 = r.o.pose[1];
        ck_assert_int_eq(motion_jog(r.mc.m, MOTION_JOG_WORLD, 1, -25, 12.5), MOTION_OK);
        peak[jerk] = fmax(peak[jerk], rig_run_limited(&r, "Y jog"));
        ck_assert_double_eq_tol(r.o.pose[1], y0 - 12.5, 1e-9);
        /* a continuous jog stopped after 0.7 s, and changed on the way */
        ck_assert_int_eq(motion_jog(r.mc.m, MOTION_JOG_WORLD, 0, 80, 0), MOTION_OK);
        double plv[KINS_MAX_JOINTS] = {0};
        for (int k = 0; k < 300; k++)
            rig_step(&r, plv);
        ck_assert_int_eq(motion_jog(r.mc.m, MOTION_JOG_WORLD, 0, 30, 0), MOTION_OK);
        double t = rig_run(&r, 200, 0.4);
        ck_assert_int_eq(motion_get_state(r.mc.m), MOTION_IDLE);
        assert_legs_within(&r, 100, rig_amax, 0);
        ck_assert_msg(jerk == 0 || rig_peak_jerk(&r) <= RIG_LEG_JERK * (1 + 1e-6),
                      "X jog: %.1f mm/s^3 after %.3f s", rig_peak_jerk(&r), t);
        double at[6];
        memcpy(at, r.o.pose, sizeof at);
        for (int k = 0; k < 50; k++)
            rig_step(&r, plv);
        for (int i = 0; i < 6; i++)
            ck_assert_msg(fabs(r.o.pose[i] - at[i]) < 1e-12, "axis %d moved on after idle", i);
        /* a rotary jog, a tool jog and a leg jog, each exact */
        ck_assert_int_eq(motion_jog(r.mc.m, MOTION_JOG_WORLD, 4, -20, 3), MOTION_OK);
        peak[jerk] = fmax(peak[jerk], rig_run_limited(&r, "B jog"));
        ck_assert_double_eq_tol(r.o.pose[4], at[4] - 3, 1e-9);
        double z0 = r.o.pose[2];
        ck_assert_int_eq(motion_jog(r.mc.m, MOTION_JOG_TOOL, 0, 40, 4), MOTION_OK);
        peak[jerk] = fmax(peak[jerk], rig_run_limited(&r, "tool jog"));
        ck_assert_msg(fabs(r.o.pose[2] - z0) > 0.05, "a tool X jog with B-3 kept Z");
        double L2 = r.o.joint_pos[2];
        ck_assert_int_eq(motion_jog(r.mc.m, MOTION_JOG_JOINT, 2, 10, 2), MOTION_OK);
        peak[jerk] = fmax(peak[jerk], rig_run_limited(&r, "leg jog"));
        ck_assert_double_eq_tol(r.o.joint_pos[2], L2 + 2, 1e-9);
        tm_close(&r.mc);
    }
    rig_jerk = 0, rig_window = 0, rig_amax = 1000;
    printf("manual motion, peak motor jerk: %.0f mm/s^3 trapezoidal, %.0f jerk-limited (the "
           "default 20 ms window), %.0f with JERK_WINDOW 0.040 (MAX_JERK %.0f)\n", peak[0],
           peak[1], peak[2],
           RIG_LEG_JERK);
    ck_assert_msg(peak[0] > 10 * RIG_LEG_JERK, "the trapezoid's jerk %.0f", peak[0]);
}
END_TEST

static Suite *motion_manual_suite(void)
{
    Suite *s = suite_create("motion_manual");
    TCase *tc = tcase_create("manual");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_world_jog_within_leg_limits);
    tcase_add_test(tc, test_rotary_and_tool_jog_within_leg_limits);
    tcase_add_test(tc, test_incremental_jog_exact);
    tcase_add_test(tc, test_jog_stops_at_workspace_edge);
    tcase_add_test(tc, test_jog_stops_at_soft_limit);
    tcase_add_test(tc, test_world_jog_needs_homing);
    tcase_add_test(tc, test_homing_with_switches_finds_offsets);
    tcase_add_test(tc, test_manual_jerk_limited);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(motion_manual_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
