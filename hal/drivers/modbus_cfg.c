/* modbus_cfg.c: INI keys of the Modbus drives, per-drive section first, then the common [MODBUS] section. */
#include "hal/drivers/modbus_cfg.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "common/config.h"

/* One lookup session: where to look and where to report. */
struct modbus_cfg_reader {
    const char *section;          /* common section, e.g. MODBUS */
    char drive_section[64];       /* e.g. MODBUS_DRIVE_3 */
    modbus_ini_get_fn get;
    void *ctx;
    const char *file;             /* INI path for messages */
    char *err;
    size_t errlen;
};

/* Value of KEY (drive section first); *where receives the section it came from. */
static const char *modbus_cfg_get(const struct modbus_cfg_reader *r, const char *key,
                                  const char **where)
{
    const char *v = r->get(r->ctx, r->drive_section, key);
    *where = r->drive_section;
    if (!v) {
        v = r->get(r->ctx, r->section, key);
        *where = r->section;
    }
    return v;
}

/* The error message for a bad value; returns MODBUS_DRIVE_ERR_CONFIG. */
static int modbus_cfg_bad(const struct modbus_cfg_reader *r, const char *where, const char *key,
                          const char *value, const char *expected)
{
    snprintf(r->err, r->errlen, "%s: [%s] %s = %s: %s", r->file ? r->file : "INI", where, key,
             value, expected);
    return MODBUS_DRIVE_ERR_CONFIG;
}

/* An integer key in lo..hi; untouched when absent. */
static int modbus_cfg_long(const struct modbus_cfg_reader *r, const char *key, long lo, long hi,
                           long *out)
{
    const char *where, *v = modbus_cfg_get(r, key, &where);
    if (!v)
        return MODBUS_DRIVE_OK;
    long n;
    if (config_parse_integer(v, &n, NULL, 0) != 0 || n < lo || n > hi) {
        char want[96];
        snprintf(want, sizeof(want), "expected a whole number from %ld to %ld", lo, hi);
        return modbus_cfg_bad(r, where, key, v, want);
    }
    *out = n;
    return MODBUS_DRIVE_OK;
}

/* A finite number key; untouched when absent. */
static int modbus_cfg_double(const struct modbus_cfg_reader *r, const char *key, bool positive,
                             double *out)
{
    const char *where, *v = modbus_cfg_get(r, key, &where);
    if (!v)
        return MODBUS_DRIVE_OK;
    double x;
    if (config_parse_number(v, &x, NULL, 0) != 0 || (positive ? x <= 0.0 : x == 0.0))
        return modbus_cfg_bad(r, where, key, v, positive ? "expected a number above 0"
                                                         : "expected a non-zero number");
    *out = x;
    return MODBUS_DRIVE_OK;
}

/* A word from a list (case-insensitive), stored as its index; untouched when absent. */
static int modbus_cfg_word(const struct modbus_cfg_reader *r, const char *key,
                           const char *const *words, int nwords, const char *expected, int *out)
{
    const char *where, *v = modbus_cfg_get(r, key, &where);
    if (!v)
        return MODBUS_DRIVE_OK;
    for (int i = 0; i < nwords; i++)
        if (!strcasecmp(v, words[i])) {
            *out = i;
            return MODBUS_DRIVE_OK;
        }
    return modbus_cfg_bad(r, where, key, v, expected);
}

/* A string key copied into buf; untouched when absent. */
static int modbus_cfg_string(const struct modbus_cfg_reader *r, const char *key, char *buf,
                             size_t len)
{
    const char *where, *v = modbus_cfg_get(r, key, &where);
    if (!v)
        return MODBUS_DRIVE_OK;
    if (!v[0] || strlen(v) >= len)
        return modbus_cfg_bad(r, where, key, v, "expected a non-empty, shorter value");
    snprintf(buf, len, "%s", v);
    return MODBUS_DRIVE_OK;
}

/* Address keys: transport, host and port (PORT, else BASE_PORT + n), serial settings, unit. */
static int modbus_cfg_address(const struct modbus_cfg_reader *r, struct modbus_drive_cfg *c)
{
    static const char *const transports[] = { "tcp", "rtu" };
    static const char *const parities[] = { "N", "E", "O" };
    int t = (int)c->transport, par = 0, rc;
    long port = -1, base = -1, baud = c->baud, data = c->data_bits, stop = c->stop_bits;
    long unit = c->unit;
    if ((rc = modbus_cfg_word(r, "TRANSPORT", transports, 2, "expected tcp or rtu", &t)) ||
        (rc = modbus_cfg_string(r, "HOST", c->host, sizeof(c->host))) ||
        (rc = modbus_cfg_long(r, "PORT", 1, 65535, &port)) ||
        (rc = modbus_cfg_long(r, "BASE_PORT", 1, 65535 - c->index, &base)) ||
        (rc = modbus_cfg_string(r, "DEVICE", c->device, sizeof(c->device))) ||
        (rc = modbus_cfg_long(r, "BAUD", 50, 4000000, &baud)) ||
        (rc = modbus_cfg_word(r, "PARITY", parities, 3, "expected N, E or O", &par)) ||
        (rc = modbus_cfg_long(r, "DATA_BITS", 5, 8, &data)) ||
        (rc = modbus_cfg_long(r, "STOP_BITS", 1, 2, &stop)) ||
        (rc = modbus_cfg_long(r, "UNIT", 0, 255, &unit)))
        return rc;
    /* A drive's own PORT wins; BASE_PORT numbers the drives; a common PORT comes last. */
    bool own_port = r->get(r->ctx, r->drive_section, "PORT") != NULL;
    c->transport = (enum modbus_transport)t;
    c->port = own_port || base < 0 ? (port > 0 ? (int)port : c->port) : (int)(base + c->index);
    c->baud = (int)baud;
    c->parity = parities[par][0];
    c->data_bits = (int)data;
    c->stop_bits = (int)stop;
    c->unit = (int)unit;
    if (c->transport == MODBUS_DRIVE_RTU && !c->device[0]) {
        snprintf(r->err, r->errlen, "%s: [%s] TRANSPORT = rtu needs DEVICE (e.g. /dev/ttyUSB0)",
                 r->file ? r->file : "INI", r->drive_section);
        return MODBUS_DRIVE_ERR_CONFIG;
    }
    return MODBUS_DRIVE_OK;
}

/* Register map, word order, scaling, timing and exchange keys. */
static int modbus_cfg_data(const struct modbus_cfg_reader *r, struct modbus_drive_cfg *c)
{
    static const char *const orders[] = { "high-first", "low-first" };
    static const char *const exchanges[] = { "fc23", "separate" };
    long ctl = c->map.control, tgt = c->map.target, st = c->map.status, act = c->map.actual;
    long period = c->period_ns;
    double timeout_ms = c->timeout_us / 1000.0;
    int order = (int)c->map.order, ex = (int)c->exchange, rc;
    if ((rc = modbus_cfg_long(r, "REG_CONTROL", 0, 65535, &ctl)) ||
        (rc = modbus_cfg_long(r, "REG_TARGET", 0, 65534, &tgt)) ||
        (rc = modbus_cfg_long(r, "REG_STATUS", 0, 65535, &st)) ||
        (rc = modbus_cfg_long(r, "REG_ACTUAL", 0, 65534, &act)) ||
        (rc = modbus_cfg_word(r, "WORD_ORDER", orders, 2, "expected high-first or low-first",
                              &order)) ||
        (rc = modbus_cfg_double(r, "COUNTS_PER_MM", false, &c->counts_per_mm)) ||
        (rc = modbus_cfg_long(r, "SETPOINT_PERIOD", 10000, 1000000000, &period)) ||
        (rc = modbus_cfg_double(r, "TIMEOUT", true, &timeout_ms)) ||
        (rc = modbus_cfg_word(r, "EXCHANGE", exchanges, 2, "expected fc23 or separate", &ex)))
        return rc;
    c->map.control = (int)ctl;
    c->map.target = (int)tgt;
    c->map.status = (int)st;
    c->map.actual = (int)act;
    c->map.order = (enum modbus_word_order)order;
    c->period_ns = period;
    c->timeout_us = lround(timeout_ms * 1000.0);
    if (c->timeout_us < 1)
        c->timeout_us = 1;
    c->exchange = (enum modbus_exchange)ex;
    return MODBUS_DRIVE_OK;
}

/* Fills cfg for drive `index` (see modbus_cfg.h). */
int modbus_cfg_read(struct modbus_drive_cfg *cfg, int index, const char *section,
                    modbus_ini_get_fn get, void *ctx, const char *file, char *err,
                    size_t errlen)
{
    struct modbus_cfg_reader r = { section, "", get, ctx, file, err, errlen };
    snprintf(r.drive_section, sizeof(r.drive_section), "%s_DRIVE_%d", section, index);
    modbus_drive_cfg_default(cfg, index);
    int rc = modbus_cfg_address(&r, cfg);
    if (!rc)
        rc = modbus_cfg_data(&r, cfg);
    return rc;
}

/* [<SECTION>] DRIVES (see modbus_cfg.h). */
int modbus_cfg_drive_count(const char *section, modbus_ini_get_fn get, void *ctx,
                           const char *file, int def, int max, char *err, size_t errlen)
{
    const char *v = get(ctx, section, "DRIVES");
    if (!v)
        return def;
    long n;
    if (config_parse_integer(v, &n, NULL, 0) != 0 || n < 1 || n > max) {
        snprintf(err, errlen, "%s: [%s] DRIVES = %s: expected a whole number from 1 to %d",
                 file ? file : "INI", section, v, max);
        return -1;
    }
    return (int)n;
}
