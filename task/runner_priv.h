/* runner_priv.h: the runner's state, shared by runner.c (setup) and runner_exec.c (running). */
#ifndef HEXCNC_TASK_RUNNER_PRIV_H
#define HEXCNC_TASK_RUNNER_PRIV_H

#include <pthread.h>
#include <stdatomic.h>
#include <sys/types.h>

#include "hal/hal.h"
#include "interp/interp.h"
#include "task/runner.h"

/* What a verification pass of a streamed program was made for (runner_stream.c): the file,
 * the files the interpreter starts from and the start pose; a run of the same starts at
 * once, anything else is checked again. */
struct runner_check {
    bool valid;
    char path[1024];
    dev_t dev;
    ino_t ino;
    off_t size;
    int64_t mtime_ns, ctime_ns;
    uint64_t files_ns;                  /* tool table and parameter file, folded */
    double start[KINS_POSE_DIM];
    struct motion_plan_info info;       /* the program's time, length, segments */
    size_t settings;                    /* CANON_SETTING commands it holds */
};
struct runner_stream;

/* Running from a line: the modal commands of the lines before from_line pass, their moves
 * and settings do not, and a rapid to where they would have left the machine comes first.
 * One command at a time, for the whole-program load (runner.c) and the stream alike. */
struct runner_cut {
    int from_line;                      /* 1: the whole program, nothing cut */
    bool started;                       /* from_line (or a later line) reached */
    double at[KINS_POSE_DIM];           /* where the cut moves would have ended */
    int last_comp;                      /* the last cut move was G141/G142's */
};
enum runner_cut_action { RUNNER_CUT_DROP, RUNNER_CUT_KEEP, RUNNER_CUT_RAPID_FIRST };
void runner_cut_init(struct runner_cut *cut, int from_line, const double start[KINS_POSE_DIM]);
/* What becomes of c; for RUNNER_CUT_RAPID_FIRST, *go is the rapid to put before c. Returns
 * an action, or -1 with the message in err (a start inside a G141/G142 run). */
int runner_cut_step(struct runner_cut *cut, const struct canon_cmd *c, struct canon_cmd *go,
                    char *err, size_t errlen);

/* The machine, the program and what the monitor has seen. */
struct runner {
    struct hal *hal;                    /* the runtime (owns kins and motion) */
    struct kins *kins;                  /* the machine's kinematics (HAL object "kins") */
    struct motion *motion;              /* the motion instance (HAL object "motion") */
    int njoints;                        /* legs */
    bool sim_clock;                     /* simulated clock, else real time */
    long period_ns;                     /* [EMCMOT] SERVO_PERIOD */
    char thread[32];                    /* the thread the monitor runs on */
    char default_program[1024];         /* [DISPLAY] OPEN_FILE, resolved; "" when none */
    bool loaded;                        /* a program is planned */
    bool started;                       /* runner_start succeeded */
    bool aborting;                      /* runner_abort was called */
    long ready_since;                   /* monitor periods when the drives were first seen
                                         * ready after the start; -1 not yet */
    const volatile sig_atomic_t *cancel; /* the operator's stop request, or NULL */
    long pre_periods;                   /* periods run before the first start, machine off
                                         * (runner_feedback_settle) */
    bool block_delete;                  /* the block-delete switch for the next load */
    runner_message_fn msg_fn;           /* gets every component message (may be NULL) */
    void *msg_ctx;
    char first_fault[300];              /* "source: text" of the first fault message: the cause */
    struct motion_plan_info plan;       /* the loaded program's plan */
    struct interp *interp;              /* the interpreter of the loaded program: it owns the
                                         * file names the plan's moves point at, so it lives
                                         * until the next program or runner_destroy */

    /* A streamed program (runner_stream.c) and its verification pass. */
    struct runner_stream *stream;       /* the run's planner thread, NULL when none */
    struct runner_check checked;        /* the last verification pass */

    /* Settings the program writes (runner_settings.c), saved as execution reaches them. */
    pthread_mutex_t settings_lock;      /* settings grows on a streamed run's planner thread */
    struct canon_prog settings;         /* the program's CANON_SETTING commands, in order */
    struct interp *store;               /* applies and saves them: set up with the machine's
                                         * parameter file and tool table (NULL: none) */
    struct tooltable *store_tt;         /* its tool table */
    size_t settings_applied;            /* settings saved so far in this run */
    char save_err[800];                 /* why a save failed ("" when none has) */
    FILE *log;                          /* the program's (LOGOPEN,) file, open ("" NULL) */

    /* The task's own pins, as LinuxCNC's iocontrol: the HAL files wire them to the e-stop
     * chain. user-enable-out is the operator's "machine on"; user-request-enable pulses for
     * one period to reset the latch; emc-enable-in reports the chain. */
    bool *user_enable_out;              /* out: task.user-enable-out */
    bool *user_request_enable;          /* out: task.user-request-enable (one-period pulse) */
    bool *emc_enable_in;                /* in: task.emc-enable-in */

    /* Pin data the monitor reads (the signals' storage once the HAL files are loaded). */
    const double *cmd_pin[KINS_MAX_JOINTS];  /* motion.joint-pos-cmd-N, mm */
    const double *fb_pin[KINS_MAX_JOINTS];   /* motion.joint-pos-fb-N, mm */

    /* Written by the monitor funct (servo thread), read by the caller. */
    double prev_cmd_mm[KINS_MAX_JOINTS];     /* last period's leg commands */
    double rate_mm_s[KINS_MAX_JOINTS];       /* this period's commanded leg rates */
    bool have_prev;                          /* prev_cmd_mm is valid */
    struct runner_summary sum;               /* peaks and extremes so far */
    _Atomic long running_periods;            /* periods since the program started moving */
    _Atomic int mon_state;                   /* enum motion_state after the last period */
    _Atomic int mon_line;                    /* program line after the last period */
    _Atomic long mon_periods;                /* periods run since start */
    _Atomic double mon_distance_mm;          /* path length covered after the last period */
    const char *_Atomic mon_file;            /* program file of the line being executed */
    _Atomic size_t mon_settings;             /* settings motion has passed (motion_out) */
    struct motion_out last;                  /* motion's output after the last period */

    runner_observer_fn observer;             /* called every period (may be NULL) */
    void *observer_ctx;
};

/* Registers the monitor funct and adds it last on the servo thread (runner_exec.c). */
int runner_monitor_install(struct runner *r, char *err, size_t errlen);

/* Whether the motion core is under way (running, pausing, paused, stopping). */
bool runner_moving(const struct runner *r);

/* A value of the INI that names a file: as is when absolute, else from the INI's folder. */
void runner_ini_path(const struct runner *r, const char *value, char *out, size_t len);
/* A fresh interpreter for a program from start, set up as every program's is (runner.c);
 * *tt_out is its tool table, to free once the interpreter no longer uses it. */
int runner_new_interp(struct runner *r, const double start[KINS_POSE_DIM], struct interp **out,
                      struct tooltable **tt_out, char *err, size_t errlen);

/* Applies [RS274NGC] FEED_UNITS, TOOL_TABLE and PARAMETER_FILE to an interpreter (runner.c). */
struct tooltable;
int runner_setup_interp(struct runner *r, struct interp *in, struct tooltable *tt, char *err,
                        size_t errlen);

/* runner_settings.c: the program's settings, checked at load, saved as they execute. */
int runner_settings_load(struct runner *r, const struct canon_prog *prog, char *err,
                         size_t errlen);
void runner_settings_apply(struct runner *r);
void runner_settings_free(struct runner *r);
/* What a setting does, in words ("changes the tool table", "opens a log file"). */
const char *runner_setting_what(const struct canon_setting *s);
/* Closes the program's log file, if one is open. */
void runner_log_close(struct runner *r);
/* The interpreter settings are saved through, for a streamed run (its settings come later). */
int runner_settings_store(struct runner *r, char *err, size_t errlen);


/* Starts the threads with the machine off until the motion component follows the legs'
 * feedback (runner_exec.c); nothing when they run already. */
void runner_feedback_settle(struct runner *r);

#endif
