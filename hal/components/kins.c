/* kins.c: the `kins` component: forward kinematics of the joint feedback into pose pins. */
#include <stdlib.h>

#include "hal/hal.h"
#include "kins/kins.h"

static const char kins_axis_names[KINS_POSE_DIM] = { 'x', 'y', 'z', 'a', 'b', 'c' };

struct kins_comp {
    struct kins *k;                        /* the machine's kinematics (object "kins") */
    double *joint_fb[KINS_MAX_JOINTS];     /* in: joint (leg length) feedback, mm */
    double *pose_fb[KINS_POSE_DIM];        /* out: pose, X Y Z mm, A B C deg */
    bool *fault;                           /* out: the last solve failed */
    int32_t *iterations;                   /* out: Newton iterations of the last solve */
    int32_t *status;                       /* out: kins status of the last solve (0 = ok) */
    double guess[KINS_POSE_DIM];           /* last converged pose: the next warm start */
};

/* One period: solve from the last good pose; a failed solve only raises the fault. */
static void kins_comp_forward(void *arg, long period_ns)
{
    struct kins_comp *c = arg;
    double joints[KINS_MAX_JOINTS];
    double pose[KINS_POSE_DIM];
    struct kins_fwd_info info = { 0, 0.0 };
    for (int i = 0; i < c->k->njoints; i++)
        joints[i] = *c->joint_fb[i];
    for (int i = 0; i < KINS_POSE_DIM; i++)
        pose[i] = c->guess[i];
    int st = kins_forward(c->k, joints, pose, &info);
    *c->status = st;
    *c->iterations = info.iterations;
    *c->fault = st != KINS_OK;
    if (st != KINS_OK)
        return;
    for (int i = 0; i < KINS_POSE_DIM; i++) {
        c->guess[i] = pose[i];
        *c->pose_fb[i] = pose[i];
    }
}

/* Creates the pins and the funct kins.forward for the loaded kinematics. */
static int kins_comp_load(struct hal *h, int argc, char **argv)
{
    struct kins *k = hal_get_object(h, "kins");
    if (!k)
        return hal_error(h, HAL_ERR_COMPONENT, "loadrt kins: no kinematics loaded; load one "
                         "by its name, e.g. loadrt [KINS]KINEMATICS");
    int st = hal_args_check(h, "kins", argc, argv, "");
    if (st != HAL_OK)
        return st;
    if (k->njoints < 1 || k->njoints > KINS_MAX_JOINTS)
        return hal_error(h, HAL_ERR_COMPONENT, "loadrt kins: kinematics has %d joints",
                         k->njoints);
    struct kins_comp *c = calloc(1, sizeof *c);
    if (!c)
        return hal_error(h, HAL_ERR_NOMEM, "loadrt kins: out of memory");
    if ((st = hal_on_destroy(h, free, c)) != HAL_OK) {
        free(c);
        return st;
    }
    c->k = k;
    for (int i = 0; i < KINS_POSE_DIM; i++)
        c->guess[i] = k->home[i];
    for (int i = 0; i < k->njoints && st == HAL_OK; i++)
        st = hal_pin_float_newf(h, HAL_IN, &c->joint_fb[i], "kins.joint-fb-%d", i);
    for (int i = 0; i < KINS_POSE_DIM && st == HAL_OK; i++)
        st = hal_pin_float_newf(h, HAL_OUT, &c->pose_fb[i], "kins.pose-fb-%c",
                                kins_axis_names[i]);
    if (st == HAL_OK)
        st = hal_pin_bit_newf(h, HAL_OUT, &c->fault, "kins.fault");
    if (st == HAL_OK)
        st = hal_pin_s32_newf(h, HAL_OUT, &c->iterations, "kins.iterations");
    if (st == HAL_OK)
        st = hal_pin_s32_newf(h, HAL_OUT, &c->status, "kins.status");
    if (st == HAL_OK)
        st = hal_export_functf(h, kins_comp_forward, c, "kins.forward");
    if (st != HAL_OK)
        return st;
    /* Start consistent: the pose pins at home, unconnected joint pins at home's lengths. */
    double joints[KINS_MAX_JOINTS];
    for (int i = 0; i < KINS_POSE_DIM; i++)
        *c->pose_fb[i] = k->home[i];
    if (kins_inverse(k, k->home, joints) == KINS_OK)
        for (int i = 0; i < k->njoints; i++)
            *c->joint_fb[i] = joints[i];
    return HAL_OK;
}

const struct hal_comp_type hal_comp_kins = { "kins", kins_comp_load };
