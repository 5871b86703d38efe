/* test_web.c: the operator's station's own logic, without a browser: its settings (address,
 * token, origins, UI folder), the program folder's fence, the method list, the listing and
 * upload methods, and the path preview (points, kinds, lines, arcs as chords). */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/inifile.h"
#include "web/web.h"

static char dir[256];

static void write_file(const char *name, const char *text, mode_t mode)
{
    char p[512];
    snprintf(p, sizeof p, "%s/%s", dir, name);
    FILE *f = fopen(p, "w");
    ck_assert_ptr_nonnull(f);
    fputs(text, f);
    fclose(f);
    chmod(p, mode);
}

static void setup(void)
{
    snprintf(dir, sizeof dir, "/tmp/hexcnc-test-web.XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(dir));
    char p[512];
    snprintf(p, sizeof p, "%s/ui", dir);
    mkdir(p, 0755);
    snprintf(p, sizeof p, "%s/progs", dir);
    mkdir(p, 0755);
    snprintf(p, sizeof p, "%s/progs/sub", dir);
    mkdir(p, 0755);
    write_file("ui/index.html", "<html></html>\n", 0644);
    write_file("progs/a.ngc", "G0 X1\r\nG1 X2 F100\r\nM2\r\n", 0644);
    write_file("progs/sub/b.ngc", "M2\n", 0644);
    snprintf(p, sizeof p, "%s/progs/out.ngc", dir);
    ck_assert_int_eq(symlink("/etc/hostname", p), 0);
}

static void teardown(void)
{
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    ck_assert_int_eq(system(cmd), 0);
}

/* Reads an INI whose [API] section holds `api` (UI_DIR and PROGRAM_PREFIX are added). */
static int config(struct inifile *ini, struct web_config *c, const char *api, char *err,
                  size_t len)
{
    char text[2048];
    snprintf(text, sizeof text, "[API]\nUI_DIR = ui\n%s\n[DISPLAY]\nPROGRAM_PREFIX = progs\n",
             api);
    write_file("m.ini", text, 0644);
    char p[512], e[512];
    snprintf(p, sizeof p, "%s/m.ini", dir);
    memset(ini, 0, sizeof *ini);
    ck_assert_int_eq(inifile_load(ini, p, e, sizeof e), 0);
    err[0] = '\0';
    return web_config_read(c, ini, NULL, NULL, err, len);
}

START_TEST(test_listen_defaults_and_token)
{
    struct inifile ini;
    struct web_config c;
    char err[1024];
    ck_assert_int_eq(config(&ini, &c, "", err, sizeof err), 0);
    ck_assert_str_eq(c.host, "127.0.0.1");
    ck_assert_int_eq(c.port, 8080);
    ck_assert(c.loopback);
    ck_assert_str_eq(c.token, "");
    ck_assert_str_eq(c.origins[0], "http://127.0.0.1:8080");
    inifile_free(&ini);

    ck_assert_int_eq(config(&ini, &c, "HTTP = [::1]:9000", err, sizeof err), 0);
    ck_assert(c.loopback);
    ck_assert_int_eq(c.port, 9000);
    inifile_free(&ini);

    /* any other address: a token is required */
    ck_assert_int_eq(config(&ini, &c, "HTTP = 0.0.0.0:8080", err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "TOKEN_FILE"));
    inifile_free(&ini);
    write_file("tok", "0123456789abcdef-secret\n", 0644);
    ck_assert_int_eq(config(&ini, &c, "HTTP = 0.0.0.0:8080\nTOKEN_FILE = tok", err,
                            sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "chmod 600"));
    inifile_free(&ini);
    write_file("tok", "short\n", 0600);
    ck_assert_int_eq(config(&ini, &c, "HTTP = 0.0.0.0:8080\nTOKEN_FILE = tok", err,
                            sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "16 to"));
    inifile_free(&ini);
    write_file("tok", "0123456789abcdef-secret\n", 0600);
    ck_assert_int_eq(config(&ini, &c, "HTTP = 0.0.0.0:8080\nTOKEN_FILE = tok\n"
                            "ALLOWED_ORIGINS = http://panel.local:8080", err, sizeof err), 0);
    ck_assert(!c.loopback);
    ck_assert_str_eq(c.token, "0123456789abcdef-secret");
    ck_assert_int_eq(c.norigins, 2);
    ck_assert_str_eq(c.origins[1], "http://panel.local:8080");
    inifile_free(&ini);

    const char *bad[] = { "HTTP = 8080", "HTTP = 127.0.0.1:0", "HTTP = 127.0.0.1:70000",
                          "HTTP = example.com:80", "ALLOWED_ORIGINS = panel.local",
                          "ALLOWED_ORIGINS = http://a/b/" };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        ck_assert_int_eq(config(&ini, &c, bad[i], err, sizeof err), -1);
        ck_assert_msg(strstr(err, "[API]"), "%s: %s", bad[i], err);
        inifile_free(&ini);
    }
    /* a UI folder without the page */
    unlink(strcat(strcpy((char[300]){ 0 }, dir), "/ui/index.html"));
    ck_assert_int_eq(config(&ini, &c, "", err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "not built"));
    inifile_free(&ini);
}
END_TEST

START_TEST(test_program_folder_fence)
{
    struct inifile ini;
    struct web_config c;
    char err[1024], out[4096];
    ck_assert_int_eq(config(&ini, &c, "", err, sizeof err), 0);
    ck_assert_int_eq(web_program_path(&c, "a.ngc", out, sizeof out, err, sizeof err), 0);
    ck_assert_ptr_nonnull(strstr(out, "/progs/a.ngc"));
    ck_assert_int_eq(out[0], '/');
    ck_assert_int_eq(web_program_path(&c, "sub/b.ngc", out, sizeof out, err, sizeof err), 0);
    const char *bad[] = { "../m.ini", "/etc/passwd", "sub/../../m.ini", "", "out.ngc",
                          "nothere.ngc" };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        ck_assert_msg(web_program_path(&c, bad[i], out, sizeof out, err, sizeof err) == -1,
                      "%s accepted", bad[i]);
    ck_assert_int_eq(web_program_path(&c, "out.ngc", out, sizeof out, err, sizeof err), -1);
    ck_assert_ptr_nonnull(strstr(err, "out of the program folder"));
    inifile_free(&ini);
}
END_TEST

START_TEST(test_methods)
{
    ck_assert(web_method_forwarded("program.open"));
    ck_assert(web_method_forwarded("machine.estop"));
    ck_assert(!web_method_forwarded("machine.shutdown"));
    ck_assert(!web_method_forwarded("program.preview"));
    ck_assert(web_method_local("program.preview"));
    ck_assert(web_method_local("station.info"));
    ck_assert(!web_method_local("status.get"));
}
END_TEST

START_TEST(test_lines_and_upload)
{
    struct inifile ini;
    struct web_config c;
    char err[1024];
    int code = 0;
    ck_assert_int_eq(config(&ini, &c, "", err, sizeof err), 0);
    json_t *p = json_pack("{s:s, s:i, s:i}", "path", "a.ngc", "from", 2, "count", 5);
    json_t *r = web_local_call(&c, "program.lines", p, false, &code, err, sizeof err);
    ck_assert_ptr_nonnull(r);
    json_t *lines = json_object_get(r, "lines");
    ck_assert_int_eq(json_array_size(lines), 2);
    ck_assert_str_eq(json_string_value(json_array_get(lines, 0)), "G1 X2 F100");
    ck_assert_str_eq(json_string_value(json_array_get(lines, 1)), "M2");
    ck_assert(json_is_true(json_object_get(r, "end")));
    json_decref(r);
    json_decref(p);

    p = json_pack("{s:s, s:s}", "name", "new.ngc", "text", "G0 X5\nM2\n");
    ck_assert_ptr_null(web_local_call(&c, "program.upload", p, false, &code, err, sizeof err));
    ck_assert_int_eq(code, -32002);
    r = web_local_call(&c, "program.upload", p, true, &code, err, sizeof err);
    ck_assert_msg(r != NULL, "%s", err);
    json_decref(r);
    json_decref(p);
    char path[512], text[64] = "";
    snprintf(path, sizeof path, "%s/progs/new.ngc", dir);
    FILE *f = fopen(path, "r");
    ck_assert_ptr_nonnull(f);
    ck_assert_uint_eq(fread(text, 1, sizeof text - 1, f), 9);
    fclose(f);
    ck_assert_str_eq(text, "G0 X5\nM2\n");
    const char *bad[] = { "../x.ngc", ".hidden", "a/b.ngc", "x;rm.ngc" };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        p = json_pack("{s:s, s:s}", "name", bad[i], "text", "M2\n");
        ck_assert_ptr_null(web_local_call(&c, "program.upload", p, true, &code, err,
                                          sizeof err));
        ck_assert_int_eq(code, -32602);
        json_decref(p);
    }

    r = web_local_call(&c, "program.list", NULL, false, &code, err, sizeof err);
    ck_assert_ptr_nonnull(r);
    json_t *files = json_object_get(r, "files");
    /* a.ngc, new.ngc, out.ngc (a link: listed, refused when opened); not the folder sub/ */
    ck_assert_int_eq(json_array_size(files), 2 + (access("/etc/hostname", R_OK) == 0));
    ck_assert_str_eq(json_string_value(json_object_get(json_array_get(files, 0), "name")),
                     "a.ngc");
    json_decref(r);
    inifile_free(&ini);
}
END_TEST

/* The point i of a preview, mm and deg. */
static double pt(json_t *r, size_t i, int k)
{
    return (double)json_integer_value(json_array_get(json_object_get(r, "pts_um"), i * 6 +
                                                     (size_t)k)) / 1000.0;
}

START_TEST(test_preview)
{
    struct inifile ini;
    struct web_config c;
    char err[1024];
    int code = 0;
    ck_assert_int_eq(config(&ini, &c, "", err, sizeof err), 0);
    write_file("progs/p.ngc", "G21 G90\nG0 X10 Y0 Z5\nG1 X20 Z0 A2 F100\n"
               "G2 X40 Y0 I10 J0 A6\nM2\n", 0644);
    json_t *p = json_pack("{s:s, s:[ffffff]}", "path", "p.ngc", "start", 0.0, 0.0, 50.0, 0.0,
                          0.0, 0.0);
    json_t *r = web_local_call(&c, "program.preview", p, false, &code, err, sizeof err);
    ck_assert_msg(r != NULL, "%s", err);
    ck_assert(json_is_null(json_object_get(r, "error")));
    /* start, rapid, feed, and a half turn in 32 chords of 1/64 turn */
    ck_assert_int_eq(json_integer_value(json_object_get(r, "points")), 35);
    json_t *kind = json_object_get(r, "kind"), *line = json_object_get(r, "line");
    ck_assert_int_eq(json_integer_value(json_array_get(kind, 1)), 0);
    ck_assert_int_eq(json_integer_value(json_array_get(line, 1)), 2);
    ck_assert_int_eq(json_integer_value(json_array_get(kind, 2)), 1);
    ck_assert_int_eq(json_integer_value(json_array_get(line, 2)), 3);
    ck_assert_double_eq_tol(pt(r, 0, 2), 50.0, 1e-9);
    ck_assert_double_eq_tol(pt(r, 2, 0), 20.0, 1e-9);
    ck_assert_double_eq_tol(pt(r, 2, 3), 2.0, 1e-9);
    for (size_t i = 3; i < 35; i++) {
        ck_assert_int_eq(json_integer_value(json_array_get(line, i)), 4);
        double dx = pt(r, i, 0) - 30.0, dy = pt(r, i, 1);
        ck_assert_double_eq_tol(hypot(dx, dy), 10.0, 1.5e-3);   /* on the circle, to 1 um */
        ck_assert_double_eq_tol(pt(r, i, 3), 2.0 + 4.0 * (double)(i - 2) / 32.0, 1.5e-3);
    }
    /* G2 from (20,0) to (40,0) about (30,0) is clockwise seen from +Z: over the top, Y > 0 */
    ck_assert_double_eq_tol(pt(r, 18, 0), 30.0, 1.5e-3);
    ck_assert_double_eq_tol(pt(r, 18, 1), 10.0, 1.5e-3);
    ck_assert_double_eq_tol(pt(r, 34, 0), 40.0, 1e-9);
    ck_assert_double_eq_tol(json_number_value(json_array_get(json_object_get(r, "max"), 0)),
                            40.0, 1e-9);
    json_decref(r);
    json_decref(p);

    /* under G43.4 the program gives the tool tip; the points drawn are the platform's poses
     * like any others: on the TMU hexapod the tip X10 Y0 Z75 on the table is the platform at
     * X-10 Z645 (the tool stands at Z720) */
    inifile_free(&ini);
    ck_assert_int_eq(config(&ini, &c, "\n[KINS]\nKINEMATICS = hexapod\nBASE_RADIUS = 500\n"
                            "PLATFORM_RADIUS = 300\nBASE_HALF_ANGLE = 10\nPLATFORM_HALF_ANGLE = "
                            "10\nHOME = 0 0 645 0 0 0\nTOOL_POINT = 0 0 780\nTOOL_LENGTH = 60\n"
                            "[JOINT_0]\nMIN_LIMIT = 520\nMAX_LIMIT = 980\n[JOINT_1]\nMIN_LIMIT = "
                            "520\nMAX_LIMIT = 980\n[JOINT_2]\nMIN_LIMIT = 520\nMAX_LIMIT = 980\n"
                            "[JOINT_3]\nMIN_LIMIT = 520\nMAX_LIMIT = 980\n[JOINT_4]\nMIN_LIMIT = "
                            "520\nMAX_LIMIT = 980\n[JOINT_5]\nMIN_LIMIT = 520\nMAX_LIMIT = 980\n",
                            err, sizeof err), 0);
    write_file("progs/tcp.ngc", "G21 G90\nG43.4 H0\nG1 X10 F600\nG49\nG1 Z650\nM2\n", 0644);
    p = json_pack("{s:s, s:[ffffff]}", "path", "tcp.ngc", "start", 0.0, 0.0, 645.0, 0.0, 0.0,
                  0.0);
    r = web_local_call(&c, "program.preview", p, false, &code, err, sizeof err);
    ck_assert_msg(r != NULL, "%s", err);
    ck_assert_msg(json_is_null(json_object_get(r, "error")), "%s",
                  json_string_value(json_object_get(r, "error")));
    ck_assert_int_eq(json_integer_value(json_object_get(r, "points")), 3);
    ck_assert_double_eq_tol(pt(r, 1, 0), -10.0, 1e-9);
    ck_assert_double_eq_tol(pt(r, 1, 2), 645.0, 1e-9);
    ck_assert_double_eq_tol(pt(r, 2, 0), -10.0, 1e-9);   /* after G49: the platform moves */
    ck_assert_double_eq_tol(pt(r, 2, 2), 650.0, 1e-9);
    json_decref(r);
    json_decref(p);

    /* G141: the tool path (kind 2) offset by the radius to the right of travel, and the
     * programmed contour beside it */
    write_file("progs/c.ngc", "G21 G90\nG0 X70 Y-100 Z630\nG141 X50 Y-80 Z630 W10 F100\n"
               "G141 X50 Y-20\nM2\n", 0644);
    p = json_pack("{s:s, s:[ffffff]}", "path", "c.ngc", "start", 0.0, 0.0, 645.0, 0.0, 0.0,
                  0.0);
    r = web_local_call(&c, "program.preview", p, false, &code, err, sizeof err);
    ck_assert_msg(r != NULL, "%s", err);
    ck_assert(json_is_null(json_object_get(r, "error")));
    json_t *cu = json_object_get(r, "contour_um"), *cf = json_object_get(r, "contour_first");
    ck_assert_int_eq(json_array_size(cu), 18);
    ck_assert(json_is_true(json_array_get(cf, 0)) && json_is_false(json_array_get(cf, 1)));
    ck_assert_int_eq(json_integer_value(json_array_get(cu, 0)), 70000);   /* from */
    ck_assert_int_eq(json_integer_value(json_array_get(cu, 1)), -100000);
    ck_assert_int_eq(json_integer_value(json_array_get(cu, 6)), 50000);   /* line 3 */
    ck_assert_int_eq(json_integer_value(json_array_get(cu, 7)), -80000);
    ck_assert_int_eq(json_integer_value(json_array_get(cu, 13)), -20000); /* line 4 */
    ck_assert_int_eq(json_integer_value(json_array_get(json_object_get(r, "contour_line"), 2)),
                     4);
    size_t n = (size_t)json_integer_value(json_object_get(r, "points")), comp = 0;
    kind = json_object_get(r, "kind");
    for (size_t i = 0; i < n; i++)
        if (json_integer_value(json_array_get(kind, i)) == 2) {
            comp++;
            if (json_integer_value(json_array_get(json_object_get(r, "line"), i)) == 4)
                ck_assert_double_eq_tol(pt(r, i, 0), 60.0, 1e-3);  /* along the wall */
        }
    ck_assert_uint_ge(comp, 1);
    json_decref(r);
    json_decref(p);

    /* a program error: the path up to it, and the interpreter's message naming file and line */
    write_file("progs/bad.ngc", "G0 X1\nG1 X2 Q\nM2\n", 0644);
    p = json_pack("{s:s, s:[ffffff]}", "path", "bad.ngc", "start", 0.0, 0.0, 0.0, 0.0, 0.0,
                  0.0);
    r = web_local_call(&c, "program.preview", p, false, &code, err, sizeof err);
    ck_assert_ptr_nonnull(r);
    const char *e = json_string_value(json_object_get(r, "error"));
    ck_assert_ptr_nonnull(e);
    ck_assert_msg(strstr(e, "bad.ngc:2"), "%s", e);
    json_decref(r);
    json_decref(p);

    /* a bound on points */
    p = json_pack("{s:s, s:[ffffff], s:i}", "path", "p.ngc", "start", 0.0, 0.0, 50.0, 0.0,
                  0.0, 0.0, "max_points", 3);
    r = web_local_call(&c, "program.preview", p, false, &code, err, sizeof err);
    ck_assert_ptr_nonnull(r);
    ck_assert(json_is_true(json_object_get(r, "truncated")));
    ck_assert_int_le(json_integer_value(json_object_get(r, "points")), 3);
    json_decref(r);
    json_decref(p);
    inifile_free(&ini);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("web");
    TCase *tc = tcase_create("station");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_add_test(tc, test_listen_defaults_and_token);
    tcase_add_test(tc, test_program_folder_fence);
    tcase_add_test(tc, test_methods);
    tcase_add_test(tc, test_lines_and_upload);
    tcase_add_test(tc, test_preview);
    suite_add_tcase(s, tc);
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? 1 : 0;
}
