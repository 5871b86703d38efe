/* runner.h: runs a program on a machine described by an INI file (the task layer). */
#ifndef HEXCNC_TASK_RUNNER_H
#define HEXCNC_TASK_RUNNER_H

#include <signal.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "hal/hal.h"
#include "kins/kins.h"
#include "motion/motion.h"

/*
 * What `hexcnc run` does, as a library so that tests and benchmarks drive the same code:
 *
 *   runner_create(&opts, &r, err, len)    INI, HAL runtime, HAL files in [HAL] HALFILE order
 *   runner_load_program(r, path, ...)     interprets the WHOLE program, then plans it: any
 *                                         error (file:line) comes here, before any motion
 *   runner_start(r, ...)                  starts the threads and the program
 *   runner_run(r, &stop, progress, ctx, ..) runs to the end (or a fault, or *stop: the
 *                                         controlled stop of Ctrl-C)
 *   runner_summary(r, &s)                 machine time, distance, peaks, final pose
 *   runner_destroy(r)
 *
 * A monitor funct (`runner.monitor`, last on the servo thread) samples every period: leg
 * commands and feedback, leg rates, following error, the program line. Tests can add an
 * observer that sees every period.
 */

enum runner_status {
    RUNNER_OK = 0,
    RUNNER_ERR_NOMEM,        /* allocation failed */
    RUNNER_ERR_CONFIG,       /* the INI file is missing or a key in it is wrong */
    RUNNER_ERR_HAL,          /* a HAL file failed (the message names file and line) */
    RUNNER_ERR_PROGRAM,      /* the interpreter refused the program (file:line: what) */
    RUNNER_ERR_PLAN,         /* the program cannot run: unreachable pose, leg limits */
    RUNNER_ERR_STATE,        /* not allowed now (start without a program, ...) */
    RUNNER_ERR_RT,           /* the threads could not be started */
    RUNNER_ERR_FAULT,        /* the machine faulted while running (following error, e-stop) */
    RUNNER_ERR_ABORTED,      /* the operator stopped the program (Ctrl-C) */
    RUNNER_ERR_TIMEOUT,      /* the machine did not finish in twice the planned time */
    RUNNER_STATUS_COUNT
};
const char *runner_strerror(int status);

/* Which clock drives the servo thread. */
enum runner_clock {
    RUNNER_CLOCK_INI = 0,    /* [EMCMOT] SIM_CLOCK decides (1 = simulated, else real time) */
    RUNNER_CLOCK_SIM,        /* simulated: exact machine time, as fast as the CPU allows */
    RUNNER_CLOCK_REALTIME,   /* paced on the wall clock */
};

struct runner_opts {
    const char *ini_path;    /* the machine's INI file */
    enum runner_clock clock;
};

/* One servo period as the monitor saw it (for observers). */
struct runner_sample {
    int64_t time_ns;                         /* machine time at the end of the period */
    int njoints;
    const double *joint_cmd_mm;              /* leg commands, [njoints] */
    const double *joint_fb_mm;               /* leg feedback, [njoints] */
    const double *joint_rate_mm_s;           /* commanded leg rates, [njoints] */
    int line;                                /* program line being executed (0 before) */
    enum motion_state state;
};
typedef void (*runner_observer_fn)(void *ctx, const struct runner_sample *s);

/* Where the program is, for progress displays. */
struct runner_progress {
    enum motion_state state;
    int line;                /* program line being executed */
    const char *file;        /* its file (NULL before the first move) */
    double elapsed_s;        /* machine time since start */
    double remaining_s;      /* from the plan */
    double percent;          /* of the planned path length (of the time when no length) */
};

/* What a run did. */
struct runner_summary {
    double machine_time_s;                   /* from start to the end of motion */
    double planned_time_s;                   /* what the planner said it would take */
    double distance_mm;                      /* XYZ path length covered */
    long periods;                            /* servo periods run, with those before the
                                              * start (machine off, drives starting) */
    int njoints;
    double peak_rate_mm_s[KINS_MAX_JOINTS];  /* largest |commanded leg rate| per leg */
    double max_ferror_mm[KINS_MAX_JOINTS];   /* largest |command - feedback| per leg */
    double leg_min_mm[KINS_MAX_JOINTS];      /* shortest commanded leg length seen */
    double leg_max_mm[KINS_MAX_JOINTS];      /* longest commanded leg length seen */
    double final_legs_mm[KINS_MAX_JOINTS];   /* leg feedback at the end */
    double final_cmd_pose[KINS_POSE_DIM];    /* the pose motion commanded last */
    double final_pose[KINS_POSE_DIM];        /* forward kinematics of the final feedback */
    int final_pose_ok;                       /* 0 when the forward solve failed */
    enum motion_state state;                 /* DONE, IDLE (after a stop), FAULT */
};

struct runner;

/* Reads the INI, creates the HAL runtime and loads the HAL files. On failure err says
 * which file, which line and what is wrong. */
int runner_create(const struct runner_opts *opts, struct runner **out, char *err,
                  size_t errlen);
void runner_destroy(struct runner *r);

/* The runtime, the kinematics and the motion instance of the machine (borrowed). */
struct hal *runner_hal(struct runner *r);
struct kins *runner_kins(struct runner *r);
struct motion *runner_motion(struct runner *r);
/* Whether the servo thread runs on the simulated clock. */
bool runner_sim_clock(const struct runner *r);

/* The program [DISPLAY] OPEN_FILE names (resolved against the INI's folder), or NULL. */
const char *runner_default_program(const struct runner *r);

/* Interprets the whole program (with [RS274NGC] FEED_UNITS, TOOL_TABLE, PARAMETER_FILE)
 * and plans it. Nothing moves; on failure err holds "file:line: what". */
int runner_load_program(struct runner *r, const char *path, char *err, size_t errlen);
/* The same from line from_line on (run from line): the whole program is interpreted, so the
 * modal state of the lines before it is rebuilt (units, offsets, tool, feed, spindle); their
 * moves and settings are left out, and a rapid move from the present pose to where line
 * from_line starts comes first, checked like any move. Refused inside a G141/G142 run. */
int runner_load_program_from(struct runner *r, const char *path, int from_line, char *err,
                             size_t errlen);
/* Plans an interpreted program (MDI): its settings are saved as they execute. */
int runner_load_canon(struct runner *r, const struct canon_prog *prog, char *err,
                      size_t errlen);
/* Block delete switch for the programs loaded next. */
void runner_set_block_delete(struct runner *r, bool on);
/* The operator's stop request (Ctrl-C) for runner_load_program: a flag the caller's signal
 * handler sets (NULL: none). The interpreter checks it before every line and the planner at
 * every command and knot; once set, loading ends with RUNNER_ERR_ABORTED and nothing moves.
 * Not owned. */
void runner_set_cancel(struct runner *r, const volatile sig_atomic_t *flag);

/* Programs are held whole in memory until they stream: about this many bytes of memory
 * per byte of G-code (a 25-byte block becomes a 216-byte command, a 248-byte segment and
 * at least two knots of 112 bytes while it is planned). */
#define RUNNER_BYTES_PER_PROGRAM_BYTE 30
/* [TASK] MAX_PROGRAM_MB when the INI has none: the largest program file loaded, MB. */
#define RUNNER_MAX_PROGRAM_MB 64
/* The plan of the loaded program. */
int runner_plan_info(const struct runner *r, struct motion_plan_info *out);

/* Sets the observer called after every servo period (NULL to remove). */
void runner_set_observer(struct runner *r, runner_observer_fn fn, void *ctx);
/* Event codes the runner posts on HEXCNC_EVENT (source "task") when lcm-status is loaded;
 * components' messages are forwarded with RUNNER_EVENT_MESSAGE and their own source. */
enum runner_event_code {
    RUNNER_EVENT_STARTED = 100,     /* the program started moving */
    RUNNER_EVENT_FINISHED = 101,    /* the program ran to its end */
    RUNNER_EVENT_FAULT = 102,       /* the machine stopped on a fault (text: the cause) */
    RUNNER_EVENT_ABORTED = 103,     /* the operator stopped the program */
    RUNNER_EVENT_MESSAGE = 110,     /* a component's message */
};

/* Components' messages (drive faults, lost nodes, warnings), handed to fn from runner_run
 * as they arrive; the first fault also becomes the cause in runner_run's error message. */
typedef void (*runner_message_fn)(void *ctx, const struct hal_msg *m);
void runner_set_message_fn(struct runner *r, runner_message_fn fn, void *ctx);

/* Starts the threads and the loaded program. */
int runner_start(struct runner *r, char *err, size_t errlen);
/* Runs the machine for dt_s of machine time (simulated) or wall time (real time). */
int runner_advance(struct runner *r, double dt_s);
/* Asks for the controlled stop: decelerate along the path, then drop the program. */
int runner_abort(struct runner *r);
/* Whether the machine has come to rest for good (done, stopped, faulted). */
bool runner_finished(const struct runner *r);
int runner_get_progress(const struct runner *r, struct runner_progress *p);

/* Called by runner_run after every slice of the run (10 servo periods of machine time on
 * the simulated clock, about 20 ms in real time) and once at the end: displays throttle. */
typedef void (*runner_progress_fn)(void *ctx, const struct runner_progress *p);
/* Runs until the machine is finished. *stop (may be NULL), set by a signal handler,
 * requests the controlled stop. Returns RUNNER_OK when the program ended, RUNNER_ERR_ABORTED
 * after a stop, RUNNER_ERR_FAULT after a fault; err then says why (leg, amount, line). */
int runner_run(struct runner *r, const volatile sig_atomic_t *stop, runner_progress_fn fn,
               void *ctx, char *err, size_t errlen);

/* What the run did (valid during and after it). */
int runner_summary(struct runner *r, struct runner_summary *s);

/* Programs that stream (runner_stream.c): read and planned window by window, in bounded
 * memory, whatever their length.
 *   runner_check_stream(r, path, &info, ...)   the verification pass over the whole file
 *                                              from where the machine is: every error
 *                                              (file:line) here, nothing moves
 *   runner_stream_start(r, path, from_line, ...) checks again unless the file, the tool
 *                                              table, the parameter file and the start pose
 *                                              are those of the last check; then starts the
 *                                              planner thread and returns once the first
 *                                              part is planned; runner_start starts it
 *   runner_stream_close(r)                     once the run has ended (done, aborted, fault)
 */
int runner_check_stream(struct runner *r, const char *path, struct motion_plan_info *info,
                        char *err, size_t errlen);
int runner_stream_start(struct runner *r, const char *path, int from_line, char *err,
                        size_t errlen);
void runner_stream_close(struct runner *r);
/* Whether the last verification pass holds for path as it is now, from where the machine
 * is (runner_stream_start would start without checking again). */
bool runner_stream_checked(struct runner *r, const char *path);
/* The planner thread's error, once it has stopped on one (RUNNER_OK otherwise). */
int runner_stream_outcome(const struct runner *r, char *err, size_t errlen);
/* Whether the machine waits at rest for a part of the program the producer will never
 * plan: it stopped on an error after a sync (a probe that found nothing, G38.2). */
bool runner_stream_stalled(const struct runner *r);
/* Whether the machine is about to run out of planned path while the planner still works
 * (a simulated clock waits for it). */
bool runner_stream_starving(const struct runner *r);

#endif
