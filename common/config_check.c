/* config_check.c: checks a whole INI file against the key table (config_keys.c) once, at
 * load: unknown sections and keys with the closest known name, values, required keys. */
#include "common/config.h"

#include <ctype.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static const char *const config_msgs[CONFIG_STATUS_COUNT] = {
    [CONFIG_OK] = "ok",
    [CONFIG_ERR_VALUE] = "a configuration value is wrong",
    [CONFIG_ERR_UNKNOWN] = "unknown configuration section or key",
    [CONFIG_ERR_MISSING] = "a required configuration key is missing",
    [CONFIG_ERR_FILE] = "the INI file cannot be read",
};

const char *config_strerror(int status)
{
    if (status < 0 || status >= CONFIG_STATUS_COUNT)
        return "unknown configuration status";
    return config_msgs[status];
}

/* Does a concrete name (JOINT_3) match a table name (JOINT_#)? '#' takes one to three
 * digits, a final '*' any non-empty rest (LinuxCNC's AXIS_X). */
static int config_name_match(const char *pattern, const char *name)
{
    for (; *pattern; pattern++, name++) {
        if (pattern[0] == '*' && !pattern[1])
            return *name != '\0';
        if (*pattern == '#') {
            size_t n = strspn(name, "0123456789");
            if (n == 0 || n > 3)
                return 0;
            name += n - 1;
        } else if (*pattern != *name) {
            return 0;
        }
    }
    return *name == '\0';
}

const struct config_section *config_find_section(const char *section)
{
    for (int i = 0; i < config_nsections; i++)
        if (config_name_match(config_sections[i].name, section))
            return &config_sections[i];
    return NULL;
}

/* The section whose keys a section takes: [MODBUS_DRIVE_#] takes [MODBUS]'s. */
static const char *config_key_section(const char *section)
{
    return config_name_match("MODBUS_DRIVE_#", section) ? "MODBUS" : section;
}

const struct config_key *config_find(const char *section, const char *key)
{
    section = config_key_section(section);
    for (int i = 0; i < config_nkeys; i++)
        if (config_name_match(config_keys[i].section, section) &&
            config_name_match(config_keys[i].key, key))
            return &config_keys[i];
    return NULL;
}

/* Edit distance counting an insertion, a deletion, a change or two swapped neighbours as
 * one edit (optimal string alignment), case-insensitive; names over 63 characters are far. */
int config_edit_distance(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    if (la > 63 || lb > 63)
        return 99;
    int d[64][64];
    for (size_t i = 0; i <= la; i++)
        d[i][0] = (int)i;
    for (size_t j = 0; j <= lb; j++)
        d[0][j] = (int)j;
    for (size_t i = 1; i <= la; i++)
        for (size_t j = 1; j <= lb; j++) {
            int cost = strncasecmp(a + i - 1, b + j - 1, 1) != 0;
            int best = d[i - 1][j - 1] + cost;
            if (d[i - 1][j] + 1 < best)
                best = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < best)
                best = d[i][j - 1] + 1;
            if (i > 1 && j > 1 && !strncasecmp(a + i - 1, b + j - 2, 1) &&
                !strncasecmp(a + i - 2, b + j - 1, 1) && d[i - 2][j - 2] + 1 < best)
                best = d[i - 2][j - 2] + 1;
            d[i][j] = best;
        }
    return d[la][lb];
}

/* A table name shown for a concrete one: JOINT_# becomes JOINT_3 when name is JOINT_3x. */
static void config_instantiate(const char *pattern, const char *like, char *out, size_t len)
{
    const char *digits = like + strcspn(like, "0123456789");
    size_t nd = strspn(digits, "0123456789");
    const char *hash = strchr(pattern, '#');
    if (!hash || nd == 0 || nd > 3)
        snprintf(out, len, "%s", pattern);
    else
        snprintf(out, len, "%.*s%.*s%s", (int)(hash - pattern), pattern, (int)nd, digits,
                 hash + 1);
}

/* Between two names as close: the one that starts like the typed name ([LMC] is [LCM],
 * not [EMC]). */
static int config_better_tie(const char *typed, const char *name, const char *kept)
{
    return kept[0] && toupper((unsigned char)name[0]) == toupper((unsigned char)typed[0]) &&
           toupper((unsigned char)kept[0]) != toupper((unsigned char)typed[0]);
}

/* The closest known name within a third of its length (at least 2 edits), "" when none. */
static void config_suggest_key(const char *section, const char *key, char *out, size_t len)
{
    int best = 3 + (int)strlen(key) / 3;
    out[0] = '\0';
    section = config_key_section(section);
    for (int i = 0; i < config_nkeys; i++) {
        if (!config_name_match(config_keys[i].section, section))
            continue;
        char name[64];
        config_instantiate(config_keys[i].key, key, name, sizeof name);
        int d = config_edit_distance(key, name);
        if (d < best || (d == best && config_better_tie(key, name, out))) {
            best = d;
            snprintf(out, len, "%s", name);
        }
    }
}

static void config_suggest_section(const char *section, char *out, size_t len)
{
    int best = 3 + (int)strlen(section) / 3;
    out[0] = '\0';
    for (int i = 0; i < config_nsections; i++) {
        char name[64];
        config_instantiate(config_sections[i].name, section, name, sizeof name);
        int d = config_edit_distance(section, name);
        if (d < best || (d == best && config_better_tie(section, name, out))) {
            best = d;
            snprintf(out, len, "%s", name);
        }
    }
}

/* Checks one value against its key's type and range. */
int config_check_value(const struct config_key *k, const char *value, char *why,
                       size_t whylen)
{
    double x[16];
    long n;
    int b;
    char reason[160];
    switch (k->type) {
    case CONFIG_NUMBER:
    case CONFIG_INTEGER:
        if (k->type == CONFIG_NUMBER ? config_parse_number(value, x, reason, sizeof reason)
                                     : config_parse_integer(value, &n, reason, sizeof reason))
            break;
        if (k->type == CONFIG_INTEGER)
            x[0] = (double)n;
        if (config_in_range(x[0], k->range, reason, sizeof reason) == 0)
            return 0;
        break;
    case CONFIG_NUMBERS:
        if (config_parse_numbers(value, x, k->count, reason, sizeof reason) == 0)
            return 0;
        break;
    case CONFIG_BOOL:
        if (config_parse_bool(value, &b, reason, sizeof reason) == 0)
            return 0;
        break;
    case CONFIG_ENUM: {
        const char *p = k->range;
        size_t lv = strlen(value);
        while (*p) {
            size_t l = strcspn(p, "|");
            if (l == lv && !strncasecmp(p, value, l))
                return 0;
            p += l + (p[l] == '|');
        }
        snprintf(reason, sizeof reason, "expected one of %s", k->range);
        break;
    }
    case CONFIG_PATH:
        if (value[0])
            return 0;
        snprintf(reason, sizeof reason, "expected a file name");
        break;
    case CONFIG_STRING:
        return 0;
    }
    if (k->unit[0] && k->type != CONFIG_ENUM)
        snprintf(why, whylen, "%s (%s)", reason, k->unit);
    else
        snprintf(why, whylen, "%s", reason);
    return -1;
}

/* One check's output: every problem a line of err, the first problem's status. */
struct config_report {
    const struct inifile *ini;   /* the file checked */
    char *err;                   /* messages, one per line; may be NULL */
    size_t errlen, used;         /* its size and the characters written */
    int status;                  /* the first problem's status, CONFIG_OK when none */
};

/* Appends one "PATH:LINE: ..." line to err; keeps the first status. */
static void config_report(struct config_report *r, int status, int line, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static void config_report(struct config_report *r, int status, int line, const char *fmt, ...)
{
    if (!r->status)
        r->status = status;
    if (!r->err || r->used + 1 >= r->errlen)
        return;
    const char *path = inifile_path(r->ini) ? inifile_path(r->ini) : "INI";
    char *p = r->err + r->used;
    size_t room = r->errlen - r->used;
    int n = line > 0 ? snprintf(p, room, "%s%s:%d: ", r->used ? "\n" : "", path, line)
                     : snprintf(p, room, "%s%s: ", r->used ? "\n" : "", path);
    if (n < 0 || (size_t)n >= room) {
        r->used = r->errlen - 1;
        return;
    }
    va_list ap;
    va_start(ap, fmt);
    int m = vsnprintf(p + n, room - (size_t)n, fmt, ap);
    va_end(ap);
    r->used += (size_t)n + (m < 0 ? 0 : (size_t)m);
    if (r->used >= r->errlen)
        r->used = r->errlen - 1;
}

/* The entry's section kind, reporting an unknown section once (at its first entry). */
static const struct config_section *config_entry_section(struct config_report *r, size_t i)
{
    const struct inifile_entry *e = &r->ini->items[i];
    const struct config_section *s = config_find_section(e->section);
    if (s)
        return s;
    for (size_t j = 0; j < i; j++)
        if (!strcmp(r->ini->items[j].section, e->section))
            return NULL;   /* reported at its first key */
    char hint[64];
    config_suggest_section(e->section, hint, sizeof hint);
    config_report(r, CONFIG_ERR_UNKNOWN, e->line, "[%s]: unknown section%s%s%s", e->section,
                  hint[0] ? "; did you mean [" : "", hint, hint[0] ? "]?" : "");
    return NULL;
}

/* One KEY = VALUE: known, not repeated unless it may be, value right. */
static void config_check_entry(struct config_report *r, size_t i)
{
    const struct inifile_entry *e = &r->ini->items[i];
    const struct config_section *s = config_entry_section(r, i);
    if (!s || s->kind == CONFIG_FOREIGN)
        return;
    const struct config_key *k = config_find(e->section, e->key);
    if (!k) {
        if (s->kind == CONFIG_OPEN)
            return;
        char hint[64];
        config_suggest_key(e->section, e->key, hint, sizeof hint);
        config_report(r, CONFIG_ERR_UNKNOWN, e->line, "[%s] %s: unknown key%s%s%s", e->section,
                      e->key, hint[0] ? "; did you mean " : "", hint, hint[0] ? "?" : "");
        return;
    }
    if (!(k->flags & CONFIG_REPEAT) && inifile_get_n(r->ini, e->section, e->key, 0) !=
                                           e->value) {
        config_report(r, CONFIG_ERR_VALUE, e->line, "[%s] %s: given again (first at line %d); "
                      "give it once", e->section, e->key,
                      inifile_line(r->ini, e->section, e->key));
        return;
    }
    char why[256];
    if (!(k->flags & CONFIG_IGNORED) && config_check_value(k, e->value, why, sizeof why))
        config_report(r, CONFIG_ERR_VALUE, e->line, "[%s] %s = %s: %s", e->section, e->key,
                      e->value, why);
}

/* Required keys of every section present (once per section, at its first entry). */
static void config_check_required(struct config_report *r, size_t i)
{
    const struct inifile_entry *e = &r->ini->items[i];
    for (size_t j = 0; j < i; j++)
        if (!strcmp(r->ini->items[j].section, e->section))
            return;
    const char *ksec = config_key_section(e->section);
    if (ksec != e->section)
        return;   /* a drive section's keys come from [MODBUS] */
    for (int k = 0; k < config_nkeys; k++) {
        const struct config_key *key = &config_keys[k];
        if (!(key->flags & CONFIG_REQUIRED) || strchr(key->key, '#') ||
            !config_name_match(key->section, e->section) ||
            inifile_get(r->ini, e->section, key->key))
            continue;
        config_report(r, CONFIG_ERR_MISSING, e->line, "[%s] %s: missing; it has no default "
                      "(%s%s%s)", e->section, key->key, key->doc, key->unit[0] ? ", " : "",
                      key->unit);
    }
}

int config_check(const struct inifile *ini, char *err, size_t errlen)
{
    struct config_report r = { ini, err, errlen, 0, CONFIG_OK };
    if (err && errlen)
        err[0] = '\0';
    for (size_t i = 0; i < ini->n; i++)
        config_check_entry(&r, i);
    for (size_t i = 0; i < ini->n; i++) {
        const struct config_section *s = config_find_section(ini->items[i].section);
        if (s && s->kind != CONFIG_FOREIGN)
            config_check_required(&r, i);
    }
    return r.status;
}

int config_load(struct inifile *ini, const char *path, char *err, size_t errlen)
{
    if (inifile_load(ini, path, err, errlen) != INIFILE_OK)
        return CONFIG_ERR_FILE;
    int st = config_check(ini, err, errlen);
    if (st != CONFIG_OK)
        inifile_free(ini);
    return st;
}
