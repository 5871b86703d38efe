/* motion_hal.h: what the runner calls on the `motion` HAL component (loadrt motion). */
#ifndef HEXCNC_MOTION_HAL_H
#define HEXCNC_MOTION_HAL_H

#include <stddef.h>

#include "hal/hal.h"
#include "interp/canon.h"
#include "motion/motion.h"

/* The motion instance of the `motion` component (the HAL object "motion"), or NULL when
 * `loadrt motion` has not run. */
struct motion *motion_hal_get(const struct hal *h);

/* Plans prog on the component's motion instance (motion_load: every move checked through
 * the kinematics first). It starts at the next motion.update that sees motion.enable true.
 * MOTION_ERR_* with a message naming file and line in err on failure. */
int motion_hal_load(struct hal *h, const struct canon_prog *prog, char *err, size_t errlen);

/* A program that streams (motion.h's motion_stream_*): a planner for the component's
 * machine, attached to its motion instance at rest after the start-pose check of
 * motion_hal_load; it starts as motion_hal_load's programs do. totals: the checked
 * program's time and length (for progress). The caller feeds it from its own thread. */
int motion_hal_stream_begin(struct hal *h, const double start[KINS_POSE_DIM],
                            const struct motion_plan_info *totals,
                            const volatile sig_atomic_t *cancel, struct motion_stream **out,
                            char *err, size_t errlen);
/* Detaches the motion instance from the stream (at rest or not: it is unloaded) and frees
 * the stream. The producer must have stopped. */
void motion_hal_stream_end(struct hal *h, struct motion_stream *s);

/* Whether motion_hal_load marks the program to start (default true); false: only
 * motion_hal_start does (a check must never start anything). */
int motion_hal_set_autostart(struct hal *h, bool on);

/* Asks the component to start the program loaded into its motion instance (by
 * motion_hal_load or motion_load): it starts at the next motion.update that sees
 * motion.enable true. MOTION_ERR_STATE when no program is loaded or motion is not idle. */
int motion_hal_start(struct hal *h);

/* Asks the component to abort (controlled stop along the path, then idle) at its next
 * motion.update. Safe from another thread than the servo thread. */
int motion_hal_abort(struct hal *h);

/* Whether a start, an abort or a manual command is queued and not yet taken by the servo
 * thread (the task waits for it before answering, so that what it reports has happened). */
bool motion_hal_pending(const struct hal *h);

/* Whether motion.enable was true in the last servo period (the drives may move). */
bool motion_hal_enabled(const struct hal *h);

/* Manual tool changes (the session): with iocontrol.0.tool-changed unconnected, programs
 * planned from now on stop at M6 until motion_hal_command(MOTION_CMD_TOOL_CHANGED). Whether
 * such a change waits for the operator now. */
int motion_hal_set_manual_toolchange(struct hal *h, bool on);
bool motion_hal_manual_toolchange_waiting(const struct hal *h);

/* The component's output of its last motion.update (pose, legs, state, line, progress);
 * before the first one, the pose it holds. MOTION_ERR_STATE without `loadrt motion`. */
int motion_hal_out(const struct hal *h, struct motion_out *out);

/* The commanded pose now (mm, deg): where a program handed over next starts from. */
int motion_hal_pose(const struct hal *h, double pose[KINS_POSE_DIM]);

/* Manual-motion commands the task queues for the servo thread (applied at the next
 * motion.update while the machine is on; dropped when it is off). */
enum motion_hal_cmd_kind { MOTION_CMD_JOG, MOTION_CMD_JOG_STOP, MOTION_CMD_MOVE_TO,
                           MOTION_CMD_HOME, MOTION_CMD_UNHOME, MOTION_CMD_PAUSE,
                           MOTION_CMD_RESUME, MOTION_CMD_STEP, MOTION_CMD_RAPID,
                           MOTION_CMD_TOOL_CHANGED /* the operator confirms a tool change */ };
struct motion_hal_cmd {
    enum motion_hal_cmd_kind kind;
    enum motion_jog_frame frame;
    int axis;                     /* jog axis; home/unhome: joint, -1 all */
    double vel;                   /* jog: signed speed; move_to: share of the limits */
    double dist;                  /* jog: distance, 0 continuous */
    double pose[KINS_POSE_DIM];   /* move_to */
};
/* MOTION_ERR_STATE when the queue is full or no motion is loaded. */
int motion_hal_command(struct hal *h, const struct motion_hal_cmd *cmd);
/* Runs fn on the motion core with the servo update kept out meanwhile (it holds still). */
int motion_hal_with(struct hal *h, void (*fn)(struct motion *m, void *ctx), void *ctx);

/* The fault or last error text ("" when none): what the runner shows the machinist. */
const char *motion_hal_fault(const struct hal *h);

#endif
