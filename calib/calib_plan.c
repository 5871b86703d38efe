/* calib_plan.c: measurement poses for calibration, greedy D-optimal over random candidates. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/calib.h"

#define P CALIB_PER_LEG

/* Defaults for a machine the size of the TMU hexapod: +-150 mm, +-60 mm in Z, +-15 deg
 * tilt and +-25 deg turn about home, legs 5 mm inside their limits, 3000 candidates. */
void calib_plan_opts_default(struct calib_plan_opts *o)
{
    static const double half[KINS_POSE_DIM] = { 150, 150, 60, 15, 15, 25 };
    memcpy(o->half_range, half, sizeof half);
    o->leg_margin_mm = 5.0;
    o->candidates = 3000;
    o->seed = 20261123;
}

/* splitmix64, uniform in [lo, hi]. */
static double calib_rand(uint64_t *s, double lo, double hi)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return lo + (hi - lo) * (double)(z >> 11) * 0x1.0p-53;
}

/* Draws reachable, well-conditioned candidate poses; returns how many were found. */
static int calib_plan_candidates(struct kins *k, const struct calib_plan_opts *o,
                                 double (*cand)[KINS_POSE_DIM])
{
    uint64_t rng = o->seed;
    int found = 0;
    for (long tries = 0; found < o->candidates && tries < 200L * o->candidates; tries++) {
        double *q = cand[found];
        for (int j = 0; j < KINS_POSE_DIM; j++)
            q[j] = k->home[j] + calib_rand(&rng, -o->half_range[j], o->half_range[j]);
        struct kins_check chk;
        if (kins_check_pose(k, q, &chk) == KINS_OK && chk.reachable && !chk.near_singular &&
            chk.leg_margin_mm >= o->leg_margin_mm)
            found++;
    }
    return found;
}

/* x' M^-1 x for a symmetric positive definite 7x7 M held as its inverse. */
static double calib_quad(const double inv[P * P], const double x[P])
{
    double s = 0.0;
    for (int r = 0; r < P; r++)
        for (int c = 0; c < P; c++)
            s += x[r] * inv[r * P + c] * x[c];
    return s;
}

/* Sherman-Morrison: inv <- (M + x x')^-1 from inv = M^-1. */
static void calib_rank1(double inv[P * P], const double x[P])
{
    double y[P], d = 1.0 + calib_quad(inv, x);
    for (int r = 0; r < P; r++) {
        y[r] = 0.0;
        for (int c = 0; c < P; c++)
            y[r] += inv[r * P + c] * x[c];
    }
    for (int r = 0; r < P; r++)
        for (int c = 0; c < P; c++)
            inv[r * P + c] -= y[r] * y[c] / d;
}

/* Greedy D-optimal choice: each step takes the candidate that raises log det of the
 * information matrices most, sum over legs of log(1 + j' M^-1 j) (determinant lemma). */
static void calib_plan_greedy(const double *jac, int nc, int n, int *taken, int *chosen)
{
    double inv[CALIB_LEGS][P * P] = { { 0 } };
    for (int i = 0; i < CALIB_LEGS; i++)
        for (int r = 0; r < P; r++)
            inv[i][r * P + r] = 1e6; /* M starts at 1e-6 I: a weak prior, mm^-2 */
    for (int s = 0; s < n; s++) {
        int best = -1;
        double best_gain = -1.0;
        for (int c = 0; c < nc; c++) {
            if (taken[c])
                continue;
            double g = 0.0;
            for (int i = 0; i < CALIB_LEGS; i++)
                g += log1p(calib_quad(inv[i], &jac[(c * CALIB_LEGS + i) * P]));
            if (g > best_gain) {
                best_gain = g;
                best = c;
            }
        }
        chosen[s] = best;
        taken[best] = 1;
        for (int i = 0; i < CALIB_LEGS; i++)
            calib_rank1(inv[i], &jac[(best * CALIB_LEGS + i) * P]);
    }
}

/* Plans n poses (see calib.h). */
enum calib_status calib_plan(struct kins *k, const struct calib_geom *g,
                             const struct calib_plan_opts *opts, int n,
                             double (*pose)[KINS_POSE_DIM], double *condition, char *err,
                             size_t errlen)
{
    enum calib_status st = CALIB_ERR_NOMEM;
    double (*cand)[KINS_POSE_DIM] = calloc((size_t)opts->candidates, sizeof *cand);
    double *jac = calloc((size_t)opts->candidates * CALIB_LEGS * P, sizeof *jac);
    int *chosen = calloc((size_t)(n > 0 ? n : 1), sizeof *chosen);
    int *taken = calloc((size_t)opts->candidates, sizeof *taken);
    struct calib_meas *m = calloc((size_t)(n > 0 ? n : 1), sizeof *m);
    if (!cand || !jac || !chosen || !taken || !m)
        goto fail;
    st = CALIB_ERR_TOO_FEW;
    if (n < CALIB_MIN_MEAS) {
        snprintf(err, errlen, "%d poses: a fit needs at least %d", n, CALIB_MIN_MEAS);
        goto fail;
    }
    int nc = calib_plan_candidates(k, opts, cand);
    if (nc < n) {
        snprintf(err, errlen, "only %d reachable candidate poses found for %d poses: widen "
                 "the range or lower the leg margin", nc, n);
        goto fail;
    }
    for (int c = 0; c < nc; c++) {
        struct calib_meas cm = { .line = 0 };
        memcpy(cm.pose, cand[c], sizeof cm.pose);
        for (int i = 0; i < CALIB_LEGS; i++) /* lengths that fit g exactly: r = 0 */
            cm.legs_mm[i] = calib_leg_residual(g, &cm, i, &jac[(c * CALIB_LEGS + i) * P]);
    }
    calib_plan_greedy(jac, nc, n, taken, chosen);
    for (int s = 0; s < n; s++) {
        memcpy(pose[s], cand[chosen[s]], sizeof pose[s]);
        memcpy(m[s].pose, cand[chosen[s]], sizeof m[s].pose);
    }
    struct calib_observability ob;
    st = calib_observe(g, m, NULL, n, &ob, err, errlen);
    *condition = ob.condition;
fail:
    free(cand);
    free(jac);
    free(chosen);
    free(taken);
    free(m);
    return st;
}
