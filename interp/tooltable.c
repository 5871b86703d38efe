/* tooltable.c: LinuxCNC-format tool table: parse, look up, wear, G10 L1 (file I/O: tooltable_file.c). */
#include "interp/tooltable.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/errbuf.h"

static const char *const tooltable_msgs[TOOLTABLE_STATUS_COUNT] = {
    [TOOLTABLE_OK] = "ok",
    [TOOLTABLE_ERR_IO] = "tool table file cannot be read or written",
    [TOOLTABLE_ERR_SYNTAX] = "tool table line does not parse",
    [TOOLTABLE_ERR_DUPLICATE] = "the same tool number appears twice in the tool table",
    [TOOLTABLE_ERR_FULL] = "the tool table is full",
    [TOOLTABLE_ERR_NO_TOOL] = "no such tool in the tool table",
    [TOOLTABLE_ERR_VALUE] = "tool diameter (with wear) is missing, zero or negative",
};

/* The text of a status. */
const char *tooltable_strerror(int status)
{
    if (status < 0 || status >= TOOLTABLE_STATUS_COUNT)
        return "unknown tool table status";
    return tooltable_msgs[status];
}

/* An empty table. */
void tooltable_init(struct tooltable *t)
{
    memset(t, 0, sizeof *t);
}

/* Index of tool `tool` in t, or -1 (const-friendly core of tooltable_find). */
static int tooltable_index(const struct tooltable *t, int tool)
{
    for (int i = 0; i < t->count; i++)
        if (t->tools[i].tool == tool)
            return i;
    return -1;
}

/* The entry of tool `tool`, or NULL. */
struct tool_entry *tooltable_find(struct tooltable *t, int tool)
{
    int i = tooltable_index(t, tool);
    return i < 0 ? NULL : &t->tools[i];
}

/* Adds or replaces an entry (tool numbers 1 .. TOOLTABLE_WEAR_BASE - 1). */
int tooltable_set(struct tooltable *t, const struct tool_entry *e)
{
    if (e->tool <= 0 || e->tool >= TOOLTABLE_WEAR_BASE)
        return TOOLTABLE_ERR_NO_TOOL;
    if (!(e->diameter_mm >= 0.0))
        return TOOLTABLE_ERR_VALUE;
    int i = tooltable_index(t, e->tool);
    if (i < 0) {
        if (t->count >= TOOLTABLE_MAX)
            return TOOLTABLE_ERR_FULL;
        i = t->count++;
    }
    t->tools[i] = *e;
    return TOOLTABLE_OK;
}

/* Sets the diameter wear delta of an existing tool. */
int tooltable_set_wear(struct tooltable *t, int tool, double wear_mm)
{
    struct tool_entry *e = tooltable_find(t, tool);
    if (!e)
        return TOOLTABLE_ERR_NO_TOOL;
    if (!isfinite(wear_mm))
        return TOOLTABLE_ERR_VALUE;
    e->wear_mm = wear_mm;
    return TOOLTABLE_OK;
}

/* G10 L1: nominal radius / length of tool p, or the wear of tool p - WEAR_BASE. */
int tooltable_g10_l1(struct tooltable *t, int p, int has_r, double r_mm, int has_z,
                     double z_mm)
{
    if (p > TOOLTABLE_WEAR_BASE) {
        if (has_z)
            return TOOLTABLE_ERR_VALUE; /* only diameter wear is kept */
        return has_r ? tooltable_set_wear(t, p - TOOLTABLE_WEAR_BASE, 2.0 * r_mm)
                     : TOOLTABLE_OK;
    }
    if (p <= 0 || p >= TOOLTABLE_WEAR_BASE)
        return TOOLTABLE_ERR_NO_TOOL;
    struct tool_entry e;
    struct tool_entry *old = tooltable_find(t, p);
    if (old) {
        e = *old;
    } else {
        memset(&e, 0, sizeof e);
        e.tool = p;
        e.pocket = p;
    }
    if (has_r) {
        if (!(r_mm >= 0.0))
            return TOOLTABLE_ERR_VALUE;
        e.diameter_mm = 2.0 * r_mm;
    }
    if (has_z) {
        e.z_offset_mm = z_mm;
        e.present |= TOOLTABLE_F_Z;
    }
    return tooltable_set(t, &e);
}

/* Effective radius for compensation: (diameter + wear) / 2, which must be > 0. */
int tooltable_radius(const struct tooltable *t, int tool, double *radius_mm)
{
    int i = tooltable_index(t, tool);
    if (i < 0)
        return TOOLTABLE_ERR_NO_TOOL;
    double d_mm = t->tools[i].diameter_mm + t->tools[i].wear_mm;
    if (!(d_mm > 0.0))
        return TOOLTABLE_ERR_VALUE;
    *radius_mm = 0.5 * d_mm;
    return TOOLTABLE_OK;
}

/* ---- parsing ---- */

/* The letters LinuxCNC's tool table knows, in the order a save writes the optional ones. */
static const char tooltable_offset_letters[] = "XYZABCUVW";

/* One parsed line: a tool or a wear entry, with the line it came from. */
struct tooltable_line {
    struct tool_entry e;
    int lineno;
};

/* Copies the comment after ';' without the leading blanks and the line end. */
static void tooltable_copy_comment(char *dst, size_t dstlen, const char *src)
{
    while (*src == ' ' || *src == '\t')
        src++;
    size_t n = strcspn(src, "\r\n");
    if (n >= dstlen)
        n = dstlen - 1;
    memcpy(dst, src, n);
    dst[n] = '\0';
}

/* Reads one word's number; integers for T P Q. Returns 0 on success. */
static int tooltable_number(const char **s, int want_int, double *v)
{
    char *end;
    size_t span = strspn(*s, "+-.0123456789eE"); /* plain decimals only: no hex, inf, nan */
    errno = 0;
    *v = strtod(*s, &end);
    if (span == 0 || end != *s + span || errno || !isfinite(*v))
        return -1;
    if (want_int && (*v != floor(*v) || fabs(*v) > 1e9))
        return -1;
    *s = end;
    return 0;
}

/* Stores a field value; `bit` marks it present. Returns 0, or -1 if the letter repeats. */
static int tooltable_store(struct tool_entry *e, unsigned *seen, char letter, double v)
{
    const char *all = "TPXYZABCUVWDIJQ";
    unsigned bit = 1u << (strchr(all, letter) - all);
    if (*seen & bit)
        return -1;
    *seen |= bit;
    const char *off = strchr(tooltable_offset_letters, letter);
    if (letter == 'T')
        e->tool = (int)v;
    else if (letter == 'P')
        e->pocket = (int)v;
    else if (letter == 'D')
        e->diameter_mm = v;
    else if (letter == 'I')
        e->front_angle_deg = v, e->present |= TOOLTABLE_F_I;
    else if (letter == 'J')
        e->back_angle_deg = v, e->present |= TOOLTABLE_F_J;
    else if (letter == 'Q')
        e->orientation = (int)v, e->present |= TOOLTABLE_F_Q;
    else if (letter == 'Z')
        e->z_offset_mm = v, e->present |= TOOLTABLE_F_Z;
    else if (off) {
        e->offset[off - tooltable_offset_letters] = v;
        e->present |= 1u << (off - tooltable_offset_letters);
    }
    return 0;
}

/* Parses one line into l->e; *is_tool says whether it held a tool (else blank/comment). */
static int tooltable_parse_line(const char *s, struct tooltable_line *l, int *is_tool,
                                const char *name, char *err, size_t errlen)
{
    unsigned seen = 0;
    memset(&l->e, 0, sizeof l->e);
    *is_tool = 0;
    for (;;) {
        while (*s == ' ' || *s == '\t' || *s == '\r')
            s++;
        if (*s == '\0' || *s == '\n')
            break;
        if (*s == ';') {
            tooltable_copy_comment(l->e.comment, sizeof l->e.comment, s + 1);
            break;
        }
        char letter = (char)toupper((unsigned char)*s);
        if (!isalpha((unsigned char)*s) || !strchr("TPXYZABCUVWDIJQ", letter))
            return errbuf_set(err, errlen, TOOLTABLE_ERR_SYNTAX,
                                  "%s:%d: unknown field '%c' (a tool table knows T P X Y Z A "
                                  "B C U V W D I J Q)", name, l->lineno, *s);
        s++;
        double v;
        if (tooltable_number(&s, letter == 'T' || letter == 'P' || letter == 'Q', &v))
            return errbuf_set(err, errlen, TOOLTABLE_ERR_SYNTAX,
                                  "%s:%d: field %c needs a %snumber", name, l->lineno,
                                  letter, strchr("TPQ", letter) ? "whole " : "");
        if (*s && !strchr(" \t\r\n;", *s))
            return errbuf_set(err, errlen, TOOLTABLE_ERR_SYNTAX,
                                  "%s:%d: field %c is followed by '%c' (put a space between "
                                  "fields)", name, l->lineno, letter, *s);
        if (tooltable_store(&l->e, &seen, letter, v))
            return errbuf_set(err, errlen, TOOLTABLE_ERR_SYNTAX,
                                  "%s:%d: field %c appears twice", name, l->lineno, letter);
    }
    if (!seen)
        return TOOLTABLE_OK;
    if (!(seen & 1u))
        return errbuf_set(err, errlen, TOOLTABLE_ERR_SYNTAX,
                              "%s:%d: the line has no tool number (T)", name, l->lineno);
    if (l->e.tool <= 0 || l->e.tool == TOOLTABLE_WEAR_BASE)
        return errbuf_set(err, errlen, TOOLTABLE_ERR_SYNTAX,
                              "%s:%d: tool number T%d is not allowed (use 1..%d, or %d+n for "
                              "the wear of tool n)", name, l->lineno, l->e.tool,
                              TOOLTABLE_WEAR_BASE - 1, TOOLTABLE_WEAR_BASE);
    if (!(seen & 2u))
        l->e.pocket = l->e.tool;
    if (l->e.tool > TOOLTABLE_WEAR_BASE && (seen & ~(1u | 2u | (1u << 11))))
        return errbuf_set(err, errlen, TOOLTABLE_ERR_SYNTAX,
                              "%s:%d: wear entry T%d may only carry P and D (diameter wear)",
                              name, l->lineno, l->e.tool);
    if (l->e.tool < TOOLTABLE_WEAR_BASE && l->e.diameter_mm < 0.0)
        return errbuf_set(err, errlen, TOOLTABLE_ERR_VALUE,
                              "%s:%d: tool T%d has a negative diameter D%g", name,
                              l->lineno, l->e.tool, l->e.diameter_mm);
    *is_tool = 1;
    return TOOLTABLE_OK;
}

/* A wear entry read from the file, applied once every tool is known. */
struct tooltable_wear {
    int tool;                 /* the worn tool's number (entry number - WEAR_BASE) */
    double wear_mm;           /* diameter wear delta */
    int lineno;               /* line of the wear entry */
};

/* Folds a wear entry (T WEAR_BASE + n) into tool n, which must be in the table. */
static int tooltable_apply_wear(struct tooltable *t, const struct tooltable_wear *l,
                                int *wear_line, const char *name, char *err, size_t errlen)
{
    int tool = l->tool;
    int i = tooltable_index(t, tool);
    if (i < 0)
        return errbuf_set(err, errlen, TOOLTABLE_ERR_NO_TOOL,
                              "%s:%d: wear entry T%d is for tool T%d, which is not in the "
                              "table", name, l->lineno, tool + TOOLTABLE_WEAR_BASE, tool);
    if (wear_line[i])
        return errbuf_set(err, errlen, TOOLTABLE_ERR_DUPLICATE,
                              "%s:%d: a second wear entry for tool T%d (the first is on line "
                              "%d)", name, l->lineno, tool, wear_line[i]);
    t->tools[i].wear_mm = l->wear_mm;
    wear_line[i] = l->lineno;
    return TOOLTABLE_OK;
}

/* Adds one tool line to t, refusing duplicates. line_of[i] remembers where tool i was. */
static int tooltable_add_line(struct tooltable *t, const struct tooltable_line *l,
                              int *line_of, const char *name, char *err, size_t errlen)
{
    int i = tooltable_index(t, l->e.tool);
    if (i >= 0)
        return errbuf_set(err, errlen, TOOLTABLE_ERR_DUPLICATE,
                              "%s:%d: tool T%d appears twice (first on line %d)", name,
                              l->lineno, l->e.tool, line_of[i]);
    if (t->count >= TOOLTABLE_MAX)
        return errbuf_set(err, errlen, TOOLTABLE_ERR_FULL,
                              "%s:%d: more than %d tools", name, l->lineno, TOOLTABLE_MAX);
    line_of[t->count] = l->lineno;
    t->tools[t->count++] = l->e;
    return TOOLTABLE_OK;
}

/* Parses a whole table from text: tools first, then the wear entries folded into them. */
int tooltable_parse(struct tooltable *t, const char *text, const char *name, char *err,
                    size_t errlen)
{
    int line_of[TOOLTABLE_MAX] = {0}, wear_line[TOOLTABLE_MAX] = {0};
    struct tooltable_wear wear[TOOLTABLE_MAX];
    int nwear = 0, rc = TOOLTABLE_OK;
    struct tooltable_line l;
    tooltable_init(t);
    l.lineno = 0;
    for (const char *s = text; s && *s && rc == TOOLTABLE_OK;) {
        const char *eol = strchr(s, '\n');
        l.lineno++;
        int is_tool;
        rc = tooltable_parse_line(s, &l, &is_tool, name, err, errlen);
        if (rc == TOOLTABLE_OK && is_tool && l.e.tool > TOOLTABLE_WEAR_BASE) {
            if (nwear >= TOOLTABLE_MAX)
                rc = errbuf_set(err, errlen, TOOLTABLE_ERR_FULL,
                                    "%s:%d: more than %d wear entries", name, l.lineno,
                                    TOOLTABLE_MAX);
            else
                wear[nwear++] = (struct tooltable_wear){
                    l.e.tool - TOOLTABLE_WEAR_BASE, l.e.diameter_mm, l.lineno};
        } else if (rc == TOOLTABLE_OK && is_tool) {
            rc = tooltable_add_line(t, &l, line_of, name, err, errlen);
        }
        s = eol ? eol + 1 : NULL;
    }
    for (int k = 0; k < nwear && rc == TOOLTABLE_OK; k++)
        rc = tooltable_apply_wear(t, &wear[k], wear_line, name, err, errlen);
    if (rc != TOOLTABLE_OK)
        tooltable_init(t);
    return rc;
}
