/* nurbs.c: G5.2 / G5.3, LinuxCNC's NURBS in the XY plane: control points collected block by
 * block, the curve sent as chords within a bound when G5.3 ends it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "interp/interp_int.h"

#define W(c) (in->blk.col[(c) - 'a'])    /* column of word c, 0 if absent */
#define V(c) (in->blk.val[(c) - 'a'])    /* value of word c */

#define NURBS_MAX_POINTS 100000  /* control points of one curve */
#define NURBS_SAMPLES 8          /* a chord is tested at 7 points inside it */
#define NURBS_MAX_DEPTH 40       /* halvings of a knot span */

/* Frees the points collected (the interpreter's end). */
void interp_nurbs_free(struct nurbs *nb)
{
    free(nb->pt);
    memset(nb, 0, sizeof *nb);
}

/* Appends a control point (machine X Y, mm) of weight w. */
static int nurbs_add(struct interp *in, double x, double y, double w)
{
    struct nurbs *nb = &in->nurbs;
    if (nb->n == nb->cap) {
        int cap = nb->cap ? 2 * nb->cap : 16;
        if (nb->n >= NURBS_MAX_POINTS)
            return interp_fail(in, INTERP_ERR_WORD, in->blk.gcol[1], "G5.2: more than %d "
                               "control points in one NURBS", NURBS_MAX_POINTS);
        struct nurbs_point *p = realloc(nb->pt, (size_t)cap * sizeof *p);
        if (!p)
            return interp_fail(in, INTERP_ERR_NOMEM, 0, "out of memory");
        nb->pt = p;
        nb->cap = cap;
    }
    nb->pt[nb->n++] = (struct nurbs_point){ x, y, w };
    return 0;
}

/*
 * G5.2 X Y P [L]: one control point X Y of weight P. The first block of a curve starts it at
 * the present point (weight 1, or P when that block has no X Y: then P weighs the present
 * point); L (more than 3) sets the order, 3 (quadratic) otherwise, as LinuxCNC. The points
 * are kept in the machine frame (G91 points are counted from the curve's start, which stays
 * the present point until G5.3, as in LinuxCNC); nothing moves before G5.3.
 */
int interp_nurbs_point(struct interp *in, int prev_motion)
{
    struct nurbs *nb = &in->nurbs;
    const struct interp_block *b = &in->blk;
    int col = b->g[1] >= 0 ? b->gcol[1] : W('x') ? W('x') : W('y');
    if (in->plane != 17)
        return interp_fail(in, INTERP_ERR_MODAL, col, "G5.2: a NURBS must be in the XY plane "
                           "(G17); G%d is in force", in->plane);
    if (in->inverse_time)
        return interp_fail(in, INTERP_ERR_MODAL, col, "G5.2 in inverse time mode (G93) is not "
                           "supported: give the feed with G94");
    static const char others[] = "zabc";
    for (int k = 0; k < 4; k++)
        if (W(others[k]))
            return interp_fail(in, INTERP_ERR_WORD, W(others[k]), "G5.2 control points lie "
                               "in the XY plane: no Z, A, B or C");
    if (!W('x') != !W('y'))
        return interp_fail(in, INTERP_ERR_WORD, W('x') ? W('x') : W('y'), "G5.2 needs both X "
                           "and Y for a control point");
    if (prev_motion != 52)
        nb->n = 0;             /* a new curve */
    if (nb->n > 0 && !W('x') && W('p'))
        return interp_fail(in, INTERP_ERR_WORD, W('p') ? W('p') : col, "G5.2 without X Y: "
                           "only the first block of a NURBS may give P alone (the start's "
                           "weight)");
    if (W('x') && !(W('p') && V('p') > 0))
        return interp_fail(in, INTERP_ERR_WORD, W('p') ? W('p') : col, "G5.2 needs a positive "
                           "weight P for every control point%s", W('p') ? "" : " (P is missing)");
    CHP(interp_need_feed(in, "G5.2"));
    if (nb->n == 0) {
        nb->order = 3;
        CHP(nurbs_add(in, in->pos[0], in->pos[1], !W('x') && W('p') && V('p') > 0 ? V('p')
                                                                              : 1.0));
    }
    if (W('l')) {
        int l;
        CHP(interp_to_int(in, V('l'), W('l'), "G5.2 L (order)", &l));
        if (l > 3)
            nb->order = l;
    }
    if (W('x')) {
        double t[6];
        interp_target(in, 0, t);
        CHP(nurbs_add(in, t[0], t[1], V('p')));
    }
    return 0;
}

/* LinuxCNC's knots for n + 1 points of order k: k zeros, 1 .. n - k + 1, k times n - k + 2. */
static double knot(int i, int n, int k)
{
    return i < k ? 0 : i <= n ? i - k + 1 : n - k + 2;
}

/* The curve at u (de Boor's algorithm on homogeneous points, Piegl & Tiller A4.1). */
static void nurbs_at(const struct nurbs *nb, double u, double out[2])
{
    int n = nb->n - 1, k = nb->order, p = k - 1;
    int span = (int)floor(u) + p;          /* knots are the integers: span from u itself */
    if (span > n)
        span = n;
    if (span < p)
        span = p;
    double h[64][3];                       /* order <= 64 (checked at G5.3) */
    for (int j = 0; j <= p; j++) {
        const struct nurbs_point *c = &nb->pt[span - p + j];
        h[j][0] = c->x * c->w, h[j][1] = c->y * c->w, h[j][2] = c->w;
    }
    for (int r = 1; r <= p; r++)
        for (int j = p; j >= r; j--) {
            int i = span - p + j;
            double lo = knot(i, n, k), hi = knot(i + p - r + 1, n, k);
            double a = hi > lo ? (u - lo) / (hi - lo) : 0;
            for (int d = 0; d < 3; d++)
                h[j][d] = (1 - a) * h[j - 1][d] + a * h[j][d];
        }
    out[0] = h[p][0] / h[p][2];
    out[1] = h[p][1] / h[p][2];
}

/* Distance from q to the segment a b. */
static double seg_dist(const double a[2], const double b[2], const double q[2])
{
    double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
    double t = l2 > 0 ? ((q[0] - a[0]) * dx + (q[1] - a[1]) * dy) / l2 : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return hypot(q[0] - a[0] - t * dx, q[1] - a[1] - t * dy);
}

/* The chord ends made so far (machine X Y, mm; [0] the curve's start). */
struct chords {
    double (*pt)[2];
    int n, cap;
};

/* Appends a chord end; -1 when out of memory. */
static int chord_push(struct chords *c, const double p[2])
{
    if (c->n == c->cap) {
        int cap = c->cap ? 2 * c->cap : 256;
        double (*q)[2] = realloc(c->pt, (size_t)cap * sizeof *q);
        if (!q)
            return -1;
        c->pt = q;
        c->cap = cap;
    }
    c->pt[c->n][0] = p[0], c->pt[c->n][1] = p[1];
    c->n++;
    return 0;
}

/* The chords from p0 = C(u0) to p1 = C(u1) within one knot span. There the curve is one
 * smooth rational polynomial; over a short step of u it is close to a parabola, whose
 * distance from the chord is sampled finely (7 points) and held to half the tolerance
 * before the chord is taken, else the step is halved. -2: more than SPLINE_MAX_CHORDS. */
static int chords_between(const struct nurbs *nb, struct chords *c, double u0,
                          const double p0[2], double u1, const double p1[2], int depth)
{
    double worst = 0, q[2];
    for (int s = 1; s < NURBS_SAMPLES; s++) {
        nurbs_at(nb, u0 + (u1 - u0) * s / NURBS_SAMPLES, q);
        worst = fmax(worst, seg_dist(p0, p1, q));
    }
    if (!(worst <= SPLINE_TOL_MM / 2) && depth < NURBS_MAX_DEPTH) {
        double um = 0.5 * (u0 + u1), pm[2];
        nurbs_at(nb, um, pm);
        int rc = chords_between(nb, c, u0, p0, um, pm, depth + 1);
        return rc ? rc : chords_between(nb, c, um, pm, u1, p1, depth + 1);
    }
    if (c->n > SPLINE_MAX_CHORDS)
        return -2;
    return chord_push(c, p1);
}

/* G5.3: the curve of the points collected, from the present point to the last one. */
int interp_nurbs_end(struct interp *in)
{
    struct nurbs *nb = &in->nurbs;
    int col = in->blk.gcol[0];
    if (in->motion != 52)
        return interp_fail(in, INTERP_ERR_MODAL, col, "G5.3 without G5.2 first: G5.3 ends the "
                           "control points G5.2 gave");
    if (in->blk.g[1] >= 0 || W('x') || W('y'))
        return interp_fail(in, INTERP_ERR_MODAL, col, "G5.3 ends a NURBS: put it in a block of "
                           "its own, without motion codes or axis words");
    in->motion = -1;
    if (nb->n < nb->order)
        return interp_fail(in, INTERP_ERR_WORD, col, "G5.3: a NURBS of order L = %d needs at "
                           "least %d control points (the start and %d G5.2 points); it has %d",
                           nb->order, nb->order, nb->order - 1, nb->n);
    if (nb->order > 64)
        return interp_fail(in, INTERP_ERR_WORD, col, "G5.3: order L = %d is more than 64",
                           nb->order);
    struct chords c = { 0 };
    double umax = nb->n - nb->order + 1, p0[2] = { nb->pt[0].x, nb->pt[0].y };
    int rc = chord_push(&c, p0);
    for (int s = 0; rc == 0 && s < (int)umax; s++) {   /* knot span by knot span */
        double a[2], b[2];
        nurbs_at(nb, s, a);
        if (s + 1 == (int)umax)
            b[0] = nb->pt[nb->n - 1].x, b[1] = nb->pt[nb->n - 1].y;  /* the end exactly */
        else
            nurbs_at(nb, s + 1, b);
        rc = chords_between(nb, &c, s, s == 0 ? p0 : a, s + 1, b, 0);
    }
    if (rc == 0)
        rc = interp_spline_emit(in, (const double (*)[2])c.pt, c.n - 1, nb->n);
    else if (rc == -2)
        rc = interp_fail(in, INTERP_ERR_WORD, col, "G5.3: the NURBS needs more than %d chords "
                         "to stay within %g mm", SPLINE_MAX_CHORDS, SPLINE_TOL_MM);
    else
        rc = interp_fail(in, INTERP_ERR_NOMEM, 0, "out of memory");
    free(c.pt);
    nb->n = 0;
    return rc;
}
