/* canon.c: the in-memory canonical program (a growable array of canonical commands). */
#include "interp/canon.h"

#include <stdlib.h>
#include <string.h>

#include "interp/tooltable.h"

static const char *const canon_names[CANON_TYPE_COUNT] = {
    [CANON_TRAVERSE] = "TRAVERSE",       [CANON_FEED] = "FEED",
    [CANON_ARC] = "ARC",                 [CANON_DWELL] = "DWELL",
    [CANON_FEED_RATE] = "FEED_RATE",     [CANON_FEED_MODE] = "FEED_MODE",
    [CANON_PATH_MODE] = "PATH_MODE",     [CANON_SPINDLE_SPEED] = "SPINDLE_SPEED",
    [CANON_SPINDLE_ON] = "SPINDLE_ON",   [CANON_SPINDLE_STOP] = "SPINDLE_STOP",
    [CANON_TOOL_CHANGE] = "TOOL_CHANGE", [CANON_COOLANT] = "COOLANT",
    [CANON_COMMENT] = "COMMENT",         [CANON_PAUSE] = "PAUSE",
    [CANON_PROGRAM_END] = "PROGRAM_END", [CANON_OFFSETS] = "OFFSETS",
    [CANON_SETTING] = "SETTING",        [CANON_DIGITAL_OUT] = "DIGITAL_OUT",
    [CANON_ANALOG_OUT] = "ANALOG_OUT",   [CANON_WAIT_INPUT] = "WAIT_INPUT",
    [CANON_PROBE] = "PROBE",
};

const char *canon_type_name(enum canon_type t)
{
    return (unsigned)t < CANON_TYPE_COUNT ? canon_names[t] : "?";
}

void canon_prog_init(struct canon_prog *p)
{
    memset(p, 0, sizeof *p);
}

/* A copy of a SETTING payload in one allocation (freed with free()), or NULL. */
static struct canon_setting *canon_setting_dup(const struct canon_setting *s)
{
    size_t tool = s->tool ? sizeof *s->tool : 0;
    size_t params = s->nparams * sizeof *s->params;
    size_t text = s->text ? strlen(s->text) + 1 : 0;
    struct canon_setting *d = malloc(sizeof *d + tool + params + text);
    if (!d)
        return NULL;
    unsigned char *after = (unsigned char *)(d + 1);
    d->tool = NULL;
    d->nparams = s->nparams;
    d->params = NULL;
    d->note = s->note;
    d->text = NULL;
    if (tool) {
        memcpy(after, s->tool, tool);
        d->tool = (const struct tool_entry *)after;
    }
    if (params) {
        memcpy(after + tool, s->params, params);
        d->params = (const struct canon_param *)(after + tool);
    }
    if (text) {
        memcpy(after + tool + params, s->text, text);
        d->text = (const char *)(after + tool + params);
    }
    return d;
}

void canon_prog_free(struct canon_prog *p)
{
    for (size_t i = 0; i < p->count; i++) {
        if (p->cmds[i].type == CANON_COMMENT)
            free((char *)p->cmds[i].text);
        if (p->cmds[i].type == CANON_SETTING)
            free((struct canon_setting *)p->cmds[i].setting);
    }
    free(p->cmds);
    canon_prog_init(p);
}

int canon_prog_sink(void *ctx, const struct canon_cmd *cmd)
{
    struct canon_prog *p = ctx;
    if (p->count == p->cap) {
        size_t cap = p->cap ? p->cap * 2 : 256;
        struct canon_cmd *n = realloc(p->cmds, cap * sizeof *n);
        if (!n)
            return -1;
        p->cmds = n;
        p->cap = cap;
    }
    struct canon_cmd *c = &p->cmds[p->count];
    *c = *cmd;
    if (cmd->type == CANON_COMMENT) {
        c->text = strdup(cmd->text ? cmd->text : "");
        if (!c->text)
            return -1;
    } else {
        c->text = NULL;
    }
    c->setting = NULL;
    if (cmd->type == CANON_SETTING && cmd->setting) {
        c->setting = canon_setting_dup(cmd->setting);
        if (!c->setting)
            return -1;
    }
    p->count++;
    return 0;
}
