/* params.c: the parameter file (LinuxCNC's format) and the work offsets kept in parameters. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "interp/interp_int.h"

/* Reads "number value" lines into in->params. A missing file is not an error: it will be
 * created when the run ends, as LinuxCNC does with a new parameter file. */
int interp_params_load(struct interp *in, const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        if (errno == ENOENT)
            return 0;
        return interp_fail(in, INTERP_ERR_IO, 0, "cannot read parameter file %s: %s", path,
                           strerror(errno));
    }
    char line[256];
    int lineno = 0, rc = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        char *p = line;
        while (*p == ' ' || *p == '\t')
            p++;
        if (*p == '\n' || *p == '\r' || *p == 0 || *p == '#' || *p == ';')
            continue;
        char *end;
        long n = strtol(p, &end, 10);
        in->line = lineno;
        if (end == p) {
            rc = interp_fail(in, INTERP_ERR_PARAM, 0, "a parameter number is expected at the "
                             "start of the line");
            break;
        }
        p = end;
        double v = strtod(p, &end);
        if (end == p || n < 1 || n >= INTERP_NPARAMS) {
            rc = interp_fail(in, INTERP_ERR_PARAM, 0, "expected 'number value' with a number "
                             "from 1 to %d", INTERP_NPARAMS - 1);
            break;
        }
        in->params[n] = v;
    }
    fclose(f);
    return rc;
}

/* Whether LinuxCNC writes parameter n to its file (the 9-axis blocks of offsets). */
static int persistent(int n)
{
    if (n < PARAM_PERSIST_LO || n > PARAM_PERSIST_HI)
        return 0;
    if (n >= 5161 && n <= 5169)
        return 1;
    if (n >= 5181 && n <= 5189)
        return 1;
    if (n >= 5210 && n <= 5220)
        return 1;
    return n >= 5221 && (n - 5221) % 20 < 9;
}

/* Whether parameter n is one the parameter file keeps (for settings.c). */
int interp_param_persistent(int n)
{
    return persistent(n);
}

/* Writes the persistent parameters to a temporary file, syncs it and renames it over the
 * parameter file, so a crash leaves either the old file or the new one, never half. */
int interp_params_save(struct interp *in)
{
    if (!in->param_path)
        return 0;
    size_t n = strlen(in->param_path);
    char *tmp = malloc(n + 8);
    if (!tmp)
        return interp_fail(in, INTERP_ERR_NOMEM, 0, "out of memory saving parameters");
    memcpy(tmp, in->param_path, n);
    memcpy(tmp + n, ".tmp", 5);
    FILE *f = fopen(tmp, "w");
    int ok = f != NULL;
    for (int i = PARAM_PERSIST_LO; ok && i <= PARAM_PERSIST_HI; i++)
        if (persistent(i) && fprintf(f, "%d\t%.6f\n", i, in->params[i]) < 0)
            ok = 0;
    if (f) {
        if (fflush(f) != 0 || fsync(fileno(f)) != 0)
            ok = 0;
        if (fclose(f) != 0)
            ok = 0;
    }
    if (ok && rename(tmp, in->param_path) != 0)
        ok = 0;
    int rc = 0;
    if (!ok) {
        rc = interp_fail(in, INTERP_ERR_IO, 0, "cannot write parameter file %s: %s",
                         in->param_path, strerror(errno));
        unlink(tmp);
    }
    free(tmp);
    return rc;
}

/* Makes coordinate system 1..9 (G54..G59.3) active, reading its offsets from parameters. */
void interp_select_coord(struct interp *in, int system)
{
    in->coord_system = system;
    in->params[PARAM_COORD] = system;
    for (int i = 0; i < 6; i++)
        in->g5x[i] = in->params[PARAM_G54 + 20 * (system - 1) + i];
}

/* Tells the sink the total offset now in force (work + G92 + tool). */
int interp_emit_offsets(struct interp *in)
{
    struct canon_cmd c;
    interp_cmd_init(in, &c, CANON_OFFSETS);
    for (int i = 0; i < 6; i++)
        c.offset[i] = in->g5x[i] + in->g92[i] + in->tool[i];
    return interp_emit(in, &c);
}
