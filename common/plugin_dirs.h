/* plugin_dirs.h: where plugins are looked for; one search order for every loader. */
#ifndef HEXCNC_PLUGIN_DIRS_H
#define HEXCNC_PLUGIN_DIRS_H

#include <limits.h>

#define PLUGIN_DIRS_MAX 4

/*
 * Fills dirs with the folders that may hold plugins of one kind (`sub`, e.g. "kins" or
 * "hal"), in search order:
 *   1. $HEXCNC_PLUGIN_DIR/sub          (tests, unusual installs)
 *   2. <exe dir>/../lib/sub            (the build tree: bin/ beside lib/)
 *   3. <exe dir>/../lib/hexcnc/sub     (an installed tree, wherever it was moved)
 *   4. <prefix>/lib/hexcnc/sub         (the prefix the program was built for)
 * Returns how many were written. Paths that would not fit are left out.
 */
int plugin_dirs(char dirs[PLUGIN_DIRS_MAX][PATH_MAX], const char *sub);

#endif
