/* check.h: verification of a program before cutting (interpreter -> motion -> kinematics, no drives). */
#ifndef HEXCNC_CHECK_H
#define HEXCNC_CHECK_H

#include <stddef.h>
#include <stdio.h>

#include "interp/canon.h"
#include "kins/kins.h"
#include "motion/motion.h"

/*
 * Use:
 *   struct check_machine *mc;  check_machine_open("tmu.ini", &mc, err, len);
 *   struct check_result res;   check_result_init(&res);
 *   check_program(mc, "part.ngc", &opts, &res);    every problem lands in res
 *   check_print_table(&res, stdout);  or  check_print_json(&res, stdout);
 *   check_result_free(&res);  check_machine_close(mc);
 *
 * The machine is the INI's: kinematics loaded by name ([KINS] KINEMATICS), motion limits from
 * [TRAJ]/[JOINT_n], [EMCMOT] SERVO_PERIOD, [RS274NGC] FEED_UNITS and TOOL_TABLE. The program
 * runs through motion_step() on a simulated clock at the servo period, exactly as the
 * machine's servo thread calls it, but without HAL threads or drives.
 */

/* Statuses of the check library; 0 is success. check_strerror() gives the text. */
enum check_status {
    CHECK_OK = 0,
    CHECK_ERR_NOMEM,         /* allocation failed */
    CHECK_ERR_CONFIG,        /* the INI is missing or a key in it is wrong */
    CHECK_ERR_KINS,          /* the kinematics could not be loaded or created */
    CHECK_ERR_IO,            /* a file could not be written (plots) */
    CHECK_ERR_VIOLATION,     /* the program has at least one problem (see the result) */
    CHECK_STATUS_COUNT
};
const char *check_strerror(int status);

/* Kinds of problem a program can have. check_kind_name() gives the JSON name. */
enum check_kind {
    CHECK_INTERP = 0,        /* the interpreter refused the program (file:line:col) */
    CHECK_UNREACHABLE,       /* a programmed end point lies outside the machine's reach */
    CHECK_LEG_RANGE,         /* a leg leaves its length range along a move */
    CHECK_LEG_VELOCITY,      /* a leg moves faster than [JOINT_n] MAX_VELOCITY */
    CHECK_LEG_ACCELERATION,  /* a leg accelerates harder than [JOINT_n] MAX_ACCELERATION */
    CHECK_SINGULAR,          /* a pose whose condition number exceeds SINGULAR_CONDITION */
    CHECK_PLAN,              /* the planner refused the program for another reason */
    CHECK_TIP_DEVIATION,     /* a warning: the tool tip leaves a straight feed's line
                              * beyond KINEMATIC_TOLERANCE (A B C turned without G43.4) */
    CHECK_LEG_JERK,          /* a leg's jerk exceeds [JOINT_n] MAX_JERK (when set) */
    CHECK_KIND_COUNT
};
const char *check_kind_name(enum check_kind k);

/* One problem, reported once per (kind, line, leg) with its worst value. */
struct check_problem {
    enum check_kind kind;
    char file[256];          /* program file ("" when not known) */
    int line;                /* 1-based program line, 0 when not known */
    int column;              /* 1-based column (interpreter errors), 0 when not known */
    int leg;                 /* 0-based leg, -1 when the problem is not about one leg */
    double value;            /* worst value: mm, mm/s, mm/s^2 or condition number */
    double limit;            /* the limit it broke, same unit */
    double time_s;           /* machine time of the worst value, s (-1: found before motion) */
    int count;               /* servo periods / samples with this problem */
    char message[400];       /* one line in a machinist's words */
};

/* Figures of one leg over the whole program. */
struct check_leg {
    double min_mm, max_mm;           /* shortest and longest commanded length, mm */
    double peak_vel_mm_s;            /* largest |rate| from successive set points, mm/s */
    double peak_acc_mm_s2;           /* largest |change of rate| per period, mm/s^2 */
    double peak_jerk_mm_s3;          /* largest |change of acceleration| per period, mm/s^3 */
    double limit_jerk_mm_s3;         /* [JOINT_n] MAX_JERK, mm/s^3 (0: none) */
    double planned_acc_mm_s2;        /* the acceleration motion plans the leg to: its
                                      * MAX_ACCELERATION, or under [TRAJ] JERK_WINDOW
                                      * MAX_JERK x window / 2 where lower */
    double limit_min_mm, limit_max_mm, limit_vel_mm_s, limit_acc_mm_s2; /* from the INI */
    const char *vel_key, *acc_key;   /* the INI keys of the rate limits: MAX_VELOCITY, or
                                      * STEPGEN_MAXVEL when the drive's limit is lower */
};

/* How and how often the costly measures are taken. */
struct check_opts {
    double deviation_every_s;        /* kinematic deviation at least this often, s; 0 = at
                                      * every servo period (the exhaustive measure) */
    double condition_every_s;        /* condition number at least this often, s; 0 = every
                                      * servo period */
    int cold_forward;                /* 1: forward kinematics started from home each time
                                      * (for comparison; the default warm start is faster) */
    int solve_every_condition;       /* 1: every condition number solved (for comparison;
                                      * by default a bound from the last one solved answers
                                      * where solving could change nothing) */
    int legs_every_period;           /* 1: the legs tested period by period (for comparison;
                                      * by default in batches of periods, the same results) */
    struct check_trace *trace;       /* optional: filled with samples for plots */
};
/* The defaults: deviation every 50 ms, condition number every 500 ms, and both at every change
 * of program line (docs/verification.md says why that is enough). */
void check_opts_default(struct check_opts *o);

/* Everything the check found. */
struct check_result {
    struct check_problem *problems;  /* in the order found */
    size_t nproblems, capproblems;
    struct check_problem *warnings;  /* what may not be meant but the machine can do (the
                                      * tool tip's swing without G43.4): reported, the
                                      * program still passes */
    size_t nwarnings, capwarnings;
    size_t *pindex, *windex;         /* hash slots of problems and warnings by kind, file,
                                      * line and leg (entry + 1, 0 empty): merging stays
                                      * O(1) when a program has warnings on every line */
    size_t pindex_cap, windex_cap;
    int simulated;                   /* 1 if the program was run through motion */
    char program[256];               /* program path */
    char config[256];                /* INI path */
    int njoints;
    struct check_leg leg[KINS_MAX_JOINTS];
    double machining_time_s;         /* machine time from start to the end of motion, s */
    double planned_time_s;           /* the planner's figure, s */
    double length_mm;                /* XYZ path length, mm */
    long periods;                    /* servo periods simulated */
    double servo_period_s;
    double max_deviation_mm;         /* largest kinematic deviation from the programmed path */
    int max_deviation_line;          /* its program line */
    double max_deviation_deg;        /* same for the orientation, deg */
    int tip_measured;                /* the kinematics has a tool: the tip was measured */
    double max_tip_deviation_mm;     /* the tool tip's largest deviation from its path: a
                                      * straight feed's line between the tip's positions at
                                      * its ends (the programmed line under G43.4), else the
                                      * chord between set points; by forward kinematics of
                                      * the legs interpolated between set points, and every
                                      * period from the commanded pose */
    int max_tip_deviation_line;
    double kin_tol_mm;               /* [TRAJ] KINEMATIC_TOLERANCE, for reference */
    double jerk_window_s;            /* the jerk limits' moving average, s (0: no jerk
                                      * limits); jerk_window_set: from [TRAJ] JERK_WINDOW */
    int jerk_window_set;
    double jerk_full_window_s;       /* the window with every acceleration in full, s */
    long deviation_evals;            /* forward solves spent on the deviation */
    double max_condition;            /* largest condition number seen */
    int max_condition_line;
    double condition_limit;          /* [KINS] SINGULAR_CONDITION */
    long condition_evals;
    long condition_bounded;          /* of them, answered by a bound from the last one solved
                                      * (check_sim.c: it could change neither the largest
                                      * nor the verdict) */
    double deviation_every_s, condition_every_s; /* the schedule used */
    double servo_cpu_s;              /* CPU time of the servo-rate pass's thread, s */
    double plan_cpu_s;               /* CPU time of the reach pass and the planner, s (a
                                      * streamed check: their thread's, the interpreter's
                                      * too) */
};
void check_result_init(struct check_result *r);
void check_result_free(struct check_result *r);
/* Number of problems (0: the program is fine). */
static inline size_t check_problem_count(const struct check_result *r) { return r->nproblems; }

/* The machine as the INI describes it, without HAL threads or drives. */
struct check_machine;
int check_machine_open(const char *ini_path, struct check_machine **out, char *err,
                       size_t errlen);
void check_machine_close(struct check_machine *mc);
struct kins *check_machine_kins(struct check_machine *mc);
/* The machine as built, when its geometry differs from the controller's (calibration
 * studies): the cutting simulation turns drive feedback into the platform pose through
 * real's forward kinematics. mc takes ownership (freed by close); NULL = the controller's. */
void check_machine_set_real(struct check_machine *mc, struct kins *real);
struct motion *check_machine_motion(struct check_machine *mc);
const struct motion_config *check_machine_motion_config(const struct check_machine *mc);
/* Stepgen steps per mm of leg n ([JOINT_n] SCALE), 0 when not given. */
double check_machine_scale(const struct check_machine *mc, int joint);
/* Effective radius of tool `tool` from [RS274NGC] TOOL_TABLE, mm; -1 if no such tool. */
double check_machine_tool_radius(struct check_machine *mc, int tool);
/* Interprets a whole program into prog (start: the kinematics' home pose). On failure
 * returns CHECK_ERR_VIOLATION and fills *problem (kind CHECK_INTERP) with file:line:col. */
int check_machine_interpret(struct check_machine *mc, const char *path, struct canon_prog *prog,
                            struct check_problem *problem);
/* The same for G-code text held in memory; name is used in messages. */
int check_machine_interpret_text(struct check_machine *mc, const char *name, const char *text,
                                 size_t len, struct canon_prog *prog,
                                 struct check_problem *problem);

/* Checks a program: returns CHECK_OK when it has no problem, CHECK_ERR_VIOLATION when it
 * has (all of them in res), another status when the check itself failed (message in res as
 * a CHECK_PLAN problem). opts may be NULL (defaults). */
int check_program(struct check_machine *mc, const char *path, const struct check_opts *opts,
                  struct check_result *res);
/* The same on an already interpreted program (bench, tests). */
int check_canon(struct check_machine *mc, const struct canon_prog *prog,
                const struct check_opts *opts, struct check_result *res);

/* Adds a problem, merging it with one of the same kind, line and leg (keeps the worst). */
int check_add_problem(struct check_result *r, const struct check_problem *p);
/* The same for a warning. */
int check_add_warning(struct check_result *r, const struct check_problem *p);

/* Human table and machine-readable JSON (schema in docs/verification.md). */
void check_print_table(const struct check_result *r, FILE *f);
void check_print_json(const struct check_result *r, FILE *f);

#endif
