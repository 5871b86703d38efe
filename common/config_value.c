/* config_value.c: the value rules of every configuration key (numbers, lists, integers,
 * booleans, ranges), one set for all readers. */
#include "common/config.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* Writes a reason and returns -1. */
static int config_why(char *why, size_t whylen, const char *text)
{
    if (why && whylen)
        snprintf(why, whylen, "%s", text);
    return -1;
}

static const char *config_skip_blanks(const char *s)
{
    while (*s == ' ' || *s == '\t')
        s++;
    return s;
}

/* One decimal number at *s (no hex, inf or nan: strtod takes those, a machine's INI must
 * not); *s moves past it. */
static int config_scan_number(const char **s, double *out)
{
    const char *p = config_skip_blanks(*s);
    size_t n = strspn(p, "0123456789+-.eE");
    if (n == 0 || n >= 64)
        return -1;
    char buf[64];
    memcpy(buf, p, n);
    buf[n] = '\0';
    char *end;
    errno = 0;
    double v = strtod(buf, &end);
    if (end != buf + n || errno == ERANGE || !isfinite(v))
        return -1;
    *out = v;
    *s = p + n;
    return 0;
}

/* One finite decimal number, blanks around it allowed, nothing else. */
int config_parse_number(const char *text, double *out, char *why, size_t whylen)
{
    const char *s = text;
    double v;
    if (config_scan_number(&s, &v) != 0 || *config_skip_blanks(s))
        return config_why(why, whylen, "not a number");
    *out = v;
    return 0;
}

/* n numbers separated by blanks or one comma ("1 2 3", "1, 2, 3"). */
int config_parse_numbers(const char *text, double *out, int n, char *why, size_t whylen)
{
    const char *s = text;
    double vals[16];
    if (n < 1 || n > 16)
        return config_why(why, whylen, "bad count");
    for (int i = 0; i < n; i++) {
        if (i > 0) {
            s = config_skip_blanks(s);
            if (*s == ',')
                s++;
        }
        if (config_scan_number(&s, &vals[i]) != 0) {
            if (why && whylen)
                snprintf(why, whylen, "expected %d numbers, number %d is missing or not a "
                         "number", n, i + 1);
            return -1;
        }
    }
    if (*config_skip_blanks(s)) {
        if (why && whylen)
            snprintf(why, whylen, "expected %d numbers, found more text", n);
        return -1;
    }
    memcpy(out, vals, (size_t)n * sizeof *out);
    return 0;
}

/* A whole number: decimal, or hexadecimal with 0x (register addresses). */
int config_parse_integer(const char *text, long *out, char *why, size_t whylen)
{
    const char *s = config_skip_blanks(text);
    int hex = (s[0] == '0' && (s[1] == 'x' || s[1] == 'X'));
    char *end;
    errno = 0;
    long v = strtol(s, &end, hex ? 16 : 10);
    if (end == s || (hex && end == s + 2) || errno == ERANGE || *config_skip_blanks(end))
        return config_why(why, whylen, "not a whole number");
    *out = v;
    return 0;
}

/* 0/1, TRUE/FALSE, YES/NO, ON/OFF in any case, as LinuxCNC's INI reader takes them. */
int config_parse_bool(const char *text, int *out, char *why, size_t whylen)
{
    static const char *const yes[] = { "1", "TRUE", "YES", "ON" };
    static const char *const no[] = { "0", "FALSE", "NO", "OFF" };
    for (int i = 0; i < 4; i++) {
        if (!strcasecmp(text, yes[i]))
            return *out = 1, 0;
        if (!strcasecmp(text, no[i]))
            return *out = 0, 0;
    }
    return config_why(why, whylen, "expected 0 or 1 (or TRUE/FALSE, YES/NO, ON/OFF)");
}

/* Range texts: "" (any), "> A", ">= A", "!= 0", "A..B" (both ends included). */
int config_in_range(double x, const char *range, char *why, size_t whylen)
{
    double lo, hi;
    int inside = 1;
    if (!range || !range[0])
        return 0;
    if (!strcmp(range, "!= 0"))
        inside = x != 0;
    else if (!strncmp(range, ">=", 2) && sscanf(range + 2, "%lf", &lo) == 1)
        inside = x >= lo;
    else if (range[0] == '>' && sscanf(range + 1, "%lf", &lo) == 1)
        inside = x > lo;
    else if (strstr(range, "..")) {   /* strtod stops at the second '.' of "0..59" */
        lo = strtod(range, NULL);
        hi = strtod(strstr(range, "..") + 2, NULL);
        inside = x >= lo && x <= hi;
    }
    if (inside)
        return 0;
    if (why && whylen) {
        const char *dots = strstr(range, "..");
        if (dots)
            snprintf(why, whylen, "must be from %.*s to %s", (int)(dots - range), range,
                     dots + 2);
        else
            snprintf(why, whylen, "must be %s", range);
    }
    return -1;
}
