/* check.c: the check of one program: interpret, scan the reach, plan, run on the servo clock. */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check/check_priv.h"

static const char *const kind_names[CHECK_KIND_COUNT] = {
    [CHECK_INTERP] = "interp",
    [CHECK_UNREACHABLE] = "unreachable",
    [CHECK_LEG_RANGE] = "leg_range",
    [CHECK_LEG_VELOCITY] = "leg_velocity",
    [CHECK_LEG_ACCELERATION] = "leg_acceleration",
    [CHECK_LEG_JERK] = "leg_jerk",
    [CHECK_SINGULAR] = "singular",
    [CHECK_PLAN] = "plan",
    [CHECK_TIP_DEVIATION] = "tip_deviation",
};

/* JSON name of a problem kind. */
const char *check_kind_name(enum check_kind k)
{
    return k < CHECK_KIND_COUNT ? kind_names[k] : "unknown";
}

/* The default schedule (see check.h). */
void check_opts_default(struct check_opts *o)
{
    memset(o, 0, sizeof *o);
    o->deviation_every_s = 0.050;
    o->condition_every_s = 0.500;
}

/* An empty result. */
void check_result_init(struct check_result *r)
{
    memset(r, 0, sizeof *r);
}

/* Frees the problem list. */
void check_result_free(struct check_result *r)
{
    free(r->problems);
    free(r->warnings);
    free(r->pindex);
    free(r->windex);
    r->problems = r->warnings = NULL;
    r->pindex = r->windex = NULL;
    r->pindex_cap = r->windex_cap = 0;
    r->nproblems = r->capproblems = r->nwarnings = r->capwarnings = 0;
}

/* Hash of what makes two problems one: kind, file, line, leg. */
static size_t problem_hash(const struct check_problem *p)
{
    size_t h = 1469598103934665603ULL;
    for (const char *c = p->file; *c; c++)
        h = (h ^ (unsigned char)*c) * 1099511628211ULL;
    h = (h ^ (size_t)p->kind) * 1099511628211ULL;
    h = (h ^ (size_t)(unsigned)p->line) * 1099511628211ULL;
    return (h ^ (size_t)(unsigned)p->leg) * 1099511628211ULL;
}

static int same_problem(const struct check_problem *q, const struct check_problem *p)
{
    return q->kind == p->kind && q->line == p->line && q->leg == p->leg &&
           strcmp(q->file, p->file) == 0;
}

/* The slot of p in the index (open addressing; cap a power of two): its entry's or the empty
 * one where it goes. */
static size_t *index_slot(size_t *index, size_t cap, const struct check_problem *list,
                          const struct check_problem *p)
{
    size_t i = problem_hash(p) & (cap - 1);
    while (index[i] && !same_problem(&list[index[i] - 1], p))
        i = (i + 1) & (cap - 1);
    return &index[i];
}

/* Rebuilds the index at twice the entries' count at least, 64 slots or more. */
static int index_grow(size_t **index, size_t *cap, const struct check_problem *list, size_t n)
{
    size_t nc = 64;
    while (nc < 4 * (n + 1))
        nc *= 2;
    size_t *ni = calloc(nc, sizeof *ni);
    if (!ni)
        return CHECK_ERR_NOMEM;
    for (size_t k = 0; k < n; k++)
        *index_slot(ni, nc, list, &list[k]) = k + 1;
    free(*index);
    *index = ni, *cap = nc;
    return CHECK_OK;
}

/* Adds or merges a problem (same kind, file, line and leg) in a list. */
static int add_to(struct check_problem **list, size_t *n, size_t *capn, size_t **index,
                  size_t *capi, const struct check_problem *p)
{
    if (2 * (*n + 1) > *capi && index_grow(index, capi, *list, *n) != CHECK_OK)
        return CHECK_ERR_NOMEM;
    size_t *slot = index_slot(*index, *capi, *list, p);
    if (*slot) {
        struct check_problem *q = &(*list)[*slot - 1];
        int count = q->count + p->count;
        if (fabs(p->value) > fabs(q->value))  /* keep the worst occurrence's figures */
            *q = *p;
        q->count = count;
        return CHECK_OK;
    }
    if (*n == *capn) {
        size_t cap = *capn ? 2 * *capn : 16;
        struct check_problem *np = realloc(*list, cap * sizeof *np);
        if (!np)
            return CHECK_ERR_NOMEM;
        *list = np, *capn = cap;
    }
    (*list)[(*n)++] = *p;
    *slot = *n;
    return CHECK_OK;
}

int check_add_problem(struct check_result *r, const struct check_problem *p)
{
    return add_to(&r->problems, &r->nproblems, &r->capproblems, &r->pindex, &r->pindex_cap, p);
}

int check_add_warning(struct check_result *r, const struct check_problem *p)
{
    return add_to(&r->warnings, &r->nwarnings, &r->capwarnings, &r->windex, &r->windex_cap,
                  p);
}

/* The file and line a motion message names ("file:line: ..."), line 0 when it names none. */
static int message_line(const char *msg, char *file, size_t len)
{
    for (const char *c = strchr(msg, ':'); c; c = strchr(c + 1, ':')) {
        const char *d = c + 1;
        while (isdigit((unsigned char)*d))
            d++;
        if (c > msg && d > c + 1 && *d == ':') {
            snprintf(file, len, "%.*s", (int)(c - msg), msg);
            return atoi(c + 1);
        }
    }
    return 0;
}

int check_add_plan_problem(struct check_result *r, const char *msg, int stopped, double time_s)
{
    struct check_problem p = { .kind = CHECK_PLAN, .leg = -1, .time_s = stopped ? time_s : -1,
                               .count = 1 };
    p.line = message_line(msg, p.file, sizeof p.file);
    if (stopped)
        snprintf(p.message, sizeof p.message, "motion stopped before the end of the program: "
                 "%.300s", msg[0] ? msg : "it did not finish in twice the planned time");
    else
        snprintf(p.message, sizeof p.message, "%s", msg);
    return check_add_problem(r, &p);
}

/* Fills the result's header fields from the machine. */
void check_result_header(struct check_machine *mc, const struct check_opts *o,
                          struct check_result *r)
{
    r->servo_period_s = mc->mcfg.servo_period_s;
    r->kin_tol_mm = mc->mcfg.kin_tol_mm;
    r->jerk_window_s = motion_jerk_window_s(&mc->mcfg);
    r->jerk_window_set = r->jerk_window_s > 0 && mc->mcfg.jerk_window_s > 0;
    r->jerk_full_window_s = motion_jerk_full_window_s(&mc->mcfg);
    r->condition_limit = mc->cond_limit;
    r->deviation_every_s = o->deviation_every_s;
    r->condition_every_s = o->condition_every_s;
    r->njoints = mc->kins->njoints;
    snprintf(r->config, sizeof r->config, "%s", mc->ini);
}

double check_thread_cpu_s(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0)
        return 0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Reach pass, plan, then the servo-rate pass. */
int check_canon(struct check_machine *mc, const struct canon_prog *prog,
                const struct check_opts *opts, struct check_result *r)
{
    struct check_opts def;
    if (!opts) {
        check_opts_default(&def);
        opts = &def;
    }
    check_result_header(mc, opts, r);
    double t0 = check_thread_cpu_s();
    int reach = check_scan_reach(mc, prog, r);
    char msg[400];
    int loaded = motion_load(mc->motion, prog, msg, sizeof msg);
    r->plan_cpu_s = check_thread_cpu_s() - t0;
    if (loaded != MOTION_OK) {
        if (reach == 0)        /* the planner found what the reach pass did not: report it */
            check_add_plan_problem(r, msg, 0, -1);
        return CHECK_ERR_VIOLATION;
    }
    if (motion_start(mc->motion) != MOTION_OK)
        return CHECK_ERR_CONFIG;
    t0 = check_thread_cpu_s();
    int st = check_simulate(mc, prog->start, opts, NULL, r);
    r->servo_cpu_s = check_thread_cpu_s() - t0;
    r->simulated = 1;
    if (st != CHECK_OK)
        check_add_plan_problem(r, motion_last_error(mc->motion), 1, r->machining_time_s);
    return r->nproblems ? CHECK_ERR_VIOLATION : CHECK_OK;
}

/* The whole program interpreted into memory, then check_canon() (check_program's way for a
 * plot, whose samples are spread over the planned time). */
int check_program_whole(struct check_machine *mc, const char *path,
                        const struct check_opts *opts, struct check_result *r)
{
    struct canon_prog prog;
    struct check_problem p;
    snprintf(r->program, sizeof r->program, "%s", path);
    canon_prog_init(&prog);
    int st = check_machine_interpret(mc, path, &prog, &p);
    if (st != CHECK_OK) {
        check_result_header(mc, opts, r);
        check_add_problem(r, &p);
    } else {
        st = check_canon(mc, &prog, opts, r);
    }
    canon_prog_free(&prog);
    return st;
}
