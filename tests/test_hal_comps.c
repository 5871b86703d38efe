/* test_hal_comps.c: the small generic components (and2, not, sum2, estop-latch watchdog,
 * streamer loop/enable, sampler enable) driven by halcmd lines on the simulated clock. */
#include <check.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <string.h>
#include <unistd.h>

#include "hal/hal.h"

/* A runtime on the simulated clock with one 1 ms thread. */
static struct hal *new_hal(void)
{
    struct hal *h = hal_create();
    ck_assert_ptr_nonnull(h);
    hal_set_sim_clock(h, true);
    ck_assert_int_eq(hal_thread_new(h, "th", 1000000), HAL_OK);
    return h;
}

static void cmd(struct hal *h, const char *line)
{
    ck_assert_msg(hal_cmd(h, line, "test", 1, NULL) == HAL_OK, "%s: %s", line,
                  hal_last_error(h));
}

/* The value of a pin as getp prints it. */
static const char *get(struct hal *h, const char *name)
{
    static char buf[64];
    ck_assert_msg(hal_getp(h, name, buf, sizeof buf) == HAL_OK, "%s", hal_last_error(h));
    return buf;
}

static void periods(struct hal *h, int n)
{
    ck_assert_int_eq(hal_sim_advance(h, (long)n * 1000000), HAL_OK);
}

START_TEST(and2_and_not_truth_tables)
{
    struct hal *h = new_hal();
    cmd(h, "loadrt and2 names=both");
    cmd(h, "loadrt not");
    cmd(h, "net a-and-b both.out not.0.in");
    cmd(h, "addf both th");
    cmd(h, "addf not.0 th");
    cmd(h, "start");
    static const char *const rows[][3] = {
        { "0", "0", "TRUE" }, { "1", "0", "TRUE" }, { "0", "1", "TRUE" }, { "1", "1", "FALSE" },
    };
    for (int i = 0; i < 4; i++) {
        ck_assert_int_eq(hal_setp(h, "both.in0", rows[i][0]), HAL_OK);
        ck_assert_int_eq(hal_setp(h, "both.in1", rows[i][1]), HAL_OK);
        periods(h, 1);
        ck_assert_str_eq(get(h, "not.0.out"), rows[i][2]);
    }
    hal_destroy(h);
}
END_TEST

START_TEST(sum2_gains_and_offset)
{
    struct hal *h = new_hal();
    cmd(h, "loadrt sum2 count=2");
    cmd(h, "setp sum2.1.gain0 0.5");
    cmd(h, "setp sum2.1.gain1 -4");
    cmd(h, "setp sum2.1.offset 10");
    cmd(h, "setp sum2.1.in0 3");
    cmd(h, "setp sum2.1.in1 0.25");
    cmd(h, "addf sum2.1 th");
    cmd(h, "start");
    periods(h, 1);
    ck_assert_str_eq(get(h, "sum2.1.out"), "10.5");
    ck_assert_str_eq(get(h, "sum2.0.out"), "0");       /* not on the thread */
    hal_destroy(h);
}
END_TEST

START_TEST(estop_watchdog_toggles_only_while_ok)
{
    struct hal *h = new_hal();
    cmd(h, "loadrt estop-latch");
    cmd(h, "addf estop-latch.0 th");
    cmd(h, "setp estop-latch.0.ok-in 1");
    cmd(h, "start");
    periods(h, 1);
    ck_assert_str_eq(get(h, "estop-latch.0.fault-out"), "TRUE");
    ck_assert_str_eq(get(h, "estop-latch.0.watchdog"), "FALSE");
    cmd(h, "setp estop-latch.0.reset 1");
    periods(h, 1);
    ck_assert_str_eq(get(h, "estop-latch.0.ok-out"), "TRUE");
    ck_assert_str_eq(get(h, "estop-latch.0.watchdog"), "TRUE");
    periods(h, 1);
    ck_assert_str_eq(get(h, "estop-latch.0.watchdog"), "FALSE");
    periods(h, 1);
    ck_assert_str_eq(get(h, "estop-latch.0.watchdog"), "TRUE");
    cmd(h, "setp estop-latch.0.fault-in 1");
    periods(h, 3);
    ck_assert_str_eq(get(h, "estop-latch.0.ok-out"), "FALSE");
    ck_assert_str_eq(get(h, "estop-latch.0.watchdog"), "FALSE");
    hal_destroy(h);
}
END_TEST

START_TEST(streamer_loop_enable_and_types)
{
    struct hal *h = new_hal();
    cmd(h, "loadrt streamer cfg=fbsu data=1.5,1,-7,7;2.5,0,-8,0x10 loop=1");
    cmd(h, "loadrt streamer cfg=s data=5;6");
    cmd(h, "addf streamer.0 th");
    cmd(h, "addf streamer.1 th");
    cmd(h, "start");
    periods(h, 1);
    ck_assert_str_eq(get(h, "streamer.0.pin.0"), "1.5");
    ck_assert_str_eq(get(h, "streamer.0.pin.1"), "TRUE");
    ck_assert_str_eq(get(h, "streamer.0.pin.2"), "-7");
    ck_assert_str_eq(get(h, "streamer.0.pin.3"), "7");
    periods(h, 1);
    ck_assert_str_eq(get(h, "streamer.0.pin.3"), "16");
    ck_assert_str_eq(get(h, "streamer.1.pin.0"), "6");
    ck_assert_str_eq(get(h, "streamer.1.empty"), "TRUE");
    periods(h, 1);                                     /* loop: back to the first row */
    ck_assert_str_eq(get(h, "streamer.0.pin.0"), "1.5");
    ck_assert_str_eq(get(h, "streamer.0.empty"), "FALSE");
    ck_assert_str_eq(get(h, "streamer.1.pin.0"), "6");  /* holds the last row */
    cmd(h, "setp streamer.0.enable 0");
    periods(h, 2);
    ck_assert_str_eq(get(h, "streamer.0.pin.0"), "1.5");
    ck_assert_str_eq(get(h, "streamer.0.row"), "1");
    hal_destroy(h);
}
END_TEST

START_TEST(sampler_writes_only_while_enabled)
{
    char dir[] = "/tmp/test_hal_comps.XXXXXX", line[4300], path[4100];
    ck_assert_ptr_nonnull(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/s.out", dir);
    struct hal *h = new_hal();
    cmd(h, "loadrt streamer cfg=fu data=1,1;2,2;3,3;4,4 names=src");
    snprintf(line, sizeof line, "loadrt sampler cfg=fu file=%s names=log", path);
    cmd(h, line);
    cmd(h, "net v src.pin.0 log.pin.0");
    cmd(h, "net n src.pin.1 log.pin.1");
    cmd(h, "addf src th");
    cmd(h, "addf log th");
    cmd(h, "start");
    periods(h, 2);
    cmd(h, "setp log.enable FALSE");
    periods(h, 1);
    cmd(h, "setp log.enable TRUE");
    periods(h, 1);
    ck_assert_str_eq(get(h, "log.sample-num"), "3");
    hal_destroy(h);
    FILE *f = fopen(path, "r");
    ck_assert_ptr_nonnull(f);
    char text[256] = "";
    size_t n = fread(text, 1, sizeof text - 1, f);
    text[n] = '\0';
    fclose(f);
    unlink(path);
    rmdir(dir);
    ck_assert_str_eq(text, "1 1\n2 2\n4 4\n");
}
END_TEST

/* The sampler replaces its file atomically: the old text stays until the runtime closes,
 * then the new one is there, with no temporary left; a read-only file is refused. */
START_TEST(sampler_file_replaced_atomically)
{
    char dir[] = "/tmp/test_hal_comps.XXXXXX", line[4300], path[4100], text[256];
    ck_assert_ptr_nonnull(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/s.out", dir);
    FILE *f = fopen(path, "w");
    fputs("old\n", f);
    fclose(f);
    struct hal *h = new_hal();
    cmd(h, "loadrt streamer cfg=f data=1;2;3 names=src");
    snprintf(line, sizeof line, "loadrt sampler cfg=f file=%s names=log", path);
    cmd(h, line);
    cmd(h, "net v src.pin.0 log.pin.0");
    cmd(h, "addf src th");
    cmd(h, "addf log th");
    cmd(h, "start");
    periods(h, 3);
    f = fopen(path, "r");
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    ck_assert_str_eq(text, "old\n");                  /* not replaced while running */
    hal_destroy(h);
    f = fopen(path, "r");
    n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    ck_assert_str_eq(text, "1\n2\n3\n");
    DIR *d = opendir(dir);                             /* no temporary left */
    struct dirent *e;
    int files = 0;
    while (d && (e = readdir(d)))
        files += e->d_name[0] != '.' || strstr(e->d_name, ".hexcnc-") != NULL;
    closedir(d);
    ck_assert_int_eq(files, 1);
    ck_assert_int_eq(chmod(path, 0444), 0);
    h = new_hal();
    snprintf(line, sizeof line, "loadrt sampler cfg=f file=%s names=log", path);
    ck_assert_int_ne(hal_cmd(h, line, "test", 1, NULL), HAL_OK);
    ck_assert_msg(strstr(hal_last_error(h), path) && strstr(hal_last_error(h), "read-only"),
                  "%s", hal_last_error(h));
    hal_destroy(h);
    unlink(path);
    rmdir(dir);
}
END_TEST

/* A write error (/dev/full: no space left) stops the sampler with one fault message naming
 * the file, instead of dropping lines silently. */
START_TEST(sampler_write_error_is_a_fault)
{
    struct hal *h = new_hal();
    struct hal_msg m;
    cmd(h, "loadrt streamer cfg=f data=1;2;3;4 names=src");
    cmd(h, "loadrt sampler cfg=f file=/dev/full names=log");
    cmd(h, "net v src.pin.0 log.pin.0");
    cmd(h, "addf src th");
    cmd(h, "addf log th");
    cmd(h, "start");
    periods(h, 4);
    ck_assert(hal_msg_take(h, &m));
    ck_assert_int_eq(m.severity, HAL_MSG_FAULT);
    ck_assert_str_eq(m.source, "log");
    ck_assert_msg(strstr(m.text, "/dev/full") && strstr(m.text, "No space"), "%s", m.text);
    ck_assert(!hal_msg_take(h, &m));                   /* once, then silence */
    ck_assert_str_eq(get(h, "log.sample-num"), "0");
    hal_destroy(h);
}
END_TEST

static Suite *hal_comps_suite(void)
{
    Suite *s = suite_create("hal_comps");
    TCase *tc = tcase_create("comps");
    tcase_add_test(tc, and2_and_not_truth_tables);
    tcase_add_test(tc, sum2_gains_and_offset);
    tcase_add_test(tc, estop_watchdog_toggles_only_while_ok);
    tcase_add_test(tc, streamer_loop_enable_and_types);
    tcase_add_test(tc, sampler_writes_only_while_enabled);
    tcase_add_test(tc, sampler_file_replaced_atomically);
    tcase_add_test(tc, sampler_write_error_is_a_fault);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(hal_comps_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
