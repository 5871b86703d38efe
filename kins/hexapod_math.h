/* hexapod_math.h: the inline core shared by the hexapod's inverse, Jacobian and forward. */
#ifndef HEXCNC_HEXAPOD_MATH_H
#define HEXCNC_HEXAPOD_MATH_H

#include <math.h>

#include "common/sincos3.h"
#include "kins/hexapod.h"

#define HEXAPOD_DEG_PER_RAD (180.0 / M_PI)
#define HEXAPOD_RAD_PER_DEG (M_PI / 180.0)

/* Orientation of the platform: R = Rz(C)·Ry(B)·Rx(A), and the axes about which the three
 * angle rates turn it, so that angular velocity = e_a·dA + e_b·dB + e_c·dC (e_c = +Z). */
struct hexapod_rot {
    double r[3][3];     /* rotation matrix, platform frame -> base frame */
    double e_a[3];      /* axis of A after B and C have acted: Rz(C)·Ry(B)·X */
    double e_b[3];      /* axis of B after C has acted: Rz(C)·Y */
};

/* Legs at one pose: lengths, unit directions and the rotated platform joints. */
struct hexapod_legs {
    double len_mm[HEXAPOD_LEGS];       /* leg lengths, mm */
    double u[HEXAPOD_LEGS][3];         /* unit vector from base joint to platform joint */
    double rp_mm[HEXAPOD_LEGS][3];     /* platform joint relative to the platform origin,
                                        * in base-frame axes (R·p), mm */
};

/* Builds R and the angle-rate axes from the sines and cosines of A, B, C. */
static inline void hexapod_rot_from_sc(struct hexapod_rot *o, double sa, double ca, double sb,
                                       double cb, double sc, double cc)
{
    o->r[0][0] = cc * cb;
    o->r[0][1] = cc * sb * sa - sc * ca;
    o->r[0][2] = cc * sb * ca + sc * sa;
    o->r[1][0] = sc * cb;
    o->r[1][1] = sc * sb * sa + cc * ca;
    o->r[1][2] = sc * sb * ca - cc * sa;
    o->r[2][0] = -sb;
    o->r[2][1] = cb * sa;
    o->r[2][2] = cb * ca;
    o->e_a[0] = cc * cb;
    o->e_a[1] = sc * cb;
    o->e_a[2] = -sb;
    o->e_b[0] = -sc;
    o->e_b[1] = cc;
    o->e_b[2] = 0.0;
}

/* Builds R from angles in radians. */
static inline void hexapod_rot_from_rad(struct hexapod_rot *o, double a_rad, double b_rad,
                                        double c_rad)
{
    double x[3] = { a_rad, b_rad, c_rad }, s[3], c[3];
    sincos3(x, s, c);
    hexapod_rot_from_sc(o, s[0], c[0], s[1], c[1], s[2], c[2]);
}

/* Leg vectors for platform origin t (mm) and orientation o: v_i = t + R·p_i - b_i. */
static inline void hexapod_legs_eval(const struct hexapod *h, const double t_mm[3],
                                     const struct hexapod_rot *o, struct hexapod_legs *lg)
{
    for (int i = 0; i < HEXAPOD_LEGS; i++) {
        const double *p = h->p_mm[i];
        double rp0 = o->r[0][0] * p[0] + o->r[0][1] * p[1] + o->r[0][2] * p[2];
        double rp1 = o->r[1][0] * p[0] + o->r[1][1] * p[1] + o->r[1][2] * p[2];
        double rp2 = o->r[2][0] * p[0] + o->r[2][1] * p[1] + o->r[2][2] * p[2];
        double v0 = t_mm[0] + rp0 - h->b_mm[i][0];
        double v1 = t_mm[1] + rp1 - h->b_mm[i][1];
        double v2 = t_mm[2] + rp2 - h->b_mm[i][2];
        double len = sqrt(v0 * v0 + v1 * v1 + v2 * v2);
        double inv = 1.0 / len;
        lg->len_mm[i] = len;
        lg->u[i][0] = v0 * inv;
        lg->u[i][1] = v1 * inv;
        lg->u[i][2] = v2 * inv;
        lg->rp_mm[i][0] = rp0;
        lg->rp_mm[i][1] = rp1;
        lg->rp_mm[i][2] = rp2;
    }
}

/* Row i of the Jacobian d(leg length)/d(X, Y, Z, A, B, C): the leg direction, then the
 * moment (R·p_i) × u_i projected on each angle's axis, in mm/rad times ang_scale. */
static inline void hexapod_jac_row(const struct hexapod_rot *o, const struct hexapod_legs *lg,
                                   int i, double ang_scale, double row[KINS_POSE_DIM])
{
    const double *u = lg->u[i], *rp = lg->rp_mm[i];
    double w0 = rp[1] * u[2] - rp[2] * u[1];
    double w1 = rp[2] * u[0] - rp[0] * u[2];
    double w2 = rp[0] * u[1] - rp[1] * u[0];
    row[0] = u[0];
    row[1] = u[1];
    row[2] = u[2];
    row[3] = (w0 * o->e_a[0] + w1 * o->e_a[1] + w2 * o->e_a[2]) * ang_scale;
    row[4] = (w0 * o->e_b[0] + w1 * o->e_b[1]) * ang_scale;
    row[5] = w2 * ang_scale;
}

#endif
