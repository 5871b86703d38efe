/* runner_stream.c: programs that stream: the verification pass over the whole file, then
 * the run, each in bounded memory, the run's interpreter and planner on their own thread. */
#include "task/runner_priv.h"

#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "common/errbuf.h"
#include "interp/tooltable.h"
#include "motion/motion_hal.h"

/* Chunks the planner may have ahead of the machine (each about STREAM_WINDOW moves). */
#define RUNNER_STREAM_AHEAD 3

/* What the interpreter's commands go through, in both passes. */
struct stream_sink {
    struct runner *r;
    struct motion_stream *ms;
    struct runner_cut cut;
    struct interp *store;            /* check pass: the settings' files are checked on it */
    bool run;                        /* run pass: settings are kept for runner_settings_apply,
                                      * the planner waits for the machine */
    const _Atomic int *stop;
    _Atomic int *first_ready;        /* run pass: set once the first chunk is out */
    size_t settings;
    unsigned waits;                  /* M66 waits sent to the machine */
    unsigned probes;                 /* G38 probe moves sent to the machine */
    int status;                      /* RUNNER_ERR_* of the first error */
    char err[800];
};

struct runner_stream {
    pthread_t thread;
    bool thread_live;
    struct motion_stream *ms;
    struct tooltable *tt;            /* the run's interpreter's tool table */
    char path[1024];
    struct stream_sink sink;
    _Atomic int stop;
    _Atomic int first_ready;         /* the first chunk is planned, or the producer ended */
    _Atomic int done;                /* the producer has ended (sink.status says how) */
};

static void sleep_ms(double ms)
{
    struct timespec ts = { 0, (long)(ms * 1e6) };
    nanosleep(&ts, NULL);
}

static int sink_fail(struct stream_sink *k, int st, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static int sink_fail(struct stream_sink *k, int st, const char *fmt, ...)
{
    if (!k->status) {
        va_list ap;
        va_start(ap, fmt);
        k->status = st;
        vsnprintf(k->err, sizeof k->err, fmt, ap);
        va_end(ap);
    }
    return -1;
}

/* One command after the from-line cut: settings checked (check pass) or kept (run pass),
 * then planned. */
static int take(struct stream_sink *k, const struct canon_cmd *c)
{
    if (c->type == CANON_SETTING) {
        k->settings++;
        if (k->store) {
            char msg[700], text[800];
            if (interp_setting_check(k->store, c->setting, msg, sizeof msg) != INTERP_OK) {
                snprintf(text, sizeof text, "%s:%d: this line %s, saved when the line "
                         "executes, but %s", c->file, c->line,
                         runner_setting_what(c->setting), msg);
                return sink_fail(k, RUNNER_ERR_CONFIG, "%s", text);
            }
        }
        if (k->run) {
            pthread_mutex_lock(&k->r->settings_lock);
            int rc = canon_prog_sink(&k->r->settings, c);
            pthread_mutex_unlock(&k->r->settings_lock);
            if (rc)
                return sink_fail(k, RUNNER_ERR_NOMEM, "%s", "out of memory");
        }
    }
    while (k->run && motion_stream_backlog(k->ms) >= RUNNER_STREAM_AHEAD &&
           !atomic_load(k->stop))
        sleep_ms(1);
    if (atomic_load(k->stop))
        return sink_fail(k, RUNNER_ERR_ABORTED, "%s", "the program was stopped");
    struct canon_cmd whole;
    if (k->run && c->type == CANON_PROBE) {
        /* the machine is planned the whole move: it stops where the probe trips */
        whole = *c;
        memcpy(whole.probe_stop, c->end, sizeof whole.probe_stop);
        c = &whole;
    }
    if (motion_stream_add(k->ms, c) != MOTION_OK)
        return sink_fail(k, RUNNER_ERR_PLAN, "%s", motion_stream_error(k->ms));
    if (k->first_ready && !atomic_load(k->first_ready) && motion_stream_backlog(k->ms) > 0)
        atomic_store(k->first_ready, 1);
    return 0;
}

/* M66 on a run: the window so far goes to the machine to a stop at the wait; the
 * interpreter reads on with the machine's answer once it has it (LinuxCNC's M66 is a
 * "queue buster" too). The verification pass reads 0, as rs274 does. */
/* A millisecond more for the machine's answer to an M66 or a G38; false (the run then
 * fails as stopped) once the operator has stopped the program. */
static bool wait_for_machine(struct stream_sink *k)
{
    if (atomic_load(k->stop)) {
        sink_fail(k, RUNNER_ERR_ABORTED, "%s", "the program was stopped");
        return false;
    }
    sleep_ms(1);
    return true;
}

static double input_answer(void *ctx, const struct canon_cmd *w)
{
    struct stream_sink *k = ctx;
    (void)w;
    if (!k->run || k->status)
        return 0;
    if (motion_stream_sync(k->ms) != MOTION_OK) {
        sink_fail(k, RUNNER_ERR_PLAN, "%s", motion_stream_error(k->ms));
        return 0;
    }
    atomic_store(k->first_ready, 1);
    k->waits++;
    for (;;) {
        unsigned seq;
        double v = motion_input_result(k->r->motion, &seq);
        if (seq >= k->waits)
            return v;
        if (!wait_for_machine(k))
            return 0;
    }
}

/* G38 on a run: the window so far, the probe move last, goes to the machine, planned to a
 * stop at the move's end; the machine stops earlier where the probe input changes. The
 * interpreter reads on with where it tripped and where the machine came to rest, and the
 * next window starts there (LinuxCNC's probe is a "queue buster" too). The verification
 * pass, and a probe before the line a run starts from, keep the interpreter's own answer. */
static int probe_answer(void *ctx, const struct canon_cmd *c, struct interp_probe_result *r,
                        char *why, size_t whylen)
{
    struct stream_sink *k = ctx;
    if (!k->run || k->status || !k->cut.started)
        return 0;
    if (motion_stream_sync(k->ms) != MOTION_OK) {
        sink_fail(k, RUNNER_ERR_PLAN, "%s", motion_stream_error(k->ms));
        snprintf(why, whylen, "%s", motion_stream_error(k->ms));
        return -1;
    }
    atomic_store(k->first_ready, 1);
    k->probes++;
    struct motion_probe_result res;
    while (motion_probe_result(k->r->motion, &res) < k->probes)
        if (!wait_for_machine(k)) {
            snprintf(why, whylen, "the program was stopped");
            return -1;
        }
    motion_stream_restart_at(k->ms, res.stop);
    if (res.already) {
        snprintf(why, whylen, "the probe is already %s where the move starts "
                 "(motion.probe-input is %s)", c->ivalue & 2 ? "clear of the workpiece"
                 : "tripped", c->ivalue & 2 ? "false" : "true");
        return -1;
    }
    r->tripped = res.tripped;
    memcpy(r->trip, res.trip, sizeof r->trip);
    memcpy(r->stop, res.stop, sizeof r->stop);
    return 0;
}

static int sink(void *ctx, const struct canon_cmd *c)
{
    struct stream_sink *k = ctx;
    if (k->status)
        return -1;
    struct canon_cmd go;
    char msg[600];
    int act = runner_cut_step(&k->cut, c, &go, msg, sizeof msg);
    if (act < 0)
        return sink_fail(k, RUNNER_ERR_PROGRAM, "%s", msg);
    if (act == RUNNER_CUT_RAPID_FIRST && take(k, &go))
        return -1;
    return act == RUNNER_CUT_DROP ? 0 : take(k, c);
}

/* The interpreter's outcome, after the sink's. */
static int interp_outcome(struct stream_sink *k, struct interp *in, int ist)
{
    if (k->status)
        return k->status;
    if (ist != INTERP_OK) {
        char msg[600];
        const struct interp_error *e = interp_last_error(in);
        interp_error_format(e, msg, sizeof msg);
        return sink_fail(k, e->status == INTERP_ERR_CANCELLED ? RUNNER_ERR_ABORTED
                         : RUNNER_ERR_PROGRAM, "%s", msg), k->status;
    }
    if (!k->cut.started) {
        return sink_fail(k, RUNNER_ERR_PROGRAM, "the program has no line %d or later to start "
                         "from", k->cut.from_line), k->status;
    }
    if (motion_stream_finish(k->ms) != MOTION_OK)
        return sink_fail(k, RUNNER_ERR_PLAN, "%s", motion_stream_error(k->ms)), k->status;
    return RUNNER_OK;
}

/* What identifies the file and the machine state a check was made for. */
static bool same_check(const struct runner_check *a, const struct runner_check *b)
{
    if (a->dev != b->dev || a->ino != b->ino || a->size != b->size ||
        a->mtime_ns != b->mtime_ns || a->ctime_ns != b->ctime_ns ||
        a->files_ns != b->files_ns || strcmp(a->path, b->path) != 0)
        return false;
    for (int i = 0; i < KINS_POSE_DIM; i++)
        if (fabs(a->start[i] - b->start[i]) > 1e-6)
            return false;
    return true;
}

static int identify(struct runner *r, const char *path, struct runner_check *id, char *err,
                    size_t errlen)
{
    struct stat st;
    memset(id, 0, sizeof *id);
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode))
        return errbuf_set(err, errlen, RUNNER_ERR_PROGRAM, "%s: cannot open the program", path);
    snprintf(id->path, sizeof id->path, "%s", path);
    id->dev = st.st_dev;
    id->ino = st.st_ino;
    id->size = st.st_size;
    id->mtime_ns = (int64_t)st.st_mtim.tv_sec * 1000000000 + st.st_mtim.tv_nsec;
    id->ctime_ns = (int64_t)st.st_ctim.tv_sec * 1000000000 + st.st_ctim.tv_nsec;
    /* the tool table and the parameter file the interpreter starts from: a G10 the last
     * run saved, or tooltable.set, makes the check stale */
    static const char *const keys[] = { "TOOL_TABLE", "PARAMETER_FILE" };
    for (int i = 0; i < 2; i++) {
        const char *v = hal_ini_get(r->hal, "RS274NGC", keys[i]);
        char f[1200];
        if (!v || !v[0])
            continue;
        runner_ini_path(r, v, f, sizeof f);
        if (stat(f, &st) == 0)
            id->files_ns = id->files_ns * 31u + (uint64_t)st.st_mtim.tv_sec * 1000000000u +
                           (uint64_t)st.st_mtim.tv_nsec + (uint64_t)st.st_ino +
                           (uint64_t)st.st_size;   /* (unsigned: wraps, as a hash may) */
    }
    motion_hal_pose(r->hal, id->start);
    return RUNNER_OK;
}

int runner_check_stream(struct runner *r, const char *path, struct motion_plan_info *info,
                        char *err, size_t errlen)
{
    struct runner_check id;
    int st = identify(r, path, &id, err, errlen);
    if (st)
        return st;
    runner_feedback_settle(r);       /* planned from where the legs are */
    motion_hal_pose(r->hal, id.start);
    r->checked.valid = false;
    struct interp *in = NULL, *store = NULL;
    struct tooltable *tt = NULL, *store_tt = NULL;
    struct stream_sink k = { .r = r };
    static const _Atomic int never;
    k.stop = &never;
    runner_cut_init(&k.cut, 1, id.start);
    if ((st = runner_new_interp(r, id.start, &in, &tt, err, errlen)) ||
        (st = runner_new_interp(r, id.start, &store, &store_tt, err, errlen)))
        goto out;
    k.store = store;
    if (motion_stream_create(r->motion, id.start, r->cancel, &k.ms, err, errlen) != MOTION_OK) {
        st = RUNNER_ERR_NOMEM;
        goto out;
    }
    st = interp_outcome(&k, in, interp_run_file(in, path, sink, &k));
    if (st) {
        errbuf_set(err, errlen, st, "%s", k.err);
        goto out;
    }
    struct motion_stream_info si;
    motion_stream_info(k.ms, &si);
    id.info = si.plan;
    id.settings = k.settings;
    id.valid = true;
    r->checked = id;
    if (info)
        *info = si.plan;
out:
    motion_stream_destroy(k.ms);
    interp_destroy(in);
    interp_destroy(store);
    free(tt);
    free(store_tt);
    return st;
}

static void *producer(void *arg)
{
    struct runner *r = arg;
    struct runner_stream *rs = r->stream;
    struct stream_sink *k = &rs->sink;
    int ist = interp_run_file(r->interp, rs->path, sink, k);
    interp_outcome(k, r->interp, ist);
    atomic_store(&rs->first_ready, 1);
    atomic_store(&rs->done, 1);
    return NULL;
}

void runner_stream_close(struct runner *r)
{
    struct runner_stream *rs = r->stream;
    if (!rs)
        return;
    atomic_store(&rs->stop, 1);
    if (rs->thread_live)
        pthread_join(rs->thread, NULL);
    motion_hal_stream_end(r->hal, rs->ms);
    if (r->interp)
        interp_set_tooltable(r->interp, NULL);
    free(rs->tt);
    free(rs);
    r->stream = NULL;
}

bool runner_stream_checked(struct runner *r, const char *path)
{
    struct runner_check id;
    char err[200];
    return identify(r, path, &id, err, sizeof err) == RUNNER_OK && r->checked.valid &&
           same_check(&r->checked, &id);
}

int runner_stream_start(struct runner *r, const char *path, int from_line, char *err,
                        size_t errlen)
{
    if (runner_moving(r))
        return errbuf_set(err, errlen, RUNNER_ERR_STATE, "the machine is still running");
    runner_stream_close(r);
    r->loaded = false;
    struct runner_check id;
    int st = identify(r, path, &id, err, errlen);
    if (st)
        return st;
    runner_feedback_settle(r);
    motion_hal_pose(r->hal, id.start);
    if (!r->checked.valid || !same_check(&r->checked, &id)) {
        /* never checked, or the file, the tools or the start changed since: again */
        if ((st = runner_check_stream(r, path, NULL, err, errlen)))
            return st;
    }
    struct runner_stream *rs = calloc(1, sizeof *rs);
    if (!rs)
        return errbuf_set(err, errlen, RUNNER_ERR_NOMEM, "out of memory");
    r->stream = rs;
    snprintf(rs->path, sizeof rs->path, "%s", path);
    interp_destroy(r->interp);
    r->interp = NULL;
    if ((st = runner_new_interp(r, id.start, &r->interp, &rs->tt, err, errlen)))
        goto fail;
    pthread_mutex_lock(&r->settings_lock);
    runner_settings_free(r);
    pthread_mutex_unlock(&r->settings_lock);
    if (r->checked.settings && (st = runner_settings_store(r, err, errlen)))
        goto fail;
    char msg[600];
    if (motion_hal_stream_begin(r->hal, id.start, &r->checked.info, r->cancel, &rs->ms, msg,
                                sizeof msg) != MOTION_OK) {
        st = errbuf_set(err, errlen, RUNNER_ERR_PLAN, "%s", msg);
        goto fail;
    }
    rs->sink.r = r;
    rs->sink.ms = rs->ms;
    rs->sink.run = true;
    rs->sink.stop = &rs->stop;
    rs->sink.first_ready = &rs->first_ready;
    runner_cut_init(&rs->sink.cut, from_line, id.start);
    interp_set_input_fn(r->interp, input_answer, &rs->sink);
    interp_set_probe_fn(r->interp, probe_answer, &rs->sink);
    if (pthread_create(&rs->thread, NULL, producer, r) != 0) {
        st = errbuf_set(err, errlen, RUNNER_ERR_NOMEM, "cannot start the planner's thread");
        goto fail;
    }
    rs->thread_live = true;
    /* the first chunk before the answer: an error in the first window (the move to a
     * from-line's start) is refused before anything moves */
    while (!atomic_load(&rs->first_ready))
        sleep_ms(0.2);
    if (atomic_load(&rs->done) && rs->sink.status) {
        st = errbuf_set(err, errlen, rs->sink.status, "%s", rs->sink.err);
        goto fail;
    }
    r->plan = r->checked.info;
    r->loaded = true;
    return RUNNER_OK;
fail:
    runner_stream_close(r);
    return st;
}

/* How the producer ended: RUNNER_OK while it runs or when it finished planning. */
int runner_stream_outcome(const struct runner *r, char *err, size_t errlen)
{
    const struct runner_stream *rs = r->stream;
    if (!rs || !atomic_load(&rs->done) || !rs->sink.status ||
        rs->sink.status == RUNNER_ERR_ABORTED)
        return RUNNER_OK;
    return errbuf_set(err, errlen, rs->sink.status, "%s", rs->sink.err);
}

bool runner_stream_stalled(const struct runner *r)
{
    char err[8];
    return r->stream && atomic_load(&r->stream->done) &&
           runner_stream_outcome(r, err, sizeof err) != RUNNER_OK &&
           motion_stream_starving(r->motion);
}

bool runner_stream_starving(const struct runner *r)
{
    return r->stream && !atomic_load(&r->stream->done) && motion_stream_starving(r->motion);
}
