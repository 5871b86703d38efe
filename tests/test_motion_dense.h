/* test_motion_dense.h: random dense programs, made the way CAM code comes (moves of 0.002 to
 * 1 mm, zero-length ones, small arcs either way, longer moves, collinear runs and corners up
 * to 175 degrees, A B C still, drifting or turning in place, G61 or G64 P with and without Q,
 * feeds from 0.3 to 12 m/min), and how far a pose is from their programmed moves; for
 * test_motion_random and test_motion_stream. */
#ifndef HEXCNC_TEST_MOTION_DENSE_H
#define HEXCNC_TEST_MOTION_DENSE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_merge.h"
#include "tests/test_motion_util.h"

#define FIRST_LINE 3           /* the first move's line (the path mode is on line 2) */

/* What a case's program is: its path mode and the moves' start points (move i on line
 * FIRST_LINE + i is command cmd[i] of the program). */
struct dense {
    struct canon_prog p;
    int g61;
    double tol_p, tol_q, max_feed_mm_s;
    int n;
    double (*from)[6];
    size_t *cmd;
    double end[6];
};

/* A turn of the heading h (unit, X Y Z) by ang rad about Z, its Z part nudged by dz. */
static inline void dense_turn(double h[3], double ang, double dz)
{
    double x = h[0] * cos(ang) - h[1] * sin(ang), y = h[0] * sin(ang) + h[1] * cos(ang);
    double z = fmax(-0.3, fmin(0.3, h[2] + dz)), n = sqrt(x * x + y * y + z * z);
    h[0] = x / n, h[1] = y / n, h[2] = z / n;
}

/* Whether a pose is inside the box the cases stay in. */
static inline int dense_inside(const double q[6])
{
    int ok = fabs(q[0]) <= 55 && fabs(q[1]) <= 55 && q[2] >= 632 && q[2] <= 658;
    for (int i = 3; i < 6; i++)
        ok = ok && fabs(q[i]) <= 7;
    return ok;
}

/* Move i starts at `at`; its command is the one the program gets next. */
static inline void dense_add_move(struct dense *d, int i, const double at[6])
{
    memcpy(d->from[i], at, sizeof d->from[i]);
    d->cmd[i] = d->p.count;
}

/* A random dense program of nmin to nmax moves (see the top of the file). */
static inline void dense_prog(struct dense *d, unsigned long long *s, int nmin, int nmax)
{
    static const double tols[] = { 0.001, 0.005, 0.01, 0.05 };
    memset(d, 0, sizeof *d);
    canon_prog_init(&d->p);
    double at[6] = { 0, 0, 645, 0, 0, 0 };
    memcpy(d->p.start, at, sizeof at);
    d->g61 = tm_uniform(s) < 0.2;
    d->tol_p = d->g61 ? 0 : tols[(int)(tm_uniform(s) * 4)];
    double q = tm_uniform(s);
    d->tol_q = d->g61 || q < 0.4 ? 0 : q < 0.7 ? d->tol_p : 0.5 * d->tol_p;
    struct canon_cmd pm = { .type = CANON_PATH_MODE, .line = 2, .file = "test.ngc",
                            .value = d->tol_p, .ivalue = d->g61 ? 610 : 640,
                            .naive_tol_mm = d->tol_q };
    if (canon_prog_sink(&d->p, &pm))
        abort();
    d->n = nmin + (int)(tm_uniform(s) * (nmax - nmin));
    d->from = calloc((size_t)d->n, sizeof *d->from);
    d->cmd = calloc((size_t)d->n, sizeof *d->cmd);
    if (!d->from || !d->cmd)
        abort();
    int abc_style = (int)(tm_uniform(s) * 3);  /* still, drifting, drifting with jumps */
    double feed = 300 + tm_uniform(s) * 11700, h[3] = { 1, 0, 0 }, rate[3] = { 0, 0, 0 };
    d->max_feed_mm_s = feed / 60;
    dense_turn(h, tm_uniform(s) * 2 * M_PI, 0);
    for (int i = 0; i < d->n; i++) {
        int line = FIRST_LINE + i;
        double to[6], u = tm_uniform(s);
        if (tm_uniform(s) < 0.05) {            /* a new feed */
            feed = 300 + tm_uniform(s) * 11700;
            d->max_feed_mm_s = fmax(d->max_feed_mm_s, feed / 60);
        }
        if (abc_style && tm_uniform(s) < 0.1)  /* A B C turn at a new rate (deg per mm) */
            for (int k = 0; k < 3; k++)
                rate[k] = -0.5 + tm_uniform(s);
        dense_add_move(d, i, at);
        if (u < 0.05) {                        /* a small arc in XY, either way, tangent */
            double r = 0.2 + tm_uniform(s) * 4.8, sweep = (10 + tm_uniform(s) * 160) * M_PI / 180;
            int ccw = tm_uniform(s) < 0.5;
            double side = ccw ? 1 : -1, c[3], n[3] = { 0, 0, side }, hn = hypot(h[0], h[1]);
            c[0] = at[0] - side * r * h[1] / hn, c[1] = at[1] + side * r * h[0] / hn;
            c[2] = at[2];
            double a0 = atan2(at[1] - c[1], at[0] - c[0]), a1 = a0 + side * sweep;
            memcpy(to, at, sizeof to);
            to[0] = c[0] + r * cos(a1), to[1] = c[1] + r * sin(a1);
            if (dense_inside(to)) {
                /* (about the normal n the arc turns counter-clockwise: n is -Z for G2) */
                tm_arc(&d->p, line, to, c, n, 1, feed);
                double hz = h[2];
                h[0] = -side * sin(a1), h[1] = side * cos(a1), h[2] = 0;
                dense_turn(h, 0, hz);
                memcpy(at, to, sizeof at);
                continue;
            }
        }
        double len = exp(log(0.002) + tm_uniform(s) * (log(1.0) - log(0.002)));
        double v = tm_uniform(s);
        if (v < 0.03)
            len = 0;                           /* the same point again */
        else if (v < 0.05)
            len = 2 + tm_uniform(s) * 8;       /* a longer move */
        double w = tm_uniform(s), ang = 0;
        if (w < 0.3)
            ang = 0;                           /* collinear */
        else if (w < 0.8)
            ang = tm_uniform(s) * 3 * M_PI / 180;
        else if (w < 0.95)
            ang = (3 + tm_uniform(s) * 27) * M_PI / 180;
        else
            ang = (30 + tm_uniform(s) * 145) * M_PI / 180;
        dense_turn(h, tm_uniform(s) < 0.5 ? ang : -ang, 0.02 * (tm_uniform(s) - 0.5));
        memcpy(to, at, sizeof to);
        for (int k = 0; k < 3; k++)
            to[k] += len * h[k], to[3 + k] += len * rate[k];
        if (abc_style == 2 && tm_uniform(s) < 0.03) /* a turn of A B C in place, or nearly */
            for (int k = 0; k < 3; k++)
                to[k] = at[k] + (tm_uniform(s) < 0.5 ? 0 : 0.002 * h[k]),
                to[3 + k] = at[3 + k] + (tm_uniform(s) - 0.5);
        if (!dense_inside(to)) {               /* back towards the middle: a sharp corner */
            double c[3] = { -at[0], -at[1], 645 - at[2] }, n = 0;
            for (int k = 0; k < 3; k++)
                n += c[k] * c[k];
            n = sqrt(n);
            for (int k = 0; k < 3; k++)
                h[k] = c[k] / n, to[k] = at[k] + len * h[k];
            for (int k = 3; k < 6; k++)
                rate[k - 3] = -0.1 * at[k], to[k] = at[k] + len * rate[k - 3];
        }
        tm_add(&d->p, CANON_FEED, line, to, feed, 0);
        memcpy(at, to, sizeof at);
    }
    memcpy(d->end, at, sizeof at);
}

static inline void dense_free(struct dense *d)
{
    canon_prog_free(&d->p);
    free(d->from);
    free(d->cmd);
}

/* How far the commanded tool may be from d's programmed moves, mm: under G64 the blends
 * within P, with jerk limits within half of it and the average's rounding the other half or
 * its share of KINEMATIC_TOLERANCE (docs/motion.md, "Jerk limiting"); the merge's Q on top. */
static inline double dense_allowed(const struct dense *d, const struct motion_config *mc,
                                   int jerk)
{
    return d->tol_q + (jerk ? fmax(d->tol_p, 0.5 * d->tol_p + mc->kin_tol_mm) : d->tol_p) +
           1e-6;
}

/* Distance of the commanded X Y Z q from the programmed moves within `reach` moves of the
 * one on `line`, and the MOTION_MERGE_MAX before those (a merged run of feeds carries its
 * last feed's line). */
static inline double off_path(const struct dense *d, const double q[3], int line, int reach)
{
    int j = line - FIRST_LINE, back = reach + MOTION_MERGE_MAX;
    int lo = j - back < 0 ? 0 : j - back;
    int hi = j + reach >= d->n ? d->n - 1 : j + reach;
    double best = HUGE_VAL;
    if (j < 0)                                 /* (before the first move: at the start) */
        return tm_dist_seg(q, d->p.start, d->p.start);
    for (int i = lo; i <= hi; i++) {
        const struct canon_cmd *c = &d->p.cmds[d->cmd[i]];
        best = fmin(best, c->type == CANON_ARC ? tm_dist_arc(q, d->from[i], c)
                                                : tm_dist_seg(q, d->from[i], c->end));
    }
    return best;
}

#endif
