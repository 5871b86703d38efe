/* bench_modbus.c: Modbus round trips for six simulated drives on loopback: serial write+read vs FC23 vs FC23 in parallel I/O threads. */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "hal/drivers/modbus_link.h"
#include "sim/modbus_sim.h"

#define NDRIVES 6
#define ROUNDS 10            /* the approaches take turns, so they see the same machine load */
#define PER_ROUND 200        /* cycles of one approach in one round */
#define CYCLES (ROUNDS * PER_ROUND)
#define WARMUP 20            /* cycles not counted at the start of each turn */

/* Monotonic time, ns. */
static int64_t now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* Ascending order of doubles for qsort. */
static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Summary of one approach's samples, us. */
struct stats { double mean_us, p99_us, max_us; };

/* Mean, 99th percentile and maximum of n samples (us); sorts them. */
static struct stats stats_of(double *us, int n)
{
    struct stats s = { 0.0, 0.0, 0.0 };
    for (int i = 0; i < n; i++)
        s.mean_us += us[i];
    s.mean_us /= n;
    qsort(us, (size_t)n, sizeof(double), cmp_double);
    s.p99_us = us[(int)ceil(0.99 * n) - 1];
    s.max_us = us[n - 1];
    return s;
}

/* Six drives connected to the simulator with the given exchange. */
static int open_drives(struct modbus_drive *d, struct modbus_sim *s)
{
    for (int i = 0; i < NDRIVES; i++) {
        struct modbus_drive_cfg c;
        modbus_drive_cfg_default(&c, i);
        c.port = modbus_sim_port(s, i);
        c.timeout_us = 500000;
        if (modbus_drive_open(&d[i], &c) || modbus_drive_connect(&d[i])) {
            fprintf(stderr, "bench_modbus: %s\n", modbus_drive_message(&d[i]));
            return -1;
        }
    }
    return 0;
}

/* One drive's exchange for cycle k (a slowly moving target). */
static int exchange(struct modbus_drive *d, int k)
{
    int32_t act;
    uint16_t st;
    int rc = modbus_drive_exchange(d, 1000 * k, MODBUS_CTRL_ENABLE, &act, &st);
    if (rc)
        fprintf(stderr, "bench_modbus: %s\n", modbus_drive_message(d));
    return rc;
}

/* Serial: the calling thread exchanges with each drive in turn; one sample per cycle. */
static int run_serial(struct modbus_drive *d, enum modbus_exchange ex, double *cycle_us)
{
    for (int i = 0; i < NDRIVES; i++)
        d[i].cfg.exchange = ex;
    for (int k = 0; k < PER_ROUND + WARMUP; k++) {
        int64_t t0 = now_ns();
        for (int i = 0; i < NDRIVES; i++)
            if (exchange(&d[i], k))
                return -1;
        if (k >= WARMUP)
            cycle_us[k - WARMUP] = (now_ns() - t0) / 1000.0;
    }
    return 0;
}

/* Parallel: one I/O thread per drive, released together each cycle by a barrier. */
struct worker {
    struct modbus_drive *d;
    pthread_barrier_t *start, *done;
    int failed;
};

static void *worker_main(void *arg)
{
    struct worker *w = arg;
    for (int k = 0; k < PER_ROUND + WARMUP; k++) {
        pthread_barrier_wait(w->start);
        if (!w->failed && exchange(w->d, k))
            w->failed = 1;
        pthread_barrier_wait(w->done);
    }
    return NULL;
}

/* One sample per cycle: from release to the last drive's answer. */
static int run_parallel(struct modbus_drive *d, double *cycle_us)
{
    for (int i = 0; i < NDRIVES; i++)
        d[i].cfg.exchange = MODBUS_EXCHANGE_FC23;
    pthread_barrier_t start, done;
    pthread_barrier_init(&start, NULL, NDRIVES + 1);
    pthread_barrier_init(&done, NULL, NDRIVES + 1);
    struct worker w[NDRIVES];
    pthread_t t[NDRIVES];
    for (int i = 0; i < NDRIVES; i++) {
        w[i] = (struct worker){ &d[i], &start, &done, 0 };
        pthread_create(&t[i], NULL, worker_main, &w[i]);
    }
    for (int k = 0; k < PER_ROUND + WARMUP; k++) {
        int64_t t0 = now_ns();
        pthread_barrier_wait(&start);
        pthread_barrier_wait(&done);
        if (k >= WARMUP)
            cycle_us[k - WARMUP] = (now_ns() - t0) / 1000.0;
    }
    int failed = 0;
    for (int i = 0; i < NDRIVES; i++) {
        pthread_join(t[i], NULL);
        failed |= w[i].failed;
    }
    pthread_barrier_destroy(&start);
    pthread_barrier_destroy(&done);
    return failed ? -1 : 0;
}

/* The three approaches in turn, ROUNDS times, over one set of connections. */
static int run_rounds(struct modbus_sim *s, double *a, double *b, double *c)
{
    struct modbus_drive d[NDRIVES];
    memset(d, 0, sizeof(d));                /* closing a never-opened drive is then safe */
    int rc = open_drives(d, s);
    for (int r = 0; !rc && r < ROUNDS; r++) {
        int o = r * PER_ROUND;
        rc = run_serial(d, MODBUS_EXCHANGE_SEPARATE, a + o) ||
             run_serial(d, MODBUS_EXCHANGE_FC23, b + o) || run_parallel(d, c + o);
    }
    for (int i = 0; i < NDRIVES; i++)
        modbus_drive_close(&d[i]);
    return rc ? -1 : 0;
}

/* The servo thread's side with the mailbox: post six commands and read six feedbacks while
 * the drives' I/O threads exchange every 1 ms; one sample per simulated servo period. */
static int run_mailbox(struct modbus_sim *s, double *servo_us, uint32_t *exchanges)
{
    struct modbus_link *l = calloc(NDRIVES, sizeof(*l));
    if (!l)
        return -1;
    for (int i = 0; i < NDRIVES; i++) {
        struct modbus_drive_cfg c;
        modbus_drive_cfg_default(&c, i);
        c.port = modbus_sim_port(s, i);
        c.period_ns = 1000000;
        c.timeout_us = 500000;
        if (modbus_link_init(&l[i], &c) || modbus_link_start(&l[i])) {
            fprintf(stderr, "bench_modbus: %s\n", modbus_drive_message(&l[i].drive));
            for (int j = 0; j <= i; j++)
                modbus_link_fini(&l[j]);
            free(l);
            return -1;
        }
    }
    struct timespec nap = { 0, 1000000 };
    struct modbus_feedback fb;
    for (int k = 0; k < CYCLES / 2 + WARMUP; k++) {
        int64_t t0 = now_ns();
        for (int i = 0; i < NDRIVES; i++) {
            modbus_link_command(&l[i], 0.001 * k, true);
            modbus_link_feedback(&l[i], &fb);
        }
        if (k >= WARMUP)
            servo_us[k - WARMUP] = (now_ns() - t0) / 1000.0;
        nanosleep(&nap, NULL);
    }
    *exchanges = 0;
    int failed = 0;
    for (int i = 0; i < NDRIVES; i++) {
        modbus_link_feedback(&l[i], &fb);
        *exchanges += fb.exchanges;
        failed |= fb.fault;
        modbus_link_fini(&l[i]);
    }
    free(l);
    return failed ? -1 : 0;
}

static void print_row(const char *name, struct stats s, struct stats base)
{
    printf("  %-48s mean %8.1f  p99 %8.1f  max %8.1f us   mean ratio %.2fx\n", name, s.mean_us,
           s.p99_us, s.max_us, base.mean_us / s.mean_us);
}

int main(void)
{
    struct modbus_sim_opts o;
    modbus_sim_opts_default(&o);
    struct modbus_sim *s;
    if (modbus_sim_create(&s, NDRIVES, &o) || modbus_sim_start_tcp(s, "127.0.0.1", 0)) {
        fprintf(stderr, "bench_modbus: cannot start the simulated drives\n");
        return 1;
    }
    double *a = calloc(CYCLES, sizeof(double)), *b = calloc(CYCLES, sizeof(double));
    double *c = calloc(CYCLES, sizeof(double)), *m = calloc(CYCLES / 2, sizeof(double));
    uint32_t mailbox_exchanges = 0;
    if (!a || !b || !c || !m || run_rounds(s, a, b, c) || run_mailbox(s, m, &mailbox_exchanges)) {
        modbus_sim_destroy(s);
        free(a);
        free(b);
        free(c);
        free(m);
        return 1;
    }
    modbus_sim_destroy(s);
    struct stats sa = stats_of(a, CYCLES), sb = stats_of(b, CYCLES), sc = stats_of(c, CYCLES);
    struct stats sm = stats_of(m, CYCLES / 2);
    printf("Modbus TCP, %d simulated drives on 127.0.0.1, %d cycles each; time for all %d drives "
           "to exchange target+control / actual+status once (approaches interleaved in %d rounds):\n",
           NDRIVES, CYCLES, NDRIVES, ROUNDS);
    print_row("serial, FC16 write + FC3 read (baseline)", sa, sa);
    print_row("serial, one FC23 write-and-read per drive", sb, sa);
    print_row("parallel I/O threads, one FC23 per drive", sc, sa);
    printf("Servo-thread time per period for %d drives (%d periods, I/O threads exchanging every "
           "1 ms: %u good exchanges):\n", NDRIVES, CYCLES / 2, mailbox_exchanges);
    print_row("blocking serial FC16 + FC3 in the servo thread", sa, sa);
    print_row("mailbox: post commands, read feedback (chosen)", sm, sa);
    printf("  per-drive round trip (serial FC23 cycle / %d): mean %.1f us\n", NDRIVES,
           sb.mean_us / NDRIVES);
    free(a);
    free(b);
    free(c);
    free(m);
    return 0;
}
