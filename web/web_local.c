/* web_local.c: which methods a browser may call, and the station's own: what the machine
 * looks like, the program folder's files, an upload, a program's lines and its path. */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/atomicfile.h"
#include "common/errbuf.h"
#include "kins/hexapod.h"
#include "web/web.h"

#define RPC_INVALID_PARAMS -32602
#define RPC_REFUSED -32001
#define RPC_CONTROL -32002
#define RPC_PROGRAM -32003
#define RPC_NOT_FOUND -32004
#define RPC_FAILED -32005

static const char *const forwarded[] = {
    "status.get", "status.subscribe", "messages.subscribe", "control.acquire",
    "control.release", "machine.estop", "machine.power", "machine.home", "machine.unhome",
    "machine.mode", "jog.move", "jog.stop", "mdi.execute", "program.open", "program.check",
    "program.run", "program.pause", "program.resume", "program.step", "program.abort",
    "override.set", "switch.set", "tooltable.get", "tooltable.set", "tool.changed",
    "hal.show", "hal.get", "hal.set",
};
static const char *const local[] = {
    "station.info", "program.list", "program.upload", "program.lines", "program.preview",
};

static bool in_list(const char *m, const char *const *list, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!strcmp(m, list[i]))
            return true;
    return false;
}

bool web_method_forwarded(const char *m)
{
    return in_list(m, forwarded, sizeof forwarded / sizeof forwarded[0]);
}

bool web_method_local(const char *m)
{
    return in_list(m, local, sizeof local / sizeof local[0]);
}

static json_t *vec3(const double *v)
{
    return json_pack("[fff]", v[0], v[1], v[2]);
}

/* The machine's shape for the 3-D view: joint centres, what the platform carries, HOME. */
static json_t *station_info(const struct web_config *c)
{
    const struct inifile *ini = c->ini;
    const char *name = inifile_get(ini, "EMC", "MACHINE");
    const char *kname = inifile_get(ini, "KINS", "KINEMATICS");
    json_t *r = json_pack("{s:s, s:s, s:s, s:b}", "machine", name ? name : "hexcnc",
                          "kinematics", kname ? kname : "", "program_folder", c->prefix,
                          "token_required", c->token[0] != '\0');
    if (!kname || strcmp(kname, "hexapod"))
        return r;
    struct kins_config cfg = { inifile_config_get, (void *)ini };
    struct kins *k = NULL;
    char err[512];
    if (kins_create(&kins_hexapod_ops, &cfg, &k, err, sizeof err) != KINS_OK) {
        json_object_set_new(r, "geometry_error", json_string(err));
        return r;
    }
    const struct hexapod *h = (const struct hexapod *)k;
    json_t *base = json_array(), *plat = json_array();
    for (int i = 0; i < HEXAPOD_LEGS; i++) {
        json_array_append_new(base, vec3(h->b_mm[i]));
        json_array_append_new(plat, vec3(h->p_mm[i]));
    }
    json_t *geo = json_pack("{s:o, s:o, s:s, s:o}", "base", base, "platform", plat,
                            "carries", h->carries == HEXAPOD_CARRIES_SPINDLE ? "spindle"
                            : "workpiece", "tool_tip", vec3(h->tool_tip_mm));
    json_object_set_new(geo, "tool_axis", vec3(h->tool_axis));
    kins_free(k);
    json_object_set_new(r, "geometry", geo);
    return r;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(json_string_value(json_object_get(*(json_t *const *)a, "name")),
                  json_string_value(json_object_get(*(json_t *const *)b, "name")));
}

/* The program folder's files (not hidden ones), by name. */
static json_t *program_list(const struct web_config *c, int *code, char *err, size_t errlen)
{
    DIR *d = opendir(c->prefix);
    if (!d) {
        *code = RPC_NOT_FOUND;
        errbuf_set(err, errlen, -1, "%s: %s", c->prefix, strerror(errno));
        return NULL;
    }
    json_t **items = NULL;   /* every file: a folder of any size is listed whole */
    size_t n = 0, cap = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        struct stat st;
        if (e->d_name[0] == '.' || fstatat(dirfd(d), e->d_name, &st, 0) || !S_ISREG(st.st_mode))
            continue;
        if (n == cap) {
            json_t **more = realloc(items, (cap = cap ? 2 * cap : 256) * sizeof *items);
            if (!more) {
                for (size_t i = 0; i < n; i++)
                    json_decref(items[i]);
                free(items);
                closedir(d);
                *code = RPC_FAILED;
                errbuf_set(err, errlen, -1, "%s: out of memory listing it", c->prefix);
                return NULL;
            }
            items = more;
        }
        items[n++] = json_pack("{s:s, s:I, s:I}", "name", e->d_name, "size",
                               (json_int_t)st.st_size, "mtime", (json_int_t)st.st_mtime);
    }
    closedir(d);
    if (n)
        qsort(items, n, sizeof items[0], by_name);
    json_t *files = json_array();
    for (size_t i = 0; i < n; i++)
        json_array_append_new(files, items[i]);
    free(items);
    return json_pack("{s:s, s:o}", "folder", c->prefix, "files", files);
}

/* A file into the program folder, replaced atomically; only by the client in control. */
static json_t *program_upload(const struct web_config *c, json_t *p, bool has_control,
                              int *code, char *err, size_t errlen)
{
    const char *name = json_string_value(json_object_get(p, "name"));
    json_t *text = json_object_get(p, "text");
    *code = RPC_INVALID_PARAMS;
    if (!name || !json_is_string(text)) {
        errbuf_set(err, errlen, -1, "program.upload needs name (a file name) and text");
        return NULL;
    }
    size_t nl = strlen(name);
    if (!nl || nl > 200 || name[0] == '.' || strpbrk(name, "/\\") || strspn(name,
        "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-+ ()") != nl) {
        errbuf_set(err, errlen, -1, "program.upload: '%s' is not a plain file name (letters, "
                   "digits, . _ - + space and parentheses; no folder)", name);
        return NULL;
    }
    if (!has_control) {
        *code = RPC_CONTROL;
        errbuf_set(err, errlen, -1, "program.upload: take control of the machine first (the "
                   "upload changes the program folder)");
        return NULL;
    }
    char path[PATH_MAX + 256];
    snprintf(path, sizeof path, "%s/%s", c->prefix, name);
    if (atomicfile_write(path, json_string_value(text), json_string_length(text), err,
                         errlen)) {
        *code = RPC_FAILED;
        return NULL;
    }
    return json_pack("{s:s, s:I}", "path", name, "size", (json_int_t)json_string_length(text));
}

/* Lines from..from+count-1 of a program in the folder (at most 5000 at once). */
static json_t *program_lines(const struct web_config *c, json_t *p, int *code, char *err,
                             size_t errlen)
{
    const char *rel = json_string_value(json_object_get(p, "path"));
    json_int_t from = json_integer_value(json_object_get(p, "from"));
    json_int_t count = json_integer_value(json_object_get(p, "count"));
    char path[PATH_MAX];
    *code = RPC_INVALID_PARAMS;
    if (!rel || from < 1 || count < 1 || count > 5000) {
        errbuf_set(err, errlen, -1, "program.lines needs path, from >= 1 and count 1..5000");
        return NULL;
    }
    if (web_program_path(c, rel, path, sizeof path, err, errlen)) {
        *code = RPC_NOT_FOUND;
        return NULL;
    }
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st)) {
        *code = RPC_NOT_FOUND;
        errbuf_set(err, errlen, -1, "%s: %s", rel, strerror(errno));
        if (fd >= 0)
            close(fd);
        return NULL;
    }
    size_t size = (size_t)st.st_size;
    const char *m = size ? mmap(NULL, size, PROT_READ, MAP_PRIVATE, fd, 0) : "";
    close(fd);
    if (m == MAP_FAILED) {
        *code = RPC_FAILED;
        errbuf_set(err, errlen, -1, "%s: %s", rel, strerror(errno));
        return NULL;
    }
    const char *s = m, *end = m + size;
    json_int_t line = 1;
    while (line < from && s < end) {
        const char *nl = memchr(s, '\n', (size_t)(end - s));
        s = nl ? nl + 1 : end;
        line++;
    }
    json_t *lines = json_array();
    for (; line < from + count && s < end; line++) {
        const char *nl = memchr(s, '\n', (size_t)(end - s));
        size_t n = (size_t)((nl ? nl : end) - s);
        if (n && s[n - 1] == '\r')
            n--;
        json_array_append_new(lines, json_stringn_nocheck(s, n > 4096 ? 4096 : n));
        s = nl ? nl + 1 : end;
    }
    if (size)
        munmap((void *)m, size);
    return json_pack("{s:s, s:I, s:o, s:b}", "path", rel, "from", from, "lines", lines,
                     "end", s >= end);
}

json_t *web_local_call(const struct web_config *c, const char *method, json_t *params,
                       bool has_control, int *code, char *err, size_t errlen)
{
    if (!strcmp(method, "station.info"))
        return station_info(c);
    if (!strcmp(method, "program.list"))
        return program_list(c, code, err, errlen);
    if (!strcmp(method, "program.upload"))
        return program_upload(c, params, has_control, code, err, errlen);
    if (!strcmp(method, "program.lines"))
        return program_lines(c, params, code, err, errlen);
    /* program.preview */
    const char *rel = json_string_value(json_object_get(params, "path"));
    json_t *start = json_object_get(params, "start");
    json_int_t maxp = json_integer_value(json_object_get(params, "max_points"));
    double s[6] = { 0 };
    *code = RPC_INVALID_PARAMS;
    if (!rel || !json_is_array(start) || json_array_size(start) != 6) {
        errbuf_set(err, errlen, -1, "program.preview needs path and start (the machine pose, "
                   "6 numbers)");
        return NULL;
    }
    for (int i = 0; i < 6; i++)
        s[i] = json_number_value(json_array_get(start, (size_t)i));
    char path[PATH_MAX];
    if (web_program_path(c, rel, path, sizeof path, err, errlen)) {
        *code = RPC_NOT_FOUND;
        return NULL;
    }
    return web_preview(c, path, s, maxp > 0 && maxp < 2000000 ? (size_t)maxp : 500000, code,
                       err, errlen);
}
