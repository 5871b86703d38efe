/* sim_toolchanger.c: HAL component `sim-toolchanger`: a simulated tool changer that takes
 * time to prepare a tool and to change it, answering LinuxCNC's iocontrol handshake. */
#include <stdlib.h>

#include "hal/hal.h"

/*
 *   sim-toolchanger.prepare       bit   in    iocontrol.0.tool-prepare
 *   sim-toolchanger.prepared      bit   out   iocontrol.0.tool-prepared: true once prepare has
 *                                             been held for prepare-time, false when it drops
 *   sim-toolchanger.change        bit   in    iocontrol.0.tool-change
 *   sim-toolchanger.changed       bit   out   iocontrol.0.tool-changed: true once change has
 *                                             been held for change-time, false when it drops
 *   sim-toolchanger.changes       s32   out   tool changes made
 *   sim-toolchanger.prepare-time  float param s (0.5)
 *   sim-toolchanger.change-time   float param s (2.0)
 */
struct sim_toolchanger {
    bool *prepare, *prepared, *change, *changed;
    int32_t *changes;
    double prepare_time, change_time;
    double prepare_s, change_s;   /* how long each request has been held */
};

static void sim_toolchanger_update(void *arg, long period_ns)
{
    struct sim_toolchanger *t = arg;
    double dt = (double)period_ns * 1e-9;
    t->prepare_s = *t->prepare ? t->prepare_s + dt : 0;
    *t->prepared = *t->prepare && t->prepare_s >= t->prepare_time - 1e-9;
    bool was = *t->changed;
    t->change_s = *t->change ? t->change_s + dt : 0;
    *t->changed = *t->change && t->change_s >= t->change_time - 1e-9;
    if (*t->changed && !was)
        (*t->changes)++;
}

static int sim_toolchanger_load(struct hal *h, int argc, char **argv)
{
    int rc = hal_args_check(h, "sim-toolchanger", argc, argv, "");
    if (rc)
        return rc;
    struct sim_toolchanger *t = calloc(1, sizeof *t);
    if (!t)
        return hal_error(h, HAL_ERR_NOMEM, "sim-toolchanger: out of memory");
    if ((rc = hal_on_destroy(h, free, t))) {
        free(t);
        return rc;
    }
    t->prepare_time = 0.5;
    t->change_time = 2.0;
    if ((rc = hal_pin_bit_newf(h, HAL_IN, &t->prepare, "sim-toolchanger.prepare")) ||
        (rc = hal_pin_bit_newf(h, HAL_OUT, &t->prepared, "sim-toolchanger.prepared")) ||
        (rc = hal_pin_bit_newf(h, HAL_IN, &t->change, "sim-toolchanger.change")) ||
        (rc = hal_pin_bit_newf(h, HAL_OUT, &t->changed, "sim-toolchanger.changed")) ||
        (rc = hal_pin_s32_newf(h, HAL_OUT, &t->changes, "sim-toolchanger.changes")) ||
        (rc = hal_param_float_newf(h, HAL_RW, &t->prepare_time,
                                   "sim-toolchanger.prepare-time")) ||
        (rc = hal_param_float_newf(h, HAL_RW, &t->change_time, "sim-toolchanger.change-time")))
        return rc;
    return hal_export_functf(h, sim_toolchanger_update, t, "sim-toolchanger.update");
}

const struct hal_comp_type hal_comp_sim_toolchanger = { "sim-toolchanger",
                                                        sim_toolchanger_load };
