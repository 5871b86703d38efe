/* cut.h: cutting simulation: the tool swept along the machine's actual path, and the wall it leaves. */
#ifndef HEXCNC_CHECK_CUT_H
#define HEXCNC_CHECK_CUT_H

#include <stddef.h>

#include "check/check.h"

/*
 * The actual path: every servo period motion_step() commands the legs, a step generator per
 * leg (sim/stepgen.h, [JOINT_n] SCALE / STEPGEN_MAXVEL / STEPGEN_MAXACCEL) follows, and the
 * forward kinematics turns the step counts back into the platform pose (R, p). On the TMU
 * machine the tool is fixed and the platform carries the workpiece, so the tool seen from the
 * workpiece (the platform frame) has its tip at R^T (tip - p) and its axis along
 * R^T TOOL_AXIS. Those are the samples kept; the tool in the spindle (CANON_TOOL_CHANGE) gives
 * each sample its flat-end radius from the tool table.
 */

/* The tool at one servo period, in the workpiece (platform) frame. */
struct cut_sample {
    double tip[3];           /* tool tip centre, mm */
    double axis[3];          /* unit, from the spindle towards the tip */
    double radius_mm;        /* flat-end radius; 0 when no tool is in the spindle */
    int line;                /* program line being executed */
};

/* The swept tool over a whole program. */
struct cut_path {
    struct cut_sample *s;
    size_t n, cap;
    double max_step_mm;      /* largest leg step (1 / SCALE) of the drives, mm */
    double machining_time_s;
};
void cut_path_init(struct cut_path *p);
void cut_path_free(struct cut_path *p);

/* Runs prog on the machine (motion + stepgens + forward kinematics at the servo period) and
 * fills path. CHECK_OK, or a status with a message in err (fault, kinematics failure). */
int cut_simulate(struct check_machine *mc, const struct canon_prog *prog, struct cut_path *path,
                 char *err, size_t errlen);

/* Where the tool tip is, in the workpiece frame, when the platform is at pose (mm). */
int cut_tip_in_workpiece(struct check_machine *mc, const double pose[KINS_POSE_DIM],
                         double tip[3]);

/* A wall and where it is measured, in the workpiece frame: stations lie on the line
 * origin + s t at the height of the workpiece's top face (the paper measured on a top-view
 * photograph); the wall position is the furthest reach of the tool towards the material,
 * along n (unit, perpendicular to t and to the table normal), from the origin. */
struct cut_wall {
    double origin[3];        /* mm */
    double t[3];             /* unit, along the wall */
    double n[3];             /* unit, into the material */
    double top_z_mm;         /* top face height in the workpiece frame, mm */
    double ref_mm;           /* the reference line, mm along n: a cut whose near side lies
                              * beyond it is on the far side of the material, not this wall */
};
/* The wall position at station s_mm (along t from origin), mm along n; NAN when no tool
 * reached the station below the top face. Computed exactly for each sample's cylinder (radius,
 * axis) and at the instants the tool centre crosses the station between samples. */
double cut_wall_at(const struct cut_path *p, const struct cut_wall *w, double s_mm);

/* The mean of cut_wall_at() over n stations spread evenly across [s_mm - half_mm, s_mm +
 * half_mm]: the wall's line read over a short length, as on a photograph, which averages the
 * drives' step quantisation out of a single point. NAN if any station has no wall. */
double cut_wall_mean(const struct cut_path *p, const struct cut_wall *w, double s_mm,
                     double half_mm, int n);

#endif
