/* sim_spindle.c: HAL component `sim-spindle`: a simulated spindle that takes time to reach
 * the speed it is given, says when it is there (for spindle.0.at-speed), and has an encoder:
 * its position in revolutions (for spindle.0.revs, G33 and G33.1). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hal/hal.h"

/*
 *   sim-spindle.speed-in   float in    commanded speed, rpm, signed (spindle.0.speed-out)
 *   sim-spindle.speed      float out   the spindle's speed, rpm, signed
 *   sim-spindle.at-speed   bit   out   |speed - speed-in| within tolerance
 *   sim-spindle.revs       float out   the encoder: revolutions turned, signed (forward
 *                                      counts up), the speed integrated each period
 *   sim-spindle.index-enable bit io    set: the count goes to 0 at the next index (a whole
 *                                      revolution, either way), and the pin is cleared
 *                                      there (LinuxCNC's encoder; spindle.0.index-enable)
 *   sim-spindle.accel      float param rpm/s the spindle gains or loses speed at (2000)
 *   sim-spindle.tolerance  float param fraction of the commanded speed that counts as at
 *                                      speed (0.02), and never less than 1 rpm
 */
struct sim_spindle {
    double *in, *speed, *revs;
    bool *at_speed, *index_enable;
    double accel, tol;
};

static void sim_spindle_update(void *arg, long period_ns)
{
    struct sim_spindle *s = arg;
    double dt = (double)period_ns * 1e-9, step = fabs(s->accel) * dt;
    double diff = *s->in - *s->speed, rpm0 = *s->speed;
    *s->speed += fabs(diff) <= step ? diff : copysign(step, diff);
    double r0 = *s->revs, r1 = r0 + 0.5 * (rpm0 + *s->speed) / 60.0 * dt; /* the ramp's mean */
    if (*s->index_enable && floor(r0) != floor(r1)) {
        r1 -= fmax(floor(r0), floor(r1));     /* the index passed: counted from it */
        *s->index_enable = false;
    }
    *s->revs = r1;
    *s->at_speed = fabs(*s->in - *s->speed) <= fmax(fabs(s->tol * *s->in), 1.0);
}

static int sim_spindle_load(struct hal *h, int argc, char **argv)
{
    int rc = hal_args_check(h, "sim-spindle", argc, argv, "");
    if (rc)
        return rc;
    struct sim_spindle *s = calloc(1, sizeof *s);
    if (!s)
        return hal_error(h, HAL_ERR_NOMEM, "sim-spindle: out of memory");
    if ((rc = hal_on_destroy(h, free, s))) {
        free(s);
        return rc;
    }
    s->accel = 2000;
    s->tol = 0.02;
    if ((rc = hal_pin_float_newf(h, HAL_IN, &s->in, "sim-spindle.speed-in")) ||
        (rc = hal_pin_float_newf(h, HAL_OUT, &s->speed, "sim-spindle.speed")) ||
        (rc = hal_pin_bit_newf(h, HAL_OUT, &s->at_speed, "sim-spindle.at-speed")) ||
        (rc = hal_pin_float_newf(h, HAL_OUT, &s->revs, "sim-spindle.revs")) ||
        (rc = hal_pin_bit_newf(h, HAL_IO, &s->index_enable, "sim-spindle.index-enable")) ||
        (rc = hal_param_float_newf(h, HAL_RW, &s->accel, "sim-spindle.accel")) ||
        (rc = hal_param_float_newf(h, HAL_RW, &s->tol, "sim-spindle.tolerance")))
        return rc;
    *s->at_speed = true;
    return hal_export_functf(h, sim_spindle_update, s, "sim-spindle.update");
}

const struct hal_comp_type hal_comp_sim_spindle = { "sim-spindle", sim_spindle_load };
