/* hexcnc.c: the bin/hexcnc front: dispatches to the subcommands in tools/cmd_*.c. */
#include <stdio.h>
#include <string.h>

#include "tools/cmd.h"

struct hexcnc_cmd {
    const char *name;
    int (*fn)(int argc, char **argv);
    const char *usage;
};

static const struct hexcnc_cmd hexcnc_cmds[] = {
#define HEXCNC_CMD(name) { #name, cmd_##name, cmd_##name##_usage },
#include "hexcnc_cmds.h"
#undef HEXCNC_CMD
    { NULL, NULL, NULL }
};

static void hexcnc_usage(FILE *f)
{
    fprintf(f, "usage: hexcnc COMMAND [ARGS...]\n\ncommands:\n");
    for (const struct hexcnc_cmd *c = hexcnc_cmds; c->name; c++)
        fprintf(f, "  %s\n", c->usage);
}

/* Whether the arguments ask for help: -h or --help anywhere before a "--", as GNU tools
 * take it (a subcommand then prints its usage on stdout and exits 0 without doing anything). */
static int hexcnc_wants_help(int argc, char **argv)
{
    for (int i = 1; i < argc && strcmp(argv[i], "--") != 0; i++)
        if (!strcmp(argv[i], "-h") || !strcmp(argv[i], "--help"))
            return 1;
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "-h") || !strcmp(argv[1], "--help")) {
        hexcnc_usage(argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    for (const struct hexcnc_cmd *c = hexcnc_cmds; c->name; c++)
        if (!strcmp(argv[1], c->name)) {
            if (hexcnc_wants_help(argc - 1, argv + 1)) {
                printf("usage: hexcnc %s\n", c->usage);
                return 0;
            }
            return c->fn(argc - 1, argv + 1);
        }
    fprintf(stderr, "hexcnc: unknown command '%s'\n", argv[1]);
    hexcnc_usage(stderr);
    return 2;
}
