/* web_config.c: the station's settings from the INI, and the program folder's rules. */
#include <arpa/inet.h>
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/errbuf.h"
#include "web/web.h"

#define DEFAULT_HTTP "127.0.0.1:8080"

/* "HOST:PORT" or "[V6]:PORT" into host and port. */
static int parse_listen(struct web_config *c, const char *s, char *err, size_t errlen)
{
    const char *colon = strrchr(s, ':');
    const char *h = s;
    size_t hl = colon ? (size_t)(colon - s) : 0;
    if (colon && s[0] == '[' && hl >= 2 && s[hl - 1] == ']') {
        h = s + 1;
        hl -= 2;
    }
    char *end;
    long port = colon ? strtol(colon + 1, &end, 10) : 0;
    if (!colon || hl == 0 || hl >= sizeof c->host || *end || end == colon + 1 || port < 1 ||
        port > 65535)
        return errbuf_set(err, errlen, -1, "[API] HTTP = %s: write ADDRESS:PORT, e.g. %s (an "
                          "address of this machine and a port 1..65535)", s, DEFAULT_HTTP);
    memcpy(c->host, h, hl);
    c->host[hl] = '\0';
    c->port = (int)port;
    unsigned char a[16];
    if (!strcmp(c->host, "localhost"))
        c->loopback = true;
    else if (inet_pton(AF_INET, c->host, a) == 1)
        c->loopback = a[0] == 127;
    else if (inet_pton(AF_INET6, c->host, a) == 1)
        c->loopback = !memcmp(a, in6addr_loopback.s6_addr, 16);
    else
        return errbuf_set(err, errlen, -1, "[API] HTTP = %s: %s is not a numeric IPv4 or IPv6 "
                          "address (or localhost)", s, c->host);
    return 0;
}

/* The token: the file's first line, at least 16 characters, the file unreadable by others. */
static int read_token(struct web_config *c, const char *path, char *err, size_t errlen)
{
    struct stat st;
    FILE *f = fopen(path, "r");
    if (!f)
        return errbuf_set(err, errlen, -1, "[API] TOKEN_FILE = %s: %s", path, strerror(errno));
    if (fstat(fileno(f), &st) == 0 && (st.st_mode & 077)) {
        fclose(f);
        return errbuf_set(err, errlen, -1, "[API] TOKEN_FILE = %s: others may read it (mode "
                          "%03o): chmod 600 it", path, (unsigned)(st.st_mode & 0777));
    }
    char line[sizeof c->token + 2] = "";
    if (!fgets(line, sizeof line, f))
        line[0] = '\0';
    fclose(f);
    line[strcspn(line, "\r\n")] = '\0';
    size_t n = strlen(line);
    if (n < 16 || n >= sizeof c->token)
        return errbuf_set(err, errlen, -1, "[API] TOKEN_FILE = %s: the token (its first line) "
                          "must be 16 to %zu characters, it has %zu", path,
                          sizeof c->token - 1, n);
    for (size_t i = 0; i < n; i++)
        if (line[i] <= ' ' || line[i] > '~' || strchr("&#%?+", line[i]))
            return errbuf_set(err, errlen, -1, "[API] TOKEN_FILE = %s: the token may hold "
                              "letters, digits and -._~:/= only", path);
    memcpy(c->token, line, n + 1);
    return 0;
}

static void add_origin(struct web_config *c, const char *host, int port)
{
    if (c->norigins < WEB_MAX_ORIGINS)
        snprintf(c->origins[c->norigins++], sizeof c->origins[0],
                 strchr(host, ':') ? "http://[%s]:%d" : "http://%s:%d", host, port);
}

/* The page's own origins (the address it is served from) and [API] ALLOWED_ORIGINS. */
static int read_origins(struct web_config *c, const char *list, char *err, size_t errlen)
{
    if (c->loopback) {
        add_origin(c, "127.0.0.1", c->port);
        add_origin(c, "localhost", c->port);
        add_origin(c, "::1", c->port);
    } else {
        add_origin(c, c->host, c->port);
    }
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", list ? list : "");
    for (char *save, *o = strtok_r(buf, " ,\t", &save); o; o = strtok_r(NULL, " ,\t", &save)) {
        size_t n = strlen(o);
        if ((strncmp(o, "http://", 7) && strncmp(o, "https://", 8)) || o[n - 1] == '/' ||
            n >= sizeof c->origins[0])
            return errbuf_set(err, errlen, -1, "[API] ALLOWED_ORIGINS: %s is not an origin "
                              "(scheme://host[:port], no path, e.g. http://panel.local:8080)", o);
        if (c->norigins == WEB_MAX_ORIGINS)
            return errbuf_set(err, errlen, -1, "[API] ALLOWED_ORIGINS: at most %d origins",
                              WEB_MAX_ORIGINS - 3);
        snprintf(c->origins[c->norigins++], sizeof c->origins[0], "%s", o);
    }
    return 0;
}

/* A path from the INI, relative to the INI's folder; an over-long one is an error naming it. */
static int ini_path(const struct inifile *ini, const char *key, const char *v, char *out,
                    size_t len, char *err, size_t errlen)
{
    if (inifile_resolve(inifile_dir(ini), v, out, len))
        return errbuf_set(err, errlen, -1, "%s = %s: the path is longer than %zu characters",
                          key, v, len - 1);
    return 0;
}

/* The built page: [API] UI_DIR, else share/hexcnc/ui beside the program's bin/. */
static int find_ui(struct web_config *c, const char *v, char *err, size_t errlen)
{
    if (v) {
        if (ini_path(c->ini, "[API] UI_DIR", v, c->ui_dir, sizeof c->ui_dir, err, errlen))
            return -1;
    } else {
        char exe[PATH_MAX - 64];
        ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
        if (n <= 0)
            return errbuf_set(err, errlen, -1, "cannot find the program's folder: set [API] "
                              "UI_DIR");
        exe[n] = '\0';
        char *slash = strrchr(exe, '/');
        *slash = '\0';
        snprintf(c->ui_dir, sizeof c->ui_dir, "%s/../share/hexcnc/ui", exe);
    }
    char idx[PATH_MAX + 16];
    snprintf(idx, sizeof idx, "%s/index.html", c->ui_dir);
    if (access(idx, R_OK) != 0)
        return errbuf_set(err, errlen, -1, "%s: %s: the page is not built (`make` builds it; "
                          "[API] UI_DIR names another folder)", idx, strerror(errno));
    char real[PATH_MAX];
    if (realpath(c->ui_dir, real))
        memcpy(c->ui_dir, real, strlen(real) + 1);
    return 0;
}

int web_config_read(struct web_config *c, const struct inifile *ini, const char *listen,
                    const char *sock, char *err, size_t errlen)
{
    memset(c, 0, sizeof *c);
    c->ini = ini;
    const char *v = listen ? listen : inifile_get(ini, "API", "HTTP");
    if (parse_listen(c, v ? v : DEFAULT_HTTP, err, errlen))
        return -1;
    const char *tok = inifile_get(ini, "API", "TOKEN_FILE");
    if (tok) {
        char p[PATH_MAX];
        if (ini_path(ini, "[API] TOKEN_FILE", tok, p, sizeof p, err, errlen) ||
            read_token(c, p, err, errlen))
            return -1;
    } else if (!c->loopback) {
        return errbuf_set(err, errlen, -1, "[API] HTTP = %s:%d is reachable from other "
                          "machines: set [API] TOKEN_FILE (a file holding a secret of 16 or "
                          "more characters, mode 600) so that only those who know it can "
                          "command the machine", c->host, c->port);
    }
    if (read_origins(c, inifile_get(ini, "API", "ALLOWED_ORIGINS"), err, errlen) ||
        find_ui(c, inifile_get(ini, "API", "UI_DIR"), err, errlen))
        return -1;
    const char *pre = inifile_get(ini, "DISPLAY", "PROGRAM_PREFIX");
    if (ini_path(ini, "[DISPLAY] PROGRAM_PREFIX", pre ? pre : ".", c->prefix, sizeof c->prefix,
                 err, errlen))
        return -1;
    char real[PATH_MAX];
    if (!realpath(c->prefix, real))
        return errbuf_set(err, errlen, -1, "[DISPLAY] PROGRAM_PREFIX = %s: %s", c->prefix,
                          strerror(errno));
    memcpy(c->prefix, real, strlen(real) + 1);
    if (inifile_api_socket(sock ? sock : inifile_get(ini, "API", "SOCKET"), inifile_dir(ini),
                           c->socket, sizeof c->socket) < 0)
        return errbuf_set(err, errlen, -1, "the session's socket path is longer than %zu "
                          "characters: set a shorter [API] SOCKET or --socket",
                          sizeof c->socket - 1);
    return 0;
}

int web_program_path(const struct web_config *c, const char *path, char *out, size_t len,
                     char *err, size_t errlen)
{
    if (!path[0] || path[0] == '/' || strstr(path, "..") || strchr(path, '\\'))
        return errbuf_set(err, errlen, -1, "%s: the station opens programs from the program "
                          "folder (%s) only: give a path inside it, without '..'", path,
                          c->prefix);
    char joined[PATH_MAX + 8], real[PATH_MAX];
    snprintf(joined, sizeof joined, "%s/%s", c->prefix, path);
    if (!realpath(joined, real))
        return errbuf_set(err, errlen, -1, "%s: %s", path, strerror(errno));
    size_t n = strlen(c->prefix);
    if (strncmp(real, c->prefix, n) || real[n] != '/')   /* a link out of the folder */
        return errbuf_set(err, errlen, -1, "%s: leads out of the program folder (%s)", path,
                          c->prefix);
    snprintf(out, len, "%s", real);
    return 0;
}
