/* motion_priv.h: the planned program (segments, knots) and the motion instance, inside motion/. */
#ifndef HEXCNC_MOTION_PRIV_H
#define HEXCNC_MOTION_PRIV_H

#include <stdbool.h>
#include <stdatomic.h>
#include <stddef.h>

#include "motion/motion.h"

/* fmin and fmax as the C library defines them (a NaN argument loses), inline: the planner
 * takes dozens per knot, and the library's are calls. Written so that the compiler makes
 * them branch-free (minsd/maxsd, which give b on a NaN or a tie, then b's NaN test): the
 * comparisons of a knot's caps are unpredictable, and the branches were a tenth of the
 * planning's time. The same results, NaNs and signed zeros included. */
static inline double motion_min2(double a, double b)
{
    double m = a < b ? a : b;
    return b != b ? a : m;
}
static inline double motion_max2(double a, double b)
{
    double m = a > b ? a : b;
    return b != b ? a : m;
}
/* A running minimum acc (or maximum) taken on to b: motion_min2(acc, b) where acc is no NaN
 * (it starts at a number and only ever takes b's that are not NaN), as one minsd (maxsd):
 * on a NaN b it gives acc, and on a tie acc (the same number: the caps are no signed
 * zeros). In the loops over the legs, whose every step waits on the last, motion_min2's
 * NaN test through the integer registers tripled the chain. */
static inline double motion_lower(double acc, double b)
{
    return b < acc ? b : acc;
}
static inline double motion_raise(double acc, double b)
{
    return b > acc ? b : acc;
}

/* What a segment does. */
enum motion_seg_kind { SEG_LINE, SEG_ARC, SEG_DWELL, SEG_PAUSE,
                       SEG_WAIT /* stop, then wait until the spindle is at speed */ };

/* A spindle or coolant command on the path (CANON_SPINDLE_*, CANON_COOLANT): applied when
 * the path reaches the segment it lies before, as a setting point is. */
enum motion_io_kind { IO_SPINDLE_SPEED, IO_SPINDLE_ON, IO_SPINDLE_STOP, IO_COOLANT,
                      IO_TOOL_CHANGE /* M6: ivalue the tool */,
                      IO_TOOL_SET /* M61 Q: the tool in the spindle, no change */,
                      IO_DOUT /* M62..M65: ivalue the output, value 0/1 */,
                      IO_AOUT /* M67, M68: ivalue the output, value */ };
struct motion_io {
    size_t at;               /* the segment it lies before (nseg: after the last) */
    enum motion_io_kind kind;
    double value;            /* rpm, or the direction (+1 M3, -1 M4) */
    int ivalue;              /* M7, M8, M9 */
};

/* Arc geometry: position(u) = center + (r0 + dr u)(cos(th u) e1 + sin(th u) e2) + (h0 + dh u) n,
 * u in [0, 1]: a planar arc, a helix, or (dr != 0) the small spiral of an arc whose end
 * radius differs from its start radius. */
struct motion_arc {
    double center[3];        /* mm */
    double e1[3], e2[3];     /* unit, in the arc plane; e2 = n x e1 */
    double n[3];             /* unit normal */
    double r0_mm, dr_mm;     /* start radius and its change to the end radius, mm */
    double h0_mm, dh_mm;     /* height along n at the start and its change, mm */
    double sweep_rad;        /* signed angle turned (> 0: counter-clockwise about n) */
    int abc_cubic;           /* 1 (G64 blend arcs): A B C follow the cubic with end slopes
                              * abc_m0, abc_m1 instead of going linearly with u */
    double abc_m0[3], abc_m1[3]; /* d(A B C)/du at u = 0 and u = 1, deg */
};

/* One planned segment: a move, a dwell or a pause. The path parameter s runs over [0, len]
 * (mm along the XYZ path, or deg along the ABC path for rotary-only moves). (What the
 * executor reads every period comes first, in the first three cache lines: a check's
 * servo pass reads each segment once, some time after the planner's thread wrote it.) */
struct motion_seg {
    enum motion_seg_kind kind;
    int rotary;              /* 1: rotary-only move, s and speeds in deg */
    int line;                /* program line */
    int tcp;                 /* tool centre point control: the path (start, end, arcs) is the
                              * tool tip and orientation; kins_tcp_to_pose with tool_len_mm
                              * gives the platform's pose */
    int sync;                /* SEG_LINE of G33/G33.1 (enum canon_sync): the spindle drives
                              * the path position, not the plan's clock (motion_sync.c) */
    int arc;                 /* index into arcs for SEG_ARC, else -1 */
    const char *file;        /* program file (interned by motion) */
    size_t k0;               /* first knot */
    size_t nk;               /* knots (>= 2) */
    double len;              /* mm (deg when rotary) */
    double xyz_len_mm;       /* XYZ length, mm (0 for rotary-only, dwell, pause) */
    double dist0_mm;         /* XYZ distance of the program before this segment, mm */
    double feed;             /* programmed speed, mm/s (deg/s when rotary); 0 = rapid */
    double tool_len_mm;
    double blend_tol_mm;     /* G64 tolerance in force (blend into the next move), 0 = stop */
    double start[KINS_POSE_DIM], end[KINS_POSE_DIM]; /* mm, deg */
    double fine_h;           /* spacing the checks need, mm (deg when rotary); knots are this
                              * close but on very long moves (MAX_INTERVALS), where the checks
                              * sample between them at this spacing */
    double dwell_s;          /* DWELL: seconds */
    int wait_tool;           /* SEG_WAIT: for a tool change (else for the spindle) */
    int wait_input;          /* SEG_WAIT: for an input (M66): input, its kind and mode */
    int input, input_analog, input_mode;
    double timeout_s;        /* M66 Q */
    int probe;               /* SEG_LINE of G38.2..G38.5: the executor watches the probe input
                              * (motion_probe.c) and stops where it changes */
    int probe_type;          /* LinuxCNC's probe type: bit 0 no error without a trip, bit 1
                              * seek loss of contact */
    /* Set-point chords near arcs (motion_chord.c): the first [0] and last [1] chord_mm of
     * the path lie within reach of a chord touching an arc whose path curvature is at most
     * chord_k (1/mm) and A B C curvature at most chord_kabc (deg/mm^2); 0: none. The cut
     * of such a chord stays within chord_tol (mm), the smallest rounding budget of those
     * arcs (motion_round_tol_mm). */
    double chord_mm[2], chord_k[2], chord_kabc[2], chord_tol[2];
    double pitch_mm_rev;     /* K, mm of path per spindle revolution */
    double retract_factor;   /* G33.1's I: the spindle's speed multiple for the way out */
    double sync_rpm;         /* the commanded spindle speed at the move, rpm */
    int sync_dir;            /* ... and its direction (1 M3, -1 M4) */
};

/* The planned program: segments and the velocity profile at knots along them. Interval i
 * joins knot i and i+1; at segment joints the two knots share the velocity (length 0).
 * Within an interval the speed goes from kv[i] at iacc[i] up to ivp[i], cruises, and comes
 * down at iacc[i] to kv[i + 1] (a trapezoid; either ramp may be empty). */
struct motion_plan {
    struct motion_seg *segs;
    size_t nseg, capseg;
    struct motion_arc *arcs;
    size_t narc, caparc;
    double *ks;              /* knot: s within its segment */
    double *kv;              /* knot: planned path speed at override 1 */
    double *kt;              /* knot: planned time from program start, s */
    double *krho;             /* knot: largest feed override allowed from here (>= 1) */
    double *iacc;            /* interval: path acceleration limit */
    double *ivp;             /* interval: cruise speed (accelerate, cruise, decelerate) */
    double *irho;             /* interval: override ceiling from speed and acceleration caps */
    size_t nknot, capknot;
    size_t *marks;           /* CANON_SETTING points in program order: the segment each lies
                              * before (nseg: after the last); passed, not planned */
    size_t nmarks, capmarks;
    struct motion_io *ios;   /* spindle and coolant commands in program order */
    size_t nios, capios;
    char **files;            /* interned file names */
    size_t nfiles;
    struct motion_plan *names_in; /* intern file names there instead (a streamed window's
                                   * plan: its names outlive it, motion_stream.c) */
    /* A streamed window (motion_stream.c): the executor enters at knot k_enter at speed
     * v_enter; the knots before it are context (moves already run, kept for the junction
     * and chord caps at the entry). 0 and 0 for a whole program. */
    size_t k_enter;
    double v_enter;
    double enter_deficit;    /* how much the planned speed at k_enter fell short of v_enter
                              * (relative; rounding only), for tests */
    double total_time_s;
    double total_len_mm;
    struct motion_plan_info info;
};

/* One planned window of a streamed program (motion_stream.c), handed to the executor:
 * context, the committed part [k_enter, k_leave), and a tail to a stop at the window's end
 * that the executor runs only if no successor came in time. Immutable once published. */
#define MOTION_TAIL_TAKEN ((struct motion_chunk *)1)
struct motion_chunk {
    struct motion_plan plan;
    size_t k_enter, s_enter; /* where the executor enters: knot and its segment */
    size_t k_leave, s_leave; /* where it leaves for the successor: knot and its segment */
    double t_leave_s;        /* plan.kt[k_leave] (0 without knots): the executor reads it
                              * every period, a cache line away from the knots' array */
    int last;                /* holds the program's end: no successor, run to the end */
    int sync;                /* ends at rest on an M66 wait: the interpreter reads on once the
                              * machine has its answer; the successor starts at rest there */
    double t0_s;             /* program plan time at k_enter, s */
    struct motion_chunk *_Atomic next; /* successor (planner), or MOTION_TAIL_TAKEN (the
                                        * executor went on into the tail) */
    _Atomic int retired;     /* the executor has left it (the planner may free it) */
    struct motion_chunk *newer; /* the planner's list */
};

/* Where a spindle-synchronised move is (motion_sync.c). */
enum motion_sync_phase {
    SYNC_IDLE,               /* not on a synchronised move */
    SYNC_INDEX,              /* at rest at its start, waiting for the spindle to pass a
                              * whole revolution (the index), so passes line up */
    SYNC_FOLLOW,             /* d follows pitch x revolutions (into the hole, or a thread) */
    SYNC_REVERSING,          /* G33.1 past the bottom: the spindle was told to reverse;
                              * still following it while it stops and turns back */
    SYNC_OUT,                /* G33.1 on the way out, following the reversed spindle */
    SYNC_RESTORING,          /* past the start: the spindle was told its own direction
                              * again; following it until it turns forward */
    SYNC_PLACE,              /* not synchronised: back to the start, then rest */
    SYNC_CHAIN,              /* a G33 ended; the next one, if it follows at once, goes on
                              * from the same revolutions (no new index) */
    SYNC_LEFT,               /* a tap ended: the plan's clock goes on from its end */
};
/* The executor's state of a synchronised move, servo thread only. d is the path position
 * along the first move of the run (a G33.1's way in): the way out runs back along it. */
struct motion_sync {
    enum motion_sync_phase phase;
    const struct motion_plan *run; /* the plan and segment being followed */
    size_t seg;
    double revs0;            /* revolutions where d is 0 */
    double k_mm_rev;         /* pitch, mm/rev (signed with the spindle's direction) */
    double d_mm, v_mm_s;     /* path position and speed along the move */
    double len_mm;           /* the move's length (G33.1: the hole's depth) */
    double vmax_mm_s, acc_mm_s2; /* speed and acceleration the follower keeps within */
    int dir0;                /* the spindle's direction and speed before a tap reversed it */
    double rpm0;
    double revs_prev;        /* last period's revolutions (the spindle's speed) */
    int index_asked;         /* spindle.0.index-enable set for this move's start */
    double index_revs0;      /* the revolutions when it was set */
};

/* An interval's ramp and cruise times for its speeds, acceleration and length (what
 * motion_phases gives, and the ramp's length): the executor evaluates one interval for many
 * periods running, and the divisions are most of the cost of evaluating it. */
struct motion_phase_memo {
    double v0, v1, vp, acc, ds;        /* the inputs (never all matched by a fresh memo: ds > 0) */
    double ta, tc, td, sa;
};

/* Manual motion (motion_manual.c): a 1-D profile along a line in pose space, or one per leg. */
enum motion_man_kind { MAN_NONE, MAN_LINE, MAN_JOINTS };
struct motion_manual {
    enum motion_man_kind kind;
    double p0[KINS_POSE_DIM], u[KINS_POSE_DIM]; /* MAN_LINE: pose(s) = p0 + s u */
    double s, v;             /* position along the line and speed (>= 0) */
    double s_end;            /* where it stops (HUGE_VAL: until stopped) */
    double v_req;            /* requested speed */
    double a_max;            /* path acceleration limit along s */
    int stop;                /* decelerate to rest now */
    int limited;             /* s_end was pulled in to a workspace edge */
    /* MAN_JOINTS: each leg its own profile towards jt at jvreq */
    int jact[KINS_MAX_JOINTS];
    double jv[KINS_MAX_JOINTS], jt[KINS_MAX_JOINTS], jvreq[KINS_MAX_JOINTS];
    int jfree[KINS_MAX_JOINTS]; /* leg not held to its limits (homing, unhomed) */
};

/* Homing of one leg (motion_home.c). */
enum motion_home_phase { HOME_IDLE, HOME_WAIT, HOME_OFF_SWITCH, HOME_SEARCH, HOME_BACKOFF,
                         HOME_LATCH, HOME_SETTLE, HOME_FINAL, HOME_DONE };

/* The lanes of the kinematics' four-at-once calls (kins_inverse4, kins_inverse_path4). */
#define MOTION_LANES 4
/* The look-ahead of a check's executor (motion_ahead.c): the next periods' path position,
 * pose and legs, each keyed by the state it is a function of; filled MOTION_LANES at a
 * time. */
#define MOTION_AHEAD 8
struct motion_ahead_at {
    size_t ci, cs;           /* the key: interval, segment and plan clock (of run) */
    double tau_s;
    double s, vp;            /* motion_plan_at's position and speed there */
};
/* One path sample through the kinematics: pose, its s-derivative, legs and their
 * first and second s-derivatives. */
struct motion_sample {
    int tcp;                 /* the segment's tool centre point control and tool length */
    double tool_len_mm;
    double pose[KINS_POSE_DIM], dp[KINS_POSE_DIM], d2p[KINS_POSE_DIM];
    double L[KINS_MAX_JOINTS], dL[KINS_MAX_JOINTS], d2L[KINS_MAX_JOINTS];
    int q_state;             /* q below: 0 not yet taken, 1 taken, -1 the Jacobian is singular */
    double q[KINS_POSE_DIM]; /* the pose's curvature as the legs see it, J^-1 d2L (the
                              * kinematic-error and chord caps both use it: taken once) */
};

/* The planner's look-ahead over knots (motion_caps.c): while all_caps samples the knots
 * in order, the next ones' samples four at a time (kins_inverse_path4), each keyed by its
 * segment and place on it. */
struct motion_knot_ahead {
    int on;                  /* all_caps is sampling the plan's knots in order */
    int off;                 /* never (a test compares plans made with and without) */
    int n, next;             /* entries filled, the next one to take */
    const struct motion_seg *sg[MOTION_LANES];
    double s[MOTION_LANES];
    int status[MOTION_LANES];
    double pose[MOTION_LANES][KINS_POSE_DIM], dp[MOTION_LANES][KINS_POSE_DIM];
    double d2p[MOTION_LANES][KINS_POSE_DIM];             /* motion_seg_derivs' */
    double L[MOTION_LANES][KINS_MAX_JOINTS], dL[MOTION_LANES][KINS_MAX_JOINTS];
    double d2L[MOTION_LANES][KINS_MAX_JOINTS];           /* kins_inverse_path4's */
    long fills, taken;       /* fills, and entries taken after the first of a fill */
};
struct motion_ahead {
    const struct motion_plan *run;
    struct motion_ahead_at at[MOTION_AHEAD];
    double pose[MOTION_AHEAD][KINS_POSE_DIM];       /* motion_seg_pose's */
    double joints[MOTION_AHEAD][KINS_MAX_JOINTS];   /* kins_inverse's, and its status */
    int status[MOTION_AHEAD];
    int n, next;             /* entries filled, the next one to take */
    long fills, taken;       /* fills, and entries taken after the first of a fill */
    long calm;               /* periods taken the short way (calm_period, motion_step_calm) */
};
_Static_assert(MOTION_AHEAD == MOTION_CALM_MAX, "a calm run is the look-ahead's entries");

/* The motion instance. */
struct motion {
    struct motion_config cfg;
    double jerk_window_s;    /* motion_jerk_window_s(&cfg), taken once */
    double chord_period_s;   /* motion_chord_period(&cfg), taken once (every knot's caps use
                              * it): the set-point period, over which drives move their legs
                              * linearly (with jerk limits, the chord that cuts a curve as
                              * much as the chords and the moving average together) */
    struct kins *kins;       /* borrowed */
    struct kins_tool_frame tf; /* the machine's tool, for tool centre point control */
    int have_tf;             /* the kinematics has a tool frame */
    int nj;                  /* joints */
    struct motion_plan plan;
    struct motion_plan *run; /* the plan being followed: &plan, or a streamed chunk's */
    int loaded;              /* a program is planned (or streams) */
    /* Streaming (motion_stream.c): chunks come from a planner thread */
    int streaming;           /* the program streams: chunks, not plan */
    struct motion_chunk *chunk; /* the chunk being followed (NULL: none yet) */
    struct motion_chunk *_Atomic stream_head; /* the first chunk, once planned */
    struct motion_chunk *_Atomic stream_wait; /* the chunk whose successor the executor
                              * is about to need (MOTION_TAIL_TAKEN: the first chunk), or
                              * NULL (motion_stream_starving) */
    int tail_taken;          /* no successor came in time: running to the tail's stop */
    size_t marks_base;       /* setting points passed in chunks left behind */
    struct motion_plan names; /* file names of streamed plans (only files used): they live
                              * as long as the instance, so a status never points at a
                              * freed chunk */
    struct motion_plan_info stream_info; /* the checked program's totals (time, length) */
    /* motion_path_build records how many segments the commands before pb_at[i] made
     * (pb_seg[i]); SIZE_MAX: nothing to record (a streamed window's cut points) */
    size_t pb_at[2], pb_seg[2];
    enum motion_state state;
    int fault_status;
    char msg[320];           /* last error / fault text */
    const volatile sig_atomic_t *cancel; /* the operator's stop request while planning, or NULL */
    double start_pose[KINS_POSE_DIM];
    /* planning scratch: the inverse Jacobian dpose/dL near jc_pose, reused while the path
     * stays within 2 mm and 1 deg of it */
    double jc_pose[KINS_POSE_DIM];
    double jc_Jinv[6][6];
    int jc_valid;
    int jc_tcp;              /* ... for this tool centre point control and tool length */
    double jc_len_mm;
    /* run state */
    double tau_s;            /* position on the plan's time axis, s */
    double rate;             /* current time-scaling rate (feed override in effect) */
    double override_cmd;     /* requested feed override */
    double rapid_cmd;        /* requested rapid override */
    size_t step_until_seg;   /* step: pause when the path leaves segment step_until_seg - 1
                              * (0: no step pending) */
    double elapsed_s;
    size_t ci;               /* current interval */
    size_t cs;               /* segment holding knot ci */
    size_t paused_at_seg;    /* pause segment already honoured (+1), 0 = none */
    size_t marks_done;       /* setting points passed since motion_start (never goes back) */
    size_t ios_done;         /* spindle and coolant commands applied since motion_start */
    struct motion_spindle io; /* the spindle and coolant as commanded now (kept from one
                              * program to the next; off after an abort or a fault) */
    int no_rates;            /* motion_set_rates(m, false): legs only, no rates (a check
                              * differences the set points itself) */
    int brief;               /* motion_set_brief(m, true): the output record's first part */
    int ahead_on;            /* motion_set_ahead(m, true): evaluate() looks ahead */
    struct motion_ahead ahead;
    struct motion_knot_ahead kahead;
    int wait_at_speed;       /* plan a wait for the spindle after M3/M4/S (motion_hal: the
                              * at-speed input is wired) */
    int at_speed;            /* the spindle's at-speed input this period */
    int waiting;             /* holding at a SEG_WAIT for the spindle */
    long io_age;             /* periods since a spindle or coolant command last changed and
                              * went out (motion_out.spindle: with jerk limits, later) */
    int wait_tool;           /* plan a wait at M6 (motion_hal: tool-changed is wired) */
    struct motion_tool tool; /* tool change requests and the tool in the spindle */
    bool din[MOTION_MAX_DIO];  /* motion.digital-in-NN this period */
    double ain[MOTION_MAX_AIO];/* motion.analog-in-NN */
    bool in_prev;            /* the waited-for digital input last period (edges) */
    double in_since_s;       /* when the present M66 wait began (elapsed_s) */
    int in_waiting;          /* an M66 wait is under way at waited segment in_seg */
    _Atomic double input_result; /* the last M66's answer: the value, or -1 (time-out) */
    _Atomic unsigned input_seq;  /* M66 waits answered since the program started */
    struct motion_outputs outputs; /* M62..M68 in force */
    struct motion_outputs outputs_out; /* what the outputs show: with jerk limits, those in
                                        * force where the mean is on the path (T/2 behind
                                        * the executor, motion_jerk.c); else outputs */
    struct motion_spindle io_out; /* the same for the spindle and coolant (motion_out) */
    unsigned tool_done_seq;  /* the last tool change the changer finished */
    size_t waited_at_seg;    /* wait segment already passed (+1), 0 = none */
    /* G38 probing (motion_probe.c), servo thread only but the result and its counter */
    bool probe_in;           /* motion.probe-input this period */
    bool probe_wired;        /* someone gives the input (the HAL component, each period):
                              * without, probe moves are plain feeds (hexcnc check) */
    size_t probe_seg;        /* probe segment being watched (+1), 0 = none */
    int probe_halt;          /* enum motion_probe_phase of the move at probe_seg */
    struct motion_probe_result probe_res; /* the last probe move's result ... */
    _Atomic unsigned probe_seq;  /* ... published by counting probe moves answered */
    /* G33/G33.1 (motion_sync.c), servo thread only but spindle_wired (set from there) */
    double spindle_revs;     /* spindle.0.revs this period, revolutions */
    _Atomic bool spindle_wired; /* spindle.0.revs is connected: synchronised moves may run */
    bool spindle_ideal;      /* no encoder: an ideal spindle (hexcnc check) */
    double ideal_rps;        /* the ideal spindle's speed, rev/s */
    bool index_wired;        /* spindle.0.index-enable is connected */
    bool index_enabled;      /* its value this period */
    int index_out;           /* motion_out.spindle_index of this period */
    struct motion_sync sync;
    struct motion_phase_memo phases; /* motion_plan_at's: the last interval's phases */
    int have_cmd;            /* joint_cmd holds a command */
    double pose[KINS_POSE_DIM];     /* the platform's commanded pose */
    double pose_vel[KINS_POSE_DIM];
    double prog_pose[KINS_POSE_DIM]; /* the path's pose: the tool tip under G43.4, else pose */
    int tcp;                 /* the segment being followed is under G43.4 ... */
    double tool_len_mm;      /* ... with this tool length */
    int seg_kind;            /* it is a line (1), an arc (2), a stop (0) ... */
    double seg_from[KINS_POSE_DIM], seg_to[KINS_POSE_DIM]; /* ... from and to these poses */
    double path_tol_mm;      /* ... rounded by at most this (motion_out) */
    const struct motion_seg *seg_at; /* the segment those (and line, file) were taken from:
                              * evaluate() takes them again only on another one (NULL
                              * wherever the plan run changes: rewind, a chunk entered) */
    double joint_cmd[KINS_MAX_JOINTS];
    double joint_vel[KINS_MAX_JOINTS];
    double ferror[KINS_MAX_JOINTS];
    double path_vel;
    double dist_mm;          /* XYZ path length covered, mm */
    /* manual motion and homing */
    struct motion_manual man;
    /* Manual motion's own pose and legs (the leader's): with jerk limits the command
     * (pose, joint_cmd) is their moving average, so the jogs' and homing's profiles keep
     * their state here; without, the two are the same. Taken from the command when manual
     * motion begins (motion_manual_enter), at rest. */
    double lead_pose[KINS_POSE_DIM];
    double lead_L[KINS_MAX_JOINTS];
    double motor_offset[KINS_MAX_JOINTS];  /* motor = joint + offset, mm */
    double joint_fb[KINS_MAX_JOINTS];      /* last leg feedback (joint positions), mm */
    double motor_fb[KINS_MAX_JOINTS];      /* last motor feedback, mm */
    bool home_sw[KINS_MAX_JOINTS];         /* home switches this period */
    bool home_sw_prev[KINS_MAX_JOINTS];
    int homed[KINS_MAX_JOINTS];
    enum motion_home_phase hphase[KINS_MAX_JOINTS];
    double hstart[KINS_MAX_JOINTS];        /* joint position where the phase began */
    int homing;              /* 1: a homing run is under way */
    int home_group;          /* |HOME_SEQUENCE| being homed, -1 before the first */
    int home_all;            /* the run homes every leg, then moves to the home pose */
    int pose_known;          /* the forward kinematics of the legs has an answer */
    char note[240];          /* last manual-motion note */
    unsigned note_seq;
    int line;
    const char *file;
    struct motion_jerk *jerk; /* jerk limiting's moving average (motion_jerk.c), or NULL */
    /* the knot caps' jobs (motion_plan.c), or NULL: set once by the planner, read by helpers */
    _Atomic(struct motion_caps_work *) caps;
};

/* The knot caps in jobs that any thread may take (motion_plan.c): one job of the planner
 * m's, when it has one on offer (true when it did one); freeing them with m. */
bool motion_caps_help(struct motion *m);
void motion_caps_free(struct motion *m);

/* Durations of the three phases of an interval of length ds: accelerate from v0 to vp,
 * cruise at vp, decelerate to v1, at acceleration a. */
static inline void motion_phases(double v0, double v1, double vp, double a, double ds,
                                 double *ta, double *tc, double *td)
{
    double sa = (vp * vp - v0 * v0) / (2 * a), sd = (vp * vp - v1 * v1) / (2 * a);
    double sc = ds - sa - sd;
    *ta = (vp - v0) / a;
    *td = (vp - v1) / a;
    *tc = sc > 0 && vp > 0 ? sc / vp : 0;
}

/* The phases of an interval from v0 (knot) through vp (its peak) to v1 (knot) over ds at
 * acceleration acc into *mp, and the path done at the cruise's start (sa), unless *mp holds
 * them for these inputs already (motion_plan_at and the look-ahead's plan_at4). */
static inline void motion_phase_memo_take(struct motion_phase_memo *mp, double v0, double v1,
                                          double vp, double acc, double ds)
{
    if (mp->v0 != v0 || mp->v1 != v1 || mp->vp != vp || mp->acc != acc || mp->ds != ds) {
        motion_phases(v0, v1, vp, acc, ds, &mp->ta, &mp->tc, &mp->td);
        mp->sa = (vp * vp - v0 * v0) / (2 * acc);
        mp->v0 = v0, mp->v1 = v1, mp->vp = vp, mp->acc = acc, mp->ds = ds;
    }
}

/* motion_stream.c, for motion.c's attach: the stream's executor and its start pose. */
void motion_stream_bind(struct motion_stream *s, struct motion *m);
const double *motion_stream_start(const struct motion_stream *s);

/* Where a probe move is (motion_probe.c). */
enum motion_probe_phase {
    PROBE_WATCHING,          /* on the move (or none yet), the input not yet as sought */
    PROBE_HALTING,           /* it changed: decelerating on the path */
    PROBE_PARKED,            /* at rest there, result published: the rest of the chunk is
                              * dropped; the next part starts here */
    PROBE_DONE,              /* the move ended without a change, result published */
};
/* Forgets the probe move (a new program or chunk: segment numbers start again). */
void motion_probe_reset(struct motion *m);
/* G38 probing (motion_probe.c), called by the executor (motion_step.c). Before the clock
 * advances: watches the probe input on a probe segment; true while a trip asks the path
 * to come to rest (the feed override's target is then 0). */
/* (Each of the three tests inline what it needs before anything else, so that the common
 * period, no probe wired and no probe move, makes no call.) */
bool motion_probe_watch_wired(struct motion *m);
static inline bool motion_probe_watch(struct motion *m)
{
    if (m->probe_halt == PROBE_HALTING || m->probe_halt == PROBE_PARKED)
        return true;
    return m->probe_wired && motion_probe_watch_wired(m);
}
/* After the clock advanced: a probe move the path came onto this period is looked at from
 * its start (an input already as sought stops it there, before it moves). */
void motion_probe_arm_wired(struct motion *m);
static inline void motion_probe_arm(struct motion *m)
{
    if (m->probe_wired)
        motion_probe_arm_wired(m);
}
/* After the pose of the period is evaluated: publishes the result once the probe move has
 * come to rest (tripped) or reached its end (no trip). */
void motion_probe_settle_move(struct motion *m);
static inline void motion_probe_settle(struct motion *m)
{
    if (m->probe_seg)
        motion_probe_settle_move(m);
}

/* The index of the period's entry in the look-ahead (motion_ahead.c), filling it with this
 * period and the next ones where it has none; -1 where it leaves the period to evaluate()
 * (a synchronised move, G43.4, off the plan's own pace). */
int motion_ahead(struct motion *m, double dt);
/* Fills the look-ahead with the periods after the present one, as the plan's own pace
 * reaches them (motion_step_calm, where no entry is left); how many, 0 where it has none. */
int motion_ahead_next(struct motion *m, double dt);
/* Whether the executor runs at the plan's own pace, where the look-ahead foresees the next
 * periods (anywhere else the clock follows the override's ramp): running, at rate 1 with
 * both overrides at 1, no wait for the spindle, no probe's trip bringing it to rest. */
static inline bool motion_at_plan_pace(const struct motion *m)
{
    return m->state == MOTION_RUNNING && m->rate == 1 && m->override_cmd == 1 &&
           m->rapid_cmd == 1 && !m->waiting && m->probe_halt != PROBE_HALTING &&
           m->probe_halt != PROBE_PARKED;
}

/* Jerk limiting (motion_jerk.c). The longest moving average allowed, s. */
#define MOTION_JERK_MAX_S 1.0
/* The shortest the default window shortens the full one to, s: below it the full window's
 * rounding is small already, and the lowered accelerations cost more than a shorter window
 * wins (motion_jerk_default_window_s). */
#define MOTION_JERK_DEFAULT_MIN_S 0.020
/* Allocates the moving average when the configuration limits jerk (m->jerk stays NULL when
 * it does not); MOTION_ERR_NOMEM with a message. */
int motion_jerk_init(struct motion *m, char *err, size_t errlen);
void motion_jerk_free(struct motion *m);
/* After the executor evaluated the period: its pose, legs and rates go into the average and
 * the motion's values become the average's (the move, line and file of the window's middle). */
void motion_jerk_average(struct motion *m);
static inline void motion_jerk_follow(struct motion *m)
{
    if (m->jerk)                 /* (without jerk limits, no call) */
        motion_jerk_average(m);
}
/* The evaluation failed: the motion's values go back to the last output. */
void motion_jerk_restore(struct motion *m);
/* A period without program motion (manual, idle, paused, done, fault): the average holds
 * the motion's present values and starts from them when the program moves again. */
void motion_jerk_hold(struct motion *m);
/* Whether the average has come to rest on the executor's pose (always without jerk limits):
 * the machine counts as stopped only then. */
bool motion_jerk_settled(const struct motion *m);
/* At the start of a pause or a wait segment sg not yet honoured (motion_hold.c): 1 when the
 * path holds there this period (the clock at the segment's start, the rate 0): an M0/M1
 * pauses the machine, a wait holds until the spindle is at speed, the tool changed or the
 * M66 input answered (or timed out), and with jerk limits any of them first lets the
 * moving average come to rest; 0 when it goes on. */
int motion_pause_or_wait_here(struct motion *m, const struct motion_seg *sg);
/* Homing's latch moved leg i's joint coordinate by shift (the motor's command stays): the
 * average's samples of that leg move with it. */
void motion_jerk_shift_leg(struct motion *m, int i, double shift);
/* The period over which a chord's and the average's cut of a curved path is bounded: the
 * set-point period T_s and the average's window T_j give the same cut as a set-point chord
 * of sqrt(T_s^2 + T_j^2 / 3) (a chord cuts q d^2 / 8, the average q (v T_j)^2 / 24). */
double motion_chord_period(const struct motion_config *c);
/* Spindle-synchronised moves (motion_sync.c). At plan time: whether the machine can follow
 * the synchronised line sg (spindle feedback, the speed and acceleration the spindle's
 * speed asks of path and legs, the reach of a tap's run-on); -2 with err naming file and
 * line if not. On the executor: before the clock advances, drives a synchronised segment
 * from the spindle (true when it did: the plan clock is left alone); in evaluate, the path
 * position and speed there (true when on one). */
int motion_sync_check(struct motion *m, const struct motion_seg *sg, char *err,
                      size_t errlen);
/* (The ideal spindle's period, when it turns or was told to, and a synchronised line's
 * follower: the calls behind the two first tests.) */
void motion_sync_spindle(struct motion *m, double dt);
bool motion_sync_advance_line(struct motion *m, const struct motion_seg *sg, double dt);
/* The ideal spindle's period (motion_sync_spindle), where it turns or is told to. */
static inline void motion_sync_turn(struct motion *m, double dt)
{
    if (m->spindle_ideal && (m->io.dir * m->io.rpm != 0 || m->ideal_rps != 0))
        motion_sync_spindle(m, dt);
}
static inline bool motion_sync_advance(struct motion *m, double dt)
{
    motion_sync_turn(m, dt);
    const struct motion_seg *sg = &m->run->segs[m->cs];
    if (!sg->sync || sg->kind != SEG_LINE) {
        m->sync.phase = SYNC_IDLE;
        return false;
    }
    return motion_sync_advance_line(m, sg, dt);
}
/* The time synchronised segment j of p takes beyond its travel at S x K, for the plan's
 * time: the wait for the index at a run's first move, and a tap's spindle reversals with
 * the run-on travelled back (the executor's clock skips it, motion_step.c). */
double motion_sync_extra_s(const struct motion *m, const struct motion_plan *p, size_t j);
bool motion_sync_position(const struct motion *m, const struct motion_seg *sg, double *s,
                          double *v);
static inline bool motion_sync_at(const struct motion *m, double *s, double *v)
{
    const struct motion_seg *sg = &m->run->segs[m->cs];
    return sg->sync && motion_sync_position(m, sg, s, v);  /* (no call off a synchronised
                                                            * move) */
}
/* Whether the spindle drives the path now (following it, or a tap's own moves between): the
 * jerk limiter's moving average stands aside, so the tool keeps its place on the thread. */
bool motion_sync_direct(const struct motion *m);
/* A synchronised move's request for the encoder's index (spindle.0.index-enable), if one
 * is out, given up: the pin is cleared. */
void motion_sync_index_withdraw(struct motion *m);

/* Formats the instance's message (motion.c). */
void motion_set_msg(struct motion *m, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Manual motion (motion_manual.c) and homing (motion_home.c). */
void motion_note(struct motion *m, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
void motion_manual_step(struct motion *m, double dt);
void motion_home_step(struct motion *m);
/* Manual motion begins here (from IDLE or DONE): its leader starts at the command. */
void motion_manual_enter(struct motion *m);
void motion_joint_move(struct motion *m, int i, double target, double vel, int free_leg);
void motion_joint_halt(struct motion *m, int i);
bool motion_joint_idle(const struct motion *m, int i);

/* Checks a caller-filled configuration (motion_config.c). */
int motion_config_check(const struct motion_config *c, char *err, size_t errlen);

/* Path geometry (motion_path.c). */
void motion_seg_pose(const struct motion_plan *p, const struct motion_seg *sg, double s,
                     double pose[KINS_POSE_DIM]);
/* d pose / ds at s (mm or deg per unit of s). */
void motion_seg_tangent(const struct motion_plan *p, const struct motion_seg *sg, double s,
                        double dp[KINS_POSE_DIM]);
/* Pose at s with its first and second derivatives along the path (per unit of s). */
void motion_seg_derivs(const struct motion_plan *p, const struct motion_seg *sg, double s,
                       double pose[KINS_POSE_DIM], double dp[KINS_POSE_DIM],
                       double d2p[KINS_POSE_DIM]);
/* abc: NULL, or one entry per command of prog marking G64 blend arcs (motion_blend.h). */
struct motion_blend_abc;
int motion_path_build(struct motion *m, const struct canon_prog *prog,
                      const struct motion_blend_abc *abc, char *err, size_t errlen);
/* Largest |d2(A B C)/ds2| at s, deg/mm^2 (0 but on blend arcs). */
double motion_seg_abc_curvature(const struct motion_plan *p, const struct motion_seg *sg,
                                double s);
/* Room in an empty plan (no arrays yet) for nseg segments, narc arcs and nknot knots at
 * once: a streamed window's plan, whose arrays the executor took with the last window, gets
 * the last one's sizes instead of growing to them by doubling, a copy at each step (4 % of
 * the planner's instructions on dense code). -1, and nothing reserved, when out of memory. */
int motion_plan_reserve(struct motion_plan *p, size_t nseg, size_t narc, size_t nknot);
void motion_plan_free(struct motion_plan *p);
/* The plan's clock under the feed override (motion_rate.c). Plan position, speed and
 * acceleration at plan time tau within interval ci (its phases memoised in *mp). */
void motion_plan_at(const struct motion_plan *p, size_t ci, double tau, double *s, double *v,
                    double *a, struct motion_phase_memo *mp);
/* The override ceiling at plan time tau, which may lie past interval ci (>= 1). */
double motion_ceiling_ahead(const struct motion_plan *p, size_t ci, double tau);
/* The rate after a period dt: toward the target, within every phase's acceleration limit
 * the period passes, and at most the ceiling (vp: the plan's speed now). */
double motion_next_rate(const struct motion *m, double target, double vp, double ceiling,
                        double dt);

/* Planning (motion_plan.c). */
int motion_plan_profile(struct motion *m, char *err, size_t errlen);

/* Share of KINEMATIC_TOLERANCE the first-order (d^2) estimates of a chord's deviation may
 * use: 10 % is kept in hand for the terms they leave out. */
#define KIN_TOL_SHARE 0.9

/* With jerk limits, the share of a G64 tolerance P the rounding of the path by set-point
 * chords and the moving average may use (the blend arcs keep to the rest of P, so blend and
 * rounding together stay within P of the programmed path). */
#define JERK_ROUND_SHARE 0.5

/* The share of a G64 P a blend arc may cut a corner by, and a joint passed with a velocity
 * jump: all of it, with jerk limits (a moving average of jerk_window_s > 0) what the
 * rounding leaves. */
static inline double motion_blend_share(double jerk_window_s)
{
    return jerk_window_s > 0 ? 1 - JERK_ROUND_SHARE : 1;
}

/* The part of segment sg's G64 P that jerk limiting's rounding may use, mm (0 without jerk
 * limits or under G61): the one place of that rule. */
static inline double motion_jerk_round_mm(const struct motion *m, const struct motion_seg *sg)
{
    return m->jerk && sg->blend_tol_mm > 0 ? JERK_ROUND_SHARE * sg->blend_tol_mm : 0;
}

/* How far the set-point chords (and with jerk limits the moving average) may cut a curve,
 * mm: KIN_TOL_SHARE of KINEMATIC_TOLERANCE, or the rounding's share of G64 P (jerk_round_mm,
 * 0 without jerk limits or under G61) when that is larger (motion_jerk.c). */
static inline double motion_round_budget_mm(const struct motion_config *c,
                                            double jerk_round_mm)
{
    double t = KIN_TOL_SHARE * c->kin_tol_mm;
    return jerk_round_mm > t ? jerk_round_mm : t;
}

/* motion_round_budget_mm for a curve of segment sg. */
static inline double motion_round_tol_mm(const struct motion *m, const struct motion_seg *sg)
{
    return motion_round_budget_mm(&m->cfg, motion_jerk_round_mm(m, sg));
}

/* Share of one period's acceleration a G64 corner's velocity jump may use. */
#define JUMP_SHARE 0.5
/* A joint that could be passed only as fast as full acceleration reaches in this many servo
 * periods is planned as a stop (motion_plan.c): the moves beside it keep their whole
 * acceleration instead of sharing it with a jump that saves next to no time. */
#define STOP_EQUIV_PERIODS 2.0

/* all_caps samples the knots in order from here (on) or no longer (off): the planner's
 * look-ahead over knots (motion_caps.c). */
void motion_knot_ahead(struct motion *m, bool on);

/* Whether the operator asked to stop planning; if so err says where (motion_caps.c). */
bool motion_cancelled(const struct motion *m, const char *file, int line, char *err,
                      size_t errlen);

/* Sampling and caps (motion_caps.c). Speed caps of the knot at s of sg (knot spacing hs):
 * hard (machine, legs, kinematic error), with the feed (cap), path acceleration at every
 * speed up to hard (acc) and at rest (acc0, unless NULL); the sample into S. A leg out of
 * range is an error naming file, line, leg and amount. The acceleration limit is concave in
 * v^2 up to hard (each leg's is (aL - m |L''| v^2) / (|L'| + |L''| hs), the machine's
 * constant), so the chord acc0 - (acc0 - acc) v^2 / hard^2 lies under it there. */
int motion_knot_caps(struct motion *m, const struct motion_seg *sg, double s, double hs,
                     struct motion_sample *S, double *hard, double *cap, double *acc,
                     double *acc0, char *err, size_t errlen);
/* The speed cap of a knot within reach of a set-point chord touching an arc of path
 * curvature k_mm (1/mm) and A B C curvature kabc (deg/mm^2): the chord's cut of the path
 * plus the legs' own deviation stay within tol_mm (motion_round_tol_mm of the arcs), and
 * KIN_TOL_SHARE of the angular tolerance. HUGE_VAL when the bound is off; -1 when the pose
 * is singular. */
double motion_chord_cap(struct motion *m, const struct motion_seg *sg,
                        const struct motion_sample *S, double k_mm, double kabc, double tol_mm);

/* Chords near arcs (motion_chord.c). Marks the path within reach of a set-point chord that
 * touches an arc (chord_mm, chord_k, chord_kabc of every segment) and puts a knot where
 * that reach ends on a segment, so the cap holds exactly there; -1 when out of memory. */
int motion_chord_zones(struct motion *m);
/* Path curvature bound of an arc segment, 1/mm, and its largest A B C curvature into kabc. */
double motion_arc_curvature(const struct motion_plan *p, const struct motion_seg *sg,
                            double *kabc);
/* Speed allowed through the joint between segments a and b (0: stop there); A and B are
 * the samples at the end of a and the start of b, acc the largest path acceleration next
 * to the joint. */
double motion_junction_speed(struct motion *m, const struct motion_seg *a,
                             const struct motion_seg *b, const struct motion_sample *A,
                             const struct motion_sample *B, double acc);
/* Share of one period's acceleration (<= JUMP_SHARE) the velocity jump at a joint passed at
 * speed v uses; the moves on either side give it up. */
double motion_junction_share(const struct motion *m, const struct motion_sample *A,
                             const struct motion_sample *B, double v);
/* 6x6 inverse with partial pivoting (a is destroyed); 0 on success, -1 when singular. */
int motion_invert6(double a[6][6], double inv[6][6]);

/* A path pose of a segment as the platform's pose (the same unless under G43.4). */
static inline void motion_platform(const struct motion *m, int tcp, double tool_len_mm,
                                   const double P[KINS_POSE_DIM], double out[KINS_POSE_DIM])
{
    if (tcp)
        kins_tcp_to_pose(&m->tf, tool_len_mm, P, out);
    else if (out != P)
        for (int i = 0; i < KINS_POSE_DIM; i++)
            out[i] = P[i];
}
/* Leg lengths of a path pose (kins_inverse's status; legs written even when out of range). */
static inline int motion_path_inverse(struct motion *m, int tcp, double tool_len_mm,
                                      const double P[KINS_POSE_DIM], double *L)
{
    double q[KINS_POSE_DIM];
    if (!tcp)
        return kins_inverse(m->kins, P, L);
    kins_tcp_to_pose(&m->tf, tool_len_mm, P, q);
    return kins_inverse(m->kins, q, L);
}

#endif
