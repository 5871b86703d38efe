/* check_sim.c: the servo-rate pass: motion_step on a simulated clock, legs, rates, deviation, singularity. */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check/check_defer.h"
#include "check/check_priv.h"
#include "check/plot.h"
#include "common/simd.h"
#include "kins/kins_svd.h"

#define LIMIT_SLACK 1e-9     /* relative: a value counts as over its limit beyond this */
#define MAX_PERIODS_FACTOR 2 /* the run stops at twice the planned time (a stuck planner) */
#define LEG_BATCH 64          /* periods whose legs are tested together (legs_batch) */
#define CHECK_COND_BOUND_MARGIN 1e-9  /* relative to the largest singular value: what the
                                       * condition bound adds for the solver's rounding */

/* State of the pass between periods. */
struct sim {
    struct check_machine *mc;
    const struct check_opts *o;
    struct check_result *r;
    int nj;
    double T;                          /* servo period, s */
    double inv_T;                      /* 1 / T, 1/s */
    double L0[KINS_MAX_JOINTS];        /* set point of the previous period, mm */
    const double *prev_L, *prev_p;     /* the previous period's legs and pose: L0 and p0, or
                                        * the entry before in a calm run */
    const double *pose, *joints;       /* the period being measured: its pose and legs, its */
    double time_s, dist_mm;            /* clock and distance done (the record's, or a calm
                                        * run's entry: motion_step_calm) */
    const struct motion_calm *calm;    /* the calm run the period is of, or NULL (its */
    int calm_k;                        /* distance done is the run's calm_k-th, taken where
                                        * read) */
    double v0[KINS_MAX_JOINTS];        /* leg rate over the last period tested, mm/s (the
                                        * machine starts at rest: 0) */
    double a0[KINS_MAX_JOINTS];        /* leg acceleration of the last period tested */
    double jerk_thr[KINS_MAX_JOINTS];  /* jerk beyond which a leg is over (HUGE_VAL: none) */
    double vel_thr[KINS_MAX_JOINTS];   /* rate and acceleration beyond which a leg is over */
    double acc_thr[KINS_MAX_JOINTS];   /* its limit (the limit plus LIMIT_SLACK) */
    double len_lo[KINS_MAX_JOINTS];    /* the legs' length range */
    double len_hi[KINS_MAX_JOINTS];
    double min_mm[KINS_MAX_JOINTS], max_mm[KINS_MAX_JOINTS];     /* the legs' figures so far */
    /* The periods whose legs are not tested yet (legs_batch): their set points leg by leg,
     * and where each period was; the legs before them are bL0 (v0 and a0 are theirs). */
    double Lb[KINS_MAX_JOINTS][LEG_BATCH];
    int bline[LEG_BATCH];
    const char *bfile[LEG_BATCH];
    double btime[LEG_BATCH];
    int bn, bcap;                      /* periods held, and how many make a batch */
    long bfirst;                       /* the pass's index of the first (r->periods) */
    double bL0[KINS_MAX_JOINTS];
    double peak_vel[KINS_MAX_JOINTS], peak_acc[KINS_MAX_JOINTS], peak_jerk[KINS_MAX_JOINTS];
    double p0[KINS_POSE_DIM];          /* commanded pose of the previous period */
    int line;                          /* program line of the previous period */
    const char *file;
    double next_dev_s, next_cond_s;    /* machine time of the next scheduled measure */
    double cond_pose[KINS_POSE_DIM];   /* pose where the condition number was last taken */
    struct kins_tool_frame tf;         /* the machine's tool: the tip's deviation */
    int have_tf;
    int tip_line;                      /* a straight feed's tip line, its ends t0 t1 (the */
    double tip_key[KINS_POSE_DIM];     /* move's start, to know when the move changes) */
    double tip_t0[3], tip_t1[3];
    double tip_d[3], tip_n2;           /* t1 - t0 and its length squared */
    double tip_to[KINS_POSE_DIM];      /* the move's end pose, and the tool its tip t1 was */
    double tip_len;                    /* taken with (-1: under G43.4): the next move's t0 */
    int tip_fresh;                     /* the move began this period */
    int tip_swing;                     /* the move turns A B C (the tip may leave the line
                                        * the platform follows) and is not under G43.4 */
    double tip_pose[4][KINS_POSE_DIM]; /* periods whose tip is not measured yet (tips_held), */
    int tip_pline[4];                  /* their lines and indices: four tips take one call */
    long tip_pperiod[4];
    int tip_n;
    double move_tip2;                  /* the square of the tip's largest deviation measured
                                        * in place in the move being followed (the next
                                        * MOVE or FLUSH carries it) */
    double tip_max2;                   /* the square of the largest measured in place, its
                                        * line and period */
    int tip_max_line;
    long tip_max_period;
    double def_tip_max;                /* the largest of the deviations' tips (applied in */
    int def_tip_line;                  /* order), its line and period */
    long def_tip_period;
    double blk_tip_max;                /* the tip's largest deviation in this move, its line */
    double blk_tip_tol;                /* and how far the planner may round the move, mm */
    int blk_tip_line;
    const char *blk_tip_file;
    long trace_every, trace_count;
    struct check_defer *dq;            /* the costly measures, applied in order */
    int have_ref;                      /* a condition matrix solved exactly: the bound's */
    double ref_m[KINS_MAX_JOINTS * KINS_POSE_DIM];   /* reference, its extreme singular */
    double ref_smax, ref_smin;         /* values */
};

static void drain_before(struct sim *s, long period);

/* Where a held period was: its program line and file, its machine time, its index. */
struct period_at {
    int line;
    const char *file;
    double time_s;
    long period;
};

/* Adds a leg limit problem (velocity or acceleration) at period w. */
static void leg_limit(struct sim *s, const struct period_at *w, enum check_kind k, int leg,
                      double value, double limit)
{
    drain_before(s, w->period);        /* the measures before it come first, as they came */
    double t_s = w->time_s;
    struct check_problem p = { .kind = k, .line = w->line, .leg = leg, .value = value,
                               .limit = limit, .time_s = t_s, .count = 1 };
    snprintf(p.file, sizeof p.file, "%s", w->file ? w->file : "");
    const char *what = k == CHECK_LEG_VELOCITY ? "moves at"
                       : k == CHECK_LEG_JERK ? "changes its acceleration at" : "accelerates at";
    const char *unit = k == CHECK_LEG_VELOCITY ? "mm/s" : k == CHECK_LEG_JERK ? "mm/s^3"
                                                                              : "mm/s^2";
    const struct check_leg *lg = &s->r->leg[leg];
    snprintf(p.message, sizeof p.message, "leg %d %s %.3f %s, over its limit of %.3f %s "
             "([JOINT_%d] %s) at %.3f s", leg + 1, what, value, unit, limit, unit, leg,
             k == CHECK_LEG_VELOCITY ? lg->vel_key : k == CHECK_LEG_JERK ? "MAX_JERK"
                                                                         : lg->acc_key, t_s);
    check_add_problem(s->r, &p);
}

/* A leg beyond its length range at period w. */
static void leg_out_of_range(struct sim *s, const struct period_at *w, int i, double L)
{
    drain_before(s, w->period);
    const struct check_leg *lg = &s->r->leg[i];
    struct check_problem p = { .kind = CHECK_LEG_RANGE, .line = w->line, .leg = i,
                               .value = L, .time_s = w->time_s, .count = 1 };
    p.limit = L > lg->limit_max_mm ? lg->limit_max_mm : lg->limit_min_mm;
    snprintf(p.file, sizeof p.file, "%s", w->file ? w->file : "");
    snprintf(p.message, sizeof p.message, "leg %d reaches %.3f mm, beyond its limit %.3f mm",
             i + 1, L, p.limit);
    check_add_problem(s->r, &p);
}

/* A leg's rate, acceleration and jerk at length L from its length, rate and acceleration a
 * period before (1/T = inv_T): the one formula of both the batch and its replay. */
static inline void leg_diffs(double L, double Lp, double vp, double ap, double inv_T,
                             double *v, double *a, double *aj)
{
    *v = (L - Lp) * inv_T;
    *a = (*v - vp) * inv_T;
    *aj = fabs(*a - ap) * inv_T;
}

/* One leg's periods of the batch, from the state before them: lengths, rates from
 * successive set points, accelerations from successive rates, jerks from successive
 * accelerations, into the figures (the same values, compared the same way, as period by
 * period: a minimum or a maximum does not depend on the order it is taken in). Its state
 * after them into end[] (length, rate, acceleration); whether any period was over a limit
 * (the batch's own extremes against the limits). Lengths, rates and accelerations are
 * finite (the kinematics refuse a pose that is not): with that said to the compiler, the
 * extremes' loop becomes the vector max and min. */
__attribute__((optimize("finite-math-only", "no-signed-zeros")))
HEXCNC_CLONES                                      /* (four lanes where there are AVX2) */
static int leg_batch(struct sim *restrict s, int i, int n, double end[3])
{
    const double *L = s->Lb[i], T = s->inv_T;
    double v[LEG_BATCH], a[LEG_BATCH], j[LEG_BATCH];
    /* (leg_diffs' three differences, each period's from the one before it: written as
     * arrays, every period's is independent of the others' and the loops are vectorised) */
    v[0] = (L[0] - s->bL0[i]) * T;
    for (int k = 1; k < n; k++)
        v[k] = (L[k] - L[k - 1]) * T;
    a[0] = (v[0] - s->v0[i]) * T;
    for (int k = 1; k < n; k++)
        a[k] = (v[k] - v[k - 1]) * T;
    j[0] = fabs(a[0] - s->a0[i]) * T;
    for (int k = 1; k < n; k++)
        j[k] = fabs(a[k] - a[k - 1]) * T;
    double lo = HUGE_VAL, hi = -HUGE_VAL, pv = 0, pa = 0, pj = 0;
    for (int k = 0; k < n; k++) {
        double Lk = L[k], av = fabs(v[k]), aa = fabs(a[k]);
        lo = Lk < lo ? Lk : lo;
        hi = Lk > hi ? Lk : hi;
        pv = av > pv ? av : pv;
        pa = aa > pa ? aa : pa;
        pj = j[k] > pj ? j[k] : pj;
    }
    end[0] = L[n - 1], end[1] = v[n - 1], end[2] = a[n - 1];
    s->min_mm[i] = lo < s->min_mm[i] ? lo : s->min_mm[i];
    s->max_mm[i] = hi > s->max_mm[i] ? hi : s->max_mm[i];
    s->peak_vel[i] = pv > s->peak_vel[i] ? pv : s->peak_vel[i];
    s->peak_acc[i] = pa > s->peak_acc[i] ? pa : s->peak_acc[i];
    s->peak_jerk[i] = pj > s->peak_jerk[i] ? pj : s->peak_jerk[i];
    return hi > s->len_hi[i] || lo < s->len_lo[i] || pv > s->vel_thr[i] ||
           pa > s->acc_thr[i] || pj > s->jerk_thr[i];
}

/* The batch again period by period, from the state before it, reporting each period's
 * legs over a limit (out of line: a batch had one). */
static __attribute__((noinline)) void legs_report(struct sim *s, int n)
{
    double Lp[KINS_MAX_JOINTS], vp[KINS_MAX_JOINTS], ap[KINS_MAX_JOINTS];
    memcpy(Lp, s->bL0, sizeof Lp);
    memcpy(vp, s->v0, sizeof vp);
    memcpy(ap, s->a0, sizeof ap);
    for (int k = 0; k < n; k++) {
        struct period_at w = { s->bline[k], s->bfile[k], s->btime[k], s->bfirst + k };
        for (int i = 0; i < s->nj; i++) {
            const struct check_leg *lg = &s->r->leg[i];
            double L = s->Lb[i][k], v, a, aj;
            leg_diffs(L, Lp[i], vp[i], ap[i], s->inv_T, &v, &a, &aj);
            double av = fabs(v), aa = fabs(a);
            if (L > s->len_hi[i] || L < s->len_lo[i])
                leg_out_of_range(s, &w, i, L);
            if (av > s->vel_thr[i])
                leg_limit(s, &w, CHECK_LEG_VELOCITY, i, av, lg->limit_vel_mm_s);
            if (aa > s->acc_thr[i])
                leg_limit(s, &w, CHECK_LEG_ACCELERATION, i, aa, lg->limit_acc_mm_s2);
            if (aj > s->jerk_thr[i])
                leg_limit(s, &w, CHECK_LEG_JERK, i, aj, lg->limit_jerk_mm_s3);
            Lp[i] = L, vp[i] = v, ap[i] = a;
        }
    }
}

/* Tests the legs of the periods held: leg by leg through the batch (independent work the
 * processor overlaps, where period by period each leg's chain waited on the last), and
 * period by period again only when some limit was over. */
static void legs_batch(struct sim *s)
{
    int n = s->bn, over = 0;
    double end[KINS_MAX_JOINTS][3];
    if (!n)
        return;
    for (int i = 0; i < s->nj; i++)
        over |= leg_batch(s, i, n, end[i]);
    if (over)
        legs_report(s, n);
    for (int i = 0; i < s->nj; i++)
        s->bL0[i] = end[i][0], s->v0[i] = end[i][1], s->a0[i] = end[i][2];
    s->bn = 0;
}

/* Holds this period's legs for legs_batch. */
static void legs_hold(struct sim *s, const struct motion_out *out)
{
    int k = s->bn;
    if (k == 0)
        s->bfirst = s->r->periods;
    for (int i = 0; i < KINS_MAX_JOINTS; i++)    /* (all: a fixed count is unrolled; the */
        s->Lb[i][k] = s->joints[i];              /* legs past nj are never tested) */
    s->bline[k] = out->line, s->bfile[k] = out->file, s->btime[k] = s->time_s;
    if (++s->bn == s->bcap)
        legs_batch(s);
}

/* The pass's leg figures into the result. */
static void legs_figures(const struct sim *s)
{
    for (int i = 0; i < s->nj; i++) {
        struct check_leg *lg = &s->r->leg[i];
        lg->min_mm = s->min_mm[i], lg->max_mm = s->max_mm[i];
        lg->peak_vel_mm_s = s->peak_vel[i], lg->peak_acc_mm_s2 = s->peak_acc[i];
        lg->peak_jerk_mm_s3 = s->peak_jerk[i];
    }
}

/* The tool tip in the workpiece's frame (G43.4's program frame) at a platform pose, with
 * the tool of this period (G43.4's length, else [KINS] TOOL_LENGTH). */
static void tip_of(const struct sim *s, const struct motion_out *out, const double pose[6],
                   double tip[3])
{
    double prog[KINS_POSE_DIM];
    kins_tcp_from_pose(&s->tf, out->tcp ? out->tool_len_mm : s->tf.length_mm, pose, prog);
    memcpy(tip, prog, 3 * sizeof *tip);
}

/* The largest tip deviation of the move just left, as a problem when beyond the tolerance. */
static void tip_flush(struct sim *s)
{
    struct check_result *r = s->r;
    if (s->blk_tip_max > s->blk_tip_tol && r->kin_tol_mm > 0) {
        struct check_problem p = { .kind = CHECK_TIP_DEVIATION, .line = s->blk_tip_line,
                                   .leg = -1, .value = s->blk_tip_max, .limit = s->blk_tip_tol,
                                   .time_s = -1, .count = 1 };
        snprintf(p.file, sizeof p.file, "%s", s->blk_tip_file ? s->blk_tip_file : "");
        snprintf(p.message, sizeof p.message, "the tool tip leaves the straight line between "
                 "its positions at the move's ends by %.3f mm, over the tolerance of %.3f mm "
                 "(%s): the move turns A B C about the platform, not about the tip; program "
                 "the tip under G43.4 to keep it on the line", s->blk_tip_max, s->blk_tip_tol,
                 s->blk_tip_tol > r->kin_tol_mm ? "with jerk limits, half the G64 P"
                                                : "[TRAJ] KINEMATIC_TOLERANCE");
        check_add_warning(r, &p);
    }
    s->blk_tip_max = 0;
}

/* The next slot of the ring for a measure of this kind (applying the oldest while it is
 * full); fill it, then check_defer_commit. */
static struct check_defer_slot *slot_for(struct sim *s, enum check_defer_kind kind,
                                         const struct motion_out *out);

/* The tips of the periods held measured (defined with tip_period). */
static void tips_held(struct sim *s);

/* The largest tip deviation measured in place in the move being followed, mm, handed on
 * (the next move starts from nothing). */
static double move_tip_taken(struct sim *s)
{
    double d = sqrt(s->move_tip2);
    s->move_tip2 = 0;
    return d;
}

/* The end of the move being followed, in order with the measures: its tip warning, with the
 * largest deviation measured in place. A straight move that follows at once ends it with
 * its own MOVE instead (one slot for both). */
static void tip_end_move(struct sim *s, const struct motion_out *out)
{
    tips_held(s);
    struct check_defer_slot *q = slot_for(s, CHECK_DEFER_FLUSH, out);
    q->value2 = move_tip_taken(s);
    check_defer_commit(s->dq);
}

/* The straight feed being followed: its tip line (from the kinematics' tool at its ends, or
 * the programmed tip under G43.4), computed once per move. */
static void tip_move(struct sim *s, const struct motion_out *out)
{
    if (out->seg_kind != 1) {
        if (s->tip_line)
            tip_end_move(s, out);
        s->tip_line = 0;
        return;
    }
    s->tip_fresh = 0;
    if (s->tip_line && !memcmp(s->tip_key, out->seg_from, sizeof s->tip_key))
        return;
    tips_held(s);                      /* (the move before's, against its line) */
    s->tip_fresh = 1;
    int flush = s->tip_line;
    s->tip_line = 1;
    memcpy(s->tip_key, out->seg_from, sizeof s->tip_key);
    double len = out->tcp ? -1 : s->tf.length_mm;    /* (tip_of's tool) */
    if (out->tcp) {
        memcpy(s->tip_t0, out->seg_from, sizeof s->tip_t0);
        memcpy(s->tip_t1, out->seg_to, sizeof s->tip_t1);
    } else {
        /* (a move that starts where the last one ended, with the same tool, starts at its
         * tip: the same function of the same numbers) */
        if (flush && len == s->tip_len && !memcmp(out->seg_from, s->tip_to, sizeof s->tip_to))
            memcpy(s->tip_t0, s->tip_t1, sizeof s->tip_t0);
        else
            tip_of(s, out, out->seg_from, s->tip_t0);
        tip_of(s, out, out->seg_to, s->tip_t1);
    }
    s->tip_len = len;
    memcpy(s->tip_to, out->seg_to, sizeof s->tip_to);
    double n2 = 0;
    for (int i = 0; i < 3; i++)
        s->tip_d[i] = s->tip_t1[i] - s->tip_t0[i], n2 += s->tip_d[i] * s->tip_d[i];
    s->tip_n2 = n2;
    s->tip_swing = !out->tcp && (out->seg_from[3] != out->seg_to[3] ||
                                 out->seg_from[4] != out->seg_to[4] ||
                                 out->seg_from[5] != out->seg_to[5]);
    struct check_defer_slot *q = slot_for(s, CHECK_DEFER_MOVE, out);
    q->value = out->path_tol_mm;             /* the warning's line, file and tolerance */
    q->ok = flush;                           /* the move before ends here: its largest */
    q->value2 = move_tip_taken(s);           /* deviation in place */
    check_defer_commit(s->dq);
}

/* A deviation's tip d at program line `line`, in order, into the figures. */
static void tip_record(struct sim *s, int line, long period, double d)
{
    if (d > s->def_tip_max)
        s->def_tip_max = d, s->def_tip_line = line, s->def_tip_period = period;
    if (d > s->blk_tip_max)
        s->blk_tip_max = d;
}

/* The periods held by tip_period measured, in order: the commanded tip against the line
 * between the tip's positions at the move's ends (all held periods are of the move being
 * followed), four tips in one call where it can (kins_tcp_tips4: the same bits as one by
 * one). Before anything reads the largest deviations or the move changes. */
static void tips_held(struct sim *s)
{
    int n = s->tip_n;
    if (!n)
        return;
    double tip[4][3];
    for (int k = n; k < 4; k++)        /* (lanes without a period: one it can take) */
        memcpy(s->tip_pose[k], s->tip_pose[0], sizeof s->tip_pose[k]);
    if (!kins_tcp_tips4(&s->tf, s->tf.length_mm, (const double(*)[KINS_POSE_DIM])s->tip_pose,
                        tip))
        for (int k = 0; k < n; k++) {
            double prog[KINS_POSE_DIM];
            kins_tcp_from_pose(&s->tf, s->tf.length_mm, s->tip_pose[k], prog);
            memcpy(tip[k], prog, sizeof tip[k]);
        }
    for (int k = 0; k < n; k++) {
        double e2 = motion_dist2_seg(tip[k], s->tip_t0, s->tip_d, s->tip_n2);
        if (e2 > s->move_tip2)
            s->move_tip2 = e2;
        if (e2 > s->tip_max2)
            s->tip_max2 = e2, s->tip_max_line = s->tip_pline[k],
            s->tip_max_period = s->tip_pperiod[k];
    }
    s->tip_n = 0;
}

/* Every period of a straight feed that turns A B C without G43.4 (tip_of's tool, the
 * kinematics' own: no G43.4 length), held for tips_held. Measured here, in place: a
 * rotation and a distance cost less than a slot of the ring every period. */
static void tip_period(struct sim *s, const struct motion_out *out, bool same_seg)
{
    if (!same_seg)
        tip_move(s, out);
    else if (out->seg_kind == 1)       /* (tip_move on the move it has: not fresh) */
        s->tip_fresh = 0;
    if (!s->tip_line || !s->tip_swing)
        return;
    int k = s->tip_n;
    memcpy(s->tip_pose[k], s->pose, sizeof s->tip_pose[k]);
    s->tip_pline[k] = out->line, s->tip_pperiod[k] = s->r->periods;
    if (++s->tip_n == 4)
        tips_held(s);
}

/* The tip's figure: the larger of the two maxima, the earlier on a tie (in a period, the
 * tip is measured before its deviation), as one pass in order would find it. */
static void tip_figure(const struct sim *s)
{
    struct check_result *r = s->r;
    double v = s->def_tip_max, tip_max = sqrt(s->tip_max2);
    int line = s->def_tip_line;
    if (tip_max > v || (tip_max == v && s->tip_max_period <= s->def_tip_period))
        v = tip_max, line = s->tip_max_line;
    if (v > r->max_tip_deviation_mm)
        r->max_tip_deviation_mm = v, r->max_tip_deviation_line = line;
}

/* Kinematic deviation between the previous set point and this one (check_defer.c computes
 * it): the legs of both, the poses, and how the tip of the interpolated legs is measured. */
static void deviation(struct sim *s, const struct motion_out *out)
{
    struct check_defer_slot *q = slot_for(s, CHECK_DEFER_DEVIATION, out);
    memcpy(q->p0, s->prev_p, sizeof q->p0);
    memcpy(q->L0, s->prev_L, sizeof q->L0);
    memcpy(q->L1, s->joints, sizeof q->L1);
    q->tool_len_mm = out->tcp ? out->tool_len_mm : s->tf.length_mm;
    q->tip_mode = CHECK_TIP_NONE;
    if (s->have_tf && s->tip_line && !s->tip_fresh) {
        /* from its move's line (a synchronised move's tool runs on past its ends along it:
         * a tap while the spindle reverses, no deviation), or (arcs, rapids) from */
        q->tip_mode = motion_sync_running(s->mc->motion) ? CHECK_TIP_AXIS : CHECK_TIP_LINE;
        memcpy(q->t0, s->tip_t0, sizeof q->t0);   /* the chord between the set points' tips */
        memcpy(q->t1, s->tip_t1, sizeof q->t1);
    } else if (s->have_tf && out->seg_kind) {
        q->tip_mode = CHECK_TIP_CHORD;
    }
    check_defer_commit(s->dq);
}

/* A deviation's result, in order. */
static void deviation_result(struct sim *s, const struct check_defer_slot *q)
{
    struct check_result *r = s->r;
    if (!q->ok)
        return;
    r->deviation_evals++;
    if (q->value > r->max_deviation_mm)
        r->max_deviation_mm = q->value, r->max_deviation_line = q->line;
    if (q->value2 > r->max_deviation_deg)
        r->max_deviation_deg = q->value2;
    if (s->o->trace)
        check_trace_deviation(s->o->trace, q->dist_mm, q->time_s, q->value);
    if (q->tip_mode != CHECK_TIP_NONE)
        tip_record(s, q->line, q->period, q->tip);
}

/* Whether the condition number of slot q's matrix is bounded by the last one solved at or
 * below both the largest so far and the limit, so that solving it could change nothing.
 * Weyl: each singular value of M moves by at most ||M - M_ref||_2 <= ||M - M_ref||_F = e,
 * so cond(M) <= (smax_ref + e) / (smin_ref - e). The margin covers the solver's rounding
 * (relative 1e-14 here) many times over. */
static int condition_bounded(const struct sim *s, const struct check_defer_slot *q)
{
    if (!s->have_ref)
        return 0;
    double e2 = 0;
    for (int i = 0; i < s->nj * KINS_POSE_DIM; i++)
        e2 += (q->m[i] - s->ref_m[i]) * (q->m[i] - s->ref_m[i]);
    double e = sqrt(e2) + CHECK_COND_BOUND_MARGIN * s->ref_smax, lo = s->ref_smin - e;
    if (!(lo > 0))
        return 0;
    double bound = (s->ref_smax + e) / lo;
    return bound <= s->r->max_condition && bound <= s->r->condition_limit;
}

/* The condition number of slot q: its value, or its matrix solved (which becomes the
 * bound's reference); -1 when a bound shows it can change nothing. */
static double condition_of(struct sim *s, const struct check_defer_slot *q)
{
    if (!q->has_m)
        return q->value;
    if (!s->o->solve_every_condition && condition_bounded(s, q)) {
        s->r->condition_bounded++;
        return -1;
    }
    double smax, smin, cond;
    int nm = s->nj * KINS_POSE_DIM;
    s->have_ref = kins_svd_extremes(q->m, s->nj, KINS_POSE_DIM, &smax, &smin, &cond) == 0;
    if (!s->have_ref)
        return INFINITY;
    memcpy(s->ref_m, q->m, (size_t)nm * sizeof *s->ref_m);
    s->ref_smax = smax, s->ref_smin = smin;
    return cond;
}

/* A condition number's result against [KINS] SINGULAR_CONDITION, in order. */
static void singularity(struct sim *s, const struct check_defer_slot *q)
{
    struct check_result *r = s->r;
    if (!q->ok)
        return;
    r->condition_evals++;
    double value = condition_of(s, q);
    if (value > r->max_condition)
        r->max_condition = value, r->max_condition_line = q->line;
    if (!(value > r->condition_limit))
        return;
    const double *P = q->pose;
    struct check_problem p = { .kind = CHECK_SINGULAR, .line = q->line, .leg = -1,
                               .value = value, .limit = r->condition_limit,
                               .time_s = q->time_s, .count = 1 };
    snprintf(p.file, sizeof p.file, "%s", q->file ? q->file : "");
    snprintf(p.message, sizeof p.message, "the machine comes close to a singular pose at X%.3f "
             "Y%.3f Z%.3f A%.3f B%.3f C%.3f: condition number %.1f above %.1f ([KINS] "
             "SINGULAR_CONDITION); it loses stiffness and accuracy there", P[0], P[1], P[2],
             P[3], P[4], P[5], value, r->condition_limit);
    check_add_problem(r, &p);
}

/* Applies one slot's result. */
static void apply(struct sim *s, const struct check_defer_slot *q)
{
    switch (q->kind) {
    case CHECK_DEFER_DEVIATION: deviation_result(s, q); break;
    case CHECK_DEFER_CONDITION: singularity(s, q); break;
    case CHECK_DEFER_FLUSH:
        s->blk_tip_max = fmax(s->blk_tip_max, q->value2);
        tip_flush(s);
        break;
    case CHECK_DEFER_MOVE:
        if (q->ok) {                   /* the move before ends here */
            s->blk_tip_max = fmax(s->blk_tip_max, q->value2);
            tip_flush(s);
        }
        s->blk_tip_line = q->line, s->blk_tip_file = q->file, s->blk_tip_tol = q->value;
        break;
    }
}

static struct check_defer_slot *slot_for(struct sim *s, enum check_defer_kind kind,
                                         const struct motion_out *out)
{
    struct check_defer_slot *q;
    while (!(q = check_defer_push(s->dq, kind))) {
        legs_batch(s);                 /* (the legs' problems before the measures after) */
        apply(s, check_defer_next(s->dq, 1));
    }
    q->line = out->line, q->file = out->file, q->period = s->r->periods;
    q->time_s = s->time_s;
    q->dist_mm = s->calm ? motion_calm_dist(s->calm, s->calm_k) : s->dist_mm;
    memcpy(q->pose, s->pose, sizeof q->pose);
    return q;
}

/* The measures taken before period `period`, applied (waiting for those being computed):
 * what comes before a problem found in that period. */
static void drain_before(struct sim *s, long period)
{
    const struct check_defer_slot *o;
    while ((o = check_defer_oldest(s->dq)) && o->period < period)
        apply(s, check_defer_next(s->dq, 1));
}

/* The legs held tested, and every measure taken so far applied. */
static void drain(struct sim *s)
{
    legs_batch(s);
    drain_before(s, LONG_MAX);
}

/* Whether the pose has moved CHECK_COND_STEP_MM or _DEG from where the condition number
 * was last taken. */
static int cond_moved(const struct sim *s, const double pose[KINS_POSE_DIM])
{
    double d2 = 0, da = 0;
    for (int i = 0; i < 3; i++)
        d2 += (pose[i] - s->cond_pose[i]) * (pose[i] - s->cond_pose[i]);
    for (int i = 3; i < KINS_POSE_DIM; i++)
        da = fmax(da, fabs(pose[i] - s->cond_pose[i]));
    return d2 >= CHECK_COND_STEP_MM * CHECK_COND_STEP_MM || da >= CHECK_COND_STEP_DEG;
}

/* The scheduled measures of one period: the deviation at every line change, the condition
 * number at a line change the pose has moved on from (dense code changes line every few
 * tenths of a millimetre, and a condition number costs several servo periods), and
 * both on their schedule. Taken here, computed by whichever thread has time (the
 * planner's, when it waits for this pass), applied in order. */
static void measures(struct sim *s, const struct motion_out *out)
{
    double t = s->time_s;
    int changed = out->line != s->line || out->file != s->file;
    if ((changed && cond_moved(s, s->pose)) || t >= s->next_cond_s) {
        slot_for(s, CHECK_DEFER_CONDITION, out);
        check_defer_commit(s->dq);
        memcpy(s->cond_pose, s->pose, sizeof s->cond_pose);
        s->next_cond_s = t + s->o->condition_every_s;
    }
    if (changed || t >= s->next_dev_s) {
        deviation(s, out);
        s->next_dev_s = t + s->o->deviation_every_s;
    }
    /* what is ready, without waiting, once the legs' batch is tested (a leg's problem comes
     * before the measures of its period and after): between batches nothing more could be
     * applied but what became ready meanwhile, and a look at the helper's claims each period
     * cost more than it saved (a cache line the other thread writes) */
    if (s->bn)
        return;
    const struct check_defer_slot *q;
    while (check_defer_oldest(s->dq) && (q = check_defer_next(s->dq, 0)))
        apply(s, q);
}

/* Per-leg limits from the kinematics and the motion configuration. */
static void leg_limits(struct sim *s)
{
    const struct kins *k = s->mc->kins;
    struct motion_config planned = s->mc->mcfg;
    motion_jerk_share(&planned);     /* what motion plans to (lower under JERK_WINDOW) */
    for (int i = 0; i < s->nj; i++) {
        struct check_leg *lg = &s->r->leg[i];
        lg->limit_min_mm = k->joint_min[i], lg->limit_max_mm = k->joint_max[i];
        lg->limit_vel_mm_s = s->mc->mcfg.joint[i].max_vel_mm_s;
        lg->limit_acc_mm_s2 = s->mc->mcfg.joint[i].max_acc_mm_s2;
        lg->planned_acc_mm_s2 = planned.joint[i].max_acc_mm_s2;
        lg->vel_key = "MAX_VELOCITY", lg->acc_key = "MAX_ACCELERATION";
        /* a step generator slower than the planner's limit cannot follow: check against it */
        if (s->mc->drive_vel[i] > 0 && s->mc->drive_vel[i] < lg->limit_vel_mm_s)
            lg->limit_vel_mm_s = s->mc->drive_vel[i], lg->vel_key = "STEPGEN_MAXVEL";
        if (s->mc->drive_acc[i] > 0 && s->mc->drive_acc[i] < lg->limit_acc_mm_s2)
            lg->limit_acc_mm_s2 = s->mc->drive_acc[i], lg->acc_key = "STEPGEN_MAXACCEL";
        s->vel_thr[i] = lg->limit_vel_mm_s * (1 + LIMIT_SLACK);
        s->acc_thr[i] = lg->limit_acc_mm_s2 * (1 + LIMIT_SLACK);
        lg->limit_jerk_mm_s3 = s->mc->mcfg.joint[i].max_jerk_mm_s3;
        s->jerk_thr[i] = lg->limit_jerk_mm_s3 > 0 ? lg->limit_jerk_mm_s3 * (1 + LIMIT_SLACK)
                                                  : HUGE_VAL;
        lg->min_mm = HUGE_VAL, lg->max_mm = -HUGE_VAL;
        s->len_lo[i] = lg->limit_min_mm, s->len_hi[i] = lg->limit_max_mm;
        s->min_mm[i] = HUGE_VAL, s->max_mm[i] = -HUGE_VAL;
        s->peak_vel[i] = lg->peak_vel_mm_s, s->peak_acc[i] = lg->peak_acc_mm_s2;
        s->peak_jerk[i] = lg->peak_jerk_mm_s3;
    }
}

/* The period count past which motion counts as stuck: twice the planned time (a streamed
 * program's once its planner has ended, none before: the planner paces it). */
static long period_bound(const struct sim *s, double planned_s)
{
    return planned_s >= 0 ? (long)(MAX_PERIODS_FACTOR * planned_s / s->T) + 1000 : LONG_MAX;
}

/* One period measured: legs, tip, the scheduled measures. Its pose, legs, clock and
 * distance are s's (sim_at), the rest the record's; same_seg: the period before was on the
 * same segment, and measured with this record (a calm run's). */
static inline void sim_period(struct sim *s, const struct motion_out *out, bool same_seg)
{
    s->r->periods++;
    legs_hold(s, out);
    if (s->have_tf)
        tip_period(s, out, same_seg);
    measures(s, out);
    s->line = out->line, s->file = out->file;
}

/* The period to measure next: pose, legs, clock and distance done. */
static inline void sim_at(struct sim *s, const double *pose, const double *joints,
                          double time_s, double dist_mm)
{
    s->pose = pose, s->joints = joints, s->time_s = time_s, s->dist_mm = dist_mm;
}

/* The period measured becomes the one before the next (kept: the record and the calm
 * run's entries are written over by the next step). */
static inline void sim_keep(struct sim *s)
{
    memcpy(s->L0, s->joints, sizeof s->L0);
    memcpy(s->p0, s->pose, sizeof s->p0);
    s->prev_L = s->L0, s->prev_p = s->p0;
}

/* Steps motion at the servo period to the program's end, measuring as it goes. */
int check_simulate(struct check_machine *mc, const double start[KINS_POSE_DIM],
                   const struct check_opts *o, const struct check_feed *feed,
                   struct check_result *r)
{
    struct sim s = { .mc = mc, .o = o, .r = r, .nj = mc->kins->njoints,
                     .T = mc->mcfg.servo_period_s, .inv_T = 1 / mc->mcfg.servo_period_s };
    s.have_tf = kins_get_tool_frame(mc->kins, &s.tf) == KINS_OK;
    r->tip_measured = s.have_tf;
    struct check_defer *own = NULL;
    s.dq = feed && feed->defer ? feed->defer
         : (own = check_defer_new(mc->kins, s.have_tf ? &s.tf : NULL, o->cold_forward));
    if (!s.dq)
        return CHECK_ERR_NOMEM;
    struct motion_out out;
    double planned_s = -1;
    if (!feed) {
        struct motion_plan_info info;
        motion_plan_info(mc->motion, &info);
        r->planned_time_s = planned_s = info.time_s;
    }
    r->njoints = s.nj;
    leg_limits(&s);
    if (kins_inverse(mc->kins, start, s.L0) != KINS_OK) {  /* motion starts here */
        check_defer_free(own);
        return CHECK_ERR_KINS;
    }
    memcpy(s.p0, start, sizeof s.p0);
    s.prev_L = s.L0, s.prev_p = s.p0;
    memcpy(s.bL0, s.L0, sizeof s.bL0);
    s.bcap = (o->trace && !feed) || o->legs_every_period ? 1 : LEG_BATCH;  /* (the trace
                                                        * samples the legs' rates) */
    for (int i = 0; i < KINS_POSE_DIM; i++)   /* the first line change takes it */
        s.cond_pose[i] = HUGE_VAL;
    int st = MOTION_OK;
    long max_periods = period_bound(&s, planned_s);
    if (o->trace && !feed)
        s.trace_every = check_trace_begin(o->trace, planned_s, s.T);
    memset(&out, 0, sizeof out);
    motion_set_rates(mc->motion, false);   /* rates come from differences of set points */
    motion_set_brief(mc->motion, true);    /* (and the record holds what the pass reads) */
    motion_set_ahead(mc->motion, true);    /* (eight periods ahead, four legs' sets at once,
                                            * where it can; runs of calm periods) */
    /* (calm periods several at a time, motion_step_calm; not where a trace samples them) */
    int calm_on = !(o->trace && !feed);
    struct motion_calm calm;
    for (long n = 0; n < max_periods;) {
        if (feed && motion_stream_starving(mc->motion)) {
            if (!feed->wait(feed->ctx))
                break;                  /* the planner stopped: nothing more to follow */
            if (max_periods == LONG_MAX)
                max_periods = period_bound(&s, feed->planned_s(feed->ctx));
        }
        int nc = calm_on && max_periods - n >= MOTION_CALM_MAX
                 ? motion_step_calm(mc->motion, s.T, &calm, &out) : 0;
        if (nc > 0) {
            /* (the record is the last period's: each period's own pose, legs, clock and
             * distance with the rest of it, which is the same in all) */
            for (int k = 0; k < nc; k++) {
                sim_at(&s, calm.pose[k], calm.joints[k], calm.time_s[k], 0);
                s.calm = &calm, s.calm_k = k;
                sim_period(&s, &out, k > 0);
                s.prev_p = calm.pose[k], s.prev_L = calm.joints[k];
            }
            sim_keep(&s);
            s.calm = NULL;
            n += nc;
            continue;
        }
        st = motion_step(mc->motion, s.T, &out);
        n++;
        sim_at(&s, out.pose, out.joint_pos, out.time_elapsed_s, out.distance_done_mm);
        sim_period(&s, &out, false);
        sim_keep(&s);
        if (o->trace && !feed && ++s.trace_count >= s.trace_every) {
            check_trace_add(o->trace, out.time_elapsed_s, s.nj, out.joint_pos, s.v0, out.pose);
            s.trace_count = 0;
        }
        if (out.state == MOTION_DONE || out.state == MOTION_FAULT || st != MOTION_OK)
            break;
        if (out.state == MOTION_PAUSED)   /* M0/M1: the operator would press resume */
            motion_resume(mc->motion);
    }
    sim_at(&s, out.pose, out.joint_pos, out.time_elapsed_s, out.distance_done_mm);
    motion_set_rates(mc->motion, true);
    motion_set_brief(mc->motion, false);
    motion_set_ahead(mc->motion, false);
    legs_batch(&s);
    legs_figures(&s);
    if (s.tip_line)
        tip_end_move(&s, &out);        /* (with the tips held) */
    drain(&s);
    tip_figure(&s);
    check_defer_free(own);
    r->machining_time_s = out.time_elapsed_s;
    r->length_mm = out.distance_total_mm;
    return st == MOTION_OK && out.state == MOTION_DONE ? CHECK_OK : CHECK_ERR_CONFIG;
}
