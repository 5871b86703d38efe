/* experiment.c: runs the paper's experiment programs through the cutting simulation and measures d1..d4. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check/experiment.h"
#include "check/plot.h"
#include "common/errbuf.h"
#include "common/inifile.h"
#include "kins/kins.h"

#define DIR "examples/paper/experiment"

/* Table 1 (L4 array, column 1 = path, column 2 = tool pair) and the G142 run on path 1 with
 * the tools 10-20; first tool T3 (diameter 20), second T1 (10) or T2 (12), as programs (10)
 * and (11) order them. Paper values in mm; run 2 has no d1 in the paper. */
static const struct exp_run_def runs[] = {
    { "1", DIR "/run1_g141.ngc", DIR "/tmu-path1.ini", 1, 141, { 3, 1 }, 50, 630, -4,
      { { -80, -20 }, { -30, 20 } }, { 8.0, 7.8, 7.7, 7.7 }, NULL, 0 },
    { "2", DIR "/run2_g141.ngc", DIR "/tmu-path1.ini", 1, 141, { 3, 2 }, 50, 630, -4,
      { { -80, -20 }, { -30, 20 } }, { NAN, 8.1, 8.3, 8.2 }, NULL, 0 },
    { "3", DIR "/run3_g141.ngc", DIR "/tmu-path2.ini", 2, 141, { 3, 1 }, 30, 658, -8,
      { { -100, -20 }, { -30, 50 } }, { NAN, 8.2, 7.9, 7.9 }, NULL, 0 },
    { "4", DIR "/run4_g141.ngc", DIR "/tmu-path2.ini", 2, 141, { 3, 2 }, 30, 658, -8,
      { { -100, -20 }, { -30, 50 } }, { NAN, 8.0, 7.8, 7.9 }, NULL, 0 },
    { "G142", DIR "/run1_g142.ngc", DIR "/tmu-path1.ini", 1, 142, { 3, 1 }, 50, 630, -4,
      { { -80, -20 }, { -30, 20 } }, { 8.0, 7.7, 7.9, 8.1 }, NULL, 0 },
    /* run 1 programmed at the tool tip (G43.4): on the paper's machine, and on the machine
     * with its head vertical (a wall drafted 4 deg: 5 tan 4 deg = 0.35 mm on the top face) */
    { "1tcp", DIR "/run1_tcp_g141.ngc", DIR "/tmu-path1.ini", 1, 141, { 3, 1 }, -40, 93, -4,
      { { 80, 20 }, { 30, -20 } }, { 8.0, 7.8, 7.7, 7.7 }, NULL, 1 },
    { "1tcpv", DIR "/run1_tcpv_g141.ngc", "configs/sim/tmu-hexapod.ini", 1, 141, { 3, 1 },
      -40, 93, -4, { { 80, 20 }, { 30, -20 } }, { 8.0, 7.8, 7.7, 7.7 }, NULL, 1 },
};

/* The run table. */
const struct exp_run_def *exp_runs(int *count)
{
    *count = (int)(sizeof runs / sizeof runs[0]);
    return runs;
}

/* The contour point (tool tip in the workpiece frame) at program Y on the run's path. */
static int contour_at(struct check_machine *mc, const struct exp_run_def *d, double y, double p[3])
{
    if (d->tcp) {              /* G43.4: the program is the contour */
        p[0] = d->x_mm, p[1] = y, p[2] = d->z_mm;
        return CHECK_OK;
    }
    double pose[KINS_POSE_DIM] = { d->x_mm, y, d->z_mm, 0, d->b_deg, 0 };
    return cut_tip_in_workpiece(mc, pose, p);
}

/* Wall frame of a run: origin, along, into the material, top face, reference line. */
int exp_wall_frame(struct check_machine *mc, const struct exp_run_def *d, struct cut_wall *w)
{
    double a[3], b[3], len = 0;
    if (contour_at(mc, d, d->part[0][0], a) || contour_at(mc, d, d->part[1][1], b))
        return CHECK_ERR_KINS;
    memcpy(w->origin, a, sizeof a);
    for (int i = 0; i < 3; i++)
        len += (b[i] - a[i]) * (b[i] - a[i]);
    len = sqrt(len);
    for (int i = 0; i < 3; i++)
        w->t[i] = (b[i] - a[i]) / len;
    /* G141 puts the tool on the right of travel seen from above (the table normal z), so the
     * material is on the left: n = z x t; G142 the other way round */
    double s = d->side == 141 ? 1 : -1;
    w->n[0] = -s * w->t[1], w->n[1] = s * w->t[0], w->n[2] = 0;
    double nn = hypot(w->n[0], w->n[1]);
    w->n[0] /= nn, w->n[1] /= nn;
    w->top_z_mm = a[2] + EXP_DEPTH_MM;
    w->ref_mm = EXP_EDGE_MM - EXP_REF_FROM_EDGE_MM;
    return CHECK_OK;
}

/* Interprets (text NULL: the file; else the given text) and cuts. */
static int simulate(struct check_machine *mc, const char *path, const char *text,
                    struct cut_path *cp, char *err, size_t errlen)
{
    struct canon_prog prog;
    struct check_problem p;
    canon_prog_init(&prog);
    int st = text ? check_machine_interpret_text(mc, path, text, strlen(text), &prog, &p)
                  : check_machine_interpret(mc, path, &prog, &p);
    if (st != CHECK_OK)
        snprintf(err, errlen, "%s", p.message);
    else
        st = cut_simulate(mc, &prog, cp, err, errlen);
    canon_prog_free(&prog);
    return st;
}

/* Stations: thirds of each tool's own part of the wall (program Y), as s along the wall. */
static int stations(struct check_machine *mc, const struct exp_run_def *d,
                    const struct cut_wall *w, double s[4])
{
    double own[2][2] = { { d->part[0][0], d->part[1][0] }, { d->part[0][1], d->part[1][1] } };
    for (int k = 0; k < 4; k++) {
        const double *o = own[k / 2];
        double y = o[0] + (o[1] - o[0]) * (k % 2 + 1) / 3.0, p[3];
        if (contour_at(mc, d, y, p))
            return CHECK_ERR_KINS;
        s[k] = (p[0] - w->origin[0]) * w->t[0] + (p[1] - w->origin[1]) * w->t[1] +
               (p[2] - w->origin[2]) * w->t[2];
    }
    return CHECK_OK;
}

/* The stripped (no compensation) text of a program file; caller frees. */
static char *nocomp_text(const char *path)
{
    FILE *f = fopen(path, "rb");
    char buf[65536];
    if (!f)
        return NULL;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    fclose(f);
    return check_strip_compensation(buf, n);
}

/* Plots of one run: top view in the workpiece frame and the wall along its length. */
static int run_plots(const char *dir, const struct exp_run_def *d, const struct cut_wall *w,
                     const struct cut_path *a, const struct cut_path *b, const double st[4]);

/* Loads the machine as built from its INI's kinematics into mc. */
static int exp_set_real(struct check_machine *mc, const char *path, char *err, size_t errlen)
{
    struct inifile ini = { 0 };
    struct kins *real = NULL;
    char msg[512] = "";
    if (inifile_load(&ini, path, msg, sizeof msg) != INIFILE_OK)
        return errbuf_set(err, errlen, CHECK_ERR_CONFIG, "%s", msg);
    const char *name = inifile_get(&ini, "KINS", "KINEMATICS");
    struct kins_config kc = { inifile_config_get, &ini };
    int st = name ? kins_load(name, &kc, &real, msg, sizeof msg) : KINS_ERR_CONFIG;
    inifile_free(&ini);
    if (st != KINS_OK)
        return errbuf_set(err, errlen, CHECK_ERR_KINS, "%s: %s", path,
                          name ? msg : "[KINS] KINEMATICS is missing");
    check_machine_set_real(mc, real);
    return CHECK_OK;
}

/* Cuts a run with and without compensation and reads the four stations. */
int exp_run(const char *root, const struct exp_run_def *d, const char *plot_dir,
            struct exp_result *res, char *err, size_t errlen)
{
    char ini[1024], prog[1024];
    struct check_machine *mc = NULL;
    struct cut_path comp, plain;
    struct cut_wall w;
    char *text = NULL;
    cut_path_init(&comp);
    cut_path_init(&plain);
    memset(res, 0, sizeof *res);
    snprintf(ini, sizeof ini, "%s/%s", root, d->ini);
    snprintf(prog, sizeof prog, "%s/%s", root, d->program);
    int st = check_machine_open(ini, &mc, err, errlen);
    if (!st && d->real_ini)
        st = exp_set_real(mc, d->real_ini, err, errlen);
    if (st || (st = exp_wall_frame(mc, d, &w)) || (st = stations(mc, d, &w, res->station_s_mm)) ||
        (st = simulate(mc, prog, NULL, &comp, err, errlen)))
        goto out;
    if (!(text = nocomp_text(prog))) {
        st = CHECK_ERR_NOMEM;
        snprintf(err, errlen, "%s: cannot read the program", prog);
        goto out;
    }
    if ((st = simulate(mc, prog, text, &plain, err, errlen)))
        goto out;
    double lo = HUGE_VAL, hi = -HUGE_VAL, plo = HUGE_VAL, phi = -HUGE_VAL, nw[4];
    for (int k = 0; k < 4; k++) {
        double pt = cut_wall_at(&comp, &w, res->station_s_mm[k]);
        plo = fmin(plo, pt), phi = fmax(phi, pt);
        res->wall_mm[k] = cut_wall_mean(&comp, &w, res->station_s_mm[k], EXP_WINDOW_MM,
                                        EXP_WINDOW_POINTS);
        res->d_mm[k] = w.ref_mm - res->wall_mm[k];
        lo = fmin(lo, res->wall_mm[k]), hi = fmax(hi, res->wall_mm[k]);
        nw[k] = cut_wall_mean(&plain, &w, res->station_s_mm[k], EXP_WINDOW_MM,
                              EXP_WINDOW_POINTS);
        res->nocomp_d_mm[k] = w.ref_mm - nw[k];
    }
    res->spread_um = (hi - lo) * 1e3;
    res->point_spread_um = (phi - plo) * 1e3;
    res->part_diff_um = 1e3 * (0.5 * (res->wall_mm[2] + res->wall_mm[3]) -
                               0.5 * (res->wall_mm[0] + res->wall_mm[1]));
    res->nocomp_step_mm = 0.5 * (nw[2] + nw[3]) - 0.5 * (nw[0] + nw[1]);
    for (int i = 0; i < 2; i++)
        res->radius_mm[i] = check_machine_tool_radius(mc, d->tool[i]);
    res->machining_time_s = comp.machining_time_s;
    res->max_step_mm = comp.max_step_mm;
    if (plot_dir && run_plots(plot_dir, d, &w, &comp, &plain, res->station_s_mm)) {
        st = CHECK_ERR_IO;
        snprintf(err, errlen, "%s: cannot write the plots", plot_dir);
    }
out:
    free(text);
    cut_path_free(&comp);
    cut_path_free(&plain);
    check_machine_close(mc);
    return st;
}

/* Coordinates along the wall (s) and into the material (u) of a workpiece-frame point. */
static void wall_coords(const struct cut_wall *w, const double p[3], double *s, double *u)
{
    double d[3] = { p[0] - w->origin[0], p[1] - w->origin[1], p[2] - w->origin[2] };
    *s = d[0] * w->t[0] + d[1] * w->t[1] + d[2] * w->t[2];
    *u = d[0] * w->n[0] + d[1] * w->n[1] + d[2] * w->n[2];
}

/* Isometric view of a workpiece-frame point: (x - y) cos 30, z + (x + y) sin 30. */
static void iso(const double p[3], double *u, double *v)
{
    *u = (p[0] - p[1]) * cos(M_PI / 6);
    *v = p[2] + (p[0] + p[1]) * sin(M_PI / 6);
}

/* The tool tip's path over the workpiece and the programmed contour, in an isometric view. */
static int iso_plot(const char *dir, const struct exp_run_def *d, const struct cut_wall *w,
                    const struct cut_path *a)
{
    size_t n = a->n ? a->n : 1;
    double *uv = malloc(2 * n * sizeof *uv), cu[2], cv[2], e[3];
    if (!uv)
        return -1;
    for (size_t k = 0; k < a->n; k++)
        iso(a->s[k].tip, &uv[2 * k], &uv[2 * k + 1]);
    double len = fabs(d->part[1][1] - d->part[0][0]);
    for (int i = 0; i < 3; i++)
        e[i] = w->origin[i] + len * w->t[i];
    iso(w->origin, &cu[0], &cv[0]);
    iso(e, &cu[1], &cv[1]);
    struct svg_series s[2] = {
        { "tool tip (actual path)", uv, uv + 1, a->n, 2, "#1f77b4", 0, 0 },
        { "programmed contour", cu, cv, 2, 0, "#d62728", 1, 0 },
    };
    char file[1200], title[160];
    snprintf(title, sizeof title, "Run %s: tool tip over the workpiece, isometric", d->name);
    struct svg_chart c = { title, "(x - y) cos 30 deg, workpiece frame (mm)",
                           "z + (x + y) sin 30 deg (mm)", 1 };
    snprintf(file, sizeof file, "%s/exp_run%s_3d.svg", dir, d->name);
    int rc = svg_write_chart(file, &c, s, 2, NULL, 0);
    free(uv);
    return rc;
}

/* Writes a run's plots. */
static int run_plots(const char *dir, const struct exp_run_def *d, const struct cut_wall *w,
                     const struct cut_path *a, const struct cut_path *b, const double st[4])
{
    enum { NW = 400 };
    size_t na = a->n;
    double *xy = malloc(2 * (na ? na : 1) * sizeof *xy), ws[NW], wc[NW], wp[NW];
    if (!xy)
        return -1;
    double s_end = st[3] * 1.2;   /* a little past the last station */
    for (size_t k = 0; k < na; k++)   /* tool tip below the top face: cutting */
        if (a->s[k].tip[2] <= w->top_z_mm)
            wall_coords(w, a->s[k].tip, &xy[2 * k], &xy[2 * k + 1]);
        else
            xy[2 * k] = xy[2 * k + 1] = NAN;
    for (int i = 0; i < NW; i++) {
        ws[i] = -10 + (s_end + 20) * i / (NW - 1);
        wc[i] = cut_wall_at(a, w, ws[i]);
        wp[i] = cut_wall_at(b, w, ws[i]);
    }
    double cs[2] = { -10, s_end + 10 }, cu[2] = { 0, 0 }, rs[2] = { -10, s_end + 10 },
           ru[2] = { w->ref_mm, w->ref_mm }, sx[4], sy[4];
    for (int k = 0; k < 4; k++)
        sx[k] = st[k], sy[k] = cut_wall_at(a, w, st[k]);
    struct svg_series s[6] = {
        { "programmed contour", cs, cu, 2, 0, "#d62728", 1, 0 },
        { "reference line", rs, ru, 2, 0, "#7f7f7f", 1, 0 },
        { "tool tip, G141/G142", xy, xy + 1, na, 2, "#1f77b4", 0, 0 },
        { "wall, G141/G142", ws, wc, NW, 0, "#2ca02c", 0, 0 },
        { "wall, G1 (no compensation)", ws, wp, NW, 0, "#ff7f0e", 0, 0 },
        { "stations d1..d4", sx, sy, 4, 0, "#000000", 0, 1 },
    };
    char file[1200], title[160];
    int rc = iso_plot(dir, d, w, a);
    snprintf(title, sizeof title, "Run %s: wall seen from above (workpiece frame)", d->name);
    struct svg_chart top = { title, "along the wall, s (mm)", "into the material, u (mm)", 1 };
    snprintf(file, sizeof file, "%s/exp_run%s_top.svg", dir, d->name);
    rc = rc ? rc : svg_write_chart(file, &top, s, 6, NULL, 0);
    /* the wall in um beyond the contour, where it is fully formed (away from the ends) */
    double len = fabs(d->part[1][1] - d->part[0][0]), s0 = 0.5 * st[0], s1 = 0.5 * (st[3] + len);
    for (int i = 0; i < NW; i++) {
        ws[i] = s0 + (s1 - s0) * i / (NW - 1);
        wc[i] = 1e3 * cut_wall_at(a, w, ws[i]);
    }
    for (int k = 0; k < 4; k++)
        sy[k] = 1e3 * cut_wall_mean(a, w, st[k], EXP_WINDOW_MM, EXP_WINDOW_POINTS);
    for (int i = 0; i < NW; i++) {   /* the same read over +-EXP_WINDOW_MM */
        double sum = 0;
        int m = 0;
        for (int j = 0; j < NW; j++)
            if (fabs(ws[j] - ws[i]) <= EXP_WINDOW_MM)
                sum += wc[j], m++;
        wp[i] = sum / m;
    }
    struct svg_series s2[3] = {
        { "wall at single points", ws, wc, NW, 0, "#9ecf9e", 0, 0 },
        { "wall read over +-1 mm", ws, wp, NW, 0, "#2ca02c", 0, 0 },
        { "stations d1..d4 (+-1 mm)", sx, sy, 4, 0, "#000000", 0, 1 } };
    snprintf(title, sizeof title, "Run %s: compensated wall beyond the contour", d->name);
    struct svg_chart wall = { title, "along the wall, s (mm)", "wall - contour (um)", 0 };
    snprintf(file, sizeof file, "%s/exp_run%s_wall.svg", dir, d->name);
    rc = rc ? rc : svg_write_chart(file, &wall, s2, 3, NULL, 0);
    free(xy);
    return rc;
}
