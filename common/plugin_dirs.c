/* plugin_dirs.c: the plugin search order shared by the kinematics and HAL loaders. */
#include "common/plugin_dirs.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#ifndef HEXCNC_PREFIX
#define HEXCNC_PREFIX "/usr/local"
#endif

/* Appends "<fmt...>" to dirs when it fits in PATH_MAX. */
static void plugin_dirs_add(char dirs[PLUGIN_DIRS_MAX][PATH_MAX], int *n, const char *a,
                            const char *mid, const char *sub)
{
    int w = snprintf(dirs[*n], PATH_MAX, "%s%s%s", a, mid, sub);
    if (w > 0 && w < PATH_MAX)
        (*n)++;
}

int plugin_dirs(char dirs[PLUGIN_DIRS_MAX][PATH_MAX], const char *sub)
{
    int n = 0;
    const char *env = getenv("HEXCNC_PLUGIN_DIR");
    if (env && *env)
        plugin_dirs_add(dirs, &n, env, "/", sub);
    char exe[PATH_MAX];
    ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (len > 0) {
        exe[len] = '\0';
        char *slash = strrchr(exe, '/');
        if (slash) {
            *slash = '\0';
            plugin_dirs_add(dirs, &n, exe, "/../lib/", sub);
            plugin_dirs_add(dirs, &n, exe, "/../lib/hexcnc/", sub);
        }
    }
    plugin_dirs_add(dirs, &n, HEXCNC_PREFIX, "/lib/hexcnc/", sub);
    return n;
}
