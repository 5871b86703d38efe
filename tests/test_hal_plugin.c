/* test_hal_plugin.c: `loadrt NAME` of a component plugin <plugindir>/hal/NAME.so, and the
 * errors for a plugin without its table. */
#include <check.h>
#include <stdlib.h>
#include <string.h>

#include "hal/hal.h"

/* Points the plugin search at the test plugins the build made. */
static struct hal *new_hal(void)
{
    const char *build = getenv("HEXCNC_BUILD");
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/tests/plugins", build ? build : "build");
    setenv("HEXCNC_PLUGIN_DIR", dir, 1);
    struct hal *h = hal_create();
    ck_assert_ptr_nonnull(h);
    return h;
}

START_TEST(plugin_component_loads_and_runs)
{
    struct hal *h = new_hal();
    ck_assert_msg(hal_cmd(h, "loadrt demo-plugin", NULL, 0, NULL) == HAL_OK, "%s",
                  hal_last_error(h));
    ck_assert_int_eq(hal_setp(h, "demo-plugin.in", "1.25"), HAL_OK);
    ck_assert_int_eq(hal_thread_new(h, "th", 1000000), HAL_OK);
    ck_assert_int_eq(hal_addf(h, "demo-plugin", "th", 0), HAL_OK);
    hal_set_sim_clock(h, true);
    ck_assert_int_eq(hal_start(h), HAL_OK);
    ck_assert_int_eq(hal_sim_advance(h, 1000000), HAL_OK);
    char buf[32];
    ck_assert_int_eq(hal_getp(h, "demo-plugin.out", buf, sizeof buf), HAL_OK);
    ck_assert_str_eq(buf, "2.5");
    /* now registered: a second load finds the type and fails only on the names */
    ck_assert_int_eq(hal_cmd(h, "loadrt demo-plugin", NULL, 0, NULL), HAL_ERR_EXISTS);
    ck_assert_str_eq(hal_last_error(h), "pin 'demo-plugin.in' already exists");
    ck_assert_int_eq(hal_cmd(h, "loadrt demo-plugin x=1", NULL, 0, NULL), HAL_ERR_ARG);
    ck_assert_str_eq(hal_last_error(h), "loadrt demo-plugin: unknown argument 'x=1' (it takes "
                     "none)");
    hal_destroy(h);                    /* closes the plugin after its cleanups */
}
END_TEST

START_TEST(plugin_without_table_is_refused)
{
    struct hal *h = new_hal();
    ck_assert_int_eq(hal_cmd(h, "loadrt nosym", NULL, 0, NULL), HAL_ERR_COMPONENT);
    char want[4400];
    snprintf(want, sizeof want, "loadrt nosym: %s/hal/nosym.so does not export "
             "'hal_comp_nosym' for a component named 'nosym'", getenv("HEXCNC_PLUGIN_DIR"));
    ck_assert_str_eq(hal_last_error(h), want);
    hal_destroy(h);
}
END_TEST

static Suite *hal_plugin_suite(void)
{
    Suite *s = suite_create("hal_plugin");
    TCase *tc = tcase_create("plugin");
    tcase_add_test(tc, plugin_component_loads_and_runs);
    tcase_add_test(tc, plugin_without_table_is_refused);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(hal_plugin_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
