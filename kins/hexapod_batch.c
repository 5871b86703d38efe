/* hexapod_batch.c: the inverse of four poses at once, lane by lane the same operations as
 * hexapod_inverse, so the same bits (the kins_ops inverse4 entry). */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "kins/hexapod.h"
#include "kins/hexapod_math.h"

/*
 * A caller with several poses ahead (the check's servo-rate pass, motion_step.c) gives four
 * at a time: each number below is a vector of the four poses' values, and each operation is
 * the scalar one of hexapod_inverse (hexapod_pose_frame, sincos3, hexapod_rot_from_sc,
 * hexapod_legs_eval, hexapod_ws_plain), in the same order: C rounds every operation to double
 * and contracts none (ISO C, -ffp-contract=off), in a vector lane as in a register of its
 * own, so each lane's lengths are the scalar function's to the bit. test_kins_shortcuts
 * holds them to that. What the common case does not cover goes to hexapod_inverse itself,
 * lane by lane: a pose that is not a number or turns beyond the series' range (pi/4), a leg
 * out of range, a workspace limit beyond the assembly's, a platform not above its base
 * joints. On a processor with AVX2 the vectors are one register each (the function is
 * built twice, and the loader picks); elsewhere two SSE2 halves.
 */

typedef double v4d __attribute__((vector_size(32)));
typedef int64_t v4l __attribute__((vector_size(32)));

#define SPLAT(c) ((v4d){ (c), (c), (c), (c) })
/* Lane by lane: a where mask (all ones), else b. */
#define SELECT(mask, a, b) ((v4d)(((v4l)(a) & (mask)) | ((v4l)(b) & ~(mask))))

/* The series of sincos3_short and sincos3_one on a vector, Horner as written there. */
#define SINCOS_SHORT(x, s, c)                                                                    \
    do {                                                                                         \
        v4d z_ = (x) * (x);                                                                      \
        v4d q_ = SPLAT(-2.505210838544172e-08), p_ = SPLAT(-2.08767569878681e-09);              \
        q_ = q_ * z_ + 2.7557319223985893e-06, p_ = p_ * z_ + 2.7557319223985888e-07;           \
        q_ = q_ * z_ - 0.00019841269841269841, p_ = p_ * z_ - 2.4801587301587302e-05;           \
        q_ = q_ * z_ + 0.0083333333333333332, p_ = p_ * z_ + 0.0013888888888888889;             \
        q_ = q_ * z_ - 0.16666666666666666, p_ = p_ * z_ - 0.041666666666666664;                \
        q_ = q_ * z_ + 1.0, p_ = p_ * z_ + 0.5;                                                  \
        (s) = q_ * (x);                                                                          \
        (c) = 1.0 - p_ * z_;                                                                     \
    } while (0)

#define SINCOS_ONE(x, s, c)                                                                      \
    do {                                                                                         \
        v4d z_ = (x) * (x);                                                                      \
        v4d q_ = SPLAT(2.8114572543455206e-15), p_ = SPLAT(1.5619206968586225e-16);            \
        q_ = q_ * z_ - 7.6471637318198164e-13, p_ = p_ * z_ - 4.7794773323873853e-14;           \
        q_ = q_ * z_ + 1.6059043836821613e-10, p_ = p_ * z_ + 1.1470745597729725e-11;           \
        q_ = q_ * z_ - 2.505210838544172e-08, p_ = p_ * z_ - 2.08767569878681e-09;              \
        q_ = q_ * z_ + 2.7557319223985893e-06, p_ = p_ * z_ + 2.7557319223985888e-07;           \
        q_ = q_ * z_ - 0.00019841269841269841, p_ = p_ * z_ - 2.4801587301587302e-05;           \
        q_ = q_ * z_ + 0.0083333333333333332, p_ = p_ * z_ + 0.0013888888888888889;             \
        q_ = q_ * z_ - 0.16666666666666666, p_ = p_ * z_ - 0.041666666666666664;                \
        q_ = q_ * z_ + 1.0, p_ = p_ * z_ + 0.5;                                                  \
        (s) = q_ * (x);                                                                          \
        (c) = 1.0 - p_ * z_;                                                                     \
    } while (0)

/* sincos1 of each lane, as a mask of the lanes it could not take (beyond pi/4, or not a
 * number: those lanes' sine and cosine are left undefined). */
#define SINCOS_LANES(x, s, c, bad)                                                               \
    do {                                                                                         \
        v4d m_ = (v4d)((v4l)(x) & INT64_MAX);  /* |x| */                                        \
        v4l short_ = m_ <= SINCOS3_SHORT_RAD;                                                    \
        (bad) |= ~(m_ <= SINCOS3_FAST_RAD);                                                      \
        SINCOS_SHORT(x, s, c);                                                                   \
        if (!(short_[0] & short_[1] & short_[2] & short_[3])) {                                  \
            v4d s1_, c1_;                                                                        \
            SINCOS_ONE(x, s1_, c1_);                                                             \
            (s) = SELECT(short_, s, s1_);                                                        \
            (c) = SELECT(short_, c, c1_);                                                        \
        }                                                                                        \
    } while (0)

__attribute__((target_clones("avx2", "default")))
void hexapod_inverse4(struct kins *k, const double (*pose)[KINS_POSE_DIM],
                      double (*joints)[KINS_MAX_JOINTS], int *status)
{
    const struct hexapod *h = (const struct hexapod *)k;
    v4d x[KINS_POSE_DIM];
    for (int j = 0; j < KINS_POSE_DIM; j++)
        for (int l = 0; l < 4; l++)
            x[j][l] = pose[l][j];
    v4d z = SPLAT(0.0);                       /* hexapod_pose_frame's test: 0 unless a */
    for (int j = 0; j < KINS_POSE_DIM; j++)   /* value is infinite or not a number */
        z = z + x[j] * 0.0;
    v4l bad = ~(z == 0);
    v4d sa, ca, sb, cb, sc, cc;
    v4d xa = x[KINS_A] * HEXAPOD_RAD_PER_DEG, xb = x[KINS_B] * HEXAPOD_RAD_PER_DEG;
    v4d xc = x[KINS_C] * HEXAPOD_RAD_PER_DEG;
    SINCOS_LANES(xa, sa, ca, bad);
    SINCOS_LANES(xb, sb, cb, bad);
    SINCOS_LANES(xc, sc, cc, bad);
    v4d r00 = cc * cb, r01 = cc * sb * sa - sc * ca, r02 = cc * sb * ca + sc * sa;
    v4d r10 = sc * cb, r11 = sc * sb * sa + cc * ca, r12 = sc * sb * ca - cc * sa;
    v4d r20 = -sb, r21 = cb * sa, r22 = cb * ca;
    v4l plain = r22 > 0;
    v4d len[HEXAPOD_LEGS];
    for (int i = 0; i < HEXAPOD_LEGS; i++) {
        const double *p = h->p_mm[i], *b = h->b_mm[i];
        v4d rp0 = r00 * p[0] + r01 * p[1] + r02 * p[2];
        v4d rp1 = r10 * p[0] + r11 * p[1] + r12 * p[2];
        v4d rp2 = r20 * p[0] + r21 * p[1] + r22 * p[2];
        v4d v0 = x[KINS_X] + rp0 - b[0];
        v4d v1 = x[KINS_Y] + rp1 - b[1];
        v4d v2 = x[KINS_Z] + rp2 - b[2];
        v4d q = v0 * v0 + v1 * v1 + v2 * v2;
        for (int l = 0; l < 4; l++)
            q[l] = sqrt(q[l]);                /* (sqrtpd: correctly rounded, as sqrtsd) */
        len[i] = q - h->offset_mm[i];
        bad |= (len[i] < k->joint_min[i]) | (len[i] > k->joint_max[i]);
        plain &= x[KINS_Z] + rp2 - b[2] > 0;
    }
    if (h->ws_extra)
        plain = (v4l){ 0, 0, 0, 0 };
    for (int l = 0; l < 4; l++) {
        if (bad[l] || !plain[l]) {
            status[l] = k->ops->inverse(k, pose[l], joints[l]);
            continue;
        }
        for (int i = 0; i < HEXAPOD_LEGS; i++)
            joints[l][i] = len[i][l];
        status[l] = KINS_OK;
    }
}
