/* test_kins.c: hexapod kinematics: hand-worked home, round trips, rates, failures, frames. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kins/hexapod.h"
#include "kins/kins.h"
#include "tests/test_kins_util.h"

#define DEG (M_PI / 180.0)

/* Creates a hexapod from a table, failing the test with the model's message. */
static struct kins *make_kins(struct tk_cfg *c)
{
    struct kins_config cfg = tk_config(c);
    struct kins *k = NULL;
    char err[512] = "";
    int st = kins_create(&kins_hexapod_ops, &cfg, &k, err, sizeof err);
    ck_assert_msg(st == KINS_OK, "create failed: %s (%s)", err, kins_strerror(st));
    return k;
}

/* The machine's own configuration file. */
static struct kins *make_tmu(void)
{
    struct tk_cfg *c = tk_ini("configs/sim/tmu-hexapod.ini");
    ck_assert_msg(c != NULL, "cannot read configs/sim/tmu-hexapod.ini (HEXCNC_ROOT?)");
    struct kins *k = make_kins(c);
    free(c);
    return k;
}

/* At the level, centred pose every leg spans the same triangle: base joint at radius rb and
 * angle hb, platform joint at radius rp and angle 60 - hp, height z. Law of cosines:
 * L^2 = rb^2 + rp^2 - 2 rb rp cos(60 - hb - hp) + z^2. With rb 500, rp 300, hb = hp = 10,
 * z 645: 250000 + 90000 - 300000 cos 40 deg + 416025. */
START_TEST(test_home_by_hand)
{
    struct tk_cfg *c = tk_hexapod(500, 300, 10, 10, 520, 980);
    struct kins *k = make_kins(c);
    double expect = sqrt(250000.0 + 90000.0 - 300000.0 * cos(40.0 * DEG) + 645.0 * 645.0);
    double pose[6] = { 0, 0, 645, 0, 0, 0 }, legs[6];
    ck_assert_int_eq(kins_inverse(k, pose, legs), KINS_OK);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(legs[i], expect, 1e-9);
    /* The same machine given by explicit joint coordinates gives the same legs. */
    struct tk_cfg *e = tk_hexapod(500, 300, 10, 10, 520, 980);
    const double bdeg[6] = { 10, 110, 130, 230, 250, 350 }, pdeg[6] = { 50, 70, 170, 190,
                                                                        290, 310 };
    for (int i = 0; i < 6; i++) {
        char key[24], val[128];
        snprintf(key, sizeof key, "BASE_%d", i);
        snprintf(val, sizeof val, "%.17g %.17g 0", 500 * cos(bdeg[i] * DEG),
                 500 * sin(bdeg[i] * DEG));
        tk_set(e, "KINS", key, val);
        snprintf(key, sizeof key, "PLATFORM_%d", i);
        snprintf(val, sizeof val, "%.17g, %.17g, 0", 300 * cos(pdeg[i] * DEG),
                 300 * sin(pdeg[i] * DEG));
        tk_set(e, "KINS", key, val);
    }
    tk_set(e, "KINS", "BASE_RADIUS", NULL);
    struct kins *k2 = make_kins(e);
    double legs2[6];
    ck_assert_int_eq(kins_inverse(k2, pose, legs2), KINS_OK);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(legs2[i], expect, 1e-9);
    /* A pure lift of 10 mm: every leg grows to sqrt(d^2 + 655^2). */
    double d2 = expect * expect - 645.0 * 645.0;
    pose[KINS_Z] = 655;
    ck_assert_int_eq(kins_inverse(k, pose, legs), KINS_OK);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(legs[i], sqrt(d2 + 655.0 * 655.0), 1e-9);
    kins_free(k);
    kins_free(k2);
    free(c);
    free(e);
}
END_TEST

/* Largest pose difference: mm for X Y Z, deg for A B C. */
static void pose_err(const double *a, const double *b, double *pos_mm, double *ang_deg)
{
    *pos_mm = 0.0;
    *ang_deg = 0.0;
    for (int j = 0; j < 3; j++) {
        *pos_mm = fmax(*pos_mm, fabs(a[j] - b[j]));
        *ang_deg = fmax(*ang_deg, fabs(a[j + 3] - b[j + 3]));
    }
}

/* 10,000 random poses over the working region: inverse then forward from home (cold) and
 * from a start 0.05 mm / 0.01 deg away (warm) must give the pose back to 1e-9. */
START_TEST(test_round_trip)
{
    struct kins *k = make_tmu();
    uint64_t rng = 12345;
    double worst_pos = 0, worst_ang = 0;
    int max_cold = 0, max_warm = 0;
    for (int n = 0; n < 10000; n++) {
        double pose[6], legs[6], back[6], ep, ea;
        struct kins_fwd_info info;
        tk_rand_pose(&rng, pose);
        ck_assert_int_eq(kins_inverse(k, pose, legs), KINS_OK);
        memcpy(back, k->home, sizeof back);
        ck_assert_int_eq(kins_forward(k, legs, back, &info), KINS_OK);
        pose_err(pose, back, &ep, &ea);
        worst_pos = fmax(worst_pos, ep);
        worst_ang = fmax(worst_ang, ea);
        max_cold = info.iterations > max_cold ? info.iterations : max_cold;
        for (int j = 0; j < 6; j++)
            back[j] = pose[j] + tk_rand(&rng, -1, 1) * (j < 3 ? 0.05 : 0.01);
        ck_assert_int_eq(kins_forward(k, legs, back, &info), KINS_OK);
        pose_err(pose, back, &ep, &ea);
        worst_pos = fmax(worst_pos, ep);
        worst_ang = fmax(worst_ang, ea);
        max_warm = info.iterations > max_warm ? info.iterations : max_warm;
    }
    ck_assert_msg(worst_pos <= 1e-9, "position error %.3g mm", worst_pos);
    ck_assert_msg(worst_ang <= 1e-9, "angle error %.3g deg", worst_ang);
    ck_assert_int_le(max_cold, 20);
    ck_assert_int_le(max_warm, 3);
    kins_free(k);
}
END_TEST

/* forward_near: from a start within 1e-7 mm of the answer (a check's mid-chord deviation) one
 * Newton step ends the solve and gives the pose kins_forward gives to within 1e-12 mm and
 * deg; from 0.05 mm away the first step is too long to stop at, and the solve goes on to
 * the pose within 1e-9 as forward does (a model without the entry: test_trivial_static). */
START_TEST(test_forward_near)
{
    struct kins *k = make_tmu();
    uint64_t rng = 777;
    double worst_pos = 0, worst_ang = 0;
    for (int n = 0; n < 2000; n++) {
        double pose[6], legs[6], full[6], near[6], far[6], ep, ea;
        struct kins_fwd_info info;
        tk_rand_pose(&rng, pose);
        ck_assert_int_eq(kins_inverse(k, pose, legs), KINS_OK);
        for (int j = 0; j < 6; j++) {
            near[j] = pose[j] + tk_rand(&rng, -1, 1) * 1e-7;
            far[j] = pose[j] + tk_rand(&rng, -1, 1) * (j < 3 ? 0.05 : 0.01);
        }
        memcpy(full, near, sizeof full);
        ck_assert_int_eq(kins_forward(k, legs, full, &info), KINS_OK);
        ck_assert_int_eq(info.iterations, 1);     /* (forward checks its step once more) */
        ck_assert_int_eq(kins_forward_near(k, legs, near, 1e-6, &info), KINS_OK);
        ck_assert_int_eq(info.iterations, 1);
        pose_err(full, near, &ep, &ea);
        worst_pos = fmax(worst_pos, ep);
        worst_ang = fmax(worst_ang, ea);
        ck_assert_int_eq(kins_forward_near(k, legs, far, 1e-6, &info), KINS_OK);
        ck_assert_int_ge(info.iterations, 2);
        pose_err(pose, far, &ep, &ea);
        ck_assert(ep <= 1e-9 && ea <= 1e-9);
    }
    ck_assert_msg(worst_pos <= 1e-12 && worst_ang <= 1e-12, "%.3g mm, %.3g deg from forward's",
                  worst_pos, worst_ang);
    kins_free(k);
}
END_TEST

/* Explicit, irregular joints with per-leg offsets: joint value = joint-centre distance -
 * offset (checked against the distance computed by hand), and inverse then forward gives
 * the pose back to 1e-9 over the working region. */
START_TEST(test_offsets_round_trip)
{
    struct tk_cfg *c = tk_ini("configs/sim/tmu-hexapod.ini");
    ck_assert_ptr_nonnull(c);
    struct kins *nominal = make_kins(c);
    static const double off[6] = { 0.7, -0.4, 1.3, -0.9, 0.25, -1.1 };
    uint64_t rng = 777;
    double b[6][3], p[6][3];
    char key[24], val[160];
    for (int i = 0; i < 6; i++) {
        double ang_b = (i / 2) * 120.0 + (i % 2 ? 110.0 : 10.0);
        double ang_p = (i / 2) * 120.0 + (i % 2 ? 70.0 : 50.0);
        for (int j = 0; j < 3; j++) {
            b[i][j] = (j == 2 ? 0.0 : 500.0 * (j ? sin(ang_b * DEG) : cos(ang_b * DEG))) +
                      tk_rand(&rng, -0.5, 0.5);
            p[i][j] = (j == 2 ? 0.0 : 300.0 * (j ? sin(ang_p * DEG) : cos(ang_p * DEG))) +
                      tk_rand(&rng, -0.5, 0.5);
        }
        snprintf(key, sizeof key, "BASE_%d", i);
        snprintf(val, sizeof val, "%.17g %.17g %.17g", b[i][0], b[i][1], b[i][2]);
        tk_set(c, "KINS", key, val);
        snprintf(key, sizeof key, "PLATFORM_%d", i);
        snprintf(val, sizeof val, "%.17g %.17g %.17g", p[i][0], p[i][1], p[i][2]);
        tk_set(c, "KINS", key, val);
    }
    tk_set(c, "KINS", "LEG_OFFSET", "0.7 -0.4 1.3 -0.9 0.25 -1.1");
    struct kins *k = make_kins(c);
    double worst = 0, legs_nom[6];
    for (int n = 0; n < 2000; n++) {
        double pose[6], legs[6], back[6], ep, ea, r[3][3];
        tk_rand_pose(&rng, pose);
        ck_assert_int_eq(kins_inverse(k, pose, legs), KINS_OK);
        ck_assert_int_eq(kins_inverse(nominal, pose, legs_nom), KINS_OK);
        double ca = cos(pose[3] * DEG), sa = sin(pose[3] * DEG), cb = cos(pose[4] * DEG);
        double sb = sin(pose[4] * DEG), cc = cos(pose[5] * DEG), sc = sin(pose[5] * DEG);
        double rr[3][3] = { { cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa },
                            { sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa },
                            { -sb, cb * sa, cb * ca } };
        memcpy(r, rr, sizeof r);
        for (int i = 0; i < 6; i++) {
            double d2 = 0;
            for (int j = 0; j < 3; j++) {
                double v = pose[j] + r[j][0] * p[i][0] + r[j][1] * p[i][1] +
                           r[j][2] * p[i][2] - b[i][j];
                d2 += v * v;
            }
            ck_assert_double_eq_tol(legs[i] + off[i], sqrt(d2), 1e-9);
        }
        memcpy(back, k->home, sizeof back);
        ck_assert_int_eq(kins_forward(k, legs, back, NULL), KINS_OK);
        pose_err(pose, back, &ep, &ea);
        worst = fmax(worst, fmax(ep, ea));
    }
    ck_assert_msg(worst <= 1e-9, "round trip error %.3g", worst);
    /* An offset moves the forward pose: the nominal model given the offset model's legs
     * lands elsewhere (by about the offsets' size). */
    double pose0[6] = { 10, -20, 640, 2, -3, 4 }, legs[6], back[6];
    ck_assert_int_eq(kins_inverse(k, pose0, legs), KINS_OK);
    memcpy(back, nominal->home, sizeof back);
    ck_assert_int_eq(kins_forward(nominal, legs, back, NULL), KINS_OK);
    double ep, ea;
    pose_err(pose0, back, &ep, &ea);
    ck_assert_msg(ep > 0.1, "offsets changed nothing (%.3g mm)", ep);
    tk_set(c, "KINS", "LEG_OFFSET", "1 2 3");
    char err[256] = "";
    struct kins_config cfg = tk_config(c);
    struct kins *bad = NULL;
    ck_assert_int_eq(kins_create(&kins_hexapod_ops, &cfg, &bad, err, sizeof err),
                     KINS_ERR_CONFIG);
    ck_assert_msg(strstr(err, "[KINS] LEG_OFFSET") != NULL, "%s", err);
    kins_free(k);
    kins_free(nominal);
    free(c);
}
END_TEST

/* Leg rates through the Jacobian equal a central difference of the inverse. */
START_TEST(test_leg_rates)
{
    struct kins *k = make_tmu();
    uint64_t rng = 777;
    for (int n = 0; n < 500; n++) {
        double pose[6], vel[6], rates[6], lp[6], lm[6], pp[6], pm[6];
        const double h = 1e-3; /* s */
        tk_rand_pose(&rng, pose);
        for (int j = 0; j < 6; j++)
            vel[j] = tk_rand(&rng, -1, 1) * (j < 3 ? 50.0 : 5.0); /* mm/s, deg/s */
        ck_assert_int_eq(kins_leg_rates(k, pose, vel, rates), KINS_OK);
        for (int j = 0; j < 6; j++) {
            pp[j] = pose[j] + h * vel[j];
            pm[j] = pose[j] - h * vel[j];
        }
        kins_inverse(k, pp, lp);
        kins_inverse(k, pm, lm);
        for (int i = 0; i < 6; i++)
            ck_assert_double_eq_tol(rates[i], (lp[i] - lm[i]) / (2 * h), 1e-5);
    }
    kins_free(k);
}
END_TEST

/* The servo thread's combined call gives exactly what inverse and leg rates give apart (the
 * hexapod evaluates the pose once; the trivial model's fallback runs in the motion tests);
 * out of range it reports unreachable with the lengths written, like inverse. */
START_TEST(test_inverse_rates)
{
    struct kins *k = make_tmu();
    ck_assert_ptr_nonnull(k->ops->inverse_rates);
    uint64_t rng = 4242;
    for (int n = 0; n < 500; n++) {
        double pose[6], vel[6], L[6], R[6], L2[6], R2[6];
        tk_rand_pose(&rng, pose);
        for (int j = 0; j < 6; j++)
            vel[j] = tk_rand(&rng, -1, 1) * (j < 3 ? 50.0 : 5.0);
        ck_assert_int_eq(kins_inverse_rates(k, pose, vel, L, R), KINS_OK);
        ck_assert_int_eq(kins_inverse(k, pose, L2), KINS_OK);
        ck_assert_int_eq(kins_leg_rates(k, pose, vel, R2), KINS_OK);
        for (int i = 0; i < 6; i++) {
            ck_assert_double_eq(L[i], L2[i]);
            ck_assert_double_eq(R[i], R2[i]);
        }
    }
    double far[6] = { 0, 0, 2000, 0, 0, 0 }, vel[6] = { 1, 0, 0, 0, 0, 0 }, L[6], R[6];
    ck_assert_int_eq(kins_inverse_rates(k, far, vel, L, R), KINS_ERR_UNREACHABLE);
    ck_assert(L[0] > k->joint_max[0]);
    kins_free(k);
}
END_TEST

/* All platform joints in one point: rotations move no leg, the Jacobian has rank 3. */
START_TEST(test_singular_geometry)
{
    struct tk_cfg *c = tk_hexapod(500, 0, 10, 10, 100, 1500);
    tk_set(c, "KINS", "HOME", "0 0 600 0 0 0");
    struct kins *k = make_kins(c);
    double pose[6] = { 5, 3, 600, 0, 0, 0 }, legs[6], out[6] = { 0, 0, 600, 0, 0, 0 };
    ck_assert_int_eq(kins_inverse(k, pose, legs), KINS_OK);
    struct kins_fwd_info info;
    ck_assert_int_eq(kins_forward(k, legs, out, &info), KINS_ERR_SINGULAR);
    ck_assert_double_eq(out[KINS_X], 0.0); /* untouched */
    ck_assert_double_eq(out[KINS_Z], 600.0);
    struct kins_check chk;
    ck_assert_int_eq(kins_check_pose(k, pose, &chk), KINS_OK);
    ck_assert_int_eq(chk.near_singular, 1);
    ck_assert_msg(chk.condition > 1e12, "condition %g", chk.condition);
    kins_free(k);
    free(c);
}
END_TEST

/* A regular platform turned so every leg lies in its plane: the legs cannot stop a twist. */
START_TEST(test_singular_pose)
{
    /* Base and platform of equal size, joints at the same angles: at the level pose every
     * leg is vertical and none resists a yaw (C) about Z. */
    struct tk_cfg *c = tk_hexapod(400, 400, 10, 10, 100, 1500);
    tk_set(c, "KINS", "PLATFORM_HALF_ANGLE", "50"); /* platform joint 60-50 = base joint */
    tk_set(c, "KINS", "HOME", "0 0 600 0 0 0");
    struct kins *k = make_kins(c);
    double pose[6] = { 0, 0, 600, 0, 0, 0 }, legs[6];
    ck_assert_int_eq(kins_inverse(k, pose, legs), KINS_OK);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(legs[i], 600.0, 1e-9);
    struct kins_check chk;
    ck_assert_int_eq(kins_check_pose(k, pose, &chk), KINS_OK);
    ck_assert_int_eq(chk.near_singular, 1);
    double out[6] = { 1, 1, 601, 0.5, 0.5, 0.5 };
    int st = kins_forward(k, legs, out, NULL);
    ck_assert_msg(st == KINS_ERR_SINGULAR || st == KINS_ERR_NO_CONVERGE,
                  "singular pose solved as %s", kins_strerror(st));
    /* The TMU machine is far from singular across its region. */
    struct kins *t = make_tmu();
    double home[6] = { 0, 0, 645, 0, 0, 0 };
    ck_assert_int_eq(kins_check_pose(t, home, &chk), KINS_OK);
    ck_assert_int_eq(chk.near_singular, 0);
    ck_assert_msg(chk.condition < 5.0, "condition %g", chk.condition);
    kins_free(k);
    kins_free(t);
    free(c);
}
END_TEST

/* Failures are statuses, never numbers: range, impossibility, iteration limit, NaN. */
START_TEST(test_failures)
{
    struct kins *k = make_tmu();
    double far[6] = { 600, 0, 645, 0, 0, 0 }, legs[6];
    ck_assert_int_eq(kins_inverse(k, far, legs), KINS_ERR_UNREACHABLE);
    ck_assert_msg(legs[1] > k->joint_max[1], "joints still written for the report");
    double pose[6] = { 1, 2, 3, 4, 5, 6 }, keep[6];
    memcpy(keep, pose, sizeof keep);
    double short_legs[6] = { 500, 700, 700, 700, 700, 700 };
    ck_assert_int_eq(kins_forward(k, short_legs, pose, NULL), KINS_ERR_LEG_RANGE);
    ck_assert_mem_eq(pose, keep, sizeof keep);
    double nan_pose[6] = { 0, 0, NAN, 0, 0, 0 };
    ck_assert_int_eq(kins_inverse(k, nan_pose, legs), KINS_ERR_ARG);
    for (int j = 0; j < 6; j++) {        /* an infinity anywhere, either sign */
        double inf_pose[6] = { 0, 0, 600, 0, 0, 0 };
        inf_pose[j] = j % 2 ? -INFINITY : INFINITY;
        ck_assert_int_eq(kins_inverse(k, inf_pose, legs), KINS_ERR_ARG);
        struct kins_check ck;
        ck_assert_int_eq(kins_check_pose(k, inf_pose, &ck), KINS_ERR_ARG);
    }
    kins_free(k);

    /* Legs of 100 mm on a machine whose platform joints are 383 mm apart across a base gap
     * of 156 mm: two platform joints cannot be that far apart, so no pose exists. */
    struct tk_cfg *c = tk_hexapod(450, 250, 10, 10, 50, 2000);
    tk_set(c, "KINS", "HOME", "0 0 600 0 0 0");
    k = make_kins(c);
    double tiny[6] = { 100, 100, 100, 100, 100, 100 };
    double start[6] = { 0, 0, 600, 0, 0, 0 };
    memcpy(keep, start, sizeof keep);
    ck_assert_int_eq(kins_forward(k, tiny, start, NULL), KINS_ERR_IMPOSSIBLE);
    ck_assert_mem_eq(start, keep, sizeof keep);
    kins_free(k);

    /* One iteration cannot reach 1e-9 mm from 60 mm away: the iteration limit, pose kept. */
    tk_set(c, "KINS", "FWD_MAX_ITERATIONS", "1");
    k = make_kins(c);
    double target[6] = { 40, -30, 640, 3, -2, 5 };
    ck_assert_int_eq(kins_inverse(k, target, legs), KINS_OK);
    struct kins_fwd_info info;
    ck_assert_int_eq(kins_forward(k, legs, start, &info), KINS_ERR_NO_CONVERGE);
    ck_assert_mem_eq(start, keep, sizeof keep);
    ck_assert_int_eq(info.iterations, 1);
    ck_assert_msg(info.residual_mm > 1e-9, "residual %g", info.residual_mm);
    kins_free(k);
    free(c);
}
END_TEST

/* Creates from a table expecting failure, and returns the message. */
static const char *create_err(struct tk_cfg *c, char *err, size_t len)
{
    struct kins_config cfg = tk_config(c);
    struct kins *k = NULL;
    ck_assert_int_eq(kins_create(&kins_hexapod_ops, &cfg, &k, err, len), KINS_ERR_CONFIG);
    ck_assert_ptr_null(k);
    return err;
}

/* Configuration errors name the section and the key. */
START_TEST(test_config_errors)
{
    char err[512];
    struct tk_cfg *c = tk_hexapod(500, 300, 10, 10, 520, 980);
    tk_set(c, "KINS", "BASE_RADIUS", NULL);
    ck_assert_str_eq(create_err(c, err, sizeof err), "[KINS] BASE_RADIUS: missing");
    tk_set(c, "KINS", "BASE_RADIUS", "500");
    tk_set(c, "JOINT_3", "MAX_LIMIT", "abc");
    ck_assert_str_eq(create_err(c, err, sizeof err), "[JOINT_3] MAX_LIMIT: 'abc' is not a number");
    tk_set(c, "JOINT_3", "MAX_LIMIT", "400");
    ck_assert_str_eq(create_err(c, err, sizeof err),
                     "[JOINT_3] MAX_LIMIT: 400 is not above MIN_LIMIT 520");
    tk_set(c, "JOINT_3", "MAX_LIMIT", "980");
    tk_set(c, "JOINT_5", "MIN_LIMIT", NULL);
    ck_assert_str_eq(create_err(c, err, sizeof err), "[JOINT_5] MIN_LIMIT: missing");
    tk_set(c, "JOINT_5", "MIN_LIMIT", "520");
    tk_set(c, "KINS", "PLATFORM_HALF_ANGLE", "75");
    ck_assert_str_eq(create_err(c, err, sizeof err),
                     "[KINS] PLATFORM_HALF_ANGLE: 75 is outside 0..59");
    tk_set(c, "KINS", "PLATFORM_HALF_ANGLE", "10");
    tk_set(c, "KINS", "BASE_0", "1 2 3");
    ck_assert_str_eq(create_err(c, err, sizeof err), "[KINS] PLATFORM_0: missing");
    tk_set(c, "KINS", "BASE_0", "1 2");
    ck_assert_ptr_nonnull(strstr(create_err(c, err, sizeof err), "[KINS] BASE_0: '1 2'"));
    tk_set(c, "KINS", "BASE_0", NULL);
    tk_set(c, "KINS", "PLATFORM_CARRIES", "TABLE");
    ck_assert_str_eq(create_err(c, err, sizeof err),
                     "[KINS] PLATFORM_CARRIES: 'TABLE': expected WORKPIECE or SPINDLE");
    tk_set(c, "KINS", "PLATFORM_CARRIES", "spindle");
    tk_set(c, "KINS", "FWD_TOLERANCE", "1e-9 mm");
    ck_assert_str_eq(create_err(c, err, sizeof err),
                     "[KINS] FWD_TOLERANCE: '1e-9 mm' is not a number");
    tk_set(c, "KINS", "FWD_TOLERANCE", NULL);
    tk_set(c, "KINS", "HOME", "0 0 2000 0 0 0");
    ck_assert_ptr_nonnull(strstr(create_err(c, err, sizeof err), "[KINS] HOME: the home pose "
                                 "is outside the leg limits"));
    free(c);
}
END_TEST

/* The workspace beyond the legs: the mirror assembly, the joints' angles, leg clearance. */
START_TEST(test_workspace)
{
    char err[512], why[300];
    double legs[6], home_legs[6];
    struct tk_cfg *c = tk_hexapod(500, 300, 10, 10, 520, 980);
    tk_set(c, "KINS", "HOME", "0 0 645 0 0 0");
    struct kins *k = make_kins(c);
    const double home[6] = { 0, 0, 645, 0, 0, 0 }, mirror[6] = { 0, 0, -645, 0, 0, 0 };
    ck_assert_int_eq(kins_inverse(k, home, home_legs), KINS_OK);
    /* mirrored through the base: every leg as long as at HOME, and no machine gets there */
    ck_assert_int_eq(kins_inverse(k, mirror, legs), KINS_ERR_WORKSPACE);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(legs[i], home_legs[i], 1e-9);
    ck_assert_int_eq(kins_describe(k, mirror, why, sizeof why), KINS_ERR_WORKSPACE);
    ck_assert_msg(strstr(why, "mirror assembly") && strstr(why, "645.000 mm below"), "%s", why);
    struct kins_check chk;
    ck_assert_int_eq(kins_check_pose(k, mirror, &chk), KINS_OK);
    ck_assert_int_eq(chk.reachable, 0);
    const double flipped[6] = { 0, 0, 645, 180, 0, 0 };   /* upside down */
    ck_assert_int_ne(kins_inverse(k, flipped, legs), KINS_OK);
    ck_assert_int_eq(kins_describe(k, home, why, sizeof why), KINS_OK);
    ck_assert_str_eq(why, "");
    kins_free(k);

    /* joint angles: at the level HOME every leg leans acos(645 / L) = 27.2322 deg from both
     * joints' axes (the base and platform planes are parallel) */
    double lean = acos(645.0 / (home_legs[0])) / DEG;
    ck_assert_double_eq_tol(lean, 27.232230608, 1e-6);
    tk_set(c, "KINS", "BASE_JOINT_MAX_ANGLE", "27.2");
    ck_assert_ptr_nonnull(strstr(create_err(c, err, sizeof err), "[KINS] HOME: the home pose "
                                 "is outside the workspace: leg 1's base joint would turn 27.23 "
                                 "deg from its axis, 0.03 deg beyond [KINS] "
                                 "BASE_JOINT_MAX_ANGLE = 27.2 deg"));
    tk_set(c, "KINS", "BASE_JOINT_MAX_ANGLE", "27.3");
    tk_set(c, "KINS", "PLATFORM_JOINT_MAX_ANGLE", "27.2");
    ck_assert_ptr_nonnull(strstr(create_err(c, err, sizeof err), "platform joint would turn "
                                 "27.23 deg"));
    tk_set(c, "KINS", "BASE_JOINT_MAX_ANGLE", "40");
    tk_set(c, "KINS", "PLATFORM_JOINT_MAX_ANGLE", "45");
    k = make_kins(c);
    const double tilt10[6] = { 0, 0, 645, 0, 10, 0 }, tilt20[6] = { 0, 0, 645, 0, 20, 0 };
    ck_assert_int_eq(kins_inverse(k, tilt10, legs), KINS_OK);
    ck_assert_int_eq(kins_inverse(k, tilt20, legs), KINS_ERR_WORKSPACE);
    for (int i = 0; i < 6; i++)      /* the legs themselves are in range there */
        ck_assert(legs[i] > 520 && legs[i] < 980);
    ck_assert_int_eq(kins_describe(k, tilt20, why, sizeof why), KINS_ERR_WORKSPACE);
    ck_assert_msg(strstr(why, "PLATFORM_JOINT_MAX_ANGLE = 45 deg"), "%s", why);
    double rates[6], vel[6] = { 0 };
    ck_assert_int_eq(kins_inverse_rates(k, tilt20, vel, legs, rates), KINS_ERR_WORKSPACE);
    kins_free(k);

    /* mounting axes: base joints mounted along their legs at HOME turn 0 deg there, so a
     * 5 deg limit that the base normal breaks by 22 deg holds; a move of 100 mm in X turns
     * leg 1's by 7.58 deg (legs 3 and 4 by 7.81, by hand): the message names the first
     * joint beyond the limit */
    struct hexapod_legs_dir { double u[6][3]; } hd;
    {
        struct kins *k0 = make_kins(c);   /* the legs' directions at HOME, by hand */
        const struct hexapod *h0 = (const struct hexapod *)k0;
        for (int i = 0; i < 6; i++) {
            double v[3], n = 0;
            for (int j = 0; j < 3; j++)
                v[j] = h0->p_mm[i][j] + home[j] - h0->b_mm[i][j], n += v[j] * v[j];
            for (int j = 0; j < 3; j++)
                hd.u[i][j] = v[j] / sqrt(n);
        }
        kins_free(k0);
    }
    tk_set(c, "KINS", "PLATFORM_JOINT_MAX_ANGLE", NULL);
    tk_set(c, "KINS", "BASE_JOINT_MAX_ANGLE", "5");
    ck_assert_ptr_nonnull(strstr(create_err(c, err, sizeof err), "base joint would turn 27.23"));
    for (int i = 0; i < 6; i++) {
        char key[40], val[120];
        snprintf(key, sizeof key, "BASE_JOINT_AXIS_%d", i);
        snprintf(val, sizeof val, "%.12f %.12f %.12f", hd.u[i][0], hd.u[i][1], hd.u[i][2]);
        tk_set(c, "KINS", key, val);
    }
    k = make_kins(c);
    ck_assert_int_eq(kins_inverse(k, home, legs), KINS_OK);
    const double x60[6] = { 100, 0, 645, 0, 0, 0 }, x10[6] = { 10, 0, 645, 0, 0, 0 };
    ck_assert_int_eq(kins_inverse(k, x10, legs), KINS_OK);
    ck_assert_int_eq(kins_inverse(k, x60, legs), KINS_ERR_WORKSPACE);
    ck_assert_int_eq(kins_describe(k, x60, why, sizeof why), KINS_ERR_WORKSPACE);
    ck_assert_msg(strstr(why, "leg 1's base joint would turn 7.58 deg from its axis, 2.58 deg "
                         "beyond [KINS] BASE_JOINT_MAX_ANGLE = 5 deg"), "%s", why);
    kins_free(k);
    tk_set(c, "KINS", "BASE_JOINT_AXIS_2", "0 0 -1");
    ck_assert_ptr_nonnull(strstr(create_err(c, err, sizeof err), "[KINS] BASE_JOINT_AXIS_2: 0 0 "
                                 "-1 points down"));
    tk_set(c, "KINS", "BASE_JOINT_MAX_ANGLE", NULL);
    tk_set(c, "KINS", "BASE_JOINT_AXIS_2", "0 0 1");
    ck_assert_ptr_nonnull(strstr(create_err(c, err, sizeof err), "needs BASE_JOINT_MAX_ANGLE"));
    for (int i = 0; i < 6; i++) {
        char key[40];
        snprintf(key, sizeof key, "BASE_JOINT_AXIS_%d", i);
        tk_set(c, "KINS", key, NULL);
    }

    /* leg clearance: at the level HOME, legs 1 and 2 come closest where they meet their
     * platform pair, 2 * 300 * sin(10 deg) = 104.189 mm apart */
    tk_set(c, "KINS", "BASE_JOINT_MAX_ANGLE", NULL);
    tk_set(c, "KINS", "PLATFORM_JOINT_MAX_ANGLE", NULL);
    tk_set(c, "KINS", "LEG_DIAMETER", "100");
    tk_set(c, "KINS", "LEG_CLEARANCE", "5");
    ck_assert_ptr_nonnull(strstr(create_err(c, err, sizeof err), "legs 1 and 2 would pass "
                                 "104.19 mm apart (axis to axis), 0.81 mm closer than [KINS] "
                                 "LEG_DIAMETER 100 mm + LEG_CLEARANCE 5 mm"));
    tk_set(c, "KINS", "LEG_DIAMETER", "95");
    k = make_kins(c);
    /* turned about Z, the legs of a platform pair close in: stopped at 100 mm */
    double turn[6] = { 0, 0, 645, 0, 0, 0 };
    int st = KINS_OK;
    for (turn[5] = 0; turn[5] < 90 && st == KINS_OK; turn[5] += 1)
        st = kins_inverse(k, turn, legs);
    ck_assert_int_eq(st, KINS_ERR_WORKSPACE);
    turn[5] -= 1;
    ck_assert_double_eq_tol(turn[5], 67, 1e-9);   /* `hexcnc kins ... workspace`: 66.74 deg */
    ck_assert_int_eq(kins_describe(k, turn, why, sizeof why), KINS_ERR_WORKSPACE);
    ck_assert_msg(strstr(why, "legs 1 and 2 would pass 99.") &&
                  strstr(why, "LEG_DIAMETER 95 mm + LEG_CLEARANCE 5 mm"), "%s", why);
    kins_free(k);
    /* the same turn without the clearance check is within the legs' lengths */
    tk_set(c, "KINS", "LEG_DIAMETER", NULL);
    tk_set(c, "KINS", "LEG_CLEARANCE", NULL);
    k = make_kins(c);
    ck_assert_int_eq(kins_inverse(k, turn, legs), KINS_OK);
    kins_free(k);

    /* soft limits of the pose, machine coordinates, as LinuxCNC's [AXIS_n] writes them */
    tk_set(c, "AXIS_Z", "MAX_LIMIT", "700");
    tk_set(c, "AXIS_B", "MIN_LIMIT", "-5");
    k = make_kins(c);
    ck_assert_int_eq(kins_inverse(k, (double[6]){ 0, 0, 700, 0, 0, 0 }, legs), KINS_OK);
    ck_assert_int_eq(kins_inverse(k, (double[6]){ 0, 0, 701, 0, 0, 0 }, legs),
                     KINS_ERR_WORKSPACE);
    kins_describe(k, (double[6]){ 0, 0, 701, 0, 0, 0 }, why, sizeof why);
    ck_assert_str_eq(why, "Z701.000 is 1.000 mm above [AXIS_Z] MAX_LIMIT = 700");
    kins_describe(k, (double[6]){ 0, 0, 645, 0, -7.5, 0 }, why, sizeof why);
    ck_assert_str_eq(why, "B-7.500 is 2.500 deg below [AXIS_B] MIN_LIMIT = -5");
    kins_free(k);
    tk_set(c, "AXIS_Z", "MAX_LIMIT", "600");
    ck_assert_ptr_nonnull(strstr(create_err(c, err, sizeof err), "[KINS] HOME: the home pose "
                                 "is outside the workspace: Z645.000 is 45.000 mm above "
                                 "[AXIS_Z] MAX_LIMIT = 600"));
    tk_set(c, "AXIS_B", "MAX_LIMIT", "-6");
    ck_assert_str_eq(create_err(c, err, sizeof err),
                     "[AXIS_B] MAX_LIMIT: -6 is not above MIN_LIMIT -5");
    tk_set(c, "AXIS_B", "MAX_LIMIT", NULL);
    tk_set(c, "AXIS_B", "MIN_LIMIT", NULL);
    tk_set(c, "AXIS_Z", "MAX_LIMIT", NULL);

    tk_set(c, "KINS", "BASE_JOINT_MAX_ANGLE", "95");
    ck_assert_str_eq(create_err(c, err, sizeof err),
                     "[KINS] BASE_JOINT_MAX_ANGLE: 95 is outside (0..89.9");
    tk_set(c, "KINS", "BASE_JOINT_MAX_ANGLE", NULL);
    tk_set(c, "KINS", "LEG_CLEARANCE", "5");
    ck_assert_ptr_nonnull(strstr(create_err(c, err, sizeof err), "[KINS] LEG_CLEARANCE: needs "
                                 "LEG_DIAMETER"));
    free(c);
}
END_TEST

/* Two machines in one process keep their own geometry. */
START_TEST(test_two_instances)
{
    struct tk_cfg *ca = tk_hexapod(500, 300, 10, 10, 400, 1200);
    struct tk_cfg *cb = tk_hexapod(400, 200, 15, 5, 400, 1200);
    struct kins *a = make_kins(ca), *b = make_kins(cb);
    double pose[6] = { 20, -10, 640, 2, -3, 4 }, la[6], lb[6], la2[6], lb2[6];
    ck_assert_int_eq(kins_inverse(a, pose, la), KINS_OK);
    ck_assert_int_eq(kins_inverse(b, pose, lb), KINS_OK);
    ck_assert_msg(fabs(la[0] - lb[0]) > 1.0, "different machines, different legs");
    /* Interleaved calls give what each gives alone. */
    ck_assert_int_eq(kins_inverse(a, pose, la2), KINS_OK);
    ck_assert_mem_eq(la, la2, sizeof la);
    double pa[6] = { 0, 0, 640, 0, 0, 0 }, pb[6] = { 0, 0, 640, 0, 0, 0 };
    ck_assert_int_eq(kins_forward(a, la, pa, NULL), KINS_OK);
    ck_assert_int_eq(kins_forward(b, lb, pb, NULL), KINS_OK);
    for (int j = 0; j < 6; j++) {
        ck_assert_double_eq_tol(pa[j], pose[j], 1e-9);
        ck_assert_double_eq_tol(pb[j], pose[j], 1e-9);
    }
    ck_assert_int_eq(kins_inverse(b, pose, lb2), KINS_OK);
    ck_assert_mem_eq(lb, lb2, sizeof lb);
    kins_free(a);
    kins_free(b);
    free(ca);
    free(cb);
}
END_TEST

/* Fixed tool over a moving table: the tip stays put in the machine, and a +X move of the
 * platform moves the cutter -X across the workpiece. */
START_TEST(test_tool_frames)
{
    struct kins *k = make_tmu();
    double pose[6] = { 0, 0, 630, 0, 0, 0 }, tb[3], tp[3];
    ck_assert_int_eq(kins_tool_point(k, pose, tb, tp), KINS_OK);
    /* TOOL_POINT 0 0 780, TOOL_AXIS 0 0 -1, TOOL_LENGTH 60: tip at Z 720. */
    ck_assert_double_eq_tol(tb[2], 720.0, 1e-12);
    ck_assert_double_eq_tol(tp[2], 90.0, 1e-12);
    double tp2[3];
    pose[KINS_X] = 10;
    ck_assert_int_eq(kins_tool_point(k, pose, tb, tp2), KINS_OK);
    ck_assert_double_eq_tol(tp2[0] - tp[0], -10.0, 1e-12);
    ck_assert_double_eq_tol(tb[0], 0.0, 1e-12);
    /* Table turned C = 90 deg: the platform's +Y axis points along machine -X, so the tip,
     * 10 mm in machine -X of the platform origin, is at platform +Y 10. */
    pose[KINS_C] = 90;
    ck_assert_int_eq(kins_tool_point(k, pose, NULL, tp2), KINS_OK);
    ck_assert_double_eq_tol(tp2[0], 0.0, 1e-9);
    ck_assert_double_eq_tol(tp2[1], 10.0, 1e-9);
    kins_free(k);

    /* Spindle on the platform: the tip rides along, 100 mm below the platform origin. */
    struct tk_cfg *c = tk_hexapod(500, 300, 10, 10, 520, 980);
    tk_set(c, "KINS", "PLATFORM_CARRIES", "SPINDLE");
    tk_set(c, "KINS", "TOOL_POINT", "0 0 -40");
    tk_set(c, "KINS", "TOOL_LENGTH", "60");
    k = make_kins(c);
    double p2[6] = { 5, 6, 650, 0, 90, 0 };
    ck_assert_int_eq(kins_tool_point(k, p2, tb, tp), KINS_OK);
    ck_assert_double_eq_tol(tp[2], -100.0, 1e-12);
    /* B = 90: the platform's -Z axis points along machine -X. */
    ck_assert_double_eq_tol(tb[0], 5.0 - 100.0, 1e-9);
    ck_assert_double_eq_tol(tb[1], 6.0, 1e-9);
    ck_assert_double_eq_tol(tb[2], 650.0, 1e-9);
    kins_free(k);
    free(c);
}
END_TEST

/* Rotation order: R = Rz(C)·Ry(B)·Rx(A), seen on one platform joint placed by hand. */
START_TEST(test_rotation_order)
{
    /* Platform joint 0 at (100, 0, 0), the others at (0, 100, 0); base joints on a 500 mm
     * circle at 5, 65, .. 305 deg. */
    struct tk_cfg *c = tk_hexapod(500, 300, 10, 10, 100, 2000);
    for (int i = 0; i < 6; i++) {
        char key[24], val[128];
        snprintf(key, sizeof key, "BASE_%d", i);
        snprintf(val, sizeof val, "%.17g %.17g 0", 500 * cos((i * 60 + 5) * DEG),
                 500 * sin((i * 60 + 5) * DEG));
        tk_set(c, "KINS", key, val);
        snprintf(key, sizeof key, "PLATFORM_%d", i);
        tk_set(c, "KINS", key, i == 0 ? "100 0 0" : "0 100 0");
    }
    tk_set(c, "KINS", "HOME", "0 0 700 0 0 0");
    struct kins *k = make_kins(c);
    /* A = 90 (about X first) keeps (100,0,0); then B = 90 about Y takes it to (0,0,-100);
     * C then leaves it there. The other order would give a different point. */
    double pose[6] = { 0, 0, 700, 90, 90, 30 }, legs[6];
    ck_assert_int_eq(kins_inverse(k, pose, legs), KINS_OK);
    double b0x = 500 * cos(5 * DEG), b0y = 500 * sin(5 * DEG);
    ck_assert_double_eq_tol(legs[0], sqrt(b0x * b0x + b0y * b0y + 600.0 * 600.0), 1e-9);
    kins_free(k);
    free(c);
}
END_TEST

/* The identity model, linked in. */
START_TEST(test_trivial_static)
{
    struct tk_cfg *c = calloc(1, sizeof *c);
    tk_set(c, "KINS", "JOINTS", "9");
    tk_set(c, "JOINT_2", "MAX_LIMIT", "100");
    struct kins_config cfg = tk_config(c);
    struct kins *k = NULL;
    char err[256];
    ck_assert_int_eq(kins_create(&kins_trivial_ops, &cfg, &k, err, sizeof err), KINS_OK);
    ck_assert_int_eq(k->njoints, 9);
    double pose[6] = { 1, 2, 3, 4, 5, 6 }, j[9], back[6] = { 0 };
    ck_assert_int_eq(kins_inverse(k, pose, j), KINS_OK);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq(j[i], pose[i]);
    ck_assert_double_eq(j[8], 0.0);
    ck_assert_int_eq(kins_forward(k, j, back, NULL), KINS_OK);
    ck_assert_mem_eq(back, pose, sizeof back);
    memset(back, 0, sizeof back);     /* (no forward_near of its own: forward answers) */
    ck_assert_int_eq(kins_forward_near(k, j, back, 1e-6, NULL), KINS_OK);
    ck_assert_mem_eq(back, pose, sizeof back);
    pose[2] = 150;
    ck_assert_int_eq(kins_inverse(k, pose, j), KINS_ERR_UNREACHABLE);
    ck_assert_int_eq(kins_tool_point(k, pose, NULL, NULL), KINS_ERR_ARG);
    kins_free(k);
    k = NULL;
    tk_set(c, "KINS", "JOINTS", "12");
    ck_assert_int_eq(kins_create(&kins_trivial_ops, &cfg, &k, err, sizeof err),
                     KINS_ERR_CONFIG);
    ck_assert_ptr_nonnull(strstr(err, "[KINS] JOINTS: 12"));
    free(c);
}
END_TEST

/* Status texts exist for every status. */
START_TEST(test_strerror)
{
    for (int s = 0; s < KINS_STATUS_COUNT; s++)
        ck_assert_str_ne(kins_strerror(s), "unknown kinematics status");
    ck_assert_str_eq(kins_strerror(-5), "unknown kinematics status");
}
END_TEST

/* The suite. */
static Suite *kins_suite(void)
{
    Suite *s = suite_create("kins");
    TCase *tc = tcase_create("hexapod");
    tcase_add_test(tc, test_home_by_hand);
    tcase_add_test(tc, test_round_trip);
    tcase_add_test(tc, test_forward_near);
    tcase_add_test(tc, test_offsets_round_trip);
    tcase_add_test(tc, test_leg_rates);
    tcase_add_test(tc, test_inverse_rates);
    tcase_add_test(tc, test_singular_geometry);
    tcase_add_test(tc, test_singular_pose);
    tcase_add_test(tc, test_failures);
    tcase_add_test(tc, test_config_errors);
    tcase_add_test(tc, test_two_instances);
    tcase_add_test(tc, test_tool_frames);
    tcase_add_test(tc, test_rotation_order);
    tcase_add_test(tc, test_trivial_static);
    tcase_add_test(tc, test_strerror);
    tcase_add_test(tc, test_workspace);
    suite_add_tcase(s, tc);
    return s;
}

/* Runs the suite; the exit status says whether every check passed. */
int main(void)
{
    SRunner *sr = srunner_create(kins_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
