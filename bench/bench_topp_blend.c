/* bench_topp_blend.c: the planner's time on blended (G64 P) programs against the time-optimal
 * parameterisation of the path it planned, blend arcs and all, under the same limits.
 *
 * bench_topp.c compares exact-stop programs move by move. Under G64 the path runs on through
 * its blend arcs without stopping, so the reference here parameterises the whole planned
 * path at once, from rest at its start to rest at its end: TOPP by reachability analysis
 * (Pham & Pham, IEEE T-RO 2018) on a grid along the path's segments (lines and the planner's
 * blend arcs, each segment at least 16 grid intervals). With x = ds/dt^2 and u = d2s/dt2, p(s)
 * the pose (p' and p'' its derivatives along s, from the planner's own geometry) and L(s) the
 * legs (L', L'' exact from the kinematics), each grid point keeps
 *     path speed            x <= F^2 (the programmed feed), x |p'_xyz|^2 <= v_max^2
 *     XYZ acceleration      |p'_xyz u + p''_xyz x| <= a_max (an ellipse in (x, u): its
 *                           circumscribed 64-gon, so the reference is, if anything, faster)
 *     A B C, each axis k    x p'_k^2 <= w^2, |p'_k u + p''_k x| <= alpha
 *     every leg             x L'^2 <= vL^2, |L' u + L'' x| <= aL
 * and x + 2 ds u must lie in the next point's controllable set. Each set comes from a
 * two-variable linear programme, solved exactly by walking every constraint's line (O(n^2)).
 * The kinematic-error bound is switched off on both sides (KINEMATIC_TOLERANCE = 0): it is a
 * speed cap of the paper's own, which the reference would only copy.
 *
 * Validated against closed-form trapezoids, and against bench_topp's move-by-move reference
 * on a G61 program (the same path: the two implementations must agree). Programmed arcs
 * (G2/G3) are measured the same way, and run at the servo rate at overrides 1 and 2 and
 * under four override walks.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_priv.h"
#include "tests/test_motion_util.h"

#define MIN_PER_SEG 16         /* grid intervals per segment, at least */
#define MAXC 96                /* constraints per grid point */
#define ELLIPSE_SIDES 64       /* the XYZ acceleration's polygon */

/* Half-planes p x + q u <= r in the (x, u) plane. */
struct lp { double p[MAXC], q[MAXC], r[MAXC]; int n; };

static void lp_add(struct lp *l, double p, double q, double r)
{
    if (l->n < MAXC)
        l->p[l->n] = p, l->q[l->n] = q, l->r[l->n] = r, l->n++;
}

/* Whether (x, u) keeps every constraint (to rounding). */
static int lp_ok(const struct lp *l, double x, double u)
{
    for (int k = 0; k < l->n; k++)
        if (l->p[k] * x + l->q[k] * u > l->r[k] + 1e-9 * (1 + fabs(l->r[k])))
            return 0;
    return 1;
}

/* The smallest (sense -1) or largest (+1) x of the feasible polygon; NAN when it is empty.
 * The optimum lies on some constraint's line: on each, the other constraints cut the line
 * to an interval, whose ends are the candidates. */
static double lp_x(const struct lp *l, int sense)
{
    double best = NAN;
    for (int i = 0; i < l->n; i++) {
        double p = l->p[i], q = l->q[i], r = l->r[i], nn = p * p + q * q;
        if (!(nn > 1e-300))
            continue;
        /* the line: (x, u) = z0 + t d, z0 its point nearest the origin, d along it */
        double x0 = p * r / nn, u0 = q * r / nn, dx = -q, du = p;
        double tlo = -HUGE_VAL, thi = HUGE_VAL;
        for (int k = 0; k < l->n && tlo <= thi; k++) {
            if (k == i)
                continue;
            double a = l->p[k] * dx + l->q[k] * du;
            double b = l->r[k] - l->p[k] * x0 - l->q[k] * u0;
            double tol = 1e-12 * (1 + fabs(l->r[k]));
            if (fabs(a) < 1e-300) {
                if (b < -tol)
                    tlo = HUGE_VAL, thi = -HUGE_VAL;     /* parallel and outside */
            } else if (a > 0) {
                thi = fmin(thi, b / a);
            } else {
                tlo = fmax(tlo, b / a);
            }
        }
        if (!(tlo <= thi + 1e-12))
            continue;
        double ts[2] = { tlo, thi };
        for (int e = 0; e < 2; e++) {
            if (isinf(ts[e]))
                continue;          /* unbounded along the line: another line bounds it */
            double x = x0 + ts[e] * dx, u = u0 + ts[e] * du;
            if (lp_ok(l, x, u) && (isnan(best) || sense * x > sense * best))
                best = x;
        }
    }
    return best;
}

/* One grid point's geometry: the pose's derivatives along s, the legs', the limits. */
struct geo {
    double dp[KINS_POSE_DIM], d2p[KINS_POSE_DIM];
    double dL[KINS_MAX_JOINTS], d2L[KINS_MAX_JOINTS];
    double feed;               /* programmed speed along s (0: rapid, the machine's limit) */
    int rotary;                /* s is deg (a rotary-only move) */
    int corner;                /* the path's direction jumps here (a G61 corner): at rest */
};

/* The limits of the machine, as the planner reads them. */
struct limits {
    double vlin, alin, w, alpha;
    double vL[KINS_MAX_JOINTS], aL[KINS_MAX_JOINTS];
    int nj;
};

static void point_lp(const struct geo *g, const struct limits *m, struct lp *l)
{
    l->n = 0;
    lp_add(l, -1, 0, 0);                                   /* x >= 0 */
    if (g->corner)
        lp_add(l, 1, 0, 0);
    if (g->feed > 0)
        lp_add(l, 1, 0, g->feed * g->feed);
    double t2 = 0, n2 = 0, tn = 0;
    for (int i = 0; i < 3; i++)
        t2 += g->dp[i] * g->dp[i], n2 += g->d2p[i] * g->d2p[i], tn += g->dp[i] * g->d2p[i];
    if (t2 > 1e-18)
        lp_add(l, t2, 0, m->vlin * m->vlin);
    if (n2 > 1e-18) {
        /* |p' u + p'' x|^2 = z^T M z, z = (x, u), M = [[n2, tn], [tn, t2]] = C C^T with C
         * lower triangular; |C^T z| <= a is the disc, cut by its tangents */
        double c11 = sqrt(n2), c21 = tn / c11, c22 = sqrt(fmax(0, t2 - c21 * c21));
        for (int k = 0; k < ELLIPSE_SIDES; k++) {
            double ph = 2 * M_PI * k / ELLIPSE_SIDES, cs = cos(ph), sn = sin(ph);
            /* (cs, sn) . C^T z = cs (c11 x + c21 u) + sn (c22 u) */
            lp_add(l, cs * c11, cs * c21 + sn * c22, m->alin);
        }
    } else if (t2 > 1e-18) {
        lp_add(l, 0, sqrt(t2), m->alin);
        lp_add(l, 0, -sqrt(t2), m->alin);
    }
    for (int k = 3; k < 6; k++) {
        if (fabs(g->dp[k]) > 1e-12)
            lp_add(l, g->dp[k] * g->dp[k], 0, m->w * m->w);
        if (fabs(g->dp[k]) > 1e-12 || fabs(g->d2p[k]) > 1e-12) {
            lp_add(l, g->d2p[k], g->dp[k], m->alpha);
            lp_add(l, -g->d2p[k], -g->dp[k], m->alpha);
        }
    }
    for (int j = 0; j < m->nj; j++) {
        lp_add(l, g->dL[j] * g->dL[j], 0, m->vL[j] * m->vL[j]);
        lp_add(l, g->d2L[j], g->dL[j], m->aL[j]);
        lp_add(l, -g->d2L[j], -g->dL[j], m->aL[j]);
    }
}

/* The grid over the planned path: s of each point and its geometry (the point at a
 * segment's end belongs to the next segment; the path ends at rest). */
struct grid {
    double *ds;                /* interval i: length along s */
    struct geo *g;             /* point i */
    size_t n;                  /* intervals */
};

static int grid_build(struct tm_machine *tm, double ds_target, struct grid *gr)
{
    const struct motion_plan *p = &tm->m->plan;
    size_t cap = 0;
    for (size_t j = 0; j < p->nseg; j++)
        if (p->segs[j].kind <= SEG_ARC && p->segs[j].len > 0)
            cap += (size_t)fmax(MIN_PER_SEG, ceil(p->segs[j].len / ds_target)) + 1;
    gr->ds = calloc(cap + 1, sizeof *gr->ds);
    gr->g = calloc(cap + 1, sizeof *gr->g);
    gr->n = 0;
    if (!gr->ds || !gr->g)
        return -1;
    double end_dp[KINS_POSE_DIM];              /* the previous segment's direction at its end */
    int have_end = 0;
    for (size_t j = 0; j < p->nseg; j++) {
        const struct motion_seg *sg = &p->segs[j];
        if (sg->kind > SEG_ARC || !(sg->len > 0))
            continue;
        int k = (int)fmax(MIN_PER_SEG, ceil(sg->len / ds_target));
        for (int i = 0; i < k; i++) {
            struct geo *g = &gr->g[gr->n];
            double pose[KINS_POSE_DIM], L[KINS_MAX_JOINTS];
            motion_seg_derivs(p, sg, sg->len * i / k, pose, g->dp, g->d2p);
            if (tm->kins->ops->inverse_path(tm->kins, pose, g->dp, g->d2p, L, g->dL, g->d2L))
                return -1;
            g->feed = sg->feed;
            g->rotary = sg->rotary;
            if (i == 0 && have_end)
                for (int a = 0; a < KINS_POSE_DIM; a++)
                    g->corner |= fabs(g->dp[a] - end_dp[a]) > 1e-6;
            gr->ds[gr->n++] = sg->len / k;
        }
        double pose[KINS_POSE_DIM], d2p[KINS_POSE_DIM];
        motion_seg_derivs(p, sg, sg->len, pose, end_dp, d2p);
        have_end = 1;
    }
    return 0;
}

/* The time-optimal time over the grid, at rest at both ends; NAN if none. */
static double topp(const struct grid *gr, const struct limits *m)
{
    size_t n = gr->n;
    double *lo = calloc(n + 1, sizeof *lo), *hi = calloc(n + 1, sizeof *hi);
    double t = NAN;
    struct lp l;
    if (!lo || !hi)
        goto out;
    lo[n] = hi[n] = 0;
    for (size_t i = n; i-- > 0;) {                 /* backward: the controllable sets */
        point_lp(&gr->g[i], m, &l);
        lp_add(&l, 1, 2 * gr->ds[i], hi[i + 1]);
        lp_add(&l, -1, -2 * gr->ds[i], -lo[i + 1]);
        lo[i] = lp_x(&l, -1), hi[i] = lp_x(&l, 1);
        if (isnan(lo[i]) || isnan(hi[i]))
            goto out;
    }
    double x = 0;                                  /* forward: the largest u staying in */
    t = 0;
    for (size_t i = 0; i < n; i++) {
        point_lp(&gr->g[i], m, &l);
        double umax = HUGE_VAL, umin = -HUGE_VAL;
        for (int c = 0; c < l.n; c++) {
            double rhs = l.r[c] - l.p[c] * x;
            if (l.q[c] > 1e-300)
                umax = fmin(umax, rhs / l.q[c]);
            else if (l.q[c] < -1e-300)
                umin = fmax(umin, rhs / l.q[c]);
        }
        umax = fmin(umax, (hi[i + 1] - x) / (2 * gr->ds[i]));
        umin = fmax(umin, (lo[i + 1] - x) / (2 * gr->ds[i]));
        double u = umax >= umin ? umax : umin;
        double xn = fmax(0, x + 2 * gr->ds[i] * u), vs = sqrt(x) + sqrt(xn);
        if (!(vs > 0)) {
            t = NAN;
            goto out;
        }
        t += 2 * gr->ds[i] / vs;
        x = xn;
    }
out:
    free(lo);
    free(hi);
    return t;
}

static void limits_of(const struct tm_machine *tm, struct limits *m)
{
    m->vlin = tm->mc.max_lin_vel_mm_s, m->alin = tm->mc.max_lin_acc_mm_s2;
    m->w = tm->mc.max_ang_vel_deg_s, m->alpha = tm->mc.max_ang_acc_deg_s2;
    m->nj = tm->kins->njoints;
    for (int j = 0; j < m->nj; j++)
        m->vL[j] = tm->mc.joint[j].max_vel_mm_s, m->aL[j] = tm->mc.joint[j].max_acc_mm_s2;
}

/* Plans the program (path mode: 610 G61, 640 G64 P tol_mm) and parameterises its path.
 * Prints a row; the reference's time into *ref, the ratio planner / reference into *ratio.
 * 0 or -1. */
static int compare(const char *name, struct tk_cfg *c, const double (*pts)[6], int n,
                   double feed_mm_min, int mode, double tol_mm, double ds_target,
                   double *ref_s, double *ratio)
{
    struct tm_machine tm;
    if (!c || tm_open(&tm, c, &kins_hexapod_ops))
        return -1;
    struct canon_prog p;
    canon_prog_init(&p);
    p.start_path_mode = mode;
    p.start_path_tol_mm = tol_mm;
    memcpy(p.start, pts[0], sizeof pts[0]);
    for (int i = 1; i < n; i++)
        tm_add(&p, CANON_FEED, i + 1, pts[i], feed_mm_min, 0);
    char err[512];
    int rc = -1;
    struct grid gr = { 0 };
    if (motion_load(tm.m, &p, err, sizeof err)) {
        fprintf(stderr, "bench_topp_blend: %s: %s\n", name, err);
        goto out;
    }
    struct motion_plan_info info;
    motion_plan_info(tm.m, &info);
    struct limits lim;
    limits_of(&tm, &lim);
    if (grid_build(&tm, ds_target, &gr))
        goto out;
    double ref = topp(&gr, &lim);
    if (isnan(ref))
        goto out;
    *ref_s = ref;
    *ratio = info.time_s / ref;
    /* the plan run at the servo rate: peak leg speed and acceleration from successive leg
     * commands, against their limits */
    struct tm_stats st;
    if (motion_start(tm.m) != MOTION_OK)
        goto out;
    tm_run(tm.m, tm.mc.servo_period_s, (int)(2 * info.time_s / tm.mc.servo_period_s) + 1000,
           &st, NULL, NULL);
    double pv = 0, pa = 0;
    for (int j = 0; j < lim.nj; j++)
        pv = fmax(pv, st.max_leg_v[j] / lim.vL[j]), pa = fmax(pa, st.max_leg_a[j] / lim.aL[j]);
    printf("  %-44s %4zu segs: planner %8.4f s, TOPP %8.4f s, ratio %.3f; legs at most "
           "%.3f, %.3f of their speed, acceleration limits\n", name, tm.m->plan.nseg,
           info.time_s, ref, *ratio, pv, pa);
    rc = st.last.state == MOTION_DONE && pv <= 1 + 1e-9 && pa <= 1 + 1e-9 ? 0 : -1;
    if (rc)
        fprintf(stderr, "bench_topp_blend: %s: a leg over its limit, or the run did not end\n",
                name);
out:
    free(gr.ds);
    free(gr.g);
    canon_prog_free(&p);
    tm_close(&tm);
    return rc;
}

/* The TMU hexapod where the legs bind (bench_topp's machine), no kinematic-error bound. */
static struct tk_cfg *leg_bound_cfg(void)
{
    struct tk_cfg *c = tm_leg_bound_hexapod_cfg();
    if (c)
        tk_set(c, "TRAJ", "KINEMATIC_TOLERANCE", "0");
    return c;
}

int main(void)
{
    int bad = 0;
    double r;
    /* validation: a straight move, path limits alone (fast legs): the closed-form trapezoid */
    printf("reference TOPP over the planned path (at least %d grid intervals per segment) "
           "against closed forms, path limits only:\n", MIN_PER_SEG);
    static const double line[][6] = { { -50, 0, 645, 0, 0, 0 }, { 50, 0, 645, 0, 0, 0 } };
    static const double feeds[2] = { 6000, 60000 };
    for (int k = 0; k < 2; k++) {
        struct tk_cfg *c = tm_fast_hexapod_cfg(0.001, 0);
        struct motion_config mc;
        struct kins_config kc = tk_config(c);
        char err[512];
        motion_config_default(&mc);
        if (motion_config_read(&mc, &kc, 6, err, sizeof err))
            return 1;
        double v = fmin(feeds[k] / 60.0, mc.max_lin_vel_mm_s), a = mc.max_lin_acc_mm_s2;
        double exact = 100 > v * v / a ? 100 / v + v / a : 2 * sqrt(100 / a), ref;
        char name[64];
        snprintf(name, sizeof name, "100 mm at F%.0f", feeds[k]);
        if (compare(name, c, line, 2, feeds[k], 610, 0, 0.01, &ref, &r))
            return 1;
        printf("    TOPP %.6f s, closed form %.6f s: error %.2e\n", ref, exact,
               fabs(ref - exact) / exact);
        bad |= !(fabs(ref - exact) < 2e-3 * exact);
    }
    const double (*prog1)[6];
    int n1 = tm_leg_bound_points(0, &prog1);
    printf("the TMU hexapod, legs 40 mm/s and 200 mm/s^2, path 500 mm/s and 5000 mm/s^2 (the "
           "legs bind), KINEMATIC_TOLERANCE 0:\n");
    double g61 = 0, g64[3] = { 0 }, ref;
    if (compare("five moves, G61 (bench_topp's program)", leg_bound_cfg(), prog1, n1, 30000,
                610, 0, 0.05, &ref, &g61))
        return 1;
    static const double tols[3] = { 0.01, 0.1, 1.0 };
    for (int k = 0; k < 3; k++) {
        char name[96];
        snprintf(name, sizeof name, "five moves, G64 P%g", tols[k]);
        if (compare(name, leg_bound_cfg(), prog1, n1, 30000, 640, tols[k], 0.05, &ref, &g64[k]))
            return 1;
    }
    /* a tilted polygon round a circle, five axes, blended: 120 chords of 1 mm (kinks of 3
     * deg, whose blends the chords' length bounds) and 24 of 5.2 mm (15 deg, bounded by P) */
    enum { NP = 121, NQ = 25 };
    static double poly[NP][6];
    for (int i = 0; i < NP; i++) {
        double a = 2 * M_PI * i / (NP - 1);
        poly[i][0] = 20 * cos(a) - 20, poly[i][1] = 20 * sin(a), poly[i][2] = 645 + 2 * sin(a);
        poly[i][3] = 6 * sin(a), poly[i][4] = 6 * cos(a) - 6, poly[i][5] = 0;
    }
    static double quad[NQ][6];
    for (int i = 0; i < NQ; i++)
        for (int a = 0; a < 6; a++)
            quad[i][a] = poly[i * ((NP - 1) / (NQ - 1))][a];
    double circ[3] = { 0 };
    if (compare("120 chords round a circle, A B tilting, P0.01", leg_bound_cfg(), poly, NP,
                30000, 640, 0.01, 0.01, &ref, &circ[0]))
        return 1;
    for (int k = 0; k < 2; k++) {
        char name[96];
        snprintf(name, sizeof name, "24 chords round it, P%g", tols[k]);
        if (compare(name, leg_bound_cfg(), quad, NQ, 30000, 640, tols[k], 0.01, &ref,
                    &circ[1 + k]))
            return 1;
    }
    /* programmed arcs (G2/G3) where the legs bind: a tilted S of four arcs, G61 and G64 */
    double arcs[2] = { 0 };
    for (int k = 0; k < 2; k++) {
        struct tk_cfg *c = leg_bound_cfg();
        struct tm_machine tm;
        if (!c || tm_open(&tm, c, &kins_hexapod_ops))
            return 1;
        struct canon_prog p;
        canon_prog_init(&p);
        p.start_path_mode = k ? 640 : 610;
        p.start_path_tol_mm = 0.05;
        double at[6] = { -40, 0, 645, 0, 0, 0 };
        memcpy(p.start, at, sizeof at);
        static const double up[3] = { 0, 0, 1 };
        for (int i = 0; i < 4; i++) {
            double c3[3] = { at[0] + 10, at[1], at[2] }, to[6];
            memcpy(to, at, sizeof to);
            to[0] += 20;
            to[3] = i % 2 ? 0 : 6, to[4] = i % 2 ? 0 : -4;
            tm_arc(&p, i + 2, to, c3, up, i % 2 ? 1 : -1, 30000);
            memcpy(at, to, sizeof at);
        }
        char err[512];
        struct grid gr = { 0 };
        struct limits lim;
        limits_of(&tm, &lim);
        if (motion_load(tm.m, &p, err, sizeof err) || grid_build(&tm, 0.01, &gr))
            return 1;
        struct motion_plan_info info;
        motion_plan_info(tm.m, &info);
        ref = topp(&gr, &lim);
        arcs[k] = info.time_s / ref;
        double pk[2];
        if (tm_run_peaks(&tm, &p, pk))
            return 1;
        printf("  four arcs of 10 mm, A B turning, %s: planner %.4f s, TOPP %.4f s, ratio %.3f; "
               "legs at most %.3f, %.3f of their speed, acceleration limits (overrides 1, 2 "
               "and changing)\n", k ? "G64 P0.05" : "G61", info.time_s, ref, arcs[k], pk[0],
               pk[1]);
        bad |= !(pk[0] <= 1 + 1e-9 && pk[1] <= 1 + 1e-9);
        free(gr.ds);
        free(gr.g);
        canon_prog_free(&p);
        tm_close(&tm);
    }
    printf("planned time against the time-optimal one along the blended path: %.3f %.3f %.3f "
           "(five moves), %.3f %.3f %.3f (the circle); G61 %.3f; programmed arcs %.3f, %.3f "
           "(G61, G64)\n", g64[0], g64[1], g64[2], circ[0], circ[1], circ[2], g61, arcs[0],
           arcs[1]);
    return bad;
}
