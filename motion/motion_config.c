/* motion_config.c: motion configuration defaults, reading it from the INI, status texts. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/config.h"
#include "motion/motion_priv.h"

/* One text per status, in enum order. */
static const struct { int code; const char *text; } motion_errors[] = {
    {MOTION_OK, "ok"},
    {MOTION_ERR_NOMEM, "out of memory"},
    {MOTION_ERR_CONFIG, "bad motion configuration"},
    {MOTION_ERR_ARG, "bad argument"},
    {MOTION_ERR_STATE, "not allowed in the current motion state"},
    {MOTION_ERR_PROGRAM, "the program holds a move that cannot be planned"},
    {MOTION_ERR_UNREACHABLE, "a move leaves the machine's reach"},
    {MOTION_ERR_KINS, "the kinematics cannot follow a move"},
    {MOTION_ERR_FERROR, "following error too large"},
    {MOTION_ERR_ESTOP, "emergency stop"},
    {MOTION_ERR_CANCELLED, "planning stopped by the operator"},
    {MOTION_ERR_STARVED, "the program's next part was not planned in time"},
    {MOTION_ERR_INDEX, "the spindle encoder's index did not come"},
};

/* Text of a motion status. */
const char *motion_strerror(int status)
{
    for (size_t i = 0; i < sizeof motion_errors / sizeof motion_errors[0]; i++)
        if (motion_errors[i].code == status)
            return motion_errors[i].text;
    return "unknown motion status";
}

/* Name of a motion state, as status displays print it. */
const char *motion_state_name(enum motion_state s)
{
    static const char *const names[MOTION_STATE_COUNT] = {
        "idle", "running", "pausing", "paused", "stopping", "done", "fault", "manual"};
    return (unsigned)s < MOTION_STATE_COUNT ? names[s] : "unknown";
}

/* Defaults for every field (see motion.h). */
void motion_config_default(struct motion_config *c)
{
    memset(c, 0, sizeof *c);
    c->servo_period_s = 0.001;
    c->setpoint_period_s = 0;
    c->max_lin_vel_mm_s = 100;
    c->max_lin_acc_mm_s2 = 1000;
    c->max_ang_vel_deg_s = 30;
    c->max_ang_acc_deg_s2 = 300;
    c->default_lin_vel_mm_s = 10;
    c->kin_tol_mm = 0.001;
    c->kin_tol_deg = 0.001;
    c->blend_tol_mm = 0.01;
    c->optional_stop = 1;
    c->num_dio = c->num_aio = 4;
    c->njoints = 6;
    c->spindle_acc_rpm_s = NAN;     /* no default: synchronised moves need them given */
    c->spindle_speed_margin = NAN;
    for (int i = 0; i < KINS_MAX_JOINTS; i++) {
        c->joint[i].max_vel_mm_s = 100;
        c->joint[i].max_acc_mm_s2 = 1000;
        c->joint[i].ferror_mm = 1;
        c->joint[i].min_ferror_mm = 0.1;
        c->joint[i].home_pos = NAN;
    }
}

static int read_num(const struct kins_config *cfg, const char *sec, const char *key,
                    double scale, int allow_zero, int required, double *out, char *err,
                    size_t errlen);

/* A signed number [sec]key (homing speeds and positions): absent keeps *out, *present says
 * whether it was there. */
static int read_signed(const struct kins_config *cfg, const char *sec, const char *key,
                       double *out, int *present, char *err, size_t errlen)
{
    const char *v = cfg->get(cfg->ctx, sec, key);
    *present = v != NULL;
    if (!v)
        return MOTION_OK;
    char why[64];
    if (config_parse_number(v, out, why, sizeof why) != 0) {
        snprintf(err, errlen, "[%s] %s = %s: %s", sec, key, v, why);
        return MOTION_ERR_CONFIG;
    }
    return MOTION_OK;
}

/* [JOINT_n] HOME_*: a switch (HOME_SEARCH_VEL != 0) needs HOME_LATCH_VEL and HOME_OFFSET,
 * since a wrong guess would put the leg's zero anywhere. */
static int read_homing(const struct kins_config *cfg, const char *sec,
                       struct motion_joint_config *j, char *err, size_t errlen)
{
    int has_search, has_latch, has_offset, has_home, has, st;
    double seq = 0, absolute = 0;
    j->home_final_vel = j->max_vel_mm_s;
    if ((st = read_signed(cfg, sec, "HOME_SEARCH_VEL", &j->home_search_vel, &has_search, err,
                          errlen)) ||
        (st = read_signed(cfg, sec, "HOME_LATCH_VEL", &j->home_latch_vel, &has_latch, err,
                          errlen)) ||
        (st = read_signed(cfg, sec, "HOME_OFFSET", &j->home_offset, &has_offset, err,
                          errlen)) ||
        (st = read_signed(cfg, sec, "HOME", &j->home_pos, &has_home, err, errlen)) ||
        (st = read_signed(cfg, sec, "HOME_SEQUENCE", &seq, &has, err, errlen)) ||
        (st = read_signed(cfg, sec, "HOME_ABSOLUTE_ENCODER", &absolute, &has, err, errlen)) ||
        (st = read_num(cfg, sec, "HOME_FINAL_VEL", 1, 0, 0, &j->home_final_vel, err,
                       errlen)) ||
        (st = read_num(cfg, sec, "HOME_SEARCH_DISTANCE", 1, 0, 0, &j->home_search_mm, err,
                       errlen)))
        return st;
    j->home_sequence = (int)seq;
    j->home_absolute = (int)absolute;
    if (j->home_search_vel != 0 && !j->home_absolute && (!has_latch || !has_offset)) {
        snprintf(err, errlen, "[%s] HOME_SEARCH_VEL = %g needs HOME_LATCH_VEL and HOME_OFFSET "
                 "(the leg length at the switch): %s missing", sec, j->home_search_vel,
                 !has_latch ? "HOME_LATCH_VEL" : "HOME_OFFSET");
        return MOTION_ERR_CONFIG;
    }
    if (j->home_search_vel != 0 && j->home_latch_vel == 0) {
        snprintf(err, errlen, "[%s] HOME_LATCH_VEL: must not be 0 when HOME_SEARCH_VEL is set",
                 sec);
        return MOTION_ERR_CONFIG;
    }
    return MOTION_OK;
}

/* Reads one number [sec]key into *out (times scale). Absent: keeps *out, or fails when the
 * key is a limit that protects the machine (required: no built-in default). */
static int read_num(const struct kins_config *cfg, const char *sec, const char *key,
                    double scale, int allow_zero, int required, double *out, char *err,
                    size_t errlen)
{
    const char *v = cfg->get(cfg->ctx, sec, key);
    if (!v && required) {
        snprintf(err, errlen, "[%s] %s: missing; a limit that protects the machine has no "
                 "default (docs/ini.md)", sec, key);
        return MOTION_ERR_CONFIG;
    }
    if (!v)
        return MOTION_OK;
    double d;
    char why[64];
    if (config_parse_number(v, &d, why, sizeof why) != 0 ||
        config_in_range(d, allow_zero ? ">= 0" : "> 0", why, sizeof why) != 0) {
        snprintf(err, errlen, "[%s] %s = %s: %s", sec, key, v, why);
        return MOTION_ERR_CONFIG;
    }
    *out = d * scale;
    return MOTION_OK;
}

/* Jerk limits: all or none (a limit left out would leave that axis or leg unlimited
 * without a word), not negative, and a moving average no longer than MOTION_JERK_MAX_S. */
static int check_jerk(const struct motion_config *c, char *err, size_t errlen)
{
    int set = (c->max_lin_jerk_mm_s3 != 0) + (c->max_ang_jerk_deg_s3 != 0), all = 2;
    const char *missing = c->max_lin_jerk_mm_s3 == 0 ? "[TRAJ] MAX_LINEAR_JERK"
                          : c->max_ang_jerk_deg_s3 == 0 ? "[TRAJ] MAX_ANGULAR_JERK" : NULL;
    char joint_key[40] = "";
    if (c->max_lin_jerk_mm_s3 < 0 || c->max_ang_jerk_deg_s3 < 0) {
        snprintf(err, errlen, "[TRAJ] MAX_LINEAR_JERK and MAX_ANGULAR_JERK must be positive");
        return MOTION_ERR_CONFIG;
    }
    for (int i = 0; i < c->njoints; i++, all++) {
        if (c->joint[i].max_jerk_mm_s3 < 0) {
            snprintf(err, errlen, "[JOINT_%d] MAX_JERK must be positive", i);
            return MOTION_ERR_CONFIG;
        }
        set += c->joint[i].max_jerk_mm_s3 != 0;
        if (c->joint[i].max_jerk_mm_s3 == 0 && !missing && !joint_key[0])
            snprintf(joint_key, sizeof joint_key, "[JOINT_%d] MAX_JERK", i);
    }
    if (set != 0 && set != all) {
        snprintf(err, errlen, "%s: missing; jerk limits are all set ([TRAJ] MAX_LINEAR_JERK, "
                 "MAX_ANGULAR_JERK and every [JOINT_n] MAX_JERK) or none (docs/motion.md)",
                 missing ? missing : joint_key);
        return MOTION_ERR_CONFIG;
    }
    if (c->jerk_window_s != 0) {
        double full = motion_jerk_full_window_s(c);
        if (set == 0) {
            snprintf(err, errlen, "[TRAJ] JERK_WINDOW = %g s: only with jerk limits ([TRAJ] "
                     "MAX_LINEAR_JERK, MAX_ANGULAR_JERK and every [JOINT_n] MAX_JERK); without "
                     "them motion is trapezoidal, with no moving average", c->jerk_window_s);
            return MOTION_ERR_CONFIG;
        }
        if (!(c->jerk_window_s > 0)) {      /* (the INI's is refused at reading already) */
            snprintf(err, errlen, "[TRAJ] JERK_WINDOW = %g s: must be positive",
                     c->jerk_window_s);
            return MOTION_ERR_CONFIG;
        }
        if (c->jerk_window_s < 2 * c->servo_period_s - 1e-12) {
            snprintf(err, errlen, "[TRAJ] JERK_WINDOW = %g s: shorter than two servo periods "
                     "(%g s)", c->jerk_window_s, 2 * c->servo_period_s);
            return MOTION_ERR_CONFIG;
        }
        if (c->jerk_window_s > full * (1 + 1e-9)) {
            snprintf(err, errlen, "[TRAJ] JERK_WINDOW = %g s: longer than the %.4f s in which "
                     "the jerk limits allow every acceleration in full (2 x acceleration / "
                     "jerk); a longer window only rounds the path more",
                     c->jerk_window_s, full);
            return MOTION_ERR_CONFIG;
        }
    }
    double w = motion_jerk_window_s(c);
    if (w > MOTION_JERK_MAX_S) {
        snprintf(err, errlen, "jerk limits: motion would need a %.3f s moving average to keep "
                 "them (2 x acceleration / jerk), over the %.1f s allowed; raise the jerk "
                 "limits or lower the accelerations", w, MOTION_JERK_MAX_S);
        return MOTION_ERR_CONFIG;
    }
    return MOTION_OK;
}

/* Checks the fields a caller filled directly. */
static int check_config(const struct motion_config *c, char *err, size_t errlen)
{
    if (!(c->servo_period_s > 0) || !(c->max_lin_vel_mm_s > 0) || !(c->max_lin_acc_mm_s2 > 0) ||
        !(c->max_ang_vel_deg_s > 0) || !(c->max_ang_acc_deg_s2 > 0) ||
        !(c->default_lin_vel_mm_s > 0) || c->setpoint_period_s < 0) {
        snprintf(err, errlen, "motion configuration: periods, speeds and accelerations must be "
                 "positive numbers");
        return MOTION_ERR_CONFIG;
    }
    for (int i = 0; i < c->njoints; i++)
        if (!(c->joint[i].max_vel_mm_s > 0) || !(c->joint[i].max_acc_mm_s2 > 0)) {
            snprintf(err, errlen, "[JOINT_%d]: MAX_VELOCITY and MAX_ACCELERATION must be "
                     "positive", i);
            return MOTION_ERR_CONFIG;
        }
    return check_jerk(c, err, errlen);
}

/* The machine-wide keys: section, key, scale to the field's unit, 0 allowed, required (the
 * path limits have no default), field. Types and ranges: common/config_keys.c. */
static const struct motion_key {
    const char *sec, *key;
    double scale;
    int zero_ok, required;
    size_t off;
} motion_keys[] = {
    {"EMCMOT", "SERVO_PERIOD", 1e-9, 0, 0, offsetof(struct motion_config, servo_period_s)},
    {"TRAJ", "SETPOINT_PERIOD", 1e-9, 1, 0, offsetof(struct motion_config, setpoint_period_s)},
    {"TRAJ", "MAX_LINEAR_VELOCITY", 1, 0, 1, offsetof(struct motion_config, max_lin_vel_mm_s)},
    {"TRAJ", "MAX_LINEAR_ACCELERATION", 1, 0, 1,
     offsetof(struct motion_config, max_lin_acc_mm_s2)},
    {"TRAJ", "MAX_ANGULAR_VELOCITY", 1, 0, 1, offsetof(struct motion_config, max_ang_vel_deg_s)},
    {"TRAJ", "MAX_ANGULAR_ACCELERATION", 1, 0, 1,
     offsetof(struct motion_config, max_ang_acc_deg_s2)},
    {"TRAJ", "MAX_LINEAR_JERK", 1, 0, 0, offsetof(struct motion_config, max_lin_jerk_mm_s3)},
    {"TRAJ", "MAX_ANGULAR_JERK", 1, 0, 0, offsetof(struct motion_config, max_ang_jerk_deg_s3)},
    {"TRAJ", "JERK_WINDOW", 1, 0, 0, offsetof(struct motion_config, jerk_window_s)},
    {"TRAJ", "DEFAULT_LINEAR_VELOCITY", 1, 0, 0,
     offsetof(struct motion_config, default_lin_vel_mm_s)},
    {"TRAJ", "KINEMATIC_TOLERANCE", 1, 1, 0, offsetof(struct motion_config, kin_tol_mm)},
    {"TRAJ", "KINEMATIC_ANGULAR_TOLERANCE", 1, 1, 0, offsetof(struct motion_config, kin_tol_deg)},
    {"TRAJ", "BLEND_TOLERANCE", 1, 1, 0, offsetof(struct motion_config, blend_tol_mm)},
    {"SPINDLE_SYNC", "ACCELERATION", 1, 0, 0,
     offsetof(struct motion_config, spindle_acc_rpm_s)},
    {"SPINDLE_SYNC", "SPEED_MARGIN", 1, 0, 0,
     offsetof(struct motion_config, spindle_speed_margin)},
};

/* Reads [EMCMOT], [TRAJ] and [JOINT_n] through cfg (see motion.h). */
int motion_config_read(struct motion_config *c, const struct kins_config *cfg, int njoints,
                       char *err, size_t errlen)
{
    if (!c || !cfg || !cfg->get || njoints < 1 || njoints > KINS_MAX_JOINTS) {
        snprintf(err, errlen, "motion configuration: bad arguments");
        return MOTION_ERR_ARG;
    }
    int st = MOTION_OK;
    c->njoints = njoints;
    for (size_t i = 0; i < sizeof motion_keys / sizeof motion_keys[0] && !st; i++) {
        const struct motion_key *k = &motion_keys[i];
        st = read_num(cfg, k->sec, k->key, k->scale, k->zero_ok, k->required,
                      (double *)(void *)((char *)c + k->off), err, errlen);
    }
    const char *opt_text = cfg->get(cfg->ctx, "TRAJ", "OPTIONAL_STOP");
    int opt = c->optional_stop;
    if (!st && opt_text && config_parse_bool(opt_text, &opt, NULL, 0) != 0) {
        snprintf(err, errlen, "[TRAJ] OPTIONAL_STOP = %s: expected 0 or 1", opt_text);
        st = MOTION_ERR_CONFIG;
    }
    static const struct { const char *key; int max; size_t off; } io_counts[] = {
        { "NUM_DIO", MOTION_MAX_DIO, offsetof(struct motion_config, num_dio) },
        { "NUM_AIO", MOTION_MAX_AIO, offsetof(struct motion_config, num_aio) },
    };
    for (size_t k = 0; k < 2 && !st; k++) {
        const char *t = cfg->get(cfg->ctx, "EMCMOT", io_counts[k].key);
        char *end;
        long v = t ? strtol(t, &end, 10) : 0;
        if (t && (end == t || *end || v < 0 || v > io_counts[k].max)) {
            snprintf(err, errlen, "[EMCMOT] %s = %s: expected a whole number 0..%d",
                     io_counts[k].key, t, io_counts[k].max);
            st = MOTION_ERR_CONFIG;
        } else if (t) {
            *(int *)(void *)((char *)c + io_counts[k].off) = (int)v;
        }
    }
    for (int i = 0; i < njoints && !st; i++) {
        char sec[24];
        snprintf(sec, sizeof sec, "JOINT_%d", i);
        struct motion_joint_config *j = &c->joint[i];
        st = read_num(cfg, sec, "MAX_VELOCITY", 1, 0, 1, &j->max_vel_mm_s, err, errlen);
        st = st ? st : read_num(cfg, sec, "MAX_ACCELERATION", 1, 0, 1, &j->max_acc_mm_s2, err,
                                errlen);
        st = st ? st : read_num(cfg, sec, "MAX_JERK", 1, 0, 0, &j->max_jerk_mm_s3, err,
                                errlen);
        st = st ? st : read_num(cfg, sec, "FERROR", 1, 0, 1, &j->ferror_mm, err, errlen);
        st = st ? st : read_num(cfg, sec, "MIN_FERROR", 1, 0, 0, &j->min_ferror_mm, err,
                                errlen);
        st = st ? st : read_homing(cfg, sec, j, err, errlen);
    }
    c->optional_stop = opt != 0;
    return st ? st : check_config(c, err, errlen);
}

/* The same checks on a caller-filled configuration, for motion_create. */
int motion_config_check(const struct motion_config *c, char *err, size_t errlen)
{
    return check_config(c, err, errlen);
}
