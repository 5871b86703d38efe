/* oword.c: O-words as LinuxCNC reads them: sub/endsub/call/return with #1..#30 arguments and
 * return values, if/elseif/else/endif, while/endwhile, do/while, repeat/endrepeat, break and
 * continue; subroutines in their own files (o<name> call finds name.ngc). Fanuc's M98/M99
 * subprograms are in oword_fanuc.c.
 *
 * The interpreter reads lines through oword_next_line() from a list of texts (the program,
 * then any subroutine file), each with a table of line starts, so a jump is a change of line
 * index. A construct is matched by its label: the lines of one if (or loop, or sub) carry the
 * same O number or name, so skipping a false branch is a scan for the next line with that
 * label and one of the keywords that can follow. */
#include <ctype.h>
#include <limits.h>
#include <sys/mman.h>
#include <unistd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "interp/interp_int.h"
#include "interp/oword_priv.h"

enum { OW_IF = 1, OW_WHILE, OW_DO, OW_REPEAT };

/* Frees the local named parameters a call frame kept for its caller. */
static void drop_calls(struct oword *ow)
{
    while (ow->ncalls > 0) {
        struct ow_call *c = &ow->calls[--ow->ncalls];
        for (size_t i = 0; i < c->nlocals; i++)
            free(c->locals[i].name);
        free(c->locals);
        c->locals = NULL;
        c->nlocals = 0;
    }
}

/* Adds one text (the program, or a subroutine file) with its line table; returns its index
 * or -1 when out of memory. owned: the text to free with the interpreter, or NULL. */
static int text_add(struct oword *ow, char *owned, const char *text, size_t len,
                    const char *file, int mapped)
{
    if (ow->ntexts == ow->captexts) {
        int cap = ow->captexts ? ow->captexts * 2 : 4;
        struct ow_text *t = realloc(ow->texts, (size_t)cap * sizeof *t);
        if (!t)
            return -1;
        ow->texts = t;
        ow->captexts = cap;
    }
    /* one pass: count the lines and note every OW_STRIDE-th line's start; a mapped program
     * gives its pages back behind the scan, as the reader does later (release_behind) */
    size_t n = 1, cap = 1024, page = (size_t)sysconf(_SC_PAGESIZE), released = 0;
    size_t *off = malloc(cap * sizeof *off);
    if (!off)
        return -1;
    off[0] = 0;
    for (const char *p = text; (p = memchr(p, '\n', (size_t)(text + len - p))); p++) {
        size_t at = (size_t)(p + 1 - text);
        if (n % OW_STRIDE == 0) {
            if (n / OW_STRIDE >= cap) {
                size_t *no = realloc(off, 2 * cap * sizeof *off);
                if (!no) {
                    free(off);
                    return -1;
                }
                off = no, cap *= 2;
            }
            off[n / OW_STRIDE] = at;
        }
        n++;
        if (mapped && at >= released + ((size_t)16 << 20)) {
            size_t upto = at / page * page;
            madvise((char *)text + released, upto - released, MADV_DONTNEED);
            released = upto;
        }
    }
    if (n > 1 && len > 0 && text[len - 1] == '\n')
        n--;  /* a final newline does not start another line */
    if (mapped && released > 0)
        madvise((char *)text, released, MADV_DONTNEED);
    if (n > (size_t)INT_MAX - 1) {
        free(off);
        return -1;
    }
    struct ow_text *t = &ow->texts[ow->ntexts];
    t->owned = owned;
    t->text = text;
    t->len = len;
    t->off = off;
    t->nlines = (int)n;
    t->cur_idx = 0;
    t->cur_off = 0;
    t->mapped = mapped;
    t->released = 0;
    snprintf(t->file, sizeof t->file, "%s", file);
    return ow->ntexts++;
}

/* Starts a program: its text becomes text 0; nothing is open. */
int oword_begin(struct interp *in, const char *text, size_t len)
{
    struct oword *ow = &in->ow;
    for (int i = 0; i < ow->ntexts; i++) {
        free(ow->texts[i].owned);
        free(ow->texts[i].off);
    }
    ow->ntexts = 0;
    ow->nctl = ow->nsubs = 0;
    drop_calls(ow);
    ow->text = ow->idx = 0;
    ow->loops = 0;
    if (!ow->loop_limit)
        ow->loop_limit = OWORD_LOOP_LIMIT;
    if (text_add(ow, NULL, text, len, in->file, in->text_mapped) < 0)
        return interp_fail(in, INTERP_ERR_NOMEM, 0, "out of memory reading the program");
    return 0;
}

/* Where line i of t starts and ends (b: past its newline, or the text's end), from the
 * cursor when reading on, else from the sparse index; the cursor moves to line i + 1. */
void oword_line_span(struct ow_text *t, int i, size_t *a, size_t *b)
{
    int k = i;
    size_t p;
    if (t->cur_idx <= i && i - t->cur_idx < OW_STRIDE) {
        k = t->cur_idx;
        p = t->cur_off;
    } else {
        k = i / OW_STRIDE * OW_STRIDE;
        p = t->off[i / OW_STRIDE];
    }
    for (; k < i; k++) {
        const char *e = memchr(t->text + p, '\n', t->len - p);
        p = e ? (size_t)(e + 1 - t->text) : t->len;
    }
    *a = p;
    const char *e = memchr(t->text + p, '\n', t->len - p);
    *b = e ? (size_t)(e + 1 - t->text) : t->len;
    t->cur_idx = i + 1;
    t->cur_off = *b;
}

/* Gives back to the system the pages of a mapped program more than 4 MB behind the line
 * being read, 16 MB at a time, so that reading a long file keeps little of it resident (a
 * jump back reads them again from the file). */
static void release_behind(struct ow_text *t, size_t at)
{
    const size_t keep = (size_t)4 << 20, step = (size_t)16 << 20;
    if (!t->mapped || at < t->released + keep + step)
        return;
    size_t page = (size_t)sysconf(_SC_PAGESIZE);
    size_t upto = (at - keep) / page * page;
    if (upto > t->released) {
        madvise((char *)t->text + t->released, upto - t->released, MADV_DONTNEED);
        t->released = upto;
    }
}

/* The next line to read (without its newline); 0 at the end of the program. */
int oword_next_line(struct interp *in, const char **line, size_t *len)
{
    struct oword *ow = &in->ow;
    struct ow_text *t = &ow->texts[ow->text];
    if (ow->idx >= t->nlines) {
        if (ow->ncalls > 0) {
            in->line = t->nlines;
            interp_fail(in, INTERP_ERR_SYNTAX, 0, "the file ends inside subroutine o%s: "
                        "'o%s endsub' is missing", ow->calls[ow->ncalls - 1].label,
                        ow->calls[ow->ncalls - 1].label);
            return -1;
        }
        return 0;
    }
    size_t a, b;
    oword_line_span(t, ow->idx, &a, &b);
    release_behind(t, a);
    if (b > a && t->text[b - 1] == '\n')
        b--;
    *line = t->text + a;
    *len = b - a;
    in->line = ++ow->idx;
    return 1;
}

/* Reads the label of an O-line from a raw line ("o100", "O<My Sub>") and its keyword:
 * label as normalised ("100", "<mysub>"), keyword lowercase. 0 when the line is no O-line. */
int oword_peek(const char *s, size_t len, char *label, char *kw)
{
    size_t i = 0, n = 0;
    while (i < len && (s[i] == ' ' || s[i] == '\t'))
        i++;
    if (i < len && s[i] == '/')
        i++;
    while (i < len && (s[i] == ' ' || s[i] == '\t'))
        i++;
    if (i >= len || (s[i] != 'o' && s[i] != 'O'))
        return 0;
    i++;
    while (i < len && (s[i] == ' ' || s[i] == '\t'))
        i++;
    if (i < len && s[i] == '<') {
        while (i < len && s[i] != '>' && n < OWORD_LABEL_MAX - 2) {
            if (s[i] != ' ' && s[i] != '\t')
                label[n++] = (char)tolower((unsigned char)s[i]);
            i++;
        }
        if (i >= len || s[i] != '>')
            return 0;
        label[n++] = '>';
        i++;
    } else {
        while (i < len && isdigit((unsigned char)s[i]) && n < OWORD_LABEL_MAX - 1)
            label[n++] = s[i++];
    }
    label[n] = 0;
    while (i < len && (s[i] == ' ' || s[i] == '\t'))
        i++;
    size_t k = 0;
    while (i < len && isalpha((unsigned char)s[i]) && k < 15)
        kw[k++] = (char)tolower((unsigned char)s[i++]);
    kw[k] = 0;
    return n > 0;
}

/* Whether kw is one of the '|'-separated words of set. */
static int kw_in(const char *kw, const char *set)
{
    size_t n = strlen(kw);
    for (const char *p = set; *p;) {
        const char *e = strchr(p, '|');
        size_t l = e ? (size_t)(e - p) : strlen(p);
        if (l == n && !memcmp(p, kw, n))
            return 1;
        p = e ? e + 1 : p + l;
    }
    return 0;
}

/* The index of the next line after line idx of text labelled `label` whose keyword is in
 * set (kw gets the keyword), or -1. */
static int find_line(struct oword *ow, int text, int idx, const char *label,
                     const char *set, char *kw)
{
    struct ow_text *t = &ow->texts[text];
    char l[OWORD_LABEL_MAX];
    int cur_idx = t->cur_idx;   /* the reader's place: a scan ahead must not move it */
    size_t cur_off = t->cur_off, a, b;
    int found = -1;
    for (int i = idx + 1; i < t->nlines && found < 0; i++) {
        oword_line_span(t, i, &a, &b);
        if (oword_peek(t->text + a, b - a, l, kw) && !strcmp(l, label) && kw_in(kw, set))
            found = i;
    }
    t->cur_idx = cur_idx;
    t->cur_off = cur_off;
    return found;
}

/* find_line, failing with a message that names what is missing. */
static int find(struct interp *in, int text, int idx, const char *label, const char *set,
                int *at, char *kw, const char *what)
{
    *at = find_line(&in->ow, text, idx, label, set, kw);
    if (*at >= 0)
        return 0;
    char want[64];  /* "elseif|else|endif" said as "elseif, else or endif" */
    size_t w = 0;
    for (const char *p = set; *p && w < sizeof want - 5; p++) {
        if (*p != '|') {
            want[w++] = *p;
        } else if (strchr(p + 1, '|')) {
            memcpy(want + w, ", ", 2);
            w += 2;
        } else {
            memcpy(want + w, " or ", 4);
            w += 4;
        }
    }
    want[w] = 0;
    return interp_fail(in, INTERP_ERR_SYNTAX, 1, "o%s %s has no matching o%s %s after it",
                       label, what, label, want);
}

/* Evaluates the [expression] at norm[*pos] (what if, while, repeat, return carry). */
static int value(struct interp *in, int *pos, const char *label, const char *kw, double *v)
{
    if (in->norm[*pos] != '[')
        return interp_fail(in, INTERP_ERR_SYNTAX, in->normcol[*pos], "o%s %s needs an "
                           "[expression]", label, kw);
    return interp_read_value(in, pos, v);
}

/* Nothing may follow a keyword that takes no value. */
static int nothing_after(struct interp *in, int pos, const char *label, const char *kw)
{
    if (in->norm[pos])
        return interp_fail(in, INTERP_ERR_SYNTAX, in->normcol[pos], "unexpected '%c' after "
                           "o%s %s", in->norm[pos], label, kw);
    return 0;
}

/* One more loop iteration (counted where a loop's body starts); too many is a runaway
 * program. */
int oword_loop_count(struct interp *in, const char *label)
{
    if (++in->ow.loops > in->ow.loop_limit)
        return interp_fail(in, INTERP_ERR_SYNTAX, 1, "o%s: more than %ld loop iterations in "
                           "this program: a loop that never ends?", label, in->ow.loop_limit);
    return 0;
}

/* Opens a construct at the current line. */
static int push(struct interp *in, const char *label, int kind, long count, int done)
{
    struct oword *ow = &in->ow;
    if (ow->nctl == ow->capctl) {
        int cap = ow->capctl ? ow->capctl * 2 : 16;
        if (cap > 100000)
            return interp_fail(in, INTERP_ERR_SYNTAX, 1, "more than 100000 open O-word "
                               "constructs");
        struct ow_ctl *c = realloc(ow->ctl, (size_t)cap * sizeof *c);
        if (!c)
            return interp_fail(in, INTERP_ERR_NOMEM, 1, "out of memory");
        ow->ctl = c;
        ow->capctl = cap;
    }
    struct ow_ctl *c = &ow->ctl[ow->nctl++];
    snprintf(c->label, sizeof c->label, "%s", label);
    c->kind = kind;
    c->text = ow->text;
    c->idx = ow->idx - 1;
    c->count = count;
    c->done = done;
    return 0;
}

/* The innermost open construct labelled `label` of one of the kinds (a bit mask), within
 * the current call; -1 when there is none. */
static int open_ctl(const struct oword *ow, const char *label, unsigned kinds)
{
    int floor = ow->ncalls ? ow->calls[ow->ncalls - 1].nctl : 0;
    for (int i = ow->nctl - 1; i >= floor; i--)
        if (!strcmp(ow->ctl[i].label, label) && (kinds & (1u << ow->ctl[i].kind)))
            return i;
    return -1;
}

/* Finds a subroutine: known already, defined further on in the current text, or in a file
 * NAME.ngc in the program's folder or the subroutine path. */
static int find_sub(struct interp *in, const char *label, int *text, int *idx)
{
    struct oword *ow = &in->ow;
    for (int i = ow->nsubs - 1; i >= 0; i--)
        if (!strcmp(ow->subs[i].label, label)) {
            *text = ow->subs[i].text;
            *idx = ow->subs[i].idx;
            return 0;
        }
    char kw[16];
    for (int t = ow->text, k = 0; k < 2; k++, t = 0) {  /* this text, then the program */
        int at = find_line(ow, t, -1, label, "sub", kw);
        if (at >= 0) {
            *text = t;
            *idx = at;
            return 0;
        }
    }
    if (label[0] != '<')
        return interp_fail(in, INTERP_ERR_SYNTAX, 1, "o%s call: no subroutine o%s sub in this "
                           "program", label, label);
    char name[OWORD_LABEL_MAX];
    snprintf(name, sizeof name, "%.*s", (int)strlen(label) - 2, label + 1);
    const char *dirs[2] = { ow->dir, ow->path };
    for (int d = 0; d < 2; d++) {
        for (const char *p = dirs[d]; p && *p;) {
            const char *e = strchr(p, ':');
            size_t l = e ? (size_t)(e - p) : strlen(p);
            char path[1200];
            snprintf(path, sizeof path, "%.*s%s%s.ngc", (int)l, p, l ? "/" : "", name);
            p = e ? e + 1 : p + l;
            FILE *f = fopen(path, "rb");
            if (!f)
                continue;
            char *buf = NULL;
            size_t len = 0, cap = 0;
            for (;;) {
                if (len + 4096 > cap) {
                    char *nb = realloc(buf, cap = cap * 2 + 8192);
                    if (!nb)
                        break;
                    buf = nb;
                }
                size_t got = fread(buf + len, 1, cap - len, f);
                len += got;
                if (got == 0)
                    break;
            }
            fclose(f);
            if (!buf)
                return interp_fail(in, INTERP_ERR_NOMEM, 1, "out of memory reading %s", path);
            int t = text_add(ow, buf, buf, len, path, 0);
            if (t < 0) {
                free(buf);
                return interp_fail(in, INTERP_ERR_NOMEM, 1, "out of memory reading %s", path);
            }
            int at;
            if (find(in, t, -1, label, "sub", &at, kw, "call"))
                return interp_fail(in, INTERP_ERR_SYNTAX, 1, "o%s call: %s has no 'o%s sub' "
                                   "line", label, path, label);
            *text = t;
            *idx = at;
            return 0;
        }
    }
    return interp_fail(in, INTERP_ERR_SYNTAX, 1, "o%s call: no subroutine o%s in this program, "
                       "nor a file %s.ngc in the program's folder or [RS274NGC] SUBROUTINE_PATH",
                       label, label, name);
}

/* Sets #<_value> and #<_value_returned>, the result of the last call. */
static int set_result(struct interp *in, double v, int returned)
{
    int e;
    CHP(interp_named_target(in, "_value", 6, 1, &e));
    interp_named_set(in, e, v);
    CHP(interp_named_target(in, "_value_returned", 15, 1, &e));
    interp_named_set(in, e, returned);
    return 0;
}

/* o<label> call [a1] [a2] ...: #1..#30 get the arguments, locals start empty. */
static int do_call(struct interp *in, const char *label, int pos)
{
    struct oword *ow = &in->ow;
    double args[30] = { 0 };
    int nargs = 0;
    while (in->norm[pos]) {
        if (nargs == 30)
            return interp_fail(in, INTERP_ERR_SYNTAX, in->normcol[pos], "o%s call: more than "
                               "30 arguments", label);
        CHP(value(in, &pos, label, "call", &args[nargs]));
        nargs++;
    }
    if (ow->ncalls == OWORD_MAX_CALLS)
        return interp_fail(in, INTERP_ERR_SYNTAX, 1, "o%s call: subroutines nested more than "
                           "%d deep (a recursion that never ends?)", label, OWORD_MAX_CALLS);
    if (!ow->calls && !(ow->calls = calloc(OWORD_MAX_CALLS, sizeof *ow->calls)))
        return interp_fail(in, INTERP_ERR_NOMEM, 1, "out of memory");
    int text = 0, idx = 0;
    CHP(find_sub(in, label, &text, &idx));
    struct ow_call *c = &ow->calls[ow->ncalls];
    snprintf(c->label, sizeof c->label, "%s", label);
    c->text = ow->text;
    c->idx = ow->idx;
    c->nctl = ow->nctl;
    c->m73.valid = 0;
    memcpy(c->args, &in->params[1], sizeof c->args);
    if (interp_named_push_locals(in, &c->locals, &c->nlocals))
        return interp_fail(in, INTERP_ERR_NOMEM, 1, "out of memory");
    ow->ncalls++;
    memcpy(&in->params[1], args, sizeof args);
    CHP(set_result(in, 0.0, 0));
    ow->text = text;
    oword_jump(ow, idx + 1);
    snprintf(in->file, sizeof in->file, "%s", ow->texts[text].file);
    return 0;
}

/* return / endsub [value]: back to the caller, its #1..#30 and locals restored. */
static int do_return(struct interp *in, const char *label, const char *kw, int pos)
{
    struct oword *ow = &in->ow;
    double v = 0.0;
    int has = in->norm[pos] != 0;
    if (has)
        CHP(value(in, &pos, label, kw, &v));
    CHP(nothing_after(in, pos, label, kw));
    /* return may carry another construct's label (LinuxCNC writes `o1010 return` inside an
     * `o1010 if` of sub o1000): it leaves the innermost call; endsub must name its sub */
    if (ow->ncalls == 0)
        return interp_fail(in, INTERP_ERR_SYNTAX, 1, "o%s %s outside a subroutine call", label,
                           kw);
    if (!strcmp(kw, "endsub") && strcmp(ow->calls[ow->ncalls - 1].label, label))
        return interp_fail(in, INTERP_ERR_SYNTAX, 1, "o%s endsub inside a call of o%s", label,
                           ow->calls[ow->ncalls - 1].label);
    struct ow_call *c = &ow->calls[ow->ncalls - 1];
    if (c->m73.valid) {  /* M73 in this call: the caller's state comes back */
        c->m73.valid = 0;
        CHP(interp_modal_restore(in, &c->m73));
    }
    ow->ncalls--;
    memcpy(&in->params[1], c->args, sizeof c->args);
    int rc = interp_named_pop_locals(in, c->locals, c->nlocals);
    c->locals = NULL;
    if (rc)
        return interp_fail(in, INTERP_ERR_NOMEM, 1, "out of memory");
    ow->nctl = c->nctl;
    ow->text = c->text;
    oword_jump(ow, c->idx);
    snprintf(in->file, sizeof in->file, "%s", ow->texts[c->text].file);
    return set_result(in, v, has);
}

/* if / elseif / else / endif. */
static int do_if(struct interp *in, const char *label, const char *kw, int pos)
{
    struct oword *ow = &in->ow;
    int here = ow->idx - 1, at, c = -1;
    char next[16];
    double v = 0.0;
    if (strcmp(kw, "if")) {
        c = open_ctl(ow, label, 1u << OW_IF);
        if (c < 0)
            return interp_fail(in, INTERP_ERR_SYNTAX, 1, "o%s %s without o%s if", label, kw,
                               label);
    }
    if (!strcmp(kw, "endif")) {
        CHP(nothing_after(in, pos, label, kw));
        ow->nctl = c;
        return 0;
    }
    int done = c >= 0 && ow->ctl[c].done;
    if (!strcmp(kw, "if") || !strcmp(kw, "elseif")) {
        if (!done)
            CHP(value(in, &pos, label, kw, &v));
    }
    CHP(nothing_after(in, done ? (int)strlen(in->norm) : pos, label, kw));
    int take = !done && (!strcmp(kw, "else") || v != 0.0);
    if (!strcmp(kw, "if"))
        CHP(push(in, label, OW_IF, 0, take));
    else if (take)
        ow->ctl[c].done = 1;
    if (take)
        return 0;
    /* this branch is not taken: on to the next elseif or else (when none has run) or endif */
    CHP(find(in, ow->text, here, label, done || !strcmp(kw, "else") ? "endif"
             : "elseif|else|endif", &at, next, kw));
    oword_jump(ow, at);
    return 0;
}

/* while (a loop's head, or the end of a do), endwhile, do, repeat, endrepeat. */
static int do_loop(struct interp *in, const char *label, const char *kw, int pos)
{
    struct oword *ow = &in->ow;
    int here = ow->idx - 1, at;
    char next[16];
    double v;
    if (!strcmp(kw, "do")) {
        CHP(nothing_after(in, pos, label, kw));
        CHP(oword_loop_count(in, label));
        return push(in, label, OW_DO, 0, 0);
    }
    if (!strcmp(kw, "while")) {
        CHP(value(in, &pos, label, kw, &v));
        CHP(nothing_after(in, pos, label, kw));
        int c = open_ctl(ow, label, 1u << OW_DO);
        if (c >= 0) {            /* the end of o<label> do */
            if (v == 0.0) {
                ow->nctl = c;
                return 0;
            }
            CHP(oword_loop_count(in, label));
            oword_jump(ow, ow->ctl[c].idx + 1);
            return 0;
        }
        if (v == 0.0) {
            CHP(find(in, ow->text, here, label, "endwhile", &at, next, kw));
            oword_jump(ow, at + 1);
            return 0;
        }
        CHP(oword_loop_count(in, label));
        return push(in, label, OW_WHILE, 0, 0);
    }
    if (!strcmp(kw, "endwhile")) {
        CHP(nothing_after(in, pos, label, kw));
        int c = open_ctl(ow, label, 1u << OW_WHILE);
        if (c < 0)
            return interp_fail(in, INTERP_ERR_SYNTAX, 1, "o%s endwhile without o%s while",
                               label, label);
        ow->nctl = c;
        oword_jump(ow, ow->ctl[c].idx);  /* the while line tests again (and counts) */
        return 0;
    }
    if (!strcmp(kw, "repeat")) {
        CHP(value(in, &pos, label, kw, &v));
        CHP(nothing_after(in, pos, label, kw));
        long n = v >= 1e15 ? (long)1e15 : (long)v;
        if (n <= 0) {
            CHP(find(in, ow->text, here, label, "endrepeat", &at, next, kw));
            oword_jump(ow, at + 1);
            return 0;
        }
        CHP(oword_loop_count(in, label));
        return push(in, label, OW_REPEAT, n, 0);
    }
    /* endrepeat */
    CHP(nothing_after(in, pos, label, kw));
    int c = open_ctl(ow, label, 1u << OW_REPEAT);
    if (c < 0)
        return interp_fail(in, INTERP_ERR_SYNTAX, 1, "o%s endrepeat without o%s repeat", label,
                           label);
    if (--ow->ctl[c].count > 0) {
        CHP(oword_loop_count(in, label));
        ow->nctl = c + 1;
        oword_jump(ow, ow->ctl[c].idx + 1);
    } else {
        ow->nctl = c;
    }
    return 0;
}

/* break (leave the loop) and continue (its next iteration). */
static int do_break(struct interp *in, const char *label, const char *kw, int pos)
{
    struct oword *ow = &in->ow;
    CHP(nothing_after(in, pos, label, kw));
    int c = open_ctl(ow, label, 1u << OW_WHILE | 1u << OW_DO | 1u << OW_REPEAT);
    if (c < 0)
        return interp_fail(in, INTERP_ERR_SYNTAX, 1, "o%s %s outside a loop labelled o%s",
                           label, kw, label);
    const struct ow_ctl *l = &ow->ctl[c];
    const char *end = l->kind == OW_WHILE ? "endwhile" : l->kind == OW_DO ? "while"
                                                                         : "endrepeat";
    int at;
    char next[16];
    CHP(find(in, l->text, l->idx, label, end, &at, next, kw));
    if (!strcmp(kw, "break")) {
        ow->nctl = c;
        oword_jump(ow, at + 1);
    } else {
        ow->nctl = c + 1;        /* the end line decides whether the loop goes on */
        oword_jump(ow, at);
    }
    return 0;
}

/* Runs the O-line in in->norm (the lexer saw it start with 'o'). */
int oword_execute(struct interp *in)
{
    struct oword *ow = &in->ow;
    char label[OWORD_LABEL_MAX], kw[16];
    int pos = 1, n = 0;
    if (in->norm[pos] == '<') {
        while (in->norm[pos] && in->norm[pos] != '>' && n < OWORD_LABEL_MAX - 2)
            label[n++] = in->norm[pos++];
        if (in->norm[pos] != '>')
            return interp_fail(in, INTERP_ERR_SYNTAX, in->normcol[0], "O-word name not closed: "
                               "'>' missing");
        label[n++] = in->norm[pos++];
    } else {
        while (isdigit((unsigned char)in->norm[pos]) && n < OWORD_LABEL_MAX - 1)
            label[n++] = in->norm[pos++];
    }
    label[n] = 0;
    if (n == 0)
        return interp_fail(in, INTERP_ERR_SYNTAX, in->normcol[0], "an O-word needs a number "
                           "or a <name>");
    int k = 0;
    while (isalpha((unsigned char)in->norm[pos]) && k < 15)
        kw[k++] = in->norm[pos++];
    kw[k] = 0;
    if (!strcmp(kw, "sub")) {    /* a definition met in the flow: remember it, skip its body */
        int known = -1;          /* met again (in a loop): the newest definition wins */
        for (int i = 0; i < ow->nsubs && known < 0; i++)
            if (!strcmp(ow->subs[i].label, label))
                known = i;
        if (known < 0 && ow->nsubs == ow->capsubs) {
            int cap = ow->capsubs ? ow->capsubs * 2 : 16;
            struct ow_sub *s = realloc(ow->subs, (size_t)cap * sizeof *s);
            if (!s)
                return interp_fail(in, INTERP_ERR_NOMEM, 1, "out of memory");
            ow->subs = s;
            ow->capsubs = cap;
        }
        struct ow_sub *s = &ow->subs[known >= 0 ? known : ow->nsubs++];
        snprintf(s->label, sizeof s->label, "%s", label);
        s->text = ow->text;
        s->idx = ow->idx - 1;
        int at;
        char next[16];
        CHP(find(in, ow->text, ow->idx - 1, label, "endsub", &at, next, kw));
        oword_jump(ow, at + 1);
        return 0;
    }
    if (!kw[0] && !in->norm[pos] && label[0] != '<') {
        /* O<n> alone: a Fanuc subprogram's start met in the flow (skip to its M99), or the
         * program's number */
        int end;
        if (oword_fanuc_sub_end(ow, ow->text, ow->idx - 1, &end))
            oword_jump(ow, end + 1);
        return 0;
    }
    if (!strcmp(kw, "call"))
        return do_call(in, label, pos);
    if (!strcmp(kw, "return") || !strcmp(kw, "endsub"))
        return do_return(in, label, kw, pos);
    if (kw_in(kw, "if|elseif|else|endif"))
        return do_if(in, label, kw, pos);
    if (kw_in(kw, "while|endwhile|do|repeat|endrepeat"))
        return do_loop(in, label, kw, pos);
    if (kw_in(kw, "break|continue"))
        return do_break(in, label, kw, pos);
    return interp_fail(in, INTERP_ERR_SYNTAX, in->normcol[0], "o%s: '%s' is not an O-word "
                       "keyword (sub, endsub, call, return, if, elseif, else, endif, while, "
                       "endwhile, do, repeat, endrepeat, break, continue)", label, kw);
}

/* At the end of the program: an if or loop still open is an error (a missing end line). */
int oword_end(struct interp *in)
{
    struct oword *ow = &in->ow;
    if (ow->nctl > 0 && !in->ended)
        return interp_fail(in, INTERP_ERR_SYNTAX, 0, "o%s is still open at the end of the "
                           "program", ow->ctl[ow->nctl - 1].label);
    return 0;
}

/* Frees the texts, stacks and paths. */
void oword_free(struct interp *in)
{
    struct oword *ow = &in->ow;
    for (int i = 0; i < ow->ntexts; i++) {
        free(ow->texts[i].owned);
        free(ow->texts[i].off);
    }
    drop_calls(ow);
    free(ow->calls);
    free(ow->texts);
    free(ow->ctl);
    free(ow->subs);
    free(ow->path);
    free(ow->dir);
    memset(ow, 0, sizeof *ow);
}
