/* hexapod.c: the 6-UPS Stewart platform: create, inverse, leg rates, checks, tool point. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "kins/hexapod.h"
#include "kins/hexapod_math.h"
#include "kins/kins_cfg.h"
#include "kins/kins_svd.h"

/* Splits a pose (mm, deg) into the platform origin and its orientation. */
static int hexapod_pose_frame(const double pose[KINS_POSE_DIM], double t_mm[3],
                              struct hexapod_rot *o)
{
    double z = 0;            /* 0 times a number is 0, times an infinity or a NaN NaN: */
    for (int j = 0; j < KINS_POSE_DIM; j++)   /* one test for the six (every period) */
        z += pose[j] * 0.0;
    if (!(z == 0))
        return KINS_ERR_ARG;
    t_mm[0] = pose[KINS_X];
    t_mm[1] = pose[KINS_Y];
    t_mm[2] = pose[KINS_Z];
    hexapod_rot_from_rad(o, pose[KINS_A] * HEXAPOD_RAD_PER_DEG,
                         pose[KINS_B] * HEXAPOD_RAD_PER_DEG, pose[KINS_C] * HEXAPOD_RAD_PER_DEG);
    return KINS_OK;
}

/* Copies the joint values (joint-centre distance - leg offset) out; KINS_ERR_UNREACHABLE
 * when any is outside its limits (all are written, so callers can say by how much). */
static int hexapod_lengths_of(const struct kins *k, const struct hexapod_legs *lg,
                              double *joints)
{
    const struct hexapod *h = (const struct hexapod *)k;
    int st = KINS_OK;
    for (int i = 0; i < HEXAPOD_LEGS; i++) {
        joints[i] = lg->len_mm[i] - h->offset_mm[i];
        if (joints[i] < k->joint_min[i] || joints[i] > k->joint_max[i])
            st = KINS_ERR_UNREACHABLE;
    }
    return st;
}

/* The platform's frame at pose and the legs through it; KINS_ERR_ARG for a pose that is not
 * a number. */
static inline int hexapod_pose_legs(const struct hexapod *h, const double *pose,
                                    struct hexapod_rot *o, struct hexapod_legs *lg)
{
    double t[3];
    if (hexapod_pose_frame(pose, t, o) != KINS_OK)
        return KINS_ERR_ARG;
    hexapod_legs_eval(h, t, o, lg);
    return KINS_OK;
}

/* Every workspace limit for the inverse, the legs evaluated afresh (out of line: the
 * inverse's own evaluation then need not compute the unit vectors it does not use). Callers
 * that have them (inverse_rates, check) call hexapod_workspace() with their own. */
static __attribute__((noinline)) int hexapod_ws_full(const struct hexapod *h,
                                                     const double *pose)
{
    struct hexapod_rot o;
    struct hexapod_legs lg;
    if (hexapod_pose_legs(h, pose, &o, &lg) != KINS_OK)
        return KINS_ERR_ARG;
    return hexapod_workspace(h, pose, &o, &lg, NULL, 0);
}

/* The common case of the workspace (hexapod_workspace.c), inline: no limit but the assembly
 * configured, and the platform above its base joints, facing up. A platform joint is above
 * its base joint when t_z + (R p)_z - b_z > 0: no division, so the inverse, which needs no
 * unit vectors, does not compute them for this. */
static inline bool hexapod_ws_plain(const struct hexapod *h, const double *pose,
                                    const struct hexapod_rot *o,
                                    const struct hexapod_legs *lg)
{
    bool up = o->r[2][2] > 0;
    for (int i = 0; i < HEXAPOD_LEGS; i++)
        up &= pose[KINS_Z] + lg->rp_mm[i][2] - h->b_mm[i][2] > 0;
    return !h->ws_extra && up;
}

/* The joints of legs already evaluated with their unit vectors, and the workspace's status
 * at that pose (inverse_rates and inverse_path: the full check reuses the legs). */
static inline int joints_checked(struct kins *k, const double *pose, const struct hexapod_rot *o,
                                 const struct hexapod_legs *lg, double *joints)
{
    const struct hexapod *h = (const struct hexapod *)k;
    int st = hexapod_lengths_of(k, lg, joints);
    if (st == KINS_OK && !hexapod_ws_plain(h, pose, o, lg))
        st = hexapod_workspace(h, pose, o, lg, NULL, 0);
    return st;
}

/* Inverse kinematics: joint i = |t + R·p_i - b_i| - offset_i; then the workspace's other
 * limits (hexapod_workspace.c). */
static int hexapod_inverse(struct kins *k, const double pose[KINS_POSE_DIM], double *joints)
{
    const struct hexapod *h = (const struct hexapod *)k;
    struct hexapod_rot o;
    struct hexapod_legs lg;
    if (hexapod_pose_legs(h, pose, &o, &lg) != KINS_OK)
        return KINS_ERR_ARG;
    int st = hexapod_lengths_of(k, &lg, joints);
    if (st != KINS_OK || hexapod_ws_plain(h, pose, &o, &lg))
        return st;
    return hexapod_ws_full(h, pose);
}

/* a x b into o. */
static inline void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

/* The planner's samples: the legs at a pose and their first and second derivatives along a
 * path whose pose changes by dp and d2p per unit of path, exact (one evaluation instead of
 * differencing three). With R = Rz(C) Ry(B) Rx(A), R' = [w]x R, where the angular velocity
 * w = e_a A' + e_b B' + z C' (hexapod_rot's axes) and its rate
 *     w' = e_a A'' + e_b B'' + z C'' + B' C' (z x e_b) + A' (C' z + B' e_b) x e_a
 * (e_b = Rz y turns with C, e_a = Rz Ry x with B and C). A leg v = t + R p - b then has
 *     v' = t' + w x Rp,   v'' = t'' + w' x Rp + w x (w x Rp),
 *     L' = u . v',        L'' = (|v'|^2 - L'^2) / L + u . v''. */
static int hexapod_inverse_path(struct kins *k, const double pose[KINS_POSE_DIM],
                                const double dp[KINS_POSE_DIM], const double d2p[KINS_POSE_DIM],
                                double *joints, double *dL, double *d2L)
{
    const struct hexapod *h = (const struct hexapod *)k;
    double t[3];
    struct hexapod_rot o;
    struct hexapod_legs lg;
    for (int j = 0; j < KINS_POSE_DIM; j++)
        if (!isfinite(dp[j]) || !isfinite(d2p[j]))
            return KINS_ERR_ARG;
    if (hexapod_pose_frame(pose, t, &o) != KINS_OK)
        return KINS_ERR_ARG;
    hexapod_legs_eval(h, t, &o, &lg);
    int st = joints_checked(k, pose, &o, &lg, joints);
    const double z[3] = { 0, 0, 1 };
    double a1 = dp[KINS_A] * HEXAPOD_RAD_PER_DEG, b1 = dp[KINS_B] * HEXAPOD_RAD_PER_DEG;
    double c1 = dp[KINS_C] * HEXAPOD_RAD_PER_DEG, a2 = d2p[KINS_A] * HEXAPOD_RAD_PER_DEG;
    double b2 = d2p[KINS_B] * HEXAPOD_RAD_PER_DEG, c2 = d2p[KINS_C] * HEXAPOD_RAD_PER_DEG;
    double w[3], wd[3], zeb[3], spin[3], spin_ea[3];
    cross3(z, o.e_b, zeb);
    for (int j = 0; j < 3; j++)
        spin[j] = c1 * z[j] + b1 * o.e_b[j];
    cross3(spin, o.e_a, spin_ea);
    for (int j = 0; j < 3; j++) {
        w[j] = a1 * o.e_a[j] + b1 * o.e_b[j] + c1 * z[j];
        wd[j] = a2 * o.e_a[j] + b2 * o.e_b[j] + c2 * z[j] + b1 * c1 * zeb[j] + a1 * spin_ea[j];
    }
    for (int i = 0; i < HEXAPOD_LEGS; i++) {
        double wr[3], wwr[3], wdr[3], v1[3], v2[3];
        cross3(w, lg.rp_mm[i], wr);
        cross3(w, wr, wwr);
        cross3(wd, lg.rp_mm[i], wdr);
        for (int j = 0; j < 3; j++) {
            v1[j] = dp[KINS_X + j] + wr[j];
            v2[j] = d2p[KINS_X + j] + wdr[j] + wwr[j];
        }
        const double *u = lg.u[i];
        double l1 = u[0] * v1[0] + u[1] * v1[1] + u[2] * v1[2];
        double vv = v1[0] * v1[0] + v1[1] * v1[1] + v1[2] * v1[2];
        dL[i] = l1;
        d2L[i] = (vv - l1 * l1) / lg.len_mm[i] + u[0] * v2[0] + u[1] * v2[1] + u[2] * v2[2];
    }
    return st;
}

/* The Jacobian d(leg length)/d(X Y Z A B C) of legs evaluated at the pose (mm/mm, mm/deg):
 * hexapod_jac_row, as the leg rates use it. */
static int hexapod_jacobian(struct kins *k, const double pose[KINS_POSE_DIM], double *jac)
{
    const struct hexapod *h = (const struct hexapod *)k;
    double joints[HEXAPOD_LEGS];
    struct hexapod_rot o;
    struct hexapod_legs lg;
    if (hexapod_pose_legs(h, pose, &o, &lg) != KINS_OK)
        return KINS_ERR_ARG;
    for (int i = 0; i < HEXAPOD_LEGS; i++)
        hexapod_jac_row(&o, &lg, i, HEXAPOD_RAD_PER_DEG, &jac[i * KINS_POSE_DIM]);
    return joints_checked(k, pose, &o, &lg, joints);
}

/* Why a pose is outside the workspace: a leg's length first, then the other limits. */
static int hexapod_describe(struct kins *k, const double pose[KINS_POSE_DIM], char *msg,
                            size_t len)
{
    const struct hexapod *h = (const struct hexapod *)k;
    double joints[HEXAPOD_LEGS];
    struct hexapod_rot o;
    struct hexapod_legs lg;
    if (hexapod_pose_legs(h, pose, &o, &lg) != KINS_OK)
        return KINS_ERR_ARG;
    if (hexapod_lengths_of(k, &lg, joints) != KINS_OK) {
        for (int i = 0; i < HEXAPOD_LEGS; i++) {
            double over = joints[i] - k->joint_max[i], under = k->joint_min[i] - joints[i];
            if (over > 0 || under > 0) {
                snprintf(msg, len, "leg %d ([JOINT_%d]) would be %.3f mm long, %.3f mm %s its "
                         "%s of %.3f mm", i + 1, i, joints[i], over > 0 ? over : under,
                         over > 0 ? "beyond" : "below", over > 0 ? "maximum" : "minimum",
                         over > 0 ? k->joint_max[i] : k->joint_min[i]);
                break;
            }
        }
        return KINS_ERR_UNREACHABLE;
    }
    return hexapod_workspace(h, pose, &o, &lg, msg, len);
}

/* Leg rates (mm/s) = J · pose velocity of legs already evaluated at the pose. */
static void hexapod_rates_of(const struct hexapod_rot *o, const struct hexapod_legs *lg,
                             const double pose_vel[KINS_POSE_DIM], double *rates)
{
    double row[KINS_POSE_DIM];
    for (int i = 0; i < HEXAPOD_LEGS; i++) {
        hexapod_jac_row(o, lg, i, HEXAPOD_RAD_PER_DEG, row);
        double r = 0.0;
        for (int j = 0; j < KINS_POSE_DIM; j++)
            r += row[j] * pose_vel[j];
        rates[i] = r;
    }
}

/* Leg rates (mm/s) = J · pose velocity, the angle rates turned into an angular velocity. */
static int hexapod_leg_rates(struct kins *k, const double pose[KINS_POSE_DIM],
                             const double pose_vel[KINS_POSE_DIM], double *rates)
{
    const struct hexapod *h = (const struct hexapod *)k;
    double t[3];
    struct hexapod_rot o;
    struct hexapod_legs lg;
    if (hexapod_pose_frame(pose, t, &o) != KINS_OK)
        return KINS_ERR_ARG;
    for (int j = 0; j < KINS_POSE_DIM; j++)
        if (!isfinite(pose_vel[j]))
            return KINS_ERR_ARG;
    hexapod_legs_eval(h, t, &o, &lg);
    hexapod_rates_of(&o, &lg, pose_vel, rates);
    return KINS_OK;
}

/* Inverse and leg rates from one evaluation of the legs (the servo thread's every period). */
static int hexapod_inverse_rates(struct kins *k, const double pose[KINS_POSE_DIM],
                                 const double pose_vel[KINS_POSE_DIM], double *joints,
                                 double *rates)
{
    const struct hexapod *h = (const struct hexapod *)k;
    struct hexapod_rot o;
    struct hexapod_legs lg;
    if (hexapod_pose_legs(h, pose, &o, &lg) != KINS_OK)
        return KINS_ERR_ARG;
    int st = joints_checked(k, pose, &o, &lg, joints);
    if (st != KINS_OK)
        return st;
    for (int j = 0; j < KINS_POSE_DIM; j++)
        if (!isfinite(pose_vel[j]))
            return KINS_ERR_ARG;
    hexapod_rates_of(&o, &lg, pose_vel, rates);
    return KINS_OK;
}

/* Leg margins and the condition number of the Jacobian with the angle columns scaled by
 * the lever arm, so that the number does not depend on mm-versus-radian units. */
static int hexapod_check(struct kins *k, const double pose[KINS_POSE_DIM],
                         struct kins_check *out)
{
    const struct hexapod *h = (const struct hexapod *)k;
    double t[3], jac[HEXAPOD_LEGS * KINS_POSE_DIM];
    struct hexapod_rot o;
    struct hexapod_legs lg;
    if (!out || hexapod_pose_frame(pose, t, &o) != KINS_OK)
        return KINS_ERR_ARG;
    hexapod_legs_eval(h, t, &o, &lg);
    out->reachable = 1;
    out->worst_leg = 0;
    out->leg_margin_mm = INFINITY;
    for (int i = 0; i < HEXAPOD_LEGS; i++) {
        double q = lg.len_mm[i] - h->offset_mm[i];
        double m = fmin(q - k->joint_min[i], k->joint_max[i] - q);
        if (m < 0.0)
            out->reachable = 0;
        if (m < out->leg_margin_mm) {
            out->leg_margin_mm = m;
            out->worst_leg = i;
        }
        hexapod_jac_row(&o, &lg, i, h->inv_char_len, &jac[i * KINS_POSE_DIM]);
    }
    if (hexapod_workspace(h, pose, &o, &lg, NULL, 0) != KINS_OK)
        out->reachable = 0;
    if (kins_svd_condition(jac, HEXAPOD_LEGS, KINS_POSE_DIM, &out->condition) != 0)
        out->condition = INFINITY;
    out->near_singular = !(out->condition <= h->singular_condition);
    return KINS_OK;
}

/* The matrix hexapod_check takes the condition number of: the Jacobian with the angle
 * columns scaled by the lever arm. */
static int hexapod_condition_matrix(struct kins *k, const double pose[KINS_POSE_DIM],
                                    double *m)
{
    const struct hexapod *h = (const struct hexapod *)k;
    struct hexapod_rot o;
    struct hexapod_legs lg;
    if (hexapod_pose_legs(h, pose, &o, &lg) != KINS_OK)
        return KINS_ERR_ARG;
    for (int i = 0; i < HEXAPOD_LEGS; i++)
        hexapod_jac_row(&o, &lg, i, h->inv_char_len, &m[i * KINS_POSE_DIM]);
    return KINS_OK;
}

/* Tool tip in both frames: one is fixed by configuration, the other follows the pose. */
static int hexapod_tool_point(struct kins *k, const double pose[KINS_POSE_DIM],
                              double tip_base_mm[3], double tip_platform_mm[3])
{
    const struct hexapod *h = (const struct hexapod *)k;
    double t[3], fixed[3], moving[3];
    struct hexapod_rot o;
    if (hexapod_pose_frame(pose, t, &o) != KINS_OK)
        return KINS_ERR_ARG;
    memcpy(fixed, h->tool_tip_mm, sizeof fixed);
    if (h->carries == HEXAPOD_CARRIES_WORKPIECE) {
        /* tip in platform frame = R^T (tip_base - t) */
        for (int j = 0; j < 3; j++)
            moving[j] = o.r[0][j] * (fixed[0] - t[0]) + o.r[1][j] * (fixed[1] - t[1]) +
                        o.r[2][j] * (fixed[2] - t[2]);
        if (tip_base_mm)
            memcpy(tip_base_mm, fixed, sizeof fixed);
        if (tip_platform_mm)
            memcpy(tip_platform_mm, moving, sizeof moving);
    } else {
        /* tip in base frame = t + R tip_platform */
        for (int j = 0; j < 3; j++)
            moving[j] = t[j] + o.r[j][0] * fixed[0] + o.r[j][1] * fixed[1] +
                        o.r[j][2] * fixed[2];
        if (tip_base_mm)
            memcpy(tip_base_mm, moving, sizeof moving);
        if (tip_platform_mm)
            memcpy(tip_platform_mm, fixed, sizeof fixed);
    }
    return KINS_OK;
}

/* What tool centre point control needs: the tool's data as configured. */
static int hexapod_tool_frame(struct kins *k, struct kins_tool_frame *out)
{
    const struct hexapod *h = (const struct hexapod *)k;
    out->on_platform = h->carries == HEXAPOD_CARRIES_SPINDLE;
    memcpy(out->gauge_mm, h->tool_gauge_mm, sizeof out->gauge_mm);
    memcpy(out->axis, h->tool_axis, sizeof out->axis);
    out->length_mm = h->tool_len_mm;
    out->program_tip = h->program_tip;
    return KINS_OK;
}

/* Frees an instance made by hexapod_create. */
static void hexapod_destroy(struct kins *k)
{
    free(k);
}

/* Builds a hexapod from configuration and checks that its home pose is reachable. */
static int hexapod_create(const struct kins_config *cfg, struct kins **out, char *err,
                          size_t errlen)
{
    if (!cfg || !cfg->get || !out) {
        if (err && errlen)
            snprintf(err, errlen, "hexapod: no configuration given");
        return KINS_ERR_ARG;
    }
    struct hexapod *h = calloc(1, sizeof *h);
    if (!h)
        return KINS_ERR_NOMEM;
    h->base.ops = &kins_hexapod_ops;
    h->base.njoints = HEXAPOD_LEGS;
    int st = hexapod_configure(h, cfg, err, errlen);
    if (st != KINS_OK)
        goto fail;
    double legs[HEXAPOD_LEGS];
    char why[300];
    if (hexapod_describe(&h->base, h->base.home, why, sizeof why) == KINS_ERR_WORKSPACE) {
        st = kins_cfg_error(err, errlen, "KINS", "HOME", "the home pose is outside the "
                            "workspace: %s", why);
        goto fail;
    }
    if (hexapod_inverse(&h->base, h->base.home, legs) != KINS_OK) {
        st = KINS_ERR_CONFIG;
        for (int i = 0; i < HEXAPOD_LEGS && err && errlen; i++)
            if (!(legs[i] >= h->base.joint_min[i] && legs[i] <= h->base.joint_max[i])) {
                snprintf(err, errlen, "[KINS] HOME: the home pose is outside the leg limits "
                         "(leg %d would be %.3f mm, limits [JOINT_%d] %.3f..%.3f mm)", i,
                         legs[i], i, h->base.joint_min[i], h->base.joint_max[i]);
                break;
            }
        goto fail;
    }
    *out = &h->base;
    return KINS_OK;
fail:
    free(h);
    return st;
}

const struct kins_ops kins_hexapod_ops = {
    .name = "hexapod",
    .create = hexapod_create,
    .destroy = hexapod_destroy,
    .inverse = hexapod_inverse,
    .forward = hexapod_forward,
    .forward_near = hexapod_forward_near,
    .leg_rates = hexapod_leg_rates,
    .check = hexapod_check,
    .tool_point = hexapod_tool_point,
    .inverse_rates = hexapod_inverse_rates,
    .inverse_path = hexapod_inverse_path,
    .jacobian = hexapod_jacobian,
    .condition_matrix = hexapod_condition_matrix,
    .inverse4 = hexapod_inverse4,
    .inverse_path4 = hexapod_inverse_path4,
    .describe = hexapod_describe,
    .tool_frame = hexapod_tool_frame,
};
