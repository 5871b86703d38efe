/* test_interp_setup.c: the interpreter's INI settings (FEED_UNITS, TOOL_TABLE with LinuxCNC's
 * [EMCIO] fallback, PARAMETER_FILE), paths relative to the INI's folder, and their errors. */
#include <check.h>
#include <sys/stat.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "interp/interp.h"
#include "interp/interp_setup.h"
#include "interp/tooltable.h"

/* An INI in memory: up to 8 [section] key = value entries, the first of a key wins. */
struct fake_ini {
    const char *e[8][3];
};

/* The get() the setup reads through. */
static const char *fake_get(void *ctx, const char *section, const char *key)
{
    const struct fake_ini *f = ctx;
    for (int i = 0; i < 8 && f->e[i][0]; i++)
        if (!strcmp(f->e[i][0], section) && !strcmp(f->e[i][1], key))
            return f->e[i][2];
    return NULL;
}

/* A fresh folder for the files of one test. */
static void make_dir(char *dir, size_t len)
{
    snprintf(dir, len, "/tmp/hexcnc-setup-XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(dir));
}

/* Writes dir/name. */
static void put(const char *dir, const char *name, const char *text)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    ck_assert_ptr_nonnull(f);
    fputs(text, f);
    fclose(f);
}

/* Reads dir/name into buf. */
static void get_text(const char *dir, const char *name, char *buf, size_t len)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "r");
    ck_assert_ptr_nonnull(f);
    size_t n = fread(buf, 1, len - 1, f);
    buf[n] = '\0';
    fclose(f);
}

/* Removes dir and the files the tests put there. */
static void remove_dir(const char *dir)
{
    static const char *const names[] = { "t.tbl", "io.tbl", "p.var", "p.var.tmp" };
    char path[512];
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        unlink(path);
    }
    rmdir(dir);
}

/* A sink that drops the commands. */
static int drop(void *ctx, const struct canon_cmd *c)
{
    (void)ctx, (void)c;
    return 0;
}

START_TEST(every_key_applied_with_relative_paths)
{
    char dir[64], err[512];
    make_dir(dir, sizeof dir);
    put(dir, "t.tbl", "T3 P3 D20.0 Z+5.0 ;twenty\n");
    put(dir, "p.var", "5220 1\n5221 40\n5222 -30\n5223 -12\n");
    struct fake_ini ini = { { { "RS274NGC", "FEED_UNITS", "m/min" },
                              { "RS274NGC", "TOOL_TABLE", "t.tbl" },
                              { "RS274NGC", "PARAMETER_FILE", "p.var" } } };
    struct interp_settings s;
    ck_assert_int_eq(interp_settings_read(&s, fake_get, &ini, dir, err, sizeof err), INTERP_OK);
    ck_assert(s.feed_factor == 1000.0);
    char want[512];
    snprintf(want, sizeof want, "%s/t.tbl", dir);
    ck_assert_str_eq(s.tool_table, want);
    snprintf(want, sizeof want, "%s/p.var", dir);
    ck_assert_str_eq(s.param_file, want);

    struct interp *in = interp_create();
    struct tooltable *tt = malloc(sizeof *tt);
    ck_assert_ptr_nonnull(in);
    ck_assert_ptr_nonnull(tt);
    tooltable_init(tt);
    ck_assert_int_eq(interp_setup(in, tt, fake_get, &ini, dir, 0, err, sizeof err), INTERP_OK);
    struct interp_view v;
    interp_get_view(in, &v);
    ck_assert(v.feed_factor == 1000.0);
    ck_assert_double_eq_tol(v.g5x_mm[0], 40.0, 1e-12);   /* G54 from the parameter file */
    ck_assert_double_eq_tol(v.g5x_mm[1], -30.0, 1e-12);
    ck_assert_double_eq_tol(v.g5x_mm[2], -12.0, 1e-12);
    ck_assert_int_eq(tt->count, 1);
    ck_assert_ptr_nonnull(tooltable_find(tt, 3));
    /* the interpreter has the table: G43 H3 takes tool 3's length (refused without one) */
    const char prog[] = "T3 M6\nG43 H3\nM2\n";
    ck_assert_int_eq(interp_run_text(in, "t.ngc", prog, strlen(prog), drop, NULL), INTERP_OK);
    interp_get_view(in, &v);
    ck_assert_double_eq_tol(v.tool_mm[2], 5.0, 1e-12);
    interp_destroy(in);
    free(tt);
    remove_dir(dir);
}
END_TEST

/* [RS274NGC] SUBROUTINE_PATH: folders relative to the INI where o<name> call finds name.ngc;
 * LOOP_LIMIT bounds the loops of one program. */
START_TEST(subroutine_path_and_loop_limit)
{
    char dir[64], err[512], sub[100];
    make_dir(dir, sizeof dir);
    snprintf(sub, sizeof sub, "%s/subs", dir);
    ck_assert_int_eq(mkdir(sub, 0755), 0);
    put(sub, "twice.ngc", "o<twice> sub\no<twice> endsub [#1 * 2]\nM2\n");
    struct fake_ini ini = { { { "RS274NGC", "SUBROUTINE_PATH", "nowhere:subs" },
                              { "RS274NGC", "LOOP_LIMIT", "5" } } };
    struct interp_settings s;
    ck_assert_int_eq(interp_settings_read(&s, fake_get, &ini, dir, err, sizeof err), INTERP_OK);
    char want[300];
    snprintf(want, sizeof want, "%s/nowhere:%s/subs", dir, dir);
    ck_assert_str_eq(s.subroutine_path, want);
    ck_assert_int_eq(s.loop_limit, 5);
    struct interp *in = interp_create();
    ck_assert_ptr_nonnull(in);
    ck_assert_int_eq(interp_setup(in, NULL, fake_get, &ini, dir, 0, err, sizeof err), INTERP_OK);
    const char prog[] = "o<twice> call [21]\n#1 = #<_value>\nM2\n";
    ck_assert_int_eq(interp_run_text(in, "t.ngc", prog, strlen(prog), drop, NULL), INTERP_OK);
    ck_assert_double_eq(interp_param(in, 1), 42);
    const char loop[] = "o1 repeat [6]\no1 endrepeat\nM2\n";  /* 6 > LOOP_LIMIT */
    ck_assert_int_eq(interp_run_text(in, "t.ngc", loop, strlen(loop), drop, NULL),
                     INTERP_ERR_SYNTAX);
    ck_assert_ptr_nonnull(strstr(interp_last_error(in)->message, "more than 5 loop"));
    interp_destroy(in);
    struct fake_ini bad = { { { "RS274NGC", "LOOP_LIMIT", "0" } } };
    ck_assert_int_eq(interp_settings_read(&s, fake_get, &bad, dir, err, sizeof err),
                     INTERP_ERR_CONFIG);
    ck_assert_ptr_nonnull(strstr(err, "LOOP_LIMIT"));
    unlink(strcat(strcpy(want, sub), "/twice.ngc"));
    rmdir(sub);
    remove_dir(dir);
}
END_TEST

START_TEST(defaults_absolute_paths_and_the_emcio_fallback)
{
    char dir[64], err[512], abs_tbl[512];
    make_dir(dir, sizeof dir);
    struct interp_settings s;
    struct fake_ini none = { { { NULL } } };
    ck_assert_int_eq(interp_settings_read(&s, fake_get, &none, dir, err, sizeof err),
                     INTERP_OK);
    ck_assert(s.feed_factor == 1.0);
    ck_assert_str_eq(s.tool_table, "");
    ck_assert_str_eq(s.param_file, "");

    /* LinuxCNC also takes the tool table from [EMCIO] ... */
    struct fake_ini io = { { { "EMCIO", "TOOL_TABLE", "io.tbl" },
                             { "RS274NGC", "FEED_UNITS", "mm/min" } } };
    ck_assert_int_eq(interp_settings_read(&s, fake_get, &io, dir, err, sizeof err), INTERP_OK);
    char want[512];
    snprintf(want, sizeof want, "%s/io.tbl", dir);
    ck_assert_str_eq(s.tool_table, want);
    ck_assert(s.feed_factor == 1.0);
    /* ... but [RS274NGC] comes first; an absolute path is kept as it is */
    snprintf(abs_tbl, sizeof abs_tbl, "%s/t.tbl", dir);
    struct fake_ini both = { { { "EMCIO", "TOOL_TABLE", "io.tbl" },
                               { "RS274NGC", "TOOL_TABLE", abs_tbl } } };
    ck_assert_int_eq(interp_settings_read(&s, fake_get, &both, "/elsewhere", err, sizeof err),
                     INTERP_OK);
    ck_assert_str_eq(s.tool_table, abs_tbl);
    /* no folder: the path as written */
    ck_assert_int_eq(interp_settings_read(&s, fake_get, &io, NULL, err, sizeof err), INTERP_OK);
    ck_assert_str_eq(s.tool_table, "io.tbl");
    remove_dir(dir);
}
END_TEST

START_TEST(errors_name_the_key_or_the_file)
{
    char dir[64], err[512], want[600];
    make_dir(dir, sizeof dir);
    struct interp_settings s;
    struct fake_ini bad = { { { "RS274NGC", "FEED_UNITS", "furlongs" } } };
    ck_assert_int_eq(interp_settings_read(&s, fake_get, &bad, dir, err, sizeof err),
                     INTERP_ERR_CONFIG);
    ck_assert_str_eq(err, "[RS274NGC] FEED_UNITS = furlongs: use mm/min or m/min");

    struct interp *in = interp_create();
    struct tooltable *tt = malloc(sizeof *tt);
    ck_assert_ptr_nonnull(in);
    ck_assert_ptr_nonnull(tt);
    tooltable_init(tt);
    struct fake_ini missing = { { { "RS274NGC", "TOOL_TABLE", "t.tbl" } } };
    ck_assert_int_eq(interp_setup(in, tt, fake_get, &missing, dir, 0, err, sizeof err),
                     INTERP_ERR_TOOL);
    snprintf(want, sizeof want, "%s/t.tbl: cannot open the tool table: No such file or "
             "directory", dir);
    ck_assert_str_eq(err, want);
    /* tt NULL: the caller brings its own table, TOOL_TABLE is not even opened */
    ck_assert_int_eq(interp_setup(in, NULL, fake_get, &missing, dir, 0, err, sizeof err),
                     INTERP_OK);

    put(dir, "p.var", "5221 40\nfive 3\n");
    struct fake_ini badp = { { { "RS274NGC", "PARAMETER_FILE", "p.var" } } };
    ck_assert_int_eq(interp_setup(in, tt, fake_get, &badp, dir, 0, err, sizeof err),
                     INTERP_ERR_PARAM);
    snprintf(want, sizeof want, "%s/p.var:2", dir);
    ck_assert_msg(strstr(err, want) && strstr(err, "parameter number"), "%s", err);
    interp_destroy(in);
    free(tt);
    remove_dir(dir);
}
END_TEST

/* Runs G10 L2 (a new G54 X) on a fresh interpreter set up with flags: the file after the
 * interpretation into mid, then after applying the program's settings (as the runner does
 * when the machine executes them) into after. */
static void run_g10(const char *dir, unsigned flags, char *mid, char *after, size_t len)
{
    char err[512];
    struct fake_ini ini = { { { "RS274NGC", "PARAMETER_FILE", "p.var" } } };
    struct interp *in = interp_create();
    ck_assert_ptr_nonnull(in);
    ck_assert_int_eq(interp_setup(in, NULL, fake_get, &ini, dir, flags, err, sizeof err),
                     INTERP_OK);
    const char prog[] = "G10 L2 P1 X7\nM2\n";
    struct canon_prog p;
    canon_prog_init(&p);
    ck_assert_int_eq(interp_run_text(in, "g10.ngc", prog, strlen(prog), canon_prog_sink, &p),
                     INTERP_OK);
    get_text(dir, "p.var", mid, len);
    for (size_t i = 0; i < p.count; i++)
        if (p.cmds[i].type == CANON_SETTING)
            ck_assert_msg(interp_setting_apply(in, p.cmds[i].setting, err, sizeof err) ==
                          INTERP_OK, "%s", err);
    canon_prog_free(&p);
    interp_destroy(in);
    get_text(dir, "p.var", after, len);
}

START_TEST(read_only_never_writes_the_parameter_file)
{
    char dir[64], mid[8192], after[8192];
    make_dir(dir, sizeof dir);
    const char *before = "5221 40\n";
    put(dir, "p.var", before);
    run_g10(dir, INTERP_SETUP_PARAMS_READ_ONLY, mid, after, sizeof after);
    ck_assert_str_eq(mid, before);
    ck_assert_str_eq(after, before);                      /* the check leaves it alone */
    run_g10(dir, 0, mid, after, sizeof after);
    ck_assert_str_eq(mid, before);                        /* interpreting writes nothing */
    ck_assert_msg(strstr(after, "5221\t7.000000\n"), "%s", after);   /* executing saves it */
    remove_dir(dir);
}
END_TEST

static Suite *interp_setup_suite(void)
{
    Suite *s = suite_create("interp_setup");
    TCase *tc = tcase_create("setup");
    tcase_add_test(tc, every_key_applied_with_relative_paths);
    tcase_add_test(tc, subroutine_path_and_loop_limit);
    tcase_add_test(tc, defaults_absolute_paths_and_the_emcio_fallback);
    tcase_add_test(tc, errors_name_the_key_or_the_file);
    tcase_add_test(tc, read_only_never_writes_the_parameter_file);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(interp_setup_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
