/* kins_cfg.c: kinematics configuration values (common/config_value.c's rules), with
 * key-naming messages. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/config.h"
#include "kins/kins_cfg.h"

/* Formats a configuration error so the user sees which section and key to fix. */
int kins_cfg_error(char *err, size_t errlen, const char *section, const char *key,
                   const char *fmt, ...)
{
    if (err && errlen) {
        int n = snprintf(err, errlen, "[%s] %s: ", section, key);
        if (n >= 0 && (size_t)n < errlen) {
            va_list ap;
            va_start(ap, fmt);
            vsnprintf(err + n, errlen - (size_t)n, fmt, ap);
            va_end(ap);
        }
    }
    return KINS_ERR_CONFIG;
}

/* Reads n numbers from one key (common/config_value.c's rules); see kins_cfg.h for the
 * absent-key rule. */
int kins_cfg_numbers(const struct kins_config *cfg, const char *section, const char *key,
                     double *out, int n, int *found, char *err, size_t errlen)
{
    const char *text = cfg && cfg->get ? cfg->get(cfg->ctx, section, key) : NULL;
    if (found)
        *found = text != NULL;
    if (!text) {
        if (found)
            return KINS_OK;
        return kins_cfg_error(err, errlen, section, key, "missing");
    }
    if (n < 1 || n > KINS_MAX_JOINTS)
        return kins_cfg_error(err, errlen, section, key, "internal: bad count %d", n);
    char why[128];
    if (n == 1 && config_parse_number(text, out, why, sizeof why) != 0)
        return kins_cfg_error(err, errlen, section, key, "'%s' is not a number", text);
    if (n > 1 && config_parse_numbers(text, out, n, why, sizeof why) != 0)
        return kins_cfg_error(err, errlen, section, key, "'%s': %s", text, why);
    return KINS_OK;
}

/* Reads one optional number, keeping the caller's default when the key is absent. */
int kins_cfg_number_or(const struct kins_config *cfg, const char *section, const char *key,
                       double *out, char *err, size_t errlen)
{
    int found;
    return kins_cfg_numbers(cfg, section, key, out, 1, &found, err, errlen);
}
