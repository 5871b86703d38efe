/* runner_exec.c: runs a planned program: start, the per-period monitor, stop, summary. */
#include "task/runner_priv.h"

#include <math.h>
#include <string.h>
#include <time.h>

#include "common/errbuf.h"
#include "hal/drivers/drive_startup.h"
#include "hal/components/lcm_status.h"
#include "motion/motion_hal.h"

/* Slice of machine time between checks of the stop flag and progress calls. */
#define RUNNER_SLICE_PERIODS 10
#define RUNNER_RT_SLICE_S 0.02

/* States in which the program is under way (the clock of the run is ticking). */
static bool runner_state_active(enum motion_state s)
{
    return s == MOTION_RUNNING || s == MOTION_PAUSING || s == MOTION_PAUSED ||
           s == MOTION_STOPPING;
}

/* Asks the motion core itself, so it works with or without the monitor. */
bool runner_moving(const struct runner *r)
{
    return runner_state_active(motion_get_state(r->motion));
}

/* The monitor funct, last on the servo thread: it sees each period's leg commands and
 * feedback after the drives have acted, and keeps the peaks for the summary. */
static void runner_monitor(void *arg, long period_ns)
{
    struct runner *r = arg;
    double dt_s = (double)period_ns * 1e-9;
    double cmd[KINS_MAX_JOINTS], fb[KINS_MAX_JOINTS];
    motion_hal_out(r->hal, &r->last);
    enum motion_state state = r->last.state;
    bool active = runner_state_active(state);
    struct runner_summary *s = &r->sum;
    for (int i = 0; i < r->njoints; i++) {
        cmd[i] = *r->cmd_pin[i];
        fb[i] = *r->fb_pin[i];
        r->rate_mm_s[i] = r->have_prev ? (cmd[i] - r->prev_cmd_mm[i]) / dt_s : 0.0;
        r->prev_cmd_mm[i] = cmd[i];
        if (!r->started)
            continue;
        s->max_ferror_mm[i] = fmax(s->max_ferror_mm[i], fabs(cmd[i] - fb[i]));
        s->leg_min_mm[i] = fmin(s->leg_min_mm[i], cmd[i]);
        s->leg_max_mm[i] = fmax(s->leg_max_mm[i], cmd[i]);
        if (active)
            s->peak_rate_mm_s[i] = fmax(s->peak_rate_mm_s[i], fabs(r->rate_mm_s[i]));
    }
    r->have_prev = true;
    /* The e-stop reset request lasts one period: the latch has seen its rising edge. */
    *r->user_request_enable = false;
    if (r->started && active)  /* only this thread writes it: no read-modify-write needed */
        atomic_store_explicit(&r->running_periods,
                              atomic_load_explicit(&r->running_periods, memory_order_relaxed)
                              + 1, memory_order_relaxed);
    if (r->observer) {
        struct runner_sample smp = {
            .time_ns = hal_now_ns(r->hal), .njoints = r->njoints, .joint_cmd_mm = cmd,
            .joint_fb_mm = fb, .joint_rate_mm_s = r->rate_mm_s, .line = r->last.line,
            .state = state,
        };
        r->observer(r->observer_ctx, &smp);
    }
    /* Relaxed: the readers only display these; no other data hangs on their order. */
    atomic_store_explicit(&r->mon_distance_mm, r->last.distance_done_mm, memory_order_relaxed);
    atomic_store_explicit(&r->mon_file, r->last.file, memory_order_relaxed);
    atomic_store_explicit(&r->mon_line, r->last.line, memory_order_relaxed);
    atomic_store_explicit(&r->mon_settings, r->last.settings_done, memory_order_release);
    atomic_store_explicit(&r->mon_state, (int)state, memory_order_relaxed);
    atomic_store_explicit(&r->mon_periods,
                          atomic_load_explicit(&r->mon_periods, memory_order_relaxed) + 1,
                          memory_order_relaxed);
}

/* Exports runner.monitor and appends it to servo-thread, after every HAL file's functs. */
int runner_monitor_install(struct runner *r, char *err, size_t errlen)
{
    snprintf(r->thread, sizeof r->thread, "servo-thread");
    if (hal_export_functf(r->hal, runner_monitor, r, "runner.monitor") != HAL_OK ||
        hal_addf(r->hal, "runner.monitor", r->thread, 0) != HAL_OK)
        return errbuf_set(err, errlen, RUNNER_ERR_HAL, "the run monitor cannot join the "
                           "servo thread: %s", hal_last_error(r->hal));
    return RUNNER_OK;
}

/* Sets the per-period observer (tests use it to check every period). */
void runner_set_observer(struct runner *r, runner_observer_fn fn, void *ctx)
{
    r->observer = fn;
    r->observer_ctx = ctx;
}

/* Clears the peaks before a run. */
static void runner_reset_summary(struct runner *r)
{
    memset(&r->sum, 0, sizeof r->sum);
    r->sum.njoints = r->njoints;
    for (int i = 0; i < r->njoints; i++) {
        r->sum.leg_min_mm[i] = INFINITY;
        r->sum.leg_max_mm[i] = -INFINITY;
    }
    r->running_periods = 0;
    atomic_store(&r->mon_periods, 0);
}

/* Machine on, program start request, threads running. */
int runner_start(struct runner *r, char *err, size_t errlen)
{
    if (!r->loaded)
        return errbuf_set(err, errlen, RUNNER_ERR_STATE, "no program is loaded");
    if (runner_moving(r))
        return errbuf_set(err, errlen, RUNNER_ERR_STATE, "the machine is still running");
    runner_reset_summary(r);
    r->aborting = false;
    r->settings_applied = 0;
    r->save_err[0] = '\0';
    atomic_store(&r->mon_settings, 0);
    r->ready_since = -1;
    r->first_fault[0] = '\0';  /* the cause of this run's stop, not of an earlier one */
    /* Machine on: out of e-stop (reset pulse to the latch), then enabled. */
    *r->user_enable_out = true;
    if (!*r->emc_enable_in)
        *r->user_request_enable = true;
    if (motion_hal_start(r->hal) != MOTION_OK)
        return errbuf_set(err, errlen, RUNNER_ERR_STATE, "%s", motion_hal_fault(r->hal));
    atomic_store(&r->mon_state, (int)MOTION_RUNNING);
    r->started = true;
    if (!hal_running(r->hal) && hal_start(r->hal) != HAL_OK) {
        r->started = false;
        return errbuf_set(err, errlen, RUNNER_ERR_RT, "%s", hal_last_error(r->hal));
    }
    lcm_status_post_event(r->hal, LCM_SEV_INFO, RUNNER_EVENT_STARTED, "task", 0,
                          "program started: %.3f s and %.3f mm planned", r->plan.time_s,
                          r->plan.length_mm);
    return RUNNER_OK;
}

/* Simulated clock: runs the threads for dt_s; real time: sleeps dt_s. Then saves the
 * settings of the lines the machine has passed meanwhile. */
int runner_advance(struct runner *r, double dt_s)
{
    int st = RUNNER_OK;
    if (r->sim_clock) {
        if (hal_sim_advance(r->hal, (long)llround(dt_s * 1e9)) != HAL_OK)
            st = RUNNER_ERR_RT;
    } else {
        struct timespec ts = { (time_t)dt_s, (long)((dt_s - floor(dt_s)) * 1e9) };
        nanosleep(&ts, NULL);
    }
    if (r->started)
        runner_settings_apply(r);
    return st;
}

/* Ctrl-C's path: motion decelerates along the path, then drops the program. */
int runner_abort(struct runner *r)
{
    if (!r->started)
        return RUNNER_ERR_STATE;
    r->aborting = true;
    return motion_hal_abort(r->hal) == MOTION_OK ? RUNNER_OK : RUNNER_ERR_STATE;
}

/* Done, faulted, or at rest after an abort. */
bool runner_finished(const struct runner *r)
{
    if (!r->started)
        return false;
    enum motion_state s = (enum motion_state)atomic_load(&r->mon_state);
    return s == MOTION_DONE || s == MOTION_FAULT || (r->aborting && s == MOTION_IDLE);
}

/* Line, percent, elapsed and remaining machine time, from the monitor's last period. */
int runner_get_progress(const struct runner *r, struct runner_progress *p)
{
    memset(p, 0, sizeof *p);
    p->state = (enum motion_state)atomic_load(&r->mon_state);
    p->line = atomic_load(&r->mon_line);
    p->file = atomic_load(&r->mon_file);
    p->elapsed_s = (double)r->running_periods * (double)r->period_ns * 1e-9;
    p->remaining_s = fmax(0.0, r->plan.time_s - p->elapsed_s);
    if (r->plan.length_mm > 0.0)
        p->percent = 100.0 * atomic_load(&r->mon_distance_mm) / r->plan.length_mm;
    else if (r->plan.time_s > 0.0)
        p->percent = 100.0 * fmin(1.0, p->elapsed_s / r->plan.time_s);
    if (p->state == MOTION_DONE)
        p->percent = 100.0;
    return RUNNER_OK;
}

void runner_set_message_fn(struct runner *r, runner_message_fn fn, void *ctx)
{
    r->msg_fn = fn;
    r->msg_ctx = ctx;
}

/* Takes the components' messages; the first fault is kept as the cause of a stop. Each
 * also goes out on HEXCNC_EVENT when lcm-status is loaded (else the post does nothing). */
static void runner_drain_messages(struct runner *r)
{
    static const enum lcm_status_severity sev[] = {
        [HAL_MSG_INFO] = LCM_SEV_INFO, [HAL_MSG_WARNING] = LCM_SEV_WARNING,
        [HAL_MSG_FAULT] = LCM_SEV_FAULT,
    };
    struct hal_msg m;
    while (hal_msg_take(r->hal, &m)) {
        if (m.severity == HAL_MSG_FAULT && !r->first_fault[0])
            snprintf(r->first_fault, sizeof r->first_fault, "%s: %s", m.source, m.text);
        lcm_status_post_event(r->hal, sev[m.severity], RUNNER_EVENT_MESSAGE, m.source, -1, "%s",
                              m.text);
        if (r->msg_fn)
            r->msg_fn(r->msg_ctx, &m);
    }
}

/* The run's outcome as an event: finished, aborted or faulted (with the error text). */
static void runner_post_outcome(struct runner *r, int st, const char *err)
{
    if (st == RUNNER_OK)
        lcm_status_post_event(r->hal, LCM_SEV_INFO, RUNNER_EVENT_FINISHED, "task", -1,
                              "program finished");
    else if (st == RUNNER_ERR_ABORTED)
        lcm_status_post_event(r->hal, LCM_SEV_WARNING, RUNNER_EVENT_ABORTED, "task", -1, "%s",
                              err);
    else
        lcm_status_post_event(r->hal, LCM_SEV_FAULT, RUNNER_EVENT_FAULT, "task", -1, "%s: %s",
                              runner_strerror(st), err);
}

/* How the run ended, as a status and a message. */
static int runner_outcome(struct runner *r, char *err, size_t errlen)
{
    enum motion_state s = (enum motion_state)atomic_load(&r->mon_state);
    double t_s = (double)r->running_periods * (double)r->period_ns * 1e-9;
    if (r->save_err[0])
        return errbuf_set(err, errlen, RUNNER_ERR_FAULT, "%s", r->save_err);
    if (s == MOTION_FAULT && r->first_fault[0])
        return errbuf_set(err, errlen, RUNNER_ERR_FAULT, "%s (cause: %s)",
                           motion_hal_fault(r->hal), r->first_fault);
    if (s == MOTION_FAULT)
        return errbuf_set(err, errlen, RUNNER_ERR_FAULT, "%s", motion_hal_fault(r->hal));
    if (r->aborting)
        return errbuf_set(err, errlen, RUNNER_ERR_ABORTED, "stopped by the operator at line "
                           "%d after %.3f s: the machine came to rest on the path",
                           atomic_load(&r->mon_line), t_s);
    return RUNNER_OK;
}

/* Once the drives are ready, a program that has not started moving after this many periods
 * never will: the machine is held in e-stop (motion.enable false). */
#define RUNNER_START_PERIODS 100

/* The drives' start-up as the drive components report it (drive_startup.h): the worst state
 * and the longest budget; ready when no drive component is loaded. */
static enum drive_startup_state runner_drives_startup(struct runner *r, int64_t *budget_ns,
                                                      const char **what)
{
    static const char *const names[] = DRIVE_STARTUP_OBJECTS;
    enum drive_startup_state worst = DRIVE_STARTUP_READY;
    *budget_ns = 0;
    *what = "the drives";
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        struct drive_startup *d = hal_get_object(r->hal, names[i]);
        if (!d)
            continue;
        int st = atomic_load(&d->state);
        if (d->budget_ns > *budget_ns)
            *budget_ns = d->budget_ns;
        if (st == DRIVE_STARTUP_FAILED || (st == DRIVE_STARTUP_STARTING &&
                                           worst == DRIVE_STARTUP_READY)) {
            worst = (enum drive_startup_state)st;
            *what = d->what;
        }
    }
    return worst;
}

/* Periods the threads run, machine off, before a program is planned: the motion component
 * takes the legs' feedback as its command after two (MOTION_FEEDBACK_SETTLE), and the
 * forward kinematics of it as the pose. */
#define RUNNER_FEEDBACK_PERIODS 4

/* Before the first program of `hexcnc run`: starts the threads with the machine off and
 * runs them until the drives have started (within their configured time-outs) and the
 * motion component follows their feedback, so the program is planned from where the legs
 * are, not from an assumed home pose. The session has its threads running already. */
void runner_feedback_settle(struct runner *r)
{
    if (hal_running(r->hal))
        return;
    *r->user_enable_out = false;
    if (hal_start(r->hal) != HAL_OK)
        return;  /* runner_start reports it */
    int64_t budget_ns;
    const char *what;
    long n = 0;
    long max = RUNNER_START_PERIODS + RUNNER_FEEDBACK_PERIODS;
    for (; n < max; n++) {
        if (n >= RUNNER_FEEDBACK_PERIODS &&
            runner_drives_startup(r, &budget_ns, &what) != DRIVE_STARTUP_STARTING)
            break;
        if (n == RUNNER_FEEDBACK_PERIODS)  /* starting: wait as long as they may take */
            max += (long)(budget_ns / r->period_ns);
        if (r->sim_clock) {
            hal_sim_advance(r->hal, r->period_ns);
        } else {
            struct timespec ts = { 0, r->period_ns };
            nanosleep(&ts, NULL);
        }
    }
    if (!r->sim_clock) {  /* the thread's own periods, not the sleeps, count */
        struct timespec ts = { 0, RUNNER_FEEDBACK_PERIODS * r->period_ns };
        nanosleep(&ts, NULL);
    }
    r->pre_periods = atomic_load(&r->mon_periods);  /* the summary counts them too */
}

/* Says why a started program stays idle: a drive that failed to start (its own message),
 * drives still starting past the time their configuration allows, or, with every drive
 * ready, an e-stop chain that never released. Waits meanwhile. */
static int runner_check_started(struct runner *r, char *err, size_t errlen)
{
    if (r->aborting || r->running_periods > 0 ||
        (enum motion_state)atomic_load(&r->mon_state) != MOTION_IDLE)
        return RUNNER_OK;
    int64_t budget_ns;
    const char *what;
    enum drive_startup_state st = runner_drives_startup(r, &budget_ns, &what);
    long periods = atomic_load(&r->mon_periods);
    double waited_ms = (double)periods * (double)r->period_ns * 1e-6;
    if (st == DRIVE_STARTUP_FAILED || r->first_fault[0])
        return errbuf_set(err, errlen, RUNNER_ERR_FAULT, "a drive faulted before motion, the "
                           "program did not start: %s", r->first_fault[0] ? r->first_fault
                           : what);
    if (st == DRIVE_STARTUP_STARTING) {
        r->ready_since = -1;
        if ((double)periods * (double)r->period_ns <= (double)budget_ns +
            RUNNER_START_PERIODS * (double)r->period_ns)
            return RUNNER_OK;
        return errbuf_set(err, errlen, RUNNER_ERR_TIMEOUT, "%s still starting after %.0f ms, "
                           "longer than their configured time-outs allow (%.0f ms): the "
                           "program did not start", what, waited_ms, (double)budget_ns * 1e-6);
    }
    if (r->ready_since < 0) {
        r->ready_since = periods;
        /* the reset pulse of runner_start may have come while a drive was still starting
         * (its fault output holding the latch open: under load the drives can take longer
         * than the settling before it); the drives are ready now, so the reset is sent
         * again, as an operator would press it again */
        if (!*r->emc_enable_in && *r->user_enable_out)
            *r->user_request_enable = true;
    }
    if (periods - r->ready_since < RUNNER_START_PERIODS)
        return RUNNER_OK;
    return errbuf_set(err, errlen, RUNNER_ERR_STATE, "the machine did not come out of "
                       "e-stop: motion.enable stayed false (task.emc-enable-in %s); the HAL "
                       "files must wire task.user-enable-out and task.user-request-enable "
                       "into the e-stop chain ([TASK] HALFILE)",
                       *r->emc_enable_in ? "true" : "false");
}

/* The run loop: slices of machine time, stop flag, progress, start check, time-out. */
int runner_run(struct runner *r, const volatile sig_atomic_t *stop, runner_progress_fn fn,
               void *ctx, char *err, size_t errlen)
{
    if (!r->started)
        return errbuf_set(err, errlen, RUNNER_ERR_STATE, "the program is not started");
    double slice_s = r->sim_clock ? RUNNER_SLICE_PERIODS * (double)r->period_ns * 1e-9
                                  : RUNNER_RT_SLICE_S;
    /* A program that overruns its plan by this much is stuck: stop rather than hang. */
    double limit_s = 2.0 * r->plan.time_s + 10.0;
    struct runner_progress p;
    int st = RUNNER_OK;
    while (!runner_finished(r)) {
        if (stop && *stop && !r->aborting)
            runner_abort(r);
        if ((st = runner_advance(r, slice_s)) != RUNNER_OK) {
            errbuf_set(err, errlen, st, "%s", hal_last_error(r->hal));
            break;
        }
        runner_drain_messages(r);
        runner_get_progress(r, &p);
        if (fn)
            fn(ctx, &p);
        if ((st = runner_check_started(r, err, errlen)) != RUNNER_OK)
            break;
        if (p.elapsed_s > limit_s) {
            st = errbuf_set(err, errlen, RUNNER_ERR_TIMEOUT, "the machine was still moving "
                             "after %.1f s, twice the planned %.1f s", p.elapsed_s,
                             r->plan.time_s);
            break;
        }
    }
    if (!r->sim_clock)
        hal_stop(r->hal);
    runner_settings_apply(r);  /* those passed in the last slice */
    runner_drain_messages(r);
    if (st == RUNNER_OK)
        st = runner_outcome(r, err, errlen);
    runner_post_outcome(r, st, err);
    runner_get_progress(r, &p);
    if (fn)
        fn(ctx, &p);
    return st;
}

/* Peaks from the monitor, plan figures, and the final pose by forward kinematics. */
int runner_summary(struct runner *r, struct runner_summary *s)
{
    *s = r->sum;
    s->njoints = r->njoints;
    s->machine_time_s = (double)r->running_periods * (double)r->period_ns * 1e-9;
    s->planned_time_s = r->plan.time_s;
    s->distance_mm = r->last.distance_done_mm;
    s->periods = atomic_load(&r->mon_periods) + r->pre_periods;
    s->state = (enum motion_state)atomic_load(&r->mon_state);
    for (int i = 0; i < r->njoints; i++)
        s->final_legs_mm[i] = *r->fb_pin[i];
    /* Forward kinematics of the final feedback, warm-started at the commanded pose. */
    memcpy(s->final_cmd_pose, r->last.pose, sizeof s->final_cmd_pose);
    memcpy(s->final_pose, r->last.pose, sizeof s->final_pose);
    s->final_pose_ok = kins_forward(r->kins, s->final_legs_mm, s->final_pose, NULL) == KINS_OK;
    return RUNNER_OK;
}
