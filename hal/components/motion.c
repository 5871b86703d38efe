/* motion.c: the `motion` HAL component: planner and interpolator of motion/ on the servo thread. */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hal/hal.h"
#include "hal/ring.h"
#include "kins/kins.h"
#include "motion/motion.h"
#include "motion/motion_hal.h"

static const char motion_axis_names[KINS_POSE_DIM] = { 'x', 'y', 'z', 'a', 'b', 'c' };

/* The instance: the motion core and its pins. */
struct motion_comp {
    struct motion *m;                        /* the planner/interpolator (object "motion") */
    struct hal *h;                           /* for messages */
    int nj;                                  /* joints */
    atomic_int start_pending;                /* a program waits to start (motion_hal_start) */
    atomic_int abort_pending;                /* motion_hal_abort was called */
    struct motion_out last;                  /* output of the last update (motion_hal_out) */
    struct ring_spsc cmds;                   /* manual-motion commands from the task */
    pthread_mutex_t plan_lock;               /* held by the task while it replaces the plan
                                              * (at rest); the update skips a period then */
    bool *home_sw[KINS_MAX_JOINTS];          /* in: home switch of each leg */
    double *joint_fb_out[KINS_MAX_JOINTS];   /* out: leg length feedback (motor - offset) */
    bool *homed_pin[KINS_MAX_JOINTS];        /* out: leg homed */
    bool was_enabled;                        /* enable in the last update */
    long updates;                            /* updates run so far */
    bool autostart;                          /* motion_hal_load marks the program to start
                                              * (tests and `hexcnc run`); the session starts
                                              * it itself (motion_hal_set_autostart) */
    double *joint_pos_cmd[KINS_MAX_JOINTS];  /* out: leg length commands, mm */
    double *joint_vel_cmd[KINS_MAX_JOINTS];  /* out: leg rate commands, mm/s */
    double *joint_pos_fb[KINS_MAX_JOINTS];   /* in: leg length feedback, mm */
    double *ferror[KINS_MAX_JOINTS];         /* out: following error (command - feedback), mm */
    double *pose_cmd[KINS_POSE_DIM];         /* out: commanded pose, mm and deg */
    double *path_vel;                        /* out: path speed, mm/s */
    double *feed_override;                   /* in: feed override 0..2 (default 1) */
    double *time_elapsed;                    /* out: s since the program started */
    double *time_remaining;                  /* out: planned s left (at override 1) */
    int32_t *program_line;                   /* out: line being executed */
    int32_t *state;                          /* out: enum motion_state */
    bool *done;                              /* out: the program has ended */
    bool *fault;                             /* out: e-stop, following error or kinematics fault */
    bool *enable;                            /* in: machine on; dropping it while moving faults */
    bool *amp_enable;                        /* out: drives may move (enabled, no fault) */
    bool *estop;                             /* in: true = stop now */
    bool *pause, *resume, *abort;            /* in: edge triggered */
    /* spindle and coolant, LinuxCNC's names (docs/machine.md) */
    bool *sp_on, *sp_fwd, *sp_rev;           /* out: spindle.0.on, .forward, .reverse */
    double *sp_speed, *sp_rps;               /* out: .speed-out (rpm, signed, with the
                                              * override), .speed-out-rps */
    double *sp_override;                     /* in: spindle.0.override 0..2 (default 1) */
    bool *sp_at_speed;                       /* in: spindle.0.at-speed (default TRUE) */
    bool *sp_at_speed_own;                   /* the pin's own storage: another address
                                              * means `net` linked it (then programs wait) */
    bool *mist, *flood;                      /* out: iocontrol.0.coolant-mist, -flood */
    int ndio, naio;                          /* [EMCMOT] NUM_DIO, NUM_AIO */
    bool *dout[MOTION_MAX_DIO];              /* out: motion.digital-out-NN (M62..M65) */
    double *aout[MOTION_MAX_AIO];            /* out: motion.analog-out-NN (M67, M68) */
    bool *din[MOTION_MAX_DIO];               /* in: motion.digital-in-NN (M66 P) */
    double *ain[MOTION_MAX_AIO];             /* in: motion.analog-in-NN (M66 E) */
    bool *probe_in;                          /* in: motion.probe-input (G38.2..G38.5) */
    double *sp_revs;                         /* in: spindle.0.revs, the spindle's position,
                                              * revolutions (G33, G33.1) */
    double *sp_revs_own;                     /* its own storage (see sp_at_speed_own) */
    bool *sp_index;                          /* io: spindle.0.index-enable, the encoder's
                                              * index handshake (G33, G33.1) */
    bool *sp_index_own;                      /* its own storage (see sp_at_speed_own) */
    /* the tool changer's handshake, LinuxCNC's iocontrol pins */
    int32_t *tc_prep_number, *tc_number;     /* out: tool-prep-number, tool-number */
    bool *tc_prepare, *tc_change;            /* out: tool-prepare, tool-change */
    bool *tc_prepared, *tc_changed;          /* in: tool-prepared, tool-changed */
    bool *tc_prepared_own, *tc_changed_own;  /* their own storage (see sp_at_speed_own) */
    int tc_phase;                            /* 0 idle, 1 preparing, 2 changing */
    unsigned tc_done_seq;                    /* the last M6 request handled */
    bool manual_tc;                          /* no changer wired: the operator confirms */
    atomic_int manual_ack;                   /* the operator confirmed (MOTION_CMD_TOOL_CHANGED) */
    bool last_pause, last_resume, last_abort;/* previous values, for the edges */
};

/* Updates before the feedback is believed (see motion_comp_commands). */
#define MOTION_FEEDBACK_SETTLE 2

/* How far the legs at a program's start may be from the command when it is loaded, mm. */
#define MOTION_START_TOL_MM 0.01

/* Applies the manual-motion commands the task queued (motion_hal_command). */
static void motion_comp_manual(struct motion_comp *c)
{
    struct motion_hal_cmd cmd;
    while (ring_spsc_pop(&c->cmds, &cmd)) {
        if (!*c->enable)
            continue;  /* the machine went off meanwhile */
        switch (cmd.kind) {
        case MOTION_CMD_JOG: motion_jog(c->m, cmd.frame, cmd.axis, cmd.vel, cmd.dist); break;
        case MOTION_CMD_JOG_STOP: motion_jog_stop(c->m); break;
        case MOTION_CMD_MOVE_TO: motion_move_to(c->m, cmd.pose, cmd.vel); break;
        case MOTION_CMD_HOME: motion_home(c->m, cmd.axis); break;
        case MOTION_CMD_UNHOME: motion_unhome(c->m, cmd.axis); break;
        case MOTION_CMD_PAUSE: motion_pause(c->m); break;
        case MOTION_CMD_RESUME: motion_resume(c->m); break;
        case MOTION_CMD_STEP: motion_step_block(c->m); break;
        case MOTION_CMD_RAPID: motion_set_rapid_override(c->m, cmd.vel); break;
        case MOTION_CMD_TOOL_CHANGED: atomic_store(&c->manual_ack, 1); break;
        }
    }
}

/* The command inputs: e-stop, enable, edges of pause/resume/abort, override. */
static void motion_comp_commands(struct motion_comp *c)
{
    enum motion_state st = motion_get_state(c->m);
    int moving = st == MOTION_RUNNING || st == MOTION_PAUSING || st == MOTION_PAUSED ||
                 st == MOTION_STOPPING;
    if (*c->estop || (!*c->enable && (moving || st == MOTION_MANUAL)))
        motion_estop(c->m);
    /* Off: the command follows the legs. Not in the first updates: until the drives'
     * functs have run once, their feedback pins hold nothing but the signals' zeros. */
    if (!*c->enable) {
        if (c->was_enabled)
            c->start_pending = 0;  /* a start queued before the machine went off is dropped */
        if (c->updates > MOTION_FEEDBACK_SETTLE)
            motion_track_feedback(c->m);
    } else if (!c->was_enabled) {
        motion_reset(c->m);           /* switched on: out of a fault, from where it is */
    }
    c->updates++;
    c->was_enabled = *c->enable;
    if (*c->enable && c->start_pending && st == MOTION_IDLE) {
        c->start_pending = 0;
        motion_start(c->m);
    }
    if (*c->pause && !c->last_pause)
        motion_pause(c->m);
    if (*c->resume && !c->last_resume)
        motion_resume(c->m);
    if ((*c->abort && !c->last_abort) || atomic_exchange(&c->abort_pending, 0)) {
        c->start_pending = 0;
        motion_abort(c->m);
    }
    c->last_pause = *c->pause, c->last_resume = *c->resume, c->last_abort = *c->abort;
    motion_comp_manual(c);  /* after a start, so that a step can follow it at once */
    motion_set_feed_override(c->m, *c->feed_override);
    motion_set_spindle_at_speed(c->m, *c->sp_at_speed);
}

/* The tool changer's handshake for the last M6 the path reached (LinuxCNC's order):
 * tool-prep-number and tool-prepare until tool-prepared, then tool-change until
 * tool-changed; then tool-number is the new tool and the path goes on. An input left
 * unconnected answers at once; with tool-changed unconnected and manual_tc, the operator's
 * confirmation (tool.changed) answers it. An abort or fault drops the request. */
static void motion_comp_toolchange(struct motion_comp *c, struct hal *h,
                                   const struct motion_out *o)
{
    bool gone = o->state == MOTION_IDLE || o->state == MOTION_FAULT || !*c->enable;
    if (o->tool.seq == c->tc_done_seq || gone) {
        if (o->tool.seq != c->tc_done_seq)
            c->tc_done_seq = o->tool.seq;  /* dropped with its program */
        *c->tc_prepare = *c->tc_change = false;
        c->tc_phase = 0;
        atomic_store(&c->manual_ack, 0);
        *c->tc_number = o->tool.number;
        return;
    }
    bool prepared_wired = c->tc_prepared != c->tc_prepared_own;
    bool changed_wired = c->tc_changed != c->tc_changed_own;
    switch (c->tc_phase) {
    case 0:
        *c->tc_prep_number = o->tool.request;
        *c->tc_prepare = true;
        c->tc_phase = 1;
        __attribute__((fallthrough));  /* an unwired tool-prepared answers at once */
    case 1:
        if (prepared_wired && !*c->tc_prepared)
            break;
        *c->tc_prepare = false;
        *c->tc_change = true;
        c->tc_phase = 2;
        if (!changed_wired && c->manual_tc)
            hal_msg_post(h, HAL_MSG_WARNING, "iocontrol", "tool change: put tool %d in the "
                         "spindle, then confirm it (tool.changed)", o->tool.request);
        break;
    case 2:
        if (changed_wired ? !*c->tc_changed
                          : c->manual_tc && !atomic_exchange(&c->manual_ack, 0))
            break;
        *c->tc_change = false;
        motion_tool_changed(c->m, o->tool.seq);
        *c->tc_number = o->tool.request;
        c->tc_done_seq = o->tool.seq;
        c->tc_phase = 0;
        break;
    }
}

/* Spindle and coolant pins from the commands in force; off while the drives are off. */
static void motion_comp_spindle(struct motion_comp *c, const struct motion_out *o)
{
    bool on = *c->amp_enable && o->spindle.dir != 0;
    double ovr = *c->sp_override < 0 ? 0 : *c->sp_override > 2 ? 2 : *c->sp_override;
    *c->sp_on = on;
    *c->sp_fwd = on && o->spindle.dir > 0;
    *c->sp_rev = on && o->spindle.dir < 0;
    *c->sp_speed = on ? o->spindle.dir * o->spindle.rpm * ovr : 0;
    *c->sp_rps = *c->sp_speed / 60.0;
    *c->mist = *c->amp_enable && o->spindle.mist;
    *c->flood = *c->amp_enable && o->spindle.flood;
}

/* One servo period: feedback check, commands, then the next set point. */
static void motion_comp_update(void *arg, long period_ns)
{
    struct motion_comp *c = arg;
    double fb[KINS_MAX_JOINTS];
    bool sw[KINS_MAX_JOINTS];
    struct motion_out o;
    if (pthread_mutex_trylock(&c->plan_lock) != 0)
        return;  /* the task is replacing the plan at rest: the outputs hold */
    for (int i = 0; i < c->nj; i++) {
        fb[i] = *c->joint_pos_fb[i];
        sw[i] = *c->home_sw[i];
    }
    motion_set_home_switches(c->m, sw);
    bool din[MOTION_MAX_DIO];
    double ain[MOTION_MAX_AIO];
    for (int i = 0; i < c->ndio; i++)
        din[i] = *c->din[i];
    for (int i = 0; i < c->naio; i++)
        ain[i] = *c->ain[i];
    motion_set_inputs(c->m, din, c->ndio, ain, c->naio);
    motion_set_probe_input(c->m, *c->probe_in);
    motion_set_spindle_revs(c->m, *c->sp_revs, c->sp_revs != c->sp_revs_own);
    motion_set_spindle_index(c->m, *c->sp_index, c->sp_index != c->sp_index_own);
    motion_feedback(c->m, fb);
    motion_comp_commands(c);
    motion_step(c->m, (double)period_ns * 1e-9, &o);
    c->last = o;
    for (int i = 0; i < c->nj; i++) {
        *c->joint_pos_cmd[i] = o.motor_pos[i];
        *c->joint_vel_cmd[i] = o.joint_vel[i];
        *c->ferror[i] = o.ferror_mm[i];
        *c->joint_fb_out[i] = o.joint_fb[i];
        *c->homed_pin[i] = motion_homed(c->m, i);
    }
    for (int i = 0; i < KINS_POSE_DIM; i++)
        *c->pose_cmd[i] = o.pose[i];
    *c->path_vel = o.path_vel;
    *c->time_elapsed = o.time_elapsed_s;
    *c->time_remaining = o.time_remaining_s;
    *c->program_line = o.line;
    *c->state = (int32_t)o.state;
    *c->done = o.state == MOTION_DONE;
    *c->fault = o.state == MOTION_FAULT;
    *c->amp_enable = *c->enable && o.state != MOTION_FAULT;
    motion_comp_spindle(c, &o);
    if (o.spindle_index)
        *c->sp_index = o.spindle_index > 0;
    for (int i = 0; i < c->ndio; i++)
        *c->dout[i] = (o.outputs.dout >> i) & 1u;
    for (int i = 0; i < c->naio; i++)
        *c->aout[i] = o.outputs.aout[i];
    motion_comp_toolchange(c, c->h, &o);
    pthread_mutex_unlock(&c->plan_lock);
}

/* Frees the instance at hal_destroy. */
static void motion_comp_free(void *arg)
{
    struct motion_comp *c = arg;
    motion_destroy(c->m);
    ring_spsc_free(&c->cmds);
    pthread_mutex_destroy(&c->plan_lock);
    free(c);
}

/* Pins, one group per call so each stays short. */
static int motion_comp_joint_pins(struct hal *h, struct motion_comp *c)
{
    int st = HAL_OK;
    for (int i = 0; i < c->nj && st == HAL_OK; i++) {
        st = hal_pin_float_newf(h, HAL_OUT, &c->joint_pos_cmd[i], "motion.joint-pos-cmd-%d", i);
        if (st == HAL_OK)
            st = hal_pin_float_newf(h, HAL_OUT, &c->joint_vel_cmd[i], "motion.joint-vel-cmd-%d", i);
        if (st == HAL_OK)
            st = hal_pin_float_newf(h, HAL_IN, &c->joint_pos_fb[i], "motion.joint-pos-fb-%d", i);
        if (st == HAL_OK)
            st = hal_pin_float_newf(h, HAL_OUT, &c->ferror[i], "motion.ferror-%d", i);
        if (st == HAL_OK)
            st = hal_pin_bit_newf(h, HAL_IN, &c->home_sw[i], "motion.joint-home-sw-in-%d", i);
        if (st == HAL_OK)
            st = hal_pin_float_newf(h, HAL_OUT, &c->joint_fb_out[i], "motion.joint-fb-%d", i);
        if (st == HAL_OK)
            st = hal_pin_bit_newf(h, HAL_OUT, &c->homed_pin[i], "motion.joint-homed-%d", i);
    }
    for (int i = 0; i < KINS_POSE_DIM && st == HAL_OK; i++)
        st = hal_pin_float_newf(h, HAL_OUT, &c->pose_cmd[i], "motion.pose-cmd-%c",
                                motion_axis_names[i]);
    return st;
}

static int motion_comp_state_pins(struct hal *h, struct motion_comp *c)
{
    int st = hal_pin_float_newf(h, HAL_OUT, &c->path_vel, "motion.path-vel");
    if (st == HAL_OK) st = hal_pin_float_newf(h, HAL_IN, &c->feed_override, "motion.feed-override");
    if (st == HAL_OK) st = hal_pin_float_newf(h, HAL_OUT, &c->time_elapsed, "motion.time-elapsed");
    if (st == HAL_OK) st = hal_pin_float_newf(h, HAL_OUT, &c->time_remaining, "motion.time-remaining");
    if (st == HAL_OK) st = hal_pin_s32_newf(h, HAL_OUT, &c->program_line, "motion.program-line");
    if (st == HAL_OK) st = hal_pin_s32_newf(h, HAL_OUT, &c->state, "motion.state");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_OUT, &c->done, "motion.done");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_OUT, &c->fault, "motion.fault");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_IN, &c->enable, "motion.enable");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_OUT, &c->amp_enable, "motion.amp-enable");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_IN, &c->estop, "motion.estop");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_IN, &c->pause, "motion.pause");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_IN, &c->resume, "motion.resume");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_IN, &c->abort, "motion.abort");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_OUT, &c->sp_on, "spindle.0.on");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_OUT, &c->sp_fwd, "spindle.0.forward");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_OUT, &c->sp_rev, "spindle.0.reverse");
    if (st == HAL_OK) st = hal_pin_float_newf(h, HAL_OUT, &c->sp_speed, "spindle.0.speed-out");
    if (st == HAL_OK) st = hal_pin_float_newf(h, HAL_OUT, &c->sp_rps, "spindle.0.speed-out-rps");
    if (st == HAL_OK) st = hal_pin_float_newf(h, HAL_IN, &c->sp_override, "spindle.0.override");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_IN, &c->sp_at_speed, "spindle.0.at-speed");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_OUT, &c->mist, "iocontrol.0.coolant-mist");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_OUT, &c->flood, "iocontrol.0.coolant-flood");
    for (int i = 0; st == HAL_OK && i < c->ndio; i++)
        st = hal_pin_bit_newf(h, HAL_OUT, &c->dout[i], "motion.digital-out-%02d", i);
    for (int i = 0; st == HAL_OK && i < c->naio; i++)
        st = hal_pin_float_newf(h, HAL_OUT, &c->aout[i], "motion.analog-out-%02d", i);
    for (int i = 0; st == HAL_OK && i < c->ndio; i++)
        st = hal_pin_bit_newf(h, HAL_IN, &c->din[i], "motion.digital-in-%02d", i);
    for (int i = 0; st == HAL_OK && i < c->naio; i++)
        st = hal_pin_float_newf(h, HAL_IN, &c->ain[i], "motion.analog-in-%02d", i);
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_IN, &c->probe_in, "motion.probe-input");
    if (st == HAL_OK) st = hal_pin_float_newf(h, HAL_IN, &c->sp_revs, "spindle.0.revs");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_IO, &c->sp_index, "spindle.0.index-enable");
    if (st == HAL_OK) st = hal_pin_s32_newf(h, HAL_OUT, &c->tc_prep_number, "iocontrol.0.tool-prep-number");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_OUT, &c->tc_prepare, "iocontrol.0.tool-prepare");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_IN, &c->tc_prepared, "iocontrol.0.tool-prepared");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_OUT, &c->tc_change, "iocontrol.0.tool-change");
    if (st == HAL_OK) st = hal_pin_bit_newf(h, HAL_IN, &c->tc_changed, "iocontrol.0.tool-changed");
    if (st == HAL_OK) st = hal_pin_s32_newf(h, HAL_OUT, &c->tc_number, "iocontrol.0.tool-number");
    return st;
}



/* Reads the configuration, creates the motion core on the machine's kinematics, the pins and
 * motion.update; registers the core as the object "motion". */
static int motion_comp_load(struct hal *h, int argc, char **argv)
{
    struct kins *k = hal_get_object(h, "kins");
    if (!k)
        return hal_error(h, HAL_ERR_COMPONENT, "loadrt motion: no kinematics loaded; load it "
                         "first, e.g. loadrt [KINS]KINEMATICS");
    int st = hal_args_check(h, "motion", argc, argv, "");
    if (st != HAL_OK)
        return st;
    struct motion_config cfg;
    struct kins_config kc = { hal_ini_lookup, h };
    char err[400] = "";
    motion_config_default(&cfg);
    if (motion_config_read(&cfg, &kc, k->njoints, err, sizeof err) != MOTION_OK)
        return hal_error(h, HAL_ERR_COMPONENT, "loadrt motion: %s", err);
    struct motion_comp *c = calloc(1, sizeof *c);
    if (!c)
        return hal_error(h, HAL_ERR_NOMEM, "loadrt motion: out of memory");
    pthread_mutex_init(&c->plan_lock, NULL);
    if (ring_spsc_init(&c->cmds, 64, sizeof(struct motion_hal_cmd)) != RING_OK) {
        free(c);
        return hal_error(h, HAL_ERR_NOMEM, "loadrt motion: out of memory");
    }
    if (motion_create(&cfg, k, &c->m, err, sizeof err) != MOTION_OK) {
        ring_spsc_free(&c->cmds);
        free(c);
        return hal_error(h, HAL_ERR_COMPONENT, "loadrt motion: %s", err);
    }
    if ((st = hal_on_destroy(h, motion_comp_free, c)) != HAL_OK) {
        motion_comp_free(c);
        return st;
    }
    c->nj = k->njoints;
    c->ndio = cfg.num_dio;
    c->naio = cfg.num_aio;
    if ((st = hal_set_object(h, "motion", c->m)) != HAL_OK)
        return hal_error(h, st, "loadrt motion: a motion component is loaded already");
    if ((st = motion_comp_joint_pins(h, c)) != HAL_OK || (st = motion_comp_state_pins(h, c)) != HAL_OK)
        return st;
    if ((st = hal_set_object(h, "motion-comp", c)) != HAL_OK)
        return st;
    if ((st = hal_export_functf(h, motion_comp_update, c, "motion.update")) != HAL_OK)
        return st;
    /* Start consistent: commands and unconnected feedback at the home pose's legs. */
    struct motion_out o;
    motion_step(c->m, cfg.servo_period_s, &o);
    c->last = o;
    for (int i = 0; i < c->nj; i++)
        *c->joint_pos_cmd[i] = *c->joint_pos_fb[i] = *c->joint_fb_out[i] = o.joint_pos[i];
    for (int i = 0; i < KINS_POSE_DIM; i++)
        *c->pose_cmd[i] = o.pose[i];
    *c->feed_override = 1;
    *c->sp_override = 1;
    c->h = h;
    *c->sp_at_speed = true;   /* unwired: the spindle is taken to be at speed */
    c->sp_at_speed_own = c->sp_at_speed;
    c->sp_revs_own = c->sp_revs;
    c->sp_index_own = c->sp_index;
    c->tc_prepared_own = c->tc_prepared;
    c->tc_changed_own = c->tc_changed;
    c->autostart = true;
    return HAL_OK;
}

const struct hal_comp_type hal_comp_motion = { "motion", motion_comp_load };

/* The motion core of h. */
struct motion *motion_hal_get(const struct hal *h)
{
    return h ? hal_get_object(h, "motion") : NULL;
}

/* Before a program is handed to motion (under the plan lock): once the servo thread has
 * run, the command is where the legs are, and a program planned from elsewhere would jump
 * there in one period (legs whose lengths give no pose, such as drives that never answered,
 * leave it to the start-up checks to say why); then the waits the wiring asks for. */
static int motion_comp_prepare(struct motion_comp *c, struct hal *h,
                               const double start[KINS_POSE_DIM], char *err, size_t errlen)
{
    double L[KINS_MAX_JOINTS];
    if (c->updates > MOTION_FEEDBACK_SETTLE && motion_pose_known(c->m) &&
        kins_inverse(hal_get_object(h, "kins"), start, L) == KINS_OK) {
        for (int i = 0; i < c->nj; i++) {
            double off = L[i] - c->last.joint_pos[i];
            if (fabs(off) > MOTION_START_TOL_MM) {
                if (err && errlen)
                    snprintf(err, errlen, "the program was planned from a pose the machine is "
                             "not at: leg %d ([JOINT_%d]) is %.4f mm from the program's start; "
                             "plan it again from where the machine is", i + 1, i, -off);
                return MOTION_ERR_STATE;
            }
        }
    }
    motion_set_wait_at_speed(c->m, c->sp_at_speed != c->sp_at_speed_own);
    motion_set_spindle_revs(c->m, *c->sp_revs, c->sp_revs != c->sp_revs_own);
    motion_set_wait_tool(c->m, c->tc_changed != c->tc_changed_own || c->manual_tc);
    return MOTION_OK;
}

/* Plans prog and marks it to start when enabled. Call it while motion is idle (it refuses
 * otherwise), so the servo thread is not reading the plan being replaced. */
int motion_hal_load(struct hal *h, const struct canon_prog *prog, char *err, size_t errlen)
{
    struct motion_comp *c = h ? hal_get_object(h, "motion-comp") : NULL;
    if (!c) {
        if (err && errlen)
            snprintf(err, errlen, "no motion component: the HAL files must `loadrt motion`");
        return MOTION_ERR_STATE;
    }
    pthread_mutex_lock(&c->plan_lock);
    int st = motion_comp_prepare(c, h, prog->start, err, errlen);
    if (st != MOTION_OK) {
        pthread_mutex_unlock(&c->plan_lock);
        return st;
    }
    st = motion_load(c->m, prog, err, errlen);
    c->start_pending = st == MOTION_OK && c->autostart;
    pthread_mutex_unlock(&c->plan_lock);
    return st;
}

/* A streamed program (motion_stream.c): the planner made for the component's machine and
 * attached to its motion instance, under the plan lock, after the same start-pose check as
 * motion_hal_load. */
int motion_hal_stream_begin(struct hal *h, const double start[KINS_POSE_DIM],
                            const struct motion_plan_info *totals,
                            const volatile sig_atomic_t *cancel, struct motion_stream **out,
                            char *err, size_t errlen)
{
    struct motion_comp *c = h ? hal_get_object(h, "motion-comp") : NULL;
    *out = NULL;
    if (!c) {
        snprintf(err, errlen, "no motion component: the HAL files must `loadrt motion`");
        return MOTION_ERR_STATE;
    }
    pthread_mutex_lock(&c->plan_lock);
    int st = motion_comp_prepare(c, h, start, err, errlen);
    if (st != MOTION_OK) {
        pthread_mutex_unlock(&c->plan_lock);
        return st;
    }
    st = motion_stream_create(c->m, start, cancel, out, err, errlen);
    if (st == MOTION_OK && (st = motion_stream_attach(c->m, *out, totals)) != MOTION_OK) {
        snprintf(err, errlen, "%s", motion_last_error(c->m));
        motion_stream_destroy(*out);
        *out = NULL;
    }
    c->start_pending = st == MOTION_OK && c->autostart;
    pthread_mutex_unlock(&c->plan_lock);
    return st;
}

void motion_hal_stream_end(struct hal *h, struct motion_stream *s)
{
    struct motion_comp *c = h ? hal_get_object(h, "motion-comp") : NULL;
    if (c) {
        pthread_mutex_lock(&c->plan_lock);
        motion_stream_detach(c->m);
        c->start_pending = 0;
        pthread_mutex_unlock(&c->plan_lock);
    }
    motion_stream_destroy(s);
}

/* Requests a start at the next update. */
int motion_hal_start(struct hal *h)
{
    struct motion_comp *c = h ? hal_get_object(h, "motion-comp") : NULL;
    if (!c)
        return MOTION_ERR_STATE;
    struct motion_plan_info info;
    if (motion_get_state(c->m) != MOTION_IDLE || motion_plan_info(c->m, &info) != MOTION_OK)
        return MOTION_ERR_STATE;           /* running, done, faulted or nothing loaded */
    c->start_pending = 1;
    return MOTION_OK;
}

bool motion_hal_enabled(const struct hal *h)
{
    const struct motion_comp *c = h ? hal_get_object(h, "motion-comp") : NULL;
    return c && c->was_enabled;
}

int motion_hal_set_manual_toolchange(struct hal *h, bool on)
{
    struct motion_comp *c = h ? hal_get_object(h, "motion-comp") : NULL;
    if (!c)
        return MOTION_ERR_STATE;
    c->manual_tc = on;
    return MOTION_OK;
}

bool motion_hal_manual_toolchange_waiting(const struct hal *h)
{
    const struct motion_comp *c = h ? hal_get_object(h, "motion-comp") : NULL;
    return c && c->manual_tc && c->tc_phase == 2 && c->tc_changed == c->tc_changed_own;
}

/* Whether a start, an abort or a manual command waits for the servo thread to take it. */
bool motion_hal_pending(const struct hal *h)
{
    const struct motion_comp *c = h ? hal_get_object(h, "motion-comp") : NULL;
    return c && (atomic_load(&c->start_pending) || atomic_load(&c->abort_pending) ||
                 ring_spsc_pushed(&c->cmds) != ring_spsc_popped(&c->cmds));
}

/* Requests an abort at the next update. */
int motion_hal_abort(struct hal *h)
{
    struct motion_comp *c = h ? hal_get_object(h, "motion-comp") : NULL;
    if (!c)
        return MOTION_ERR_STATE;
    c->abort_pending = 1;
    return MOTION_OK;
}

/* The output of the last update. */
int motion_hal_out(const struct hal *h, struct motion_out *out)
{
    const struct motion_comp *c = h ? hal_get_object(h, "motion-comp") : NULL;
    if (!c || !out)
        return MOTION_ERR_STATE;
    *out = c->last;
    return MOTION_OK;
}

/* The commanded pose of the last update. */
int motion_hal_pose(const struct hal *h, double pose[KINS_POSE_DIM])
{
    const struct motion_comp *c = h ? hal_get_object(h, "motion-comp") : NULL;
    if (!c || !pose)
        return MOTION_ERR_STATE;
    memcpy(pose, c->last.pose, sizeof c->last.pose);
    return MOTION_OK;
}

/* The motion core's fault or error text. */
const char *motion_hal_fault(const struct hal *h)
{
    struct motion *m = motion_hal_get(h);
    return m ? motion_last_error(m) : "no motion component loaded";
}

/* Queues a manual-motion command for the next update. */
int motion_hal_command(struct hal *h, const struct motion_hal_cmd *cmd)
{
    struct motion_comp *c = h ? hal_get_object(h, "motion-comp") : NULL;
    if (!c)
        return MOTION_ERR_STATE;
    return ring_spsc_push(&c->cmds, cmd) ? MOTION_OK : MOTION_ERR_STATE;
}

/* Runs fn(m, ctx) with the update kept out (for work on the motion core at rest). */
int motion_hal_with(struct hal *h, void (*fn)(struct motion *m, void *ctx), void *ctx)
{
    struct motion_comp *c = h ? hal_get_object(h, "motion-comp") : NULL;
    if (!c)
        return MOTION_ERR_STATE;
    pthread_mutex_lock(&c->plan_lock);
    fn(c->m, ctx);
    pthread_mutex_unlock(&c->plan_lock);
    return MOTION_OK;
}

/* Whether motion_hal_load marks a program to start by itself. */
int motion_hal_set_autostart(struct hal *h, bool on)
{
    struct motion_comp *c = h ? hal_get_object(h, "motion-comp") : NULL;
    if (!c)
        return MOTION_ERR_STATE;
    c->autostart = on;
    return MOTION_OK;
}
