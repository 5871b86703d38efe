/* web_preview.c: a program's path for the 3-D view, read by the interpreter as `hexcnc
 * check` reads it (the machine's tool table, parameters and subroutine folders, the parameter
 * file never written), from the machine's present pose. Each point is X Y Z A B C in
 * thousandths (micrometres, millidegrees); arcs are chords of at most 1/64 turn. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/errbuf.h"
#include "interp/canon.h"
#include "interp/interp.h"
#include "interp/interp_setup.h"
#include "interp/tooltable.h"
#include "kins/kins.h"
#include "web/web.h"

#define RPC_FAILED -32005

enum { KIND_RAPID = 0, KIND_FEED = 1, KIND_COMP = 2 };

struct preview {
    json_t *pts, *kind, *line;
    json_t *contour, *contour_line, *contour_first;  /* G141/G142's programmed contour */
    size_t n, max;
    double at[6];              /* where the path is, in the commands' coordinates */
    double lo[3], hi[3];
    bool truncated;
    struct kins_tool_frame tf; /* under G43.4 the commands give the tool tip: the points */
    bool have_tf;              /* drawn are the platform's poses, as for any move */
    int at_tcp;                /* at is the tip, with this tool length */
    double at_len;
    int tcp;                   /* the command being drawn is under G43.4 ... */
    double len;                /* ... with this tool length */
};

/* The platform's pose of a command's pose (the same unless under G43.4). */
static void platform(const struct preview *p, int tcp, double len, const double x[6],
                     double out[6])
{
    if (tcp && p->have_tf)
        kins_tcp_to_pose(&p->tf, len, x, out);
    else
        memcpy(out, x, 6 * sizeof *out);
}

/* A command under another G43.4 state than the path so far: where the path is, re-expressed
 * in its coordinates (the machine does not move at the switch). */
static void follow_tcp(struct preview *p, const struct canon_cmd *cmd)
{
    p->tcp = cmd->tcp && p->have_tf;
    p->len = p->tcp ? cmd->tool_len_mm : 0;
    if (p->tcp == p->at_tcp && p->len == p->at_len)
        return;
    double plat[6];
    platform(p, p->at_tcp, p->at_len, p->at, plat);
    if (p->tcp)
        kins_tcp_from_pose(&p->tf, p->len, plat, p->at);
    else
        memcpy(p->at, plat, sizeof p->at);
    p->at_tcp = p->tcp, p->at_len = p->len;
}

static void put(struct preview *p, const double xc[6], int kind, int line)
{
    double x[6];
    platform(p, p->tcp, p->len, xc, x);
    for (int i = 0; i < 6; i++)
        json_array_append_new(p->pts, json_integer((json_int_t)llround(x[i] * 1000.0)));
    for (int i = 0; i < 3; i++) {
        if (x[i] < p->lo[i])
            p->lo[i] = x[i];
        if (x[i] > p->hi[i])
            p->hi[i] = x[i];
    }
    json_array_append_new(p->kind, json_integer(kind));
    json_array_append_new(p->line, json_integer(line));
    memcpy(p->at, xc, sizeof p->at);
    p->n++;
}

static double dot(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross(const double *a, const double *b, double *o)
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

/* The arc from p->at to end as chords: the radius and the height along the normal change
 * linearly with the angle (a helix, or an arc whose ends lie at different radii). */
static void put_arc(struct preview *p, const struct canon_cmd *cmd, int kind)
{
    const struct canon_arc *a = &cmd->arc;
    const double *n = a->normal;
    double r0[3], r1[3], h0, h1, at0[6];
    memcpy(at0, p->at, sizeof at0);   /* put() moves p->at on */
    for (int i = 0; i < 3; i++) {
        r0[i] = at0[i] - a->center[i];
        r1[i] = cmd->end[i] - a->center[i];
    }
    h0 = dot(r0, n);
    h1 = dot(r1, n);
    for (int i = 0; i < 3; i++) {
        r0[i] -= h0 * n[i];
        r1[i] -= h1 * n[i];
    }
    double c[3];
    cross(r0, r1, c);
    double th = atan2(dot(n, c), dot(r0, r1));
    if (a->rotation > 0 && th <= 1e-12)
        th += 2 * M_PI;
    if (a->rotation < 0 && th >= -1e-12)
        th -= 2 * M_PI;
    int turns = abs(a->rotation) - 1;
    th += (a->rotation > 0 ? 1 : -1) * 2 * M_PI * (turns > 0 ? turns : 0);
    double len0 = sqrt(dot(r0, r0)), len1 = sqrt(dot(r1, r1));
    int steps = (int)ceil(fabs(th) / (2 * M_PI / 64));
    if (steps < 1)
        steps = 1;
    double u[3], w[3];   /* r0's direction and the direction a quarter turn on */
    for (int i = 0; i < 3; i++)
        u[i] = len0 > 0 ? r0[i] / len0 : 0;
    cross(n, u, w);
    for (int s = 1; s < steps; s++) {
        double f = (double)s / steps, phi = th * f, rad = len0 + (len1 - len0) * f;
        double h = h0 + (h1 - h0) * f, x[6];
        for (int i = 0; i < 3; i++)
            x[i] = a->center[i] + rad * (u[i] * cos(phi) + w[i] * sin(phi)) + h * n[i];
        for (int i = 3; i < 6; i++)
            x[i] = at0[i] + (cmd->end[i] - at0[i]) * f;
        put(p, x, kind, cmd->line);
    }
    put(p, cmd->end, kind, cmd->line);
}

static void contour_point(struct preview *p, const double xc[6], int line, int first)
{
    double x[6];
    platform(p, p->tcp, p->len, xc, x);
    for (int i = 0; i < 6; i++)
        json_array_append_new(p->contour, json_integer((json_int_t)llround(x[i] * 1000.0)));
    json_array_append_new(p->contour_line, json_integer(line));
    json_array_append_new(p->contour_first, json_boolean(first));
}

/* The contour a G141/G142 block programs, beside the tool path the compensation makes. */
static void contour(void *ctx, int line, int first, const double from[6], const double point[6])
{
    struct preview *p = ctx;
    if (p->n >= p->max)
        return;
    if (first)
        contour_point(p, from, line, 1);
    contour_point(p, point, line, 0);
}

static int sink(void *ctx, const struct canon_cmd *cmd)
{
    struct preview *p = ctx;
    if (p->n >= p->max) {
        p->truncated = true;
        return 1;
    }
    int kind = cmd->compensated ? KIND_COMP : KIND_FEED;
    if (cmd->type == CANON_TRAVERSE || cmd->type == CANON_FEED || cmd->type == CANON_ARC)
        follow_tcp(p, cmd);
    if (cmd->type == CANON_TRAVERSE)
        put(p, cmd->end, KIND_RAPID, cmd->line);
    else if (cmd->type == CANON_FEED)
        put(p, cmd->end, kind, cmd->line);
    else if (cmd->type == CANON_PROBE)   /* G38: to where the interpreter takes it to stop */
        put(p, cmd->probe_stop, KIND_FEED, cmd->line);
    else if (cmd->type == CANON_ARC)
        put_arc(p, cmd, kind);
    return 0;
}

json_t *web_preview(const struct web_config *c, const char *path, const double start[6],
                    size_t max_points, int *code, char *err, size_t errlen)
{
    struct interp *in = interp_create();
    struct tooltable *tt = malloc(sizeof *tt);
    struct preview p = { .pts = json_array(), .kind = json_array(), .line = json_array(),
                         .contour = json_array(), .contour_line = json_array(),
                         .contour_first = json_array(), .max = max_points };
    json_t *r = NULL;
    char msg[1024];
    *code = RPC_FAILED;
    if (!in || !tt || !p.pts || !p.kind || !p.line || !p.contour || !p.contour_line ||
        !p.contour_first) {
        errbuf_set(err, errlen, -1, "out of memory");
        goto out;
    }
    tooltable_init(tt);
    interp_set_start(in, start);
    if (interp_setup(in, tt, inifile_config_get, (void *)c->ini, inifile_dir(c->ini),
                     INTERP_SETUP_PARAMS_READ_ONLY, msg, sizeof msg) != INTERP_OK) {
        errbuf_set(err, errlen, -1, "%s", msg);
        goto out;
    }
    const char *kname = inifile_get(c->ini, "KINS", "KINEMATICS");
    if (kname && !strcmp(kname, "hexapod")) {   /* the tool, for G43.4 (the path drawn is
                                                 * then the tool tip's) */
        struct kins_config kc = { inifile_config_get, (void *)c->ini };
        struct kins *k = NULL;
        if (kins_create(&kins_hexapod_ops, &kc, &k, msg, sizeof msg) == KINS_OK) {
            interp_use_kins(in, k);
            p.have_tf = kins_get_tool_frame(k, &p.tf) == KINS_OK;
        }
        kins_free(k);
    }
    for (int i = 0; i < 3; i++) {
        p.lo[i] = HUGE_VAL;
        p.hi[i] = -HUGE_VAL;
    }
    put(&p, start, KIND_RAPID, 0);
    interp_set_contour_fn(in, contour, &p);
    int st = interp_run_file(in, path, sink, &p);
    const char *problem = NULL;
    if (st != INTERP_OK && !p.truncated)
        problem = interp_error_format(interp_last_error(in), msg, sizeof msg);
    r = json_pack("{s:o, s:o, s:o, s:I, s:b, s:[fff], s:[fff]}", "pts_um", p.pts, "kind",
                  p.kind, "line", p.line, "points", (json_int_t)p.n, "truncated",
                  p.truncated, "min", p.lo[0], p.lo[1], p.lo[2], "max", p.hi[0], p.hi[1],
                  p.hi[2]);
    json_object_set_new(r, "contour_um", p.contour);
    json_object_set_new(r, "contour_line", p.contour_line);
    json_object_set_new(r, "contour_first", p.contour_first);
    p.pts = p.kind = p.line = p.contour = p.contour_line = p.contour_first = NULL;
    json_object_set_new(r, "error", problem ? json_string(problem) : json_null());
out:
    json_decref(p.pts);
    json_decref(p.kind);
    json_decref(p.line);
    json_decref(p.contour);
    json_decref(p.contour_line);
    json_decref(p.contour_first);
    interp_set_tooltable(in, NULL);
    interp_destroy(in);
    free(tt);
    return r;
}
