/* motion_path.c: turns the canonical program into path segments and evaluates poses on them. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/sincos3.h"
#include "motion/motion_blend.h"
#include "motion/motion_priv.h"

#define EPS_LEN 1e-9           /* mm or deg: shorter moves are skipped */
#define SAMPLE_MM 1.0          /* largest knot spacing along the XYZ path, mm */
#define SAMPLE_DEG 0.5         /* largest change of any of A B C between knots, deg */
#define SAMPLE_RAD 0.05        /* largest arc angle between knots, rad */
/* ... on a G64 blend arc: the knots' caps bound the legs between knots to first order in
 * the spacing (L' may grow by L'' h), the rest grows with the angle's square; the angle rule
 * decides only on arcs shorter than SAMPLE_MM per this angle (radius under 4 mm), where the
 * centripetal cap keeps the speed low (docs/motion.md, *Segments and knots*) */
#define SAMPLE_BLEND_RAD 0.25
#define MAX_INTERVALS 4000     /* knots per segment are capped (very long moves) */


/* A B C on a blend arc: the cubic (Hermite) in u from the start to the end orientation with
 * slopes m0, m1, so the rate joins the lines' on both sides. d = 0: value, 1: d/du, 2: d2/du2. */
static void abc_cubic(const struct motion_seg *sg, const struct motion_arc *a, double u, int d,
                      double out[3])
{
    double u2 = u * u, u3 = u2 * u, h00, h10, h01, h11;
    if (d == 0)
        h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = 3 * u2 - 2 * u3, h11 = u3 - u2;
    else if (d == 1)
        h00 = 6 * u2 - 6 * u, h10 = 3 * u2 - 4 * u + 1, h01 = 6 * u - 6 * u2, h11 = 3 * u2 - 2 * u;
    else
        h00 = 12 * u - 6, h10 = 6 * u - 4, h01 = 6 - 12 * u, h11 = 6 * u - 2;
    for (int k = 0; k < 3; k++)
        out[k] = h00 * sg->start[3 + k] + h10 * a->abc_m0[k] + h01 * sg->end[3 + k] +
                 h11 * a->abc_m1[k];
}

/* Largest |d2(A B C)/ds2| at s, deg/mm^2: 0 except on blend arcs. */
double motion_seg_abc_curvature(const struct motion_plan *p, const struct motion_seg *sg,
                                double s)
{
    if (sg->kind != SEG_ARC || !p->arcs[sg->arc].abc_cubic || !(sg->len > 0))
        return 0;
    double c[3], w = 0;
    abc_cubic(sg, &p->arcs[sg->arc], s / sg->len, 2, c);
    for (int k = 0; k < 3; k++)
        w = motion_max2(w, fabs(c[k]));
    return w / (sg->len * sg->len);
}

/* Pose at s on a segment (s may lie slightly outside [0, len]: the geometry extends). */
void motion_seg_pose(const struct motion_plan *p, const struct motion_seg *sg, double s,
                     double pose[KINS_POSE_DIM])
{
    double u = sg->len > 0 ? s / sg->len : 0.0;
    for (int i = 0; i < KINS_POSE_DIM; i++)
        pose[i] = sg->start[i] + u * (sg->end[i] - sg->start[i]);
    if (sg->kind != SEG_ARC)
        return;
    const struct motion_arc *a = &p->arcs[sg->arc];
    double ang = a->sweep_rad * u, r = a->r0_mm + a->dr_mm * u, h = a->h0_mm + a->dh_mm * u;
    double c, sn;
    sincos1(ang, &sn, &c);
    for (int i = 0; i < 3; i++)
        pose[i] = a->center[i] + r * (c * a->e1[i] + sn * a->e2[i]) + h * a->n[i];
    if (a->abc_cubic)
        abc_cubic(sg, a, u, 0, pose + 3);
}

/* d pose / ds at s, analytic. */
void motion_seg_tangent(const struct motion_plan *p, const struct motion_seg *sg, double s,
                        double dp[KINS_POSE_DIM])
{
    double il = sg->len > 0 ? 1.0 / sg->len : 0.0, u = s * il;
    for (int i = 0; i < KINS_POSE_DIM; i++)
        dp[i] = (sg->end[i] - sg->start[i]) * il;
    if (sg->kind != SEG_ARC)
        return;
    const struct motion_arc *a = &p->arcs[sg->arc];
    double ang = a->sweep_rad * u, r = a->r0_mm + a->dr_mm * u, c, sn;
    sincos1(ang, &sn, &c);
    for (int i = 0; i < 3; i++)
        dp[i] = il * (a->dr_mm * (c * a->e1[i] + sn * a->e2[i])
                      + r * a->sweep_rad * (-sn * a->e1[i] + c * a->e2[i]) + a->dh_mm * a->n[i]);
    if (a->abc_cubic) {
        abc_cubic(sg, a, u, 1, dp + 3);
        for (int k = 3; k < 6; k++)
            dp[k] *= il;
    }
}

/* Pose at s and its first and second derivatives along the path (per unit of s), analytic:
 * what the planner samples through the kinematics (one sine and cosine for all three). */
void motion_seg_derivs(const struct motion_plan *p, const struct motion_seg *sg, double s,
                       double pose[KINS_POSE_DIM], double dp[KINS_POSE_DIM],
                       double d2p[KINS_POSE_DIM])
{
    double il = sg->len > 0 ? 1.0 / sg->len : 0.0, u = s * il;
    for (int i = 0; i < KINS_POSE_DIM; i++) {
        pose[i] = sg->start[i] + u * (sg->end[i] - sg->start[i]);
        dp[i] = (sg->end[i] - sg->start[i]) * il;
        d2p[i] = 0;
    }
    if (sg->kind != SEG_ARC)
        return;
    const struct motion_arc *a = &p->arcs[sg->arc];
    double th = a->sweep_rad, ang = th * u, r = a->r0_mm + a->dr_mm * u;
    double h = a->h0_mm + a->dh_mm * u, c = 1, sn = 0;
    if (ang != 0)              /* (every arc's first knot: sin and cos of 0 are exactly 0, 1) */
        sincos1(ang, &sn, &c);
    for (int i = 0; i < 3; i++) {
        double radial = c * a->e1[i] + sn * a->e2[i], along = -sn * a->e1[i] + c * a->e2[i];
        pose[i] = a->center[i] + r * radial + h * a->n[i];
        dp[i] = il * (a->dr_mm * radial + r * th * along + a->dh_mm * a->n[i]);
        d2p[i] = il * il * (2 * a->dr_mm * th * along - r * th * th * radial);
    }
    if (a->abc_cubic) {        /* abc_cubic's three at once: the planner's every arc knot */
        double u2 = u * u, u3 = u2 * u, scale[3] = {1, il, il * il};
        double b[3][4] = {{2 * u3 - 3 * u2 + 1, u3 - 2 * u2 + u, 3 * u2 - 2 * u3, u3 - u2},
                          {6 * u2 - 6 * u, 3 * u2 - 4 * u + 1, 6 * u - 6 * u2, 3 * u2 - 2 * u},
                          {12 * u - 6, 6 * u - 4, 6 - 12 * u, 6 * u - 2}};
        double *out[3] = {pose, dp, d2p};
        for (int d = 0; d < 3; d++)
            for (int k = 0; k < 3; k++)
                out[d][3 + k] = (b[d][0] * sg->start[3 + k] + b[d][1] * a->abc_m0[k] +
                                 b[d][2] * sg->end[3 + k] + b[d][3] * a->abc_m1[k]) * scale[d];
    }
}

/* The file name, copied once per distinct name so the plan owns it. */
static const char *intern_file(struct motion_plan *p, const char *name)
{
    if (!name)
        return NULL;
    if (p->names_in)
        p = p->names_in;
    for (size_t i = p->nfiles; i-- > 0;)
        if (strcmp(p->files[i], name) == 0)
            return p->files[i];
    char **nf = realloc(p->files, (p->nfiles + 1) * sizeof *nf);
    if (!nf)
        return NULL;
    p->files = nf;
    if (!(nf[p->nfiles] = strdup(name)))
        return NULL;
    return nf[p->nfiles++];
}

/* Grows one per-knot array to cap entries; the old array stays valid on failure. */
static int motion_grow(double **a, size_t cap)
{
    double *n = realloc(*a, cap * sizeof *n);
    if (!n)
        return -1;
    *a = n;
    return 0;
}

/* Room for one more segment and n more knots. */
static int grow(struct motion_plan *p, size_t nknots)
{
    if (p->nseg == p->capseg) {
        size_t cap = p->capseg ? 2 * p->capseg : 256;
        struct motion_seg *s = realloc(p->segs, cap * sizeof *s);
        if (!s)
            return -1;
        p->segs = s, p->capseg = cap;
    }
    if (p->nknot + nknots > p->capknot) {
        size_t cap = p->capknot ? 2 * p->capknot : 1024;
        while (cap < p->nknot + nknots)
            cap *= 2;
        /* capknot grows only once every array has: a failure leaves the plan consistent */
        if (motion_grow(&p->ks, cap) || motion_grow(&p->kv, cap) || motion_grow(&p->kt, cap) ||
            motion_grow(&p->krho, cap) || motion_grow(&p->iacc, cap) ||
            motion_grow(&p->irho, cap) || motion_grow(&p->ivp, cap))
            return -1;
        p->capknot = cap;
    }
    return 0;
}

/* Appends a segment with n intervals of equal length (n + 1 knots). */
static struct motion_seg *add_seg(struct motion_plan *p, const struct canon_cmd *c,
                                  enum motion_seg_kind kind, size_t n)
{
    if (grow(p, n + 1) < 0)
        return NULL;
    struct motion_seg *sg = &p->segs[p->nseg++];
    memset(sg, 0, sizeof *sg);
    sg->kind = kind;
    sg->line = c->line;
    sg->file = intern_file(p, c->file);
    sg->k0 = p->nknot;
    sg->nk = n + 1;
    sg->arc = -1;
    p->nknot += n + 1;
    return sg;
}

/* Intervals a move needs for the reachability and limit checks to hold between samples
 * (SAMPLE_MM, SAMPLE_DEG, and arc_steps: the arc's angle over SAMPLE_RAD or
 * SAMPLE_BLEND_RAD), at least 1; not capped. */
static double fine_intervals(double xyz_mm, double abc_max_deg, double arc_steps)
{
    double n = motion_max2(motion_max2(xyz_mm / SAMPLE_MM, abc_max_deg / SAMPLE_DEG), arc_steps);
    return motion_max2(1.0, ceil(n));
}

/* Knot intervals for a move: the fine ones, capped at MAX_INTERVALS (the checks then sample
 * between the knots, motion_caps.c). */
static size_t intervals_for(double xyz_mm, double abc_max_deg, double arc_steps)
{
    double n = fine_intervals(xyz_mm, abc_max_deg, arc_steps);
    return n > MAX_INTERVALS ? MAX_INTERVALS : (size_t)n;
}

/* Spreads the knots of sg evenly over [0, len]; fine_n is what fine_intervals gave. */
static void place_knots(struct motion_plan *p, struct motion_seg *sg, double fine_n)
{
    size_t n = sg->nk - 1;
    for (size_t i = 0; i <= n; i++)
        p->ks[sg->k0 + i] = sg->len * (double)i / (double)n;
    sg->fine_h = sg->len / fine_n;
}

/* Largest |change| of A B C between two poses, deg. */
static double abc_max(const double *a, const double *b)
{
    double d = 0;
    for (int i = 3; i < 6; i++)
        d = motion_max2(d, fabs(b[i] - a[i]));
    return d;
}

/* A straight move (TRAVERSE or FEED) from `from` to c->end. */
static int add_line(struct motion_plan *p, const struct canon_cmd *c, const double *from)
{
    double dx = c->end[0] - from[0], dy = c->end[1] - from[1], dz = c->end[2] - from[2];
    double xyz = sqrt(dx * dx + dy * dy + dz * dz);
    double da = c->end[3] - from[3], db = c->end[4] - from[4], dc = c->end[5] - from[5];
    double abc = sqrt(da * da + db * db + dc * dc);
    if (xyz < EPS_LEN && abc < EPS_LEN)
        return 0;              /* no motion: nothing to plan */
    double abc_deg = abc_max(from, c->end);
    struct motion_seg *sg = add_seg(p, c, SEG_LINE, intervals_for(xyz, abc_deg, 0));
    if (!sg)
        return -1;
    memcpy(sg->start, from, sizeof sg->start);
    memcpy(sg->end, c->end, sizeof sg->end);
    sg->rotary = xyz < EPS_LEN;
    sg->len = sg->rotary ? abc : xyz;
    sg->xyz_len_mm = sg->rotary ? 0 : xyz;
    place_knots(p, sg, fine_intervals(xyz, abc_deg, 0));
    return 0;
}

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* Fills arc geometry from the canonical arc; -1 with a message when it is degenerate. */
static int arc_geometry(const struct canon_cmd *c, const double *from, struct motion_arc *a,
                        char *err, size_t errlen)
{
    double nl = sqrt(dot3(c->arc.normal, c->arc.normal));
    if (!(nl > 1e-12) || c->arc.rotation == 0) {
        snprintf(err, errlen, "%s:%d: arc without a plane normal or turn direction",
                 c->file ? c->file : "program", c->line);
        return -1;
    }
    double rs[3], re[3], us[3], ue[3];
    for (int i = 0; i < 3; i++) {
        a->n[i] = c->arc.normal[i] / nl;
        a->center[i] = c->arc.center[i];
        rs[i] = from[i] - a->center[i];
        re[i] = c->end[i] - a->center[i];
    }
    a->h0_mm = dot3(rs, a->n);
    double he = dot3(re, a->n);
    for (int i = 0; i < 3; i++) {
        us[i] = rs[i] - a->h0_mm * a->n[i];
        ue[i] = re[i] - he * a->n[i];
    }
    a->r0_mm = sqrt(dot3(us, us));
    double r1 = sqrt(dot3(ue, ue));
    if (a->r0_mm < 1e-6 || r1 < 1e-6) {
        snprintf(err, errlen, "%s:%d: arc of zero radius (start or end on the centre)",
                 c->file ? c->file : "program", c->line);
        return -1;
    }
    a->dr_mm = r1 - a->r0_mm;
    a->dh_mm = he - a->h0_mm;
    for (int i = 0; i < 3; i++)
        a->e1[i] = us[i] / a->r0_mm;
    a->e2[0] = a->n[1] * a->e1[2] - a->n[2] * a->e1[1];
    a->e2[1] = a->n[2] * a->e1[0] - a->n[0] * a->e1[2];
    a->e2[2] = a->n[0] * a->e1[1] - a->n[1] * a->e1[0];
    double phi = atan2(dot3(ue, a->e2), dot3(ue, a->e1)); /* (-pi, pi] */
    int turns = abs(c->arc.rotation) - 1;
    if (c->arc.rotation > 0)
        a->sweep_rad = (phi > 1e-12 ? phi : phi + 2 * M_PI) + 2 * M_PI * turns;
    else
        a->sweep_rad = (phi < -1e-12 ? phi : phi - 2 * M_PI) - 2 * M_PI * turns;
    return 0;
}

/* An arc or helix from `from` to c->end; blend: a G64 blend arc (its knots' angle rule is
 * SAMPLE_BLEND_RAD). */
static int add_arc(struct motion_plan *p, const struct canon_cmd *c, const double *from,
                   int blend, char *err, size_t errlen)
{
    struct motion_arc a;
    memset(&a, 0, sizeof a);
    if (arc_geometry(c, from, &a, err, errlen) < 0)
        return -2;
    if (p->narc == p->caparc) {
        size_t cap = p->caparc ? 2 * p->caparc : 64;
        struct motion_arc *na = realloc(p->arcs, cap * sizeof *na);
        if (!na)
            return -1;
        p->arcs = na, p->caparc = cap;
    }
    double rm = a.r0_mm + 0.5 * a.dr_mm;
    double planar = fabs(a.sweep_rad) * rm;
    double xyz = sqrt(planar * planar + a.dh_mm * a.dh_mm + a.dr_mm * a.dr_mm);
    double abc_deg = abc_max(from, c->end);
    double steps = fabs(a.sweep_rad) / (blend ? SAMPLE_BLEND_RAD : SAMPLE_RAD);
    struct motion_seg *sg = add_seg(p, c, SEG_ARC, intervals_for(xyz, abc_deg, steps));
    if (!sg)
        return -1;
    p->arcs[p->narc] = a;
    sg->arc = (int)p->narc++;
    memcpy(sg->start, from, sizeof sg->start);
    memcpy(sg->end, c->end, sizeof sg->end);
    sg->len = xyz;
    sg->xyz_len_mm = xyz;
    place_knots(p, sg, fine_intervals(xyz, abc_deg, steps));
    return 0;
}

/* A setting point (CANON_SETTING): no segment, only its place between segments, so that
 * the machine passes it without slowing down and reports it passed (motion_out). */
static int add_mark(struct motion_plan *p)
{
    if (p->nmarks == p->capmarks) {
        size_t cap = p->capmarks ? 2 * p->capmarks : 16;
        size_t *n = realloc(p->marks, cap * sizeof *n);
        if (!n)
            return -1;
        p->marks = n, p->capmarks = cap;
    }
    p->marks[p->nmarks++] = p->nseg;
    return 0;
}

/* A dwell or a pause: two knots at one point, speed 0. */
static int add_stop(struct motion_plan *p, const struct canon_cmd *c, const double *at,
                    enum motion_seg_kind kind, double dwell_s)
{
    struct motion_seg *sg = add_seg(p, c, kind, 1);
    if (!sg)
        return -1;
    memcpy(sg->start, at, sizeof sg->start);
    memcpy(sg->end, at, sizeof sg->end);
    sg->dwell_s = dwell_s;
    p->ks[sg->k0] = p->ks[sg->k0 + 1] = 0;
    return 0;
}

static void set_speed(const struct motion *m, struct motion_seg *sg, const struct canon_cmd *c,
                      double blend_tol_mm);
static int add_sync(struct motion *m, struct motion_plan *p, const struct canon_cmd *c,
                    const double *from, int sp_dir, double sp_rpm, char *err, size_t errlen);

/* G38.2..G38.5: a straight feed from rest to rest towards probe_stop (where the planner is
 * told the move ends: the whole move on the machine, which stops earlier on a trip), which
 * the executor watches the probe input on (motion_probe.c). */
static int add_probe(struct motion *m, struct motion_plan *p, const struct canon_cmd *c,
                     const double *from)
{
    struct canon_cmd line = *c;
    line.type = CANON_FEED;
    memcpy(line.end, c->probe_stop, sizeof line.end);
    if (c->inverse_time_min > 0) {
        /* G93: the whole move to end takes that long, wherever the probe stops it */
        double xyz = 0, abc = 0;
        for (int i = 0; i < 3; i++) {
            xyz += (c->end[i] - from[i]) * (c->end[i] - from[i]);
            abc += (c->end[i + 3] - from[i + 3]) * (c->end[i + 3] - from[i + 3]);
        }
        double len = sqrt(xyz) >= EPS_LEN ? sqrt(xyz) : sqrt(abc);
        line.feed_mm_min = len / c->inverse_time_min;
        line.inverse_time_min = 0;
    }
    if (add_stop(p, c, from, SEG_DWELL, 0) < 0)
        return -1;
    size_t n0 = p->nseg;
    if (add_line(p, &line, from) < 0)
        return -1;
    if (p->nseg > n0) {
        struct motion_seg *sg = &p->segs[p->nseg - 1];
        set_speed(m, sg, &line, 0);
        sg->probe = 1;
        sg->probe_type = c->ivalue;
    }
    return add_stop(p, c, c->probe_stop, SEG_DWELL, 0);
}

/* G33/G33.1: a straight line whose path position the spindle drives (motion_sync.c). A run
 * of them is met at rest; within a run (a tap's way in and out, G33s that follow on) the
 * executor hands over itself. Refused (-2, err) when the machine cannot follow it. */
static int add_sync(struct motion *m, struct motion_plan *p, const struct canon_cmd *c,
                    const double *from, int sp_dir, double sp_rpm, char *err, size_t errlen)
{
    if (!(p->nseg && p->segs[p->nseg - 1].sync) && add_stop(p, c, from, SEG_DWELL, 0) < 0)
        return -1;
    size_t n0 = p->nseg;
    if (add_line(p, c, from) < 0)
        return -1;
    if (p->nseg == n0)
        return 0;              /* no length (the interpreter refuses those) */
    struct motion_seg *sg = &p->segs[p->nseg - 1];
    set_speed(m, sg, c, 0);
    sg->sync = c->sync;
    sg->pitch_mm_rev = c->pitch_mm_rev;
    sg->retract_factor = c->retract_factor > 0 ? c->retract_factor : 1.0;
    sg->sync_rpm = sp_rpm;
    sg->sync_dir = sp_dir;
    return motion_sync_check(m, sg, err, errlen);
}

/* The programmed speed of a move (feed, G93 inverse time, or rapid) and its path mode. */
static void set_speed(const struct motion *m, struct motion_seg *sg, const struct canon_cmd *c,
                      double blend_tol_mm)
{
    sg->blend_tol_mm = blend_tol_mm;
    if (c->type == CANON_TRAVERSE || sg->kind == SEG_DWELL || sg->kind == SEG_PAUSE ||
        sg->kind == SEG_WAIT)
        sg->feed = 0;
    else if (c->inverse_time_min > 0)
        sg->feed = sg->len / (c->inverse_time_min * 60.0);
    else if (c->feed_mm_min > 0)
        sg->feed = c->feed_mm_min / 60.0;
    else
        sg->feed = m->cfg.default_lin_vel_mm_s;
}

/* The last segment, a blend arc, turns A B C along the cubic whose rates at both ends are
 * the lines' (slopes per unit of u: rate per mm times the arc's length). */
static void blend_abc(struct motion_plan *p, const struct motion_blend_abc *b)
{
    struct motion_seg *sg = &p->segs[p->nseg - 1];
    struct motion_arc *a = &p->arcs[sg->arc];
    a->abc_cubic = 1;
    for (int k = 0; k < 3; k++) {
        a->abc_m0[k] = b->rate0[k] * sg->len;
        a->abc_m1[k] = b->rate1[k] * sg->len;
    }
}

/* A spindle or coolant command before the segment that comes next. */
static int add_io(struct motion_plan *p, enum motion_io_kind kind, double value, int ivalue)
{
    if (p->nios == p->capios) {
        size_t cap = p->capios ? 2 * p->capios : 16;
        struct motion_io *n = realloc(p->ios, cap * sizeof *n);
        if (!n)
            return -1;
        p->ios = n, p->capios = cap;
    }
    p->ios[p->nios++] = (struct motion_io){ p->nseg, kind, value, ivalue };
    return 0;
}

/* Under tool centre point control the path is the tool tip's: a move carries its mode and
 * tool length, and the pose it starts from is re-expressed when they change (the machine
 * stands still there: an exact stop, as the two paths' tangents are in different spaces). */
static int tcp_switch(struct motion *m, const struct canon_cmd *c, double at[KINS_POSE_DIM],
                      int *at_tcp, double *at_len, char *err, size_t errlen)
{
    double len = c->tcp ? c->tool_len_mm : 0;
    if (c->tcp == *at_tcp && len == *at_len)
        return 0;
    if (c->tcp && !m->have_tf) {
        snprintf(err, errlen, "%s:%d: tool centre point control (G43.4) needs kinematics that "
                 "know where the tool is; this machine's do not", c->file ? c->file
                 : "program", c->line);
        return -2;
    }
    double plat[KINS_POSE_DIM];
    motion_platform(m, *at_tcp, *at_len, at, plat);
    if (c->tcp)
        kins_tcp_from_pose(&m->tf, len, plat, at);
    else
        memcpy(at, plat, sizeof plat);
    *at_tcp = c->tcp, *at_len = len;
    struct motion_plan *p = &m->plan;
    if (p->nseg == 0 || (p->segs[p->nseg - 1].kind != SEG_LINE &&
                         p->segs[p->nseg - 1].kind != SEG_ARC))
        return 0;
    if (add_stop(p, c, at, SEG_DWELL, 0) < 0)
        return -1;
    p->segs[p->nseg - 1].tcp = *at_tcp;
    p->segs[p->nseg - 1].tool_len_mm = *at_len;
    return 0;
}

/* Builds the segment list from the program (geometry only; speeds come later). */
int motion_path_build(struct motion *m, const struct canon_prog *prog,
                      const struct motion_blend_abc *abc, char *err, size_t errlen)
{
    struct motion_plan *p = &m->plan;
    double at[KINS_POSE_DIM];
    double blend = motion_blend_start(&m->cfg, prog); /* LinuxCNC's G64 unless told */
    int sp_dir = m->io.dir;    /* the spindle as the program leaves it so far */
    double sp_rpm = m->io.rpm;
    memcpy(at, prog->start, sizeof at);
    int at_tcp = prog->start_tcp;
    double at_len = prog->start_tcp ? prog->start_tool_len_mm : 0;
    for (int k = 0; k < 2; k++)
        m->pb_seg[k] = p->nseg;
    size_t i = 0;
    for (; i < prog->count; i++) {
        const struct canon_cmd *c = &prog->cmds[i];
        size_t nseg0 = p->nseg;
        for (int k = 0; k < 2; k++)
            if (m->pb_at[k] != SIZE_MAX && i <= m->pb_at[k])
                m->pb_seg[k] = p->nseg;
        if (motion_cancelled(m, c->file, c->line, err, errlen))
            return MOTION_ERR_CANCELLED;
        int rc = 0;
        if (c->type == CANON_TRAVERSE || c->type == CANON_FEED || c->type == CANON_ARC ||
            c->type == CANON_PROBE) {
            rc = tcp_switch(m, c, at, &at_tcp, &at_len, err, errlen);
            if (rc == -2)
                return MOTION_ERR_PROGRAM;
            if (rc < 0) {
                snprintf(err, errlen, "out of memory planning the program");
                return MOTION_ERR_NOMEM;
            }
            nseg0 = p->nseg;
        }
        bool moves = c->type == CANON_TRAVERSE || c->type == CANON_FEED ||
                     c->type == CANON_ARC || c->type == CANON_PROBE;
        if (moves && p->nseg && p->segs[p->nseg - 1].sync && !(c->type == CANON_FEED &&
                                                                c->sync))
            rc = add_stop(p, c, at, SEG_DWELL, 0);  /* a synchronised run ends at rest */
        if (rc < 0) {
            snprintf(err, errlen, "out of memory planning the program");
            return MOTION_ERR_NOMEM;
        }
        nseg0 = p->nseg;
        switch (c->type) {
        case CANON_FEED:
            rc = c->sync ? add_sync(m, p, c, at, sp_dir, sp_rpm, err, errlen)
                         : add_line(p, c, at);
            break;
        case CANON_TRAVERSE: rc = add_line(p, c, at); break;
        case CANON_PROBE: rc = add_probe(m, p, c, at); break;
        case CANON_ARC:
            rc = add_arc(p, c, at, abc && abc[i].blend, err, errlen);
            if (rc == 0 && abc && abc[i].blend)
                blend_abc(p, &abc[i]);
            break;
        case CANON_DWELL: rc = c->value > 0 ? add_stop(p, c, at, SEG_DWELL, c->value) : 0; break;
        case CANON_SETTING: rc = add_mark(p); break;
        case CANON_SPINDLE_SPEED: case CANON_SPINDLE_ON: case CANON_SPINDLE_STOP: {
            enum motion_io_kind k = c->type == CANON_SPINDLE_SPEED ? IO_SPINDLE_SPEED :
                                    c->type == CANON_SPINDLE_ON ? IO_SPINDLE_ON
                                                                : IO_SPINDLE_STOP;
            rc = add_io(p, k, c->value, 0);
            int dir = k == IO_SPINDLE_ON ? (c->value < 0 ? -1 : 1) : k == IO_SPINDLE_STOP
                      ? 0 : sp_dir;
            double rpm = k == IO_SPINDLE_SPEED ? fabs(c->value) : sp_rpm;
            /* started, reversed or a new speed while turning: wait until it is at speed */
            if (rc == 0 && m->wait_at_speed && dir != 0 && (dir != sp_dir || rpm != sp_rpm))
                rc = add_stop(p, c, at, SEG_WAIT, 0);
            sp_dir = dir, sp_rpm = rpm;
            break;
        }
        case CANON_COOLANT: rc = add_io(p, IO_COOLANT, 0, c->ivalue); break;
        case CANON_DIGITAL_OUT: case CANON_ANALOG_OUT: {
            bool dig = c->type == CANON_DIGITAL_OUT;
            int n = dig ? m->cfg.num_dio : m->cfg.num_aio;
            if (c->ivalue >= n) {
                snprintf(err, errlen, "%s:%d: M%d: %s output %d does not exist: the machine "
                         "has %d ([EMCMOT] %s)", c->file ? c->file : "program", c->line,
                         dig ? (c->immediate ? 64 : 62) + (c->value == 0) : c->immediate ?
                         68 : 67, dig ? "digital" : "analog", c->ivalue, n,
                         dig ? "NUM_DIO" : "NUM_AIO");
                return MOTION_ERR_PROGRAM;
            }
            rc = add_io(p, dig ? IO_DOUT : IO_AOUT, c->value, c->ivalue);
            break;
        }
        case CANON_WAIT_INPUT: {
            int n = c->analog ? m->cfg.num_aio : m->cfg.num_dio;
            if (c->ivalue >= n) {
                snprintf(err, errlen, "%s:%d: M66: %s input %d does not exist: the machine has "
                         "%d ([EMCMOT] %s)", c->file ? c->file : "program", c->line,
                         c->analog ? "analog" : "digital", c->ivalue, n,
                         c->analog ? "NUM_AIO" : "NUM_DIO");
                return MOTION_ERR_PROGRAM;
            }
            if ((rc = add_stop(p, c, at, SEG_WAIT, 0)) == 0) {
                struct motion_seg *w = &p->segs[p->nseg - 1];
                w->wait_input = 1;
                w->input = c->ivalue;
                w->input_analog = c->analog;
                w->input_mode = c->wait_mode;
                w->timeout_s = c->value;
            }
            break;
        }
        case CANON_TOOL_CHANGE:
            rc = add_io(p, c->value == 0 ? IO_TOOL_CHANGE : IO_TOOL_SET, 0, c->ivalue);
            if (rc == 0 && c->value == 0 && m->wait_tool && (rc = add_stop(p, c, at, SEG_WAIT,
                                                                           0)) == 0)
                p->segs[p->nseg - 1].wait_tool = 1;
            break;
        case CANON_PAUSE:
            if (c->ivalue == 0 || m->cfg.optional_stop)
                rc = add_stop(p, c, at, SEG_PAUSE, 0);
            break;
        default: break;        /* informational, or read again by the planner */
        }
        if (rc == -2)
            return MOTION_ERR_PROGRAM;
        if (rc < 0) {
            snprintf(err, errlen, "out of memory planning the program");
            return MOTION_ERR_NOMEM;
        }
        if (p->nseg > nseg0) {
            struct motion_seg *sg = &p->segs[p->nseg - 1];
            set_speed(m, sg, c, sg->sync ? 0 : blend);
            sg->tcp = at_tcp;
            sg->tool_len_mm = at_len;
        }
        if (c->type == CANON_PATH_MODE)  /* G64 (ivalue 640) without P: BLEND_TOLERANCE */
            blend = motion_blend_tolerance(&m->cfg, c);
        if (c->type == CANON_TRAVERSE || c->type == CANON_FEED || c->type == CANON_ARC)
            memcpy(at, c->end, sizeof at);
        else if (c->type == CANON_PROBE)
            memcpy(at, c->probe_stop, sizeof at);
        if (c->type == CANON_PROGRAM_END)
            break;
    }
    for (int k = 0; k < 2; k++)   /* cut points at or past the end: every segment before */
        if (m->pb_at[k] != SIZE_MAX && m->pb_at[k] >= i)
            m->pb_seg[k] = p->nseg;
    if (motion_chord_zones(m) < 0) {   /* knots where a chord's reach of an arc ends */
        snprintf(err, errlen, "out of memory planning the program");
        return MOTION_ERR_NOMEM;
    }
    double dist = 0;
    for (i = 0; i < p->nseg; i++) {
        p->segs[i].dist0_mm = dist;
        dist += p->segs[i].xyz_len_mm;
    }
    p->total_len_mm = dist;
    return MOTION_OK;
}

int motion_plan_reserve(struct motion_plan *p, size_t nseg, size_t narc, size_t nknot)
{
    if (p->capseg || p->caparc || p->capknot)
        return 0;                     /* (an empty plan's arrays only) */
    struct motion_plan r = { 0 };
    double **arr[7] = {&r.ks, &r.kv, &r.kt, &r.krho, &r.iacc, &r.irho, &r.ivp};
    int ok = nseg && nknot && (r.segs = malloc(nseg * sizeof *r.segs)) &&
             (!narc || (r.arcs = malloc(narc * sizeof *r.arcs)));
    for (int i = 0; i < 7 && ok; i++)
        ok = (*arr[i] = malloc(nknot * sizeof **arr[i])) != NULL;
    if (!ok) {                        /* (the plan grows as it needs instead) */
        free(r.segs), free(r.arcs);
        for (int i = 0; i < 7; i++)
            free(*arr[i]);
        return -1;
    }
    p->segs = r.segs, p->capseg = nseg;
    p->arcs = r.arcs, p->caparc = narc;
    p->ks = r.ks, p->kv = r.kv, p->kt = r.kt, p->krho = r.krho;
    p->iacc = r.iacc, p->irho = r.irho, p->ivp = r.ivp, p->capknot = nknot;
    return 0;
}

/* Frees everything a plan holds and empties it. */
void motion_plan_free(struct motion_plan *p)
{
    free(p->segs);
    free(p->arcs);
    free(p->ks);
    free(p->kv);
    free(p->kt);
    free(p->krho);
    free(p->iacc);
    free(p->irho);
    free(p->ivp);
    for (size_t i = 0; i < p->nfiles; i++)
        free(p->files[i]);
    free(p->files);
    free(p->marks);
    free(p->ios);
    memset(p, 0, sizeof *p);
}
