/* comp5.c: five-axis tool radius compensation G141/G142 (the paper's algorithm) over a run of blocks. */
#include "interp/comp5.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "interp/comp5_join.h"
#include "kins/kins.h"

#define COMP5_DEG_TO_RAD (M_PI / 180.0)

static const char *const comp5_msgs[COMP5_STATUS_COUNT] = {
    [COMP5_OK] = "ok",
    [COMP5_ERR_SINGLE_BLOCK] = "G141/G142 needs at least two blocks with different points",
    [COMP5_ERR_ZERO_LENGTH] = "G141/G142 block does not move X, Y or Z",
    [COMP5_ERR_ALONG_AXIS] = "G141/G142 move runs along the tool axis: no side to offset to",
    [COMP5_ERR_MIXED_SIDES] = "G141 and G142 mixed in one compensated path",
    [COMP5_ERR_RADIUS] = "G141/G142 tool radius missing, zero or negative",
    [COMP5_ERR_GOUGE] = "G141/G142 inside corner: the tool would gouge (segment too short)",
    [COMP5_ERR_GOUGE_CONTOUR] = "G141/G142 path would gouge its programmed contour",
    [COMP5_ERR_NO_MEMORY] = "G141/G142: out of memory for the gouge check of the path",
    [COMP5_ERR_SINK] = "G141/G142 moves were refused by the motion queue",
    [COMP5_ERR_SIDE] = "G141/G142 side must be 141 or 142",
};

/* The text of a status. */
const char *comp5_strerror(int status)
{
    if (status < 0 || status >= COMP5_STATUS_COUNT)
        return "unknown compensation status";
    return comp5_msgs[status];
}

/* An idle compensator (no run open). */
void comp5_init(struct comp5 *c)
{
    memset(c, 0, sizeof *c);
}

/* Drops the record of a run left open (the interpreter stopped on another error). */
void comp5_free(struct comp5 *c)
{
    comp5_gouge_free(&c->gouge);
    c->active = 0;
    c->nblocks = 0;
}

/* Where the emitted moves have left the tool. */
const double *comp5_tool_pos(const struct comp5 *c)
{
    return c->tool_pos;
}

/* The last error in words. */
const char *comp5_errmsg(const struct comp5 *c)
{
    return c->err_msg[0] ? c->err_msg : comp5_strerror(COMP5_OK);
}

/* "G141" or "G142". */
static const char *comp5_code(int side)
{
    return side == 142 ? "G142" : "G141";
}

/* Records an error (line and words), drops the run, and returns status. */
__attribute__((format(printf, 4, 5)))
static int comp5_fail(struct comp5 *c, int status, int line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->err_msg, sizeof c->err_msg, fmt, ap);
    va_end(ap);
    c->err_line = line;
    comp5_free(c);
    return status;
}

/* The paper's step 2: N = Rz(C) Ry(B) Rx(A) [0 0 1], the third column of R. */
void comp5_normal(double a_deg, double b_deg, double c_deg, double n[3])
{
    double a = a_deg * COMP5_DEG_TO_RAD, b = b_deg * COMP5_DEG_TO_RAD;
    double c = c_deg * COMP5_DEG_TO_RAD;
    n[0] = cos(c) * sin(b) * cos(a) + sin(c) * sin(a);
    n[1] = sin(c) * sin(b) * cos(a) - cos(c) * sin(a);
    n[2] = cos(b) * cos(a);
}

/* N: the paper's R [0 0 1], or under G43.4 the tool axis in the program's frame. */
void comp5_axis(const struct kins_tool_frame *tf, const double abc[3], double n[3])
{
    if (tf)
        kins_tcp_tool_dir(tf, abc, n);
    else
        comp5_normal(abc[0], abc[1], abc[2], n);
}

static int offset_point_n(const double from[6], const double to[6], int side,
                          double radius_mm, const double p[6], const double *nt, double out[6]);

/* The paper's steps 1..4 for one point: p + s W unit(T x N), T from `from` to `to`, N from
 * p's orientation; s = +1 right (G141), -1 left (G142). */
int comp5_offset_point(const double from[6], const double to[6], int side, double radius_mm,
                       const double p[6], double out[6])
{
    return offset_point_n(from, to, side, radius_mm, p, NULL, out);
}

/* The same with the tool axis N given (G43.4), or from p's orientation when nt is NULL. */
static int offset_point_n(const double from[6], const double to[6], int side,
                          double radius_mm, const double p[6], const double *nt, double out[6])
{
    double t[3], n[3], v[3];
    if (side != 141 && side != 142)
        return COMP5_ERR_SIDE;
    if (!(radius_mm >= COMP5_EPS_MM) || !isfinite(radius_mm))
        return COMP5_ERR_RADIUS;
    comp5_sub(to, from, t);
    double len_mm = comp5_len(t);
    if (!(len_mm >= COMP5_EPS_MM))
        return COMP5_ERR_ZERO_LENGTH;
    for (int i = 0; i < 3; i++)
        t[i] /= len_mm;
    if (nt)
        memcpy(n, nt, sizeof n);
    else
        comp5_normal(p[3], p[4], p[5], n);
    comp5_cross(t, n, v);
    double sin_mag = comp5_len(v); /* |T x N| = sin of the angle between motion and axis */
    if (!(sin_mag >= COMP5_MIN_SIN_AXIS))
        return COMP5_ERR_ALONG_AXIS;
    double s = side == 141 ? 1.0 : -1.0;
    for (int i = 0; i < 3; i++) {
        out[i] = p[i] + s * radius_mm * v[i] / sin_mag;
        out[3 + i] = p[3 + i];
    }
    return COMP5_OK;
}

/* The offset line of the programmed segment from -> to: each end offset with its own
 * block's radius and orientation. Errors name the block that ends the segment. */
static int comp5_make_seg(struct comp5 *c, const struct comp5_block *from,
                          const struct comp5_block *to, struct comp5_seg *seg)
{
    double n0[3], n1[3];
    comp5_axis(c->tf, from->point + 3, n0);
    comp5_axis(c->tf, to->point + 3, n1);
    int rc = offset_point_n(from->point, to->point, to->side, from->radius_mm, from->point, n0,
                            seg->a0);
    if (rc == COMP5_OK)
        rc = offset_point_n(from->point, to->point, to->side, to->radius_mm, to->point, n1,
                            seg->a1);
    if (rc == COMP5_ERR_ALONG_AXIS)
        return comp5_fail(c, rc, to->line,
                          "%s: the move from line %d to line %d runs along the tool axis "
                          "(A B C), so there is no side to offset the tool to; compensate "
                          "only moves across the tool axis", comp5_code(to->side), from->line,
                          to->line);
    if (rc != COMP5_OK)
        return comp5_fail(c, rc, to->line, "%s", comp5_strerror(rc));
    comp5_sub(to->point, from->point, seg->dir);
    double len_mm = comp5_len(seg->dir); /* >= COMP5_EPS_MM: checked by offset_point */
    for (int i = 0; i < 3; i++)
        seg->dir[i] /= len_mm;
    seg->t_start = 0.0;
    return COMP5_OK;
}

/* True when two poses coincide within COMP5_EPS_MM / COMP5_EPS_DEG. */
static int comp5_same_pose(const double a[6], const double b[6])
{
    if (comp5_dist(a, b) >= COMP5_EPS_MM)
        return 0;
    for (int i = 3; i < 6; i++)
        if (fabs(a[i] - b[i]) >= COMP5_EPS_DEG)
            return 0;
    return 1;
}

/* Sends one compensated FEED or ARC ending at `end`, carrying block b's line, file and feed;
 * a move that goes nowhere is left out. */
static int comp5_emit(struct comp5 *c, enum canon_type type, const double end[6],
                      const struct canon_arc *arc, const struct comp5_block *b,
                      canon_sink_fn sink, void *ctx)
{
    struct canon_cmd cmd;
    if (comp5_same_pose(c->tool_pos, end))
        return COMP5_OK;
    memset(&cmd, 0, sizeof cmd);
    cmd.type = type;
    cmd.line = b->line;
    cmd.file = b->file;
    memcpy(cmd.end, end, sizeof cmd.end);
    cmd.feed_mm_min = b->feed_mm_min;
    cmd.compensated = c->side;
    if (arc)
        cmd.arc = *arc;
    if (sink && sink(ctx, &cmd) != 0)
        return comp5_fail(c, COMP5_ERR_SINK, b->line,
                          "%s: the compensated move of line %d was refused by the motion "
                          "queue", comp5_code(c->side), b->line);
    struct comp5_gmove m;
    memset(&m, 0, sizeof m);
    m.arc = type == CANON_ARC;
    m.positioning = c->nblocks == 1;
    memcpy(m.p0, c->tool_pos, sizeof m.p0);
    memcpy(m.p1, end, sizeof m.p1);
    if (arc) {
        memcpy(m.center, arc->center, sizeof m.center);
        memcpy(m.normal, arc->normal, sizeof m.normal);
    }
    m.radius_mm = b->radius_mm;
    m.line = b->line;
    m.tf = c->tf;
    memcpy(c->tool_pos, end, sizeof c->tool_pos);
    if (comp5_gouge_add_move(&c->gouge, &m))
        return comp5_fail(c, COMP5_ERR_NO_MEMORY, b->line, "%s", comp5_strerror(COMP5_ERR_NO_MEMORY));
    return COMP5_OK;
}

/* Refuses an inside join that lies before the start of the cut of segment a, or beyond the
 * end of segment b: either segment is too short for the tool (it would gouge). */
static int comp5_check_gouge(struct comp5 *c, const struct comp5_seg *b,
                             const struct comp5_join *j)
{
    const struct comp5_seg *a = &c->seg;
    double len_a = comp5_dist(a->a1, a->a0), len_b = comp5_dist(b->a1, b->a0);
    if ((j->t_a - a->t_start) * len_a < -COMP5_EPS_MM)
        return comp5_fail(c, COMP5_ERR_GOUGE, c->prev.line,
                          "%s inside corner at line %d: the tool (radius %.4g mm) would gouge; "
                          "the segment ending at line %d leaves %.4f mm of offset path but the "
                          "corner needs %.4f mm: lengthen it or use a smaller tool",
                          comp5_code(c->side), c->prev.line, c->prev.radius_mm, c->prev.line,
                          (1.0 - a->t_start) * len_a, (1.0 - j->t_a) * len_a);
    if ((j->u_b - 1.0) * len_b > COMP5_EPS_MM)
        return comp5_fail(c, COMP5_ERR_GOUGE, c->prev.line,
                          "%s inside corner at line %d: the tool (radius %.4g mm) would gouge; "
                          "the next segment is %.4f mm of offset path but the corner needs "
                          "%.4f mm: lengthen it or use a smaller tool", comp5_code(c->side),
                          c->prev.line, c->prev.radius_mm, len_b, j->u_b * len_b);
    return COMP5_OK;
}

/* Cuts the pending segment up to its corner with segment b and makes the join; b's cut
 * will then begin where the join left the tool. */
static int comp5_corner(struct comp5 *c, struct comp5_seg *b, canon_sink_fn sink, void *ctx)
{
    struct comp5_join j;
    struct canon_arc arc;
    int rc;
    comp5_join_corner(&c->seg, b, c->prev.point, c->tf, &j);
    switch (j.kind) {
    case COMP5_JOIN_INSIDE:
        rc = comp5_check_gouge(c, b, &j);
        if (rc == COMP5_OK)
            rc = comp5_emit(c, CANON_FEED, j.point, NULL, &c->prev, sink, ctx);
        b->t_start = j.u_b;
        return rc;
    case COMP5_JOIN_OUTSIDE:
        rc = comp5_emit(c, CANON_FEED, c->seg.a1, NULL, &c->prev, sink, ctx);
        if (rc != COMP5_OK)
            return rc;
        memset(&arc, 0, sizeof arc);
        memcpy(arc.center, c->prev.point, sizeof arc.center);
        memcpy(arc.normal, j.normal, sizeof arc.normal);
        arc.rotation = 1;
        arc.plane = 0;
        return comp5_emit(c, CANON_ARC, b->a0, &arc, &c->prev, sink, ctx);
    case COMP5_JOIN_LINE:
        rc = comp5_emit(c, CANON_FEED, c->seg.a1, NULL, &c->prev, sink, ctx);
        return rc == COMP5_OK ? comp5_emit(c, CANON_FEED, b->a0, NULL, &c->prev, sink, ctx)
                              : rc;
    case COMP5_JOIN_NONE:
    default:
        return comp5_emit(c, CANON_FEED, c->seg.a1, NULL, &c->prev, sink, ctx);
    }
}

/* Checks what a block must carry on its own: a valid side and a usable radius. */
static int comp5_check_block(struct comp5 *c, const struct comp5_block *b)
{
    if (b->side != 141 && b->side != 142)
        return comp5_fail(c, COMP5_ERR_SIDE, b->line, "line %d: compensation side %d is "
                          "neither G141 nor G142", b->line, b->side);
    if (!(b->radius_mm >= COMP5_EPS_MM) || !isfinite(b->radius_mm))
        return comp5_fail(c, COMP5_ERR_RADIUS, b->line,
                          "%s at line %d has no usable tool radius (%g mm): give W (the "
                          "radius, mm) or select a tool with D whose diameter plus wear is "
                          "positive", comp5_code(b->side), b->line, b->radius_mm);
    if (c->active && b->side != c->side)
        return comp5_fail(c, COMP5_ERR_MIXED_SIDES, b->line,
                          "%s at line %d follows %s at line %d in the same compensated path; "
                          "end the path with a block without G141/G142 before changing side",
                          comp5_code(b->side), b->line, comp5_code(c->side), c->prev.line);
    return COMP5_OK;
}

/* Keeps the block's contour point for the gouge check at the end of the run. */
static int comp5_record_point(struct comp5 *c, const struct comp5_block *b)
{
    struct comp5_gpt pt;
    memcpy(pt.p, b->point, sizeof pt.p);
    memcpy(pt.prog_off, b->prog_off_mm, sizeof pt.prog_off);
    pt.unit_mm = b->unit_mm > 0.0 ? b->unit_mm : 1.0;
    pt.radius_mm = b->radius_mm;
    pt.line = b->line;
    if (comp5_gouge_add_point(&c->gouge, &pt))
        return comp5_fail(c, COMP5_ERR_NO_MEMORY, b->line, "%s",
                          comp5_strerror(COMP5_ERR_NO_MEMORY));
    return COMP5_OK;
}

/* Refuses the run when its tool path comes closer than W to any of its programmed contour
 * segments (comp5_gouge.c): names the move's line, the depth and the contour point. */
static int comp5_check_run(struct comp5 *c)
{
    struct comp5_gouge_hit h;
    int found = comp5_gouge_check(&c->gouge, &h);
    if (found < 0)
        return comp5_fail(c, COMP5_ERR_NO_MEMORY, c->prev.line, "%s",
                          comp5_strerror(COMP5_ERR_NO_MEMORY));
    if (!found)
        return COMP5_OK;
    return comp5_fail(c, COMP5_ERR_GOUGE_CONTOUR, h.move_line,
                      "%s %s line %d gouges the contour from line %d to %d by %.4f mm at "
                      "X%.4f Y%.4f Z%.4f (tool radius %.4g mm): %s", comp5_code(c->side),
                      h.positioning ? "positioning move of" : "at", h.move_line, h.seg_line0,
                      h.seg_line1, h.depth_mm, h.point_prog[0] + 0.0, h.point_prog[1] + 0.0,
                      h.point_prog[2] + 0.0, h.radius_mm,
                      h.positioning ? "approach from the compensation side, clear of the contour"
                      : h.tilt      ? "A B C change too much along the move: split it"
                                    : "use a smaller tool, or start a closed contour mid-edge");
}

/* Adds a compensated block: the first is only stored, the second positions the tool at the
 * compensated start, every later one cuts the segment before it up to their corner. */
int comp5_block(struct comp5 *c, const struct comp5_block *b, const double start[6],
                canon_sink_fn sink, void *ctx)
{
    struct comp5_seg seg;
    int rc = comp5_check_block(c, b);
    if (rc != COMP5_OK)
        return rc;
    if (!c->active) {
        c->active = 1;
        c->nblocks = 0;
        c->side = b->side;
        memcpy(c->start, start, sizeof c->start);
        memcpy(c->tool_pos, start, sizeof c->tool_pos);
        comp5_gouge_clear(&c->gouge);
    }
    if (c->nblocks > 0 && comp5_dist(b->point, c->prev.point) < COMP5_EPS_MM)
        return comp5_fail(c, COMP5_ERR_ZERO_LENGTH, b->line,
                          "%s at line %d programs the same X Y Z as line %d: a compensated "
                          "move needs a direction of travel", comp5_code(b->side), b->line,
                          c->prev.line);
    if (c->nblocks > 0) {
        rc = comp5_make_seg(c, &c->prev, b, &seg);
        if (rc == COMP5_OK && c->nblocks == 1)
            rc = comp5_emit(c, CANON_FEED, seg.a0, NULL, &c->prev, sink, ctx);
        else if (rc == COMP5_OK)
            rc = comp5_corner(c, &seg, sink, ctx);
        if (rc != COMP5_OK)
            return rc;
        c->seg = seg;
    }
    c->prev2 = c->prev;
    c->prev = *b;
    c->nblocks++;
    return comp5_record_point(c, b);
}

/* Ends the run: cuts the last segment to its compensated end. */
int comp5_flush(struct comp5 *c, canon_sink_fn sink, void *ctx)
{
    if (!c->active)
        return COMP5_OK;
    if (c->nblocks < 2)
        return comp5_fail(c, COMP5_ERR_SINGLE_BLOCK, c->prev.line,
                          "%s at line %d is alone: compensation takes its direction from two "
                          "consecutive blocks with different points, so program at least two",
                          comp5_code(c->side), c->prev.line);
    int rc = comp5_emit(c, CANON_FEED, c->seg.a1, NULL, &c->prev, sink, ctx);
    if (rc == COMP5_OK)
        rc = comp5_check_run(c);
    if (rc != COMP5_OK)
        return rc;
    comp5_free(c); /* the record lives only as long as its run */
    return COMP5_OK;
}
