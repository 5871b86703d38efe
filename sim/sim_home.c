/* sim_home.c: HAL component `sim-home`: the home switches of simulated legs. */
#include <stdlib.h>
#include <string.h>

#include "hal/hal.h"

/*
 * A leg driven by a step generator knows only how many steps it made since power-up: the
 * stepgen primes at the first command, so the controller's idea of the leg's length is off
 * by whatever the leg's true length was then. This component holds that truth for a
 * simulated leg: its true length is the motor position plus `offset` (the error the
 * controller cannot see), and its home switch closes when the true length passes
 * `home-pos`, as a cam on the leg would close a switch. Homing has to find the switch and
 * so the offset; tests compare the homed leg with `length`.
 *
 * Per channel N:
 *   sim-home.N.motor-pos  float in    the motor's position, mm (stepgen.N.position-fb)
 *   sim-home.N.length     float out   true leg length, mm
 *   sim-home.N.home-sw    bit   out   the home switch
 *   sim-home.N.offset     float param true length - motor position, mm
 *   sim-home.N.home-pos   float param true length where the switch changes, mm
 *   sim-home.N.hysteresis float param mm the length must go back before it changes back
 *   sim-home.N.above      bit   param 1: closed at lengths >= home-pos (default), 0: below
 */

#define SIM_HOME_MAX 16

struct sim_home_chan {
    double *motor, *length;
    bool *sw;
    double offset, home_pos, hyst;
    bool above;
    bool state;
};

struct sim_home {
    int n;
    struct sim_home_chan ch[SIM_HOME_MAX];
};

static void sim_home_update(void *arg, long period_ns)
{
    struct sim_home *c = arg;
    for (int i = 0; i < c->n; i++) {
        struct sim_home_chan *h = &c->ch[i];
        double len = *h->motor + h->offset;
        /* distance past the switch point, positive on the closed side */
        double past = h->above ? len - h->home_pos : h->home_pos - len;
        if (past >= 0)
            h->state = true;
        else if (past < -h->hyst)
            h->state = false;
        *h->length = len;
        *h->sw = h->state;
    }
}

static int sim_home_load(struct hal *h, int argc, char **argv)
{
    int n = 1;
    for (int i = 0; i < argc; i++) {
        char *end;
        long v = strncmp(argv[i], "count=", 6) ? -1 : strtol(argv[i] + 6, &end, 10);
        if (v < 1 || v > SIM_HOME_MAX || *end)
            return hal_error(h, HAL_ERR_ARG, "sim-home: expected count=1..%d, not '%s'",
                             SIM_HOME_MAX, argv[i]);
        n = (int)v;
    }
    struct sim_home *c = calloc(1, sizeof *c);
    if (!c)
        return hal_error(h, HAL_ERR_NOMEM, "sim-home: out of memory");
    int rc = hal_on_destroy(h, free, c);
    if (rc) {
        free(c);
        return rc;
    }
    c->n = n;
    for (int i = 0; i < n; i++) {
        struct sim_home_chan *ch = &c->ch[i];
        ch->hyst = 0.05;
        ch->above = true;
        if ((rc = hal_pin_float_newf(h, HAL_IN, &ch->motor, "sim-home.%d.motor-pos", i)) ||
            (rc = hal_pin_float_newf(h, HAL_OUT, &ch->length, "sim-home.%d.length", i)) ||
            (rc = hal_pin_bit_newf(h, HAL_OUT, &ch->sw, "sim-home.%d.home-sw", i)) ||
            (rc = hal_param_float_newf(h, HAL_RW, &ch->offset, "sim-home.%d.offset", i)) ||
            (rc = hal_param_float_newf(h, HAL_RW, &ch->home_pos, "sim-home.%d.home-pos", i)) ||
            (rc = hal_param_float_newf(h, HAL_RW, &ch->hyst, "sim-home.%d.hysteresis", i)) ||
            (rc = hal_param_bit_newf(h, HAL_RW, &ch->above, "sim-home.%d.above", i)))
            return rc;
    }
    return hal_export_functf(h, sim_home_update, c, "sim-home.update");
}

const struct hal_comp_type hal_comp_sim_home = { "sim-home", sim_home_load };
