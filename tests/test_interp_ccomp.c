/* test_interp_ccomp.c: G41/G42 cutter compensation: properties of the offset path. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "interp/tooltable.h"
#include "kins/kins.h"
#include "tests/test_interp_util.h"

#define TOL 1e-9

/* Distance from (x, y) to the segment (ax, ay)-(bx, by). */
static double seg_dist(double x, double y, double ax, double ay, double bx, double by)
{
    double dx = bx - ax, dy = by - ay;
    double t = ((x - ax) * dx + (y - ay) * dy) / (dx * dx + dy * dy);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    return hypot(x - (ax + t * dx), y - (ay + t * dy));
}

/* Distance from (x, y) to the closed outline of the rectangle 0..w x 0..h. */
static double rect_dist(double x, double y, double w, double h)
{
    double d = seg_dist(x, y, 0, 0, w, 0);
    d = fmin(d, seg_dist(x, y, w, 0, w, h));
    d = fmin(d, seg_dist(x, y, w, h, 0, h));
    return fmin(d, seg_dist(x, y, 0, h, 0, 0));
}

/* Around a rectangle with G42.1 (outside of a counter-clockwise path), every point the tool centre
 * is sent to lies one tool radius from the contour, and each corner is an arc of the tool
 * radius about the programmed corner that starts where the move before it ended. */
START_TEST(ccomp_outline_one_radius_away)
{
    struct canon_prog p;
    interp_ok("G0 X-20 Y-20\nG42.1 D6 G1 X0 Y0 F100\nX50\nY30\nX0\nY0\nX10\n"
              "G40 G1 X-20 Y-20\nM2\n", &p);
    ck_assert_int_eq(count_type(&p, CANON_ARC), 4);  /* one per corner */
    double prev[6] = {0};
    int moves = 0;
    for (size_t i = 0; i < p.count; i++) {
        const struct canon_cmd *c = &p.cmds[i];
        if (c->type != CANON_FEED && c->type != CANON_ARC && c->type != CANON_TRAVERSE)
            continue;
        moves++;
        /* from the entry move's end to the last compensated move's end */
        if (moves >= 3 && moves <= 2 + 4 + 5)
            ck_assert_double_eq_tol(rect_dist(c->end[0], c->end[1], 50, 30), 3.0, TOL);
        if (c->type == CANON_ARC) {
            double cx = c->arc.center[0], cy = c->arc.center[1];
            ck_assert_double_eq_tol(rect_dist(cx, cy, 50, 30), 0.0, TOL);  /* a corner */
            ck_assert_double_eq_tol(hypot(prev[0] - cx, prev[1] - cy), 3.0, TOL);
            ck_assert_double_eq_tol(hypot(c->end[0] - cx, c->end[1] - cy), 3.0, TOL);
            ck_assert_int_eq(c->arc.rotation, 1);  /* around the corner with the path */
        }
        memcpy(prev, c->end, sizeof prev);
    }
    canon_prog_free(&p);
}
END_TEST

/* A pocket (tool inside, clockwise with G42.1): inside corners are single points, one tool
 * radius from both edges, with no arc. */
START_TEST(ccomp_inside_corners_meet)
{
    struct canon_prog p;
    interp_ok("G0 X20 Y20\nG42.1 D4 G1 X10 Y10 F100\nY40\nX60\nY10\nX10\nG40 G1 X20 Y20\nM2\n",
              &p);
    ck_assert_int_eq(count_type(&p, CANON_ARC), 0);
    /* tool right of a clockwise outline: inside; corners at (12, 38), (58, 38), ... */
    ck_assert_pose(nth(&p, CANON_FEED, 1)->end, 12, 38, 0, 0, 0, 0, TOL);
    ck_assert_pose(nth(&p, CANON_FEED, 2)->end, 58, 38, 0, 0, 0, 0, TOL);
    ck_assert_pose(nth(&p, CANON_FEED, 3)->end, 58, 12, 0, 0, 0, 0, TOL);
    canon_prog_free(&p);
}
END_TEST

/* The move before a corner waits for the next one: a dwell programmed after a move comes
 * after it, and a feed change takes effect after it too. */
START_TEST(ccomp_queue_keeps_the_order)
{
    struct canon_prog p;
    interp_ok("G0 X-20 Y-20\nG41.1 D2 G1 X0 Y0 F100\nX50\nG4 P1\nF200\nY30\nG40 X60 Y40\nM2\n",
              &p);
    size_t feed_x50 = p.count, dwell = p.count, rate = p.count, arc = p.count;
    for (size_t i = 0; i < p.count; i++) {
        const struct canon_cmd *c = &p.cmds[i];
        if (c->type == CANON_FEED && c->line == 3)
            feed_x50 = i;
        else if (c->type == CANON_DWELL)
            dwell = i;
        else if (c->type == CANON_FEED_RATE && c->line == 5)
            rate = i;
        else if (c->type == CANON_ARC && c->line == 6)
            arc = i;
    }
    ck_assert_uint_lt(feed_x50, dwell);
    ck_assert_uint_lt(dwell, rate);
    ck_assert_uint_lt(rate, arc);  /* the corner arc belongs to line 6, after them */
    canon_prog_free(&p);
}
END_TEST

/* A negative diameter puts the tool on the other side (LinuxCNC); a work offset moves the
 * compensated path with the program. */
START_TEST(ccomp_side_swap_and_offsets)
{
    struct canon_prog a, b;
    const char *path = "G1 X0 Y0 F100\nX30\nG3 X30 Y20 R10\nG1 X0\nG40 X-10 Y-10\nM2\n";
    char t1[256], t2[256];
    snprintf(t1, sizeof t1, "G0 X-10 Y-10\nG41.1 D-5\n%s", path);
    snprintf(t2, sizeof t2, "G0 X-10 Y-10\nG42.1 D5\n%s", path);
    interp_ok(t1, &a);
    interp_ok(t2, &b);
    ck_assert_uint_eq(a.count, b.count);
    for (size_t i = 0; i < a.count; i++)
        if (a.cmds[i].type == CANON_FEED || a.cmds[i].type == CANON_ARC)
            ck_assert_pose(a.cmds[i].end, b.cmds[i].end[0], b.cmds[i].end[1],
                           b.cmds[i].end[2], 0, 0, 0, TOL);
    canon_prog_free(&a);
    snprintf(t1, sizeof t1, "G10 L2 P2 X100 Y-7\nG55 G0 X-10 Y-10\nG42.1 D5\n%s", path);
    interp_ok(t1, &a);
    ck_assert_uint_eq(count_type(&a, CANON_ARC), count_type(&b, CANON_ARC));
    for (int k = 0; k < count_type(&b, CANON_FEED); k++) {
        const double *e = nth(&b, CANON_FEED, k)->end;
        ck_assert_pose(nth(&a, CANON_FEED, k)->end, e[0] + 100, e[1] - 7, e[2], 0, 0, 0, 1e-9);
    }
    canon_prog_free(&a);
    canon_prog_free(&b);
}
END_TEST

/* G41/G42 and G141/G142 never run at once; G41 is refused in MDI (no next line to wait
 * for); a G141 run closed by the G41 block is fine. */
START_TEST(ccomp_refusals)
{
    struct interp_error e;
    struct canon_prog p;
    ck_assert_int_eq(run_text("G0 X-9 Y-9\nG41.1 D2 G1 X0 Y0 F10\nG141 X5 W1\nM2\n", &p, &e),
                     INTERP_ERR_CCOMP);
    ck_assert_ptr_nonnull(strstr(e.message, "G141/G142"));
    canon_prog_free(&p);
    ck_assert_int_eq(interp_status_of("G42.1 D2 G141 X5 W1 F10\nM2\n"), INTERP_ERR_CCOMP);
    ck_assert_int_eq(interp_status_of("G19 G41.1 D2\nM2\n"), INTERP_ERR_CCOMP);
    ck_assert_int_eq(interp_status_of("G41.1 D2\nG42.1 D2\nM2\n"), INTERP_ERR_CCOMP);
    interp_ok("G0 X-5 Y-5\nG1 X0 Y-1 F10\nG141 X10 Y0 W1\nG141 X20 Y0\nG41.1 D2 G1 X20 Y20\n"
              "X30\nG40 X0\nM2\n", &p);
    ck_assert_pose(nth(&p, CANON_FEED, 3)->end, 19, 20, 0, 0, 0, 0, TOL); /* entry from the
                                                       * G141 run's end (20, -1) */
    canon_prog_free(&p);

    struct interp *in = interp_create();
    interp_set_mdi(in, 1);
    ck_assert_int_eq(run_on(in, "G41.1 D2\n", &p), INTERP_ERR_UNSUPPORTED);
    canon_prog_free(&p);
    interp_destroy(in);
}
END_TEST

/* The radius from the tool table: D n is half tool n's diameter plus wear; D0 and no D are
 * the tool in the spindle; an empty spindle gives radius 0: moves are not offset. */
START_TEST(ccomp_radius_from_the_table)
{
    static const char table[] = "T1 P1 D10\nT2 P2 D6\n";
    struct tooltable tt;
    char err[256];
    ck_assert_int_eq(tooltable_parse(&tt, table, "t.tbl", err, sizeof err), TOOLTABLE_OK);
    const char *progs[] = {
        "G41 D2 G1 X0 Y0 F100\nX20\nG40 X30 Y10\nM2\n",
        "T2 M6\nG41 G1 X0 Y0 F100\nX20\nG40 X30 Y10\nM2\n",
        "T2 M6\nG41 D0 G1 X0 Y0 F100\nX20\nG40 X30 Y10\nM2\n",
        "G41.1 D6 G1 X0 Y0 F100\nX20\nG40 X30 Y10\nM2\n",
    };
    for (int i = 0; i < 4; i++) {
        struct interp *in = interp_create();
        struct canon_prog p;
        interp_set_tooltable(in, &tt);
        char text[200];
        snprintf(text, sizeof text, "G0 X-10 Y-10\n%s", progs[i]);
        ck_assert_int_eq(run_on(in, text, &p), INTERP_OK);
        /* the move along X ends 3 mm left of it (+Y) */
        ck_assert_pose(nth(&p, CANON_FEED, 1)->end, 20, 3, 0, 0, 0, 0, TOL);
        canon_prog_free(&p);
        interp_destroy(in);
    }
    struct interp *in = interp_create();
    struct canon_prog p;
    interp_set_tooltable(in, &tt);
    ck_assert_int_eq(run_on(in, "G41 G1 X0 Y0 F100\nX20\nG40 X30\nM2\n", &p), INTERP_OK);
    ck_assert_pose(nth(&p, CANON_FEED, 1)->end, 20, 0, 0, 0, 0, 0, TOL);  /* no tool */
    canon_prog_free(&p);
    ck_assert_int_eq(run_on(in, "G41 D7 G1 X0 Y0 F100\nM2\n", &p), INTERP_ERR_TOOL);
    canon_prog_free(&p);
    interp_destroy(in);
}
END_TEST

/* Under tool centre point control (PROGRAM_POINT = TOOL_TIP) the moves the queue holds are
 * the tool tip's, and say so, as every other command does. */
START_TEST(ccomp_moves_carry_the_tcp_state)
{
    static const struct kins_tool_frame tf = {0, {0, 0, 780}, {0, 0, -1}, 60, 1};
    struct interp *in = interp_create();
    struct canon_prog p;
    interp_set_tool_frame(in, &tf);
    ck_assert_int_eq(run_on(in, "G0 X-10 Y-10 Z600\nG41.1 D4 G1 X0 Y0 F100\nX20\nY20\n"
                                "G40 X30 Y30\nM2\n", &p), INTERP_OK);
    int moves = 0;
    for (size_t i = 0; i < p.count; i++) {
        const struct canon_cmd *c = &p.cmds[i];
        if (c->type == CANON_FEED || c->type == CANON_ARC || c->type == CANON_TRAVERSE) {
            moves++;
            ck_assert_int_eq(c->tcp, 1);
            ck_assert_double_eq(c->tool_len_mm, 60);
        }
    }
    ck_assert_int_eq(moves, 6);  /* rapid, entry, X20, corner arc, Y20, exit */
    canon_prog_free(&p);
    interp_destroy(in);
}
END_TEST

static Suite *ccomp_suite(void)
{
    Suite *s = suite_create("interp_ccomp");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, ccomp_outline_one_radius_away);
    tcase_add_test(tc, ccomp_inside_corners_meet);
    tcase_add_test(tc, ccomp_queue_keeps_the_order);
    tcase_add_test(tc, ccomp_side_swap_and_offsets);
    tcase_add_test(tc, ccomp_refusals);
    tcase_add_test(tc, ccomp_radius_from_the_table);
    tcase_add_test(tc, ccomp_moves_carry_the_tcp_state);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(ccomp_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
