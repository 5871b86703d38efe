/* interp_int.h: the interpreter's internal state and the functions its files share. */
#ifndef HEXCNC_INTERP_INT_H
#define HEXCNC_INTERP_INT_H

#include <stdarg.h>

#include "interp/ccomp.h"
#include "interp/comp5.h"
#include "interp/interp.h"
#include "interp/probe_model.h"
#include "kins/kins.h"

#define INTERP_NPARAMS 5603      /* #1 .. #5602, as LinuxCNC */
#define INTERP_LINE_MAX 4096     /* characters in one program line */
#define INTERP_MAX_ASSIGN 64     /* #n= and #<name>= settings in one block */
#define INTERP_NAME_MAX 255      /* characters in a #<name> */
#define INTERP_GROUPS 15         /* G modal groups 0..14 (LinuxCNC numbering) */
#define INTERP_MGROUPS 10        /* M modal groups 0..9 */
#define MM_PER_INCH 25.4

enum { AX_X, AX_Y, AX_Z, AX_A, AX_B, AX_C };

/* Parameters with a fixed meaning (LinuxCNC's numbers). */
enum {
    PARAM_G28 = 5161,            /* 5161..5166: G28 home X..C, machine mm/deg */
    PARAM_G30 = 5181,            /* 5181..5186: G30 home */
    PARAM_G92_ON = 5210,         /* 1 while G92 offsets are applied */
    PARAM_G92 = 5211,            /* 5211..5216: G92 offsets */
    PARAM_COORD = 5220,          /* active coordinate system 1..9 */
    PARAM_G54 = 5221,            /* 5221..5226 G54, then every 20 up to 5381 (G59.3) */
    PARAM_ROT = 9,               /* PARAM_G54 + 20 n + PARAM_ROT: that system's rotation about
                                  * Z, deg (#5230 for G54, G10 L2 R) */
    PARAM_POS = 5420,            /* 5420..5428: the current point, program frame (read-only) */
    PARAM_PERSIST_LO = 5161,
    PARAM_PERSIST_HI = 5390,
};

/* One block as read: words by letter, G and M codes by modal group, #n= settings. */
struct interp_block {
    double val[28];              /* value of each letter word ('a' = 0; '@' 26, '^' 27) */
    int col[28];                 /* 1-based column of each word, 0 = absent */
    int plane_before;            /* the plane in force before this block (polar words) */
    int polar_inc;               /* G91 polar words: each cycle repeat turns about the origin
                                  * (interp_polar_step); X and Y hold the point itself, not
                                  * a step (interp_target), as LinuxCNC computes it */
    int g[INTERP_GROUPS];        /* G code x10 per group (G92.1 = 921), -1 = none */
    int gcol[INTERP_GROUPS];
    int m[INTERP_MGROUPS];       /* M code per group, -1 = none */
    int mcol[INTERP_MGROUPS];
    int nassign;
    int assign_idx[INTERP_MAX_ASSIGN];   /* parameter number, or named table entry */
    unsigned char assign_named[INTERP_MAX_ASSIGN]; /* 1: assign_idx is a named entry */
    double assign_val[INTERP_MAX_ASSIGN];
    int n_present;               /* the block has an N word */
    int n_number;
    int n_digits;                /* digits the N word was written with (N0100: 4), 0 if none */
    int has_comment;
    char comment[256];           /* last ( ) comment of the line, as written */
};

/* One named parameter; entries keep their place, so a block can refer to them by number. */
struct named_entry {
    char *name;                  /* lowercase, without spaces, as the line was normalised */
    int len;
    unsigned hash;
    double value;                /* mm and deg for lengths and angles, as numbered ones */
};

/* The named parameters set so far: entries in order, and an open-addressing hash index. */
struct named_table {
    struct named_entry *e;
    size_t n, cap;
    int *slot;                   /* entry number or -1; nslot is a power of two */
    size_t nslot;
};

/* G5.2 control points collected until G5.3 (nurbs.c). */
struct nurbs_point {
    double x, y;                 /* machine frame, mm */
    double w;                    /* weight (P) */
};
struct nurbs {
    struct nurbs_point *pt;      /* [0] is where the curve starts */
    int n, cap;
    int order;                   /* L: 3 (quadratic) unless a G5.2 gave more */
};

/* O-words (oword.c): the texts lines are read from, the open conditions and loops, the
 * subroutines known so far and the calls in progress. Positions are (text, line index). */
#define OWORD_LABEL_MAX 72       /* "123" or "<name>" as normalised, with the brackets */
#define OWORD_MAX_CALLS 64       /* subroutine nesting (recursion included) */
#define OWORD_LOOP_LIMIT 10000000L /* loop iterations in one program: more is a runaway */
/* Lines are found through a sparse index (the start of every OW_STRIDE-th line) and a
 * cursor (the line read last), so the index of a 10-million-line program takes 1.3 MB and
 * reading on from the cursor costs nothing. */
#define OW_STRIDE 64
struct ow_text {
    char *owned;                 /* the text, when read from a subroutine file, else NULL */
    const char *text;
    size_t len;
    size_t *off;                 /* off[k]: where line k * OW_STRIDE starts */
    int nlines;
    int cur_idx;                 /* a line whose start is cur_off (the next to read) */
    size_t cur_off;
    int mapped;                  /* text is a read-only mapping of the file: pages behind
                                  * the reading point are given back (oword_next_line) */
    size_t released;             /* bytes from the start given back so far */
    char file[256];              /* for messages */
};
struct ow_ctl {                  /* an open if, while, do or repeat */
    char label[OWORD_LABEL_MAX];
    int kind;                    /* OW_IF, OW_WHILE, OW_DO, OW_REPEAT */
    int text, idx;               /* the opening line */
    long count;                  /* repeat: iterations left */
    int done;                    /* if: a branch has run */
};
struct ow_sub {                  /* a subroutine: where its `sub` line is */
    char label[OWORD_LABEL_MAX];
    int text, idx;
};
/* The modal state M70/M73 save and M72 restores (LinuxCNC's list, as far as this machine
 * has it): units, plane, distance modes, feed mode, work offset system, tool length offset,
 * retract mode, path mode, F, S, spindle direction, coolant. */
struct modal_save {
    int valid;
    int inch, plane, incremental, arc_absolute, inverse_time, coord_system, retract_old_z;
    int per_rev;
    int path_mode;
    double path_tol_mm, naive_cam_tol_mm, feed_mm_min, f_word, spindle_rpm;
    int spindle_dir, mist, flood;
    double tool[6];
};

struct ow_call {                 /* a call in progress */
    char label[OWORD_LABEL_MAX];
    int text, idx;               /* where to go on when it returns */
    int nctl;                    /* the open constructs of the caller */
    double args[30];             /* the caller's #1..#30 */
    struct named_entry *locals;  /* the caller's local named parameters */
    size_t nlocals;
    struct modal_save m73;       /* M73 in this call: the state its return restores */
    int m98;                     /* an M98 call (a Fanuc subprogram, no arguments) ... */
    long m98_left;               /* ... to run this many more times (L) ... */
    int sub_idx;                 /* ... from this O<n> line of text `sub_text` */
    int sub_text;
};
struct oword {
    struct ow_text *texts;       /* [0] is the program */
    int ntexts, captexts;
    struct ow_ctl *ctl;
    int nctl, capctl;
    struct ow_sub *subs;
    int nsubs, capsubs;
    struct ow_call *calls;       /* [OWORD_MAX_CALLS], allocated at the first call */
    int ncalls;
    int text, idx;               /* the next line to read */
    long loops;                  /* loop iterations so far */
    long loop_limit;
    char *path;                  /* folders searched for o<name> call files, ':' separated */
    char *dir;                   /* the program's folder */
};

struct interp {
    /* configuration */
    double start[6];             /* initial machine pose, mm/deg */
    char *param_path;            /* parameter file or NULL */
    struct tooltable *tt;        /* tool table or NULL (not owned) */
    int mdi;                     /* lines typed one at a time: no program end needed */
    int text_mapped;             /* the program text is a file mapping (interp_run_file) */
    interp_input_fn input_fn;    /* M66's answer (NULL: 0) */
    void *input_ctx;
    interp_probe_fn probe_fn;    /* G38's answer from the machine (NULL: probe_model) */
    void *probe_ctx;
    struct probe_model probe_model; /* the workpiece interp and check probe */
    interp_contour_fn contour_fn; /* G141/G142's programmed points, for displays (NULL: none) */
    interp_ini_fn ini_get;       /* #<_ini[SECTION]KEY> (NULL: no INI) */
    void *ini_ctx;
    interp_hal_fn hal_fn;        /* #<_hal[name]> (NULL: no machine; reads 0) */
    void *hal_ctx;
    void *contour_ctx;
    double feed_factor;          /* mm/min per F unit in G21 */
    int block_delete;            /* 1: skip lines starting with '/' */
    const volatile sig_atomic_t *cancel; /* the operator's stop request, or NULL */

    /* where we are in the program */
    char file[256];
    int line;                    /* 1-based */
    int depth;                   /* nesting of [ ] and # while reading a value */
    int pct_open;                /* the program began with a % line */
    int pct_line;                /* the line of that opening % */
    int ended;                   /* M2/M30 or closing % seen */
    canon_sink_fn sink;
    void *sink_ctx;
    struct interp_error err;

    /* numbered parameters, mm and deg for lengths and angles */
    double params[INTERP_NPARAMS];
    struct named_table named;    /* #<name> (local to a program) and #<_name> (global) */
    /* #5161..#5390 as last reported in a CANON_SETTING (settings.c) */
    double persist_prev[PARAM_PERSIST_HI - PARAM_PERSIST_LO + 1];

    /* modal state */
    double pos[6];               /* current machine pose, mm/deg */
    int motion;                  /* G code x10 of group 1, -1 = G80 */
    int plane;                   /* 17, 18, 19 */
    int inch;                    /* G20 */
    int incremental;             /* G91 */
    int arc_absolute;            /* G90.1 (IJK absolute) */
    int inverse_time;            /* G93 */
    int per_rev;                 /* G95: F is mm (G20: inch) per spindle revolution, run as
                                  * F x the commanded S (feed.c) */
    int coord_system;            /* 1..9 */
    int retract_old_z;           /* G98 */
    int path_mode;               /* 610, 611 or 640 */
    double path_tol_mm;          /* G64 P */
    double naive_cam_tol_mm;     /* G64 Q: LinuxCNC's "naive CAM detector" tolerance; stored
                                  * and reported, not used by the planner (docs/gcode.md) */
    double g5x[6];               /* active work offset, mm/deg */
    double rot_deg;              /* the active system's rotation about Z, deg (rotation.c) */
    double g92[6];               /* active G92 offset */
    double tool[6];              /* active tool length offset (0 under G43.4) */
    struct kins_tool_frame tf;   /* where the machine's tool is (interp_set_tool_frame) */
    int have_tf;                 /* tf is set: G43.4 can run */
    int tcp_on;                  /* G43.4 (or PROGRAM_POINT = TOOL_TIP): pos is the tool tip
                                  * and orientation (kins_tcp_*), not the platform's pose */
    double tcp_len_mm;           /* the tool length tool centre point control uses */
    double feed_mm_min;          /* F in force, converted */
    double f_word;               /* F as programmed (for printers) */
    double cycle_r, cycle_q, cycle_p; /* sticky canned cycle words, program units */
    double cycle_depth;          /* sticky hole depth: the drilling axis word (Z in G17) */
    int cycle_mode;              /* the cycle (x10) whose words are sticky, 0 = none */
    int cycle_il_on;             /* a series of cycle blocks is going on */
    double cycle_il;             /* the level on the drilling axis (program units) that series
                                  * started from */
    int current_tool, selected_tool;
    int spindle_dir;             /* 1, -1, 0 */
    int flood, mist;             /* M8, M7 on (M9 turns both off) */
    double spindle_rpm;
    double comp_radius_mm;       /* W (or D's radius) of the open G141/G142 run, 0 = none */
    double g5_ij[2];             /* G5 without I J starts with these (program units): -P -Q
                                  * of the last G5, as LinuxCNC keeps them */
    struct nurbs nurbs;          /* G5.2 points waiting for G5.3 */

    struct oword ow;             /* O-word control flow */
    struct modal_save m70;       /* the state M70 saved, for M72 */
    struct comp5 comp;           /* G141/G142 run in progress */
    struct ccomp cc;             /* G41/G42 cutter compensation and its queued move */
    struct interp_block blk;     /* the block being worked on */
    char norm[INTERP_LINE_MAX];  /* the line lowercased without spaces and comments */
    int normcol[INTERP_LINE_MAX];/* original column of each norm char */
};

/* messages.c: a line's ( ) comment: COMMENT, and for (MSG,) (DEBUG,) (PRINT,) (LOG...) the
 * SETTING the machine acts on when the line executes. */
int interp_comment(struct interp *in, const char *text);
/* A PATH_MODE command for the path mode, G64 P and Q in force (exec.c). */
int interp_emit_path_mode(struct interp *in);
/* exec.c: M70..M73 state: fills a save; restores one (emitting what changed). */
void interp_modal_save(const struct interp *in, struct modal_save *m);
int interp_modal_restore(struct interp *in, const struct modal_save *m);

/* spline.c: G5 (cubic) and G5.1 (quadratic) splines as straight feeds (chords) that leave
 * the curve by at most SPLINE_TOL_MM; the planner follows them exactly. */
#define SPLINE_TOL_MM 1e-4
#define SPLINE_MAX_CHORDS 100000
int interp_spline(struct interp *in);
int interp_spline_cubic(struct interp *in);
/* Emits chords pts[1..n] from pts[0] (machine X Y, mm) as one spline block; ncp is the
 * number of control points printers show (rs274's NURBS_FEED(ncp, ...)). */
int interp_spline_emit(struct interp *in, const double (*pts)[2], int n, int ncp);
/* nurbs.c: G5.2 (a control point; prev_motion the motion mode before the block) and G5.3
 * (the curve). */
int interp_nurbs_point(struct interp *in, int prev_motion);
int interp_nurbs_end(struct interp *in);
void interp_nurbs_free(struct nurbs *nb);

/* The canon sink G141/G142 and the G41/G42 queue emit through (exec.c): stamps the tool
 * centre point state. */
int interp_comp_sink(void *ctx, const struct canon_cmd *cmd);

/* Records the first error (printf-style message) and returns status. */
int interp_fail(struct interp *in, int status, int column, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* lexer.c: reads one raw line into in->blk (evaluating expressions). *kind: 1 = a block
 * to run, 0 = nothing (deleted line), 2 = a lone '%', 3 = an O-word line (in->norm). */
int interp_read_line(struct interp *in, const char *raw, size_t len, int *kind);
/* expr.c: reads a real value at norm[*pos] ([expr], #n, function, number). */
int interp_read_value(struct interp *in, int *pos, double *out);
/* Reads an integer-valued parameter index or code (within 1e-4 of an integer). */
int interp_to_int(struct interp *in, double v, int column, const char *what, int *out);

/* named.c: #<name> parameters. interp_read_name reads "<name>" at norm[*pos] == '<' (col is
 * the '#' column for errors); name points into in->norm. */
int interp_read_name(struct interp *in, int *pos, int col, const char **name, int *len);
int interp_named_get(struct interp *in, const char *name, int len, int col, double *out);
int interp_named_exists(struct interp *in, const char *name, int len);
int interp_named_target(struct interp *in, const char *name, int len, int col, int *entry);
void interp_named_set(struct interp *in, int entry, double v);
void interp_named_clear_locals(struct interp *in);
void interp_named_free(struct interp *in);
/* oword.c */
int oword_begin(struct interp *in, const char *text, size_t len);
int oword_next_line(struct interp *in, const char **line, size_t *len);
int oword_execute(struct interp *in);
/* M98 P<n> L<k>: runs the subprogram that starts at the bare line O<n> k times. */
int oword_m98(struct interp *in);
/* M99: the end of an M98 subprogram (again while L lasts, then back after the M98); in the
 * main program *end is set: the program ends there, as rs274 reads it. */
int oword_m99(struct interp *in, int *end);
int oword_end(struct interp *in);
void oword_free(struct interp *in);
int interp_named_push_locals(struct interp *in, struct named_entry **saved, size_t *nsaved);
int interp_named_pop_locals(struct interp *in, struct named_entry *saved, size_t nsaved);
/* predef.c: 1 and *out = its value when name is one of the read-only #<_...> parameters. */
int interp_predefined(const struct interp *in, const char *name, int len, double *out);

/* block.c: files a G or M code into its group; checks the block as a whole. */
int interp_add_g(struct interp *in, double v, int column);
int interp_add_m(struct interp *in, double v, int column);
int interp_check_block(struct interp *in);

/* params.c */
int interp_params_load(struct interp *in, const char *path);
int interp_params_save(struct interp *in);
int interp_param_persistent(int n);     /* 1 if #n is written to the parameter file */
void interp_select_coord(struct interp *in, int system);
int interp_emit_offsets(struct interp *in);

/* settings.c: settings the machine keeps go out as CANON_SETTING commands; no file I/O. */
void interp_settings_begin(struct interp *in);
int interp_emit_param_changes(struct interp *in);
int interp_emit_tool_setting(struct interp *in, int tool);

/* exec.c: runs the block in in->blk in LinuxCNC's order of execution. */
int interp_execute(struct interp *in);
int interp_emit(struct interp *in, struct canon_cmd *c);
/* Polar coordinates (@ radius, ^ angle, in the XY plane about the program origin): the
 * block's X and Y words made from them, as G90 or G91 reads them (exec.c). */
int interp_polar_words(struct interp *in);
/* The next point of a G91 polar step from (x, y), program units (cycle repeats). */
void interp_polar_step(const struct interp *in, double *x, double *y);
void interp_cmd_init(struct interp *in, struct canon_cmd *c, enum canon_type t);
double interp_len_mm(const struct interp *in, double v); /* program length -> mm */
void interp_prog_pos(const struct interp *in, double prog[6]); /* current pos, program units */
/* Resolves axis words to a machine target (G90/G91, offsets, units; G53 when machine). */
void interp_target(struct interp *in, int machine, double target[6]);
/* G33 (g 330) and G33.1 (331), the block's axis words present or not (sync.c). */
int interp_sync_move(struct interp *in, int g, int axis);
int interp_straight(struct interp *in, enum canon_type t, const double end[6]);
/* feed.c: G95, feed per revolution. The feed in mm/min a block runs at (G94 and G95);
 * the feed mode command's value (0 G94, 1 G93, 2 G95); the checks of a feed move under G95. */
double interp_feed_mm_min(const struct interp *in);
int interp_feed_mode_value(const struct interp *in);
int interp_need_spindle(struct interp *in, const char *what, int col);
/* Checks a feed move has a feed (F in force, or F in the block under G93). */
int interp_need_feed(struct interp *in, const char *what);
int interp_probe(struct interp *in, int g);   /* G38.2..G38.5 (g x10), probe.c */

/* rotation.c: the active system's rotation about Z (G10 L2 R). */
/* Machine pose to program coordinates: offsets and rotation removed, inches under G20. */
void interp_machine_to_program(const struct interp *in, const double m[6], double out[6]);
void interp_rotate_xy(double *x, double *y, double deg);
/* Program X Y (program units) to machine X Y (mm), offsets and rotation applied. */
void interp_xy_to_machine(const struct interp *in, double px, double py, double m[2]);
/* The current point in the rotated frame (program X Y + G92), mm. */
void interp_rotated_pos(const struct interp *in, double q[2]);
/* G10 L2/L20 X Y (and L2 R) on system sys when a rotation is involved (offsets.c). */
void interp_g10_rotated(struct interp *in, int l, int sys);
/* G28/G30 with X or Y alone under a rotation: the machine X Y of the home move (t[0..1]). */
void interp_home_rotated(const struct interp *in, int base, double t[2]);

/* arc.c */
int interp_arc(struct interp *in, int g);
/* cycles.c */
int interp_cycle(struct interp *in, int g);
/* offsets.c: G10, G28/G30, G92 family, G43/G49. */
int interp_g10(struct interp *in);
int interp_home(struct interp *in, int g);
int interp_g92(struct interp *in, int g);
int interp_tool_length(struct interp *in, int g);
/* The machine's platform pose of in->pos, and back: in->pos set from a platform pose in the
 * representation in force (the tip under G43.4). */
void interp_pos_platform(const struct interp *in, double plat[6]);
void interp_pos_from_platform(struct interp *in, const double plat[6]);

#define CHP(call) do { int rc_ = (call); if (rc_) return rc_; } while (0)

#endif
