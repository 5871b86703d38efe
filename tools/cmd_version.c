/* cmd_version.c: `hexcnc version` prints the program version. */
#include <stdio.h>

#include "tools/cmd.h"

const char cmd_version_usage[] = "version                         print the hexcnc version";

int cmd_version(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    printf("hexcnc 0.1.0\n");
    return 0;
}
