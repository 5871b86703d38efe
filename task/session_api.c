/* session_api.c: JSON-RPC 2.0 requests: validation, control, the method table. */
#include "task/session_priv.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "motion/motion_hal.h"

/* A method: needs control or not; fills *result or returns an error code with err. */
typedef int (*method_fn)(struct session *s, struct session_client *c, json_t *params,
                         json_t **result, char *err, size_t len);

struct method {
    const char *name;
    bool control;      /* acts on the machine: refused while another client holds control */
    method_fn fn;
};

/* ---- parameter helpers: each returns 0, or RPC_PARAMS with the message ---------------- */

static int perr(char *err, size_t len, const char *name, const char *what)
{
    snprintf(err, len, "parameter %s: %s", name, what);
    return RPC_PARAMS;
}

static int get_bool(json_t *p, const char *name, bool required, bool *out, bool *present,
                    char *err, size_t len)
{
    json_t *v = json_object_get(p, name);
    if (present)
        *present = v != NULL;
    if (!v)
        return required ? perr(err, len, name, "missing (true or false)") : 0;
    if (!json_is_boolean(v))
        return perr(err, len, name, "must be true or false");
    *out = json_is_true(v);
    return 0;
}

static int get_num(json_t *p, const char *name, bool required, double *out, bool *present,
                   char *err, size_t len)
{
    json_t *v = json_object_get(p, name);
    if (present)
        *present = v != NULL;
    if (!v)
        return required ? perr(err, len, name, "missing (a number)") : 0;
    if (!json_is_number(v) || !isfinite(json_number_value(v)))
        return perr(err, len, name, "must be a finite number");
    *out = json_number_value(v);
    return 0;
}

static int get_int(json_t *p, const char *name, bool required, long lo, long hi, long *out,
                   bool *present, char *err, size_t len)
{
    json_t *v = json_object_get(p, name);
    if (present)
        *present = v != NULL;
    if (!v)
        return required ? perr(err, len, name, "missing (a whole number)") : 0;
    if (!json_is_integer(v) || json_integer_value(v) < lo || json_integer_value(v) > hi) {
        char what[80];
        snprintf(what, sizeof what, "must be a whole number %ld..%ld", lo, hi);
        return perr(err, len, name, what);
    }
    *out = (long)json_integer_value(v);
    return 0;
}

static int get_str(json_t *p, const char *name, const char **out, char *err, size_t len)
{
    json_t *v = json_object_get(p, name);
    if (!v)
        return perr(err, len, name, "missing (a string)");
    if (!json_is_string(v))
        return perr(err, len, name, "must be a string");
    *out = json_string_value(v);
    return 0;
}

/* ---- methods --------------------------------------------------------------------------- */

static int m_status_get(struct session *s, struct session_client *c, json_t *p, json_t **r,
                        char *err, size_t len)
{
    *r = session_status(s);
    return 0;
}

static int m_status_subscribe(struct session *s, struct session_client *c, json_t *p,
                              json_t **r, char *err, size_t len)
{
    double rate = 10;
    int rc = get_num(p, "rate_hz", false, &rate, NULL, err, len);
    if (rc)
        return rc;
    if (rate < 0 || rate > 100)
        return perr(err, len, "rate_hz", "must be 0..100");
    c->status_rate_hz = rate;
    c->next_status_ns = 0;
    return 0;
}

static int m_messages_subscribe(struct session *s, struct session_client *c, json_t *p,
                                json_t **r, char *err, size_t len)
{
    c->messages = true;
    return 0;
}

static int m_control_acquire(struct session *s, struct session_client *c, json_t *p,
                             json_t **r, char *err, size_t len)
{
    if (s->holder && s->holder != c->id) {
        snprintf(err, len, "control is held by client %u (it must control.release, or "
                 "disconnect)", s->holder);
        return RPC_CONTROL;
    }
    s->holder = c->id;
    *r = json_pack("{s:i}", "client", (int)c->id);
    return 0;
}

static int m_control_release(struct session *s, struct session_client *c, json_t *p,
                             json_t **r, char *err, size_t len)
{
    if (s->holder == c->id)
        s->holder = 0;
    return 0;
}

static int m_estop(struct session *s, struct session_client *c, json_t *p, json_t **r,
                   char *err, size_t len)
{
    bool active;
    int rc = get_bool(p, "active", true, &active, NULL, err, len);
    if (rc)
        return rc;
    /* pressing e-stop is everyone's; releasing it is the controlling client's */
    if (!active && s->holder && s->holder != c->id) {
        snprintf(err, len, "control is held by client %u", s->holder);
        return RPC_CONTROL;
    }
    return session_estop(s, active, err, len);
}

static int m_power(struct session *s, struct session_client *c, json_t *p, json_t **r,
                   char *err, size_t len)
{
    bool on;
    int rc = get_bool(p, "on", true, &on, NULL, err, len);
    return rc ? rc : session_power(s, on, err, len);
}

static int m_home(struct session *s, struct session_client *c, json_t *p, json_t **r,
                  char *err, size_t len)
{
    long j = -1;
    int rc = get_int(p, "joint", false, 0, s->nj - 1, &j, NULL, err, len);
    return rc ? rc : session_home(s, (int)j, err, len);
}

static int m_unhome(struct session *s, struct session_client *c, json_t *p, json_t **r,
                    char *err, size_t len)
{
    long j = -1;
    int rc = get_int(p, "joint", false, 0, s->nj - 1, &j, NULL, err, len);
    return rc ? rc : session_unhome(s, (int)j, err, len);
}

static int m_mode(struct session *s, struct session_client *c, json_t *p, json_t **r,
                  char *err, size_t len)
{
    const char *mode;
    int rc = get_str(p, "mode", &mode, err, len);
    if (rc)
        return rc;
    enum session_mode md = !strcmp(mode, "manual") ? SESS_MANUAL : !strcmp(mode, "auto")
                           ? SESS_AUTO : !strcmp(mode, "mdi") ? SESS_MDI : (enum session_mode)-1;
    if ((int)md < 0)
        return perr(err, len, "mode", "must be manual, auto or mdi");
    return session_set_mode(s, md, err, len);
}

static int m_shutdown(struct session *s, struct session_client *c, json_t *p, json_t **r,
                      char *err, size_t len)
{
    s->shutdown = true;
    return 0;
}

/* Axis names of the world and tool frames. */
static int axis_index(json_t *v)
{
    static const char names[] = "XYZABC";
    if (!json_is_string(v) || strlen(json_string_value(v)) != 1)
        return -1;
    const char *q = strchr(names, json_string_value(v)[0] & ~0x20);
    return q ? (int)(q - names) : -1;
}

static int m_jog(struct session *s, struct session_client *c, json_t *p, json_t **r,
                 char *err, size_t len)
{
    const char *frame;
    double vel, dist = 0;
    bool has_dist;
    int rc;
    if ((rc = get_str(p, "frame", &frame, err, len)) ||
        (rc = get_num(p, "velocity", true, &vel, NULL, err, len)) ||
        (rc = get_num(p, "distance", false, &dist, &has_dist, err, len)))
        return rc;
    int f = !strcmp(frame, "world") ? MOTION_JOG_WORLD : !strcmp(frame, "tool")
            ? MOTION_JOG_TOOL : !strcmp(frame, "joint") ? MOTION_JOG_JOINT : -1;
    if (f < 0)
        return perr(err, len, "frame", "must be world, tool or joint");
    json_t *a = json_object_get(p, "axis");
    int axis = -1;
    if (!a)
        return perr(err, len, "axis", "missing");
    if (f == MOTION_JOG_JOINT) {
        if (json_is_integer(a) && json_integer_value(a) >= 0 &&
            json_integer_value(a) < s->nj)
            axis = (int)json_integer_value(a);
        if (axis < 0)
            return perr(err, len, "axis", "a joint jog needs a leg number 0..5");
    } else {
        axis = axis_index(a);
        if (axis < 0 || (f == MOTION_JOG_TOOL && axis > 2))
            return perr(err, len, "axis", f == MOTION_JOG_TOOL ? "must be X, Y or Z"
                        : "must be one of X Y Z A B C");
    }
    if (vel == 0)
        return perr(err, len, "velocity", "must not be 0 (its sign is the direction)");
    if (has_dist && !(dist > 0))
        return perr(err, len, "distance", "must be positive (the direction is velocity's "
                    "sign)");
    int st = session_jog(s, f, axis, vel, dist, err, len);
    if (st == 0)
        s->jogger = has_dist ? 0 : c->id;
    return st;
}

static int m_jog_stop(struct session *s, struct session_client *c, json_t *p, json_t **r,
                      char *err, size_t len)
{
    s->jogger = 0;
    return session_jog_stop(s, err, len);
}

static int m_mdi(struct session *s, struct session_client *c, json_t *p, json_t **r,
                 char *err, size_t len)
{
    const char *line;
    int rc = get_str(p, "line", &line, err, len);
    return rc ? rc : session_mdi(s, line, err, len);
}

static int m_open(struct session *s, struct session_client *c, json_t *p, json_t **r,
                  char *err, size_t len)
{
    const char *path;
    int rc = get_str(p, "path", &path, err, len);
    if (!rc)
        rc = session_open(s, path, err, len);
    if (!rc)
        *r = json_pack("{s:s, s:I}", "path", s->program, "lines", (json_int_t)s->program_lines);
    return rc;
}

static int m_check(struct session *s, struct session_client *c, json_t *p, json_t **r,
                   char *err, size_t len)
{
    return session_check(s, r, err, len);
}

static int m_run(struct session *s, struct session_client *c, json_t *p, json_t **r,
                 char *err, size_t len)
{
    long from = 1;
    int rc = get_int(p, "from_line", false, 1, 1000000000L, &from, NULL, err, len);
    return rc ? rc : session_run_program(s, (int)from, err, len);
}

static int m_pause(struct session *s, struct session_client *c, json_t *p, json_t **r,
                   char *err, size_t len)
{
    return session_pause(s, err, len);
}

static int m_resume(struct session *s, struct session_client *c, json_t *p, json_t **r,
                    char *err, size_t len)
{
    return session_resume(s, err, len);
}

static int m_step(struct session *s, struct session_client *c, json_t *p, json_t **r,
                  char *err, size_t len)
{
    return session_step(s, err, len);
}

static int m_abort(struct session *s, struct session_client *c, json_t *p, json_t **r,
                   char *err, size_t len)
{
    return session_abort(s, err, len);
}

static int m_tool_changed(struct session *s, struct session_client *c, json_t *p, json_t **r,
                          char *err, size_t len)
{
    return session_tool_changed(s, err, len);
}

static int m_override(struct session *s, struct session_client *c, json_t *p, json_t **r,
                      char *err, size_t len)
{
    double f, ra, sp;
    bool hf, hr, hs;
    int rc;
    if ((rc = get_num(p, "feed", false, &f, &hf, err, len)) ||
        (rc = get_num(p, "rapid", false, &ra, &hr, err, len)) ||
        (rc = get_num(p, "spindle", false, &sp, &hs, err, len)))
        return rc;
    return session_overrides(s, hf ? &f : NULL, hr ? &ra : NULL, hs ? &sp : NULL, err, len);
}

static int m_switch(struct session *s, struct session_client *c, json_t *p, json_t **r,
                    char *err, size_t len)
{
    bool os, bd, hos, hbd;
    int rc;
    if ((rc = get_bool(p, "optional_stop", false, &os, &hos, err, len)) ||
        (rc = get_bool(p, "block_delete", false, &bd, &hbd, err, len)))
        return rc;
    if (s->running)
        return snprintf(err, len, "switch.set refused while a program runs: the switches "
                        "take effect when a program is loaded"), RPC_STATE;
    if (hos) {
        s->optional_stop = os;
        motion_set_optional_stop(s->m, os);
    }
    if (hbd) {
        s->block_delete = bd;
        runner_set_block_delete(s->r, bd);
        interp_set_block_delete(s->mdi, bd);
    }
    return 0;
}

static int m_tooltable_get(struct session *s, struct session_client *c, json_t *p,
                           json_t **r, char *err, size_t len)
{
    json_t *a = json_array();
    for (int i = 0; i < s->mdi_tt.count; i++) {
        const struct tool_entry *t = &s->mdi_tt.tools[i];
        json_array_append_new(a, json_pack("{s:i, s:i, s:f, s:f, s:f, s:s}", "tool", t->tool,
                                           "pocket", t->pocket, "length", t->z_offset_mm,
                                           "diameter", t->diameter_mm, "wear", t->wear_mm,
                                           "comment", t->comment));
    }
    *r = json_pack("{s:o, s:s}", "tools", a, "path", s->mdi_tt.path);
    return 0;
}

static int m_tooltable_set(struct session *s, struct session_client *c, json_t *p,
                           json_t **r, char *err, size_t len)
{
    struct session_tool_edit e = { 0 };
    long tool = 0, pocket = 0;
    bool hp, hc = json_object_get(p, "comment") != NULL;
    int rc;
    if ((rc = get_int(p, "tool", true, 1, TOOLTABLE_WEAR_BASE - 1, &tool, NULL, err, len)) ||
        (rc = get_int(p, "pocket", false, 0, 99999, &pocket, &hp, err, len)) ||
        (rc = get_num(p, "length", false, &e.length, &e.has_length, err, len)) ||
        (rc = get_num(p, "diameter", false, &e.diameter, &e.has_diameter, err, len)) ||
        (rc = get_num(p, "wear", false, &e.wear, &e.has_wear, err, len)) ||
        (hc && (rc = get_str(p, "comment", &e.comment, err, len))))
        return rc;
    if (e.has_diameter && e.diameter < 0)
        return perr(err, len, "diameter", "must not be negative");
    if (e.comment && strpbrk(e.comment, "\r\n"))
        return perr(err, len, "comment", "one line of text");
    e.tool = (int)tool;
    e.pocket = hp ? (int)pocket : -1;
    return session_tooltable_set(s, &e, err, len);
}

static int m_hal_show(struct session *s, struct session_client *c, json_t *p, json_t **r,
                      char *err, size_t len)
{
    const char *pattern = "";
    json_t *v = json_object_get(p, "pattern");
    if (v && !json_is_string(v))
        return perr(err, len, "pattern", "must be a string");
    if (v)
        pattern = json_string_value(v);
    if (strpbrk(pattern, " \t\r\n;#"))
        return perr(err, len, "pattern", "one name or glob, without spaces");
    char *text = NULL;
    size_t tlen = 0;
    FILE *f = open_memstream(&text, &tlen);
    if (!f)
        return snprintf(err, len, "out of memory"), RPC_FAILED;
    char cmd[600];
    snprintf(cmd, sizeof cmd, "show all %s", pattern);
    int st = hal_cmd(s->hal, cmd, NULL, 0, f);
    fclose(f);
    if (st != HAL_OK) {
        free(text);
        return snprintf(err, len, "%s", hal_last_error(s->hal)), RPC_NOT_FOUND;
    }
    *r = json_pack("{s:s}", "text", text ? text : "");
    free(text);
    return 0;
}

static int m_hal_get(struct session *s, struct session_client *c, json_t *p, json_t **r,
                     char *err, size_t len)
{
    const char *name;
    int rc = get_str(p, "name", &name, err, len);
    if (rc)
        return rc;
    char buf[128];
    if (hal_getp(s->hal, name, buf, sizeof buf) != HAL_OK &&
        hal_gets(s->hal, name, buf, sizeof buf) != HAL_OK)
        return snprintf(err, len, "%s: no such pin, parameter or signal", name), RPC_NOT_FOUND;
    *r = json_pack("{s:s, s:s}", "name", name, "value", buf);
    return 0;
}

static int m_hal_set(struct session *s, struct session_client *c, json_t *p, json_t **r,
                     char *err, size_t len)
{
    const char *name;
    int rc = get_str(p, "name", &name, err, len);
    if (rc)
        return rc;
    json_t *v = json_object_get(p, "value");
    char buf[64];
    if (json_is_string(v))
        snprintf(buf, sizeof buf, "%s", json_string_value(v));
    else if (json_is_boolean(v))
        snprintf(buf, sizeof buf, "%d", json_is_true(v) ? 1 : 0);
    else if (json_is_integer(v))
        snprintf(buf, sizeof buf, "%lld", (long long)json_integer_value(v));
    else if (json_is_real(v))
        snprintf(buf, sizeof buf, "%.17g", json_real_value(v));
    else
        return perr(err, len, "value", "missing (a number, true/false, or a string)");
    if (hal_setp(s->hal, name, buf) != HAL_OK && hal_sets(s->hal, name, buf) != HAL_OK)
        return snprintf(err, len, "%s", hal_last_error(s->hal)), RPC_NOT_FOUND;
    return 0;
}

static const struct method methods[] = {
    { "status.get", false, m_status_get },
    { "status.subscribe", false, m_status_subscribe },
    { "messages.subscribe", false, m_messages_subscribe },
    { "control.acquire", false, m_control_acquire },
    { "control.release", false, m_control_release },
    { "machine.estop", false, m_estop },
    { "machine.power", true, m_power },
    { "machine.home", true, m_home },
    { "machine.unhome", true, m_unhome },
    { "machine.mode", true, m_mode },
    { "machine.shutdown", true, m_shutdown },
    { "jog.move", true, m_jog },
    { "jog.stop", false, m_jog_stop },   /* stopping motion is everyone's, as e-stop */
    { "mdi.execute", true, m_mdi },
    { "program.open", true, m_open },
    { "program.check", true, m_check },
    { "program.run", true, m_run },
    { "program.pause", true, m_pause },
    { "program.resume", true, m_resume },
    { "program.step", true, m_step },
    { "program.abort", false, m_abort }, /* as jog.stop: anyone may stop the machine */
    { "override.set", true, m_override },
    { "switch.set", true, m_switch },
    { "tool.changed", true, m_tool_changed },
    { "tooltable.get", false, m_tooltable_get },
    { "tooltable.set", true, m_tooltable_set },
    { "hal.show", false, m_hal_show },
    { "hal.get", false, m_hal_get },
    { "hal.set", true, m_hal_set },
};

static json_t *error_response(json_t *id, int code, const char *msg)
{
    return json_pack("{s:s, s:O?, s:{s:i, s:s}}", "jsonrpc", "2.0", "id", id, "error", "code",
                     code, "message", msg);
}

json_t *session_dispatch(struct session *s, struct session_client *c, const char *line,
                         size_t len)
{
    json_error_t jerr;
    json_t *req = json_loadb(line, len, JSON_REJECT_DUPLICATES, &jerr);
    if (!req) {
        char msg[300];
        snprintf(msg, sizeof msg, "not JSON: %s (column %d)", jerr.text, jerr.column);
        return error_response(NULL, RPC_PARSE, msg);
    }
    json_t *resp = NULL;
    json_t *id = json_object_get(req, "id");
    json_t *jv = json_object_get(req, "jsonrpc");
    json_t *mv = json_object_get(req, "method");
    json_t *params = json_object_get(req, "params");
    if (json_is_array(req)) {
        resp = error_response(NULL, RPC_INVALID, "batches (JSON arrays) are not supported: "
                              "send one request per line");
        goto out;
    }
    if (!json_is_object(req) || !json_is_string(jv) || strcmp(json_string_value(jv), "2.0") ||
        !json_is_string(mv) || (id && !json_is_string(id) && !json_is_integer(id) &&
                                !json_is_null(id))) {
        resp = error_response(json_is_string(id) || json_is_integer(id) ? id : NULL,
                              RPC_INVALID, "not a JSON-RPC 2.0 request: an object with "
                              "\"jsonrpc\": \"2.0\", a string \"method\" and a number or "
                              "string \"id\"");
        goto out;
    }
    if (json_is_null(params))
        params = NULL;
    if (params && !json_is_object(params)) {
        resp = error_response(id, RPC_PARAMS, "params must be an object of named parameters");
        goto out;
    }
    const char *name = json_string_value(mv);
    const struct method *m = NULL;
    for (size_t i = 0; i < sizeof methods / sizeof methods[0]; i++)
        if (!strcmp(methods[i].name, name))
            m = &methods[i];
    if (!m) {
        char msg[200];
        snprintf(msg, sizeof msg, "no method '%.100s' (docs/api.md lists them)", name);
        resp = error_response(id, RPC_NO_METHOD, msg);
        goto out;
    }
    char err[900] = "";
    json_t *result = NULL;
    int code;
    if (m->control && s->holder && s->holder != c->id) {
        snprintf(err, sizeof err, "%s refused: control is held by client %u", name,
                 s->holder);
        code = RPC_CONTROL;
    } else {
        json_t *empty = json_object();
        code = m->fn(s, c, params ? params : empty, &result, err, sizeof err);
        json_decref(empty);
    }
    if (code == RPC_DEFERRED) {  /* the answer comes when the work ends */
        s->check_client = c->id;
        s->check_id = id ? json_incref(id) : NULL;
        goto out;
    }
    if (!id) {           /* a notification: no answer */
        json_decref(result);
        goto out;
    }
    if (code) {
        json_decref(result);
        resp = error_response(id, code, err);
    } else {
        resp = json_pack("{s:s, s:O, s:o}", "jsonrpc", "2.0", "id", id, "result",
                         result ? result : json_object());
    }
out:
    json_decref(req);
    return resp;
}
