/* hexapod_workspace.c: the hexapod's workspace beyond its legs' lengths: the pose's soft
 * limits ([AXIS_X..C] MIN_LIMIT/MAX_LIMIT), the passive joints' angles, the clearance between
 * legs, and the assembly (platform above its base, facing up). The checks run in every
 * inverse solve; all but the assembly only when configured. */
#include <math.h>
#include <stdio.h>

#include "kins/hexapod.h"
#include "kins/hexapod_math.h"
#include "kins/kins_cfg.h"

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

int hexapod_read_workspace(struct hexapod *h, const struct kins_config *cfg, char *err,
                           size_t errlen)
{
    static const char *const keys[] = { "BASE_JOINT_MAX_ANGLE", "PLATFORM_JOINT_MAX_ANGLE",
                                        "LEG_DIAMETER", "LEG_CLEARANCE" };
    double *out[] = { &h->base_max_deg, &h->plat_max_deg, &h->leg_diameter_mm,
                      &h->leg_clearance_mm };
    static const double hi[] = { 89.9, 89.9, 1000, 1000 };
    for (int i = 0; i < 4; i++) {
        int found;
        *out[i] = 0;
        int st = kins_cfg_numbers(cfg, "KINS", keys[i], out[i], 1, &found, err, errlen);
        if (st != KINS_OK)
            return st;
        if (found && !(*out[i] > 0 && *out[i] <= hi[i]) && !(i == 3 && *out[i] == 0))
            return kins_cfg_error(err, errlen, "KINS", keys[i], "%g is outside %s..%g", *out[i],
                                  i == 3 ? "0" : "(0", hi[i]);
    }
    /* the joints' mounting axes: one for all (BASE_JOINT_AXIS), or per joint (_n) */
    static const char *const akeys[2] = { "BASE_JOINT_AXIS", "PLATFORM_JOINT_AXIS" };
    for (int b = 0; b < 2; b++) {
        double (*ax)[3] = b ? h->plat_jaxis : h->base_jaxis, all[3] = { 0, 0, 1 };
        int found_all, found;
        int st = kins_cfg_numbers(cfg, "KINS", akeys[b], all, 3, &found_all, err, errlen);
        if (st != KINS_OK)
            return st;
        int any = found_all;
        for (int i = 0; i < HEXAPOD_LEGS; i++) {
            char key[40];
            snprintf(key, sizeof key, "%s_%d", akeys[b], i);
            double *a = ax[i];
            a[0] = all[0], a[1] = all[1], a[2] = all[2];
            if ((st = kins_cfg_numbers(cfg, "KINS", key, a, 3, &found, err, errlen)) != KINS_OK)
                return st;
            any |= found;
            double n = sqrt(dot3(a, a));
            if (!(n > 1e-9))
                return kins_cfg_error(err, errlen, "KINS", found ? key : akeys[b],
                                      "the direction is zero");
            if (a[2] <= 0)
                return kins_cfg_error(err, errlen, "KINS", found ? key : akeys[b], "%g %g %g "
                                      "points down: give a joint's axis pointing up, the way "
                                      "a leg runs from its base joint to its platform joint "
                                      "(%s frame)", a[0], a[1], a[2], b ? "platform" : "base");
            for (int j = 0; j < 3; j++)
                a[j] /= n;
        }
        if (any && !(b ? h->plat_max_deg : h->base_max_deg))
            return kins_cfg_error(err, errlen, "KINS", akeys[b], "needs %s_JOINT_MAX_ANGLE "
                                  "(the angle the joint turns from this axis)", b ? "PLATFORM"
                                  : "BASE");
    }
    if (h->leg_clearance_mm > 0 && h->leg_diameter_mm == 0)
        return kins_cfg_error(err, errlen, "KINS", "LEG_CLEARANCE", "needs LEG_DIAMETER (the "
                              "legs' outer diameter) to mean anything");
    h->axis_limited = false;
    static const char *const axes[] = { "AXIS_X", "AXIS_Y", "AXIS_Z", "AXIS_A", "AXIS_B",
                                        "AXIS_C" };
    for (int j = 0; j < KINS_POSE_DIM; j++) {
        int fmin_found, fmax_found, st;
        h->axis_min[j] = -INFINITY;
        h->axis_max[j] = INFINITY;
        if ((st = kins_cfg_numbers(cfg, axes[j], "MIN_LIMIT", &h->axis_min[j], 1, &fmin_found,
                                   err, errlen)) ||
            (st = kins_cfg_numbers(cfg, axes[j], "MAX_LIMIT", &h->axis_max[j], 1, &fmax_found,
                                   err, errlen)))
            return st;
        h->axis_limited |= fmin_found || fmax_found;
        if (!(h->axis_min[j] < h->axis_max[j]))
            return kins_cfg_error(err, errlen, axes[j], "MAX_LIMIT", "%g is not above "
                                  "MIN_LIMIT %g", h->axis_max[j], h->axis_min[j]);
    }
    h->ws_extra = h->axis_limited || h->base_max_deg > 0 || h->plat_max_deg > 0 ||
                  h->leg_diameter_mm > 0;
    h->base_cos_max = h->base_max_deg > 0 ? cos(h->base_max_deg * HEXAPOD_RAD_PER_DEG) : -2;
    h->plat_cos_max = h->plat_max_deg > 0 ? cos(h->plat_max_deg * HEXAPOD_RAD_PER_DEG) : -2;
    return KINS_OK;
}


static double clamp01(double x)
{
    return x < 0 ? 0 : x > 1 ? 1 : x;
}

/* Shortest distance between segments p0 + s·d1 and q0 + t·d2, s, t in [0, 1]. */
static double segment_distance(const double p0[3], const double d1[3], const double q0[3],
                               const double d2[3])
{
    double r[3] = { p0[0] - q0[0], p0[1] - q0[1], p0[2] - q0[2] };
    double a = dot3(d1, d1), e = dot3(d2, d2), f = dot3(d2, r), c = dot3(d1, r);
    double b = dot3(d1, d2), den = a * e - b * b, s, t;
    s = den > 1e-12 * a * e ? clamp01((b * f - c * e) / den) : 0;
    t = (b * s + f) / e;
    if (t < 0) {
        t = 0;
        s = clamp01(-c / a);
    } else if (t > 1) {
        t = 1;
        s = clamp01((b - c) / a);
    }
    double w[3];
    for (int j = 0; j < 3; j++)
        w[j] = r[j] + s * d1[j] - t * d2[j];
    return sqrt(dot3(w, w));
}

#define FAIL(...) do { if (msg) snprintf(msg, len, __VA_ARGS__); return KINS_ERR_WORKSPACE; } \
                  while (0)

int hexapod_workspace(const struct hexapod *h, const double pose[KINS_POSE_DIM],
                      const struct hexapod_rot *o, const struct hexapod_legs *lg, char *msg,
                      size_t len)
{
    static const char names[] = "XYZABC";
    for (int j = 0; j < KINS_POSE_DIM && h->axis_limited; j++) {
        if (pose[j] < h->axis_min[j])
            FAIL("%c%.3f is %.3f %s below [AXIS_%c] MIN_LIMIT = %g", names[j], pose[j],
                 h->axis_min[j] - pose[j], j < 3 ? "mm" : "deg", names[j], h->axis_min[j]);
        if (pose[j] > h->axis_max[j])
            FAIL("%c%.3f is %.3f %s above [AXIS_%c] MAX_LIMIT = %g", names[j], pose[j],
                 pose[j] - h->axis_max[j], j < 3 ? "mm" : "deg", names[j], h->axis_max[j]);
    }
    /* the platform faces up (its normal R·z has a positive Z) and every platform joint is
     * above its base joint: the other assembly, mirrored through the base, has the same
     * leg lengths and no machine can get there */
    if (o->r[2][2] <= 0)
        FAIL("the platform would face down (tilted %.1f deg from level): that is the mirror "
             "assembly, which the machine cannot reach", acos(fmax(-1, o->r[2][2])) *
             HEXAPOD_DEG_PER_RAD);
    for (int i = 0; i < HEXAPOD_LEGS; i++)
        if (lg->u[i][2] <= 0)
            FAIL("leg %d's platform joint would be %.3f mm below its base joint: that is the "
                 "mirror assembly, with the platform on the wrong side of the base, which the "
                 "machine cannot reach", i + 1, -lg->u[i][2] * lg->len_mm[i]);
    /* the joints' mounting axes (by default the base normal +Z, and the platform normal
     * turned with the platform): cos(angle) = u·a */
    for (int i = 0; i < HEXAPOD_LEGS && (h->base_max_deg > 0 || h->plat_max_deg > 0); i++) {
        const double *pa = h->plat_jaxis[i];
        double pz[3];
        for (int j = 0; j < 3; j++)
            pz[j] = o->r[j][0] * pa[0] + o->r[j][1] * pa[1] + o->r[j][2] * pa[2];
        double cb = dot3(lg->u[i], h->base_jaxis[i]), cp = dot3(lg->u[i], pz);
        if (cb < h->base_cos_max) {
            double a = acos(fmax(-1, fmin(1, cb))) * HEXAPOD_DEG_PER_RAD;
            FAIL("leg %d's base joint would turn %.2f deg from its axis, %.2f deg beyond [KINS] "
                 "BASE_JOINT_MAX_ANGLE = %g deg", i + 1, a, a - h->base_max_deg,
                 h->base_max_deg);
        }
        if (cp < h->plat_cos_max) {
            double a = acos(fmax(-1, fmin(1, cp))) * HEXAPOD_DEG_PER_RAD;
            FAIL("leg %d's platform joint would turn %.2f deg from its axis, %.2f deg beyond "
                 "[KINS] PLATFORM_JOINT_MAX_ANGLE = %g deg", i + 1, a, a - h->plat_max_deg,
                 h->plat_max_deg);
        }
    }
    if (h->leg_diameter_mm > 0) {
        double need = h->leg_diameter_mm + h->leg_clearance_mm, v[HEXAPOD_LEGS][3];
        for (int i = 0; i < HEXAPOD_LEGS; i++)
            for (int j = 0; j < 3; j++)
                v[i][j] = lg->u[i][j] * lg->len_mm[i];
        for (int i = 0; i < HEXAPOD_LEGS; i++)
            for (int j = i + 1; j < HEXAPOD_LEGS; j++) {
                double d = segment_distance(h->b_mm[i], v[i], h->b_mm[j], v[j]);
                if (d < need)
                    FAIL("legs %d and %d would pass %.2f mm apart (axis to axis), %.2f mm "
                         "closer than [KINS] LEG_DIAMETER %g mm + LEG_CLEARANCE %g mm", i + 1,
                         j + 1, d, need - d, h->leg_diameter_mm, h->leg_clearance_mm);
            }
    }
    if (msg && len)
        msg[0] = '\0';
    return KINS_OK;
}
