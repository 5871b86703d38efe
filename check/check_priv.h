/* check_priv.h: the check library's machine struct and shared internals (inside check/ only). */
#ifndef HEXCNC_CHECK_PRIV_H
#define HEXCNC_CHECK_PRIV_H

#include "check/check.h"
#include "interp/interp_setup.h"

struct hal;
struct tooltable;
struct interp;
struct check_defer;

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

/* A line change takes the condition number once the pose is this far from where it was
 * last taken (the planner's knot spacing): check_sim.c measures, check_report.c says so. */
#define CHECK_COND_STEP_MM 1.0
#define CHECK_COND_STEP_DEG 0.5

/* CPU time the calling thread has used, s (the check's per-thread figures). */
double check_thread_cpu_s(void);

/* Whether a canonical command moves the machine. */
static inline int check_is_motion(enum canon_type t)
{
    return t == CANON_TRAVERSE || t == CANON_FEED || t == CANON_ARC;
}

/* Pose at fraction u in [0, 1] of move c starting at `from` (lines and arcs/helices). */
void check_move_pose(const double from[KINS_POSE_DIM], const struct canon_cmd *c, double u,
                     double pose[KINS_POSE_DIM]);

/* The reach pass one command at a time (a streamed check): where the previous move ended. */
struct check_reach {
    double from[KINS_POSE_DIM];
    int from_tcp;                    /* from is the tool tip under G43.4, this tool length */
    double from_len;
};
void check_reach_begin(struct check_reach *rs, const double start[KINS_POSE_DIM], int tcp,
                       double tool_len_mm);
/* A move's end and inside sampled through the inverse kinematics; problems into r. */
void check_reach_cmd(struct check_machine *mc, struct check_reach *rs, const struct canon_cmd *c,
                     struct check_result *r);

/* Static pass: every move sampled through the inverse kinematics; reach problems into r.
 * Returns the number of problems found. */
int check_scan_reach(struct check_machine *mc, const struct canon_prog *prog,
                     struct check_result *r);

/* What the servo-rate pass of a streamed program waits on (check_stream.c). */
struct check_feed {
    int (*wait)(void *ctx);          /* motion is short of plan: returns once it has more (1),
                                      * or 0 when no more will come (the pass stops) */
    double (*planned_s)(void *ctx);  /* the program's planned time once known, else < 0 */
    void *ctx;
    struct check_defer *defer;       /* the measures' ring, which the planner's thread
                                      * helps with (check_defer.h), or NULL: the pass's own */
};

/* Servo-rate pass through motion_step (the program must be loaded, or a stream attached,
 * and motion started; feed: NULL for a loaded program). */
int check_simulate(struct check_machine *mc, const double start[KINS_POSE_DIM],
                   const struct check_opts *o, const struct check_feed *feed,
                   struct check_result *r);

/* check_program with the whole program in memory (for a trace). */
int check_program_whole(struct check_machine *mc, const char *path,
                        const struct check_opts *opts, struct check_result *r);

/* A problem of kind CHECK_PLAN from motion's message, with the file and line it names:
 * the planner's refusal (stopped 0), or motion stopped at time_s before the program's end
 * (stopped 1; an empty message: it ran past twice the planned time). */
int check_add_plan_problem(struct check_result *r, const char *msg, int stopped, double time_s);

/* The result's header fields (configuration, tolerances, schedule) from the machine. */
void check_result_header(struct check_machine *mc, const struct check_opts *o,
                         struct check_result *r);

/* A new interpreter for one program, set up as the runner's (start at HOME, the kinematics'
 * tool, the INI's settings, its parameter file read-only); kept in mc (the commands point at
 * its file names). On failure pb says why. */
int check_machine_interp_new(struct check_machine *mc, struct interp **out,
                             struct check_problem *pb);

#endif
