/* test_interp_number.c: the exact decimal reader against strtod, the fixed printer against printf. */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "interp/interp.h"
#include "interp/printer.h"

/* xorshift64: reproducible random numbers without global state. */
static uint64_t next_rand(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

/* Parses s both ways and requires the very same double. */
static void check_parse(const char *s)
{
    double mine = -1, ref = strtod(s, NULL);
    size_t n = interp_parse_decimal(s, strlen(s), &mine);
    ck_assert_msg(n == strlen(s), "%s: read %zu characters", s, n);
    ck_assert_msg(memcmp(&mine, &ref, sizeof mine) == 0, "%s: %.17g, strtod %.17g", s, mine, ref);
}

START_TEST(parse_edge_cases)
{
    static const char *const cases[] = {
        "0", "-0", "-0.0", ".5", "5.", "+3.25", "0.1", "0.3", "1.7976931348623157",
        "9007199254740992", "9007199254740993", "9007199254740993.5", "123456789012345678901234.5",
        "0.0000000000000000000001", "0.00000000000000000000001", "12345678901234567890",
        "1.0000000000000000000000000001", "2.675", "1234.56789", "-99999.99999",
        "00000000000000000000000000012.5", "0.000000000000000000000000000000000000001",
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        check_parse(cases[i]);
}
END_TEST

START_TEST(parse_stops_and_rejects)
{
    double v = 0;
    ck_assert_uint_eq(interp_parse_decimal("12.5y3", 6, &v), 4);
    ck_assert_double_eq(v, 12.5);
    ck_assert_uint_eq(interp_parse_decimal("1.2.3", 5, &v), 3);
    ck_assert_uint_eq(interp_parse_decimal("-x", 2, &v), 0);
    ck_assert_uint_eq(interp_parse_decimal(".", 1, &v), 0);
    ck_assert_uint_eq(interp_parse_decimal("7", 0, &v), 0);
}
END_TEST

/* 200,000 random decimals of every shape G-code uses (and longer), each equal to strtod's. */
START_TEST(parse_random_matches_strtod)
{
    uint64_t s = 0x9e3779b97f4a7c15u;
    char buf[64];
    for (int i = 0; i < 200000; i++) {
        uint64_t r = next_rand(&s);
        int ip = (int)(r % 12), fp = (int)((r >> 4) % 26), n = 0;
        if (r & (1u << 9))
            buf[n++] = '-';
        for (int k = 0; k < ip; k++)
            buf[n++] = (char)('0' + next_rand(&s) % 10);
        if (fp || !ip) {
            buf[n++] = '.';
            for (int k = 0; k < (fp ? fp : 1); k++)
                buf[n++] = (char)('0' + next_rand(&s) % 10);
        }
        buf[n] = 0;
        check_parse(buf);
    }
}
END_TEST

/* Formats v both ways and requires the same text. */
static void check_format(double v, int digits)
{
    char mine[400], ref[400];
    interp_format_fixed(v, digits, mine);
    snprintf(ref, sizeof ref, "%.*f", digits, v);
    ck_assert_msg(strcmp(mine, ref) == 0, "%.17g at %d digits: %s, printf %s", v, digits, mine, ref);
}

START_TEST(format_edge_cases)
{
    static const double cases[] = {
        0.0, -0.0, 1.03125, -1.03125, 0.00005, -0.00005, 0.00015, 2.5, 3.5, -2.5, 0.5,
        1.00005, 123.45675, 1e15, 4503599627370495.5, 1e20, 1e300, -1e300, 9.99995, 0.99995,
        1.0 / 3.0, 2.0 / 3.0, 1e-20, -1e-20, 5e-5, 25.4, 630.697565, 59.975641,
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++)
        for (int d = 0; d <= 12; d++)
            check_format(cases[i], d);
    check_format(INFINITY, 4);
    check_format(-INFINITY, 4);
}
END_TEST

/* Random doubles: short decimals (ties included), arbitrary bit patterns and magnitudes. */
START_TEST(format_random_matches_printf)
{
    uint64_t s = 0x2545f4914f6cdd1du;
    for (int i = 0; i < 200000; i++) {
        uint64_t r = next_rand(&s);
        double v;
        switch (r % 3) {
        case 0: /* a short decimal, often exactly halfway at 4 digits */
            v = (double)(int64_t)(next_rand(&s) % 200000000 - 100000000) / 100000.0;
            break;
        case 1: /* dyadic values: exact ties at many digit counts */
            v = (double)(int64_t)(next_rand(&s) % 2000000 - 1000000) / 1024.0;
            break;
        default: { /* any finite double of moderate exponent */
            uint64_t bits = next_rand(&s);
            bits = (bits & 0x800fffffffffffffu) | ((uint64_t)(1023 - 30 + next_rand(&s) % 70) << 52);
            memcpy(&v, &bits, sizeof v);
        }
        }
        check_format(v, (int)((r >> 8) % 10));
    }
}
END_TEST

static Suite *number_suite(void)
{
    Suite *s = suite_create("interp_number");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, parse_edge_cases);
    tcase_add_test(tc, parse_stops_and_rejects);
    tcase_add_test(tc, parse_random_matches_strtod);
    tcase_add_test(tc, format_edge_cases);
    tcase_add_test(tc, format_random_matches_printf);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(number_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
