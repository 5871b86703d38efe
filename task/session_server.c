/* session_server.c: the session's Unix socket: clients, line framing, bounded buffers. */
#include "task/session_priv.h"

#include <errno.h>
#include <fcntl.h>
#include <grp.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

/*
 * Non-blocking sockets served from the session loop: a client that sends garbage gets an
 * error, one that sends a line longer than SESSION_MAX_LINE is answered and dropped, one
 * that does not read its answers is dropped once SESSION_MAX_OUT bytes wait for it. No
 * call here blocks, so no client can stall the session (and the servo thread never sees a
 * client at all).
 */

#define SESSION_MAX_LINE (1u << 20)
#define SESSION_MAX_OUT (4u << 20)
/* Requests answered per client per loop turn: a flood cannot starve the machine. */
#define SESSION_MAX_REQUESTS 64

static int set_nonblock(int fd)
{
    int fl = fcntl(fd, F_GETFL);
    return fl < 0 ? -1 : fcntl(fd, F_SETFL, fl | O_NONBLOCK);
}

/* Whether a session answers on path (then a second one must not take it over). */
static bool socket_alive(const char *path)
{
    int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    struct sockaddr_un a = { .sun_family = AF_UNIX };
    snprintf(a.sun_path, sizeof a.sun_path, "%s", path);
    bool alive = fd >= 0 && connect(fd, (struct sockaddr *)&a, sizeof a) == 0;
    if (fd >= 0)
        close(fd);
    return alive;
}

int session_server_open(struct session *s, const char *path, char *err, size_t len)
{
    struct sockaddr_un a = { .sun_family = AF_UNIX };
    if (strlen(path) >= sizeof a.sun_path) {
        snprintf(err, len, "%s: a socket path may have at most %zu characters", path,
                 sizeof a.sun_path - 1);
        return 1;
    }
    struct stat st;
    if (lstat(path, &st) == 0) {
        if (!S_ISSOCK(st.st_mode)) {
            snprintf(err, len, "%s: exists and is not a socket; not replacing it", path);
            return 1;
        }
        if (socket_alive(path)) {
            snprintf(err, len, "%s: another machine session is running on this socket", path);
            return 1;
        }
        unlink(path);  /* stale: its session has gone */
    }
    snprintf(a.sun_path, sizeof a.sun_path, "%s", path);
    int fd = socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
    mode_t old = umask(0177);  /* 0600 from the start: no window with a wider mode */
    int rc = fd < 0 ? -1 : bind(fd, (struct sockaddr *)&a, sizeof a);
    umask(old);
    if (rc != 0 || listen(fd, SESSION_MAX_CLIENTS) != 0 || set_nonblock(fd) != 0) {
        snprintf(err, len, "%s: %s", path, strerror(errno));
        if (fd >= 0)
            close(fd);
        return 1;
    }
    snprintf(s->sock_path, sizeof s->sock_path, "%s", path);
    s->lfd = fd;
    const char *group = hal_ini_get(s->hal, "API", "GROUP");
    if (group && group[0]) {
        struct group *g = getgrnam(group);
        if (!g || chown(path, (uid_t)-1, g->gr_gid) != 0 || chmod(path, 0660) != 0) {
            snprintf(err, len, "[API] GROUP = %s: %s", group, g ? strerror(errno)
                     : "no such group");
            session_server_close(s);
            return 1;
        }
    }
    return 0;
}

static void drop_client(struct session *s, int i)
{
    struct session_client *c = s->cl[i];
    if (s->holder == c->id) {
        s->holder = 0;
        session_message(s, "info", "api", "client %u disconnected: control released", c->id);
    }
    if (s->jogger == c->id) {  /* a hold-to-jog whose button can no longer be released */
        char err[200];
        s->jogger = 0;
        if (session_jog_stop(s, err, sizeof err) == 0 && s->state == SESS_ON)
            session_message(s, "warning", "api", "client %u disconnected during a continuous "
                            "jog: the jog is stopped", c->id);
    }
    close(c->fd);
    free(c->in);
    free(c->out);
    free(c);
    s->cl[i] = NULL;
}

void session_server_close(struct session *s)
{
    for (int i = 0; i < SESSION_MAX_CLIENTS; i++)
        if (s->cl[i])
            drop_client(s, i);
    if (s->lfd >= 0) {
        close(s->lfd);
        unlink(s->sock_path);
        s->lfd = -1;
    }
}

/* Appends bytes to a client's output; false when its backlog would pass the bound. */
static bool out_append(struct session_client *c, const char *p, size_t n)
{
    if (c->outlen + n > SESSION_MAX_OUT)
        return false;
    if (c->outlen + n > c->outcap) {
        size_t cap = c->outcap ? c->outcap : 4096;
        while (cap < c->outlen + n)
            cap *= 2;
        char *q = realloc(c->out, cap);
        if (!q)
            return false;
        c->out = q;
        c->outcap = cap;
    }
    memcpy(c->out + c->outlen, p, n);
    c->outlen += n;
    return true;
}

void session_server_send(struct session *s, struct session_client *c, json_t *msg)
{
    char *text = json_dumps(msg, JSON_COMPACT);
    if (!text)
        return;
    if (!c->closing && (!out_append(c, text, strlen(text)) || !out_append(c, "\n", 1))) {
        c->closing = true;  /* it does not read: drop it rather than grow */
        c->outlen = 0;
    }
    free(text);
}

void session_server_broadcast_message(struct session *s, json_t *msg)
{
    for (int i = 0; i < SESSION_MAX_CLIENTS; i++)
        if (s->cl[i] && s->cl[i]->messages)
            session_server_send(s, s->cl[i], msg);
}

void session_server_status(struct session *s)
{
    int64_t now = hal_now_ns(s->hal);
    json_t *st = NULL;
    for (int i = 0; i < SESSION_MAX_CLIENTS; i++) {
        struct session_client *c = s->cl[i];
        if (!c || c->status_rate_hz <= 0 || now < c->next_status_ns)
            continue;
        if (!st)
            st = json_pack("{s:s, s:s, s:o}", "jsonrpc", "2.0", "method", "status", "params",
                           session_status(s));
        session_server_send(s, c, st);
        int64_t step = (int64_t)(1e9 / c->status_rate_hz);
        c->next_status_ns = now - now % step + step;
    }
    json_decref(st);
}

static void accept_clients(struct session *s)
{
    for (;;) {
        int fd = accept4(s->lfd, NULL, NULL, SOCK_NONBLOCK | SOCK_CLOEXEC);
        if (fd < 0)
            return;
        int slot = -1;
        for (int i = 0; i < SESSION_MAX_CLIENTS && slot < 0; i++)
            if (!s->cl[i])
                slot = i;
        struct session_client *c = slot < 0 ? NULL : calloc(1, sizeof *c);
        if (!c) {
            static const char full[] = "{\"jsonrpc\":\"2.0\",\"id\":null,\"error\":{\"code\":"
                                       "-32005,\"message\":\"too many clients: the session "
                                       "serves at most 32 at once\"}}\n";
            ssize_t w = write(fd, full, sizeof full - 1);
            (void)w;
            close(fd);
            continue;
        }
        c->fd = fd;
        c->id = ++s->next_id;
        s->cl[slot] = c;
    }
}

/* A line longer than SESSION_MAX_LINE: answered with an error, then the client is dropped. */
static void refuse_long_line(struct session *s, struct session_client *c)
{
    json_t *e = json_pack("{s:s, s:n, s:{s:i, s:s}}", "jsonrpc", "2.0", "id", "error", "code",
                          RPC_INVALID, "message", "request longer than 1 MiB: connection closed");
    session_server_send(s, c, e);
    json_decref(e);
    c->closing = true;
}

/* Reads what the client sent and answers each whole line (at most SESSION_MAX_REQUESTS). */
static void read_client(struct session *s, struct session_client *c)
{
    char buf[65536];
    for (;;) {
        ssize_t n = read(c->fd, buf, sizeof buf);
        if (n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
            c->closing = true;
            c->outlen = 0;
            return;
        }
        if (n < 0)
            break;
        if (c->inlen + (size_t)n > c->incap) {
            size_t cap = c->incap ? c->incap : 4096;
            while (cap < c->inlen + (size_t)n)
                cap *= 2;
            if (cap > 2 * SESSION_MAX_LINE)
                cap = 2 * SESSION_MAX_LINE;
            if (c->inlen + (size_t)n > cap) {
                json_t *e = json_pack("{s:s, s:n, s:{s:i, s:s}}", "jsonrpc", "2.0", "id",
                                      "error", "code", RPC_INVALID, "message",
                                      "request longer than 1 MiB: connection closed");
                session_server_send(s, c, e);
                json_decref(e);
                c->closing = true;
                return;
            }
            char *q = realloc(c->in, cap);
            if (!q) {
                c->closing = true;
                return;
            }
            c->in = q;
            c->incap = cap;
        }
        memcpy(c->in + c->inlen, buf, (size_t)n);
        c->inlen += (size_t)n;
        if (c->inlen > SESSION_MAX_LINE && !memchr(c->in, '\n', c->inlen))
            break;
        if ((size_t)n < sizeof buf)
            break;
    }
    size_t start = 0;
    int answered = 0;
    char *nl;
    while (answered < SESSION_MAX_REQUESTS && !c->closing &&
           (nl = memchr(c->in + start, '\n', c->inlen - start))) {
        size_t len = (size_t)(nl - (c->in + start));
        if (len > SESSION_MAX_LINE) {
            refuse_long_line(s, c);
            break;
        }
        if (len > 0) {
            json_t *resp = session_dispatch(s, c, c->in + start, len);
            if (resp) {
                session_server_send(s, c, resp);
                json_decref(resp);
            }
        }
        start += len + 1;
        answered++;
    }
    if (!c->closing && c->inlen - start > SESSION_MAX_LINE) {
        refuse_long_line(s, c);
    }
    memmove(c->in, c->in + start, c->inlen - start);
    c->inlen -= start;
}

static void write_client(struct session_client *c)
{
    while (c->outlen > 0) {
        ssize_t n = send(c->fd, c->out, c->outlen, MSG_NOSIGNAL | MSG_DONTWAIT);
        if (n <= 0) {
            if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK))
                return;
            c->outlen = 0;
            c->closing = true;
            return;
        }
        memmove(c->out, c->out + n, c->outlen - (size_t)n);
        c->outlen -= (size_t)n;
    }
}

void session_server_poll(struct session *s, int timeout_ms)
{
    struct pollfd pf[SESSION_MAX_CLIENTS + 1];
    int map[SESSION_MAX_CLIENTS + 1];
    int n = 0;
    pf[n] = (struct pollfd){ .fd = s->lfd, .events = POLLIN };
    map[n++] = -1;
    for (int i = 0; i < SESSION_MAX_CLIENTS; i++) {
        struct session_client *c = s->cl[i];
        if (!c)
            continue;
        pf[n] = (struct pollfd){ .fd = c->fd, .events = (short)((c->closing ? 0 : POLLIN) |
                                                                 (c->outlen ? POLLOUT : 0)) };
        map[n++] = i;
    }
    if (poll(pf, (nfds_t)n, timeout_ms) < 0)
        return;
    for (int k = 0; k < n; k++) {
        if (map[k] < 0) {
            if (pf[k].revents & POLLIN)
                accept_clients(s);
            continue;
        }
        struct session_client *c = s->cl[map[k]];
        if (!c)
            continue;
        if (pf[k].revents & (POLLIN | POLLHUP | POLLERR))
            read_client(s, c);
        if (c->outlen)
            write_client(c);
        if (c->closing && c->outlen == 0)
            drop_client(s, map[k]);
    }
    /* clients whose lines wait beyond the per-turn bound, and subscribers' backlogs */
    for (int i = 0; i < SESSION_MAX_CLIENTS; i++) {
        struct session_client *c = s->cl[i];
        if (!c)
            continue;
        if (!c->closing && c->inlen && memchr(c->in, '\n', c->inlen))
            read_client(s, c);
        if (c->outlen)
            write_client(c);
        if (c->closing && c->outlen == 0)
            drop_client(s, i);
    }
}
