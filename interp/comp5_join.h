/* comp5_join.h: corner geometry of G141/G142 runs, and the small vector helpers it needs. */
#ifndef HEXCNC_COMP5_JOIN_H
#define HEXCNC_COMP5_JOIN_H

#include <math.h>

#include "interp/comp5.h"

/* How two consecutive offset segments meet at a programmed corner. */
enum comp5_join_kind {
    COMP5_JOIN_NONE,          /* collinear: the first ends where the second begins */
    COMP5_JOIN_INSIDE,        /* the offset lines cross, seen along the tool axis */
    COMP5_JOIN_OUTSIDE,       /* an arc of radius W about the programmed corner */
    COMP5_JOIN_LINE,          /* degenerate corner: a straight move from a1 to b0 */
};

/* The join of segment a (ending at the corner) with segment b (starting there). */
struct comp5_join {
    enum comp5_join_kind kind;
    double t_a;               /* INSIDE: the join's place on a, as a0 + t_a (a1 - a0) */
    double u_b;               /* INSIDE: the join's place on b, as b0 + u_b (b1 - b0) */
    double point[6];          /* INSIDE: the join point; orientation = the corner's */
    double gap_mm;            /* INSIDE: skew offset lines: their distance along the corner's
                               * tool axis there (shared by the join) */
    double normal[3];         /* OUTSIDE: unit normal of the arc's plane (rotation +1) */
};

/* Classifies the corner and computes the join point or arc (pure geometry, no checks
 * against the segments' lengths: the caller does those). */
struct kins_tool_frame;
void comp5_join_corner(const struct comp5_seg *a, const struct comp5_seg *b,
                       const double corner[6], const struct kins_tool_frame *tf,
                       struct comp5_join *j);

/* Vector helpers on the X Y Z part of poses. */
static inline double comp5_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static inline void comp5_sub(const double a[3], const double b[3], double out[3])
{
    out[0] = a[0] - b[0], out[1] = a[1] - b[1], out[2] = a[2] - b[2];
}
static inline void comp5_cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}
static inline double comp5_len(const double a[3])
{
    return sqrt(comp5_dot(a, a));
}
/* Distance between the X Y Z of two poses, mm. */
static inline double comp5_dist(const double a[3], const double b[3])
{
    double d[3];
    comp5_sub(a, b, d);
    return comp5_len(d);
}

#endif
