/* modbus_sim_hal.c: HAL component `modbus-sim-server`: starts simulated Modbus drives in-process for a config. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hal/hal.h"
#include "hal/drivers/modbus_cfg.h"
#include "kins/kins.h"
#include "sim/modbus_sim.h"

/*
 *   loadrt modbus-sim-server [count=N] [section=MODBUS]
 *
 * Reads the same [MODBUS] / [MODBUS_DRIVE_n] keys as the `modbus` component, so client and
 * simulated drives agree on ports, register map, word order and scaling by construction,
 * and serves drive n on its configured TCP port. Load it before `modbus`. With the
 * simulated clock the drive model advances one SETPOINT_PERIOD per exchange (lockstep:
 * deterministic); on the real-time clock it runs on wall time. [MODBUS_SIM] TAU (s) and
 * MAX_VELOCITY (mm/s) shape the drive model. When the kinematics is loaded the drives
 * start at the leg lengths of [KINS] HOME, where a parked machine stands.
 * The simulator is stored as the HAL object "modbus-sim" so tests can inject faults.
 */

/* What the component keeps: the simulator, freed at hal_destroy. */
static void modbus_sim_hal_free(void *arg)
{
    modbus_sim_destroy(arg);
}

/* Parses count= and section=. */
static int modbus_sim_hal_args(struct hal *h, int argc, char **argv, long *count, char *section,
                               size_t len)
{
    for (int i = 0; i < argc; i++) {
        const char *a = argv[i];
        if (!strncmp(a, "count=", 6)) {
            char *end;
            *count = strtol(a + 6, &end, 10);
            if (*end || *count < 1 || *count > 64)
                return hal_error(h, HAL_ERR_ARG, "modbus-sim-server: count must be 1..64, "
                                 "not '%s'", a + 6);
        } else if (!strncmp(a, "section=", 8) && a[8] && strlen(a + 8) < len - 16) {
            snprintf(section, len, "%s", a + 8);
        } else {
            return hal_error(h, HAL_ERR_ARG, "modbus-sim-server: unknown argument '%s' "
                             "(expected count=N or section=NAME)", a);
        }
    }
    return HAL_OK;
}

/* Drive model options from drive 0's config and [MODBUS_SIM]. */
static int modbus_sim_hal_opts(struct hal *h, const struct modbus_drive_cfg *c0,
                               struct modbus_sim_opts *o)
{
    modbus_sim_opts_default(o);
    o->map = c0->map;
    int top = c0->map.control;
    const int regs[] = { c0->map.target + 1, c0->map.status, c0->map.actual + 1 };
    for (int i = 0; i < 3; i++)
        top = regs[i] > top ? regs[i] : top;
    o->nb_registers = top + 1 > 64 ? top + 1 : 64;
    double vmax_mm_s = 0.0;
    if (hal_ini_double(h, "MODBUS_SIM", "TAU", o->tau_s, &o->tau_s) == HAL_ERR_SYNTAX ||
        hal_ini_double(h, "MODBUS_SIM", "MAX_VELOCITY", 0.0, &vmax_mm_s) == HAL_ERR_SYNTAX)
        return HAL_ERR_COMPONENT;
    if (vmax_mm_s > 0.0)
        o->vmax_counts_s = vmax_mm_s * fabs(c0->counts_per_mm);
    o->step_ns = hal_sim_clock(h) ? c0->period_ns : 0;
    o->timeout_us = hal_sim_clock(h) ? c0->timeout_us : 0;
    o->unit = c0->unit;
    return HAL_OK;
}

/* Parks drive i at the leg length of the kinematics' home pose, when there is one. */
static void modbus_sim_hal_park(struct hal *h, struct modbus_sim *s, int n,
                                const struct modbus_drive_cfg *cfg)
{
    struct kins *k = hal_get_object(h, "kins");
    if (!k || k->njoints < n)
        return;
    double legs_mm[KINS_MAX_JOINTS];
    if (kins_inverse(k, k->home, legs_mm) != KINS_OK)
        return;
    for (int i = 0; i < n; i++) {
        int32_t counts;
        if (modbus_mm_to_counts(legs_mm[i], cfg[i].counts_per_mm, &counts) == MODBUS_DRIVE_OK)
            modbus_sim_set_position(s, i, counts);
    }
}

/* `loadrt modbus-sim-server ...`: one simulated drive per configured Modbus drive. */
static int modbus_sim_hal_load(struct hal *h, int argc, char **argv)
{
    char section[48] = "MODBUS", err[320];
    long count = -1;
    int rc = modbus_sim_hal_args(h, argc, argv, &count, section, sizeof(section));
    if (rc)
        return rc;
    if (count < 0 && (count = modbus_cfg_drive_count(section, hal_ini_lookup, h,
                                                     hal_ini_path(h), 1, 64, err,
                                                     sizeof(err))) < 0)
        return hal_error(h, HAL_ERR_COMPONENT, "modbus-sim-server: %s", err);
    struct modbus_drive_cfg cfg[64];
    for (int i = 0; i < count; i++) {
        if (modbus_cfg_read(&cfg[i], i, section, hal_ini_lookup, h, hal_ini_path(h),
                            err, sizeof(err)))
            return hal_error(h, HAL_ERR_COMPONENT, "modbus-sim-server: %s", err);
        if (cfg[i].transport != MODBUS_DRIVE_TCP)
            return hal_error(h, HAL_ERR_COMPONENT, "modbus-sim-server: drive %d is not Modbus "
                             "TCP: the in-process simulator serves TCP drives only", i);
    }
    struct modbus_sim_opts o;
    if (modbus_sim_hal_opts(h, &cfg[0], &o))
        return HAL_ERR_COMPONENT;
    struct modbus_sim *s;
    if ((rc = modbus_sim_create(&s, (int)count, &o)))
        return hal_error(h, HAL_ERR_COMPONENT, "modbus-sim-server: %s", modbus_sim_strerror(rc));
    if ((rc = hal_on_destroy(h, modbus_sim_hal_free, s))) {
        modbus_sim_destroy(s);
        return rc;
    }
    modbus_sim_hal_park(h, s, (int)count, cfg);
    for (int i = 0; i < count; i++)
        if ((rc = modbus_sim_start_tcp_port(s, i, cfg[i].host, cfg[i].port)))
            return hal_error(h, HAL_ERR_COMPONENT, "modbus-sim-server: drive %d on %s:%d: %s",
                             i, cfg[i].host, cfg[i].port, modbus_sim_strerror(rc));
    return hal_set_object(h, "modbus-sim", s);
}

const struct hal_comp_type hal_comp_modbus_sim_server = { "modbus-sim-server",
                                                          modbus_sim_hal_load };
