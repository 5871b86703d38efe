/* trivial.c: identity kinematics (joint i = pose axis i), to prove the plugin boundary. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "kins/kins.h"
#include "kins/kins_cfg.h"

/* Number of joints that mirror a pose axis; joints past the pose (up to 9) stay at 0. */
static int trivial_mapped(const struct kins *k)
{
    return k->njoints < KINS_POSE_DIM ? k->njoints : KINS_POSE_DIM;
}

/* Reports a joint outside its optional limits as unreachable, after writing every joint. */
static int trivial_inverse(struct kins *k, const double pose[KINS_POSE_DIM], double *joints)
{
    int st = KINS_OK;
    for (int i = 0; i < k->njoints; i++) {
        joints[i] = i < KINS_POSE_DIM ? pose[i] : 0.0;
        if (!isfinite(joints[i]))
            return KINS_ERR_ARG;
        if (joints[i] < k->joint_min[i] || joints[i] > k->joint_max[i])
            st = KINS_ERR_UNREACHABLE;
    }
    return st;
}

/* Copies joints back to pose axes; axes without a joint come back as 0. */
static int trivial_forward(struct kins *k, const double *joints, double pose[KINS_POSE_DIM],
                           struct kins_fwd_info *info)
{
    for (int i = 0; i < k->njoints; i++) {
        if (!isfinite(joints[i]))
            return KINS_ERR_ARG;
        if (joints[i] < k->joint_min[i] || joints[i] > k->joint_max[i])
            return KINS_ERR_LEG_RANGE;
    }
    for (int j = 0; j < KINS_POSE_DIM; j++)
        pose[j] = j < trivial_mapped(k) ? joints[j] : 0.0;
    if (info) {
        info->iterations = 0;
        info->residual_mm = 0.0;
    }
    return KINS_OK;
}

/* The Jacobian is the identity, so joint rates are the axis rates. */
static int trivial_leg_rates(struct kins *k, const double pose[KINS_POSE_DIM],
                             const double pose_vel[KINS_POSE_DIM], double *rates)
{
    for (int i = 0; i < k->njoints; i++)
        rates[i] = i < KINS_POSE_DIM ? pose_vel[i] : 0.0;
    return KINS_OK;
}

/* Limits only; the identity is never singular. */
static int trivial_check(struct kins *k, const double pose[KINS_POSE_DIM],
                         struct kins_check *out)
{
    double joints[KINS_MAX_JOINTS];
    int st = trivial_inverse(k, pose, joints);
    if (st == KINS_ERR_ARG)
        return st;
    out->reachable = st == KINS_OK;
    out->worst_leg = 0;
    out->leg_margin_mm = INFINITY;
    for (int i = 0; i < k->njoints; i++) {
        double m = fmin(joints[i] - k->joint_min[i], k->joint_max[i] - joints[i]);
        if (m < out->leg_margin_mm) {
            out->leg_margin_mm = m;
            out->worst_leg = i;
        }
    }
    out->condition = 1.0;
    out->near_singular = 0;
    return KINS_OK;
}

/* Frees an instance. */
static void trivial_destroy(struct kins *k)
{
    free(k);
}

/* Reads [KINS] JOINTS (1..9, default 6) and optional [JOINT_n] MIN_LIMIT / MAX_LIMIT. */
static int trivial_create(const struct kins_config *cfg, struct kins **out, char *err,
                          size_t errlen)
{
    double n = KINS_POSE_DIM;
    int st = kins_cfg_number_or(cfg, "KINS", "JOINTS", &n, err, errlen);
    if (st != KINS_OK)
        return st;
    if (n < 1 || n > KINS_MAX_JOINTS || n != floor(n))
        return kins_cfg_error(err, errlen, "KINS", "JOINTS", "%g: expected a whole number "
                              "1..%d", n, KINS_MAX_JOINTS);
    struct kins *k = calloc(1, sizeof *k);
    if (!k)
        return KINS_ERR_NOMEM;
    k->ops = &kins_trivial_ops;
    k->njoints = (int)n;
    for (int i = 0; i < k->njoints; i++) {
        char sec[24];
        snprintf(sec, sizeof sec, "JOINT_%d", i);
        k->joint_min[i] = -INFINITY;
        k->joint_max[i] = INFINITY;
        if ((st = kins_cfg_number_or(cfg, sec, "MIN_LIMIT", &k->joint_min[i], err, errlen)) ||
            (st = kins_cfg_number_or(cfg, sec, "MAX_LIMIT", &k->joint_max[i], err, errlen))) {
            free(k);
            return st;
        }
    }
    *out = k;
    return KINS_OK;
}

const struct kins_ops kins_trivial_ops = {
    .name = "trivial",
    .create = trivial_create,
    .destroy = trivial_destroy,
    .inverse = trivial_inverse,
    .forward = trivial_forward,
    .leg_rates = trivial_leg_rates,
    .check = trivial_check,
    .tool_point = NULL,
};
