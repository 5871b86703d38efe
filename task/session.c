/* session.c: the machine session's state machine and commands (LinuxCNC's task, for hexcnc). */
#include "task/session_priv.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "common/errbuf.h"
#include "interp/interp.h"
#include "motion/motion_hal.h"

/* Periods the e-stop chain gets to close after machine.power {on: true}. */
#define SESSION_POWER_PERIODS 20
/* Servo periods the drives have to report ready after the e-stop chain closed. */
#define SESSION_ENABLE_PERIODS 2000

/* Formats an RPC error into err and returns its code. */
static int fail(int code, char *err, size_t len, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static int fail(int code, char *err, size_t len, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, len, fmt, ap);
    va_end(ap);
    return code;
}

static void sleep_ms(double ms)
{
    struct timespec ts = { (time_t)(ms / 1000), (long)(fmod(ms, 1000.0) * 1e6) };
    nanosleep(&ts, NULL);
}

/* Runs the machine for n servo periods (simulated clock) or waits as long (real time). */
static void session_wait_periods(struct session *s, int n)
{
    if (s->sim)
        hal_sim_advance(s->hal, (long)n * s->period_ns);
    else
        sleep_ms((double)n * (double)s->period_ns * 1e-6);
}

static enum motion_state mstate(const struct session *s)
{
    return motion_get_state(s->m);
}

/* Nothing moves: no program, no jog, no homing. */
static bool at_rest(const struct session *s)
{
    enum motion_state st = mstate(s);
    return !s->running && (st == MOTION_IDLE || st == MOTION_DONE || st == MOTION_FAULT);
}

bool session_busy(const struct session *s)
{
    enum motion_state st = mstate(s);
    return s->running || st == MOTION_MANUAL || motion_homing(s->m);
}

/* Whether programs and MDI may run: every leg homed, or [TRAJ] NO_FORCE_HOMING. */
static int need_homed(struct session *s, const char *what, char *err, size_t len)
{
    if (!motion_pose_known(s->m))
        return fail(RPC_STATE, err, len, "%s refused: the legs' lengths give no pose of the "
                    "platform (the forward kinematics has no answer): jog the legs (frame "
                    "joint) into the workspace, or home them", what);
    if (s->no_force_homing || motion_all_homed(s->m))
        return 0;
    return fail(RPC_STATE, err, len, "%s refused: the machine is not homed (machine.home "
                "first, or [TRAJ] NO_FORCE_HOMING = 1)", what);
}

static int need_on(struct session *s, const char *what, char *err, size_t len)
{
    if (s->state == SESS_ON)
        return 0;
    return fail(RPC_STATE, err, len, "%s refused: the machine is %s (%s)", what,
                s->state == SESS_ESTOP ? "in e-stop" : "off",
                s->state == SESS_ESTOP ? "machine.estop {active: false}, then machine.power "
                "{on: true}" : "machine.power {on: true} first");
}

static int need_idle(struct session *s, const char *what, char *err, size_t len)
{
    if (s->running)
        return fail(RPC_STATE, err, len, "%s refused: %s is running (program.abort first)",
                    what, s->run_is_mdi ? "an MDI line" : "a program");
    if (!at_rest(s))
        return fail(RPC_STATE, err, len, "%s refused: the machine is %s (jog.stop first)",
                    what, motion_homing(s->m) ? "homing" : "moving");
    return 0;
}

void session_message(struct session *s, const char *sev, const char *source,
                     const char *fmt, ...)
{
    char text[800];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    if (!strcmp(sev, "error"))
        snprintf(s->last_error, sizeof s->last_error, "%s", text);
    if (!s->quiet)
        fprintf(stderr, "hexcnc machine: %s: %s: %s\n", sev, source, text);
    json_t *msg = json_pack("{s:s, s:s, s:{s:f, s:s, s:s, s:s}}", "jsonrpc", "2.0", "method",
                            "message", "params", "time", (double)hal_now_ns(s->hal) * 1e-9,
                            "severity", sev, "source", source, "text", text);
    if (msg)
        session_server_broadcast_message(s, msg);
    json_decref(msg);
}

/* Waits until the servo thread has taken what the task queued (a start, an abort, a manual
 * command), so that the answer and any status read after it show its effect. */
static void session_settle(struct session *s)
{
    if (s->sim) {
        for (int i = 0; i < SESSION_POWER_PERIODS && motion_hal_pending(s->hal); i++)
            session_wait_periods(s, 1);
        return;
    }
    /* on the wall clock: look every 50 us, so the answer follows the servo thread's next
     * period rather than a whole period later */
    double max_ms = SESSION_POWER_PERIODS * (double)s->period_ns * 1e-6;
    for (double t = 0; t < max_ms && motion_hal_pending(s->hal); t += 0.05)
        sleep_ms(0.05);
}

/* Queues a manual command for the servo thread. */
static int push(struct session *s, const struct motion_hal_cmd *c, char *err, size_t len)
{
    if (motion_hal_command(s->hal, c) != MOTION_OK)
        return fail(RPC_FAILED, err, len, "the motion command queue is full; try again");
    session_settle(s);
    return 0;
}

static void mdi_renew(struct session *s);

/* The machine went off under a program or MDI line: the run ends where the legs stopped. */
static void run_cut(struct session *s, const char *why)
{
    if (!s->running)
        return;
    int line = atomic_load(&s->r->mon_line);
    s->running = false;
    s->stopping = false;
    runner_settings_apply(s->r);
    session_message(s, "error", "task", "%s stopped at line %d: %s", s->run_is_mdi ?
                    "MDI line" : "program", line, why);
    if (!s->run_is_mdi)
        mdi_renew(s);
}

/* Waits until the e-stop chain is open and motion has stopped: the answer to an e-stop or
 * a switch-off goes out once the machine is off, never before. */
static void wait_off(struct session *s)
{
    for (int i = 0; i < SESSION_POWER_PERIODS; i++) {
        enum motion_state st = mstate(s);
        bool moving = st == MOTION_RUNNING || st == MOTION_PAUSING || st == MOTION_STOPPING ||
                      st == MOTION_MANUAL;
        if (!*s->r->emc_enable_in && !moving)
            return;
        session_wait_periods(s, 1);
    }
}

int session_estop(struct session *s, bool active, char *err, size_t len)
{
    if (active) {
        *s->r->user_enable_out = false;
        wait_off(s);
        run_cut(s, "e-stop");
        if (s->state != SESS_ESTOP)
            session_message(s, "warning", "task", "e-stop: the machine stopped at once");
        s->state = SESS_ESTOP;
        return 0;
    }
    if (s->state == SESS_ESTOP)
        s->state = SESS_OFF;
    return 0;
}

int session_power(struct session *s, bool on, char *err, size_t len)
{
    if (!on) {
        *s->r->user_enable_out = false;
        wait_off(s);
        run_cut(s, "the machine was switched off");
        if (s->state == SESS_ON)
            s->state = SESS_OFF;
        return 0;
    }
    if (s->state == SESS_ESTOP)
        return fail(RPC_STATE, err, len, "machine on refused: the machine is in e-stop "
                    "(machine.estop {active: false} first)");
    if (s->state == SESS_ON)
        return 0;
    *s->r->user_enable_out = true;
    *s->r->user_request_enable = true;
    /* a drive that faulted clears its fault on the reset edge before the chain closes:
     * CiA 402 drives take tens of periods for it */
    for (int i = 0; i < SESSION_ENABLE_PERIODS && !*s->r->emc_enable_in; i++)
        session_wait_periods(s, 1);
    if (!*s->r->emc_enable_in) {
        *s->r->user_enable_out = false;
        return fail(RPC_FAILED, err, len, "machine on failed: the e-stop chain did not close "
                    "(task.emc-enable-in stayed false; check the e-stop wiring in the HAL "
                    "files)");
    }
    /* the drives may need longer than the e-stop chain to be ready (CiA 402 drives switch
     * on through their state machine): motion.enable says when they are */
    for (int i = 0; i < SESSION_ENABLE_PERIODS && !motion_hal_enabled(s->hal); i++)
        session_wait_periods(s, 1);
    if (!motion_hal_enabled(s->hal)) {
        *s->r->user_enable_out = false;
        return fail(RPC_FAILED, err, len, "machine on failed: motion.enable stayed false "
                    "for %d servo periods after the e-stop chain closed (the drives did not "
                    "report ready; see the messages)", SESSION_ENABLE_PERIODS);
    }
    session_wait_periods(s, 2);  /* motion has seen enable: the command is the legs' */
    s->state = SESS_ON;
    session_message(s, "info", "task", "machine on");
    return 0;
}

int session_set_mode(struct session *s, enum session_mode mode, char *err, size_t len)
{
    if (mode == s->mode)
        return 0;
    if (s->running || !at_rest(s))
        return fail(RPC_STATE, err, len, "mode change refused: the machine is %s",
                    s->running ? "running a program" : "moving");
    s->mode = mode;
    return 0;
}

int session_home(struct session *s, int joint, char *err, size_t len)
{
    int rc;
    if ((rc = need_on(s, "homing", err, len)) || (rc = need_idle(s, "homing", err, len)))
        return rc;
    s->mode = SESS_MANUAL;
    struct motion_hal_cmd c = { .kind = MOTION_CMD_HOME, .axis = joint };
    return push(s, &c, err, len);
}

int session_unhome(struct session *s, int joint, char *err, size_t len)
{
    int rc;
    if ((rc = need_idle(s, "unhoming", err, len)))
        return rc;
    struct motion_hal_cmd c = { .kind = MOTION_CMD_UNHOME, .axis = joint };
    if (s->state != SESS_ON) {  /* the queue only runs while on: the legs are at rest */
        motion_unhome(s->m, joint);
        return 0;
    }
    return push(s, &c, err, len);
}

int session_jog(struct session *s, int frame, int axis, double vel, double dist, char *err,
                size_t len)
{
    int rc;
    if ((rc = need_on(s, "jog", err, len)))
        return rc;
    if (s->running)
        return fail(RPC_STATE, err, len, "jog refused: %s is running",
                    s->run_is_mdi ? "an MDI line" : "a program");
    if (motion_homing(s->m))
        return fail(RPC_STATE, err, len, "jog refused: the machine is homing");
    if (frame != MOTION_JOG_JOINT && !motion_all_homed(s->m))
        return fail(RPC_STATE, err, len, "%s jog refused: the machine is not homed (home it, "
                    "or jog a leg: frame joint)", frame == MOTION_JOG_TOOL ? "tool" : "world");
    s->mode = SESS_MANUAL;
    struct motion_hal_cmd c = { .kind = MOTION_CMD_JOG, .frame = frame, .axis = axis,
                                .vel = vel, .dist = dist };
    return push(s, &c, err, len);
}

/* Changes one tool's entry and saves the table (atomically, common/atomicfile); the MDI
 * interpreter sees it at once, programs when they are next read. Refused while a program
 * runs: its G10 L1 lines save the same file. */
int session_tooltable_set(struct session *s, const struct session_tool_edit *e, char *err,
                          size_t len)
{
    int rc;
    if ((rc = need_idle(s, "tooltable.set", err, len)))
        return rc;
    if (!s->mdi_tt.path[0])
        return fail(RPC_STATE, err, len, "tooltable.set: this machine has no tool table file "
                    "([EMCIO] TOOL_TABLE)");
    struct tooltable *tt = malloc(sizeof *tt);
    if (!tt)
        return fail(RPC_FAILED, err, len, "out of memory");
    *tt = s->mdi_tt;
    struct tool_entry ent, *old = tooltable_find(tt, e->tool);
    if (old) {
        ent = *old;
    } else {
        memset(&ent, 0, sizeof ent);
        ent.tool = e->tool;
        ent.pocket = e->tool;
    }
    if (e->pocket >= 0)
        ent.pocket = e->pocket;
    if (e->has_length) {
        ent.z_offset_mm = e->length;
        ent.present |= TOOLTABLE_F_Z;
    }
    if (e->has_diameter)
        ent.diameter_mm = e->diameter;
    if (e->comment)
        snprintf(ent.comment, sizeof ent.comment, "%s", e->comment);
    char msg[600];
    int st = tooltable_set(tt, &ent);
    if (st == TOOLTABLE_OK)
        st = tooltable_save(tt, tt->path, msg, sizeof msg);
    else
        snprintf(msg, sizeof msg, "tool %d: %s", e->tool, tooltable_strerror(st));
    if (st == TOOLTABLE_OK)
        s->mdi_tt = *tt;  /* the interpreter holds a pointer to mdi_tt: same place */
    free(tt);
    if (st != TOOLTABLE_OK)
        return fail(RPC_FAILED, err, len, "tooltable.set: %s", msg);
    session_message(s, "info", "task", "tool %d changed in %s", e->tool, s->mdi_tt.path);
    return 0;
}

/* The operator has put the tool M6 asked for in the spindle. */
int session_tool_changed(struct session *s, char *err, size_t len)
{
    if (!motion_hal_manual_toolchange_waiting(s->hal))
        return fail(RPC_STATE, err, len, "tool.changed: no manual tool change is waiting");
    struct motion_hal_cmd c = { .kind = MOTION_CMD_TOOL_CHANGED };
    return push(s, &c, err, len);
}

int session_jog_stop(struct session *s, char *err, size_t len)
{
    struct motion_hal_cmd c = { .kind = MOTION_CMD_JOG_STOP };
    if (s->state != SESS_ON)
        return 0;
    return push(s, &c, err, len);
}

/* Starts what runner_load_* loaded. */
static int start_loaded(struct session *s, bool mdi, char *err, size_t len)
{
    char msg[600];
    if (runner_start(s->r, msg, sizeof msg) != RUNNER_OK)
        return fail(RPC_FAILED, err, len, "%s", msg);
    s->running = true;
    s->run_is_mdi = mdi;
    s->stopping = false;
    session_settle(s);
    return 0;
}

int session_mdi(struct session *s, const char *line, char *err, size_t len)
{
    int rc;
    if ((rc = need_on(s, "MDI", err, len)) || (rc = need_idle(s, "MDI", err, len)) ||
        (rc = need_homed(s, "MDI", err, len)))
        return rc;
    if (strchr(line, '\n'))
        return fail(RPC_PARAMS, err, len, "line: one line of G-code, without a newline");
    struct canon_prog prog;
    canon_prog_init(&prog);
    double pose[KINS_POSE_DIM];
    motion_hal_pose(s->hal, pose);
    interp_set_start(s->mdi, pose);
    memcpy(prog.start, pose, sizeof pose);
    if (interp_run_text(s->mdi, "MDI", line, strlen(line), canon_prog_sink, &prog) !=
        INTERP_OK) {
        char msg[600];
        interp_error_format(interp_last_error(s->mdi), msg, sizeof msg);
        canon_prog_free(&prog);
        return fail(RPC_PROGRAM, err, len, "%s", msg);
    }
    struct interp_view v;
    interp_get_view(s->mdi, &v);
    if (v.comp5_active) {
        canon_prog_free(&prog);
        /* the interpreter keeps the open run: drop it with a fresh interpreter state */
        return fail(RPC_PROGRAM, err, len, "MDI:1: a G141/G142 run cannot span MDI lines: "
                    "give the whole run, to its G140, in one line (or run it from a "
                    "program)");
    }
    s->mode = SESS_MDI;
    char msg[600];
    int st = runner_load_canon(s->r, &prog, msg, sizeof msg);
    canon_prog_free(&prog);
    if (st != RUNNER_OK)
        return fail(RPC_PROGRAM, err, len, "%s", msg);
    if ((rc = start_loaded(s, true, err, len)))
        return rc;
    struct motion_plan_info pi;
    runner_plan_info(s->r, &pi);
    if (pi.segments == 0) {
        /* nothing moves (G90, G10, M-codes without motion): done when the answer goes out,
         * so that the next line is not refused */
        for (int i = 0; i < SESSION_POWER_PERIODS && s->running; i++) {
            session_wait_periods(s, 1);
            session_tick(s);
        }
    }
    return 0;
}

/* A program path from the API: relative ones from [DISPLAY] PROGRAM_PREFIX or the INI's
 * folder. */
static void resolve_program(struct session *s, const char *path, char *out, size_t len)
{
    const char *prefix = hal_ini_get(s->hal, "DISPLAY", "PROGRAM_PREFIX");
    const char *dir = hal_ini_dir(s->hal);
    if (path[0] == '/')
        snprintf(out, len, "%s", path);
    else if (prefix && prefix[0] == '/')
        snprintf(out, len, "%s/%s", prefix, path);
    else if (prefix && prefix[0])
        snprintf(out, len, "%s/%s/%s", dir ? dir : ".", prefix, path);
    else
        snprintf(out, len, "%s/%s", dir && dir[0] ? dir : ".", path);
}

int session_open(struct session *s, const char *path, char *err, size_t len)
{
    if (s->running)
        return fail(RPC_STATE, err, len, "program.open refused: a program is running");
    char full[1024];
    resolve_program(s, path, full, sizeof full);
    struct stat st;
    if (stat(full, &st) != 0)
        return fail(RPC_NOT_FOUND, err, len, "%s: %s", full, strerror(errno));
    if (!S_ISREG(st.st_mode))
        return fail(RPC_NOT_FOUND, err, len, "%s: not a regular file", full);
    FILE *f = fopen(full, "r");
    if (!f)
        return fail(RPC_NOT_FOUND, err, len, "%s: %s", full, strerror(errno));
    long lines = 0;
    int ch, last = '\n';
    while ((ch = getc(f)) != EOF) {
        if (ch == '\n')
            lines++;
        last = ch;
    }
    if (last != '\n')
        lines++;
    fclose(f);
    snprintf(s->program, sizeof s->program, "%s", full);
    s->program_lines = lines;
    return 0;
}

int session_check(struct session *s, json_t **result, char *err, size_t len)
{
    int rc;
    if (!s->program[0])
        return fail(RPC_STATE, err, len, "program.check: no program is open (program.open)");
    if ((rc = need_idle(s, "program.check", err, len)))
        return rc;
    char msg[800];
    int st = runner_load_program(s->r, s->program, msg, sizeof msg);
    if (st != RUNNER_OK) {
        *result = json_pack("{s:b, s:[{s:i, s:s}]}", "ok", 0, "problems", "line", 0, "text",
                            msg);
        return 0;
    }
    struct motion_plan_info pi;
    runner_plan_info(s->r, &pi);
    *result = json_pack("{s:b, s:[], s:f, s:f, s:I}", "ok", 1, "problems", "time_s",
                        pi.time_s, "length_mm", pi.length_mm, "segments",
                        (json_int_t)pi.segments);
    return 0;
}

int session_run_program(struct session *s, int from_line, char *err, size_t len)
{
    int rc;
    if (!s->program[0])
        return fail(RPC_STATE, err, len, "program.run refused: no program is open "
                    "(program.open)");
    if ((rc = need_on(s, "program.run", err, len)) ||
        (rc = need_idle(s, "program.run", err, len)) ||
        (rc = need_homed(s, "program.run", err, len)))
        return rc;
    s->mode = SESS_AUTO;
    char msg[800];
    /* checked again from where the machine is now, whatever an earlier check said */
    if (runner_load_program_from(s->r, s->program, from_line > 1 ? from_line : 1, msg,
                                 sizeof msg) != RUNNER_OK)
        return fail(RPC_PROGRAM, err, len, "%s", msg);
    if ((rc = start_loaded(s, false, err, len)))
        return rc;
    struct motion_plan_info pi;
    runner_plan_info(s->r, &pi);
    session_message(s, "info", "task", "program started%s: %s (%.3f s, %.3f mm planned)",
                    from_line > 1 ? " from a line" : "", s->program, pi.time_s, pi.length_mm);
    return 0;
}

int session_pause(struct session *s, char *err, size_t len)
{
    if (!s->running)
        return fail(RPC_STATE, err, len, "program.pause: nothing is running");
    struct motion_hal_cmd c = { .kind = MOTION_CMD_PAUSE };
    return push(s, &c, err, len);
}

int session_resume(struct session *s, char *err, size_t len)
{
    if (!s->running)
        return fail(RPC_STATE, err, len, "program.resume: nothing is running");
    struct motion_hal_cmd c = { .kind = MOTION_CMD_RESUME };
    return push(s, &c, err, len);
}

int session_step(struct session *s, char *err, size_t len)
{
    int rc;
    if (!s->running && (rc = session_run_program(s, 1, err, len)))
        return rc;
    struct motion_hal_cmd c = { .kind = MOTION_CMD_STEP };
    return push(s, &c, err, len);
}

int session_abort(struct session *s, char *err, size_t len)
{
    if (!s->running) {
        struct motion_hal_cmd c = { .kind = MOTION_CMD_JOG_STOP };
        return s->state == SESS_ON ? push(s, &c, err, len) : 0;
    }
    s->stopping = true;
    runner_abort(s->r);
    session_settle(s);  /* the tick must not take "at rest" before motion saw the abort */
    return 0;
}

int session_overrides(struct session *s, const double *feed, const double *rapid,
                      const double *spindle, char *err, size_t len)
{
    if ((feed && !(*feed >= 0 && *feed <= 2)) || (rapid && !(*rapid >= 0 && *rapid <= 1)) ||
        (spindle && !(*spindle >= 0 && *spindle <= 2)))
        return fail(RPC_PARAMS, err, len, "override out of range: feed 0..2, rapid 0..1, "
                    "spindle 0..2");
    if (feed) {
        s->feed_ovr = *feed;
        if (s->feed_ovr_pin)
            *s->feed_ovr_pin = *feed;
    }
    if (rapid) {
        s->rapid_ovr = *rapid;
        struct motion_hal_cmd c = { .kind = MOTION_CMD_RAPID, .vel = *rapid };
        if (s->state == SESS_ON) {
            int rc = push(s, &c, err, len);
            if (rc)
                return rc;
        } else {
            motion_set_rapid_override(s->m, *rapid);
        }
    }
    if (spindle) {
        s->spindle_ovr = *spindle;
        if (s->spindle_ovr_pin)
            *s->spindle_ovr_pin = *spindle;
        if (s->state == SESS_ON)
            session_wait_periods(s, 1);  /* in effect when the answer goes out */
    }
    return 0;
}

/* Components' messages (drive faults, warnings) to the subscribers. */
static void drain_hal_messages(struct session *s)
{
    static const char *const sev[] = {
        [HAL_MSG_INFO] = "info", [HAL_MSG_WARNING] = "warning", [HAL_MSG_FAULT] = "error",
    };
    struct hal_msg m;
    while (hal_msg_take(s->hal, &m)) {
        if (m.severity == HAL_MSG_FAULT && !s->r->first_fault[0])
            snprintf(s->r->first_fault, sizeof s->r->first_fault, "%s: %s", m.source, m.text);
        session_message(s, sev[m.severity], m.source, "%s", m.text);
    }
}

/* After a program: the MDI interpreter starts afresh from the INI and the saved parameters,
 * so that offsets the program set (G10, saved in the parameter file) are the ones MDI and the
 * status show, and its modal state is the default one, as after LinuxCNC's M2. The tool in
 * the spindle is the one the machine has. */
static void mdi_renew(struct session *s)
{
    struct motion_out o;
    motion_hal_out(s->hal, &o);
    struct interp *in = interp_create();
    struct tooltable *tt = malloc(sizeof *tt);
    char err[1024];
    if (!in || !tt) {
        session_message(s, "error", "task", "out of memory renewing the MDI state");
    } else {
        tooltable_init(tt);
        if (runner_setup_interp(s->r, in, tt, err, sizeof err) != RUNNER_OK) {
            session_message(s, "error", "task", "the MDI state keeps what it had: %s", err);
        } else {
            s->mdi_tt = *tt;
            interp_set_tooltable(in, &s->mdi_tt);
            interp_set_mdi(in, 1);
            interp_set_current_tool(in, o.tool.number);  /* the tool the machine has */
            interp_destroy(s->mdi);
            s->mdi = in;
            in = NULL;
        }
    }
    interp_destroy(in);
    free(tt);
}

/* The end of a program or MDI line: finished, stopped by the operator, or faulted. */
static void run_outcome(struct session *s, enum motion_state st)
{
    int line = atomic_load(&s->r->mon_line);
    s->running = false;
    runner_settings_apply(s->r);
    const char *what = s->run_is_mdi ? "MDI line" : "program";
    if (s->r->save_err[0])
        session_message(s, "error", "task", "%s", s->r->save_err);
    if (st == MOTION_FAULT)
        session_message(s, "error", "motion", "%s stopped on a fault: %s%s%s%s", what,
                        motion_hal_fault(s->hal), s->r->first_fault[0] ? " (cause: " : "",
                        s->r->first_fault, s->r->first_fault[0] ? ")" : "");
    else if (s->stopping)
        session_message(s, "warning", "task", "%s stopped by the operator at line %d: the "
                        "machine came to rest on the path", what, line);
    else if (!s->run_is_mdi)
        session_message(s, "info", "task", "program finished");
    s->stopping = false;
    if (!s->run_is_mdi)
        mdi_renew(s);
}

void session_tick(struct session *s)
{
    drain_hal_messages(s);
    enum motion_state st = mstate(s);
    if (s->state == SESS_ON && !*s->r->emc_enable_in) {
        s->state = SESS_ESTOP;
        run_cut(s, "the e-stop chain opened");
        session_message(s, "error", "task", "the e-stop chain opened: the machine is in "
                        "e-stop%s%s", s->r->first_fault[0] ? "; cause: " : "",
                        s->r->first_fault);
    }
    if (s->running) {
        runner_settings_apply(s->r);
        if (st == MOTION_DONE || st == MOTION_FAULT || (st == MOTION_IDLE && s->stopping))
            run_outcome(s, st);
    } else if (st == MOTION_FAULT && s->last_mstate != MOTION_FAULT &&
               s->state == SESS_ON) {
        session_message(s, "error", "motion", "%s", motion_hal_fault(s->hal));
    }
    unsigned seq;
    const char *note = motion_manual_note(s->m, &seq);
    if (seq != s->note_seq) {
        s->note_seq = seq;
        bool bad = strstr(note, "failed") || strstr(note, "stopped");
        session_message(s, bad ? "warning" : "info", "motion", "%s", note);
    }
    s->last_mstate = st;
}

/* [API] SOCKET, else $XDG_RUNTIME_DIR/hexcnc.sock, else /tmp/hexcnc-UID/hexcnc.sock. */
static int default_socket(struct session *s, char *out, size_t len, char *err, size_t errlen)
{
    const char *ini = hal_ini_get(s->hal, "API", "SOCKET");
    const char *xdg = getenv("XDG_RUNTIME_DIR");
    if (ini && ini[0]) {
        const char *dir = hal_ini_dir(s->hal);
        if (ini[0] == '/' || !dir || !dir[0])
            snprintf(out, len, "%s", ini);
        else
            snprintf(out, len, "%s/%s", dir, ini);
    } else if (xdg && xdg[0]) {
        snprintf(out, len, "%s/hexcnc.sock", xdg);
    } else {
        char dir[64];
        snprintf(dir, sizeof dir, "/tmp/hexcnc-%u", (unsigned)getuid());
        if (mkdir(dir, 0700) != 0 && errno != EEXIST)
            return fail(1, err, errlen, "%s: %s", dir, strerror(errno));
        struct stat st;
        if (lstat(dir, &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != getuid())
            return fail(1, err, errlen, "%s: not a folder of this user; set [API] SOCKET "
                        "or XDG_RUNTIME_DIR", dir);
        snprintf(out, len, "%s/hexcnc.sock", dir);
    }
    return 0;
}

int session_create(const struct session_opts *opts, struct session **out, char *err,
                   size_t errlen)
{
    *out = NULL;
    struct session *s = calloc(1, sizeof *s);
    if (!s)
        return fail(1, err, errlen, "out of memory");
    s->lfd = -1;
    s->quiet = opts->quiet;
    s->feed_ovr = s->rapid_ovr = s->spindle_ovr = 1;
    s->optional_stop = true;
    struct runner_opts ro = { opts->ini_path, opts->clock };
    if (runner_create(&ro, &s->r, err, errlen) != RUNNER_OK) {
        free(s);
        return 1;
    }
    s->hal = runner_hal(s->r);
    s->m = runner_motion(s->r);
    s->k = runner_kins(s->r);
    s->nj = s->k->njoints;
    s->sim = runner_sim_clock(s->r);
    s->period_ns = s->r->period_ns;
    long nfh = 0;
    if (hal_ini_int(s->hal, "TRAJ", "NO_FORCE_HOMING", 0, &nfh) == HAL_ERR_SYNTAX) {
        fail(1, err, errlen, "%s", hal_last_error(s->hal));
        goto fail;
    }
    s->no_force_homing = nfh != 0;
    enum hal_type t;
    s->feed_ovr_pin = hal_data_ptr(s->hal, "motion.feed-override", &t);
    if (s->feed_ovr_pin && t != HAL_FLOAT)
        s->feed_ovr_pin = NULL;
    s->spindle_ovr_pin = hal_data_ptr(s->hal, "spindle.0.override", &t);
    if (s->spindle_ovr_pin && t != HAL_FLOAT)
        s->spindle_ovr_pin = NULL;
    motion_hal_set_autostart(s->hal, false);  /* only program.run starts a program */
    /* no tool changer wired: M6 waits for the operator's tool.changed */
    motion_hal_set_manual_toolchange(s->hal, true);
    s->mdi = interp_create();
    tooltable_init(&s->mdi_tt);
    if (!s->mdi || runner_setup_interp(s->r, s->mdi, &s->mdi_tt, err, errlen) != RUNNER_OK)
        goto fail;
    interp_set_mdi(s->mdi, 1);
    char path[512];
    if (opts->socket_path)
        snprintf(path, sizeof path, "%s", opts->socket_path);
    else if (default_socket(s, path, sizeof path, err, errlen))
        goto fail;
    if (session_server_open(s, path, err, errlen))
        goto fail;
    s->state = SESS_ESTOP;
    *s->r->user_enable_out = false;
    if (hal_start(s->hal) != HAL_OK) {  /* on the simulated clock: ready to advance */
        fail(1, err, errlen, "%s", hal_last_error(s->hal));
        goto fail;
    }
    /* motion takes the legs' feedback as its command once the drives have run a few periods
     * (MOTION_FEEDBACK_SETTLE): the machine must not be switched on before */
    session_wait_periods(s, 8);
    s->last_mstate = mstate(s);
    motion_manual_note(s->m, &s->note_seq);
    *out = s;
    return 0;
fail:
    session_destroy(s);
    return 1;
}

void session_destroy(struct session *s)
{
    if (!s)
        return;
    session_server_close(s);
    runner_destroy(s->r);
    interp_destroy(s->mdi);
    free(s);
}

const char *session_socket_path(const struct session *s)
{
    return s->sock_path;
}

/* Wall-clock seconds. */
static double wall_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* The loop: serve the socket, advance the machine, tick, send status. */
int session_run(struct session *s, const volatile sig_atomic_t *stop)
{
    double last = wall_s();
    while (!s->shutdown && !(stop && *stop)) {
        bool busy = session_busy(s);
        session_server_poll(s, busy && s->sim ? 0 : 10);
        if (s->sim) {
            /* flat out while anything moves; at rest, as fast as the wall clock */
            double now = wall_s();
            long ns = busy ? 10 * s->period_ns
                           : (long)fmin((now - last) * 1e9, 20e6);
            ns -= ns % s->period_ns;
            if (ns > 0)
                hal_sim_advance(s->hal, ns);
            last = now;
        }
        session_tick(s);
        session_server_status(s);
    }
    if (s->running && s->state == SESS_ON) {
        /* a controlled stop before the session ends */
        runner_abort(s->r);
        for (int i = 0; i < 100000 && motion_get_state(s->m) != MOTION_IDLE &&
                        motion_get_state(s->m) != MOTION_FAULT; i++)
            session_wait_periods(s, 1);
    }
    *s->r->user_enable_out = false;
    session_wait_periods(s, 2);
    hal_stop(s->hal);
    return 0;
}
