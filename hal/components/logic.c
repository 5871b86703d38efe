/* logic.c: small generic components: sum2, and2, not, estop-latch (as in LinuxCNC). */
#include <stdlib.h>

#include "hal/hal.h"

#define LOGIC_MAX_INST 16

/* Creates the instances named by count=/names= with one instance-setup function. */
static int logic_load(struct hal *h, const char *comp, int argc, char **argv, size_t size,
                      int (*setup)(struct hal *h, void *inst, const char *name))
{
    char names[LOGIC_MAX_INST][HAL_INST_NAME_MAX];
    int n, st = hal_args_check(h, comp, argc, argv, "count,names");
    if (st == HAL_OK)
        st = hal_arg_instances(h, comp, argc, argv, LOGIC_MAX_INST, names, &n);
    for (int i = 0; st == HAL_OK && i < n; i++) {
        void *inst = calloc(1, size);
        if (!inst)
            return hal_error(h, HAL_ERR_NOMEM, "loadrt %s: out of memory", comp);
        if ((st = hal_on_destroy(h, free, inst)) != HAL_OK) {
            free(inst);
            return st;
        }
        st = setup(h, inst, names[i]);
    }
    return st;
}

/* sum2: out = in0 * gain0 + in1 * gain1 + offset. */
struct sum2 {
    double *in0, *in1;                     /* in */
    double *out;                           /* out */
    double gain0, gain1, offset;           /* params (RW) */
};

static void sum2_run(void *arg, long period_ns)
{
    struct sum2 *s = arg;
    *s->out = *s->in0 * s->gain0 + *s->in1 * s->gain1 + s->offset;
}

static int sum2_setup(struct hal *h, void *inst, const char *name)
{
    struct sum2 *s = inst;
    s->gain0 = s->gain1 = 1.0;
    int st = hal_pin_float_newf(h, HAL_IN, &s->in0, "%s.in0", name);
    if (st == HAL_OK)
        st = hal_pin_float_newf(h, HAL_IN, &s->in1, "%s.in1", name);
    if (st == HAL_OK)
        st = hal_pin_float_newf(h, HAL_OUT, &s->out, "%s.out", name);
    if (st == HAL_OK)
        st = hal_param_float_newf(h, HAL_RW, &s->gain0, "%s.gain0", name);
    if (st == HAL_OK)
        st = hal_param_float_newf(h, HAL_RW, &s->gain1, "%s.gain1", name);
    if (st == HAL_OK)
        st = hal_param_float_newf(h, HAL_RW, &s->offset, "%s.offset", name);
    return st == HAL_OK ? hal_export_functf(h, sum2_run, s, "%s", name) : st;
}

static int sum2_load(struct hal *h, int argc, char **argv)
{
    return logic_load(h, "sum2", argc, argv, sizeof(struct sum2), sum2_setup);
}

/* and2: out = in0 AND in1. */
struct and2 {
    bool *in0, *in1, *out;
};

static void and2_run(void *arg, long period_ns)
{
    struct and2 *a = arg;
    *a->out = *a->in0 && *a->in1;
}

static int and2_setup(struct hal *h, void *inst, const char *name)
{
    struct and2 *a = inst;
    int st = hal_pin_bit_newf(h, HAL_IN, &a->in0, "%s.in0", name);
    if (st == HAL_OK)
        st = hal_pin_bit_newf(h, HAL_IN, &a->in1, "%s.in1", name);
    if (st == HAL_OK)
        st = hal_pin_bit_newf(h, HAL_OUT, &a->out, "%s.out", name);
    return st == HAL_OK ? hal_export_functf(h, and2_run, a, "%s", name) : st;
}

static int and2_load(struct hal *h, int argc, char **argv)
{
    return logic_load(h, "and2", argc, argv, sizeof(struct and2), and2_setup);
}

/* not: out = NOT in. */
struct not1 {
    bool *in, *out;
};

static void not_run(void *arg, long period_ns)
{
    struct not1 *n = arg;
    *n->out = !*n->in;
}

static int not_setup(struct hal *h, void *inst, const char *name)
{
    struct not1 *n = inst;
    int st = hal_pin_bit_newf(h, HAL_IN, &n->in, "%s.in", name);
    if (st == HAL_OK)
        st = hal_pin_bit_newf(h, HAL_OUT, &n->out, "%s.out", name);
    return st == HAL_OK ? hal_export_functf(h, not_run, n, "%s", name) : st;
}

static int not_load(struct hal *h, int argc, char **argv)
{
    return logic_load(h, "not", argc, argv, sizeof(struct not1), not_setup);
}

/* estop-latch: a fault (ok-in false or fault-in true) latches; only a rising edge on reset
 * with ok-in true and fault-in false clears it. watchdog toggles while ok, so a drive can
 * see that the servo thread is alive. */
struct estop_latch {
    bool *ok_in, *fault_in, *reset;        /* in */
    bool *ok_out, *fault_out, *watchdog;   /* out */
    bool faulted;                          /* the latch */
    bool last_reset;                       /* reset in the previous period (edge detect) */
};

static void estop_latch_run(void *arg, long period_ns)
{
    struct estop_latch *e = arg;
    bool healthy = *e->ok_in && !*e->fault_in;
    if (!healthy)
        e->faulted = true;
    else if (*e->reset && !e->last_reset)
        e->faulted = false;
    e->last_reset = *e->reset;
    *e->ok_out = !e->faulted;
    *e->fault_out = e->faulted;
    *e->watchdog = e->faulted ? false : !*e->watchdog;
}

static int estop_latch_setup(struct hal *h, void *inst, const char *name)
{
    struct estop_latch *e = inst;
    e->faulted = true;                     /* a machine starts in e-stop until reset */
    int st = hal_pin_bit_newf(h, HAL_IN, &e->ok_in, "%s.ok-in", name);
    if (st == HAL_OK)
        st = hal_pin_bit_newf(h, HAL_IN, &e->fault_in, "%s.fault-in", name);
    if (st == HAL_OK)
        st = hal_pin_bit_newf(h, HAL_IN, &e->reset, "%s.reset", name);
    if (st == HAL_OK)
        st = hal_pin_bit_newf(h, HAL_OUT, &e->ok_out, "%s.ok-out", name);
    if (st == HAL_OK)
        st = hal_pin_bit_newf(h, HAL_OUT, &e->fault_out, "%s.fault-out", name);
    if (st == HAL_OK)
        st = hal_pin_bit_newf(h, HAL_OUT, &e->watchdog, "%s.watchdog", name);
    if (st != HAL_OK)
        return st;
    *e->fault_out = true;
    return hal_export_functf(h, estop_latch_run, e, "%s", name);
}

static int estop_latch_load(struct hal *h, int argc, char **argv)
{
    return logic_load(h, "estop-latch", argc, argv, sizeof(struct estop_latch),
                      estop_latch_setup);
}

const struct hal_comp_type hal_comp_sum2 = { "sum2", sum2_load };
const struct hal_comp_type hal_comp_and2 = { "and2", and2_load };
const struct hal_comp_type hal_comp_not = { "not", not_load };
const struct hal_comp_type hal_comp_estop_latch = { "estop-latch", estop_latch_load };
