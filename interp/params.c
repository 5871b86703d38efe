/* params.c: the parameter file (LinuxCNC's format) and the work offsets kept in parameters. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "common/atomicfile.h"
#include "common/errbuf.h"
#include "interp/interp_int.h"

/* Column (1-based) of p in line. */
static int params_col(const char *line, const char *p)
{
    return (int)(p - line) + 1;
}

/* Parses one "number value" line (blank and comment lines leave *n at 0). Plain decimals
 * only: nan, inf, hex, out-of-range numbers and anything after the value are refused. */
static int params_parse_line(struct interp *in, const char *line, long *n, double *v)
{
    const char *p = line + strspn(line, " \t");
    char *end;
    *n = 0;
    if (*p == '\n' || *p == '\r' || *p == 0 || *p == '#' || *p == ';')
        return 0;
    size_t span = strspn(p, "0123456789");
    errno = 0;
    *n = strtol(p, &end, 10);
    if (span == 0 || end != p + span)
        return interp_fail(in, INTERP_ERR_PARAM, params_col(line, p), "a parameter number "
                           "is expected at the start of the line");
    if (errno == ERANGE || *n < 1 || *n >= INTERP_NPARAMS)
        return interp_fail(in, INTERP_ERR_PARAM, params_col(line, p), "parameter number %.*s "
                           "is out of range (1 to %d)", (int)span, p, INTERP_NPARAMS - 1);
    if (*end != ' ' && *end != '\t')
        return interp_fail(in, INTERP_ERR_PARAM, params_col(line, end), "expected 'number "
                           "value': a blank after the parameter number");
    p = end + strspn(end, " \t");
    span = strspn(p, "+-.0123456789eE");
    errno = 0;
    *v = strtod(p, &end);
    if (span == 0 || end != p + span || !isfinite(*v) || (errno == ERANGE && *v != 0.0))
        return interp_fail(in, INTERP_ERR_PARAM, params_col(line, p), "parameter %ld: the "
                           "value '%.*s' is not a finite decimal number", *n,
                           (int)(strcspn(p, " \t\r\n") ? strcspn(p, " \t\r\n") : 1), p);
    end += strspn(end, " \t\r\n");
    if (*end)
        return interp_fail(in, INTERP_ERR_PARAM, params_col(line, end), "parameter %ld: "
                           "unexpected '%.*s' after the value", *n,
                           (int)strcspn(end, "\r\n"), end);
    return 0;
}

/* Reads "number value" lines into in->params, all or nothing: a bad line is an error naming
 * the file, line and column, and no parameter is changed. A missing file is not an error:
 * it will be created when the run ends, as LinuxCNC does with a new parameter file. */
int interp_params_load(struct interp *in, const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        if (errno == ENOENT)
            return 0;
        return interp_fail(in, INTERP_ERR_IO, 0, "cannot read parameter file %s: %s", path,
                           strerror(errno));
    }
    atomicfile_clean_stale(path);
    double *vals = calloc(INTERP_NPARAMS, sizeof *vals);
    unsigned char *set = calloc(INTERP_NPARAMS, 1);
    char line[256];
    int rc = vals && set ? 0 : interp_fail(in, INTERP_ERR_NOMEM, 0, "out of memory");
    in->line = 0;
    while (rc == 0 && fgets(line, sizeof line, f)) {
        long n;
        double v = 0.0;
        in->line++;
        if (!strchr(line, '\n') && !feof(f))
            rc = interp_fail(in, INTERP_ERR_PARAM, 0, "line longer than %d characters",
                             (int)sizeof line - 2);
        else if ((rc = params_parse_line(in, line, &n, &v)) == 0 && n > 0)
            vals[n] = v, set[n] = 1;
    }
    if (rc == 0 && ferror(f))
        rc = interp_fail(in, INTERP_ERR_IO, 0, "cannot read parameter file %s", path);
    for (int i = 0; rc == 0 && i < INTERP_NPARAMS; i++)
        if (set[i])
            in->params[i] = vals[i];
    free(vals);
    free(set);
    fclose(f);
    return rc;
}

/* Whether LinuxCNC writes parameter n to its file (the 9-axis blocks of offsets and each
 * system's rotation). */
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
    return n >= 5221 && (n - 5221) % 20 < 10;   /* X..W and the rotation R */
}

/* Whether parameter n is one the parameter file keeps (for settings.c). */
int interp_param_persistent(int n)
{
    return persistent(n);
}

/* Writes the persistent parameters through common/atomicfile: a private temporary next to
 * the file, fsync, rename; a crash leaves the old file or the new one, never half, and two
 * processes saving the same file never share a temporary. */
int interp_params_save(struct interp *in)
{
    if (!in->param_path)
        return 0;
    struct atomicfile a;
    char err[512];
    int st = atomicfile_open(&a, in->param_path, err, sizeof err);
    for (int i = PARAM_PERSIST_LO; st == ATOMICFILE_OK && i <= PARAM_PERSIST_HI; i++)
        if (persistent(i) && fprintf(a.f, "%d\t%.6f\n", i, in->params[i]) < 0) {
            atomicfile_abort(&a);
            st = errbuf_set(err, sizeof err, ATOMICFILE_ERR_IO, "%s: cannot write the file: "
                            "%s (left as it was)", in->param_path, strerror(errno));
        }
    if (st == ATOMICFILE_OK)
        st = atomicfile_commit(&a, err, sizeof err);
    if (st != ATOMICFILE_OK)
        return interp_fail(in, INTERP_ERR_IO, 0, "cannot save the parameter file: %s", err);
    return 0;
}

/* Makes coordinate system 1..9 (G54..G59.3) active, reading its offsets from parameters. */
void interp_select_coord(struct interp *in, int system)
{
    in->coord_system = system;
    in->params[PARAM_COORD] = system;
    for (int i = 0; i < 6; i++)
        in->g5x[i] = in->params[PARAM_G54 + 20 * (system - 1) + i];
    in->rot_deg = in->params[PARAM_G54 + 20 * (system - 1) + PARAM_ROT];
}

/* Tells the sink the total offset now in force (work + G92 + tool) and the rotation. */
int interp_emit_offsets(struct interp *in)
{
    struct canon_cmd c;
    interp_cmd_init(in, &c, CANON_OFFSETS);
    for (int i = 0; i < 6; i++)
        c.offset[i] = in->g5x[i] + in->g92[i] + in->tool[i];
    c.value = in->rot_deg;
    return interp_emit(in, &c);
}
