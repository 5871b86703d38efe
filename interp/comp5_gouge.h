/* comp5_gouge.h: does a G141/G142 tool path cut into its own programmed contour? */
#ifndef HEXCNC_COMP5_GOUGE_H
#define HEXCNC_COMP5_GOUGE_H

#include <stddef.h>

/*
 * The whole compensated run is kept (its programmed contour points and the moves the
 * compensation emitted) and checked when the run ends: for every tool position along the
 * compensated path, the distance from the tool axis line to every programmed contour segment
 * of the run, measured in the plane normal to the tool axis, must be at least W minus the
 * tolerance. Non-adjacent segments count (a slot or pocket narrower than the tool, the
 * closing segment of a closed contour). Memory: the current run only (two growing arrays,
 * reused by the next run, freed by comp5_free()).
 *
 * The positioning move into the run is checked the same way when it is level (it starts at
 * the cutting depth along the tool axis, within the tolerance): it must come from the
 * compensation side without crossing the contour. A positioning move that changes depth is
 * a descent from off the workpiece; the interpreter does not know the stock, so only its end
 * (the compensated start, which the first cut checks as well) is checked.
 */

#define COMP5_GOUGE_REL 1e-6 /* tolerance, relative to W: tol = 1e-6 * max(W, 1 mm) mm */

/* One programmed contour point of the run. */
struct comp5_gpt {
    double p[6];          /* machine frame, mm and deg */
    double prog_off[3];   /* machine = prog * unit_mm + prog_off (mm): to name points */
    double unit_mm;       /* mm per program length unit (1 or 25.4) */
    double radius_mm;     /* the block's tool radius W */
    int line;             /* the block's source line */
};

/* One emitted tool move (tool tip positions, machine frame). */
struct kins_tool_frame;

struct comp5_gmove {
    int arc;              /* 0: straight from p0 to p1; 1: arc about center, see canon.h */
    int positioning;      /* the move into the run */
    double p0[6], p1[6];  /* start and end poses */
    double center[3];     /* arc only */
    double normal[3];     /* arc only: unit, counter-clockwise turn (rotation +1) */
    double radius_mm;     /* W of the block the move belongs to */
    int line;             /* that block's line */
    const struct kins_tool_frame *tf; /* how N follows A B C (comp5_axis) */
};

/* What the check found: the deepest cut of the first move (in path order) that gouges. */
struct comp5_gouge_hit {
    double depth_mm;      /* W - distance (> tolerance) */
    double dist_mm;       /* distance from the tool axis to the contour there */
    double radius_mm;     /* the tool's radius */
    int move_line;        /* line of the gouging move */
    int positioning;      /* the gouging move is the positioning move, before its end */
    int tilt;             /* the move cuts into its own segment while A B C change along it */
    int seg_line0;        /* the contour segment cut into: from this line ... */
    int seg_line1;        /* ... to this one */
    double point_prog[3]; /* the contour point cut into, program coordinates */
    double tool_prog[3];  /* the tool tip then, program coordinates */
};

/* The record of the current run. */
struct comp5_gouge {
    struct comp5_gpt *pts;
    size_t npts, cap_pts;
    struct comp5_gmove *moves;
    size_t nmoves, cap_moves;
};

/* Empties the record (keeps the memory for the next run). */
void comp5_gouge_clear(struct comp5_gouge *g);
void comp5_gouge_free(struct comp5_gouge *g);
/* Appends a contour point / a move; -1 when memory runs out. */
int comp5_gouge_add_point(struct comp5_gouge *g, const struct comp5_gpt *pt);
int comp5_gouge_add_move(struct comp5_gouge *g, const struct comp5_gmove *m);
/* Checks the run: 0 clean, 1 a gouge (described in *hit), -1 out of memory. */
int comp5_gouge_check(const struct comp5_gouge *g, struct comp5_gouge_hit *hit);

#endif
