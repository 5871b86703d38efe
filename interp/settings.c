/* settings.c: settings G-code writes (tool table, persistent parameters) as CANON_SETTING
 * commands, and their application and saving when the machine executes them. */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/errbuf.h"
#include "interp/interp_int.h"
#include "interp/tooltable.h"

#define PERSIST_N (PARAM_PERSIST_HI - PARAM_PERSIST_LO + 1)

/* Remembers the persistent parameters as the program starts: changes are counted from here. */
void interp_settings_begin(struct interp *in)
{
    memcpy(in->persist_prev, &in->params[PARAM_PERSIST_LO], sizeof in->persist_prev);
}

/* One CANON_SETTING for the current line. */
static int emit_setting(struct interp *in, const struct canon_setting *s)
{
    struct canon_cmd c;
    interp_cmd_init(in, &c, CANON_SETTING);
    c.setting = s;
    return interp_emit(in, &c);
}

/* Reports the persistent parameters changed since the last report (none: nothing). */
int interp_emit_param_changes(struct interp *in)
{
    struct canon_param ch[PERSIST_N];
    size_t n = 0;
    for (int i = PARAM_PERSIST_LO; i <= PARAM_PERSIST_HI; i++) {
        double *prev = &in->persist_prev[i - PARAM_PERSIST_LO];
        if (in->params[i] == *prev || !interp_param_persistent(i))
            continue;
        *prev = in->params[i];
        ch[n].number = i;
        ch[n++].value = in->params[i];
    }
    if (n == 0)
        return 0;
    struct canon_setting s = { .tool = NULL, .nparams = n, .params = ch };
    return emit_setting(in, &s);
}

/* Reports tool `tool`'s entry as G10 L1 left it. */
int interp_emit_tool_setting(struct interp *in, int tool)
{
    const struct tool_entry *e = in->tt ? tooltable_find(in->tt, tool) : NULL;
    if (!e)
        return 0;
    struct canon_setting s = { .tool = e, .nparams = 0, .params = NULL };
    return emit_setting(in, &s);
}

/* Whether path can be replaced by a new file (temporary file in its folder, rename), without
 * touching it. what names the file for the message. */
static int file_writable(const char *path, const char *what, char *err, size_t errlen)
{
    char dir[1024];
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else
        snprintf(dir, sizeof dir, "%.*s", slash == path ? 1 : (int)(slash - path), path);
    struct stat st;
    int exists = stat(path, &st) == 0;
    if (exists && !S_ISREG(st.st_mode))
        return errbuf_set(err, errlen, INTERP_ERR_IO, "%s: the %s cannot be saved: it is not "
                          "a regular file", path, what);
    if (access(dir, W_OK | X_OK) != 0)
        return errbuf_set(err, errlen, INTERP_ERR_IO, "%s: the %s cannot be saved: folder %s: "
                          "%s", path, what, dir, strerror(errno));
    if (exists && access(path, W_OK) != 0)
        return errbuf_set(err, errlen, INTERP_ERR_IO, "%s: the %s cannot be saved: %s", path,
                          what, strerror(errno));
    return INTERP_OK;
}

/* Checks that the files interp_setting_apply(in, s) would write can be written. */
int interp_setting_check(const struct interp *in, const struct canon_setting *s, char *err,
                         size_t errlen)
{
    if ((s->note == CANON_NOTE_LOGOPEN || s->note == CANON_NOTE_LOGAPPEND) && s->text)
        CHP(file_writable(s->text, "log file", err, errlen));
    if (s->nparams && in->param_path)
        CHP(file_writable(in->param_path, "parameter file", err, errlen));
    if (s->tool && in->tt && in->tt->path[0])
        CHP(file_writable(in->tt->path, "tool table", err, errlen));
    return INTERP_OK;
}

/* Applies an executed setting to in's parameters and tool table, then saves their files (a
 * comment's action is the machine's: nothing here). */
int interp_setting_apply(struct interp *in, const struct canon_setting *s, char *err,
                         size_t errlen)
{
    if (s->tool && in->tt) {
        int rc = tooltable_set(in->tt, s->tool);
        if (rc)
            return errbuf_set(err, errlen, INTERP_ERR_TOOL, "tool %d: %s", s->tool->tool,
                              tooltable_strerror(rc));
        if (in->tt->path[0] && tooltable_save(in->tt, in->tt->path, err, errlen))
            return INTERP_ERR_IO;
    }
    if (!s->nparams)
        return INTERP_OK;
    for (size_t i = 0; i < s->nparams; i++)
        if (s->params[i].number >= PARAM_PERSIST_LO && s->params[i].number <= PARAM_PERSIST_HI)
            in->params[s->params[i].number] = s->params[i].value;
    memset(&in->err, 0, sizeof in->err);
    int rc = interp_params_save(in);
    return rc ? errbuf_set(err, errlen, rc, "%s", in->err.message) : INTERP_OK;
}
