/* check_priv.h: the check library's machine struct and shared internals (inside check/ only). */
#ifndef HEXCNC_CHECK_PRIV_H
#define HEXCNC_CHECK_PRIV_H

#include "check/check.h"
#include "interp/interp_setup.h"

struct hal;
struct tooltable;
struct interp;

/* The machine of one INI: its reader, kinematics, motion and interpreter settings. */
struct check_machine {
    struct hal *hal;                 /* used only for its INI reader (no threads) */
    struct kins *kins;               /* loaded by name from [KINS] KINEMATICS */
    struct kins *real_kins;          /* the machine as built, if set: the cutting
                                      * simulation's forward kinematics (owned) */
    struct motion *motion;           /* the planner and interpolator the machine runs */
    struct motion_config mcfg;       /* its limits, from [EMCMOT] [TRAJ] [JOINT_n] */
    struct tooltable *tt;            /* [RS274NGC] TOOL_TABLE (empty when none) */
    struct interp_settings interp;   /* [RS274NGC] FEED_UNITS, TOOL_TABLE, PARAMETER_FILE,
                                      * applied to each program's interpreter as the runner
                                      * applies them (the parameter file read-only) */
    double cond_limit;               /* [KINS] SINGULAR_CONDITION */
    double scale[KINS_MAX_JOINTS];   /* [JOINT_n] SCALE, steps per mm (0 = none) */
    double drive_vel[KINS_MAX_JOINTS]; /* [JOINT_n] STEPGEN_MAXVEL, mm/s (0 = none) */
    double drive_acc[KINS_MAX_JOINTS]; /* [JOINT_n] STEPGEN_MAXACCEL, mm/s^2 (0 = none) */
    double tool_axis[3];             /* [KINS] TOOL_AXIS, unit (the spindle's direction) */
    char ini[256];
    struct interp **interps;         /* every interpreter used: the canonical commands point
                                      * at their file name, so they live as long as mc */
    size_t ninterps;
};

/* Whether a canonical command moves the machine. */
static inline int check_is_motion(enum canon_type t)
{
    return t == CANON_TRAVERSE || t == CANON_FEED || t == CANON_ARC;
}

/* Pose at fraction u in [0, 1] of move c starting at `from` (lines and arcs/helices). */
void check_move_pose(const double from[KINS_POSE_DIM], const struct canon_cmd *c, double u,
                     double pose[KINS_POSE_DIM]);

/* Static pass: every move sampled through the inverse kinematics; reach problems into r.
 * Returns the number of problems found. */
int check_scan_reach(struct check_machine *mc, const struct canon_prog *prog,
                     struct check_result *r);

/* Servo-rate pass through motion_step (the program must be loaded and started). */
int check_simulate(struct check_machine *mc, const double start[KINS_POSE_DIM],
                   const struct check_opts *o, struct check_result *r);

#endif
