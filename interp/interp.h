/* interp.h: the RS274/NGC interpreter (LinuxCNC dialect): G-code text in, canonical commands out. */
#ifndef HEXCNC_INTERP_H
#define HEXCNC_INTERP_H

#include <signal.h>
#include <stddef.h>

#include "interp/canon.h"

struct tooltable;
struct interp;

/* What went wrong. 0 = OK; every other value comes with a message in struct interp_error. */
enum interp_status {
    INTERP_OK = 0,
    INTERP_ERR_IO,            /* the program, parameter or tool file cannot be read/written */
    INTERP_ERR_NOMEM,         /* out of memory */
    INTERP_ERR_SYNTAX,        /* a word, number or expression that does not parse */
    INTERP_ERR_EXPR,          /* an expression that cannot be evaluated (domain, /0) */
    INTERP_ERR_PARAM,         /* a bad parameter number or parameter file */
    INTERP_ERR_MODAL,         /* two codes of one modal group, or a code that needs another */
    INTERP_ERR_WORD,          /* a word missing, repeated, out of range or not allowed here */
    INTERP_ERR_UNSUPPORTED,   /* a valid RS274/NGC construct this interpreter does not run */
    INTERP_ERR_ARC,           /* an arc that cannot be made (radius mismatch, zero radius) */
    INTERP_ERR_CYCLE,         /* a canned cycle with inconsistent R/Z/Q/P */
    INTERP_ERR_TOOL,          /* a tool number not in the tool table, or a tool table error */
    INTERP_ERR_COMP5,         /* G141/G142 compensation refused the path */
    INTERP_ERR_SINK,          /* the canon sink asked to stop */
    INTERP_ERR_CONFIG,        /* a bad interpreter setting in the machine's INI file */
    INTERP_ERR_CANCELLED,     /* the cancel flag was set (Ctrl-C) while the program was read */
    INTERP_ERR_CCOMP,         /* G41/G42 cutter compensation refused the path or the code */
    INTERP_ERR_PROBE,         /* G38.2/G38.4 without a trip, a probe tripped at the start, or
                               * probing the machine cannot do */
    INTERP_STATUS_COUNT
};
const char *interp_strerror(int status);

/* The first error of a run: where and what. column is 1-based, 0 when not known. */
struct interp_error {
    int status;               /* enum interp_status */
    char file[256];           /* program file name as given to the interpreter */
    int line;                 /* 1-based source line, 0 when the error is not in the program */
    int column;               /* 1-based column of the offending word, 0 if unknown */
    char message[256];        /* what is wrong, in a machinist's words */
};
/* Formats "file:line:col: error: message" (col left out when 0) into buf; returns buf. */
char *interp_error_format(const struct interp_error *e, char *buf, size_t len);

/* Lifecycle. interp_create returns NULL when out of memory. */
struct interp *interp_create(void);
void interp_destroy(struct interp *in);

/* Configuration (before a run). The initial pose is in machine coordinates (mm, deg). */
void interp_set_start(struct interp *in, const double pose[6]);
/* Parameter file (LinuxCNC's format, "number value" per line). Loads it now if it exists and
 * remembers it as the file interp_setting_apply() saves the persistent parameters
 * (5161..5390) to. Interpreting a program never writes it. NULL: no file. Returns INTERP_OK
 * or an error (details in interp_last_error). */
int interp_set_param_file(struct interp *in, const char *path);
/* Loads a parameter file as interp_set_param_file() does but remembers no file to save to,
 * so that even interp_setting_apply() leaves the machine's offsets as they are. */
int interp_load_param_file(struct interp *in, const char *path);
/* Folders, ':' separated, where `o<name> call` looks for name.ngc when the program does not
 * define the subroutine (after the program's own folder). NULL: none. */
int interp_set_subroutine_path(struct interp *in, const char *path);
/* Loop iterations one program may run before it is refused as a runaway (default 10^7). */
void interp_set_loop_limit(struct interp *in, long iterations);
/* Tool table for T/M6, G43 H and the D word of G141/G142; not owned. NULL: no table. */
void interp_set_tooltable(struct interp *in, struct tooltable *tt);
/* F multiplier for metric programs: 1 for FEED_UNITS = mm/min, 1000 for m/min. */
void interp_set_feed_factor(struct interp *in, double mm_min_per_f_unit);
/* Block delete switch: 1 skips lines that start with '/'; 0 (the default, as rs274) runs
 * them. */
void interp_set_block_delete(struct interp *in, int on);
/* A flag (set by the caller's SIGINT handler; NULL: none) that the line loop checks before
 * every line: once it is non-zero the run stops with INTERP_ERR_CANCELLED at that line.
 * Not owned; it must outlive the runs. */
void interp_set_cancel(struct interp *in, const volatile sig_atomic_t *flag);
/* Parses an [RS274NGC] FEED_UNITS value ("mm/min" or "m/min"); -1 if unknown, else 0. */
int interp_feed_units_parse(const char *name, double *factor);

/*
 * Settings that G-code writes (G10 L1 tool entries; G10 L2/L20, G28.1/G30.1, G92, G54..G59.3
 * and #n= on the persistent parameters 5161..5390) change the interpreter's state at once, so
 * later lines see them, but no file is written while interpreting: each line that changes
 * them sends a CANON_SETTING command, and whoever executes the program hands it to
 * interp_setting_apply() of an interpreter set up with the machine's files when execution
 * reaches it (the runner does; `hexcnc interp` and `hexcnc check` never do).
 */
/* Applies setting s to in's parameters and tool table and saves the parameter file and/or
 * the tool table (when in has them). INTERP_OK, or a status with err naming the file. */
int interp_setting_apply(struct interp *in, const struct canon_setting *s, char *err,
                         size_t errlen);
/* Whether the files interp_setting_apply(in, s) would write can be written, without writing
 * anything: INTERP_OK, or INTERP_ERR_IO with err naming the file and the reason. */
int interp_setting_check(const struct interp *in, const struct canon_setting *s, char *err,
                         size_t errlen);

/* Runs a whole program, sending canonical commands to sink. The state (modes, position,
 * offsets, parameters) persists from run to run on one interpreter. Returns INTERP_OK or
 * the status of the first error, after which nothing more is emitted. */
int interp_run_file(struct interp *in, const char *path, canon_sink_fn sink, void *ctx);
/* The same for a program held in memory; file_name is used in commands and errors. */
int interp_run_text(struct interp *in, const char *file_name, const char *text, size_t len,
                    canon_sink_fn sink, void *ctx);
const struct interp_error *interp_last_error(const struct interp *in);
/* M66: after the sink got the CANON_WAIT_INPUT command, fn returns the machine's answer
 * (the input's value, or -1 after the time-out), which becomes #5399 for the lines after it;
 * fn may block until the machine has reached the wait. NULL (the default): 0, as rs274. */
typedef double (*interp_input_fn)(void *ctx, const struct canon_cmd *wait);
void interp_set_input_fn(struct interp *in, interp_input_fn fn, void *ctx);
/* G38.2..G38.5: after the sink got the CANON_PROBE command, fn gives the machine's answer in
 * r (it may block until the move has ended): 0, or non-zero with why (a machinist's words:
 * "the probe is already tripped") and the program stops with an error at the probe's line.
 * NULL (the default): the probe model of interp_set_probe_model answers, and without one
 * the interpreter answers as LinuxCNC's rs274 does (no trip; the move ends 0.254 mm short
 * of its end point). */
struct interp_probe_result {
    int tripped;              /* the probe changed state during the move: #5070 = 1 */
    double trip[6];           /* machine pose where it did (else where the move ended):
                               * #5061..#5066, in program coordinates */
    double stop[6];           /* machine pose the machine came to rest at: the program goes
                               * on from here */
};
typedef int (*interp_probe_fn)(void *ctx, const struct canon_cmd *probe,
                               struct interp_probe_result *r, char *why, size_t whylen);
void interp_set_probe_fn(struct interp *in, interp_probe_fn fn, void *ctx);
/* The simulated workpiece `hexcnc interp` and `check` probe ([PROBE] in the INI, read by
 * interp_setup); copied. NULL or PROBE_MODEL_NONE: none. */
struct probe_model;
void interp_set_probe_model(struct interp *in, const struct probe_model *m);
/* G141/G142, for displays: fn gets each block's programmed contour point (machine frame, mm
 * and deg) before the compensation offsets it; first is 1 for a run's first block, whose
 * contour starts at from. NULL (the default): nothing is called. */
typedef void (*interp_contour_fn)(void *ctx, int line, int first, const double from[6],
                                  const double point[6]);
void interp_set_contour_fn(struct interp *in, interp_contour_fn fn, void *ctx);
/* #<_ini[SECTION]KEY>: get(ctx, SECTION, KEY) gives the INI's value text or NULL (the same
 * lookup as struct kins_config); ctx must outlive the interpreter's runs. NULL: no INI. */
typedef const char *(*interp_ini_fn)(void *ctx, const char *section, const char *key);
void interp_set_ini(struct interp *in, interp_ini_fn get, void *ctx);
/* #<_hal[name]>: fn(ctx, name, &value) reads a HAL pin or signal of the running machine, 0
 * or -1 when there is none. NULL (the default, `hexcnc interp` and `check`): reads 0. */
typedef int (*interp_hal_fn)(void *ctx, const char *name, double *value);
void interp_set_hal_fn(struct interp *in, interp_hal_fn fn, void *ctx);
/* Sets numbered parameter #n (1..5602) (the session: #5399 after an MDI line's M66). */
void interp_set_param(struct interp *in, int n, double v);
/* MDI: lines come one at a time (a run need not end with M2 or M30). */
void interp_set_mdi(struct interp *in, int on);
/* Where the machine's tool is, from its kinematics (kins_tool_frame): G43.4 needs it. When
 * f->program_tip ([KINS] PROGRAM_POINT = TOOL_TIP), tool centre point control is on from the
 * start with f->length_mm. The start pose stays the platform's pose (the machine's). */
struct kins_tool_frame;
void interp_set_tool_frame(struct interp *in, const struct kins_tool_frame *f);
/* The same from a kinematics instance, when its model has a tool (else nothing changes). */
struct kins;
void interp_use_kins(struct interp *in, struct kins *k);
/* The tool in the spindle (as M61 Q sets it, without a tool change). */
void interp_set_current_tool(struct interp *in, int tool);

/* A read-only view of the modal state, for tools that print program coordinates. */
struct interp_view {
    int inch;                 /* 1 under G20 */
    int plane;                /* 17, 18 or 19 */
    int coord_system;         /* 1..9 for G54..G59.3 */
    double g5x_mm[6];         /* offset of the active coordinate system (mm, deg) */
    double g92_mm[6];         /* G92 offset (mm, deg) */
    double tool_mm[6];        /* tool length offset (Z only for G43 H; 0 under G43.4) */
    double xy_rotation_deg;   /* the coordinate system's rotation about Z (G10 L2 R), deg */
    int tcp;                  /* tool centre point control (G43.4) is on */
    double tcp_len_mm;        /* its tool length, mm */
    double feed_factor;       /* see interp_set_feed_factor */
    int current_tool;         /* tool in the spindle */
    int path_mode;            /* 610 (G61), 611 (G61.1) or 640 (G64) */
    double path_tol_mm;       /* G64 P: blend tolerance, mm (0: none given) */
    double naive_cam_tol_mm;  /* G64 Q: naive CAM tolerance, mm (0: none given) */
    int comp5_active;         /* a G141/G142 run is open */
    int motion;               /* group 1 modal code x10 (0 G0, 10 G1, ...), -1: G80 */
    int incremental;          /* 1 under G91 */
    int inverse_time;         /* 1 under G93 */
    int per_rev;              /* 1 under G95 (feed per revolution) */
    double feed_mm_min;       /* F in force, mm/min */
    int spindle_dir;          /* 1 (M3), -1 (M4), 0 (M5) */
    double spindle_rpm;       /* S in force */
    int flood, mist;          /* M8, M7 in force */
    int selected_tool;        /* T of the last T word */
};
void interp_get_view(const struct interp *in, struct interp_view *v);
/* A machine pose (mm, deg) in the program coordinates of view v: offsets and the rotation
 * removed, inches under G20 (what rs274 prints, what a display shows). */
void interp_view_to_program(const struct interp_view *v, const double machine[6],
                            double prog[6]);
/* Numbered parameter #n (1..5602), or 0 when out of range. */
double interp_param(const struct interp *in, int n);

/* Number conversion used by the lexer: reads a decimal such as "-12.345" starting at s
 * (no exponent, as in G-code), correctly rounded (the same double strtod gives). Returns
 * the number of characters read, 0 if none. Exposed for tests and the benchmark. */
size_t interp_parse_decimal(const char *s, size_t len, double *out);

#endif
