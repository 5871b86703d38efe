/* comp5.h: five-axis tool radius compensation, G141 (right) and G142 (left), as in the paper. */
#ifndef HEXCNC_COMP5_H
#define HEXCNC_COMP5_H

#include "interp/canon.h"
#include "interp/comp5_gouge.h"

/*
 * The interpreter hands every block that carries G141 or G142 to comp5_block(), with the
 * programmed contour point already resolved to machine coordinates (offsets applied, mm,
 * deg). Consecutive compensated blocks form a run: comp5 keeps one block of look-ahead,
 * positions the tool at the compensated start, cuts each segment offset by the radius along
 * V = unit(T x N) (right: +W V, left: -W V; N = Rz(C) Ry(B) Rx(A) [0 0 1]), and joins
 * segments at corners (inside: the meeting point of the offset lines, or their closest
 * approach when skew; outside: an arc of radius W about the programmed corner). The first
 * block that does not carry G141/G142 (or the end of the program) ends the run: the
 * interpreter calls comp5_flush() before it handles that block.
 *
 * What comp5 emits (docs/compensation.md has the details and the reasons):
 *  - The second block of a run emits the positioning move: a CANON_FEED (not a rapid: it
 *    belongs to a G141/G142 block that carries F) from the tool's pose to the compensated
 *    start, with the FIRST block's line, file and feed.
 *  - Each segment P(k-1) -> P(k) is cut as a CANON_FEED with block k's line, file and feed,
 *    ending at the join it makes with the next segment (or, at comp5_flush(), at its own
 *    compensated end). Each point P(k) is offset with its own block's radius and with the
 *    normal N of its own A B C, as in the paper's per-block formula.
 *  - An outside corner at P(k) adds a CANON_ARC (plane 0, center P(k), radius W(k), normal
 *    unit(u_a x u_b) of the two offset directions, rotation +1), with block k's line. Both
 *    ends of the arc use P(k)'s orientation, so A B C stay constant along the arc.
 *  - Every emitted move has compensated = 141 or 142 and starts where the last one ended.
 *
 * Between comp5_block() calls the emitted path lags one block behind the program: the
 * interpreter takes comp5_tool_pos() as the tool's pose after comp5_flush(). After an error
 * the run is dropped (c->active = 0); c->err_line and comp5_errmsg() say what was wrong.
 */

/* Tolerances, with their units. */
#define COMP5_EPS_MM 1e-6          /* mm: shorter moves are zero-length; points closer coincide */
#define COMP5_EPS_DEG 1e-9         /* deg: orientations closer than this are equal */
#define COMP5_MIN_SIN_AXIS 1e-3    /* |T x N| below this (motion within ~0.06 deg of the tool
                                    * axis) leaves the compensation direction undefined */
#define COMP5_EPS_SIN_PARALLEL 1e-9 /* sine below which two offset lines count as parallel */

enum comp5_status {
    COMP5_OK = 0,
    COMP5_ERR_SINGLE_BLOCK,   /* a run with fewer than two distinct points */
    COMP5_ERR_ZERO_LENGTH,    /* a compensated block that does not move X Y Z */
    COMP5_ERR_ALONG_AXIS,     /* motion parallel to the tool axis: T x N = 0 */
    COMP5_ERR_MIXED_SIDES,    /* G141 and G142 in one run */
    COMP5_ERR_RADIUS,         /* radius missing, zero or negative */
    COMP5_ERR_GOUGE,          /* an inside corner the tool cannot reach without gouging */
    COMP5_ERR_GOUGE_CONTOUR,  /* the tool comes closer than W to the run's contour */
    COMP5_ERR_NO_MEMORY,      /* the run's record for the gouge check could not grow */
    COMP5_ERR_SINK,           /* the canon sink refused a command */
    COMP5_ERR_SIDE,           /* side is neither 141 nor 142 (a caller's mistake) */
    COMP5_STATUS_COUNT
};
const char *comp5_strerror(int status);

/* One compensated block, as the interpreter resolved it. */
struct comp5_block {
    int side;                 /* 141 (right) or 142 (left) */
    double point[6];          /* programmed contour point and orientation, machine frame */
    double radius_mm;         /* effective tool radius (W, or tool table diameter/2 + wear);
                               * 0 or NaN when the block has none: an error (COMP5_ERR_RADIUS) */
    double feed_mm_min;       /* feed in force */
    int line;                 /* source line, for the emitted moves and for errors */
    const char *file;
    double prog_off_mm[3];    /* machine X Y Z = program X Y Z * unit_mm + prog_off_mm: lets
                               * errors name points in program coordinates */
    double unit_mm;           /* mm per program length unit (0 is taken as 1) */
};

/* The offset line of one programmed segment: its two compensated ends. */
struct comp5_seg {
    double a0[6];             /* compensated start (P(k-1) + s W(k-1) V), its orientation */
    double a1[6];             /* compensated end (P(k) + s W(k) V), its orientation */
    double dir[3];            /* unit direction of travel T of the programmed segment */
    double t_start;           /* where the cut of this segment begins, as a fraction of
                               * a0 -> a1 (0 unless an inside join moved it) */
};

/* State of one run. Embedded in the interpreter's state; no allocation. */
struct comp5 {
    int active;               /* a run is open */
    int nblocks;              /* blocks seen in the current run */
    int side;                 /* 141 or 142 for the current run */
    double start[6];          /* tool position when the run began (machine frame) */
    struct comp5_block prev;  /* the buffered block (look-ahead of one) */
    struct comp5_block prev2; /* the block before it (corner joins need both segments) */
    double tool_pos[6];       /* where the emitted moves have left the tool */
    int err_line;             /* line the last error refers to */
    struct comp5_seg seg;     /* the segment prev2 -> prev, not yet cut (nblocks >= 2) */
    char err_msg[240];        /* the last error in a machinist's words (no file:line prefix) */
    struct comp5_gouge gouge; /* the run's contour and moves, checked when it ends (heap) */
    const struct kins_tool_frame *tf; /* G43.4: the tool (N from it, comp5_axis); NULL: the
                               * paper's N. Set by the interpreter before each block */
};

void comp5_init(struct comp5 *c);
/* Frees the record of an open run (a run dropped by an error elsewhere); then idle. */
void comp5_free(struct comp5 *c);
/* Adds a compensated block; start is the tool pose before it (used when it opens a run).
 * May emit canon commands. On error returns a status and sets c->err_line. */
int comp5_block(struct comp5 *c, const struct comp5_block *b, const double start[6],
                canon_sink_fn sink, void *ctx);
/* Ends the current run (no-op when none is open), emitting the buffered moves, then checks
 * the whole run for gouges (comp5_gouge.h): COMP5_ERR_GOUGE_CONTOUR names the line, the
 * depth and the contour point. */
int comp5_flush(struct comp5 *c, canon_sink_fn sink, void *ctx);
/* Where the tool is after the emitted moves (valid after comp5_flush or while active). */
const double *comp5_tool_pos(const struct comp5 *c);
/* The last error, in words, e.g. "G141 inside corner at line 12: ..." (never NULL). */
const char *comp5_errmsg(const struct comp5 *c);

/* The tool axis N at orientation abc (deg): the paper's R [0 0 1] when tf is NULL, else the
 * tool's direction in the program's frame under G43.4 (kins_tcp_tool_dir). */
struct kins_tool_frame;
void comp5_axis(const struct kins_tool_frame *tf, const double abc[3], double n[3]);
/* The table normal N = R [0 0 1] for orientation A, B, C in degrees (paper's step 2). */
void comp5_normal(double a_deg, double b_deg, double c_deg, double n[3]);
/* The compensated point of one segment (paper's steps 1..4): p + s W unit(T x N), with
 * s = +1 for G141 and -1 for G142, T from `from` to `to`, N from p's A B C. */
int comp5_offset_point(const double from[6], const double to[6], int side, double radius_mm,
                       const double p[6], double out[6]);

#endif
