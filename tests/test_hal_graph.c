/* test_hal_graph.c: HAL-graph tests: HAL files in tests/hal stream inputs through components
 * on the simulated clock, and the sampled output must equal the stored expectation. */
#include <check.h>
#include <dlfcn.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "hal/hal.h"
#include "kins/kins.h"

/* Reads a whole file (NULL if it cannot). */
static char *slurp(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return NULL;
    char *text = NULL;
    size_t len = 0;
    FILE *mem = open_memstream(&text, &len);
    int c;
    while ((c = fgetc(f)) != EOF)
        fputc(c, mem);
    fclose(mem);
    fclose(f);
    return text;
}

/* Runs tests/hal/<name>.hal for `periods` servo periods with graph.ini plus [TEST] OUT_DIR,
 * then compares <OUT_DIR>/<name>.out with tests/hal/<name>.expected. */
static void run_graph(const char *name, int periods)
{
    const char *root = getenv("HEXCNC_ROOT");
    char dir[4096], tmp[] = "/tmp/test_hal_graph.XXXXXX", ini[4200], path[4300];
    snprintf(dir, sizeof dir, "%s/tests/hal", root ? root : ".");
    ck_assert_msg(chdir(dir) == 0, "cannot enter %s", dir);
    ck_assert_ptr_nonnull(mkdtemp(tmp));
    char *base = slurp("graph.ini");
    ck_assert_ptr_nonnull(base);
    snprintf(ini, sizeof ini, "%s/graph.ini", tmp);
    FILE *f = fopen(ini, "w");
    ck_assert_ptr_nonnull(f);
    fprintf(f, "%s\n[TEST]\nOUT_DIR = %s\n", base, tmp);
    fclose(f);
    free(base);

    struct hal *h = hal_create();
    ck_assert_ptr_nonnull(h);
    hal_set_sim_clock(h, true);
    ck_assert_int_eq(hal_load_ini(h, ini), HAL_OK);
    snprintf(path, sizeof path, "%s.hal", name);
    ck_assert_msg(hal_source(h, path) == HAL_OK, "%s", hal_last_error(h));
    ck_assert_int_eq(hal_start(h), HAL_OK);
    ck_assert_int_eq(hal_sim_advance(h, (long)periods * 1000000), HAL_OK);
    hal_destroy(h);                            /* closes the sampler's file */

    snprintf(path, sizeof path, "%s/%s.out", tmp, name);
    char *got = slurp(path);
    unlink(path);
    unlink(ini);
    rmdir(tmp);
    snprintf(path, sizeof path, "%s.expected", name);
    char *want = slurp(path);
    ck_assert_ptr_nonnull(got);
    ck_assert_ptr_nonnull(want);
    ck_assert_str_eq(got, want);
    free(got);
    free(want);
}

START_TEST(streamer_sum2_sampler)
{
    run_graph("sum2", 6);
}
END_TEST

START_TEST(estop_latch_sequence)
{
    run_graph("estop", 13);
}
END_TEST

START_TEST(kins_forward_of_joint_feedback)
{
    void *dl = NULL;
    char err[512];
    const struct kins_ops *ops = kins_find("trivial", &dl, err, sizeof err);
    if (!ops) {
        fprintf(stderr, "test_hal_graph: skipping the kins graph: no 'trivial' kinematics "
                "(%s)\n", err);
        return;
    }
    if (dl)
        dlclose(dl);
    run_graph("kins", 4);
}
END_TEST

static Suite *hal_graph_suite(void)
{
    Suite *s = suite_create("hal_graph");
    TCase *tc = tcase_create("graph");
    tcase_add_test(tc, streamer_sum2_sampler);
    tcase_add_test(tc, estop_latch_sequence);
    tcase_add_test(tc, kins_forward_of_joint_feedback);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(hal_graph_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
