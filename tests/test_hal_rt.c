/* test_hal_rt.c: a few milliseconds of real-time threads: they run, in order within a period,
 * and report their run time pins; no timing is asserted (the machine is shared). */
#include <check.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "hal/hal.h"

/* Counts calls and checks that within a thread `first` always runs before `second`. */
struct probe {
    int first_calls, second_calls;
    int out_of_order;
};

static void first_fn(void *arg, long period_ns)
{
    struct probe *p = arg;
    if (p->first_calls != p->second_calls)
        p->out_of_order++;
    p->first_calls++;
}

static void second_fn(void *arg, long period_ns)
{
    struct probe *p = arg;
    p->second_calls++;
    if (p->second_calls != p->first_calls)
        p->out_of_order++;
}

static void busy_fn(void *arg, long period_ns)
{
    (*(int *)arg)++;
}

START_TEST(threads_run_in_real_time_mode)
{
    struct hal *h = hal_create();
    ck_assert_ptr_nonnull(h);
    struct probe p = { 0, 0, 0 };
    int fast_calls = 0;
    ck_assert_int_eq(hal_thread_new(h, "servo-thread", 1000000), HAL_OK);
    ck_assert_int_eq(hal_thread_new(h, "base-thread", 250000), HAL_OK);
    ck_assert_int_eq(hal_export_functf(h, first_fn, &p, "probe.first"), HAL_OK);
    ck_assert_int_eq(hal_export_functf(h, second_fn, &p, "probe.second"), HAL_OK);
    ck_assert_int_eq(hal_export_functf(h, busy_fn, &fast_calls, "fast"), HAL_OK);
    ck_assert_int_eq(hal_addf(h, "probe.second", "servo-thread", 0), HAL_OK);
    ck_assert_int_eq(hal_addf(h, "probe.first", "servo-thread", 1), HAL_OK);
    ck_assert_int_eq(hal_addf(h, "fast", "base-thread", 0), HAL_OK);
    ck_assert(!hal_sim_clock(h));
    ck_assert_int_eq(hal_start(h), HAL_OK);
    ck_assert(hal_running(h));
    ck_assert_int_eq(hal_start(h), HAL_ERR_STATE);
    struct timespec ts = { 0, 20000000 };
    nanosleep(&ts, NULL);
    /* a graph change while running waits for the threads' periods to finish */
    ck_assert_int_eq(hal_cmd(h, "loadrt sum2", NULL, 0, NULL), HAL_OK);
    ck_assert(hal_now_ns(h) > 0);
    ck_assert_int_eq(hal_stop(h), HAL_OK);
    ck_assert(!hal_running(h));
    ck_assert_int_gt(p.first_calls, 0);
    ck_assert_int_eq(p.first_calls, p.second_calls);
    ck_assert_int_eq(p.out_of_order, 0);
    ck_assert_int_gt(fast_calls, 0);
    int32_t *tmax = hal_data_ptr(h, "servo-thread.tmax", NULL);
    int32_t *last = hal_data_ptr(h, "servo-thread.time", NULL);
    ck_assert_ptr_nonnull(tmax);
    ck_assert_int_ge(*tmax, *last);
    ck_assert_int_ge(*last, 0);
    hal_destroy(h);
}
END_TEST

static Suite *hal_rt_suite(void)
{
    Suite *s = suite_create("hal_rt");
    TCase *tc = tcase_create("rt");
    tcase_add_test(tc, threads_run_in_real_time_mode);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(hal_rt_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
