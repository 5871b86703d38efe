/* modbus_sim_model.c: the simulated drive's motion (first-order lag with a velocity limit) and status word. */
#include "sim/modbus_sim.h"

#include <math.h>
#include <string.h>

/* Defaults: the default register map, 64 registers, 2 ms lag, no practical velocity limit. */
void modbus_sim_opts_default(struct modbus_sim_opts *o)
{
    memset(o, 0, sizeof(*o));
    modbus_regmap_default(&o->map);
    o->nb_registers = 64;
    o->tau_s = 0.002;
    o->vmax_counts_s = 1e9;
    o->step_ns = 0;
    o->unit = 1;
}

/* Exact discretisation of x' = (target - x) / tau over dt, then the step is clamped to
 * vmax * dt: a drive that interpolates toward each new set point and cannot exceed its
 * rated speed. A disabled or faulted drive holds its position. */
void modbus_sim_model_step(struct modbus_sim_model *m, const struct modbus_sim_opts *o, double dt_s)
{
    if (!m->enabled || m->fault || dt_s <= 0.0)
        return;
    double err = (double)m->target_counts - m->actual_counts;
    double step = o->tau_s > 0.0 ? err * (1.0 - exp(-dt_s / o->tau_s)) : err;
    double lim = o->vmax_counts_s * dt_s;
    if (step > lim)
        step = lim;
    else if (step < -lim)
        step = -lim;
    m->actual_counts += step;
}

/* READY unless faulted, ENABLED while following, FAULT, AT_TARGET within one count. */
uint16_t modbus_sim_model_status(const struct modbus_sim_model *m)
{
    uint16_t s = 0;
    if (m->fault)
        s |= MODBUS_STAT_FAULT;
    else
        s |= MODBUS_STAT_READY;
    if (m->enabled && !m->fault)
        s |= MODBUS_STAT_ENABLED;
    if (fabs((double)m->target_counts - m->actual_counts) <= 1.0)
        s |= MODBUS_STAT_AT_TARGET;
    return s;
}
