/* bench_topp.c: the planner's time against the time-optimal path parameterisation (TOPP by
 * reachability analysis, Pham & Pham, IEEE T-RO 2018) of the same path under the same limits.
 *
 * A reference, written here for the comparison: on exact-stop (G61) programs every move
 * starts and ends at rest, so each straight move is parameterised alone. Along the path s
 * (XYZ mm, or A B C deg for a rotary-only move) the state is x = ds/dt^2 and the control
 * u = d2s/dt2, with x(i+1) = x(i) + 2 ds u(i) between grid points. At each grid point:
 *   path speed and acceleration      x <= v^2, |u| <= a
 *   A B C (deg per unit of s, r)     x r^2 <= w^2, |u| r <= alpha
 *   every leg (L', L'' along s)      x L'^2 <= vL^2, |L' u + L'' x| <= aL
 * The backward pass gives each grid point's controllable set [lo, hi] of x (the states from
 * which the end at rest is reachable), each from a two-variable linear programme; the forward
 * pass takes the largest u that stays in the next set. Time: sum of 2 ds / (sqrt(x_i) +
 * sqrt(x_i+1)). Validated against closed-form trapezoids (d / v + v / a).
 *
 * The planner's side is also run at the servo rate, at feed overrides 1 and 2 and with the
 * override switched up and down mid-program, the legs differenced every period: the time is
 * worth nothing if a leg passes its limits to make it.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/test_motion_util.h"

#define GRID 4000              /* grid intervals per move */
#define MAXC 32                /* constraints per grid point */

/* Half-planes p x + q u <= r in the (x, u) plane. */
struct lp { double p[MAXC], q[MAXC], r[MAXC]; int n; };

static void lp_add(struct lp *l, double p, double q, double r)
{
    l->p[l->n] = p, l->q[l->n] = q, l->r[l->n] = r;
    l->n++;
}

/* The smallest (sense -1) or largest (+1) x over the feasible polygon; NAN when empty. The
 * optimum of a 2-D LP lies on a vertex: every pair of constraint lines is tried. */
static double lp_x(const struct lp *l, int sense)
{
    double best = NAN;
    for (int i = 0; i < l->n; i++)
        for (int j = i + 1; j < l->n; j++) {
            double det = l->p[i] * l->q[j] - l->p[j] * l->q[i];
            if (fabs(det) < 1e-300)
                continue;
            double x = (l->r[i] * l->q[j] - l->r[j] * l->q[i]) / det;
            double u = (l->p[i] * l->r[j] - l->p[j] * l->r[i]) / det;
            int ok = 1;
            for (int k = 0; k < l->n && ok; k++)
                ok = l->p[k] * x + l->q[k] * u <= l->r[k] + 1e-9 * (1 + fabs(l->r[k]));
            if (ok && (isnan(best) || sense * x > sense * best))
                best = x;
        }
    return best;
}

/* The limits at one grid point of a move, as half-planes in (x, u). */
struct move_geo {
    double vmax, amax;         /* path speed and acceleration along s */
    double r;                  /* |dABC/ds|, deg per unit of s */
    double w, alpha;           /* angular limits, deg/s, deg/s^2 */
    double dL[KINS_MAX_JOINTS], d2L[KINS_MAX_JOINTS];
    double vL[KINS_MAX_JOINTS], aL[KINS_MAX_JOINTS];
    int nj;
};

static void point_lp(const struct move_geo *g, struct lp *l)
{
    l->n = 0;
    lp_add(l, -1, 0, 0);                         /* x >= 0 */
    lp_add(l, 1, 0, g->vmax * g->vmax);
    if (g->amax < HUGE_VAL) {
        lp_add(l, 0, 1, g->amax);
        lp_add(l, 0, -1, g->amax);
    }
    if (g->r > 1e-12) {
        lp_add(l, g->r * g->r, 0, g->w * g->w);
        lp_add(l, 0, g->r, g->alpha);
        lp_add(l, 0, -g->r, g->alpha);
    }
    for (int j = 0; j < g->nj; j++) {
        lp_add(l, g->dL[j] * g->dL[j], 0, g->vL[j] * g->vL[j]);
        lp_add(l, g->d2L[j], g->dL[j], g->aL[j]);
        lp_add(l, -g->d2L[j], -g->dL[j], g->aL[j]);
    }
}

/* The move's geometry at s: legs by central differences of the inverse kinematics. */
static int geo_at(struct kins *k, const double *S, const double *dir, double s, double h,
                  struct move_geo *g)
{
    double p[3][6], L[3][KINS_MAX_JOINTS];
    for (int m = 0; m < 3; m++) {
        for (int i = 0; i < 6; i++)
            p[m][i] = S[i] + (s + (m - 1) * h) * dir[i];
        if (kins_inverse(k, p[m], L[m]) != KINS_OK)
            return -1;
    }
    for (int j = 0; j < g->nj; j++) {
        g->dL[j] = (L[2][j] - L[0][j]) / (2 * h);
        g->d2L[j] = (L[2][j] - 2 * L[1][j] + L[0][j]) / (h * h);
    }
    return 0;
}

/* The time-optimal time of a straight move from S to E at rest at both ends, s. */
static double topp_line(struct kins *k, const struct motion_config *mc, const double *S,
                        const double *E, double feed_mm_s)
{
    double d[6], xyz = 0, abc = 0;
    for (int i = 0; i < 6; i++)
        d[i] = E[i] - S[i];
    for (int i = 0; i < 3; i++)
        xyz += d[i] * d[i], abc += d[3 + i] * d[3 + i];
    xyz = sqrt(xyz), abc = sqrt(abc);
    int rotary = xyz < 1e-9;
    double len = rotary ? abc : xyz, dir[6], r = 0;
    for (int i = 0; i < 6; i++)
        dir[i] = d[i] / len;
    for (int i = 3; i < 6; i++)
        r = fmax(r, fabs(dir[i]));
    /* A B C are limited per axis (their largest rate); a rotary-only move's s is deg */
    struct move_geo g = { .nj = k->njoints, .r = r, .w = mc->max_ang_vel_deg_s,
                          .alpha = mc->max_ang_acc_deg_s2 };
    g.vmax = rotary ? feed_mm_s : fmin(feed_mm_s, mc->max_lin_vel_mm_s);
    g.amax = rotary ? HUGE_VAL : mc->max_lin_acc_mm_s2;
    for (int j = 0; j < g.nj; j++)
        g.vL[j] = mc->joint[j].max_vel_mm_s, g.aL[j] = mc->joint[j].max_acc_mm_s2;
    double ds = len / GRID, h = fmin(0.05, ds);
    static double lo[GRID + 1], hi[GRID + 1], x[GRID + 1];
    static struct move_geo geo[GRID + 1];
    for (int i = 0; i <= GRID; i++) {
        geo[i] = g;
        if (geo_at(k, S, dir, i * ds, h, &geo[i]))
            return NAN;
    }
    lo[GRID] = hi[GRID] = 0;                     /* at rest at the end */
    struct lp l;
    for (int i = GRID - 1; i >= 0; i--) {        /* backward: the controllable sets */
        point_lp(&geo[i], &l);
        lp_add(&l, 1, 2 * ds, hi[i + 1]);        /* x + 2 ds u within K(i+1) */
        lp_add(&l, -1, -2 * ds, -lo[i + 1]);
        lo[i] = lp_x(&l, -1), hi[i] = lp_x(&l, 1);
        if (isnan(lo[i]) || isnan(hi[i]))
            return NAN;
    }
    x[0] = 0;                                    /* forward: the largest u that stays in */
    double t = 0;
    for (int i = 0; i < GRID; i++) {
        point_lp(&geo[i], &l);
        double umax = HUGE_VAL, umin = -HUGE_VAL;
        for (int c = 0; c < l.n; c++) {          /* x fixed: bounds on u */
            double rhs = l.r[c] - l.p[c] * x[i];
            if (l.q[c] > 1e-300)
                umax = fmin(umax, rhs / l.q[c]);
            else if (l.q[c] < -1e-300)
                umin = fmax(umin, rhs / l.q[c]);
        }
        umax = fmin(umax, (hi[i + 1] - x[i]) / (2 * ds));
        umin = fmax(umin, (lo[i + 1] - x[i]) / (2 * ds));
        double u = umax >= umin ? umax : umin;   /* rounding: keep within K(i+1) */
        x[i + 1] = fmax(0, x[i] + 2 * ds * u);
        double vs = sqrt(x[i]) + sqrt(x[i + 1]);
        if (!(vs > 0))
            return NAN;
        t += 2 * ds / vs;
    }
    return t;
}

/* A G61 program of straight moves: the planner's time and the reference's. */
static int compare(const char *name, struct tk_cfg *c, const double (*pts)[6], int n,
                   double feed_mm_min, double *ratio, double pk[2])
{
    struct tm_machine m;
    if (!c || tm_open(&m, c, &kins_hexapod_ops))
        return -1;
    struct canon_prog p;
    tm_g61_points(&p, pts, n, feed_mm_min);
    char err[512];
    if (motion_load(m.m, &p, err, sizeof err)) {
        fprintf(stderr, "bench_topp: %s: %s\n", name, err);
        return -1;
    }
    struct motion_plan_info info;
    motion_plan_info(m.m, &info);
    double ref = 0;
    for (int i = 1; i < n; i++)
        ref += topp_line(m.kins, &m.mc, pts[i - 1], pts[i], feed_mm_min / 60.0);
    *ratio = info.time_s / ref;
    int st = tm_run_peaks(&m, &p, pk);
    printf("  %-44s planner %8.4f s, TOPP %8.4f s: ratio %.3f; legs at the servo rate: "
           "speed %.4f, acceleration %.4f of their limits\n", name, info.time_s, ref, *ratio,
           pk[0], pk[1]);
    canon_prog_free(&p);
    tm_close(&m);
    return isnan(ref) || st ? -1 : 0;
}

int main(void)
{
    /* validation: path limits alone (fast legs), closed-form trapezoids and triangles */
    struct tk_cfg *c = tm_fast_hexapod_cfg(0.001, 0.001);
    struct tm_machine m;
    if (!c || tm_open(&m, c, &kins_hexapod_ops)) {
        fprintf(stderr, "bench_topp: cannot build the TMU hexapod (HEXCNC_ROOT?)\n");
        return 1;
    }
    printf("reference TOPP (reachability analysis, %d grid intervals per move) against closed "
           "forms, path limits only (legs 1000 mm/s, 20000 mm/s^2):\n", GRID);
    static const struct { double d, f; } lines[] = { { 100, 6000 }, { 100, 60000 },
                                                     { 2, 60000 } };
    int bad = 0;
    for (size_t i = 0; i < sizeof lines / sizeof lines[0]; i++) {
        double S[6] = { -50, 0, 645, 0, 0, 0 }, E[6] = { -50 + lines[i].d, 0, 645, 0, 0, 0 };
        double v = fmin(lines[i].f / 60.0, m.mc.max_lin_vel_mm_s), a = m.mc.max_lin_acc_mm_s2;
        double exact = lines[i].d > v * v / a ? lines[i].d / v + v / a
                                              : 2 * sqrt(lines[i].d / a);
        double t = topp_line(m.kins, &m.mc, S, E, lines[i].f / 60.0);
        printf("  %5.0f mm at F%-6.0f  TOPP %.6f s, closed form %.6f s: error %.2e\n",
               lines[i].d, lines[i].f, t, exact, fabs(t - exact) / exact);
        bad |= !(fabs(t - exact) < 2e-3 * exact);
    }
    tm_close(&m);
    /* where the legs bind: the TMU hexapod with slow legs and fast path limits */
    printf("G61 five-axis moves on the TMU hexapod, legs 40 mm/s and 200 mm/s^2, path 500 mm/s "
           "and 5000 mm/s^2 (the legs bind):\n");
    double r[2], pk[2][2];
    for (int k = 0; k < 2; k++) {
        const double (*pts)[6];
        int n = tm_leg_bound_points(k, &pts);
        if (compare(k ? "turns in place, then a short move, F30000"
                      : "five moves through the workspace, F30000",
                    tm_leg_bound_hexapod_cfg(), pts, n, 30000, &r[k], pk[k]))
            return 1;
    }
    double v = fmax(pk[0][0], pk[1][0]), a = fmax(pk[0][1], pk[1][1]);
    printf("planned time against the time-optimal one where legs bind: %.3f and %.3f "
           "(the goal: at most 1.05); the legs' peaks over every servo period at overrides 1, "
           "2 and changing: speed %.4f, acceleration %.4f of their limits (the goal: at most "
           "1)\n", r[0], r[1], v, a);
    /* (the acceleration differenced twice from set points: 0.1 % for rounding, as the tests) */
    return bad || v > 1 + 1e-9 || a > 1.001;
}
