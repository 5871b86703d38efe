/* canon.h: the canonical command stream from the interpreter to the motion planner. */
#ifndef HEXCNC_CANON_H
#define HEXCNC_CANON_H

#include <stddef.h>

/*
 * Units and frames: every position in this stream is a pose in machine coordinates, the
 * frame the kinematics takes (X Y Z mm, A B C deg): work offsets (G54..G59, G92) and the
 * tool length offset are already applied, inch programs already converted. Feeds are mm/min
 * for linear motion (rotary-only moves: deg/min), whatever the program's F units were.
 * The start of every move is the end of the previous one (the interpreter's initial
 * position is given to it by its caller).
 */
enum canon_type {
    CANON_TRAVERSE,        /* G0: rapid to end */
    CANON_FEED,            /* G1 (and compensated G141/G142 lines): straight feed to end */
    CANON_ARC,             /* G2/G3 (and the corner arcs of G141/G142): arc/helix to end */
    CANON_DWELL,           /* G4: seconds */
    CANON_FEED_RATE,       /* F changed: feed_mm_min (G95, ivalue 1: value = F per rev) */
    CANON_FEED_MODE,       /* G93/G94/G95: value = 1 for inverse time, 0 for units/min, 2 for
                            * feed per revolution (moves still carry feed_mm_min: F x S) */
    CANON_PATH_MODE,       /* G61 (value 0) / G64 (value = blend tolerance mm, 0 = none) */
    CANON_SPINDLE_SPEED,   /* S: value = rpm */
    CANON_SPINDLE_ON,      /* M3 (value = +1) / M4 (value = -1) */
    CANON_SPINDLE_STOP,    /* M5 */
    CANON_TOOL_CHANGE,     /* M6 (value 0) or M61 Q (value 1: the number only, no change):
                            * ivalue = the tool now in the spindle */
    CANON_COOLANT,         /* M7 (ivalue 7), M8 (8), M9 (9) */
    CANON_COMMENT,         /* ( ... ): text; ivalue a CANON_NOTE_* for an active comment
                            * (its text then expanded: printers show rs274's MESSAGE, LOG...) */
    CANON_PAUSE,           /* M0 (ivalue 0) / M1 optional stop (ivalue 1) */
    CANON_PROGRAM_END,     /* M2 / M30 (ivalue 2 or 30) */
    CANON_OFFSETS,         /* informational: the total offset in force changed (offset[]:
                            * work + G92 + tool, as if unrotated) or the coordinate system's
                            * rotation about Z did (value, deg: G10 L2 R) */
    CANON_SETTING,         /* a setting the machine keeps (setting): a tool-table entry (G10
                            * L1) and/or persistent parameters #5161..#5390 (G10 L2/L20,
                            * G28.1/G30.1, G92, G54..G59.3, #n=) changed by this line. It
                            * takes effect, and is saved, when execution reaches it: motion
                            * passes it in order as a point of zero length */
    CANON_DIGITAL_OUT,     /* M62/M63 (synchronised with motion) and M64/M65 (immediate):
                            * output ivalue set (value 1) or cleared (0) */
    CANON_ANALOG_OUT,      /* M67 (synchronised) / M68 (immediate): output ivalue = value */
    CANON_WAIT_INPUT,      /* M66: wait (at rest) on input ivalue (analog: E, else P) in
                            * wait_mode (0 read at once, 1 rise, 2 fall, 3 high, 4 low) for
                            * at most value seconds; its result is #5399 */
    CANON_PROBE,           /* G38.2..G38.5: straight feed towards end that stops where the
                            * probe input changes; ivalue = LinuxCNC's probe type (0 G38.2,
                            * 1 G38.3, 2 G38.4, 3 G38.5: bit 0 no error without a trip, bit 1
                            * away from the workpiece: trip on loss of contact). The move
                            * starts and ends at rest; the next command starts at probe_stop */
    CANON_TYPE_COUNT
};

/* One arc: in the plane through `center` normal to `normal` (unit vector, right-handed),
 * from the previous end to end[0..2], turning counter-clockwise about `normal` when
 * rotation > 0 and clockwise when < 0; |rotation| - 1 extra full turns (LinuxCNC's
 * convention). The component of the motion along `normal` and the A B C axes change
 * linearly with the angle (helix). plane is 17, 18 or 19 for G17/G18/G19 arcs, 0 for 3-D
 * arcs the compensation made (any normal). */
struct canon_arc {
    double center[3];      /* mm, machine frame */
    double normal[3];      /* unit */
    int rotation;          /* signed turn count, see above */
    int plane;             /* 17, 18, 19, or 0 */
};

/* One persistent parameter as a line left it. */
struct canon_param {
    int number;            /* 5161..5390 */
    double value;          /* mm and deg for lengths and angles, as in the parameter file */
};

struct tool_entry;

/* What a comment asks of the machine when its line executes (LinuxCNC's active comments). */
enum canon_note {
    CANON_NOTE_NONE = 0,
    CANON_NOTE_MSG,        /* (MSG, text): a message to the operator */
    CANON_NOTE_DEBUG,      /* (DEBUG, text #1 #<name>): the same, parameters in their values */
    CANON_NOTE_PRINT,      /* (PRINT, text): on the controller's standard error */
    CANON_NOTE_LOGOPEN,    /* (LOGOPEN, file): the log file, new */
    CANON_NOTE_LOGAPPEND,  /* (LOGAPPEND, file): the log file, added to */
    CANON_NOTE_LOG,        /* (LOG, text): a line in the log file */
    CANON_NOTE_LOGCLOSE,   /* (LOGCLOSE) */
};

/* Spindle-synchronised moves (G33, G33.1). A rigid tap is two moves, into the hole and back
 * out to where it started, so that every consumer sees where the tool goes; printers show
 * the pair as rs274's one RIGID_TAP. */
enum canon_sync {
    CANON_SYNC_NONE = 0,
    CANON_SYNC_THREAD,     /* G33: the path position is pitch x spindle revolutions */
    CANON_SYNC_TAP_IN,     /* G33.1 into the hole: at its end the spindle reverses */
    CANON_SYNC_TAP_OUT,    /* G33.1 back out, following the reversed spindle; at its end the
                            * spindle's direction is restored */
};

/* The payload of CANON_SETTING: what the machine saves (or says, or logs) when it executes
 * the line. */
struct canon_setting {
    const struct tool_entry *tool; /* the tool's whole entry after G10 L1, or NULL */
    size_t nparams;                /* persistent parameters the line changed */
    const struct canon_param *params;
    enum canon_note note;          /* a comment's action, or CANON_NOTE_NONE */
    const char *text;              /* its text, parameters expanded (a log file: its path,
                                    * relative ones from the program's folder) */
};

struct canon_cmd {
    enum canon_type type;
    int line;              /* source line number (1-based) in `file` */
    const char *file;      /* program file name (owned by the interpreter, outlives the stream) */
    double end[6];         /* TRAVERSE, FEED, ARC: target pose, machine frame */
    double feed_mm_min;    /* FEED, ARC: the feed in force (FEED_RATE: the new feed) */
    double inverse_time_min; /* FEED, ARC under G93: minutes the move must take, else 0 */
    double value;          /* DWELL s, PATH_MODE tol, SPINDLE_* rpm/dir, FEED_MODE */
    double naive_tol_mm;   /* PATH_MODE under G64: Q, LinuxCNC's naive CAM tolerance (straight
                            * feeds that stay within it of one line run as that line) */
    int ivalue;            /* TOOL_CHANGE tool, COOLANT code, PAUSE/PROGRAM_END code */
    int compensated;       /* FEED, ARC: 141 or 142 when made by G141/G142, else 0 */
    int spline;            /* FEED: a chord of a G5/G5.1 spline or a G5.3 NURBS, 1 the
                            * block's first (ivalue: its control points), 2 the others
                            * (printers show rs274's one NURBS_FEED(ivalue, ...) line) */
    int tcp;               /* under tool centre point control (G43.4): end (and an arc's
                            * geometry) is the tool tip and orientation (kins_tcp_to_pose
                            * gives the platform's pose), tool_len_mm the tool's length */
    double tool_len_mm;
    int sync;              /* FEED: 0, or a spindle-synchronised move whose path position
                            * follows the spindle (motion/motion_sync.c): CANON_SYNC_* */
    double pitch_mm_rev;   /* FEED with sync: K, mm of path per spindle revolution */
    double pitch_word;     /* ... K as the program wrote it (inch under G20), for printers */
    double retract_factor; /* CANON_SYNC_TAP_IN/OUT: G33.1's I, the multiple of the spindle's
                            * speed it reverses to for the way out (1 without I) */
    int immediate;         /* DIGITAL_OUT, ANALOG_OUT: M64/M65/M68 (else M62/M63/M67) */
    int analog;            /* WAIT_INPUT: an analog input (E), else digital (P) */
    int wait_mode;         /* WAIT_INPUT: L, 0..4 */
    double offset[6];      /* OFFSETS: total offset in force (work + G92 + tool), mm/deg */
    double probe_stop[6];  /* PROBE: where the interpreter takes the move to end, machine
                            * frame: where its probe model trips, else 0.254 mm short of end
                            * (rs274's back-off) or at end; the machine answers its own */
    struct canon_arc arc;  /* ARC only */
    const char *text;      /* COMMENT text (owned by the interpreter) */
    const struct canon_setting *setting; /* SETTING only: valid during the sink call (the
                                          * interpreter's); canon_prog_sink keeps a copy */
    int has_n;             /* the source block had an N word (for printers) */
    int n_number;          /* its value */
    int n_digits;          /* digits as written, leading zeros kept (N0100: 4), for printers */
};

/* Where the interpreter sends commands. Return 0 to continue, non-zero to stop the
 * interpreter (its status is then INTERP_ERR_SINK). */
typedef int (*canon_sink_fn)(void *ctx, const struct canon_cmd *cmd);

/* A growable in-memory program: the whole canonical stream of one program, so that a
 * program is interpreted and verified completely before any motion starts. */
struct canon_prog {
    struct canon_cmd *cmds;
    size_t count;
    size_t cap;
    double start[6];       /* pose the program starts from */
    int start_tcp;         /* start is the tool tip under G43.4 with this tool length (a */
    double start_tool_len_mm; /* streamed window's start); 0: the platform's pose */
    int start_path_mode;   /* the path mode before the first command: 0 LinuxCNC's default
                            * (G64 with [TRAJ] BLEND_TOLERANCE), 610 exact stop, 640 G64 with
                            * start_path_tol_mm (an MDI line under its interpreter's mode) */
    double start_path_tol_mm;
};
void canon_prog_init(struct canon_prog *p);
void canon_prog_free(struct canon_prog *p);
/* A canon_sink_fn that appends to a struct canon_prog (ctx); it copies COMMENT text and
 * SETTING payloads, so the program owns everything it holds. Returns -1 on allocation
 * failure. */
int canon_prog_sink(void *ctx, const struct canon_cmd *cmd);
const char *canon_type_name(enum canon_type t);

#endif
