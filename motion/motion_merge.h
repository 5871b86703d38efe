/* motion_merge.h: G64 Q, LinuxCNC's naive CAM detector: runs of straight feeds that stay
 * within Q of one line become that line, before the planner sees them (inside motion/ only). */
#ifndef HEXCNC_MOTION_MERGE_H
#define HEXCNC_MOTION_MERGE_H

#include <stddef.h>

#include "interp/canon.h"
#include "kins/kins.h"

#define MOTION_MERGE_MAX 101   /* feeds in one run at most (LinuxCNC's bound) */

/* What the filter passes on: 0 to go on, else a status that stops it. */
typedef int (*motion_merge_emit_fn)(void *ctx, const struct canon_cmd *c);

/*
 * A run starts at the path's present point and holds feeds while each new end keeps every
 * end before it within Q of the line from the start to the new end, and the run neither
 * turns A B C nor changes feed, feed mode, tool centre point state or file. The run goes out
 * as its last feed (its line, feed and end): one straight move. Any other command ends the
 * run first, so that commands stay in program order. Q comes with each PATH_MODE (G64 P Q;
 * G64 P alone: Q = P; G61 and G64 without P or Q: none).
 */
struct motion_merge {
    int continuous;                  /* G64 in force */
    double tol_mm;                   /* its Q */
    double at[KINS_POSE_DIM];        /* where the path is before the run */
    int at_tcp;                      /* ... under G43.4 with this tool length */
    double at_len_mm;
    double pts[MOTION_MERGE_MAX][3]; /* the run's ends, in order */
    int n;
    struct canon_cmd last;           /* the run's last feed */
    size_t merged;                   /* feeds that went out inside a longer move */
};

/* A filter that starts at pose start (tcp, len: G43.4's state there) in the given path mode
 * (610, 611, 640; 0 for LinuxCNC's default, G64) with no Q. */
void motion_merge_init(struct motion_merge *g, const double start[KINS_POSE_DIM], int tcp,
                       double len_mm, int path_mode);
/* Takes one command; passes on what is decided (none, one or two commands). */
int motion_merge_add(struct motion_merge *g, const struct canon_cmd *c,
                     motion_merge_emit_fn emit, void *ctx);
/* Passes on the run held, if any (at the program's end, a sync). */
int motion_merge_flush(struct motion_merge *g, motion_merge_emit_fn emit, void *ctx);

/* The whole program through the filter into out (a new program: free it with
 * canon_prog_free); *merged: feeds that went out inside a longer move. Returns 0, or -1 when
 * memory ran out. */
int motion_merge_program(const struct canon_prog *in, struct canon_prog *out, size_t *merged);
/* Whether a program sets a Q anywhere (else the filter would change nothing). */
int motion_merge_wanted(const struct canon_prog *p);

#endif
