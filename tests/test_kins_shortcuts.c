/* test_kins_shortcuts.c: the kinematics' fast paths against the plain computations: the
 * condition number from the Gram matrix, the legs of the planner's finite differences. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* The planner's finite differences: the legs of two poses near one, from that pose's sines
 * and cosines, equal the plain inverse of each (series and library angles alike). */
START_TEST(test_inverse_near)
{
    struct kins *k = make_tmu();
    const double base[6] = { 12.5, -30.25, 640, 4.5, -6.25, 9 };
    const double steps[3][6] = {
        { 0.05, -0.02, 0.01, 0.0042, -0.003, 0.002 },   /* along a dense five-axis block */
        { 0, 0, 0, 0.05, 0.05, -0.05 },                 /* a rotary-only move's 0.05 deg */
        { 0.3, 0.1, -0.2, 1.5, -0.9, 2 },               /* past the series: the library's */
    };
    for (int c = 0; c < 3; c++) {
        double pm[6], pp[6], L[6], Lm[6], Lp[6], R[6], Rm[6], Rp[6];
        for (int i = 0; i < 6; i++)
            pm[i] = base[i] - steps[c][i], pp[i] = base[i] + steps[c][i];
        ck_assert_int_eq(kins_inverse_near(k, base, pm, pp, L, Lm, Lp), KINS_OK);
        ck_assert_int_eq(kins_inverse(k, base, R), KINS_OK);
        ck_assert_int_eq(kins_inverse(k, pm, Rm), KINS_OK);
        ck_assert_int_eq(kins_inverse(k, pp, Rp), KINS_OK);
        for (int i = 0; i < 6; i++) {
            ck_assert_double_eq_tol(L[i], R[i], 1e-12);
            ck_assert_double_eq_tol(Lm[i], Rm[i], 1e-11);
            ck_assert_double_eq_tol(Lp[i], Rp[i], 1e-11);
        }
    }
    /* out of reach: the status is the pose's, the neighbours' legs are written all the same */
    double far[6] = { 0, 0, 1200, 0, 0, 0 }, fm[6], fp[6], L[6], Lm[6], Lp[6], R[6];
    for (int i = 0; i < 6; i++)
        fm[i] = far[i] - 0.01, fp[i] = far[i] + 0.01;
    ck_assert_int_eq(kins_inverse_near(k, far, fm, fp, L, Lm, Lp), KINS_ERR_UNREACHABLE);
    kins_inverse(k, fp, R);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(Lp[i], R[i], 1e-11);
    const double bad[6] = { 0, 0, NAN, 0, 0, 0 };
    ck_assert_int_eq(kins_inverse_near(k, base, bad, base, L, Lm, Lp), KINS_ERR_ARG);
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

int main(void)
{
    Suite *s = suite_create("kins_shortcuts");
    TCase *tc = tcase_create("shortcuts");
    tcase_add_test(tc, test_condition_number);
    tcase_add_test(tc, test_inverse_near);
    suite_add_tcase(s, tc);
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
