/* session.c: the machine session's core (LinuxCNC's task, for hexcnc): the state checks and
 * the hand-over to the servo thread the commands share, the end of a run, the tick, and the
 * session's life (create, the loop, destroy). The commands are in session_machine.c and
 * session_prog.c. */
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
#include "common/inifile.h"
#include "interp/interp.h"
#include "motion/motion_hal.h"


static void sleep_ms(double ms)
{
    struct timespec ts = { (time_t)(ms / 1000), (long)(fmod(ms, 1000.0) * 1e6) };
    nanosleep(&ts, NULL);
}

/* Runs the machine for n servo periods (simulated clock) or waits as long (real time). */
void session_wait_periods(struct session *s, int n)
{
    if (s->sim)
        hal_sim_advance(s->hal, (long)n * s->period_ns);
    else
        sleep_ms((double)n * (double)s->period_ns * 1e-6);
}

enum motion_state session_mstate(const struct session *s)
{
    return motion_get_state(s->m);
}

/* Nothing moves: no program, no jog, no homing. */
bool session_at_rest(const struct session *s)
{
    enum motion_state st = session_mstate(s);
    return !s->running && (st == MOTION_IDLE || st == MOTION_DONE || st == MOTION_FAULT);
}

bool session_busy(const struct session *s)
{
    enum motion_state st = session_mstate(s);
    struct motion_out o;
    /* a program held by M66 waits on the world outside: the simulated clock then keeps the
     * wall clock's pace, so that its time-out means what it says to whoever sets the input */
    if (s->running && motion_hal_out(s->hal, &o) == MOTION_OK && o.waiting == 3)
        return false;
    return s->running || st == MOTION_MANUAL || motion_homing(s->m);
}

/* Whether programs and MDI may run: every leg homed, or [TRAJ] NO_FORCE_HOMING. */
int session_need_homed(struct session *s, const char *what, char *err, size_t len)
{
    if (!motion_pose_known(s->m))
        return errbuf_set(err, len, RPC_STATE, "%s refused: the legs' lengths give no pose of the "
                    "platform (the forward kinematics has no answer): jog the legs (frame "
                    "joint) into the workspace, or home them", what);
    if (s->no_force_homing || motion_all_homed(s->m))
        return 0;
    return errbuf_set(err, len, RPC_STATE, "%s refused: the machine is not homed (machine.home "
                "first, or [TRAJ] NO_FORCE_HOMING = 1)", what);
}

int session_need_on(struct session *s, const char *what, char *err, size_t len)
{
    if (s->state == SESS_ON)
        return 0;
    return errbuf_set(err, len, RPC_STATE, "%s refused: the machine is %s (%s)", what,
                s->state == SESS_ESTOP ? "in e-stop" : "off",
                s->state == SESS_ESTOP ? "machine.estop {active: false}, then machine.power "
                "{on: true}" : "machine.power {on: true} first");
}

int session_need_idle(struct session *s, const char *what, char *err, size_t len)
{
    if (s->checking)
        return errbuf_set(err, len, RPC_STATE, "%s refused: program.check is under way (it "
                          "answers when it ends; program.abort stops it)", what);
    if (s->running)
        return errbuf_set(err, len, RPC_STATE, "%s refused: %s is running (program.abort first)",
                    what, s->run_is_mdi ? "an MDI line" : "a program");
    if (!session_at_rest(s))
        return errbuf_set(err, len, RPC_STATE, "%s refused: the machine is %s (jog.stop first)",
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
void session_settle(struct session *s)
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
int session_push(struct session *s, const struct motion_hal_cmd *c, char *err, size_t len)
{
    if (motion_hal_command(s->hal, c) != MOTION_OK)
        return errbuf_set(err, len, RPC_FAILED, "the motion command queue is full; try again");
    session_settle(s);
    return 0;
}

static void mdi_renew(struct session *s);

/* The machine went off under a program or MDI line: the run ends where the legs stopped. */
void session_run_cut(struct session *s, const char *why)
{
    if (!s->running)
        return;
    int line = atomic_load(&s->r->mon_line);
    s->running = false;
    s->stopping = false;
    runner_settings_apply(s->r);
    runner_stream_close(s->r);
    session_message(s, "error", "task", "%s stopped at line %d: %s", s->run_is_mdi ?
                    "MDI line" : "program", line, why);
    if (!s->run_is_mdi)
        mdi_renew(s);
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
    char perr[800];
    bool planner_failed = runner_stream_outcome(s->r, perr, sizeof perr) != RUNNER_OK;
    runner_stream_close(s->r);
    const char *what = s->run_is_mdi ? "MDI line" : "program";
    if (s->r->save_err[0])
        session_message(s, "error", "task", "%s", s->r->save_err);
    if (planner_failed)  /* the file changed under the run, or memory ran out */
        session_message(s, "error", "task", "%s stopped on the path at line %d: reading it on "
                        "failed: %s", what, line, perr);
    else if (st == MOTION_FAULT)
        session_message(s, "error", "motion", "%s stopped on a fault: %s%s%s%s", what,
                        motion_hal_fault(s->hal), s->r->first_fault[0] ? " (cause: " : "",
                        s->r->first_fault, s->r->first_fault[0] ? ")" : "");
    else if (s->stopping)
        session_message(s, "warning", "task", "%s stopped by the operator at line %d: the "
                        "machine came to rest on the path", what, line);
    else if (!s->run_is_mdi)
        session_message(s, "info", "task", "program finished");
    s->stopping = false;
    unsigned waits;
    double answer = motion_input_result(s->m, &waits);
    if (s->run_is_mdi && waits > 0)  /* an MDI line's M66: the next lines read its answer */
        interp_set_param(s->mdi, 5399, answer);
    if (s->run_is_mdi)
        session_mdi_probe_done(s);
    if (!s->run_is_mdi)
        mdi_renew(s);
}

void session_tick(struct session *s)
{
    drain_hal_messages(s);
    session_check_poll(s, false);
    enum motion_state st = session_mstate(s);
    if (s->state == SESS_ON && !*s->r->emc_enable_in) {
        s->state = SESS_ESTOP;
        session_run_cut(s, "the e-stop chain opened");
        session_message(s, "error", "task", "the e-stop chain opened: the machine is in "
                        "e-stop%s%s", s->r->first_fault[0] ? "; cause: " : "",
                        s->r->first_fault);
    }
    if (s->running && !s->stopping && runner_stream_stalled(s->r)) {
        s->stopping = true;      /* at rest where the program stopped on an error (G38.2 */
        runner_abort(s->r);      /* without a trip): end the run there; run_outcome says why */
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
    int where = inifile_api_socket(ini, hal_ini_dir(s->hal), out, len);
    if (where < 0)
        return errbuf_set(err, errlen, 1, "the session's socket path is longer than %zu "
                          "characters: set a shorter [API] SOCKET", len - 1);
    if (where == INIFILE_SOCKET_TMP) {   /* the folder is ours to make, and must be ours */
        char dir[64];
        snprintf(dir, sizeof dir, "/tmp/hexcnc-%u", (unsigned)getuid());
        if (mkdir(dir, 0700) != 0 && errno != EEXIST)
            return errbuf_set(err, errlen, 1, "%s: %s", dir, strerror(errno));
        struct stat st;
        if (lstat(dir, &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != getuid())
            return errbuf_set(err, errlen, 1, "%s: not a folder of this user; set [API] SOCKET "
                        "or XDG_RUNTIME_DIR", dir);
    }
    return 0;
}

int session_create(const struct session_opts *opts, struct session **out, char *err,
                   size_t errlen)
{
    *out = NULL;
    struct session *s = calloc(1, sizeof *s);
    if (!s)
        return errbuf_set(err, errlen, 1, "out of memory");
    s->lfd = -1;
    s->mdi_probe = -1;
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
        errbuf_set(err, errlen, 1, "%s", hal_last_error(s->hal));
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
        errbuf_set(err, errlen, 1, "%s", hal_last_error(s->hal));
        goto fail;
    }
    /* motion takes the legs' feedback as its command once the drives have run a few periods
     * (MOTION_FEEDBACK_SETTLE): the machine must not be switched on before */
    session_wait_periods(s, 8);
    s->last_mstate = session_mstate(s);
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
    s->check_cancel = 1;          /* a check under way stops at its next line */
    session_check_poll(s, true);
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
            if (runner_stream_starving(s->r)) {
                /* the simulated machine outran the planner's thread: wait for it, as a
                 * real machine never has to (the planner is far ahead in real time) */
                struct timespec ts = { 0, 200000 };
                nanosleep(&ts, NULL);
                ns = 0;
            }
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
