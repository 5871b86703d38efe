/* motion_merge.c: G64 Q, LinuxCNC's naive CAM detector (see motion_merge.h). */
#include <math.h>
#include <string.h>

#include "motion/motion.h"
#include "motion/motion_merge.h"

void motion_merge_init(struct motion_merge *g, const double start[KINS_POSE_DIM], int tcp,
                       double len_mm, int path_mode)
{
    memset(g, 0, sizeof *g);
    memcpy(g->at, start, sizeof g->at);
    g->at_tcp = tcp;
    g->at_len_mm = tcp ? len_mm : 0;
    g->continuous = path_mode == 0 || path_mode == 640;
}

/* Whether a feed may be held at all: a straight feed in G64 with a Q, at units per minute,
 * not made by G141/G142 nor a spline's chord, not synchronised with the spindle, that keeps A B C and G43.4's state, and moves. */
static int holdable(const struct motion_merge *g, const struct canon_cmd *c)
{
    if (c->type != CANON_FEED || !g->continuous || !(g->tol_mm > 0) || c->compensated ||
        c->sync ||
        c->spline || c->inverse_time_min > 0 || c->tcp != g->at_tcp ||
        (c->tcp && c->tool_len_mm != g->at_len_mm))
        return 0;
    for (int i = 3; i < KINS_POSE_DIM; i++)
        if (c->end[i] != g->at[i])
            return 0;
    return c->end[0] != g->at[0] || c->end[1] != g->at[1] || c->end[2] != g->at[2];
}

double motion_dist2_seg(const double p[3], const double a[3], const double d[3], double n2)
{
    double w[3], u = 0, e2 = 0;
    for (int i = 0; i < 3; i++)
        w[i] = p[i] - a[i], u += w[i] * d[i];
    u = n2 > 0 ? fmin(1, fmax(0, u / n2)) : 0;
    for (int i = 0; i < 3; i++)
        e2 += (w[i] - u * d[i]) * (w[i] - u * d[i]);
    return e2;
}

double motion_dist_seg(const double p[3], const double a[3], const double b[3])
{
    double d[3], n2 = 0;
    for (int i = 0; i < 3; i++)
        d[i] = b[i] - a[i], n2 += d[i] * d[i];
    return sqrt(motion_dist2_seg(p, a, d, n2));
}

/* Whether holdable feed c joins the run: same feed and file, room left, and every end of the
 * run within Q of the line from the run's start to c's end. */
static int joins(const struct motion_merge *g, const struct canon_cmd *c)
{
    if (g->n >= MOTION_MERGE_MAX || c->feed_mm_min != g->last.feed_mm_min ||
        c->file != g->last.file)
        return 0;
    for (int k = 0; k < g->n; k++)
        if (motion_dist_seg(g->pts[k], g->at, c->end) > g->tol_mm)
            return 0;
    return 1;
}

int motion_merge_flush(struct motion_merge *g, motion_merge_emit_fn emit, void *ctx)
{
    if (!g->n)
        return 0;
    g->merged += (size_t)(g->n - 1);
    g->n = 0;
    memcpy(g->at, g->last.end, sizeof g->at);
    return emit(ctx, &g->last);
}

int motion_merge_add(struct motion_merge *g, const struct canon_cmd *c,
                     motion_merge_emit_fn emit, void *ctx)
{
    int st;
    if (holdable(g, c)) {
        if (g->n && !joins(g, c) && (st = motion_merge_flush(g, emit, ctx)))
            return st;
        memcpy(g->pts[g->n++], c->end, sizeof g->pts[0]);
        g->last = *c;
        return 0;
    }
    if ((st = motion_merge_flush(g, emit, ctx)))
        return st;
    if (c->type == CANON_PATH_MODE) {
        g->continuous = c->ivalue == 640;
        g->tol_mm = g->continuous ? c->naive_tol_mm : 0;
    } else if (c->type == CANON_TRAVERSE || c->type == CANON_FEED || c->type == CANON_ARC) {
        memcpy(g->at, c->end, sizeof g->at);
        g->at_tcp = c->tcp;
        g->at_len_mm = c->tcp ? c->tool_len_mm : 0;
    }
    return emit(ctx, c);
}

int motion_merge_wanted(const struct canon_prog *p)
{
    for (size_t i = 0; i < p->count; i++)
        if (p->cmds[i].type == CANON_PATH_MODE && p->cmds[i].ivalue == 640 &&
            p->cmds[i].naive_tol_mm > 0)
            return 1;
    return 0;
}

static int to_prog(void *ctx, const struct canon_cmd *c)
{
    return canon_prog_sink(ctx, c);
}

int motion_merge_program(const struct canon_prog *in, struct canon_prog *out, size_t *merged)
{
    struct motion_merge g;
    canon_prog_init(out);
    memcpy(out->start, in->start, sizeof out->start);
    out->start_tcp = in->start_tcp;
    out->start_tool_len_mm = in->start_tool_len_mm;
    out->start_path_mode = in->start_path_mode;
    out->start_path_tol_mm = in->start_path_tol_mm;
    motion_merge_init(&g, in->start, in->start_tcp, in->start_tool_len_mm, in->start_path_mode);
    for (size_t i = 0; i < in->count; i++)
        if (motion_merge_add(&g, &in->cmds[i], to_prog, out))
            goto fail;
    if (motion_merge_flush(&g, to_prog, out))
        goto fail;
    *merged = g.merged;
    return 0;
fail:
    canon_prog_free(out);
    return -1;
}
