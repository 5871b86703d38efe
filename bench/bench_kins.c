/* bench_kins.c: hexapod inverse and forward timing beside a naive baseline, same run. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "kins/kins.h"
#include "tests/test_kins_util.h"

#define RUNS 15            /* timed runs; the best one is reported (the machine is shared) */
#define NPOSE 50000        /* random poses for the inverse */
#define NPATH 20000        /* 1 ms samples of the path: 20 s of machining */
#define NCOLD 5000         /* cold-started forward solves */
#define DEG (M_PI / 180.0)

/* Monotonic time in ns. */
static double now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e9 + (double)ts.tv_nsec;
}

/* ---- naive baseline: matrices multiplied out, finite differences, Gauss-Jordan ---- */

/* c = a * b for 3x3 matrices. */
static void mat3_mul(const double a[3][3], const double b[3][3], double c[3][3])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            c[i][j] = 0;
            for (int k = 0; k < 3; k++)
                c[i][j] += a[i][k] * b[k][j];
        }
}

/* Inverse kinematics as a textbook writes it: three rotation matrices multiplied out. */
static void naive_inverse(const double b[6][3], const double p[6][3], const double pose[6],
                          double legs[6])
{
    double ca = cos(pose[3] * DEG), sa = sin(pose[3] * DEG), cb = cos(pose[4] * DEG),
           sb = sin(pose[4] * DEG), cc = cos(pose[5] * DEG), sc = sin(pose[5] * DEG);
    double rx[3][3] = { { 1, 0, 0 }, { 0, ca, -sa }, { 0, sa, ca } };
    double ry[3][3] = { { cb, 0, sb }, { 0, 1, 0 }, { -sb, 0, cb } };
    double rz[3][3] = { { cc, -sc, 0 }, { sc, cc, 0 }, { 0, 0, 1 } };
    double ryx[3][3], r[3][3];
    mat3_mul(ry, rx, ryx);
    mat3_mul(rz, ryx, r);
    for (int i = 0; i < 6; i++) {
        double v[3];
        for (int j = 0; j < 3; j++)
            v[j] = pose[j] + r[j][0] * p[i][0] + r[j][1] * p[i][1] + r[j][2] * p[i][2] -
                   b[i][j];
        legs[i] = sqrt(pow(v[0], 2) + pow(v[1], 2) + pow(v[2], 2));
    }
}

/* General matrix inverse by Gauss-Jordan with partial pivoting; -1 if singular. */
static int gauss_jordan_inverse(double a[6][6], double inv[6][6])
{
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++)
            inv[i][j] = i == j;
    for (int c = 0; c < 6; c++) {
        int p = c;
        for (int r = c + 1; r < 6; r++)
            if (fabs(a[r][c]) > fabs(a[p][c]))
                p = r;
        if (fabs(a[p][c]) < 1e-14)
            return -1;
        for (int j = 0; j < 6; j++) {
            double t = a[c][j];
            a[c][j] = a[p][j];
            a[p][j] = t;
            t = inv[c][j];
            inv[c][j] = inv[p][j];
            inv[p][j] = t;
        }
        double d = a[c][c];
        for (int j = 0; j < 6; j++) {
            a[c][j] /= d;
            inv[c][j] /= d;
        }
        for (int r = 0; r < 6; r++)
            if (r != c) {
                double f = a[r][c];
                for (int j = 0; j < 6; j++) {
                    a[r][j] -= f * a[c][j];
                    inv[r][j] -= f * inv[c][j];
                }
            }
    }
    return 0;
}

/* Newton with a forward-difference Jacobian and an explicit inverse; same stopping rule
 * (step below tol: mm, angles scaled by the lever arm). Returns iterations, -1 on failure. */
static int naive_forward(const double b[6][3], const double p[6][3], double lever_mm,
                         const double legs[6], double pose[6], double tol_mm)
{
    for (int it = 1; it <= 50; it++) {
        double l0[6], jac[6][6], inv[6][6];
        naive_inverse(b, p, pose, l0);
        for (int j = 0; j < 6; j++) {
            double q[6], l1[6], h = j < 3 ? 1e-6 : 1e-6 / DEG / lever_mm; /* mm, deg */
            memcpy(q, pose, sizeof q);
            q[j] += h;
            naive_inverse(b, p, q, l1);
            for (int i = 0; i < 6; i++)
                jac[i][j] = (l1[i] - l0[i]) / h;
        }
        if (gauss_jordan_inverse(jac, inv) != 0)
            return -1;
        double step = 0;
        for (int j = 0; j < 6; j++) {
            double d = 0;
            for (int i = 0; i < 6; i++)
                d += inv[j][i] * (legs[i] - l0[i]);
            pose[j] += d;
            step = fmax(step, j < 3 ? fabs(d) : fabs(d) * DEG * lever_mm);
        }
        if (step <= tol_mm)
            return it;
    }
    return -1;
}

/* ---- the path: a smooth 5-axis curve at about 2 m/min, sampled every 1 ms ---- */

/* Pose at time t_s on a Lissajous-like path through the working region. */
static void path_pose(double t_s, double pose[6])
{
    /* 100 mm amplitudes at these rates: up to about 2000 mm/min, the paper's F2. */
    const double w1 = 0.28, w2 = 0.18, w3 = 0.05; /* rad/s */
    pose[0] = 100 * sin(w1 * t_s);
    pose[1] = 100 * sin(w2 * t_s + 0.7);
    pose[2] = 645 + 20 * sin(w3 * t_s);
    pose[3] = 8 * sin(0.3 * t_s);
    pose[4] = -4 + 5 * cos(0.25 * t_s);
    pose[5] = 12 * sin(0.2 * t_s + 0.3);
}

/* The joint coordinates from the parametric keys, expanded independently of the model
 * (pairs at 0/120/240 deg on the base, 60/180/300 deg on the platform). */
static int geometry(struct tk_cfg *c, double b[6][3], double p[6][3])
{
    const char *keys[4] = { "BASE_RADIUS", "PLATFORM_RADIUS", "BASE_HALF_ANGLE",
                            "PLATFORM_HALF_ANGLE" };
    double v[4];
    for (int n = 0; n < 4; n++) {
        const char *s = tk_get(c, "KINS", keys[n]);
        if (!s)
            return -1;
        v[n] = atof(s);
    }
    const double zb = tk_get(c, "KINS", "BASE_Z") ? atof(tk_get(c, "KINS", "BASE_Z")) : 0;
    const double zp = tk_get(c, "KINS", "PLATFORM_Z") ? atof(tk_get(c, "KINS", "PLATFORM_Z")) : 0;
    for (int k = 0; k < 3; k++)
        for (int j = 0; j < 2; j++) {
            int i = 2 * k + j;
            double ba = (120.0 * k + (j ? 120.0 - v[2] : v[2])) * DEG;
            double pa = (120.0 * k + 60.0 + (j ? v[3] : -v[3])) * DEG;
            b[i][0] = v[0] * cos(ba), b[i][1] = v[0] * sin(ba), b[i][2] = zb;
            p[i][0] = v[1] * cos(pa), p[i][1] = v[1] * sin(pa), p[i][2] = zp;
        }
    return 0;
}

int main(void)
{
    struct tk_cfg *c = tk_ini("configs/sim/tmu-hexapod.ini");
    if (!c) {
        fprintf(stderr, "bench_kins: cannot read configs/sim/tmu-hexapod.ini (HEXCNC_ROOT)\n");
        return 1;
    }
    struct kins_config cfg = tk_config(c);
    struct kins *k = NULL;
    char err[512];
    if (kins_create(&kins_hexapod_ops, &cfg, &k, err, sizeof err) != KINS_OK) {
        fprintf(stderr, "bench_kins: %s\n", err);
        return 1;
    }
    double tol = atof(tk_get(c, "KINS", "FWD_TOLERANCE"));
    double (*poses)[6] = malloc(sizeof(double[6]) * NPOSE);
    double (*path)[6] = malloc(sizeof(double[6]) * NPATH);
    double (*plegs)[6] = malloc(sizeof(double[6]) * NPATH);
    double (*legs)[6] = malloc(sizeof(double[6]) * NPOSE);
    if (!poses || !path || !plegs || !legs)
        return 1;
    uint64_t rng = 42;
    for (int n = 0; n < NPOSE; n++)
        tk_rand_pose(&rng, poses[n]);
    double top_speed = 0;
    for (int n = 0; n < NPATH; n++) {
        path_pose(n * 1e-3, path[n]);
        if (kins_inverse(k, path[n], plegs[n]) != KINS_OK) {
            fprintf(stderr, "bench_kins: path leaves the workspace at sample %d\n", n);
            return 1;
        }
        if (n > 0)
            top_speed = fmax(top_speed, 60.0 * 1e3 * hypot(hypot(path[n][0] - path[n - 1][0],
                             path[n][1] - path[n - 1][1]), path[n][2] - path[n - 1][2]));
    }
    double b[6][3], p[6][3];
    if (geometry(c, b, p) != 0) {
        fprintf(stderr, "bench_kins: the baseline needs the parametric geometry keys\n");
        return 1;
    }
    /* The baseline must compute the same legs as the model, else it measures something else. */
    double chk[6];
    naive_inverse(b, p, path[123], chk);
    for (int i = 0; i < 6; i++)
        if (fabs(chk[i] - plegs[123][i]) > 1e-9) {
            fprintf(stderr, "bench_kins: baseline geometry differs from the INI\n");
            return 1;
        }
    double lever = 0;
    for (int i = 0; i < 6; i++)
        lever += hypot(p[i][0], p[i][1]) / 6;

    double sink = 0;
    double best_inv = 1e99, best_inv_naive = 1e99, best_warm = 1e99, best_warm_naive = 1e99,
           best_cold = 1e99, best_cold_naive = 1e99;
    long warm_iters = 0, cold_iters = 0, naive_warm_iters = 0, naive_cold_iters = 0;
    int warm_max = 0, cold_max = 0, fails = 0;
    double warm_err = 0;
    for (int run = 0; run < RUNS; run++) {
        double t0 = now_ns();
        for (int n = 0; n < NPOSE; n++)
            kins_inverse(k, poses[n], legs[n]);
        double t1 = now_ns();
        best_inv = fmin(best_inv, (t1 - t0) / NPOSE);
        sink += legs[NPOSE / 2][3];
        t0 = now_ns();
        for (int n = 0; n < NPOSE; n++)
            naive_inverse(b, p, poses[n], legs[n]);
        t1 = now_ns();
        best_inv_naive = fmin(best_inv_naive, (t1 - t0) / NPOSE);
        sink += legs[NPOSE / 3][2];

        /* Warm start along the path: each solve starts from the previous result. */
        double q[6];
        struct kins_fwd_info info;
        long iters = 0;
        memcpy(q, path[0], sizeof q);
        t0 = now_ns();
        for (int n = 1; n < NPATH; n++) {
            fails += kins_forward(k, plegs[n], q, &info) != KINS_OK;
            iters += info.iterations;
            warm_max = info.iterations > warm_max ? info.iterations : warm_max;
        }
        t1 = now_ns();
        best_warm = fmin(best_warm, (t1 - t0) / (NPATH - 1));
        warm_iters = iters;
        for (int j = 0; j < 6; j++)
            warm_err = fmax(warm_err, fabs(q[j] - path[NPATH - 1][j]));
        iters = 0;
        memcpy(q, path[0], sizeof q);
        t0 = now_ns();
        for (int n = 1; n < NPATH; n++) {
            int it = naive_forward(b, p, lever, plegs[n], q, tol);
            fails += it < 0;
            iters += it;
        }
        t1 = now_ns();
        best_warm_naive = fmin(best_warm_naive, (t1 - t0) / (NPATH - 1));
        naive_warm_iters = iters;
        sink += q[0];

        /* Cold start: every solve begins at home. */
        iters = 0;
        t0 = now_ns();
        for (int n = 0; n < NCOLD; n++) {
            memcpy(q, k->home, sizeof q);
            fails += kins_forward(k, legs[n], q, &info) != KINS_OK;
            iters += info.iterations;
            cold_max = info.iterations > cold_max ? info.iterations : cold_max;
        }
        t1 = now_ns();
        best_cold = fmin(best_cold, (t1 - t0) / NCOLD);
        cold_iters = iters;
        sink += q[1];
        iters = 0;
        t0 = now_ns();
        for (int n = 0; n < NCOLD; n++) {
            memcpy(q, k->home, sizeof q);
            int it = naive_forward(b, p, lever, legs[n], q, tol);
            fails += it < 0;
            iters += it;
        }
        t1 = now_ns();
        best_cold_naive = fmin(best_cold_naive, (t1 - t0) / NCOLD);
        naive_cold_iters = iters;
        sink += q[2];
    }
    printf("hexapod kinematics, configs/sim/tmu-hexapod.ini, tolerance %g mm, best of %d runs\n",
           tol, RUNS);
    printf("path: %d samples at 1 ms, top speed %.0f mm/min; warm end error %.2g\n", NPATH,
           top_speed, warm_err);
    printf("%-34s %10s %10s %8s\n", "", "hexcnc", "naive", "ratio");
    printf("%-34s %10.1f %10.1f %7.1fx\n", "inverse, ns/pose", best_inv, best_inv_naive,
           best_inv_naive / best_inv);
    printf("%-34s %10.1f %10.1f %7.1fx\n", "forward warm (1 kHz path), ns", best_warm,
           best_warm_naive, best_warm_naive / best_warm);
    printf("%-34s %10.2f %10.2f\n", "  mean iterations", (double)warm_iters / (NPATH - 1),
           (double)naive_warm_iters / (NPATH - 1));
    printf("%-34s %10d\n", "  max iterations", warm_max);
    printf("%-34s %10.1f %10.1f %7.1fx\n", "forward cold (from home), ns", best_cold,
           best_cold_naive, best_cold_naive / best_cold);
    printf("%-34s %10.2f %10.2f\n", "  mean iterations", (double)cold_iters / NCOLD,
           (double)naive_cold_iters / NCOLD);
    printf("%-34s %10d\n", "  max iterations", cold_max);
    printf("failed solves: %d (checksum %.3f)\n", fails, sink);
    kins_free(k);
    free(poses);
    free(path);
    free(plegs);
    free(legs);
    free(c);
    return fails ? 1 : 0;
}
