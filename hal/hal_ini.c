/* hal_ini.c: the runtime's INI file (common/inifile.c, checked by common/config.h) and typed
 * readers (common/config_value.c's rules). */
#include <stdlib.h>
#include <string.h>

#include "common/config.h"
#include "hal/hal_priv.h"

/* Frees the INI entries and paths. */
void hal_ini_free(struct hal *h)
{
    inifile_free(&h->ini);
}

/* Reads an INI file, replacing any read before (common/inifile.c: lines kept for messages). */
int hal_load_ini(struct hal *h, const char *path)
{
    char err[sizeof h->err];
    int st = inifile_load(&h->ini, path, err, sizeof err);
    if (st == INIFILE_OK)
        return HAL_OK;
    int hst = st == INIFILE_ERR_NOMEM ? HAL_ERR_NOMEM
            : st == INIFILE_ERR_SYNTAX ? HAL_ERR_SYNTAX : HAL_ERR_IO;
    return hal_error(h, hst, "%s", err);
}

/* Reads the INI and checks it whole against the key table. */
int hal_load_machine_ini(struct hal *h, const char *path)
{
    int st = hal_load_ini(h, path);
    if (st != HAL_OK)
        return st;
    char err[sizeof h->err];
    if (config_check(&h->ini, err, sizeof err) == CONFIG_OK)
        return HAL_OK;
    inifile_free(&h->ini);
    return hal_error(h, HAL_ERR_SYNTAX, "%s", err);
}

/* The n-th occurrence of [section]key, or NULL. */
const char *hal_ini_get_n(const struct hal *h, const char *section, const char *key, int n)
{
    return inifile_get_n(&h->ini, section, key, n);
}

/* The first [section]key, or NULL. */
const char *hal_ini_get(const struct hal *h, const char *section, const char *key)
{
    return inifile_get(&h->ini, section, key);
}

/* hal_ini_get through a void * (kins_config, interp_setup, modbus_cfg). */
const char *hal_ini_lookup(void *h, const char *section, const char *key)
{
    return hal_ini_get(h, section, key);
}

const char *hal_ini_path(const struct hal *h)
{
    return inifile_path(&h->ini);
}

const char *hal_ini_dir(const struct hal *h)
{
    return inifile_dir(&h->ini);
}

/* The INI file itself, for lines in messages (inifile_line, inifile_locate_msg). */
const struct inifile *hal_ini_file(const struct hal *h)
{
    return &h->ini;
}

/* The value text, or NULL with out-of-band default handling left to the caller. */
static const char *hal_ini_value(struct hal *h, const char *section, const char *key)
{
    const char *v = hal_ini_get(h, section, key);
    if (!v)
        hal_error(h, HAL_ERR_NOT_FOUND, "%s: [%s]%s is missing",
                  hal_ini_path(h) ? hal_ini_path(h) : "(no INI file)", section, key);
    return v;
}

/* [section]key as a floating-point number. */
int hal_ini_double(struct hal *h, const char *section, const char *key, double def, double *out)
{
    const char *v = hal_ini_value(h, section, key);
    *out = def;
    if (!v)
        return HAL_ERR_NOT_FOUND;
    double d;
    if (config_parse_number(v, &d, NULL, 0) != 0)
        return hal_error(h, HAL_ERR_SYNTAX, "%s:%d: [%s]%s = '%s' is not a number",
                         hal_ini_path(h), inifile_line(&h->ini, section, key), section, key, v);
    *out = d;
    return HAL_OK;
}

/* [section]key as a whole decimal number. */
int hal_ini_int(struct hal *h, const char *section, const char *key, long def, long *out)
{
    const char *v = hal_ini_value(h, section, key);
    *out = def;
    if (!v)
        return HAL_ERR_NOT_FOUND;
    long n;
    if (config_parse_integer(v, &n, NULL, 0) != 0)
        return hal_error(h, HAL_ERR_SYNTAX, "%s:%d: [%s]%s = '%s' is not a whole number",
                         hal_ini_path(h), inifile_line(&h->ini, section, key), section, key, v);
    *out = n;
    return HAL_OK;
}
