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
#define CHUNK 500          /* calls per timed chunk */
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

/* Everything the timed loops share. */
struct bench {
    struct kins *k;            /* the model under test */
    double b[6][3], p[6][3];   /* joint coordinates for the baseline, mm */
    double lever_mm;           /* baseline's lever arm for the stopping rule, mm */
    double tol_mm;             /* forward tolerance, mm */
    double (*poses)[6];        /* NPOSE random poses of the working region */
    double (*legs)[6];         /* their leg lengths (scratch for the inverse loops) */
    double (*path)[6];         /* NPATH poses of the 1 ms path */
    double (*plegs)[6];        /* the path's leg lengths */
    double sink;               /* results folded in so no loop is optimised away */
    int fails;                 /* forward solves that did not converge */
};

/* One timed figure: best ns per call of ours and of the baseline, iterations. */
struct figure {
    double ns, naive_ns;       /* best of RUNS, ns per call */
    double iters, naive_iters; /* mean iterations */
    int max_iters;             /* largest iteration count of ours */
};

/* Best-of-RUNS ns per inverse, ours and the baseline. Each run is timed in chunks of
 * CHUNK calls and every chunk keeps its best time, so a chunk preempted by another process
 * on the shared machine does not count. */
static struct figure bench_inverse(struct bench *B)
{
    struct figure f = { 0, 0, 0, 0, 0 };
    for (int from = 0; from < NPOSE; from += CHUNK) {
        double best = 1e99, naive_best = 1e99;
        for (int run = 0; run < RUNS; run++) {
            double t0 = now_ns();
            for (int n = from; n < from + CHUNK; n++)
                kins_inverse(B->k, B->poses[n], B->legs[n]);
            double t1 = now_ns();
            B->sink += B->legs[from][3];
            for (int n = from; n < from + CHUNK; n++)
                naive_inverse(B->b, B->p, B->poses[n], B->legs[n]);
            double t2 = now_ns();
            B->sink += B->legs[from][2];
            best = fmin(best, t1 - t0);
            naive_best = fmin(naive_best, t2 - t1);
        }
        f.ns += best / NPOSE;
        f.naive_ns += naive_best / NPOSE;
    }
    return f;
}

/* Best-of-RUNS ns per pose of the four-at-once calls beside the same call one pose at a
 * time, chunked as bench_inverse: kins_inverse4 against kins_inverse or, with path set,
 * kins_inverse_path4 against inverse_path (the planner's samples, on the random poses with
 * the first and second derivatives of a five-axis move). .ns four at once, .naive_ns one at
 * a time. */
static struct figure bench_four(struct bench *B, int path)
{
    struct figure f = { 0, 0, 0, 0, 0 };
    double dp[4][KINS_POSE_DIM] = { { 0.6, -0.5, 0.1, 0.2, -0.1, 0.3 } };
    double d2p[4][KINS_POSE_DIM] = { { 0.01, 0.02, 0, -0.01, 0.005, 0.002 } };
    for (int l = 1; l < 4; l++)
        memcpy(dp[l], dp[0], sizeof dp[l]), memcpy(d2p[l], d2p[0], sizeof d2p[l]);
    double L[4][KINS_MAX_JOINTS] = { { 0 } }, dL[4][KINS_MAX_JOINTS] = { { 0 } };
    double d2L[4][KINS_MAX_JOINTS] = { { 0 } };
    int st[4];
    for (int from = 0; from < NPOSE; from += CHUNK) {
        double best = 1e99, one_best = 1e99;
        for (int run = 0; run < RUNS; run++) {
            double t0 = now_ns();
            for (int n = from; n + 4 <= from + CHUNK; n += 4) {
                const double(*q)[KINS_POSE_DIM] = (const double(*)[KINS_POSE_DIM])B->poses[n];
                if (path)
                    kins_inverse_path4(B->k, q, (const double(*)[KINS_POSE_DIM])dp,
                                       (const double(*)[KINS_POSE_DIM])d2p, L, dL, d2L, st);
                else
                    kins_inverse4(B->k, q, L, st);
                B->sink += L[3][5] + d2L[3][5];
            }
            double t1 = now_ns();
            for (int n = from; n < from + CHUNK; n++) {
                if (path)
                    B->k->ops->inverse_path(B->k, B->poses[n], dp[0], d2p[0], L[0], dL[0],
                                            d2L[0]);
                else
                    kins_inverse(B->k, B->poses[n], L[0]);
                B->sink += L[0][4] + d2L[0][4];
            }
            double t2 = now_ns();
            best = fmin(best, t1 - t0);
            one_best = fmin(one_best, t2 - t1);
        }
        f.ns += best / NPOSE;
        f.naive_ns += one_best / NPOSE;
    }
    return f;
}

/* Forward solves of legs[from..to); warm: each starts from the previous result (the first
 * from the path pose before it), else from home. Returns total iterations of ours or, with
 * naive set, of the baseline. */
static long bench_forward_pass(struct bench *B, double (*legs)[6], int from, int to, int warm,
                               int naive, int *max_iters)
{
    double q[6];
    long iters = 0;
    memcpy(q, warm ? B->path[from] : B->k->home, sizeof q);
    for (int n = from; n < to; n++) {
        if (!warm)
            memcpy(q, B->k->home, sizeof q);
        if (naive) {
            int it = naive_forward(B->b, B->p, B->lever_mm, legs[n], q, B->tol_mm);
            B->fails += it < 0;
            iters += it;
            continue;
        }
        struct kins_fwd_info info;
        B->fails += kins_forward(B->k, legs[n], q, &info) != KINS_OK;
        iters += info.iterations;
        *max_iters = info.iterations > *max_iters ? info.iterations : *max_iters;
    }
    B->sink += q[0];
    return iters;
}

/* Best-of-RUNS forward timing (chunked as the inverse), warm along the path or cold from
 * home on random poses. */
static struct figure bench_forward(struct bench *B, int warm)
{
    struct figure f = { 0, 0, 0, 0, 0 };
    double (*legs)[6] = warm ? B->plegs + 1 : B->legs;
    int count = warm ? NPATH - 1 : NCOLD;
    long it = 0, nit = 0;
    for (int from = 0; from < count; from += CHUNK) {
        int to = from + CHUNK < count ? from + CHUNK : count;
        double best = 1e99, naive_best = 1e99;
        for (int run = 0; run < RUNS; run++) {
            double t0 = now_ns();
            long a = bench_forward_pass(B, legs, from, to, warm, 0, &f.max_iters);
            double t1 = now_ns();
            long b = bench_forward_pass(B, legs, from, to, warm, 1, &f.max_iters);
            double t2 = now_ns();
            best = fmin(best, t1 - t0);
            naive_best = fmin(naive_best, t2 - t1);
            if (run == 0)
                it += a, nit += b;
        }
        f.ns += best / count;
        f.naive_ns += naive_best / count;
    }
    f.iters = (double)it / count;
    f.naive_iters = (double)nit / count;
    return f;
}

/* Fills the poses, the path and their legs; checks the baseline computes the same legs. */
static int bench_setup(struct bench *B, struct tk_cfg *c, double *top_speed_mm_min)
{
    B->poses = malloc(sizeof(double[6]) * NPOSE);
    B->legs = malloc(sizeof(double[6]) * NPOSE);
    B->path = malloc(sizeof(double[6]) * NPATH);
    B->plegs = malloc(sizeof(double[6]) * NPATH);
    if (!B->poses || !B->legs || !B->path || !B->plegs)
        return -1;
    uint64_t rng = 42;
    for (int n = 0; n < NPOSE; n++)
        tk_rand_pose(&rng, B->poses[n]);
    *top_speed_mm_min = 0;
    for (int n = 0; n < NPATH; n++) {
        path_pose(n * 1e-3, B->path[n]);
        if (kins_inverse(B->k, B->path[n], B->plegs[n]) != KINS_OK) {
            fprintf(stderr, "bench_kins: path leaves the workspace at sample %d\n", n);
            return -1;
        }
        if (n > 0) {
            double (*q)[6] = B->path;
            *top_speed_mm_min = fmax(*top_speed_mm_min, 60e3 * hypot(hypot(q[n][0] -
                                     q[n - 1][0], q[n][1] - q[n - 1][1]), q[n][2] - q[n - 1][2]));
        }
    }
    if (geometry(c, B->b, B->p) != 0) {
        fprintf(stderr, "bench_kins: the baseline needs the parametric geometry keys\n");
        return -1;
    }
    double chk[6];
    naive_inverse(B->b, B->p, B->path[123], chk);
    for (int i = 0; i < 6; i++)
        if (fabs(chk[i] - B->plegs[123][i]) > 1e-9) {
            fprintf(stderr, "bench_kins: baseline geometry differs from the INI\n");
            return -1;
        }
    B->lever_mm = 0;
    for (int i = 0; i < 6; i++)
        B->lever_mm += hypot(B->p[i][0], B->p[i][1]) / 6;
    return 0;
}

/* Prints one row: ours, baseline, ratio. */
static void bench_row(const char *what, double ns, double naive_ns)
{
    printf("%-34s %10.1f %10.1f %7.1fx\n", what, ns, naive_ns, naive_ns / ns);
}

/* Times inverse and forward on the TMU configuration and prints them beside the baseline. */
int main(void)
{
    struct tk_cfg *c = tk_ini("configs/sim/tmu-hexapod.ini");
    if (!c) {
        fprintf(stderr, "bench_kins: cannot read configs/sim/tmu-hexapod.ini (HEXCNC_ROOT)\n");
        return 1;
    }
    struct bench B;
    memset(&B, 0, sizeof B);
    struct kins_config cfg = tk_config(c);
    char err[512];
    if (kins_create(&kins_hexapod_ops, &cfg, &B.k, err, sizeof err) != KINS_OK) {
        fprintf(stderr, "bench_kins: %s\n", err);
        return 1;
    }
    B.tol_mm = atof(tk_get(c, "KINS", "FWD_TOLERANCE"));
    double top_speed;
    if (bench_setup(&B, c, &top_speed) != 0)
        return 1;
    struct figure inv = bench_inverse(&B);
    struct figure inv4 = bench_four(&B, 0);
    struct figure path4 = bench_four(&B, 1);
    struct figure warm = bench_forward(&B, 1);
    struct figure cold = bench_forward(&B, 0);

    printf("hexapod kinematics, configs/sim/tmu-hexapod.ini, tolerance %g mm, best of %d runs"
           " (per chunk of %d calls)\n", B.tol_mm, RUNS, CHUNK);
    printf("path: %d samples at 1 ms, top speed %.0f mm/min\n", NPATH, top_speed);
    printf("%-34s %10s %10s %8s\n", "", "hexcnc", "naive", "ratio");
    bench_row("inverse, ns/pose", inv.ns, inv.naive_ns);
    printf("%-34s %10.1f %10s %7.1fx  (one at a time: %.1f ns)\n", "  four at once (inverse4)",
           inv4.ns, "", inv4.naive_ns / inv4.ns, inv4.naive_ns);
    printf("%-34s %10.1f %10s %7.1fx  (one at a time: %.1f ns)\n",
           "inverse_path, four at once, ns", path4.ns, "", path4.naive_ns / path4.ns,
           path4.naive_ns);
    bench_row("forward warm (1 kHz path), ns", warm.ns, warm.naive_ns);
    printf("%-34s %10.2f %10.2f\n", "  mean iterations", warm.iters, warm.naive_iters);
    printf("%-34s %10d\n", "  max iterations", warm.max_iters);
    bench_row("forward cold (from home), ns", cold.ns, cold.naive_ns);
    printf("%-34s %10.2f %10.2f\n", "  mean iterations", cold.iters, cold.naive_iters);
    printf("%-34s %10d\n", "  max iterations", cold.max_iters);
    printf("failed solves: %d (checksum %.3f)\n", B.fails, B.sink);
    kins_free(B.k);
    free(B.poses);
    free(B.legs);
    free(B.path);
    free(B.plegs);
    free(c);
    return B.fails ? 1 : 0;
}
