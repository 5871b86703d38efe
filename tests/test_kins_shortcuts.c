/* test_kins_shortcuts.c: the kinematics' fast paths against the plain computations: the
 * condition number from the Gram matrix, the legs' exact derivatives along a path, the
 * series for the sines and cosines of a pose's angles. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/simd.h"
#include "common/sincos3.h"
#include "kins/hexapod.h"
#include "kins/kins.h"
#include "kins/kins_svd.h"
#include "tests/test_kins_util.h"

/* The machine's own configuration file. */
static struct kins *make_tmu(void)
{
    struct tk_cfg *c = tk_ini("configs/sim/tmu-hexapod.ini");
    ck_assert_msg(c != NULL, "cannot read configs/sim/tmu-hexapod.ini (HEXCNC_ROOT?)");
    struct kins_config cfg = tk_config(c);
    struct kins *k = NULL;
    char err[512] = "";
    int st = kins_create(&kins_hexapod_ops, &cfg, &k, err, sizeof err);
    ck_assert_msg(st == KINS_OK, "create failed: %s (%s)", err, kins_strerror(st));
    free(c);
    return k;
}

/* A path through a pose: p(s) = pose + s dp + s^2 d2p / 2 (mm, deg). */
static void path_at(const double pose[6], const double dp[6], const double d2p[6], double s,
                    double out[6])
{
    for (int i = 0; i < 6; i++)
        out[i] = pose[i] + s * dp[i] + 0.5 * s * s * d2p[i];
}

/* The planner's samples: the legs' exact first and second derivatives along a path equal
 * Richardson-extrapolated central differences of the plain inverse (errors h^4), for a dense
 * five-axis block, a rotary-only move, a blend arc's bend and A B C cubic, and a pose turned
 * far in every angle (the axes e_a, e_b then matter). */
START_TEST(test_inverse_path)
{
    struct kins *k = make_tmu();
    const double base[4][6] = {
        { 12.5, -30.25, 640, 4.5, -6.25, 9 }, { 0, 0, 645, 0, 0, 0 },
        { -40, 25, 650, 2, 3, -4 }, { 30, 20, 630, 14, -11, 35 },
    };
    const double dp[4][6] = {
        { 0.8, -0.6, 0.02, 0.0084, -0.006, 0.004 },     /* per mm along a dense block */
        { 0, 0, 0, 0.6, 0.64, 0.48 },                    /* rotary only: per deg */
        { 0.6, 0.8, 0, 0.01, -0.02, 0.03 },              /* a blend arc */
        { -0.3, 0.9, 0.3, 1.5, -2, 2.5 },
    };
    const double d2p[4][6] = {
        { 0 }, { 0 },
        { -0.48, 0.36, 0, 0.004, 0.002, -0.006 },        /* bend of radius 1.67 mm */
        { 0.2, 0.1, -0.3, 0.7, 0.5, -0.9 },
    };
    for (int c = 0; c < 4; c++) {
        double L[6], dL[6], d2L[6], R0[6], d1[2][6], d2[2][6];
        ck_assert_int_eq(k->ops->inverse_path(k, base[c], dp[c], d2p[c], L, dL, d2L), KINS_OK);
        ck_assert_int_eq(kins_inverse(k, base[c], R0), KINS_OK);
        for (int e = 0; e < 2; e++) {        /* steps h and h / 2 */
            double h = e ? 0.01 : 0.02, pm[6], pp[6], Lm[6], Lp[6];
            path_at(base[c], dp[c], d2p[c], -h, pm);
            path_at(base[c], dp[c], d2p[c], h, pp);
            kins_inverse(k, pm, Lm);
            kins_inverse(k, pp, Lp);
            for (int i = 0; i < 6; i++) {
                d1[e][i] = (Lp[i] - Lm[i]) / (2 * h);
                d2[e][i] = (Lp[i] - 2 * R0[i] + Lm[i]) / (h * h);
            }
        }
        for (int i = 0; i < 6; i++) {
            ck_assert_double_eq(L[i], R0[i]);
            double r1 = (4 * d1[1][i] - d1[0][i]) / 3, r2 = (4 * d2[1][i] - d2[0][i]) / 3;
            ck_assert_msg(fabs(dL[i] - r1) < 1e-8, "case %d leg %d: dL %.12g, differenced "
                          "%.12g", c, i, dL[i], r1);
            ck_assert_msg(fabs(d2L[i] - r2) < 1e-5 * (1 + fabs(r2)), "case %d leg %d: d2L "
                          "%.12g, differenced %.12g", c, i, d2L[i], r2);
        }
    }
    /* out of reach: the status is the pose's, the derivatives are written all the same */
    const double far[6] = { 0, 0, 1200, 0, 0, 0 }, z[6] = { 0 }, up[6] = { 0, 0, 1, 0, 0, 0 };
    double L[6], dL[6] = { 0 }, d2L[6];
    ck_assert_int_eq(k->ops->inverse_path(k, far, up, z, L, dL, d2L), KINS_ERR_UNREACHABLE);
    for (int i = 0; i < 6; i++)
        ck_assert(dL[i] > 0.5);              /* every leg lengthens as the platform rises */
    const double bad[6] = { 0, 0, NAN, 0, 0, 0 };
    ck_assert_int_eq(k->ops->inverse_path(k, base[0], bad, z, L, dL, d2L), KINS_ERR_ARG);
    kins_free(k);
}
END_TEST

/* The analytic Jacobian the planner asks for equals central differences of the inverse. */
START_TEST(test_jacobian)
{
    struct kins *k = make_tmu();
    const double pose[6] = { 30, 20, 630, 14, -11, 35 };
    double J[36], Lm[6], Lp[6], p[6];
    ck_assert_int_eq(k->ops->jacobian(k, pose, J), KINS_OK);
    for (int j = 0; j < 6; j++) {
        double h = 1e-4;
        memcpy(p, pose, sizeof p);
        p[j] = pose[j] - h;
        kins_inverse(k, p, Lm);
        p[j] = pose[j] + h;
        kins_inverse(k, p, Lp);
        for (int i = 0; i < 6; i++)
            ck_assert_msg(fabs(J[i * 6 + j] - (Lp[i] - Lm[i]) / (2 * h)) < 1e-7, "leg %d, "
                          "pose %d: %.12g against %.12g", i, j, J[i * 6 + j],
                          (Lp[i] - Lm[i]) / (2 * h));
    }
    const double far[6] = { 0, 0, 1200, 0, 0, 0 };
    ck_assert_int_eq(k->ops->jacobian(k, far, J), KINS_ERR_UNREACHABLE);
    kins_free(k);
}
END_TEST

/* A 6 x 6 with known singular values: U diag(s) V^T with U, V rotations in two planes. */
static void known_matrix(const double s[6], double m[36])
{
    double u[36] = { 0 }, v[36] = { 0 }, c1 = cos(0.7), s1 = sin(0.7), c2 = cos(-1.1),
           s2 = sin(-1.1);
    for (int i = 0; i < 6; i++)
        u[i * 6 + i] = v[i * 6 + i] = 1;
    u[0] = c1, u[1] = -s1, u[6] = s1, u[7] = c1;         /* U turns rows 0,1 */
    v[4 * 6 + 4] = c2, v[4 * 6 + 5] = -s2, v[5 * 6 + 4] = s2, v[5 * 6 + 5] = c2;
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++) {
            double a = 0;
            for (int k = 0; k < 6; k++)
                a += u[i * 6 + k] * s[k] * v[j * 6 + k];
            m[i * 6 + j] = a;
        }
}

/* The condition number is the ratio of the extreme singular values: from the Gram matrix
 * where that is accurate, by SVD where it is not (and +inf for a rank-deficient matrix). */
START_TEST(test_condition_number)
{
    double m[36], cond;
    const double well[6] = { 3, 2.5, 2, 1.5, 1.2, 0.75 };      /* 4 */
    known_matrix(well, m);
    ck_assert_int_eq(kins_svd_condition(m, 6, 6, &cond), 0);
    ck_assert_msg(fabs(cond / 4.0 - 1) < 1e-12, "condition %.15g", cond);
    const double ill[6] = { 2, 1, 1, 1, 1, 2e-7 };             /* 1e7: the SVD's branch */
    known_matrix(ill, m);
    ck_assert_int_eq(kins_svd_condition(m, 6, 6, &cond), 0);
    ck_assert_msg(fabs(cond / 1e7 - 1) < 1e-8, "condition %.15g", cond);
    const double mid[6] = { 5, 4, 3, 2, 1, 5e-3 };             /* 1000: still the Gram's */
    known_matrix(mid, m);
    ck_assert_int_eq(kins_svd_condition(m, 6, 6, &cond), 0);
    ck_assert_msg(fabs(cond / 1000.0 - 1) < 1e-9, "condition %.15g", cond);
    const double rank5[6] = { 2, 1, 1, 1, 1, 0 };
    known_matrix(rank5, m);
    ck_assert_int_eq(kins_svd_condition(m, 6, 6, &cond), 0);
    ck_assert_msg(cond > 1e15, "condition %g", cond);
    double wide[2 * 3] = { 3, 0, 0, 0, 1, 0 };                  /* 2 x 3: 3 */
    ck_assert_int_eq(kins_svd_condition(wide, 2, 3, &cond), 0);
    ck_assert_double_eq_tol(cond, 3.0, 1e-12);
    m[7] = NAN;
    ck_assert_int_eq(kins_svd_condition(m, 6, 6, &cond), -1);
    ck_assert_int_eq(kins_svd_condition(m, 10, 6, &cond), -1);
}
END_TEST

/* Distance from the C library's value in units in the last place of it. */
static double ulps(double got, double want)
{
    if (got == want)
        return 0;
    return fabs(got - want) / fabs(nextafter(want, INFINITY) - want);
}

/* sincos3 and sincos1 against sincos(): within 1 ulp over +-pi/4 (the two series), equal beyond
 * it (the C library's own). */
START_TEST(test_sincos3)
{
    double worst = 0;
    srand48(7);
    for (int n = 0; n < 300000; n++) {
        double x[3], s[3], c[3];
        /* the whole range; within the short series' on every third; near 0 on every fifth */
        double range = n % 3 ? SINCOS3_FAST_RAD : SINCOS3_SHORT_RAD;
        for (int i = 0; i < 3; i++)
            x[i] = (2 * drand48() - 1) * range * (n % 5 ? 1 : 1e-3 * drand48());
        if (n == 0)
            x[0] = SINCOS3_FAST_RAD, x[1] = -SINCOS3_FAST_RAD, x[2] = 0;
        if (n == 1)
            x[0] = SINCOS3_SHORT_RAD, x[1] = -SINCOS3_SHORT_RAD, x[2] = 1e-300;
        sincos3(x, s, c);
        for (int i = 0; i < 3; i++) {
            double ws, wc, s1, c1;
            sincos(x[i], &ws, &wc);
            sincos1(x[i], &s1, &c1);
            ck_assert(s1 == s[i] && c1 == c[i]);
            worst = fmax(worst, fmax(ulps(s[i], ws), ulps(c[i], wc)));
        }
    }
    ck_assert_msg(worst <= 1.0, "%.2f ulp from sincos()", worst);
    double far[3] = { 0.8, 2.5, -40.0 }, s[3], c[3];
    sincos3(far, s, c);
    for (int i = 0; i < 3; i++) {
        double ws, wc;
        sincos(far[i], &ws, &wc);
        ck_assert(s[i] == ws && c[i] == wc);
    }
    double nan3[3] = { NAN, 0, 0 };
    sincos3(nan3, s, c);
    ck_assert(isnan(s[0]) && isnan(c[0]));
}
END_TEST

/* Four at once give what one at a time gives, bit for bit: kins_inverse4 the inverse's
 * joints and status, kins_inverse_path4 inverse_path's joints, first and second derivatives
 * and status. Lanes at random: angles within the short series' range, beyond it, beyond the
 * series' own (pi/4), mixed within one call; angles and their rates exactly 0 on some lanes
 * (the sign of a zero must come out the same); legs out of range, a platform below its base
 * joints, a pose or a derivative that is not a number or is infinite; and a workspace limit
 * beyond the assembly's (every lane then goes to the single call). */
START_TEST(test_four_at_once)
{
    struct kins *k = make_tmu();
    struct hexapod *h = (struct hexapod *)k;
    srand48(11);
    long lanes = 0, ok = 0;
    for (int n = 0; n < 40000; n++) {
        double pose[4][6], dp[4][6], d2p[4][6];
        double L[2][4][KINS_MAX_JOINTS], dL[2][4][KINS_MAX_JOINTS], d2L[2][4][KINS_MAX_JOINTS];
        double J[2][4][KINS_MAX_JOINTS];
        int st[4], st4[4];
        memset(L, 0, sizeof L), memset(dL, 0, sizeof dL), memset(d2L, 0, sizeof d2L);
        memset(J, 0, sizeof J);
        for (int l = 0; l < 4; l++) {
            int kind = (int)(drand48() * 8);
            double deg = kind < 5 ? 14.0 : kind < 7 ? 45.0 : 55.0;
            for (int i = 0; i < 6; i++) {
                pose[l][i] = (2 * drand48() - 1) * (i < 3 ? 120.0 : deg);
                dp[l][i] = (2 * drand48() - 1) * (i < 3 ? 1.0 : 0.5);
                d2p[l][i] = (2 * drand48() - 1) * (i < 3 ? 0.5 : 0.2);
                if (i >= 3 && (l + n) % 2 == 0 && drand48() < 0.5)
                    pose[l][i] = dp[l][i] = d2p[l][i] = 0.0;
            }
            pose[l][KINS_Z] += 645.0;
            if (kind == 7 && n % 4 == 0)
                pose[l][(int)(drand48() * 6)] = n % 8 ? NAN : -INFINITY;
            if (kind == 7 && n % 4 == 1)
                d2p[l][(int)(drand48() * 6)] = NAN;
            if (kind == 7 && n % 4 == 2)
                pose[l][KINS_Z] = n % 8 == 2 ? 1100.0 : -200.0;   /* out of reach, or below */
        }
        h->ws_extra = n % 500 == 499;
        const double(*P)[6] = (const double(*)[6])pose;
        kins_inverse4(k, P, J[0], st4);
        kins_inverse_path4(k, P, (const double(*)[6])dp, (const double(*)[6])d2p, L[0], dL[0],
                           d2L[0], st);
        for (int l = 0; l < 4; l++) {
            int w4 = kins_inverse(k, pose[l], J[1][l]);
            int w = k->ops->inverse_path(k, pose[l], dp[l], d2p[l], L[1][l], dL[1][l],
                                         d2L[1][l]);
            ck_assert_int_eq(st4[l], w4);
            ck_assert_int_eq(st[l], w);
            ck_assert_msg(!memcmp(J[0][l], J[1][l], sizeof J[0][l]), "inverse %d lane %d", n, l);
            ck_assert_msg(!memcmp(L[0][l], L[1][l], sizeof L[0][l]) &&
                          !memcmp(dL[0][l], dL[1][l], sizeof dL[0][l]) &&
                          !memcmp(d2L[0][l], d2L[1][l], sizeof d2L[0][l]),
                          "sample %d lane %d", n, l);
            lanes++;
            ok += w4 == KINS_OK;
        }
    }
    h->ws_extra = false;
    ck_assert(ok > lanes / 2 && ok < lanes);     /* both kinds of lane were there */
    kins_free(k);
}
END_TEST

/* kins_tcp_tips4 gives each lane the bits kins_tcp_from_pose gives its pose, for a spindle
 * on the platform and a tool on the frame, with tools of any length; it declines (writing
 * nothing) exactly when some lane's angle lies beyond +-45 deg or is not a number (or the
 * processor has no AVX2). */
START_TEST(test_tips_four_at_once)
{
    srand48(12);
    long done = 0, declined = 0;
    for (int n = 0; n < 40000; n++) {
        struct kins_tool_frame f = { .on_platform = n % 2 };
        double nn = 0;
        for (int i = 0; i < 3; i++) {
            f.gauge_mm[i] = (2 * drand48() - 1) * 200;
            f.axis[i] = 2 * drand48() - 1, nn += f.axis[i] * f.axis[i];
        }
        for (int i = 0; i < 3; i++)
            f.axis[i] /= sqrt(nn);
        double len = drand48() * 150, pose[4][6], tip[4][3], want[4][6];
        int beyond = 0;
        for (int l = 0; l < 4; l++) {
            int kind = (int)(drand48() * 8);
            double deg = kind < 5 ? 14.0 : kind < 7 ? 44.9 : 55.0;
            for (int i = 0; i < 6; i++)
                pose[l][i] = (2 * drand48() - 1) * (i < 3 ? 120.0 : deg);
            if (kind == 7 && n % 3 == 0)
                pose[l][3 + (int)(drand48() * 3)] = n % 2 ? NAN : INFINITY;
            for (int i = 3; i < 6; i++)
                beyond |= !(fabs(pose[l][i]) <= 45.0);
            kins_tcp_from_pose(&f, len, pose[l], want[l]);
        }
        memset(tip, 0x5a, sizeof tip);
        int ok = kins_tcp_tips4(&f, len, (const double(*)[6])pose, tip);
        ck_assert_int_eq(ok, !beyond && hexcnc_avx2());
        for (int l = 0; l < 4; l++)
            for (int i = 0; i < 3 && ok; i++)
                ck_assert_msg(!memcmp(&tip[l][i], &want[l][i], sizeof tip[l][i]),
                              "tip %d lane %d: %.17g, one at a time %.17g", n, l, tip[l][i],
                              want[l][i]);
        done += ok, declined += !ok;
    }
    /* (without AVX2, or in the baseline build, every call declines: common/simd.h) */
    ck_assert(hexcnc_avx2() ? done > 10000 && declined > 10000 : done == 0);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("kins_shortcuts");
    TCase *tc = tcase_create("shortcuts");
    tcase_add_test(tc, test_condition_number);
    tcase_add_test(tc, test_inverse_path);
    tcase_add_test(tc, test_jacobian);
    tcase_add_test(tc, test_sincos3);
    tcase_add_test(tc, test_four_at_once);
    tcase_add_test(tc, test_tips_four_at_once);
    suite_add_tcase(s, tc);
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
