/* test_check_util.h: paths, a tiny JSON reader and an XML tag balance check for the check tests. */
#ifndef HEXCNC_TEST_CHECK_UTIL_H
#define HEXCNC_TEST_CHECK_UTIL_H

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A path under the source tree (make sets HEXCNC_ROOT; else the tests run from it). */
static inline const char *tc_path(const char *rel, char *buf, size_t len)
{
    const char *root = getenv("HEXCNC_ROOT");
    if (rel[0] == '/')                   /* absolute: as it is */
        snprintf(buf, len, "%s", rel);
    else
        snprintf(buf, len, "%s/%s", root ? root : ".", rel);
    return buf;
}

/* ---- JSON: a recursive-descent validator (RFC 8259 grammar, no semantics) ---- */

static inline const char *tj_ws(const char *s)
{
    while (*s == ' ' || *s == '\n' || *s == '\r' || *s == '\t')
        s++;
    return s;
}
static const char *tj_value(const char *s, int depth);
static inline const char *tj_string(const char *s)
{
    if (*s != '"')
        return NULL;
    for (s++; *s && *s != '"'; s++) {
        if ((unsigned char)*s < 0x20)
            return NULL;
        if (*s == '\\') {
            s++;
            if (*s == 'u') {
                for (int i = 1; i <= 4; i++)
                    if (!isxdigit((unsigned char)s[i]))
                        return NULL;
                s += 4;
            } else if (!strchr("\"\\/bfnrt", *s) || !*s) {
                return NULL;
            }
        }
    }
    return *s == '"' ? s + 1 : NULL;
}
static inline const char *tj_number(const char *s)
{
    const char *b = s;
    if (*s == '-')
        s++;
    if (!isdigit((unsigned char)*s))
        return NULL;
    while (isdigit((unsigned char)*s))
        s++;
    if (*s == '.') {
        s++;
        if (!isdigit((unsigned char)*s))
            return NULL;
        while (isdigit((unsigned char)*s))
            s++;
    }
    if (*s == 'e' || *s == 'E') {
        s++;
        if (*s == '+' || *s == '-')
            s++;
        if (!isdigit((unsigned char)*s))
            return NULL;
        while (isdigit((unsigned char)*s))
            s++;
    }
    return s > b ? s : NULL;
}
static inline const char *tj_container(const char *s, int depth, char close, int object)
{
    s = tj_ws(s + 1);
    if (*s == close)
        return s + 1;
    for (;;) {
        if (object) {
            if (!(s = tj_string(s)))
                return NULL;
            s = tj_ws(s);
            if (*s++ != ':')
                return NULL;
        }
        if (!(s = tj_value(s, depth + 1)))
            return NULL;
        s = tj_ws(s);
        if (*s == close)
            return s + 1;
        if (*s++ != ',')
            return NULL;
        s = tj_ws(s);
    }
}
static const char *tj_value(const char *s, int depth)
{
    s = tj_ws(s);
    if (depth > 64)
        return NULL;
    if (*s == '{')
        return tj_container(s, depth, '}', 1);
    if (*s == '[')
        return tj_container(s, depth, ']', 0);
    if (*s == '"')
        return tj_string(s);
    if (!strncmp(s, "true", 4))
        return s + 4;
    if (!strncmp(s, "false", 5))
        return s + 5;
    if (!strncmp(s, "null", 4))
        return s + 4;
    return tj_number(s);
}
/* 1 when text is exactly one JSON value (with surrounding blanks). */
static inline int tj_valid(const char *text)
{
    const char *e = tj_value(text, 0);
    return e && *tj_ws(e) == 0;
}

/* ---- XML: every start tag closed by its own end tag, properly nested ---- */

static inline int tx_balanced(const char *s)
{
    char stack[64][32];
    int depth = 0, seen_root = 0;
    while ((s = strchr(s, '<'))) {
        if (s[1] == '?' || s[1] == '!') {          /* declaration or comment */
            s = strchr(s, '>');
            if (!s)
                return 0;
            continue;
        }
        int closing = s[1] == '/';
        const char *n = s + 1 + closing, *e = strchr(s, '>');
        size_t len = strcspn(n, " \t\n/>");
        if (!e || len == 0 || len >= sizeof stack[0])
            return 0;
        int empty = e[-1] == '/';
        if (closing) {
            if (depth == 0 || strncmp(stack[depth - 1], n, len) || stack[depth - 1][len])
                return 0;
            depth--;
        } else if (!empty) {
            if (depth == 64)
                return 0;
            memcpy(stack[depth], n, len);
            stack[depth++][len] = 0;
            seen_root = 1;
        }
        s = e + 1;
    }
    return depth == 0 && seen_root;
}

/* A whole file in memory (NULL when unreadable); caller frees. */
static inline char *tc_read(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *buf = NULL;
    size_t len = 0, cap = 0, n;
    char chunk[4096];
    while ((n = fread(chunk, 1, sizeof chunk, f)) > 0) {
        if (len + n + 1 > cap) {
            cap = 2 * (len + n + 1);
            char *nb = realloc(buf, cap);
            if (!nb)
                break;
            buf = nb;
        }
        memcpy(buf + len, chunk, n);
        len += n;
    }
    fclose(f);
    if (buf)
        buf[len] = 0;
    return buf;
}

#endif
