/* motion_manual.c: manual motion on the servo thread: jogs, moves to a pose, leg moves. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "motion/motion_priv.h"

/*
 * Two shapes of manual motion, each a one-dimensional profile advanced once per period:
 *
 *  - MAN_LINE, a straight line in pose space, pose(s) = p0 + s u: world jogs (u a unit axis),
 *    tool jogs (u an axis of the platform's frame) and moves to a pose. Each period the legs'
 *    sensitivity dL/ds at the present pose caps the speed (MAX_VELOCITY / |dL/ds|) and the
 *    acceleration (MAX_ACCELERATION / |dL/ds|, with a share kept back for the change of dL/ds
 *    along the line). A look-ahead one stopping distance (plus two periods) ahead finds the
 *    edge of the workspace (a leg at its limit or no inverse solution) before the motion gets
 *    there; the edge is then located by bisection and the profile ends short of it.
 *  - MAN_JOINTS, one profile per leg, at its own speed and acceleration, the pose following
 *    by forward kinematics: leg jogs and the moves of homing.
 *
 * Both keep their state in the leader (m->lead_pose, m->lead_L) and give it to the command
 * each period. With jerk limits the command is the leader's moving average (motion_jerk.c),
 * as for a program: jogs, moves to a pose and homing keep every leg within MAX_JERK; a jog
 * that ends settles T (the average's window) later, on the leader's end exactly, and the
 * machine counts as idle only then.
 */

/* Share of a leg's acceleration the first-order term dL/ds * a may use along a line; the
 * rest covers d2L/ds2 * v^2 and the change of dL/ds over a period. */
#define MAN_ACC_SHARE 0.8
/* Share of a leg's speed a jog may use (dL/ds varies along the line). */
#define MAN_VEL_SHARE 0.95
/* Distance kept from a workspace edge, mm (deg for rotary jogs). */
#define MAN_EDGE_MARGIN 0.01
/* Step for the numeric dL/ds, in units of s. */
#define MAN_DS 1e-3

/* Records a note (a limit reached, homing finished): the session reports each once. */
void motion_note(struct motion *m, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(m->note, sizeof m->note, fmt, ap);
    va_end(ap);
    m->note_seq++;
}

const char *motion_manual_note(const struct motion *m, unsigned *seq)
{
    if (seq)
        *seq = m->note_seq;
    return m->note;
}

/* The highest speed (distance per period over dt) from which a stop that lowers the speed by
 * a dt each period fits in dist: m a dt with m (m + 1) / 2 = dist / (a dt^2). */
static double stop_speed(double dist, double a, double dt)
{
    if (dist <= 0)
        return 0;
    return a * dt * (sqrt(0.25 + 2.0 * dist / (a * dt * dt)) - 0.5);
}

/* Braking runs at a / MAN_BRAKE_SLACK, so that the last period of a stop, which cannot fall
 * on the grid of whole a dt steps, changes the speed by no more than a dt either. */
#define MAN_BRAKE_SLACK 1.125

/* The distance a stop from speed w takes (the inverse of stop_speed, braking as
 * profile_step does). */
static double stop_dist(double w, double a, double dt)
{
    w = fabs(w);
    return MAN_BRAKE_SLACK * w * w / (2 * a) + 0.5 * w * dt;
}

/* One period of a 1-D profile in distance per period: *v (the last period's distance / dt)
 * moves towards vt by at most a dt, and never so fast that a stop no longer fits in rem. The
 * speeds a servo sees from successive set points change by at most a dt per period, so the
 * differenced acceleration stays within a. Returns the distance moved (>= 0); one period
 * after the end, *v is 0. */
static double profile_step(double *v, double vt, double a, double rem, double dt)
{
    double w = *v + (vt > *v ? fmin(vt - *v, a * dt) : -fmin(*v - vt, a * dt));
    w = fmin(w, stop_speed(rem, a / MAN_BRAKE_SLACK, dt));
    if (w <= 0 || rem <= 0) {
        *v = 0;
        return 0;
    }
    if (w * dt >= rem) {  /* arrives: the last bit; the next period is at rest */
        *v = rem / dt;
        return rem;
    }
    *v = w;
    return w * dt;
}

/* Whether the pose is inside the workspace: every leg solvable and within its limits
 * (kept MAN_EDGE_MARGIN inside them). */
static bool pose_ok(struct motion *m, const double *pose, double *L)
{
    if (kins_inverse(m->kins, pose, L) != KINS_OK)
        return false;
    for (int i = 0; i < m->nj; i++)
        if (L[i] < m->kins->joint_min[i] + MAN_EDGE_MARGIN ||
            L[i] > m->kins->joint_max[i] - MAN_EDGE_MARGIN)
            return false;
    return true;
}

static void line_pose(const struct motion_manual *mm, double s, double *pose)
{
    for (int k = 0; k < KINS_POSE_DIM; k++)
        pose[k] = mm->p0[k] + s * mm->u[k];
}

/* Speed and acceleration caps at s (moving at v) from the legs' sensitivity there. A leg's
 * acceleration is L' s'' + L'' s'^2: the second term (large on rotary jogs) takes its share
 * of the leg's acceleration first, and the speed is held where it would take more than half. */
static void line_caps(struct motion *m, double s, double v, double *vcap, double *acap)
{
    struct motion_manual *mm = &m->man;
    double p[KINS_POSE_DIM], L0[KINS_MAX_JOINTS], L1[KINS_MAX_JOINTS], Lm[KINS_MAX_JOINTS];
    const double h = MAN_DS;
    *vcap = mm->v_req;
    *acap = mm->a_max;
    line_pose(mm, s, p);
    if (kins_inverse(m->kins, p, L0) != KINS_OK)
        return;
    line_pose(mm, s + h, p);
    if (kins_inverse(m->kins, p, L1) != KINS_OK)
        return;
    line_pose(mm, s - h, p);
    bool curv = kins_inverse(m->kins, p, Lm) == KINS_OK;
    double dt = m->cfg.servo_period_s;
    for (int i = 0; i < m->nj; i++) {
        double d1 = curv ? fabs(L1[i] - Lm[i]) / (2 * h) : fabs(L1[i] - L0[i]) / h;
        double d2 = curv ? fabs(L1[i] - 2 * L0[i] + Lm[i]) / (h * h) : 0;
        double amax = MAN_ACC_SHARE * m->cfg.joint[i].max_acc_mm_s2;
        if (d2 > 1e-9)
            *vcap = fmin(*vcap, sqrt(0.5 * amax / d2));
        if (d1 < 1e-9)
            continue;
        *vcap = fmin(*vcap, MAN_VEL_SHARE * m->cfg.joint[i].max_vel_mm_s / d1);
        double vn = fmin(fmax(v, 0) + amax / d1 * dt, fmax(*vcap, v));
        *acap = fmin(*acap, fmax(amax - d2 * vn * vn, 0.5 * amax) / d1);
    }
}

/* The first s in (a, b] outside the workspace, to within 1e-4, given pose(a) inside. */
static double find_edge(struct motion *m, double a, double b)
{
    double p[KINS_POSE_DIM], L[KINS_MAX_JOINTS];
    for (int it = 0; it < 40 && b - a > 1e-4; it++) {
        double c = 0.5 * (a + b);
        line_pose(&m->man, c, p);
        if (pose_ok(m, p, L))
            a = c;
        else
            b = c;
    }
    return a;
}

/* Names the leg that limits a pose just past the edge, for the note. */
static void edge_note(struct motion *m, double s)
{
    double p[KINS_POSE_DIM], L[KINS_MAX_JOINTS];
    line_pose(&m->man, s, p);
    int st = kins_inverse(m->kins, p, L);
    for (int i = 0; i < m->nj && st == KINS_OK; i++) {
        if (L[i] < m->kins->joint_min[i] + MAN_EDGE_MARGIN) {
            motion_note(m, "jog stopped at the workspace edge: leg %d at its shortest "
                        "([JOINT_%d] MIN_LIMIT = %.3f mm)", i + 1, i, m->kins->joint_min[i]);
            return;
        }
        if (L[i] > m->kins->joint_max[i] - MAN_EDGE_MARGIN) {
            motion_note(m, "jog stopped at the workspace edge: leg %d at its longest "
                        "([JOINT_%d] MAX_LIMIT = %.3f mm)", i + 1, i, m->kins->joint_max[i]);
            return;
        }
    }
    char why[300];
    if (st == KINS_ERR_WORKSPACE && kins_describe(m->kins, p, why, sizeof why) != KINS_OK) {
        motion_note(m, "jog stopped at the workspace edge: %s", why);
        return;
    }
    motion_note(m, "jog stopped at the edge of the reachable workspace (%s)",
                kins_strerror(st));
}

/* One period along the line. */
static void line_step(struct motion *m, double dt)
{
    struct motion_manual *mm = &m->man;
    double vcap, acap, p[KINS_POSE_DIM], L[KINS_MAX_JOINTS];
    line_caps(m, mm->s, mm->v, &vcap, &acap);
    /* Look ahead one stopping distance and two periods: an edge there pulls s_end in. */
    double look = mm->s + stop_dist(mm->v, acap, dt) + 3 * fmax(mm->v, vcap) * dt +
                  MAN_EDGE_MARGIN;
    if (look < mm->s_end) {
        line_pose(mm, look, p);
        if (!pose_ok(m, p, L)) {
            double edge = find_edge(m, mm->s, look);
            if (edge < mm->s_end) {
                if (!mm->limited)
                    edge_note(m, look);
                mm->s_end = edge;
                mm->limited = 1;
            }
        }
    }
    double vt = mm->stop ? 0 : vcap;
    double ds = profile_step(&mm->v, vt, acap, mm->s_end - mm->s, dt);
    line_pose(mm, mm->s + ds, p);
    bool inside = pose_ok(m, p, L);  /* L: the legs at p, whatever pose_ok said */
    if (ds > 0 && !inside) {  /* never step outside, whatever the estimate said */
        if (!mm->limited)
            edge_note(m, mm->s + ds);
        mm->limited = 1;
        mm->v = 0;
        ds = 0;
        mm->s_end = mm->s;
        line_pose(mm, mm->s, p);
        kins_inverse(m->kins, p, L);
    }
    mm->s += ds;
    for (int i = 0; i < m->nj; i++)
        m->joint_vel[i] = (L[i] - m->lead_L[i]) / dt;
    memcpy(m->lead_pose, p, sizeof m->lead_pose);
    memcpy(m->lead_L, L, sizeof(double) * (size_t)m->nj);
    for (int k = 0; k < KINS_POSE_DIM; k++)
        m->pose_vel[k] = mm->u[k] * mm->v;
    m->path_vel = mm->v;
    if (mm->v == 0 && (mm->stop || mm->s >= mm->s_end - 1e-12))
        mm->kind = MAN_NONE;
}

/* One period of the legs' own profiles; the pose follows by forward kinematics. */
static void joints_step(struct motion *m, double dt)
{
    struct motion_manual *mm = &m->man;
    int any = 0;
    for (int i = 0; i < m->nj; i++) {
        m->joint_vel[i] = 0;
        if (!mm->jact[i])
            continue;
        const struct motion_joint_config *j = &m->cfg.joint[i];
        double target = mm->jt[i];
        if (!mm->jfree[i])
            target = fmin(fmax(target, m->kins->joint_min[i]), m->kins->joint_max[i]);
        double dir = target >= m->lead_L[i] ? 1 : -1;
        /* a reversal of direction first brakes: profile_step works on |v| along dir */
        double v = mm->jv[i] * dir;
        double rem = fabs(target - m->lead_L[i]);
        if (v < 0) {  /* moving away from the target: brake first */
            double dv = fmin(-v, j->max_acc_mm_s2 * dt);
            double vn = v + dv;
            m->lead_L[i] += dir * vn * dt;
            mm->jv[i] = vn * dir;
            m->joint_vel[i] = mm->jv[i];
            any = 1;
            continue;
        }
        double vt = mm->stop ? 0 : fmin(fabs(mm->jvreq[i]), j->max_vel_mm_s);
        double d = profile_step(&v, vt, j->max_acc_mm_s2, rem, dt);
        m->lead_L[i] += dir * d;
        mm->jv[i] = v * dir;
        m->joint_vel[i] = d * dir / dt;
        if (v == 0 && (mm->stop || rem - d <= 1e-9))
            mm->jact[i] = 0;
        else
            any = 1;
    }
    double pose[KINS_POSE_DIM];
    memcpy(pose, m->lead_pose, sizeof pose);
    m->pose_known = kins_forward(m->kins, m->lead_L, pose, NULL) == KINS_OK;
    if (m->pose_known)
        memcpy(m->lead_pose, pose, sizeof pose);
    memset(m->pose_vel, 0, sizeof m->pose_vel);
    m->path_vel = 0;
    if (!any)
        mm->kind = MAN_NONE;
}

void motion_manual_enter(struct motion *m)
{
    if (m->state == MOTION_MANUAL)
        return;
    memcpy(m->lead_pose, m->pose, sizeof m->lead_pose);
    memcpy(m->lead_L, m->joint_cmd, sizeof m->lead_L);
}

/* Manual motion may start or change only when no program runs; it begins at the command
 * (motion_manual_enter). */
static int manual_allowed(struct motion *m)
{
    if (m->state == MOTION_IDLE || m->state == MOTION_DONE || m->state == MOTION_MANUAL) {
        motion_manual_enter(m);
        return MOTION_OK;
    }
    motion_set_msg(m, "manual motion is not possible while the motion core is %s",
                   motion_state_name(m->state));
    return MOTION_ERR_STATE;
}

/* Starts a line from the present pose along u (unit in the sense of s) to s_end. */
static void start_line(struct motion *m, const double *u, double v_req, double a_max,
                       double s_end)
{
    struct motion_manual *mm = &m->man;
    double v0 = 0;
    /* A jog changed while moving along the same line keeps its speed. */
    if (mm->kind == MAN_LINE && !mm->stop) {
        double dot = 0;
        for (int k = 0; k < KINS_POSE_DIM; k++)
            dot += u[k] * mm->u[k];
        if (dot > 0.999999)
            v0 = mm->v;
    }
    memset(mm, 0, sizeof *mm);
    mm->kind = MAN_LINE;
    memcpy(mm->p0, m->lead_pose, sizeof mm->p0);
    memcpy(mm->u, u, sizeof mm->u);
    mm->v = v0;
    mm->v_req = v_req;
    mm->a_max = a_max;
    mm->s_end = s_end;
    m->state = MOTION_MANUAL;
}

/* The platform's own axis `axis` (0..2) in the base frame: column of R = Rz(C) Ry(B) Rx(A). */
static void platform_axis(const double *pose, int axis, double *out)
{
    double d2r = M_PI / 180.0;
    double sa = sin(pose[3] * d2r), ca = cos(pose[3] * d2r), sb = sin(pose[4] * d2r),
           cb = cos(pose[4] * d2r), sc = sin(pose[5] * d2r), cc = cos(pose[5] * d2r);
    double r[3][3] = {
        { cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa },
        { sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa },
        { -sb, cb * sa, cb * ca },
    };
    for (int k = 0; k < 3; k++)
        out[k] = r[k][axis];
}

int motion_jog(struct motion *m, enum motion_jog_frame frame, int axis, double vel,
               double dist)
{
    if (!m || !isfinite(vel) || vel == 0 || isnan(dist))
        return MOTION_ERR_ARG;
    int st = manual_allowed(m);
    if (st)
        return st;
    if (frame == MOTION_JOG_JOINT) {
        if (axis < 0 || axis >= m->nj)
            return MOTION_ERR_ARG;
        struct motion_manual *mm = &m->man;
        if (mm->kind != MAN_JOINTS) {
            memset(mm, 0, sizeof *mm);
            mm->kind = MAN_JOINTS;
        }
        mm->stop = 0;
        mm->jact[axis] = 1;
        mm->jvreq[axis] = fabs(vel);
        mm->jfree[axis] = !m->homed[axis];
        double far = vel > 0 ? HUGE_VAL : -HUGE_VAL;
        if (m->homed[axis])
            far = vel > 0 ? m->kins->joint_max[axis] : m->kins->joint_min[axis];
        else
            far = m->lead_L[axis] + (vel > 0 ? 1 : -1) *
                  (m->kins->joint_max[axis] - m->kins->joint_min[axis]);
        mm->jt[axis] = dist > 0 ? m->lead_L[axis] + (vel > 0 ? dist : -dist) : far;
        m->state = MOTION_MANUAL;
        return MOTION_OK;
    }
    if (axis < 0 || axis >= (frame == MOTION_JOG_TOOL ? 3 : KINS_POSE_DIM))
        return MOTION_ERR_ARG;
    if (!motion_all_homed(m) || !m->pose_known) {
        motion_set_msg(m, "world and tool jogs need every leg homed (joint jogs do not)");
        return MOTION_ERR_STATE;
    }
    double u[KINS_POSE_DIM] = { 0 };
    double sign = vel > 0 ? 1 : -1;
    if (frame == MOTION_JOG_TOOL)
        platform_axis(m->lead_pose, axis, u);
    else
        u[axis] = 1;
    for (int k = 0; k < KINS_POSE_DIM; k++)
        u[k] *= sign;
    int rot = frame == MOTION_JOG_WORLD && axis >= 3;
    double vmax = rot ? m->cfg.max_ang_vel_deg_s : m->cfg.max_lin_vel_mm_s;
    double amax = rot ? m->cfg.max_ang_acc_deg_s2 : m->cfg.max_lin_acc_mm_s2;
    start_line(m, u, fmin(fabs(vel), vmax), amax, dist > 0 ? dist : HUGE_VAL);
    return MOTION_OK;
}

int motion_move_to(struct motion *m, const double pose[KINS_POSE_DIM], double speed_scale)
{
    if (!m || !pose || !(speed_scale > 0) || speed_scale > 1)
        return MOTION_ERR_ARG;
    int st = manual_allowed(m);
    if (st)
        return st;
    /* s measures mm of XYZ, or deg when only A B C change; u carries the rest along */
    double d[KINS_POSE_DIM], lin = 0, ang = 0;
    for (int k = 0; k < KINS_POSE_DIM; k++) {
        d[k] = pose[k] - m->lead_pose[k];
        if (k < 3)
            lin += d[k] * d[k];
        else
            ang = fmax(ang, fabs(d[k]));
    }
    lin = sqrt(lin);
    if (lin < 1e-9 && ang < 1e-9)
        return MOTION_OK;
    double len = lin > 1e-9 ? lin : ang;
    double u[KINS_POSE_DIM];
    for (int k = 0; k < KINS_POSE_DIM; k++)
        u[k] = d[k] / len;
    /* the angular limits hold for the rotary parts: scale the path limits down to them */
    double vmax = lin > 1e-9 ? m->cfg.max_lin_vel_mm_s : m->cfg.max_ang_vel_deg_s;
    double amax = lin > 1e-9 ? m->cfg.max_lin_acc_mm_s2 : m->cfg.max_ang_acc_deg_s2;
    for (int k = 3; k < KINS_POSE_DIM; k++)
        if (fabs(u[k]) > 1e-12) {
            vmax = fmin(vmax, m->cfg.max_ang_vel_deg_s / fabs(u[k]));
            amax = fmin(amax, m->cfg.max_ang_acc_deg_s2 / fabs(u[k]));
        }
    start_line(m, u, vmax * speed_scale, amax, len);
    return MOTION_OK;
}

int motion_jog_stop(struct motion *m)
{
    if (!m)
        return MOTION_ERR_ARG;
    if (m->state == MOTION_MANUAL)
        m->man.stop = 1;
    if (m->homing) {
        m->homing = 0;
        for (int i = 0; i < m->nj; i++)
            if (m->hphase[i] != HOME_DONE)
                m->hphase[i] = HOME_IDLE;
        motion_note(m, "homing stopped by the operator: the legs not yet homed stay unhomed");
    }
    return MOTION_OK;
}

/* Starts a leg's own move to target at speed vel (homing uses it); free: not held to the
 * leg's limits. */
void motion_joint_move(struct motion *m, int i, double target, double vel, int free_leg)
{
    struct motion_manual *mm = &m->man;
    if (mm->kind != MAN_JOINTS) {
        memset(mm, 0, sizeof *mm);
        mm->kind = MAN_JOINTS;
    }
    mm->stop = 0;
    mm->jact[i] = 1;
    mm->jt[i] = target;
    mm->jvreq[i] = fabs(vel);
    mm->jfree[i] = free_leg;
    m->state = MOTION_MANUAL;
}

/* Brakes leg i to rest where it is (homing, on a switch edge). */
void motion_joint_halt(struct motion *m, int i)
{
    struct motion_manual *mm = &m->man;
    double v = mm->jv[i], a = m->cfg.joint[i].max_acc_mm_s2;
    mm->jt[i] = m->lead_L[i] + (v >= 0 ? 1 : -1) * stop_dist(v, a, m->cfg.servo_period_s);
}

/* Whether leg i's own move has ended. */
bool motion_joint_idle(const struct motion *m, int i)
{
    return m->man.kind != MAN_JOINTS || !m->man.jact[i];
}

/* One period of manual motion (motion_step calls it in MOTION_MANUAL). */
void motion_manual_step(struct motion *m, double dt)
{
    motion_home_step(m);
    if (m->man.kind == MAN_LINE)
        line_step(m, dt);
    else if (m->man.kind == MAN_JOINTS)
        joints_step(m, dt);
    if (m->man.kind == MAN_NONE) {
        memset(m->joint_vel, 0, sizeof m->joint_vel);
        memset(m->pose_vel, 0, sizeof m->pose_vel);
        m->path_vel = 0;
        /* (with jerk limits, idle once the average has come to rest on the leader) */
        if (!m->homing && motion_jerk_settled(m))
            m->state = MOTION_IDLE;
    }
    /* the leader to the command (motion_jerk_follow averages it) */
    memcpy(m->pose, m->lead_pose, sizeof m->pose);
    memcpy(m->joint_cmd, m->lead_L, sizeof(double) * (size_t)m->nj);
}

bool motion_pose_known(const struct motion *m)
{
    return m && m->pose_known;
}

/* While the machine is off, the command follows the legs (see motion.h). */
void motion_track_feedback(struct motion *m)
{
    if (!m || m->state == MOTION_RUNNING || m->state == MOTION_PAUSING ||
        m->state == MOTION_STOPPING)
        return;
    int differs = 0;
    for (int i = 0; i < m->nj; i++)
        if (fabs(m->joint_fb[i] - m->joint_cmd[i]) > m->cfg.joint[i].min_ferror_mm)
            differs = 1;
    if (m->state == MOTION_MANUAL) {  /* the machine went off under a jog: it is over */
        memset(&m->man, 0, sizeof m->man);
        m->homing = 0;
        m->state = MOTION_IDLE;
    }
    if (!differs)
        return;
    memcpy(m->joint_cmd, m->joint_fb, sizeof(double) * (size_t)m->nj);
    double pose[KINS_POSE_DIM];
    memcpy(pose, m->pose, sizeof pose);
    m->pose_known = kins_forward(m->kins, m->joint_cmd, pose, NULL) == KINS_OK;
    if (!m->pose_known) {  /* a cold start from the home pose may still find it */
        memcpy(pose, m->kins->home, sizeof pose);
        m->pose_known = kins_forward(m->kins, m->joint_cmd, pose, NULL) == KINS_OK;
    }
    if (m->pose_known)
        memcpy(m->pose, pose, sizeof pose);
    memcpy(m->lead_pose, m->pose, sizeof m->lead_pose);
    memcpy(m->lead_L, m->joint_cmd, sizeof m->lead_L);
}

int motion_reset(struct motion *m)
{
    if (!m)
        return MOTION_ERR_ARG;
    if (m->state != MOTION_FAULT)
        return MOTION_OK;
    m->state = MOTION_IDLE;
    m->fault_status = MOTION_OK;
    m->loaded = 0;
    memset(&m->man, 0, sizeof m->man);
    m->homing = 0;
    return MOTION_OK;
}
