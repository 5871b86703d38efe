/* comp5.h: five-axis tool radius compensation, G141 (right) and G142 (left), as in the paper. */
#ifndef HEXCNC_COMP5_H
#define HEXCNC_COMP5_H

#include "interp/canon.h"

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
 */

enum comp5_status {
    COMP5_OK = 0,
    COMP5_ERR_SINGLE_BLOCK,   /* a run with fewer than two distinct points */
    COMP5_ERR_ZERO_LENGTH,    /* a compensated block that does not move X Y Z */
    COMP5_ERR_ALONG_AXIS,     /* motion parallel to the tool axis: T x N = 0 */
    COMP5_ERR_MIXED_SIDES,    /* G141 and G142 in one run */
    COMP5_ERR_RADIUS,         /* radius missing, zero or negative */
    COMP5_ERR_GOUGE,          /* an inside corner the tool cannot reach without gouging */
    COMP5_ERR_SINK,           /* the canon sink refused a command */
    COMP5_STATUS_COUNT
};
const char *comp5_strerror(int status);

/* One compensated block, as the interpreter resolved it. */
struct comp5_block {
    int side;                 /* 141 (right) or 142 (left) */
    double point[6];          /* programmed contour point and orientation, machine frame */
    double radius_mm;         /* effective tool radius (W, or tool table diameter/2 + wear) */
    double feed_mm_min;       /* feed in force */
    int line;                 /* source line, for the emitted moves and for errors */
    const char *file;
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
};

void comp5_init(struct comp5 *c);
/* Adds a compensated block; start is the tool pose before it (used when it opens a run).
 * May emit canon commands. On error returns a status and sets c->err_line. */
int comp5_block(struct comp5 *c, const struct comp5_block *b, const double start[6],
                canon_sink_fn sink, void *ctx);
/* Ends the current run (no-op when none is open), emitting the buffered moves. */
int comp5_flush(struct comp5 *c, canon_sink_fn sink, void *ctx);
/* Where the tool is after the emitted moves (valid after comp5_flush or while active). */
const double *comp5_tool_pos(const struct comp5 *c);

/* The table normal N = R [0 0 1] for orientation A, B, C in degrees (paper's step 2). */
void comp5_normal(double a_deg, double b_deg, double c_deg, double n[3]);
/* The compensated point of one segment (paper's steps 1..4): p + s W unit(T x N), with
 * s = +1 for G141 and -1 for G142, T from `from` to `to`. */
int comp5_offset_point(const double from[6], const double to[6], int side, double radius_mm,
                       const double p[6], double out[6]);

#endif
