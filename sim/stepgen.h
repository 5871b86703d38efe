/* stepgen.h: the simulated step generator (HAL component `stepgen`) and its pure core. */
#ifndef HEXCNC_SIM_STEPGEN_H
#define HEXCNC_SIM_STEPGEN_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/hal.h"

/* Most channels one `loadrt stepgen count=N` creates (LinuxCNC's limit too). */
#define STEPGEN_MAX_CHAN 16

/*
 * HAL interface, per channel N (0-based), as LinuxCNC's stepgen in position mode:
 *   stepgen.N.position-cmd   float in   commanded position, mm
 *   stepgen.N.enable         bit   in   steps are generated only while true
 *   stepgen.N.position-fb    float out  counts / position-scale, mm (quantised to a step)
 *   stepgen.N.counts         s32   out  whole steps since start
 *   stepgen.N.velocity-fb    float out  current step rate / position-scale, mm/s
 *   stepgen.N.velocity-cmd   float in   commanded velocity, mm/s (velocity mode only)
 *   stepgen.N.position-scale float param steps per mm
 *   stepgen.N.maxvel         float param mm/s (0 = no limit)
 *   stepgen.N.maxaccel       float param mm/s^2 (0 = no limit)
 *   stepgen.N.sim-start      float param where the motor is at power-up, mm (0, the
 *                            default: where the first command puts it)
 * Funct: stepgen.update (all channels; add it after the funct that writes position-cmd).
 * `loadrt stepgen count=N [ctrl_type=p,v,...]`: as in LinuxCNC, p (the default) follows
 * position-cmd, v follows velocity-cmd.
 */
extern const struct hal_comp_type hal_comp_stepgen;

/* Limits of one channel. */
struct stepgen_limits {
    double scale;             /* steps per mm */
    double maxvel_mm_s;       /* 0 = no limit */
    double maxaccel_mm_s2;    /* 0 = no limit */
};

/* The controller state of one channel. */
struct stepgen_state {
    double pos_mm;            /* internal motor position before quantisation, mm */
    double vel_mm_s;          /* step rate of the last period, mm/s */
    double cmd_prev_mm;       /* position-cmd of the last period, mm */
    int64_t counts;           /* whole steps */
    bool primed;              /* enabled once: from then on only steps move the motor */
};

/* Starts a channel at pos_mm, at rest. */
void stepgen_state_init(struct stepgen_state *s, double pos_mm);
/* One period of dt_s seconds towards cmd_mm; returns the step count afterwards. Pure:
 * tests stream commands through it without a HAL. */
int64_t stepgen_step(struct stepgen_state *s, const struct stepgen_limits *lim,
                     double cmd_mm, bool enable, double dt_s);

/* One period of velocity mode: the step rate follows vel_cmd_mm_s within the limits. */
int64_t stepgen_step_velocity(struct stepgen_state *s, const struct stepgen_limits *lim,
                              double vel_cmd_mm_s, bool enable, double dt_s);

#endif
