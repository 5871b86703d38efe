/* runner_settings.c: settings G-code writes (CANON_SETTING: tool-table entries, persistent
 * parameters) applied and saved when execution reaches their line, never before. */
#include "task/runner_priv.h"

#include <stdlib.h>
#include <string.h>

#include "common/errbuf.h"
#include "interp/tooltable.h"

/* Drops the settings of the previous program and the interpreter that saves them. */
void runner_settings_free(struct runner *r)
{
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
            return errbuf_set(err, errlen, RUNNER_ERR_CONFIG, "%s:%d: this line changes %s, "
                              "saved when the line executes, but %s", c->file, c->line,
                              c->setting->tool ? "the tool table" : "persistent parameters",
                              msg);
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
        }
    }
    pthread_mutex_unlock(&r->settings_lock);
}
