/* test_motion_same.h: two machines that ran the same program compared bit for bit: the output
 * record's brief part (motion_set_brief) and the executor's own state. For the tests that
 * include motion/motion_priv.h. */
#ifndef HEXCNC_TEST_MOTION_SAME_H
#define HEXCNC_TEST_MOTION_SAME_H

#include <check.h>
#include <string.h>

#include "motion/motion_priv.h"

/* The brief part of two output records (motion_set_brief) is the same, bit for bit. */
static inline void same_brief(const struct motion_out *a, const struct motion_out *b)
{
    ck_assert(!memcmp(a->pose, b->pose, sizeof a->pose));
    ck_assert(!memcmp(a->joint_pos, b->joint_pos, sizeof a->joint_pos));
    ck_assert(!memcmp(a->seg_from, b->seg_from, sizeof a->seg_from));
    ck_assert(!memcmp(a->seg_to, b->seg_to, sizeof a->seg_to));
    ck_assert_int_eq(a->tcp, b->tcp);
    ck_assert(a->tool_len_mm == b->tool_len_mm && a->path_tol_mm == b->path_tol_mm);
    ck_assert_int_eq(a->seg_kind, b->seg_kind);
    ck_assert_int_eq(a->line, b->line);
    ck_assert((!a->file && !b->file) || (a->file && b->file && !strcmp(a->file, b->file)));
    ck_assert_int_eq(a->state, b->state);
    ck_assert_int_eq(a->status, b->status);
    ck_assert(a->time_elapsed_s == b->time_elapsed_s);
    ck_assert(a->distance_done_mm == b->distance_done_mm);
    ck_assert(a->distance_total_mm == b->distance_total_mm);
}

/* Two executors stand at the same place of their plans with the same values, bit for bit:
 * clock, interval, segment, rate, pose, speeds, legs, and the counts the next period
 * depends on. */
static inline void same_executor(const struct motion *a, const struct motion *b)
{
    ck_assert(a->tau_s == b->tau_s && a->elapsed_s == b->elapsed_s && a->rate == b->rate);
    ck_assert(a->ci == b->ci && a->cs == b->cs && a->io_age == b->io_age);
    ck_assert(a->path_vel == b->path_vel && a->dist_mm == b->dist_mm);
    ck_assert(!memcmp(a->pose, b->pose, sizeof a->pose));
    ck_assert(!memcmp(a->prog_pose, b->prog_pose, sizeof a->prog_pose));
    ck_assert(!memcmp(a->pose_vel, b->pose_vel, sizeof a->pose_vel));
    ck_assert(!memcmp(a->joint_cmd, b->joint_cmd, sizeof a->joint_cmd));
    ck_assert(!memcmp(a->joint_vel, b->joint_vel, sizeof a->joint_vel));
    ck_assert(a->marks_done == b->marks_done && a->ios_done == b->ios_done);
    ck_assert(a->waiting == b->waiting && a->state == b->state);
}

/* One machine's periods one by one, taken several at a time by motion_step_calm where it
 * takes them (on), else by motion_step: each period's record is the run's last record with
 * that period's pose, legs, clock and distance done, which is what motion_step would have
 * given for it (its brief part). */
struct calm_feed {
    int on;
    struct motion_calm c;
    struct motion_out last;              /* the run's last period's record */
    int k;                               /* the run's periods handed out */
    long runs, periods;                  /* runs taken, and periods in them */
};

/* The next period into out (its brief part where the machine's record is brief); the
 * return of motion_step, or MOTION_OK for a period of a run. *in_step: whether the
 * executor stands at this period (1), or at the end of a run still being handed out (0). */
static inline int calm_next(struct motion *m, double dt, struct calm_feed *f,
                            struct motion_out *out, int *in_step)
{
    if (f->k >= f->c.n) {
        f->k = f->c.n = 0;
        if (!f->on || motion_step_calm(m, dt, &f->c, &f->last) == 0) {
            *in_step = 1;
            return motion_step(m, dt, out);
        }
        f->runs++, f->periods += f->c.n;
    }
    int k = f->k++;
    *out = f->last;
    memcpy(out->pose, f->c.pose[k], sizeof out->pose);
    memcpy(out->joint_pos, f->c.joints[k], (size_t)m->nj * sizeof *out->joint_pos);
    out->time_elapsed_s = f->c.time_s[k];
    out->distance_done_mm = motion_calm_dist(&f->c, k);
    *in_step = f->k == f->c.n;
    return MOTION_OK;
}

#endif
