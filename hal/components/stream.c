/* stream.c: `streamer` (rows of values from a file or the loadrt line onto out pins, one row
 * per period) and `sampler` (in-pin values to a file, one line per period, saved atomically),
 * for graph tests. */
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/atomicfile.h"
#include "common/config.h"
#include "hal/hal.h"

#define STREAM_MAX_COLS 32

/* One column's pin pointer, by type letter f b s u. */
union stream_pin {
    double *f;
    bool *b;
    int32_t *s;
    uint32_t *u;
};

/* One value of a streamer row. */
union stream_val {
    double f;
    bool b;
    int32_t s;
    uint32_t u;
};

/* Checks cfg=: 1 to 32 letters among f (float), b (bit), s (s32), u (u32). */
static int stream_cfg(struct hal *h, const char *comp, const char *cfg, int *ncols)
{
    size_t n = cfg ? strlen(cfg) : 0;
    if (n == 0 || n > STREAM_MAX_COLS || strspn(cfg, "fbsu") != n)
        return hal_error(h, HAL_ERR_ARG, "loadrt %s: cfg=%s must be 1 to %d letters f "
                         "(float), b (bit), s (s32) or u (u32)", comp, cfg ? cfg : "",
                         STREAM_MAX_COLS);
    *ncols = (int)n;
    return HAL_OK;
}

/* Instance name: names=NAME, else the first free comp.N. */
static void stream_name(struct hal *h, const char *comp, int argc, char **argv, char *buf,
                        size_t len)
{
    const char *given = hal_arg(argc, argv, "names");
    if (given) {
        snprintf(buf, len, "%s", given);
        return;
    }
    for (int i = 0;; i++) {
        char probe[HAL_INST_NAME_MAX + 16];
        snprintf(buf, len, "%s.%d", comp, i);
        snprintf(probe, sizeof probe, "%s.enable", buf);
        if (!hal_data_ptr(h, probe, NULL))
            return;
    }
}

/* Creates the column pins <name>.pin.K. */
static int stream_pins(struct hal *h, const char *name, const char *cfg, enum hal_dir dir,
                       union stream_pin *pins)
{
    int st = HAL_OK;
    for (int i = 0; cfg[i] && st == HAL_OK; i++) {
        switch (cfg[i]) {
        case 'f': st = hal_pin_float_newf(h, dir, &pins[i].f, "%s.pin.%d", name, i); break;
        case 'b': st = hal_pin_bit_newf(h, dir, &pins[i].b, "%s.pin.%d", name, i); break;
        case 's': st = hal_pin_s32_newf(h, dir, &pins[i].s, "%s.pin.%d", name, i); break;
        default: st = hal_pin_u32_newf(h, dir, &pins[i].u, "%s.pin.%d", name, i); break;
        }
    }
    return st;
}

struct streamer {
    char cfg[STREAM_MAX_COLS + 1];
    int ncols;
    union stream_pin pins[STREAM_MAX_COLS];    /* out: the current row's values */
    bool *enable;                              /* in: stream only while TRUE (default) */
    bool *empty;                               /* out: every row has been output */
    int32_t *row;                              /* out: rows output so far */
    union stream_val *rows;                    /* nrows * ncols values */
    int nrows, cap;
    int next;                                  /* next row to output */
    bool loop;                                 /* start again after the last row */
};

static void streamer_free(void *arg)
{
    struct streamer *s = arg;
    free(s->rows);
    free(s);
}

/* One period: the next row onto the pins (outputs hold after the last row). */
static void streamer_run(void *arg, long period_ns)
{
    struct streamer *s = arg;
    if (!*s->enable)
        return;
    if (s->next >= s->nrows && s->loop)
        s->next = 0;
    if (s->next >= s->nrows) {
        *s->empty = true;
        return;
    }
    const union stream_val *v = &s->rows[(size_t)s->next * (size_t)s->ncols];
    for (int i = 0; i < s->ncols; i++) {
        switch (s->cfg[i]) {
        case 'f': *s->pins[i].f = v[i].f; break;
        case 'b': *s->pins[i].b = v[i].b; break;
        case 's': *s->pins[i].s = v[i].s; break;
        default: *s->pins[i].u = v[i].u; break;
        }
    }
    s->next++;
    *s->row = s->next;
    *s->empty = s->next >= s->nrows && !s->loop;
}

/* Parses one value of type letter t; false when it is not one. */
static bool stream_parse(char t, const char *w, union stream_val *v)
{
    char *end;
    errno = 0;
    if (t == 'b') {
        if (strcmp(w, "0") && strcmp(w, "1"))
            return false;
        v->b = w[0] == '1';
        return true;
    }
    if (t == 'f')   /* the configuration's number rules (common/config_value.c) */
        return config_parse_number(w, &v->f, NULL, 0) == 0;
    long long n = strtoll(w, &end, 0);
    if (end == w || *end || errno == ERANGE)
        return false;
    if (t == 's' && (n < INT32_MIN || n > INT32_MAX))
        return false;
    if (t == 'u' && (n < 0 || n > UINT32_MAX))
        return false;
    if (t == 's')
        v->s = (int32_t)n;
    else
        v->u = (uint32_t)n;
    return true;
}

/* Adds one row from text; `where` and lineno name it in errors. */
static int streamer_row(struct hal *h, struct streamer *s, char *text, const char *where,
                        int lineno)
{
    char *words[STREAM_MAX_COLS + 1], *save = NULL;
    int n = 0;
    for (char *w = strtok_r(text, " \t,\r\n", &save); w; w = strtok_r(NULL, " \t,\r\n", &save))
        if (n <= STREAM_MAX_COLS)
            words[n++] = w;
    if (n == 0)
        return HAL_OK;
    if (n != s->ncols)
        return hal_error(h, HAL_ERR_SYNTAX, "%s:%d: streamer: expected %d values (cfg=%s), "
                         "found %d", where, lineno, s->ncols, s->cfg, n);
    if (s->nrows == s->cap) {
        int cap = s->cap ? s->cap * 2 : 64;
        union stream_val *r = realloc(s->rows, (size_t)cap * (size_t)s->ncols * sizeof *r);
        if (!r)
            return hal_error(h, HAL_ERR_NOMEM, "streamer: out of memory");
        s->rows = r;
        s->cap = cap;
    }
    union stream_val *v = &s->rows[(size_t)s->nrows * (size_t)s->ncols];
    for (int i = 0; i < n; i++)
        if (!stream_parse(s->cfg[i], words[i], &v[i]))
            return hal_error(h, HAL_ERR_SYNTAX, "%s:%d: streamer: '%s' in column %d is not "
                             "a %s value", where, lineno, words[i], i + 1,
                             s->cfg[i] == 'f' ? "float" : s->cfg[i] == 'b' ? "bit (0 or 1)" :
                             s->cfg[i] == 's' ? "s32" : "u32");
    s->nrows++;
    return HAL_OK;
}

/* What a file that is not a regular one is, for the message. */
static const char *stream_file_kind(mode_t m)
{
    return S_ISFIFO(m) ? "a FIFO" : S_ISCHR(m) ? "a character device" : S_ISBLK(m) ?
           "a block device" : S_ISDIR(m) ? "a folder" : S_ISSOCK(m) ? "a socket" : "not a file";
}

/* Opens file= for reading. The rows are all read at load time, so only a regular file will
 * do: a FIFO without a writer, /dev/zero or a terminal would hold start-up forever. The
 * open itself does not wait (O_NONBLOCK: a FIFO's open would block until a writer came). */
static FILE *streamer_open(struct hal *h, const char *path)
{
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        hal_error(h, HAL_ERR_IO, "streamer: cannot open '%s': %s", path, strerror(errno));
        return NULL;
    }
    struct stat st;
    int stat_failed = fstat(fd, &st) != 0;
    if (stat_failed || !S_ISREG(st.st_mode)) {
        hal_error(h, HAL_ERR_IO, "streamer: '%s' is %s, not a regular file: file= is read "
                  "whole when the streamer is loaded", path,
                  stat_failed ? "unreadable" : stream_file_kind(st.st_mode));
        close(fd);
        return NULL;
    }
    FILE *f = fdopen(fd, "r");
    if (!f) {
        hal_error(h, HAL_ERR_NOMEM, "streamer: cannot read '%s': %s", path, strerror(errno));
        close(fd);
    }
    return f;
}

/* Reads the rows: file= (one row a line, `#` comments) or data= (rows split by `;`). */
static int streamer_read(struct hal *h, struct streamer *s, const char *file, const char *data)
{
    int st = HAL_OK, lineno = 0;
    if (data) {
        char *copy = strdup(data), *save = NULL;
        if (!copy)
            return hal_error(h, HAL_ERR_NOMEM, "streamer: out of memory");
        for (char *r = strtok_r(copy, ";", &save); r && st == HAL_OK;
             r = strtok_r(NULL, ";", &save))
            st = streamer_row(h, s, r, "data=", ++lineno);
        free(copy);
        return st;
    }
    char path[PATH_MAX];
    if (hal_path_resolve(h, file, path, sizeof path) != HAL_OK)
        return hal_error(h, HAL_ERR_ARG, "streamer: file name '%s' is too long", file);
    FILE *f = streamer_open(h, path);
    if (!f)
        return HAL_ERR_IO;
    char line[4096];
    while (st == HAL_OK && fgets(line, sizeof line, f)) {
        lineno++;
        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        st = streamer_row(h, s, line, path, lineno);
    }
    fclose(f);
    return st;
}

/* loadrt streamer cfg=LETTERS (file=PATH | data=ROWS) [names=NAME] [loop=1]. */
static int streamer_load(struct hal *h, int argc, char **argv)
{
    const char *cfg = hal_arg(argc, argv, "cfg"), *file = hal_arg(argc, argv, "file");
    const char *data = hal_arg(argc, argv, "data"), *loop = hal_arg(argc, argv, "loop");
    char name[HAL_INST_NAME_MAX];
    int ncols = 0, st = hal_args_check(h, "streamer", argc, argv, "cfg,file,data,names,loop");
    if (st == HAL_OK)
        st = stream_cfg(h, "streamer", cfg, &ncols);
    if (st != HAL_OK)
        return st;
    if (!file == !data)
        return hal_error(h, HAL_ERR_ARG, "loadrt streamer: give file= or data=, one of them");
    struct streamer *s = calloc(1, sizeof *s);
    if (!s)
        return hal_error(h, HAL_ERR_NOMEM, "loadrt streamer: out of memory");
    if ((st = hal_on_destroy(h, streamer_free, s)) != HAL_OK) {
        free(s);
        return st;
    }
    snprintf(s->cfg, sizeof s->cfg, "%s", cfg);
    s->ncols = ncols;
    s->loop = loop && !strcmp(loop, "1");
    if ((st = streamer_read(h, s, file, data)) != HAL_OK)
        return st;
    stream_name(h, "streamer", argc, argv, name, sizeof name);
    st = stream_pins(h, name, cfg, HAL_OUT, s->pins);
    if (st == HAL_OK)
        st = hal_pin_bit_newf(h, HAL_IN, &s->enable, "%s.enable", name);
    if (st == HAL_OK)
        st = hal_pin_bit_newf(h, HAL_OUT, &s->empty, "%s.empty", name);
    if (st == HAL_OK)
        st = hal_pin_s32_newf(h, HAL_OUT, &s->row, "%s.row", name);
    if (st != HAL_OK)
        return st;
    *s->enable = true;
    *s->empty = s->nrows == 0;
    return hal_export_functf(h, streamer_run, s, "%s", name);
}

/* The sampler's file: written through common/atomicfile (a private temporary next to the
 * target, renamed into place when the runtime closes), or straight into an existing FIFO or
 * device (file=/dev/stdout, a pipe a reader follows live). */
struct sampler {
    char cfg[STREAM_MAX_COLS + 1];
    union stream_pin pins[STREAM_MAX_COLS];    /* in: the values written each period */
    bool *enable;                              /* in: sample only while TRUE (default) */
    int32_t *sample_num;                       /* out: lines written so far */
    /* Written by the thread function only, read by sampler_free after the threads stop. */
    FILE *f;                                   /* the temporary, or the FIFO / device */
    bool failed;                               /* a write failed: no more lines, no rename */
    /* Set at load. */
    struct atomicfile af;                      /* the save in progress (atomic mode) */
    bool atomic;                               /* f belongs to af */
    bool loaded;                               /* loadrt succeeded: commit at the end */
    struct hal *h;                             /* for the fault message */
    char name[HAL_INST_NAME_MAX];
    char path[PATH_MAX];
};

/* Renames the finished file into place (or drops it after a write error) and frees s. */
static void sampler_free(void *arg)
{
    struct sampler *s = arg;
    char err[PATH_MAX + 128];
    if (s->atomic && s->loaded && !s->failed) {
        if (atomicfile_commit(&s->af, err, sizeof err) != ATOMICFILE_OK)
            fprintf(stderr, "sampler: %s\n", err);   /* the runtime is going: no one else */
    } else if (s->atomic) {
        atomicfile_abort(&s->af);
    } else if (s->f) {
        fclose(s->f);
    }
    free(s);
}

/* Writes one line with every column (floats %.9g, bits 0/1); false on a write error. */
static bool sampler_line(struct sampler *s)
{
    int bad = 0;
    for (int i = 0; s->cfg[i]; i++) {
        if (i)
            bad |= fputc(' ', s->f) == EOF;
        switch (s->cfg[i]) {
        case 'f': bad |= fprintf(s->f, "%.9g", *s->pins[i].f) < 0; break;
        case 'b': bad |= fputc(*s->pins[i].b ? '1' : '0', s->f) == EOF; break;
        case 's': bad |= fprintf(s->f, "%" PRId32, *s->pins[i].s) < 0; break;
        default: bad |= fprintf(s->f, "%" PRIu32, *s->pins[i].u) < 0; break;
        }
    }
    bad |= fputc('\n', s->f) == EOF;
    return !bad && !ferror(s->f);
}

/* One period: one line while enabled. A write error (disk full, ...) stops the sampler
 * with a fault message; the file it was to replace is left as it was. */
static void sampler_run(void *arg, long period_ns)
{
    struct sampler *s = arg;
    (void)period_ns;
    if (!*s->enable || s->failed)
        return;
    int e = errno;
    errno = 0;
    if (!sampler_line(s)) {
        s->failed = true;
        hal_msg_post(s->h, HAL_MSG_FAULT, s->name, "cannot write %s: %s: sampling stopped "
                     "after %d lines%s", s->path, strerror(errno ? errno : EIO),
                     (int)*s->sample_num, s->atomic ? ", the file is left as it was" : "");
    } else {
        (*s->sample_num)++;
    }
    errno = e;
}

/* Opens the output: straight into an existing FIFO or device, else an atomic save. */
static int sampler_open(struct hal *h, struct sampler *s)
{
    struct stat st;
    char err[PATH_MAX + 128];
    if (stat(s->path, &st) == 0 && !S_ISREG(st.st_mode)) {
        if (!(s->f = fopen(s->path, "w")))
            return hal_error(h, HAL_ERR_IO, "sampler: cannot write '%s': %s", s->path,
                             strerror(errno));
    } else {
        if (atomicfile_open(&s->af, s->path, err, sizeof err) != ATOMICFILE_OK)
            return hal_error(h, HAL_ERR_IO, "sampler: %s", err);
        s->atomic = true;
        s->f = s->af.f;
    }
    setvbuf(s->f, NULL, _IOLBF, 0);        /* whole lines: a write error shows at once */
    return HAL_OK;
}

/* loadrt sampler cfg=LETTERS file=PATH [names=NAME]. */
static int sampler_load(struct hal *h, int argc, char **argv)
{
    const char *cfg = hal_arg(argc, argv, "cfg"), *file = hal_arg(argc, argv, "file");
    char path[PATH_MAX];
    int ncols = 0, st = hal_args_check(h, "sampler", argc, argv, "cfg,file,names");
    if (st == HAL_OK)
        st = stream_cfg(h, "sampler", cfg, &ncols);
    if (st != HAL_OK)
        return st;
    if (!file || hal_path_resolve(h, file, path, sizeof path) != HAL_OK)
        return hal_error(h, HAL_ERR_ARG, "loadrt sampler: needs file=PATH (shorter than %d "
                         "characters)", PATH_MAX);
    struct sampler *s = calloc(1, sizeof *s);
    if (!s)
        return hal_error(h, HAL_ERR_NOMEM, "loadrt sampler: out of memory");
    if ((st = hal_on_destroy(h, sampler_free, s)) != HAL_OK) {
        free(s);
        return st;
    }
    snprintf(s->cfg, sizeof s->cfg, "%s", cfg);
    memcpy(s->path, path, sizeof path);
    s->h = h;
    if ((st = sampler_open(h, s)) != HAL_OK)
        return st;
    stream_name(h, "sampler", argc, argv, s->name, sizeof s->name);
    st = stream_pins(h, s->name, cfg, HAL_IN, s->pins);
    if (st == HAL_OK)
        st = hal_pin_bit_newf(h, HAL_IN, &s->enable, "%s.enable", s->name);
    if (st == HAL_OK)
        st = hal_pin_s32_newf(h, HAL_OUT, &s->sample_num, "%s.sample-num", s->name);
    if (st == HAL_OK)
        st = hal_export_functf(h, sampler_run, s, "%s", s->name);
    if (st != HAL_OK)
        return st;
    *s->enable = true;
    s->loaded = true;
    return HAL_OK;
}

const struct hal_comp_type hal_comp_streamer = { "streamer", streamer_load };
const struct hal_comp_type hal_comp_sampler = { "sampler", sampler_load };
