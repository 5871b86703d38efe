/* runner.c: sets a machine up from its INI and HAL files, and interprets and plans a program. */
#include "task/runner_priv.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/errbuf.h"
#include "common/inifile.h"
#include "interp/interp.h"
#include "interp/interp_setup.h"
#include "interp/tooltable.h"
#include "motion/motion_hal.h"

static const char *const runner_msgs[RUNNER_STATUS_COUNT] = {
    [RUNNER_OK] = "ok",
    [RUNNER_ERR_NOMEM] = "out of memory",
    [RUNNER_ERR_CONFIG] = "the machine configuration (INI file) is wrong",
    [RUNNER_ERR_HAL] = "a HAL file failed",
    [RUNNER_ERR_PROGRAM] = "the program has an error",
    [RUNNER_ERR_PLAN] = "the program cannot run on this machine",
    [RUNNER_ERR_STATE] = "not possible in the machine's present state",
    [RUNNER_ERR_RT] = "the servo thread could not be started",
    [RUNNER_ERR_FAULT] = "the machine stopped on a fault",
    [RUNNER_ERR_ABORTED] = "the program was stopped by the operator",
    [RUNNER_ERR_TIMEOUT] = "the machine did not finish the program in time",
};

/* The text of a status. */
const char *runner_strerror(int status)
{
    if (status < 0 || status >= RUNNER_STATUS_COUNT)
        return "unknown runner status";
    return runner_msgs[status];
}

/* A path from the INI, made relative to the INI's folder unless absolute. */
void runner_ini_path(const struct runner *r, const char *value, char *out, size_t len)
{
    inifile_resolve(hal_ini_dir(r->hal), value, out, len);
}

/* Clock choice and servo period from the options and [EMCMOT]. */
static int runner_read_timing(struct runner *r, const struct runner_opts *opts, char *err,
                              size_t errlen)
{
    long sim = 0, period = 1000000;
    if (hal_ini_int(r->hal, "EMCMOT", "SIM_CLOCK", 0, &sim) == HAL_ERR_SYNTAX ||
        hal_ini_int(r->hal, "EMCMOT", "SERVO_PERIOD", 1000000, &period) == HAL_ERR_SYNTAX)
        return errbuf_set(err, errlen, RUNNER_ERR_CONFIG, "%s", hal_last_error(r->hal));
    if (period <= 0)
        return errbuf_set(err, errlen, RUNNER_ERR_CONFIG,
                           "%s: [EMCMOT] SERVO_PERIOD must be a positive number of ns",
                           opts->ini_path);
    r->period_ns = period;
    r->sim_clock = opts->clock == RUNNER_CLOCK_SIM ||
                   (opts->clock == RUNNER_CLOCK_INI && sim == 1);
    hal_set_sim_clock(r->hal, r->sim_clock);
    return RUNNER_OK;
}

/* The task's pins, created before the HAL files so that they can wire the e-stop chain. */
static int runner_task_pins(struct runner *r, char *err, size_t errlen)
{
    struct hal *h = r->hal;
    if (hal_pin_bit_newf(h, HAL_OUT, &r->user_enable_out, "task.user-enable-out") ||
        hal_pin_bit_newf(h, HAL_OUT, &r->user_request_enable, "task.user-request-enable") ||
        hal_pin_bit_newf(h, HAL_IN, &r->emc_enable_in, "task.emc-enable-in"))
        return errbuf_set(err, errlen, RUNNER_ERR_HAL, "%s", hal_last_error(h));
    return RUNNER_OK;
}

/* Runs every [HAL] HALFILE in order, then every [TASK] HALFILE (the wiring of the task.*
 * pins, which only hexcnc run has); the first error names its file and line. */
static int runner_load_halfiles(struct runner *r, const char *ini_path, char *err,
                                size_t errlen)
{
    if (!hal_ini_get_n(r->hal, "HAL", "HALFILE", 0))
        return errbuf_set(err, errlen, RUNNER_ERR_CONFIG,
                           "%s: no [HAL] HALFILE: the machine has no HAL wiring", ini_path);
    static const char *const sections[] = { "HAL", "TASK" };
    for (int sec = 0; sec < 2; sec++) {
        const char *name;
        for (int n = 0; (name = hal_ini_get_n(r->hal, sections[sec], "HALFILE", n)); n++) {
            char path[1024];
            runner_ini_path(r, name, path, sizeof path);
            if (hal_source(r->hal, path) != HAL_OK)
                return errbuf_set(err, errlen, RUNNER_ERR_HAL, "%s", hal_last_error(r->hal));
        }
    }
    return RUNNER_OK;
}

/* Finds the kinematics, motion and the leg pins the HAL files created. */
static int runner_bind(struct runner *r, const char *ini_path, char *err, size_t errlen)
{
    r->kins = hal_get_object(r->hal, "kins");
    r->motion = motion_hal_get(r->hal);
    if (!r->kins || !r->motion)
        return errbuf_set(err, errlen, RUNNER_ERR_CONFIG, "%s: the HAL files load no %s "
                           "(they need `loadrt [KINS]KINEMATICS` and `loadrt motion`)",
                           ini_path, r->kins ? "motion" : "kinematics");
    r->njoints = r->kins->njoints;
    for (int i = 0; i < r->njoints; i++) {
        char name[64];
        enum hal_type t;
        snprintf(name, sizeof name, "motion.joint-pos-cmd-%d", i);
        r->cmd_pin[i] = hal_data_ptr(r->hal, name, &t);
        if (!r->cmd_pin[i] || t != HAL_FLOAT)
            return errbuf_set(err, errlen, RUNNER_ERR_HAL, "no float pin %s", name);
        snprintf(name, sizeof name, "motion.joint-pos-fb-%d", i);
        r->fb_pin[i] = hal_data_ptr(r->hal, name, &t);
        if (!r->fb_pin[i] || t != HAL_FLOAT)
            return errbuf_set(err, errlen, RUNNER_ERR_HAL, "no float pin %s", name);
    }
    const char *open = hal_ini_get(r->hal, "DISPLAY", "OPEN_FILE");
    if (open && open[0])
        runner_ini_path(r, open, r->default_program, sizeof r->default_program);
    return RUNNER_OK;
}

/* INI, HAL runtime, task pins, HAL files, monitor; unwinds through one error path. */
int runner_create(const struct runner_opts *opts, struct runner **out, char *err,
                  size_t errlen)
{
    *out = NULL;
    struct runner *r = calloc(1, sizeof *r);
    if (!r || !(r->hal = hal_create())) {
        free(r);
        return errbuf_set(err, errlen, RUNNER_ERR_NOMEM, "out of memory");
    }
    pthread_mutex_init(&r->settings_lock, NULL);
    int st;
    if (hal_load_machine_ini(r->hal, opts->ini_path) != HAL_OK) {
        st = errbuf_set(err, errlen, RUNNER_ERR_CONFIG, "%s", hal_last_error(r->hal));
        goto fail;
    }
    if ((st = runner_read_timing(r, opts, err, errlen)) ||
        (st = runner_task_pins(r, err, errlen)) ||
        (st = runner_load_halfiles(r, opts->ini_path, err, errlen)) ||
        (st = runner_bind(r, opts->ini_path, err, errlen)) ||
        (st = runner_monitor_install(r, err, errlen)))
        goto fail;
    *out = r;
    return RUNNER_OK;
fail:
    runner_destroy(r);
    return st;
}

/* Stops the threads, frees the runtime (and with it motion and kins), the interpreter. */
void runner_destroy(struct runner *r)
{
    if (!r)
        return;
    runner_stream_close(r);  /* the planner thread first: it feeds motion */
    hal_destroy(r->hal);  /* stops the threads first */
    interp_destroy(r->interp);
    runner_settings_free(r);
    pthread_mutex_destroy(&r->settings_lock);
    free(r);
}

/* Accessors for callers that need the parts (tests, benchmarks). */
struct hal *runner_hal(struct runner *r) { return r->hal; }
struct kins *runner_kins(struct runner *r) { return r->kins; }
struct motion *runner_motion(struct runner *r) { return r->motion; }
bool runner_sim_clock(const struct runner *r) { return r->sim_clock; }

/* [DISPLAY] OPEN_FILE resolved against the INI folder, or NULL. */
const char *runner_default_program(const struct runner *r)
{
    return r->default_program[0] ? r->default_program : NULL;
}

/* #<_hal[name]>: a pin or parameter of the running machine, read as it is now. */
static int runner_hal_value(void *ctx, const char *name, double *v)
{
    enum hal_type t;
    const void *p = hal_data_ptr(ctx, name, &t);
    if (!p)
        return -1;
    switch (t) {
    case HAL_BIT: *v = *(const volatile bool *)p ? 1 : 0; return 0;
    case HAL_FLOAT: *v = *(const volatile double *)p; return 0;
    case HAL_S32: *v = *(const volatile int32_t *)p; return 0;
    case HAL_U32: *v = *(const volatile uint32_t *)p; return 0;
    }
    return -1;
}

/* Applies [RS274NGC] FEED_UNITS, TOOL_TABLE and PARAMETER_FILE (interp_setup: the same code
 * hexcnc check and hexcnc interp use); a bad value is pointed at its INI line. */
int runner_setup_interp(struct runner *r, struct interp *in, struct tooltable *tt, char *err,
                        size_t errlen)
{
    char msg[1024];
    int st = interp_setup(in, tt, hal_ini_lookup, r->hal, hal_ini_dir(r->hal), 0, msg,
                          sizeof msg);
    if (st == INTERP_OK) {
        interp_use_kins(in, r->kins);   /* G43.4 and [KINS] PROGRAM_POINT */
        interp_set_hal_fn(in, runner_hal_value, r->hal);   /* #<_hal[..]> */
        return RUNNER_OK;
    }
    char where[1536];
    return errbuf_set(err, errlen, RUNNER_ERR_CONFIG, "%s", st == INTERP_ERR_CONFIG
                       ? inifile_locate_msg(hal_ini_file(r->hal), msg, where, sizeof where)
                       : msg);
}

void runner_set_cancel(struct runner *r, const volatile sig_atomic_t *flag)
{
    r->cancel = flag;
}

/* Memory the system can give now, bytes (MemAvailable; free pages when unknown). */
static double runner_mem_available(void)
{
    FILE *f = fopen("/proc/meminfo", "r");
    char line[128];
    double kb = -1;
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "MemAvailable: %lf kB", &kb) == 1)
            break;
    if (f)
        fclose(f);
    if (kb >= 0)
        return kb * 1024.0;
    return (double)sysconf(_SC_AVPHYS_PAGES) * (double)sysconf(_SC_PAGESIZE);
}

/* Refuses, before reading it, a program too large to hold in memory: larger than [TASK]
 * MAX_PROGRAM_MB, or needing (RUNNER_BYTES_PER_PROGRAM_BYTE per byte) more memory than the
 * system has available. A missing file is left to the interpreter's message. */
static int runner_check_size(struct runner *r, const char *path, char *err, size_t errlen)
{
    struct stat st;
    long max_mb = RUNNER_MAX_PROGRAM_MB;
    if (hal_ini_int(r->hal, "TASK", "MAX_PROGRAM_MB", RUNNER_MAX_PROGRAM_MB, &max_mb) ==
        HAL_ERR_SYNTAX || max_mb <= 0)
        return errbuf_set(err, errlen, RUNNER_ERR_CONFIG, "[TASK] MAX_PROGRAM_MB must be a "
                          "positive whole number of MB");
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode))
        return RUNNER_OK;
    double mb = (double)st.st_size / 1e6, need_mb = mb * RUNNER_BYTES_PER_PROGRAM_BYTE;
    double avail_mb = runner_mem_available() / 1e6;
    if (mb > (double)max_mb)
        return errbuf_set(err, errlen, RUNNER_ERR_PROGRAM, "%s: the program is %.1f MB "
                          "(%lld bytes), more than [TASK] MAX_PROGRAM_MB = %ld MB: hexcnc holds "
                          "a whole program in memory while it plans it (about %.0f MB for this "
                          "one; %.0f MB available now)", path, mb, (long long)st.st_size, max_mb,
                          need_mb, avail_mb);
    if (avail_mb > 0 && need_mb > avail_mb)
        return errbuf_set(err, errlen, RUNNER_ERR_PROGRAM, "%s: the program is %.1f MB "
                          "(%lld bytes): planning it needs about %.0f MB of memory, only %.0f MB "
                          "are available", path, mb, (long long)st.st_size, need_mb, avail_mb);
    return RUNNER_OK;
}

/* A fresh interpreter for a program from start: the INI's settings, the tool the machine
 * has, the cancel flag and block delete switch. Its tool table tt stays the caller's. */
int runner_new_interp(struct runner *r, const double start[KINS_POSE_DIM], struct interp **out,
                      struct tooltable **tt_out, char *err, size_t errlen)
{
    struct interp *in = interp_create();
    struct tooltable *tt = malloc(sizeof *tt);
    *out = NULL;
    *tt_out = NULL;
    if (!in || !tt) {
        interp_destroy(in);
        free(tt);
        return errbuf_set(err, errlen, RUNNER_ERR_NOMEM, "out of memory");
    }
    tooltable_init(tt);
    interp_set_start(in, start);
    int st = runner_setup_interp(r, in, tt, err, errlen);
    if (st) {
        interp_destroy(in);
        free(tt);
        return st;
    }
    struct motion_out mo;
    if (motion_hal_out(r->hal, &mo) == MOTION_OK)
        interp_set_current_tool(in, mo.tool.number);  /* the tool the machine has */
    interp_set_cancel(in, r->cancel);
    interp_set_block_delete(in, r->block_delete);
    *out = in;
    *tt_out = tt;
    return RUNNER_OK;
}

/* Interprets the whole program into prog, starting from the machine's present pose. */
/* A whole program is planned before the machine moves: it cannot go on from where a probe
 * stops, which only the machine knows. */
static int probe_refused(void *ctx, const struct canon_cmd *c, struct interp_probe_result *r,
                         char *why, size_t whylen)
{
    (void)ctx, (void)c, (void)r;
    snprintf(why, whylen, "`hexcnc run` plans the whole program before the machine moves, so "
             "it cannot go on from where a probe stops: run programs that probe in the "
             "machine session (hexcnc machine)");
    return -1;
}

static int runner_interpret(struct runner *r, const char *path, struct canon_prog *prog,
                            char *err, size_t errlen)
{
    interp_destroy(r->interp);  /* the previous program's plan is being replaced */
    r->interp = NULL;
    struct tooltable *tt;
    double start[KINS_POSE_DIM];
    motion_hal_pose(r->hal, start);
    memcpy(prog->start, start, sizeof start);
    int st = runner_new_interp(r, start, &r->interp, &tt, err, errlen);
    if (st)
        return st;
    interp_set_probe_fn(r->interp, probe_refused, NULL);
    if (interp_run_file(r->interp, path, canon_prog_sink, prog) != INTERP_OK) {
        char msg[600];
        const struct interp_error *e = interp_last_error(r->interp);
        st = errbuf_set(err, errlen, e->status == INTERP_ERR_CANCELLED ? RUNNER_ERR_ABORTED
                        : RUNNER_ERR_PROGRAM, "%s", interp_error_format(e, msg, sizeof msg));
    }
    interp_set_tooltable(r->interp, NULL);  /* the table goes; the interpreter stays */
    free(tt);
    return st;
}

void runner_set_block_delete(struct runner *r, bool on)
{
    r->block_delete = on;
}

/* Settings, then the plan; nothing is handed to motion unless both succeed. */
int runner_load_canon(struct runner *r, const struct canon_prog *prog, char *err,
                      size_t errlen)
{
    if (runner_moving(r))
        return errbuf_set(err, errlen, RUNNER_ERR_STATE, "the machine is still running");
    runner_stream_close(r);
    r->loaded = false;
    int st = runner_settings_load(r, prog, err, errlen);
    if (st == RUNNER_OK) {
        char msg[512];
        motion_set_cancel(r->motion, r->cancel);
        int ms = motion_hal_load(r->hal, prog, msg, sizeof msg);
        motion_set_cancel(r->motion, NULL);
        if (ms != MOTION_OK)
            st = errbuf_set(err, errlen, ms == MOTION_ERR_CANCELLED ? RUNNER_ERR_ABORTED
                            : RUNNER_ERR_PLAN, "%s", msg);
        else if (motion_plan_info(r->motion, &r->plan) != MOTION_OK)
            st = errbuf_set(err, errlen, RUNNER_ERR_PLAN, "%s", motion_hal_fault(r->hal));
    }
    r->loaded = st == RUNNER_OK;
    return st;
}

/* Whether a command is a move or another command that happens on the path. */
void runner_cut_init(struct runner_cut *cut, int from_line, const double start[KINS_POSE_DIM])
{
    memset(cut, 0, sizeof *cut);
    cut->from_line = from_line > 1 ? from_line : 1;
    memcpy(cut->at, start, sizeof cut->at);
}

int runner_cut_step(struct runner_cut *cut, const struct canon_cmd *c, struct canon_cmd *go,
                    char *err, size_t errlen)
{
    if (cut->started)
        return RUNNER_CUT_KEEP;
    if (c->line >= cut->from_line && c->type != CANON_OFFSETS) {
        cut->started = true;
        if (cut->from_line == 1)
            return RUNNER_CUT_KEEP;
        if ((c->type == CANON_FEED || c->type == CANON_ARC) && c->compensated &&
            cut->last_comp)
            return errbuf_set(err, errlen, -1, "%s:%d: the program cannot start inside a "
                              "G141/G142 run: start at the line that begins it", c->file,
                              c->line);
        *go = *c;
        go->type = CANON_TRAVERSE;
        memcpy(go->end, cut->at, sizeof go->end);
        go->compensated = 0;
        go->setting = NULL;
        go->text = NULL;
        return RUNNER_CUT_RAPID_FIRST;
    }
    switch (c->type) {
    case CANON_TRAVERSE:
    case CANON_FEED:
    case CANON_ARC:
        memcpy(cut->at, c->end, sizeof cut->at);
        cut->last_comp = c->compensated;
        return RUNNER_CUT_DROP;
    case CANON_PROBE:    /* skipped: the interpreter reads on with its own answer */
        memcpy(cut->at, c->probe_stop, sizeof cut->at);
        cut->last_comp = 0;
        return RUNNER_CUT_DROP;
    case CANON_DWELL:
    case CANON_PAUSE:
    case CANON_SETTING:
        return RUNNER_CUT_DROP;
    default:
        return RUNNER_CUT_KEEP;
    }
}

/* The program from line from_line on (see runner.h), whole, through runner_cut_step. */
static int runner_cut_before(const struct canon_prog *in, int from_line, struct canon_prog *out,
                             char *err, size_t errlen)
{
    struct runner_cut cut;
    runner_cut_init(&cut, from_line, in->start);
    memcpy(out->start, in->start, sizeof out->start);
    for (size_t i = 0; i < in->count; i++) {
        struct canon_cmd go;
        int act = runner_cut_step(&cut, &in->cmds[i], &go, err, errlen);
        if (act < 0)
            return RUNNER_ERR_PROGRAM;
        if ((act == RUNNER_CUT_RAPID_FIRST && canon_prog_sink(out, &go) != 0) ||
            (act != RUNNER_CUT_DROP && canon_prog_sink(out, &in->cmds[i]) != 0))
            return errbuf_set(err, errlen, RUNNER_ERR_NOMEM, "out of memory");
    }
    if (!cut.started)
        return errbuf_set(err, errlen, RUNNER_ERR_PROGRAM, "the program has no line %d or "
                          "later to start from", from_line);
    return RUNNER_OK;
}

/* Interprets, then plans from line from_line (1: the whole program). */
int runner_load_program_from(struct runner *r, const char *path, int from_line, char *err,
                             size_t errlen)
{
    if (runner_moving(r))
        return errbuf_set(err, errlen, RUNNER_ERR_STATE, "the machine is still running");
    struct canon_prog prog, cut;
    canon_prog_init(&prog);
    canon_prog_init(&cut);
    r->loaded = false;
    int st = runner_check_size(r, path, err, errlen);
    if (st == RUNNER_OK)
        runner_feedback_settle(r);  /* planned from where the legs are */
    if (st == RUNNER_OK)
        st = runner_interpret(r, path, &prog, err, errlen);
    if (st == RUNNER_OK && from_line > 1)
        st = runner_cut_before(&prog, from_line, &cut, err, errlen);
    if (st == RUNNER_OK)
        st = runner_load_canon(r, from_line > 1 ? &cut : &prog, err, errlen);
    canon_prog_free(&prog);
    canon_prog_free(&cut);
    return st;
}

/* Interprets then plans the whole program. */
int runner_load_program(struct runner *r, const char *path, char *err, size_t errlen)
{
    return runner_load_program_from(r, path, 1, err, errlen);
}

/* The plan of the loaded program (time, length, peak leg rates). */
int runner_plan_info(const struct runner *r, struct motion_plan_info *out)
{
    if (!r->loaded)
        return RUNNER_ERR_STATE;
    *out = r->plan;
    return RUNNER_OK;
}
