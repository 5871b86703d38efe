/* runner_settings.c: settings G-code writes (CANON_SETTING: tool-table entries, persistent
 * parameters) applied and saved when execution reaches their line, never before. */
#include "task/runner_priv.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/errbuf.h"
#include "interp/tooltable.h"

/* What a setting does, for the refusal before motion when its file cannot be written. */
const char *runner_setting_what(const struct canon_setting *s)
{
    if (s->note == CANON_NOTE_LOGOPEN || s->note == CANON_NOTE_LOGAPPEND)
        return "opens a log file";
    return s->tool ? "changes the tool table" : "changes persistent parameters";
}

/* A comment's action as its line executes: a message to the operator ((MSG,), (DEBUG,)), a
 * line on standard error ((PRINT,)), the log file ((LOGOPEN,) and the rest). 0, or -1 with
 * the reason in msg when the log file cannot be opened or written. */
static int run_note(struct runner *r, const struct canon_setting *s, char *msg, size_t len)
{
    const char *t = s->text ? s->text : "";
    switch (s->note) {
    case CANON_NOTE_MSG:
    case CANON_NOTE_DEBUG:
        hal_msg_post(r->hal, HAL_MSG_INFO, "program", "%s", t);
        return 0;
    case CANON_NOTE_PRINT:
        fprintf(stderr, "%s\n", t);
        return 0;
    case CANON_NOTE_LOGOPEN:
    case CANON_NOTE_LOGAPPEND:
        if (r->log)
            fclose(r->log);
        r->log = fopen(t, s->note == CANON_NOTE_LOGOPEN ? "w" : "a");
        if (!r->log) {
            snprintf(msg, len, "%s: the log file cannot be opened: %s", t, strerror(errno));
            return -1;
        }
        return 0;
    case CANON_NOTE_LOG:           /* (no log open: nothing, as in LinuxCNC) */
        if (r->log && (fprintf(r->log, "%s\n", t) < 0 || fflush(r->log) != 0)) {
            snprintf(msg, len, "the log file cannot be written: %s", strerror(errno));
            return -1;
        }
        return 0;
    case CANON_NOTE_LOGCLOSE:
        runner_log_close(r);
        return 0;
    default:
        return 0;
    }
}

void runner_log_close(struct runner *r)
{
    if (r->log)
        fclose(r->log);
    r->log = NULL;
}

/* Drops the settings of the previous program and the interpreter that saves them. */
void runner_settings_free(struct runner *r)
{
    runner_log_close(r);
    canon_prog_free(&r->settings);
    interp_destroy(r->store);
    r->store = NULL;
    free(r->store_tt);
    r->store_tt = NULL;
    r->settings_applied = 0;
    r->save_err[0] = '\0';
}

/* Keeps the program's CANON_SETTING commands, in order, and an interpreter set up with the
 * machine's parameter file and tool table to apply them to; refuses the program (before any
 * motion) when a file one of them would be saved to cannot be written. */
int runner_settings_load(struct runner *r, const struct canon_prog *prog, char *err,
                         size_t errlen)
{
    runner_settings_free(r);
    for (size_t i = 0; i < prog->count; i++)
        if (prog->cmds[i].type == CANON_SETTING &&
            canon_prog_sink(&r->settings, &prog->cmds[i]) != 0)
            return errbuf_set(err, errlen, RUNNER_ERR_NOMEM, "out of memory");
    if (r->settings.count == 0)
        return RUNNER_OK;
    int st = runner_settings_store(r, err, errlen);
    if (st != RUNNER_OK)
        return st;
    for (size_t i = 0; i < r->settings.count; i++) {
        const struct canon_cmd *c = &r->settings.cmds[i];
        char msg[700];
        if (interp_setting_check(r->store, c->setting, msg, sizeof msg) != INTERP_OK)
            return errbuf_set(err, errlen, RUNNER_ERR_CONFIG, "%s:%d: this line %s, "
                              "saved when the line executes, but %s", c->file, c->line,
                              runner_setting_what(c->setting), msg);
    }
    return RUNNER_OK;
}

int runner_settings_store(struct runner *r, char *err, size_t errlen)
{
    r->store = interp_create();
    r->store_tt = malloc(sizeof *r->store_tt);
    if (!r->store || !r->store_tt)
        return errbuf_set(err, errlen, RUNNER_ERR_NOMEM, "out of memory");
    tooltable_init(r->store_tt);
    return runner_setup_interp(r, r->store, r->store_tt, err, errlen);
}

/* Applies and saves every setting the machine has passed and that is not saved yet. A save
 * that fails stops the program (controlled stop); the run then reports it. */
void runner_settings_apply(struct runner *r)
{
    size_t done = atomic_load_explicit(&r->mon_settings, memory_order_acquire);
    pthread_mutex_lock(&r->settings_lock);  /* a streamed run's planner appends */
    if (done > r->settings.count)
        done = r->settings.count;
    while (r->settings_applied < done && !r->save_err[0]) {
        const struct canon_cmd *c = &r->settings.cmds[r->settings_applied++];
        char msg[700];
        if (interp_setting_apply(r->store, c->setting, msg, sizeof msg) != INTERP_OK) {
            snprintf(r->save_err, sizeof r->save_err, "%s:%d: the setting of this line "
                     "could not be saved: %s", c->file, c->line, msg);
            runner_abort(r);
        } else if (run_note(r, c->setting, msg, sizeof msg) != 0) {
            snprintf(r->save_err, sizeof r->save_err, "%s:%d: %s", c->file, c->line, msg);
            runner_abort(r);
        }
    }
    pthread_mutex_unlock(&r->settings_lock);
}
