/* hexapod_fwd.c: forward kinematics by Newton-Raphson on the analytic Jacobian. */
#include <math.h>
#include <string.h>

#include "kins/hexapod.h"
#include "kins/hexapod_math.h"

#define N KINS_POSE_DIM

/* Smallest pivot accepted in the scaled Jacobian (entries are of order 1): below it the
 * legs no longer constrain some direction and the step would divide by almost zero. */
#define HEXAPOD_PIVOT_MIN 1e-10

/* The 6x6 loops below run every servo period; fully unrolled, the warm-started forward
 * solve took 0.47 us instead of 0.80 us as loops (bench/bench_kins). */
#define HEXAPOD_UNROLL _Pragma("GCC unroll 6")

/* LU factorisation of a 6x6 matrix in place, with partial pivoting; -1 on a tiny pivot. */
static inline int hexapod_lu(double a[N][N], int piv[N])
{
    HEXAPOD_UNROLL
    for (int c = 0; c < N; c++) {
        int p = c;
        double best = fabs(a[c][c]);
        HEXAPOD_UNROLL
        for (int r = c + 1; r < N; r++)
            if (fabs(a[r][c]) > best) {
                best = fabs(a[r][c]);
                p = r;
            }
        if (!(best >= HEXAPOD_PIVOT_MIN))
            return -1;
        piv[c] = p;
        if (p != c) {
            HEXAPOD_UNROLL
            for (int j = 0; j < N; j++) {
                double tmp = a[c][j];
                a[c][j] = a[p][j];
                a[p][j] = tmp;
            }
        }
        double inv = 1.0 / a[c][c];
        HEXAPOD_UNROLL
        for (int r = c + 1; r < N; r++) {
            double f = a[r][c] * inv;
            a[r][c] = f;
            HEXAPOD_UNROLL
            for (int j = c + 1; j < N; j++)
                a[r][j] -= f * a[c][j];
        }
    }
    return 0;
}

/* Solves (LU) x = b in place on b, with the row swaps recorded by hexapod_lu. */
static inline void hexapod_lu_solve(const double a[N][N], const int piv[N], double b[N])
{
    /* hexapod_lu swaps whole rows (multipliers too), so all swaps come first. */
    HEXAPOD_UNROLL
    for (int c = 0; c < N; c++)
        if (piv[c] != c) {
            double tmp = b[c];
            b[c] = b[piv[c]];
            b[piv[c]] = tmp;
        }
    HEXAPOD_UNROLL
    for (int c = 0; c < N; c++)
        HEXAPOD_UNROLL
        for (int r = c + 1; r < N; r++)
            b[r] -= a[r][c] * b[c];
    HEXAPOD_UNROLL
    for (int c = N - 1; c >= 0; c--) {
        double s = b[c];
        HEXAPOD_UNROLL
        for (int j = c + 1; j < N; j++)
            s -= a[c][j] * b[j];
        b[c] = s / a[c][c];
    }
}

/* Proof that no pose has these lengths: platform joints i and j lie on spheres of radius
 * L_i, L_j about base joints i and j, so their distance is bounded; if the platform's own
 * joint spacing falls outside those bounds for any pair, the legs cannot be assembled. */
static int hexapod_lengths_impossible(const struct hexapod *h, const double *len_mm)
{
    for (int i = 0; i < HEXAPOD_LEGS; i++)
        for (int j = i + 1; j < HEXAPOD_LEGS; j++) {
            double d = h->bdist_mm[i][j], li = len_mm[i], lj = len_mm[j];
            double far = d + li + lj;
            double near = fmax(0.0, fmax(d - li - lj, fabs(li - lj) - d));
            double slack = 1e-9 * (far + 1.0);
            if (h->pdist_mm[i][j] > far + slack || h->pdist_mm[i][j] < near - slack)
                return 1;
        }
    return 0;
}

/* Largest magnitude in a 6-vector whose angle part is already in mm (lever-arm scaled).
 * Plain comparisons: fmax() is a library call here and this runs every iteration. */
static inline double hexapod_max_abs(const double v[N])
{
    double m = 0.0;
    for (int j = 0; j < N; j++) {
        double a = fabs(v[j]);
        m = a > m ? a : m;
    }
    return m;
}

/* Turns the sine and cosine of an angle by a step d (rad) without calling sincos: Newton
 * steps are small after the first, and the angle-sum formulas with a Taylor series of d
 * (exact to double precision for |d| < 0.01) cost a few multiplications. */
static inline void hexapod_turn(double *s, double *c, double angle_rad, double d)
{
    if (fabs(d) < 1e-2) {
        double d2 = d * d;
        double sd = d * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0)));
        double cd = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0));
        double s0 = *s;
        *s = s0 * cd + *c * sd;
        *c = *c * cd - s0 * sd;
    } else {
        sincos(angle_rad, s, c);
    }
}

/* Adds a scaled Newton step to the pose: angle entries come back from mm to radians, and
 * the angles' sines and cosines follow. */
static inline void hexapod_apply_step(const struct hexapod *h, double q[N], double sn[3],
                                      double cs[3], const double d[N])
{
    q[0] += d[0];
    q[1] += d[1];
    q[2] += d[2];
    for (int j = 0; j < 3; j++) {
        double da = d[3 + j] * h->inv_char_len;
        q[3 + j] += da;
        hexapod_turn(&sn[j], &cs[j], q[3 + j], da);
    }
}

/* Residual of the leg lengths at pose q (angles given by their sines and cosines):
 * r_i = target_i - L_i(q), the Newton right-hand side. Returns the largest |r_i|, NaN if
 * the pose blew up. */
static inline double hexapod_residual(const struct hexapod *h, const double q[N],
                                      const double sn[3], const double cs[3],
                                      const double *target, struct hexapod_rot *o,
                                      struct hexapod_legs *lg, double rhs[N])
{
    hexapod_rot_from_sc(o, sn[0], cs[0], sn[1], cs[1], sn[2], cs[2]);
    hexapod_legs_eval(h, q, o, lg);
    for (int i = 0; i < HEXAPOD_LEGS; i++)
        rhs[i] = target[i] - lg->len_mm[i];
    double m = hexapod_max_abs(rhs);
    return isfinite(m) ? m : (double)NAN;
}

/* Newton-Raphson from the pose passed in. Each round evaluates the legs; once a
 * factorisation exists, the correction it gives for the new residual is tried first, and
 * if that correction is below the tolerance it is applied and the solve has converged
 * (the error left is of the order of the correction squared). Otherwise a full Newton step
 * with a fresh analytic Jacobian is taken; where accept_mm > 0, a first one within it ends
 * the solve too (forward_near). The pose is written back only on success. */
static int forward(struct kins *k, const double *joints, double pose[KINS_POSE_DIM],
                   double accept_mm, struct kins_fwd_info *info)
{
    const struct hexapod *h = (const struct hexapod *)k;
    double q[N], rhs[N], lu[N][N], sn[3], cs[3];
    int piv[N] = { 0 }, iter = 0, have_lu = 0, st;
    struct hexapod_rot o;
    struct hexapod_legs lg;
    double resid = (double)NAN, centre_mm[HEXAPOD_LEGS];

    for (int i = 0; i < HEXAPOD_LEGS; i++) {
        if (!isfinite(joints[i]) || !isfinite(pose[i]))
            return KINS_ERR_ARG;
        if (joints[i] < k->joint_min[i] || joints[i] > k->joint_max[i])
            return KINS_ERR_LEG_RANGE;
        centre_mm[i] = joints[i] + h->offset_mm[i]; /* the drives' length + leg offset */
    }
    q[0] = pose[KINS_X];
    q[1] = pose[KINS_Y];
    q[2] = pose[KINS_Z];
    q[3] = pose[KINS_A] * HEXAPOD_RAD_PER_DEG;
    q[4] = pose[KINS_B] * HEXAPOD_RAD_PER_DEG;
    q[5] = pose[KINS_C] * HEXAPOD_RAD_PER_DEG;
    sincos3(q + 3, sn, cs);

    for (;;) {
        resid = hexapod_residual(h, q, sn, cs, centre_mm, &o, &lg, rhs);
        if (isnan(resid)) {
            st = KINS_ERR_NO_CONVERGE;
            break;
        }
        if (have_lu) {
            double d[N];
            memcpy(d, rhs, sizeof d);
            hexapod_lu_solve(lu, piv, d);
            if (hexapod_max_abs(d) <= h->fwd_tol_mm) {
                hexapod_apply_step(h, q, sn, cs, d);
                st = KINS_OK;
                break;
            }
        }
        if (iter >= h->fwd_max_iter) {
            st = KINS_ERR_NO_CONVERGE;
            break;
        }
        for (int i = 0; i < HEXAPOD_LEGS; i++)
            hexapod_jac_row(&o, &lg, i, h->inv_char_len, lu[i]);
        if (hexapod_lu(lu, piv) != 0) {
            st = KINS_ERR_SINGULAR;
            break;
        }
        hexapod_lu_solve(lu, piv, rhs);
        hexapod_apply_step(h, q, sn, cs, rhs);
        iter++;
        if (accept_mm > 0 && !have_lu && hexapod_max_abs(rhs) <= accept_mm) {
            st = KINS_OK;
            break;
        }
        have_lu = 1;
    }
    if (info) {
        info->iterations = iter;
        info->residual_mm = resid;
    }
    if (st != KINS_OK)
        return hexapod_lengths_impossible(h, centre_mm) ? KINS_ERR_IMPOSSIBLE : st;
    pose[KINS_X] = q[0];
    pose[KINS_Y] = q[1];
    pose[KINS_Z] = q[2];
    pose[KINS_A] = q[3] * HEXAPOD_DEG_PER_RAD;
    pose[KINS_B] = q[4] * HEXAPOD_DEG_PER_RAD;
    pose[KINS_C] = q[5] * HEXAPOD_DEG_PER_RAD;
    return KINS_OK;
}

int hexapod_forward(struct kins *k, const double *joints, double pose[KINS_POSE_DIM],
                    struct kins_fwd_info *info)
{
    return forward(k, joints, pose, 0, info);
}

int hexapod_forward_near(struct kins *k, const double *joints, double pose[KINS_POSE_DIM],
                         double accept_mm, struct kins_fwd_info *info)
{
    return forward(k, joints, pose, accept_mm, info);
}
