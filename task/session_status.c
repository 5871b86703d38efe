/* session_status.c: the session's status object (docs/api.md, "Status"). */
#include "task/session_priv.h"

#include <math.h>
#include <string.h>

#include "interp/interp.h"
#include "motion/motion_hal.h"

const char *session_state_name(enum session_state st)
{
    return st == SESS_ESTOP ? "estop" : st == SESS_OFF ? "off" : "on";
}

const char *session_mode_name(enum session_mode md)
{
    return md == SESS_MANUAL ? "manual" : md == SESS_AUTO ? "auto" : "mdi";
}

/* An array of n doubles (null entries for NaN). */
static json_t *vec(const double *v, int n)
{
    json_t *a = json_array();
    for (int i = 0; i < n; i++)
        json_array_append_new(a, isfinite(v[i]) ? json_real(v[i]) : json_null());
    return a;
}

/* What the interpreter is doing, as LinuxCNC names it. */
static const char *interp_name(const struct session *s, enum motion_state st, bool waiting)
{
    if (!s->running)
        return "idle";
    if (st == MOTION_PAUSED || st == MOTION_PAUSING)
        return "paused";
    return waiting ? "waiting" : "reading";
}

/* The modal G codes of the MDI interpreter (the program's are its own while it runs). */
static json_t *gcodes(const struct session *s)
{
    struct interp_view v;
    interp_get_view(s->mdi, &v);
    char buf[16];
    json_t *a = json_array();
    snprintf(buf, sizeof buf, "G%d", v.plane);
    json_array_append_new(a, json_string(buf));
    json_array_append_new(a, json_string(v.inch ? "G20" : "G21"));
    static const char *const cs[] = { "G54", "G55", "G56", "G57", "G58", "G59", "G59.1",
                                      "G59.2", "G59.3" };
    if (v.coord_system >= 1 && v.coord_system <= 9)
        json_array_append_new(a, json_string(cs[v.coord_system - 1]));
    json_array_append_new(a, json_string(v.path_mode == 640 ? "G64" : v.path_mode == 611
                                         ? "G61.1" : "G61"));
    if (v.motion < 0)
        snprintf(buf, sizeof buf, "G80");
    else if (v.motion % 10)
        snprintf(buf, sizeof buf, "G%d.%d", v.motion / 10, v.motion % 10);
    else
        snprintf(buf, sizeof buf, "G%d", v.motion / 10);
    json_array_insert_new(a, 0, json_string(buf));
    json_array_append_new(a, json_string(v.incremental ? "G91" : "G90"));
    json_array_append_new(a, json_string(v.inverse_time ? "G93" : v.per_rev ? "G95" : "G94"));
    if (v.tcp)
        json_array_append_new(a, json_string("G43.4"));
    return a;
}

/* The session's modal M codes: spindle and coolant. */
static json_t *mcodes(const struct interp_view *v)
{
    json_t *a = json_array();
    json_array_append_new(a, json_string(v->spindle_dir > 0 ? "M3" : v->spindle_dir < 0
                                         ? "M4" : "M5"));
    if (v->mist)
        json_array_append_new(a, json_string("M7"));
    if (v->flood)
        json_array_append_new(a, json_string("M8"));
    if (!v->mist && !v->flood)
        json_array_append_new(a, json_string("M9"));
    return a;
}

/* G38: the probe input now and the machine's last probe move (machine coordinates). */
static json_t *probe_status(struct session *s, const struct motion_out *o)
{
    struct motion_probe_result r;
    unsigned n = motion_probe_result(s->m, &r);
    return json_pack("{s:b, s:i, s:b, s:o, s:o}", "input", o->probe_input != 0, "moves",
                     (int)n, "tripped",
                     n && r.tripped, "trip", n ? vec(r.trip, KINS_POSE_DIM) : json_null(),
                     "stop", n ? vec(r.stop, KINS_POSE_DIM) : json_null());
}

json_t *session_status(struct session *s)
{
    struct motion_out o;
    motion_hal_out(s->hal, &o);
    enum motion_state st = o.state;
    json_t *homed = json_array();
    for (int i = 0; i < s->nj; i++)
        json_array_append_new(homed, json_boolean(motion_homed(s->m, i)));
    /* the actual pose: forward kinematics of the legs' feedback, warm-started at the command */
    double actual[KINS_POSE_DIM], nanpose[KINS_POSE_DIM];
    memcpy(actual, o.pose, sizeof actual);
    bool ok = motion_pose_known(s->m) &&
              kins_forward(s->k, o.joint_fb, actual, NULL) == KINS_OK;
    for (int i = 0; i < KINS_POSE_DIM; i++)
        nanpose[i] = (double)NAN;
    const double *cmd = motion_pose_known(s->m) ? o.pose : nanpose;
    struct interp_view v;
    interp_get_view(s->mdi, &v);
    /* under G43.4 (the running program's, else MDI's) the program's position is the tip's */
    int tcp = s->running ? o.tcp : v.tcp;
    double tcp_len = s->running ? o.tool_len_mm : v.tcp_len_mm;
    struct kins_tool_frame tf;
    double tcmd[KINS_POSE_DIM], tact[KINS_POSE_DIM];
    memcpy(tcmd, cmd, sizeof tcmd);
    memcpy(tact, actual, sizeof tact);
    if (tcp && kins_get_tool_frame(s->k, &tf) == KINS_OK) {
        kins_tcp_from_pose(&tf, tcp_len, cmd, tcmd);
        kins_tcp_from_pose(&tf, tcp_len, actual, tact);
    } else {
        tcp = 0;
    }
    double pcmd[KINS_POSE_DIM], pact[KINS_POSE_DIM];
    struct interp_view vmm = v;   /* the program's position in mm, offsets and rotation off */
    vmm.inch = 0;
    interp_view_to_program(&vmm, tcmd, pcmd);
    interp_view_to_program(&vmm, tact, pact);
    if (!ok)
        for (int i = 0; i < KINS_POSE_DIM; i++)
            pact[i] = (double)NAN;
    json_t *legs = json_array();
    for (int i = 0; i < s->nj; i++)
        json_array_append_new(legs, json_pack("{s:f, s:f, s:f, s:f, s:f}", "length",
                                              o.joint_fb[i], "rate", o.joint_vel[i],
                                              "ferror", o.ferror_mm[i], "min",
                                              s->k->joint_min[i], "max", s->k->joint_max[i]));
    struct runner_progress p;
    runner_get_progress(s->r, &p);
    double progress = s->running ? fmin(1.0, p.percent / 100.0) : 0.0;
    json_t *j = json_pack(
        "{s:f, s:s, s:s, s:o, s:b, s:s, s:s, s:s?, s:i, s:f,"
        " s:{s:o, s:o}, s:{s:o, s:o}, s:o, s:o, s:o, s:{s:i, s:i, s:f, s:b, s:f}, s:f,"
        " s:{s:f, s:i, s:f}, s:{s:b, s:b}, s:{s:f, s:f, s:f}, s:{s:b, s:b}, s:s?}",
        "time", (double)hal_now_ns(s->hal) * 1e-9,
        "state", session_state_name(s->state),
        "mode", session_mode_name(s->mode),
        "homed", homed,
        "homing", motion_homing(s->m),
        "interp", interp_name(s, st, o.waiting),
        "motion", motion_state_name(st),
        "program", s->program[0] ? s->program : NULL,
        "line", s->running ? o.line : 0,
        "progress", progress,
        "pose", "commanded", vec(pcmd, KINS_POSE_DIM), "actual",
        ok ? vec(pact, KINS_POSE_DIM) : json_null(),
        "machine_pose", "commanded", vec(cmd, KINS_POSE_DIM), "actual",
        ok ? vec(actual, KINS_POSE_DIM) : json_null(),
        "legs", legs,
        "gcodes", gcodes(s),
        "mcodes", mcodes(&v),
        "tool", "number", o.tool.number, "selected", v.selected_tool, "length",
        v.tool_mm[2], "tcp", tcp != 0, "tcp_length", tcp ? tcp_len : 0.0,
        "feed", v.feed_mm_min,
        "spindle", "speed", o.spindle.rpm, "direction", o.spindle.dir, "override",
        s->spindle_ovr,
        "coolant", "mist", o.spindle.mist != 0, "flood", o.spindle.flood != 0,
        "overrides", "feed", s->feed_ovr, "rapid", s->rapid_ovr, "spindle", s->spindle_ovr,
        "switches", "optional_stop", s->optional_stop, "block_delete", s->block_delete,
        "error", s->last_error[0] ? s->last_error : NULL);
    json_object_set_new(j, "probe", probe_status(s, &o));
    return j;
}
