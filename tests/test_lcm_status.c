/* test_lcm_status.c: lcm-status in a HAL graph on the simulated clock, read back over memq://
 * (in process) and from a file:// LCM log: values, order, decimation, fault events. */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <lcm/eventlog.h>
#include <lcm/lcm.h>

#include "hal/components/lcm_status.h"
#include "hal/hal.h"
#include "lcmtypes/hexcnc_event_t.h"
#include "lcmtypes/hexcnc_status_t.h"

#define PERIOD_NS 1000000L          /* servo period: 1 ms */
#define MAX_MSGS 256

/* What the test received, in order. */
struct got {
    int n_status, n_event;
    hexcnc_status_t status[MAX_MSGS];   /* fault_text not kept */
    char fault_text[MAX_MSGS][64];
    hexcnc_event_t event[16];           /* source/text copied below */
    char source[16][32], text[16][1400];
};

/* Keeps one decoded status message. */
static void got_status(struct got *g, const hexcnc_status_t *m)
{
    ck_assert_int_lt(g->n_status, MAX_MSGS);
    g->status[g->n_status] = *m;
    snprintf(g->fault_text[g->n_status], sizeof g->fault_text[0], "%s", m->fault_text);
    g->status[g->n_status++].fault_text = NULL;
}

/* Keeps one decoded event. */
static void got_event(struct got *g, const hexcnc_event_t *m)
{
    ck_assert_int_lt(g->n_event, 16);
    g->event[g->n_event] = *m;
    snprintf(g->source[g->n_event], 32, "%s", m->source);
    snprintf(g->text[g->n_event], sizeof g->text[0], "%s", m->text);
    g->n_event++;
}

static void on_status(const lcm_recv_buf_t *rb, const char *ch, const hexcnc_status_t *m, void *u)
{
    got_status(u, m);
}

static void on_event(const lcm_recv_buf_t *rb, const char *ch, const hexcnc_event_t *m, void *u)
{
    got_event(u, m);
}

/* Runs a HAL command, failing with the runtime's message. */
static void cmd(struct hal *h, const char *line)
{
    int st = hal_cmd(h, line, "test", 0, stdout);
    ck_assert_msg(st == HAL_OK, "'%s': %s", line, hal_last_error(h));
}

/* A graph on the simulated clock: sum2.0 counts periods (out = previous out + 1, so at
 * machine time n ms it is n); pose-cmd-x and leg-cmd-2 get the count, leg-fb-5 half of it,
 * line a constant; then lcm-status.sample runs last, as in a machine's HAL file. */
static struct hal *make_graph(const char *loadrt)
{
    struct hal *h = hal_create();
    ck_assert_ptr_nonnull(h);
    hal_set_sim_clock(h, true);
    cmd(h, "newthread servo-thread 1000000");
    cmd(h, "loadrt sum2 count=2");
    cmd(h, "setp sum2.0.offset 1");
    cmd(h, "net count sum2.0.out => sum2.0.in0 sum2.1.in0");
    cmd(h, "setp sum2.1.gain0 0.5");
    cmd(h, loadrt);
    cmd(h, "net count => lcm-status.pose-cmd-x lcm-status.leg-cmd-2");
    cmd(h, "net half sum2.1.out => lcm-status.leg-fb-5");
    cmd(h, "setp lcm-status.line 42");
    cmd(h, "setp lcm-status.state 1");
    cmd(h, "addf sum2.0 servo-thread");
    cmd(h, "addf sum2.1 servo-thread");
    cmd(h, "addf lcm-status.sample servo-thread");
    return h;
}

/* Runs ms milliseconds of machine time in 10 ms steps (as a runner does between looks). */
static void run_ms(struct hal *h, int ms)
{
    for (int i = 0; i < ms / 10; i++)
        ck_assert_int_eq(hal_sim_advance(h, 10 * PERIOD_NS), HAL_OK);
}

/* The stream of a 1 s run at 50 Hz: samples at 1 ms, then on the 20 ms grid; the kins fault
 * input raised from 300 to 600 ms; one event posted by "runner". */
static void run_scenario(struct hal *h)
{
    ck_assert_int_eq(hal_start(h), HAL_OK);
    run_ms(h, 300);
    cmd(h, "setp lcm-status.fault-kins 1");
    run_ms(h, 300);
    cmd(h, "setp lcm-status.fault-kins 0");
    ck_assert_int_eq(lcm_status_post_event(h, LCM_SEV_WARNING, LCM_CODE_USER + 1, "runner", -1,
                                           "spindle %d rpm", 12000), LCM_STATUS_OK);
    run_ms(h, 400);
    ck_assert_int_eq(lcm_status_flush(h, 5000), LCM_STATUS_OK);
}

/* Events come from two queues (fault edges with the samples, posted events on their own),
 * so their order between channels depends on when the publisher looked: sort by time. */
static void sort_events(struct got *g)
{
    for (int i = 1; i < g->n_event; i++)
        for (int j = i; j > 0 && g->event[j].utime < g->event[j - 1].utime; j--) {
            hexcnc_event_t e = g->event[j];
            char src[32], txt[sizeof g->text[0]];
            memcpy(src, g->source[j], sizeof src);
            memcpy(txt, g->text[j], sizeof txt);
            g->event[j] = g->event[j - 1];
            memcpy(g->source[j], g->source[j - 1], sizeof src);
            memcpy(g->text[j], g->text[j - 1], sizeof txt);
            g->event[j - 1] = e;
            memcpy(g->source[j - 1], src, sizeof src);
            memcpy(g->text[j - 1], txt, sizeof txt);
        }
}

/* What run_scenario must give at 50 Hz. */
static void check_scenario(struct got *g)
{
    sort_events(g);
    ck_assert_int_eq(g->n_status, 51);           /* t = 1 ms, 20, 40, ..., 1000 ms */
    for (int i = 0; i < g->n_status; i++) {
        const hexcnc_status_t *m = &g->status[i];
        int64_t t_ms = i == 0 ? 1 : 20 * i;
        ck_assert_int_eq(m->seq, i);
        ck_assert_int_eq(m->machine_time_ns, t_ms * PERIOD_NS);
        ck_assert_int_eq(m->utime, t_ms * 1000);
        ck_assert(m->pose_cmd[0] == (double)t_ms);
        ck_assert(m->leg_cmd_mm[2] == (double)t_ms);
        ck_assert(m->leg_fb_mm[5] == 0.5 * (double)t_ms);
        ck_assert_int_eq(m->line, 42);
        ck_assert_int_eq(m->state, 1);
        ck_assert_int_eq(m->dropped, 0);
        bool faulted = t_ms > 300 && t_ms <= 600;
        ck_assert_int_eq(m->fault_flags, faulted ? 2 : 0);   /* motion, kins, estop */
        ck_assert_str_eq(g->fault_text[i], faulted ? "kins" : "");
    }
    ck_assert_int_eq(g->n_event, 3);
    ck_assert_int_eq(g->event[0].severity, HEXCNC_EVENT_T_FAULT);
    ck_assert_int_eq(g->event[0].code, LCM_CODE_FAULT_RAISED);
    ck_assert_int_eq(g->event[0].utime, 301000);         /* first period that saw it */
    ck_assert_str_eq(g->source[0], "kins");
    ck_assert_str_eq(g->text[0], "kins reports a fault (program line 42)");
    ck_assert_int_eq(g->event[0].line, 42);
    ck_assert_int_eq(g->event[1].severity, HEXCNC_EVENT_T_WARNING);
    ck_assert_int_eq(g->event[1].code, LCM_CODE_USER + 1);
    ck_assert_int_eq(g->event[1].utime, 600000);         /* machine time when posted */
    ck_assert_int_eq(g->event[1].line, 42);              /* line < 0: the last sample's */
    ck_assert_str_eq(g->source[1], "runner");
    ck_assert_str_eq(g->text[1], "spindle 12000 rpm");
    ck_assert_int_eq(g->event[2].severity, HEXCNC_EVENT_T_INFO);
    ck_assert_int_eq(g->event[2].code, LCM_CODE_FAULT_CLEARED);
    ck_assert_int_eq(g->event[2].utime, 601000);
    ck_assert_str_eq(g->text[2], "kins fault cleared (program line 42)");
}

/* memq:// is in-process: subscribe on the component's own LCM instance. */
START_TEST(test_memq_stream)
{
    static struct got g;
    memset(&g, 0, sizeof g);
    struct hal *h = make_graph("loadrt lcm-status url=memq:// rate=50");
    lcm_t *lcm = lcm_status_lcm(h);
    ck_assert_ptr_nonnull(lcm);
    hexcnc_status_t_subscription_t *ss =
        hexcnc_status_t_subscribe(lcm, LCM_STATUS_CHANNEL, on_status, &g);
    hexcnc_event_t_subscription_t *se =
        hexcnc_event_t_subscribe(lcm, LCM_EVENT_CHANNEL, on_event, &g);
    run_scenario(h);
    while (lcm_handle_timeout(lcm, 50) > 0) {
    }
    check_scenario(&g);
    struct lcm_status_stats st;
    ck_assert_int_eq(lcm_status_get_stats(h, &st), LCM_STATUS_OK);
    ck_assert_uint_eq(st.samples, 51);
    ck_assert_uint_eq(st.status_sent, 51);
    ck_assert_uint_eq(st.events_sent, 3);
    ck_assert_uint_eq(st.samples_dropped + st.events_dropped + st.publish_errors, 0);
    hexcnc_status_t_unsubscribe(lcm, ss);
    hexcnc_event_t_unsubscribe(lcm, se);
    hal_destroy(h);
}
END_TEST

/* The whole text of a long event arrives (a runner's fault outcome with its cause at the
 * end was cut at 159 characters), and on the simulated clock the stop is published: a
 * change of the state input between grid points gives a sample at once, with its state. */
START_TEST(test_long_event_and_final_sample)
{
    static struct got g;
    memset(&g, 0, sizeof g);
    struct hal *h = make_graph("loadrt lcm-status url=memq:// rate=50");
    lcm_t *lcm = lcm_status_lcm(h);
    hexcnc_status_t_subscription_t *ss =
        hexcnc_status_t_subscribe(lcm, LCM_STATUS_CHANNEL, on_status, &g);
    hexcnc_event_t_subscription_t *se =
        hexcnc_event_t_subscribe(lcm, LCM_EVENT_CHANNEL, on_event, &g);
    char cause[1100];
    memset(cause, 'x', sizeof cause);
    memcpy(cause + sizeof cause - 41, " (cause: cia402.2: CAN node 3 (joint 2))", 40);
    cause[sizeof cause - 1] = '\0';
    ck_assert_int_eq(hal_start(h), HAL_OK);
    ck_assert_int_eq(hal_sim_advance(h, 95 * PERIOD_NS), HAL_OK);   /* samples 1..80 ms */
    cmd(h, "setp lcm-status.state 4");                              /* the run stops */
    ck_assert_int_eq(lcm_status_post_event(h, LCM_SEV_FAULT, LCM_CODE_USER + 2, "task", -1,
                                           "fault: %s", cause), LCM_STATUS_OK);
    ck_assert_int_eq(hal_sim_advance(h, 2 * PERIOD_NS), HAL_OK);
    ck_assert_int_eq(lcm_status_flush(h, 5000), LCM_STATUS_OK);
    while (lcm_handle_timeout(lcm, 50) > 0) {
    }
    ck_assert_int_eq(g.n_event, 1);
    ck_assert_uint_eq(strlen(g.text[0]), strlen("fault: ") + strlen(cause));
    ck_assert_ptr_nonnull(strstr(g.text[0], "(cause: cia402.2: CAN node 3 (joint 2))"));
    ck_assert_int_eq(g.n_status, 6);                      /* 1, 20, 40, 60, 80, and 96 ms */
    ck_assert_int_eq(g.status[4].machine_time_ns, 80 * PERIOD_NS);
    ck_assert_int_eq(g.status[4].state, 1);
    ck_assert_int_eq(g.status[5].machine_time_ns, 96 * PERIOD_NS);  /* first period seeing it */
    ck_assert_int_eq(g.status[5].state, 4);
    ck_assert(g.status[5].pose_cmd[0] == 96.0);
    hexcnc_status_t_unsubscribe(lcm, ss);
    hexcnc_event_t_unsubscribe(lcm, se);
    hal_destroy(h);
}
END_TEST

/* Reads every message of an LCM log back with lcm_eventlog_*. */
static void read_log(const char *path, struct got *g)
{
    lcm_eventlog_t *log = lcm_eventlog_create(path, "r");
    ck_assert_msg(log != NULL, "cannot read %s", path);
    lcm_eventlog_event_t *ev;
    while ((ev = lcm_eventlog_read_next_event(log))) {
        if (!strcmp(ev->channel, LCM_STATUS_CHANNEL)) {
            hexcnc_status_t m;
            ck_assert_int_ge(hexcnc_status_t_decode(ev->data, 0, (int)ev->datalen, &m), 0);
            got_status(g, &m);
            hexcnc_status_t_decode_cleanup(&m);
        } else if (!strcmp(ev->channel, LCM_EVENT_CHANNEL)) {
            hexcnc_event_t m;
            ck_assert_int_ge(hexcnc_event_t_decode(ev->data, 0, (int)ev->datalen, &m), 0);
            got_event(g, &m);
            hexcnc_event_t_decode_cleanup(&m);
        }
        lcm_eventlog_free_event(ev);
    }
    lcm_eventlog_destroy(log);
}

/* file:// writes an LCM log; hal_destroy publishes what is left and closes it. */
START_TEST(test_file_log)
{
    static struct got g;
    memset(&g, 0, sizeof g);
    char dir[] = "/tmp/test_lcm_XXXXXX", path[64], line[160];
    ck_assert_ptr_nonnull(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/status.lcmlog", dir);
    snprintf(line, sizeof line, "loadrt lcm-status url=file://%s?mode=w rate=50", path);
    struct hal *h = make_graph(line);
    run_scenario(h);
    hal_destroy(h);
    read_log(path, &g);
    check_scenario(&g);
    unlink(path);
    rmdir(dir);
}
END_TEST

/* Decimation by machine time at 8 Hz (125 ms): samples at 1, 125, 250, ..., 1000 ms. The URL
 * and rate come from the INI's [LCM] section when loadrt gives none. */
START_TEST(test_rate_from_ini)
{
    static struct got g;
    memset(&g, 0, sizeof g);
    char dir[] = "/tmp/test_lcm_XXXXXX", ini[64], path[64];
    ck_assert_ptr_nonnull(mkdtemp(dir));
    snprintf(ini, sizeof ini, "%s/m.ini", dir);
    snprintf(path, sizeof path, "%s/r.lcmlog", dir);
    FILE *f = fopen(ini, "w");
    ck_assert_ptr_nonnull(f);
    fprintf(f, "[LCM]\nURL = file://%s?mode=w\nRATE_HZ = 8\n", path);
    fclose(f);
    struct hal *g2 = hal_create();
    ck_assert_int_eq(hal_load_ini(g2, ini), HAL_OK);
    hal_set_sim_clock(g2, true);
    cmd(g2, "newthread servo-thread 1000000");
    cmd(g2, "loadrt lcm-status");
    cmd(g2, "setp lcm-status.pose-fb-c 7.5");
    cmd(g2, "addf lcm-status.sample servo-thread");
    ck_assert_int_eq(hal_start(g2), HAL_OK);
    run_ms(g2, 1000);
    hal_destroy(g2);
    read_log(path, &g);
    ck_assert_int_eq(g.n_status, 9);
    for (int i = 0; i < 9; i++) {
        ck_assert_int_eq(g.status[i].seq, i);
        ck_assert_int_eq(g.status[i].machine_time_ns, (i == 0 ? 1 : 125 * i) * PERIOD_NS);
        ck_assert(g.status[i].pose_fb[5] == 7.5);
    }
    ck_assert_int_eq(g.n_event, 0);
    unlink(path);
    unlink(ini);
    rmdir(dir);
}
END_TEST

/* No URL, or one that does not open: the machine runs, nothing is published. */
START_TEST(test_disabled)
{
    const char *loads[] = { "loadrt lcm-status", "loadrt lcm-status url=nosuchprovider://x" };
    for (int i = 0; i < 2; i++) {
        struct hal *h = make_graph(loads[i]);
        bool *active = hal_data_ptr(h, "lcm-status.active", NULL);
        ck_assert_ptr_nonnull(active);
        ck_assert(!*active);
        ck_assert_ptr_null(lcm_status_lcm(h));
        ck_assert_int_eq(hal_start(h), HAL_OK);
        run_ms(h, 50);
        ck_assert_int_eq(lcm_status_post_event(h, LCM_SEV_INFO, 100, "x", 0, "y"),
                         LCM_STATUS_DISABLED);
        struct lcm_status_stats st;
        ck_assert_int_eq(lcm_status_get_stats(h, &st), LCM_STATUS_DISABLED);
        ck_assert_uint_eq(st.samples, 0);
        hal_destroy(h);
    }
    struct hal *h = hal_create();
    ck_assert_int_eq(lcm_status_post_event(h, LCM_SEV_INFO, 100, "x", 0, "y"),
                     LCM_STATUS_NOT_LOADED);
    ck_assert_int_eq(lcm_status_flush(h, 10), LCM_STATUS_NOT_LOADED);
    hal_destroy(h);
}
END_TEST

/* Wrong arguments are refused with a message that says what is wrong; nothing is left. */
START_TEST(test_bad_args)
{
    struct hal *h = hal_create();
    ck_assert_int_ne(hal_cmd(h, "loadrt lcm-status url=memq:// rate=0", "m.hal", 3, stdout), HAL_OK);
    ck_assert_msg(strstr(hal_last_error(h), "publish rate must be a number") != NULL, "%s",
                  hal_last_error(h));
    ck_assert_int_ne(hal_cmd(h, "loadrt lcm-status url=memq:// ring=1000", "m.hal", 4, stdout), HAL_OK);
    ck_assert_msg(strstr(hal_last_error(h), "ring=1000: the ring size must be a power of two")
                  != NULL, "%s", hal_last_error(h));
    ck_assert_int_ne(hal_cmd(h, "loadrt lcm-status speed=3", "m.hal", 5, stdout), HAL_OK);
    ck_assert_ptr_null(hal_data_ptr(h, "lcm-status.line", NULL));
    /* After the failures the name is free: a good load works. */
    cmd(h, "loadrt lcm-status url=memq:// faults=modbus.0,modbus.1");
    ck_assert_ptr_nonnull(hal_data_ptr(h, "lcm-status.fault-modbus.1", NULL));
    ck_assert_ptr_null(hal_data_ptr(h, "lcm-status.fault-motion", NULL));
    hal_destroy(h);
}
END_TEST

/* A ring of 2 samples filled faster than the publisher looks: samples are dropped, never
 * waited for; sent + dropped = taken, and a warning event says how many were lost. */
START_TEST(test_full_ring_drops)
{
    static struct got g;
    memset(&g, 0, sizeof g);
    struct hal *h = make_graph("loadrt lcm-status url=memq:// rate=1000 ring=2");
    lcm_t *lcm = lcm_status_lcm(h);
    hexcnc_status_t_subscription_t *ss =
        hexcnc_status_t_subscribe(lcm, LCM_STATUS_CHANNEL, on_status, &g);
    hexcnc_event_t_subscription_t *se =
        hexcnc_event_t_subscribe(lcm, LCM_EVENT_CHANNEL, on_event, &g);
    ck_assert_int_eq(hal_start(h), HAL_OK);
    ck_assert_int_eq(hal_sim_advance(h, 200 * PERIOD_NS), HAL_OK);   /* 200 samples at once */
    ck_assert_int_eq(lcm_status_flush(h, 5000), LCM_STATUS_OK);
    struct lcm_status_stats st;
    lcm_status_get_stats(h, &st);
    while (lcm_handle_timeout(lcm, 50) > 0) {
    }
    ck_assert_uint_gt(st.samples_dropped, 0);
    ck_assert_uint_eq(st.samples, 200);
    ck_assert_uint_eq(st.status_sent + st.samples_dropped, 200);
    ck_assert_int_eq(g.n_status, (int)st.status_sent);
    for (int i = 1; i < g.n_status; i++) {     /* what got through is in order; gaps = drops */
        ck_assert_int_lt(g.status[i - 1].seq, g.status[i].seq);
        ck_assert_int_eq(g.status[i].machine_time_ns, (g.status[i].seq + 1) * PERIOD_NS);
    }
    ck_assert_int_ge(g.n_event, 1);
    ck_assert_int_eq(g.event[0].code, LCM_CODE_SAMPLES_DROPPED);
    ck_assert_int_eq(g.event[0].severity, HEXCNC_EVENT_T_WARNING);
    hexcnc_status_t_unsubscribe(lcm, ss);
    hexcnc_event_t_unsubscribe(lcm, se);
    hal_destroy(h);
}
END_TEST

/* Real time: the servo thread samples every period and the publisher sends the newest per
 * publish period, so published sample numbers skip (decimation) and only grow. */
START_TEST(test_realtime_decimates)
{
    static struct got g;
    memset(&g, 0, sizeof g);
    struct hal *h = hal_create();
    cmd(h, "newthread servo-thread 1000000");
    cmd(h, "loadrt lcm-status url=memq:// rate=50");
    cmd(h, "addf lcm-status.sample servo-thread");
    lcm_t *lcm = lcm_status_lcm(h);
    hexcnc_status_t_subscription_t *ss =
        hexcnc_status_t_subscribe(lcm, LCM_STATUS_CHANNEL, on_status, &g);
    ck_assert_int_eq(hal_start(h), HAL_OK);
    struct timespec ts = { 0, 300000000 };
    nanosleep(&ts, NULL);
    ck_assert_int_eq(hal_stop(h), HAL_OK);
    ck_assert_int_eq(lcm_status_flush(h, 5000), LCM_STATUS_OK);
    while (lcm_handle_timeout(lcm, 50) > 0) {
    }
    struct lcm_status_stats st;
    lcm_status_get_stats(h, &st);
    ck_assert_int_ge(g.n_status, 2);
    ck_assert_uint_lt((uint64_t)g.n_status, st.samples);      /* fewer sent than taken */
    for (int i = 1; i < g.n_status; i++) {
        ck_assert_int_gt(g.status[i].seq, g.status[i - 1].seq);
        ck_assert_int_ge(g.status[i].utime, g.status[i - 1].utime);
    }
    hexcnc_status_t_unsubscribe(lcm, ss);
    hal_destroy(h);
}
END_TEST

/* Real time at a rate far below the servo rate: 500 samples per publish period go through a
 * ring of 256 without loss, because the publisher empties it at every look (at most 10 ms
 * apart), not once per publish period. */
START_TEST(test_realtime_slow_rate)
{
    struct hal *h = hal_create();
    cmd(h, "newthread servo-thread 1000000");
    cmd(h, "loadrt lcm-status url=memq:// rate=2 ring=256");
    cmd(h, "addf lcm-status.sample servo-thread");
    ck_assert_int_eq(hal_start(h), HAL_OK);
    struct timespec ts = { 0, 700000000 };
    nanosleep(&ts, NULL);
    ck_assert_int_eq(hal_stop(h), HAL_OK);
    ck_assert_int_eq(lcm_status_flush(h, 5000), LCM_STATUS_OK);
    struct lcm_status_stats st;
    lcm_status_get_stats(h, &st);
    ck_assert_uint_gt(st.samples, 256);
    ck_assert_uint_eq(st.samples_dropped, 0);
    ck_assert_uint_ge(st.status_sent, 1);
    ck_assert_uint_le(st.status_sent, 3);
    hal_destroy(h);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("lcm_status");
    TCase *tc = tcase_create("lcm_status");
    tcase_add_test(tc, test_memq_stream);
    tcase_add_test(tc, test_long_event_and_final_sample);
    tcase_add_test(tc, test_file_log);
    tcase_add_test(tc, test_rate_from_ini);
    tcase_add_test(tc, test_disabled);
    tcase_add_test(tc, test_bad_args);
    tcase_add_test(tc, test_full_ring_drops);
    tcase_add_test(tc, test_realtime_decimates);
    tcase_add_test(tc, test_realtime_slow_rate);
    suite_add_tcase(s, tc);
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? 1 : 0;
}
