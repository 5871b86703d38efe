/* motion_blend.c: G64 P corner rounding: trims straight feed moves and joins them by tangent arcs. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_blend.h"
#include "motion/motion_priv.h"

#define LINE_EPS_MM 1e-9       /* shorter XYZ motion is not a line to blend (as motion_path) */

/* What the program says about one command, for finding and making the blends. */
struct blend_rec {
    double from[6];          /* pose the command starts from, mm / deg */
    double len_mm;           /* XYZ length of a straight feed move, 0 for anything else */
    double dir[3];           /* its unit XYZ direction */
    double tol_mm;           /* G64 tolerance in force at the command, 0 = exact path */
    double arc_tol_mm;       /* the part of it a blend arc may cut the corner by (with jerk
                              * limits the rest is the rounding's, JERK_ROUND_SHARE) */
    double trim_in_mm;       /* length given to the blend at its start, mm */
    double trim_out_mm;      /* length given to the blend at its end, mm */
    size_t next;             /* command the end blends into (0 = none; it is always > this) */
    struct motion_blend_geom g; /* the blend at the end */
};

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* a x b into o. */
static void cross3(const double *a, const double *b, double *o)
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

/* The arc tangent to both lines at distance tol from the corner. With the turning angle
 * theta, the centre lies on the bisector at r / cos(theta/2) from the corner, so the arc's
 * midpoint is r / cos(theta/2) - r = r (1 - cos(theta/2)) / cos(theta/2) from it; setting
 * that to tol gives r = tol cos(theta/2) / (1 - cos(theta/2)) (the interior angle alpha =
 * pi - theta: cos(theta/2) = sin(alpha/2)); the tangent points lie r tan(theta/2) from the
 * corner. 1 - cos is written 2 sin^2(theta/4) so that gentle corners keep their digits. */
int motion_blend_corner(const double d1[3], const double d2[3], double len1_mm, double len2_mm,
                        double tol_mm, struct motion_blend_geom *g)
{
    double x[3];
    cross3(d1, d2, x);
    double sn = sqrt(dot3(x, x)), theta = atan2(sn, dot3(d1, d2));
    if (!(tol_mm > 0) || !(theta >= MOTION_BLEND_MIN_TURN_RAD) || !(sn > 1e-6))
        return 0;
    double half = 0.5 * theta, c = cos(half), q = sin(0.5 * half);
    double one_minus_c = 2 * q * q, tn = tan(half);
    double r = tol_mm * c / one_minus_c, t = r * tn;
    double tmax = 0.5 * fmin(len1_mm, len2_mm);   /* the other end may blend too */
    if (t > tmax) {
        t = tmax;
        r = t / tn;
    }
    if (!(r >= MOTION_BLEND_MIN_RADIUS_MM))
        return 0;
    g->turn_rad = theta;
    g->radius_mm = r;
    g->trim_mm = t;
    g->dev_mm = r * one_minus_c / c;
    return 1;
}

/* The G64 tolerance a PATH_MODE command sets (the rule motion_path applies to joints). */
double motion_blend_tolerance(const struct motion_config *c, const struct canon_cmd *pm)
{
    if (pm->value > 0)
        return pm->value;
    return pm->ivalue == 640 ? c->blend_tol_mm : 0;
}

double motion_blend_start(const struct motion_config *c, const struct canon_prog *p)
{
    if (p->start_path_mode == 610 || p->start_path_mode == 611)
        return 0;
    return p->start_path_mode == 640 && p->start_path_tol_mm > 0 ? p->start_path_tol_mm
                                                                  : c->blend_tol_mm;
}

/* Commands that may sit between two moves without stopping the blend between them (they
 * change nothing on the path: the next move carries its own feed). */
static int transparent(enum canon_type t)
{
    return t == CANON_FEED_RATE || t == CANON_FEED_MODE || t == CANON_PATH_MODE ||
           t == CANON_COMMENT || t == CANON_OFFSETS || t == CANON_SPINDLE_SPEED ||
           t == CANON_SETTING;
}

/* Start poses, straight-feed lengths and directions, and the tolerance at every command. */
static void scan(const struct motion_config *cfg, const struct canon_prog *in,
                 struct blend_rec *rec)
{
    double at[6], tol = motion_blend_start(cfg, in);
    double arc_share = motion_blend_share(motion_jerk_window_s(cfg));
    double at_len = in->start_tcp ? in->start_tool_len_mm : 0;
    int at_tcp = in->start_tcp;
    memcpy(at, in->start, sizeof at);
    for (size_t i = 0; i < in->count; i++) {
        const struct canon_cmd *c = &in->cmds[i];
        struct blend_rec *b = &rec[i];
        memcpy(b->from, at, sizeof at);
        b->tol_mm = tol;
        b->arc_tol_mm = tol * arc_share;
        /* a move after G43.4 or G49 starts from a pose in other coordinates: never blended
         * (the planner stops there) */
        int moves = c->type == CANON_TRAVERSE || c->type == CANON_FEED || c->type == CANON_ARC;
        double len_c = c->tcp ? c->tool_len_mm : 0;
        int switched = moves && (c->tcp != at_tcp || len_c != at_len);
        if (moves)
            at_tcp = c->tcp, at_len = len_c;
        if (c->type == CANON_FEED && !switched && !c->sync) {  /* (G33 follows the spindle:
                                                                * never rounded) */
            double d[3] = {c->end[0] - at[0], c->end[1] - at[1], c->end[2] - at[2]};
            double len = sqrt(dot3(d, d));
            if (len > LINE_EPS_MM) {
                b->len_mm = len;
                for (int k = 0; k < 3; k++)
                    b->dir[k] = d[k] / len;
            }
        }
        if (c->type == CANON_PATH_MODE)
            tol = motion_blend_tolerance(cfg, c);
        if (c->type == CANON_TRAVERSE || c->type == CANON_FEED || c->type == CANON_ARC)
            memcpy(at, c->end, sizeof at);
        else if (c->type == CANON_PROBE)   /* the next move starts where the probe stops */
            memcpy(at, c->probe_stop, sizeof at);
    }
}

/* With jerk limits, where half of P is below the rounding's share of KINEMATIC_TOLERANCE
 * (motion_round_budget_mm: the average may round the path by more than the arc cuts the
 * corner), whether blend arc g (under G64 P tol_mm) is shorter than the moving average's
 * window T at the fastest the arc may be passed (its chord cap, chord period cp:
 * motion_chord.c). The average then spans the whole arc and sees a corner: the arc's
 * curvature holds the speed down around it, and the path's acceleration on either side
 * spreads the window's samples beyond the rounding's estimate (a constant speed on a
 * constant curvature). Such a joint is left sharp: passed with a velocity jump whose cut,
 * the average's with the acceleration's, the junction rule keeps within the arc's share of
 * P, or stopped at, where the leader rests T (motion_junction_speed). */
static int shorter_than_window(const struct motion_config *cfg, double T, double cp,
                               double tol_mm, const struct motion_blend_geom *g)
{
    if (!(T > 0) || !(cfg->kin_tol_mm > 0))
        return 0;
    double round = motion_round_budget_mm(cfg, JERK_ROUND_SHARE * tol_mm);
    if (!(round > tol_mm * motion_blend_share(T)))
        return 0;
    return g->radius_mm * g->turn_rad < sqrt(8 * round * g->radius_mm) / cp * T;
}

/* Finds the corners to round: a straight feed move under G64 P followed (past commands that
 * do not stop the path) by another straight feed move. Returns the count. */
static size_t find_blends(const struct motion_config *cfg, const struct canon_prog *in,
                          struct blend_rec *rec)
{
    size_t n = 0;
    double T = motion_jerk_window_s(cfg), cp = motion_chord_period(cfg);
    for (size_t i = 0; i < in->count; i++) {
        if (in->cmds[i].type == CANON_PROGRAM_END)
            break;
        if (rec[i].len_mm <= 0 || rec[i].tol_mm <= 0)
            continue;
        size_t j = i + 1;
        while (j < in->count && transparent(in->cmds[j].type))
            j++;
        if (j >= in->count || rec[j].len_mm <= 0)
            continue;
        struct motion_blend_geom g;
        if (!motion_blend_corner(rec[i].dir, rec[j].dir, rec[i].len_mm, rec[j].len_mm,
                                 rec[i].arc_tol_mm, &g) ||
            shorter_than_window(cfg, T, cp, rec[i].tol_mm, &g))
            continue;
        rec[i].g = g;
        rec[i].next = j;
        rec[i].trim_out_mm = g.trim_mm;
        rec[j].trim_in_mm = g.trim_mm;
        n++;
    }
    return n;
}

/* Pose at XYZ distance s along the straight move cmd starting at from (all six axes
 * linear in s, as the planner moves them). */
static void line_pose(const double *from, const struct canon_cmd *c, double len_mm, double s,
                      double pose[6])
{
    double u = s / len_mm;
    for (int k = 0; k < 6; k++)
        pose[k] = from[k] + u * (c->end[k] - from[k]);
}

/* The plane-0 arc of the blend at the end of command i, into line j. The arc belongs to the
 * move it enters (line, feed); it goes from the pose at line i's trim point to the pose at
 * line j's (A B C between them along the cubic of motion_blend_abc). t1 is where line i now
 * ends (the arc's start). */
static void blend_arc(const struct canon_prog *in, const struct blend_rec *rec, size_t i,
                      const double t1[6], struct canon_cmd *a)
{
    const struct blend_rec *bi = &rec[i], *bj = &rec[bi->next];
    const struct canon_cmd *cj = &in->cmds[bi->next];
    double n[3], u[3];
    cross3(bi->dir, bj->dir, n);
    double nl = sqrt(dot3(n, n));
    for (int k = 0; k < 3; k++)
        n[k] /= nl;
    cross3(n, bi->dir, u);   /* toward the centre: the side the path turns to */
    memset(a, 0, sizeof *a);
    a->type = CANON_ARC;
    a->line = cj->line;
    a->file = cj->file;
    a->has_n = cj->has_n;
    a->n_number = cj->n_number;
    a->feed_mm_min = cj->feed_mm_min;
    a->compensated = cj->compensated;
    a->tcp = cj->tcp;
    a->tool_len_mm = cj->tool_len_mm;
    line_pose(bj->from, cj, bj->len_mm, bi->g.trim_mm, a->end);
    if (cj->inverse_time_min > 0)  /* G93: keep the entered move's speed on the arc */
        a->inverse_time_min = cj->inverse_time_min * bi->g.radius_mm * bi->g.turn_rad /
                              bj->len_mm;
    for (int k = 0; k < 3; k++) {
        a->arc.center[k] = t1[k] + bi->g.radius_mm * u[k];
        a->arc.normal[k] = n[k];
    }
    a->arc.rotation = 1;     /* counter-clockwise about d1 x d2: from d1 toward d2 */
    a->arc.plane = 0;
}

/* A B C rate of a straight feed move, deg per mm of XYZ path. */
static void abc_rate(const struct blend_rec *b, const struct canon_cmd *c, double rate[3])
{
    for (int k = 0; k < 3; k++)
        rate[k] = (c->end[3 + k] - b->from[3 + k]) / b->len_mm;
}

/* Writes the blended program: trimmed lines, each followed by its blend arc; abc (out->count
 * entries) marks the arcs and the lines' A B C rates at their ends. */
static void emit(const struct canon_prog *in, const struct blend_rec *rec, struct canon_prog *out,
                 struct motion_blend_abc *abc, size_t *ends)
{
    memcpy(out->start, in->start, sizeof out->start);
    out->start_tcp = in->start_tcp;
    out->start_path_mode = in->start_path_mode;
    out->start_path_tol_mm = in->start_path_tol_mm;
    out->start_tool_len_mm = in->start_tool_len_mm;
    for (size_t i = 0; i < in->count; i++) {
        /* straight into out's array (sized for all), without the payloads: motion reads none */
        struct canon_cmd *c = &out->cmds[out->count++];
        *c = in->cmds[i];
        c->text = NULL;
        c->setting = NULL;
        const struct blend_rec *b = &rec[i];
        if (b->trim_in_mm > 0 || b->trim_out_mm > 0) {
            double keep = b->len_mm - b->trim_in_mm - b->trim_out_mm;
            line_pose(b->from, &in->cmds[i], b->len_mm, b->len_mm - b->trim_out_mm, c->end);
            if (c->inverse_time_min > 0)   /* G93: the shorter line keeps its speed */
                c->inverse_time_min *= fmax(keep, 0) / b->len_mm;
        }
        if (b->next) {
            struct motion_blend_abc *ab = &abc[out->count];
            blend_arc(in, rec, i, c->end, &out->cmds[out->count++]);
            ab->blend = 1;
            abc_rate(b, &in->cmds[i], ab->rate0);
            abc_rate(&rec[b->next], &in->cmds[b->next], ab->rate1);
        }
        if (ends)
            ends[i] = out->count;
    }
}

/* See motion_blend.h. */
int motion_blend_program(const struct motion_config *c, const struct canon_prog *in,
                         struct canon_prog *out, size_t *nblends, struct motion_blend_abc **abc)
{
    return motion_blend_program_map(c, in, out, nblends, abc, NULL);
}

int motion_blend_program_map(const struct motion_config *c, const struct canon_prog *in,
                             struct canon_prog *out, size_t *nblends,
                             struct motion_blend_abc **abc, size_t *ends)
{
    if (ends)
        for (size_t i = 0; i < in->count; i++)
            ends[i] = i + 1;
    canon_prog_init(out);
    *nblends = 0;
    if (abc)
        *abc = NULL;
    if (in->count == 0)
        return MOTION_OK;
    struct blend_rec *rec = calloc(in->count, sizeof *rec);
    if (!rec)
        return MOTION_ERR_NOMEM;
    scan(c, in, rec);
    size_t n = find_blends(c, in, rec);
    struct motion_blend_abc *ab = n ? calloc(in->count + n, sizeof *ab) : NULL;
    if (n && ab) {             /* the blended program's size is known: one allocation, not a
                                * dozen growing copies per streamed window */
        out->cmds = malloc((in->count + n) * sizeof *out->cmds);
        out->cap = out->cmds ? in->count + n : 0;
    }
    int st = n && (!ab || !out->cmds) ? MOTION_ERR_NOMEM : MOTION_OK;
    if (n && !st)
        emit(in, rec, out, ab, ends);
    free(rec);
    if (st || !abc)
        free(ab);
    if (st) {
        canon_prog_free(out);
        return st;
    }
    if (abc)
        *abc = ab;
    *nblends = n;
    return MOTION_OK;
}
