/* motion.h: the segment queue, velocity planner and servo-period interpolator (no HAL). */
#ifndef HEXCNC_MOTION_H
#define HEXCNC_MOTION_H

#include <signal.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "interp/canon.h"
#include "kins/kins.h"

/*
 * Use:
 *   struct motion_config c;  motion_config_default(&c);  (or motion_config_read(&c, &get, ..))
 *   motion_create(&c, kins, &m, err, len);      kins stays the caller's, must outlive m
 *   motion_load(m, &prog, err, len);            plans the whole program; a program that cannot
 *                                                run (unreachable pose, leg limits) fails here,
 *                                                naming file and line, before any motion
 *   motion_start(m);
 *   every servo period: motion_feedback(m, legs_fb);  motion_step(m, period_s, &out);
 *   motion_pause / motion_resume / motion_abort / motion_set_feed_override / motion_estop
 *   motion_destroy(m);
 * Nothing here allocates or plans after motion_load: motion_step is cheap and bounded.
 */

/* Every call returns one of these; 0 is success. motion_strerror() gives the text. */
enum motion_status {
    MOTION_OK = 0,
    MOTION_ERR_NOMEM,        /* allocation failed */
    MOTION_ERR_CONFIG,       /* a configuration value is missing or wrong (message names it) */
    MOTION_ERR_ARG,          /* bad argument (NULL, NaN, negative period) */
    MOTION_ERR_STATE,        /* not allowed in this state (e.g. load while running) */
    MOTION_ERR_PROGRAM,      /* the program holds a move that cannot be planned (zero feed,
                              * degenerate arc); message names file and line */
    MOTION_ERR_UNREACHABLE,  /* a pose along a move is outside the workspace */
    MOTION_ERR_KINS,         /* the kinematics failed otherwise (singular, ...) */
    MOTION_ERR_FERROR,       /* following error beyond its limit: fault */
    MOTION_ERR_ESTOP,        /* emergency stop: fault */
    MOTION_ERR_CANCELLED,    /* the cancel flag was set (Ctrl-C) while planning */
    MOTION_ERR_STARVED,      /* a streamed program's next part was not planned in time: the
                              * machine stopped on the path at the end of what was planned */
    MOTION_ERR_INDEX,        /* a synchronised move asked for the spindle encoder's index and
                              * the spindle turned MOTION_INDEX_WAIT_REVS without one */
    MOTION_STATUS_COUNT
};
const char *motion_strerror(int status);

/* What the machine is doing. */
enum motion_state {
    MOTION_IDLE = 0,         /* holding still; a loaded program waits for motion_start */
    MOTION_RUNNING,          /* following the program */
    MOTION_PAUSING,          /* decelerating along the path to a pause */
    MOTION_PAUSED,           /* stopped on the path (pause, M0/M1); motion_resume continues */
    MOTION_STOPPING,         /* decelerating along the path after motion_abort */
    MOTION_DONE,             /* program end reached */
    MOTION_FAULT,            /* e-stop or following error: stopped, see motion_last_error */
    MOTION_MANUAL,           /* manual motion under way: a jog, homing, a move to a pose
                              * (motion_manual.c); back to IDLE at rest */
    MOTION_STATE_COUNT
};
const char *motion_state_name(enum motion_state s);

/* Limits of one joint (leg), from [JOINT_n]. */
struct motion_joint_config {
    double max_vel_mm_s;     /* MAX_VELOCITY, mm/s (deg/s for a rotary joint of trivial kins) */
    double max_acc_mm_s2;    /* MAX_ACCELERATION, mm/s^2 */
    double max_jerk_mm_s3;   /* MAX_JERK, mm/s^3; 0: none (jerk limiting off) */
    double ferror_mm;        /* FERROR: following-error limit at MAX_VELOCITY, mm */
    double min_ferror_mm;    /* MIN_FERROR: following-error limit at standstill, mm */
    /* Homing ([JOINT_n] HOME_*, docs/machine.md). search_vel 0: no switch (absolute). */
    double home_search_vel;  /* mm/s, signed: the direction towards the switch */
    double home_latch_vel;   /* mm/s, signed: same sign approaches again, opposite latches on
                              * the release */
    double home_final_vel;   /* mm/s of the move to HOME after the latch */
    double home_offset;      /* leg length where the switch latches, mm */
    double home_pos;         /* leg length after homing, mm (NAN: the leg's length at the
                              * kinematics' home pose) */
    double home_search_mm;   /* travel without a switch after which homing faults, mm */
    int home_sequence;       /* legs home in groups of equal |sequence|, lowest first */
    int home_absolute;       /* HOME_ABSOLUTE_ENCODER: homed without motion */
};

/* Everything the planner needs, filled by the caller (or by motion_config_read). */
struct motion_config {
    double servo_period_s;          /* [EMCMOT] SERVO_PERIOD (ns in the INI), s */
    double setpoint_period_s;       /* [TRAJ] SETPOINT_PERIOD: drive set-point period, s;
                                     * 0 = servo period */
    double max_lin_vel_mm_s;        /* [TRAJ] MAX_LINEAR_VELOCITY, mm/s (also the rapid rate) */
    double max_lin_acc_mm_s2;       /* [TRAJ] MAX_LINEAR_ACCELERATION, mm/s^2 */
    double max_ang_vel_deg_s;       /* [TRAJ] MAX_ANGULAR_VELOCITY, deg/s, per rotary axis */
    double max_ang_acc_deg_s2;      /* [TRAJ] MAX_ANGULAR_ACCELERATION, deg/s^2 */
    double max_lin_jerk_mm_s3;      /* [TRAJ] MAX_LINEAR_JERK, mm/s^3; 0: none. Jerk limiting
                                     * is on when this, max_ang_jerk_deg_s3 and every joint's
                                     * max_jerk_mm_s3 are set, off when none is */
    double max_ang_jerk_deg_s3;     /* [TRAJ] MAX_ANGULAR_JERK, deg/s^3; 0: none */
    double jerk_window_s;           /* [TRAJ] JERK_WINDOW, s: the jerk limits' moving average,
                                     * up to the longest 2 x acceleration / jerk, every
                                     * acceleration lowered to jerk x window / 2 where above
                                     * (motion_jerk_share); 0: the default window
                                     * (motion_jerk_default_window_s) */
    double default_lin_vel_mm_s;    /* [TRAJ] DEFAULT_LINEAR_VELOCITY, mm/s: feed of a move
                                     * programmed before any F word (canon feed 0) */
    double kin_tol_mm;              /* [TRAJ] KINEMATIC_TOLERANCE, mm: largest deviation of the
                                     * tool point from the programmed path when the drives move
                                     * legs linearly between set points; <= 0 disables the
                                     * limiter (for comparison only) */
    double kin_tol_deg;             /* [TRAJ] KINEMATIC_ANGULAR_TOLERANCE, deg: the same for
                                     * orientation */
    double blend_tol_mm;            /* [TRAJ] BLEND_TOLERANCE, mm: G64 tolerance used when the
                                     * program gives G64 without P (canon value 0) */
    int optional_stop;              /* [TRAJ] OPTIONAL_STOP: 1 = M1 pauses like M0 (default) */
    int num_dio, num_aio;           /* [EMCMOT] NUM_DIO, NUM_AIO: outputs M62..M68 may set */
    /* Spindle-synchronised moves (G33, G33.1; motion_sync.c). NAN: not given, and a program
     * with such a move is refused naming the key (they protect the thread and the tap). */
    double spindle_acc_rpm_s;       /* [SPINDLE_SYNC] ACCELERATION: how fast the spindle
                                     * changes speed, rpm/s (how far a tap runs on while the
                                     * spindle reverses) */
    double spindle_speed_margin;    /* [SPINDLE_SYNC] SPEED_MARGIN: how much faster than
                                     * commanded the spindle may turn, a fraction (0.1: 10 %);
                                     * the path's speed limits must hold at that speed */
    int njoints;                    /* joints configured (the kinematics' count) */
    struct motion_joint_config joint[KINS_MAX_JOINTS]; /* [JOINT_0..] */
};

/* Sensible defaults: 1 kHz, 100 mm/s, 1000 mm/s^2, 30 deg/s, 0.001 mm, 6 legs of 100 mm/s,
 * 1000 mm/s^2, FERROR 1 mm, MIN_FERROR 0.1 mm. */
void motion_config_default(struct motion_config *c);
/* Reads the keys listed above through cfg->get (the INI: [EMCMOT], [TRAJ], [JOINT_n] for
 * n < njoints); absent keys keep the defaults. MOTION_ERR_CONFIG with a message naming
 * [SECTION]KEY when a value is not a positive number. */
int motion_config_read(struct motion_config *c, const struct kins_config *cfg, int njoints,
                       char *err, size_t errlen);

/* Jerk limiting (motion_jerk.c): the length of the moving average the legs' and the pose's
 * set points go through, s (0: jerk limiting off). With it no leg's jerk, measured by
 * differencing the set points period by period, exceeds MAX_JERK wherever the unfiltered
 * motion keeps its acceleration limits. */
double motion_jerk_window_s(const struct motion_config *c);
/* The window in which every acceleration may be used in full: the longest 2 x acceleration /
 * jerk, s (0: jerk limiting off). [TRAJ] JERK_WINDOW may be shorter, not longer. */
double motion_jerk_full_window_s(const struct motion_config *c);
/* The window without [TRAJ] JERK_WINDOW (not yet in whole periods), s: the path's and A B C's
 * 2 x acceleration / jerk, and each leg's with its acceleration no higher than
 * MAX_LINEAR_ACCELERATION, but no shorter than 20 ms or the full window, whichever is shorter
 * (0: jerk limiting off). */
double motion_jerk_default_window_s(const struct motion_config *c);
/* Where the window (motion_jerk_window_s) is shorter than the full one: lowers each
 * acceleration limit of c (path, A B C, every leg) to its jerk limit x the window / 2, so that
 * the mean of that window keeps every jerk limit, and sets c's JERK_WINDOW to it.
 * motion_create applies it to its own copy; the machine's limits (what a check reports
 * against) stay as configured. Nothing where the window is the full one. */
void motion_jerk_share(struct motion_config *c);

struct motion;

/* Creates a motion instance for kinematics k (borrowed). Message in err on failure. */
int motion_create(const struct motion_config *cfg, struct kins *k, struct motion **out,
                  char *err, size_t errlen);
void motion_destroy(struct motion *m);

/* Plans the whole program: every move sampled along its length through the inverse
 * kinematics (reachability, leg rate and acceleration limits, kinematic-error bound), then
 * the velocity profile. The program is copied; prog may be freed afterwards. Allowed in IDLE,
 * DONE and FAULT (clears the fault); the pose jumps to prog->start. On failure the message
 * names file:line and what is wrong; the previous program is dropped. */
int motion_load(struct motion *m, const struct canon_prog *prog, char *err, size_t errlen);
/* A flag (set by the caller's SIGINT handler; NULL: none) that motion_load checks as it goes
 * (every command and every knot): once it is non-zero planning stops with
 * MOTION_ERR_CANCELLED and nothing is loaded. Not owned. */
void motion_set_cancel(struct motion *m, const volatile sig_atomic_t *flag);
/* Starts the loaded program (IDLE with a program -> RUNNING). */
int motion_start(struct motion *m);

/* Summary of the plan made by motion_load. */
struct motion_plan_info {
    double time_s;           /* planned duration at feed override 1, dwells included, s */
    double length_mm;        /* XYZ path length of all moves, mm */
    size_t segments;         /* segments (moves, dwells, pauses) */
    size_t samples;          /* path samples (knots) checked through the kinematics */
    double max_leg_vel_mm_s[KINS_MAX_JOINTS]; /* largest planned leg rate per leg, mm/s */
    int limited_by_legs;     /* samples where leg limits lowered the speed below the feed */
    int limited_by_kin_tol;  /* samples where the kinematic-error bound lowered it */
    size_t blends;           /* G64 P corners rounded by a tangent arc (motion_blend.h) */
    size_t merged;           /* straight feeds that G64 Q ran inside a longer line */
    size_t stops_held;       /* stops where the path changes direction, held for one set-point
                              * period so that a set point lands on them (docs/motion.md) */
};
int motion_plan_info(const struct motion *m, struct motion_plan_info *out);

/* Inputs M66 waits on (motion.digital-in-NN, motion.analog-in-NN), this period. */
void motion_set_inputs(struct motion *m, const bool *din, int nd, const double *ain, int na);
/* The last M66's answer (the input's value, or -1 after its time-out) and, in *seq, how many
 * M66 waits have been answered since the program started (any thread). */
double motion_input_result(const struct motion *m, unsigned *seq);

/* G38.2..G38.5: the probe input (motion.probe-input), this period. During a probe move the
 * executor stops on the path where it changes as the move seeks (towards the workpiece:
 * becomes true; away: becomes false), decelerating within the path's and legs'
 * acceleration limits, as a pause does. */
void motion_set_probe_input(struct motion *m, bool on);
/* (Until it is first called, as in `hexcnc check`, probe moves run as plain feeds.) */

/* G33, G33.1: the spindle's position, revolutions (spindle.0.revs), this period, and whether
 * anything gives it (wired: the pin is connected). A synchronised move's path position is
 * its pitch times the revolutions since it began (motion_sync.c); without feedback such a
 * program is refused when it is planned. */
void motion_set_spindle_revs(struct motion *m, double revs, bool wired);
/* The encoder's index handshake (spindle.0.index-enable, LinuxCNC's): whether the pin is
 * connected, and its value this period. Connected, a synchronised move that needs the
 * spindle's angle sets it (motion_out.spindle_index) and starts once the encoder has cleared
 * it, having reset its count to 0 at the index; not connected, the move starts at the first
 * whole revolution the count passes. An index comes once a revolution: when the spindle has
 * turned MOTION_INDEX_WAIT_REVS with the pin set and still set, the machine faults
 * (MOTION_ERR_INDEX) at the move's start, the pin withdrawn. */
#define MOTION_INDEX_WAIT_REVS 2.0
void motion_set_spindle_index(struct motion *m, bool enabled, bool wired);
/* `hexcnc check`: no spindle, an ideal one instead: it turns at the commanded speed, reached
 * at [SPINDLE_SYNC] ACCELERATION, and synchronised moves follow it. */
void motion_set_spindle_ideal(struct motion *m, bool on);
/* Whether the path follows the spindle now: on a synchronised move, whose path may run on
 * past its ends along its line (a tap while the spindle reverses). */
bool motion_sync_running(const struct motion *m);
struct motion_probe_result {
    int already;             /* G38.2/G38.4: the input was already as sought where the move
                              * starts (LinuxCNC's error); nothing moved */
    int tripped;             /* the input changed during the move */
    double trip[KINS_POSE_DIM];  /* path pose commanded the period the change was seen (the
                                  * end of the move without a trip), mm, deg */
    double stop[KINS_POSE_DIM];  /* path pose where the machine came to rest */
};
/* How many probe moves have been answered since the program started (any thread), and the
 * last one's result in out (NULL: none wanted). The result holds from the moment the count
 * moves until the next probe move starts, which in a program is after the interpreter has
 * read it (a status reader at that instant may see the next move's result being filled). */
unsigned motion_probe_result(const struct motion *m, struct motion_probe_result *out);

/* The spindle and coolant as the program commands them at the point the path has reached. */
struct motion_spindle {
    int dir;                 /* 1 (M3), -1 (M4), 0 (stopped) */
    double rpm;              /* S in force (>= 0) */
    int mist, flood;         /* M7, M8 */
};

/* Digital and analog outputs (M62..M68) as the path reaches them. */
#define MOTION_MAX_DIO 64
#define MOTION_MAX_AIO 16
struct motion_outputs {
    uint64_t dout;                   /* bit n: motion.digital-out-n */
    double aout[MOTION_MAX_AIO];     /* motion.analog-out-n */
};

/* Tool changes (M6) as the path reaches them: a request the machine's tool changer (the
 * motion component's iocontrol pins) carries out, and the tool in the spindle. */
struct motion_tool {
    int number;              /* the tool in the spindle */
    int request;             /* the tool of the last M6 */
    unsigned seq;            /* counts M6 requests; motion_tool_changed(seq) answers one */
};

/* What one servo period produces. */
struct motion_out {
    double pose[KINS_POSE_DIM];        /* commanded pose: mm, deg */
    double pose_vel[KINS_POSE_DIM];    /* its rate: mm/s, deg/s */
    double prog_pose[KINS_POSE_DIM];   /* the path's pose: under G43.4 (tcp) the tool tip and
                                        * orientation (kins_tcp_*), else pose */
    int tcp;                           /* the path being followed is under G43.4 ... */
    double tool_len_mm;                /* ... with this tool length, mm */
    int seg_kind;                      /* the move being followed: 1 a straight feed, 2 an arc,
                                        * 3 a rapid, 0 none (a stop, or no program) ... */
    double seg_from[KINS_POSE_DIM];    /* ... from and to these path poses (the tool tip's */
    double seg_to[KINS_POSE_DIM];      /* under tcp): for checks of the path between them */
    double path_tol_mm;                /* how far the planner lets that move's path be
                                        * rounded, mm: KINEMATIC_TOLERANCE, or with jerk limits
                                        * under G64 P the larger of it and half of P */
    double joint_pos[KINS_MAX_JOINTS]; /* leg position commands, mm */
    double joint_vel[KINS_MAX_JOINTS]; /* leg rate commands, mm/s */
    double motor_pos[KINS_MAX_JOINTS]; /* what the drives get: joint_pos + home offset, mm */
    double joint_fb[KINS_MAX_JOINTS];  /* leg feedback: motor feedback - home offset, mm */
    double ferror_mm[KINS_MAX_JOINTS]; /* last following error (command - feedback), mm */
    int njoints;
    int line;                          /* program line being executed (0 before any) */
    const char *file;                  /* its file (NULL before any) */
    enum motion_state state;
    int status;                        /* MOTION_OK, or the fault's status */
    double path_vel;                   /* path speed: mm/s (deg/s on rotary-only moves) */
    double time_elapsed_s;             /* since motion_start, s */
    double time_remaining_s;           /* from the plan at feed override 1, s */
    double distance_done_mm;           /* XYZ path length covered, mm */
    double distance_total_mm;          /* XYZ path length of the program, mm */
    double feed_override;              /* override in effect now (ramps to the requested) */
    struct motion_spindle spindle;     /* spindle and coolant commands in force */
    int spindle_index;                 /* 1: set spindle.0.index-enable (a synchronised move
                                        * waits for the index), -1: clear it (that wait was
                                        * given up), 0: leave it */
    int waiting;                       /* holding on the path: 1 for the spindle to be at
                                        * speed, 2 for a tool change, 3 for an input (M66) */
    struct motion_tool tool;           /* tool change requests, the tool in the spindle */
    struct motion_outputs outputs;     /* M62..M68 in force (kept from program to program) */
    int probe_input;                   /* motion.probe-input as motion saw it (G38) */
    size_t settings_done;              /* CANON_SETTING commands of the program the machine has
                                        * passed since motion_start, in program order: the
                                        * path reached their place (never decreases) */
};

/* Advances the clock by period_s and fills out. In FAULT, IDLE, PAUSED and DONE the pose
 * holds. Returns the status of a fault raised during this period, else MOTION_OK. */
int motion_step(struct motion *m, double period_s, struct motion_out *out);

/* Leg position feedback, mm, one per joint: compared with the command of the previous period
 * (the one the drives were following). Beyond the limit (MIN_FERROR at standstill growing to
 * FERROR at MAX_VELOCITY, LinuxCNC's rule) the machine stops at once in MOTION_FAULT and
 * motion_last_error names the leg, the amount and the program line. */
int motion_feedback(struct motion *m, const double *joints_fb_mm);

/* Decelerates along the path to a stop (RUNNING -> PAUSING -> PAUSED). */
int motion_pause(struct motion *m);
/* Continues after a pause or an M0/M1 stop. */
int motion_resume(struct motion *m);
/* Decelerates along the path to a stop, then drops the program (-> STOPPING -> IDLE). */
int motion_abort(struct motion *m);
/* Feed override 0..2 (clamped); applied smoothly within the acceleration limits, and never
 * beyond a leg or machine speed limit. */
int motion_set_feed_override(struct motion *m, double scale);
/* Rapid override 0..1 (clamped): the override of rapid (G0) moves, in place of the feed
 * override, as LinuxCNC applies it. */
int motion_set_rapid_override(struct motion *m, double scale);
/* Whether M1 pauses (the optional-stop switch), for programs loaded from now on. */
int motion_set_optional_stop(struct motion *m, bool on);
/* Step: run to the end of the present block, then pause (decelerating on the path). */
int motion_step_block(struct motion *m);
/* Emergency stop: command freezes where it is, state FAULT (status MOTION_ERR_ESTOP). */
int motion_estop(struct motion *m);

/* ---- Streaming (motion_stream.c): a program planned window by window while it runs, in
 * bounded memory, motion starting as soon as the first window is planned.
 *   motion_stream_create(m, start, cancel, &s, ...)   a planner for m's machine
 *   with an executor: motion_stream_attach(m, s, totals) at rest (the servo update kept
 *     out), then motion_start(m); the machine holds until the first chunk is planned
 *   the producer: motion_stream_add(s, cmd) for each command (windows are planned as they
 *     fill), then motion_stream_finish(s); keep motion_stream_backlog(s) small (it frees the
 *     chunks the executor has left)
 *   at the end (done, idle, fault): motion_stream_detach(m) at rest, motion_stream_destroy(s)
 * Without an executor the same calls only plan and check: `hexcnc check`'s pass before a
 * streamed run. Every move is checked as motion_load checks it; the first error stops the
 * stream (motion_stream_error). */
struct motion_stream;
struct motion_stream_info {
    struct motion_plan_info plan; /* what was committed so far: time, length, segments,
                                   * samples, largest leg rates */
    size_t windows;               /* windows planned */
    double entry_shortfall;       /* largest relative shortfall of a window's planned entry
                                   * speed below the speed the previous one left (rounding) */
    size_t window_capacity;       /* commands the window's buffer holds (memory bound) */
};
int motion_stream_create(struct motion *m, const double start[KINS_POSE_DIM],
                         const volatile sig_atomic_t *cancel, struct motion_stream **out,
                         char *err, size_t errlen);
/* Adds one command; MOTION_OK or the stream's first error (message: motion_stream_error). */
int motion_stream_add(struct motion_stream *s, const struct canon_cmd *cmd);
/* Plans what is left, to the program's end. */
int motion_stream_finish(struct motion_stream *s);
/* Chunks handed to the executor that it has not left yet (frees those it has). */
size_t motion_stream_backlog(struct motion_stream *s);
const char *motion_stream_error(const struct motion_stream *s);
void motion_stream_info(const struct motion_stream *s, struct motion_stream_info *out);
void motion_stream_destroy(struct motion_stream *s);
/* Executor side, with the servo update kept out: m follows s's chunks from now on (m idle,
 * done or faulted; totals: the checked program's time and length for progress, or NULL). */
int motion_stream_attach(struct motion *m, struct motion_stream *s,
                         const struct motion_plan_info *totals);
/* m forgets the stream's chunks (before motion_stream_destroy); the program is unloaded. */
void motion_stream_detach(struct motion *m);
/* Sync: the window so far is planned to a stop at its end (an M66 wait there) and handed
 * over; what comes next starts a new window at rest there. */
int motion_stream_sync(struct motion_stream *s);
/* After a sync on a probe move: the next window starts at rest at pose (where the machine
 * stopped on the probe, not the move's end); call before adding what follows. */
void motion_stream_restart_at(struct motion_stream *s, const double pose[KINS_POSE_DIM]);
/* Whether the executor is about to run out of planned path (a simulated clock waits). */
bool motion_stream_starving(const struct motion *m);
/* From a thread that waits for s's plan: one share of the planner's present work (the knot
 * caps of a window, in jobs the planner takes too); true when it did one, false when none
 * was on offer. The plan is the same whichever thread does which share. */
bool motion_stream_help(struct motion_stream *s);

/* ---- Manual motion (motion_manual.c, motion_home.c): allowed in IDLE, DONE (and MANUAL, to
 * change a jog); never while a program runs. Leg positions below are joint positions (leg
 * lengths); the drives get motor positions = joint + the leg's home offset. */
enum motion_jog_frame { MOTION_JOG_WORLD, MOTION_JOG_TOOL, MOTION_JOG_JOINT };
/* Jog axis (0..5: X Y Z A B C; in the tool frame 0..2 are the platform's own X Y Z; in the
 * joint frame the leg) at vel (signed, mm/s or deg/s). dist > 0: that far, else until
 * motion_jog_stop. Speed and acceleration stay within the axis's and every leg's limits; a
 * jog stops at the edge of the reachable workspace (a leg's limit), and motion_manual_note
 * says so. World and tool jogs need every leg homed. */
int motion_jog(struct motion *m, enum motion_jog_frame frame, int axis, double vel,
               double dist);
/* Decelerates any manual motion to rest (homing stops too, unhomed). */
int motion_jog_stop(struct motion *m);
/* A straight move in pose space to pose at speed_scale (0..1] of the path limits. */
int motion_move_to(struct motion *m, const double pose[KINS_POSE_DIM], double speed_scale);
/* Starts homing: joint -1 all legs by HOME_SEQUENCE then the move to the kinematics' home
 * pose, else that leg alone. */
int motion_home(struct motion *m, int joint);
int motion_unhome(struct motion *m, int joint);
/* The home switch of each leg, this period (the component's pins). */
void motion_set_home_switches(struct motion *m, const bool *sw);
/* Whether leg i is homed; whether a homing run is under way. */
bool motion_homed(const struct motion *m, int joint);
bool motion_homing(const struct motion *m);
/* The last note of manual motion (a limit reached, homing finished or failed), "" when
 * none; a counter that grows with each new note, so a reader sees each once. */
const char *motion_manual_note(const struct motion *m, unsigned *seq);
/* While the machine is off: takes the commanded legs from the feedback when they differ by
 * more than MIN_FERROR, and the pose from the forward kinematics of them. Out of FAULT on
 * the machine's next start (motion_reset). */
void motion_track_feedback(struct motion *m);
/* Leaves FAULT (the program is dropped); the pose stays where the legs are. */
int motion_reset(struct motion *m);
/* Whether the commanded pose is known (the forward kinematics of the legs has an answer). */
bool motion_pose_known(const struct motion *m);
/* Spindle (motion_step.c): whether programs planned from now on stop after M3/M4 and S
 * changes until the spindle reports it is at speed, and that report, each period. */
void motion_set_wait_at_speed(struct motion *m, bool on);
/* Distance of point p from the segment a..b (X Y Z, mm); from a when the two coincide. */
double motion_dist_seg(const double p[3], const double a[3], const double b[3]);
/* Its square, for the segment from a along d, with n2 = |d|^2 given (a caller that measures
 * many points against one segment, and keeps the largest: the root of the largest square is
 * the largest root). */
double motion_dist2_seg(const double p[3], const double a[3], const double d[3], double n2);
/* Off: motion_step computes the leg positions alone, joint_vel and pose_vel read 0 (a check
 * that differences successive set points; a fifth less time per period). On by default. */
void motion_set_rates(struct motion *m, bool on);
/* On: motion_step fills only what a check of the path reads (pose, tcp, tool_len_mm,
 * seg_kind, seg_from, seg_to, path_tol_mm, joint_pos, line, file, state, status,
 * time_elapsed_s, distance_done_mm, distance_total_mm) and leaves the rest of the record as
 * it was: on dense code the record was a tenth of a check's period. Off by default. */
void motion_set_brief(struct motion *m, bool on);
/* On (with rates off): the executor computes the path's pose and legs eight periods ahead,
 * four at a time, where the plan's pace lets it see them coming, the same bits as period by
 * period (motion_ahead.c): a check's pass, not a machine's servo thread. Off by default. */
void motion_set_ahead(struct motion *m, bool on);
/* A check's calm periods, several in one call (ahead and brief on, rates off): where the
 * next periods run at the plan's own pace on one segment, a line or an arc, with no probe,
 * pause, jerk limiting, stepped block, override or chunk hand-over among them, takes up to
 * MOTION_CALM_MAX of them exactly as that many motion_step calls would (the same bits:
 * test_calm_same_bits), and returns how many: 0 when the next period is not one of them
 * (nothing done; motion_step takes it). out: the last period's record; c: each period's
 * pose, legs, clock and place on the segment, its distance done by motion_calm_dist (pose
 * and legs valid until the next call into m). */
#define MOTION_CALM_MAX 8
struct motion_calm {
    int n;                                      /* periods taken */
    const double (*pose)[KINS_POSE_DIM];        /* period k's pose, pose[k] */
    const double (*joints)[KINS_MAX_JOINTS];    /* its legs (joint_pos) */
    double time_s[MOTION_CALM_MAX];             /* time_elapsed_s at its end */
    double s[MOTION_CALM_MAX];                  /* its place on the segment */
    double dist0_mm, xyz_len_mm, len;           /* the segment's: distance done at its
                                                 * start, X Y Z length, length */
};
/* Period k's distance_done_mm (a division: taken where it is read). */
static inline double motion_calm_dist(const struct motion_calm *c, int k)
{
    return c->dist0_mm + (c->len > 0 ? c->s[k] * c->xyz_len_mm / c->len : 0);
}
int motion_step_calm(struct motion *m, double period_s, struct motion_calm *c,
                     struct motion_out *out);
void motion_set_spindle_at_speed(struct motion *m, bool at_speed);
/* Tool changes: whether programs planned from now on stop at M6 until the changer is done,
 * and the changer's answer to request seq (the tool is then in the spindle). */
void motion_set_wait_tool(struct motion *m, bool on);
void motion_tool_changed(struct motion *m, unsigned seq);
/* Homed status of all legs. */
bool motion_all_homed(const struct motion *m);

enum motion_state motion_get_state(const struct motion *m);
/* The last error or fault message ("" when none): file:line and what happened. */
const char *motion_last_error(const struct motion *m);

#endif
