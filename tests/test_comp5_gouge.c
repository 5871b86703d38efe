/* test_comp5_gouge.c: G141/G142 paths that would cut into their own contour are refused, with line, depth and point. */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "comp5_testutil.h"
#include "interp/comp5.h"
#include "interp/interp.h"
#include "interp/tooltable.h"
#include "test_interp_util.h"

/* The closest the tool axis comes to the programmed contour (pts, n points) along the
 * compensated moves of p, by dense sampling (every 0.01 mm of travel, arcs included),
 * independent of comp5_gouge.c. Flat table only (axis +Z: distances in XY). */
static double sampled_clearance(const struct canon_prog *p, const double pts[][2], int n)
{
    double best = INFINITY, pos[3] = {p->start[0], p->start[1], p->start[2]};
    int first = 1;
    for (size_t i = 0; i < p->count; i++) {
        const struct canon_cmd *c = &p->cmds[i];
        if (c->type != CANON_FEED && c->type != CANON_ARC && c->type != CANON_TRAVERSE)
            continue;
        if (c->compensated && !first) {
            double r0[3], r1[3], a0 = 0, a1 = 0, len;
            for (int k = 0; k < 3; k++)
                r0[k] = pos[k] - c->arc.center[k], r1[k] = c->end[k] - c->arc.center[k];
            if (c->type == CANON_ARC) {
                a0 = atan2(r0[1], r0[0]), a1 = atan2(r1[1], r1[0]);
                if (c->arc.normal[2] > 0 && a1 <= a0) /* counter-clockwise seen from +Z */
                    a1 += 2 * M_PI;
                if (c->arc.normal[2] < 0 && a1 >= a0) /* clockwise */
                    a1 -= 2 * M_PI;
                len = fabs(a1 - a0) * hypot(r0[0], r0[1]);
            } else {
                len = tu_dist(pos, c->end);
            }
            int steps = 1 + (int)(len / 0.01);
            for (int s = 0; s <= steps; s++) {
                double t = (double)s / steps, q[3];
                if (c->type == CANON_ARC) {
                    double r = hypot(r0[0], r0[1]), a = a0 + t * (a1 - a0);
                    q[0] = c->arc.center[0] + r * cos(a), q[1] = c->arc.center[1] + r * sin(a);
                } else {
                    q[0] = pos[0] + t * (c->end[0] - pos[0]);
                    q[1] = pos[1] + t * (c->end[1] - pos[1]);
                }
                q[2] = 0;
                for (int k = 1; k < n; k++) {
                    double a[3] = {pts[k - 1][0], pts[k - 1][1], 0};
                    double b[3] = {pts[k][0], pts[k][1], 0};
                    double d = tu_dist_segment(q, a, b);
                    best = d < best ? d : best;
                }
            }
        }
        if (c->compensated)
            first = 0; /* the positioning move is not part of the cut */
        memcpy(pos, c->end, sizeof pos);
    }
    return best;
}

/* Runs text with the tool table `table` (may be NULL); err gets the error. */
static int run_tt(const char *text, const char *table, struct canon_prog *p,
                  struct interp_error *err)
{
    static struct tooltable tt; /* large: not on the stack */
    char msg[256];
    struct interp *in = interp_create();
    ck_assert_ptr_nonnull(in);
    if (table) {
        tooltable_init(&tt);
        ck_assert_int_eq(tooltable_parse(&tt, table, "t.tbl", msg, sizeof msg), TOOLTABLE_OK);
        interp_set_tooltable(in, &tt);
    }
    int rc = run_on(in, text, p);
    *err = *interp_last_error(in);
    interp_destroy(in);
    return rc;
}

/* Expects a refusal on `line` whose message holds every string of `want` (NULL-ended). */
static void expect_gouge(const char *text, const char *table, int line, const char *const *want)
{
    struct canon_prog p;
    struct interp_error e;
    ck_assert_int_eq(run_tt(text, table, &p, &e), INTERP_ERR_COMP5);
    canon_prog_free(&p);
    ck_assert_str_eq(e.file, "t.ngc");
    ck_assert_msg(e.line == line, "line %d, expected %d: %s", e.line, line, e.message);
    for (; *want; want++)
        ck_assert_msg(strstr(e.message, *want), "'%s' not in: %s", *want, e.message);
}

/* A closed pocket (40 x 30, counter-clockwise, G142 = inside) started at a corner: the
 * compensated start (0,5) lies on the closing wall X0, the end (5,0) on the first wall Y0:
 * the tool cuts its full radius, 5 mm, into the contour. Before: accepted. */
START_TEST(test_pocket_started_at_corner)
{
    static const char *const want[] = {"G142", "line 3", "from line 6 to 7", "by 5.0000 mm",
                                       "X0.0000 Y5.0000 Z0.0000", "radius 5 mm", NULL};
    expect_gouge("G21 G90 G0 X20 Y15 Z0\nF500\nG142 X0 Y0 W5\nG142 X40 Y0\nG142 X40 Y30\n"
                 "G142 X0 Y30\nG142 X0 Y0\nG0 X20 Y15\nM2\n", NULL, 3, want);
    /* the same with the end of the program right after the run (the % end) */
    expect_gouge("%\nG21 G90 G0 X20 Y15 Z0\nG142 X0 Y0 W5 F500\nG142 X40 Y0\nG142 X40 Y30\n"
                 "G142 X0 Y30\nG142 X0 Y0\n%\n", NULL, 3, want);
}
END_TEST

/* The same pocket started mid-edge is clean: the tool never comes closer than W. */
START_TEST(test_pocket_started_mid_edge)
{
    static const double pts[][2] = {{20, 0}, {40, 0}, {40, 30}, {0, 30}, {0, 0}, {20, 0}};
    struct canon_prog p;
    interp_ok("G21 G90 G0 X20 Y15 Z0\nG142 X20 Y0 W5 F500\nG142 X40 Y0\nG142 X40 Y30\n"
              "G142 X0 Y30\nG142 X0 Y0\nG142 X20 Y0\nG0 X20 Y15\nM2\n", &p);
    double d = sampled_clearance(&p, pts, 6);
    ck_assert_msg(d > 5.0 - 1e-6 && d < 5.0 + 1e-6, "clearance %.9f", d);
    canon_prog_free(&p);
}
END_TEST

/* The pocket, horizontal, on a table tilted B-4 (the paper's tilt): the contour is not
 * normal to the tool axis, so the offset lines of each corner are skew. The joins are where
 * they cross seen along the axis: the tool axis is exactly W from both walls there (X35 in
 * the view along the axis, X35 + depth * tan 4 deg in X), no gouge. The closest approach of
 * the skew lines (the join before) left the axis 4.9878 mm from the wall X40: 0.0122 mm of
 * gouge. */
START_TEST(test_tilted_table_pocket)
{
    struct canon_prog p;
    double n[3];
    interp_ok("G21 G90 G0 X20 Y15 Z630 A0 B-4\nG142 X20 Y0 W5 F500\nG142 X40 Y0\n"
              "G142 X40 Y30\nG142 X0 Y30\nG142 X0 Y0\nG142 X20 Y0\nG0 X20 Y15\nM2\n", &p);
    tu_normal(0, -4, 0, n);
    int joins = 0;
    for (size_t i = 0; i < p.count; i++) {
        const struct canon_cmd *c = &p.cmds[i];
        if (c->type != CANON_FEED || !c->compensated)
            continue;
        /* distance, seen along the axis, from the tool to the nearer of the walls X0, X40 */
        double wall = c->end[0] > 20 ? 40 : 0;
        double d[3] = {c->end[0] - wall, 0, c->end[2] - 630}, dn = tu_dot(d, n);
        for (int k = 0; k < 3; k++)
            d[k] -= dn * n[k];
        if (fabs(c->end[1] - 5) < 1e-6 || fabs(c->end[1] - 25) < 1e-6) {
            if (fabs(c->end[0] - 20) > 1e-6) {
                ck_assert_msg(fabs(tu_norm(d) - 5.0) < 1e-9, "join %zu: %.9f from the wall", i,
                              tu_norm(d));
                joins++;
            }
        }
    }
    ck_assert_int_eq(joins, 4);
    canon_prog_free(&p);
}
END_TEST

/* The pocket on a table tilted B-4 that also turns (C +0.5 deg a block): the tool axis
 * changes along the run and along every move. Mid-edge start: clean; corner start: the
 * closing wall is found through the search that allows for the turning axis. */
START_TEST(test_turning_table_pocket)
{
    struct canon_prog p;
    interp_ok("G21 G90 G0 X20 Y15 Z630 A0 B-4 C0\nG142 X20 Y0 W5 F500\nG142 X40 Y0 C0.5\n"
              "G142 X40 Y30 C1\nG142 X0 Y30 C1.5\nG142 X0 Y0 C2\nG142 X20 Y0 C2.5\n"
              "G0 X20 Y15\nM2\n", &p);
    canon_prog_free(&p);
    static const char *const want[] = {"G142 at line 3", "from line 5 to 6", "by 5.0000 mm",
                                       "X0.0000 Y5.0000 Z630.0000", NULL};
    expect_gouge("G21 G90 G0 X20 Y15 Z630 A0 B-4 C0\nG142 X0 Y0 W5 F500\nG142 X40 Y0 C0.5\n"
                 "G142 X40 Y30 C1\nG142 X0 Y30 C1.5\nG142 X0 Y0 C2\nG0 X20 Y15\nM2\n", NULL, 3,
                 want);
}
END_TEST

/* An island (the same rectangle, cut from outside): counter-clockwise with G141 and
 * clockwise with G142 both put the tool outside. Started at a corner, the run's start and
 * end stay open (no closing arc), but outside they are clear of the contour. */
START_TEST(test_island)
{
    static const double ccw[][2] = {{0, 0}, {40, 0}, {40, 30}, {0, 30}, {0, 0}};
    static const double cw[][2] = {{0, 0}, {0, 30}, {40, 30}, {40, 0}, {0, 0}};
    struct canon_prog p;
    interp_ok("G21 G90 G0 X-10 Y-10 Z0\nG141 X0 Y0 W5 F500\nG141 X40 Y0\nG141 X40 Y30\n"
              "G141 X0 Y30\nG141 X0 Y0\nG0 X-10 Y-10\nM2\n", &p);
    double d = sampled_clearance(&p, ccw, 5);
    ck_assert_msg(fabs(d - 5.0) < 1e-6, "G141 island clearance %.9f", d);
    canon_prog_free(&p);
    interp_ok("G21 G90 G0 X-10 Y-10 Z0\nG142 X0 Y0 W5 F500\nG142 X0 Y30\nG142 X40 Y30\n"
              "G142 X40 Y0\nG142 X0 Y0\nG0 X-10 Y-10\nM2\n", &p);
    d = sampled_clearance(&p, cw, 5);
    ck_assert_msg(fabs(d - 5.0) < 1e-6, "G142 island clearance %.9f", d);
    canon_prog_free(&p);
    /* the island with the side the other way round is a pocket started at a corner */
    static const char *const want[] = {"G141", "by 5.0000 mm", "X5.0000 Y0.0000", NULL};
    expect_gouge("G21 G90 G0 X20 Y15 Z0\nG141 X0 Y0 W5 F500\nG141 X0 Y30\nG141 X40 Y30\n"
                 "G141 X40 Y0\nG141 X0 Y0\nM2\n", NULL, 2, want);
}
END_TEST

/* Two rooms joined by a neck 8 mm wide (Y11..Y19, X30..X50): the neck's walls are not
 * neighbours in the contour, so the corner check cannot see them. A 10 mm tool rolling
 * round the corner X30 Y11 (line 4) into the neck ends at Y16, 3 mm from the upper wall:
 * 2 mm of gouge at X30 Y19. A 6 mm tool fits (3 mm of clearance). Radii from the tool table
 * (D): right for the small tool, refused for the large one. */
#define DUMBBELL "G21 G90 G0 X15 Y10 Z0\nG142 X15 Y0 D%d F500\nG142 X30 Y0\nG142 X30 Y11\n" \
                 "G142 X50 Y11\nG142 X50 Y0\nG142 X80 Y0\nG142 X80 Y30\nG142 X50 Y30\n"   \
                 "G142 X50 Y19\nG142 X30 Y19\nG142 X30 Y30\nG142 X0 Y30\nG142 X0 Y0\n"     \
                 "G142 X15 Y0\nG0 X15 Y10\nM2\n"
START_TEST(test_neck_narrower_than_tool)
{
    static const char table[] = "T1 P1 D6\nT2 P2 D10\n";
    static const double pts[][2] = {{15, 0}, {30, 0}, {30, 11}, {50, 11}, {50, 0},
                                    {80, 0}, {80, 30}, {50, 30}, {50, 19}, {30, 19},
                                    {30, 30}, {0, 30}, {0, 0}, {15, 0}};
    char prog[1024];
    struct canon_prog p;
    struct interp_error e;
    snprintf(prog, sizeof prog, DUMBBELL, 1);
    ck_assert_msg(run_tt(prog, table, &p, &e) == INTERP_OK, "%s", e.message);
    double d = sampled_clearance(&p, pts, 14);
    ck_assert_msg(fabs(d - 3.0) < 1e-6, "small tool clearance %.9f", d);
    canon_prog_free(&p);
    snprintf(prog, sizeof prog, DUMBBELL, 2);
    static const char *const want[] = {"G142 at line 4", "from line 10 to 11", "by 2.0000 mm",
                                       "X30.0000 Y19.0000", "radius 5 mm", NULL};
    expect_gouge(prog, table, 4, want);
    /* C turns the table about the tool axis here (A = B = 0): the axis stays +Z, so the
     * same figures, but the run's orientation changes: the search that allows for it */
    char turned[1200], *o = turned;
    snprintf(prog, sizeof prog, DUMBBELL, 2);
    int blocks = 0;
    for (const char *q = prog; *q; q++) {
        *o++ = *q;
        if (*q == '\n' && q[1] == 'G' && q[2] == '1')
            o += sprintf(o, "C%d ", 5 * (blocks++ % 3));
    }
    *o = 0;
    expect_gouge(turned, table, 4, want);
}
END_TEST

/* A straight slot of width 8 (walls Y0 and Y8, open at X0) with a 10 mm tool: the corner
 * checks already refuse it at the far end (the tool cannot turn in the slot). */
START_TEST(test_slot_narrower_than_tool)
{
    ck_assert_int_eq(interp_status_of("G21 G90 G0 X-10 Y4 Z0\nG142 X0 Y0 W5 F500\n"
                                      "G142 X40 Y0\nG142 X40 Y8\nG142 X0 Y8\nM2\n"),
                     INTERP_ERR_COMP5);
    struct canon_prog p;
    interp_ok("G21 G90 G0 X-10 Y4 Z0\nG142 X0 Y0 W3.5 F500\nG142 X40 Y0\nG142 X40 Y8\n"
              "G142 X0 Y8\nM2\n", &p);
    canon_prog_free(&p);
}
END_TEST

/* The positioning move: level with the cut and crossing the wall it is about to cut
 * (the tool starts on the wrong side, Y+10, for G141 along +X: right = -Y). */
START_TEST(test_approach_crossing)
{
    static const char *const want[] = {"G141 positioning move of line 2", "from line 2 to 3",
                                       "by 5.0000 mm", "approach from the compensation side",
                                       NULL};
    expect_gouge("G21 G90 G0 X20 Y10 Z0\nG141 X0 Y0 W5 F500\nG141 X40 Y0\nG0 Z10\nM2\n",
                 NULL, 2, want);
    /* from the compensation side: clean */
    struct canon_prog p;
    interp_ok("G21 G90 G0 X-10 Y-10 Z0\nG141 X0 Y0 W5 F500\nG141 X40 Y0\nG0 Z10\nM2\n", &p);
    canon_prog_free(&p);
    /* behind the start on the wrong side: passes the first corner too close */
    ck_assert_int_eq(interp_status_of("G21 G90 G0 X-20 Y6 Z0\nG141 X0 Y0 W5 F500\n"
                                      "G141 X40 Y0\nM2\n"), INTERP_ERR_COMP5);
    /* a descent from another depth is not checked (the stock is unknown): the paper's
     * programs start like this from the machine's home */
    interp_ok("G21 G90 G0 X20 Y10 Z-20\nG141 X0 Y0 Z0 W5 F500\nG141 X40 Y0\nM2\n", &p);
    canon_prog_free(&p);
}
END_TEST

/* Offsets and inches: the point is named in program coordinates (G92 shift, G20 inches). */
START_TEST(test_point_in_program_coordinates)
{
    static const char *const want[] = {"by 5.0800 mm", "X0.0000 Y0.2000 Z0.0000", NULL};
    expect_gouge("G20 G90 G0 X1 Y0.5 Z0\nG92 X-3 Y-2\nG0 X1 Y0.5\nG142 X0 Y0 W0.2 F20\n"
                 "G142 X2 Y0\nG142 X2 Y1\nG142 X0 Y1\nG142 X0 Y0\nM2\n", NULL, 4, want);
}
END_TEST

/* A tilting move (A B C change along it) comes closer than W to its own segment midway:
 * about W (1 - cos(half the change of the offset direction)), measured here for A0 -> A20
 * along a straight 50 mm X move, W10 (0.1519 mm at X25). */
START_TEST(test_tilting_move)
{
    struct comp5 c;
    struct canon_prog p;
    double start[6] = {0, -20, 0, 0, 0, 0};
    struct comp5_block b0 = tu_block(141, 0, 0, 0, 0, 0, 0, 10, 1);
    struct comp5_block b1 = tu_block(141, 50, 0, 0, 20, 0, 0, 10, 2);
    comp5_init(&c);
    canon_prog_init(&p);
    ck_assert_int_eq(comp5_block(&c, &b0, start, canon_prog_sink, &p), COMP5_OK);
    ck_assert_int_eq(comp5_block(&c, &b1, start, canon_prog_sink, &p), COMP5_OK);
    ck_assert_int_eq(comp5_flush(&c, canon_prog_sink, &p), COMP5_ERR_GOUGE_CONTOUR);
    ck_assert_int_eq(c.err_line, 2);
    ck_assert_msg(strstr(comp5_errmsg(&c), "A B C change"), "%s", comp5_errmsg(&c));
    /* the depth, independently: sample the straight move, axis from the interpolated A */
    const double *e0 = p.cmds[0].end, *e1 = p.cmds[1].end;
    double worst = 0;
    for (int s = 0; s <= 20000; s++) {
        double t = s / 20000.0, q[3], n[3], a = e0[3] + t * (e1[3] - e0[3]);
        for (int i = 0; i < 3; i++)
            q[i] = e0[i] + t * (e1[i] - e0[i]);
        tu_normal(a, 0, 0, n);
        double px = q[0] < 0 ? 0 : q[0] > 50 ? 50 : q[0]; /* contour is the X axis */
        double d[3] = {q[0] - px, q[1], q[2]}, dn = tu_dot(d, n);
        for (int i = 0; i < 3; i++)
            d[i] -= dn * n[i];
        worst = fmax(worst, 10.0 - tu_norm(d));
    }
    char want[64];
    snprintf(want, sizeof want, "by %.4f mm", worst);
    ck_assert_msg(worst > 0.1 && strstr(comp5_errmsg(&c), want), "%s (sampled %.6f)",
                  comp5_errmsg(&c), worst);
    canon_prog_free(&p);
}
END_TEST

/* The paper's programs, read as files with their tool table: still accepted. */
START_TEST(test_paper_programs_accepted)
{
    static const char *const progs[] = {
        "prog10_g141_d20.ngc", "prog10_g142_d20.ngc", "prog11_g141_d10.ngc",
        "prog11_g142_d10.ngc", "path2_g141_d20.ngc", "path2_g141_d12.ngc",
        "path1_tooltable.ngc", "experiment/run1_g141.ngc", "experiment/run1_g142.ngc",
        "experiment/run2_g141.ngc", "experiment/run3_g141.ngc", "experiment/run4_g141.ngc"};
    static struct tooltable tt;
    const char *root = getenv("HEXCNC_ROOT");
    char path[1024], err[256];
    if (!root)
        root = ".";
    snprintf(path, sizeof path, "%s/configs/sim/tmu-hexapod.tbl", root);
    tooltable_init(&tt);
    ck_assert_msg(tooltable_load(&tt, path, err, sizeof err) == TOOLTABLE_OK, "%s", err);
    for (size_t i = 0; i < sizeof progs / sizeof progs[0]; i++) {
        struct interp *in = interp_create();
        struct canon_prog p;
        interp_set_tooltable(in, &tt);
        snprintf(path, sizeof path, "%s/examples/paper/%s", root, progs[i]);
        canon_prog_init(&p);
        int rc = interp_run_file(in, path, canon_prog_sink, &p);
        ck_assert_msg(rc == INTERP_OK, "%s: %s", progs[i], interp_last_error(in)->message);
        canon_prog_free(&p);
        interp_destroy(in);
    }
}
END_TEST

/* xorshift: the same random runs on every test. */
static double rnd(unsigned long long *st)
{
    *st ^= *st << 13, *st ^= *st >> 7, *st ^= *st << 17;
    return (double)(*st % 1000000ULL) / 1e6;
}

/* The deepest cut of the emitted moves (the first, the positioning, left out) into the
 * contour pts, sampled every 0.01 mm (arcs about their normal by Rodrigues' formula), the
 * tool axis from each sample's A B C: independent of comp5_gouge.c. */
static double sampled_depth(const struct canon_prog *p, const struct comp5_block *blk, int n)
{
    double worst = -INFINITY, pos[6];
    memcpy(pos, p->cmds[0].end, sizeof pos);
    for (size_t i = 1; i < p->count; i++) {
        const struct canon_cmd *c = &p->cmds[i];
        double r0[3], r1[3], x[3], ang = 0, len;
        for (int k = 0; k < 3; k++)
            r0[k] = pos[k] - c->arc.center[k], r1[k] = c->end[k] - c->arc.center[k];
        if (c->type == CANON_ARC) {
            tu_cross(r0, r1, x);
            ang = atan2(tu_dot(x, c->arc.normal), tu_dot(r0, r1));
            ang = ang <= 0 ? ang + 2 * M_PI : ang;
            len = ang * tu_norm(r0);
        } else {
            len = tu_dist(pos, c->end);
        }
        int steps = 2 + (int)(len / 0.01);
        for (int s = 0; s <= steps; s++) {
            double t = (double)s / steps, q[3], nrm[3], abc[3];
            for (int k = 0; k < 3; k++)
                abc[k] = pos[3 + k] + t * (c->end[3 + k] - pos[3 + k]);
            if (c->type == CANON_ARC) {
                tu_rotate(c->arc.normal, ang * t / TU_DEG, r0, q);
                for (int k = 0; k < 3; k++)
                    q[k] += c->arc.center[k];
            } else {
                for (int k = 0; k < 3; k++)
                    q[k] = pos[k] + t * (c->end[k] - pos[k]);
            }
            tu_normal(abc[0], abc[1], abc[2], nrm);
            for (int k = 1; k < n; k++) { /* nearest point of the segment, seen along nrm */
                double a[3], e[3], ap[3], ep[3];
                for (int m = 0; m < 3; m++)
                    a[m] = blk[k - 1].point[m] - q[m], e[m] = blk[k].point[m] - blk[k - 1].point[m];
                double da = tu_dot(a, nrm), de = tu_dot(e, nrm);
                for (int m = 0; m < 3; m++)
                    ap[m] = a[m] - da * nrm[m], ep[m] = e[m] - de * nrm[m];
                double u = -tu_dot(ap, ep) / tu_dot(ep, ep);
                u = u < 0 ? 0 : u > 1 ? 1 : u;
                for (int m = 0; m < 3; m++)
                    ap[m] += u * ep[m];
                worst = fmax(worst, blk[k].radius_mm - tu_norm(ap));
            }
        }
        memcpy(pos, c->end, sizeof pos);
    }
    return worst;
}

/* Random runs (6 points on an open convex polygon, or anywhere in a 40 mm square; flat,
 * tilted or turning table; W 2..8 mm): the
 * check refuses exactly those whose sampled depth is beyond the tolerance, and its depth
 * agrees with the sampled one. Runs the corner check refuses first are left out. */
START_TEST(test_random_runs_against_sampling)
{
    unsigned long long st = 0x9e3779b97f4a7c15ULL;
    int refused = 0, accepted = 0;
    for (int run = 0; run < 300; run++) {
        struct comp5 c;
        struct canon_prog p;
        struct comp5_block blk[6];
        int mode = run % 3, side = run % 2 ? 141 : 142, rc = COMP5_OK;
        double w = 2 + 6 * rnd(&st), b0 = mode ? -10 + 20 * rnd(&st) : 0;
        comp5_init(&c);
        canon_prog_init(&p);
        for (int k = 0; k < 6 && rc == COMP5_OK; k++) {
            double cdeg = mode == 2 ? 3.0 * k * rnd(&st) : 0, x, y;
            if (run % 4 < 2) { /* an open convex arc of a polygon, counter-clockwise */
                double ang = (k * 50.0 + 40.0 * rnd(&st)) * TU_DEG, r = 15 + 5 * rnd(&st);
                x = 20 + r * cos(ang), y = 20 + r * sin(ang);
            } else {           /* anything */
                x = 40 * rnd(&st), y = 40 * rnd(&st);
            }
            blk[k] = tu_block(side, x, y, 600, 0, b0, cdeg, w, k + 1);
            double start[6] = {-100, -100, 500, 0, b0, 0}; /* off the work: not level */
            rc = comp5_block(&c, &blk[k], start, canon_prog_sink, &p);
        }
        if (rc == COMP5_OK)
            rc = comp5_flush(&c, canon_prog_sink, &p);
        if (rc != COMP5_OK && rc != COMP5_ERR_GOUGE_CONTOUR) {
            comp5_free(&c);
            canon_prog_free(&p);
            continue;
        }
        double depth = sampled_depth(&p, blk, 6), tol = 1e-6 * fmax(w, 1.0);
        if (rc == COMP5_OK) {
            ck_assert_msg(depth < tol + 1e-9, "run %d accepted, sampled depth %g", run, depth);
            accepted++;
        } else {
            /* the reported cut is the first gouging move's deepest: no deeper than the
             * deepest sampled (which, every 0.01 mm, may miss up to 0.01 mm of it), and
             * beyond the tolerance */
            double got;
            const char *q = strstr(comp5_errmsg(&c), " by ");
            ck_assert_ptr_nonnull(q);
            got = strtod(q + 4, NULL);
            ck_assert_msg(got <= depth + 0.01 && depth > tol, "run %d: reported %.4f, "
                          "sampled %.6f: %s", run, got, depth, comp5_errmsg(&c));
            refused++;
        }
        canon_prog_free(&p);
    }
    ck_assert_msg(refused > 20 && accepted > 20, "refused %d, accepted %d", refused, accepted);
    printf("random runs: %d refused, %d accepted\n", refused, accepted);
}
END_TEST

static Suite *suite(void)
{
    Suite *s = suite_create("comp5_gouge");
    TCase *tc = tcase_create("gouge");
    tcase_add_test(tc, test_pocket_started_at_corner);
    tcase_add_test(tc, test_pocket_started_mid_edge);
    tcase_add_test(tc, test_tilted_table_pocket);
    tcase_add_test(tc, test_turning_table_pocket);
    tcase_add_test(tc, test_island);
    tcase_add_test(tc, test_neck_narrower_than_tool);
    tcase_add_test(tc, test_slot_narrower_than_tool);
    tcase_add_test(tc, test_approach_crossing);
    tcase_add_test(tc, test_point_in_program_coordinates);
    tcase_add_test(tc, test_tilting_move);
    tcase_add_test(tc, test_paper_programs_accepted);
    tcase_add_test(tc, test_random_runs_against_sampling);
    tcase_set_timeout(tc, 60);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
