/* kins_cfg.h: reading numbers from a struct kins_config with messages that name the key. */
#ifndef HEXCNC_KINS_CFG_H
#define HEXCNC_KINS_CFG_H

#include <stddef.h>

#include "kins/kins.h"

/* Reads exactly n numbers (separated by blanks or commas) from [section] key into out.
 * An absent key sets *found = 0 and returns KINS_OK with out untouched (the caller decides
 * whether that is an error or a default); found may be NULL when the key is required, in
 * which case absence is KINS_ERR_CONFIG "[SECTION] KEY: missing". */
int kins_cfg_numbers(const struct kins_config *cfg, const char *section, const char *key,
                     double *out, int n, int *found, char *err, size_t errlen);

/* Reads one number; an absent key leaves *out (the default) as it is. */
int kins_cfg_number_or(const struct kins_config *cfg, const char *section, const char *key,
                       double *out, char *err, size_t errlen);

/* Writes "[SECTION] KEY: <message>" into err and returns KINS_ERR_CONFIG. */
int kins_cfg_error(char *err, size_t errlen, const char *section, const char *key,
                   const char *fmt, ...) __attribute__((format(printf, 5, 6)));

#endif
