/* test_hal_cmd.c: the HAL command language: the error message of every file in
 * tests/hal/errors, word for word, and the commands' effects and output. */
#include <check.h>
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "hal/hal.h"
#include "kins/kins.h"

/* Runs in tests/hal so that messages carry the short relative paths. */
static void enter_test_dir(void)
{
    const char *root = getenv("HEXCNC_ROOT");
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/tests/hal", root ? root : ".");
    ck_assert_msg(chdir(dir) == 0, "cannot enter %s", dir);
}

/* A runtime with tests/hal/graph.ini loaded. */
static struct hal *new_hal(void)
{
    enter_test_dir();
    struct hal *h = hal_create();
    ck_assert_ptr_nonnull(h);
    ck_assert_int_eq(hal_load_ini(h, "graph.ini"), HAL_OK);
    return h;
}

/* Sources a bad file and compares the message word for word. */
static void expect_error(const char *file, int status, const char *message)
{
    struct hal *h = new_hal();
    FILE *devnull = fopen("/dev/null", "w");
    ck_assert_int_eq(hal_source_to(h, file, devnull), status);
    ck_assert_str_eq(hal_last_error(h), message);
    fclose(devnull);
    hal_destroy(h);
}

START_TEST(bad_hal_files_name_file_line_and_fault)
{
    expect_error("errors/unknown_pin.hal", HAL_ERR_NOT_FOUND,
                 "errors/unknown_pin.hal:3: net: pin 'stepgen.9.position-cmd' does not exist");
    expect_error("errors/type_mismatch.hal", HAL_ERR_TYPE,
                 "errors/type_mismatch.hal:3: net: signal 'x' is float but pin 'and2.0.in0' "
                 "is bit");
    expect_error("errors/second_writer.hal", HAL_ERR_DIR,
                 "errors/second_writer.hal:4: net: signal 'total' already has a writer "
                 "'sum2.0.out'; 'sum2.1.out' cannot also write it");
    expect_error("errors/unknown_command.hal", HAL_ERR_SYNTAX,
                 "errors/unknown_command.hal:2: unknown command 'nett'");
    expect_error("errors/bad_number.hal", HAL_ERR_SYNTAX,
                 "errors/bad_number.hal:2: setp: '1.5.2' is not a valid float number for "
                 "'sum2.0.gain0'");
    expect_error("errors/bad_period.hal", HAL_ERR_SYNTAX,
                 "errors/bad_period.hal:1: newthread: period '1ms' is not a whole number");
    expect_error("errors/unknown_ini_key.hal", HAL_ERR_NOT_FOUND,
                 "errors/unknown_ini_key.hal:2: [KINS]NO_SUCH_KEY: no such key in graph.ini");
    expect_error("errors/continued.hal", HAL_ERR_NOT_FOUND,
                 "errors/continued.hal:3: net: pin 'sum2.0.nope' does not exist");
    expect_error("errors/nested.hal", HAL_ERR_DIR,
                 "errors/nested_inner.hal:3: setp: pin 'sum2.0.out' is an output; its "
                 "component writes it");
    expect_error("errors/missing_source.hal", HAL_ERR_IO,
                 "errors/missing_source.hal:1: cannot open HAL file "
                 "'errors/no_such_file.hal': No such file or directory");
}
END_TEST

START_TEST(missing_plugin_names_the_paths_tried)
{
    setenv("HEXCNC_PLUGIN_DIR", "/nonexistent/plugins", 1);
    struct hal *h = new_hal();
    ck_assert_int_eq(hal_source(h, "errors/missing_plugin.hal"), HAL_ERR_NOT_FOUND);
    const char *msg = hal_last_error(h);
    const char *start = "errors/missing_plugin.hal:1: loadrt: no component 'no-such-comp': "
                        "it is not built in, no plugin at /nonexistent/plugins/hal/"
                        "no-such-comp.so, ";
    ck_assert_msg(!strncmp(msg, start, strlen(start)), "got: %s", msg);
    ck_assert_ptr_nonnull(strstr(msg, "/lib/hexcnc/hal/no-such-comp.so"));
    ck_assert_ptr_nonnull(strstr(msg, "and no kinematics of that name"));
    hal_destroy(h);
    unsetenv("HEXCNC_PLUGIN_DIR");
}
END_TEST

/* Runs command lines, returning what they printed. */
static char *run(struct hal *h, const char *const *lines, int expect_status)
{
    char *text = NULL;
    size_t len = 0;
    FILE *out = open_memstream(&text, &len);
    int st = HAL_OK;
    for (int i = 0; lines[i] && st == HAL_OK; i++)
        st = hal_cmd(h, lines[i], "t.hal", i + 1, out);
    fclose(out);
    ck_assert_msg(st == expect_status, "status %d, error: %s", st, hal_last_error(h));
    return text;
}

START_TEST(commands_comments_quotes_and_output)
{
    struct hal *h = new_hal();
    const char *const lines[] = {
        "# a comment line",
        "   ",
        "loadrt sum2 names=mix,other   # a trailing comment",
        "setp mix.gain0 [JOINT_2]MAX_LIMIT",
        "mix.offset = 0.5",
        "newsig \"in#1\" float",
        "linkps mix.in0 \"in#1\"",
        "linksp in#1 other.in1",
        "sets in#1 2",
        "loadrt threads name1=servo-thread period1=1000000",
        "addf mix servo-thread",
        "start",
        "getp mix.gain0",
        "gets in#1",
        "getp other.in1",
        NULL
    };
    char *text = run(h, lines, HAL_OK);
    ck_assert_int_eq(hal_sim_clock(h), false);
    ck_assert_str_eq(text, "100\n2\n2\n");
    free(text);
    ck_assert_int_eq(hal_stop(h), HAL_OK);
    hal_destroy(h);
}
END_TEST

START_TEST(start_runs_the_simulated_clock_and_show_lists)
{
    struct hal *h = new_hal();
    hal_set_sim_clock(h, true);
    hal_set_start_run(h, 3000000);
    const char *const lines[] = {
        "loadrt threads name1=servo-thread period1=1000000",
        "loadrt sum2",
        "setp sum2.0.offset 1",
        "net fb sum2.0.out => sum2.0.in0",
        "addf sum2.0 servo-thread",
        "start",
        "getp sum2.0.out",
        "show funct",
        "show thread",
        "show sig fb",
        "show pin sum2.0.in*",
        NULL
    };
    char *text = run(h, lines, HAL_OK);
    ck_assert_int_eq(hal_now_ns(h), 3000000);
    ck_assert_str_eq(text,
        "3\n"
        "Exported Functions:\n"
        "  Thread            Name\n"
        "  servo-thread      sum2.0\n"
        "Threads:\n"
        "     Period_ns  Name  (time_ns, tmax_ns, overruns)\n"
        "       1000000  servo-thread  (0, 0, 0)\n"
        "                 1 sum2.0\n"
        "Signals:\n"
        "  Type           Value  Name  (linked to)\n"
        "  float              3  fb\n"
        "                       <== sum2.0.out\n"
        "                       ==> sum2.0.in0\n"
        "Component Pins:\n"
        "  Type  Dir          Value  Name\n"
        "  float IN               3  sum2.0.in0 <== fb\n"
        "  float IN               0  sum2.0.in1\n");
    free(text);
    hal_destroy(h);
}
END_TEST

START_TEST(command_errors)
{
    struct hal *h = new_hal();
    static const struct {
        const char *line;
        const char *msg;
    } cases[] = {
        { "loadusr halmeter", "t.hal:1: loadusr: not supported; hexcnc runs every component "
          "in one process with loadrt" },
        { "loadrt sum2 gain=2", "t.hal:1: loadrt sum2: unknown argument 'gain=2' (it takes "
          "count,names)" },
        { "loadrt sum2 count=0", "t.hal:1: loadrt sum2: count=0 must be a whole number from "
          "1 to 16" },
        { "show pins extra words", "t.hal:1: show: [pin|sig|funct|thread|param|comp] "
          "[pattern]" },
        { "show wires", "t.hal:1: show: unknown section 'wires' (pin, sig, param, funct, "
          "thread, comp or all)" },
        { "setp \"unterminated", "t.hal:1: missing closing quote" },
        { "loadrt threads name1=x", "t.hal:1: loadrt threads: name1= needs period1=" },
        { "addf nothing servo", "t.hal:1: addf: function 'nothing' does not exist" },
        { "net onlysignal", "t.hal:1: net: needs a signal name and at least one pin" },
        { "loadrt kins", "t.hal:1: loadrt kins: no kinematics loaded; load one by its name, "
          "e.g. loadrt [KINS]KINEMATICS" },
        { "loadrt streamer cfg=fx data=1", "t.hal:1: loadrt streamer: cfg=fx must be 1 to 32 "
          "letters f (float), b (bit), s (s32) or u (u32)" },
        { "loadrt streamer cfg=fb data=1,0;2", "t.hal:1: data=:2: streamer: expected 2 "
          "values (cfg=fb), found 1" },
        { "loadrt streamer cfg=fb data=1,2", "t.hal:1: data=:1: streamer: '2' in column 2 is "
          "not a bit (0 or 1) value" },
        { "stop now", "t.hal:1: stop: takes no arguments" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        ck_assert_int_ne(hal_cmd(h, cases[i].line, "t.hal", 1, NULL), HAL_OK);
        ck_assert_str_eq(hal_last_error(h), cases[i].msg);
    }
    char *longline = malloc(5000);
    ck_assert_ptr_nonnull(longline);
    memset(longline, 'x', 4999);
    longline[4999] = '\0';
    ck_assert_int_eq(hal_cmd(h, longline, "t.hal", 9, NULL), HAL_ERR_SYNTAX);
    ck_assert_str_eq(hal_last_error(h), "t.hal:9: line longer than 4095 characters");
    free(longline);
    /* the failed streamer loads left nothing behind */
    ck_assert_ptr_null(hal_data_ptr(h, "streamer.0.pin.0", NULL));
    ck_assert_int_eq(hal_cmd(h, "loadrt streamer cfg=fb data=1,0;2,1", "t.hal", 1, NULL),
                     HAL_OK);
    ck_assert_ptr_nonnull(hal_data_ptr(h, "streamer.0.pin.0", NULL));
    hal_destroy(h);
}
END_TEST

/* addf positions beyond an int are refused as such, not wrapped onto a valid position
 * (4294967297 used to become 1, 4294967296 to become 0: "append"). */
START_TEST(addf_position_out_of_range)
{
    struct hal *h = new_hal();
    ck_assert_int_eq(hal_cmd(h, "loadrt threads name1=servo period1=1000000", "t.hal", 1, NULL),
                     HAL_OK);
    ck_assert_int_eq(hal_cmd(h, "loadrt sum2 count=2", "t.hal", 2, NULL), HAL_OK);
    static const char *const bad[] = { "4294967297", "4294967296", "-4294967296",
                                       "2147483648", "-2147483648", "9223372036854775807" };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char line[80], msg[200];
        snprintf(line, sizeof line, "addf sum2.0 servo %s", bad[i]);
        ck_assert_int_eq(hal_cmd(h, line, "t.hal", 3, NULL), HAL_ERR_ARG);
        snprintf(msg, sizeof msg, "t.hal:3: addf: position %s is outside thread 'servo', "
                 "which has 0 functions", bad[i]);
        ck_assert_str_eq(hal_last_error(h), msg);
    }
    /* nothing was added: the function is still free and goes first */
    ck_assert_int_eq(hal_cmd(h, "addf sum2.0 servo 1", "t.hal", 4, NULL), HAL_OK);
    ck_assert_int_eq(hal_cmd(h, "addf sum2.1 servo -1", "t.hal", 5, NULL), HAL_OK);
    ck_assert_int_eq(hal_cmd(h, "addf sum2.0 servo 3", "t.hal", 6, NULL), HAL_ERR_EXISTS);
    hal_destroy(h);
}
END_TEST

/* streamer file= reads the whole file at load time: a FIFO without a writer, /dev/zero or a
 * folder is refused at once with what it is, instead of holding start-up forever. */
START_TEST(streamer_refuses_files_that_never_end)
{
    struct hal *h = new_hal();
    char dir[] = "/tmp/hexcnc-streamer.XXXXXX", fifo[64], line[128];
    ck_assert_ptr_nonnull(mkdtemp(dir));
    snprintf(fifo, sizeof fifo, "%s/fifo", dir);
    ck_assert_int_eq(mkfifo(fifo, 0600), 0);
    static const struct { const char *file, *kind; } cases[] = {
        { "/dev/zero", "a character device" }, { NULL, "a FIFO" }, { "/tmp", "a folder" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const char *file = cases[i].file ? cases[i].file : fifo;
        char msg[300];
        snprintf(line, sizeof line, "loadrt streamer cfg=f file=%s", file);
        ck_assert_int_eq(hal_cmd(h, line, "t.hal", 7, NULL), HAL_ERR_IO);
        snprintf(msg, sizeof msg, "t.hal:7: streamer: '%s' is %s, not a regular file: file= "
                 "is read whole when the streamer is loaded", file, cases[i].kind);
        ck_assert_str_eq(hal_last_error(h), msg);
        ck_assert_ptr_null(hal_data_ptr(h, "streamer.0.pin.0", NULL));
    }
    unlink(fifo);
    rmdir(dir);
    hal_destroy(h);
}
END_TEST

START_TEST(kinematics_by_name_becomes_the_kins_component)
{
    void *dl = NULL;
    char err[512];
    if (!kins_find("trivial", &dl, err, sizeof err)) {
        fprintf(stderr, "test_hal_cmd: skipping loadrt of kinematics: %s\n", err);
        return;
    }
    if (dl)
        dlclose(dl);
    struct hal *h = new_hal();
    ck_assert_int_eq(hal_cmd(h, "loadrt [KINS]KINEMATICS", NULL, 0, NULL), HAL_OK);
    ck_assert_ptr_nonnull(hal_get_object(h, "kins"));
    ck_assert_ptr_nonnull(hal_data_ptr(h, "kins.joint-fb-5", NULL));
    ck_assert_ptr_null(hal_data_ptr(h, "kins.joint-fb-6", NULL));
    ck_assert_ptr_nonnull(hal_data_ptr(h, "kins.pose-fb-c", NULL));
    ck_assert_int_eq(hal_cmd(h, "loadrt trivial", NULL, 0, NULL), HAL_ERR_EXISTS);
    ck_assert_str_eq(hal_last_error(h), "loadrt trivial: a kinematics is already loaded; a "
                     "machine has one");
    hal_destroy(h);
}
END_TEST

/* A kinematics' own config error, through loadrt, names the INI file and the key's line. */
START_TEST(kinematics_config_error_names_the_ini_line)
{
    void *dl = NULL;
    char err[512];
    if (!kins_find("hexapod", &dl, err, sizeof err)) {
        fprintf(stderr, "test_hal_cmd: skipping loadrt of kinematics: %s\n", err);
        return;
    }
    if (dl)
        dlclose(dl);
    char path[] = "/tmp/hexcnc-hal-kins-XXXXXX";
    int fd = mkstemp(path);
    ck_assert_int_ge(fd, 0);
    FILE *f = fdopen(fd, "w");
    fprintf(f, "[KINS]\nKINEMATICS = hexapod\nBASE_RADIUS = 500\nPLATFORM_RADIUS = 300\n"
               "BASE_HALF_ANGLE = 10\nPLATFORM_HALF_ANGLE = 10\n");
    for (int i = 0; i < 6; i++)
        fprintf(f, "[JOINT_%d]\nMIN_LIMIT = 520\nMAX_LIMIT = %s\n", i, i == 3 ? "abc" : "980");
    fclose(f);
    struct hal *h = new_hal();
    ck_assert_int_eq(hal_load_ini(h, path), HAL_OK);
    ck_assert_int_eq(hal_cmd(h, "loadrt [KINS]KINEMATICS", "m.hal", 4, NULL),
                     HAL_ERR_COMPONENT);
    char want[256];
    snprintf(want, sizeof want, "m.hal:4: loadrt hexapod: %s:18: [JOINT_3] MAX_LIMIT: 'abc' "
             "is not a number", path);
    ck_assert_str_eq(hal_last_error(h), want);
    ck_assert_ptr_null(hal_get_object(h, "kins"));
    hal_destroy(h);
    unlink(path);
}
END_TEST

static Suite *hal_cmd_suite(void)
{
    Suite *s = suite_create("hal_cmd");
    TCase *tc = tcase_create("cmd");
    tcase_add_test(tc, bad_hal_files_name_file_line_and_fault);
    tcase_add_test(tc, missing_plugin_names_the_paths_tried);
    tcase_add_test(tc, commands_comments_quotes_and_output);
    tcase_add_test(tc, start_runs_the_simulated_clock_and_show_lists);
    tcase_add_test(tc, command_errors);
    tcase_add_test(tc, addf_position_out_of_range);
    tcase_add_test(tc, streamer_refuses_files_that_never_end);
    tcase_add_test(tc, kinematics_by_name_becomes_the_kins_component);
    tcase_add_test(tc, kinematics_config_error_names_the_ini_line);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(hal_cmd_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
