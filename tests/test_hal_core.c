/* test_hal_core.c: pins, signals, parameters, functs, threads and the simulated clock through
 * the C API of hal/hal.h. */
#include <check.h>
#include <stdlib.h>
#include <string.h>

#include "hal/hal.h"

/* A test component instance: pins of every type and direction plus a call log. */
struct tcomp {
    double *fout, *fin1, *fin2, *fio1, *fio2;
    bool *bout;
    int32_t *s32in;
    uint32_t *u32in;
    double gain;
    int32_t ro_count;
};

/* hal_net with the pins given as one blank-separated string. */
static int net(struct hal *h, const char *signal, const char *pins)
{
    char buf[256], *words[8], *save = NULL;
    int n = 0;
    snprintf(buf, sizeof buf, "%s", pins);
    for (char *w = strtok_r(buf, " ", &save); w && n < 8; w = strtok_r(NULL, " ", &save))
        words[n++] = w;
    return hal_net(h, signal, n, words);
}

static struct hal *new_hal(void)
{
    struct hal *h = hal_create();
    ck_assert_ptr_nonnull(h);
    return h;
}

static void make_pins(struct hal *h, struct tcomp *c)
{
    ck_assert_int_eq(hal_pin_float_newf(h, HAL_OUT, &c->fout, "t.%d.out", 0), HAL_OK);
    ck_assert_int_eq(hal_pin_float_newf(h, HAL_IN, &c->fin1, "t.0.in1"), HAL_OK);
    ck_assert_int_eq(hal_pin_float_newf(h, HAL_IN, &c->fin2, "t.0.in2"), HAL_OK);
    ck_assert_int_eq(hal_pin_float_newf(h, HAL_IO, &c->fio1, "t.0.io1"), HAL_OK);
    ck_assert_int_eq(hal_pin_float_newf(h, HAL_IO, &c->fio2, "t.0.io2"), HAL_OK);
    ck_assert_int_eq(hal_pin_bit_newf(h, HAL_OUT, &c->bout, "t.0.bout"), HAL_OK);
    ck_assert_int_eq(hal_pin_s32_newf(h, HAL_IN, &c->s32in, "t.0.s32in"), HAL_OK);
    ck_assert_int_eq(hal_pin_u32_newf(h, HAL_IN, &c->u32in, "t.0.u32in"), HAL_OK);
    ck_assert_int_eq(hal_param_float_newf(h, HAL_RW, &c->gain, "t.0.gain"), HAL_OK);
    ck_assert_int_eq(hal_param_s32_newf(h, HAL_RO, &c->ro_count, "t.0.count"), HAL_OK);
}

START_TEST(pins_start_on_own_storage_and_duplicates_fail)
{
    struct hal *h = new_hal();
    struct tcomp c;
    make_pins(h, &c);
    *c.fin1 = 2.5;
    char buf[64];
    ck_assert_int_eq(hal_getp(h, "t.0.in1", buf, sizeof buf), HAL_OK);
    ck_assert_str_eq(buf, "2.5");
    double *dup;
    ck_assert_int_eq(hal_pin_float_newf(h, HAL_IN, &dup, "t.0.in1"), HAL_ERR_EXISTS);
    ck_assert_str_eq(hal_last_error(h), "pin 't.0.in1' already exists");
    ck_assert_int_eq(hal_param_float_newf(h, HAL_RW, &c.gain, "t.0.in1"), HAL_ERR_EXISTS);
    hal_destroy(h);
}
END_TEST

START_TEST(one_writer_many_readers)
{
    struct hal *h = new_hal();
    struct tcomp c;
    make_pins(h, &c);
    ck_assert_int_eq(net(h, "x", "t.0.in1 t.0.out t.0.in2"), HAL_OK);
    ck_assert_ptr_eq(c.fin1, c.fout);          /* every linked pin points at the signal */
    ck_assert_ptr_eq(c.fin2, c.fout);
    *c.fout = 7.25;
    ck_assert(*c.fin1 == 7.25 && *c.fin2 == 7.25);
    char buf[64];
    ck_assert_int_eq(hal_gets(h, "x", buf, sizeof buf), HAL_OK);
    ck_assert_str_eq(buf, "7.25");
    ck_assert_int_eq(hal_sets(h, "x", "1"), HAL_ERR_DIR);
    ck_assert_str_eq(hal_last_error(h), "sets: signal 'x' is written by pin 't.0.out'");
    hal_destroy(h);
}
END_TEST

START_TEST(second_writer_and_type_mismatch_are_refused)
{
    struct hal *h = new_hal();
    struct tcomp c, d;
    make_pins(h, &c);
    ck_assert_int_eq(hal_pin_float_newf(h, HAL_OUT, &d.fout, "u.0.out"), HAL_OK);
    ck_assert_int_eq(net(h, "x", "t.0.out t.0.in1 t.0.out"), HAL_OK);   /* named twice */
    ck_assert_int_eq(net(h, "x", "u.0.out"), HAL_ERR_DIR);
    ck_assert_str_eq(hal_last_error(h), "net: signal 'x' already has a writer 't.0.out'; "
                     "'u.0.out' cannot also write it");
    ck_assert_int_eq(net(h, "x", "t.0.bout"), HAL_ERR_TYPE);
    ck_assert_str_eq(hal_last_error(h), "net: signal 'x' is float but pin 't.0.bout' is bit");
    ck_assert_int_eq(net(h, "y", "t.0.in2 stepgen.9.position-cmd"), HAL_ERR_NOT_FOUND);
    ck_assert_str_eq(hal_last_error(h), "net: pin 'stepgen.9.position-cmd' does not exist");
    /* all or nothing: the first pin was not linked to y */
    *c.fin2 = 3.0;
    ck_assert(*c.fout != 3.0);
    ck_assert_ptr_null(hal_data_ptr(h, "y", NULL));
    ck_assert_int_eq(net(h, "z", "t.0.in1"), HAL_ERR_EXISTS);
    ck_assert_str_eq(hal_last_error(h), "net: pin 't.0.in1' is already connected to signal 'x'");
    hal_destroy(h);
}
END_TEST

START_TEST(io_pins_share_a_signal_without_writer)
{
    struct hal *h = new_hal();
    struct tcomp c;
    make_pins(h, &c);
    *c.fio1 = 4.0;
    ck_assert_int_eq(net(h, "bus", "t.0.io1 t.0.io2 t.0.in1"), HAL_OK);
    ck_assert(*c.fio2 == 4.0 && *c.fin1 == 4.0);   /* the first pin gave the signal its value */
    *c.fio2 = 5.0;
    ck_assert(*c.fio1 == 5.0);
    ck_assert_int_eq(hal_sets(h, "bus", "6"), HAL_OK);
    ck_assert(*c.fio1 == 6.0);
    ck_assert_int_eq(net(h, "bus", "t.0.out"), HAL_ERR_DIR);
    ck_assert_str_eq(hal_last_error(h), "net: signal 'bus' has I/O pins; output pin "
                     "'t.0.out' cannot also write it");
    hal_destroy(h);
}
END_TEST

START_TEST(unlink_keeps_the_last_value)
{
    struct hal *h = new_hal();
    struct tcomp c;
    make_pins(h, &c);
    ck_assert_int_eq(net(h, "x", "t.0.out t.0.in1"), HAL_OK);
    *c.fout = 9.5;
    ck_assert_int_eq(hal_unlinkp(h, "t.0.in1"), HAL_OK);
    ck_assert_ptr_ne(c.fin1, c.fout);
    ck_assert(*c.fin1 == 9.5);
    *c.fout = 1.0;
    ck_assert(*c.fin1 == 9.5);
    ck_assert_int_eq(hal_setp(h, "t.0.in1", "2"), HAL_OK);  /* settable again */
    ck_assert(*c.fin1 == 2.0);
    ck_assert_int_eq(net(h, "x", "t.0.in1"), HAL_OK);
    ck_assert(*c.fin1 == 1.0);
    hal_destroy(h);
}
END_TEST

START_TEST(setp_rules_and_values)
{
    struct hal *h = new_hal();
    struct tcomp c;
    make_pins(h, &c);
    ck_assert_int_eq(hal_setp(h, "t.0.out", "1"), HAL_ERR_DIR);
    ck_assert_str_eq(hal_last_error(h), "setp: pin 't.0.out' is an output; its component "
                     "writes it");
    ck_assert_int_eq(hal_setp(h, "t.0.s32in", "-12"), HAL_OK);
    ck_assert_int_eq(*c.s32in, -12);
    ck_assert_int_eq(hal_setp(h, "t.0.s32in", "3000000000"), HAL_ERR_SYNTAX);
    ck_assert_int_eq(hal_setp(h, "t.0.u32in", "0x10"), HAL_OK);
    ck_assert_uint_eq(*c.u32in, 16);
    ck_assert_int_eq(hal_setp(h, "t.0.u32in", "-1"), HAL_ERR_SYNTAX);
    ck_assert_int_eq(hal_setp(h, "t.0.in1", "1.5x"), HAL_ERR_SYNTAX);
    ck_assert_str_eq(hal_last_error(h), "setp: '1.5x' is not a valid float number for "
                     "'t.0.in1'");
    ck_assert_int_eq(hal_setp(h, "t.0.gain", "0.25"), HAL_OK);
    ck_assert(c.gain == 0.25);
    /* floats follow the configuration's number rules: no NaN, infinity or hexadecimal */
    ck_assert_int_eq(hal_setp(h, "t.0.gain", "nan"), HAL_ERR_SYNTAX);
    ck_assert_int_eq(hal_setp(h, "t.0.gain", "inf"), HAL_ERR_SYNTAX);
    ck_assert_int_eq(hal_setp(h, "t.0.gain", "0x10"), HAL_ERR_SYNTAX);
    ck_assert(c.gain == 0.25);
    ck_assert_int_eq(hal_setp(h, "t.0.count", "3"), HAL_ERR_DIR);
    ck_assert_str_eq(hal_last_error(h), "setp: parameter 't.0.count' is read-only");
    ck_assert_int_eq(hal_setp(h, "t.0.nope", "3"), HAL_ERR_NOT_FOUND);
    ck_assert_int_eq(net(h, "x", "t.0.in1"), HAL_OK);
    ck_assert_int_eq(hal_setp(h, "t.0.in1", "1"), HAL_ERR_DIR);
    ck_assert_str_eq(hal_last_error(h), "setp: pin 't.0.in1' is connected to signal 'x'; "
                     "set the signal with sets");
    enum hal_type type;
    ck_assert_ptr_eq(hal_data_ptr(h, "t.0.gain", &type), &c.gain);
    ck_assert_int_eq(type, HAL_FLOAT);
    hal_destroy(h);
}
END_TEST

/* A funct that appends its tag to a shared log. */
struct logger {
    char *log;
    char tag;
    long last_period_ns;
};

static void log_fn(void *arg, long period_ns)
{
    struct logger *l = arg;
    size_t n = strlen(l->log);
    l->log[n] = l->tag;
    l->log[n + 1] = '\0';
    l->last_period_ns = period_ns;
}

START_TEST(addf_order_and_positions)
{
    struct hal *h = new_hal();
    char log[64] = "";
    struct logger l[5];
    for (int i = 0; i < 5; i++) {
        l[i] = (struct logger){ log, (char)('a' + i), 0 };
        ck_assert_int_eq(hal_export_functf(h, log_fn, &l[i], "f.%c", 'a' + i), HAL_OK);
    }
    ck_assert_int_eq(hal_thread_new(h, "th", 1000), HAL_OK);
    ck_assert_int_eq(hal_addf(h, "f.a", "th", 0), HAL_OK);   /* a */
    ck_assert_int_eq(hal_addf(h, "f.b", "th", 1), HAL_OK);   /* b a */
    ck_assert_int_eq(hal_addf(h, "f.c", "th", -1), HAL_OK);  /* b a c */
    ck_assert_int_eq(hal_addf(h, "f.d", "th", -2), HAL_OK);  /* b a d c */
    ck_assert_int_eq(hal_addf(h, "f.e", "th", 2), HAL_OK);   /* b e a d c */
    ck_assert_int_eq(hal_addf(h, "f.e", "th", 0), HAL_ERR_EXISTS);
    ck_assert_str_eq(hal_last_error(h), "addf: function 'f.e' is already on thread 'th'");
    ck_assert_int_eq(hal_delf(h, "f.a", "th"), HAL_OK);       /* b e d c */
    ck_assert_int_eq(hal_addf(h, "f.a", "th", 7), HAL_ERR_ARG);
    ck_assert_int_eq(hal_addf(h, "f.x", "th", 0), HAL_ERR_NOT_FOUND);
    ck_assert_int_eq(hal_addf(h, "f.a", "nothread", 0), HAL_ERR_NOT_FOUND);
    hal_set_sim_clock(h, true);
    ck_assert_int_eq(hal_start(h), HAL_OK);
    ck_assert_int_eq(hal_sim_advance(h, 2000), HAL_OK);
    ck_assert_str_eq(log, "bedcbedc");
    ck_assert_int_eq(l[1].last_period_ns, 1000);
    hal_destroy(h);
}
END_TEST

START_TEST(two_threads_run_in_deadline_order)
{
    struct hal *h = new_hal();
    char log[64] = "";
    struct logger slow = { log, 'S', 0 }, fast = { log, 'f', 0 };
    ck_assert_int_eq(hal_thread_new(h, "servo", 1000000), HAL_OK);
    ck_assert_int_eq(hal_thread_new(h, "base", 250000), HAL_OK);
    ck_assert_int_eq(hal_export_functf(h, log_fn, &slow, "slow"), HAL_OK);
    ck_assert_int_eq(hal_export_functf(h, log_fn, &fast, "fast"), HAL_OK);
    ck_assert_int_eq(hal_addf(h, "slow", "servo", 0), HAL_OK);
    ck_assert_int_eq(hal_addf(h, "fast", "base", 0), HAL_OK);
    ck_assert_int_eq(hal_sim_advance(h, 1), HAL_ERR_STATE);     /* clock off */
    hal_set_sim_clock(h, true);
    ck_assert_int_eq(hal_sim_advance(h, 1), HAL_ERR_STATE);     /* not started */
    ck_assert_int_eq(hal_start(h), HAL_OK);
    ck_assert_int_eq(hal_now_ns(h), 0);
    ck_assert_int_eq(hal_sim_advance(h, 2000000), HAL_OK);
    /* base at 0.25 0.5 0.75 1.0, servo at 1.0 runs first on the tie (created first) */
    ck_assert_str_eq(log, "fffSffffSf");
    ck_assert_int_eq(hal_now_ns(h), 2000000);
    ck_assert_int_eq(hal_sim_advance(h, 100000), HAL_OK);        /* nothing due */
    ck_assert_str_eq(log, "fffSffffSf");
    ck_assert_int_eq(hal_sim_advance(h, 150000), HAL_OK);        /* 2.25 ms: base */
    ck_assert_str_eq(log, "fffSffffSff");
    ck_assert_int_eq(slow.last_period_ns, 1000000);
    ck_assert_int_eq(fast.last_period_ns, 250000);
    ck_assert_int_eq(hal_thread_new(h, "late", 1000), HAL_ERR_STATE);
    ck_assert_int_eq(hal_stop(h), HAL_OK);
    ck_assert(!hal_running(h));
    hal_destroy(h);
}
END_TEST

/* A little stateful graph: an integrator fed by a counter, sampled each period. */
struct integ {
    double *in, *out;
    double state;
    int n;
};

static void integ_fn(void *arg, long period_ns)
{
    struct integ *g = arg;
    g->state += *g->in * (double)period_ns * 1e-9 + 1.0 / (double)(++g->n);
    *g->out = g->state;
}

static void counter_fn(void *arg, long period_ns)
{
    struct integ *g = arg;
    *g->out = (double)(++g->n) * 0.1;
}

/* Builds the graph, runs 50 ms of two threads, returns the sampled outputs. */
static void run_graph(double *samples, int n)
{
    struct hal *h = new_hal();
    struct integ cnt = { 0 }, in = { 0 };
    ck_assert_int_eq(hal_pin_float_newf(h, HAL_OUT, &cnt.out, "cnt.out"), HAL_OK);
    ck_assert_int_eq(hal_pin_float_newf(h, HAL_IN, &in.in, "int.in"), HAL_OK);
    ck_assert_int_eq(hal_pin_float_newf(h, HAL_OUT, &in.out, "int.out"), HAL_OK);
    ck_assert_int_eq(hal_export_functf(h, counter_fn, &cnt, "cnt"), HAL_OK);
    ck_assert_int_eq(hal_export_functf(h, integ_fn, &in, "int"), HAL_OK);
    ck_assert_int_eq(net(h, "c", "cnt.out int.in"), HAL_OK);
    ck_assert_int_eq(hal_thread_new(h, "slow", 1000000), HAL_OK);
    ck_assert_int_eq(hal_thread_new(h, "fast", 300000), HAL_OK);
    ck_assert_int_eq(hal_addf(h, "int", "slow", 0), HAL_OK);
    ck_assert_int_eq(hal_addf(h, "cnt", "fast", 0), HAL_OK);
    hal_set_sim_clock(h, true);
    ck_assert_int_eq(hal_start(h), HAL_OK);
    for (int i = 0; i < n; i++) {
        ck_assert_int_eq(hal_sim_advance(h, 1000000), HAL_OK);
        samples[i] = *(double *)hal_data_ptr(h, "int.out", NULL);
    }
    hal_destroy(h);
}

START_TEST(same_graph_twice_same_samples)
{
    double a[50], b[50];
    run_graph(a, 50);
    run_graph(b, 50);
    ck_assert_mem_eq(a, b, sizeof a);
    ck_assert(a[49] > a[0]);
}
END_TEST

/* A component type whose load registers things and then fails (or not). */
struct fail_ctx {
    int cleanups;
    bool fail;
};

static void count_cleanup(void *arg)
{
    ((struct fail_ctx *)arg)->cleanups++;
}

static void nop_fn(void *arg, long period_ns)
{
}

static int failing_load(struct hal *h, int argc, char **argv)
{
    static double *p, *q;
    static double param;
    struct fail_ctx *ctx = hal_get_object(h, "ctx");
    if (hal_on_destroy(h, count_cleanup, ctx) != HAL_OK ||
        hal_pin_float_newf(h, HAL_OUT, &p, "fl.out") != HAL_OK ||
        hal_pin_float_newf(h, HAL_IN, &q, "fl.in") != HAL_OK ||
        hal_param_float_newf(h, HAL_RW, &param, "fl.param") != HAL_OK ||
        hal_export_functf(h, nop_fn, NULL, "fl.run") != HAL_OK)
        return HAL_ERR_COMPONENT;
    if (ctx->fail)
        return hal_error(h, HAL_ERR_COMPONENT, "fl: failing on purpose");
    return HAL_OK;
}

static const struct hal_comp_type failing_type = { "fl", failing_load };

START_TEST(failed_load_unwinds_everything)
{
    struct hal *h = new_hal();
    struct fail_ctx ctx = { 0, true };
    ck_assert_int_eq(hal_set_object(h, "ctx", &ctx), HAL_OK);
    ck_assert_int_eq(hal_set_object(h, "ctx", &ctx), HAL_ERR_EXISTS);
    ck_assert_int_eq(hal_register_type(h, &failing_type), HAL_OK);
    ck_assert_int_eq(hal_register_type(h, &failing_type), HAL_ERR_EXISTS);
    double *other;
    ck_assert_int_eq(hal_pin_float_newf(h, HAL_IN, &other, "other.in"), HAL_OK);
    ck_assert_int_eq(net(h, "s", "other.in"), HAL_OK);
    ck_assert_int_eq(hal_loadrt(h, "fl", 0, NULL), HAL_ERR_COMPONENT);
    ck_assert_str_eq(hal_last_error(h), "fl: failing on purpose");
    ck_assert_int_eq(ctx.cleanups, 1);                 /* its cleanup ran at once */
    ck_assert_ptr_null(hal_data_ptr(h, "fl.out", NULL));
    ck_assert_ptr_null(hal_data_ptr(h, "fl.param", NULL));
    ck_assert_ptr_nonnull(hal_data_ptr(h, "other.in", NULL));
    ck_assert_ptr_nonnull(hal_get_object(h, "ctx"));   /* not its object */
    ctx.fail = false;                                  /* the names are free again */
    ck_assert_int_eq(hal_loadrt(h, "fl", 0, NULL), HAL_OK);
    ck_assert_int_eq(net(h, "s", "fl.out"), HAL_OK);
    ck_assert_int_eq(hal_thread_new(h, "th", 1000), HAL_OK);
    ck_assert_int_eq(hal_addf(h, "fl.run", "th", 0), HAL_OK);
    hal_destroy(h);
    ck_assert_int_eq(ctx.cleanups, 2);
}
END_TEST

/* Cleanups run newest first at hal_destroy. */
struct order_log {
    char s[8];
};
static void order_a(void *arg) { strcat(((struct order_log *)arg)->s, "a"); }
static void order_b(void *arg) { strcat(((struct order_log *)arg)->s, "b"); }

START_TEST(cleanups_run_in_reverse)
{
    struct order_log log = { "" };
    struct hal *h = new_hal();
    ck_assert_int_eq(hal_on_destroy(h, order_a, &log), HAL_OK);
    ck_assert_int_eq(hal_on_destroy(h, order_b, &log), HAL_OK);
    hal_destroy(h);
    ck_assert_str_eq(log.s, "ba");
    ck_assert_str_eq(hal_strerror(HAL_ERR_TYPE), "type mismatch");
    ck_assert_str_eq(hal_strerror(-3), "unknown HAL status");
}
END_TEST

START_TEST(thread_pins_and_bad_period)
{
    struct hal *h = new_hal();
    ck_assert_int_eq(hal_thread_new(h, "servo-thread", 0), HAL_ERR_ARG);
    ck_assert_int_eq(hal_thread_new(h, "servo-thread", 1000000), HAL_OK);
    ck_assert_int_eq(hal_thread_new(h, "servo-thread", 1000000), HAL_ERR_EXISTS);
    enum hal_type type;
    ck_assert_ptr_nonnull(hal_data_ptr(h, "servo-thread.time", &type));
    ck_assert_int_eq(type, HAL_S32);
    ck_assert_ptr_nonnull(hal_data_ptr(h, "servo-thread.tmax", &type));
    ck_assert_ptr_nonnull(hal_data_ptr(h, "servo-thread.overruns", &type));
    ck_assert_int_eq(type, HAL_U32);
    hal_destroy(h);
}
END_TEST

/* Messages from components reach the shell in order, with source and text; a burst beyond
 * the queue is dropped and counted, never blocking the poster. */
START_TEST(messages_in_order_and_overflow_counted)
{
    struct hal *h = hal_create();
    ck_assert_ptr_nonnull(h);
    struct hal_msg m;
    ck_assert(!hal_msg_take(h, &m));
    ck_assert_int_eq(hal_msg_post(h, HAL_MSG_FAULT, "drive.3", "no answer within %d ms", 20),
                     HAL_OK);
    ck_assert_int_eq(hal_msg_post(h, HAL_MSG_INFO, "drive.3", "fault cleared"), HAL_OK);
    ck_assert(hal_msg_take(h, &m));
    ck_assert_int_eq(m.severity, HAL_MSG_FAULT);
    ck_assert_str_eq(m.source, "drive.3");
    ck_assert_str_eq(m.text, "no answer within 20 ms");
    ck_assert_str_eq(hal_msg_severity_name(m.severity), "fault");
    ck_assert(hal_msg_take(h, &m));
    ck_assert_str_eq(m.text, "fault cleared");
    ck_assert(!hal_msg_take(h, &m));
    int posted = 0;
    for (int i = 0; i < 200; i++)
        posted += hal_msg_post(h, HAL_MSG_WARNING, "burst", "message %d", i) == HAL_OK;
    ck_assert_int_lt(posted, 200);
    ck_assert_int_eq((int)hal_msg_dropped(h), 200 - posted);
    for (int i = 0; i < posted; i++) {  /* the ones kept are the first ones, in order */
        char want[32];
        snprintf(want, sizeof want, "message %d", i);
        ck_assert(hal_msg_take(h, &m));
        ck_assert_str_eq(m.text, want);
    }
    ck_assert(!hal_msg_take(h, &m));
    hal_destroy(h);
}
END_TEST

static Suite *hal_core_suite(void)
{
    Suite *s = suite_create("hal_core");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, pins_start_on_own_storage_and_duplicates_fail);
    tcase_add_test(tc, one_writer_many_readers);
    tcase_add_test(tc, second_writer_and_type_mismatch_are_refused);
    tcase_add_test(tc, io_pins_share_a_signal_without_writer);
    tcase_add_test(tc, unlink_keeps_the_last_value);
    tcase_add_test(tc, setp_rules_and_values);
    tcase_add_test(tc, addf_order_and_positions);
    tcase_add_test(tc, two_threads_run_in_deadline_order);
    tcase_add_test(tc, same_graph_twice_same_samples);
    tcase_add_test(tc, failed_load_unwinds_everything);
    tcase_add_test(tc, cleanups_run_in_reverse);
    tcase_add_test(tc, thread_pins_and_bad_period);
    tcase_add_test(tc, messages_in_order_and_overflow_counted);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(hal_core_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
