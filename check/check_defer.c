/* check_defer.c: the servo-rate pass's costly measures (deviation, condition number) computed
 * by whichever thread has time, their results applied in order by the pass itself. */
#include <math.h>
#include <sched.h>
#include <string.h>
#include <sys/mman.h>

#include "check/check_defer.h"

/*
 * The servo-rate pass (check_sim.c) writes each measure into the next slot of a ring, with
 * everything it needs (legs, poses, the tip's line), and goes on stepping motion. A slot is
 * computed by whoever claims it first, by advancing `claim`: the planner's thread when it
 * waits for the pass to use up its chunks (check_stream.c), else the pass itself once the
 * ring is full. The results are pure functions of the slot, so it does not matter which
 * thread computes them; the pass applies them (figures, problems, warnings) in the order the
 * measures were taken, as it did when it computed them on the spot.
 *
 *     slots:  ... [applied] [apply ... done or being computed ... claim ... waiting ... head)
 *
 * Only the pass writes head and apply; both threads advance claim by compare-and-swap, and a
 * slot's `state` says when its results are there (release / acquire).
 */

struct check_defer *check_defer_new(struct kins *k, const struct kins_tool_frame *tf,
                                    int cold_forward)
{
    /* pages the kernel gives zeroed, each when the ring first reaches it: a memset of the
     * whole ring (7 MB) took 15 ms at the start of every check, before any thread ran */
    void *mem = mmap(NULL, sizeof(struct check_defer), PROT_READ | PROT_WRITE,
                     MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mem == MAP_FAILED)
        return NULL;
    struct check_defer *d = mem;
    d->kins = k;
    d->have_tf = tf != NULL;
    if (tf)
        d->tf = *tf;
    d->cold_forward = cold_forward;
    return d;
}

void check_defer_free(struct check_defer *d)
{
    if (d)
        munmap(d, sizeof *d);
}

/* The tool tip in the workpiece's frame at a platform pose, with a tool len_mm long. */
static void tip_at(const struct check_defer *d, double len_mm, const double pose[6],
                   double tip[3])
{
    double prog[KINS_POSE_DIM];
    kins_tcp_from_pose(&d->tf, len_mm, pose, prog);
    memcpy(tip, prog, 3 * sizeof *tip);
}

/* Distance of p from the line through a and b, mm: a synchronised move's tool runs on past
 * its ends along it (a tap while the spindle reverses), which is no deviation. */
static double dist_line(const double p[3], const double a[3], const double b[3])
{
    double d[3], n2 = 0, u = 0, e2 = 0;
    for (int i = 0; i < 3; i++)
        d[i] = b[i] - a[i], n2 += d[i] * d[i];
    if (!(n2 > 1e-24))
        return motion_dist_seg(p, a, b);
    for (int i = 0; i < 3; i++)
        u += (p[i] - a[i]) * d[i];
    for (int i = 0; i < 3; i++)
        e2 += (p[i] - a[i] - u / n2 * d[i]) * (p[i] - a[i] - u / n2 * d[i]);
    return sqrt(e2);
}

/* Kinematic deviation between two set points: the legs at mid-chord (where linear leg motion
 * strays furthest) through the forward kinematics, distance from the commanded chord; the
 * tip of those legs against its move's line or the chord between the set points' tips. */
static void deviation(const struct check_defer *d, struct check_defer_slot *s)
{
    double Lm[KINS_MAX_JOINTS], P[KINS_POSE_DIM], dv[3], n2 = 0, u = 0, e2 = 0, ang = 0;
    const double *p0 = s->p0, *p1 = s->pose;
    for (int i = 0; i < d->kins->njoints; i++)
        Lm[i] = 0.5 * (s->L0[i] + s->L1[i]);
    if (d->cold_forward) {     /* the baseline: every solve from the home pose */
        memcpy(P, d->kins->home, sizeof P);
        s->ok = kins_forward(d->kins, Lm, P, NULL) == KINS_OK;
    } else {                   /* warm: the commanded chord's midpoint is within about
                                * 1e-7 mm of the answer (the deviation, and the legs'
                                * bend along the path), so one Newton step does: its error
                                * is of the order of its square over the machine's size */
        for (int i = 0; i < KINS_POSE_DIM; i++)
            P[i] = 0.5 * (p0[i] + p1[i]);
        s->ok = kins_forward_near(d->kins, Lm, P, CHECK_NEAR_STEP_MM, NULL) == KINS_OK;
    }
    if (!s->ok)
        return;
    for (int i = 0; i < 3; i++)
        dv[i] = p1[i] - p0[i], n2 += dv[i] * dv[i];
    for (int i = 0; i < 3; i++)
        u += (P[i] - p0[i]) * dv[i];
    u = n2 > 1e-24 ? u / n2 : 0.5;
    for (int i = 0; i < 3; i++)
        e2 += (P[i] - p0[i] - u * dv[i]) * (P[i] - p0[i] - u * dv[i]);
    for (int i = 3; i < 6; i++)
        ang = fmax(ang, fabs(P[i] - p0[i] - u * (p1[i] - p0[i])));
    s->value = sqrt(e2);
    s->value2 = ang;
    if (s->tip_mode == CHECK_TIP_NONE)
        return;
    if (s->tip_mode == CHECK_TIP_LINE || s->tip_mode == CHECK_TIP_AXIS) {
        double tm[3];
        tip_at(d, s->tool_len_mm, P, tm);
        s->tip = s->tip_mode == CHECK_TIP_LINE ? motion_dist_seg(tm, s->t0, s->t1)
                                               : dist_line(tm, s->t0, s->t1);
        return;
    }
    /* the three tips in one call where it can (the same bits as one by one) */
    double poses[4][KINS_POSE_DIM], tips[4][3];
    memcpy(poses[0], P, sizeof poses[0]);
    memcpy(poses[1], p0, sizeof poses[1]);
    memcpy(poses[2], p1, sizeof poses[2]);
    memcpy(poses[3], P, sizeof poses[3]);
    if (!kins_tcp_tips4(&d->tf, s->tool_len_mm, (const double(*)[KINS_POSE_DIM])poses, tips))
        for (int i = 0; i < 3; i++)
            tip_at(d, s->tool_len_mm, poses[i], tips[i]);
    s->tip = motion_dist_seg(tips[0], tips[1], tips[2]);
}

/* Computes slot s (a measure; the other kinds need nothing computed). */
static void compute(const struct check_defer *d, struct check_defer_slot *s)
{
    if (s->kind == CHECK_DEFER_DEVIATION) {
        deviation(d, s);
    } else if (s->kind == CHECK_DEFER_CONDITION) {
        s->has_m = d->kins->ops->condition_matrix != NULL;
        if (s->has_m) {            /* the pass solves it only where no bound answers */
            s->ok = kins_condition_matrix(d->kins, s->pose, s->m) == KINS_OK;
        } else {
            struct kins_check ck;
            s->ok = kins_check_pose(d->kins, s->pose, &ck) == KINS_OK;
            s->value = s->ok ? ck.condition : 0;
        }
    }
    atomic_store_explicit(&s->state, CHECK_DEFER_DONE, memory_order_release);
}

/* Claims up to `most` slots from `claim` on, as far as head, with one compare-and-swap;
 * the first's index into *first, how many it took. */
static size_t claim_run(struct check_defer *d, size_t most, size_t *first)
{
    size_t c = atomic_load_explicit(&d->claim, memory_order_relaxed);
    for (;;) {
        size_t h = atomic_load_explicit(&d->head, memory_order_acquire);
        if (c >= h)
            return 0;
        size_t n = h - c < most ? h - c : most;
        if (atomic_compare_exchange_weak(&d->claim, &c, c + n)) {
            *first = c;
            return n;
        }
    }
}

/* Computes the n slots claimed from index first on (those not done already). */
static void compute_run(struct check_defer *d, size_t first, size_t n)
{
    for (size_t i = first; i < first + n; i++) {
        struct check_defer_slot *s = &d->slot[i % CHECK_DEFER_SLOTS];
        if (atomic_load_explicit(&s->state, memory_order_acquire) != CHECK_DEFER_DONE)
            compute(d, s);
    }
}

int check_defer_work(struct check_defer *d)
{
    size_t i, n;
    if (!d || !(n = claim_run(d, 1, &i)))
        return 0;
    compute_run(d, i, n);
    return 1;
}

struct check_defer_slot *check_defer_push(struct check_defer *d, enum check_defer_kind kind)
{
    if (d->head_local - d->apply >= CHECK_DEFER_SLOTS)
        return NULL;                     /* full: the pass applies the oldest first */
    struct check_defer_slot *s = &d->slot[d->head_local % CHECK_DEFER_SLOTS];
    s->kind = kind;
    atomic_store_explicit(&s->state, kind == CHECK_DEFER_DEVIATION ||
                          kind == CHECK_DEFER_CONDITION ? CHECK_DEFER_WAITING
                                                        : CHECK_DEFER_DONE,
                          memory_order_relaxed);
    return s;
}

void check_defer_commit(struct check_defer *d)
{
    d->head_local++;
    atomic_store_explicit(&d->head, d->head_local, memory_order_release);
}

const struct check_defer_slot *check_defer_oldest(const struct check_defer *d)
{
    return d->apply == d->head_local ? NULL : &d->slot[d->apply % CHECK_DEFER_SLOTS];
}

struct check_defer_slot *check_defer_next(struct check_defer *d, int wait)
{
    if (d->apply == d->head_local)
        return NULL;
    struct check_defer_slot *s = &d->slot[d->apply % CHECK_DEFER_SLOTS];
    for (;;) {
        int state = atomic_load_explicit(&s->state, memory_order_acquire);
        if (atomic_load_explicit(&d->claim, memory_order_acquire) <= d->apply) {
            /* nobody has taken it: a measure waits for the helper unless the pass must
             * go on; a value is taken at once (claim never passes a slot untaken) */
            if (state != CHECK_DEFER_DONE && !wait)
                return NULL;
            /* (waiting, the pass computes a run at once; else it takes the value alone,
             * and leaves the measures after it to the helper) */
            size_t i = 0, n = claim_run(d, wait ? CHECK_DEFER_RUN : 1, &i);
            compute_run(d, i, n);
            continue;
        }
        if (state == CHECK_DEFER_DONE)
            break;
        if (!wait)
            return NULL;
        sched_yield();                   /* the helper is computing it: a microsecond */
    }
    d->apply++;
    return s;
}
