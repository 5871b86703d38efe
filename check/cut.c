/* cut.c: the tool swept along the actual (stepgen feedback) path in the workpiece frame, and the wall it cuts. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check/check_priv.h"
#include "check/cut.h"
#include "sim/stepgen.h"

#define SETTLE_PERIODS 50    /* periods after the program end for the drives to arrive */
#define DEG (M_PI / 180.0)

/* An empty path. */
void cut_path_init(struct cut_path *p)
{
    memset(p, 0, sizeof *p);
}

/* Frees the samples. */
void cut_path_free(struct cut_path *p)
{
    free(p->s);
    cut_path_init(p);
}

/* R = Rz(C) Ry(B) Rx(A) of a pose (docs/kinematics.md). */
static void rotation(const double pose[KINS_POSE_DIM], double R[3][3])
{
    double ca = cos(pose[3] * DEG), sa = sin(pose[3] * DEG), cb = cos(pose[4] * DEG),
           sb = sin(pose[4] * DEG), cc = cos(pose[5] * DEG), sc = sin(pose[5] * DEG);
    R[0][0] = cc * cb, R[0][1] = cc * sb * sa - sc * ca, R[0][2] = cc * sb * ca + sc * sa;
    R[1][0] = sc * cb, R[1][1] = sc * sb * sa + cc * ca, R[1][2] = sc * sb * ca - cc * sa;
    R[2][0] = -sb, R[2][1] = cb * sa, R[2][2] = cb * ca;
}

/* Tool tip in the platform (workpiece) frame. */
int cut_tip_in_workpiece(struct check_machine *mc, const double pose[KINS_POSE_DIM],
                         double tip[3])
{
    return kins_tool_point(mc->kins, pose, NULL, tip);
}

/* Appends the tool at the actual pose. */
static int add_sample(struct check_machine *mc, struct cut_path *p, const double pose[6],
                      double radius, int line)
{
    if (p->n == p->cap) {
        size_t cap = p->cap ? 2 * p->cap : 4096;
        struct cut_sample *s = realloc(p->s, cap * sizeof *s);
        if (!s)
            return CHECK_ERR_NOMEM;
        p->s = s, p->cap = cap;
    }
    struct cut_sample *s = &p->s[p->n];
    double R[3][3];
    if (kins_tool_point(mc->kins, pose, NULL, s->tip) != KINS_OK)
        return CHECK_ERR_KINS;
    rotation(pose, R);
    for (int i = 0; i < 3; i++)   /* R^T TOOL_AXIS: the fixed tool seen from the workpiece */
        s->axis[i] = R[0][i] * mc->tool_axis[0] + R[1][i] * mc->tool_axis[1] +
                     R[2][i] * mc->tool_axis[2];
    s->radius_mm = radius, s->line = line;
    p->n++;
    return CHECK_OK;
}

/* Tool radius per program line: the tool in the spindle when that line's moves run. */
static double *line_radii(struct check_machine *mc, const struct canon_prog *prog, int *nlines)
{
    int maxl = 0, tool = 0;
    for (size_t k = 0; k < prog->count; k++)
        maxl = prog->cmds[k].line > maxl ? prog->cmds[k].line : maxl;
    double *r = calloc((size_t)maxl + 1, sizeof *r);
    if (!r)
        return NULL;
    for (size_t k = 0; k < prog->count; k++) {
        const struct canon_cmd *c = &prog->cmds[k];
        if (c->type == CANON_TOOL_CHANGE)
            tool = c->ivalue;
        else if (check_is_motion(c->type) && c->line >= 0) {
            double rad = tool > 0 ? check_machine_tool_radius(mc, tool) : 0;
            r[c->line] = rad > 0 ? rad : 0;
        }
    }
    *nlines = maxl + 1;
    return r;
}

/* One servo period of the machine: motion, stepgens, feedback, forward kinematics. */
static int machine_period(struct check_machine *mc, struct stepgen_state *sg,
                          const struct stepgen_limits *lim, struct motion_out *out,
                          double pose[KINS_POSE_DIM], char *err, size_t errlen)
{
    double fb[KINS_MAX_JOINTS], T = mc->mcfg.servo_period_s;
    int nj = mc->kins->njoints;
    motion_step(mc->motion, T, out);
    for (int i = 0; i < nj; i++) {
        int64_t counts = stepgen_step(&sg[i], &lim[i], out->joint_pos[i], true, T);
        fb[i] = lim[i].scale > 0 ? (double)counts / lim[i].scale : sg[i].pos_mm;
    }
    motion_feedback(mc->motion, fb);
    struct kins *built = mc->real_kins ? mc->real_kins : mc->kins; /* the machine as built */
    int st = kins_forward(built, fb, pose, NULL);   /* warm: from the last actual pose */
    if (st != KINS_OK) {
        snprintf(err, errlen, "forward kinematics of the drive feedback failed at line %d: %s",
                 out->line, kins_strerror(st));
        return CHECK_ERR_KINS;
    }
    return CHECK_OK;
}

/* Runs the program period by period and keeps the tool in the workpiece frame. */
int cut_simulate(struct check_machine *mc, const struct canon_prog *prog, struct cut_path *path,
                 char *err, size_t errlen)
{
    struct stepgen_state sg[KINS_MAX_JOINTS];
    struct stepgen_limits lim[KINS_MAX_JOINTS];
    double L[KINS_MAX_JOINTS], pose[KINS_POSE_DIM];
    int nj = mc->kins->njoints, nlines = 0, st;
    char msg[400];
    double *radii = line_radii(mc, prog, &nlines);
    if (!radii)
        return CHECK_ERR_NOMEM;
    if (motion_load(mc->motion, prog, msg, sizeof msg) != MOTION_OK ||
        motion_start(mc->motion) != MOTION_OK || kins_inverse(mc->kins, prog->start, L)) {
        snprintf(err, errlen, "%s", msg);
        free(radii);
        return CHECK_ERR_VIOLATION;
    }
    for (int i = 0; i < nj; i++) {
        lim[i] = (struct stepgen_limits){ mc->scale[i], mc->drive_vel[i], mc->drive_acc[i] };
        stepgen_state_init(&sg[i], L[i]);
        if (mc->scale[i] > 0 && 1 / mc->scale[i] > path->max_step_mm)
            path->max_step_mm = 1 / mc->scale[i];
    }
    memcpy(pose, prog->start, sizeof pose);
    struct motion_out out;
    struct motion_plan_info info;
    motion_plan_info(mc->motion, &info);
    long left = (long)(2 * info.time_s / mc->mcfg.servo_period_s) + 1000; /* a stuck plan */
    int settle = 0;
    do {
        if ((st = machine_period(mc, sg, lim, &out, pose, err, errlen)))
            break;
        double rad = out.line > 0 && out.line < nlines ? radii[out.line] : 0;
        if ((st = add_sample(mc, path, pose, rad, out.line)))
            break;
        if (out.state == MOTION_FAULT) {
            snprintf(err, errlen, "%s", motion_last_error(mc->motion));
            st = CHECK_ERR_VIOLATION;
            break;
        }
        if (out.state == MOTION_PAUSED)   /* M0/M1: the operator would press resume */
            motion_resume(mc->motion);
        settle += out.state == MOTION_DONE;
    } while (settle < SETTLE_PERIODS && --left > 0);
    if (st == CHECK_OK && left <= 0) {
        snprintf(err, errlen, "motion did not finish in twice the planned time");
        st = CHECK_ERR_VIOLATION;
    }
    path->machining_time_s = out.time_elapsed_s;
    free(radii);
    return st;
}

/* Dot product of two 3-vectors. */
static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Furthest point along n of the station line b + u n inside the cylinder (tip c, unit axis a,
 * radius W), if the tip is below the measuring height and the cut starts on the slot's side
 * of the reference line (u < ref). -HUGE_VAL when the line misses it. */
static double reach(const double b[3], const double n[3], const double c[3], const double a[3],
                    double W, double top_z, double ref)
{
    if (W <= 0 || c[2] > top_z)
        return -HUGE_VAL;
    double g[3] = { b[0] - c[0], b[1] - c[1], b[2] - c[2] };
    double na = dot3(n, a), ga = dot3(g, a);
    double A = 1 - na * na, B = 2 * (dot3(g, n) - ga * na), C = dot3(g, g) - ga * ga - W * W;
    double disc = B * B - 4 * A * C;
    if (A <= 1e-12 || disc < 0)
        return -HUGE_VAL;
    if ((-B - sqrt(disc)) / (2 * A) >= ref)   /* a cut beyond the reference line: not this wall */
        return -HUGE_VAL;
    return (-B + sqrt(disc)) / (2 * A);
}

/* Furthest reach of all swept cylinders along n at one station. */
double cut_wall_at(const struct cut_path *p, const struct cut_wall *w, double s_mm)
{
    double b[3], best = -HUGE_VAL;
    for (int i = 0; i < 3; i++)
        b[i] = w->origin[i] + s_mm * w->t[i];
    b[2] = w->top_z_mm;
    double prev_sig = 0;
    for (size_t k = 0; k < p->n; k++) {
        const struct cut_sample *s = &p->s[k];
        double d[3] = { s->tip[0] - b[0], s->tip[1] - b[1], s->tip[2] - b[2] };
        double sig = dot3(d, w->t), margin = s->radius_mm + fabs(w->top_z_mm - s->tip[2]) + 1;
        if (fabs(sig) <= margin)
            best = fmax(best, reach(b, w->n, s->tip, s->axis, s->radius_mm, w->top_z_mm, w->ref_mm));
        /* between samples the centre crosses the station: the disc there reaches furthest */
        const struct cut_sample *q = k ? &p->s[k - 1] : NULL;
        if (q && q->radius_mm == s->radius_mm && (prev_sig < 0) != (sig < 0) && prev_sig != sig) {
            double f = prev_sig / (prev_sig - sig), c[3], a[3], an;
            for (int i = 0; i < 3; i++)
                c[i] = q->tip[i] + f * (s->tip[i] - q->tip[i]),
                a[i] = q->axis[i] + f * (s->axis[i] - q->axis[i]);
            an = sqrt(dot3(a, a));
            for (int i = 0; i < 3; i++)
                a[i] /= an;
            best = fmax(best, reach(b, w->n, c, a, s->radius_mm, w->top_z_mm, w->ref_mm));
        }
        prev_sig = sig;
    }
    return best > -HUGE_VAL ? best : (double)NAN;
}

/* The wall read over a short length around a station. */
double cut_wall_mean(const struct cut_path *p, const struct cut_wall *w, double s_mm,
                     double half_mm, int n)
{
    double sum = 0;
    for (int i = 0; i < n; i++) {
        double s = n > 1 ? s_mm - half_mm + 2 * half_mm * i / (n - 1) : s_mm;
        sum += cut_wall_at(p, w, s);
    }
    return sum / n;
}
