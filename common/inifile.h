/* inifile.h: a machine's INI file (LinuxCNC conventions, read by libinih), every entry kept
 * in file order with its line number so that messages can point at the line. */
#ifndef HEXCNC_INIFILE_H
#define HEXCNC_INIFILE_H

#include <stddef.h>

/* What went wrong while loading. 0 = OK; the message is in the caller's err buffer. */
enum inifile_status {
    INIFILE_OK = 0,
    INIFILE_ERR_IO,          /* the file cannot be opened or read */
    INIFILE_ERR_NOMEM,       /* out of memory */
    INIFILE_ERR_SYNTAX,      /* a line that is not a header, KEY = VALUE or comment, or too long */
    INIFILE_STATUS_COUNT
};
const char *inifile_strerror(int status);

/* One KEY = VALUE of the file. A repeated key is kept as often as it appears. */
struct inifile_entry {
    char *section;           /* without the brackets */
    char *key;
    char *value;             /* as libinih gives it: blanks and `;` comments stripped */
    int line;                /* 1-based line the value came from */
};

/* The whole file in memory. A zeroed struct is an empty file (nothing loaded). */
struct inifile {
    struct inifile_entry *items;   /* entries in file order */
    size_t n, cap;                 /* used and allocated entries */
    char *path;                    /* the path as given, NULL before a load */
    char *dir;                     /* its folder ("." for a bare name), for relative paths */
};

/* Reads path, replacing what ini held. On failure ini is left empty and err gets a message
 * naming the file and, for a bad line, its number ("path:line: ..."). */
int inifile_load(struct inifile *ini, const char *path, char *err, size_t errlen);
/* Frees every entry; ini is empty (and reusable) afterwards. */
void inifile_free(struct inifile *ini);

/* The first [section]key (names are exact, as in LinuxCNC), or NULL. */
const char *inifile_get(const struct inifile *ini, const char *section, const char *key);
/* The n-th (0-based) occurrence of [section]key, or NULL. */
const char *inifile_get_n(const struct inifile *ini, const char *section, const char *key,
                          int n);
/* The line of the first [section]key, 0 when it is absent. */
int inifile_line(const struct inifile *ini, const char *section, const char *key);
/* The path loaded and its folder, NULL before a load. */
const char *inifile_path(const struct inifile *ini);
const char *inifile_dir(const struct inifile *ini);
/* A path as an INI writes it: value itself when absolute or dir is NULL or "", else
 * dir/value. Returns 0, or -1 when out (len bytes) cannot hold it. */
int inifile_resolve(const char *dir, const char *value, char *out, size_t len);

/* The machine session's socket: [API] SOCKET (value, relative to dir), else
 * $XDG_RUNTIME_DIR/hexcnc.sock, else /tmp/hexcnc-UID/hexcnc.sock. Which one it is, or -1
 * when out cannot hold it; for the last, the folder (which `hexcnc machine` creates) is
 * /tmp/hexcnc-UID. value may be NULL. */
enum inifile_socket { INIFILE_SOCKET_INI, INIFILE_SOCKET_XDG, INIFILE_SOCKET_TMP };
int inifile_api_socket(const char *value, const char *dir, char *out, size_t len);

/* inifile_get with an untyped context (a struct inifile *): the get() of struct kins_config
 * and of interp_setup(). */
const char *inifile_config_get(void *ctx, const char *section, const char *key);

/* Points a message about a key at its line: a msg that starts "[SECTION] KEY" (followed by
 * ':', ' ' or '=') naming a key of the file becomes "PATH:LINE: msg"; naming a key the file
 * lacks in a section it has, the section's first line (where config_check puts a missing
 * key); any other becomes "PATH: msg" ("msg" alone when nothing is loaded). Returns out. */
char *inifile_locate_msg(const struct inifile *ini, const char *msg, char *out, size_t len);

#endif
