/* test_config.c: the configuration table and its one reader (common/config*.c): unknown
 * sections and keys with the closest name, each type's errors, ranges, required safety
 * limits, LinuxCNC's sections accepted, the table's own consistency, every shipped INI. */
#include <check.h>
#include <ftw.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "common/config.h"

/* A valid base: a small machine with every required key. */
#define BASE_INI                                                                           \
    "# base\n[KINS]\nKINEMATICS = hexapod\n"                                                       \
    "[TRAJ]\nMAX_LINEAR_VELOCITY = 100\nMAX_LINEAR_ACCELERATION = 500\n"                    \
    "MAX_ANGULAR_VELOCITY = 30\nMAX_ANGULAR_ACCELERATION = 300\n"                           \
    "[JOINT_3]\nMIN_LIMIT = 520\nMAX_LIMIT = 980\nMAX_VELOCITY = 100\n"                     \
    "MAX_ACCELERATION = 1000\nFERROR = 1\n"

/* Writes text to a temporary INI, checks it; err gets the messages, path the file name. */
static int check_text(const char *text, char *path, size_t pathlen, char *err, size_t errlen)
{
    snprintf(path, pathlen, "/tmp/hexcnc-config-XXXXXX");
    int fd = mkstemp(path);
    ck_assert_int_ge(fd, 0);
    FILE *f = fdopen(fd, "w");
    ck_assert_ptr_nonnull(f);
    fputs(text, f);
    fclose(f);
    struct inifile ini = { 0 };
    int st = config_load(&ini, path, err, errlen);
    inifile_free(&ini);
    unlink(path);
    return st;
}

/* Checks BASE_INI + extra and expects one message "PATH:LINE: want". */
static void expect_error(const char *extra, int status, int line, const char *want)
{
    char text[2048], path[64], err[2048], full[512];
    snprintf(text, sizeof text, "%s%s", BASE_INI, extra);
    ck_assert_int_eq(check_text(text, path, sizeof path, err, sizeof err), status);
    snprintf(full, sizeof full, "%s:%d: %s", path, line, want);
    ck_assert_str_eq(err, full);
}

/* BASE_INI is 14 lines: what is added starts at line 15 (its first key at 16). */
START_TEST(test_base_is_valid)
{
    char path[64], err[1024];
    ck_assert_int_eq(check_text(BASE_INI, path, sizeof path, err, sizeof err), CONFIG_OK);
    ck_assert_str_eq(err, "");
}
END_TEST

/* The example: MAX_VELOCTY used to leave the leg at 100 mm/s without a word, and
 * a misspelt FEED_UNITS every feed 1000 times slower. */
START_TEST(test_unknown_key_suggests)
{
    expect_error("[JOINT_4]\nMIN_LIMIT = 520\nMAX_LIMIT = 980\nMAX_VELOCITY = 100\n"
                 "MAX_ACCELERATION = 1000\nFERROR = 1\nMAX_VELOCTY = 20\n", CONFIG_ERR_UNKNOWN,
                 21, "[JOINT_4] MAX_VELOCTY: unknown key; did you mean MAX_VELOCITY?");
    expect_error("[RS274NGC]\nFEED_UNIT = m/min\n", CONFIG_ERR_UNKNOWN, 16,
                 "[RS274NGC] FEED_UNIT: unknown key; did you mean FEED_UNITS?");
    expect_error("[KINS]\nPLATFORM_3X = 1 2 3\n", CONFIG_ERR_UNKNOWN, 16,
                 "[KINS] PLATFORM_3X: unknown key; did you mean PLATFORM_3?");
    expect_error("[LCM]\nCOLOUR = blue\n", CONFIG_ERR_UNKNOWN, 16,
                 "[LCM] COLOUR: unknown key");
}
END_TEST

START_TEST(test_unknown_section_suggests)
{
    expect_error("[LMC]\nURL = \n", CONFIG_ERR_UNKNOWN, 16,
                 "[LMC]: unknown section; did you mean [LCM]?");
    expect_error("[JOIN_3]\nFERROR = 1\n", CONFIG_ERR_UNKNOWN, 16,
                 "[JOIN_3]: unknown section; did you mean [JOINT_3]?");
    expect_error("[WIDGETS]\nA = 1\n", CONFIG_ERR_UNKNOWN, 16, "[WIDGETS]: unknown section");
}
END_TEST

/* Each type's errors, with the key named and the unit. */
START_TEST(test_type_errors)
{
    expect_error("[LCM]\nRATE_HZ = fast\n", CONFIG_ERR_VALUE, 16,
                 "[LCM] RATE_HZ = fast: not a number (1/s)");
    expect_error("[LCM]\nRATE_HZ = 20 Hz\n", CONFIG_ERR_VALUE, 16,
                 "[LCM] RATE_HZ = 20 Hz: not a number (1/s)");
    expect_error("[LCM]\nRATE_HZ = inf\n", CONFIG_ERR_VALUE, 16,
                 "[LCM] RATE_HZ = inf: not a number (1/s)");
    expect_error("[LCM]\nRATE_HZ = 1e999\n", CONFIG_ERR_VALUE, 16,
                 "[LCM] RATE_HZ = 1e999: not a number (1/s)");
    expect_error("[LCM]\nRATE_HZ = 0x10\n", CONFIG_ERR_VALUE, 16,
                 "[LCM] RATE_HZ = 0x10: not a number (1/s)");
    expect_error("[KINS]\nHOME = 0 0 645 0 0\n", CONFIG_ERR_VALUE, 16,
                 "[KINS] HOME = 0 0 645 0 0: expected 6 numbers, number 6 is missing or not a "
                 "number (mm, deg)");
    expect_error("[KINS]\nTOOL_AXIS = 0 0 -1 2\n", CONFIG_ERR_VALUE, 16,
                 "[KINS] TOOL_AXIS = 0 0 -1 2: expected 3 numbers, found more text");
    expect_error("[EMCMOT]\nSERVO_PERIOD = 1e6\n", CONFIG_ERR_VALUE, 16,
                 "[EMCMOT] SERVO_PERIOD = 1e6: not a whole number (ns)");
    expect_error("[TRAJ]\nOPTIONAL_STOP = maybe\n", CONFIG_ERR_VALUE, 16,
                 "[TRAJ] OPTIONAL_STOP = maybe: expected 0 or 1 (or TRUE/FALSE, YES/NO, "
                 "ON/OFF)");
    expect_error("[RS274NGC]\nFEED_UNITS = furlongs\n", CONFIG_ERR_VALUE, 16,
                 "[RS274NGC] FEED_UNITS = furlongs: expected one of mm/min|m/min");
    expect_error("[HAL]\nHALFILE =\n", CONFIG_ERR_VALUE, 16,
                 "[HAL] HALFILE = : expected a file name");
}
END_TEST

START_TEST(test_ranges)
{
    expect_error("[JOINT_2]\nMIN_LIMIT = 520\nMAX_LIMIT = 980\nMAX_VELOCITY = -5\n"
                 "MAX_ACCELERATION = 1000\nFERROR = 1\n", CONFIG_ERR_VALUE, 18,
                 "[JOINT_2] MAX_VELOCITY = -5: must be > 0 (mm/s)");
    expect_error("[MODBUS]\nPORT = 70000\n", CONFIG_ERR_VALUE, 16,
                 "[MODBUS] PORT = 70000: must be from 1 to 65535");
    expect_error("[MODBUS_DRIVE_2]\nREG_TARGET = 0x10000\n", CONFIG_ERR_VALUE, 16,
                 "[MODBUS_DRIVE_2] REG_TARGET = 0x10000: must be from 0 to 65534");
    expect_error("[CAN_NODE_0]\nNODE_ID = 5\nCOUNTS_PER_MM = 0\n", CONFIG_ERR_VALUE, 17,
                 "[CAN_NODE_0] COUNTS_PER_MM = 0: must be != 0 (counts/mm)");
    expect_error("[TRAJ]\nKINEMATIC_TOLERANCE = -0.001\n", CONFIG_ERR_VALUE, 16,
                 "[TRAJ] KINEMATIC_TOLERANCE = -0.001: must be >= 0 (mm)");
    char path[64], err[1024];   /* hexadecimal registers, a range's end, zero where >= 0 */
    ck_assert_int_eq(check_text(BASE_INI "[MODBUS_DRIVE_1]\nREG_CONTROL = 0x20\nPORT = 65535\n"
                                "[TRAJ]\nKINEMATIC_TOLERANCE = 0\n",
                                path, sizeof path, err, sizeof err), CONFIG_OK);
}
END_TEST

/* A limit that protects the machine has no default: missing is an error naming it. */
START_TEST(test_missing_required)
{
    expect_error("[JOINT_5]\nMIN_LIMIT = 520\nMAX_LIMIT = 980\nMAX_VELOCITY = 100\n"
                 "MAX_ACCELERATION = 1000\n", CONFIG_ERR_MISSING, 16,
                 "[JOINT_5] FERROR: missing; it has no default (following-error limit at "
                 "MAX_VELOCITY, mm)");
    char path[64], err[2048];
    ck_assert_int_eq(check_text("[TRAJ]\nMAX_LINEAR_VELOCITY = 100\n[KINS]\nJOINTS = 6\n",
                                path, sizeof path, err, sizeof err), CONFIG_ERR_MISSING);
    ck_assert_msg(strstr(err, ":2: [TRAJ] MAX_LINEAR_ACCELERATION: missing") &&
                  strstr(err, ":2: [TRAJ] MAX_ANGULAR_VELOCITY: missing") &&
                  strstr(err, ":2: [TRAJ] MAX_ANGULAR_ACCELERATION: missing") &&
                  strstr(err, ":4: [KINS] KINEMATICS: missing") &&
                  !strstr(err, "MAX_LINEAR_VELOCITY"), "%s", err);
}
END_TEST

/* A key given twice is an error (the reader would use the first); HALFILE may repeat. */
START_TEST(test_repeated_keys)
{
    expect_error("[LCM]\nRATE_HZ = 20\nRATE_HZ = 50\n", CONFIG_ERR_VALUE, 17,
                 "[LCM] RATE_HZ: given again (first at line 16); give it once");
    char path[64], err[1024];
    ck_assert_int_eq(check_text(BASE_INI "[HAL]\nHALFILE = a.hal\nHALFILE = b.hal\n", path,
                                sizeof path, err, sizeof err), CONFIG_OK);
}
END_TEST

/* A LinuxCNC user's INI: other programs' sections and keys are accepted as documented. */
START_TEST(test_foreign_sections_accepted)
{
    char path[64], err[1024];
    ck_assert_int_eq(check_text(BASE_INI
                                "[EMC]\nMACHINE = m\nDEBUG = 0\nNML_FILE = x.nml\n"
                                "[DISPLAY]\nDISPLAY = axis\nCYCLE_TIME = 0.1\n"
                                "[EMCIO]\nEMCIO = io\nTOOL_TABLE = t.tbl\n"
                                "[HALUI]\nMDI_COMMAND = G0 X0\n[FILTER]\nPROGRAM_EXTENSION = "
                                ".py Python\n[AXIS_X]\nMAX_VELOCITY = 5\nMIN_LIMIT = -200\n"
                                "[AXIS_U]\nWHATEVER = 1\n"
                                "[SPINDLE_0]\nMAX_FORWARD_VELOCITY = 100\n"
                                "[EMCMOT]\nEMCMOT = motmod\nBASE_PERIOD = 50000\n"
                                "[TASK]\nTASK = milltask\nCYCLE_TIME = 0.010\n"
                                "[TRAJ]\nCOORDINATES = X Y Z A B C\nLINEAR_UNITS = mm\n",
                                path, sizeof path, err, sizeof err), CONFIG_OK);
    ck_assert_str_eq(err, "");
    /* ... but a key LinuxCNC does not have either is still an error in hexcnc's sections */
    expect_error("[EMCMOT]\nBASE_PERIODE = 50000\n", CONFIG_ERR_UNKNOWN, 16,
                 "[EMCMOT] BASE_PERIODE: unknown key; did you mean BASE_PERIOD?");
    /* [AXIS_X..C] hold the pose's soft limits: checked like hexcnc's own sections */
    expect_error("[AXIS_Z]\nMAX_LIMITS = 700\n", CONFIG_ERR_UNKNOWN, 16,
                 "[AXIS_Z] MAX_LIMITS: unknown key; did you mean MAX_LIMIT?");
}
END_TEST

/* The value rules themselves. */
START_TEST(test_parsers)
{
    double x, v[3];
    long n;
    int b;
    char why[128];
    ck_assert_int_eq(config_parse_number(" -1.5e-3 ", &x, why, sizeof why), 0);
    ck_assert(x == -1.5e-3);
    ck_assert_int_eq(config_parse_number("", &x, why, sizeof why), -1);
    ck_assert_int_eq(config_parse_number("nan", &x, why, sizeof why), -1);
    ck_assert_int_eq(config_parse_number("5-3", &x, why, sizeof why), -1);
    ck_assert_str_eq(why, "not a number");
    ck_assert_int_eq(config_parse_numbers("1, 2 ,3", v, 3, why, sizeof why), 0);
    ck_assert(v[0] == 1 && v[1] == 2 && v[2] == 3);
    ck_assert_int_eq(config_parse_numbers("1,,2,3", v, 3, why, sizeof why), -1);
    ck_assert_int_eq(config_parse_integer("0x1F", &n, why, sizeof why), 0);
    ck_assert_int_eq(n, 31);
    ck_assert_int_eq(config_parse_integer("017", &n, why, sizeof why), 0);
    ck_assert_int_eq(n, 17);                       /* decimal, not octal */
    ck_assert_int_eq(config_parse_integer("0x", &n, why, sizeof why), -1);
    ck_assert_int_eq(config_parse_bool("Yes", &b, why, sizeof why), 0);
    ck_assert_int_eq(b, 1);
    ck_assert_int_eq(config_parse_bool("off", &b, why, sizeof why), 0);
    ck_assert_int_eq(b, 0);
    ck_assert_int_eq(config_in_range(0, "> 0", why, sizeof why), -1);
    ck_assert_str_eq(why, "must be > 0");
    ck_assert_int_eq(config_in_range(59, "0..59", why, sizeof why), 0);
    ck_assert_int_eq(config_in_range(59.5, "0..59", why, sizeof why), -1);
    ck_assert_str_eq(why, "must be from 0 to 59");
    ck_assert_int_eq(config_edit_distance("MAX_VELOCTY", "MAX_VELOCITY"), 1);
    ck_assert_int_eq(config_edit_distance("LMC", "LCM"), 1);
    ck_assert_int_eq(config_edit_distance("feed_units", "FEED_UNITS"), 0);
}
END_TEST

/* The table is consistent: sections known, no key twice, defaults inside their ranges,
 * required keys without a default, one-line descriptions. */
START_TEST(test_table_consistent)
{
    for (int i = 0; i < config_nkeys; i++) {
        const struct config_key *k = &config_keys[i];
        int known = 0;
        for (int s = 0; s < config_nsections; s++)
            known |= !strcmp(config_sections[s].name, k->section);
        ck_assert_msg(known, "[%s] %s: section not in config_sections", k->section, k->key);
        for (int j = 0; j < i; j++)
            ck_assert_msg(strcmp(config_keys[j].section, k->section) ||
                          strcmp(config_keys[j].key, k->key), "[%s] %s twice", k->section,
                          k->key);
        ck_assert_msg(k->doc[0] && !strchr(k->doc, '\n'), "[%s] %s: doc", k->section, k->key);
        ck_assert_msg(!(k->flags & CONFIG_REQUIRED) || !k->def[0], "[%s] %s: required with a "
                      "default", k->section, k->key);
        char why[256];
        double x;
        long n;
        int numeric_default = k->def[0] && (k->type == CONFIG_NUMBER
                                            ? config_parse_number(k->def, &x, NULL, 0) == 0
                                            : k->type == CONFIG_INTEGER &&
                                              config_parse_integer(k->def, &n, NULL, 0) == 0);
        if (numeric_default || (k->def[0] && k->type == CONFIG_ENUM))
            ck_assert_msg(config_check_value(k, k->def, why, sizeof why) == 0,
                          "[%s] %s: default %s: %s", k->section, k->key, k->def, why);
    }
}
END_TEST

/* Every INI the tree ships validates (the reader's own test files in tests/hal/ini, made
 * to be odd, excepted). */
static int shipped_bad;
static char shipped_root[4096];

static int check_one_ini(const char *path, const struct stat *sb, int type, struct FTW *ftw)
{
    (void)sb;
    (void)ftw;
    size_t n = strlen(path);
    if (type != FTW_F || n < 4 || strcmp(path + n - 4, ".ini") ||
        strstr(path, "/tests/hal/ini/") || strstr(path, "/build/"))
        return 0;
    struct inifile ini = { 0 };
    char err[4096];
    if (config_load(&ini, path, err, sizeof err) != CONFIG_OK) {
        fprintf(stderr, "%s\n", err);
        shipped_bad++;
    }
    inifile_free(&ini);
    return 0;
}

START_TEST(test_shipped_inis_validate)
{
    const char *root = getenv("HEXCNC_ROOT");
    static const char *const dirs[] = { "configs", "examples", "tests" };
    shipped_bad = 0;
    for (int i = 0; i < 3; i++) {
        snprintf(shipped_root, sizeof shipped_root, "%s/%s", root ? root : ".", dirs[i]);
        ck_assert_int_eq(nftw(shipped_root, check_one_ini, 16, FTW_PHYS), 0);
    }
    ck_assert_int_eq(shipped_bad, 0);
}
END_TEST

static Suite *config_suite(void)
{
    Suite *s = suite_create("config");
    TCase *tc = tcase_create("config");
    tcase_add_test(tc, test_base_is_valid);
    tcase_add_test(tc, test_unknown_key_suggests);
    tcase_add_test(tc, test_unknown_section_suggests);
    tcase_add_test(tc, test_type_errors);
    tcase_add_test(tc, test_ranges);
    tcase_add_test(tc, test_missing_required);
    tcase_add_test(tc, test_repeated_keys);
    tcase_add_test(tc, test_foreign_sections_accepted);
    tcase_add_test(tc, test_parsers);
    tcase_add_test(tc, test_table_consistent);
    tcase_add_test(tc, test_shipped_inis_validate);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(config_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
