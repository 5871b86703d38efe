/* calib_csv.c: the measurement file of `hexcnc calibrate fit`, parsed from text in memory:
 * header L1,L2,L3,L4,L5,L6,X,Y,Z,A,B,C, one measurement a row, `#` comments. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "calib/calib_csv.h"

#define CALIB_CSV_COLS (CALIB_LEGS + KINS_POSE_DIM)

static const char *const calib_csv_header[CALIB_CSV_COLS] = {
    "L1", "L2", "L3", "L4", "L5", "L6", "X", "Y", "Z", "A", "B", "C"
};

/* Cuts a `#` comment and trailing blanks off a line in place; returns its first non-blank. */
static char *calib_csv_clean(char *line)
{
    char *hash = strchr(line, '#');
    if (hash)
        *hash = '\0';
    size_t len = strlen(line);
    while (len && (line[len - 1] == ' ' || line[len - 1] == '\t' || line[len - 1] == '\r'))
        line[--len] = '\0';
    while (*line == ' ' || *line == '\t')
        line++;
    return line;
}

/* Splits a comma-separated line into at most max fields, blanks trimmed; returns the count
 * (max + 1 when there are more). */
static int calib_csv_split(char *line, char **field, int max)
{
    int n = 0;
    for (char *s = line;; ) {
        char *comma = strchr(s, ',');
        if (comma)
            *comma = '\0';
        if (n == max)
            return max + 1;
        field[n++] = calib_csv_clean(s);
        if (!comma)
            return n;
        s = comma + 1;
    }
}

/* Checks the header line's names and order. */
static int calib_csv_check_header(char *line, const char *path, int lineno, char *err,
                                  size_t errlen)
{
    char *f[CALIB_CSV_COLS + 1];
    int n = calib_csv_split(line, f, CALIB_CSV_COLS);
    for (int c = 0; c < CALIB_CSV_COLS; c++)
        if (n != CALIB_CSV_COLS || strcasecmp(f[c], calib_csv_header[c])) {
            snprintf(err, errlen, "%s:%d: the header must be "
                     "L1,L2,L3,L4,L5,L6,X,Y,Z,A,B,C", path, lineno);
            return -1;
        }
    return 0;
}

/* Reads one data row into m. */
static int calib_csv_row(char *line, const char *path, int lineno, struct calib_meas *m,
                         char *err, size_t errlen)
{
    char *f[CALIB_CSV_COLS + 1];
    int n = calib_csv_split(line, f, CALIB_CSV_COLS);
    if (n != CALIB_CSV_COLS) {
        snprintf(err, errlen, "%s:%d: %s %d fields: expected %d (L1..L6, X Y Z A B C)", path,
                 lineno, n > CALIB_CSV_COLS ? "more than" : "only", n > CALIB_CSV_COLS ?
                 CALIB_CSV_COLS : n, CALIB_CSV_COLS);
        return -1;
    }
    for (int c = 0; c < CALIB_CSV_COLS; c++) {
        char *end;
        errno = 0;
        double v = strtod(f[c], &end);
        if (end == f[c] || *end != '\0' || errno == ERANGE || !isfinite(v)) {
            snprintf(err, errlen, "%s:%d: %s: '%s' is not a number", path, lineno,
                     calib_csv_header[c], f[c]);
            return -1;
        }
        if (c < CALIB_LEGS)
            m->legs_mm[c] = v;
        else
            m->pose[c - CALIB_LEGS] = v;
    }
    m->line = lineno;
    return 0;
}

/* Parses text (see calib_csv.h). */
enum calib_status calib_csv_parse(const char *text, const char *path, struct calib_meas **out,
                                  int *n_out, char *err, size_t errlen)
{
    char *copy = strdup(text);
    struct calib_meas *m = NULL;
    int n = 0, cap = 0, lineno = 0, have_header = 0;
    enum calib_status st = CALIB_ERR_NOMEM;
    if (!copy)
        goto fail;
    st = CALIB_ERR_ARG;
    for (char *save = NULL, *raw = copy; raw; raw = save) {
        save = strchr(raw, '\n');
        if (save)
            *save++ = '\0';
        lineno++;
        char *line = calib_csv_clean(raw);
        if (!*line)
            continue;
        if (!have_header) {
            if (calib_csv_check_header(line, path, lineno, err, errlen) != 0)
                goto fail;
            have_header = 1;
            continue;
        }
        if (n == cap) {
            int ncap = cap ? 2 * cap : 64;
            struct calib_meas *grown = realloc(m, (size_t)ncap * sizeof *m);
            if (!grown) {
                st = CALIB_ERR_NOMEM;
                goto fail;
            }
            m = grown;
            cap = ncap;
        }
        if (calib_csv_row(line, path, lineno, &m[n], err, errlen) != 0)
            goto fail;
        n++;
    }
    if (!have_header) {
        snprintf(err, errlen, "%s: empty: no header L1,L2,L3,L4,L5,L6,X,Y,Z,A,B,C", path);
        goto fail;
    }
    free(copy);
    *out = m;
    *n_out = n;
    return CALIB_OK;
fail:
    free(copy);
    free(m);
    return st;
}
