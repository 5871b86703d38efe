/* motion_caps.c: a move sampled through the kinematics: reachability and the speed caps. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "motion/motion_priv.h"

#define FD_H 0.05              /* finite-difference step along the path, mm (deg) */
#define LEG_ACC_SPLIT 0.6      /* share of a leg's acceleration for the path acceleration term */
#define LEG_CURV_HAND 1.2      /* the curvature term's margin: 20 % in hand */
#define BLEND_CURV_SHARE 0.95  /* on blend arcs: the curvature term's share ... */
#define BLEND_CURV_HAND 1.05   /* ... and its margin (see leg_share) */
#define ARC_NORMAL_SHARE 0.5   /* share of the linear acceleration spent on centripetal */
#define FINE_SLACK 1e-9        /* relative: knots this much wider than fine_h are as close */


/* Samples segment sg at s; returns the inverse kinematics status at s itself. The pose and
 * its derivatives are the path's own; the legs' come from the kinematics' exact ones where
 * it has them, else (and under G43.4, whose tip-to-platform map is not the kinematics')
 * by central differences of three inverse solutions FD_H apart. */
static int sample_at(struct motion *m, const struct motion_seg *sg, double s,
                     struct motion_sample *o)
{
    o->tcp = sg->tcp;
    o->tool_len_mm = sg->tool_len_mm;
    o->q_state = 0;
    motion_seg_derivs(&m->plan, sg, s, o->pose, o->dp, o->d2p);
    if (!sg->tcp && m->kins->ops->inverse_path)
        return m->kins->ops->inverse_path(m->kins, o->pose, o->dp, o->d2p, o->L, o->dL, o->d2L);
    double h = FD_H, pm[KINS_POSE_DIM], pp[KINS_POSE_DIM];
    double Lm[KINS_MAX_JOINTS], Lp[KINS_MAX_JOINTS];
    if (sg->kind == SEG_ARC)
        h = motion_min2(h, 0.01 * m->plan.arcs[sg->arc].r0_mm);
    motion_seg_pose(&m->plan, sg, s - h, pm);
    motion_seg_pose(&m->plan, sg, s + h, pp);
    int st = motion_path_inverse(m, sg->tcp, sg->tool_len_mm, o->pose, o->L);
    motion_path_inverse(m, sg->tcp, sg->tool_len_mm, pm, Lm); /* written even out of range */
    motion_path_inverse(m, sg->tcp, sg->tool_len_mm, pp, Lp);
    for (int i = 0; i < m->nj; i++) {
        o->dL[i] = (Lp[i] - Lm[i]) / (2 * h);
        o->d2L[i] = (Lp[i] - 2 * o->L[i] + Lm[i]) / (h * h);
    }
    return st;
}

/*
 * The planner's look-ahead over knots. all_caps samples every knot of the plan in order
 * (segment_caps: the knots of each move, moves that are not lines or arcs skipped). Where a
 * knot's sample is not there yet, it and the next three are sampled together: their poses
 * and derivatives one by one (motion_seg_derivs), the kinematics of all four in one
 * kins_inverse_path4 call, under half the time of four (bench_kins). An entry is keyed by its
 * segment and its place s on it, and what it holds is the function of those that sample_at
 * computes, to the bit; a request with another key (a sample between knots, a move under
 * G43.4) is sampled alone as before.
 */
void motion_knot_ahead(struct motion *m, bool on)
{
    m->kahead.on = on && !m->kahead.off && m->kins->ops->inverse_path;
    m->kahead.n = m->kahead.next = 0;
}

/* Fills the look-ahead from the knot at s of sg on; false when s is no knot of sg or sg is
 * one sample_at takes another way (under G43.4). */
static bool knot_fill(struct motion *m, const struct motion_seg *sg, double s)
{
    struct motion_knot_ahead *a = &m->kahead;
    const struct motion_plan *p = &m->plan;
    size_t k = sg->k0, j = (size_t)(sg - p->segs);
    while (k < sg->k0 + sg->nk && p->ks[k] != s)
        k++;
    if (k == sg->k0 + sg->nk || sg->tcp)
        return false;
    double (*pose)[KINS_POSE_DIM] = a->pose, (*dp)[KINS_POSE_DIM] = a->dp;
    double (*d2p)[KINS_POSE_DIM] = a->d2p;
    int n = 0;
    while (n < MOTION_LANES) {
        const struct motion_seg *g = &p->segs[j];
        a->sg[n] = g, a->s[n] = p->ks[k];
        motion_seg_derivs(p, g, p->ks[k], pose[n], dp[n], d2p[n]);
        n++;
        if (++k == g->k0 + g->nk) {    /* on into the next line or arc (segment_caps) */
            while (++j < p->nseg && p->segs[j].kind > SEG_ARC)
                ;
            if (j == p->nseg || p->segs[j].tcp)
                break;
            k = p->segs[j].k0;
        }
    }
    for (int l = n; l < MOTION_LANES; l++) {    /* (lanes without a knot: one it can take) */
        memcpy(pose[l], pose[0], sizeof pose[l]);
        memcpy(dp[l], dp[0], sizeof dp[l]);
        memcpy(d2p[l], d2p[0], sizeof d2p[l]);
    }
    kins_inverse_path4(m->kins, (const double(*)[KINS_POSE_DIM])pose,
                       (const double(*)[KINS_POSE_DIM])dp, (const double(*)[KINS_POSE_DIM])d2p,
                       a->L, a->dL, a->d2L, a->status);
    a->n = n, a->next = 0;
    a->fills++;
    return true;
}

/* sample_at for a knot, from the look-ahead. */
static int sample_knot(struct motion *m, const struct motion_seg *sg, double s,
                       struct motion_sample *o)
{
    struct motion_knot_ahead *a = &m->kahead;
    if (!(a->next < a->n && a->sg[a->next] == sg && a->s[a->next] == s)) {
        if (!a->on || !knot_fill(m, sg, s))
            return sample_at(m, sg, s, o);
    } else {
        a->taken++;
    }
    int j = a->next++;
    if (a->status[j] != KINS_OK)       /* (a failure as sample_at has it, written or not) */
        return sample_at(m, sg, s, o);
    o->tcp = 0;                        /* (what sample_at writes, from the entry's arrays) */
    o->tool_len_mm = sg->tool_len_mm;
    o->q_state = 0;
    memcpy(o->pose, a->pose[j], sizeof o->pose);
    memcpy(o->dp, a->dp[j], sizeof o->dp);
    memcpy(o->d2p, a->d2p[j], sizeof o->d2p);
    memcpy(o->L, a->L[j], sizeof o->L);
    memcpy(o->dL, a->dL[j], sizeof o->dL);
    memcpy(o->d2L, a->d2L[j], sizeof o->d2L);
    return KINS_OK;
}

/* Inverts a 6x6 matrix by Gauss-Jordan elimination with partial pivoting (a is destroyed);
 * -1 when it is singular. */
int motion_invert6(double a[6][6], double inv[6][6])
{
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++)
            inv[i][j] = i == j;
    for (int c = 0; c < 6; c++) {
        int p = c;
        for (int r = c + 1; r < 6; r++)
            if (fabs(a[r][c]) > fabs(a[p][c]))
                p = r;
        if (!(fabs(a[p][c]) > 1e-12))
            return -1;
        for (int k = 0; k < 6 && p != c; k++) {
            double t = a[c][k]; a[c][k] = a[p][k]; a[p][k] = t;
            t = inv[c][k]; inv[c][k] = inv[p][k]; inv[p][k] = t;
        }
        double f = 1 / a[c][c];
        for (int k = 0; k < 6; k++)
            a[c][k] *= f, inv[c][k] *= f;
        for (int r = 0; r < 6; r++) {
            if (r == c || a[r][c] == 0)
                continue;
            double g = a[r][c];
            for (int k = 0; k < 6; k++)
                a[r][k] -= g * a[c][k], inv[r][k] -= g * inv[c][k];
        }
    }
    return 0;
}

/* The inverse of the Jacobian dL/dpose (mm/mm, mm/deg) at S's pose: the kinematics' own
 * (analytic) where it has one, else (and under G43.4, whose tip-to-platform map is not the
 * kinematics') by finite differences of the inverse kinematics; or the cached one when S
 * lies within 2 mm and 1 deg of where it was taken (it changes by well under 1 % there). -1
 * when the Jacobian is singular. */
static int jacobian_inverse_near(struct motion *m, const struct motion_sample *S)
{
    int near = m->jc_valid && m->jc_tcp == S->tcp && m->jc_len_mm == S->tool_len_mm;
    for (int i = 0; i < 6 && near; i++)
        near = fabs(S->pose[i] - m->jc_pose[i]) <= (i < 3 ? 2.0 : 1.0);
    if (near)
        return 0;
    double J[6][6], L1[KINS_MAX_JOINTS], p1[KINS_POSE_DIM], d = 1e-4;
    if (!S->tcp && m->kins->ops->jacobian) {
        m->kins->ops->jacobian(m->kins, S->pose, &J[0][0]);
    } else {
        for (int j = 0; j < 6; j++) {
            memcpy(p1, S->pose, sizeof p1);
            p1[j] += d;
            motion_path_inverse(m, S->tcp, S->tool_len_mm, p1, L1);
            for (int i = 0; i < 6; i++)
                J[i][j] = (L1[i] - S->L[i]) / d;
        }
    }
    if (motion_invert6(J, m->jc_Jinv) < 0)
        return -1;
    memcpy(m->jc_pose, S->pose, sizeof m->jc_pose);
    m->jc_valid = 1;
    m->jc_tcp = S->tcp;
    m->jc_len_mm = S->tool_len_mm;
    return 0;
}

/* q = J^-1 d2L at a sample: the pose's second derivative along the path as the legs see
 * it (the path's own, d2p, plus the kinematics' bending), into S->q once per sample. -1
 * when J is singular. */
static int pose_curvature(struct motion *m, struct motion_sample *S)
{
    if (S->q_state)
        return S->q_state > 0 ? 0 : -1;
    if (jacobian_inverse_near(m, S) < 0) {
        S->q_state = -1;
        return -1;
    }
    for (int i = 0; i < 6; i++) {
        double qi = 0;
        for (int j = 0; j < 6; j++)
            qi += m->jc_Jinv[i][j] * S->d2L[j];
        S->q[i] = qi;
    }
    S->q_state = 1;
    return 0;
}

/* The parts of a pose deviation q across the path (the part along it is only a timing
 * shift): the X Y Z distance into *perp_mm, the largest A B C one into *ang_deg. */
static void across_path(const struct motion_seg *sg, const struct motion_sample *S,
                        const double q[6], double *perp_mm, double *ang_deg)
{
    double shift = 0, w2 = 0, perp2 = 0, ang = 0;   /* shift: along-path part, s units */
    int base = sg->rotary ? 3 : 0;
    for (int i = base; i < base + 3; i++)
        w2 += S->dp[i] * S->dp[i], shift += q[i] * S->dp[i];
    shift = w2 > 0 ? shift / w2 : 0;
    for (int i = 0; i < 3; i++)
        perp2 += (q[i] - shift * S->dp[i]) * (q[i] - shift * S->dp[i]);
    for (int i = 3; i < 6; i++)
        ang = motion_max2(ang, fabs(q[i] - shift * S->dp[i]));
    *perp_mm = sqrt(perp2);
    *ang_deg = ang;
}

/* The kinematic-error speed cap at a sample (the paper's interpolator). Drives move legs
 * linearly between set points T apart, so over a chord of path length d the legs sit off the
 * leg-space curve by d2L d^2 / 8 at mid-chord; through the inverse Jacobian that is a pose
 * deviation q d^2 / 8 with J q = d2L. Its part across the path (the part along the path is
 * only a timing shift) must stay within KINEMATIC_TOLERANCE: d <= sqrt(8 tol / |q_perp|),
 * v <= d / T. Returns HUGE_VAL when no cap applies, -1 when J is singular. */
static double kin_tol_cap(struct motion *m, const struct motion_seg *sg,
                          struct motion_sample *S)
{
    const struct motion_config *c = &m->cfg;
    if (c->kin_tol_mm <= 0 || m->nj != 6)
        return HUGE_VAL;
    double perp, ang, dmax = HUGE_VAL;
    if (pose_curvature(m, S) < 0)
        return -1;
    across_path(sg, S, S->q, &perp, &ang);
    if (perp > 1e-15)
        dmax = sqrt(8 * motion_round_tol_mm(m, sg) / perp);
    if (ang > 1e-30 && c->kin_tol_deg > 0)
        dmax = motion_min2(dmax, sqrt(8 * KIN_TOL_SHARE * c->kin_tol_deg / ang));
    return dmax / m->chord_period_s;
}

/* See motion_priv.h. A set-point chord of length d that touches an arc spans a C1 path whose
 * curvature is at most k: it cuts the path by at most the sagitta of a circle of radius 1/k,
 * k d^2 / 8 · f with f = 2 / (1 + sqrt(1 - (k d / 2)^2)) (f -> 1 for short chords). The legs
 * add their own deviation |q_kin| d^2 / 8, q_kin = q - d2p being the kinematics' part of the
 * pose curvature (0 on a linear machine). The two add and share KIN_TOL_SHARE of the
 * tolerance in proportion to their curvatures:
 *     (k f + |q_kin,perp|) d^2 / 8 <= KIN_TOL_SHARE tol,
 * and the same for A B C with the arc's A B C curvature kabc (blend arcs) and tol_deg. */
double motion_chord_cap(struct motion *m, const struct motion_seg *sg,
                        const struct motion_sample *S, double k_mm, double kabc, double tol_mm)
{
    const struct motion_config *c = &m->cfg;
    if (c->kin_tol_mm <= 0)
        return HUGE_VAL;
    double qk[6] = {0}, perp = 0, ang = 0, tol = tol_mm;
    if (m->nj == 6) {
        struct motion_sample T;       /* a sample whose q was not taken yet (not the planner's
                                       * knots: motion_knot_caps takes it) */
        const struct motion_sample *Q = S;
        if (!S->q_state) {
            T = *S;
            pose_curvature(m, &T);
            Q = &T;
        }
        if (Q->q_state < 0)
            return -1;
        for (int i = 0; i < 6; i++)
            qk[i] = Q->q[i] - S->d2p[i];
        across_path(sg, S, qk, &perp, &ang);
    }
    double d = HUGE_VAL;
    if (k_mm + perp > 1e-15) {
        double d0 = sqrt(8 * tol / (k_mm + perp)), x = motion_min2(1.0, k_mm * d0 / 2);
        double f = 2 / (1 + sqrt(1 - x * x));
        d = sqrt(8 * tol / (k_mm * f + perp));
    }
    if (c->kin_tol_deg > 0 && kabc + ang > 1e-30)
        d = motion_min2(d, sqrt(8 * KIN_TOL_SHARE * c->kin_tol_deg / (kabc + ang)));
    return d / m->chord_period_s;
}

/* Reports a leg out of range at a sample, naming file, line, leg, amount and pose. */
static int unreachable(struct motion *m, const struct motion_seg *sg,
                       const struct motion_sample *S,
                       int st, char *err, size_t errlen)
{
    const struct kins *k = m->kins;
    const char *f = sg->file ? sg->file : "program";
    const double *P = S->pose;
    for (int i = 0; i < m->nj; i++) {
        double over = S->L[i] - k->joint_max[i], under = k->joint_min[i] - S->L[i];
        if (over > 0 || under > 0) {
            snprintf(err, errlen, "%s:%d: the move leaves the machine's reach: leg %d "
                     "([JOINT_%d]) would be %.3f mm long, %.3f mm %s its %s of %.3f mm, at X%.3f "
                     "Y%.3f Z%.3f A%.3f B%.3f C%.3f", f, sg->line, i + 1, i, S->L[i], over > 0 ? over : under,
                     over > 0 ? "beyond" : "below", over > 0 ? "maximum" : "minimum",
                     over > 0 ? k->joint_max[i] : k->joint_min[i], P[0], P[1], P[2], P[3], P[4], P[5]);
            return MOTION_ERR_UNREACHABLE;
        }
    }
    char why[300];
    double Q[KINS_POSE_DIM];
    motion_platform(m, S->tcp, S->tool_len_mm, P, Q);
    if (st == KINS_ERR_WORKSPACE && kins_describe(m->kins, Q, why, sizeof why) ==
        KINS_ERR_WORKSPACE) {
        snprintf(err, errlen, "%s:%d: the move leaves the machine's workspace: %s, at X%.3f "
                 "Y%.3f Z%.3f A%.3f B%.3f C%.3f", f, sg->line, why, P[0], P[1], P[2], P[3],
                 P[4], P[5]);
        return MOTION_ERR_UNREACHABLE;
    }
    snprintf(err, errlen, "%s:%d: the kinematics cannot follow the move (%s) at X%.3f Y%.3f "
             "Z%.3f A%.3f B%.3f C%.3f", f, sg->line, kins_strerror(st), P[0], P[1], P[2], P[3],
             P[4], P[5]);
    return st == KINS_ERR_UNREACHABLE || st == KINS_ERR_LEG_RANGE ? MOTION_ERR_UNREACHABLE
                                                                  : MOTION_ERR_KINS;
}

/* Reachability at a knot, with the overshoot a leg can have before the next knot
 * (|d2L/ds2| hs^2 / 8) counted in, so a leg leaving its range mid-move is caught. */
static int reach_check(struct motion *m, const struct motion_seg *sg, struct motion_sample *S,
                       double hs, int st, char *err, size_t errlen)
{
    const struct kins *k = m->kins;
    for (int i = 0; i < m->nj && st == KINS_OK; i++) {
        double bulge = fabs(S->d2L[i]) * hs * hs / 8;
        if (S->L[i] + bulge > k->joint_max[i])
            st = KINS_ERR_UNREACHABLE, S->L[i] += bulge;
        else if (S->L[i] - bulge < k->joint_min[i])
            st = KINS_ERR_UNREACHABLE, S->L[i] -= bulge;
    }
    return st == KINS_OK ? MOTION_OK : unreachable(m, sg, S, st, err, errlen);
}

/* How a leg's acceleration is shared between the curvature term L'' v^2 (curv, with its
 * margin: |L''| v^2 hand <= curv aL) and the path term L' a (the rest). */
struct leg_share { double curv, hand; };

/* The share on move sg. A share of the legs' acceleration holds either the speed on a bend
 * down or the path acceleration there. 40 % for the curvature (LEG_ACC_SPLIT for the path),
 * with 20 % in hand, suits moves that must speed up or slow down along their bends
 * (programmed arcs: with 95 % on every arc, a chain of kinked arcs took twice as long and a
 * full circle 24 % longer, docs/motion.md). A G64 blend arc is a different case: it joins
 * its two lines tangentially, and they keep their legs' whole acceleration for the speed
 * changes (motion_junction_share), while the time-optimal profile crosses the arc at the
 * speed its curvature allows with next to no path acceleration. With 40 % the arc was
 * crossed at sqrt(1/3) of that speed, and on a polygon whose blends are short the planned
 * time was 1.25x the time-optimal one (bench_topp_blend). So on blend arcs the curvature
 * takes BLEND_CURV_SHARE and the path the rest of what the knot's speed leaves
 * (leg_acc_at_speed). Its margin is 5 %: the speed between two knots stays within both
 * their caps, and between knots (at most 0.25 rad of the arc's turn apart, motion_path.c)
 * |L''| v^2 reached 0.956 of the 95 % share at most, against 1 / 1.05 = 0.952 at the knots
 * (test_blend_arc_knots_conservative: 24 turns of 0.05 to 1.3 rad under P0.005 to P0.05,
 * every interval sampled at 200 points). The share depends on
 * the move alone, so streamed windows that share a move give it the same caps. */
static struct leg_share leg_share(const struct motion *m, const struct motion_seg *sg)
{
    if (sg->kind == SEG_ARC && m->plan.arcs[sg->arc].abc_cubic)
        return (struct leg_share){ BLEND_CURV_SHARE, BLEND_CURV_HAND };
    return (struct leg_share){ 1 - LEG_ACC_SPLIT, LEG_CURV_HAND };
}

/* Leg caps at a knot: path speed into *vl, path acceleration into *am (lowered). The leg's
 * rate is L' v and its acceleration L'' v^2 + L' a; L' may grow by L'' hs before the next
 * knot. The shares of the leg's acceleration are sh's. rest (not NULL): lowered to the
 * path acceleration at rest, leg_acc_at_speed(m, S, hs, 0, sh), which the same loop has
 * at hand (at rest the curvature terms take nothing: each leg's whole aL / L'). */
static void leg_caps(const struct motion *m, const struct motion_sample *S, double hs,
                     struct leg_share sh, double *vl, double *am, double *rest)
{
    const struct motion_config *c = &m->cfg;
    double v2 = HUGE_VAL;      /* the curvature terms' speed, squared: one square root for
                                * all legs (it is monotonic, so the smallest root is exact) */
    *vl = HUGE_VAL;
    for (int i = 0; i < m->nj; i++) {
        double d1 = fabs(S->dL[i]) + fabs(S->d2L[i]) * hs, d2 = fabs(S->d2L[i]);
        if (d1 > 1e-12) {
            *vl = motion_lower(*vl, c->joint[i].max_vel_mm_s / d1);
            *am = motion_lower(*am, (1 - sh.curv) * c->joint[i].max_acc_mm_s2 / d1);
            if (rest)
                *rest = motion_lower(*rest, c->joint[i].max_acc_mm_s2 / d1);
        }
        if (d2 > 1e-12)
            v2 = motion_lower(v2, sh.curv * c->joint[i].max_acc_mm_s2 / (sh.hand * d2));
    }
    if (v2 < HUGE_VAL)
        *vl = motion_min2(*vl, sqrt(v2));
}

/* The path acceleration the legs allow at a knot once its speed is known to stay within vh
 * (its hard cap, which no feed override exceeds; 0 for the limit at rest, which the planner
 * takes with it for ramps, motion_plan.c): each leg's curvature term takes
 * hand |L''| vh^2 of its acceleration (with the speed cap's margin) and the path term the
 * rest, at least the 1 - curv share leg_caps gives (the speed cap keeps the curvature
 * term within curv). Where the speed is capped well below the legs' curvature
 * limit (by the feed, the machine or another leg), the legs lend the path most of their
 * acceleration instead of half: bench_topp measures the gain against the time-optimal. */
static double leg_acc_at_speed(const struct motion *m, const struct motion_sample *S,
                               double hs, double vh, struct leg_share sh)
{
    const struct motion_config *c = &m->cfg;
    double am = HUGE_VAL;
    for (int i = 0; i < m->nj; i++) {
        double d1 = fabs(S->dL[i]) + fabs(S->d2L[i]) * hs, aL = c->joint[i].max_acc_mm_s2;
        if (d1 > 1e-12)
            am = motion_lower(am, motion_raise((1 - sh.curv) * aL,
                                               aL - sh.hand * fabs(S->d2L[i]) * vh * vh) / d1);
    }
    return am;
}

/* Machine caps at a knot: path speed into *vm and acceleration into *am from the linear and
 * angular limits, and the centripetal share on arcs. w: the largest |d(A B C)/ds| until the
 * next knot. */
static void machine_caps(const struct motion *m, const struct motion_seg *sg, double w,
                         double *vm, double *am)
{
    const struct motion_config *c = &m->cfg;
    *vm = sg->rotary ? HUGE_VAL : c->max_lin_vel_mm_s;
    *am = sg->rotary ? HUGE_VAL : c->max_lin_acc_mm_s2;
    if (w > 1e-12) {
        *vm = motion_min2(*vm, c->max_ang_vel_deg_s / w);
        *am = motion_min2(*am, c->max_ang_acc_deg_s2 / w);
    }
    if (sg->kind == SEG_ARC) {
        const struct motion_arc *a = &m->plan.arcs[sg->arc];
        double r = motion_min2(a->r0_mm, a->r0_mm + a->dr_mm);
        *vm = motion_min2(*vm, sqrt(ARC_NORMAL_SHARE * c->max_lin_acc_mm_s2 * r));
        *am *= sqrt(1 - ARC_NORMAL_SHARE * ARC_NORMAL_SHARE);
    }
}

/* The cancel flag's check; on a stop request err names the move being planned. */
bool motion_cancelled(const struct motion *m, const char *file, int line, char *err,
                      size_t errlen)
{
    if (!m->cancel || !*m->cancel)
        return false;
    snprintf(err, errlen, "%s:%d: planning stopped by the operator", file ? file : "program",
             line);
    return true;
}

/* Knots of a very long move (a helix of many turns) lie further apart (hs) than the checks
 * are made for (sg->fine_h): the error terms grow with the square of the spacing and once
 * refused a 20000-turn helix with a leg "1231.725 mm long". The interval from s to the next
 * knot is then sampled at no more than fine_h: every sample is checked for reach and
 * lowers the knot's leg caps, each with the error term of the fine spacing. */
static int between_knots(struct motion *m, const struct motion_seg *sg, double s, double hs,
                         struct leg_share sh, double *vl, double *am, char *err, size_t errlen)
{
    double n = ceil(hs / sg->fine_h), h = hs / n;
    for (double j = 1; j < n && s + j * h < sg->len; j++) {
        struct motion_sample T;
        double v = HUGE_VAL;
        if (motion_cancelled(m, sg->file, sg->line, err, errlen))
            return MOTION_ERR_CANCELLED;
        int st = reach_check(m, sg, &T, h, sample_at(m, sg, s + j * h, &T), err, errlen);
        if (st)
            return st;
        leg_caps(m, &T, h, sh, &v, am, NULL);
        *vl = motion_min2(*vl, v);
    }
    return MOTION_OK;
}

/* Speed caps of one knot: hard (machine, legs, kinematic error) into *hard, with the feed
 * into *cap, the path acceleration limit at every speed up to *hard into *acc, and (acc0 not
 * NULL) the limit at rest into *acc0: below *hard the legs' curvature terms take less, and
 * the limit at speed v is at least acc0 - (acc0 - acc) v^2 / hard^2 (see motion_priv.h). */
int motion_knot_caps(struct motion *m, const struct motion_seg *sg, double s, double hs,
                     struct motion_sample *S, double *hard, double *cap, double *acc,
                     double *acc0, char *err, size_t errlen)
{
    /* The error terms' spacing: the knots' own, unless they lie further apart than the
     * checks are made for (a move capped at MAX_INTERVALS). Evenly spread knots come out an
     * ulp or so wider than fine_h (len i / n against len / n): that is the knots' spacing,
     * not a reason to sample every interval again in between. */
    double h = sg->fine_h > 0 && hs > sg->fine_h * (1 + FINE_SLACK) ? sg->fine_h : hs;
    int st = reach_check(m, sg, S, h, sample_knot(m, sg, s, S), err, errlen);
    if (st)
        return st;
    double vm, am, vl, kabc = 0;   /* |d2(A B C)/ds2|: the path's, 0 but on blend arcs */
    double w = 0;                  /* |d(A B C)/ds| */
    for (int i = 3; i < 6; i++)
        kabc = motion_max2(kabc, fabs(S->d2p[i])), w = motion_max2(w, fabs(S->dp[i]));
    /* On a blend arc the rate changes before the next knot, hs on: by at most kabc hs, the
     * cubic's |d2(A B C)/ds2| being linear along it (so largest at an interval's end, whose
     * knot's cap the interval takes) */
    w += kabc * hs;
    machine_caps(m, sg, w, &vm, &am);
    if (kabc > 1e-12) {        /* A B C bend along a blend arc: half the angular acceleration
                                * for the bend (abc'' v^2), half for the path's (abc' a) */
        vm = motion_min2(vm, sqrt(0.5 * m->cfg.max_ang_acc_deg_s2 / kabc));
        if (w > 1e-12)
            am = motion_min2(am, 0.5 * m->cfg.max_ang_acc_deg_s2 / w);
    }
    double am_machine = am;
    struct leg_share sh = leg_share(m, sg);
    double rest = HUGE_VAL;    /* the legs' path acceleration at rest */
    leg_caps(m, S, h, sh, &vl, &am, &rest);
    if (h < hs && (st = between_knots(m, sg, s, hs, sh, &vl, &am, err, errlen)))
        return st;
    double vk = kin_tol_cap(m, sg, S);
    if (vk < 0) {
        snprintf(err, errlen, "%s:%d: the move passes through a singular pose of the machine "
                 "at X%.3f Y%.3f Z%.3f A%.3f B%.3f C%.3f", sg->file ? sg->file : "program",
                 sg->line, S->pose[0], S->pose[1], S->pose[2], S->pose[3], S->pose[4],
                 S->pose[5]);
        return MOTION_ERR_KINS;
    }
    double feed = sg->feed > 0 ? sg->feed : HUGE_VAL;
    double soft = motion_min2(feed, vm);
    if (vl < soft)
        m->plan.info.limited_by_legs++;
    if (vk < motion_min2(soft, vl))
        m->plan.info.limited_by_kin_tol++;
    *hard = motion_min2(motion_min2(vm, vl), vk);
    *cap = motion_min2(*hard, feed);
    double am0 = am;
    if (h >= hs) {             /* the legs' share for the path, now the speed is known */
        am0 = motion_min2(am_machine, rest);
        am = motion_min2(am_machine, leg_acc_at_speed(m, S, h, *hard, sh));
    }
    *acc = am;
    if (acc0)
        *acc0 = motion_max2(am0, am);
    return MOTION_OK;
}
/* The speed at which the joint from segment a into b may be passed (G64): the velocity
 * changes direction within one servo period there, so its jump may use JUMP_SHARE of one
 * period's acceleration on every axis (a quarter on every leg) while the moves on either
 * side give up that share of their path acceleration (all_caps); and the corner cut by the
 * set-point chord (and the moving average of jerk limiting) stays within the blend
 * tolerance, with jerk limits within the blend arcs' share of it (motion_blend.c): the
 * average's rounding of the curves next to the joint has the rest. acc: the largest path
 * acceleration the moves may have next to the joint. 0 when the moves must stop between. */
double motion_junction_speed(struct motion *m, const struct motion_seg *a,
                             const struct motion_seg *b, const struct motion_sample *Ap,
                             const struct motion_sample *Bp, double acc)
{
    const struct motion_config *c = &m->cfg;
    if (a->blend_tol_mm <= 0 || a->rotary != b->rotary || a->kind > SEG_ARC || b->kind > SEG_ARC)
        return 0;
    const struct motion_sample *A = Ap, *B = Bp;
    double T = c->servo_period_s, Ts = c->setpoint_period_s > 0 ? c->setpoint_period_s : T;
    double dx = 0, da = 0, v = HUGE_VAL, Tj = m->jerk_window_s;
    double tol = a->blend_tol_mm * motion_blend_share(Tj);
    /* a jump of the direction by dx at speed v: a set-point chord across it cuts the corner
     * by up to v Ts dx / 4, the moving average of jerk limiting by v Tj dx / 8, and by
     * acc Tj^2 dx / 48 more while the path slows into the corner and speeds up out of it
     * (the mean of the distances from the corner over the window, v Tj / 4 + acc Tj^2 / 24,
     * times dx / 2) */
    Ts += Tj / 2;
    for (int i = 0; i < 3; i++)
        dx += (B->dp[i] - A->dp[i]) * (B->dp[i] - A->dp[i]);
    dx = sqrt(dx);
    double room = tol - acc * Tj * Tj * dx / 48;
    for (int i = 3; i < 6; i++)
        da = motion_max2(da, fabs(B->dp[i] - A->dp[i]));
    if (dx > 1e-12) {
        v = motion_min2(v, JUMP_SHARE * c->max_lin_acc_mm_s2 * T / dx);
        v = room > 0 ? motion_min2(v, 4 * room / (Ts * dx)) : 0;
    }
    if (da > 1e-12)
        v = motion_min2(v, JUMP_SHARE * c->max_ang_acc_deg_s2 * T / da);
    for (int i = 0; i < m->nj; i++) {
        double dl = fabs(B->dL[i] - A->dL[i]);
        if (dl > 1e-12)
            v = motion_lower(v, 0.5 * JUMP_SHARE * c->joint[i].max_acc_mm_s2 * T / dl);
    }
    return v;
}

/* The share of one period's acceleration that passing the joint between samples A and B at
 * speed v uses for its velocity jump (the largest over X Y Z, A B C and the legs, as in
 * motion_junction_speed; at most JUMP_SHARE): the moves on either side give up that share
 * of their path acceleration. A tangent joint (a G64 blend arc meeting its lines) uses
 * next to none, so the moves around it keep their full acceleration. */
double motion_junction_share(const struct motion *m, const struct motion_sample *A,
                             const struct motion_sample *B, double v)
{
    const struct motion_config *c = &m->cfg;
    double T = c->servo_period_s, dx = 0, f = 0;
    for (int i = 0; i < 3; i++)
        dx += (B->dp[i] - A->dp[i]) * (B->dp[i] - A->dp[i]);
    f = v * sqrt(dx) / (c->max_lin_acc_mm_s2 * T);
    for (int i = 3; i < 6; i++)
        f = motion_max2(f, v * fabs(B->dp[i] - A->dp[i]) / (c->max_ang_acc_deg_s2 * T));
    for (int i = 0; i < m->nj; i++)
        f = motion_max2(f, v * fabs(B->dL[i] - A->dL[i]) / (0.5 * c->joint[i].max_acc_mm_s2 * T));
    return motion_min2(f, JUMP_SHARE);
}
