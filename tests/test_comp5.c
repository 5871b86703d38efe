/* test_comp5.c: G141/G142 against the paper's worked numbers, oblique moves and every error. */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "interp/comp5.h"
#include "tests/comp5_testutil.h"

#define EPS6 1e-6 /* the paper's table is given to 6 decimals */

/* One row of the table in paper.md: program points, W, B, compensated points. */
struct worked {
    int side;
    double from[3], to[3];
    double w_mm, b_deg;
    double out_from[3], out_to[3];
};

static const struct worked worked[6] = {
    {141, {50, -80, 630}, {50, -20, 630}, 10, -4,
     {59.975641, -80, 630.697565}, {59.975641, -20, 630.697565}},
    {141, {50, -30, 630}, {50, 20, 630}, 5, -4,
     {54.987820, -30, 630.348782}, {54.987820, 20, 630.348782}},
    {142, {50, -80, 630}, {50, -20, 630}, 10, -4,
     {40.024359, -80, 629.302435}, {40.024359, -20, 629.302435}},
    {142, {50, -30, 630}, {50, 20, 630}, 5, -4,
     {45.012180, -30, 629.651218}, {45.012180, 20, 629.651218}},
    {141, {30, -100, 658}, {30, 50, 658}, 10, -8,
     {39.902681, -100, 659.391731}, {39.902681, 50, 659.391731}},
    {141, {30, -100, 658}, {30, 50, 658}, 6, -8,
     {35.941608, -100, 658.835039}, {35.941608, 50, 658.835039}},
};

static void check_xyz(const double got[], const double want[3], double eps)
{
    for (int i = 0; i < 3; i++)
        ck_assert_msg(fabs(got[i] - want[i]) < eps, "axis %d: got %.9f want %.9f", i, got[i],
                      want[i]);
}

/* The paper's steps 1..4, one point at a time. */
START_TEST(test_worked_offset_point)
{
    const struct worked *w = &worked[_i];
    double from[6] = {w->from[0], w->from[1], w->from[2], 0, w->b_deg, 0};
    double to[6] = {w->to[0], w->to[1], w->to[2], 0, w->b_deg, 0};
    double out[6];
    ck_assert_int_eq(comp5_offset_point(from, to, w->side, w->w_mm, from, out), COMP5_OK);
    check_xyz(out, w->out_from, EPS6);
    ck_assert_double_eq_tol(out[4], w->b_deg, 1e-12);
    ck_assert_int_eq(comp5_offset_point(from, to, w->side, w->w_mm, to, out), COMP5_OK);
    check_xyz(out, w->out_to, EPS6);
}
END_TEST

/* The same numbers through the run: a positioning FEED and one cut, both compensated. */
START_TEST(test_worked_block_flush)
{
    const struct worked *w = &worked[_i];
    struct comp5 c;
    struct canon_prog p;
    double start[6] = {0, 0, 700, 0, 0, 0};
    comp5_init(&c);
    canon_prog_init(&p);
    struct comp5_block b1 = tu_block(w->side, w->from[0], w->from[1], w->from[2], 0, w->b_deg,
                                      0, w->w_mm, 7);
    struct comp5_block b2 = tu_block(w->side, w->to[0], w->to[1], w->to[2], 0, w->b_deg, 0,
                                      w->w_mm, 8);
    b2.feed_mm_min = 1500.0;
    ck_assert_int_eq(comp5_block(&c, &b1, start, canon_prog_sink, &p), COMP5_OK);
    ck_assert_uint_eq(p.count, 0); /* one block of look-ahead: nothing yet */
    ck_assert_int_eq(comp5_block(&c, &b2, start, canon_prog_sink, &p), COMP5_OK);
    ck_assert_int_eq(comp5_flush(&c, canon_prog_sink, &p), COMP5_OK);
    ck_assert_uint_eq(p.count, 2);
    ck_assert_int_eq(p.cmds[0].type, CANON_FEED);
    check_xyz(p.cmds[0].end, w->out_from, EPS6);
    ck_assert_int_eq(p.cmds[0].line, 7);
    ck_assert_double_eq(p.cmds[0].feed_mm_min, 2000.0);
    ck_assert_int_eq(p.cmds[1].type, CANON_FEED);
    check_xyz(p.cmds[1].end, w->out_to, EPS6);
    ck_assert_int_eq(p.cmds[1].line, 8);
    ck_assert_double_eq(p.cmds[1].feed_mm_min, 1500.0);
    for (int k = 0; k < 2; k++) {
        ck_assert_int_eq(p.cmds[k].compensated, w->side);
        ck_assert_str_eq(p.cmds[k].file, "test.ngc");
        ck_assert_double_eq_tol(p.cmds[k].end[4], w->b_deg, 1e-12);
    }
    check_xyz(comp5_tool_pos(&c), w->out_to, EPS6);
    ck_assert_int_eq(c.active, 0);
    canon_prog_free(&p);
}
END_TEST

/* A flat table, travel +X: right (G141) is -Y and left (G142) is +Y seen from above, as a
 * machinist reads G42/G41. */
START_TEST(test_sign_convention_flat)
{
    double from[6] = {0, 0, 0, 0, 0, 0}, to[6] = {100, 0, 0, 0, 0, 0}, out[6];
    ck_assert_int_eq(comp5_offset_point(from, to, 141, 3.0, from, out), COMP5_OK);
    ck_assert_double_eq_tol(out[1], -3.0, 1e-12);
    ck_assert_int_eq(comp5_offset_point(from, to, 142, 3.0, from, out), COMP5_OK);
    ck_assert_double_eq_tol(out[1], 3.0, 1e-12);
    ck_assert_double_eq_tol(out[0], 0.0, 1e-12);
    ck_assert_double_eq_tol(out[2], 0.0, 1e-12);
}
END_TEST

/* The paper's normal formula against successive Rodrigues rotations. */
START_TEST(test_normal_independent)
{
    static const double abc[][3] = {{0, -4, 0}, {17, -23, 41}, {-60, 35, -170}, {90, 0, 0}};
    for (size_t k = 0; k < sizeof abc / sizeof abc[0]; k++) {
        double n[3], m[3];
        comp5_normal(abc[k][0], abc[k][1], abc[k][2], n);
        tu_normal(abc[k][0], abc[k][1], abc[k][2], m);
        for (int i = 0; i < 3; i++)
            ck_assert_double_eq_tol(n[i], m[i], 1e-12);
    }
}
END_TEST

/* Oblique moves (T not perpendicular to N, A B C all non-zero): every emitted point is at
 * distance W from the contour line, perpendicular to T and N, on the side of T x N. */
START_TEST(test_oblique)
{
    const double a = 12.0, b = -27.0, cdeg = 38.0, w_mm = 6.5;
    const double p0[3] = {10, -20, 600}, p1[3] = {55, 15, 585}; /* descends as it goes */
    for (int side = 141; side <= 142; side++) {
        struct comp5 c;
        struct canon_prog p;
        double start[6] = {0, 0, 650, a, b, cdeg}, n[3], t[3], v[3];
        comp5_init(&c);
        canon_prog_init(&p);
        struct comp5_block b0 = tu_block(side, p0[0], p0[1], p0[2], a, b, cdeg, w_mm, 1);
        struct comp5_block b1 = tu_block(side, p1[0], p1[1], p1[2], a, b, cdeg, w_mm, 2);
        ck_assert_int_eq(comp5_block(&c, &b0, start, canon_prog_sink, &p), COMP5_OK);
        ck_assert_int_eq(comp5_block(&c, &b1, start, canon_prog_sink, &p), COMP5_OK);
        ck_assert_int_eq(comp5_flush(&c, canon_prog_sink, &p), COMP5_OK);
        ck_assert_uint_eq(p.count, 2);
        tu_normal(a, b, cdeg, n);
        for (int i = 0; i < 3; i++)
            t[i] = p1[i] - p0[i];
        tu_unit(t);
        ck_assert(fabs(tu_dot(t, n)) > 0.1); /* really oblique */
        tu_cross(t, n, v);
        for (int k = 0; k < 2; k++) {
            const double *e = p.cmds[k].end, *prog = k ? p1 : p0;
            double d[3] = {e[0] - prog[0], e[1] - prog[1], e[2] - prog[2]};
            ck_assert_double_eq_tol(tu_dist_line(e, p0, t), w_mm, 1e-9);
            ck_assert_double_eq_tol(tu_norm(d), w_mm, 1e-9);
            ck_assert_double_eq_tol(tu_dot(d, t), 0.0, 1e-9);
            ck_assert_double_eq_tol(tu_dot(d, n), 0.0, 1e-9);
            ck_assert(side == 141 ? tu_dot(d, v) > 0 : tu_dot(d, v) < 0);
            ck_assert_int_eq(p.cmds[k].compensated, side);
        }
        canon_prog_free(&p);
    }
}
END_TEST

/* Collinear blocks need no join: three FEEDs, no arc. */
START_TEST(test_collinear)
{
    struct comp5 c;
    struct canon_prog p;
    double start[6] = {-4, 8, 0, 0, 0, 0}; /* beside the start, on the left: no gouge */
    comp5_init(&c);
    canon_prog_init(&p);
    for (int k = 0; k < 3; k++) {
        struct comp5_block b = tu_block(142, 10.0 * k, 5.0 * k, 0, 0, 0, 0, 4, k + 1);
        ck_assert_int_eq(comp5_block(&c, &b, start, canon_prog_sink, &p), COMP5_OK);
    }
    ck_assert_int_eq(comp5_flush(&c, canon_prog_sink, &p), COMP5_OK);
    ck_assert_uint_eq(p.count, 3);
    for (size_t k = 0; k < p.count; k++)
        ck_assert_int_eq(p.cmds[k].type, CANON_FEED);
    ck_assert_int_eq(p.cmds[1].line, 2);
    canon_prog_free(&p);
}
END_TEST

/* Runs blocks and a flush; returns the first non-OK status (or OK). */
static int run_blocks(struct comp5 *c, const struct comp5_block *b, int n, canon_sink_fn sink,
                      void *ctx)
{
    double start[6] = {0, 0, 100, 0, 0, 0};
    for (int k = 0; k < n; k++) {
        int rc = comp5_block(c, &b[k], start, sink, ctx);
        if (rc != COMP5_OK)
            return rc;
    }
    return comp5_flush(c, sink, ctx);
}

/* Expects status `want` at line `line`, with the line's number in the message. */
static void expect_error(const struct comp5_block *b, int n, canon_sink_fn sink, int want,
                         int line)
{
    struct comp5 c;
    struct canon_prog p;
    char num[16];
    comp5_init(&c);
    canon_prog_init(&p);
    ck_assert_int_eq(run_blocks(&c, b, n, sink ? sink : canon_prog_sink, &p), want);
    ck_assert_int_eq(c.err_line, line);
    ck_assert_int_eq(c.active, 0);
    snprintf(num, sizeof num, "%d", line);
    ck_assert_msg(strstr(comp5_errmsg(&c), num), "message lacks the line: %s",
                  comp5_errmsg(&c));
    ck_assert_str_ne(comp5_strerror(want), "unknown compensation status");
    canon_prog_free(&p);
}

START_TEST(test_errors)
{
    struct comp5_block b[3];
    b[0] = tu_block(141, 0, 0, 0, 0, 0, 0, 5, 10);
    expect_error(b, 1, NULL, COMP5_ERR_SINGLE_BLOCK, 10);
    b[1] = tu_block(141, 0, 0, 0, 0, 0, 20, 5, 11); /* same X Y Z, only C changes */
    expect_error(b, 2, NULL, COMP5_ERR_ZERO_LENGTH, 11);
    b[1] = tu_block(141, 0, 0, -30, 0, 0, 0, 5, 12); /* plunge along the tool axis */
    expect_error(b, 2, NULL, COMP5_ERR_ALONG_AXIS, 12);
    b[1] = tu_block(141, 1e-5, 0, -30, 0, 0, 0, 5, 12); /* within COMP5_MIN_SIN_AXIS */
    expect_error(b, 2, NULL, COMP5_ERR_ALONG_AXIS, 12);
    b[1] = tu_block(142, 40, 0, 0, 0, 0, 0, 5, 13);
    expect_error(b, 2, NULL, COMP5_ERR_MIXED_SIDES, 13);
    b[1] = tu_block(141, 40, 0, 0, 0, 0, 0, 0.0, 14);
    expect_error(b, 2, NULL, COMP5_ERR_RADIUS, 14);
    b[1].radius_mm = -2.0;
    expect_error(b, 2, NULL, COMP5_ERR_RADIUS, 14);
    b[1].radius_mm = NAN;
    expect_error(b, 2, NULL, COMP5_ERR_RADIUS, 14);
    b[1] = tu_block(141, 40, 0, 0, 0, 0, 0, 5, 15);
    expect_error(b, 2, tu_refuse_sink, COMP5_ERR_SINK, 10);
    b[1].side = 41;
    expect_error(b, 2, NULL, COMP5_ERR_SIDE, 15);
    /* Right turn with G141 is an inside corner; a 4 mm leg cannot take a 5 mm radius. */
    b[1] = tu_block(141, 40, 0, 0, 0, 0, 0, 5, 16);
    b[2] = tu_block(141, 40, -4, 0, 0, 0, 0, 5, 17);
    expect_error(b, 3, NULL, COMP5_ERR_GOUGE, 16);
    /* ... and the 40 mm leg before it cannot be shorter than the radius either. */
    b[0] = tu_block(141, 37, 0, 0, 0, 0, 0, 5, 10);
    b[2] = tu_block(141, 40, -30, 0, 0, 0, 0, 5, 17);
    expect_error(b, 3, NULL, COMP5_ERR_GOUGE, 16);
}
END_TEST

/* The same gouging corner is accepted once the legs are long enough. */
START_TEST(test_inside_fits)
{
    struct comp5 c;
    struct canon_prog p;
    struct comp5_block b[3] = {tu_block(141, 30, 0, 0, 0, 0, 0, 5, 1),
                               tu_block(141, 40, 0, 0, 0, 0, 0, 5, 2),
                               tu_block(141, 40, -5.0, 0, 0, 0, 0, 5, 3)};
    comp5_init(&c);
    canon_prog_init(&p);
    ck_assert_int_eq(run_blocks(&c, b, 3, canon_prog_sink, &p), COMP5_OK);
    /* positioning to (30,-5), cut to the join (35,-5), and the second leg ends there too */
    ck_assert_uint_eq(p.count, 2);
    ck_assert_double_eq_tol(p.cmds[1].end[0], 35.0, 1e-9);
    ck_assert_double_eq_tol(p.cmds[1].end[1], -5.0, 1e-9);
    canon_prog_free(&p);
}
END_TEST

/* Runs are separate: after a flush the other side may start a new run; a tool already at
 * the compensated start gets no positioning move. */
START_TEST(test_runs_separate)
{
    struct comp5 c;
    struct canon_prog p;
    double start[6] = {0, -5, 0, 0, 0, 0}; /* exactly the G141 start below */
    comp5_init(&c);
    canon_prog_init(&p);
    struct comp5_block b[4] = {tu_block(141, 0, 0, 0, 0, 0, 0, 5, 1),
                               tu_block(141, 30, 0, 0, 0, 0, 0, 5, 2),
                               tu_block(142, 40, -10, 0, 0, 0, 0, 5, 4),
                               tu_block(142, 70, -10, 0, 0, 0, 0, 5, 5)};
    ck_assert_int_eq(comp5_block(&c, &b[0], start, canon_prog_sink, &p), COMP5_OK);
    ck_assert_int_eq(comp5_block(&c, &b[1], start, canon_prog_sink, &p), COMP5_OK);
    ck_assert_uint_eq(p.count, 0); /* no positioning: the tool is there */
    ck_assert_int_eq(comp5_flush(&c, canon_prog_sink, &p), COMP5_OK);
    ck_assert_uint_eq(p.count, 1);
    ck_assert_int_eq(comp5_flush(&c, canon_prog_sink, &p), COMP5_OK); /* no run: no-op */
    ck_assert_uint_eq(p.count, 1);
    const double *pos = comp5_tool_pos(&c);
    ck_assert_double_eq_tol(pos[0], 30.0, 1e-12);
    ck_assert_double_eq_tol(pos[1], -5.0, 1e-12);
    ck_assert_int_eq(comp5_block(&c, &b[2], pos, canon_prog_sink, &p), COMP5_OK);
    ck_assert_int_eq(comp5_block(&c, &b[3], pos, canon_prog_sink, &p), COMP5_OK);
    ck_assert_int_eq(comp5_flush(&c, canon_prog_sink, &p), COMP5_OK);
    ck_assert_uint_eq(p.count, 3);
    ck_assert_int_eq(p.cmds[1].line, 4); /* positioning from (30,-5) to (40,-5) */
    ck_assert_double_eq_tol(p.cmds[1].end[0], 40.0, 1e-12);
    ck_assert_double_eq_tol(p.cmds[1].end[1], -5.0, 1e-12);
    ck_assert_int_eq(p.cmds[2].compensated, 142);
    canon_prog_free(&p);
}
END_TEST

static Suite *comp5_suite(void)
{
    Suite *s = suite_create("comp5");
    TCase *tc = tcase_create("core");
    tcase_add_loop_test(tc, test_worked_offset_point, 0, 6);
    tcase_add_loop_test(tc, test_worked_block_flush, 0, 6);
    tcase_add_test(tc, test_sign_convention_flat);
    tcase_add_test(tc, test_normal_independent);
    tcase_add_test(tc, test_oblique);
    tcase_add_test(tc, test_collinear);
    tcase_add_test(tc, test_errors);
    tcase_add_test(tc, test_inside_fits);
    tcase_add_test(tc, test_runs_separate);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(comp5_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
