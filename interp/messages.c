/* messages.c: LinuxCNC's active comments, (MSG,) (DEBUG,) (PRINT,) and (LOGOPEN,) (LOGAPPEND,)
 * (LOG,) (LOGCLOSE): what the printer shows as rs274 does, and a CANON_SETTING that the
 * machine acts on when the line executes (never `interp` nor `check`: they write no file). */
#include <ctype.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "interp/interp_int.h"

static const struct {
    const char *word;                /* as written, any case, then ',' (but LOGCLOSE) */
    enum canon_note note;
} notes[] = {
    { "msg", CANON_NOTE_MSG },           { "debug", CANON_NOTE_DEBUG },
    { "print", CANON_NOTE_PRINT },       { "logopen", CANON_NOTE_LOGOPEN },
    { "logappend", CANON_NOTE_LOGAPPEND }, { "logclose", CANON_NOTE_LOGCLOSE },
    { "log", CANON_NOTE_LOG },
};

/* The comment's action, and where its text starts (after the comma). Blanks before the word
 * are allowed, as rs274 reads them. */
static enum canon_note note_of(const char *c, const char **rest)
{
    while (*c == ' ' || *c == '\t')
        c++;
    for (size_t i = 0; i < sizeof notes / sizeof notes[0]; i++) {
        size_t n = strlen(notes[i].word);
        if (strncasecmp(c, notes[i].word, n) != 0)
            continue;
        if (notes[i].note == CANON_NOTE_LOGCLOSE) {   /* the word alone */
            *rest = c + n;
            return c[n] ? CANON_NOTE_NONE : CANON_NOTE_LOGCLOSE;
        }
        if (c[n] == ',') {
            *rest = c + n + 1;
            return notes[i].note;
        }
    }
    return CANON_NOTE_NONE;
}

/* Appends s (n bytes) to out, cut at its end. */
static void put(char *out, size_t len, size_t *at, const char *s, size_t n)
{
    if (*at + n >= len)
        n = *at + 1 < len ? len - *at - 1 : 0;
    memcpy(out + *at, s, n);
    *at += n;
    out[*at] = 0;
}

/* The text with #n and #<name> in their values as rs274 writes them (%f); a name that is not
 * defined reads ######; anything else (an expression, ## ...) stays as written. */
static void expand(struct interp *in, const char *t, char *out, size_t len)
{
    size_t at = 0;
    out[0] = 0;
    while (*t) {
        char num[64];
        if (t[0] == '#' && isdigit((unsigned char)t[1])) {
            long k = 0;
            const char *e = t + 1;
            while (isdigit((unsigned char)*e) && k < INTERP_NPARAMS)
                k = 10 * k + (*e++ - '0');
            if (k >= 1 && k < INTERP_NPARAMS && !isdigit((unsigned char)*e)) {
                put(out, len, &at, num, (size_t)snprintf(num, sizeof num, "%f", in->params[k]));
                t = e;
                continue;
            }
        } else if (t[0] == '#' && t[1] == '<' && strchr(t + 2, '>')) {
            char name[128];
            size_t n = 0;
            const char *e = t + 2;
            for (; *e != '>'; e++)
                if (*e != ' ' && *e != '\t' && n + 1 < sizeof name)
                    name[n++] = (char)tolower((unsigned char)*e);
            name[n] = 0;
            double v;
            if (n && interp_named_exists(in, name, (int)n) &&
                interp_named_get(in, name, (int)n, 0, &v) == INTERP_OK)
                put(out, len, &at, num, (size_t)snprintf(num, sizeof num, "%f", v));
            else
                put(out, len, &at, "######", 6);
            t = e + 1;
            continue;
        }
        put(out, len, &at, t, 1);
        t++;
    }
}

/* A log file's path: relative ones from the program's folder, blanks around it dropped. */
static void log_path(const char *prog, const char *t, char *out, size_t len)
{
    while (*t == ' ' || *t == '\t')
        t++;
    size_t n = strlen(t);
    while (n && (t[n - 1] == ' ' || t[n - 1] == '\t'))
        n--;
    const char *slash = prog ? strrchr(prog, '/') : NULL;
    if (t[0] == '/' || !slash)
        snprintf(out, len, "%.*s", (int)n, t);
    else
        snprintf(out, len, "%.*s/%.*s", (int)(slash - prog), prog, (int)n, t);
}

int interp_comment(struct interp *in, const char *text)
{
    const char *rest = NULL;
    enum canon_note note = note_of(text, &rest);
    char shown[512], path[1024];
    struct canon_cmd c;
    interp_cmd_init(in, &c, CANON_COMMENT);
    c.ivalue = note;
    c.text = text;
    struct canon_setting s = { .note = note };
    if (note == CANON_NOTE_MSG || note == CANON_NOTE_LOGCLOSE) {
        c.text = s.text = rest;
    } else if (note == CANON_NOTE_LOGOPEN || note == CANON_NOTE_LOGAPPEND) {
        c.text = rest;                    /* rs274 shows it as written */
        log_path(c.file, rest, path, sizeof path);
        s.text = path;
    } else if (note != CANON_NOTE_NONE) {
        expand(in, rest, shown, sizeof shown);
        c.text = s.text = shown;
    }
    CHP(interp_emit(in, &c));
    if (note == CANON_NOTE_NONE)
        return INTERP_OK;
    struct canon_cmd st;
    interp_cmd_init(in, &st, CANON_SETTING);
    st.setting = &s;
    return interp_emit(in, &st);
}
