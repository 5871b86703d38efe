/* cmd_ctl.c: `hexcnc ctl`: one call to the machine session's API, result as JSON. */
#include <errno.h>
#include <stdbool.h>
#include <jansson.h>
#include <math.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include "common/inifile.h"
#include "tools/cmd.h"

const char cmd_ctl_usage[] =
    "ctl [--socket PATH] METHOD [KEY=VALUE ...] | watch | wait [timeout=S]   call the "
    "machine session (docs/api.md)";

/* The connection: a socket and what has been read from it but not used. */
struct ctl_conn {
    int fd;
    char buf[1 << 16];
    size_t len;
    char *line;              /* the last whole line (malloc'd) */
};

static int ctl_default_socket(char *out, size_t len)
{
    return inifile_api_socket(NULL, NULL, out, len) < 0;
}

static int ctl_connect(struct ctl_conn *c, const char *path)
{
    struct sockaddr_un a = { .sun_family = AF_UNIX };
    if (strlen(path) >= sizeof a.sun_path) {
        fprintf(stderr, "hexcnc ctl: %s: a socket path has at most %zu characters\n", path,
                sizeof a.sun_path - 1);
        return -1;
    }
    memcpy(a.sun_path, path, strlen(path) + 1);
    c->fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (c->fd < 0 || connect(c->fd, (struct sockaddr *)&a, sizeof a) != 0) {
        fprintf(stderr, "hexcnc ctl: %s: %s (is `hexcnc machine` running?)\n", path,
                strerror(errno));
        return -1;
    }
    return 0;
}

/* The next line from the session, parsed; NULL on end of stream or after timeout_ms. */
static json_t *ctl_read(struct ctl_conn *c, int timeout_ms)
{
    for (;;) {
        char *nl = memchr(c->buf, '\n', c->len);
        if (nl) {
            size_t n = (size_t)(nl - c->buf);
            json_t *j = json_loadb(c->buf, n, 0, NULL);
            memmove(c->buf, nl + 1, c->len - n - 1);
            c->len -= n + 1;
            if (j)
                return j;
            continue;
        }
        if (c->len == sizeof c->buf) {
            fprintf(stderr, "hexcnc ctl: a line from the session is longer than %zu bytes\n",
                    sizeof c->buf);
            return NULL;
        }
        struct pollfd pf = { c->fd, POLLIN, 0 };
        if (poll(&pf, 1, timeout_ms) <= 0)
            return NULL;
        ssize_t r = read(c->fd, c->buf + c->len, sizeof c->buf - c->len);
        if (r <= 0)
            return NULL;
        c->len += (size_t)r;
    }
}

static int ctl_send(struct ctl_conn *c, const char *method, json_t *params, int id)
{
    json_t *req = json_pack("{s:s, s:i, s:s, s:O?}", "jsonrpc", "2.0", "id", id, "method",
                            method, "params", params);
    char *text = req ? json_dumps(req, JSON_COMPACT) : NULL;
    json_decref(req);
    if (!text)
        return -1;
    size_t n = strlen(text);
    text[n] = '\n';
    ssize_t w = write(c->fd, text, n + 1);
    free(text);
    return w == (ssize_t)(n + 1) ? 0 : -1;
}

/* How long to wait for a method's answer, ms (-1: while the session is there).
 * program.check (and a run or step that checks first) answers when the check of the whole
 * file ends, a minute for ten million lines. */
static int ctl_timeout_ms(const char *method)
{
    static const char *const checking[] = { "program.check", "program.run", "program.step" };
    for (size_t i = 0; i < sizeof checking / sizeof *checking; i++)
        if (!strcmp(method, checking[i]))
            return -1;
    return 30000;
}

/* One call: the response with this id (notifications skipped), waiting timeout_ms for it
 * (ctl_timeout_ms). */
static json_t *ctl_call(struct ctl_conn *c, const char *method, json_t *params, int id,
                        int timeout_ms)
{
    if (ctl_send(c, method, params, id) != 0)
        return NULL;
    for (;;) {
        json_t *j = ctl_read(c, timeout_ms);
        if (!j)
            return NULL;
        json_t *jid = json_object_get(j, "id");
        if (json_is_integer(jid) && json_integer_value(jid) == id)
            return j;
        json_decref(j);
    }
}

/* KEY=VALUE: VALUE as JSON when it parses as such, else as a string. */
static int ctl_params(int argc, char **argv, json_t *params)
{
    for (int i = 0; i < argc; i++) {
        char *eq = strchr(argv[i], '=');
        if (!eq || eq == argv[i]) {
            fprintf(stderr, "hexcnc ctl: '%s': parameters are KEY=VALUE\n", argv[i]);
            return -1;
        }
        *eq = '\0';
        json_t *v = json_loads(eq + 1, JSON_DECODE_ANY, NULL);
        if (!v)
            v = json_string(eq + 1);
        json_object_set_new(params, argv[i], v);
    }
    return 0;
}

/* Prints the result, or the error on stderr: the exit status. */
static int ctl_print(json_t *resp)
{
    if (!resp) {
        fprintf(stderr, "hexcnc ctl: no answer from the session (it ended, or took longer "
                "than 30 s; program.check, program.run and program.step wait as long as "
                "it takes)\n");
        return 1;
    }
    json_t *e = json_object_get(resp, "error");
    if (e) {
        fprintf(stderr, "hexcnc ctl: %s\n", json_string_value(json_object_get(e, "message")));
        return 1;
    }
    char *text = json_dumps(json_object_get(resp, "result"), JSON_INDENT(2) |
                            JSON_ENCODE_ANY);
    printf("%s\n", text);
    free(text);
    return 0;
}

static double ctl_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* `wait`: until the interpreter is idle and nothing moves; 1 on e-stop, fault or timeout. */
static int ctl_wait(struct ctl_conn *c, json_t *params)
{
    double timeout = 600;
    json_t *t = json_object_get(params, "timeout");
    if (t && json_is_number(t))
        timeout = json_number_value(t);
    double end = ctl_now() + timeout;
    json_t *sub = json_pack("{s:f}", "rate_hz", 50.0);
    json_t *r = ctl_call(c, "messages.subscribe", sub, 1, 30000);
    json_decref(r);
    json_decref(sub);
    int id = 2;
    while (ctl_now() < end) {
        json_t *st = ctl_call(c, "status.get", NULL, id++, 30000);
        json_t *res = json_object_get(st, "result");
        if (!res) {
            int rc = st ? ctl_print(st) : 1;
            if (!st)
                fprintf(stderr, "hexcnc ctl: the session ended\n");
            json_decref(st);
            return rc ? rc : 1;
        }
        const char *state = json_string_value(json_object_get(res, "state"));
        const char *interp = json_string_value(json_object_get(res, "interp"));
        const char *motion = json_string_value(json_object_get(res, "motion"));
        const char *error = json_string_value(json_object_get(res, "error"));
        int homing = json_is_true(json_object_get(res, "homing"));
        int done = 0, rc = 0;
        if (state && !strcmp(state, "estop")) {
            fprintf(stderr, "hexcnc ctl: the machine is in e-stop%s%s\n", error ? ": " : "",
                    error ? error : "");
            done = rc = 1;
        } else if (motion && !strcmp(motion, "fault")) {
            fprintf(stderr, "hexcnc ctl: %s\n", error ? error : "the machine faulted");
            done = rc = 1;
        } else if (interp && !strcmp(interp, "idle") && !homing && motion &&
                   strcmp(motion, "manual") && strcmp(motion, "running") &&
                   strcmp(motion, "stopping") && strcmp(motion, "pausing")) {
            done = 1;
        }
        json_decref(st);
        if (done)
            return rc;
        struct timespec ts = { 0, 20000000 };
        nanosleep(&ts, NULL);
    }
    fprintf(stderr, "hexcnc ctl: still busy after %g s\n", timeout);
    return 1;
}

/* `watch`: status notifications, one per line, until the session ends. */
static int ctl_watch(struct ctl_conn *c, json_t *params)
{
    json_t *rate = json_object_get(params, "rate_hz");
    json_t *p = json_pack("{s:O}", "rate_hz", rate ? rate : json_real(5));
    json_t *r = ctl_call(c, "status.subscribe", p, 1, 30000);
    json_decref(p);
    int rc = ctl_print(r) ? 1 : 0;
    json_decref(r);
    json_t *j;
    while (!rc && (j = ctl_read(c, -1))) {
        char *text = json_dumps(json_object_get(j, "params"), JSON_COMPACT);
        if (text)
            printf("%s\n", text);
        fflush(stdout);
        free(text);
        json_decref(j);
    }
    return rc;
}

/* `hexcnc halcmd --attach [SOCKET] COMMAND...`: show, getp/gets, setp/sets on the running
 * machine through hal.show, hal.get and hal.set. */
int ctl_halcmd_attach(int argc, char **argv)
{
    static const char *const cmds[] = { "show", "getp", "gets", "setp", "sets" };
    char path[256];
    if (ctl_default_socket(path, sizeof path)) {
        fprintf(stderr, "halcmd: the socket path is too long\n");
        return 1;
    }
    int i = 0;
    bool known = false;
    for (size_t k = 0; argc > 0 && k < sizeof cmds / sizeof *cmds; k++)
        known |= !strcmp(argv[0], cmds[k]);
    if (argc > 1 && !known) {  /* the first word is the socket */
        snprintf(path, sizeof path, "%s", argv[0]);
        i = 1;
    }
    if (i >= argc) {
        fprintf(stderr, "halcmd --attach: give a command: show [PATTERN], getp NAME, "
                "gets NAME, setp NAME VALUE, sets NAME VALUE\n");
        return 2;
    }
    const char *cmd = argv[i++];
    int nargs = argc - i;
    json_t *params = NULL;
    const char *method = NULL;
    if (!strcmp(cmd, "show") && nargs <= 2) {
        /* `show [pin|param|sig|all] [PATTERN]`: the session shows everything matching */
        const char *pat = nargs == 2 ? argv[i + 1] : nargs == 1 && strcmp(argv[i], "pin") &&
                          strcmp(argv[i], "param") && strcmp(argv[i], "sig") &&
                          strcmp(argv[i], "all") ? argv[i] : "";
        method = "hal.show";
        params = json_pack("{s:s}", "pattern", pat);
    } else if ((!strcmp(cmd, "getp") || !strcmp(cmd, "gets")) && nargs == 1) {
        method = "hal.get";
        params = json_pack("{s:s}", "name", argv[i]);
    } else if ((!strcmp(cmd, "setp") || !strcmp(cmd, "sets")) && nargs == 2) {
        method = "hal.set";
        params = json_pack("{s:s, s:s}", "name", argv[i], "value", argv[i + 1]);
    } else {
        fprintf(stderr, "halcmd --attach: '%s' with %d argument%s: on a running machine only "
                "show [PATTERN], getp NAME, gets NAME, setp NAME VALUE and sets NAME VALUE "
                "work\n", cmd, nargs, nargs == 1 ? "" : "s");
        return 2;
    }
    static struct ctl_conn c;
    if (!params || ctl_connect(&c, path) != 0) {
        json_decref(params);
        return 1;
    }
    json_t *resp = ctl_call(&c, method, params, 1, 30000);    /* hal.*: at once */
    json_decref(params);
    close(c.fd);
    json_t *res = json_object_get(resp, "result"), *e = json_object_get(resp, "error");
    int rc = 0;
    if (!resp) {
        fprintf(stderr, "halcmd: %s: no answer from the session\n", path);
        rc = 1;
    } else if (e) {
        fprintf(stderr, "halcmd: %s\n", json_string_value(json_object_get(e, "message")));
        rc = 1;
    } else if (!strcmp(method, "hal.show")) {
        fputs(json_string_value(json_object_get(res, "text")), stdout);
    } else if (!strcmp(method, "hal.get")) {
        printf("%s\n", json_string_value(json_object_get(res, "value")));
    }
    json_decref(resp);
    return rc;
}

int cmd_ctl(int argc, char **argv)
{
    char path[256];
    int i = 1;
    if (ctl_default_socket(path, sizeof path)) {
        fprintf(stderr, "hexcnc ctl: the socket path is too long\n");
        return 1;
    }
    if (i + 1 < argc && !strcmp(argv[i], "--socket")) {
        snprintf(path, sizeof path, "%s", argv[i + 1]);
        i += 2;
    }
    if (i >= argc) {
        fprintf(stderr, "usage: hexcnc %s\n", cmd_ctl_usage);
        return 2;
    }
    const char *method = argv[i++];
    json_t *params = json_object();
    if (ctl_params(argc - i, argv + i, params) != 0) {
        json_decref(params);
        return 2;
    }
    static struct ctl_conn c;
    if (ctl_connect(&c, path) != 0) {
        json_decref(params);
        return 1;
    }
    int rc;
    if (!strcmp(method, "wait"))
        rc = ctl_wait(&c, params);
    else if (!strcmp(method, "watch"))
        rc = ctl_watch(&c, params);
    else {
        json_t *resp = ctl_call(&c, method, params, 1, ctl_timeout_ms(method));
        rc = ctl_print(resp);
        json_decref(resp);
    }
    json_decref(params);
    close(c.fd);
    return rc;
}
