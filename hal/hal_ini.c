/* hal_ini.c: the INI file (libinih), every entry kept in order, and typed readers. */
#include <errno.h>
#include <ini.h>
#include <stdlib.h>
#include <string.h>

#include "hal/hal_priv.h"

/* Frees the INI entries and paths. */
void hal_ini_free(struct hal *h)
{
    for (int i = 0; i < h->nini; i++) {
        free(h->ini[i].section);
        free(h->ini[i].key);
        free(h->ini[i].value);
    }
    free(h->ini);
    free(h->ini_path);
    free(h->ini_dir);
    h->ini = NULL;
    h->nini = h->capini = 0;
    h->ini_path = h->ini_dir = NULL;
}

/* libinih callback: keeps every entry, repeated keys included (ini_parse is told to go on). */
static int hal_ini_handler(void *user, const char *section, const char *key, const char *value)
{
    struct hal *h = user;
    if (h->nini == h->capini) {
        int cap = h->capini ? h->capini * 2 : 64;
        struct hal_ini_entry *v = realloc(h->ini, (size_t)cap * sizeof *v);
        if (!v)
            return 0;
        h->ini = v;
        h->capini = cap;
    }
    struct hal_ini_entry *e = &h->ini[h->nini];
    e->section = hal_strdup(section);
    e->key = hal_strdup(key);
    e->value = hal_strdup(value);
    e->lineno = 0;
    if (!e->section || !e->key || !e->value) {
        free(e->section);
        free(e->key);
        free(e->value);
        return 0;
    }
    h->nini++;
    return 1;
}

/* libinih (as Debian builds it) reads lines of at most INI_MAX_LINE - 1 characters and
 * parses the rest of a longer line as a line of its own; say so instead. Returns the first
 * too-long line's number, 0 if none, -1 if the file cannot be opened. */
static int hal_ini_long_line(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    char *line = NULL;
    size_t cap = 0;
    ssize_t n;
    int lineno = 0, bad = 0;
    while (!bad && (n = getline(&line, &cap, f)) >= 0) {
        lineno++;
        while (n > 0 && (line[n - 1] == '\n' || line[n - 1] == '\r'))
            n--;
        if (n >= INI_MAX_LINE - 1)
            bad = lineno;
    }
    free(line);
    fclose(f);
    return bad;
}

/* Reads an INI file, replacing any read before. */
int hal_load_ini(struct hal *h, const char *path)
{
    hal_ini_free(h);
    errno = 0;
    int longl = hal_ini_long_line(path);
    if (longl == -1)
        return hal_error(h, HAL_ERR_IO, "cannot open INI file '%s': %s", path,
                         strerror(errno ? errno : ENOENT));
    if (longl > 0)
        return hal_error(h, HAL_ERR_SYNTAX, "%s:%d: line longer than %d characters (the INI "
                         "reader's limit)", path, longl, INI_MAX_LINE - 2);
    errno = 0;
    int r = ini_parse(path, hal_ini_handler, h);
    if (r == -1)
        return hal_error(h, HAL_ERR_IO, "cannot open INI file '%s': %s", path,
                         strerror(errno ? errno : ENOENT));
    if (r == -2) {
        hal_ini_free(h);
        return hal_error(h, HAL_ERR_NOMEM, "out of memory reading INI file '%s'", path);
    }
    if (r > 0) {
        hal_ini_free(h);
        return hal_error(h, HAL_ERR_SYNTAX, "%s:%d: this line is not a [SECTION] header, a "
                         "KEY = VALUE line or a comment", path, r);
    }
    h->ini_path = hal_strdup(path);
    const char *slash = strrchr(path, '/');
    h->ini_dir = slash ? strndup(path, (size_t)(slash - path + (slash == path))) : hal_strdup(".");
    if (!h->ini_path || !h->ini_dir) {
        hal_ini_free(h);
        return hal_error(h, HAL_ERR_NOMEM, "out of memory reading INI file '%s'", path);
    }
    return HAL_OK;
}

/* The n-th occurrence of [section]key, or NULL. */
const char *hal_ini_get_n(const struct hal *h, const char *section, const char *key, int n)
{
    for (int i = 0; i < h->nini; i++) {
        const struct hal_ini_entry *e = &h->ini[i];
        if (!strcmp(e->section, section) && !strcmp(e->key, key) && n-- == 0)
            return e->value;
    }
    return NULL;
}

/* The first [section]key, or NULL. */
const char *hal_ini_get(const struct hal *h, const char *section, const char *key)
{
    return hal_ini_get_n(h, section, key, 0);
}

const char *hal_ini_path(const struct hal *h)
{
    return h->ini_path;
}

const char *hal_ini_dir(const struct hal *h)
{
    return h->ini_dir;
}

/* The value text, or NULL with out-of-band default handling left to the caller. */
static const char *hal_ini_value(struct hal *h, const char *section, const char *key)
{
    const char *v = hal_ini_get(h, section, key);
    if (!v)
        hal_error(h, HAL_ERR_NOT_FOUND, "%s: [%s]%s is missing",
                  h->ini_path ? h->ini_path : "(no INI file)", section, key);
    return v;
}

/* [section]key as a floating-point number. */
int hal_ini_double(struct hal *h, const char *section, const char *key, double def, double *out)
{
    const char *v = hal_ini_value(h, section, key);
    *out = def;
    if (!v)
        return HAL_ERR_NOT_FOUND;
    char *end;
    errno = 0;
    double d = strtod(v, &end);
    if (end == v || *end || errno == ERANGE)
        return hal_error(h, HAL_ERR_SYNTAX, "%s: [%s]%s = '%s' is not a number", h->ini_path,
                         section, key, v);
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
    char *end;
    errno = 0;
    long n = strtol(v, &end, 10);
    if (end == v || *end || errno == ERANGE)
        return hal_error(h, HAL_ERR_SYNTAX, "%s: [%s]%s = '%s' is not a whole number",
                         h->ini_path, section, key, v);
    *out = n;
    return HAL_OK;
}
