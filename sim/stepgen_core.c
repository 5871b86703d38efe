/* stepgen_core.c: the step generator's position-tracking controller, without HAL. */
#include "sim/stepgen.h"

#include <math.h>
#include <string.h>

/*
 * The controller, per period dt, with p the internal (unquantised) motor position:
 *
 *     vc  = (cmd - cmd_prev) / dt            velocity the command is moving at
 *     d   = cmd - p - vc dt                  what is left if the motor just matched vc
 *     r   = a (sqrt(dt^2 + 2 |d| / a) - dt)  catch-up speed from which the motor can still
 *                                            stop within |d|: r dt + r^2 / 2a = |d|
 *     v   = clamp(vc + sign(d) r, +-maxvel), then within +-maxaccel dt of the last v
 *
 * For small |d| the catch-up is r ~ |d| / dt (close the gap in one period); for large |d|
 * it is the braking curve sqrt(2 a |d|). Since r dt <= |d| it never steps past the
 * command on its own; only the acceleration clamp can cause a small overshoot, when the
 * command itself breaks the limits.
 */

/* The catch-up speed (mm/s) from which a motor braking at accel_mm_s2 stops within
 * dist_mm, given that it first moves for one period dt_s at that speed. */
static double stepgen_catchup(double dist_mm, double accel_mm_s2, double dt_s)
{
    if (accel_mm_s2 <= 0.0)
        return dist_mm / dt_s;
    return accel_mm_s2 * (sqrt(dt_s * dt_s + 2.0 * dist_mm / accel_mm_s2) - dt_s);
}

/* Limits x to [-lim, lim]; lim <= 0 means no limit. */
static double stepgen_clamp(double x, double lim)
{
    if (lim <= 0.0)
        return x;
    return x > lim ? lim : (x < -lim ? -lim : x);
}

/* A channel at rest at pos_mm, not yet primed by an enabled period. */
void stepgen_state_init(struct stepgen_state *s, double pos_mm)
{
    memset(s, 0, sizeof *s);
    s->pos_mm = pos_mm;
    s->cmd_prev_mm = pos_mm;
}

/* One period of the controller described above; returns the whole-step count. */
int64_t stepgen_step(struct stepgen_state *s, const struct stepgen_limits *lim,
                     double cmd_mm, bool enable, double dt_s)
{
    if (!s->primed) {
        /* The simulated machine powers up homed: until its first enabled period the motor
         * is where the command says, so no leg jumps from 0 to its working length. */
        s->pos_mm = cmd_mm;
        s->cmd_prev_mm = cmd_mm;
        s->counts = (int64_t)llround(cmd_mm * lim->scale);
        s->primed = enable;
        return s->counts;
    }
    double vc = (cmd_mm - s->cmd_prev_mm) / dt_s;
    s->cmd_prev_mm = cmd_mm;
    double v;
    if (enable) {
        double d = cmd_mm - s->pos_mm - vc * dt_s;
        double r = stepgen_catchup(fabs(d), lim->maxaccel_mm_s2, dt_s);
        v = stepgen_clamp(vc + (d < 0.0 ? -r : r), lim->maxvel_mm_s);
    } else {
        v = 0.0;  /* a disabled stepper gets no pulses: it stands still */
    }
    double dv_max = lim->maxaccel_mm_s2 * dt_s;
    if (lim->maxaccel_mm_s2 > 0.0 && enable)
        v = s->vel_mm_s + stepgen_clamp(v - s->vel_mm_s, dv_max);
    s->vel_mm_s = v;
    s->pos_mm += v * dt_s;
    /* Whole steps: the motor moves in increments of 1/scale; round to the nearest. */
    s->counts = (int64_t)llround(s->pos_mm * lim->scale);
    return s->counts;
}

/* Velocity mode (LinuxCNC's ctrl_type v): the step rate follows vel_cmd_mm_s within maxvel
 * and maxaccel; the position is whatever the steps add up to. */
int64_t stepgen_step_velocity(struct stepgen_state *s, const struct stepgen_limits *lim,
                              double vel_cmd_mm_s, bool enable, double dt_s)
{
    s->primed = s->primed || enable;
    double v = enable ? stepgen_clamp(vel_cmd_mm_s, lim->maxvel_mm_s) : 0.0;
    if (lim->maxaccel_mm_s2 > 0.0 && enable)
        v = s->vel_mm_s + stepgen_clamp(v - s->vel_mm_s, lim->maxaccel_mm_s2 * dt_s);
    s->vel_mm_s = v;
    s->pos_mm += v * dt_s;
    s->cmd_prev_mm = s->pos_mm;
    s->counts = (int64_t)llround(s->pos_mm * lim->scale);
    return s->counts;
}
