/* hexapod_geom.c: hexapod geometry, leg limits, solver and tool settings from configuration. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "kins/hexapod.h"
#include "kins/kins_cfg.h"

#define HEXAPOD_DEG_TO_RAD (M_PI / 180.0)

/* Reads the twelve explicit joint keys BASE_n / PLATFORM_n = x y z (mm). */
static int hexapod_read_explicit(struct hexapod *h, const struct kins_config *cfg, char *err,
                                 size_t errlen)
{
    char key[32];
    for (int i = 0; i < HEXAPOD_LEGS; i++) {
        snprintf(key, sizeof key, "BASE_%d", i);
        int st = kins_cfg_numbers(cfg, "KINS", key, h->b_mm[i], 3, NULL, err, errlen);
        if (st != KINS_OK)
            return st;
        snprintf(key, sizeof key, "PLATFORM_%d", i);
        st = kins_cfg_numbers(cfg, "KINS", key, h->p_mm[i], 3, NULL, err, errlen);
        if (st != KINS_OK)
            return st;
    }
    return KINS_OK;
}

/* Reads a required positive length (mm) or an angle range check, naming the key on error. */
static int hexapod_read_ranged(const struct kins_config *cfg, const char *key, double lo,
                               double hi, int required, double *out, char *err, size_t errlen)
{
    int found;
    int st = kins_cfg_numbers(cfg, "KINS", key, out, 1, required ? NULL : &found, err, errlen);
    if (st != KINS_OK)
        return st;
    if (*out < lo || *out > hi)
        return kins_cfg_error(err, errlen, "KINS", key, "%g is outside %g..%g", *out, lo, hi);
    return KINS_OK;
}

/* Expands the parametric description into joint coordinates. Base joint pairs are centred
 * at 0, 120 and 240 deg, platform pairs at 60, 180 and 300 deg; leg 2k runs from base angle
 * 120k + hb to platform angle 120k + 60 - hp, leg 2k+1 from 120k + 120 - hb to 120k + 60 + hp,
 * so legs are numbered counter-clockwise seen from above and every leg is equally long at
 * the centred, level pose. */
static int hexapod_read_parametric(struct hexapod *h, const struct kins_config *cfg,
                                   char *err, size_t errlen)
{
    double rb, rp, hb_deg, hp_deg, zb = 0.0, zp = 0.0;
    int st;
    if ((st = hexapod_read_ranged(cfg, "BASE_RADIUS", 1e-3, 1e6, 1, &rb, err, errlen)) ||
        (st = hexapod_read_ranged(cfg, "PLATFORM_RADIUS", 0.0, 1e6, 1, &rp, err, errlen)) ||
        (st = hexapod_read_ranged(cfg, "BASE_HALF_ANGLE", 0.0, 59.0, 1, &hb_deg, err, errlen)) ||
        (st = hexapod_read_ranged(cfg, "PLATFORM_HALF_ANGLE", 0.0, 59.0, 1, &hp_deg, err,
                                  errlen)) ||
        (st = kins_cfg_number_or(cfg, "KINS", "BASE_Z", &zb, err, errlen)) ||
        (st = kins_cfg_number_or(cfg, "KINS", "PLATFORM_Z", &zp, err, errlen)))
        return st;
    for (int k = 0; k < 3; k++) {
        double centre_deg = 120.0 * k;
        double b_deg[2] = { centre_deg + hb_deg, centre_deg + 120.0 - hb_deg };
        double p_deg[2] = { centre_deg + 60.0 - hp_deg, centre_deg + 60.0 + hp_deg };
        for (int j = 0; j < 2; j++) {
            int leg = 2 * k + j;
            h->b_mm[leg][0] = rb * cos(b_deg[j] * HEXAPOD_DEG_TO_RAD);
            h->b_mm[leg][1] = rb * sin(b_deg[j] * HEXAPOD_DEG_TO_RAD);
            h->b_mm[leg][2] = zb;
            h->p_mm[leg][0] = rp * cos(p_deg[j] * HEXAPOD_DEG_TO_RAD);
            h->p_mm[leg][1] = rp * sin(p_deg[j] * HEXAPOD_DEG_TO_RAD);
            h->p_mm[leg][2] = zp;
        }
    }
    return KINS_OK;
}

/* Reads [JOINT_n] MIN_LIMIT / MAX_LIMIT, the leg length limits in mm. */
static int hexapod_read_limits(struct hexapod *h, const struct kins_config *cfg, char *err,
                               size_t errlen)
{
    char sec[24];
    for (int i = 0; i < HEXAPOD_LEGS; i++) {
        snprintf(sec, sizeof sec, "JOINT_%d", i);
        int st = kins_cfg_numbers(cfg, sec, "MIN_LIMIT", &h->base.joint_min[i], 1, NULL, err,
                                  errlen);
        if (st == KINS_OK)
            st = kins_cfg_numbers(cfg, sec, "MAX_LIMIT", &h->base.joint_max[i], 1, NULL, err,
                                  errlen);
        if (st != KINS_OK)
            return st;
        if (h->base.joint_min[i] < 0.0)
            return kins_cfg_error(err, errlen, sec, "MIN_LIMIT", "%g: a leg length cannot be "
                                  "negative", h->base.joint_min[i]);
        if (h->base.joint_max[i] <= h->base.joint_min[i])
            return kins_cfg_error(err, errlen, sec, "MAX_LIMIT", "%g is not above MIN_LIMIT %g",
                                  h->base.joint_max[i], h->base.joint_min[i]);
    }
    return KINS_OK;
}

/* Reads [KINS] LEG_OFFSET = six numbers (mm, default 0): what each leg's joint-centre
 * distance exceeds the length its drive reports, as `hexcnc calibrate fit` identifies it. */
static int hexapod_read_offsets(struct hexapod *h, const struct kins_config *cfg, char *err,
                                size_t errlen)
{
    int found;
    memset(h->offset_mm, 0, sizeof h->offset_mm);
    int st = kins_cfg_numbers(cfg, "KINS", "LEG_OFFSET", h->offset_mm, HEXAPOD_LEGS, &found,
                              err, errlen);
    if (st != KINS_OK)
        return st;
    for (int i = 0; i < HEXAPOD_LEGS; i++)
        if (fabs(h->offset_mm[i]) > 1e3)
            return kins_cfg_error(err, errlen, "KINS", "LEG_OFFSET", "leg %d: %g mm is beyond "
                                  "+-1000 mm", i + 1, h->offset_mm[i]);
    return KINS_OK;
}

/* The default home: level and centred, at the height where the legs average mid-range. */
static int hexapod_default_home(struct hexapod *h, char *err, size_t errlen)
{
    double z_sum = 0.0;
    for (int i = 0; i < HEXAPOD_LEGS; i++) {
        double mid = 0.5 * (h->base.joint_min[i] + h->base.joint_max[i]) + h->offset_mm[i];
        double dx = h->p_mm[i][0] - h->b_mm[i][0], dy = h->p_mm[i][1] - h->b_mm[i][1];
        double d2 = dx * dx + dy * dy;
        if (mid * mid <= d2)
            return kins_cfg_error(err, errlen, "KINS", "HOME", "missing, and leg %d cannot "
                                  "reach mid-range at a level, centred pose: give HOME", i);
        z_sum += sqrt(mid * mid - d2) - (h->p_mm[i][2] - h->b_mm[i][2]);
    }
    memset(h->base.home, 0, sizeof h->base.home);
    h->base.home[KINS_Z] = z_sum / HEXAPOD_LEGS;
    return KINS_OK;
}

/* Mean distance of the platform joints (else the base joints) from their centroid: the
 * lever arm that makes a radian of rotation comparable with a millimetre of travel. */
static double hexapod_default_char_len(const struct hexapod *h)
{
    const double (*sets[2])[3] = { h->p_mm, h->b_mm };
    for (int s = 0; s < 2; s++) {
        double c[3] = { 0, 0, 0 }, sum = 0.0;
        for (int i = 0; i < HEXAPOD_LEGS; i++)
            for (int j = 0; j < 3; j++)
                c[j] += sets[s][i][j] / HEXAPOD_LEGS;
        for (int i = 0; i < HEXAPOD_LEGS; i++)
            sum += hypot(hypot(sets[s][i][0] - c[0], sets[s][i][1] - c[1]),
                         sets[s][i][2] - c[2]) / HEXAPOD_LEGS;
        if (sum > 1e-6)
            return sum;
    }
    return 1.0;
}

/* Reads solver settings: tolerance, iteration limit, singularity threshold, lever arm. */
static int hexapod_read_solver(struct hexapod *h, const struct kins_config *cfg, char *err,
                               size_t errlen)
{
    double iters = 20.0;
    int st;
    h->fwd_tol_mm = 1e-9;
    h->singular_condition = 100.0;
    h->char_len_mm = hexapod_default_char_len(h);
    if ((st = hexapod_read_ranged(cfg, "FWD_TOLERANCE", 1e-15, 1.0, 0, &h->fwd_tol_mm, err,
                                  errlen)) ||
        (st = hexapod_read_ranged(cfg, "FWD_MAX_ITERATIONS", 1.0, 1000.0, 0, &iters, err,
                                  errlen)) ||
        (st = hexapod_read_ranged(cfg, "SINGULAR_CONDITION", 1.0, 1e15, 0,
                                  &h->singular_condition, err, errlen)) ||
        (st = hexapod_read_ranged(cfg, "CHARACTERISTIC_LENGTH", 1e-3, 1e6, 0, &h->char_len_mm,
                                  err, errlen)))
        return st;
    if (iters != floor(iters))
        return kins_cfg_error(err, errlen, "KINS", "FWD_MAX_ITERATIONS", "%g is not a whole "
                              "number", iters);
    h->fwd_max_iter = (int)iters;
    h->inv_char_len = 1.0 / h->char_len_mm;
    return KINS_OK;
}

/* Reads what the platform carries and where the tool tip is (gauge point + tool length). */
static int hexapod_read_tool(struct hexapod *h, const struct kins_config *cfg, char *err,
                             size_t errlen)
{
    const char *carries = cfg->get(cfg->ctx, "KINS", "PLATFORM_CARRIES");
    h->carries = HEXAPOD_CARRIES_WORKPIECE;
    if (carries && !strcasecmp(carries, "SPINDLE"))
        h->carries = HEXAPOD_CARRIES_SPINDLE;
    else if (carries && strcasecmp(carries, "WORKPIECE"))
        return kins_cfg_error(err, errlen, "KINS", "PLATFORM_CARRIES", "'%s': expected "
                              "WORKPIECE or SPINDLE", carries);
    /* Default gauge point: the platform origin at home, seen from the frame the tool is on. */
    double gauge[3] = { 0.0, 0.0, 0.0 }, axis[3] = { 0.0, 0.0, -1.0 }, len_mm = 0.0;
    if (h->carries == HEXAPOD_CARRIES_WORKPIECE)
        memcpy(gauge, h->base.home, sizeof gauge);
    int found, st;
    if ((st = kins_cfg_numbers(cfg, "KINS", "TOOL_POINT", gauge, 3, &found, err, errlen)) ||
        (st = kins_cfg_numbers(cfg, "KINS", "TOOL_AXIS", axis, 3, &found, err, errlen)) ||
        (st = kins_cfg_number_or(cfg, "KINS", "TOOL_LENGTH", &len_mm, err, errlen)))
        return st;
    double n = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    if (n < 1e-9)
        return kins_cfg_error(err, errlen, "KINS", "TOOL_AXIS", "the direction is zero");
    const char *pp = cfg->get(cfg->ctx, "KINS", "PROGRAM_POINT");
    h->program_tip = pp && !strcasecmp(pp, "TOOL_TIP");
    if (pp && !h->program_tip && strcasecmp(pp, "PLATFORM"))
        return kins_cfg_error(err, errlen, "KINS", "PROGRAM_POINT", "'%s': expected PLATFORM "
                              "or TOOL_TIP", pp);
    h->tool_len_mm = len_mm;
    for (int j = 0; j < 3; j++) {
        h->tool_gauge_mm[j] = gauge[j];
        h->tool_axis[j] = axis[j] / n;
        h->tool_tip_mm[j] = gauge[j] + len_mm * h->tool_axis[j];
    }
    return KINS_OK;
}

/* Reads everything a hexapod needs; see docs/kinematics.md for the keys. */
int hexapod_configure(struct hexapod *h, const struct kins_config *cfg, char *err,
                      size_t errlen)
{
    int explicit_found;
    double probe[3];
    int st = kins_cfg_numbers(cfg, "KINS", "BASE_0", probe, 3, &explicit_found, err, errlen);
    if (st != KINS_OK)
        return st;
    st = explicit_found ? hexapod_read_explicit(h, cfg, err, errlen)
                        : hexapod_read_parametric(h, cfg, err, errlen);
    if (st == KINS_OK)
        st = hexapod_read_limits(h, cfg, err, errlen);
    if (st == KINS_OK)
        st = hexapod_read_offsets(h, cfg, err, errlen);
    if (st != KINS_OK)
        return st;
    int home_found;
    st = kins_cfg_numbers(cfg, "KINS", "HOME", h->base.home, KINS_POSE_DIM, &home_found, err,
                          errlen);
    if (st == KINS_OK && !home_found)
        st = hexapod_default_home(h, err, errlen);
    if (st == KINS_OK)
        st = hexapod_read_solver(h, cfg, err, errlen);
    if (st == KINS_OK)
        st = hexapod_read_tool(h, cfg, err, errlen);
    if (st == KINS_OK)
        st = hexapod_read_workspace(h, cfg, err, errlen);
    if (st != KINS_OK)
        return st;
    for (int i = 0; i < HEXAPOD_LEGS; i++)
        for (int j = 0; j < HEXAPOD_LEGS; j++) {
            h->pdist_mm[i][j] = hypot(hypot(h->p_mm[i][0] - h->p_mm[j][0],
                                            h->p_mm[i][1] - h->p_mm[j][1]),
                                      h->p_mm[i][2] - h->p_mm[j][2]);
            h->bdist_mm[i][j] = hypot(hypot(h->b_mm[i][0] - h->b_mm[j][0],
                                            h->b_mm[i][1] - h->b_mm[j][1]),
                                      h->b_mm[i][2] - h->b_mm[j][2]);
        }
    return KINS_OK;
}
