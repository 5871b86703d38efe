/* motion_stream.c: a program planned window by window as its commands come (streaming). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_blend.h"
#include "motion/motion_merge.h"
#include "motion/motion_priv.h"

/*
 * The interpreter's commands gather in a window. Once the window holds STREAM_WINDOW
 * commands and enough path after some move to stop from full speed (the tail), it is
 * planned like a whole program that ends at rest, and cut after that move:
 *
 *     window:  [context][ committed ........ ][ tail ........ ] (v = 0 at the end)
 *                        ^ k_enter (speed v_enter)  ^ k_leave (speed v_leave)
 *
 * The committed part and the tail go to the executor as one chunk. The next window starts
 * with the move before the cut as context (for the junction and chord caps at the entry)
 * and holds the whole tail again, and more: it is planned from v_leave at k_leave. Its plan
 * can always keep that speed, because the previous window could stop from it within the
 * tail, which the new window holds under the same caps. The executor hands over from one
 * chunk to the next at k_leave (motion_step.c); if the next is not there in time, it runs on
 * into the tail, which stops on the path (MOTION_ERR_STARVED), and nothing more is attached.
 * Memory: the window and at most the chunks the caller lets the executor have ahead.
 */

#define STREAM_WINDOW 2048          /* commands that make a window worth planning */
#define STREAM_WINDOW_MAX 65536     /* planned at this size even with a short tail */

struct motion_stream {
    struct motion *m;               /* the executor (motion_stream_attach), or NULL */
    struct motion *pm;              /* the planner's own instance (scratch, messages) */
    struct canon_cmd *win;          /* the window's commands (no payloads: motion needs none) */
    size_t n, cap;
    size_t nctx;                    /* context commands at its start */
    size_t fresh;                   /* commands added since the window was last cut */
    double start[KINS_POSE_DIM];    /* pose where win[0] starts */
    int start_tcp;                  /* ... the tool tip under G43.4 with this tool length */
    double start_len_mm;
    double start0[KINS_POSE_DIM];   /* the program's start */
    double tol_mm;                  /* G64 tolerance in force at win[0] */
    double tail_mm, tail_deg;       /* path a window keeps after its cut */
    double v_enter;                 /* speed at the next window's entry */
    double t_done_s, dist_done_mm;  /* plan time and XYZ path committed so far */
    struct motion_chunk *oldest, *newest; /* chunks published and not yet freed */
    size_t live;
    struct motion_plan_info info;   /* totals of what was committed */
    double deficit;                 /* largest entry shortfall (rounding), relative */
    size_t windows;
    int ended;
    int status;                     /* first error (then nothing more is planned) */
    char err[400];
    struct motion_merge merge;      /* G64 Q: runs of straight feeds held until they end */
};

static bool is_move(enum canon_type t)
{
    return t == CANON_TRAVERSE || t == CANON_FEED || t == CANON_ARC || t == CANON_PROBE;
}

/* Where a move leaves the path: a probe move where the planner is told it stops. */
static const double *move_end(const struct canon_cmd *c)
{
    return c->type == CANON_PROBE ? c->probe_stop : c->end;
}

int motion_stream_create(struct motion *m, const double start[KINS_POSE_DIM],
                         const volatile sig_atomic_t *cancel, struct motion_stream **out,
                         char *err, size_t errlen)
{
    *out = NULL;
    struct motion_stream *s = calloc(1, sizeof *s);
    if (!s) {
        snprintf(err, errlen, "out of memory");
        return MOTION_ERR_NOMEM;
    }
    int st = motion_create(&m->cfg, m->kins, &s->pm, err, errlen);
    if (st) {
        free(s);
        return st;
    }
    s->pm->wait_at_speed = m->wait_at_speed;
    s->pm->wait_tool = m->wait_tool;
    s->pm->io = m->io;              /* the spindle as the program finds it */
    atomic_store(&s->pm->spindle_wired, atomic_load(&m->spindle_wired));
    s->pm->spindle_ideal = m->spindle_ideal;
    s->pm->cancel = cancel;
    memcpy(s->start, start, sizeof s->start);
    memcpy(s->start0, start, sizeof s->start0);
    const struct motion_config *c = &m->cfg;
    s->tol_mm = c->blend_tol_mm;    /* a program starts in G64 (LinuxCNC's default) */
    motion_merge_init(&s->merge, start, 0, 0, 0);
    double acc = c->max_lin_acc_mm_s2;
    for (int j = 0; j < m->nj; j++)
        acc = fmin(acc, c->joint[j].max_acc_mm_s2);
    /* the stop from twice the fastest speed (feed override 200 %) */
    s->tail_mm = 4 * c->max_lin_vel_mm_s * c->max_lin_vel_mm_s / (2 * acc) + 1;
    s->tail_deg = 4 * c->max_ang_vel_deg_s * c->max_ang_vel_deg_s /
                  (2 * c->max_ang_acc_deg_s2) + 1;
    *out = s;
    return MOTION_OK;
}

/* Frees chunks the executor has left. */
static void reclaim(struct motion_stream *s)
{
    while (s->oldest && atomic_load_explicit(&s->oldest->retired, memory_order_acquire)) {
        struct motion_chunk *o = s->oldest;
        s->oldest = o->newer;
        if (s->newest == o)
            s->newest = NULL;
        motion_plan_free(&o->plan);
        free(o);
        s->live--;
    }
}

size_t motion_stream_backlog(struct motion_stream *s)
{
    reclaim(s);
    return s->live;
}

static int fail(struct motion_stream *s, int st, const char *msg)
{
    if (!s->status) {
        s->status = st;
        snprintf(s->err, sizeof s->err, "%s", msg);
    }
    return st;
}

/* Empties a plan but keeps its arrays (and their pages) for the next window. */
static void plan_reset(struct motion_plan *p)
{
    p->nseg = p->narc = p->nknot = p->nmarks = p->nios = 0;
    p->k_enter = 0;
    p->v_enter = p->enter_deficit = p->total_time_s = p->total_len_mm = 0;
    memset(&p->info, 0, sizeof p->info);
}

/* Hands a planned chunk to the executor (or drops it: a check). */
static int publish(struct motion_stream *s, struct motion_chunk *c)
{
    if (!s->m) {
        motion_plan_free(&c->plan);
        free(c);
        return MOTION_OK;
    }
    atomic_init(&c->next, NULL);
    atomic_init(&c->retired, 0);
    c->newer = NULL;
    if (!s->newest && !s->oldest) {
        atomic_store_explicit(&s->m->stream_head, c, memory_order_release);
    } else {
        struct motion_chunk *expect = NULL;
        if (!atomic_compare_exchange_strong(&s->newest->next, &expect, c)) {
            motion_plan_free(&c->plan);
            free(c);
            return fail(s, MOTION_ERR_STARVED, "the machine ran out of planned path before "
                        "the next part was ready");
        }
    }
    if (s->newest)
        s->newest->newer = c;
    else
        s->oldest = c;
    s->newest = c;
    s->live++;
    return MOTION_OK;
}

/* XYZ length and largest A B C turn of a move from `from` (an arc's chord: short of its
 * length, which only makes the tail longer than counted). */
static void move_size(const struct canon_cmd *c, const double *from, double *mm, double *deg)
{
    double d2 = 0, a = 0;
    for (int k = 0; k < 3; k++)
        d2 += (move_end(c)[k] - from[k]) * (move_end(c)[k] - from[k]);
    for (int k = 3; k < 6; k++)
        a = fmax(a, fabs(move_end(c)[k] - from[k]));
    *mm = sqrt(d2);
    *deg = a;
}

/* The raw move after which to cut: the last with a tail long enough behind it; SIZE_MAX
 * when there is none (yet). */
static size_t choose_cut(const struct motion_stream *s)
{
    double *from = malloc(s->n * sizeof(double[KINS_POSE_DIM]));
    if (!from)
        return SIZE_MAX;
    double at[KINS_POSE_DIM];
    memcpy(at, s->start, sizeof at);
    for (size_t i = 0; i < s->n; i++) {
        memcpy(&from[i * KINS_POSE_DIM], at, sizeof at);
        if (is_move(s->win[i].type))
            memcpy(at, move_end(&s->win[i]), sizeof at);
    }
    double mm = 0, deg = 0;
    size_t cut = SIZE_MAX, moves_after = 0, second_last = SIZE_MAX;
    for (size_t i = s->n; i-- > s->nctx;) {
        if (!is_move(s->win[i].type))
            continue;
        if (moves_after > 0 && (mm >= s->tail_mm || deg >= s->tail_deg)) {
            cut = i;
            break;
        }
        if (moves_after == 1)
            second_last = i;
        double a, b;
        move_size(&s->win[i], &from[i * KINS_POSE_DIM], &a, &b);
        mm += a, deg += b;
        moves_after++;
    }
    free(from);
    if (cut == SIZE_MAX && s->n >= STREAM_WINDOW_MAX)
        cut = second_last;     /* a short tail: slower near the cut, still safe */
    return cut;
}

/* The state the window's first `end` commands leave for what follows: where the path is,
 * the G64 tolerance, and (from the committed commands) the spindle, which the path build of
 * the next window starts from. */
static void carry_state(struct motion_stream *s, size_t end)
{
    for (size_t i = 0; i < end; i++) {
        const struct canon_cmd *c = &s->win[i];
        if (is_move(c->type)) {
            memcpy(s->start, move_end(c), sizeof s->start);
            s->start_tcp = c->tcp;
            s->start_len_mm = c->tool_len_mm;
        } else if (c->type == CANON_PATH_MODE)
            s->tol_mm = motion_blend_tolerance(&s->pm->cfg, c);
        else if (i < s->nctx)
            continue;
        else if (c->type == CANON_SPINDLE_ON)
            s->pm->io.dir = c->value < 0 ? -1 : 1;
        else if (c->type == CANON_SPINDLE_STOP)
            s->pm->io.dir = 0;
        else if (c->type == CANON_SPINDLE_SPEED)
            s->pm->io.rpm = fabs(c->value);
    }
}

/* The window's first command after a cut or a sync: the path mode in force, stated. */
static struct canon_cmd path_mode_cmd(const struct motion_stream *s, const struct canon_cmd *at)
{
    struct canon_cmd pm = *at;
    pm.type = CANON_PATH_MODE;
    pm.value = s->tol_mm;
    pm.ivalue = s->tol_mm > 0 ? 640 : 610;
    return pm;
}

/* Starts the next window after the cut: the path mode in force, the move cut after
 * (context), and everything after it. */
static void shift_window(struct motion_stream *s, size_t cut)
{
    carry_state(s, cut);
    struct canon_cmd pm = path_mode_cmd(s, &s->win[cut]);
    /* (add() keeps one spare entry, for cut 0) */
    memmove(&s->win[1], &s->win[cut], (s->n - cut) * sizeof *s->win);
    s->win[0] = pm;
    s->n = s->n - cut + 1;
    s->fresh = 0;
    s->nctx = 2;
}

/* After a sync: the next window starts at rest where this one ended, with the path mode and
 * the spindle it left. */
static void restart_window(struct motion_stream *s)
{
    carry_state(s, s->n);
    s->win[0] = path_mode_cmd(s, &s->win[s->n ? s->n - 1 : 0]);
    s->n = 1;
    s->nctx = 0;
    s->fresh = 0;
    s->v_enter = 0;
}

/* Plans the window; with final, all of it (the program's end), else up to a cut when one
 * fits (returns MOTION_OK and plans nothing when not: more commands are needed). */
static int plan_window(struct motion_stream *s, bool final, bool sync)
{
    struct motion *pm = s->pm;
    size_t cut = final ? SIZE_MAX : choose_cut(s);
    if (!final && cut == SIZE_MAX)
        return MOTION_OK;
    struct canon_prog raw = { .cmds = s->win, .count = s->n, .cap = s->cap };
    memcpy(raw.start, s->start, sizeof raw.start);
    raw.start_tcp = s->start_tcp;
    raw.start_tool_len_mm = s->start_len_mm;
    size_t *ends = malloc((s->n ? s->n : 1) * sizeof *ends);
    struct canon_prog blended;
    struct motion_blend_abc *abc = NULL;
    size_t nb = 0;
    if (!ends)
        return fail(s, MOTION_ERR_NOMEM, "out of memory planning the program");
    int st = motion_blend_program_map(&pm->cfg, &raw, &blended, &nb, &abc, ends);
    if (st) {
        free(ends);
        return fail(s, st, "out of memory planning the program");
    }
    plan_reset(&pm->plan);        /* (a chunk handed over took the arrays before) */
    pm->plan.names_in = s->m ? &s->m->names : &pm->names;
    pm->pb_at[0] = s->nctx ? ends[s->nctx - 1] : 0;
    pm->pb_at[1] = final ? SIZE_MAX : ends[cut];
    free(ends);
    st = motion_path_build(pm, nb ? &blended : &raw, abc, pm->msg, sizeof pm->msg);
    canon_prog_free(&blended);
    free(abc);
    struct motion_plan *p = &pm->plan;
    size_t s_enter = pm->pb_seg[0], s_leave = final ? p->nseg : pm->pb_seg[1];
    pm->pb_at[0] = pm->pb_at[1] = SIZE_MAX;
    if (st)
        return fail(s, st, pm->msg);
    if (!final && (s_leave >= p->nseg || s_leave <= s_enter)) {
        plan_reset(p);           /* nothing to commit, or no path after the cut: wait */
        return MOTION_OK;
    }
    p->k_enter = s_enter < p->nseg ? p->segs[s_enter].k0 : 0;
    p->v_enter = s->v_enter;
    if ((st = motion_plan_profile(pm, pm->msg, sizeof pm->msg)))
        return fail(s, st, pm->msg);
    double L[KINS_MAX_JOINTS];
    if (p->nseg == 0 && motion_path_inverse(pm, s->start_tcp, s->start_len_mm, s->start, L)
        != KINS_OK)
        return fail(s, MOTION_ERR_UNREACHABLE, "the program's start position is outside the "
                    "machine's reach");
    s->deficit = fmax(s->deficit, p->enter_deficit);
    struct motion_chunk *c = calloc(1, sizeof *c);
    if (!c)
        return fail(s, MOTION_ERR_NOMEM, "out of memory planning the program");
    size_t k_enter = p->k_enter;
    size_t k_leave = final ? (p->nknot ? p->nknot - 1 : 0) : p->segs[s_leave].k0;
    double len = 0;
    for (size_t j = s_enter; j < s_leave; j++)
        len += p->segs[j].xyz_len_mm;
    double off = s->dist_done_mm - (s_enter < p->nseg ? p->segs[s_enter].dist0_mm : 0);
    for (size_t j = 0; j < p->nseg; j++)
        p->segs[j].dist0_mm += off;
    double t = p->nknot ? (final ? p->total_time_s : p->kt[k_leave]) - p->kt[k_enter] : 0;
    c->k_enter = k_enter;
    c->s_enter = s_enter;
    c->k_leave = k_leave;
    c->s_leave = s_leave;
    c->t_leave_s = p->nknot ? p->kt[k_leave] : 0;
    c->last = final && !sync;
    c->sync = sync;
    c->t0_s = s->t_done_s;
    s->v_enter = final ? 0 : p->kv[k_leave];
    s->t_done_s += t;
    s->dist_done_mm += len;
    s->info.time_s += t;
    s->info.length_mm += len;
    s->info.segments += s_leave - s_enter;
    for (size_t j = s_enter; j < s_leave; j++)
        s->info.samples += p->segs[j].nk;
    for (int l = 0; l < pm->nj; l++)
        s->info.max_leg_vel_mm_s[l] = fmax(s->info.max_leg_vel_mm_s[l],
                                           p->info.max_leg_vel_mm_s[l]);
    s->info.limited_by_legs += p->info.limited_by_legs;
    s->info.limited_by_kin_tol += p->info.limited_by_kin_tol;
    s->info.stops_held += p->info.stops_held;
    s->windows++;
    if (s->m) {                  /* the executor's from now on; a check keeps the arrays */
        c->plan = *p;
        memset(p, 0, sizeof *p);
        motion_plan_reserve(p, c->plan.capseg, c->plan.caparc, c->plan.capknot);
    }
    if (!final)
        shift_window(s, cut);
    else if (sync)
        restart_window(s);
    else
        s->n = 0;
    return publish(s, c);
}

/* One command past the G64 Q filter into the window. */
static int take(void *ctx, const struct canon_cmd *cmd)
{
    struct motion_stream *s = ctx;
    if (s->ended)
        return MOTION_OK;       /* after M2/M30 nothing runs (motion_path_build's rule) */
    if (s->n + 1 >= s->cap) {       /* one spare: shift_window may need it */
        size_t cap = s->cap ? 2 * s->cap : 4096;
        struct canon_cmd *w = realloc(s->win, cap * sizeof *w);
        if (!w)
            return fail(s, MOTION_ERR_NOMEM, "out of memory planning the program");
        s->win = w, s->cap = cap;
    }
    struct canon_cmd *c = &s->win[s->n++];
    *c = *cmd;
    c->text = NULL;             /* payloads are the interpreter's: motion reads none */
    c->setting = NULL;
    if (cmd->type == CANON_PROGRAM_END) {
        s->ended = 1;
        return MOTION_OK;
    }
    /* plan once the new commands are a whole window and at least what the window carries
     * over (the tail): each command is planned about twice, however long the tail */
    if (++s->fresh >= STREAM_WINDOW && s->fresh % 256 == 0 &&
        (2 * s->fresh >= s->n || s->n >= STREAM_WINDOW_MAX))
        return plan_window(s, false, false);
    return MOTION_OK;
}

int motion_stream_add(struct motion_stream *s, const struct canon_cmd *cmd)
{
    if (s->status)
        return s->status;
    int st = motion_merge_add(&s->merge, cmd, take, s);
    return st ? st : s->status;
}

int motion_stream_finish(struct motion_stream *s)
{
    if (s->status)
        return s->status;
    int st = motion_merge_flush(&s->merge, take, s);
    return st ? st : plan_window(s, true, false);
}

int motion_stream_sync(struct motion_stream *s)
{
    if (s->status)
        return s->status;
    int st = motion_merge_flush(&s->merge, take, s);
    return st ? st : plan_window(s, true, true);
}

void motion_stream_restart_at(struct motion_stream *s, const double pose[KINS_POSE_DIM])
{
    memcpy(s->start, pose, sizeof s->start);
    s->start_tcp = 0;             /* (G38 is refused under G43.4) */
    s->start_len_mm = 0;
}

bool motion_stream_help(struct motion_stream *s)
{
    return motion_caps_help(s->pm);
}

const char *motion_stream_error(const struct motion_stream *s)
{
    return s->status ? s->err : "";
}

void motion_stream_info(const struct motion_stream *s, struct motion_stream_info *out)
{
    memset(out, 0, sizeof *out);
    out->plan = s->info;
    out->plan.merged = s->merge.merged;
    out->windows = s->windows;
    out->entry_shortfall = s->deficit;
    out->window_capacity = s->cap;
}

void motion_stream_destroy(struct motion_stream *s)
{
    if (!s)
        return;
    while (s->oldest) {
        struct motion_chunk *o = s->oldest;
        s->oldest = o->newer;
        motion_plan_free(&o->plan);
        free(o);
    }
    motion_destroy(s->pm);
    free(s->win);
    free(s);
}

void motion_stream_bind(struct motion_stream *s, struct motion *m)
{
    s->m = m;
}

const double *motion_stream_start(const struct motion_stream *s)
{
    return s->start0;
}
