/* test_tooltable.c: the LinuxCNC-format tool table: load, wear, G10 L1, atomic save, errors. */
#include <check.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "interp/tooltable.h"
#include "test_file_util.h"

static const char paper_table[] =
    "; the paper's tools\n"
    "T1 P1 D10.0 Z+0.0 ;carbide end mill, 10 mm\n"
    "\n"
    "t2 p2 d12 z-1.5 x0.25 ;lower-case letters are accepted\n"
    "T3 P3 D20.0 Z+0.0 I10 J80 Q2 ;carbide end mill, 20 mm\n"
    "T10001 P0 D-0.04 ;wear of T1\n";

START_TEST(test_load_find)
{
    char dir[64], path[128], err[256] = "";
    struct tooltable t;
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/tool.tbl", dir);
    write_file(path, paper_table);
    ck_assert_int_eq(tooltable_load(&t, path, err, sizeof err), TOOLTABLE_OK);
    ck_assert_int_eq(t.count, 3);
    ck_assert_str_eq(t.path, path);
    struct tool_entry *e = tooltable_find(&t, 2);
    ck_assert_ptr_nonnull(e);
    ck_assert_int_eq(e->pocket, 2);
    ck_assert_double_eq(e->diameter_mm, 12.0);
    ck_assert_double_eq(e->z_offset_mm, -1.5);
    ck_assert_double_eq(e->offset[0], 0.25);
    ck_assert_str_eq(e->comment, "lower-case letters are accepted");
    ck_assert_ptr_null(tooltable_find(&t, 4));
    ck_assert_ptr_null(tooltable_find(&t, 10001)); /* the wear entry is not a tool */
    e = tooltable_find(&t, 1);
    ck_assert_double_eq_tol(e->wear_mm, -0.04, 1e-15);
    double r;
    ck_assert_int_eq(tooltable_radius(&t, 1, &r), TOOLTABLE_OK);
    ck_assert_double_eq_tol(r, 4.98, 1e-12); /* (10 - 0.04) / 2 */
    ck_assert_int_eq(tooltable_radius(&t, 3, &r), TOOLTABLE_OK);
    ck_assert_double_eq_tol(r, 10.0, 1e-12);
    ck_assert_int_eq(tooltable_radius(&t, 9, &r), TOOLTABLE_ERR_NO_TOOL);
    rm_dir(dir);
}
END_TEST

/* Wear set from the program, saved atomically, read back: nothing lost, no stray files. */
START_TEST(test_save_round_trip)
{
    char dir[64], path[128], err[256] = "";
    struct tooltable t, u;
    make_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/tool.tbl", dir);
    write_file(path, paper_table);
    ck_assert_int_eq(tooltable_load(&t, path, err, sizeof err), TOOLTABLE_OK);
    ck_assert_int_eq(tooltable_set_wear(&t, 3, -0.125), TOOLTABLE_OK);
    ck_assert_int_eq(tooltable_set_wear(&t, 7, -0.1), TOOLTABLE_ERR_NO_TOOL);
    /* A second name for the old file: a save that renames a new file into place leaves it
     * alone, one that rewrote the file in place would change it. */
    char old_link[160];
    snprintf(old_link, sizeof old_link, "%s/old.tbl", dir);
    ck_assert_int_eq(link(path, old_link), 0);
    ck_assert_int_eq(tooltable_save(&t, path, err, sizeof err), TOOLTABLE_OK);
    ck_assert_int_eq(count_entries(dir, ""), 2); /* tool.tbl and old.tbl: no temporary left */
    ck_assert_int_eq(tooltable_load(&u, old_link, err, sizeof err), TOOLTABLE_OK);
    ck_assert_double_eq(tooltable_find(&u, 3)->wear_mm, 0.0);
    unlink(old_link);
    ck_assert_int_eq(tooltable_load(&u, path, err, sizeof err), TOOLTABLE_OK);
    ck_assert_int_eq(u.count, t.count);
    for (int i = 0; i < t.count; i++) {
        const struct tool_entry *a = &t.tools[i];
        const struct tool_entry *b = tooltable_find(&u, a->tool);
        ck_assert_ptr_nonnull(b);
        ck_assert_int_eq(b->pocket, a->pocket);
        ck_assert_double_eq(b->diameter_mm, a->diameter_mm);
        ck_assert_double_eq(b->wear_mm, a->wear_mm);
        ck_assert_double_eq(b->z_offset_mm, a->z_offset_mm);
        ck_assert_double_eq(b->offset[0], a->offset[0]);
        ck_assert_double_eq(b->front_angle_deg, a->front_angle_deg);
        ck_assert_double_eq(b->back_angle_deg, a->back_angle_deg);
        ck_assert_int_eq(b->orientation, a->orientation);
        ck_assert_uint_eq(b->present, a->present);
        ck_assert_str_eq(b->comment, a->comment);
    }
    double r;
    ck_assert_int_eq(tooltable_radius(&u, 3, &r), TOOLTABLE_OK);
    ck_assert_double_eq_tol(r, 9.9375, 1e-12);
    /* The wear is stored as LinuxCNC's wear entry T10003 in the file. */
    FILE *f = fopen(path, "r");
    char text[2048];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    ck_assert_ptr_nonnull(strstr(text, "T10003 P0 D-0.125"));
    rm_dir(dir);
}
END_TEST

/* A failed save leaves the old file untouched and no temporary file behind. */
START_TEST(test_save_fails_cleanly)
{
    char err[256] = "";
    struct tooltable t;
    tooltable_init(&t);
    ck_assert_int_eq(tooltable_g10_l1(&t, 1, 1, 5.0, 0, 0.0), TOOLTABLE_OK);
    ck_assert_int_eq(tooltable_save(&t, "/nonexistent-dir/tool.tbl", err, sizeof err),
                     TOOLTABLE_ERR_IO);
    ck_assert_ptr_nonnull(strstr(err, "/nonexistent-dir/tool.tbl"));
    ck_assert_int_eq(tooltable_load(&t, "/nonexistent-dir/tool.tbl", err, sizeof err),
                     TOOLTABLE_ERR_IO);
    ck_assert_int_eq(t.count, 0);
}
END_TEST

/* Parses text and expects `status` with "name:line:" at the start of the message. */
static void expect_parse_error(const char *text, int status, int line, const char *word)
{
    struct tooltable t;
    char err[256] = "", where[32];
    ck_assert_int_eq(tooltable_parse(&t, text, "x.tbl", err, sizeof err), status);
    snprintf(where, sizeof where, "x.tbl:%d: ", line);
    ck_assert_msg(!strncmp(err, where, strlen(where)), "'%s' does not start with '%s'", err,
                  where);
    ck_assert_msg(strstr(err, word), "'%s' lacks '%s'", err, word);
    ck_assert_int_eq(t.count, 0); /* never half-loaded */
}

START_TEST(test_syntax_errors)
{
    expect_parse_error("T1 P1 D10\nT2 P2 K5 D6\n", TOOLTABLE_ERR_SYNTAX, 2, "unknown field");
    expect_parse_error("T1 P1 D10\n\nP3 D6 ;no T\n", TOOLTABLE_ERR_SYNTAX, 3, "no tool number");
    expect_parse_error("T1 P1 Dabc\n", TOOLTABLE_ERR_SYNTAX, 1, "field D");
    expect_parse_error("T1.5 P1 D10\n", TOOLTABLE_ERR_SYNTAX, 1, "whole");
    expect_parse_error("T1 P1 D10 D12\n", TOOLTABLE_ERR_SYNTAX, 1, "twice");
    expect_parse_error("T1 P1 D10Z0\n", TOOLTABLE_ERR_SYNTAX, 1, "space");
    expect_parse_error("T1 P1 D0x10\n", TOOLTABLE_ERR_SYNTAX, 1, "field D");
    expect_parse_error("T1 P1 Dinf\n", TOOLTABLE_ERR_SYNTAX, 1, "field D");
    expect_parse_error("T-1 P1 D10\n", TOOLTABLE_ERR_SYNTAX, 1, "negative");
    expect_parse_error("TOOLNO POCKET LENGTH DIAMETER COMMENT\n1 1 +0.5 abc x\n",
                       TOOLTABLE_ERR_SYNTAX, 2, "column 4 (D)");
    expect_parse_error("TOOLNO POCKET WIDTH\n", TOOLTABLE_ERR_SYNTAX, 1, "WIDTH");
    expect_parse_error("T1 P1 D-10\n", TOOLTABLE_ERR_VALUE, 1, "negative diameter");
}
END_TEST

START_TEST(test_duplicates)
{
    struct tooltable t;
    char err[256] = "";
    double r;
    /* LinuxCNC uses the first of two lines for one tool (its woodpecker example has two T6);
     * so does hexcnc, with a warning, and refuses compensation with that ambiguous tool. */
    ck_assert_int_eq(tooltable_parse(&t, "T1 P1 D10\nT2 P2 D6\nT1 P3 D8\n", "x.tbl", err,
                                     sizeof err), TOOLTABLE_OK);
    ck_assert_int_eq(t.count, 2);
    ck_assert_int_eq(tooltable_find(&t, 1)->pocket, 1);
    ck_assert_int_eq(tooltable_find(&t, 1)->duplicate_line, 3);
    ck_assert_int_eq(t.nwarnings, 1);
    ck_assert_msg(!strncmp(t.warning, "x.tbl:3: tool T1 appears again (first on line 1)", 47),
                  "%s", t.warning);
    ck_assert_int_eq(tooltable_radius(&t, 1, &r), TOOLTABLE_ERR_DUPLICATE);
    ck_assert_int_eq(tooltable_radius(&t, 2, &r), TOOLTABLE_OK);
    expect_parse_error("T1 D10\nT10001 D-0.1\nT10001 D-0.2\n", TOOLTABLE_ERR_DUPLICATE, 3,
                       "line 2");
}
END_TEST

/* What LinuxCNC's shipped tables hold: T0, big tool numbers, wear entries with every field,
 * T10000+n without tool n, the older headed format, header and comment lines. */
START_TEST(test_linuxcnc_cases)
{
    struct tooltable t;
    char err[256] = "";
    ck_assert_msg(tooltable_parse(&t,
        "; header comment\n"
        "T0 P0 X0 Y0 Z0 A0 B0 C0 U0 V0 W0 D0 I0 J0 Q0 ;NO TOOL LOADED \n"
        "T1 P1 X0.10000 Y0 Z0 A0 B0 C0 U0 V0 W0 D0.10000 I95.0 J155.0 Q1 ;face \n"
        "T99999 P99999 Z+0.1 ;big tool number\n"
        "T10005 P5 D3 ;no T5: an ordinary tool\n"
        "T10001 P0 X0.00100 Y0 Z0.00100 A0 B0 C0 U0 V0 W0 D-0.02 I0 J0 Q0 ;Wear Offset 1 \n",
        "lathe.tbl", err, sizeof err) == TOOLTABLE_OK, "%s", err);
    ck_assert_int_eq(t.count, 4);                       /* T0 T1 T99999 T10005 */
    ck_assert_ptr_nonnull(tooltable_find(&t, 0));
    ck_assert_double_eq(tooltable_find(&t, 99999)->z_offset_mm, 0.1);
    ck_assert_double_eq(tooltable_find(&t, 10005)->diameter_mm, 3);
    ck_assert_ptr_null(tooltable_find(&t, 10001));      /* tool 1's wear */
    ck_assert_double_eq(tooltable_find(&t, 1)->wear_mm, -0.02);
    ck_assert_int_eq(tooltable_find(&t, 1)->orientation, 1);
    ck_assert_double_eq(tooltable_find(&t, 1)->front_angle_deg, 95);
    /* a number that would read back as something else is refused */
    struct tool_entry e = { .tool = 10001, .pocket = 1 };
    ck_assert_int_eq(tooltable_set(&t, &e), TOOLTABLE_ERR_DUPLICATE);
    e.tool = 5;
    ck_assert_int_eq(tooltable_set(&t, &e), TOOLTABLE_ERR_DUPLICATE);
    /* LinuxCNC's older format: a header naming the columns, rows of bare numbers */
    ck_assert_msg(tooltable_parse(&t,
        "TOOLNO POCKET       LENGTH    DIAMETER  COMMENT\n\n"
        "     1      1    +0.511000    0.125000  1/8 end mill\n"
        " 99999  99999    +0.100000    0.000000  big tool number\n",
        "gantry.tbl", err, sizeof err) == TOOLTABLE_OK, "%s", err);
    ck_assert_int_eq(t.count, 2);
    ck_assert_double_eq(tooltable_find(&t, 1)->z_offset_mm, 0.511);
    ck_assert_double_eq(tooltable_find(&t, 1)->diameter_mm, 0.125);
    ck_assert_str_eq(tooltable_find(&t, 1)->comment, "1/8 end mill");
}
END_TEST

/* The radius: from the diameter plus wear; missing, zero or negative is refused. */
START_TEST(test_radius)
{
    struct tooltable t;
    char err[256];
    double r = -1;
    ck_assert_int_eq(tooltable_parse(&t, "T1 P1\nT2 D0.1\nT10002 D-0.3\nT3 D6\n", "m", err,
                                     sizeof err), TOOLTABLE_OK);
    ck_assert_int_eq(tooltable_radius(&t, 1, &r), TOOLTABLE_ERR_VALUE); /* no D */
    ck_assert_int_eq(tooltable_radius(&t, 2, &r), TOOLTABLE_ERR_VALUE); /* worn below 0 */
    ck_assert_double_eq(r, -1);
    ck_assert_int_eq(tooltable_radius(&t, 3, &r), TOOLTABLE_OK);
    ck_assert_double_eq(r, 3.0);
    ck_assert_str_ne(tooltable_strerror(TOOLTABLE_ERR_VALUE), "unknown tool table status");
}
END_TEST

/* G10 L1 keeps R = radius; P 10000 + n carries tool n's wear (as a radius delta). */
START_TEST(test_g10_l1)
{
    struct tooltable t;
    double r;
    tooltable_init(&t);
    ck_assert_int_eq(tooltable_g10_l1(&t, 4, 1, 6.0, 1, 12.5), TOOLTABLE_OK);
    struct tool_entry *e = tooltable_find(&t, 4);
    ck_assert_ptr_nonnull(e);
    ck_assert_double_eq(e->diameter_mm, 12.0);
    ck_assert_double_eq(e->z_offset_mm, 12.5);
    ck_assert_int_eq(tooltable_g10_l1(&t, 10004, 1, -0.02, 0, 0), TOOLTABLE_OK);
    ck_assert_double_eq_tol(e->wear_mm, -0.04, 1e-15);
    ck_assert_double_eq(e->diameter_mm, 12.0); /* the nominal size is untouched */
    ck_assert_int_eq(tooltable_radius(&t, 4, &r), TOOLTABLE_OK);
    ck_assert_double_eq_tol(r, 5.98, 1e-12);
    ck_assert_int_eq(tooltable_g10_l1(&t, 4, 0, 0, 1, 3.0), TOOLTABLE_OK); /* Z only */
    ck_assert_double_eq(e->diameter_mm, 12.0);
    ck_assert_double_eq_tol(e->wear_mm, -0.04, 1e-15);
    ck_assert_int_eq(tooltable_g10_l1(&t, 10005, 1, -0.02, 0, 0), TOOLTABLE_ERR_NO_TOOL);
    ck_assert_int_eq(tooltable_g10_l1(&t, 10004, 1, -0.02, 1, 1.0), TOOLTABLE_ERR_VALUE);
    ck_assert_int_eq(tooltable_g10_l1(&t, 4, 1, -1.0, 0, 0), TOOLTABLE_ERR_VALUE);
    ck_assert_int_eq(tooltable_g10_l1(&t, 0, 1, 1.0, 0, 0), TOOLTABLE_ERR_NO_TOOL);
}
END_TEST

START_TEST(test_full)
{
    struct tooltable t;
    struct tool_entry e;
    tooltable_init(&t);
    memset(&e, 0, sizeof e);
    for (int k = 1; k <= TOOLTABLE_MAX; k++) {
        e.tool = k;
        ck_assert_int_eq(tooltable_set(&t, &e), TOOLTABLE_OK);
    }
    e.tool = TOOLTABLE_MAX + 1;
    ck_assert_int_eq(tooltable_set(&t, &e), TOOLTABLE_ERR_FULL);
    e.tool = 5; /* replacing is still possible */
    e.diameter_mm = 3.0;
    ck_assert_int_eq(tooltable_set(&t, &e), TOOLTABLE_OK);
    ck_assert_int_eq(t.count, TOOLTABLE_MAX);
}
END_TEST

/* The simulated machine's table (configs/sim) loads. */
START_TEST(test_sim_table)
{
    const char *root = getenv("HEXCNC_ROOT");
    char path[600], err[256] = "";
    struct tooltable t;
    double r;
    snprintf(path, sizeof path, "%s/configs/sim/tmu-hexapod.tbl", root ? root : ".");
    ck_assert_msg(tooltable_load(&t, path, err, sizeof err) == TOOLTABLE_OK, "%s", err);
    ck_assert_int_eq(tooltable_radius(&t, 3, &r), TOOLTABLE_OK);
    ck_assert_double_eq_tol(r, 10.0, 1e-12);
}
END_TEST

static Suite *tooltable_suite(void)
{
    Suite *s = suite_create("tooltable");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, test_load_find);
    tcase_add_test(tc, test_save_round_trip);
    tcase_add_test(tc, test_save_fails_cleanly);
    tcase_add_test(tc, test_syntax_errors);
    tcase_add_test(tc, test_duplicates);
    tcase_add_test(tc, test_linuxcnc_cases);
    tcase_add_test(tc, test_radius);
    tcase_add_test(tc, test_g10_l1);
    tcase_add_test(tc, test_full);
    tcase_add_test(tc, test_sim_table);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(tooltable_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
