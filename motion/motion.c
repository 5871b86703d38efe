/* motion.c: the motion instance: lifetime, loading a program, commands and the following-error check. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_blend.h"
#include "motion/motion_merge.h"
#include "motion/motion_priv.h"

/* Formats the instance's message. */
void motion_set_msg(struct motion *m, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(m->msg, sizeof m->msg, fmt, ap);
    va_end(ap);
}

/* Copies a message into err (when given) and into the instance. */
static int fail(struct motion *m, int st, char *err, size_t errlen)
{
    if (err && errlen && err != m->msg)
        snprintf(err, errlen, "%s", m->msg);
    return st;
}

/* Creates an instance; the pose starts at the kinematics' home pose. */
int motion_create(const struct motion_config *cfg, struct kins *k, struct motion **out,
                  char *err, size_t errlen)
{
    char tmp[1];
    if (!err || !errlen)
        err = tmp, errlen = sizeof tmp;
    if (!cfg || !k || !out) {
        snprintf(err, errlen, "motion_create: missing configuration or kinematics");
        return MOTION_ERR_ARG;
    }
    *out = NULL;
    int st = motion_config_check(cfg, err, errlen);
    if (st)
        return st;
    if (k->njoints < 1 || k->njoints > KINS_MAX_JOINTS) {
        snprintf(err, errlen, "motion: the kinematics has %d joints", k->njoints);
        return MOTION_ERR_CONFIG;
    }
    struct motion *m = calloc(1, sizeof *m);
    if (!m) {
        snprintf(err, errlen, "out of memory creating motion");
        return MOTION_ERR_NOMEM;
    }
    m->cfg = *cfg;
    m->kins = k;
    m->have_tf = kins_get_tool_frame(k, &m->tf) == KINS_OK;
    m->nj = k->njoints;
    m->cfg.njoints = m->nj;
    motion_jerk_share(&m->cfg);     /* (a window shorter than the full one: the leader's
                                     * accelerations lowered, the window kept in the copy) */
    m->jerk_window_s = motion_jerk_window_s(&m->cfg);
    m->chord_period_s = motion_chord_period(&m->cfg);
    m->override_cmd = 1;
    m->rapid_cmd = 1;
    m->state = MOTION_IDLE;
    memcpy(m->pose, k->home, sizeof m->pose);
    memcpy(m->start_pose, k->home, sizeof m->start_pose);
    kins_inverse(k, m->pose, m->joint_cmd);
    memcpy(m->joint_fb, m->joint_cmd, sizeof m->joint_fb);
    memcpy(m->motor_fb, m->joint_cmd, sizeof m->motor_fb);
    m->pose_known = 1;
    m->run = &m->plan;
    m->pb_at[0] = m->pb_at[1] = SIZE_MAX;
    if ((st = motion_jerk_init(m, err, errlen)) != MOTION_OK) {
        free(m);
        return st;
    }
    *out = m;
    return MOTION_OK;
}

/* Frees the instance and its plan (the kinematics stays the caller's). */
void motion_destroy(struct motion *m)
{
    if (!m)
        return;
    motion_plan_free(&m->plan);
    motion_plan_free(&m->names);
    motion_jerk_free(m);
    motion_caps_free(m);
    free(m);
}

/* Resets the run state to the start of the plan. */
static void rewind_plan(struct motion *m)
{
    m->tau_s = 0;
    m->rate = 0;
    m->elapsed_s = 0;
    m->ci = 0;
    m->cs = 0;
    m->paused_at_seg = 0;
    m->step_until_seg = 0;
    m->marks_done = 0;
    m->ios_done = 0;
    m->waiting = 0;
    m->waited_at_seg = 0;
    m->path_vel = 0;
    memset(m->pose_vel, 0, sizeof m->pose_vel);
    memset(m->joint_vel, 0, sizeof m->joint_vel);
    memset(m->ferror, 0, sizeof m->ferror);
    m->marks_base = 0;
    m->tail_taken = 0;
    m->in_waiting = 0;
    atomic_store(&m->input_seq, 0);
    motion_probe_reset(m);
    atomic_store(&m->probe_seq, 0);
    motion_sync_index_withdraw(m);
    m->sync.phase = SYNC_IDLE;
    m->seg_at = NULL;
    m->line = m->run && m->run->nseg ? m->run->segs[0].line : 0;
    m->file = m->run && m->run->nseg ? m->run->segs[0].file : NULL;
}

/* Plans a program (see motion.h). */
int motion_load(struct motion *m, const struct canon_prog *prog, char *err, size_t errlen)
{
    if (!m || !prog)
        return MOTION_ERR_ARG;
    if (m->state != MOTION_IDLE && m->state != MOTION_DONE && m->state != MOTION_FAULT) {
        motion_set_msg(m, "cannot load a program while %s",
                 motion_state_name(m->state));
        return fail(m, MOTION_ERR_STATE, err, errlen);
    }
    motion_plan_free(&m->plan);
    m->run = &m->plan;
    m->streaming = 0;
    m->chunk = NULL;
    m->loaded = 0;
    m->msg[0] = 0;
    m->state = MOTION_IDLE;
    m->fault_status = MOTION_OK;
    /* G64 P corners become tangent arcs first (motion_blend.c); the planner then treats
     * them like any programmed arc */
    struct canon_prog blended, merged;
    struct motion_blend_abc *abc = NULL;
    size_t nblends = 0, nmerged = 0;
    int st = 0;
    canon_prog_init(&merged);
    if (motion_merge_wanted(prog)) {   /* G64 Q: runs of straight feeds as single lines */
        st = motion_merge_program(prog, &merged, &nmerged) ? MOTION_ERR_NOMEM : 0;
        prog = &merged;
    }
    if (!st)
        st = motion_blend_program(&m->cfg, prog, &blended, &nblends, &abc);
    else
        canon_prog_init(&blended);
    if (st)
        motion_set_msg(m, "out of memory planning the program");
    if (!st)
        st = motion_path_build(m, nblends ? &blended : prog, abc, m->msg, sizeof m->msg);
    canon_prog_free(&blended);
    free(abc);
    if (!st)
        st = motion_plan_profile(m, m->msg, sizeof m->msg);
    m->plan.info.blends = nblends;
    m->plan.info.merged = nmerged;
    double L[KINS_MAX_JOINTS];
    if (!st && m->plan.nseg == 0 && kins_inverse(m->kins, prog->start, L) != KINS_OK) {
        motion_set_msg(m, "the program's start position is outside the machine's "
                 "reach");
        st = MOTION_ERR_UNREACHABLE;
    }
    memcpy(m->start_pose, prog->start, sizeof m->start_pose);
    canon_prog_free(&merged);          /* (prog pointed at it: not used below) */
    if (st) {
        motion_plan_free(&m->plan);
        return fail(m, st, err, errlen);
    }
    memcpy(m->pose, m->start_pose, sizeof m->pose);
    kins_inverse(m->kins, m->pose, m->joint_cmd);
    m->loaded = 1;
    rewind_plan(m);
    motion_jerk_hold(m);               /* the average starts at rest where the program does */
    if (err && errlen)
        err[0] = 0;
    return MOTION_OK;
}

/* The operator's stop request while planning. */
void motion_set_cancel(struct motion *m, const volatile sig_atomic_t *flag)
{
    m->cancel = flag;
}

/* Starts the loaded program. */
int motion_start(struct motion *m)
{
    if (!m)
        return MOTION_ERR_ARG;
    if (m->state != MOTION_IDLE || !m->loaded)
        return MOTION_ERR_STATE;
    rewind_plan(m);
    m->rate = m->override_cmd;
    m->state = m->streaming || m->plan.nseg ? MOTION_RUNNING : MOTION_DONE;
    return MOTION_OK;
}

/* The summary of the current plan. */
int motion_plan_info(const struct motion *m, struct motion_plan_info *out)
{
    if (!m || !out)
        return MOTION_ERR_ARG;
    if (!m->loaded)
        return MOTION_ERR_STATE;
    *out = m->streaming ? m->stream_info : m->plan.info;
    return MOTION_OK;
}

/* Pause: decelerate along the path. */
int motion_pause(struct motion *m)
{
    if (!m)
        return MOTION_ERR_ARG;
    if (m->state != MOTION_RUNNING)
        return m->state == MOTION_PAUSING || m->state == MOTION_PAUSED ? MOTION_OK
                                                                       : MOTION_ERR_STATE;
    m->state = MOTION_PAUSING;
    return MOTION_OK;
}

/* Resume after a pause or an M0/M1. */
int motion_resume(struct motion *m)
{
    if (!m)
        return MOTION_ERR_ARG;
    if (m->state != MOTION_PAUSING && m->state != MOTION_PAUSED)
        return m->state == MOTION_RUNNING ? MOTION_OK : MOTION_ERR_STATE;
    m->state = MOTION_RUNNING;
    return MOTION_OK;
}

/* Abort: decelerate along the path, then drop the program. */
int motion_abort(struct motion *m)
{
    if (!m)
        return MOTION_ERR_ARG;
    switch (m->state) {
    case MOTION_RUNNING: case MOTION_PAUSING:
        m->state = MOTION_STOPPING;
        return MOTION_OK;
    case MOTION_PAUSED: case MOTION_IDLE: case MOTION_DONE:
        m->state = MOTION_IDLE;
        m->loaded = 0;
        return MOTION_OK;
    default:
        return m->state == MOTION_STOPPING ? MOTION_OK : MOTION_ERR_STATE;
    }
}

/* Requested feed override, clamped to 0..2. */
int motion_set_feed_override(struct motion *m, double scale)
{
    if (!m || isnan(scale))
        return MOTION_ERR_ARG;
    m->override_cmd = scale < 0 ? 0 : scale > 2 ? 2 : scale;
    return MOTION_OK;
}

int motion_set_rapid_override(struct motion *m, double scale)
{
    if (!m || isnan(scale))
        return MOTION_ERR_ARG;
    m->rapid_cmd = scale < 0 ? 0 : scale > 1 ? 1 : scale;
    return MOTION_OK;
}

int motion_set_optional_stop(struct motion *m, bool on)
{
    if (!m)
        return MOTION_ERR_ARG;
    m->cfg.optional_stop = on;
    return MOTION_OK;
}

int motion_step_block(struct motion *m)
{
    if (!m)
        return MOTION_ERR_ARG;
    if (m->state != MOTION_PAUSED && m->state != MOTION_PAUSING && m->state != MOTION_RUNNING)
        return MOTION_ERR_STATE;
    m->step_until_seg = m->cs + 1;
    m->state = MOTION_RUNNING;
    return MOTION_OK;
}

/* Stops at once: the command freezes. */
static void halt(struct motion *m, int status)
{
    memset(&m->man, 0, sizeof m->man);
    m->homing = 0;
    m->state = MOTION_FAULT;
    m->fault_status = status;
    m->rate = 0;
    m->path_vel = 0;
    memset(m->pose_vel, 0, sizeof m->pose_vel);
    memset(m->joint_vel, 0, sizeof m->joint_vel);
}

/* Where the program is, for messages: "file:line" or "before the program". */
static void where(const struct motion *m, char *buf, size_t len)
{
    if (m->line > 0)
        snprintf(buf, len, "%s:%d", m->file ? m->file : "program", m->line);
    else
        snprintf(buf, len, "before the program");
}

/* Emergency stop. */
int motion_estop(struct motion *m)
{
    if (!m)
        return MOTION_ERR_ARG;
    if (m->state == MOTION_FAULT)
        return MOTION_OK;
    char at[200];
    where(m, at, sizeof at);
    motion_set_msg(m, "%s: emergency stop: the machine stopped at once at X%.3f "
             "Y%.3f Z%.3f A%.3f B%.3f C%.3f", at, m->pose[0], m->pose[1], m->pose[2],
             m->pose[3], m->pose[4], m->pose[5]);
    halt(m, MOTION_ERR_ESTOP);
    return MOTION_OK;
}

/* Following-error check against the command the drives were following (LinuxCNC's rule:
 * the limit grows from MIN_FERROR at standstill to FERROR at MAX_VELOCITY). */
int motion_feedback(struct motion *m, const double *fb)
{
    if (!m || !fb)
        return MOTION_ERR_ARG;
    for (int i = 0; i < m->nj; i++) {
        m->motor_fb[i] = fb[i];
        m->joint_fb[i] = fb[i] - m->motor_offset[i];
        m->ferror[i] = m->joint_cmd[i] - m->joint_fb[i];
    }
    if (m->state != MOTION_RUNNING && m->state != MOTION_PAUSING && m->state != MOTION_PAUSED &&
        m->state != MOTION_STOPPING && m->state != MOTION_MANUAL)
        return MOTION_OK;
    for (int i = 0; i < m->nj; i++) {
        const struct motion_joint_config *j = &m->cfg.joint[i];
        double lim = j->ferror_mm * fabs(m->joint_vel[i]) / j->max_vel_mm_s;
        if (lim < j->min_ferror_mm)
            lim = j->min_ferror_mm;
        if (!(fabs(m->ferror[i]) <= lim)) {
            char at[200];
            where(m, at, sizeof at);
            motion_set_msg(m, "%s: following error on leg %d ([JOINT_%d]): the leg "
                     "is %.4f mm off its commanded length, more than the %.4f mm allowed at "
                     "%.2f mm/s; machine stopped", at, i + 1, i, fabs(m->ferror[i]), lim,
                     fabs(m->joint_vel[i]));
            halt(m, MOTION_ERR_FERROR);
            return MOTION_ERR_FERROR;
        }
    }
    return MOTION_OK;
}

/* Current state. */
enum motion_state motion_get_state(const struct motion *m)
{
    return m ? m->state : MOTION_FAULT;
}

/* Last error or fault text. */
const char *motion_last_error(const struct motion *m)
{
    return m ? m->msg : "no motion instance";
}

/* Follows a stream's chunks from now on (motion_stream.c). */
int motion_stream_attach(struct motion *m, struct motion_stream *s,
                         const struct motion_plan_info *totals)
{
    if (!m || !s)
        return MOTION_ERR_ARG;
    if (m->state != MOTION_IDLE && m->state != MOTION_DONE && m->state != MOTION_FAULT) {
        motion_set_msg(m, "cannot load a program while %s", motion_state_name(m->state));
        return MOTION_ERR_STATE;
    }
    motion_plan_free(&m->plan);
    m->run = NULL;
    m->chunk = NULL;
    atomic_store(&m->stream_head, NULL);
    atomic_store(&m->stream_wait, NULL);
    m->streaming = 1;
    m->msg[0] = 0;
    m->state = MOTION_IDLE;
    m->fault_status = MOTION_OK;
    memset(&m->stream_info, 0, sizeof m->stream_info);
    if (totals)
        m->stream_info = *totals;
    motion_stream_bind(s, m);
    memcpy(m->start_pose, motion_stream_start(s), sizeof m->start_pose);
    memcpy(m->pose, m->start_pose, sizeof m->pose);
    kins_inverse(m->kins, m->pose, m->joint_cmd);
    m->loaded = 1;
    rewind_plan(m);
    motion_jerk_hold(m);               /* the average starts at rest where the program does */
    return MOTION_OK;
}

void motion_stream_detach(struct motion *m)
{
    if (!m || !m->streaming)
        return;
    m->streaming = 0;
    m->chunk = NULL;
    atomic_store(&m->stream_head, NULL);
    atomic_store(&m->stream_wait, NULL);
    m->run = &m->plan;
    m->loaded = 0;
    if (m->state == MOTION_RUNNING || m->state == MOTION_PAUSING ||
        m->state == MOTION_PAUSED || m->state == MOTION_STOPPING)
        m->state = MOTION_IDLE;
}

bool motion_stream_starving(const struct motion *m)
{
    if (!m)
        return false;
    struct motion *w = (struct motion *)m;
    struct motion_chunk *c = atomic_load_explicit(&w->stream_wait, memory_order_acquire);
    if (!c)
        return false;
    if (c == MOTION_TAIL_TAKEN)     /* no chunk yet: until the first is out */
        return !atomic_load_explicit(&w->stream_head, memory_order_acquire);
    /* the chunk stays alive while the executor is on it (it retires it when it leaves) */
    return !atomic_load_explicit(&c->next, memory_order_acquire);
}
