/* ccomp.h: two-dimensional cutter radius compensation G41/G42 (LinuxCNC's), with its one-move queue. */
#ifndef HEXCNC_CCOMP_H
#define HEXCNC_CCOMP_H

#include "interp/canon.h"

struct interp;

enum ccomp_side { CCOMP_OFF = 0, CCOMP_LEFT = 1, CCOMP_RIGHT = 2 };

/*
 * Geometry is worked in the plane of compensation as LinuxCNC works it: program units, work
 * offsets removed, coordinates ordered (first, second, normal) = (X, Y, Z) under G17 and
 * (Z, X, Y) under G18. A corner can only be placed once the next move is known, so the last
 * compensated move waits in a queue (with the feed, spindle, coolant, dwell and comment
 * commands issued after it) until the next move moves its end point and sends it on.
 */
struct ccomp_item {
    struct canon_cmd cmd;       /* what goes to the sink (machine frame) */
    char text[256];             /* a COMMENT's text (the block's buffer does not outlive it) */
    int move;                   /* 0: not a move; 1 straight; 2 arc */
    double dir[2];              /* straight: its programmed direction in the plane */
    double end[2];              /* end point in the plane, program units */
    double center[2];           /* arc: centre in the plane, program units */
    int turn;                   /* arc: +n counter-clockwise, -n clockwise */
    double sweep_rad;           /* arc: programmed sweep, 0 when its end may not be checked */
};

struct ccomp {
    enum ccomp_side side;       /* G41 left, G42 right (after a negative radius swapped it) */
    char name[8];               /* "G41", "G42.1", ... as programmed, for messages */
    double radius;              /* tool radius, program units (0: moves are not offset) */
    int first;                  /* no compensated move yet: the next one is the entry move */
    int arc_not_allowed;        /* G40 just ended a path: the next move must be straight */
    double cur[3];              /* where the tool centre is (plane order, program units) */
    double prog[3];             /* the programmed point it is offset from */
    double endpoint[2];         /* start of the queued move, for the gouge checks ... */
    int endpoint_valid;         /* ... when known */
    struct ccomp_item *q;       /* the queue, oldest first */
    int n, cap;
    double sent_end[6];         /* the end of the last compensated move sent on (in->pos's */
    int sent_valid;             /* frame): where the tool is when G40 comes */
    int resync;                 /* G40 left the tool there and no move has come since */
};

/* "G41", "G42.1", ... for the code g (x10: 410, 421, ...). */
void ccomp_name(char name[8], int g);
void ccomp_free(struct ccomp *cc);
/* Forgets the queue and turns compensation off (a new run). */
void ccomp_reset(struct ccomp *cc);
/* Whether compensated moves are being made (on, with a radius over 0). */
int ccomp_active(const struct interp *in);
/* Whether a command of this type must wait behind a queued move (interp_emit asks). */
int ccomp_holds(const struct interp *in, enum canon_type t);
/* Appends a command behind the queued move. */
int ccomp_hold(struct interp *in, const struct canon_cmd *c);

/* M6: the present point becomes where the tool is, if G40 left it beside the programmed
 * point and nothing has moved since (rs274 reads the machine's position back at a tool
 * change). */
void ccomp_tool_change(struct interp *in);
/* G40 (g = 400), G41/G42 (410/420), G41.1/G42.1 (411/421) of the current block. */
int ccomp_mode(struct interp *in, int g);
/* The checks LinuxCNC makes on a block while compensation is on (before it runs). */
int ccomp_check_block(struct interp *in);
/* The programmed point a compensated arc starts from (plane order, program units), when
 * compensation is past its entry move: 1, else 0 (s untouched). */
int ccomp_start(const struct interp *in, double s[2]);
/* G0 (move 0) or G1 (10) to the block's target `end` (machine frame) with compensation on. */
int ccomp_straight(struct interp *in, int move, const double end[6]);
/* G2 (20) / G3 (30): s and e the programmed start and end, c the centre (plane order,
 * program units), turns the signed turn count, end the block's machine target. */
int ccomp_arc(struct interp *in, int move, const double s[2], const double e[2],
              const double c[2], int turns, const double end[6]);
/* Sends the queued moves with the last one ending where the tool is (M0, M1, M2, end). */
int ccomp_flush(struct interp *in);
/* G20/G21 while compensation is on: state and queue to the new program units (k per old). */
void ccomp_scale(struct interp *in, double k);

#endif
