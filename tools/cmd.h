/* cmd.h: prototypes of the bin/hexcnc subcommands (one tools/cmd_NAME.c each). */
#ifndef HEXCNC_CMD_H
#define HEXCNC_CMD_H

/* Each subcommand: argv[0] is its own name; returns the process exit status. Its usage
 * line is `cmd_NAME_usage`, shown by `hexcnc --help`. */
#define HEXCNC_CMD(name) int cmd_##name(int argc, char **argv); extern const char cmd_##name##_usage[];
#include "hexcnc_cmds.h"
#undef HEXCNC_CMD

/* `hexcnc halcmd --attach [SOCKET] COMMAND...` (in cmd_ctl.c): argv holds what follows
 * --attach. */
int ctl_halcmd_attach(int argc, char **argv);

#endif
