/* sim_probe.c: HAL component `sim-probe`: a simulated touch probe and workpiece. It drives
 * motion.probe-input from the machine's pose and the workpiece of [PROBE] in the INI (the
 * same model `hexcnc interp -i` and `hexcnc check` probe, interp/probe_model.h). */
#include <stdio.h>
#include <stdlib.h>

#include "hal/hal.h"
#include "interp/probe_model.h"

/*
 *   sim-probe.x, .y, .z  float in    the probe's position, mm, machine coordinates (the
 *                                    platform's pose from the kinematics, kins.pose-fb-*)
 *   sim-probe.tripped    bit   out   the probe touches the workpiece (motion.probe-input)
 *   sim-probe.stuck      bit   in    test hook: the probe reads tripped wherever it is
 *   sim-probe.missing    bit   in    test hook: the workpiece is not there (never tripped)
 */
struct sim_probe {
    double *pos[3];          /* in: mm */
    bool *tripped;           /* out */
    bool *stuck, *missing;   /* in */
    struct probe_model model;
};

static void sim_probe_update(void *arg, long period_ns)
{
    struct sim_probe *s = arg;
    (void)period_ns;
    double p[3] = { *s->pos[0], *s->pos[1], *s->pos[2] };
    *s->tripped = *s->stuck || (!*s->missing && probe_model_contact(&s->model, p));
}

static int sim_probe_load(struct hal *h, int argc, char **argv)
{
    int rc = hal_args_check(h, "sim-probe", argc, argv, "");
    if (rc)
        return rc;
    struct sim_probe *s = calloc(1, sizeof *s);
    if (!s)
        return hal_error(h, HAL_ERR_NOMEM, "sim-probe: out of memory");
    if ((rc = hal_on_destroy(h, free, s))) {
        free(s);
        return rc;
    }
    char err[300];
    if (probe_model_read(&s->model, hal_ini_lookup, h, err, sizeof err) != 0)
        return hal_error(h, HAL_ERR_COMPONENT, "sim-probe: %s", err);
    if ((rc = hal_pin_float_newf(h, HAL_IN, &s->pos[0], "sim-probe.x")) ||
        (rc = hal_pin_float_newf(h, HAL_IN, &s->pos[1], "sim-probe.y")) ||
        (rc = hal_pin_float_newf(h, HAL_IN, &s->pos[2], "sim-probe.z")) ||
        (rc = hal_pin_bit_newf(h, HAL_OUT, &s->tripped, "sim-probe.tripped")) ||
        (rc = hal_pin_bit_newf(h, HAL_IN, &s->stuck, "sim-probe.stuck")) ||
        (rc = hal_pin_bit_newf(h, HAL_IN, &s->missing, "sim-probe.missing")))
        return rc;
    return hal_export_functf(h, sim_probe_update, s, "sim-probe.update");
}

const struct hal_comp_type hal_comp_sim_probe = { "sim-probe", sim_probe_load };
