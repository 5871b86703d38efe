/* modbus_cfg.h: reads a Modbus drive's configuration from INI sections [MODBUS] and [MODBUS_DRIVE_n]. */
#ifndef HEXCNC_MODBUS_CFG_H
#define HEXCNC_MODBUS_CFG_H

#include <stdbool.h>
#include <stddef.h>

#include "hal/drivers/modbus_drive.h"

/*
 * Every key is looked up first in the drive's own section `[<SECTION>_DRIVE_<n>]`, then in
 * `[<SECTION>]` (the defaults for all drives), then the built-in default. SECTION is
 * usually MODBUS. Keys (docs/modbus.md has the full table):
 *   TRANSPORT tcp|rtu   HOST  PORT  BASE_PORT (drive n: BASE_PORT + n)  UNIT
 *   DEVICE  BAUD  PARITY N|E|O  DATA_BITS  STOP_BITS
 *   REG_CONTROL  REG_TARGET  REG_STATUS  REG_ACTUAL  WORD_ORDER high-first|low-first
 *   COUNTS_PER_MM  SETPOINT_PERIOD (ns)  TIMEOUT (ms, decimals allowed)
 *   EXCHANGE fc23|separate
 * The reader is handed a lookup function, so it needs no HAL and tests can feed it a table.
 */

/* Returns the value of KEY in SECTION, or NULL when absent. */
typedef const char *(*modbus_ini_get_fn)(void *ctx, const char *section, const char *key);

/* Fills `cfg` for drive `index`. On a bad value returns MODBUS_DRIVE_ERR_CONFIG with a
 * message in err naming `file`, the section and key, and what is expected. */
int modbus_cfg_read(struct modbus_drive_cfg *cfg, int index, const char *section,
                    modbus_ini_get_fn get, void *ctx, const char *file, char *err,
                    size_t errlen);

/* [<SECTION>] DRIVES, or `def` when absent; -1 with a message when not 1..max. */
int modbus_cfg_drive_count(const char *section, modbus_ini_get_fn get, void *ctx,
                           const char *file, int def, int max, char *err, size_t errlen);

#endif
