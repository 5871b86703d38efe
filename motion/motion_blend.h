/* motion_blend.h: G64 P corner rounding: straight feed moves joined by tangent arcs within P. */
#ifndef HEXCNC_MOTION_BLEND_H
#define HEXCNC_MOTION_BLEND_H

#include <stddef.h>

#include "interp/canon.h"
#include "motion/motion.h"

/*
 * Where G64 with a tolerance P is in force and two straight feed moves meet at a corner, the
 * corner is replaced by a circular arc tangent to both lines, in the plane of the two
 * directions, passing at distance P from the programmed corner point (LinuxCNC's meaning of
 * P: the path stays within P of the programmed end point). Each line gives up at most half
 * of its length to a blend, so a short line makes a smaller blend (closer than P).
 *
 *    first line  T1   corner      turning angle theta between the directions d1, d2;
 *    ────────────●‥‥‥‥‥‥●          radius r, trim t = r tan(theta/2) along each line,
 *                  ╲    ‥          corner to arc midpoint: r / cos(theta/2) - r = P
 *                    ╲  ‥
 *                      ╲●  T2
 *                       │ second line
 */

/* One corner's blend. */
struct motion_blend_geom {
    double turn_rad;         /* angle between the two XYZ directions, rad */
    double radius_mm;        /* arc radius, mm */
    double trim_mm;          /* length taken from the end of the first line and from the
                              * start of the second, mm */
    double dev_mm;           /* distance from the programmed corner to the arc's midpoint
                              * (the largest distance from the corner point), mm: P, or
                              * less when a line is too short */
};

/* Corners turning less than this are left to the joint-speed rule (nearly tangent). */
#define MOTION_BLEND_MIN_TURN_RAD 1e-3
/* Blends smaller than this radius are not made (near reversals): the joint stops instead. */
#define MOTION_BLEND_MIN_RADIUS_MM 1e-3

/* The blend of a corner between unit directions d1 (incoming) and d2 (outgoing) of lines
 * len1_mm and len2_mm long, tolerance tol_mm. Returns 1 and fills g when the corner is to
 * be rounded, 0 when not (collinear, near reversal, lines too short, no tolerance). */
int motion_blend_corner(const double d1[3], const double d2[3], double len1_mm, double len2_mm,
                        double tol_mm, struct motion_blend_geom *g);

/* The G64 tolerance a PATH_MODE command sets: its P (value), BLEND_TOLERANCE for G64 without
 * P (ivalue 640), 0 (no blending) for G61 and G61.1. */
double motion_blend_tolerance(const struct motion_config *c, const struct canon_cmd *pm);
/* The G64 tolerance in force before a program's first command (canon_prog's start_path_mode:
 * by default G64 with [TRAJ] BLEND_TOLERANCE, as LinuxCNC starts in G64). */
double motion_blend_start(const struct motion_config *c, const struct canon_prog *p);

/* How A B C turn along a blend arc: the rates of the two lines at its ends, so that the
 * orientation follows a cubic in the arc's angle whose rate joins both lines' without a step
 * (motion_path.c). One per command of the blended program; blend = 0 for the others. */
struct motion_blend_abc {
    int blend;               /* 1: the command is a blend arc */
    double rate0[3];         /* d(A B C)/ds at its start: the line left, deg/mm */
    double rate1[3];         /* d(A B C)/ds at its end: the line entered, deg/mm */
};

/* A copy of `in` with every G64 corner between two straight feed moves rounded: the lines
 * trimmed and a plane-0 CANON_ARC inserted (canon.h's convention, as G141/G142 make them),
 * without the commands' payloads (text and setting NULL: motion reads none).
 * out is initialised here and holds the copy only when *nblends > 0 (else it stays empty and
 * `in` is to be used as is); the caller frees it with canon_prog_free. When abc is not NULL
 * and there are blends, *abc receives out->count entries (free() them), else NULL.
 * MOTION_ERR_NOMEM when memory runs out (out is then empty). */
int motion_blend_program(const struct motion_config *c, const struct canon_prog *in,
                         struct canon_prog *out, size_t *nblends, struct motion_blend_abc **abc);
/* The same, and ends[i] (in->count entries, the caller's) = the count of commands of the
 * blended program once command i and the blend arc after it are in (when there are no
 * blends, i + 1): where a window of a streamed program may be cut (motion_stream.c). */
int motion_blend_program_map(const struct motion_config *c, const struct canon_prog *in,
                             struct canon_prog *out, size_t *nblends,
                             struct motion_blend_abc **abc, size_t *ends);

#endif
