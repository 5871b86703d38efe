/* hexapod_batch.c: the inverse and the planner's samples of four poses at once, lane by
 * lane the same operations as hexapod_inverse and hexapod_inverse_path, so the same bits
 * (the kins_ops inverse4 and inverse_path4 entries). */
#include <math.h>
#include <stdint.h>

#include "common/simd.h"
#include "common/sincos4.h"
#include "kins/hexapod.h"
#include "kins/hexapod_math.h"

/*
 * A caller with several poses ahead (a check's executor, motion_ahead.c; the planner's
 * knots, motion_caps.c) gives four at a time: each number below is a vector of the four
 * poses' values, and each operation is the scalar one of hexapod_inverse
 * (hexapod_pose_frame, sincos3, hexapod_rot_from_sc, hexapod_legs_eval, hexapod_ws_plain),
 * in the same order: C rounds every operation to double and contracts none (ISO C,
 * -ffp-contract=off), in a vector lane as in a register of its own, so each lane's lengths
 * are the scalar function's to the bit. test_kins_shortcuts holds them to that. What the
 * common case does not cover goes to hexapod_inverse itself, lane by lane: a pose that is
 * not a number or turns beyond the series' range (pi/4), a leg out of range, a workspace
 * limit beyond the assembly's, a platform not above its base joints. The vectors are built
 * for AVX2 alone, one register each; a processor without it takes four single calls
 * (common/simd.h).
 */

/* The platform's rotation at four poses x[] (hexapod_pose_frame's angles, sincos3's series,
 * hexapod_rot_from_sc's products), and the sine and cosine of C; lanes beyond the series'
 * range (pi/4) or not a number into *bad. (Pointers, not vectors by value, and inlined
 * always: into the AVX2 functions that call them.) */
static inline __attribute__((always_inline)) void rot4(const v4d *x, v4d (*r)[3], v4d *sc_out,
                                                       v4d *cc_out, v4l *bad)
{
    v4d sa, ca, sb, cb, sc, cc;
    v4d xa = x[KINS_A] * HEXAPOD_RAD_PER_DEG, xb = x[KINS_B] * HEXAPOD_RAD_PER_DEG;
    v4d xc = x[KINS_C] * HEXAPOD_RAD_PER_DEG;
    SINCOS_LANES(xa, sa, ca, *bad);
    SINCOS_LANES(xb, sb, cb, *bad);
    SINCOS_LANES(xc, sc, cc, *bad);
    r[0][0] = cc * cb, r[0][1] = cc * sb * sa - sc * ca, r[0][2] = cc * sb * ca + sc * sa;
    r[1][0] = sc * cb, r[1][1] = sc * sb * sa + cc * ca, r[1][2] = sc * sb * ca - cc * sa;
    r[2][0] = -sb, r[2][1] = cb * sa, r[2][2] = cb * ca;
    *sc_out = sc, *cc_out = cc;
}

/* Leg i at four poses (hexapod_legs_eval's): the rotated platform joint rp[], the leg's
 * vector v[] and its length *len. */
static inline __attribute__((always_inline)) void leg4(const struct hexapod *h, int i,
                                                       const v4d *x, v4d (*r)[3], v4d *rp,
                                                       v4d *v, v4d *len)
{
    const double *p = h->p_mm[i], *b = h->b_mm[i];
    for (int j = 0; j < 3; j++)
        rp[j] = r[j][0] * p[0] + r[j][1] * p[1] + r[j][2] * p[2];
    for (int j = 0; j < 3; j++)
        v[j] = x[KINS_X + j] + rp[j] - b[j];
    v4d q = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    for (int l = 0; l < 4; l++)
        q[l] = sqrt(q[l]);                /* (sqrtpd: correctly rounded, as sqrtsd) */
    *len = q;
}

HEXCNC_AVX2
static void inverse4_avx2(struct kins *k, const double (*pose)[KINS_POSE_DIM],
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
    v4d r[3][3], sc, cc, len[HEXAPOD_LEGS];
    rot4(x, r, &sc, &cc, &bad);
    v4l plain = r[2][2] > 0;
    for (int i = 0; i < HEXAPOD_LEGS; i++) {
        v4d rp[3], v[3], q;
        leg4(h, i, x, r, rp, v, &q);
        len[i] = q - h->offset_mm[i];
        bad |= (len[i] < k->joint_min[i]) | (len[i] > k->joint_max[i]);
        plain &= x[KINS_Z] + rp[2] - h->b_mm[i][2] > 0;
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

/* a x b of vectors, as cross3. */
#define CROSS_V(a, b, o)                                                                         \
    do {                                                                                         \
        (o)[0] = (a)[1] * (b)[2] - (a)[2] * (b)[1];                                              \
        (o)[1] = (a)[2] * (b)[0] - (a)[0] * (b)[2];                                              \
        (o)[2] = (a)[0] * (b)[1] - (a)[1] * (b)[0];                                              \
    } while (0)

/* The planner's samples four at a time: hexapod_inverse_path's operations on vectors, as
 * hexapod_inverse4 does the inverse's (the kins_ops inverse_path4 entry). */
HEXCNC_AVX2
static void inverse_path4_avx2(struct kins *k, const double (*pose)[KINS_POSE_DIM],
                               const double (*dp)[KINS_POSE_DIM],
                               const double (*d2p)[KINS_POSE_DIM],
                               double (*joints)[KINS_MAX_JOINTS], double (*dL)[KINS_MAX_JOINTS],
                               double (*d2L)[KINS_MAX_JOINTS], int *status)
{
    const struct hexapod *h = (const struct hexapod *)k;
    v4d x[KINS_POSE_DIM], d1[KINS_POSE_DIM], d2[KINS_POSE_DIM];
    for (int j = 0; j < KINS_POSE_DIM; j++)
        for (int l = 0; l < 4; l++)
            x[j][l] = pose[l][j], d1[j][l] = dp[l][j], d2[j][l] = d2p[l][j];
    v4d z = SPLAT(0.0);                       /* poses and their derivatives: numbers */
    for (int j = 0; j < KINS_POSE_DIM; j++)
        z = z + x[j] * 0.0 + d1[j] * 0.0 + d2[j] * 0.0;
    v4l bad = ~(z == 0);
    v4d r[3][3], sc, cc;
    rot4(x, r, &sc, &cc, &bad);
    v4d e_a[3] = { r[0][0], r[1][0], r[2][0] }, e_b[3] = { -sc, cc, SPLAT(0.0) };
    v4l plain = r[2][2] > 0;
    const double zz[3] = { 0, 0, 1 };
    v4d a1 = d1[KINS_A] * HEXAPOD_RAD_PER_DEG, b1 = d1[KINS_B] * HEXAPOD_RAD_PER_DEG;
    v4d c1 = d1[KINS_C] * HEXAPOD_RAD_PER_DEG, a2 = d2[KINS_A] * HEXAPOD_RAD_PER_DEG;
    v4d b2 = d2[KINS_B] * HEXAPOD_RAD_PER_DEG, c2 = d2[KINS_C] * HEXAPOD_RAD_PER_DEG;
    v4d zv[3] = { SPLAT(zz[0]), SPLAT(zz[1]), SPLAT(zz[2]) };
    v4d w[3], wd[3], zeb[3], spin[3], spin_ea[3];
    CROSS_V(zv, e_b, zeb);
    for (int j = 0; j < 3; j++)
        spin[j] = c1 * zz[j] + b1 * e_b[j];
    CROSS_V(spin, e_a, spin_ea);
    for (int j = 0; j < 3; j++) {
        w[j] = a1 * e_a[j] + b1 * e_b[j] + c1 * zz[j];
        wd[j] = a2 * e_a[j] + b2 * e_b[j] + c2 * zz[j] + b1 * c1 * zeb[j] + a1 * spin_ea[j];
    }
    v4d len[HEXAPOD_LEGS], l1v[HEXAPOD_LEGS], l2v[HEXAPOD_LEGS];
    for (int i = 0; i < HEXAPOD_LEGS; i++) {
        v4d rp[3], v[3], q, u[3], wr[3], wwr[3], wdr[3], v1[3], v2[3];
        leg4(h, i, x, r, rp, v, &q);
        v4d inv = 1.0 / q;
        for (int j = 0; j < 3; j++)
            u[j] = v[j] * inv;
        len[i] = q - h->offset_mm[i];
        bad |= (len[i] < k->joint_min[i]) | (len[i] > k->joint_max[i]);
        plain &= x[KINS_Z] + rp[2] - h->b_mm[i][2] > 0;
        CROSS_V(w, rp, wr);
        CROSS_V(w, wr, wwr);
        CROSS_V(wd, rp, wdr);
        for (int j = 0; j < 3; j++) {
            v1[j] = d1[KINS_X + j] + wr[j];
            v2[j] = d2[KINS_X + j] + wdr[j] + wwr[j];
        }
        v4d l1 = u[0] * v1[0] + u[1] * v1[1] + u[2] * v1[2];
        v4d vv = v1[0] * v1[0] + v1[1] * v1[1] + v1[2] * v1[2];
        l1v[i] = l1;
        l2v[i] = (vv - l1 * l1) / q + u[0] * v2[0] + u[1] * v2[1] + u[2] * v2[2];
    }
    if (h->ws_extra)
        plain = (v4l){ 0, 0, 0, 0 };
    for (int l = 0; l < 4; l++) {
        if (bad[l] || !plain[l]) {
            status[l] = k->ops->inverse_path(k, pose[l], dp[l], d2p[l], joints[l], dL[l],
                                             d2L[l]);
            continue;
        }
        for (int i = 0; i < HEXAPOD_LEGS; i++)
            joints[l][i] = len[i][l], dL[l][i] = l1v[i][l], d2L[l][i] = l2v[i][l];
        status[l] = KINS_OK;
    }
}

/* The kins_ops entries: the vectors where the processor has AVX2, else four single calls
 * (common/simd.h). */
void hexapod_inverse4(struct kins *k, const double (*pose)[KINS_POSE_DIM],
                      double (*joints)[KINS_MAX_JOINTS], int *status)
{
    if (hexcnc_avx2()) {
        inverse4_avx2(k, pose, joints, status);
        return;
    }
    for (int l = 0; l < 4; l++)
        status[l] = k->ops->inverse(k, pose[l], joints[l]);
}

void hexapod_inverse_path4(struct kins *k, const double (*pose)[KINS_POSE_DIM],
                           const double (*dp)[KINS_POSE_DIM], const double (*d2p)[KINS_POSE_DIM],
                           double (*joints)[KINS_MAX_JOINTS], double (*dL)[KINS_MAX_JOINTS],
                           double (*d2L)[KINS_MAX_JOINTS], int *status)
{
    if (hexcnc_avx2()) {
        inverse_path4_avx2(k, pose, dp, d2p, joints, dL, d2L, status);
        return;
    }
    for (int l = 0; l < 4; l++)
        status[l] = k->ops->inverse_path(k, pose[l], dp[l], d2p[l], joints[l], dL[l], d2L[l]);
}
