/* stepgen.c: HAL component `stepgen`, a simulated step generator (position or velocity mode). */
#include "sim/stepgen.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/*
 * One channel per leg, as LinuxCNC's stepgen in position mode (control type 0). Each servo
 * period `stepgen.update` chooses a step rate that makes the motor follow position-cmd
 * within maxvel and maxaccel, integrates it, and counts whole steps. position-fb is the
 * step count divided by the scale: what an encoder-less stepper machine really knows.
 * Channels loaded with ctrl_type v follow velocity-cmd instead (LinuxCNC's velocity mode).
 *
 * The controller itself is in stepgen_core.c (pure, so tests can drive it alone).
 */

/* Pins and parameters of one channel. */
struct stepgen_chan {
    double *pos_cmd;          /* in: commanded position, mm */
    bool *enable;             /* in: generate steps only when true */
    double *pos_fb;           /* out: counts / scale, mm (quantised) */
    int32_t *counts;          /* out: whole steps since start */
    double *vel_fb;           /* out: step rate / scale, mm/s */
    double *vel_cmd;          /* in: commanded velocity, mm/s (velocity mode) */
    bool velocity_mode;       /* ctrl_type v: follow vel_cmd instead of pos_cmd */
    double scale;             /* param: steps per mm (sign sets the direction) */
    double maxvel;            /* param: mm/s, 0 = no limit */
    double maxaccel;          /* param: mm/s^2, 0 = no limit */
    double sim_start;         /* param: where the motor is at power-up, mm; 0 = where the
                               * first command says (the simulated machine "powers up homed") */
    bool started;             /* sim_start has been applied */
    struct stepgen_state st;  /* the controller's state */
};

/* The loaded component: all channels of one `loadrt stepgen count=N`. */
struct stepgen_comp {
    int count;                       /* channels */
    struct stepgen_chan chan[STEPGEN_MAX_CHAN];
};

/* The thread function: every channel, one period. */
static void stepgen_update(void *arg, long period_ns)
{
    struct stepgen_comp *c = arg;
    double dt_s = (double)period_ns * 1e-9;
    for (int i = 0; i < c->count; i++) {
        struct stepgen_chan *ch = &c->chan[i];
        if (ch->scale == 0.0)
            continue;  /* unconfigured: nothing sensible to count */
        struct stepgen_limits lim = { ch->scale, ch->maxvel, ch->maxaccel };
        if (!ch->started && ch->sim_start != 0.0) {
            /* the motor is where the machine was left, whatever the command says */
            stepgen_state_init(&ch->st, ch->sim_start);
            ch->st.counts = (int64_t)llround(ch->sim_start * ch->scale);
            ch->st.primed = true;
        }
        ch->started = true;
        int64_t n = ch->velocity_mode
                        ? stepgen_step_velocity(&ch->st, &lim, *ch->vel_cmd, *ch->enable, dt_s)
                        : stepgen_step(&ch->st, &lim, *ch->pos_cmd, *ch->enable, dt_s);
        *ch->counts = (int32_t)n;
        *ch->pos_fb = (double)n / ch->scale;
        *ch->vel_fb = ch->st.vel_mm_s;
    }
}

/* Creates the pins and parameters of channel i. */
static int stepgen_chan_new(struct hal *h, struct stepgen_chan *ch, int i)
{
    int rc;
    if ((rc = hal_pin_float_newf(h, HAL_IN, &ch->pos_cmd, "stepgen.%d.position-cmd", i)) ||
        (rc = hal_pin_bit_newf(h, HAL_IN, &ch->enable, "stepgen.%d.enable", i)) ||
        (rc = hal_pin_float_newf(h, HAL_OUT, &ch->pos_fb, "stepgen.%d.position-fb", i)) ||
        (rc = hal_pin_s32_newf(h, HAL_OUT, &ch->counts, "stepgen.%d.counts", i)) ||
        (rc = hal_pin_float_newf(h, HAL_OUT, &ch->vel_fb, "stepgen.%d.velocity-fb", i)) ||
        (rc = hal_pin_float_newf(h, HAL_IN, &ch->vel_cmd, "stepgen.%d.velocity-cmd", i)) ||
        (rc = hal_param_float_newf(h, HAL_RW, &ch->scale, "stepgen.%d.position-scale", i)) ||
        (rc = hal_param_float_newf(h, HAL_RW, &ch->maxvel, "stepgen.%d.maxvel", i)) ||
        (rc = hal_param_float_newf(h, HAL_RW, &ch->maxaccel, "stepgen.%d.maxaccel", i)) ||
        (rc = hal_param_float_newf(h, HAL_RW, &ch->sim_start, "stepgen.%d.sim-start", i)))
        return rc;
    ch->scale = 1.0;  /* LinuxCNC's default: one step per unit until setp says otherwise */
    stepgen_state_init(&ch->st, 0.0);
    return HAL_OK;
}

/* Parses `count=N` (default 1) and `ctrl_type=p,v,...` (default p for every channel). */
static int stepgen_parse_args(struct hal *h, int argc, char **argv, int *count,
                              bool velocity[STEPGEN_MAX_CHAN])
{
    *count = 1;
    int ntypes = 0;
    for (int i = 0; i < argc; i++) {
        if (!strncmp(argv[i], "ctrl_type=", 10)) {
            for (const char *t = argv[i] + 10; *t; t++) {
                if (*t == ',')
                    continue;
                if ((*t != 'p' && *t != 'v') || ntypes == STEPGEN_MAX_CHAN)
                    return hal_error(h, HAL_ERR_ARG, "stepgen: ctrl_type is a list of p "
                                     "(position) and v (velocity), not '%s'", argv[i] + 10);
                velocity[ntypes++] = *t == 'v';
            }
            continue;
        }
        if (strncmp(argv[i], "count=", 6) != 0)
            return hal_error(h, HAL_ERR_ARG, "stepgen: unknown argument '%s' (expected "
                             "count=N, ctrl_type=p,v,...)", argv[i]);
        char *end;
        long n = strtol(argv[i] + 6, &end, 10);
        if (*end || n < 1 || n > STEPGEN_MAX_CHAN)
            return hal_error(h, HAL_ERR_ARG, "stepgen: count must be 1..%d, not '%s'",
                             STEPGEN_MAX_CHAN, argv[i] + 6);
        *count = (int)n;
    }
    if (ntypes > *count)
        *count = ntypes;  /* LinuxCNC: ctrl_type alone also sets the number of channels */
    return HAL_OK;
}

/* `loadrt stepgen count=N`: N channels and one funct, stepgen.update. */
static int stepgen_load(struct hal *h, int argc, char **argv)
{
    int count, rc;
    bool velocity[STEPGEN_MAX_CHAN] = { false };
    if ((rc = stepgen_parse_args(h, argc, argv, &count, velocity)))
        return rc;
    struct stepgen_comp *c = calloc(1, sizeof *c);
    if (!c)
        return hal_error(h, HAL_ERR_NOMEM, "stepgen: out of memory");
    if ((rc = hal_on_destroy(h, free, c))) {
        free(c);
        return rc;
    }
    c->count = count;
    for (int i = 0; i < count; i++) {
        c->chan[i].velocity_mode = velocity[i];
        if ((rc = stepgen_chan_new(h, &c->chan[i], i)))
            return rc;
    }
    return hal_export_functf(h, stepgen_update, c, "stepgen.update");
}

const struct hal_comp_type hal_comp_stepgen = { "stepgen", stepgen_load };
