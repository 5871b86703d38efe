/* tooltable_parse.c: reading LinuxCNC tool table text, both its letter format and its older
 * headed columns, into a table; wear entries T(10000 + n) folded into tool n. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/errbuf.h"
#include "interp/tooltable_priv.h"

/* The offset letters, index = offset[] index and TOOLTABLE_F_* bit. */
static const char tooltable_offset_letters[] = "XYZABCUVW";

/* The value of field `letter` in e. */
double tooltable_field_value(const struct tool_entry *e, char letter)
{
    const char *off = strchr(tooltable_offset_letters, letter);
    switch (letter) {
    case 'T': return e->tool;
    case 'P': return e->pocket;
    case 'D': return e->diameter_mm;
    case 'Z': return e->z_offset_mm;
    case 'I': return e->front_angle_deg;
    case 'J': return e->back_angle_deg;
    case 'Q': return e->orientation;
    default: return off ? e->offset[off - tooltable_offset_letters] : 0.0;
    }
}

/* Copies the comment without the leading blanks and the line end. */
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

/* Reads one number; integers for T P Q. Returns 0 on success. */
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

/* Stores a field value and records where its text is. Returns 0, or -1 if it repeats. */
static int tooltable_store(struct tooltable_line *l, char letter, const char *num, size_t len,
                           double v)
{
    unsigned bit = 1u << (strchr(TOOLTABLE_LETTERS, letter) - TOOLTABLE_LETTERS);
    struct tool_entry *e = &l->e;
    if (l->seen & bit)
        return -1;
    l->seen |= bit;
    l->f[l->nf++] = (struct tooltable_span){ letter, num, len };
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

/* The column letter of a header word (TOOLNO, POCKET, LENGTH, DIAMETER, ...), 'c' for
 * COMMENT, 0 if unknown. */
static char tooltable_column(const char *w, size_t n)
{
    static const struct { const char *word; char letter; } cols[] = {
        {"TOOLNO", 'T'}, {"TOOL", 'T'}, {"FMS", 'T'}, {"POCKET", 'P'}, {"POC", 'P'},
        {"LENGTH", 'Z'}, {"LEN", 'Z'}, {"DIAMETER", 'D'}, {"DIAM", 'D'}, {"COMMENT", 'c'},
    };
    for (size_t k = 0; k < sizeof cols / sizeof cols[0]; k++)
        if (strlen(cols[k].word) == n && !strncasecmp(w, cols[k].word, n))
            return cols[k].letter;
    return 0;
}

/* A header line (a word of two or more letters first): sets fmt->cols. *is_header = 0 when
 * the line is no header. */
static int tooltable_header(const char *s, struct tooltable_line *l,
                            struct tooltable_format *fmt, int *is_header, const char *name,
                            char *err, size_t errlen)
{
    size_t n = strspn(s, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz");
    char cols[TOOLTABLE_COLS_MAX + 1] = "";
    int nc = 0;
    *is_header = n >= 2 && (s[n] == ' ' || s[n] == '\t' || s[n] == '\r' || s[n] == '\n' ||
                            !s[n]) && tooltable_column(s, n);
    while (*is_header && *s && *s != '\n' && *s != '\r') {
        n = strcspn(s, " \t\r\n");
        char c = tooltable_column(s, n);
        if (c == 'c')
            break;
        if (!c || nc == TOOLTABLE_COLS_MAX || strchr(cols, c))
            return errbuf_set(err, errlen, TOOLTABLE_ERR_SYNTAX, "%s:%d: header column "
                              "'%.*s' is %s (known: TOOLNO POCKET LENGTH DIAMETER COMMENT)",
                              name, l->lineno, (int)n, s, c ? "repeated" : "unknown");
        cols[nc++] = c;
        cols[nc] = '\0';
        s += n;
        s += strspn(s, " \t");
    }
    if (*is_header && !strchr(cols, 'T'))
        return errbuf_set(err, errlen, TOOLTABLE_ERR_SYNTAX, "%s:%d: the header names no "
                          "tool number column (TOOLNO)", name, l->lineno);
    if (*is_header)
        memcpy(fmt->cols, cols, sizeof cols);
    return TOOLTABLE_OK;
}

/* A row of a headed table: one number per column, then the comment. */
static int tooltable_row(const char *s, struct tooltable_line *l,
                         const struct tooltable_format *fmt, const char *name, char *err,
                         size_t errlen)
{
    l->headed = 1;
    for (int k = 0; fmt->cols[k]; k++) {
        char c = fmt->cols[k];
        const char *num = s;
        double v;
        if (tooltable_number(&s, strchr("TPQ", c) != NULL, &v) ||
            (*s && !strchr(" \t\r\n", *s)))
            return errbuf_set(err, errlen, TOOLTABLE_ERR_SYNTAX, "%s:%d: column %d (%c) needs "
                              "a %snumber", name, l->lineno, k + 1, c,
                              strchr("TPQ", c) ? "whole " : "");
        tooltable_store(l, c, num, (size_t)(s - num), v);
        l->fields_end = s;
        s += strspn(s, " \t");
    }
    if (*s && *s != '\r' && *s != '\n') {
        l->comment = s;
        tooltable_copy_comment(l->e.comment, sizeof l->e.comment, *s == ';' ? s + 1 : s);
    }
    return TOOLTABLE_OK;
}

/* Letter format: `T1 P1 X.. D.. ;comment`, letters in either case. */
static int tooltable_letters(const char *s, struct tooltable_line *l, const char *name,
                             char *err, size_t errlen)
{
    for (;;) {
        s += strspn(s, " \t\r");
        if (*s == '\0' || *s == '\n')
            return TOOLTABLE_OK;
        if (*s == ';') {
            l->comment = s;
            tooltable_copy_comment(l->e.comment, sizeof l->e.comment, s + 1);
            return TOOLTABLE_OK;
        }
        char letter = (char)toupper((unsigned char)*s);
        if (!isalpha((unsigned char)*s) || !strchr(TOOLTABLE_LETTERS, letter))
            return errbuf_set(err, errlen, TOOLTABLE_ERR_SYNTAX, "%s:%d: unknown field '%c' "
                              "(a tool table knows T P X Y Z A B C U V W D I J Q)", name,
                              l->lineno, *s);
        const char *num = ++s;
        double v;
        if (tooltable_number(&s, strchr("TPQ", letter) != NULL, &v))
            return errbuf_set(err, errlen, TOOLTABLE_ERR_SYNTAX, "%s:%d: field %c needs a "
                              "%snumber", name, l->lineno, letter,
                              strchr("TPQ", letter) ? "whole " : "");
        if (*s && !strchr(" \t\r\n;", *s))
            return errbuf_set(err, errlen, TOOLTABLE_ERR_SYNTAX, "%s:%d: field %c is "
                              "followed by '%c' (put a space between fields)", name,
                              l->lineno, letter, *s);
        if (tooltable_store(l, letter, num, (size_t)(s - num), v))
            return errbuf_set(err, errlen, TOOLTABLE_ERR_SYNTAX, "%s:%d: field %c appears "
                              "twice", name, l->lineno, letter);
        l->fields_end = s;
    }
}

/* Parses one line: blank, comment, header, headed row or letter line. */
int tooltable_parse_line(const char *s, struct tooltable_line *l,
                         struct tooltable_format *fmt, const char *name, char *err,
                         size_t errlen)
{
    int lineno = l->lineno, is_header, rc;
    memset(l, 0, sizeof *l);
    l->lineno = lineno;
    l->eol = s + strcspn(s, "\r\n");
    s += strspn(s, " \t");
    if ((rc = tooltable_header(s, l, fmt, &is_header, name, err, errlen)) || is_header)
        return rc;
    if (fmt->cols[0] && strchr("+-.0123456789", *s) && *s)
        rc = tooltable_row(s, l, fmt, name, err, errlen);
    else
        rc = tooltable_letters(s, l, name, err, errlen);
    if (rc || !l->seen)
        return rc;
    if (!(l->seen & 1u))
        return errbuf_set(err, errlen, TOOLTABLE_ERR_SYNTAX, "%s:%d: the line has no tool "
                          "number (T)", name, l->lineno);
    if (l->e.tool < 0)
        return errbuf_set(err, errlen, TOOLTABLE_ERR_SYNTAX, "%s:%d: tool number T%d is "
                          "negative", name, l->lineno, l->e.tool);
    if (!(l->seen & 2u))
        l->e.pocket = l->e.tool;
    l->is_entry = 1;
    return TOOLTABLE_OK;
}

/* The entries of a file before wear entries are told from tools. */
struct tooltable_lines {
    struct tooltable_line *v;
    int n, cap;
};

/* Appends an entry line; TOOLTABLE_ERR_FULL past two entries per tool. */
static int tooltable_lines_add(struct tooltable_lines *ls, const struct tooltable_line *l,
                               const char *name, char *err, size_t errlen)
{
    if (ls->n == ls->cap) {
        if (ls->cap >= 2 * TOOLTABLE_MAX)
            return errbuf_set(err, errlen, TOOLTABLE_ERR_FULL, "%s:%d: more than %d tools",
                              name, l->lineno, TOOLTABLE_MAX);
        int cap = ls->cap ? 2 * ls->cap : 64;
        struct tooltable_line *v = realloc(ls->v, (size_t)cap * sizeof *v);
        if (!v)
            return errbuf_set(err, errlen, TOOLTABLE_ERR_FULL, "%s: out of memory", name);
        ls->v = v, ls->cap = cap;
    }
    ls->v[ls->n++] = *l;
    return TOOLTABLE_OK;
}

/* Index of the entry with tool number `tool` among ls (ordinary reading), or -1. */
static int tooltable_lines_find(const struct tooltable_lines *ls, int tool)
{
    for (int i = 0; i < ls->n; i++)
        if (ls->v[i].e.tool == tool)
            return i;
    return -1;
}

/* Whether entry k is a wear entry: T(WEAR_BASE + n), n = 1 .. WEAR_BASE - 1, with tool n
 * in the file. Any other number (T0, T10000, T99999, T10005 without T5) is a tool. */
static int tooltable_is_wear(const struct tooltable_lines *ls, int k)
{
    int tool = ls->v[k].e.tool;
    return tooltable_is_wear_number(tool) &&
           tooltable_lines_find(ls, tool - TOOLTABLE_WEAR_BASE) >= 0;
}

/* Adds the ordinary tools of ls to t (duplicates and negative diameters refused). */
static int tooltable_add_tools(struct tooltable *t, const struct tooltable_lines *ls,
                               const char *name, char *err, size_t errlen)
{
    for (int k = 0; k < ls->n; k++) {
        const struct tooltable_line *l = &ls->v[k];
        int first = tooltable_lines_find(ls, l->e.tool);
        if (tooltable_is_wear(ls, k))
            continue;
        if (first != k) {          /* LinuxCNC uses the first; so do we, and say so */
            struct tool_entry *e = tooltable_find(t, l->e.tool);
            if (!e->duplicate_line)
                e->duplicate_line = l->lineno;
            if (!t->warning[0])
                snprintf(t->warning, sizeof t->warning, "%s:%d: tool T%d appears again (first "
                         "on line %d): the first is used, and cutter compensation with T%d "
                         "is refused", name, l->lineno, l->e.tool, ls->v[first].lineno,
                         l->e.tool);
            t->nwarnings++;
            continue;
        }
        if (l->e.diameter_mm < 0.0)
            return errbuf_set(err, errlen, TOOLTABLE_ERR_VALUE, "%s:%d: tool T%d has a "
                              "negative diameter D%g", name, l->lineno, l->e.tool,
                              l->e.diameter_mm);
        if (t->count >= TOOLTABLE_MAX)
            return errbuf_set(err, errlen, TOOLTABLE_ERR_FULL, "%s:%d: more than %d tools",
                              name, l->lineno, TOOLTABLE_MAX);
        t->tools[t->count++] = l->e;
    }
    return TOOLTABLE_OK;
}

/* Folds the wear entries of ls into their tools: D is the diameter wear. */
static int tooltable_add_wear(struct tooltable *t, const struct tooltable_lines *ls,
                              const char *name, char *err, size_t errlen)
{
    for (int k = 0; k < ls->n; k++) {
        if (!tooltable_is_wear(ls, k))
            continue;
        const struct tooltable_line *l = &ls->v[k];
        int first = tooltable_lines_find(ls, l->e.tool);
        if (first != k)
            return errbuf_set(err, errlen, TOOLTABLE_ERR_DUPLICATE, "%s:%d: a second wear "
                              "entry for tool T%d (the first is on line %d)", name, l->lineno,
                              l->e.tool - TOOLTABLE_WEAR_BASE, ls->v[first].lineno);
        tooltable_find(t, l->e.tool - TOOLTABLE_WEAR_BASE)->wear_mm = l->e.diameter_mm;
    }
    return TOOLTABLE_OK;
}

/* Parses a whole table from text: all lines first, then tools, then their wear entries. */
int tooltable_parse(struct tooltable *t, const char *text, const char *name, char *err,
                    size_t errlen)
{
    struct tooltable_lines ls = {0};
    struct tooltable_format fmt = {""};
    struct tooltable_line l;
    int rc = TOOLTABLE_OK;
    tooltable_init(t);
    l.lineno = 0;
    for (const char *s = text; s && *s && rc == TOOLTABLE_OK;) {
        const char *eol = strchr(s, '\n');
        l.lineno++;
        rc = tooltable_parse_line(s, &l, &fmt, name, err, errlen);
        if (rc == TOOLTABLE_OK && l.is_entry)
            rc = tooltable_lines_add(&ls, &l, name, err, errlen);
        s = eol ? eol + 1 : NULL;
    }
    if (rc == TOOLTABLE_OK)
        rc = tooltable_add_tools(t, &ls, name, err, errlen);
    if (rc == TOOLTABLE_OK)
        rc = tooltable_add_wear(t, &ls, name, err, errlen);
    free(ls.v);
    if (rc != TOOLTABLE_OK)
        tooltable_init(t);
    return rc;
}
