/* calib_csv.h: the measurement CSV of `hexcnc calibrate fit`, parsed from memory. */
#ifndef HEXCNC_CALIB_CSV_H
#define HEXCNC_CALIB_CSV_H

#include "calib/calib.h"

/* Parses a measurement file's text: header L1,L2,L3,L4,L5,L6,X,Y,Z,A,B,C (any case), one
 * measurement a row, blank lines and `#` comments skipped. On success *out (free() it) and
 * *n get the rows; on failure err says "PATH:LINE: what is wrong". */
enum calib_status calib_csv_parse(const char *text, const char *path, struct calib_meas **out,
                                  int *n, char *err, size_t errlen);

#endif
