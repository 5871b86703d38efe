/* web_server.c: the HTTP server (civetweb: static files from the UI folder only) and the
 * WebSocket bridge. Each browser's WebSocket gets its own connection to the session's
 * socket, so the session sees each browser as a client of its own (control, subscriptions).
 * Browser -> session: every message is parsed and checked against the method list, a
 * program path is resolved inside the program folder, then it is sent on as one line.
 * Session -> browser: a thread per browser sends each line as one text message. */
#include <errno.h>
#include <poll.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include <civetweb.h>

#include "common/errbuf.h"
#include "web/web.h"

#define RPC_PARSE -32700
#define RPC_INVALID -32600
#define RPC_NO_METHOD -32601
#define RPC_NOT_FOUND -32004

struct client {
    struct mg_connection *conn;
    const struct web_config *cfg;
    int fd;                       /* the session connection */
    pthread_t reader;
    bool reader_live;
    char *msg;                    /* a message arriving in fragments */
    size_t msg_len;
    pthread_mutex_t lock;         /* control tracking */
    json_t *acquire_id, *release_id; /* ids of pending control requests */
    bool has_control;
};

struct server {
    const struct web_config *cfg;
    bool quiet;
};

static void ws_send(struct client *cl, const char *s, size_t n)
{
    mg_lock_connection(cl->conn);
    mg_websocket_write(cl->conn, MG_WEBSOCKET_OPCODE_TEXT, s, n);
    mg_unlock_connection(cl->conn);
}

static void ws_send_json(struct client *cl, json_t *j)
{
    char *s = json_dumps(j, JSON_COMPACT);
    if (s)
        ws_send(cl, s, strlen(s));
    free(s);
    json_decref(j);
}

static void ws_error(struct client *cl, json_t *id, int code, const char *msg)
{
    ws_send_json(cl, json_pack("{s:s, s:O, s:{s:i, s:s}}", "jsonrpc", "2.0", "id",
                               id ? id : json_null(), "error", "code", code, "message", msg));
}

/* Does this answer end a control request of this client's? */
static void track_control(struct client *cl, const char *line, size_t n)
{
    pthread_mutex_lock(&cl->lock);
    if (cl->acquire_id || cl->release_id) {
        json_t *j = json_loadb(line, n, 0, NULL);
        json_t *id = j ? json_object_get(j, "id") : NULL;
        if (id && !json_object_get(j, "method")) {
            bool ok = json_object_get(j, "result") != NULL;
            if (cl->acquire_id && json_equal(id, cl->acquire_id)) {
                cl->has_control = ok || cl->has_control;
                json_decref(cl->acquire_id);
                cl->acquire_id = NULL;
            } else if (cl->release_id && json_equal(id, cl->release_id)) {
                if (ok)
                    cl->has_control = false;
                json_decref(cl->release_id);
                cl->release_id = NULL;
            }
        }
        json_decref(j);
    }
    pthread_mutex_unlock(&cl->lock);
}

/* Is this line a status notification? (They are the only ones that start so.) */
static bool is_status(const char *line, size_t n)
{
    static const char pre[] = "{\"jsonrpc\":\"2.0\",\"method\":\"status\"";
    return n > sizeof pre && !memcmp(line, pre, sizeof pre - 1);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* Session -> browser, line by line, until the session closes or the browser leaves. Status
 * notifications come at the subscribed rate of machine time, which on the simulated clock
 * runs many times faster than the wall: they reach the browser at most every
 * WEB_STATUS_PERIOD_S of wall time, the latest one each time, so a browser never falls behind
 * the machine and the session never sees this client stop reading. Everything else passes at
 * once, after the status it followed. */
#define WEB_STATUS_PERIOD_S 0.04
static void *reader(void *arg)
{
    struct client *cl = arg;
    size_t cap = 1 << 16, len = 0;
    char *buf = malloc(cap), *held = NULL;   /* held: the latest status not yet sent */
    size_t held_len = 0, held_cap = 0;
    double last_status = 0;
    while (buf) {
        char *nl, *s = buf;
        while ((nl = memchr(s, '\n', len - (size_t)(s - buf)))) {
            size_t n = (size_t)(nl - s);
            if (is_status(s, n)) {
                if (n > held_cap) {
                    char *h = realloc(held, n);
                    if (!h)
                        goto out;
                    held = h;
                    held_cap = n;
                }
                memcpy(held, s, n);
                held_len = n;
            } else {
                if (held_len) {
                    ws_send(cl, held, held_len);
                    held_len = 0;
                    last_status = now_s();
                }
                track_control(cl, s, n);
                ws_send(cl, s, n);
            }
            s = nl + 1;
        }
        len -= (size_t)(s - buf);
        memmove(buf, s, len);
        double t = now_s();
        if (held_len && t - last_status >= WEB_STATUS_PERIOD_S) {
            ws_send(cl, held, held_len);
            held_len = 0;
            last_status = t;
        }
        if (len == cap) {
            char *b = cap < (64u << 20) ? realloc(buf, cap * 2) : NULL;
            if (!b)
                break;
            buf = b;
            cap *= 2;
        }
        struct pollfd pf = { cl->fd, POLLIN, 0 };
        int wait_ms = held_len ? (int)((WEB_STATUS_PERIOD_S - (t - last_status)) * 1000) + 1 : -1;
        int pr = poll(&pf, 1, wait_ms);
        if (pr < 0 && errno == EINTR)
            continue;
        if (pr == 0)
            continue;   /* time to send the held status */
        ssize_t r = read(cl->fd, buf + len, cap - len);
        if (r < 0 && errno == EINTR)
            continue;
        if (r <= 0)
            break;
        len += (size_t)r;
    }
out:
    free(buf);
    free(held);
    /* the session went away (or the browser did, and the close handler shut the socket) */
    ws_send_json(cl, json_pack("{s:s, s:s, s:{s:s}}", "jsonrpc", "2.0", "method",
                               "station.disconnected", "params", "reason",
                               "the machine session closed the connection"));
    mg_lock_connection(cl->conn);
    mg_websocket_write(cl->conn, MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE, "", 0);
    mg_unlock_connection(cl->conn);
    return NULL;
}

static bool token_equal(const char *a, const char *b)
{
    size_t na = strlen(a), nb = strlen(b);
    unsigned char d = na != nb;
    for (size_t i = 0; i < na && i < nb; i++)
        d |= (unsigned char)(a[i] ^ b[i]);
    return d == 0;
}

/* The WebSocket handshake: the origin must be allowed, and the token right when there is one. */
static int ws_connect(const struct mg_connection *conn, void *cbdata)
{
    struct server *sv = cbdata;
    const struct web_config *c = sv->cfg;
    const char *origin = mg_get_header(conn, "Origin");
    if (origin) {
        bool ok = false;
        for (int i = 0; i < c->norigins && !ok; i++)
            ok = !strcmp(origin, c->origins[i]);
        /* behind a token (any address but loopback), the page's own origin is whatever
         * name the operator reached it by: the Host it asked for. On loopback, where there
         * is no token, only the fixed names count (a rebound DNS name must not). */
        const char *host = mg_get_header(conn, "Host");
        if (!ok && c->token[0] && host && !strncmp(origin, "http", 4)) {
            const char *o = origin + (strncmp(origin, "https://", 8) ? 7 : 8);
            ok = !strcmp(o, host);
        }
        if (!ok) {
            if (!sv->quiet)
                fprintf(stderr, "hexcnc web: refused a WebSocket from origin %s (not in "
                        "[API] ALLOWED_ORIGINS)\n", origin);
            return 1;
        }
    }
    if (c->token[0]) {
        const struct mg_request_info *ri = mg_get_request_info(conn);
        char tok[256] = "";
        const char *q = ri->query_string;
        if (!q || mg_get_var(q, strlen(q), "token", tok, sizeof tok) <= 0 ||
            !token_equal(tok, c->token)) {
            if (!sv->quiet)
                fprintf(stderr, "hexcnc web: refused a WebSocket from %s: %s token\n",
                        ri->remote_addr, tok[0] ? "a wrong" : "no");
            return 1;
        }
    }
    return 0;
}

static int session_connect(const char *path)
{
    struct sockaddr_un a = { .sun_family = AF_UNIX };
    if (strlen(path) >= sizeof a.sun_path)
        return -1;
    memcpy(a.sun_path, path, strlen(path) + 1);
    int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd >= 0 && connect(fd, (struct sockaddr *)&a, sizeof a) != 0) {
        int e = errno;
        close(fd);
        errno = e;
        fd = -1;
    }
    return fd;
}

static void ws_ready(struct mg_connection *conn, void *cbdata)
{
    struct server *sv = cbdata;
    struct client *cl = calloc(1, sizeof *cl);
    if (!cl)
        return;
    cl->conn = conn;
    cl->cfg = sv->cfg;
    pthread_mutex_init(&cl->lock, NULL);
    mg_set_user_connection_data(conn, cl);
    cl->fd = session_connect(sv->cfg->socket);
    if (cl->fd < 0) {
        char msg[400];
        snprintf(msg, sizeof msg, "no machine session answers on %s (%s): start it with "
                 "scripts/hexcnc-start or hexcnc machine", sv->cfg->socket, strerror(errno));
        ws_send_json(cl, json_pack("{s:s, s:s, s:{s:s}}", "jsonrpc", "2.0", "method",
                                   "station.disconnected", "params", "reason", msg));
        mg_lock_connection(conn);
        mg_websocket_write(conn, MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE, "", 0);
        mg_unlock_connection(conn);
        return;
    }
    cl->reader_live = pthread_create(&cl->reader, NULL, reader, cl) == 0;
}

static bool write_all(int fd, const char *s, size_t n)
{
    while (n) {
        ssize_t w = write(fd, s, n);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0)
            return false;
        s += w;
        n -= (size_t)w;
    }
    return true;
}

/* One whole message from the browser. */
static void handle(struct client *cl, const char *data, size_t len)
{
    json_error_t je;
    json_t *req = json_loadb(data, len, 0, &je);
    if (!req) {
        ws_error(cl, NULL, RPC_PARSE, "the message is not JSON");
        return;
    }
    json_t *id = json_object_get(req, "id");
    const char *method = json_string_value(json_object_get(req, "method"));
    json_t *params = json_object_get(req, "params");
    char err[1200];
    if (!json_is_object(req) || !method || (params && !json_is_object(params))) {
        ws_error(cl, id, RPC_INVALID, "not a JSON-RPC 2.0 request object (method, params as "
                 "an object)");
    } else if (web_method_local(method)) {
        int code = 0;
        pthread_mutex_lock(&cl->lock);
        bool ctl = cl->has_control;
        pthread_mutex_unlock(&cl->lock);
        json_t *res = web_local_call(cl->cfg, method, params, ctl, &code, err, sizeof err);
        if (!res)
            ws_error(cl, id, code, err);
        else if (id)
            ws_send_json(cl, json_pack("{s:s, s:O, s:o}", "jsonrpc", "2.0", "id", id,
                                       "result", res));
        else
            json_decref(res);
    } else if (!web_method_forwarded(method)) {
        snprintf(err, sizeof err, "%s: no such method at the operator's station", method);
        ws_error(cl, id, RPC_NO_METHOD, err);
    } else {
        bool ok = true;
        if (!strcmp(method, "program.open")) {
            const char *p = json_string_value(json_object_get(params, "path"));
            char abs[4096];
            if (!p) {
                ok = false;
                ws_error(cl, id, -32602, "program.open needs path");
            } else if (web_program_path(cl->cfg, p, abs, sizeof abs, err, sizeof err)) {
                ok = false;
                ws_error(cl, id, RPC_NOT_FOUND, err);
            } else {
                json_object_set_new(params, "path", json_string(abs));
            }
        }
        if (ok && id) {
            pthread_mutex_lock(&cl->lock);
            json_t **slot = !strcmp(method, "control.acquire") ? &cl->acquire_id
                            : !strcmp(method, "control.release") ? &cl->release_id : NULL;
            if (slot) {
                json_decref(*slot);
                *slot = json_incref(id);
            }
            pthread_mutex_unlock(&cl->lock);
        }
        char *line = ok ? json_dumps(req, JSON_COMPACT) : NULL;
        if (line) {
            size_t n = strlen(line);
            line[n] = '\n';
            if (!write_all(cl->fd, line, n + 1))
                ws_error(cl, id, -32005, "the machine session is gone");
        }
        free(line);
    }
    json_decref(req);
}

static int ws_data(struct mg_connection *conn, int flags, char *data, size_t len, void *cbdata)
{
    struct client *cl = mg_get_user_connection_data(conn);
    int op = flags & 0x0f;
    if (op == MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE)
        return 0;
    if (!cl || cl->fd < 0)
        return 0;
    if (op != MG_WEBSOCKET_OPCODE_TEXT && op != MG_WEBSOCKET_OPCODE_CONTINUATION)
        return 1;   /* pings are answered by civetweb; binary is ignored */
    if (cl->msg_len + len > WEB_MAX_MESSAGE) {
        ws_error(cl, NULL, RPC_INVALID, "a message is larger than 32 MiB");
        return 0;
    }
    bool fin = flags & 0x80;
    if (fin && !cl->msg_len) {
        handle(cl, data, len);
        return 1;
    }
    char *m = realloc(cl->msg, cl->msg_len + len + 1);
    if (!m)
        return 0;
    cl->msg = m;
    memcpy(m + cl->msg_len, data, len);
    cl->msg_len += len;
    if (fin) {
        handle(cl, cl->msg, cl->msg_len);
        cl->msg_len = 0;
    }
    return 1;
}

static void ws_close(const struct mg_connection *conn, void *cbdata)
{
    struct client *cl = mg_get_user_connection_data(conn);
    if (!cl)
        return;
    if (cl->fd >= 0)
        shutdown(cl->fd, SHUT_RDWR);
    if (cl->reader_live)
        pthread_join(cl->reader, NULL);
    if (cl->fd >= 0)
        close(cl->fd);
    json_decref(cl->acquire_id);
    json_decref(cl->release_id);
    pthread_mutex_destroy(&cl->lock);
    free(cl->msg);
    free(cl);
}

static int log_message(const struct mg_connection *conn, const char *message)
{
    fprintf(stderr, "hexcnc web: %s\n", message);
    return 1;
}

int web_serve(const struct web_config *c, const volatile sig_atomic_t *stop, bool quiet,
              char *err, size_t errlen)
{
    char ports[300];
    snprintf(ports, sizeof ports, strchr(c->host, ':') ? "[%s]:%d" : "%s:%d",
             strcmp(c->host, "localhost") ? c->host : "127.0.0.1", c->port);
    const char *opts[] = {
        "listening_ports", ports,
        "document_root", c->ui_dir,
        "enable_directory_listing", "no",
        "num_threads", "16",
        "websocket_timeout_ms", "3600000",
        "enable_websocket_ping_pong", "yes",
        NULL,
    };
    struct server sv = { c, quiet };
    struct mg_callbacks cb = { .log_message = log_message };
    mg_init_library(0);
    struct mg_context *ctx = mg_start(&cb, &sv, opts);
    if (!ctx) {
        mg_exit_library();
        return errbuf_set(err, errlen, -1, "cannot listen on %s (is the port taken? [API] "
                          "HTTP names another)", ports);
    }
    mg_set_websocket_handler(ctx, "/ws", ws_connect, ws_ready, ws_data, ws_close, &sv);
    if (!quiet)
        fprintf(stderr, "hexcnc web: the operator's station is at http://%s/ (the machine "
                "session at %s, programs from %s)\n", ports, c->socket, c->prefix);
    while (!*stop) {
        struct timespec ts = { 0, 50 * 1000 * 1000 };
        nanosleep(&ts, NULL);
    }
    mg_stop(ctx);
    mg_exit_library();
    return 0;
}
