/* motion_home.c: homing of the legs, as LinuxCNC configures it per joint, on the servo thread. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "motion/motion_priv.h"

/*
 * A leg with a home switch (HOME_SEARCH_VEL != 0) homes in phases, each a leg move of
 * motion_manual.c that brakes to rest when its switch edge comes:
 *
 *   OFF_SWITCH  (only when the switch is already closed) away from it until it opens
 *   SEARCH      at HOME_SEARCH_VEL until the switch closes
 *   BACKOFF     (HOME_LATCH_VEL of the search's sign) away until it opens again
 *   LATCH       at HOME_LATCH_VEL until the switch closes (same sign) or opens (opposite
 *               sign): the leg's motor position at that edge becomes HOME_OFFSET
 *   FINAL       to HOME at HOME_FINAL_VEL; then the leg is homed
 *
 * A leg without a switch, or with HOME_ABSOLUTE_ENCODER, is homed at once: its feedback is
 * its length. Legs home in groups of equal |HOME_SEQUENCE|, lowest first; the legs of a
 * group move together. After the last group the platform moves to the kinematics' home pose.
 */

static double sgn(double x) { return x >= 0 ? 1 : -1; }

/* HOME of leg i: the key, or the leg's length at the kinematics' home pose. */
static double home_pos(struct motion *m, int i)
{
    double L[KINS_MAX_JOINTS];
    if (!isnan(m->cfg.joint[i].home_pos))
        return m->cfg.joint[i].home_pos;
    if (kins_inverse(m->kins, m->kins->home, L) == KINS_OK)
        return L[i];
    return 0.5 * (m->kins->joint_min[i] + m->kins->joint_max[i]);
}

static double search_mm(const struct motion *m, int i)
{
    const struct motion_joint_config *j = &m->cfg.joint[i];
    if (j->home_search_mm > 0)
        return j->home_search_mm;
    return 1.5 * (m->kins->joint_max[i] - m->kins->joint_min[i]);
}

/* Enters phase ph of leg i: starts its move. */
static void enter(struct motion *m, int i, enum motion_home_phase ph)
{
    const struct motion_joint_config *j = &m->cfg.joint[i];
    double s = sgn(j->home_search_vel), here = m->lead_L[i], far = search_mm(m, i);
    m->hphase[i] = ph;
    m->hstart[i] = here;
    switch (ph) {
    case HOME_OFF_SWITCH: motion_joint_move(m, i, here - s * far, j->home_search_vel, 1); break;
    case HOME_SEARCH: motion_joint_move(m, i, here + s * far, j->home_search_vel, 1); break;
    case HOME_BACKOFF: motion_joint_move(m, i, here - s * far, j->home_latch_vel, 1); break;
    case HOME_LATCH:
        motion_joint_move(m, i, here + sgn(j->home_latch_vel) * far, j->home_latch_vel, 1);
        break;
    case HOME_FINAL: motion_joint_move(m, i, home_pos(m, i), j->home_final_vel, 1); break;
    default: break;
    }
}

/* The latch edge: the motor position there is HOME_OFFSET from now on. The command shifts
 * with the offset, so the motor command does not move (nor, with jerk limits, the average
 * of the leader's last set points, which all shift with it). */
static void latch(struct motion *m, int i)
{
    double off = m->motor_fb[i] - m->cfg.joint[i].home_offset;
    double shift = m->motor_offset[i] - off;
    m->motor_offset[i] = off;
    m->joint_cmd[i] += shift;
    m->joint_fb[i] += shift;
    m->lead_L[i] += shift;
    m->man.jt[i] += shift;
    motion_jerk_shift_leg(m, i, shift);
}

/* Ends homing with a note (failure: the leg stays unhomed). */
static void home_fail(struct motion *m, int i, const char *why)
{
    motion_note(m, "homing failed: leg %d ([JOINT_%d]) %s; homing stopped", i + 1, i, why);
    for (int k = 0; k < m->nj; k++)
        if (m->hphase[k] != HOME_DONE)
            m->hphase[k] = HOME_IDLE;
    m->homing = 0;
    m->man.stop = 1;
}

/* One period of leg i's homing. */
static void home_leg(struct motion *m, int i)
{
    const struct motion_joint_config *j = &m->cfg.joint[i];
    bool sw = m->home_sw[i], was = m->home_sw_prev[i];
    bool idle = motion_joint_idle(m, i);
    bool latch_on_close = sgn(j->home_latch_vel) == sgn(j->home_search_vel);
    switch (m->hphase[i]) {
    case HOME_WAIT:
        if (j->home_absolute || j->home_search_vel == 0) {
            m->homed[i] = 1;
            m->hphase[i] = HOME_DONE;
        } else {
            enter(m, i, sw ? HOME_OFF_SWITCH : HOME_SEARCH);
        }
        return;
    case HOME_OFF_SWITCH:
    case HOME_BACKOFF:
        if (!sw && was) {
            motion_joint_halt(m, i);
            m->hphase[i] = m->hphase[i] == HOME_OFF_SWITCH ? HOME_SEARCH : HOME_LATCH;
            m->hstart[i] = NAN;  /* the next phase starts once the leg is at rest */
        } else if (idle) {
            home_fail(m, i, "did not leave its home switch");
        }
        return;
    case HOME_SEARCH:
        if (sw && !was && !isnan(m->hstart[i])) {
            motion_joint_halt(m, i);
            m->hphase[i] = latch_on_close ? HOME_BACKOFF : HOME_LATCH;
            m->hstart[i] = NAN;
        } else if (idle && !isnan(m->hstart[i])) {
            home_fail(m, i, "found no home switch within HOME_SEARCH_DISTANCE");
        } else if (idle) {
            enter(m, i, HOME_SEARCH);
        }
        return;
    case HOME_LATCH:
        if (isnan(m->hstart[i])) {
            if (idle)
                enter(m, i, HOME_LATCH);
            return;
        }
        if ((latch_on_close && sw && !was) || (!latch_on_close && !sw && was)) {
            latch(m, i);
            motion_joint_halt(m, i);
            m->hphase[i] = HOME_SETTLE;
        } else if (idle) {
            home_fail(m, i, "lost its home switch during the latch pass");
        }
        return;
    case HOME_SETTLE:
        if (idle)
            enter(m, i, HOME_FINAL);
        return;
    case HOME_FINAL:
        if (idle) {
            m->homed[i] = 1;
            m->hphase[i] = HOME_DONE;
        }
        return;
    default:
        return;
    }
}

/* Phases waiting for the leg to come to rest after a switch edge (hstart NAN). */
static void home_resume(struct motion *m, int i)
{
    if (!isnan(m->hstart[i]) || !motion_joint_idle(m, i))
        return;
    if (m->hphase[i] == HOME_SEARCH || m->hphase[i] == HOME_BACKOFF ||
        m->hphase[i] == HOME_LATCH)
        enter(m, i, m->hphase[i]);
}

/* Starts the next group of legs; false when none is left. */
static bool next_group(struct motion *m)
{
    int best = -1;
    for (int i = 0; i < m->nj; i++) {
        int g = abs(m->cfg.joint[i].home_sequence);
        if (m->hphase[i] == HOME_WAIT && g > m->home_group && (best < 0 || g < best))
            best = g;
    }
    if (best < 0)
        return false;
    m->home_group = best;
    return true;
}

/* One period of a homing run (motion_manual_step calls it). */
void motion_home_step(struct motion *m)
{
    if (!m->homing)
        goto out;
    int busy = 0;
    for (int i = 0; i < m->nj && m->homing; i++) {
        if (abs(m->cfg.joint[i].home_sequence) != m->home_group ||
            m->hphase[i] == HOME_IDLE || m->hphase[i] == HOME_DONE)
            continue;
        home_resume(m, i);
        home_leg(m, i);
        busy |= m->hphase[i] != HOME_DONE && m->hphase[i] != HOME_IDLE;
    }
    if (!m->homing || busy || next_group(m))
        goto out;
    m->homing = 0;
    if (!m->home_all) {
        motion_note(m, "homed");
        goto out;
    }
    if (!m->pose_known) {
        motion_note(m, "legs homed, but the forward kinematics finds no pose for their "
                    "lengths: the platform stays where it is");
        goto out;
    }
    motion_note(m, "legs homed; the platform moves to [KINS] HOME");
    motion_move_to(m, m->kins->home, 0.5);
out:
    memcpy(m->home_sw_prev, m->home_sw, sizeof m->home_sw_prev);
}

int motion_home(struct motion *m, int joint)
{
    if (!m || joint < -1 || joint >= m->nj)
        return MOTION_ERR_ARG;
    if (m->state != MOTION_IDLE && m->state != MOTION_DONE) {
        motion_set_msg(m, "homing is not possible while the motion core is %s",
                       motion_state_name(m->state));
        return MOTION_ERR_STATE;
    }
    m->home_all = joint < 0;
    m->home_group = -1;
    memcpy(m->home_sw_prev, m->home_sw, sizeof m->home_sw_prev);
    for (int i = 0; i < m->nj; i++) {
        if (joint >= 0 && i != joint)
            continue;
        m->homed[i] = 0;
        m->hphase[i] = HOME_WAIT;
    }
    if (joint >= 0)
        m->home_group = abs(m->cfg.joint[joint].home_sequence) - 1;
    if (!next_group(m))
        return MOTION_OK;
    m->homing = 1;
    motion_manual_enter(m);
    memset(&m->man, 0, sizeof m->man);
    m->man.kind = MAN_JOINTS;
    m->state = MOTION_MANUAL;
    return MOTION_OK;
}

int motion_unhome(struct motion *m, int joint)
{
    if (!m || joint < -1 || joint >= m->nj)
        return MOTION_ERR_ARG;
    for (int i = 0; i < m->nj; i++)
        if (joint < 0 || i == joint) {
            m->homed[i] = 0;
            m->hphase[i] = HOME_IDLE;
        }
    return MOTION_OK;
}

void motion_set_home_switches(struct motion *m, const bool *sw)
{
    memcpy(m->home_sw, sw, sizeof(bool) * (size_t)m->nj);
}

bool motion_homed(const struct motion *m, int joint)
{
    return m && joint >= 0 && joint < m->nj && m->homed[joint];
}

bool motion_homing(const struct motion *m)
{
    return m && m->homing;
}

bool motion_all_homed(const struct motion *m)
{
    for (int i = 0; m && i < m->nj; i++)
        if (!m->homed[i])
            return false;
    return m != NULL;
}
