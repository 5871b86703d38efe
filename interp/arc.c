/* arc.c: G2/G3 in G17/G18/G19: centre (I J K) and radius (R) forms, full circles, helices. */
#include <math.h>
#include <string.h>

#include "interp/interp_int.h"

#define W(c) (in->blk.col[(c) - 'a'])
#define V(c) (in->blk.val[(c) - 'a'])

/* LinuxCNC's check that both ends are on one circle: an error when the radii differ by more
 * than 0.0283 mm (0.00283 in: a centre and ends rounded to 0.01 mm, 2 sqrt(2) 0.01) and by
 * 0.1 %, or by more than 100 times that absolute tolerance. */
#define ARC_TOL_MM (0.02 * M_SQRT2)
#define ARC_TOL_IN (0.002 * M_SQRT2)
#define ARC_REL_TOL 0.001

/* The two in-plane axes (first, second, as LinuxCNC orders them), the normal axis and the
 * centre words of a plane. G18's first axis is Z, so that (Z, X, Y) is right-handed. */
struct plane_axes {
    int a1, a2, n;
    char w1, w2, wn;
};

/* The axes and centre words of G17, G18 or G19. */
static struct plane_axes plane_of(int plane)
{
    if (plane == 18)
        return (struct plane_axes){AX_Z, AX_X, AX_Y, 'k', 'i', 'j'};
    if (plane == 19)
        return (struct plane_axes){AX_Y, AX_Z, AX_X, 'j', 'k', 'i'};
    return (struct plane_axes){AX_X, AX_Y, AX_Z, 'i', 'j', 'k'};
}

/* R form: the centre on the side that gives the short arc (R > 0) or the long one (R < 0).
 * Program units, and LinuxCNC's very formula, so that the centres agree to the last bit. */
static int centre_from_r(struct interp *in, int ccw, const double s[2], const double e[2],
                         double c[2])
{
    double r = V('r'), ar = fabs(r);
    double mid0 = (e[0] + s[0]) / 2.0, mid1 = (e[1] + s[1]) / 2.0;
    double half = hypot(mid0 - e[0], mid1 - e[1]);
    if (half < 1e-12)
        return interp_fail(in, INTERP_ERR_ARC, W('r'), "an arc in R form cannot end where it "
                           "starts: program a full circle with I J K");
    if (ar < 1e-12 || half / ar > 1.0 + 1e-12)
        return interp_fail(in, INTERP_ERR_ARC, W('r'), "arc radius R%g is too small to reach "
                           "the end point (half the distance is %.4f)", V('r'), half);
    if (half / ar > 1.0 - 1e-12)
        half = ar; /* a half circle, give or take rounding */
    double th = atan2(e[1] - s[1], e[0] - s[0]) +
                (((ccw && r > 0) || (!ccw && r < 0)) ? M_PI_2 : -M_PI_2);
    double off = ar * cos(asin(half / ar));
    c[0] = mid0 + off * cos(th);
    c[1] = mid1 + off * sin(th);
    return 0;
}

/* I J K form, program units: the centre as an offset from the start (G91.1) or absolute
 * (G90.1). */
static int centre_from_ijk(struct interp *in, const struct plane_axes *p, const double s[2],
                           double c[2])
{
    if (W(p->wn))
        return interp_fail(in, INTERP_ERR_WORD, W(p->wn), "%c word in a G%d arc: the centre "
                           "words of this plane are %c and %c", p->wn - 32, in->plane,
                           p->w1 - 32, p->w2 - 32);
    if (!W(p->w1) && !W(p->w2))
        return interp_fail(in, INTERP_ERR_WORD, in->blk.g[1] >= 0 ? in->blk.gcol[1] : 0,
                           "arc with neither R nor a centre word (%c, "
                           "%c) for G%d", p->w1 - 32, p->w2 - 32, in->plane);
    double o1 = W(p->w1) ? V(p->w1) : 0.0, o2 = W(p->w2) ? V(p->w2) : 0.0;
    c[0] = in->arc_absolute ? o1 : s[0] + o1;
    c[1] = in->arc_absolute ? o2 : s[1] + o2;
    return 0;
}

/* Both ends must lie on one circle about the centre (LinuxCNC's tolerances), program units. */
static int check_radii(struct interp *in, const double s[2], const double e[2], const double c[2])
{
    double r1 = hypot(s[0] - c[0], s[1] - c[1]), r2 = hypot(e[0] - c[0], e[1] - c[1]);
    double tol = in->inch ? ARC_TOL_IN : ARC_TOL_MM;
    int col = in->blk.g[1] >= 0 ? in->blk.gcol[1] : 0;
    const char *u = in->inch ? "in" : "mm";
    if (r1 < 1e-9 || r2 < 1e-9)
        return interp_fail(in, INTERP_ERR_ARC, col, "zero-radius arc: the centre is on the %s "
                           "point (start radius %.4f %s, end radius %.4f %s)",
                           r1 < 1e-9 ? "start" : "end", r1, u, r2, u);
    double err = fabs(r1 - r2), rel = err / fmax(r1, r2);
    if (err > tol * 100.0 || (rel > ARC_REL_TOL && err > tol))
        return interp_fail(in, INTERP_ERR_ARC, col, "the end of the arc is not on its circle: "
                           "radius %.4f %s at the start, %.4f %s at the end (difference %.4f %s; "
                           "check the centre words and the end point)", r1, u, r2, u, err, u);
    return 0;
}

/* G2 (g = 20) or G3 (30): centre from R or I J K, checked, then one ARC command. */
int interp_arc(struct interp *in, int g)
{
    static const char letter[3] = {'x', 'y', 'z'};
    struct plane_axes p = plane_of(in->plane);
    int ccw = g == 30, turns = 1;
    double end[6], cur[6], s[2], e[2], c[2] = {0, 0};
    if (in->cc.arc_not_allowed)
        return interp_fail(in, INTERP_ERR_CCOMP, in->blk.g[1] >= 0 ? in->blk.gcol[1] : 0,
                           "the move after G40 must be straight, not an arc: the tool is "
                           "still beside the contour, a radius away from the arc's start");
    interp_target(in, 0, end);
    interp_prog_pos(in, cur);
    int ax[2] = {p.a1, p.a2};
    double from[2] = {cur[ax[0]], cur[ax[1]]};
    ccomp_start(in, from);  /* under G41/G42: the programmed point, not the tool's */
    for (int i = 0; i < 2; i++) { /* the ends in program units, as LinuxCNC computes arcs */
        s[i] = from[i];
        e[i] = !W(letter[ax[i]]) ? s[i] : in->incremental ? s[i] + V(letter[ax[i]])
                                                           : V(letter[ax[i]]);
    }
    if (W('r') && (W('i') || W('j') || W('k')))
        return interp_fail(in, INTERP_ERR_WORD, W('r'), "arc with both R and I/J/K: use one form "
                           "or the other");
    if (W('p')) {
        CHP(interp_to_int(in, V('p'), W('p'), "P (number of turns)", &turns));
        if (turns < 1)
            return interp_fail(in, INTERP_ERR_WORD, W('p'), "P (number of turns) must be 1 or "
                               "more, not %d", turns);
    }
    if (W('r'))
        CHP(centre_from_r(in, ccw, s, e, c));
    else
        CHP(centre_from_ijk(in, &p, s, c));
    CHP(check_radii(in, s, e, c));
    if (ccomp_active(in))
        return ccomp_arc(in, g, s, e, c, ccw ? turns : -turns, end);

    struct canon_cmd cmd;
    interp_cmd_init(in, &cmd, CANON_ARC);
    memcpy(cmd.end, end, sizeof cmd.end);
    for (int i = 0; i < 2; i++)
        cmd.arc.center[ax[i]] = interp_len_mm(in, c[i]) + in->g5x[ax[i]] + in->g92[ax[i]] +
                                in->tool[ax[i]];
    cmd.arc.center[p.n] = in->pos[p.n];
    cmd.arc.normal[p.n] = 1.0;
    if (in->rot_deg != 0.0) {  /* the centre and the plane turn with the coordinate system */
        double pc[6], m[2];
        interp_prog_pos(in, pc);
        pc[ax[0]] = c[0], pc[ax[1]] = c[1];
        interp_xy_to_machine(in, pc[AX_X], pc[AX_Y], m);
        cmd.arc.center[AX_X] = m[0], cmd.arc.center[AX_Y] = m[1];
        interp_rotate_xy(&cmd.arc.normal[AX_X], &cmd.arc.normal[AX_Y], in->rot_deg);
    }
    cmd.arc.rotation = ccw ? turns : -turns;
    cmd.arc.plane = in->plane;
    cmd.feed_mm_min = in->feed_mm_min;
    if (in->inverse_time)
        cmd.inverse_time_min = 1.0 / in->f_word;
    memcpy(in->pos, end, sizeof in->pos);
    return interp_emit(in, &cmd);
}
