/* calib_ini.h: the calibrated INI: a machine's INI text with the identified geometry. */
#ifndef HEXCNC_CALIB_INI_H
#define HEXCNC_CALIB_INI_H

#include "calib/calib.h"

/* Returns (malloc'd; NULL when out of memory) the INI text with the [KINS] geometry keys
 * (BASE_RADIUS, ..., BASE_n, PLATFORM_n, LEG_OFFSET) commented out ("# before calibration:")
 * and the explicit joints and leg offsets of g written after the [KINS] header, note as a
 * comment above them. Every other line is kept as it was. */
char *calib_ini_rewrite(const char *text, const struct calib_geom *g, const char *note);

#endif
