/* check_machine.c: the machine of an INI file (kinematics, motion, interpreter settings) without HAL threads. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check/check_priv.h"
#include "common/errbuf.h"
#include "common/config.h"
#include "common/inifile.h"
#include "hal/hal.h"
#include "interp/interp.h"
#include "interp/tooltable.h"

static const char *const status_text[CHECK_STATUS_COUNT] = {
    [CHECK_OK] = "ok",
    [CHECK_ERR_NOMEM] = "out of memory",
    [CHECK_ERR_CONFIG] = "the machine configuration is wrong",
    [CHECK_ERR_KINS] = "the kinematics could not be loaded",
    [CHECK_ERR_IO] = "a file could not be written",
    [CHECK_ERR_VIOLATION] = "the program has problems",
};

/* Text of a check status. */
const char *check_strerror(int status)
{
    if (status < 0 || status >= CHECK_STATUS_COUNT)
        return "unknown check status";
    return status_text[status];
}


/* [KINS] TOOL_AXIS as a unit vector (default 0 0 -1, as the kinematics reads it). */
static int read_tool_axis(struct check_machine *mc, const char *ini, char *err, size_t errlen)
{
    const char *v = hal_ini_get(mc->hal, "KINS", "TOOL_AXIS");
    double a[3] = { 0, 0, -1 };
    if (v && config_parse_numbers(v, a, 3, NULL, 0) != 0)
        return errbuf_set(err, errlen, CHECK_ERR_CONFIG, "%s: [KINS] TOOL_AXIS = %s: expected three "
                    "numbers x y z", ini, v);
    double n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    if (!(n > 0))
        return errbuf_set(err, errlen, CHECK_ERR_CONFIG, "%s: [KINS] TOOL_AXIS has no direction", ini);
    for (int i = 0; i < 3; i++)
        mc->tool_axis[i] = a[i] / n;
    return CHECK_OK;
}

/* Reads the interpreter's settings (interp_settings_read, as the runner does) and applies
 * them once to a scratch interpreter, so that a missing tool table or a bad parameter file
 * is a configuration error now; then the drives' [JOINT_n] figures. */
static int read_interp_settings(struct check_machine *mc, const char *ini, char *err,
                                size_t errlen)
{
    char msg[1024], where[1536];
    int st = interp_settings_read(&mc->interp, hal_ini_lookup, mc->hal, hal_ini_dir(mc->hal), msg,
                                  sizeof msg);
    if (st != INTERP_OK)
        return errbuf_set(err, errlen, CHECK_ERR_CONFIG, "%s",
                    inifile_locate_msg(hal_ini_file(mc->hal), msg, where, sizeof where));
    struct interp *probe = interp_create();
    if (!probe)
        return errbuf_set(err, errlen, CHECK_ERR_NOMEM, "out of memory");
    st = interp_settings_apply(probe, &mc->interp, mc->tt, INTERP_SETUP_PARAMS_READ_ONLY, msg,
                               sizeof msg);
    interp_destroy(probe);
    if (st != INTERP_OK)
        return errbuf_set(err, errlen, CHECK_ERR_CONFIG, "%s", msg);
    for (int i = 0; i < KINS_MAX_JOINTS; i++) {
        char sec[24];
        snprintf(sec, sizeof sec, "JOINT_%d", i);
        if (hal_ini_double(mc->hal, sec, "SCALE", 0, &mc->scale[i]) == HAL_ERR_SYNTAX ||
            hal_ini_double(mc->hal, sec, "STEPGEN_MAXVEL", 0, &mc->drive_vel[i]) ==
                HAL_ERR_SYNTAX ||
            hal_ini_double(mc->hal, sec, "STEPGEN_MAXACCEL", 0, &mc->drive_acc[i]) ==
                HAL_ERR_SYNTAX)
            return errbuf_set(err, errlen, CHECK_ERR_CONFIG, "%s", hal_last_error(mc->hal));
    }
    return CHECK_OK;
}

/* Reads the INI and builds kinematics (by name), motion and the interpreter settings. */
int check_machine_open(const char *ini, struct check_machine **out, char *err, size_t errlen)
{
    *out = NULL;
    struct check_machine *mc = calloc(1, sizeof *mc);
    int st = CHECK_ERR_NOMEM;
    if (!mc || !(mc->hal = hal_create()) || !(mc->tt = malloc(sizeof *mc->tt))) {
        errbuf_set(err, errlen, st, "out of memory");
        goto fail;
    }
    tooltable_init(mc->tt);
    snprintf(mc->ini, sizeof mc->ini, "%s", ini);
    if (hal_load_machine_ini(mc->hal, ini) != HAL_OK) {
        st = errbuf_set(err, errlen, CHECK_ERR_CONFIG, "%s", hal_last_error(mc->hal));
        goto fail;
    }
    struct kins_config kc = { hal_ini_lookup, mc->hal };
    const char *name = hal_ini_get(mc->hal, "KINS", "KINEMATICS");
    char msg[768];
    if (!name) {
        st = errbuf_set(err, errlen, CHECK_ERR_CONFIG, "%s: [KINS] KINEMATICS is missing: which "
                  "kinematics does the machine have?", ini);
        goto fail;
    }
    char where[1024];   /* "[SECTION] KEY: ..." messages get the key's INI line */
    if (kins_load(name, &kc, &mc->kins, msg, sizeof msg) != KINS_OK) {
        st = errbuf_set(err, errlen, CHECK_ERR_KINS, "%s",
                  inifile_locate_msg(hal_ini_file(mc->hal), msg, where, sizeof where));
        goto fail;
    }
    motion_config_default(&mc->mcfg);
    if (motion_config_read(&mc->mcfg, &kc, mc->kins->njoints, msg, sizeof msg) != MOTION_OK ||
        motion_create(&mc->mcfg, mc->kins, &mc->motion, msg, sizeof msg) != MOTION_OK) {
        st = errbuf_set(err, errlen, CHECK_ERR_CONFIG, "%s",
                  inifile_locate_msg(hal_ini_file(mc->hal), msg, where, sizeof where));
        goto fail;
    }
    motion_set_spindle_ideal(mc->motion, true);  /* G33, G33.1: no encoder, an ideal one */
    mc->cond_limit = 100;
    if (hal_ini_double(mc->hal, "KINS", "SINGULAR_CONDITION", 100, &mc->cond_limit) ==
        HAL_ERR_SYNTAX) {
        st = errbuf_set(err, errlen, CHECK_ERR_CONFIG, "%s", hal_last_error(mc->hal));
        goto fail;
    }
    if ((st = read_interp_settings(mc, ini, err, errlen)) ||
        (st = read_tool_axis(mc, ini, err, errlen)))
        goto fail;
    *out = mc;
    return CHECK_OK;
fail:
    check_machine_close(mc);
    return st;
}

/* Frees the machine and the interpreters its programs point into. */
void check_machine_close(struct check_machine *mc)
{
    if (!mc)
        return;
    motion_destroy(mc->motion);
    kins_free(mc->kins);
    kins_free(mc->real_kins);
    for (size_t i = 0; i < mc->ninterps; i++)
        interp_destroy(mc->interps[i]);
    free(mc->interps);
    hal_destroy(mc->hal);
    free(mc->tt);
    free(mc);
}

/* Accessors (borrowed pointers). */
struct kins *check_machine_kins(struct check_machine *mc) { return mc->kins; }
struct motion *check_machine_motion(struct check_machine *mc) { return mc->motion; }
void check_machine_set_real(struct check_machine *mc, struct kins *real)
{
    kins_free(mc->real_kins);
    mc->real_kins = real;
}
const struct motion_config *check_machine_motion_config(const struct check_machine *mc)
{
    return &mc->mcfg;
}

/* [JOINT_n] SCALE, steps per mm. */
double check_machine_scale(const struct check_machine *mc, int joint)
{
    return joint >= 0 && joint < KINS_MAX_JOINTS ? mc->scale[joint] : 0;
}

/* Effective radius of a tool from the tool table, mm. */
double check_machine_tool_radius(struct check_machine *mc, int tool)
{
    double r;
    if (!mc->interp.tool_table[0] || tooltable_radius(mc->tt, tool, &r) != TOOLTABLE_OK)
        return -1;
    return r;
}

int check_machine_interp_new(struct check_machine *mc, struct interp **out,
                             struct check_problem *pb)
{
    struct interp *in = interp_create();
    struct interp **list = realloc(mc->interps, (mc->ninterps + 1) * sizeof *list);
    memset(pb, 0, sizeof *pb);
    pb->kind = CHECK_INTERP, pb->leg = -1, pb->time_s = -1, pb->count = 1;
    *out = NULL;
    if (list)
        mc->interps = list;
    if (!in || !list) {
        interp_destroy(in);
        snprintf(pb->message, sizeof pb->message, "out of memory");
        return CHECK_ERR_NOMEM;
    }
    interp_set_start(in, mc->kins->home);
    interp_use_kins(in, mc->kins);       /* G43.4 and [KINS] PROGRAM_POINT */
    interp_set_ini(in, hal_ini_lookup, mc->hal);   /* #<_ini[..]..> */
    mc->interps[mc->ninterps++] = in;   /* commands point at in's file name */
    /* the runner's settings, but the machine's parameter file is never written */
    if (interp_settings_apply(in, &mc->interp, mc->tt, INTERP_SETUP_PARAMS_READ_ONLY,
                              pb->message, sizeof pb->message) != INTERP_OK)
        return CHECK_ERR_CONFIG;
    *out = in;
    return CHECK_OK;
}

/* Interprets a file (text NULL) or text held in memory into prog. */
static int interpret(struct check_machine *mc, const char *path, const char *text, size_t len,
                     struct canon_prog *prog, struct check_problem *pb)
{
    struct interp *in;
    int st = check_machine_interp_new(mc, &in, pb);
    if (st)
        return st;
    memcpy(prog->start, mc->kins->home, sizeof prog->start);
    int ist = text ? interp_run_text(in, path, text, len, canon_prog_sink, prog)
                   : interp_run_file(in, path, canon_prog_sink, prog);
    if (ist != INTERP_OK) {
        const struct interp_error *e = interp_last_error(in);
        snprintf(pb->file, sizeof pb->file, "%s", e->file[0] ? e->file : path);
        pb->line = e->line, pb->column = e->column;
        interp_error_format(e, pb->message, sizeof pb->message);
        st = CHECK_ERR_VIOLATION;
    }
    return st;
}

/* Interprets a program file. */
int check_machine_interpret(struct check_machine *mc, const char *path, struct canon_prog *prog,
                            struct check_problem *pb)
{
    return interpret(mc, path, NULL, 0, prog, pb);
}

/* Interprets G-code held in memory. */
int check_machine_interpret_text(struct check_machine *mc, const char *name, const char *text,
                                 size_t len, struct canon_prog *prog, struct check_problem *pb)
{
    return interpret(mc, name, text, len, prog, pb);
}
