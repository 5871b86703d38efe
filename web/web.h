/* web.h: `hexcnc web`, the operator's station: an HTTP and WebSocket server (civetweb) that
 * serves the page from the UI folder and bridges each browser's WebSocket, message for
 * message, to its own connection on the machine session's Unix socket (docs/ui.md).
 * The controller never parses HTTP; this process holds no machine state of its own. */
#ifndef HEXCNC_WEB_H
#define HEXCNC_WEB_H

#include <signal.h>
#include <stdbool.h>
#include <limits.h>
#include <stddef.h>

#include <jansson.h>

#include "common/inifile.h"

#define WEB_MAX_ORIGINS 16
#define WEB_MAX_MESSAGE (32u << 20)   /* largest message from a browser (an upload), bytes */

/* Everything the server needs, read once from the INI (web_config_read). */
struct web_config {
    const struct inifile *ini;
    char host[256];               /* the address to listen on, as written ("127.0.0.1") */
    int port;
    bool loopback;                /* host is a loopback address: no token needed */
    char token[256];              /* the secret from [API] TOKEN_FILE; "" = none */
    char origins[WEB_MAX_ORIGINS][256]; /* origins allowed to open the WebSocket */
    int norigins;
    char ui_dir[PATH_MAX];            /* the built page (index.html, app.js) */
    char prefix[PATH_MAX];            /* programs are opened from and uploaded to this folder */
    char socket[108];             /* the machine session's socket */
};

/* Reads [API] HTTP, TOKEN_FILE, ALLOWED_ORIGINS, UI_DIR, SOCKET and [DISPLAY] PROGRAM_PREFIX.
 * listen (NULL: the INI's) and sock (NULL: the INI's) override. Returns 0, or -1 with the
 * reason in err: a non-loopback address without a token, a token file others can read, a
 * UI folder without index.html. */
int web_config_read(struct web_config *c, const struct inifile *ini, const char *listen,
                    const char *sock, char *err, size_t errlen);

/* Serves until *stop is set. Returns 0, or -1 with the reason in err (the port is taken). */
int web_serve(const struct web_config *c, const volatile sig_atomic_t *stop, bool quiet,
              char *err, size_t errlen);

/* Methods a browser may call: the session's (forwarded) and the station's own (answered
 * here). machine.shutdown is not among them: the session is ended where it runs. */
bool web_method_forwarded(const char *method);
bool web_method_local(const char *method);

/* A program path from a browser, resolved in the program folder: a relative path (no
 * "..", nothing outside) becomes absolute in out. Returns 0, or -1 with the reason in err. */
int web_program_path(const struct web_config *c, const char *path, char *out, size_t len,
                     char *err, size_t errlen);

/* Answers one of the station's own methods: the result object, or NULL with *code and the
 * message in err (JSON-RPC error). has_control: the browser holds the session's control. */
json_t *web_local_call(const struct web_config *c, const char *method, json_t *params,
                       bool has_control, int *code, char *err, size_t errlen);

/* The open program's path for the 3-D view (web_preview.c): the interpreter's moves from
 * start (machine pose), as points with their kind and line. */
json_t *web_preview(const struct web_config *c, const char *path, const double start[6],
                    size_t max_points, int *code, char *err, size_t errlen);

#endif
