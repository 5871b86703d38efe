/* test_comp5_join.c: G141/G142 corners: inside points, outside arcs, skew joins, continuity. */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>

#include "interp/comp5.h"
#include "tests/comp5_testutil.h"

#define TOL 1e-9 /* mm: the joins are closed-form, so they hold to rounding */

/* A tilted table (A B C all non-zero) and two unit directions in its plane: e1, and e2 = N x
 * e1, so that the right of travel along e1 (T x N) is -e2. */
struct plane {
    double abc[3], n[3], e1[3], e2[3], origin[3];
};

static struct plane tilted_plane(void)
{
    struct plane p = {{15, -20, 30}, {0}, {0}, {0}, {40, -10, 620}};
    tu_normal(p.abc[0], p.abc[1], p.abc[2], p.n);
    double x[3] = {1, 0, 0};
    double xn = tu_dot(x, p.n);
    for (int i = 0; i < 3; i++)
        p.e1[i] = x[i] - xn * p.n[i];
    tu_unit(p.e1);
    tu_cross(p.n, p.e1, p.e2);
    return p;
}

/* The machine point of in-plane coordinates (u, v), mm. */
static void plane_point(const struct plane *p, double u, double v, double out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = p->origin[i] + u * p->e1[i] + v * p->e2[i];
}

/* Runs a path of points (all at orientation abc) through comp5, recording the moves. */
static int run_path(int side, double pts[][3], double abc[][3], int n, double w_mm,
                    struct canon_prog *out)
{
    struct comp5 c;
    double start[6] = {0, 0, 700, 0, 0, 0};
    comp5_init(&c);
    canon_prog_init(out);
    for (int k = 0; k < n; k++) {
        struct comp5_block b = tu_block(side, pts[k][0], pts[k][1], pts[k][2], abc[k][0],
                                        abc[k][1], abc[k][2], w_mm, 10 + k);
        int rc = comp5_block(&c, &b, start, canon_prog_sink, out);
        if (rc != COMP5_OK)
            return rc;
    }
    return comp5_flush(&c, canon_prog_sink, out);
}

/* The compensated point of p for travel t at orientation abc, built independently. */
static void expected_offset(const double p[3], const double t[3], const double abc[3],
                            int side, double w_mm, double out[3])
{
    double n[3], v[3], tu[3] = {t[0], t[1], t[2]};
    tu_unit(tu);
    tu_normal(abc[0], abc[1], abc[2], n);
    tu_cross(tu, n, v);
    tu_unit(v);
    double s = side == 141 ? 1.0 : -1.0;
    for (int i = 0; i < 3; i++)
        out[i] = p[i] + s * w_mm * v[i];
}

/* A three-point corner in the tilted plane turning by turn_deg towards -e2 (right). */
static void corner_path(const struct plane *pl, double turn_deg, double pts[3][3],
                        double abc[3][3])
{
    double th = turn_deg * TU_DEG;
    plane_point(pl, 0, 0, pts[0]);
    plane_point(pl, 60, 0, pts[1]);
    plane_point(pl, 60 + 40 * cos(th), -40 * sin(th), pts[2]);
    for (int k = 0; k < 3; k++)
        memcpy(abc[k], pl->abc, sizeof abc[k]);
}

/* G141 turning right in a tilted plane: an inside corner. The join point lies on both
 * offset lines and at distance W from both contour segments; no arc. */
START_TEST(test_inside_tilted)
{
    struct plane pl = tilted_plane();
    double pts[3][3], abc[3][3], ta[3], tb[3], oa[3], ob[3];
    struct canon_prog p;
    const double w_mm = 6.0;
    corner_path(&pl, 70.0, pts, abc);
    ck_assert_int_eq(run_path(141, pts, abc, 3, w_mm, &p), COMP5_OK);
    ck_assert_uint_eq(p.count, 3);
    for (size_t k = 0; k < p.count; k++)
        ck_assert_int_eq(p.cmds[k].type, CANON_FEED);
    const double *j = p.cmds[1].end;
    for (int i = 0; i < 3; i++)
        ta[i] = pts[1][i] - pts[0][i], tb[i] = pts[2][i] - pts[1][i];
    expected_offset(pts[0], ta, abc[0], 141, w_mm, oa);
    expected_offset(pts[1], tb, abc[1], 141, w_mm, ob);
    ck_assert_double_eq_tol(tu_dist_line(j, oa, ta), 0.0, TOL);  /* on offset line a */
    ck_assert_double_eq_tol(tu_dist_line(j, ob, tb), 0.0, TOL);  /* on offset line b */
    ck_assert_double_eq_tol(tu_dist_line(j, pts[0], ta), w_mm, TOL);
    ck_assert_double_eq_tol(tu_dist_line(j, pts[1], tb), w_mm, TOL);
    double jo[3] = {j[0] - pl.origin[0], j[1] - pl.origin[1], j[2] - pl.origin[2]};
    ck_assert_double_eq_tol(tu_dot(jo, pl.n), 0.0, TOL);      /* stays in the plane */
    ck_assert_int_eq(p.cmds[1].line, 11);                       /* the corner's block */
    ck_assert_int_eq(p.cmds[1].compensated, 141);
    canon_prog_free(&p);
}
END_TEST

/* G141 turning left in the tilted plane: an outside corner, cut with an arc of radius W
 * about the programmed corner, in the plane of the two offset directions. */
START_TEST(test_outside_tilted)
{
    struct plane pl = tilted_plane();
    double pts[3][3], abc[3][3], ta[3], tb[3], a1[3], b0[3];
    struct canon_prog p;
    const double w_mm = 6.0;
    corner_path(&pl, -70.0, pts, abc);
    ck_assert_int_eq(run_path(141, pts, abc, 3, w_mm, &p), COMP5_OK);
    ck_assert_uint_eq(p.count, 4);
    const struct canon_cmd *arc = &p.cmds[2];
    const double *s = p.cmds[1].end; /* the arc starts where the cut ended */
    ck_assert_int_eq(arc->type, CANON_ARC);
    ck_assert_int_eq(arc->arc.plane, 0);
    ck_assert_int_eq(arc->arc.rotation, 1);
    ck_assert_int_eq(arc->compensated, 141);
    for (int i = 0; i < 3; i++)
        ta[i] = pts[1][i] - pts[0][i], tb[i] = pts[2][i] - pts[1][i];
    expected_offset(pts[1], ta, abc[1], 141, w_mm, a1);
    expected_offset(pts[1], tb, abc[1], 141, w_mm, b0);
    for (int i = 0; i < 3; i++) {
        ck_assert_double_eq_tol(arc->arc.center[i], pts[1][i], TOL);
        ck_assert_double_eq_tol(s[i], a1[i], TOL);
        ck_assert_double_eq_tol(arc->end[i], b0[i], TOL);
        ck_assert_double_eq_tol(arc->end[3 + i], abc[1][i], 1e-12); /* constant orientation */
    }
    double rs[3], re[3], x[3];
    for (int i = 0; i < 3; i++)
        rs[i] = s[i] - pts[1][i], re[i] = arc->end[i] - pts[1][i];
    ck_assert_double_eq_tol(tu_norm(rs), w_mm, TOL);
    ck_assert_double_eq_tol(tu_norm(re), w_mm, TOL);
    ck_assert_double_eq_tol(tu_norm(arc->arc.normal), 1.0, TOL);
    ck_assert_double_eq_tol(tu_dot(arc->arc.normal, rs), 0.0, TOL);
    ck_assert_double_eq_tol(tu_dot(arc->arc.normal, re), 0.0, TOL);
    tu_cross(rs, re, x); /* counter-clockwise about the normal, the short way (70 deg) */
    ck_assert(tu_dot(x, arc->arc.normal) > 0);
    ck_assert_double_eq_tol(acos(tu_dot(rs, re) / (w_mm * w_mm)) / TU_DEG, 70.0, 1e-9);
    /* The arc swings round the outside: its start tangent continues the travel. */
    double tan0[3];
    tu_cross(arc->arc.normal, rs, tan0);
    ck_assert(tu_dot(tan0, ta) > 0);
    ck_assert_double_eq_tol(fabs(tu_dot(arc->arc.normal, pl.n)), 1.0, TOL);
    canon_prog_free(&p);
}
END_TEST

/* A U-turn: a half circle about the corner, starting forward along the travel. */
START_TEST(test_u_turn)
{
    double pts[3][3] = {{0, 0, 0}, {50, 0, 0}, {10, 0, 0}}, abc[3][3] = {{0}};
    struct canon_prog p;
    ck_assert_int_eq(run_path(141, pts, abc, 3, 4.0, &p), COMP5_OK);
    ck_assert_uint_eq(p.count, 4);
    ck_assert_int_eq(p.cmds[2].type, CANON_ARC);
    ck_assert_double_eq_tol(p.cmds[1].end[1], -4.0, TOL);
    ck_assert_double_eq_tol(p.cmds[2].end[0], 50.0, TOL);
    ck_assert_double_eq_tol(p.cmds[2].end[1], 4.0, TOL);
    ck_assert_double_eq_tol(p.cmds[2].arc.normal[2], 1.0, TOL); /* CCW from -Y via +X */
    ck_assert_double_eq_tol(p.cmds[3].end[0], 10.0, TOL);
    canon_prog_free(&p);
}
END_TEST

/* The point of the line a + s d closest to the line j + r n (n unit): where the tool axis
 * through j meets the line, when the two cross. */
static void line_axis_point(const double j[3], const double n[3], const double a[3],
                            const double d[3], double out[3])
{
    double w[3] = {a[0] - j[0], a[1] - j[1], a[2] - j[2]};
    double dd = tu_dot(d, d), dn = tu_dot(d, n), wd = tu_dot(w, d), wn = tu_dot(w, n);
    double s = (dn * wn - wd) / (dd - dn * dn);
    for (int i = 0; i < 3; i++)
        out[i] = a[i] + s * d[i];
}

/* Orientation changes at every block: the offset lines of an inside corner are skew; seen
 * along the corner's tool axis they cross, and the join is the midpoint of the two points
 * that axis passes (they differ only along it). */
START_TEST(test_skew_inside)
{
    double pts[3][3] = {{0, 0, 500}, {60, 0, 500}, {60, -40, 500}};
    double abc[3][3] = {{0, 0, 0}, {8, -6, 0}, {0, -15, 10}};
    double a0[3], a1[3], b0[3], b1[3], da[3], db[3], pa[3], pb[3], t[3];
    struct canon_prog p;
    const double w_mm = 5.0;
    /* The A B C change along each move (the tool tilts while it moves straight), so the tool
     * comes closer than W to its own segment midway: the gouge check refuses the run once its
     * moves are out (test_comp5_gouge.c measures that); the geometry is checked here. */
    ck_assert_int_eq(run_path(141, pts, abc, 3, w_mm, &p), COMP5_ERR_GOUGE_CONTOUR);
    ck_assert_uint_eq(p.count, 3);
    for (int i = 0; i < 3; i++)
        t[i] = pts[1][i] - pts[0][i];
    expected_offset(pts[0], t, abc[0], 141, w_mm, a0);
    expected_offset(pts[1], t, abc[1], 141, w_mm, a1);
    for (int i = 0; i < 3; i++)
        t[i] = pts[2][i] - pts[1][i];
    expected_offset(pts[1], t, abc[1], 141, w_mm, b0);
    expected_offset(pts[2], t, abc[2], 141, w_mm, b1);
    for (int i = 0; i < 3; i++)
        da[i] = a1[i] - a0[i], db[i] = b1[i] - b0[i];
    const double *j = p.cmds[1].end;
    /* pa, pb: the points of the two lines that the corner's tool axis through j passes */
    double n[3], x[3];
    tu_normal(abc[1][0], abc[1][1], abc[1][2], n);
    line_axis_point(j, n, a0, da, pa);
    line_axis_point(j, n, b0, db, pb);
    double gap[3] = {pa[0] - pb[0], pa[1] - pb[1], pa[2] - pb[2]};
    ck_assert_msg(tu_norm(gap) > 1e-3, "lines not skew: gap %g", tu_norm(gap));
    tu_cross(gap, n, x);
    ck_assert_double_eq_tol(tu_norm(x), 0.0, TOL); /* they differ only along the axis */
    for (int i = 0; i < 3; i++) {
        ck_assert_double_eq_tol(j[i], 0.5 * (pa[i] + pb[i]), TOL);
        ck_assert_double_eq_tol(j[3 + i], abc[1][i], 1e-12); /* the corner's orientation */
        ck_assert_double_eq_tol(p.cmds[0].end[i], a0[i], TOL);
        ck_assert_double_eq_tol(p.cmds[2].end[i], b1[i], TOL);
    }
    canon_prog_free(&p);
}
END_TEST

/* An outside corner where A B C change from block to block: the arc keeps the corner's
 * orientation at both ends, lies perpendicular to the corner's tool axis, radius W. */
START_TEST(test_outside_orientation_change)
{
    double pts[3][3] = {{0, 0, 500}, {60, 0, 500}, {60, 40, 500}};
    double abc[3][3] = {{-5, 3, 0}, {6, -9, 12}, {0, -15, 25}};
    double n[3], rs[3], re[3];
    struct canon_prog p;
    const double w_mm = 5.0;
    /* The A B C change along each move (the tool tilts while it moves straight), so the tool
     * comes closer than W to its own segment midway: the gouge check refuses the run once its
     * moves are out (test_comp5_gouge.c measures that); the geometry is checked here. */
    ck_assert_int_eq(run_path(141, pts, abc, 3, w_mm, &p), COMP5_ERR_GOUGE_CONTOUR);
    ck_assert_uint_eq(p.count, 4);
    const struct canon_cmd *arc = &p.cmds[2];
    ck_assert_int_eq(arc->type, CANON_ARC);
    tu_normal(abc[1][0], abc[1][1], abc[1][2], n);
    for (int i = 0; i < 3; i++) {
        rs[i] = p.cmds[1].end[i] - pts[1][i];
        re[i] = arc->end[i] - pts[1][i];
        ck_assert_double_eq_tol(p.cmds[1].end[3 + i], abc[1][i], 1e-12);
        ck_assert_double_eq_tol(arc->end[3 + i], abc[1][i], 1e-12);
        ck_assert_double_eq_tol(p.cmds[0].end[3 + i], abc[0][i], 1e-12);
        ck_assert_double_eq_tol(p.cmds[3].end[3 + i], abc[2][i], 1e-12);
    }
    ck_assert_double_eq_tol(tu_norm(rs), w_mm, TOL);
    ck_assert_double_eq_tol(tu_norm(re), w_mm, TOL);
    ck_assert_double_eq_tol(tu_dot(rs, n), 0.0, TOL);
    ck_assert_double_eq_tol(tu_dot(re, n), 0.0, TOL);
    ck_assert_double_eq_tol(fabs(tu_dot(arc->arc.normal, n)), 1.0, TOL);
    canon_prog_free(&p);
}
END_TEST

/* Samples move k of a program (FEED: straight; ARC: about its normal) at fraction f. */
static void sample(const struct canon_prog *p, size_t k, const double from[3], double f,
                   double out[3])
{
    const struct canon_cmd *c = &p->cmds[k];
    if (c->type == CANON_FEED) {
        for (int i = 0; i < 3; i++)
            out[i] = from[i] + f * (c->end[i] - from[i]);
        return;
    }
    double rs[3], re[3], x[3];
    for (int i = 0; i < 3; i++)
        rs[i] = from[i] - c->arc.center[i], re[i] = c->end[i] - c->arc.center[i];
    tu_cross(rs, re, x);
    double sweep = atan2(tu_dot(x, c->arc.normal), tu_dot(rs, re));
    if (sweep <= 0)
        sweep += 2 * M_PI; /* rotation +1: counter-clockwise, possibly a half turn or more */
    tu_rotate(c->arc.normal, f * sweep / TU_DEG, rs, out);
    for (int i = 0; i < 3; i++)
        out[i] += c->arc.center[i];
}

/* A zigzag in the tilted plane with inside and outside corners: the emitted path is
 * continuous, never closer to the contour than W, and at W everywhere (no gap). */
START_TEST(test_path_distance)
{
    static const double uv[][2] = {{0, 0}, {50, 0}, {80, 30}, {120, 10}, {140, 40},
                                   {100, 70}, {60, 55}};
    enum { NPTS = sizeof uv / sizeof uv[0] };
    struct plane pl = tilted_plane();
    double pts[NPTS][3], abc[NPTS][3];
    const double w_mm = 4.0;
    for (int side = 141; side <= 142; side++) {
        struct canon_prog p;
        int arcs = 0, outside = 0;
        for (int k = 0; k < NPTS; k++) {
            plane_point(&pl, uv[k][0], uv[k][1], pts[k]);
            memcpy(abc[k], pl.abc, sizeof abc[k]);
        }
        for (int k = 1; k + 1 < NPTS; k++) { /* left turn (+e2 side) is outside for G141 */
            double cr = (uv[k][0] - uv[k - 1][0]) * (uv[k + 1][1] - uv[k][1]) -
                        (uv[k][1] - uv[k - 1][1]) * (uv[k + 1][0] - uv[k][0]);
            outside += side == 141 ? cr > 0 : cr < 0;
        }
        ck_assert_int_eq(run_path(side, pts, abc, NPTS, w_mm, &p), COMP5_OK);
        const double *from = p.cmds[0].end;
        for (size_t k = 1; k < p.count; k++) {
            arcs += p.cmds[k].type == CANON_ARC;
            ck_assert(tu_dist(from, p.cmds[k].end) > 1e-6); /* no empty moves */
            for (int f = 0; f <= 20; f++) {
                double q[3], dmin = 1e9;
                sample(&p, k, from, f / 20.0, q);
                for (int s = 0; s + 1 < NPTS; s++) {
                    double d = tu_dist_segment(q, pts[s], pts[s + 1]);
                    dmin = d < dmin ? d : dmin;
                }
                ck_assert_msg(fabs(dmin - w_mm) < 1e-6, "side %d move %zu at %d/20: %.9f mm",
                              side, k, f, dmin);
            }
            from = p.cmds[k].end;
        }
        ck_assert_int_eq(arcs, outside);
        ck_assert(outside > 0 && outside < NPTS - 2); /* both kinds of corner occur */
        canon_prog_free(&p);
    }
}
END_TEST

static Suite *comp5_join_suite(void)
{
    Suite *s = suite_create("comp5_join");
    TCase *tc = tcase_create("corners");
    tcase_add_test(tc, test_inside_tilted);
    tcase_add_test(tc, test_outside_tilted);
    tcase_add_test(tc, test_u_turn);
    tcase_add_test(tc, test_skew_inside);
    tcase_add_test(tc, test_outside_orientation_change);
    tcase_add_test(tc, test_path_distance);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(comp5_join_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
