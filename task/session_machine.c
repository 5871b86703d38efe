/* session_machine.c: the session's machine commands: e-stop, power, mode, homing, jogs,
 * overrides, the tool table and the operator's tool change. */
#include "task/session_priv.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/errbuf.h"
#include "interp/interp.h"
#include "motion/motion_hal.h"

/* Waits until the e-stop chain is open and motion has stopped: the answer to an e-stop or
 * a switch-off goes out once the machine is off, never before. */
static void wait_off(struct session *s)
{
    for (int i = 0; i < SESSION_POWER_PERIODS; i++) {
        enum motion_state st = session_mstate(s);
        bool moving = st == MOTION_RUNNING || st == MOTION_PAUSING || st == MOTION_STOPPING ||
                      st == MOTION_MANUAL;
        if (!*s->r->emc_enable_in && !moving)
            return;
        session_wait_periods(s, 1);
    }
}

int session_estop(struct session *s, bool active, char *err, size_t len)
{
    if (active) {
        *s->r->user_enable_out = false;
        wait_off(s);
        session_run_cut(s, "e-stop");
        if (s->state != SESS_ESTOP)
            session_message(s, "warning", "task", "e-stop: the machine stopped at once");
        s->state = SESS_ESTOP;
        return 0;
    }
    if (s->state == SESS_ESTOP)
        s->state = SESS_OFF;
    return 0;
}

int session_power(struct session *s, bool on, char *err, size_t len)
{
    if (!on) {
        *s->r->user_enable_out = false;
        wait_off(s);
        session_run_cut(s, "the machine was switched off");
        if (s->state == SESS_ON)
            s->state = SESS_OFF;
        return 0;
    }
    if (s->state == SESS_ESTOP)
        return errbuf_set(err, len, RPC_STATE, "machine on refused: the machine is in e-stop "
                    "(machine.estop {active: false} first)");
    if (s->state == SESS_ON)
        return 0;
    *s->r->user_enable_out = true;
    *s->r->user_request_enable = true;
    /* a drive that faulted clears its fault on the reset edge before the chain closes:
     * CiA 402 drives take tens of periods for it */
    for (int i = 0; i < SESSION_ENABLE_PERIODS && !*s->r->emc_enable_in; i++)
        session_wait_periods(s, 1);
    if (!*s->r->emc_enable_in) {
        *s->r->user_enable_out = false;
        return errbuf_set(err, len, RPC_FAILED, "machine on failed: the e-stop chain did not close "
                    "(task.emc-enable-in stayed false; check the e-stop wiring in the HAL "
                    "files)");
    }
    /* the drives may need longer than the e-stop chain to be ready (CiA 402 drives switch
     * on through their state machine): motion.enable says when they are */
    for (int i = 0; i < SESSION_ENABLE_PERIODS && !motion_hal_enabled(s->hal); i++)
        session_wait_periods(s, 1);
    if (!motion_hal_enabled(s->hal)) {
        *s->r->user_enable_out = false;
        return errbuf_set(err, len, RPC_FAILED, "machine on failed: motion.enable stayed false "
                    "for %d servo periods after the e-stop chain closed (the drives did not "
                    "report ready; see the messages)", SESSION_ENABLE_PERIODS);
    }
    session_wait_periods(s, 2);  /* motion has seen enable: the command is the legs' */
    s->state = SESS_ON;
    session_message(s, "info", "task", "machine on");
    return 0;
}

int session_set_mode(struct session *s, enum session_mode mode, char *err, size_t len)
{
    if (mode == s->mode)
        return 0;
    if (s->running || !session_at_rest(s))
        return errbuf_set(err, len, RPC_STATE, "mode change refused: the machine is %s",
                    s->running ? "running a program" : "moving");
    s->mode = mode;
    return 0;
}

int session_home(struct session *s, int joint, char *err, size_t len)
{
    int rc;
    if ((rc = session_need_on(s, "homing", err, len)) || (rc = session_need_idle(s, "homing", err, len)))
        return rc;
    s->mode = SESS_MANUAL;
    struct motion_hal_cmd c = { .kind = MOTION_CMD_HOME, .axis = joint };
    return session_push(s, &c, err, len);
}

int session_unhome(struct session *s, int joint, char *err, size_t len)
{
    int rc;
    if ((rc = session_need_idle(s, "unhoming", err, len)))
        return rc;
    struct motion_hal_cmd c = { .kind = MOTION_CMD_UNHOME, .axis = joint };
    if (s->state != SESS_ON) {  /* the queue only runs while on: the legs are at rest */
        motion_unhome(s->m, joint);
        return 0;
    }
    return session_push(s, &c, err, len);
}

int session_jog(struct session *s, int frame, int axis, double vel, double dist, char *err,
                size_t len)
{
    int rc;
    if ((rc = session_need_on(s, "jog", err, len)))
        return rc;
    if (s->running)
        return errbuf_set(err, len, RPC_STATE, "jog refused: %s is running",
                    s->run_is_mdi ? "an MDI line" : "a program");
    if (motion_homing(s->m))
        return errbuf_set(err, len, RPC_STATE, "jog refused: the machine is homing");
    if (frame != MOTION_JOG_JOINT && !motion_all_homed(s->m))
        return errbuf_set(err, len, RPC_STATE, "%s jog refused: the machine is not homed (home it, "
                    "or jog a leg: frame joint)", frame == MOTION_JOG_TOOL ? "tool" : "world");
    s->mode = SESS_MANUAL;
    struct motion_hal_cmd c = { .kind = MOTION_CMD_JOG, .frame = frame, .axis = axis,
                                .vel = vel, .dist = dist };
    return session_push(s, &c, err, len);
}

/* Changes one tool's entry and saves the table (atomically, common/atomicfile); the MDI
 * interpreter sees it at once, programs when they are next read. Refused while a program
 * runs: its G10 L1 lines save the same file. */
int session_tooltable_set(struct session *s, const struct session_tool_edit *e, char *err,
                          size_t len)
{
    int rc;
    if ((rc = session_need_idle(s, "tooltable.set", err, len)))
        return rc;
    if (!s->mdi_tt.path[0])
        return errbuf_set(err, len, RPC_STATE, "tooltable.set: this machine has no tool table file "
                    "([EMCIO] TOOL_TABLE)");
    struct tooltable *tt = malloc(sizeof *tt);
    if (!tt)
        return errbuf_set(err, len, RPC_FAILED, "out of memory");
    *tt = s->mdi_tt;
    struct tool_entry ent, *old = tooltable_find(tt, e->tool);
    if (old) {
        ent = *old;
    } else {
        memset(&ent, 0, sizeof ent);
        ent.tool = e->tool;
        ent.pocket = e->tool;
    }
    if (e->pocket >= 0)
        ent.pocket = e->pocket;
    if (e->has_length) {
        ent.z_offset_mm = e->length;
        ent.present |= TOOLTABLE_F_Z;
    }
    if (e->has_diameter)
        ent.diameter_mm = e->diameter;
    if (e->comment)
        snprintf(ent.comment, sizeof ent.comment, "%s", e->comment);
    char msg[600];
    if (e->has_wear)
        ent.wear_mm = e->wear;
    int st = tooltable_set(tt, &ent);
    if (st == TOOLTABLE_OK)
        st = tooltable_save(tt, tt->path, msg, sizeof msg);
    else
        snprintf(msg, sizeof msg, "tool %d: %s", e->tool, tooltable_strerror(st));
    if (st == TOOLTABLE_OK)
        s->mdi_tt = *tt;  /* the interpreter holds a pointer to mdi_tt: same place */
    free(tt);
    if (st != TOOLTABLE_OK)
        return errbuf_set(err, len, RPC_FAILED, "tooltable.set: %s", msg);
    session_message(s, "info", "task", "tool %d changed in %s", e->tool, s->mdi_tt.path);
    return 0;
}

/* The operator has put the tool M6 asked for in the spindle. */
int session_tool_changed(struct session *s, char *err, size_t len)
{
    if (!motion_hal_manual_toolchange_waiting(s->hal))
        return errbuf_set(err, len, RPC_STATE, "tool.changed: no manual tool change is waiting");
    struct motion_hal_cmd c = { .kind = MOTION_CMD_TOOL_CHANGED };
    return session_push(s, &c, err, len);
}

int session_jog_stop(struct session *s, char *err, size_t len)
{
    struct motion_hal_cmd c = { .kind = MOTION_CMD_JOG_STOP };
    if (s->state != SESS_ON)
        return 0;
    return session_push(s, &c, err, len);
}

int session_overrides(struct session *s, const double *feed, const double *rapid,
                      const double *spindle, char *err, size_t len)
{
    if ((feed && !(*feed >= 0 && *feed <= 2)) || (rapid && !(*rapid >= 0 && *rapid <= 1)) ||
        (spindle && !(*spindle >= 0 && *spindle <= 2)))
        return errbuf_set(err, len, RPC_PARAMS, "override out of range: feed 0..2, rapid 0..1, "
                    "spindle 0..2");
    if (feed) {
        s->feed_ovr = *feed;
        if (s->feed_ovr_pin)
            *s->feed_ovr_pin = *feed;
    }
    if (rapid) {
        s->rapid_ovr = *rapid;
        struct motion_hal_cmd c = { .kind = MOTION_CMD_RAPID, .vel = *rapid };
        if (s->state == SESS_ON) {
            int rc = session_push(s, &c, err, len);
            if (rc)
                return rc;
        } else {
            motion_set_rapid_override(s->m, *rapid);
        }
    }
    if (spindle) {
        s->spindle_ovr = *spindle;
        if (s->spindle_ovr_pin)
            *s->spindle_ovr_pin = *spindle;
        if (s->state == SESS_ON)
            session_wait_periods(s, 1);  /* in effect when the answer goes out */
    }
    return 0;
}
