/* calib_ini.c: a machine's INI text with its geometry replaced by a calibrated one, every
 * other line kept as it was (comments, order, other sections). */
#include <ctype.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/calib_ini.h"

/* The [KINS] keys that describe the geometry; the calibrated INI comments them out. */
static int calib_ini_is_geometry_key(const char *key, size_t len)
{
    static const char *const keys[] = { "BASE_RADIUS", "PLATFORM_RADIUS", "BASE_HALF_ANGLE",
                                         "PLATFORM_HALF_ANGLE", "BASE_Z", "PLATFORM_Z",
                                         "LEG_OFFSET" };
    char name[40];
    int idx;
    char tail;
    if (len == 0 || len >= sizeof name)
        return 0;
    memcpy(name, key, len);
    name[len] = '\0';
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
        if (!strcmp(name, keys[i]))
            return 1;
    return sscanf(name, "BASE_%d%c", &idx, &tail) == 1 ||
           sscanf(name, "PLATFORM_%d%c", &idx, &tail) == 1;
}

/* A growing output string. */
struct calib_buf {
    char *s;        /* text, NUL-terminated */
    size_t n, cap;  /* length and allocation */
    int failed;     /* an allocation failed */
};

/* Appends formatted text. */
static void calib_buf_printf(struct calib_buf *b, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static void calib_buf_printf(struct calib_buf *b, const char *fmt, ...)
{
    va_list ap;
    for (int pass = 0; pass < 2 && !b->failed; pass++) {
        va_start(ap, fmt);
        int w = vsnprintf(b->s ? b->s + b->n : NULL, b->s ? b->cap - b->n : 0, fmt, ap);
        va_end(ap);
        if (w < 0) {
            b->failed = 1;
            return;
        }
        if (b->s && b->n + (size_t)w < b->cap) {
            b->n += (size_t)w;
            return;
        }
        size_t cap = 2 * (b->cap + (size_t)w) + 64;
        char *grown = realloc(b->s, cap);
        if (!grown) {
            b->failed = 1;
            return;
        }
        b->s = grown;
        b->cap = cap;
    }
}

/* Writes the calibrated geometry block. */
static void calib_ini_block(struct calib_buf *b, const struct calib_geom *g, const char *note)
{
    char key[24], val[160];
    calib_buf_printf(b, "# Calibrated geometry (explicit joints, mm, and leg offsets: joint "
                     "value + offset = joint-centre distance)\n");
    if (note && *note)
        calib_buf_printf(b, "# %s\n", note);
    for (int i = 0; i < CALIB_LEGS; i++) {
        snprintf(key, sizeof key, "BASE_%d", i);
        calib_buf_printf(b, "%s = %s\n", key, calib_geom_key_value(g, key, val, sizeof val));
    }
    for (int i = 0; i < CALIB_LEGS; i++) {
        snprintf(key, sizeof key, "PLATFORM_%d", i);
        calib_buf_printf(b, "%s = %s\n", key, calib_geom_key_value(g, key, val, sizeof val));
    }
    calib_buf_printf(b, "LEG_OFFSET = %s\n", calib_geom_key_value(g, "LEG_OFFSET", val,
                                                                   sizeof val));
}

/* Rewrites the INI text (see calib_ini.h). */
char *calib_ini_rewrite(const char *text, const struct calib_geom *g, const char *note)
{
    struct calib_buf b = { 0 };
    int in_kins = 0, placed = 0;
    calib_buf_printf(&b, "%s", "");
    for (const char *line = text; *line; ) {
        const char *eol = strchr(line, '\n');
        size_t len = eol ? (size_t)(eol - line) : strlen(line);
        const char *s = line;
        while (s < line + len && isspace((unsigned char)*s))
            s++;
        if (*s == '[') {
            in_kins = !strncmp(s, "[KINS]", 6);
        } else if (in_kins && *s != '#' && *s != ';') {
            size_t k = 0;
            while (s + k < line + len && (isalnum((unsigned char)s[k]) || s[k] == '_'))
                k++;
            if (calib_ini_is_geometry_key(s, k))
                calib_buf_printf(&b, "# before calibration: ");
        }
        calib_buf_printf(&b, "%.*s\n", (int)len, line);
        if (*s == '[' && in_kins && !placed) {
            calib_ini_block(&b, g, note);
            placed = 1;
        }
        line += len + (eol ? 1 : 0);
    }
    if (!placed) {
        calib_buf_printf(&b, "\n[KINS]\n");
        calib_ini_block(&b, g, note);
    }
    if (b.failed) {
        free(b.s);
        return NULL;
    }
    return b.s;
}
