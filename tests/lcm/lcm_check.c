/* lcm_check.c: checks what tests/lcm/publish.hal published: from an LCM log (lcm_eventlog_*)
 * or live on an LCM URL. Used by tests/lcm/udpm.sh; prints one line, exit 0 when it is right.
 *
 *   lcm_check LOG COUNT                 the log holds exactly COUNT status messages, right
 *   lcm_check --listen URL COUNT MS     COUNT status messages arrive within MS ms
 *   lcm_check --run LOG PERIOD_MS       a log of `hexcnc run` on the simulated machine
 */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <lcm/eventlog.h>
#include <lcm/lcm.h>

#include "lcmtypes/hexcnc_event_t.h"
#include "lcmtypes/hexcnc_status_t.h"

/* What was seen, and the first thing found wrong. */
struct check {
    int status, events, estop_events;
    int64_t last_seq;
    int64_t last_grid_ns;           /* machine time of the last on-grid sample */
    int stop_state;                 /* state of the stop sample; -1 none yet */
    int running;                    /* the start sample was seen */
    char error[200];
};

/* One status message of publish.hal at 20 Hz (tests/lcm/udpm.ini): seq n at 1 ms, then every
 * 50 ms; the counter in pose-cmd-x equals the machine time in ms. */
static void check_status(struct check *c, const hexcnc_status_t *m)
{
    int64_t t_ms = m->machine_time_ns / 1000000;
    int64_t want_ms = m->seq == 0 ? 1 : 50 * m->seq;
    if (c->error[0])
        return;
    if (m->seq != c->last_seq + 1)
        snprintf(c->error, sizeof c->error, "sample %lld follows %lld", (long long)m->seq,
                 (long long)c->last_seq);
    else if (t_ms != want_ms || m->pose_cmd[0] != (double)t_ms || m->leg_cmd_mm[0] != (double)t_ms)
        snprintf(c->error, sizeof c->error, "sample %lld: time %lld ms, pose-cmd-x %g (want %lld)",
                 (long long)m->seq, (long long)t_ms, m->pose_cmd[0], (long long)want_ms);
    else if (m->line != 7 || m->pose_fb[2] != 630.5 || m->utime != t_ms * 1000)
        snprintf(c->error, sizeof c->error, "sample %lld: line %d, pose-fb-z %g, utime %lld",
                 (long long)m->seq, (int)m->line, m->pose_fb[2], (long long)m->utime);
    else if ((t_ms >= 5) != (m->fault_flags == 4) || (t_ms >= 5) != !strcmp(m->fault_text, "estop"))
        snprintf(c->error, sizeof c->error, "sample %lld: fault flags %d '%s'", (long long)m->seq,
                 (int)m->fault_flags, m->fault_text);
    c->last_seq = m->seq;
    c->status++;
}

/* The e-stop input rose at 5 ms: one FAULT event from source "estop". */
static void check_event(struct check *c, const hexcnc_event_t *m)
{
    c->events++;
    if (!strcmp(m->source, "estop") && m->severity == HEXCNC_EVENT_T_FAULT && m->code == 1 &&
        m->utime == 5000 && m->line == 7)
        c->estop_events++;
}

static void on_status(const lcm_recv_buf_t *rb, const char *ch, const hexcnc_status_t *m, void *u)
{
    check_status(u, m);
}

static void on_event(const lcm_recv_buf_t *rb, const char *ch, const hexcnc_event_t *m, void *u)
{
    check_event(u, m);
}

/* Reads and decodes every message of the log. */
static int read_log(const char *path, struct check *c)
{
    lcm_eventlog_t *log = lcm_eventlog_create(path, "r");
    if (!log) {
        snprintf(c->error, sizeof c->error, "cannot read the LCM log %s", path);
        return -1;
    }
    lcm_eventlog_event_t *ev;
    while ((ev = lcm_eventlog_read_next_event(log))) {
        if (!strcmp(ev->channel, "HEXCNC_STATUS")) {
            hexcnc_status_t m;
            if (hexcnc_status_t_decode(ev->data, 0, (int)ev->datalen, &m) < 0) {
                snprintf(c->error, sizeof c->error, "a HEXCNC_STATUS message does not decode");
            } else {
                check_status(c, &m);
                hexcnc_status_t_decode_cleanup(&m);
            }
        } else if (!strcmp(ev->channel, "HEXCNC_EVENT")) {
            hexcnc_event_t m;
            if (hexcnc_event_t_decode(ev->data, 0, (int)ev->datalen, &m) >= 0) {
                check_event(c, &m);
                hexcnc_event_t_decode_cleanup(&m);
            }
        }
        lcm_eventlog_free_event(ev);
    }
    lcm_eventlog_destroy(log);
    return 0;
}

/* Subscribes on url and handles messages until count status messages or ms ms. */
static int listen_url(const char *url, int count, int ms, struct check *c)
{
    lcm_t *lcm = lcm_create(url);
    if (!lcm) {
        snprintf(c->error, sizeof c->error, "cannot open %s", url);
        return -1;
    }
    hexcnc_status_t_subscription_t *ss =
        hexcnc_status_t_subscribe(lcm, "HEXCNC_STATUS", on_status, c);
    hexcnc_event_t_subscription_t *se = hexcnc_event_t_subscribe(lcm, "HEXCNC_EVENT", on_event, c);
    printf("lcm_check: listening on %s\n", url);
    fflush(stdout);
    struct timespec t0, t;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (;;) {
        clock_gettime(CLOCK_MONOTONIC, &t);
        long left = ms - ((t.tv_sec - t0.tv_sec) * 1000 + (t.tv_nsec - t0.tv_nsec) / 1000000);
        if (left <= 0 || (c->status >= count && c->estop_events >= 1))
            break;
        lcm_handle_timeout(lcm, (int)(left < 100 ? left : 100));
    }
    hexcnc_status_t_unsubscribe(lcm, ss);
    hexcnc_event_t_unsubscribe(lcm, se);
    lcm_destroy(lcm);
    return 0;
}

/* A program run on the simulated machine, as `hexcnc run` makes it: first the machine at
 * rest while it is switched on (the threads run a few periods before the program starts, so
 * that it is planned from where the legs are): samples not running, on line 0, and the
 * e-stop's fault raised and cleared as the machine comes out of e-stop, nothing else. Then
 * the run: a start sample (the state change), samples every PERIOD_MS of machine time,
 * numbered without gaps, running (state 1) on a program line, feedback within 0.01 mm (and
 * deg) of the command, which moves; and last the stop: one sample off the grid in state
 * done (5, MOTION_DONE), at the end of the program's time. Returns the number of status
 * messages, or -1. */
static int check_run(const char *path, int period_ms, struct check *c)
{
    lcm_eventlog_t *log = lcm_eventlog_create(path, "r");
    if (!log) {
        snprintf(c->error, sizeof c->error, "cannot read the LCM log %s", path);
        return -1;
    }
    lcm_eventlog_event_t *ev;
    double first_x = NAN, moved = 0;
    while ((ev = lcm_eventlog_read_next_event(log)) && !c->error[0]) {
        hexcnc_status_t m;
        hexcnc_event_t e;
        if (!strcmp(ev->channel, "HEXCNC_EVENT") &&
            hexcnc_event_t_decode(ev->data, 0, (int)ev->datalen, &e) >= 0) {
            /* the runner's own events: started (100) before any other, finished (101) */
            if (!strcmp(e.source, "task") && e.code == 100 && c->events == 0)
                c->events = 1;
            else if (!strcmp(e.source, "task") && e.code == 101 && c->events == 1)
                c->events = 2;
            else if (e.severity == HEXCNC_EVENT_T_FAULT &&
                     !(c->events == 0 && !strcmp(e.source, "estop") && e.line == 0))
                snprintf(c->error, sizeof c->error, "fault event from %s: %s", e.source,
                         e.text);
            hexcnc_event_t_decode_cleanup(&e);
        }
        if (!strcmp(ev->channel, "HEXCNC_STATUS") &&
            hexcnc_status_t_decode(ev->data, 0, (int)ev->datalen, &m) >= 0) {
            int64_t grid_ns = (int64_t)period_ms * 1000000;
            bool on_grid = m.machine_time_ns == 1000000 || m.machine_time_ns % grid_ns == 0;
            double worst = 0;
            for (int i = 0; i < 6; i++) {
                worst = fmax(worst, fabs(m.pose_cmd[i] - m.pose_fb[i]));
                worst = fmax(worst, fabs(m.leg_cmd_mm[i] - m.leg_fb_mm[i]));
                worst = fmax(worst, fabs(m.ferror_mm[i]));
            }
            if (m.state == 1 && isnan(first_x))
                first_x = m.pose_cmd[0];
            if (m.state == 1)
                moved = fmax(moved, fabs(m.pose_cmd[0] - first_x));
            if (m.seq != c->last_seq + 1)
                snprintf(c->error, sizeof c->error, "sample %lld after %lld", (long long)m.seq,
                         (long long)c->last_seq);
            else if (c->stop_state >= 0)
                snprintf(c->error, sizeof c->error, "sample %lld after the stop sample",
                         (long long)m.seq);
            else if (!c->running && m.state != 1) {
                if (m.line != 0)  /* the prelude: at rest, before any line */
                    snprintf(c->error, sizeof c->error, "sample %lld before the start: "
                             "state %d line %d", (long long)m.seq, (int)m.state, (int)m.line);
            } else if (!c->running) {
                c->running = 1;  /* the start sample (a state change: on the grid or not) */
            } else if (m.state != 1) {
                if (on_grid)
                    snprintf(c->error, sizeof c->error, "sample %lld: the stop sample on the "
                             "grid (%lld ns)", (long long)m.seq, (long long)m.machine_time_ns);
                c->stop_state = m.state;
            } else if (!on_grid || m.machine_time_ns <= c->last_grid_ns) {
                snprintf(c->error, sizeof c->error, "sample %lld at %lld ns, off the %d ms grid",
                         (long long)m.seq, (long long)m.machine_time_ns, period_ms);
            } else {
                c->last_grid_ns = m.machine_time_ns;
            }
            if (!c->error[0] && c->running && c->stop_state < 0 &&
                (m.state != 1 || m.line <= 0 || worst > 0.01 || m.fault_flags))
                snprintf(c->error, sizeof c->error, "sample %lld: state %d line %d, feedback "
                         "%g from command, faults '%s'", (long long)m.seq, (int)m.state,
                         (int)m.line, worst, m.fault_text);
            c->last_seq = m.seq;
            c->status++;
            hexcnc_status_t_decode_cleanup(&m);
        }
        lcm_eventlog_free_event(ev);
    }
    lcm_eventlog_destroy(log);
    if (!c->error[0] && (c->status < 2 || moved < 1.0))
        snprintf(c->error, sizeof c->error, "%d status messages, X moved %g mm", c->status,
                 moved);
    if (!c->error[0] && c->stop_state != 5)
        snprintf(c->error, sizeof c->error, "no stop sample in state done (5) after the last "
                 "one on the grid (state %d)", c->stop_state);
    if (!c->error[0] && c->events != 2)
        snprintf(c->error, sizeof c->error, "the runner's 'program started' and 'program "
                 "finished' events are missing or out of order (%d of 2 seen)", c->events);
    return c->error[0] ? -1 : c->status;
}

int main(int argc, char **argv)
{
    if (argc == 4 && !strcmp(argv[1], "--run")) {
        struct check c = { .last_seq = -1, .stop_state = -1 };
        if (check_run(argv[2], atoi(argv[3]), &c) < 0) {
            printf("FAIL %s: %s\n", argv[2], c.error);
            return 1;
        }
        printf("ok   %s: %d status messages of a program run, on the machine-time grid, "
               "feedback following the command; started and finished events\n", argv[2],
               c.status);
        return 0;
    }
    struct check c = { .last_seq = -1 };
    int count, st;
    const char *what;
    if (argc == 5 && !strcmp(argv[1], "--listen")) {
        count = atoi(argv[3]);
        what = argv[2];
        st = listen_url(argv[2], count, atoi(argv[4]), &c);
    } else if (argc == 3) {
        count = atoi(argv[2]);
        what = argv[1];
        st = read_log(argv[1], &c);
    } else {
        fprintf(stderr, "usage: lcm_check LOG COUNT | lcm_check --listen URL COUNT MS | "
                "lcm_check --run LOG PERIOD_MS\n");
        return 2;
    }
    if (st == 0 && !c.error[0] && c.status != count)
        snprintf(c.error, sizeof c.error, "%d status messages, want %d", c.status, count);
    if (st == 0 && !c.error[0] && c.estop_events != 1)
        snprintf(c.error, sizeof c.error, "%d e-stop fault events (of %d), want 1",
                 c.estop_events, c.events);
    if (c.error[0]) {
        printf("FAIL %s: %s\n", what, c.error);
        return 1;
    }
    printf("ok   %s: %d status messages in order with the right values, %d event(s)\n", what,
           c.status, c.events);
    return 0;
}
