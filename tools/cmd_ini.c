/* cmd_ini.c: `hexcnc ini check FILE...` checks INI files against the key table and, for a
 * machine's INI, builds its configuration as `hexcnc check` does; `hexcnc ini doc` prints the
 * reference of every key (docs/ini.md). */
#include <stdio.h>
#include <string.h>

#include "check/check.h"
#include "common/config.h"
#include "tools/cmd.h"

const char cmd_ini_usage[] =
    "ini check CONFIG.ini... | ini doc\n"
    "                                check INI files / print the key reference (docs/ini.md)";

/* Checks each file; every problem is printed, the exit status is 1 if any. A file that
 * passes the key table and names its kinematics ([KINS] KINEMATICS) is then opened as the
 * machine `hexcnc check` opens: what only keys together say (the kinematics' geometry, jerk
 * limits all or none, [TRAJ] JERK_WINDOW against them, the tool table) is checked too, so a
 * file this passes is one `hexcnc check` can load (`hexcnc run` loads its HAL files besides). */
static int ini_check_files(int argc, char **argv)
{
    int bad = 0;
    for (int i = 0; i < argc; i++) {
        struct inifile ini = { 0 };
        char err[8192];
        int loaded = config_load(&ini, argv[i], err, sizeof err) == CONFIG_OK;
        int machine = loaded && inifile_get(&ini, "KINS", "KINEMATICS") != NULL;
        inifile_free(&ini);
        struct check_machine *mc;
        if (!loaded || (machine && check_machine_open(argv[i], &mc, err, sizeof err) !=
                        CHECK_OK)) {
            fprintf(stderr, "%s\n", err);
            bad = 1;
        } else if (machine) {
            check_machine_close(mc);
        }
    }
    return bad;
}

int cmd_ini(int argc, char **argv)
{
    if (argc >= 3 && !strcmp(argv[1], "check"))
        return ini_check_files(argc - 2, argv + 2);
    if (argc == 2 && !strcmp(argv[1], "doc"))
        return config_write_doc(stdout) != 0 || fflush(stdout) != 0;
    fprintf(stderr, "usage: hexcnc %s\n", cmd_ini_usage);
    return 2;
}
