/* motion_jerk.c: jerk limiting: the executor's set points through a moving average. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_priv.h"

/*
 * The executor (motion_step.c) follows the trapezoidal plan and keeps every leg within its
 * speed and acceleration in every servo period. With jerk limits set, what it computes is
 * the "leader"; the drives get the mean of the leader's last N set points (N periods of
 * length dt, T = N dt):
 *
 *      leader legs  L_k ──► [ mean of L_k .. L_k-N+1 ] ──► drives   (and so for the pose)
 *
 * Differencing commutes with the mean, so period by period
 *      speed  = mean of the leader's speeds          <= MAX_VELOCITY
 *      accel. = mean of the leader's accelerations   <= MAX_ACCELERATION
 *      jerk   = (a_k - a_k-N) / T                    <= 2 MAX_ACCELERATION / T <= MAX_JERK
 * for every leg, exactly, whatever the leader does: ramps, corners, curvature steps where a
 * line meets an arc, feed holds, overrides and aborts (all of which ramp the leader's speed
 * on the path). T = 2 a / j over the path's linear and angular limits, and over the legs' with
 * a leg's acceleration lowered to fit where its own ratio is longer (the default window,
 * motion_jerk_default_window_s; [TRAJ] JERK_WINDOW sets another).
 *
 * The price is a lag of T/2 and a rounding of the path: where the leader goes straight at any
 * speed or acceleration the mean stays on its line (only the legs' own curvature rounds it);
 * on a curve it cuts inside by |q| v^2 T^2 / 24 (q: the pose curvature), which the planner
 * keeps within KINEMATIC_TOLERANCE together with the set-point chords (motion_chord_period).
 * Where the path changes direction at a stop the leader rests T (motion_plan.c), so the mean
 * comes to rest exactly on the corner. The machine counts as stopped (paused, done, idle,
 * parked on a probe trip) only once the mean has settled on the leader. Spindle-synchronised
 * moves (G33, G33.1) bypass the mean: their jerk is the spindle's. The outputs M62..M68
 * and the spindle's and coolant's commands (M3 M4 M5 S, M7 M8 M9) switch with the mean too,
 * where the tool reaches them on the path, not T/2 ahead of it (at rest, at once). The
 * executor's own logic goes by the leader's, but for a wait for the spindle at speed, which
 * counts from when motion_out gives the spindle the command (motion_step.c).
 */

/* Values averaged, in this order: pose, pose rate, path pose, legs, leg rates, path speed,
 * distance. */
#define JERK_DIM (3 * KINS_POSE_DIM + 2 * KINS_MAX_JOINTS + 2)
#define JERK_LEGS (3 * KINS_POSE_DIM)  /* where the legs begin in a sample */

/* What is not averaged: the move being followed, delayed by half the window (where the mean
 * lies on the path). */
struct motion_jerk_meta {
    int line, seg_kind, tcp;
    const char *file;
    double tool_len_mm, path_tol_mm;
    double seg_from[KINS_POSE_DIM], seg_to[KINS_POSE_DIM];
    struct motion_outputs outputs;     /* M62..M68: switched where the tool is */
    struct motion_spindle io;          /* spindle and coolant: switched where the tool is */
};

struct motion_jerk {
    int n;                   /* periods averaged (N) */
    int head;                /* ring slot the next leader sample goes to */
    int primed;              /* the ring holds the leader's samples (0: at rest on last) */
    int still;               /* consecutive leader samples equal to the one before */
    int fresh_n;             /* samples in fresh since it was last taken as the sums */
    double *ring;            /* n x JERK_DIM leader samples */
    struct motion_jerk_meta *meta; /* n */
    double sum[JERK_DIM];    /* running sums of the window: the newest in, the oldest out */
    double fresh[JERK_DIM];  /* the newest fresh_n samples summed anew: after n of them it is
                              * the window's exact sum and replaces sum, so rounding never
                              * accumulates (O(1) a period, no recount of the window) */
    double last[JERK_DIM];   /* the last output, or the pose held while not following */
    struct motion_jerk_meta last_meta;
};

/* The longest of 2 x acceleration / jerk over the path, A B C and the legs, a leg's
 * acceleration taken no higher than leg_acc_cap, s (0: no jerk limits). */
static double longest_window(const struct motion_config *c, double leg_acc_cap)
{
    if (!c || c->max_lin_jerk_mm_s3 <= 0)
        return 0;
    double t = 2 * c->max_lin_acc_mm_s2 / c->max_lin_jerk_mm_s3;
    if (c->max_ang_jerk_deg_s3 > 0)
        t = fmax(t, 2 * c->max_ang_acc_deg_s2 / c->max_ang_jerk_deg_s3);
    for (int i = 0; i < c->njoints; i++)
        if (c->joint[i].max_jerk_mm_s3 > 0)
            t = fmax(t, 2 * fmin(c->joint[i].max_acc_mm_s2, leg_acc_cap) /
                            c->joint[i].max_jerk_mm_s3);
    return t;
}

/* The longest of 2 x acceleration / jerk over the path, A B C and the legs, s (not yet in
 * whole periods): the window in which the leader may use every acceleration in full. */
double motion_jerk_full_window_s(const struct motion_config *c)
{
    return longest_window(c, HUGE_VAL);
}

/* The window without [TRAJ] JERK_WINDOW, s (not yet in whole periods): the path's and A B C's
 * 2 x acceleration / jerk, and each leg's with its acceleration taken no higher than the
 * path's; but no shorter than MOTION_JERK_DEFAULT_MIN_S where the full window is longer. The
 * path and A B C keep every acceleration in full; a leg whose own ratio asks a longer window
 * is given MAX_JERK x window / 2 (motion_jerk_share), never less than the path's
 * acceleration: a translation at the path's full acceleration asks no more of any leg (a
 * leg's length changes by at most the tool's distance), and the legs keep their share for
 * the bends. On the TMU (legs 1000 mm/s^2 against the path's 500, jerk 50,000 on both) the
 * default is 20 ms where the full window is 40 ms: the dense hour in 7,421 s against 13,682,
 * each of 300 random dense programs on it and two variants of it in 0.50 - 0.88 of its time,
 * none longer (docs/motion.md).
 * With four times those jerk limits the path's ratio is 5 ms and the full window 10 ms: there
 * the 5 ms one took longer (a random program under G64 P0.001 1.16 times, its corners passed
 * with a velocity jump that the lowered accelerations halve), hence the least. */
double motion_jerk_default_window_s(const struct motion_config *c)
{
    if (!c || c->max_lin_jerk_mm_s3 <= 0)
        return 0;
    return fmax(longest_window(c, c->max_lin_acc_mm_s2),
                fmin(motion_jerk_full_window_s(c), MOTION_JERK_DEFAULT_MIN_S));
}

double motion_jerk_window_s(const struct motion_config *c)
{
    double t = motion_jerk_default_window_s(c);
    if (t <= 0)
        return 0;
    if (c->jerk_window_s > 0)       /* [TRAJ] JERK_WINDOW, up to the full window */
        t = c->jerk_window_s;
    /* whole periods: the window is n periods, never shorter than asked */
    double n = ceil(t / c->servo_period_s - 1e-9);
    return fmax(n, 2) * c->servo_period_s;
}

void motion_jerk_share(struct motion_config *c)
{
    double T = motion_jerk_window_s(c);
    if (T <= 0 || T >= motion_jerk_full_window_s(c))
        return;                     /* (every acceleration in full: nothing to lower) */
    /* the mean's jerk is at most 2 a / T: a leader within j T / 2 keeps j */
    c->max_lin_acc_mm_s2 = fmin(c->max_lin_acc_mm_s2, c->max_lin_jerk_mm_s3 * T / 2);
    c->max_ang_acc_deg_s2 = fmin(c->max_ang_acc_deg_s2, c->max_ang_jerk_deg_s3 * T / 2);
    for (int i = 0; i < c->njoints; i++)
        c->joint[i].max_acc_mm_s2 = fmin(c->joint[i].max_acc_mm_s2,
                                         c->joint[i].max_jerk_mm_s3 * T / 2);
    c->jerk_window_s = T;           /* (the lowered limits' own default could differ) */
}

double motion_chord_period(const struct motion_config *c)
{
    double ts = c->setpoint_period_s > 0 ? c->setpoint_period_s : c->servo_period_s;
    double tj = motion_jerk_window_s(c);
    return tj > 0 ? sqrt(ts * ts + tj * tj / 3) : ts;
}

/* The motion's values of the period into x and meta. */
static void gather(const struct motion *m, double *x, struct motion_jerk_meta *mt)
{
    int o = 0;
    memcpy(x + o, m->pose, sizeof m->pose), o += KINS_POSE_DIM;
    memcpy(x + o, m->pose_vel, sizeof m->pose_vel), o += KINS_POSE_DIM;
    memcpy(x + o, m->prog_pose, sizeof m->prog_pose), o += KINS_POSE_DIM;
    memcpy(x + o, m->joint_cmd, sizeof m->joint_cmd), o += KINS_MAX_JOINTS;
    memcpy(x + o, m->joint_vel, sizeof m->joint_vel), o += KINS_MAX_JOINTS;
    x[o++] = m->path_vel;
    x[o] = m->dist_mm;
    mt->line = m->line, mt->seg_kind = m->seg_kind, mt->tcp = m->tcp, mt->file = m->file;
    mt->tool_len_mm = m->tool_len_mm;
    mt->path_tol_mm = m->path_tol_mm;
    memcpy(mt->seg_from, m->seg_from, sizeof mt->seg_from);
    memcpy(mt->seg_to, m->seg_to, sizeof mt->seg_to);
    mt->outputs = m->outputs;
    mt->io = m->io;
}

/* x and meta into the motion's values. */
static void scatter(struct motion *m, const double *x, const struct motion_jerk_meta *mt)
{
    int o = 0;
    memcpy(m->pose, x + o, sizeof m->pose), o += KINS_POSE_DIM;
    memcpy(m->pose_vel, x + o, sizeof m->pose_vel), o += KINS_POSE_DIM;
    memcpy(m->prog_pose, x + o, sizeof m->prog_pose), o += KINS_POSE_DIM;
    memcpy(m->joint_cmd, x + o, sizeof m->joint_cmd), o += KINS_MAX_JOINTS;
    memcpy(m->joint_vel, x + o, sizeof m->joint_vel), o += KINS_MAX_JOINTS;
    m->path_vel = x[o++];
    m->dist_mm = x[o];
    m->line = mt->line, m->seg_kind = mt->seg_kind, m->tcp = mt->tcp, m->file = mt->file;
    m->seg_at = NULL;          /* (the leader's segment values are taken again) */
    m->tool_len_mm = mt->tool_len_mm;
    m->path_tol_mm = mt->path_tol_mm;
    memcpy(m->seg_from, mt->seg_from, sizeof m->seg_from);
    memcpy(m->seg_to, mt->seg_to, sizeof m->seg_to);
    m->outputs_out = mt->outputs;
    m->io_out = mt->io;
}

int motion_jerk_init(struct motion *m, char *err, size_t errlen)
{
    double w = motion_jerk_window_s(&m->cfg);
    if (w <= 0)
        return MOTION_OK;
    struct motion_jerk *j = calloc(1, sizeof *j);
    int n = (int)lround(w / m->cfg.servo_period_s);
    if (j) {
        j->ring = calloc((size_t)n * JERK_DIM, sizeof *j->ring);
        j->meta = calloc((size_t)n, sizeof *j->meta);
    }
    if (!j || !j->ring || !j->meta) {
        if (j)
            free(j->ring), free(j->meta);
        free(j);
        snprintf(err, errlen, "out of memory for the jerk limiter's %d periods", n);
        return MOTION_ERR_NOMEM;
    }
    j->n = n;
    m->jerk = j;
    motion_jerk_hold(m);
    return MOTION_OK;
}

void motion_jerk_free(struct motion *m)
{
    if (m->jerk) {
        free(m->jerk->ring);
        free(m->jerk->meta);
        free(m->jerk);
        m->jerk = NULL;
    }
}

bool motion_jerk_settled(const struct motion *m)
{
    const struct motion_jerk *j = m->jerk;
    return !j || !j->primed || j->still >= j->n - 1;
}

/* Every slot of the ring holds the last output: the mean is at rest there. */
static void prime(struct motion_jerk *j)
{
    for (int k = 0; k < j->n; k++) {
        memcpy(j->ring + (size_t)k * JERK_DIM, j->last, sizeof j->last);
        j->meta[k] = j->last_meta;
    }
    for (int d = 0; d < JERK_DIM; d++)
        j->sum[d] = j->n * j->last[d];
    j->primed = 1;
    j->still = j->n - 1;
    memset(j->fresh, 0, sizeof j->fresh);
    j->fresh_n = 0;
}

/* The leader's sample x in, the mean of the window into the motion. */
static void push(struct motion *m, const double *x, const struct motion_jerk_meta *mt)
{
    struct motion_jerk *j = m->jerk;
    double *slot = j->ring + (size_t)j->head * JERK_DIM;
    const double *newest = j->ring + (size_t)((j->head + j->n - 1) % j->n) * JERK_DIM;
    j->still = memcmp(x, newest, JERK_DIM * sizeof *x) ? 0 : j->still + 1;
    for (int d = 0; d < JERK_DIM; d++)
        j->sum[d] += x[d] - slot[d], j->fresh[d] += x[d];
    memcpy(slot, x, JERK_DIM * sizeof *x);
    j->meta[j->head] = *mt;
    j->head = (j->head + 1) % j->n;
    if (++j->fresh_n == j->n) {        /* fresh holds exactly the window now */
        memcpy(j->sum, j->fresh, sizeof j->sum);
        memset(j->fresh, 0, sizeof j->fresh);
        j->fresh_n = 0;
    }
    if (j->still >= j->n - 1)           /* settled: exactly the leader's, not a rounded mean */
        memcpy(j->last, x, sizeof j->last);
    else
        for (int d = 0; d < JERK_DIM; d++)
            j->last[d] = j->sum[d] / j->n;
    /* the window's middle sample: where the mean lies on the path; at rest, where the
     * leader is (the mean is there too): what the leader passed standing there is reached,
     * so a spindle started at a stop is out before the wait for its speed begins */
    j->last_meta = j->still >= j->n - 1 ? *mt : j->meta[(j->head + j->n / 2) % j->n];
    scatter(m, j->last, &j->last_meta);
}

void motion_jerk_shift_leg(struct motion *m, int i, double shift)
{
    struct motion_jerk *j = m->jerk;
    if (!j)
        return;
    int d = JERK_LEGS + i;
    for (int k = 0; k < j->n; k++)
        j->ring[(size_t)k * JERK_DIM + (size_t)d] += shift;
    j->sum[d] += j->n * shift;
    j->fresh[d] += j->fresh_n * shift;
    j->last[d] += shift;
}

void motion_jerk_average(struct motion *m)
{
    struct motion_jerk *j = m->jerk;
    if (motion_sync_direct(m)) {
        /* a synchronised move follows the spindle itself: a lag of T/2 would put the tool
         * off the thread, by a different amount on the way out of a tap than on the way in.
         * It starts and ends at rest, with the average settled (motion_sync.c), so the
         * average stands aside and starts again from where it ends. */
        motion_jerk_hold(m);
        return;
    }
    double x[JERK_DIM];
    struct motion_jerk_meta mt;
    gather(m, x, &mt);
    if (!j->primed)
        prime(j);
    push(m, x, &mt);
}

void motion_jerk_restore(struct motion *m)
{
    if (m->jerk)
        scatter(m, m->jerk->last, &m->jerk->last_meta);
}

void motion_jerk_hold(struct motion *m)
{
    struct motion_jerk *j = m->jerk;
    if (!j)
        return;
    gather(m, j->last, &j->last_meta);
    j->primed = 0;
    m->outputs_out = m->outputs;
    m->io_out = m->io;
}
