/* cmd_halcmd.c: `hexcnc halcmd`: runs a HAL file, one command, or commands from stdin. */
#include <stdlib.h>
#include <string.h>

#include "hal/hal.h"
#include "tools/cmd.h"

const char cmd_halcmd_usage[] =
    "halcmd [-i CONFIG.ini] [-s] [--run-ms N] [-f FILE.hal | COMMAND...]\n"
    "                                  run HAL commands (-s: simulated clock; --run-ms: run\n"
    "                                  the threads N ms after each `start`)\n"
    "  halcmd --attach [SOCKET] show [PATTERN] | getp NAME | setp NAME VALUE | sets NAME VALUE\n"
    "                                  on the running machine session (docs/api.md)";

/* Prints the components' messages (drive faults, warnings) that arrived so far. */
static void halcmd_messages(struct hal *h)
{
    struct hal_msg m;
    while (hal_msg_take(h, &m))
        fprintf(stderr, "halcmd: %s: %s: %s\n", hal_msg_severity_name(m.severity), m.source,
                m.text);
}

/* Reads commands from stdin, one a line, stopping at the first error. */
static int halcmd_stdin(struct hal *h)
{
    char *line = NULL;
    size_t cap = 0;
    int lineno = 0, st = HAL_OK;
    while (st == HAL_OK && getline(&line, &cap, stdin) >= 0) {
        st = hal_cmd(h, line, "<stdin>", ++lineno, stdout);
        halcmd_messages(h);
    }
    free(line);
    return st;
}

/* Joins argv into one command line. */
static int halcmd_words(struct hal *h, int argc, char **argv)
{
    size_t len = 1;
    for (int i = 0; i < argc; i++)
        len += strlen(argv[i]) + 3;
    char *line = malloc(len);
    if (!line)
        return hal_error(h, HAL_ERR_NOMEM, "out of memory");
    line[0] = '\0';
    for (int i = 0; i < argc; i++) {
        bool blank = strpbrk(argv[i], " \t") != NULL;     /* keep a quoted word one word */
        strcat(line, i ? " " : "");
        strcat(line, blank ? "\"" : "");
        strcat(line, argv[i]);
        strcat(line, blank ? "\"" : "");
    }
    int st = hal_cmd(h, line, NULL, 0, stdout);
    free(line);
    return st;
}

int cmd_halcmd(int argc, char **argv)
{
    const char *ini = NULL, *file = NULL;
    bool sim = false;
    long run_ms = 0;
    int i = 1;
    if (argc > 1 && !strcmp(argv[1], "--attach"))
        return ctl_halcmd_attach(argc - 2, argv + 2);
    for (; i < argc && argv[i][0] == '-'; i++) {
        if (!strcmp(argv[i], "-s")) {
            sim = true;
        } else if (!strcmp(argv[i], "-i") && i + 1 < argc) {
            ini = argv[++i];
        } else if (!strcmp(argv[i], "-f") && i + 1 < argc) {
            file = argv[++i];
        } else if (!strcmp(argv[i], "--run-ms") && i + 1 < argc) {
            char *end;
            run_ms = strtol(argv[++i], &end, 10);
            if (*end || run_ms < 0) {
                fprintf(stderr, "halcmd: --run-ms needs a whole number of ms, not '%s'\n",
                        argv[i]);
                return 2;
            }
        } else {
            fprintf(stderr, "usage: hexcnc %s\n", cmd_halcmd_usage);
            return 2;
        }
    }
    if (file && i < argc) {
        fprintf(stderr, "halcmd: give -f FILE or a command, not both\n");
        return 2;
    }
    struct hal *h = hal_create();
    if (!h) {
        fprintf(stderr, "halcmd: out of memory\n");
        return 1;
    }
    hal_set_sim_clock(h, sim);
    hal_set_start_run(h, (int64_t)run_ms * 1000000);
    int st = ini ? hal_load_machine_ini(h, ini) : HAL_OK;
    if (st == HAL_OK)
        st = file ? hal_source(h, file) : i < argc ? halcmd_words(h, argc - i, argv + i)
                                                   : halcmd_stdin(h);
    halcmd_messages(h);
    if (st != HAL_OK)
        fprintf(stderr, "%s\n", hal_last_error(h));
    fflush(stdout);
    hal_destroy(h);
    return st == HAL_OK ? 0 : 1;
}
