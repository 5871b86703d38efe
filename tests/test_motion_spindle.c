/* test_motion_spindle.c: machine I/O on the path: spindle and coolant commands applied where
 * the path reaches them, kept after the program, off after an abort; with the at-speed input
 * wired, programs stop after M3/M4/S and wait for the spindle, and only then; tool changes
 * wait for the changer; M62..M68 outputs switch where the path reaches them. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/test_motion_util.h"

#define DT 0.001

static const double P0[6] = {0, 0, 645, 0, 0, 0};
static const double P1[6] = {20, 0, 645, 0, 0, 0};
static const double P2[6] = {20, 20, 645, 0, 0, 0};
static const double P3[6] = {0, 20, 645, 0, 0, 0};

static void add_simple(struct canon_prog *p, enum canon_type t, int line, double value,
                       int ivalue)
{
    struct canon_cmd c;
    memset(&c, 0, sizeof c);
    c.type = t;
    c.line = line;
    c.file = "test.ngc";
    c.value = value;
    c.ivalue = ivalue;
    if (canon_prog_sink(p, &c))
        abort();
}

/* S1000 M3, feed to P1, M8, feed to P2, M5 M9, feed to P3 (the trivial machine). */
static void spindle_program(struct canon_prog *p)
{
    canon_prog_init(p);
    p->start_path_mode = 610;        /* exact stops: the commands lie at rest points */
    memcpy(p->start, P0, sizeof P0);
    add_simple(p, CANON_SPINDLE_SPEED, 1, 1000, 0);
    add_simple(p, CANON_SPINDLE_ON, 1, 1, 0);
    tm_add(p, CANON_FEED, 2, P1, 1200, 0);
    add_simple(p, CANON_COOLANT, 3, 0, 8);
    tm_add(p, CANON_FEED, 4, P2, 1200, 0);
    add_simple(p, CANON_SPINDLE_STOP, 5, 0, 0);
    add_simple(p, CANON_COOLANT, 5, 0, 9);
    tm_add(p, CANON_FEED, 6, P3, 1200, 0);
}

static double dist2(const double *a, const double *b)
{
    return hypot(a[0] - b[0], a[1] - b[1]);
}

/* Where each command takes effect: the spindle from the start, flood at P1, both off at P2
 * (within one period's travel at 20 mm/s); the plan is the same as without them. */
START_TEST(test_commands_where_the_path_reaches_them)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
    struct canon_prog p, bare;
    spindle_program(&p);
    canon_prog_init(&bare);
    bare.start_path_mode = 610;
    memcpy(bare.start, P0, sizeof P0);
    tm_add(&bare, CANON_FEED, 2, P1, 1200, 0);
    tm_add(&bare, CANON_FEED, 4, P2, 1200, 0);
    tm_add(&bare, CANON_FEED, 6, P3, 1200, 0);
    char err[256];
    struct motion_plan_info with, without;
    ck_assert_int_eq(motion_load(mc.m, &bare, err, sizeof err), MOTION_OK);
    motion_plan_info(mc.m, &without);
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_OK);
    motion_plan_info(mc.m, &with);
    ck_assert_uint_eq(with.segments, without.segments);
    ck_assert_double_eq_tol(with.time_s, without.time_s, 1e-12);
    ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
    struct motion_out o = { 0 };
    double flood_at[6] = {0}, off_at[6] = {0};
    int had_flood = 0, had_off = 0, first = 1;
    for (int k = 0; k < 100000; k++) {
        motion_step(mc.m, DT, &o);
        if (first) {
            ck_assert_int_eq(o.spindle.dir, 1);
            ck_assert_double_eq(o.spindle.rpm, 1000);
            ck_assert_int_eq(o.spindle.flood, 0);
            first = 0;
        }
        if (o.spindle.flood && !had_flood)
            had_flood = 1, memcpy(flood_at, o.pose, sizeof flood_at);
        if (had_flood && o.spindle.dir == 0 && !had_off)
            had_off = 1, memcpy(off_at, o.pose, sizeof off_at);
        if (o.state == MOTION_DONE)
            break;
    }
    ck_assert_int_eq(o.state, MOTION_DONE);
    ck_assert(had_flood && had_off);
    ck_assert_msg(dist2(flood_at, P1) <= 20 * DT + 1e-9, "flood on %.4f mm from P1",
                  dist2(flood_at, P1));
    ck_assert_msg(dist2(off_at, P2) <= 20 * DT + 1e-9, "spindle off %.4f mm from P2",
                  dist2(off_at, P2));
    ck_assert_int_eq(o.spindle.flood, 0);
    canon_prog_free(&p);
    canon_prog_free(&bare);
    tm_close(&mc);
}
END_TEST

/* An MDI-like program (S1200 M4 only) leaves the spindle turning after it is done, into the
 * next program; an abort stops it. */
START_TEST(test_spindle_kept_then_stopped_by_abort)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
    struct canon_prog p;
    canon_prog_init(&p);
    memcpy(p.start, P0, sizeof P0);
    add_simple(&p, CANON_SPINDLE_SPEED, 1, 1200, 0);
    add_simple(&p, CANON_SPINDLE_ON, 1, -1, 0);
    char err[256];
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_OK);
    ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
    struct motion_out o = { 0 };
    for (int k = 0; k < 3; k++)
        motion_step(mc.m, DT, &o);
    ck_assert_int_eq(o.state, MOTION_DONE);
    ck_assert_int_eq(o.spindle.dir, -1);
    ck_assert_double_eq(o.spindle.rpm, 1200);
    canon_prog_free(&p);
    canon_prog_init(&p);
    memcpy(p.start, P0, sizeof P0);
    tm_add(&p, CANON_FEED, 2, P1, 600, 0);
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_OK);
    ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
    for (int k = 0; k < 200; k++)
        motion_step(mc.m, DT, &o);
    ck_assert_int_eq(o.state, MOTION_RUNNING);
    ck_assert_int_eq(o.spindle.dir, -1);          /* still turning in the next program */
    ck_assert_int_eq(motion_abort(mc.m), MOTION_OK);
    for (int k = 0; k < 2000 && o.state != MOTION_IDLE; k++)
        motion_step(mc.m, DT, &o);
    ck_assert_int_eq(o.state, MOTION_IDLE);
    motion_step(mc.m, DT, &o);
    ck_assert_int_eq(o.spindle.dir, 0);           /* an abort stops it */
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* With the at-speed input wired: feed to P1, S1000 M3, feed to P2. The path stops at P1 and
 * holds while the spindle is not at speed (waiting), then goes on to P2 once it is. */
START_TEST(test_wait_for_spindle_at_speed)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
    motion_set_wait_at_speed(mc.m, true);
    motion_set_spindle_at_speed(mc.m, false);
    struct canon_prog p;
    canon_prog_init(&p);
    memcpy(p.start, P0, sizeof P0);
    tm_add(&p, CANON_FEED, 2, P1, 1200, 0);
    add_simple(&p, CANON_SPINDLE_SPEED, 3, 1000, 0);
    add_simple(&p, CANON_SPINDLE_ON, 3, 1, 0);
    tm_add(&p, CANON_FEED, 4, P2, 1200, 0);
    char err[256];
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_OK);
    ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
    struct motion_out o = { 0 };
    int k = 0;
    for (; k < 100000 && !(o.waiting); k++)
        motion_step(mc.m, DT, &o);
    ck_assert_int_eq(o.waiting, 1);
    ck_assert_msg(dist2(o.pose, P1) < 1e-9, "waits %.6f mm from P1", dist2(o.pose, P1));
    ck_assert_int_eq(o.spindle.dir, 1);           /* started, so that it can get there */
    for (int j = 0; j < 3000; j++) {               /* 3 s without the spindle at speed */
        motion_step(mc.m, DT, &o);
        ck_assert_int_eq(o.state, MOTION_RUNNING);
        ck_assert_msg(dist2(o.pose, P1) < 1e-9, "moved while waiting");
        ck_assert_double_eq(o.path_vel, 0);
    }
    motion_set_spindle_at_speed(mc.m, true);
    for (k = 0; k < 100000 && o.state != MOTION_DONE; k++)
        motion_step(mc.m, DT, &o);
    ck_assert_int_eq(o.state, MOTION_DONE);
    ck_assert_int_eq(o.waiting, 0);
    ck_assert_msg(dist2(o.pose, P2) < 1e-9, "did not reach P2");
    /* the same program without the input wired: no stop planned */
    struct motion_plan_info waits, plain;
    motion_plan_info(mc.m, &waits);
    motion_set_wait_at_speed(mc.m, false);
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_OK);
    motion_plan_info(mc.m, &plain);
    ck_assert_uint_eq(waits.segments, plain.segments + 1);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* An abort while waiting ends the program at rest, the spindle off. */
START_TEST(test_abort_while_waiting)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
    motion_set_wait_at_speed(mc.m, true);
    motion_set_spindle_at_speed(mc.m, false);
    struct canon_prog p;
    canon_prog_init(&p);
    memcpy(p.start, P0, sizeof P0);
    add_simple(&p, CANON_SPINDLE_SPEED, 1, 800, 0);
    add_simple(&p, CANON_SPINDLE_ON, 1, 1, 0);
    tm_add(&p, CANON_FEED, 2, P1, 1200, 0);
    char err[256];
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_OK);
    ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
    struct motion_out o = { 0 };
    for (int k = 0; k < 100; k++)
        motion_step(mc.m, DT, &o);
    ck_assert_int_eq(o.waiting, 1);
    ck_assert_int_eq(motion_abort(mc.m), MOTION_OK);
    motion_step(mc.m, DT, &o);
    motion_step(mc.m, DT, &o);
    ck_assert_int_eq(o.state, MOTION_IDLE);
    ck_assert_int_eq(o.spindle.dir, 0);
    ck_assert_msg(dist2(o.pose, P0) < 1e-9, "moved");
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* A program that only starts the spindle (an MDI line S1000 M3) waits for it too, then is
 * done; the at-speed report must come after the command (one that was true for the
 * stopped spindle does not count). */
START_TEST(test_lone_spindle_start_waits)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
    motion_set_wait_at_speed(mc.m, true);
    motion_set_spindle_at_speed(mc.m, true);  /* true for the stopped spindle */
    struct canon_prog p;
    canon_prog_init(&p);
    memcpy(p.start, P0, sizeof P0);
    add_simple(&p, CANON_SPINDLE_SPEED, 1, 1000, 0);
    add_simple(&p, CANON_SPINDLE_ON, 1, 1, 0);
    char err[256];
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_OK);
    ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
    struct motion_out o = { 0 };
    motion_step(mc.m, DT, &o);
    ck_assert_int_eq(o.state, MOTION_RUNNING);
    ck_assert_int_eq(o.waiting, 1);
    motion_set_spindle_at_speed(mc.m, false);   /* the spindle sees the command: not yet */
    for (int k = 0; k < 500; k++) {
        motion_step(mc.m, DT, &o);
        ck_assert_int_eq(o.state, MOTION_RUNNING);
    }
    motion_set_spindle_at_speed(mc.m, true);
    for (int k = 0; k < 3 && o.state != MOTION_DONE; k++)
        motion_step(mc.m, DT, &o);
    ck_assert_int_eq(o.state, MOTION_DONE);
    ck_assert_int_eq(o.spindle.dir, 1);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* M6 with a tool changer: the path stops at the M6 and holds (waiting 2) with the request
 * out until the changer answers that request; then the tool is in the spindle and the path
 * goes on. M61 Q sets the tool without a change or a stop. */
START_TEST(test_tool_change_waits_for_the_changer)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
    motion_set_wait_tool(mc.m, true);
    struct canon_prog p;
    canon_prog_init(&p);
    memcpy(p.start, P0, sizeof P0);
    add_simple(&p, CANON_TOOL_CHANGE, 1, 1, 7);     /* M61 Q7 */
    tm_add(&p, CANON_FEED, 2, P1, 1200, 0);
    add_simple(&p, CANON_TOOL_CHANGE, 3, 0, 3);     /* T3 M6 */
    tm_add(&p, CANON_FEED, 4, P2, 1200, 0);
    char err[256];
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_OK);
    ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
    struct motion_out o = { 0 };
    motion_step(mc.m, DT, &o);
    ck_assert_int_eq(o.tool.number, 7);
    ck_assert_int_eq(o.waiting, 0);
    for (int k = 0; k < 100000 && !o.waiting; k++)
        motion_step(mc.m, DT, &o);
    ck_assert_int_eq(o.waiting, 2);
    ck_assert_msg(dist2(o.pose, P1) < 1e-9, "waits %.6f mm from P1", dist2(o.pose, P1));
    ck_assert_int_eq(o.tool.request, 3);
    ck_assert_int_eq(o.tool.number, 7);
    unsigned seq = o.tool.seq;
    motion_tool_changed(mc.m, seq + 1);              /* not this request: ignored */
    for (int k = 0; k < 1000; k++) {
        motion_step(mc.m, DT, &o);
        ck_assert_int_eq(o.waiting, 2);
    }
    motion_tool_changed(mc.m, seq);
    for (int k = 0; k < 100000 && o.state != MOTION_DONE; k++)
        motion_step(mc.m, DT, &o);
    ck_assert_int_eq(o.state, MOTION_DONE);
    ck_assert_int_eq(o.tool.number, 3);
    ck_assert_msg(dist2(o.pose, P2) < 1e-9, "did not reach P2");
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

static void add_out(struct canon_prog *p, enum canon_type t, int line, int n, double v,
                    int immediate)
{
    struct canon_cmd c;
    memset(&c, 0, sizeof c);
    c.type = t;
    c.line = line;
    c.file = "test.ngc";
    c.ivalue = n;
    c.value = v;
    c.immediate = immediate;
    if (canon_prog_sink(p, &c))
        abort();
}

/* M62 P1 before the move to P1 (on as it starts), M63 P1 and M67 E2 Q3.5 before the move to
 * P2 (at P1), M64 P3 and M68 E0 Q-2 before the move to P3 (at P2): each where the path
 * reaches it, and all kept after the program. An output the machine does not have
 * ([EMCMOT] NUM_DIO) is refused at planning, naming the line. */
START_TEST(test_outputs_where_the_path_reaches_them)
{
    struct tm_machine mc;
    ck_assert_int_eq(tm_open(&mc, tm_trivial_cfg(), &kins_trivial_ops), 0);
    struct canon_prog p;
    canon_prog_init(&p);
    memcpy(p.start, P0, sizeof P0);
    add_out(&p, CANON_DIGITAL_OUT, 1, 1, 1, 0);
    tm_add(&p, CANON_FEED, 2, P1, 1200, 0);
    add_out(&p, CANON_DIGITAL_OUT, 3, 1, 0, 0);
    add_out(&p, CANON_ANALOG_OUT, 3, 2, 3.5, 0);
    tm_add(&p, CANON_FEED, 4, P2, 1200, 0);
    add_out(&p, CANON_DIGITAL_OUT, 5, 3, 1, 1);
    add_out(&p, CANON_ANALOG_OUT, 5, 0, -2, 1);
    tm_add(&p, CANON_FEED, 6, P3, 1200, 0);
    char err[256];
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_OK);
    ck_assert_int_eq(motion_start(mc.m), MOTION_OK);
    struct motion_out o = { 0 };
    double off_at[6] = {0}, d3_at[6] = {0};
    int off = 0, d3 = 0;
    motion_step(mc.m, DT, &o);
    ck_assert_uint_eq(o.outputs.dout, 1u << 1);
    for (int k = 0; k < 100000 && o.state != MOTION_DONE; k++) {
        motion_step(mc.m, DT, &o);
        if (!off && !(o.outputs.dout & 2u)) {
            off = 1;
            memcpy(off_at, o.pose, sizeof off_at);
            ck_assert_double_eq(o.outputs.aout[2], 3.5);
        }
        if (!d3 && (o.outputs.dout & 8u)) {
            d3 = 1;
            memcpy(d3_at, o.pose, sizeof d3_at);
            ck_assert_double_eq(o.outputs.aout[0], -2);
        }
    }
    ck_assert_int_eq(o.state, MOTION_DONE);
    ck_assert(off && d3);
    ck_assert_msg(dist2(off_at, P1) <= 20 * DT + 1e-9, "M63 %.4f mm from P1",
                  dist2(off_at, P1));
    ck_assert_msg(dist2(d3_at, P2) <= 20 * DT + 1e-9, "M64 %.4f mm from P2", dist2(d3_at, P2));
    ck_assert_uint_eq(o.outputs.dout, 1u << 3);
    canon_prog_free(&p);
    canon_prog_init(&p);
    memcpy(p.start, P0, sizeof P0);
    add_out(&p, CANON_DIGITAL_OUT, 9, 4, 1, 0);   /* 4 outputs by default: 0..3 */
    ck_assert_int_eq(motion_load(mc.m, &p, err, sizeof err), MOTION_ERR_PROGRAM);
    ck_assert_msg(strstr(err, "test.ngc:9: M62: digital output 4 does not exist: the machine "
                         "has 4 ([EMCMOT] NUM_DIO)"), "%s", err);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

static Suite *spindle_suite(void)
{
    Suite *s = suite_create("motion_spindle");
    TCase *tc = tcase_create("spindle");
    tcase_add_test(tc, test_commands_where_the_path_reaches_them);
    tcase_add_test(tc, test_spindle_kept_then_stopped_by_abort);
    tcase_add_test(tc, test_wait_for_spindle_at_speed);
    tcase_add_test(tc, test_abort_while_waiting);
    tcase_add_test(tc, test_lone_spindle_start_waits);
    tcase_add_test(tc, test_tool_change_waits_for_the_changer);
    tcase_add_test(tc, test_outputs_where_the_path_reaches_them);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(spindle_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
