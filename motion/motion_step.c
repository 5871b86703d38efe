/* motion_step.c: the servo-period interpolator: follows the planned profile on a scaled clock. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "motion/motion_priv.h"

/* (The plan's clock under the feed override, motion_rate.c: motion_plan_at, motion_next_rate,
 * motion_ceiling_ahead.) */

/* At the start of an M0/M1 segment not yet honoured: stop there and pause (and at a wait's,
 * wait: motion_hold.c). Only those two segments call out of the period's path. */
static inline int pause_here(struct motion *m)
{
    const struct motion_seg *sg = &m->run->segs[m->cs];
    if (sg->kind != SEG_PAUSE && sg->kind != SEG_WAIT) {
        m->waiting = 0;                /* (what the two below come to on any other) */
        return 0;
    }
    return motion_pause_or_wait_here(m, sg);
}

static void pass_marks_to(struct motion *m, size_t reached);
static void pass_ios_to(struct motion *m, size_t reached);

/* Goes on in chunk n at its entry, its clock at tau, with its own indices; the chunk left
 * (NULL for the first) is retired for the planner to free. */
static void enter_chunk(struct motion *m, struct motion_chunk *c, struct motion_chunk *n,
                        double tau)
{
    m->tau_s = tau;
    m->ci = n->k_enter;
    m->cs = n->s_enter;
    m->marks_base += m->marks_done;
    m->marks_done = 0;
    m->ios_done = 0;
    m->paused_at_seg = 0;
    m->waited_at_seg = 0;
    m->chunk = n;
    m->run = &n->plan;
    m->seg_at = NULL;
    motion_probe_reset(m);
    if (c)
        atomic_store_explicit(&c->retired, 1, memory_order_release);
}

/* A streamed program's path has reached the knot where the chunk hands over (k_leave): on
 * into the successor, at the same place and speed, with its own clock and indices. With
 * no successor yet, the executor claims the tail (which stops at the window's end) and the
 * planner can attach nothing more. Returns whether it switched. */
static bool switch_chunk(struct motion *m)
{
    struct motion_chunk *c = m->chunk, *n = NULL;
    if (!atomic_compare_exchange_strong(&c->next, &n, MOTION_TAIL_TAKEN)) {
        /* what came before the hand-over point is passed; what lies at it is the next
         * chunk's (its first commands) */
        pass_marks_to(m, c->s_leave - 1);
        pass_ios_to(m, c->s_leave - 1);
        if (m->step_until_seg) {      /* the stepped block ended at the hand-over */
            m->step_until_seg = 0;
            if (m->state == MOTION_RUNNING)
                m->state = MOTION_PAUSING;
        }
        enter_chunk(m, c, n, m->tau_s + n->plan.kt[n->k_enter] - c->plan.kt[c->k_leave]);
        return true;
    }
    m->tail_taken = 1;
    return false;
}

/* Moves ci and cs forward to the interval holding tau; stops at an unhonoured pause. */
static void follow_knots(struct motion *m)
{
    const struct motion_plan *p = m->run;
    if (pause_here(m))
        return;
    while (m->ci + 2 < p->nknot && m->tau_s >= p->kt[m->ci + 1]) {
        m->ci++;
        while (m->ci >= p->segs[m->cs].k0 + p->segs[m->cs].nk)
            m->cs++;
        if (m->chunk && !m->chunk->last && !m->tail_taken && m->ci == m->chunk->k_leave &&
            switch_chunk(m))
            p = m->run;
        if (pause_here(m))
            return;
    }
}

/* Whether interval ci of segment sg is a rest: a dwell, or the hold of a stop where the path
 * changes direction (motion_plan.c). A rest lasts its time whatever the override: the hold
 * must cover one whole set-point period. */
static int resting(const struct motion_plan *p, size_t ci, const struct motion_seg *sg)
{
    if (sg->kind == SEG_DWELL)
        return ci == sg->k0;
    return ci + 1 == sg->k0 + sg->nk && p->kt[ci + 1] > p->kt[ci];
}

/* At rest where a probe tripped: the rest of the chunk is dropped; on into the next part
 * once the planner, which starts it here, has it (a whole program ends here). */
static void probe_parked(struct motion *m)
{
    struct motion_chunk *c = m->chunk, *n = c ? atomic_load(&c->next) : NULL;
    m->rate = 0;
    if (m->state == MOTION_PAUSING)
        m->state = MOTION_PAUSED;
    if (m->state == MOTION_STOPPING) {
        m->state = MOTION_IDLE;
        m->loaded = 0;
    } else if (!c) {
        m->state = MOTION_DONE;    /* a whole program (an MDI line) ends where it stopped */
    } else if (n && n != MOTION_TAIL_TAKEN && m->state == MOTION_RUNNING) {
        pass_marks_to(m, c->plan.nseg);
        pass_ios_to(m, c->plan.nseg);
        enter_chunk(m, c, n, n->plan.nknot ? n->plan.kt[n->k_enter] : 0);
        if (n->plan.nseg == 0 && n->last)
            m->state = MOTION_DONE;
    }
}

/* Advances the plan clock by one period. */
static void advance(struct motion *m, double dt)
{
    const struct motion_plan *p = m->run;
    const struct motion_seg *sg = &p->segs[m->cs];
    double s, vp, ap;
    double tau0 = m->tau_s;
    m->elapsed_s += dt;
    if (m->probe_halt == PROBE_PARKED) {
        probe_parked(m);
        return;
    }
    bool probe_halt = motion_probe_watch(m);
    if (m->waiting) {  /* held for the spindle: pause and abort end the wait at rest */
        if (m->state == MOTION_RUNNING)
            follow_knots(m);
        if (m->waiting) {
            if (m->state == MOTION_PAUSING)
                m->state = MOTION_PAUSED;
            if (m->state == MOTION_STOPPING) {
                m->state = MOTION_IDLE;
                m->loaded = 0;
                m->waiting = 0;
            }
            return;
        }
    }
    if (motion_sync_advance(m, dt))
        ;                               /* the spindle drives the path (motion_sync.c) */
    else if (resting(p, m->ci, sg)) {
        if (m->state == MOTION_RUNNING && !probe_halt)
            m->tau_s += dt;             /* a rest lasts its time whatever the override */
        else
            m->rate = 0;
    } else {
        double ovr = sg->kind == SEG_LINE && sg->feed == 0 ? m->rapid_cmd : m->override_cmd;
        double target = m->state == MOTION_RUNNING && !probe_halt ? ovr : 0;
        if (target == 1 && m->rate == 1) {
            /* at the plan's own pace, which motion_next_rate keeps: the ceiling is at least 1
             * (motion_plan.c), and every phase's acceleration is within its interval's
             * limit, so 1 lies within every bound motion_next_rate takes */
            m->tau_s += dt;
        } else {
            motion_plan_at(p, m->ci, m->tau_s, &s, &vp, &ap, &m->phases);
            /* the ceiling where this period ends: the rate is down to it by then, not a
             * period late, when the plan's own ramp begins at the next knot (with the
             * ceiling where the period began, the last step down came on top of the ramp's
             * full deceleration: a leg 5 % over its limit at override 2 on a blended
             * 12-gon, test_blend_legs_time_optimal) */
            double rn = motion_next_rate(m, target, vp,
                                         motion_ceiling_ahead(p, m->ci,
                                                              m->tau_s + m->rate * dt), dt);
            m->tau_s += 0.5 * (m->rate + rn) * dt;
            m->rate = rn;
        }
    }
    follow_knots(m);
    p = m->run;                  /* a streamed program may have gone on into the next chunk */
    motion_probe_arm(m);
    if (m->step_until_seg && m->cs >= m->step_until_seg && m->state == MOTION_RUNNING) {
        m->step_until_seg = 0;   /* the block is done: pause on the path */
        m->state = MOTION_PAUSING;
    }
    if (m->tau_s >= p->total_time_s && m->state != MOTION_PAUSED && !m->waiting) {
        m->tau_s = p->total_time_s;
        m->rate = 0;
        if (m->chunk && m->chunk->sync) {
            /* at rest after an M66: on into the next part once the interpreter, which has
             * the answer now, has planned it */
            struct motion_chunk *c = m->chunk, *n = atomic_load(&c->next);
            if (n && n != MOTION_TAIL_TAKEN && motion_jerk_settled(m)) {
                pass_marks_to(m, c->plan.nseg);
                pass_ios_to(m, c->plan.nseg);
                /* (the part after the wait may hold no move: the program's end) */
                enter_chunk(m, c, n, n->plan.nknot ? n->plan.kt[n->k_enter] : 0);
                if (n->plan.nseg == 0 && n->last)
                    m->state = MOTION_DONE;
            }
        } else if (m->chunk && !m->chunk->last) {
            /* the tail of a chunk whose successor never came: stopped on the path (once the
             * jerk limiter's average has come to rest too) */
            if (!motion_jerk_settled(m))
                return;
            const struct motion_seg *e = &p->segs[p->nseg - 1];
            motion_set_msg(m, "%s:%d: the program's next part was not planned in time (the "
                           "planner fell behind the machine, or stopped on an error): the "
                           "machine stopped on the path; run from line %d to go on",
                           e->file ? e->file : "program", e->line, e->line);
            m->state = MOTION_FAULT;
            m->fault_status = MOTION_ERR_STARVED;
        } else if (motion_jerk_settled(m) && (!m->jerk || tau0 >= p->total_time_s)) {
            /* (with jerk limits, not in the period the executor came to the end: the average
             * settled on where it stood before, and would stop short by what it moved) */
            m->state = MOTION_DONE;
        }
    }
    /* (with jerk limits the machine has stopped once the moving average has) */
    bool still = m->rate == 0 && motion_jerk_settled(m);
    if (still && m->state == MOTION_PAUSING)
        m->state = MOTION_PAUSED;
    if (still && m->state == MOTION_STOPPING) {
        m->state = MOTION_IDLE;
        m->loaded = 0;
    }
}

/* What the status reports of the segment being followed, taken once per segment. */
static void seg_values(struct motion *m, const struct motion_seg *sg)
{
    m->seg_at = sg;
    m->tcp = sg->tcp;
    m->tool_len_mm = sg->tool_len_mm;
    m->seg_kind = sg->kind > SEG_ARC ? 0 : sg->feed == 0 ? 3 : sg->kind == SEG_LINE ? 1 : 2;
    memcpy(m->seg_from, sg->start, sizeof m->seg_from);
    memcpy(m->seg_to, sg->end, sizeof m->seg_to);
    m->path_tol_mm = fmax(m->cfg.kin_tol_mm, motion_jerk_round_mm(m, sg));
    m->line = sg->line;
    m->file = sg->file;
}

/* The look-ahead's entry j (motion_ahead.c) as the period's pose and legs, where the period
 * computes no rates and segment sg is no G43.4 move: what evaluate() would compute. (Out of
 * line, as report() is: inlined into motion_step's branches, whose every test GCC guesses
 * even, their copies counted as rare and were built as string moves, `rep movs`, slow for a
 * few bytes: a check took 1.4 times as long.) */
static __attribute__((noinline)) void entry_values(struct motion *m, const struct motion_seg *sg,
                                                  int j)
{
    double s = m->ahead.at[j].s;
    memcpy(m->prog_pose, m->ahead.pose[j], sizeof m->prog_pose);
    memcpy(m->pose, m->prog_pose, sizeof m->pose);
    memset(m->pose_vel, 0, sizeof m->pose_vel);
    m->path_vel = m->ahead.at[j].vp * m->rate;
    if (m->state == MOTION_PAUSED || m->state == MOTION_IDLE)
        m->path_vel = 0;
    m->dist_mm = sg->dist0_mm + (sg->len > 0 ? s * sg->xyz_len_mm / sg->len : 0);
    memset(m->joint_vel, 0, sizeof m->joint_vel);
    for (int i = 0; i < m->nj; i++)        /* (inverse writes nj: the rest stays) */
        m->joint_cmd[i] = m->ahead.joints[j][i];
}

/* Pose, rates and legs at the current plan time (a check's, from the look-ahead's entry
 * when it has one: motion_ahead.c). */
static int evaluate(struct motion *m, double dt)
{
    const struct motion_plan *p = m->run;
    const struct motion_seg *sg = &p->segs[m->cs];
    double s, vp, ap, dp[KINS_POSE_DIM];
    int j = m->ahead_on && m->no_rates && m->state != MOTION_DONE ? motion_ahead(m, dt) : -1;
    if (sg != m->seg_at)
        seg_values(m, sg);
    if (j >= 0 && !sg->tcp && m->ahead.status[j] == KINS_OK) {
        entry_values(m, sg, j);   /* (the look-ahead fills no G43.4 move; a lane that failed
                                   * goes the whole way below, its error as it comes) */
        return KINS_OK;
    }
    if (j >= 0) {
        s = m->ahead.at[j].s, vp = m->ahead.at[j].vp;
    } else {
        motion_plan_at(p, m->ci, m->tau_s, &s, &vp, &ap, &m->phases);
        motion_sync_at(m, &s, &vp);    /* a synchronised move: where the spindle has it */
        if (m->state == MOTION_DONE) {
            s = sg->len;
            vp = 0;
        }
    }
    double v = vp * m->rate;
    if (m->state == MOTION_PAUSED || m->state == MOTION_IDLE)
        v = 0;
    if (j >= 0)
        memcpy(m->prog_pose, m->ahead.pose[j], sizeof m->prog_pose);
    else
        motion_seg_pose(p, sg, s, m->prog_pose);
    double vr = m->no_rates ? 0 : v;   /* the speed the rates are computed for */
    if (vr != 0)
        motion_seg_tangent(p, sg, s, dp);
    else
        memset(dp, 0, sizeof dp);
    if (sg->tcp && vr == 0) {
        kins_tcp_to_pose(&m->tf, sg->tool_len_mm, m->prog_pose, m->pose);
        memset(m->pose_vel, 0, sizeof m->pose_vel);
    } else if (sg->tcp) {      /* G43.4: the path is the tip's; the platform's pose follows */
        double pv[KINS_POSE_DIM];
        for (int i = 0; i < KINS_POSE_DIM; i++)
            pv[i] = dp[i] * vr;
        kins_tcp_to_pose_vel(&m->tf, sg->tool_len_mm, m->prog_pose, pv, m->pose, m->pose_vel);
    } else {
        memcpy(m->pose, m->prog_pose, sizeof m->pose);
        for (int i = 0; i < KINS_POSE_DIM; i++)
            m->pose_vel[i] = dp[i] * vr;
    }
    m->path_vel = v;
    m->dist_mm = sg->dist0_mm + (sg->len > 0 ? s * sg->xyz_len_mm / sg->len : 0);
    if (vr == 0) {
        memset(m->joint_vel, 0, sizeof m->joint_vel);
        if (j < 0 || m->ahead.status[j] != KINS_OK)   /* (a failure as it comes, written or
                                                      * not) */
            return kins_inverse(m->kins, m->pose, m->joint_cmd);
        for (int i = 0; i < m->nj; i++)        /* (inverse writes nj: the rest stays) */
            m->joint_cmd[i] = m->ahead.joints[j][i];
        return KINS_OK;
    }
    int st = kins_inverse_rates(m->kins, m->pose, m->pose_vel, m->joint_cmd, m->joint_vel);
    if (st != KINS_OK)
        memset(m->joint_vel, 0, sizeof m->joint_vel);
    return st;
}

/* Counts the setting points the path has reached: those before the segment being followed,
 * and every one once the program is done. */
static void pass_marks_to(struct motion *m, size_t reached)
{
    const struct motion_plan *p = m->run;
    while (m->marks_done < p->nmarks && p->marks[m->marks_done] <= reached)
        m->marks_done++;
}

/* Applies the spindle and coolant commands before segment `reached` and at it. */
static void pass_ios_to(struct motion *m, size_t reached)
{
    const struct motion_plan *p = m->run;
    while (m->ios_done < p->nios && p->ios[m->ios_done].at <= reached) {
        const struct motion_io *io = &p->ios[m->ios_done++];
        m->io_age = 0;
        switch (io->kind) {
        case IO_SPINDLE_SPEED: m->io.rpm = fabs(io->value); break;
        case IO_SPINDLE_ON: m->io.dir = io->value < 0 ? -1 : 1; break;
        case IO_SPINDLE_STOP: m->io.dir = 0; break;
        case IO_DOUT:
            if (io->value != 0)
                m->outputs.dout |= UINT64_C(1) << io->ivalue;
            else
                m->outputs.dout &= ~(UINT64_C(1) << io->ivalue);
            break;
        case IO_AOUT: m->outputs.aout[io->ivalue] = io->value; break;
        case IO_TOOL_CHANGE:
            m->tool.request = io->ivalue;
            m->tool.seq++;
            break;
        case IO_TOOL_SET: m->tool.number = m->tool.request = io->ivalue; break;
        case IO_COOLANT:
            if (io->ivalue == 7)
                m->io.mist = 1;
            else if (io->ivalue == 8)
                m->io.flood = 1;
            else
                m->io.mist = m->io.flood = 0;
            break;
        }
    }
}

/* The setting points and commands the path has reached: those before the segment being
 * followed, and every one once the program is done. */
static size_t reached_seg(const struct motion *m)
{
    return m->state == MOTION_DONE ? m->run->nseg : m->cs;
}

static void pass_marks(struct motion *m)
{
    pass_marks_to(m, reached_seg(m));
}

static inline void pass_ios(struct motion *m)
{
    size_t reached = reached_seg(m);   /* (most periods have none to pass: tested here) */
    const struct motion_plan *p = m->run;
    if (m->ios_done < p->nios && p->ios[m->ios_done].at <= reached)
        pass_ios_to(m, reached);
}

void motion_set_inputs(struct motion *m, const bool *din, int nd, const double *ain, int na)
{
    if (!m)
        return;
    for (int i = 0; i < nd && i < MOTION_MAX_DIO; i++)
        m->din[i] = din[i];
    for (int i = 0; i < na && i < MOTION_MAX_AIO; i++)
        m->ain[i] = ain[i];
}

double motion_input_result(const struct motion *m, unsigned *seq)
{
    struct motion *w = (struct motion *)m;
    if (seq)
        *seq = atomic_load_explicit(&w->input_seq, memory_order_acquire);
    return atomic_load_explicit(&w->input_result, memory_order_relaxed);
}

void motion_set_wait_tool(struct motion *m, bool on)
{
    if (m)
        m->wait_tool = on;
}

void motion_tool_changed(struct motion *m, unsigned seq)
{
    if (!m || seq != m->tool.seq)
        return;
    m->tool_done_seq = seq;
    m->tool.number = m->tool.request;
}

void motion_set_rates(struct motion *m, bool on)
{
    if (m)
        m->no_rates = !on;
}

void motion_set_brief(struct motion *m, bool on)
{
    if (m)
        m->brief = on;
}

void motion_set_wait_at_speed(struct motion *m, bool on)
{
    if (m)
        m->wait_at_speed = on;
}

void motion_set_spindle_at_speed(struct motion *m, bool at_speed)
{
    if (m)
        m->at_speed = at_speed;
}

/* A streamed program's first chunk, once the planner has published it (until then the
 * machine holds where it is). Always true for a whole program. */
static bool stream_ready(struct motion *m)
{
    if (!m->streaming || m->chunk)
        return m->run != NULL;
    struct motion_chunk *c = atomic_load_explicit(&m->stream_head, memory_order_acquire);
    if (!c)
        return false;
    enter_chunk(m, NULL, c, c->plan.nknot ? c->plan.kt[c->k_enter] : 0);
    return true;
}

/* Plan time left at override 1: of the program (a streamed one: from its checked total). */
static double remaining(const struct motion *m)
{
    if (!m->loaded || !m->run)
        return m->streaming ? m->stream_info.time_s : 0;
    if (!m->streaming || !m->chunk)
        return m->run->total_time_s - m->tau_s;
    if (!m->run->nknot)      /* a streamed end that holds no move */
        return 0;
    double t = m->chunk->t0_s + m->tau_s - m->run->kt[m->chunk->k_enter];
    return fmax(0, m->stream_info.time_s - t);
}

/* Tells the planner's side whether the executor is short of plan: running on a chunk with
 * no successor within 0.25 s of plan time of its hand-over, or with no chunk at all. */
static void stream_watch(struct motion *m)
{
    struct motion_chunk *wait = NULL;
    if (m->streaming && m->loaded && (m->state == MOTION_RUNNING ||
                                      m->state == MOTION_PAUSING ||
                                      m->state == MOTION_STOPPING)) {
        struct motion_chunk *c = m->chunk;
        if (!c)
            wait = MOTION_TAIL_TAKEN;
        else if (m->probe_halt == PROBE_PARKED)  /* stopped on the probe: read on */
            wait = !atomic_load_explicit(&c->next, memory_order_acquire) ? c : NULL;
        else if (c->sync)    /* after the M66 wait: the interpreter reads on (once the
                              * jerk limiter's average has come to rest there) */
            wait = m->tau_s >= c->plan.total_time_s && !m->waiting && motion_jerk_settled(m) &&
                   !atomic_load_explicit(&c->next, memory_order_acquire) ? c : NULL;
        else if (!c->last && !m->tail_taken &&
                 !atomic_load_explicit(&c->next, memory_order_acquire) &&
                 c->t_leave_s - m->tau_s < 0.25)
            wait = c;
    }
    atomic_store_explicit(&m->stream_wait, wait, memory_order_release);
}

/* The period's output record (only its first part where the record is brief). */
static __attribute__((noinline)) void report(struct motion *m, struct motion_out *out)
{
    /* (with jerk limits the spindle gets a command when the average reaches it: the wait
     * for it at speed counts from then, not from when the executor passed it) */
    const struct motion_spindle *sp = m->jerk ? &m->io_out : &m->io;
    if (sp->dir != m->io.dir || sp->rpm != m->io.rpm || sp->mist != m->io.mist ||
        sp->flood != m->io.flood)
        m->io_age = 0;
    int index_out = m->index_out;
    m->index_out = 0;
    memcpy(out->pose, m->pose, sizeof out->pose);
    out->tcp = m->loaded && m->tcp;
    out->tool_len_mm = out->tcp ? m->tool_len_mm : 0;
    out->seg_kind = m->loaded ? m->seg_kind : 0;
    memcpy(out->seg_from, m->seg_from, sizeof out->seg_from);
    memcpy(out->seg_to, m->seg_to, sizeof out->seg_to);
    out->path_tol_mm = m->path_tol_mm;
    memcpy(out->joint_pos, m->joint_cmd, sizeof out->joint_pos);
    out->line = m->line;
    out->file = m->file;
    out->state = m->state;
    out->status = m->state == MOTION_FAULT ? m->fault_status : MOTION_OK;
    out->time_elapsed_s = m->elapsed_s;
    out->distance_done_mm = m->dist_mm;
    out->distance_total_mm = m->streaming ? m->stream_info.length_mm : m->run->total_len_mm;
    if (m->brief)
        return;
    memcpy(out->pose_vel, m->pose_vel, sizeof out->pose_vel);
    memcpy(out->prog_pose, out->tcp ? m->prog_pose : m->pose, sizeof out->prog_pose);
    memcpy(out->joint_vel, m->joint_vel, sizeof out->joint_vel);
    for (int i = 0; i < KINS_MAX_JOINTS; i++)   /* (all: a fixed count is vectorised; */
        out->motor_pos[i] = m->joint_cmd[i] + m->motor_offset[i];  /* unused ones are 0) */
    memcpy(out->joint_fb, m->joint_fb, sizeof out->joint_fb);
    memcpy(out->ferror_mm, m->ferror, sizeof out->ferror_mm);
    out->njoints = m->nj;
    out->path_vel = m->path_vel;
    out->time_remaining_s = remaining(m);
    out->feed_override = m->rate;
    out->settings_done = m->marks_base + m->marks_done;
    out->spindle = *sp;
    out->spindle_index = index_out;
    out->waiting = m->waiting;
    out->tool = m->tool;
    out->outputs = m->jerk ? m->outputs_out : m->outputs;
    out->probe_input = m->probe_in;
}

/* A check's period at the plan's own pace that stays within its interval of the plan, with
 * the look-ahead's entry for it ready (motion_ahead.c): motion_step's work for it without
 * the tests that cannot come true there (no probe, wait, pause, jerk average, synchronised
 * or G43.4 move, stepped block, override, chunk hand-over or end of the plan). Any other
 * period is motion_step's (false, nothing done). Every value is the one the full path
 * computes (test_ahead_same_bits compares them period by period). */
static inline bool calm_period(struct motion *m, double dt, struct motion_out *out)
{
    struct motion_ahead *a = &m->ahead;
    const struct motion_plan *p = m->run;
    if (!m->brief || a->next >= a->n || a->run != p || !motion_at_plan_pace(m))
        return false;
    const struct motion_ahead_at *e = &a->at[a->next];
    const struct motion_seg *sg = &p->segs[m->cs];
    double tau = m->tau_s + dt;              /* advance() at the plan's pace */
    /* (the entry was filled at this clock in this interval: follow_knots stays in it) */
    if (e->ci != m->ci || e->cs != m->cs || e->tau_s != tau || !(tau < p->total_time_s) ||
        sg != m->seg_at || sg->kind > SEG_ARC || a->status[a->next] != KINS_OK || m->jerk ||
        !m->no_rates || m->probe_wired || m->probe_seg || m->step_until_seg || !m->loaded ||
        (m->streaming && !m->chunk))
        return false;
    m->io_age++;
    pass_ios(m);
    m->elapsed_s += dt;
    motion_sync_advance(m, dt);          /* (the ideal spindle turns; no synchronised move) */
    m->tau_s = tau;
    pass_marks(m);
    pass_ios(m);
    a->taken++, a->calm++;
    entry_values(m, sg, a->next++);
    stream_watch(m);
    report(m, out);
    return true;
}

/* See motion.h. The periods calm_period would take one by one, and past the knots inside
 * the segment as well (follow_knots does nothing else there: no pause or wait lies on a
 * line or an arc, and the chunk's hand-over knot ends the run), their entries filled here
 * where none is left (at the plan's pace the next periods' key is known before the clock
 * moves: motion_ahead_next). The per-period work is the clock, the interval, the passed
 * commands and the place; the record, the status watch and the executor's pose are
 * written once, for the last. */
int motion_step_calm(struct motion *m, double dt, struct motion_calm *c, struct motion_out *out)
{
    if (!m || !c || !out || !(dt > 0) || !m->ahead_on || !m->brief || !m->no_rates ||
        !m->loaded || m->jerk || m->probe_wired || m->probe_seg || m->step_until_seg ||
        (m->streaming && !m->chunk) || !motion_at_plan_pace(m))
        return 0;
    struct motion_ahead *a = &m->ahead;
    const struct motion_plan *p = m->run;
    const struct motion_seg *sg = &p->segs[m->cs];
    if (sg != m->seg_at || sg->kind > SEG_ARC)
        return 0;
    if ((a->next >= a->n || a->run != p) && !motion_ahead_next(m, dt))
        return 0;
    /* (a chunk's hand-over knot, where follow_knots switches to the successor: no run
     * passes it) */
    size_t k_leave = m->chunk && !m->chunk->last && !m->tail_taken ? m->chunk->k_leave
                                                                    : SIZE_MAX;
    int first = a->next, n = 0;
    while (a->next < a->n) {
        const struct motion_ahead_at *e = &a->at[a->next];
        double tau = m->tau_s + dt;          /* advance() at the plan's pace */
        /* (the entry was filled at this clock, its knots followed as follow_knots follows
         * them: on this segment, a line or an arc, whose knots hold no pause or wait) */
        if (e->cs != m->cs || e->tau_s != tau || !(tau < p->total_time_s) ||
            a->status[a->next] != KINS_OK || (e->ci != m->ci && e->ci >= k_leave))
            break;
        /* (the run's first period passes the commands at the segment, and the periods
         * after it find none left to pass: the segment is the same) */
        m->ci = e->ci;
        m->io_age++;
        if (n == 0)
            pass_ios(m);
        m->elapsed_s += dt;
        motion_sync_turn(m, dt);             /* motion_sync_advance off a synchronised */
        m->sync.phase = SYNC_IDLE;           /* move: the ideal spindle turns */
        m->tau_s = tau;
        if (n == 0) {
            pass_marks(m);
            pass_ios(m);
        }
        c->time_s[n] = m->elapsed_s;
        c->s[n] = e->s;            /* (entry_values' distance from it: motion_calm_dist) */
        a->taken++, a->calm++;
        a->next++, n++;
    }
    if (!n)
        return 0;
    entry_values(m, sg, a->next - 1);
    stream_watch(m);
    report(m, out);
    c->n = n;
    c->dist0_mm = sg->dist0_mm, c->xyz_len_mm = sg->xyz_len_mm, c->len = sg->len;
    c->pose = (const double(*)[KINS_POSE_DIM])a->pose[first];
    c->joints = (const double(*)[KINS_MAX_JOINTS])a->joints[first];
    return n;
}

/* One servo period (see motion.h). */
int motion_step(struct motion *m, double period_s, struct motion_out *out)
{
    if (!m || !out || !(period_s > 0))
        return MOTION_ERR_ARG;
    if (m->ahead_on && calm_period(m, period_s, out))
        return MOTION_OK;
    int ret = MOTION_OK;
    int moving = m->state == MOTION_RUNNING || m->state == MOTION_PAUSING ||
                 m->state == MOTION_STOPPING;
    if (m->state == MOTION_PAUSED)
        m->elapsed_s += period_s;
    if (moving && m->streaming && stream_ready(m) && m->chunk->last && m->run->nseg == 0)
        m->state = MOTION_DONE;  /* a streamed program without a move */
    if (m->state == MOTION_MANUAL) {
        motion_manual_step(m, period_s);   /* the leader ... */
        motion_jerk_follow(m);             /* ... and with jerk limits its average */
    } else if (moving && m->loaded && stream_ready(m) && m->run->nseg) {
        m->io_age++;
        pass_ios(m);           /* the commands at the present place first: a wait there */
        advance(m, period_s);  /* must see its own spindle command out */
        pass_marks(m);
        pass_ios(m);
        /* (a streamed end holds no move; at rest on a probe's trip the pose holds) */
        int st = m->run->nseg && m->probe_halt != PROBE_PARKED ? evaluate(m, period_s) : KINS_OK;
        if (st == KINS_OK)
            motion_jerk_follow(m);
        else
            motion_jerk_restore(m);
        motion_probe_settle(m);
        if (st != KINS_OK) {
            motion_set_msg(m, "%s:%d: the kinematics failed on the planned path "
                     "(%s); machine stopped", m->file ? m->file : "program", m->line,
                     kins_strerror(st));
            m->state = MOTION_FAULT;
            m->fault_status = ret = MOTION_ERR_KINS;
        }
    } else {
        if (m->loaded && m->state == MOTION_DONE) {
            pass_marks(m);     /* a program without moves is done at once */
            pass_ios(m);
        }
        if (m->state == MOTION_FAULT || (m->state == MOTION_IDLE && !m->loaded))
            memset(&m->io, 0, sizeof m->io);  /* a fault or an abort stops the spindle */
        m->path_vel = 0;
        memset(m->pose_vel, 0, sizeof m->pose_vel);
        memset(m->joint_vel, 0, sizeof m->joint_vel);
        motion_jerk_hold(m);
    }
    stream_watch(m);
    report(m, out);
    return ret;
}
