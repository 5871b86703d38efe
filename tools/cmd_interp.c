/* cmd_interp.c: `hexcnc interp` prints a program's canonical commands as LinuxCNC's `rs274 -g`. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/config.h"
#include "interp/interp.h"
#include "interp/interp_setup.h"
#include "interp/printer.h"
#include "interp/tooltable.h"
#include "kins/kins.h"
#include "tools/cmd.h"

const char cmd_interp_usage[] =
    "interp [-t TOOLTABLE] [-i CONFIG.ini] [-b] [--digits N] PROGRAM\n"
    "                                print the canonical commands of a G-code program";

/* The printer's output: a stdio stream. */
static int write_stdout(void *ctx, const char *buf, size_t len)
{
    return fwrite(buf, 1, len, ctx) == len ? 0 : -1;
}

/* Applies the INI's interpreter settings (interp_setup); its tool table goes into tt unless
 * tt is NULL (-t given). ini stays loaded for #<_ini[..]..> (the caller frees it). Returns 0
 * or prints why not. */
static int apply_ini(struct interp *in, const char *path, struct inifile *ini,
                     struct tooltable *tt)
{
    char err[1024], msg[1536];
    if (config_load(ini, path, err, sizeof err) != CONFIG_OK) {
        fprintf(stderr, "error: %s\n", err);
        return -1;
    }
    if (tt)
        tooltable_init(tt);
    int st = interp_setup(in, tt, inifile_config_get, ini, inifile_dir(ini), 0, err,
                          sizeof err);
    if (st != INTERP_OK)   /* a bad value names its key: point it at the INI's line */
        fprintf(stderr, "error: %s\n", st == INTERP_ERR_CONFIG
                ? inifile_locate_msg(ini, err, msg, sizeof msg) : err);
    const char *kname = inifile_get(ini, "KINS", "KINEMATICS");
    if (st == INTERP_OK && kname) {   /* the machine's tool, for G43.4 */
        struct kins_config cfg = { inifile_config_get, ini };
        struct kins *k = NULL;
        if (kins_load(kname, &cfg, &k, err, sizeof err) != KINS_OK) {
            fprintf(stderr, "error: %s\n", err);
            st = INTERP_ERR_CONFIG;
        }
        interp_use_kins(in, k);
        kins_free(k);
    }
    return st == INTERP_OK ? 0 : -1;
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
    struct inifile inidata = { 0 };   /* kept for #<_ini[..]..> while the program runs */
    int rc = 1;
    if (!in || !tt) {
        fprintf(stderr, "hexcnc interp: out of memory\n");
        goto out;
    }
    interp_set_block_delete(in, block_delete);
    if (ini && apply_ini(in, ini, &inidata, ttpath ? NULL : tt))
        goto out;
    if (ttpath) {
        char err[512];
        tooltable_init(tt);
        if (tooltable_load(tt, ttpath, err, sizeof err)) {
            fprintf(stderr, "error: %s\n", err);
            goto out;
        }
        if (tt->warning[0])
            fprintf(stderr, "warning: %s\n", tt->warning);
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
    inifile_free(&inidata);
    return rc;
}
