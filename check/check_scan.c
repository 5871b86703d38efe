/* check_scan.c: the static reach pass: every programmed move sampled through the inverse kinematics. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check/check_priv.h"

#define SCAN_STEP_MM 1.0     /* largest XYZ distance between samples, mm */
#define SCAN_STEP_DEG 0.5    /* largest change of A B C between samples, deg */
#define SCAN_MAX_SAMPLES 100000 /* per move (very long moves are sampled more coarsely) */

/* Arc/helix geometry of a canonical arc from `from`: centre, frame, radii, heights, sweep. */
struct arc_geom {
    double c[3], e1[3], e2[3], n[3];
    double r0, r1, h0, h1, sweep_rad;
};

/* Dot product of two 3-vectors. */
static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Builds the arc frame: e1 towards the start, e2 = n x e1, the signed sweep (canon.h rules). */
static void arc_geom(const double from[KINS_POSE_DIM], const struct canon_cmd *cm,
                     struct arc_geom *g)
{
    double s[3], e[3];
    memcpy(g->c, cm->arc.center, sizeof g->c);
    memcpy(g->n, cm->arc.normal, sizeof g->n);
    for (int i = 0; i < 3; i++)
        s[i] = from[i] - g->c[i], e[i] = cm->end[i] - g->c[i];
    g->h0 = dot3(s, g->n), g->h1 = dot3(e, g->n);
    for (int i = 0; i < 3; i++)
        s[i] -= g->h0 * g->n[i], e[i] -= g->h1 * g->n[i];
    g->r0 = sqrt(dot3(s, s)), g->r1 = sqrt(dot3(e, e));
    for (int i = 0; i < 3; i++)
        g->e1[i] = g->r0 > 0 ? s[i] / g->r0 : 0;
    g->e2[0] = g->n[1] * g->e1[2] - g->n[2] * g->e1[1];
    g->e2[1] = g->n[2] * g->e1[0] - g->n[0] * g->e1[2];
    g->e2[2] = g->n[0] * g->e1[1] - g->n[1] * g->e1[0];
    double ang = atan2(dot3(e, g->e2), dot3(e, g->e1));
    int turns = abs(cm->arc.rotation) - 1;
    if (cm->arc.rotation > 0) {
        if (ang <= 1e-12)
            ang += 2 * M_PI;
        g->sweep_rad = ang + 2 * M_PI * turns;
    } else {
        if (ang >= -1e-12)
            ang -= 2 * M_PI;
        g->sweep_rad = ang - 2 * M_PI * turns;
    }
}

/* Pose along a move: linear in all six axes, on the arc/helix for arcs. */
void check_move_pose(const double from[KINS_POSE_DIM], const struct canon_cmd *c, double u,
                     double pose[KINS_POSE_DIM])
{
    for (int i = 0; i < KINS_POSE_DIM; i++)
        pose[i] = from[i] + u * (c->end[i] - from[i]);
    if (c->type != CANON_ARC)
        return;
    struct arc_geom g;
    arc_geom(from, c, &g);
    double a = g.sweep_rad * u, r = g.r0 + u * (g.r1 - g.r0), h = g.h0 + u * (g.h1 - g.h0);
    double sa, ca;
    sincos(a, &sa, &ca);       /* one call, the values of sin() and cos() */
    for (int i = 0; i < 3; i++)
        pose[i] = g.c[i] + r * (ca * g.e1[i] + sa * g.e2[i]) + h * g.n[i];
}

/* Samples needed on a move: by XYZ length (arc length for arcs) and by A B C change. */
static int move_samples(const double from[KINS_POSE_DIM], const struct canon_cmd *c)
{
    double len = 0, ang = 0;
    if (c->type == CANON_ARC) {
        struct arc_geom g;
        arc_geom(from, c, &g);
        double rm = fmax(g.r0, g.r1);
        len = hypot(fabs(g.sweep_rad) * rm, g.h1 - g.h0);
    } else {
        double d[3] = { c->end[0] - from[0], c->end[1] - from[1], c->end[2] - from[2] };
        len = sqrt(dot3(d, d));
    }
    for (int i = 3; i < KINS_POSE_DIM; i++)
        ang = fmax(ang, fabs(c->end[i] - from[i]));
    double n = fmax(len / SCAN_STEP_MM, ang / SCAN_STEP_DEG);
    return n < 1 ? 1 : n > SCAN_MAX_SAMPLES ? SCAN_MAX_SAMPLES : (int)ceil(n);
}

/* The platform's pose of a command's pose: under G43.4 the command's pose is the tool tip. */
static void platform_of(struct check_machine *mc, int tcp, double len_mm, const double *P,
                        double *out)
{
    struct kins_tool_frame tf;
    if (tcp && kins_get_tool_frame(mc->kins, &tf) == KINS_OK)
        kins_tcp_to_pose(&tf, len_mm, P, out);
    else
        memmove(out, P, KINS_POSE_DIM * sizeof *out);
}

/* The command pose's legs (kins_inverse's status). */
static int cmd_inverse(struct check_machine *mc, const struct canon_cmd *c, const double *P,
                       double *L)
{
    double q[KINS_POSE_DIM];
    platform_of(mc, c->tcp, c->tool_len_mm, P, q);
    return kins_inverse(mc->kins, q, L);
}

/* Records the worst leg outside its range at a pose as a problem of kind k. */
static void leg_problem(struct check_machine *mc, const struct canon_cmd *c, enum check_kind k,
                        const double *pose, const double *L, struct check_result *r)
{
    const struct kins *kn = mc->kins;
    int worst = -1;
    double excess = 0;
    for (int i = 0; i < kn->njoints; i++) {
        double e = fmax(L[i] - kn->joint_max[i], kn->joint_min[i] - L[i]);
        if (e > excess)
            excess = e, worst = i;
    }
    struct check_problem p = { .kind = k, .line = c->line, .leg = worst, .time_s = -1,
                               .count = 1 };
    snprintf(p.file, sizeof p.file, "%s", c->file ? c->file : "");
    char why[300];
    double plat[KINS_POSE_DIM];
    platform_of(mc, c->tcp, c->tool_len_mm, pose, plat);
    if (worst < 0 && kins_describe(mc->kins, plat, why, sizeof why) == KINS_ERR_WORKSPACE) {
        snprintf(p.message, sizeof p.message, "%s X%.3f Y%.3f Z%.3f A%.3f B%.3f C%.3f, outside "
                 "the workspace: %s", k == CHECK_UNREACHABLE ? "the programmed point is"
                 : "the move passes through", pose[0], pose[1], pose[2], pose[3], pose[4],
                 pose[5], why);
        check_add_problem(r, &p);
        return;
    }
    if (worst < 0) {
        snprintf(p.message, sizeof p.message, "the kinematics cannot compute the legs at X%.3f "
                 "Y%.3f Z%.3f A%.3f B%.3f C%.3f", pose[0], pose[1], pose[2], pose[3], pose[4],
                 pose[5]);
        check_add_problem(r, &p);
        return;
    }
    int over = L[worst] > kn->joint_max[worst];
    p.value = L[worst];
    p.limit = over ? kn->joint_max[worst] : kn->joint_min[worst];
    snprintf(p.message, sizeof p.message, "%s X%.3f Y%.3f Z%.3f A%.3f B%.3f C%.3f, out of "
             "reach: leg %d would be %.3f mm, %.3f mm %s its %s %.3f mm ([JOINT_%d] %s)",
             k == CHECK_UNREACHABLE ? "the programmed point is" : "the move passes through",
             pose[0], pose[1], pose[2], pose[3], pose[4], pose[5], worst + 1, L[worst], excess,
             over ? "above" : "below", over ? "maximum" : "minimum", p.limit, worst,
             over ? "MAX_LIMIT" : "MIN_LIMIT");
    check_add_problem(r, &p);
}

/* Largest amount by which any leg is beyond its range (<= 0 when all are within). */
static double leg_excess(const struct kins *k, const double *L)
{
    double e = -HUGE_VAL;
    for (int i = 0; i < k->njoints; i++)
        e = fmax(e, fmax(L[i] - k->joint_max[i], k->joint_min[i] - L[i]));
    return e;
}

/* Samples the inside of a move whose end is reachable; reports the worst pose beyond reach. */
static void scan_move(struct check_machine *mc, const double from[KINS_POSE_DIM],
                      const struct canon_cmd *c, struct check_result *r)
{
    double pose[KINS_POSE_DIM], L[KINS_MAX_JOINTS], wpose[KINS_POSE_DIM], wL[KINS_MAX_JOINTS];
    double worst = -HUGE_VAL;
    int n = move_samples(from, c);
    for (int j = 1; j < n; j++) {
        check_move_pose(from, c, (double)j / n, pose);
        if (cmd_inverse(mc, c, pose, L) == KINS_OK)
            continue;
        double e = leg_excess(mc->kins, L);
        if (e > worst) {
            worst = e;
            memcpy(wpose, pose, sizeof wpose);
            memcpy(wL, L, sizeof wL);
        }
    }
    if (worst > -HUGE_VAL)     /* one report per move, at its worst pose */
        leg_problem(mc, c, CHECK_LEG_RANGE, wpose, wL, r);
}

void check_reach_begin(struct check_reach *rs, const double start[KINS_POSE_DIM], int tcp,
                       double tool_len_mm)
{
    memcpy(rs->from, start, sizeof rs->from);
    rs->from_tcp = tcp;
    rs->from_len = tool_len_mm;
}

void check_reach_cmd(struct check_machine *mc, struct check_reach *rs, const struct canon_cmd *c,
                     struct check_result *r)
{
    double L[KINS_MAX_JOINTS];
    if (!check_is_motion(c->type))
        return;
    if (c->tcp != rs->from_tcp || c->tool_len_mm != rs->from_len) {  /* G43.4 / G49 */
        struct kins_tool_frame tf;
        platform_of(mc, rs->from_tcp, rs->from_len, rs->from, rs->from);
        if (c->tcp && kins_get_tool_frame(mc->kins, &tf) == KINS_OK)
            kins_tcp_from_pose(&tf, c->tool_len_mm, rs->from, rs->from);
        rs->from_tcp = c->tcp, rs->from_len = c->tool_len_mm;
    }
    if (cmd_inverse(mc, c, c->end, L) != KINS_OK)
        leg_problem(mc, c, CHECK_UNREACHABLE, c->end, L, r);
    else
        scan_move(mc, rs->from, c, r);
    memcpy(rs->from, c->end, sizeof rs->from);
}

/* The reach pass over every move of the program. */
int check_scan_reach(struct check_machine *mc, const struct canon_prog *prog,
                     struct check_result *r)
{
    struct check_reach rs;
    size_t before = r->nproblems;
    check_reach_begin(&rs, prog->start, prog->start_tcp, prog->start_tool_len_mm);
    for (size_t k = 0; k < prog->count; k++)
        check_reach_cmd(mc, &rs, &prog->cmds[k], r);
    return (int)(r->nproblems - before);
}
