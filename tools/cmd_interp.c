/* cmd_interp.c: `hexcnc interp` prints a program's canonical commands as LinuxCNC's `rs274 -g`. */
#include <ini.h>
#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "interp/interp.h"
#include "interp/printer.h"
#include "interp/tooltable.h"
#include "tools/cmd.h"

const char cmd_interp_usage[] =
    "interp [-t TOOLTABLE] [-i CONFIG.ini] [-b] [--digits N] PROGRAM\n"
    "                                print the canonical commands of a G-code program";

/* What the INI's [RS274NGC] (and [EMCIO]) sections say, paths relative to the INI. */
struct interp_ini {
    char feed_units[32];
    char param_file[1024];
    char tool_table[1024];
};

/* libinih callback: picks the keys this command uses. */
static int ini_key(void *user, const char *section, const char *name, const char *value)
{
    struct interp_ini *c = user;
    int rs = strcmp(section, "RS274NGC") == 0, io = strcmp(section, "EMCIO") == 0;
    if (rs && strcmp(name, "FEED_UNITS") == 0)
        snprintf(c->feed_units, sizeof c->feed_units, "%s", value);
    else if (rs && strcmp(name, "PARAMETER_FILE") == 0)
        snprintf(c->param_file, sizeof c->param_file, "%s", value);
    else if ((rs || (io && !c->tool_table[0])) && strcmp(name, "TOOL_TABLE") == 0)
        snprintf(c->tool_table, sizeof c->tool_table, "%s", value);
    return 1;
}

/* A path from the INI, taken relative to the INI's folder unless absolute. */
static void ini_path(const char *ini, const char *p, char *out, size_t len)
{
    if (p[0] == '/') {
        snprintf(out, len, "%s", p);
        return;
    }
    char *copy = strdup(ini);
    snprintf(out, len, "%s/%s", copy ? dirname(copy) : ".", p);
    free(copy);
}

/* The printer's output: a stdio stream. */
static int write_stdout(void *ctx, const char *buf, size_t len)
{
    return fwrite(buf, 1, len, ctx) == len ? 0 : -1;
}

/* Applies the INI to the interpreter and loads its tool table; returns 0 or prints why not. */
static int apply_ini(struct interp *in, const char *ini, struct tooltable *tt, const char **tpath,
                     char *tbuf, size_t tlen)
{
    struct interp_ini c;
    memset(&c, 0, sizeof c);
    int rc = ini_parse(ini, ini_key, &c);
    if (rc != 0) {
        fprintf(stderr, rc < 0 ? "%s: error: cannot read the INI file\n"
                               : "%s:%d: error: INI syntax error\n", ini, rc);
        return -1;
    }
    if (c.feed_units[0]) {
        double f;
        if (interp_feed_units_parse(c.feed_units, &f)) {
            fprintf(stderr, "%s: error: [RS274NGC] FEED_UNITS = %s: use mm/min or m/min\n", ini,
                    c.feed_units);
            return -1;
        }
        interp_set_feed_factor(in, f);
    }
    if (c.param_file[0]) {
        char p[2048];
        ini_path(ini, c.param_file, p, sizeof p);
        if (interp_set_param_file(in, p)) {
            char m[600];
            fprintf(stderr, "%s\n", interp_error_format(interp_last_error(in), m, sizeof m));
            return -1;
        }
    }
    if (c.tool_table[0] && !*tpath) {
        ini_path(ini, c.tool_table, tbuf, tlen);
        *tpath = tbuf;
    }
    (void)tt;
    return 0;
}

/* hexcnc interp: options, INI, tool table, then the program through the printer. */
int cmd_interp(int argc, char **argv)
{
    const char *ttpath = NULL, *ini = NULL, *prog = NULL;
    int digits = 4, block_delete = 0;
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "-t") == 0 && i + 1 < argc)
            ttpath = argv[++i];
        else if (strcmp(argv[i], "-i") == 0 && i + 1 < argc)
            ini = argv[++i];
        else if (strcmp(argv[i], "--digits") == 0 && i + 1 < argc)
            digits = atoi(argv[++i]);
        else if (strcmp(argv[i], "-b") == 0)
            block_delete = 1;
        else if (argv[i][0] != '-' && !prog)
            prog = argv[i];
        else {
            fprintf(stderr, "usage: hexcnc %s\n", cmd_interp_usage);
            return 2;
        }
    }
    if (!prog || digits < 0 || digits > 15) {
        fprintf(stderr, "usage: hexcnc %s\n(--digits: 0 to 15)\n", cmd_interp_usage);
        return 2;
    }
    struct interp *in = interp_create();
    struct tooltable *tt = calloc(1, sizeof *tt);
    char tbuf[2048];
    int rc = 1;
    if (!in || !tt) {
        fprintf(stderr, "hexcnc interp: out of memory\n");
        goto out;
    }
    interp_set_block_delete(in, block_delete);
    if (ini && apply_ini(in, ini, tt, &ttpath, tbuf, sizeof tbuf))
        goto out;
    if (ttpath) {
        char err[512];
        tooltable_init(tt);
        if (tooltable_load(tt, ttpath, err, sizeof err)) {
            fprintf(stderr, "error: %s\n", err);
            goto out;
        }
        interp_set_tooltable(in, tt);
    }
    struct interp_printer *pr = malloc(sizeof *pr);
    if (!pr)
        goto out;
    interp_printer_init(pr, in, digits, write_stdout, stdout);
    interp_printer_preamble(pr);
    int st = interp_run_file(in, prog, interp_printer_sink, pr);
    int wr = interp_printer_flush(pr);
    free(pr);
    fflush(stdout);
    if (st) {
        char m[600];
        fprintf(stderr, "%s\n", interp_error_format(interp_last_error(in), m, sizeof m));
    } else if (wr) {
        fprintf(stderr, "hexcnc interp: error writing the output\n");
    } else {
        rc = 0;
    }
out:
    free(tt);
    interp_destroy(in);
    return rc;
}
