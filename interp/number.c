/* number.c: exact decimal reading and exact fixed-point printing, both fast for short numbers. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "interp/interp.h"
#include "interp/printer.h"

/* Powers of ten that a double holds exactly (10^22 is the last one). */
static const double pow10_exact[23] = {
    1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
    1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
};

/* Slow path: hands the digits to strtod, which rounds correctly (C locale point). */
static double decimal_slow(const char *s, size_t n)
{
    char buf[512];
    if (n >= sizeof buf) {
        char *p = malloc(n + 1);
        if (!p)
            return NAN;
        memcpy(p, s, n);
        p[n] = 0;
        double v = strtod(p, NULL);
        free(p);
        return v;
    }
    memcpy(buf, s, n);
    buf[n] = 0;
    return strtod(buf, NULL);
}

/*
 * Reads [+-]digits[.digits]. Fast path: when the significant digits form an integer
 * m <= 2^53 and there are k <= 22 digits after the point, m and 10^k are both exact
 * doubles, so the one IEEE division m / 10^k is correctly rounded: the same double that
 * strtod returns. Anything else goes to strtod.
 */
size_t interp_parse_decimal(const char *s, size_t len, double *out)
{
    size_t i = 0, lead;
    int neg = 0;
    if (i < len && (s[i] == '+' || s[i] == '-'))
        neg = s[i++] == '-';
    size_t start = i;
    while (i < len && s[i] == '0')
        i++;
    lead = i;
    uint64_t m = 0; /* wraps when sig > 19: then it is not used */
    while (i < len && (unsigned)(s[i] - '0') < 10)
        m = m * 10 + (uint64_t)(s[i++] - '0');
    size_t sig = i - lead, frac = 0;
    int digits = i > start;
    if (i < len && s[i] == '.') {
        size_t fs = ++i;
        if (sig == 0)
            while (i < len && s[i] == '0')
                i++;
        size_t fsig = i;
        while (i < len && (unsigned)(s[i] - '0') < 10)
            m = m * 10 + (uint64_t)(s[i++] - '0');
        frac = i - fs;
        sig += i - fsig;
        digits |= i > fs;
    }
    if (!digits)
        return 0;
    double v;
    if (sig <= 19 && m <= (UINT64_C(1) << 53) && frac <= 22)
        v = frac ? (double)m / pow10_exact[frac] : (double)m;
    else
        v = fabs(decimal_slow(s, i));
    *out = neg ? -v : v;
    return i;
}

/* "00" .. "99": two digits per division when printing. */
static const char digit_pairs[201] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

/* Writes the decimal digits of n backwards ending at end, exactly `width` of them (zero
 * padded) or, with width 0, as many as n needs; returns the start. */
static char *utoa_back(uint64_t n, char *end, int width)
{
    char *q = end;
    while (n >= 100) {
        unsigned d = (unsigned)(n % 100) * 2;
        n /= 100;
        *--q = digit_pairs[d + 1];
        *--q = digit_pairs[d];
    }
    if (n >= 10) {
        *--q = digit_pairs[n * 2 + 1];
        *--q = digit_pairs[n * 2];
    } else {
        *--q = (char)('0' + n);
    }
    while (end - q < width)
        *--q = '0';
    return q;
}

/*
 * printf("%.*f", digits, v), exactly, without printf. With s = 10^digits exact, the
 * product p = fl(v s) and its exact error e = fma(v, s, -p) give v s = p + e exactly.
 * Below 2^52, p - floor(p) is exact and a multiple of ulp(p), while |e| <= ulp(p) / 2, so
 * comparing p - floor(p) with 0.5 decides the rounding except on an exact 0.5, where the
 * sign of e decides, and e = 0 is a true tie: rounded to even, as glibc does.
 */
size_t interp_format_fixed(double v, int digits, char *out)
{
    if (digits < 0 || digits > 15 || !isfinite(v))
        return (size_t)sprintf(out, "%.*f", digits < 0 ? 0 : digits, v);
    double a = fabs(v), s = pow10_exact[digits];
    double p = a * s;
    if (!(p < 4503599627370496.0)) /* 2^52 */
        return (size_t)sprintf(out, "%.*f", digits, v);
    double e = fma(a, s, -p);
    double fl = floor(p), f = p - fl;
    uint64_t n = (uint64_t)fl;
    if (f > 0.5 || (f == 0.5 && (e > 0 || (e == 0 && (n & 1)))))
        n++;
    char tmp[48], *end = tmp + sizeof tmp, *q = end;
    uint64_t ip = n;
    if (digits) {
        uint64_t sc = (uint64_t)s;
        ip = n / sc;
        q = utoa_back(n % sc, q, digits);
        *--q = '.';
    }
    q = utoa_back(ip, q, 0);
    if (signbit(v))
        *--q = '-';
    size_t len = (size_t)(end - q);
    memcpy(out, q, len);
    out[len] = 0;
    return len;
}
