/* cia402_sim_hal.h: the simulated drives' settings from the INI, shared by `cia402-sim` and `hexcnc can_sim`. */
#ifndef HEXCNC_CIA402_SIM_HAL_H
#define HEXCNC_CIA402_SIM_HAL_H

#include "hal/hal.h"
#include "sim/cia402_sim.h"

/* Drive i from [CAN_NODE_i]: NODE_ID, COUNTS_PER_MM (required), OFFSET, SIM_START (mm),
 * SIM_MAX_VELOCITY (mm/s), SIM_BOOT_DELAY (ms). A HAL status; the message is in hal. */
int cia402_sim_cfg_read(struct hal *h, int i, struct cia402_sim_cfg *sc);

#endif
