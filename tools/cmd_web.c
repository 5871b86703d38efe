/* cmd_web.c: `hexcnc web`: runs bin/hexcnc-web (web/web_main.c), found beside this program. */
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "tools/cmd.h"

const char cmd_web_usage[] =
    "web [--listen ADDRESS:PORT] [--socket PATH] [--quiet] [--exit-with-parent] CONFIG.ini   serve the operator's "
    "station for the machine session (docs/ui.md)";

int cmd_web(int argc, char **argv)
{
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 16);
    if (n <= 0) {
        fprintf(stderr, "hexcnc web: cannot find the program's folder: %s\n", strerror(errno));
        return 1;
    }
    exe[n] = '\0';
    strcpy(strrchr(exe, '/') + 1, "hexcnc-web");
    argv[0] = exe;
    execv(exe, argv);
    fprintf(stderr, "hexcnc web: %s: %s (run make)\n", exe, strerror(errno));
    return 1;
}
