/* inifile.c: the one INI reader (libinih's ini_parse_stream with a line-counting reader). */
#include "common/inifile.h"

#include <errno.h>
#include <ini.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const char *const inifile_msgs[INIFILE_STATUS_COUNT] = {
    [INIFILE_OK] = "ok",
    [INIFILE_ERR_IO] = "the INI file cannot be read",
    [INIFILE_ERR_NOMEM] = "out of memory",
    [INIFILE_ERR_SYNTAX] = "the INI file has a line that cannot be read",
};

/* The text of a status. */
const char *inifile_strerror(int status)
{
    if (status < 0 || status >= INIFILE_STATUS_COUNT)
        return "unknown INI file status";
    return inifile_msgs[status];
}

/* State of one parse: the open file, the line being parsed and what went wrong. */
struct inifile_reader {
    struct inifile *ini;
    FILE *f;
    int line;                /* number of the line handed to libinih last */
    int long_line;           /* first line too long for libinih's buffer, 0 if none */
    int limit;               /* longest line libinih takes whole, characters */
    int nomem;               /* an allocation failed */
};

/* libinih's line reader: fgets that counts lines. libinih parses what does not fit its
 * buffer as a line of its own, so a line that fills the buffer without its newline stops
 * the parse and is reported instead (a CR LF ending that just misses the buffer is fine). */
static char *inifile_read_line(char *str, int num, void *stream)
{
    struct inifile_reader *rd = stream;
    if (rd->long_line || !fgets(str, num, rd->f))
        return NULL;
    rd->line++;
    rd->limit = num - 2;
    size_t n = strlen(str);
    if (n == 0 || str[n - 1] == '\n' || n + 1 < (size_t)num)
        return str;   /* a whole line, or the last one of the file without its newline */
    int c = getc(rd->f);
    if (c == '\n' && str[n - 1] == '\r')
        return str;
    rd->long_line = rd->line;
    return NULL;
}

/* libinih's handler: stores one entry with its line, repeated keys included. */
static int inifile_store(void *user, const char *section, const char *key, const char *value)
{
    struct inifile_reader *rd = user;
    struct inifile *ini = rd->ini;
    if (ini->n == ini->cap) {
        size_t cap = ini->cap ? 2 * ini->cap : 64;
        struct inifile_entry *p = realloc(ini->items, cap * sizeof *p);
        if (!p) {
            rd->nomem = 1;
            return 0;
        }
        ini->items = p;
        ini->cap = cap;
    }
    struct inifile_entry *e = &ini->items[ini->n];
    e->section = strdup(section);
    e->key = strdup(key);
    e->value = strdup(value);
    e->line = rd->line;
    if (!e->section || !e->key || !e->value) {
        free(e->section);
        free(e->key);
        free(e->value);
        rd->nomem = 1;
        return 0;
    }
    ini->n++;
    return 1;
}

/* Frees every entry and the paths. */
void inifile_free(struct inifile *ini)
{
    for (size_t i = 0; i < ini->n; i++) {
        free(ini->items[i].section);
        free(ini->items[i].key);
        free(ini->items[i].value);
    }
    free(ini->items);
    free(ini->path);
    free(ini->dir);
    memset(ini, 0, sizeof *ini);
}

/* Keeps the path and its folder ("." for a bare name, "/" for a file at the root). */
static int inifile_set_path(struct inifile *ini, const char *path)
{
    const char *slash = strrchr(path, '/');
    ini->path = strdup(path);
    ini->dir = slash ? strndup(path, (size_t)(slash - path) + (slash == path)) : strdup(".");
    return ini->path && ini->dir ? 0 : -1;
}

/* Formats err (when given) and returns status. */
static int inifile_fail(struct inifile *ini, int status, char *err, size_t errlen,
                        const char *fmt, ...) __attribute__((format(printf, 5, 6)));
static int inifile_fail(struct inifile *ini, int status, char *err, size_t errlen,
                        const char *fmt, ...)
{
    inifile_free(ini);
    if (err && errlen) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, errlen, fmt, ap);
        va_end(ap);
    }
    return status;
}

/* Reads the file; the first bad line (too long or unreadable) is the one reported. */
int inifile_load(struct inifile *ini, const char *path, char *err, size_t errlen)
{
    inifile_free(ini);
    struct inifile_reader rd = { .ini = ini, .f = fopen(path, "r") };
    if (!rd.f)
        return inifile_fail(ini, INIFILE_ERR_IO, err, errlen, "cannot open INI file '%s': %s",
                            path, strerror(errno));
    int rc = ini_parse_stream(inifile_read_line, &rd, inifile_store, &rd);
    int read_error = ferror(rd.f);
    fclose(rd.f);
    if (rd.nomem || rc == -2)
        return inifile_fail(ini, INIFILE_ERR_NOMEM, err, errlen, "out of memory reading INI "
                            "file '%s'", path);
    if (rc > 0 && (!rd.long_line || rc < rd.long_line))
        return inifile_fail(ini, INIFILE_ERR_SYNTAX, err, errlen, "%s:%d: this line is not a "
                            "[SECTION] header, a KEY = VALUE line or a comment", path, rc);
    if (rd.long_line)
        return inifile_fail(ini, INIFILE_ERR_SYNTAX, err, errlen, "%s:%d: line longer than %d "
                            "characters (the INI reader's limit)", path, rd.long_line,
                            rd.limit);
    if (read_error || rc != 0)
        return inifile_fail(ini, INIFILE_ERR_IO, err, errlen, "cannot read INI file '%s'",
                            path);
    if (inifile_set_path(ini, path) != 0)
        return inifile_fail(ini, INIFILE_ERR_NOMEM, err, errlen, "out of memory reading INI "
                            "file '%s'", path);
    return INIFILE_OK;
}

/* The n-th [section]key entry, or NULL. */
static const struct inifile_entry *inifile_find(const struct inifile *ini, const char *section,
                                                const char *key, int n)
{
    for (size_t i = 0; i < ini->n; i++) {
        const struct inifile_entry *e = &ini->items[i];
        if (!strcmp(e->section, section) && !strcmp(e->key, key) && n-- == 0)
            return e;
    }
    return NULL;
}

/* The n-th occurrence's value, or NULL. */
const char *inifile_get_n(const struct inifile *ini, const char *section, const char *key,
                          int n)
{
    const struct inifile_entry *e = inifile_find(ini, section, key, n);
    return e ? e->value : NULL;
}

/* The first occurrence's value, or NULL. */
const char *inifile_get(const struct inifile *ini, const char *section, const char *key)
{
    return inifile_get_n(ini, section, key, 0);
}

/* The first occurrence's line, 0 when absent. */
int inifile_line(const struct inifile *ini, const char *section, const char *key)
{
    const struct inifile_entry *e = inifile_find(ini, section, key, 0);
    return e ? e->line : 0;
}

const char *inifile_path(const struct inifile *ini)
{
    return ini->path;
}

const char *inifile_dir(const struct inifile *ini)
{
    return ini->dir;
}

int inifile_resolve(const char *dir, const char *value, char *out, size_t len)
{
    int n = value[0] == '/' || !dir || !dir[0] ? snprintf(out, len, "%s", value)
                                               : snprintf(out, len, "%s/%s", dir, value);
    return n < 0 || (size_t)n >= len ? -1 : 0;
}

int inifile_api_socket(const char *value, const char *dir, char *out, size_t len)
{
    const char *xdg = getenv("XDG_RUNTIME_DIR");
    if (value && value[0])
        return inifile_resolve(dir, value, out, len) ? -1 : INIFILE_SOCKET_INI;
    int n = xdg && xdg[0] ? snprintf(out, len, "%s/hexcnc.sock", xdg)
                          : snprintf(out, len, "/tmp/hexcnc-%u/hexcnc.sock", (unsigned)getuid());
    if (n < 0 || (size_t)n >= len)
        return -1;
    return xdg && xdg[0] ? INIFILE_SOCKET_XDG : INIFILE_SOCKET_TMP;
}

/* inifile_get for callers that hold the file as a void *. */
const char *inifile_config_get(void *ctx, const char *section, const char *key)
{
    return inifile_get(ctx, section, key);
}

/* Prefixes a message with the file and, when it starts with a key of the file, its line. */
char *inifile_locate_msg(const struct inifile *ini, const char *msg, char *out, size_t len)
{
    char section[64], key[64] = "";
    int line = 0;
    if (sscanf(msg, "[%63[^]]] %63[^ :=]", section, key) == 2)
        line = inifile_line(ini, section, key);
    for (size_t i = 0; line == 0 && key[0] && i < ini->n; i++)
        if (!strcmp(ini->items[i].section, section))    /* a missing key: its section's */
            line = ini->items[i].line;                   /* first line, as config_check */
    if (!ini->path)
        snprintf(out, len, "%s", msg);
    else if (line > 0)
        snprintf(out, len, "%s:%d: %s", ini->path, line, msg);
    else
        snprintf(out, len, "%s: %s", ini->path, msg);
    return out;
}
