/* named.c: named parameters #<name> (local) and #<_name> (global), kept as LinuxCNC keeps them. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "interp/interp_int.h"

#define NAMED_MAX 100000         /* distinct names in one interpreter: more is a runaway program */

/* FNV-1a over the name's bytes (names are already lowercase and without spaces). */
static uint32_t name_hash(const char *s, int len)
{
    uint32_t h = 2166136261u;
    for (int i = 0; i < len; i++)
        h = (h ^ (unsigned char)s[i]) * 16777619u;
    return h;
}

/* The slot of the hash index holding name, or the empty slot where it would go. */
static size_t find_slot(const struct named_table *t, const char *s, int len, uint32_t h)
{
    size_t mask = t->nslot - 1, i = h & mask;
    for (;;) {
        int e = t->slot[i];
        if (e < 0)
            return i;
        const struct named_entry *en = &t->e[e];
        if (en->hash == h && en->len == len && memcmp(en->name, s, (size_t)len) == 0)
            return i;
        i = (i + 1) & mask;
    }
}

/* The entry of name, or -1 when it was never set. */
static int lookup(const struct named_table *t, const char *s, int len)
{
    if (t->n == 0)
        return -1;
    return t->slot[find_slot(t, s, len, name_hash(s, len))];
}

/* Empties the hash index and enters every name again. */
static void fill_index(struct named_table *t)
{
    for (size_t i = 0; i < t->nslot; i++)
        t->slot[i] = -1;
    for (size_t e = 0; e < t->n; e++)
        t->slot[find_slot(t, t->e[e].name, t->e[e].len, t->e[e].hash)] = (int)e;
}

/* A new hash index of nslot slots (a power of two, more than twice the names). */
static int reindex(struct named_table *t, size_t nslot)
{
    int *slot = malloc(nslot * sizeof *slot);
    if (!slot)
        return -1;
    free(t->slot);
    t->slot = slot;
    t->nslot = nslot;
    fill_index(t);
    return 0;
}

/* Adds name with value 0 and returns its entry (entries never move: the index refers to them
 * by number, so a setting read earlier on the line still lands after the table grew). */
static int add(struct interp *in, const char *s, int len, int col, int *entry)
{
    struct named_table *t = &in->named;
    if (t->n >= NAMED_MAX)
        return interp_fail(in, INTERP_ERR_PARAM, col, "more than %d named parameters",
                           NAMED_MAX);
    if (t->n == t->cap) {
        size_t cap = t->cap ? t->cap * 2 : 16;
        struct named_entry *e = realloc(t->e, cap * sizeof *e);
        if (!e)
            return interp_fail(in, INTERP_ERR_NOMEM, col, "out of memory for named parameters");
        t->e = e;
        t->cap = cap;
    }
    if ((t->n + 1) * 2 > t->nslot && reindex(t, t->nslot ? t->nslot * 2 : 32))
        return interp_fail(in, INTERP_ERR_NOMEM, col, "out of memory for named parameters");
    char *name = malloc((size_t)len + 1);
    if (!name)
        return interp_fail(in, INTERP_ERR_NOMEM, col, "out of memory for named parameters");
    memcpy(name, s, (size_t)len);
    name[len] = 0;
    struct named_entry *en = &t->e[t->n];
    en->name = name;
    en->len = len;
    en->hash = name_hash(s, len);
    en->value = 0.0;
    t->slot[find_slot(t, s, len, en->hash)] = (int)t->n;
    *entry = (int)t->n++;
    return 0;
}

/* Reads "<name>" at norm[*pos] == '<' (after a '#' at column col): name points into the line. */
int interp_read_name(struct interp *in, int *pos, int col, const char **name, int *len)
{
    const char *s = in->norm + *pos + 1;
    const char *end = strchr(s, '>');
    if (!end)
        return interp_fail(in, INTERP_ERR_SYNTAX, col, "named parameter not closed: '>' missing "
                           "after #<%.40s", s);
    if (end == s)
        return interp_fail(in, INTERP_ERR_SYNTAX, col, "named parameter without a name: #<> "
                           "(write #<name>, or #<_name> for a global one)");
    if (end - s > INTERP_NAME_MAX)
        return interp_fail(in, INTERP_ERR_SYNTAX, col, "named parameter name longer than %d "
                           "characters", INTERP_NAME_MAX);
    *name = s;
    *len = (int)(end - s);
    *pos += *len + 2;
    return 0;
}

/* The value of #<name>: a predefined one, or one set before; reading any other is an error. */
/* #<_ini[SECTION]KEY> and #<_hal[name]>: 1 with *out set, 0 when name is neither, -1 when
 * it is one whose value cannot be had (why in why). The section and key are looked up in
 * upper case (the interpreter reads names in lower case), as LinuxCNC does; only a number
 * is a value. A HAL pin or signal is read from the running machine; without one it is 0. */
static int outside_value(const struct interp *in, const char *name, int len, double *out,
                         char *why, size_t wlen)
{
    int ini = len > 5 && !strncmp(name, "_ini[", 5), hal = len > 5 && !strncmp(name, "_hal[", 5);
    if (!ini && !hal)
        return 0;
    const char *close = memchr(name + 5, ']', (size_t)(len - 5));
    if (!close || (hal && close != name + len - 1) || (ini && close == name + len - 1)) {
        snprintf(why, wlen, "write #<_ini[SECTION]KEY> or #<_hal[pin]>");
        return -1;
    }
    char a[128], b[128];
    int na = (int)(close - (name + 5)), nb = len - (int)(close - name) - 1;
    if (na <= 0 || na >= (int)sizeof a || nb >= (int)sizeof b) {
        snprintf(why, wlen, "the name is empty or too long");
        return -1;
    }
    for (int i = 0; i < na; i++)
        a[i] = ini ? (char)toupper((unsigned char)name[5 + i]) : name[5 + i];
    a[na] = 0;
    for (int i = 0; i < nb; i++)
        b[i] = (char)toupper((unsigned char)close[1 + i]);
    b[nb] = 0;
    if (hal) {
        if (!in->hal_fn) {
            *out = 0;     /* no machine to read: `hexcnc interp` and `check` take 0 */
            return 1;
        }
        if (in->hal_fn(in->hal_ctx, a, out) == 0)
            return 1;
        snprintf(why, wlen, "the machine has no HAL pin or parameter '%.100s'", a);
        return -1;
    }
    const char *v = in->ini_get ? in->ini_get(in->ini_ctx, a, b) : NULL;
    if (!v) {
        snprintf(why, wlen, in->ini_get ? "the INI file has no [%.40s] %.60s" : "no INI file is "
                 "given (hexcnc interp -i CONFIG.ini)", a, b);
        return -1;
    }
    char *end = NULL;
    errno = 0;
    double d = strtod(v, &end);
    const char *rest = end ? end : v;
    while (isspace((unsigned char)*rest))
        rest++;
    if (rest == v || *rest || errno || !isfinite(d)) {
        snprintf(why, wlen, "[%.40s] %.60s = %.60s is not a number", a, b, v);
        return -1;
    }
    *out = d;
    return 1;
}

int interp_named_get(struct interp *in, const char *name, int len, int col, double *out)
{
    if (name[0] == '_' && interp_predefined(in, name, len, out))
        return 0;
    char why[200];
    int o = name[0] == '_' ? outside_value(in, name, len, out, why, sizeof why) : 0;
    if (o > 0)
        return 0;
    if (o < 0)
        return interp_fail(in, INTERP_ERR_PARAM, col, "named parameter #<%.*s> is not "
                           "defined: %s", len > 60 ? 60 : len, name, why);
    int e = lookup(&in->named, name, len);
    if (e < 0)
        return interp_fail(in, INTERP_ERR_PARAM, col, "named parameter #<%.*s> is not defined "
                           "(set it first, e.g. #<%.*s>=0)", len > 60 ? 60 : len, name,
                           len > 60 ? 60 : len, name);
    *out = in->named.e[e].value;
    return 0;
}

/* Whether #<name> can be read now (EXISTS[#<name>]). */
int interp_named_exists(struct interp *in, const char *name, int len)
{
    double v;
    char why[200];
    if (name[0] == '_' && (interp_predefined(in, name, len, &v) ||
                           outside_value(in, name, len, &v, why, sizeof why) > 0))
        return 1;
    return lookup(&in->named, name, len) >= 0;
}

/* The entry a setting #<name>=... will write. As in LinuxCNC a new name exists (as 0) from
 * here on, its value landing after the line; predefined names are read-only. */
int interp_named_target(struct interp *in, const char *name, int len, int col, int *entry)
{
    double v;
    if (name[0] == '_' && interp_predefined(in, name, len, &v))
        return interp_fail(in, INTERP_ERR_PARAM, col, "#<%.*s> is read-only (it tells the "
                           "interpreter's state and cannot be set)", len, name);
    if (len > 5 && (!strncmp(name, "_ini[", 5) || !strncmp(name, "_hal[", 5)))
        return interp_fail(in, INTERP_ERR_PARAM, col, "#<%.*s> is read-only (it reads the "
                           "machine's %s)", len, name, name[1] == 'i' ? "INI file" : "HAL");
    *entry = lookup(&in->named, name, len);
    if (*entry >= 0)
        return 0;
    return add(in, name, len, col, entry);
}

/* Writes a setting's value (after its line has been read). */
void interp_named_set(struct interp *in, int entry, double v)
{
    in->named.e[entry].value = v;
}

/* Forgets the local names (those not starting with '_') at the start of a program. */
void interp_named_clear_locals(struct interp *in)
{
    struct named_table *t = &in->named;
    size_t k = 0;
    for (size_t i = 0; i < t->n; i++) {
        if (t->e[i].name[0] == '_')
            t->e[k++] = t->e[i];
        else
            free(t->e[i].name);
    }
    if (k == t->n)
        return;
    t->n = k;
    fill_index(t);
}

/* A subroutine call starts with no local names: the caller's locals (those not starting with
 * '_') move out of the table into *saved (the caller keeps them in its call frame). Returns
 * 0, or -1 when out of memory (nothing moved). */
int interp_named_push_locals(struct interp *in, struct named_entry **saved, size_t *nsaved)
{
    struct named_table *t = &in->named;
    size_t nloc = 0;
    for (size_t i = 0; i < t->n; i++)
        nloc += t->e[i].name[0] != '_';
    *saved = NULL;
    *nsaved = 0;
    if (nloc == 0)
        return 0;
    struct named_entry *out = malloc(nloc * sizeof *out);
    if (!out)
        return -1;
    size_t k = 0, j = 0;
    for (size_t i = 0; i < t->n; i++) {
        if (t->e[i].name[0] == '_')
            t->e[k++] = t->e[i];
        else
            out[j++] = t->e[i];
    }
    t->n = k;
    fill_index(t);
    *saved = out;
    *nsaved = nloc;
    return 0;
}

/* The return of a call: the subroutine's locals are freed and the caller's come back.
 * Returns 0, or -1 when out of memory (the caller's locals are then lost). */
int interp_named_pop_locals(struct interp *in, struct named_entry *saved, size_t nsaved)
{
    interp_named_clear_locals(in);
    struct named_table *t = &in->named;
    size_t need = t->n + nsaved, nslot = t->nslot ? t->nslot : 32;
    while (need * 2 > nslot)
        nslot *= 2;
    int rc = 0;
    if (need > t->cap) {
        struct named_entry *e = realloc(t->e, need * sizeof *e);
        if (e) {
            t->e = e;
            t->cap = need;
        } else {
            rc = -1;
        }
    }
    if (!rc && nslot != t->nslot && reindex(t, nslot))
        rc = -1;
    for (size_t i = 0; i < nsaved; i++) {
        if (rc)
            free(saved[i].name);
        else
            t->e[t->n++] = saved[i];
    }
    if (!rc)
        fill_index(t);
    free(saved);
    return rc;
}

/* Frees every name. */
void interp_named_free(struct interp *in)
{
    struct named_table *t = &in->named;
    for (size_t i = 0; i < t->n; i++)
        free(t->e[i].name);
    free(t->e);
    free(t->slot);
    memset(t, 0, sizeof *t);
}
