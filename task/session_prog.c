/* session_prog.c: the session's MDI and program commands: MDI lines, open, check, run (from
 * a line), pause, resume, step, abort. */
#include "task/session_priv.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "common/errbuf.h"
#include "interp/interp.h"
#include "motion/motion_hal.h"

/* Starts what runner_load_* loaded. */
static int start_loaded(struct session *s, bool mdi, char *err, size_t len)
{
    char msg[600];
    if (runner_start(s->r, msg, sizeof msg) != RUNNER_OK)
        return errbuf_set(err, len, RPC_FAILED, "%s", msg);
    s->running = true;
    s->run_is_mdi = mdi;
    s->stopping = false;
    session_settle(s);
    return 0;
}

int session_mdi(struct session *s, const char *line, char *err, size_t len)
{
    int rc;
    if ((rc = session_need_on(s, "MDI", err, len)) || (rc = session_need_idle(s, "MDI", err, len)) ||
        (rc = session_need_homed(s, "MDI", err, len)))
        return rc;
    if (strchr(line, '\n'))
        return errbuf_set(err, len, RPC_PARAMS, "line: one line of G-code, without a newline");
    struct canon_prog prog;
    canon_prog_init(&prog);
    double pose[KINS_POSE_DIM];
    motion_hal_pose(s->hal, pose);
    interp_set_start(s->mdi, pose);
    memcpy(prog.start, pose, sizeof pose);
    struct interp_view v0;           /* the line starts in the path mode MDI left */
    interp_get_view(s->mdi, &v0);
    prog.start_path_mode = v0.path_mode == 640 ? 640 : 610;
    prog.start_path_tol_mm = v0.path_tol_mm;
    if (interp_run_text(s->mdi, "MDI", line, strlen(line), canon_prog_sink, &prog) !=
        INTERP_OK) {
        char msg[600];
        interp_error_format(interp_last_error(s->mdi), msg, sizeof msg);
        canon_prog_free(&prog);
        return errbuf_set(err, len, RPC_PROGRAM, "%s", msg);
    }
    struct interp_view v;
    interp_get_view(s->mdi, &v);
    if (v.comp5_active) {
        canon_prog_free(&prog);
        /* the interpreter keeps the open run: drop it with a fresh interpreter state */
        return errbuf_set(err, len, RPC_PROGRAM, "MDI:1: a G141/G142 run cannot span MDI lines: "
                    "give the whole run, to its G140, in one line (or run it from a "
                    "program)");
    }
    s->mode = SESS_MDI;
    s->mdi_probe = -1;
    for (size_t i = 0; i < prog.count; i++)   /* the machine runs the whole probe move: it */
        if (prog.cmds[i].type == CANON_PROBE) {   /* stops where the probe trips */
            memcpy(prog.cmds[i].probe_stop, prog.cmds[i].end, sizeof prog.cmds[i].end);
            s->mdi_probe = prog.cmds[i].ivalue;
        }
    char msg[600];
    int st = runner_load_canon(s->r, &prog, msg, sizeof msg);
    canon_prog_free(&prog);
    if (st != RUNNER_OK)
        return errbuf_set(err, len, RPC_PROGRAM, "%s", msg);
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

void session_mdi_probe_done(struct session *s)
{
    int type = s->mdi_probe;
    struct motion_probe_result r;
    s->mdi_probe = -1;
    if (type < 0 || motion_probe_result(s->m, &r) == 0)
        return;                  /* no probe, or stopped before the move ended */
    static const char *const names[] = { "G38.2", "G38.3", "G38.4", "G38.5" };
    if (r.already) {
        session_message(s, "error", "task", "MDI:1: %s: the probe is already %s where the "
                        "move starts (motion.probe-input is %s)", names[type], type & 2 ?
                        "clear of the workpiece" : "tripped", type & 2 ? "false" : "true");
        return;
    }
    if (!r.tripped && !(type & 1))
        session_message(s, "error", "task", "MDI:1: %s: the move ended without the probe %s",
                        names[type], type & 2 ? "losing contact" : "touching anything");
    struct interp_view v;        /* #5061..#5066 in the coordinates the line ran in */
    interp_get_view(s->mdi, &v);
    for (int i = 0; i < KINS_POSE_DIM; i++) {
        double p = r.trip[i] - v.g5x_mm[i] - v.g92_mm[i] - v.tool_mm[i];
        interp_set_param(s->mdi, 5061 + i, i < 3 && v.inch ? p / 25.4 : p);
    }
    interp_set_param(s->mdi, 5070, r.tripped);
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
        return errbuf_set(err, len, RPC_STATE, "program.open refused: a program is running");
    if (s->checking)
        return errbuf_set(err, len, RPC_STATE, "program.open refused: program.check is under "
                          "way");
    char full[1024];
    resolve_program(s, path, full, sizeof full);
    struct stat st;
    if (stat(full, &st) != 0)
        return errbuf_set(err, len, RPC_NOT_FOUND, "%s: %s", full, strerror(errno));
    if (!S_ISREG(st.st_mode))
        return errbuf_set(err, len, RPC_NOT_FOUND, "%s: not a regular file", full);
    FILE *f = fopen(full, "r");
    if (!f)
        return errbuf_set(err, len, RPC_NOT_FOUND, "%s: %s", full, strerror(errno));
    long lines = 0;
    char buf[1 << 16], last = '\n';
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0) {
        for (const char *p = buf; (p = memchr(p, '\n', (size_t)(buf + n - p))); p++)
            lines++;
        last = buf[n - 1];
    }
    if (last != '\n')
        lines++;
    fclose(f);
    snprintf(s->program, sizeof s->program, "%s", full);
    s->program_lines = lines;
    return 0;
}

/* The line an error message names ("file:LINE:..."), 0 when none. */
static int session_error_line(const char *msg)
{
    for (const char *p = strchr(msg, ':'); p; p = strchr(p + 1, ':')) {
        char *end;
        long n = strtol(p + 1, &end, 10);
        if (end > p + 1 && *end == ':' && n > 0 && n < 1000000000L)
            return (int)n;
    }
    return 0;
}

static void *check_main(void *arg)
{
    struct session *s = arg;
    s->check_status = runner_check_stream(s->r, s->program, &s->check_info, s->check_err,
                                          sizeof s->check_err);
    atomic_store(&s->check_done, 1);
    return NULL;
}

/* program.check: the verification pass streams over the whole file in bounded memory, on
 * its own thread; the session goes on serving (status, e-stop) meanwhile and answers the
 * caller when it ends. A run of the same file from the same place then starts at once. */
/* Starts the verification pass on its own thread (the answer comes later). */
static int check_start(struct session *s, char *err, size_t len)
{
    atomic_store(&s->check_done, 0);
    s->check_cancel = 0;
    runner_set_cancel(s->r, &s->check_cancel);
    if (pthread_create(&s->check_thread, NULL, check_main, s) != 0)
        return errbuf_set(err, len, RPC_FAILED, "program.check: cannot start its thread");
    s->checking = true;
    return RPC_DEFERRED;
}

int session_check(struct session *s, json_t **result, char *err, size_t len)
{
    int rc;
    (void)result;
    if (!s->program[0])
        return errbuf_set(err, len, RPC_STATE, "program.check: no program is open (program.open)");
    if ((rc = session_need_idle(s, "program.check", err, len)))
        return rc;
    s->check_then_run = s->check_then_step = false;
    return check_start(s, err, len);
}

void session_check_poll(struct session *s, bool wait)
{
    if (!s->checking || (!wait && !atomic_load(&s->check_done)))
        return;
    pthread_join(s->check_thread, NULL);
    s->checking = false;
    runner_set_cancel(s->r, NULL);
    json_t *result = NULL;
    int code = 0;
    char err[800];
    if (s->check_then_run) {
        /* program.run that needed a check first: now it runs, or says why not */
        bool step = s->check_then_step;
        s->check_then_step = false;
        if (s->check_status != RUNNER_OK)
            code = errbuf_set(err, sizeof err, RPC_PROGRAM, "%s", s->check_err);
        else
            code = session_run_program(s, s->check_from_line, err, sizeof err);
        if (code == RPC_DEFERRED) {   /* the machine moved meanwhile: checked again */
            s->check_then_step = step;
            return;
        }
        if (!code && step) {
            struct motion_hal_cmd sc = { .kind = MOTION_CMD_STEP };
            code = session_push(s, &sc, err, sizeof err);
        }
        if (!code)
            result = json_object();
    } else if (s->check_status != RUNNER_OK) {
        result = json_pack("{s:b, s:[{s:i, s:s}]}", "ok", 0, "problems", "line",
                           session_error_line(s->check_err), "text", s->check_err);
    } else {
        result = json_pack("{s:b, s:[], s:f, s:f, s:I, s:I}", "ok", 1, "problems", "time_s",
                           s->check_info.time_s, "length_mm", s->check_info.length_mm,
                           "segments", (json_int_t)s->check_info.segments,
                           "merged", (json_int_t)s->check_info.merged);
    }
    for (int i = 0; i < SESSION_MAX_CLIENTS && s->check_id; i++) {
        struct session_client *c = s->cl[i];
        if (c && c->id == s->check_client) {
            json_t *resp = code ? json_pack("{s:s, s:O, s:{s:i, s:s}}", "jsonrpc", "2.0",
                                            "id", s->check_id, "error", "code", code,
                                            "message", err)
                                : json_pack("{s:s, s:O, s:O}", "jsonrpc", "2.0", "id",
                                            s->check_id, "result", result);
            session_server_send(s, c, resp);
            json_decref(resp);
        }
    }
    json_decref(result);
    json_decref(s->check_id);
    s->check_id = NULL;
}

int session_run_program(struct session *s, int from_line, char *err, size_t len)
{
    int rc;
    if (!s->program[0])
        return errbuf_set(err, len, RPC_STATE, "program.run refused: no program is open "
                    "(program.open)");
    if ((rc = session_need_on(s, "program.run", err, len)) ||
        (rc = session_need_idle(s, "program.run", err, len)) ||
        (rc = session_need_homed(s, "program.run", err, len)))
        return rc;
    if (!runner_stream_checked(s->r, s->program)) {
        /* the verification pass first, on its own thread: the answer (and the run) come
         * when it passes; the session serves everyone meanwhile */
        s->check_then_run = true;
        s->check_then_step = false;
        s->check_from_line = from_line;
        return check_start(s, err, len);
    }
    s->mode = SESS_AUTO;
    char msg[800];
    /* streamed: checked first unless the last check was of this file, unchanged, with the
     * same tools and offsets, from where the machine is now; motion starts once the first
     * part is planned */
    if (runner_stream_start(s->r, s->program, from_line > 1 ? from_line : 1, msg,
                            sizeof msg) != RUNNER_OK)
        return errbuf_set(err, len, RPC_PROGRAM, "%s", msg);
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
        return errbuf_set(err, len, RPC_STATE, "program.pause: nothing is running");
    struct motion_hal_cmd c = { .kind = MOTION_CMD_PAUSE };
    return session_push(s, &c, err, len);
}

int session_resume(struct session *s, char *err, size_t len)
{
    if (!s->running)
        return errbuf_set(err, len, RPC_STATE, "program.resume: nothing is running");
    struct motion_hal_cmd c = { .kind = MOTION_CMD_RESUME };
    return session_push(s, &c, err, len);
}

int session_step(struct session *s, char *err, size_t len)
{
    int rc;
    if (!s->running && (rc = session_run_program(s, 1, err, len))) {
        if (rc == RPC_DEFERRED)
            s->check_then_step = true;  /* one block once the check has passed */
        return rc;
    }
    struct motion_hal_cmd c = { .kind = MOTION_CMD_STEP };
    return session_push(s, &c, err, len);
}

int session_abort(struct session *s, char *err, size_t len)
{
    if (s->checking)
        s->check_cancel = 1;     /* the check stops at its next line and says so */
    if (!s->running) {
        struct motion_hal_cmd c = { .kind = MOTION_CMD_JOG_STOP };
        return s->state == SESS_ON ? session_push(s, &c, err, len) : 0;
    }
    s->stopping = true;
    runner_abort(s->r);
    session_settle(s);  /* the tick must not take "at rest" before motion saw the abort */
    return 0;
}
