/* tooltable_file.c: reading a tool table file, and saving one through common/atomicfile,
 * rewriting only the lines whose entries changed. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/atomicfile.h"
#include "common/errbuf.h"
#include "interp/tooltable_priv.h"

#define TOOLTABLE_MAX_FILE_BYTES (4L << 20) /* a table file larger than 4 MiB is refused */

/* The offset letters in the order a save writes them (as LinuxCNC does). */
static const char tooltable_offset_letters[] = "XYZABCUVW";

/* Reads the whole file into a NUL-terminated buffer the caller frees. A missing file gives
 * NULL with *rc = TOOLTABLE_OK when missing_ok. */
static char *tooltable_slurp(const char *path, int missing_ok, char *err, size_t errlen,
                             int *rc)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    long n;
    *rc = TOOLTABLE_ERR_IO;
    if (!f) {
        if (missing_ok && errno == ENOENT)
            *rc = TOOLTABLE_OK;
        else
            errbuf_set(err, errlen, *rc, "%s: cannot open the tool table: %s", path,
                       strerror(errno));
        return NULL;
    }
    if (fseek(f, 0, SEEK_END) || (n = ftell(f)) < 0 || n > TOOLTABLE_MAX_FILE_BYTES ||
        fseek(f, 0, SEEK_SET)) {
        errbuf_set(err, errlen, *rc, "%s: cannot read the tool table (too large?)", path);
        goto out;
    }
    buf = malloc((size_t)n + 1);
    if (!buf || fread(buf, 1, (size_t)n, f) != (size_t)n) {
        errbuf_set(err, errlen, *rc, "%s: cannot read the tool table", path);
        free(buf);
        buf = NULL;
        goto out;
    }
    buf[n] = '\0';
    *rc = TOOLTABLE_OK;
out:
    fclose(f);
    return buf;
}

/* Reads a table file; err gets "file:line: what" on failure. Temporaries left next to it by
 * killed saves are removed. */
int tooltable_load(struct tooltable *t, const char *path, char *err, size_t errlen)
{
    int rc;
    tooltable_init(t);
    if (strlen(path) >= sizeof t->path)
        return errbuf_set(err, errlen, TOOLTABLE_ERR_IO, "%.200s...: tool table path longer "
                          "than %zu characters (the limit)", path, sizeof t->path - 1);
    char *text = tooltable_slurp(path, 0, err, errlen, &rc);
    if (!text)
        return rc;
    rc = tooltable_parse(t, text, path, err, errlen);
    free(text);
    if (rc == TOOLTABLE_OK) {
        snprintf(t->path, sizeof t->path, "%s", path);
        atomicfile_clean_stale(path);
    }
    return rc;
}

/* ---- saving ---- */

/* The shortest of %.15g / %.17g that reads back as exactly v (so a save loses nothing
 * and -0.04 stays "-0.04"). */
static const char *tooltable_num(char *buf, size_t len, double v, int plus)
{
    snprintf(buf, len, plus ? "%+.15g" : "%.15g", v);
    if (strtod(buf, NULL) != v)
        snprintf(buf, len, plus ? "%+.17g" : "%.17g", v);
    return buf;
}

/* A new value in the style of the number it replaces: its '+' and its count of decimals
 * where that reads back exactly, else the shortest exact form. old may be NULL. */
static const char *tooltable_num_like(char *buf, size_t len, double v, char letter,
                                      const char *old, size_t oldlen)
{
    int plus = old ? old[0] == '+' && v >= 0 : strchr(tooltable_offset_letters, letter) != NULL;
    if (strchr("TPQ", letter)) {
        snprintf(buf, len, plus ? "%+d" : "%d", (int)v);
        return buf;
    }
    const char *dot = old ? memchr(old, '.', oldlen) : NULL;
    if (dot && !memchr(old, 'e', oldlen) && !memchr(old, 'E', oldlen)) {
        int decimals = (int)(old + oldlen - dot - 1);
        snprintf(buf, len, plus ? "%+.*f" : "%.*f", decimals, v);
        if (strtod(buf, NULL) == v)
            return buf;
    }
    return tooltable_num(buf, len, v, plus);
}

/* Writes one tool in LinuxCNC's letter format (a new line). */
static void tooltable_write_tool(FILE *f, const struct tool_entry *e)
{
    char n[40];
    fprintf(f, "T%d P%d", e->tool, e->pocket);
    for (int k = 0; k < 9; k++) {
        if (!(e->present & (1u << k)))
            continue;
        double v = k == 2 ? e->z_offset_mm : e->offset[k];
        fprintf(f, " %c%s", tooltable_offset_letters[k], tooltable_num(n, sizeof n, v, 1));
    }
    fprintf(f, " D%s", tooltable_num(n, sizeof n, e->diameter_mm, 0));
    if (e->present & TOOLTABLE_F_I)
        fprintf(f, " I%s", tooltable_num(n, sizeof n, e->front_angle_deg, 0));
    if (e->present & TOOLTABLE_F_J)
        fprintf(f, " J%s", tooltable_num(n, sizeof n, e->back_angle_deg, 0));
    if (e->present & TOOLTABLE_F_Q)
        fprintf(f, " Q%d", e->orientation);
    fprintf(f, "%s%s\n", e->comment[0] ? " ;" : "", e->comment);
}

/* Writes one tool as a row of a headed table; refuses fields it has no column for. */
static int tooltable_write_row(FILE *f, const struct tool_entry *e,
                               const struct tooltable_format *fmt, const char *name,
                               char *err, size_t errlen)
{
    char n[40];
    for (const char *c = &TOOLTABLE_LETTERS[1]; *c; c++)
        if (!strchr(fmt->cols, *c) && tooltable_field_value(e, *c) != (*c == 'P' ? e->tool : 0))
            return errbuf_set(err, errlen, TOOLTABLE_ERR_IO, "%s: tool T%d needs a field %c, "
                              "which this table's columns (header line) cannot hold: not "
                              "saved", name, e->tool, *c);
    for (int k = 0; fmt->cols[k]; k++)
        fprintf(f, "%s%6s", k ? " " : "", tooltable_num_like(n, sizeof n,
                tooltable_field_value(e, fmt->cols[k]), fmt->cols[k], NULL, 0));
    fprintf(f, "%s%s\n", e->comment[0] ? "  " : "", e->comment);
    return TOOLTABLE_OK;
}

/* Writes line l (text from start up to next, its line end included) with the values of
 * want: changed numbers replaced in place, missing fields added after the last one, the
 * comment replaced if it changed; everything else as it was. */
static int tooltable_rewrite_line(FILE *f, const struct tooltable_line *l, const char *start,
                                  const char *next, const struct tool_entry *want,
                                  const char *name, char *err, size_t errlen)
{
    const char *cur = start;
    char n[40];
    for (int k = 0; k < l->nf; k++) {
        const struct tooltable_span *fl = &l->f[k];
        double v = tooltable_field_value(want, fl->letter);
        if (v == tooltable_field_value(&l->e, fl->letter))
            continue;
        fwrite(cur, 1, (size_t)(fl->num - cur), f);
        fputs(tooltable_num_like(n, sizeof n, v, fl->letter, fl->num, fl->len), f);
        cur = fl->num + fl->len;
    }
    for (const char *c = TOOLTABLE_LETTERS; *c; c++) {
        double v = tooltable_field_value(want, *c);
        if ((l->seen & (1u << (c - TOOLTABLE_LETTERS))) || v == tooltable_field_value(&l->e, *c))
            continue;
        if (l->headed)
            return errbuf_set(err, errlen, TOOLTABLE_ERR_IO, "%s:%d: tool T%d needs a field "
                              "%c, which this table's columns (header line) cannot hold: not "
                              "saved", name, l->lineno, want->tool, *c);
        fwrite(cur, 1, (size_t)(l->fields_end - cur), f);
        fprintf(f, " %c%s", *c, tooltable_num_like(n, sizeof n, v, *c, NULL, 0));
        cur = l->fields_end;
    }
    if (strcmp(want->comment, l->e.comment)) {
        const char *at = l->comment ? l->comment : l->eol;
        int letters = !l->headed;
        fwrite(cur, 1, (size_t)(at - cur), f);
        fprintf(f, "%s%s%s", l->comment ? "" : " ", letters ? ";" : " ", want->comment);
        cur = l->eol;
    }
    fwrite(cur, 1, (size_t)(next - cur), f);
    return ferror(f) ? errbuf_set(err, errlen, TOOLTABLE_ERR_IO, "%s: cannot write: %s", name,
                                  strerror(errno)) : TOOLTABLE_OK;
}

/* Save state: which tools and wear entries of t the old text already held. */
struct tooltable_saver {
    const struct tooltable *t;
    FILE *f;
    struct tooltable_format fmt;       /* the old file's format (headed or letters) */
    unsigned char done[TOOLTABLE_MAX]; /* tool i written */
    unsigned char wear_done[TOOLTABLE_MAX]; /* wear entry of tool i written */
    const char *name;
    int need_eol;                      /* the old text ends without a line end */
};

/* Index of tool `tool` in t, or -1. */
static int tooltable_saver_index(const struct tooltable *t, int tool)
{
    for (int i = 0; i < t->count; i++)
        if (t->tools[i].tool == tool)
            return i;
    return -1;
}

/* One line of the old text: an entry of t gets its current values, anything else (comments,
 * blank lines, headers, lines of tools t does not hold) stays as it was. */
static int tooltable_save_line(struct tooltable_saver *sv, const char *s, const char *next,
                               int lineno, char *err, size_t errlen)
{
    struct tooltable_line l;
    char scratch[8];
    l.lineno = lineno;
    if (tooltable_parse_line(s, &l, &sv->fmt, sv->name, scratch, sizeof scratch) ||
        !l.is_entry) {
        fwrite(s, 1, (size_t)(next - s), sv->f);
        return TOOLTABLE_OK;
    }
    int i = tooltable_saver_index(sv->t, l.e.tool);
    if (i >= 0 && !sv->done[i]) {
        sv->done[i] = 1;
        return tooltable_rewrite_line(sv->f, &l, s, next, &sv->t->tools[i], sv->name, err,
                                      errlen);
    }
    int base = i < 0 && tooltable_is_wear_number(l.e.tool)
                   ? tooltable_saver_index(sv->t, l.e.tool - TOOLTABLE_WEAR_BASE) : -1;
    if (base >= 0 && !sv->wear_done[base]) {
        struct tool_entry want = l.e;
        want.diameter_mm = sv->t->tools[base].wear_mm;
        sv->wear_done[base] = 1;
        return tooltable_rewrite_line(sv->f, &l, s, next, &want, sv->name, err, errlen);
    }
    fwrite(s, 1, (size_t)(next - s), sv->f);
    return TOOLTABLE_OK;
}

/* Appends an entry in the file's format. */
static int tooltable_append(struct tooltable_saver *sv, const struct tool_entry *e, char *err,
                            size_t errlen)
{
    if (sv->need_eol)
        fputc('\n', sv->f);
    sv->need_eol = 0;
    if (sv->fmt.cols[0])
        return tooltable_write_row(sv->f, e, &sv->fmt, sv->name, err, errlen);
    tooltable_write_tool(sv->f, e);
    return TOOLTABLE_OK;
}

/* The wear entry T(WEAR_BASE + n) of tool e. */
static struct tool_entry tooltable_wear_entry(const struct tool_entry *e)
{
    struct tool_entry w;
    memset(&w, 0, sizeof w);
    w.tool = e->tool + TOOLTABLE_WEAR_BASE;
    w.diameter_mm = e->wear_mm;
    snprintf(w.comment, sizeof w.comment, "wear of T%d", e->tool);
    return w;
}

/* Appends the tools the old text did not hold, and the wear entries it lacked. */
static int tooltable_save_rest(struct tooltable_saver *sv, char *err, size_t errlen)
{
    int rc = TOOLTABLE_OK;
    for (int i = 0; i < sv->t->count && rc == TOOLTABLE_OK; i++) {
        const struct tool_entry *e = &sv->t->tools[i];
        if (!sv->done[i])
            rc = tooltable_append(sv, e, err, errlen);
        if (rc == TOOLTABLE_OK && !sv->wear_done[i] && e->wear_mm != 0.0) {
            struct tool_entry w = tooltable_wear_entry(e);
            rc = tooltable_append(sv, &w, err, errlen);
        }
    }
    return rc;
}

/* Writes the table atomically, rewriting the file it replaces (when there is one) line by
 * line: what did not change keeps its text. */
int tooltable_save(const struct tooltable *t, const char *path, char *err, size_t errlen)
{
    int rc;
    char *old = tooltable_slurp(path, 1, err, errlen, &rc);
    if (rc != TOOLTABLE_OK)
        return rc;
    struct tooltable_saver *sv = calloc(1, sizeof *sv);
    struct atomicfile a;
    if (!sv) {
        free(old);
        return errbuf_set(err, errlen, TOOLTABLE_ERR_IO, "%s: out of memory", path);
    }
    if (atomicfile_open(&a, path, err, errlen) != ATOMICFILE_OK) {
        rc = TOOLTABLE_ERR_IO;
        goto out;
    }
    sv->t = t, sv->f = a.f, sv->name = path;
    int lineno = 0;
    const char *s = old;
    while (s && *s && rc == TOOLTABLE_OK) {
        const char *eol = strchr(s, '\n'), *next = eol ? eol + 1 : s + strlen(s);
        rc = tooltable_save_line(sv, s, next, ++lineno, err, errlen);
        sv->need_eol = !eol;       /* the last line has no line end: added if entries follow */
        s = next;
    }
    if (rc == TOOLTABLE_OK)
        rc = tooltable_save_rest(sv, err, errlen);
    if (rc != TOOLTABLE_OK)
        atomicfile_abort(&a);
    else if (atomicfile_commit(&a, err, errlen) != ATOMICFILE_OK)
        rc = TOOLTABLE_ERR_IO;
out:
    free(sv);
    free(old);
    return rc;
}
