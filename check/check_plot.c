/* check_plot.c: the check's sample trace, the no-compensation variant of a program, and its SVG plots. */
#include <ctype.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check/check_priv.h"
#include "check/plot.h"
#include "common/errbuf.h"

static const char *const leg_colors[KINS_MAX_JOINTS] = {
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
    "#bcbd22",
};

/* An empty trace. */
void check_trace_init(struct check_trace *t)
{
    memset(t, 0, sizeof *t);
}

/* Frees the trace's arrays. */
void check_trace_free(struct check_trace *t)
{
    free(t->t_s), free(t->legs_mm), free(t->rates_mm_s), free(t->pose);
    free(t->dev_dist_mm), free(t->dev_t_s), free(t->dev_mm);
    check_trace_init(t);
}

/* Chooses the decimation for about CHECK_TRACE_POINTS samples. */
long check_trace_begin(struct check_trace *t, double planned_s, double period_s)
{
    long periods = (long)(planned_s / period_s) + 1;
    long every = periods / CHECK_TRACE_POINTS + 1;
    t->dev_every = 1, t->dev_count = 0;
    return every;
}

/* Grows an array of doubles to hold cap * width values; 0 or -1. */
static int grow(double **a, size_t cap, size_t width)
{
    double *n = realloc(*a, cap * width * sizeof *n);
    if (!n)
        return -1;
    *a = n;
    return 0;
}

/* Keeps one period's legs, rates and pose. */
void check_trace_add(struct check_trace *t, double t_s, int nj, const double *legs,
                     const double *rates, const double *pose)
{
    if (t->n == t->cap) {
        size_t cap = t->cap ? 2 * t->cap : 1024;
        if (grow(&t->t_s, cap, 1) || grow(&t->legs_mm, cap, KINS_MAX_JOINTS) ||
            grow(&t->rates_mm_s, cap, KINS_MAX_JOINTS) || grow(&t->pose, cap, KINS_POSE_DIM)) {
            t->failed = 1;
            return;
        }
        t->cap = cap;
    }
    t->njoints = nj;
    t->t_s[t->n] = t_s;
    memcpy(&t->legs_mm[t->n * KINS_MAX_JOINTS], legs, (size_t)nj * sizeof *legs);
    memcpy(&t->rates_mm_s[t->n * KINS_MAX_JOINTS], rates, (size_t)nj * sizeof *rates);
    memcpy(&t->pose[t->n * KINS_POSE_DIM], pose, KINS_POSE_DIM * sizeof *pose);
    t->n++;
}

/* Keeps one deviation measure (halving the kept ones when there are too many). */
void check_trace_deviation(struct check_trace *t, double dist_mm, double t_s, double dev_mm)
{
    if (++t->dev_count < t->dev_every)
        return;
    t->dev_count = 0;
    if (t->ndev == t->capdev) {
        if (t->capdev >= 4 * CHECK_TRACE_POINTS) {   /* too many: keep every other one */
            size_t j = 0;
            for (size_t i = 0; i < t->ndev; i += 2, j++)
                t->dev_dist_mm[j] = t->dev_dist_mm[i], t->dev_t_s[j] = t->dev_t_s[i],
                t->dev_mm[j] = t->dev_mm[i];
            t->ndev = j, t->dev_every *= 2;
        } else {
            size_t cap = t->capdev ? 2 * t->capdev : 1024;
            if (grow(&t->dev_dist_mm, cap, 1) || grow(&t->dev_t_s, cap, 1) ||
                grow(&t->dev_mm, cap, 1)) {
                t->failed = 1;
                return;
            }
            t->capdev = cap;
        }
    }
    t->dev_dist_mm[t->ndev] = dist_mm, t->dev_t_s[t->ndev] = t_s, t->dev_mm[t->ndev] = dev_mm;
    t->ndev++;
}

/* Length of a number word's value at s (sign, digits, point), 0 when none. */
static size_t number_len(const char *s, size_t left)
{
    size_t i = 0;
    while (i < left && (s[i] == ' ' || s[i] == '\t'))
        i++;
    if (i < left && (s[i] == '+' || s[i] == '-'))
        i++;
    size_t d = i;
    while (i < left && (isdigit((unsigned char)s[i]) || s[i] == '.'))
        i++;
    return i > d ? i : 0;
}

/* G141/G142 -> G1, W and D words blanked, same length and lines (errors keep their columns). */
char *check_strip_compensation(const char *text, size_t len)
{
    char *o = malloc(len + 1);
    if (!o)
        return NULL;
    memcpy(o, text, len);
    o[len] = 0;
    for (size_t i = 0; i < len; i++) {
        char c = (char)toupper((unsigned char)o[i]);
        if (c == 'G' && i + 4 <= len && o[i + 1] == '1' && o[i + 2] == '4' &&
            (o[i + 3] == '1' || o[i + 3] == '2') &&
            (i + 4 == len || !isdigit((unsigned char)o[i + 4]))) {
            o[i + 2] = ' ', o[i + 3] = ' ';   /* G141 / G142 -> G1 */
            i += 3;
        } else if (c == 'W' || c == 'D') {
            size_t n = number_len(o + i + 1, len - i - 1);
            for (size_t j = 0; n && j <= n; j++)
                o[i + j] = ' ';
        }
    }
    return o;
}

/* Whether line is one of the lines the compensation made moves for (comp: per line, or NULL). */
static int on_comp_line(const unsigned char *comp, int ncomp, int line)
{
    return comp && line >= 0 && line < ncomp && comp[line];
}

/* XYZ of the moves of a canonical program, lines as their ends, arcs in 32 pieces. With comp
 * given, only the contour: moves on a compensated line that follow a move on one (the first
 * move of a run only brings the tool to the contour's start); NaN breaks the line elsewhere. */
static size_t path_points(const struct canon_prog *p, const unsigned char *comp, int ncomp,
                          double *xyz, size_t cap)
{
    double from[KINS_POSE_DIM], pose[KINS_POSE_DIM];
    size_t n = 0;
    int prev_comp = 0;
    memcpy(from, p->start, sizeof from);
    if (cap)
        memcpy(xyz, from, 3 * sizeof *xyz), n = 1;
    for (size_t k = 0; k < p->count && n + 1 < cap; k++) {
        const struct canon_cmd *c = &p->cmds[k];
        if (!check_is_motion(c->type))
            continue;
        int here = on_comp_line(comp, ncomp, c->line);
        if (comp && !(here && prev_comp)) {     /* not contour: break the line, restart */
            xyz[3 * n] = xyz[3 * n + 1] = xyz[3 * n + 2] = NAN;
            memcpy(&xyz[3 * (n + 1)], c->end, 3 * sizeof *xyz);
            n += 2;
        } else {
            int pieces = c->type == CANON_ARC ? 32 : 1;
            for (int j = 1; j <= pieces && n < cap; j++, n++) {
                check_move_pose(from, c, (double)j / pieces, pose);
                memcpy(&xyz[3 * n], pose, 3 * sizeof *xyz);
            }
        }
        prev_comp = here;
        memcpy(from, c->end, sizeof from);
    }
    return n;
}

/* Marks the lines on which the compensation emitted moves; NULL when none (or no memory). */
static unsigned char *comp_lines(const struct canon_prog *p, int *n)
{
    int maxl = 0, any = 0;
    for (size_t k = 0; k < p->count; k++)
        if (p->cmds[k].compensated && p->cmds[k].line > maxl)
            maxl = p->cmds[k].line, any = 1;
    unsigned char *m = any ? calloc((size_t)maxl + 1, 1) : NULL;
    for (size_t k = 0; m && k < p->count; k++)
        if (p->cmds[k].compensated && p->cmds[k].line >= 0)
            m[p->cmds[k].line] = 1;
    *n = maxl + 1;
    return m;
}

/* Isometric view: u = (X - Y) cos 30, v = Z + (X + Y) sin 30, in place over n points. */
static void isometric(double *xyz, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        double x = xyz[3 * i], y = xyz[3 * i + 1], z = xyz[3 * i + 2];
        xyz[3 * i] = (x - y) * cos(M_PI / 6);
        xyz[3 * i + 1] = z + (x + y) * sin(M_PI / 6);
    }
}

/* "DIR/BASE" into file; a name that does not fit is an error naming the limit, never cut. */
static int plot_name(char *file, size_t flen, const char *dir, const char *base, char *err,
                     size_t errlen)
{
    int n = snprintf(file, flen, "%s/%s", dir, base);
    if (n < 0 || (size_t)n >= flen)
        return errbuf_set(err, errlen, -1, "%.200s...: plot folder name too long (the limit "
                          "is %zu characters with the file name)", dir, flen - 1);
    return 0;
}

/* The two tool path views: programmed contour (dashed) against compensated tool path. */
static int path_plots(const char *dir, const struct canon_prog *path,
                      const struct canon_prog *contour, char *file, size_t flen, char *err,
                      size_t errlen)
{
    size_t cap = 2 + 33 * (path->count + (contour ? contour->count : 0));
    double *a = malloc(3 * cap * sizeof *a), *b = malloc(3 * cap * sizeof *b);
    int st = -1, ncomp = 0;
    unsigned char *comp = comp_lines(path, &ncomp);
    if (!a || !b)
        goto out;
    size_t na = path_points(path, NULL, 0, a, cap);
    size_t nb = contour && comp ? path_points(contour, comp, ncomp, b, cap) : 0;
    struct svg_series s[2] = {
        { "compensated tool path", a, a + 1, na, 3, "#1f77b4", 0, 0 },
        { "programmed contour", b, b + 1, nb, 3, "#d62728", 1, 0 },
    };
    struct svg_chart top = { "Tool path, top view (program X Y: platform pose)", "X (mm)",
                             "Y (mm)", 1 };
    if (plot_name(file, flen, dir, "toolpath_top.svg", err, errlen) ||
        svg_write_chart(file, &top, s, nb ? 2 : 1, err, errlen))
        goto out;
    isometric(a, na), isometric(b, nb);
    struct svg_chart iso = { "Tool path, isometric view", "(X - Y) cos 30 deg (mm)",
                             "Z + (X + Y) sin 30 deg (mm)", 1 };
    st = plot_name(file, flen, dir, "toolpath_3d.svg", err, errlen);
    st = st ? st : svg_write_chart(file, &iso, s, nb ? 2 : 1, err, errlen);
out:
    free(a), free(b), free(comp);
    return st;
}

/* Leg lengths and leg rates against time, one series per leg. */
static int leg_plots(const char *dir, const struct check_trace *t, char *file, size_t flen,
                     char *err, size_t errlen)
{
    struct svg_series s[KINS_MAX_JOINTS];
    char names[KINS_MAX_JOINTS][16];
    for (int i = 0; i < t->njoints; i++) {
        snprintf(names[i], sizeof names[i], "leg %d", i + 1);
        s[i] = (struct svg_series){ names[i], t->t_s, NULL, t->n, 0, leg_colors[i], 0, 0 };
    }
    /* the legs are stored KINS_MAX_JOINTS apart: copy each into its own run */
    double *y = malloc((t->n ? t->n : 1) * KINS_MAX_JOINTS * sizeof *y);
    if (!y)
        return -1;
    for (size_t k = 0; k < t->n; k++)
        for (int i = 0; i < t->njoints; i++)
            y[i * t->n + k] = t->legs_mm[k * KINS_MAX_JOINTS + i];
    for (int i = 0; i < t->njoints; i++)
        s[i].y = y + i * t->n;
    struct svg_chart c1 = { "Leg lengths", "machine time (s)", "leg length (mm)", 0 };
    int st = plot_name(file, flen, dir, "legs.svg", err, errlen);
    st = st ? st : svg_write_chart(file, &c1, s, t->njoints, err, errlen);
    for (size_t k = 0; k < t->n; k++)
        for (int i = 0; i < t->njoints; i++)
            y[i * t->n + k] = t->rates_mm_s[k * KINS_MAX_JOINTS + i];
    struct svg_chart c2 = { "Leg rates", "machine time (s)", "leg rate (mm/s)", 0 };
    st = st ? st : plot_name(file, flen, dir, "leg_rates.svg", err, errlen);
    st = st ? st : svg_write_chart(file, &c2, s, t->njoints, err, errlen);
    free(y);
    return st;
}

/* Kinematic deviation along the path, with the tolerance. */
static int deviation_plot(const char *dir, const struct check_trace *t,
                          const struct check_result *r, char *file, size_t flen, char *err,
                          size_t errlen)
{
    double *um = malloc((t->ndev ? t->ndev : 1) * sizeof *um);
    if (!um)
        return -1;
    for (size_t i = 0; i < t->ndev; i++)
        um[i] = t->dev_mm[i] * 1e3;
    double tx[2] = { 0, r->length_mm }, ty[2] = { r->kin_tol_mm * 1e3, r->kin_tol_mm * 1e3 };
    struct svg_series s[2] = {
        { "mid-chord deviation", t->dev_dist_mm, um, t->ndev, 0, "#1f77b4", 0, 1 },
        { "KINEMATIC_TOLERANCE", tx, ty, 2, 0, "#d62728", 1, 0 },
    };
    struct svg_chart c = { "Kinematic deviation from the programmed path",
                           "distance along the path (mm)", "deviation (um)", 0 };
    int st = plot_name(file, flen, dir, "deviation.svg", err, errlen);
    st = st ? st : svg_write_chart(file, &c, s, r->kin_tol_mm > 0 ? 2 : 1, err, errlen);
    free(um);
    return st;
}

/* All the check's plots into dir, each replaced atomically (common/atomicfile). */
int check_write_plots(const char *dir, const struct canon_prog *path,
                      const struct canon_prog *contour, const struct check_trace *trace,
                      const struct check_result *r, char *err, size_t errlen)
{
    char file[PATH_MAX];
    if (trace->failed) {
        snprintf(err, errlen, "out of memory while keeping the plot samples");
        return CHECK_ERR_NOMEM;
    }
    if (errlen)
        err[0] = '\0';
    if (path_plots(dir, path, contour, file, sizeof file, err, errlen) ||
        leg_plots(dir, trace, file, sizeof file, err, errlen) ||
        deviation_plot(dir, trace, r, file, sizeof file, err, errlen)) {
        if (errlen && !err[0])
            snprintf(err, errlen, "out of memory while writing the plots");
        return CHECK_ERR_IO;
    }
    return CHECK_OK;
}
