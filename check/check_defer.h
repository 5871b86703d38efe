/* check_defer.h: the servo-rate pass's costly measures, computed by whichever thread has time
 * and applied in order by the pass (check_defer.c). Inside check/ only. */
#ifndef HEXCNC_CHECK_DEFER_H
#define HEXCNC_CHECK_DEFER_H

#include <stdalign.h>
#include <stdatomic.h>
#include <stddef.h>

#include "check/check_priv.h"

#define CHECK_DEFER_SLOTS 8192       /* measures in flight (7 MB): several times what the
                                      * pass takes while the planner plans a window (about
                                      * 10 ms, 40 s of machine time, 3000 measures on dense
                                      * code) */

#define CHECK_NEAR_STEP_MM 1e-6     /* a deviation's forward kinematics: a first Newton step
                                     * within this ends the solve (error about 1e-13 mm, the
                                     * rounding of the coordinates) */
#define CHECK_DEFER_RUN 32           /* slots the pass claims at once when it computes them
                                      * itself (one locked instruction, a full fence on x86,
                                      * for all of them) */

enum check_defer_kind {
    CHECK_DEFER_DEVIATION,           /* forward kinematics at mid-chord: computed */
    CHECK_DEFER_CONDITION,           /* the condition number at a pose: computed, or the
                                      * matrix it is of (has_m), which the pass bounds */
    CHECK_DEFER_FLUSH,               /* a straight move's end: its tip warning (value2: the
                                      * largest tip deviation the pass measured in the move) */
    CHECK_DEFER_MOVE,                /* a straight move's start: its line and file; with ok
                                      * set, also the end of the move before (as FLUSH) */
};
enum check_defer_state { CHECK_DEFER_WAITING, CHECK_DEFER_DONE };
/* How a deviation measures the tip of the interpolated legs. */
enum check_defer_tip { CHECK_TIP_NONE, CHECK_TIP_LINE /* against the segment t0 t1 */,
                       CHECK_TIP_AXIS /* against the line through t0 t1 (a synchronised
                                       * move's tool runs on past its ends along it) */,
                       CHECK_TIP_CHORD /* against the chord between the set points' tips */ };

/* One measure: what the pass took (written before commit, read-only after) and the result
 * (written by the thread that computes it, before `state` becomes DONE). */
struct check_defer_slot {
    alignas(64) _Atomic int state;   /* enum check_defer_state (each slot on cache lines
                                      * of its own: the helper writes one while the pass
                                      * fills the next) */
    enum check_defer_kind kind;
    int line;                        /* the period's program line and file, machine time */
    const char *file;
    long period;                     /* the period's index in the pass */
    double time_s, dist_mm;
    double pose[KINS_POSE_DIM];      /* this period's commanded pose */
    double p0[KINS_POSE_DIM];        /* deviation: the last period's, and both set points */
    double L0[KINS_MAX_JOINTS], L1[KINS_MAX_JOINTS];
    enum check_defer_tip tip_mode;
    double tool_len_mm;              /* the tool of the period, for the tip */
    double t0[3], t1[3];             /* CHECK_TIP_LINE and _AXIS: the move's tip line */
    int ok;                          /* result: the solve succeeded (MOVE: see above) */
    double value;                    /* deviation (mm), condition number; MOVE: how far the
                                      * planner may round the move, mm */
    double value2;                   /* deviation: the orientation's, deg; FLUSH, MOVE: the
                                      * tip's largest deviation in the move before, mm */
    double tip;                      /* deviation: the tip's, mm (tip_mode != NONE) */
    int has_m;                       /* condition: m holds the kinematics' condition matrix
                                      * (kins_condition_matrix), value nothing */
    double m[KINS_MAX_JOINTS * KINS_POSE_DIM];
};

struct check_defer {
    struct kins *kins;               /* what the measures are computed with (read-only) */
    struct kins_tool_frame tf;
    int have_tf, cold_forward;
    /* Each on a cache line of its own: a line both threads write goes back and forth
     * between the cores at every write, and the pass commits a slot every few periods. */
    alignas(64) _Atomic size_t head; /* slots committed (the pass writes) */
    alignas(64) _Atomic size_t claim;/* slots taken for computing (both, compare-and-swap) */
    alignas(64) size_t head_local;   /* the pass's own: committed, applied */
    size_t apply;
    struct check_defer_slot slot[CHECK_DEFER_SLOTS];
};

/* A ring for measures with kinematics k and tool tf (NULL: none); NULL when out of memory. */
struct check_defer *check_defer_new(struct kins *k, const struct kins_tool_frame *tf,
                                    int cold_forward);
void check_defer_free(struct check_defer *d);
/* The helper's side: computes the oldest measure nobody has taken; 1 if there was one. */
int check_defer_work(struct check_defer *d);
/* The pass's side. The next slot to fill, of this kind, or NULL when the ring is full (apply
 * first); then check_defer_commit publishes it. */
struct check_defer_slot *check_defer_push(struct check_defer *d, enum check_defer_kind kind);
void check_defer_commit(struct check_defer *d);
/* The oldest slot not yet applied (what the pass wrote in it; its result may not be there
 * yet), or NULL when every slot is applied. */
const struct check_defer_slot *check_defer_oldest(const struct check_defer *d);
/* The oldest slot not yet applied, once its result is there (wait: computing it, or waiting
 * for the helper that is); NULL when none is ready without waiting, or none is left. */
struct check_defer_slot *check_defer_next(struct check_defer *d, int wait);

#endif
