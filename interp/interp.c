/* interp.c: the interpreter's public face: lifecycle, configuration, the line loop, errors. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/mman.h>
#include <sys/stat.h>

#include "interp/interp_int.h"
#include "interp/tooltable.h"

static const char *const status_text[INTERP_STATUS_COUNT] = {
    [INTERP_OK] = "no error",
    [INTERP_ERR_IO] = "file cannot be read or written",
    [INTERP_ERR_NOMEM] = "out of memory",
    [INTERP_ERR_SYNTAX] = "syntax error",
    [INTERP_ERR_EXPR] = "expression cannot be evaluated",
    [INTERP_ERR_PARAM] = "bad parameter",
    [INTERP_ERR_MODAL] = "modal group conflict",
    [INTERP_ERR_WORD] = "word missing, repeated or out of range",
    [INTERP_ERR_UNSUPPORTED] = "not supported",
    [INTERP_ERR_ARC] = "impossible arc",
    [INTERP_ERR_CYCLE] = "bad canned cycle",
    [INTERP_ERR_TOOL] = "tool error",
    [INTERP_ERR_COMP5] = "G141/G142 compensation error",
    [INTERP_ERR_SINK] = "stopped by the command consumer",
    [INTERP_ERR_CONFIG] = "bad interpreter setting in the INI file",
    [INTERP_ERR_CANCELLED] = "stopped by the operator",
    [INTERP_ERR_CCOMP] = "G41/G42 cutter compensation error",
    [INTERP_ERR_PROBE] = "a probe move did not find what it sought",
};

/* The fixed text of a status (the message of a run is in struct interp_error). */
const char *interp_strerror(int status)
{
    if (status < 0 || status >= INTERP_STATUS_COUNT)
        return "unknown interpreter status";
    return status_text[status];
}

/* Records the first error of the run at the current line; later ones are ignored. */
int interp_fail(struct interp *in, int status, int column, const char *fmt, ...)
{
    if (in->err.status)
        return in->err.status;
    in->err.status = status;
    snprintf(in->err.file, sizeof in->err.file, "%s", in->file);
    in->err.line = in->line;
    in->err.column = column;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(in->err.message, sizeof in->err.message, fmt, ap);
    va_end(ap);
    return status;
}

/* "file:line:col: error: message", the form compilers use, so editors can jump to it. */
char *interp_error_format(const struct interp_error *e, char *buf, size_t len)
{
    if (e->line > 0 && e->column > 0)
        snprintf(buf, len, "%s:%d:%d: error: %s", e->file, e->line, e->column, e->message);
    else if (e->line > 0)
        snprintf(buf, len, "%s:%d: error: %s", e->file, e->line, e->message);
    else
        snprintf(buf, len, "%s: error: %s", e->file[0] ? e->file : "interp", e->message);
    return buf;
}

/* The modal state a fresh interpreter (and LinuxCNC at start-up) has. */
static void modal_defaults(struct interp *in)
{
    in->motion = 0;
    in->plane = 17;
    in->inch = 0;
    in->incremental = 0;
    in->arc_absolute = 0;
    in->inverse_time = 0;
    in->retract_old_z = 0;
    in->path_mode = 640;
    in->path_tol_mm = 0;
    interp_select_coord(in, 1);
}

/* A new interpreter in LinuxCNC's start-up modes, at the origin. */
struct interp *interp_create(void)
{
    struct interp *in = calloc(1, sizeof *in);
    if (!in)
        return NULL;
    in->feed_factor = 1.0;
    modal_defaults(in);
    comp5_init(&in->comp);
    ccomp_reset(&in->cc);
    return in;
}

/* Frees the interpreter (the tool table is the caller's). */
void interp_destroy(struct interp *in)
{
    if (!in)
        return;
    interp_named_free(in);
    oword_free(in);
    comp5_free(&in->comp);
    ccomp_free(&in->cc);
    interp_nurbs_free(&in->nurbs);
    free(in->param_path);
    free(in);
}

/* Where the machine is before the first move (machine frame, mm/deg). */
void interp_set_start(struct interp *in, const double pose[6])
{
    memcpy(in->start, pose, sizeof in->start);
    if (in->tcp_on)
        kins_tcp_from_pose(&in->tf, in->tcp_len_mm, pose, in->pos);
    else
        memcpy(in->pos, pose, sizeof in->pos);
}

void interp_set_ini(struct interp *in, interp_ini_fn get, void *ctx)
{
    in->ini_get = get;
    in->ini_ctx = ctx;
}

void interp_set_hal_fn(struct interp *in, interp_hal_fn fn, void *ctx)
{
    in->hal_fn = fn;
    in->hal_ctx = ctx;
}

void interp_use_kins(struct interp *in, struct kins *k)
{
    struct kins_tool_frame f;
    if (k && kins_get_tool_frame(k, &f) == KINS_OK)
        interp_set_tool_frame(in, &f);
}

void interp_set_tool_frame(struct interp *in, const struct kins_tool_frame *f)
{
    double plat[6];
    interp_pos_platform(in, plat);
    in->tf = *f;
    in->have_tf = 1;
    in->tcp_on = f->program_tip;
    in->tcp_len_mm = f->length_mm;
    interp_pos_from_platform(in, plat);
}

/* Names the parameter file and loads it, restoring the saved coordinate system and G92. */
int interp_set_param_file(struct interp *in, const char *path)
{
    free(in->param_path);
    in->param_path = NULL;
    memset(&in->err, 0, sizeof in->err);
    if (!path)
        return 0;
    in->param_path = strdup(path);
    if (!in->param_path)
        return interp_fail(in, INTERP_ERR_NOMEM, 0, "out of memory");
    snprintf(in->file, sizeof in->file, "%s", path);
    in->line = 0;
    CHP(interp_params_load(in, path));
    /* The offsets come back as LinuxCNC restores them: the saved system, G92 if it was on. */
    int sys = (int)in->params[PARAM_COORD];
    interp_select_coord(in, sys >= 1 && sys <= 9 ? sys : 1);
    for (int i = 0; i < 6; i++)
        in->g92[i] = in->params[PARAM_G92_ON] != 0.0 ? in->params[PARAM_G92 + i] : 0.0;
    return 0;
}

/* The same load with no file remembered: nothing is written when a run ends. */
int interp_load_param_file(struct interp *in, const char *path)
{
    int st = interp_set_param_file(in, path);
    free(in->param_path);
    in->param_path = NULL;
    return st;
}

/* Tool table used by T, G43 H, G10 L1 and G141/G142 D. */
void interp_set_tooltable(struct interp *in, struct tooltable *tt)
{
    in->tt = tt;
}

/* mm/min per unit of F in metric programs (FEED_UNITS). */
void interp_set_feed_factor(struct interp *in, double mm_min_per_f_unit)
{
    in->feed_factor = mm_min_per_f_unit;
}

/* The block delete switch ('/' lines skipped when on). */
void interp_set_block_delete(struct interp *in, int on)
{
    in->block_delete = on != 0;
}

/* Folders (':' separated) where o<name> call finds name.ngc after the program's folder. */
int interp_set_subroutine_path(struct interp *in, const char *path)
{
    free(in->ow.path);
    in->ow.path = path ? strdup(path) : NULL;
    return path && !in->ow.path ? INTERP_ERR_NOMEM : INTERP_OK;
}

/* How many loop iterations (while, do, repeat) one program may run: more is a runaway
 * program, refused with the loop's label. Default OWORD_LOOP_LIMIT. */
void interp_set_loop_limit(struct interp *in, long iterations)
{
    in->ow.loop_limit = iterations > 0 ? iterations : OWORD_LOOP_LIMIT;
}

/* The operator's stop request, checked before every line. */
void interp_set_cancel(struct interp *in, const volatile sig_atomic_t *flag)
{
    in->cancel = flag;
}

/* FEED_UNITS text to the F multiplier (any case, as every enum key of docs/ini.md). */
int interp_feed_units_parse(const char *name, double *factor)
{
    if (strcasecmp(name, "mm/min") == 0)
        *factor = 1.0;
    else if (strcasecmp(name, "m/min") == 0)
        *factor = 1000.0;
    else
        return -1;
    return 0;
}

/* The error of the last failed call. */
const struct interp_error *interp_last_error(const struct interp *in)
{
    return &in->err;
}

/* Copies the modal state a printer needs to show program coordinates. */
void interp_get_view(const struct interp *in, struct interp_view *v)
{
    v->inch = in->inch;
    v->plane = in->plane;
    v->coord_system = in->coord_system;
    memcpy(v->g5x_mm, in->g5x, sizeof v->g5x_mm);
    memcpy(v->g92_mm, in->g92, sizeof v->g92_mm);
    memcpy(v->tool_mm, in->tool, sizeof v->tool_mm);
    v->xy_rotation_deg = in->rot_deg;
    v->tcp = in->tcp_on;
    v->tcp_len_mm = in->tcp_len_mm;
    v->feed_factor = in->feed_factor;
    v->current_tool = in->current_tool;
    v->path_mode = in->path_mode;
    v->path_tol_mm = in->path_tol_mm;
    v->naive_cam_tol_mm = in->naive_cam_tol_mm;
    v->comp5_active = in->comp.active;
    v->motion = in->motion;
    v->incremental = in->incremental;
    v->inverse_time = in->inverse_time;
    v->per_rev = in->per_rev;
    v->feed_mm_min = in->feed_mm_min;
    v->spindle_dir = in->spindle_dir;
    v->spindle_rpm = in->spindle_rpm;
    v->flood = in->flood;
    v->mist = in->mist;
    v->selected_tool = in->selected_tool;
}

void interp_set_current_tool(struct interp *in, int tool)
{
    in->current_tool = in->selected_tool = tool;
}

/* Reads numbered parameter #n. */
double interp_param(const struct interp *in, int n)
{
    return n >= 1 && n < INTERP_NPARAMS ? in->params[n] : 0.0;
}

/* A G141/G142 error at the end of the program, on the line the compensation names. */
static int interp_comp5_fail(struct interp *in)
{
    interp_fail(in, INTERP_ERR_COMP5, 0, "%s", comp5_errmsg(&in->comp));
    if (in->comp.err_line)
        in->err.line = in->comp.err_line;
    return INTERP_ERR_COMP5;
}

/* Handles a lone '%': one on the first line opens the program, the next one ends it. */
static int percent_line(struct interp *in, int first)
{
    if (first) {
        in->pct_open = 1;
        in->pct_line = in->line;
        return 0;
    }
    if (!in->pct_open)
        return interp_fail(in, INTERP_ERR_SYNTAX, 1, "a '%%' line may only open the program (on "
                           "its first line) and then close it");
    in->ended = 1;
    CHP(ccomp_flush(in));    /* the last compensated move ends where it was placed */
    int rc = comp5_flush(&in->comp, interp_comp_sink, in);
    if (rc)
        return interp_comp5_fail(in);
    return 0;
}

/* Reads and runs every line until the end of the text or of the program; O-words move the
 * line to read next (oword.c). */
static int run_lines(struct interp *in, const char *text, size_t len)
{
    int first = 1;
    if (len >= 3 && !memcmp(text, "\xEF\xBB\xBF", 3)) {
        text += 3;  /* a UTF-8 byte order mark, as editors on Windows write: not part of line 1 */
        len -= 3;
    }
    CHP(oword_begin(in, text, len));
    const char *p;
    size_t l;
    int more;
    while (!in->ended && (more = oword_next_line(in, &p, &l)) != 0) {
        if (more < 0)
            return in->err.status;
        if (in->cancel && *in->cancel)
            return interp_fail(in, INTERP_ERR_CANCELLED, 0, "stopped by the operator while "
                               "reading the program");
        in->depth = 0;
        int kind;
        CHP(interp_read_line(in, p, l, &kind));
        if (kind == 2)
            CHP(percent_line(in, first));
        else if (kind == 1)
            CHP(interp_execute(in));
        else if (kind == 3)
            CHP(oword_execute(in));
        if (kind == 2 || in->norm[0] || in->blk.has_comment)
            first = 0;
    }
    CHP(oword_end(in));
    /* A program opened by % and not closed is a truncated file, as rs274 says ("File ended
     * with no percent sign"): refused, so that no motion starts on it. */
    if (!in->ended && in->pct_open)
        return interp_fail(in, INTERP_ERR_SYNTAX, 0, "the program opened with '%%' on line %d "
                           "ends without its closing '%%' line (a truncated file?)",
                           in->pct_line);
    if (!in->ended && !in->mdi)
        return interp_fail(in, INTERP_ERR_SYNTAX, 0, "the program ends without M2, M30 or a "
                           "closing %% line");
    return 0;
}

void interp_set_input_fn(struct interp *in, interp_input_fn fn, void *ctx)
{
    in->input_fn = fn;
    in->input_ctx = ctx;
}

void interp_set_contour_fn(struct interp *in, interp_contour_fn fn, void *ctx)
{
    in->contour_fn = fn;
    in->contour_ctx = ctx;
}

void interp_set_param(struct interp *in, int n, double v)
{
    if (n >= 1 && n < INTERP_NPARAMS)
        in->params[n] = v;
}

void interp_set_mdi(struct interp *in, int on)
{
    in->mdi = on != 0;
}

int interp_run_text(struct interp *in, const char *file_name, const char *text, size_t len,
                    canon_sink_fn sink, void *ctx)
{
    memset(&in->err, 0, sizeof in->err);
    snprintf(in->file, sizeof in->file, "%s", file_name);
    in->line = 0;
    in->ended = 0;
    in->pct_open = 0;
    in->sink = sink;
    in->sink_ctx = ctx;
    comp5_free(&in->comp);
    comp5_init(&in->comp);
    ccomp_reset(&in->cc);
    interp_named_clear_locals(in); /* #<name> belongs to one program, #<_name> stays */
    interp_settings_begin(in);     /* settings are reported, never saved, from here */
    return run_lines(in, text, len);
}

/* Maps the file (read-only; the reader gives back the pages it has passed, oword.c) and
 * runs it as text; a file that cannot be mapped (a pipe) is read into memory. */
int interp_run_file(struct interp *in, const char *path, canon_sink_fn sink, void *ctx)
{
    memset(&in->err, 0, sizeof in->err);
    snprintf(in->file, sizeof in->file, "%s", path);
    in->line = 0;
    free(in->ow.dir);  /* o<name> call looks for name.ngc beside the program first */
    const char *slash = strrchr(path, '/');
    in->ow.dir = slash ? strndup(path, (size_t)(slash - path == 0 ? 1 : slash - path))
                       : strdup(".");
    if (!in->ow.dir)
        return interp_fail(in, INTERP_ERR_NOMEM, 0, "out of memory");
    FILE *f = fopen(path, "rb");
    if (!f)
        return interp_fail(in, INTERP_ERR_IO, 0, "cannot open the program: %s", strerror(errno));
    struct stat st;
    if (fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0) {
        size_t len = (size_t)st.st_size;
        void *map = mmap(NULL, len, PROT_READ, MAP_PRIVATE, fileno(f), 0);
        fclose(f);
        if (map == MAP_FAILED)
            return interp_fail(in, INTERP_ERR_IO, 0, "cannot read the program: %s",
                               strerror(errno));
        /* not locked in memory (a real-time process locks what it maps): the reader gives
         * back the pages it has passed (oword.c), which locked pages would refuse */
        munlock(map, len);
        madvise(map, len, MADV_SEQUENTIAL);
        in->text_mapped = 1;
        int rc = interp_run_text(in, path, map, len, sink, ctx);
        in->text_mapped = 0;
        munmap(map, len);
        return rc;
    }
    size_t cap = 1 << 16, len = 0;
    char *buf = malloc(cap);
    int rc = 0;
    while (buf) {
        size_t n = fread(buf + len, 1, cap - len, f);
        len += n;
        if (len < cap)
            break;
        char *nb = realloc(buf, cap * 2);
        if (!nb) {
            free(buf);
            buf = NULL;
            break;
        }
        buf = nb;
        cap *= 2;
    }
    if (!buf)
        rc = interp_fail(in, INTERP_ERR_NOMEM, 0, "out of memory reading the program");
    else if (ferror(f))
        rc = interp_fail(in, INTERP_ERR_IO, 0, "cannot read the program: %s", strerror(errno));
    fclose(f);
    if (!rc)
        rc = interp_run_text(in, path, buf, len, sink, ctx);
    free(buf);
    return rc;
}
