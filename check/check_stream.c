/* check_stream.c: the check of a program file in bounded memory: the interpreter, the reach
 * pass and the planner on a thread of their own, window by window (motion_stream), while the
 * servo-rate pass runs on the caller's thread behind them. */
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check/check_defer.h"
#include "check/check_priv.h"
#include "interp/interp.h"

#define AHEAD_CHUNKS 4       /* planned windows the producer may have ahead of the servo pass
                              * (each about 2048 moves): the memory bound */

/* The producer's side: what it reads, what it found. Its check_result holds the reach
 * problems (the servo pass fills the caller's); they are merged at the end. */
struct producer {
    pthread_t thread;
    struct check_machine *mc;
    struct interp *in;
    const char *path;
    struct motion_stream *ms;
    struct check_reach reach;
    struct check_result found;       /* reach problems */
    int plan_status;                 /* the stream's first error (planning stops there, the
                                      * reach pass goes on to the end) */
    int interp_status;               /* CHECK_OK, or the interpreter's error (in pb) */
    struct check_problem pb;
    _Atomic int ready;               /* the first window is planned, or the producer ended */
    _Atomic int done;                /* the producer has ended */
    _Atomic int stop;                /* the servo pass has ended: plan no more (the reach
                                      * pass goes on), and wait for no chunk to be left */
    double cpu_s;                    /* the thread's CPU time, once it has ended */
    struct check_defer *defer;       /* the servo pass's measures, which this thread computes
                                      * while it waits for the pass (check_defer.h) */
};


static void pause_us(long us)
{
    struct timespec ts = { 0, us * 1000 };
    nanosleep(&ts, NULL);
}

/* While the planner waits for the servo pass: a measure of the pass's, else a short sleep. */
static void help_or_pause(struct producer *p, long us)
{
    if (!check_defer_work(p->defer))
        pause_us(us);
}

/* The interpreter's commands: reach pass, then the planner (while it has not failed), with
 * at most AHEAD_CHUNKS windows ahead of the servo pass. */
static int sink(void *ctx, const struct canon_cmd *c)
{
    struct producer *p = ctx;
    size_t before = p->found.nproblems;
    check_reach_cmd(p->mc, &p->reach, c, &p->found);
    if (p->found.nproblems > before && !p->plan_status)
        p->plan_status = MOTION_ERR_UNREACHABLE;  /* the planner would refuse it too: the
                                                   * reach pass's words are the clearer */
    if (p->plan_status || atomic_load(&p->stop))
        return 0;
    while (motion_stream_backlog(p->ms) >= AHEAD_CHUNKS)
        if (atomic_load(&p->stop))
            return 0;
        else
            help_or_pause(p, 200);
    if (motion_stream_add(p->ms, c) != MOTION_OK)
        p->plan_status = MOTION_ERR_PROGRAM;
    else if (!atomic_load(&p->ready) && motion_stream_backlog(p->ms) > 0)
        atomic_store(&p->ready, 1);
    return 0;
}

static void *produce(void *arg)
{
    struct producer *p = arg;
    int ist = interp_run_file(p->in, p->path, sink, p);
    if (ist != INTERP_OK) {
        const struct interp_error *e = interp_last_error(p->in);
        memset(&p->pb, 0, sizeof p->pb);
        p->pb.kind = CHECK_INTERP, p->pb.leg = -1, p->pb.time_s = -1, p->pb.count = 1;
        snprintf(p->pb.file, sizeof p->pb.file, "%s", e->file[0] ? e->file : p->path);
        p->pb.line = e->line, p->pb.column = e->column;
        interp_error_format(e, p->pb.message, sizeof p->pb.message);
        p->interp_status = CHECK_ERR_VIOLATION;
    } else if (!p->plan_status && !atomic_load(&p->stop) &&
               motion_stream_finish(p->ms) != MOTION_OK) {
        p->plan_status = MOTION_ERR_PROGRAM;
    }
    atomic_store(&p->ready, 1);
    atomic_store(&p->done, 1);
    while (!atomic_load(&p->stop))      /* the pass runs on through the last chunks */
        help_or_pause(p, 100);
    p->cpu_s = check_thread_cpu_s();
    return NULL;
}

/* The servo pass is short of plan: waits for the producer, taking a share of the planner's
 * work where it offers one (motion_stream_help: the plan it waits for comes sooner), else
 * computing its own measures (the planner's thread then finds fewer to take from its
 * planning). 1 to go on, 0 when no more plan will come (the producer ended without
 * finishing the stream). */
static int feed_wait(void *ctx)
{
    struct producer *p = ctx;
    struct motion *m = p->mc->motion;
    while (motion_stream_starving(m)) {
        if (atomic_load(&p->done))
            return !motion_stream_starving(m);
        if (!motion_stream_help(p->ms) && !check_defer_work(p->defer))
            pause_us(50);
    }
    return 1;
}

/* The planned time once the producer has ended, else -1 (no bound yet). */
static double feed_planned(void *ctx)
{
    struct producer *p = ctx;
    if (!atomic_load(&p->done) || p->plan_status || p->interp_status)
        return -1;
    struct motion_stream_info si;
    motion_stream_info(p->ms, &si);
    return si.plan.time_s;
}

/* Problems in the order a reader expects (the reach pass's first, as check_canon gives them):
 * found's, then r's, into r. */
static int merge_found(struct check_result *r, struct check_result *found)
{
    struct check_result all;
    check_result_init(&all);
    int st = CHECK_OK;
    for (size_t i = 0; i < found->nproblems && !st; i++)
        st = check_add_problem(&all, &found->problems[i]);
    for (size_t i = 0; i < r->nproblems && !st; i++)
        st = check_add_problem(&all, &r->problems[i]);
    free(r->problems);
    free(r->pindex);
    r->problems = all.problems, r->nproblems = all.nproblems, r->capproblems = all.capproblems;
    r->pindex = all.pindex, r->pindex_cap = all.pindex_cap;
    free(all.windex);
    return st;
}

/* What the producer found when it could not plan to the end: the interpreter's error alone,
 * else the reach problems, else the planner's message; the servo pass's figures are
 * dropped (they cover only part of a program that cannot run), as check_canon has none. */
static void plan_failure(struct producer *p, struct check_result *r)
{
    check_result_free(r);    /* (warnings too: a program that cannot run has none) */
    r->simulated = 0;
    r->machining_time_s = r->length_mm = 0;
    r->periods = 0;
    if (p->interp_status) {
        check_add_problem(r, &p->pb);
        return;
    }
    if (p->found.nproblems) {
        merge_found(r, &p->found);
        return;
    }
    check_add_plan_problem(r, motion_stream_error(p->ms), 0, -1);
}

int check_program(struct check_machine *mc, const char *path, const struct check_opts *opts,
                  struct check_result *r)
{
    struct check_opts def;
    if (!opts) {
        check_opts_default(&def);
        opts = &def;
    }
    if (opts->trace)
        return check_program_whole(mc, path, opts, r);
    snprintf(r->program, sizeof r->program, "%s", path);
    check_result_header(mc, opts, r);
    struct producer *p = calloc(1, sizeof *p);
    if (!p)
        return CHECK_ERR_NOMEM;
    p->mc = mc, p->path = path;
    check_result_init(&p->found);
    struct kins_tool_frame tf;
    int have_tf = kins_get_tool_frame(mc->kins, &tf) == KINS_OK;
    if (!(p->defer = check_defer_new(mc->kins, have_tf ? &tf : NULL, opts->cold_forward))) {
        free(p);
        return CHECK_ERR_NOMEM;
    }
    int st = check_machine_interp_new(mc, &p->in, &p->pb);
    if (st) {
        check_add_problem(r, &p->pb);
        check_defer_free(p->defer);
        free(p);
        return st;
    }
    check_reach_begin(&p->reach, mc->kins->home, 0, 0);
    char err[400];
    const char *why = NULL;
    int e;
    if (motion_stream_create(mc->motion, mc->kins->home, NULL, &p->ms, err, sizeof err) !=
        MOTION_OK)
        why = err;
    else if (motion_stream_attach(mc->motion, p->ms, NULL) != MOTION_OK)
        why = motion_last_error(mc->motion);
    else if ((e = pthread_create(&p->thread, NULL, produce, p)) != 0) {
        snprintf(err, sizeof err, "the planner's thread cannot start: %s", strerror(e));
        why = err;
    }
    if (why) {                           /* the check cannot run: say why */
        check_add_plan_problem(r, why, 0, -1);
        motion_stream_detach(mc->motion);
        motion_stream_destroy(p->ms);
        check_defer_free(p->defer);
        free(p);
        return CHECK_ERR_CONFIG;
    }
    while (!atomic_load(&p->ready))     /* (the first window's share: the pass starts sooner) */
        if (!motion_stream_help(p->ms))
            pause_us(20);
    struct check_feed feed = { feed_wait, feed_planned, p, p->defer };
    int sim = CHECK_OK;
    double t0 = check_thread_cpu_s();
    if (!p->plan_status && !p->interp_status)
        sim = motion_start(mc->motion) == MOTION_OK
                  ? check_simulate(mc, mc->kins->home, opts, &feed, r) : CHECK_ERR_CONFIG;
    double servo_cpu_s = check_thread_cpu_s() - t0;
    atomic_store(&p->stop, 1);          /* (a servo pass cut short leaves chunks unread) */
    pthread_join(p->thread, NULL);
    if (p->plan_status || p->interp_status) {
        plan_failure(p, r);
        st = CHECK_ERR_VIOLATION;
    } else {
        struct motion_stream_info si;
        motion_stream_info(p->ms, &si);
        r->planned_time_s = si.plan.time_s;
        r->length_mm = si.plan.length_mm;
        r->simulated = 1;
        r->servo_cpu_s = servo_cpu_s;
        r->plan_cpu_s = p->cpu_s;
        st = merge_found(r, &p->found);
        if (!st && sim != CHECK_OK)
            st = check_add_plan_problem(r, motion_last_error(mc->motion), 1,
                                        r->machining_time_s);
        if (!st)
            st = r->nproblems ? CHECK_ERR_VIOLATION : CHECK_OK;
    }
    motion_stream_detach(mc->motion);
    motion_stream_destroy(p->ms);
    check_result_free(&p->found);
    check_defer_free(p->defer);
    free(p);
    return st;
}
