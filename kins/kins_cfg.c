/* kins_cfg.c: number parsing for kinematics configuration, with key-naming messages. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* Skips blanks and at most one comma, so "1 2 3" and "1, 2, 3" both read. */
static const char *kins_cfg_skip_sep(const char *s, int allow_comma)
{
    while (*s == ' ' || *s == '\t')
        s++;
    if (allow_comma && *s == ',') {
        s++;
        while (*s == ' ' || *s == '\t')
            s++;
    }
    return s;
}

/* Reads n numbers from one key; see kins_cfg.h for the absent-key rule. */
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
    double vals[KINS_MAX_JOINTS];
    if (n < 1 || n > KINS_MAX_JOINTS)
        return kins_cfg_error(err, errlen, section, key, "internal: bad count %d", n);
    const char *s = kins_cfg_skip_sep(text, 0);
    for (int i = 0; i < n; i++) {
        if (i > 0)
            s = kins_cfg_skip_sep(s, 1);
        char *end;
        errno = 0;
        double v = strtod(s, &end);
        if (end == s || errno == ERANGE || !isfinite(v)) {
            if (n == 1)
                return kins_cfg_error(err, errlen, section, key, "'%s' is not a number", text);
            return kins_cfg_error(err, errlen, section, key,
                                  "'%s': expected %d numbers, number %d is missing or wrong",
                                  text, n, i + 1);
        }
        vals[i] = v;
        s = end;
    }
    s = kins_cfg_skip_sep(s, 0);
    if (*s != '\0') {
        if (n == 1)
            return kins_cfg_error(err, errlen, section, key, "'%s' is not a number", text);
        return kins_cfg_error(err, errlen, section, key,
                              "'%s': expected %d numbers, found more text", text, n);
    }
    memcpy(out, vals, (size_t)n * sizeof *out);
    return KINS_OK;
}

/* Reads one optional number, keeping the caller's default when the key is absent. */
int kins_cfg_number_or(const struct kins_config *cfg, const char *section, const char *key,
                       double *out, char *err, size_t errlen)
{
    int found;
    return kins_cfg_numbers(cfg, section, key, out, 1, &found, err, errlen);
}
