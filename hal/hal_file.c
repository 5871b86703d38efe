/* hal_file.c: HAL files (`source`): continuation lines, nesting, and paths relative to the
 * file being read. */
#include <errno.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "hal/hal_priv.h"

/* Resolves `name` against the folder of the HAL file being read (else leaves it as is). */
int hal_path_resolve(const struct hal *h, const char *name, char *buf, size_t len)
{
    const char *cur = h->source_depth ? h->source_stack[h->source_depth - 1] : NULL;
    const char *slash = cur ? strrchr(cur, '/') : NULL;
    int n;
    if (name[0] == '/' || !slash)
        n = snprintf(buf, len, "%s", name);
    else
        n = snprintf(buf, len, "%.*s/%s", (int)(slash - cur), cur, name);
    return n < 0 || (size_t)n >= len ? HAL_ERR_ARG : HAL_OK;
}

/* Reads one logical line: physical lines ending in `\` are joined. Returns its length, or
 * -1 at the end of the file; *lines counts the physical lines consumed. */
static long hal_read_logical(FILE *f, char **buf, size_t *cap, int *lines)
{
    size_t used = 0;
    char *line = NULL;
    size_t lcap = 0;
    ssize_t n;
    *lines = 0;
    while ((n = getline(&line, &lcap, f)) >= 0) {
        (*lines)++;
        while (n > 0 && (line[n - 1] == '\n' || line[n - 1] == '\r'))
            line[--n] = '\0';
        bool more = n > 0 && line[n - 1] == '\\';
        if (more)
            line[--n] = ' ';
        if (used + (size_t)n + 2 > *cap) {
            size_t ncap = (used + (size_t)n + 2) * 2;
            char *nb = realloc(*buf, ncap);
            if (!nb) {
                free(line);
                return -2;
            }
            *buf = nb;
            *cap = ncap;
        }
        memcpy(*buf + used, line, (size_t)n);
        used += (size_t)n;
        (*buf)[used] = '\0';
        if (!more)
            break;
    }
    free(line);
    return *lines ? (long)used : -1;
}

/* Runs every command of a HAL file, stopping at the first error; output goes to out. */
int hal_source_to(struct hal *h, const char *path, FILE *out)
{
    char full[PATH_MAX];
    if (hal_path_resolve(h, path, full, sizeof full) != HAL_OK)
        return hal_error(h, HAL_ERR_ARG, "source: path '%s' is too long", path);
    if (h->source_depth == (int)(sizeof h->source_stack / sizeof h->source_stack[0]))
        return hal_error(h, HAL_ERR_STATE, "source: '%s': HAL files nested too deep (does "
                         "one source itself?)", full);
    FILE *f = fopen(full, "r");
    if (!f)
        return hal_error(h, HAL_ERR_IO, "cannot open HAL file '%s': %s", full,
                         strerror(errno));
    h->source_stack[h->source_depth++] = full;
    char *buf = NULL;
    size_t cap = 0;
    int lineno = 1, nlines, st = HAL_OK;
    long len;
    while ((len = hal_read_logical(f, &buf, &cap, &nlines)) >= 0) {
        st = hal_cmd(h, buf, full, lineno, out);
        if (st != HAL_OK)
            break;
        lineno += nlines;
    }
    if (len == -2)
        st = hal_error(h, HAL_ERR_NOMEM, "out of memory reading '%s'", full);
    free(buf);
    fclose(f);
    h->source_depth--;
    return st;
}

/* Runs a HAL file with its output on stdout. */
int hal_source(struct hal *h, const char *path)
{
    return hal_source_to(h, path, stdout);
}

/* Simulated clock: `start` then advances this long; real time: sleeps this long. */
void hal_set_start_run(struct hal *h, int64_t run_ns)
{
    h->start_run_ns = run_ns;
}
