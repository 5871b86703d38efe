/* comp5_testutil.h: independent geometry and a recording sink for the G141/G142 tests. */
#ifndef HEXCNC_COMP5_TESTUTIL_H
#define HEXCNC_COMP5_TESTUTIL_H

#include <math.h>
#include <string.h>

#include "interp/canon.h"
#include "interp/comp5.h"

#define TU_DEG (M_PI / 180.0)

static inline double tu_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void tu_cross(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static inline double tu_norm(const double a[3])
{
    return sqrt(tu_dot(a, a));
}

static inline void tu_unit(double a[3])
{
    double n = tu_norm(a);
    a[0] /= n, a[1] /= n, a[2] /= n;
}

static inline double tu_dist(const double a[3], const double b[3])
{
    double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return tu_norm(d);
}

/* Rodrigues' formula: v rotated by angle_deg about unit axis k (a construction independent
 * of comp5's closed-form matrix product). */
static inline void tu_rotate(const double k[3], double angle_deg, const double v[3], double o[3])
{
    double c = cos(angle_deg * TU_DEG), s = sin(angle_deg * TU_DEG), kxv[3];
    tu_cross(k, v, kxv);
    double kv = tu_dot(k, v);
    for (int i = 0; i < 3; i++)
        o[i] = v[i] * c + kxv[i] * s + k[i] * kv * (1.0 - c);
}

/* The table normal by successive rotations of +Z: first about X by A, then Y by B, then Z
 * by C (all about the fixed axes), i.e. Rz(C) Ry(B) Rx(A) [0 0 1]. */
static inline void tu_normal(double a_deg, double b_deg, double c_deg, double n[3])
{
    static const double ex[3] = {1, 0, 0}, ey[3] = {0, 1, 0}, ez[3] = {0, 0, 1};
    double v1[3], v2[3];
    tu_rotate(ex, a_deg, ez, v1);
    tu_rotate(ey, b_deg, v1, v2);
    tu_rotate(ez, c_deg, v2, n);
}

/* Distance from point p to the infinite line through a with direction d. */
static inline double tu_dist_line(const double p[3], const double a[3], const double d[3])
{
    double ap[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]}, x[3];
    tu_cross(ap, d, x);
    return tu_norm(x) / tu_norm(d);
}

/* Distance from point p to the segment a..b. */
static inline double tu_dist_segment(const double p[3], const double a[3], const double b[3])
{
    double ab[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double ap[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
    double t = tu_dot(ap, ab) / tu_dot(ab, ab);
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    double q[3] = {a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]};
    return tu_dist(p, q);
}

/* A sink that always refuses (to test COMP5_ERR_SINK). */
static inline int tu_refuse_sink(void *ctx, const struct canon_cmd *cmd)
{
    (void)ctx, (void)cmd;
    return -1;
}

/* Fills a compensated block. */
static inline struct comp5_block tu_block(int side, double x, double y, double z, double a,
                                          double b, double c, double w_mm, int line)
{
    struct comp5_block blk;
    memset(&blk, 0, sizeof blk);
    blk.side = side;
    blk.point[0] = x, blk.point[1] = y, blk.point[2] = z;
    blk.point[3] = a, blk.point[4] = b, blk.point[5] = c;
    blk.radius_mm = w_mm;
    blk.feed_mm_min = 2000.0;
    blk.line = line;
    blk.file = "test.ngc";
    return blk;
}

#endif
