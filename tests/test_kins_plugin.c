/* test_kins_plugin.c: kinematics loaded by name from lib/kins, the TMU machine's workspace,
 * and `hexcnc kins` end to end. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "kins/kins.h"
#include "tests/test_kins_util.h"

/* Loads a model by name through the plugin path; fails the test with the message. */
static struct kins *load(const char *name, struct tk_cfg *c)
{
    struct kins_config cfg = tk_config(c);
    struct kins *k = NULL;
    char err[2048] = "";
    int st = kins_load(name, &cfg, &k, err, sizeof err);
    ck_assert_msg(st == KINS_OK, "kins_load(%s): %s", name, err);
    return k;
}

/* The hexapod comes from lib/kins/hexapod.so, not from the copy linked into this test. */
START_TEST(test_load_hexapod)
{
    ck_assert_msg(getenv("HEXCNC_PLUGIN_DIR"), "HEXCNC_PLUGIN_DIR not set (run by make test)");
    struct tk_cfg *c = tk_ini("configs/sim/tmu-hexapod.ini");
    ck_assert_ptr_nonnull(c);
    struct kins *k = load(tk_get(c, "KINS", "KINEMATICS"), c);
    ck_assert_ptr_nonnull(k->plugin_handle);
    ck_assert_ptr_ne(k->ops, &kins_hexapod_ops);
    ck_assert_str_eq(k->ops->name, "hexapod");
    struct kins_config cfg = tk_config(c);
    struct kins *s = NULL;
    char err[512];
    ck_assert_int_eq(kins_create(&kins_hexapod_ops, &cfg, &s, err, sizeof err), KINS_OK);
    ck_assert_ptr_null(s->plugin_handle);
    double pose[6] = { 50, -80, 630, 0, -4, 0 }, lp[6], ls[6], back[6];
    ck_assert_int_eq(kins_inverse(k, pose, lp), KINS_OK);
    ck_assert_int_eq(kins_inverse(s, pose, ls), KINS_OK);
    ck_assert_mem_eq(lp, ls, sizeof lp);
    memcpy(back, k->home, sizeof back);
    ck_assert_int_eq(kins_forward(k, lp, back, NULL), KINS_OK);
    for (int j = 0; j < 6; j++)
        ck_assert_double_eq_tol(back[j], pose[j], 1e-9);
    kins_free(k);
    kins_free(s);
    free(c);
}
END_TEST

/* The second plugin, and two plugin instances of different geometry side by side. */
START_TEST(test_load_trivial_and_two)
{
    struct tk_cfg *t = calloc(1, sizeof *t);
    tk_set(t, "KINS", "JOINTS", "6");
    struct kins *k = load("trivial", t);
    ck_assert_ptr_nonnull(k->plugin_handle);
    double pose[6] = { 1, 2, 3, 4, 5, 6 }, j[6];
    ck_assert_int_eq(kins_inverse(k, pose, j), KINS_OK);
    ck_assert_mem_eq(j, pose, sizeof j);
    kins_free(k);

    struct tk_cfg *ca = tk_hexapod(500, 300, 10, 10, 400, 1200);
    struct tk_cfg *cb = tk_hexapod(350, 250, 20, 8, 400, 1200);
    struct kins *a = load("hexapod", ca), *b = load("hexapod", cb);
    double p[6] = { 10, 20, 640, 1, 2, 3 }, la[6], lb[6], pa[6], pb[6];
    ck_assert_int_eq(kins_inverse(a, p, la), KINS_OK);
    ck_assert_int_eq(kins_inverse(b, p, lb), KINS_OK);
    ck_assert_msg(fabs(la[2] - lb[2]) > 1.0, "two geometries, two answers");
    memcpy(pa, a->home, sizeof pa);
    memcpy(pb, b->home, sizeof pb);
    ck_assert_int_eq(kins_forward(a, la, pa, NULL), KINS_OK);
    ck_assert_int_eq(kins_forward(b, lb, pb, NULL), KINS_OK);
    for (int n = 0; n < 6; n++) {
        ck_assert_double_eq_tol(pa[n], p[n], 1e-9);
        ck_assert_double_eq_tol(pb[n], p[n], 1e-9);
    }
    kins_free(a);
    kins_free(b);
    free(t);
    free(ca);
    free(cb);
}
END_TEST

/* An unknown name, a file without the ops table and a file that is no library: each a
 * plugin error naming the plugin and the paths tried. */
START_TEST(test_load_errors)
{
    struct tk_cfg *c = tk_hexapod(500, 300, 10, 10, 520, 980);
    struct kins_config cfg = tk_config(c);
    struct kins *k = (struct kins *)1;
    char err[4096];
    ck_assert_int_eq(kins_load("nosuch", &cfg, &k, err, sizeof err), KINS_ERR_PLUGIN);
    ck_assert_ptr_null(k);
    ck_assert_ptr_nonnull(strstr(err, "'nosuch' not found"));
    ck_assert_ptr_nonnull(strstr(err, "/kins/nosuch.so (no such file)"));
    ck_assert_ptr_nonnull(strstr(err, "/lib/hexcnc/kins/nosuch.so"));
    ck_assert_int_eq(kins_load("../etc", &cfg, &k, err, sizeof err), KINS_ERR_PLUGIN);

    /* A broken configuration through a loaded plugin is the model's own message. */
    tk_set(c, "JOINT_3", "MAX_LIMIT", "abc");
    ck_assert_int_eq(kins_load("hexapod", &cfg, &k, err, sizeof err), KINS_ERR_CONFIG);
    ck_assert_str_eq(err, "[JOINT_3] MAX_LIMIT: 'abc' is not a number");
    ck_assert_ptr_null(k);

    /* A private plugin directory: other.so is a library without kins_other_ops. */
    char dir[] = "/tmp/hexcnc-kins-XXXXXX", sub[64], cmd[512];
    ck_assert_ptr_nonnull(mkdtemp(dir));
    snprintf(sub, sizeof sub, "%s/kins", dir);
    ck_assert_int_eq(mkdir(sub, 0700), 0);
    snprintf(cmd, sizeof cmd, "cp '%s/kins/trivial.so' '%s/other.so' && echo junk > '%s/junk.so'",
             getenv("HEXCNC_PLUGIN_DIR"), sub, sub);
    ck_assert_int_eq(system(cmd), 0);
    setenv("HEXCNC_PLUGIN_DIR", dir, 1);
    ck_assert_int_eq(kins_load("other", &cfg, &k, err, sizeof err), KINS_ERR_PLUGIN);
    ck_assert_msg(strstr(err, "other.so (no symbol kins_other_ops)"), "%s", err);
    ck_assert_int_eq(kins_load("junk", &cfg, &k, err, sizeof err), KINS_ERR_PLUGIN);
    ck_assert_msg(strstr(err, "junk.so ("), "%s", err);
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    ck_assert_int_eq(system(cmd), 0);
    free(c);
}
END_TEST

/* Every pose of the working region (a grid that includes all its corners) is reachable with
 * at least 20 mm to spare on every leg and far from singular, as are the paper's poses. */
START_TEST(test_tmu_workspace)
{
    struct tk_cfg *c = tk_ini("configs/sim/tmu-hexapod.ini");
    ck_assert_ptr_nonnull(c);
    struct kins_config cfg = tk_config(c);
    struct kins *k = NULL;
    char err[512];
    ck_assert_int_eq(kins_create(&kins_hexapod_ops, &cfg, &k, err, sizeof err), KINS_OK);
    double threshold = atof(tk_get(c, "KINS", "SINGULAR_CONDITION"));
    double worst_margin = INFINITY, worst_cond = 0;
    int idx[6], steps = 5 * 5 * 3 * 3 * 3 * 3, corners = 0;
    for (int n = 0; n < steps; n++) {
        int m = n;
        const int div[6] = { 5, 5, 3, 3, 3, 3 };
        double pose[6];
        int corner = 1;
        for (int j = 0; j < 6; j++) {
            idx[j] = m % div[j];
            m /= div[j];
            pose[j] = tk_region_lo[j] +
                      (tk_region_hi[j] - tk_region_lo[j]) * idx[j] / (div[j] - 1);
            corner &= idx[j] == 0 || idx[j] == div[j] - 1;
        }
        corners += corner;
        struct kins_check chk;
        ck_assert_int_eq(kins_check_pose(k, pose, &chk), KINS_OK);
        ck_assert_msg(chk.reachable, "pose %g %g %g %g %g %g unreachable", pose[0], pose[1],
                      pose[2], pose[3], pose[4], pose[5]);
        worst_margin = fmin(worst_margin, chk.leg_margin_mm);
        worst_cond = fmax(worst_cond, chk.condition);
    }
    ck_assert_int_eq(corners, 64);
    ck_assert_msg(worst_margin >= 20.0, "leg margin only %.3f mm", worst_margin);
    ck_assert_msg(worst_cond <= threshold / 5, "condition %.3f vs threshold %g", worst_cond,
                  threshold);
    /* The paper's programs and their compensated points (paper.md). */
    static const double paper[][6] = {
        { 50, -80, 630, 0, -4, 0 }, { 50, -20, 630, 0, -4, 0 }, { 50, 20, 630, 0, -4, 0 },
        { 30, -100, 658, 0, -8, 0 }, { 30, 50, 658, 0, -8, 0 },
        { 59.975641, -80, 630.697565, 0, -4, 0 }, { 54.987820, 20, 630.348782, 0, -4, 0 },
        { 40.024359, -80, 629.302435, 0, -4, 0 }, { 45.012180, 20, 629.651218, 0, -4, 0 },
        { 39.902681, -100, 659.391731, 0, -8, 0 }, { 35.941608, 50, 658.835039, 0, -8, 0 },
    };
    for (size_t n = 0; n < sizeof paper / sizeof paper[0]; n++) {
        struct kins_check chk;
        ck_assert_int_eq(kins_check_pose(k, paper[n], &chk), KINS_OK);
        ck_assert_msg(chk.reachable && chk.leg_margin_mm >= 40.0, "paper pose %zu margin %g",
                      n, chk.leg_margin_mm);
        ck_assert_int_eq(chk.near_singular, 0);
    }
    kins_free(k);
    free(c);
}
END_TEST

/* Runs a shell command, capturing stdout and stderr; returns the exit status. */
static int run(const char *cmd, char *out, size_t len)
{
    char full[2048];
    snprintf(full, sizeof full, "%s 2>&1", cmd);
    FILE *p = popen(full, "r");
    ck_assert_ptr_nonnull(p);
    size_t n = fread(out, 1, len - 1, p);
    out[n] = '\0';
    int st = pclose(p);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

/* `hexcnc kins` inverse and forward against the library, and its failures. */
START_TEST(test_cli)
{
    const char *bin = getenv("HEXCNC_BIN");
    ck_assert_msg(bin, "HEXCNC_BIN not set (run by make test)");
    char ini[1024], cmd[2048], out[4096];
    tk_tree_path(ini, sizeof ini, "configs/sim/tmu-hexapod.ini");
    snprintf(cmd, sizeof cmd, "'%s' kins '%s' inverse 59.975641 -80 630.697565 0 -4 0", bin,
             ini);
    ck_assert_int_eq(run(cmd, out, sizeof out), 0);
    double legs[6], want[6], pose[6] = { 59.975641, -80, 630.697565, 0, -4, 0 };
    ck_assert_int_eq(sscanf(out, "%lf %lf %lf %lf %lf %lf", &legs[0], &legs[1], &legs[2],
                            &legs[3], &legs[4], &legs[5]), 6);
    struct tk_cfg *c = tk_ini("configs/sim/tmu-hexapod.ini");
    struct kins_config cfg = tk_config(c);
    struct kins *k = NULL;
    char err[512];
    ck_assert_int_eq(kins_create(&kins_hexapod_ops, &cfg, &k, err, sizeof err), KINS_OK);
    ck_assert_int_eq(kins_inverse(k, pose, want), KINS_OK);
    for (int i = 0; i < 6; i++)
        ck_assert_double_eq_tol(legs[i], want[i], 1e-9);
    ck_assert_ptr_nonnull(strchr(out, '.'));
    ck_assert_int_eq((int)strlen(strchr(out, '.') + 1) >= 9, 1);

    snprintf(cmd, sizeof cmd, "'%s' kins '%s' forward %.9f %.9f %.9f %.9f %.9f %.9f", bin, ini,
             legs[0], legs[1], legs[2], legs[3], legs[4], legs[5]);
    ck_assert_int_eq(run(cmd, out, sizeof out), 0);
    double back[6];
    ck_assert_int_eq(sscanf(out, "%lf %lf %lf %lf %lf %lf", &back[0], &back[1], &back[2],
                            &back[3], &back[4], &back[5]), 6);
    for (int j = 0; j < 6; j++) /* the legs were printed to 1e-9 mm */
        ck_assert_double_eq_tol(back[j], pose[j], 1e-7);

    /* Without HEXCNC_PLUGIN_DIR the plugin is found in lib/kins beside the executable's
     * bin/ directory. */
    snprintf(cmd, sizeof cmd, "env -u HEXCNC_PLUGIN_DIR '%s' kins '%s' inverse 59.975641 -80 "
             "630.697565 0 -4 0", bin, ini);
    ck_assert_int_eq(run(cmd, out, sizeof out), 0);
    ck_assert_int_eq(sscanf(out, "%lf", &back[0]), 1);
    ck_assert_double_eq_tol(back[0], want[0], 1e-9);

    snprintf(cmd, sizeof cmd, "'%s' kins '%s' inverse 500 0 645 0 0 0", bin, ini);
    ck_assert_int_eq(run(cmd, out, sizeof out), 1);
    ck_assert_msg(strstr(out, "leg 2 would be") && strstr(out, "above its maximum 980.000 mm "
                  "([JOINT_1] MAX_LIMIT)"), "%s", out);
    snprintf(cmd, sizeof cmd, "'%s' kins '%s' forward 700 700 700 700 700 990", bin, ini);
    ck_assert_int_eq(run(cmd, out, sizeof out), 1);
    ck_assert_msg(strstr(out, "leg 6 is 990.000 mm, 10.000 mm above"), "%s", out);
    snprintf(cmd, sizeof cmd, "'%s' kins '%s' inverse 1 2 three 0 0 0", bin, ini);
    ck_assert_int_ne(run(cmd, out, sizeof out), 0);
    ck_assert_msg(strstr(out, "Z: 'three' is not a number"), "%s", out);
    kins_free(k);
    free(c);
}
END_TEST

/* A broken INI: the message names the file, the line and the key; a bad plugin name too. */
START_TEST(test_cli_config_errors)
{
    const char *bin = getenv("HEXCNC_BIN");
    ck_assert_msg(bin, "HEXCNC_BIN not set (run by make test)");
    char path[] = "/tmp/hexcnc-kins-ini-XXXXXX", cmd[2048], out[4096];
    int fd = mkstemp(path);
    ck_assert_int_ge(fd, 0);
    FILE *f = fdopen(fd, "w");
    fprintf(f, "[KINS]\nKINEMATICS = hexapod\nBASE_RADIUS = 500\nPLATFORM_RADIUS = 300\n"
               "BASE_HALF_ANGLE = 10\nPLATFORM_HALF_ANGLE = 10\n");
    for (int i = 0; i < 6; i++)
        fprintf(f, "[JOINT_%d]\nMIN_LIMIT = 520\nMAX_LIMIT = %s\nMAX_VELOCITY = 100\n"
                   "MAX_ACCELERATION = 1000\nFERROR = 1\n", i, i == 3 ? "abc" : "980");
    fclose(f);
    snprintf(cmd, sizeof cmd, "'%s' kins '%s' inverse 0 0 645 0 0 0", bin, path);
    ck_assert_int_eq(run(cmd, out, sizeof out), 1);
    char want[256];
    snprintf(want, sizeof want, "%s:27: [JOINT_3] MAX_LIMIT = abc: not a number (mm)", path);
    ck_assert_msg(strstr(out, want), "%s", out);

    f = fopen(path, "w");
    fprintf(f, "[KINS]\nKINEMATICS = hexapodd\n");
    fclose(f);
    ck_assert_int_eq(run(cmd, out, sizeof out), 1);
    snprintf(want, sizeof want, "%s:2: [KINS] KINEMATICS: kinematics plugin 'hexapodd' not "
             "found; tried: ", path);
    ck_assert_msg(strstr(out, want) && strstr(out, "hexapodd.so (no such file)"), "%s", out);
    unlink(path);
}
END_TEST

/* The suite. */
static Suite *kins_plugin_suite(void)
{
    Suite *s = suite_create("kins_plugin");
    TCase *tc = tcase_create("plugin");
    tcase_add_test(tc, test_load_hexapod);
    tcase_add_test(tc, test_load_trivial_and_two);
    tcase_add_test(tc, test_load_errors);
    tcase_add_test(tc, test_tmu_workspace);
    tcase_add_test(tc, test_cli);
    tcase_add_test(tc, test_cli_config_errors);
    suite_add_tcase(s, tc);
    return s;
}

/* Runs the suite; the exit status says whether every check passed. */
int main(void)
{
    SRunner *sr = srunner_create(kins_plugin_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
