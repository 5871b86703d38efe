/* oword_fanuc.c: Fanuc-style subprograms as LinuxCNC reads them: M98 P<n> L<k> runs the lines
 * from a bare O<n> to its M99 k times; a bare O<n> met in the flow is a subprogram to skip or
 * the program's number. Calls share oword.c's call stack (struct ow_call, m98 set). */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "interp/interp_int.h"
#include "interp/oword_priv.h"

/* The raw line as a block's words: lower case, without blanks and comments. */
static size_t squeeze(const char *s, size_t len, char *out, size_t cap)
{
    size_t n = 0;
    int paren = 0;
    for (size_t i = 0; i < len && n + 1 < cap; i++) {
        char c = s[i];
        if (paren) {
            paren = c != ')';
            continue;
        }
        if (c == '(') {
            paren = 1;
            continue;
        }
        if (c == ';')
            break;
        if (c != ' ' && c != '\t' && c != '\r')
            out[n++] = (char)tolower((unsigned char)c);
    }
    out[n] = 0;
    return n;
}

/* Whether a squeezed block holds M<code> (not M<code><digit>, nor M0<code> forms beyond it). */
static int has_m(const char *b, int code)
{
    for (const char *p = strchr(b, 'm'); p; p = strchr(p + 1, 'm')) {
        char *e;
        long v = strtol(p + 1, &e, 10);
        if (e != p + 1 && v == code && *e != '.')
            return 1;
    }
    return 0;
}

/* A bare O<n> line at idx: 1 when it starts a Fanuc subprogram (the first of M99, M2, M30
 * or another bare O-line after it is an M99; *end gets that line), 0 when it only numbers
 * the program. */
int oword_fanuc_sub_end(struct oword *ow, int text, int idx, int *end)
{
    struct ow_text *t = &ow->texts[text];
    int cur_idx = t->cur_idx, found = 0;
    size_t cur_off = t->cur_off, a, b;
    char buf[512], l[OWORD_LABEL_MAX], kw[16];
    for (int i = idx + 1; i < t->nlines; i++) {
        oword_line_span(t, i, &a, &b);
        if (oword_peek(t->text + a, b - a, l, kw) && !kw[0])
            break;
        squeeze(t->text + a, b - a, buf, sizeof buf);
        if (has_m(buf, 99)) {
            found = 1;
            *end = i;
            break;
        }
        if (has_m(buf, 2) || has_m(buf, 30) || !strcmp(buf, "%"))
            break;
    }
    t->cur_idx = cur_idx;
    t->cur_off = cur_off;
    return found;
}

/* The bare line O<label> of a text, or -1. */
static int find_bare(struct oword *ow, int text, const char *label)
{
    struct ow_text *t = &ow->texts[text];
    int cur_idx = t->cur_idx, found = -1;
    size_t cur_off = t->cur_off, a, b;
    char l[OWORD_LABEL_MAX], kw[16];
    for (int i = 0; i < t->nlines && found < 0; i++) {
        oword_line_span(t, i, &a, &b);
        if (oword_peek(t->text + a, b - a, l, kw) && !kw[0] && !strcmp(l, label))
            found = i;
    }
    t->cur_idx = cur_idx;
    t->cur_off = cur_off;
    return found;
}

int oword_m98(struct interp *in)
{
    struct oword *ow = &in->ow;
    const struct interp_block *bl = &in->blk;
    int p, l = 1;
    if (!bl->col['p' - 'a'])
        return interp_fail(in, INTERP_ERR_WORD, bl->mcol[4], "M98 needs P: the number of the "
                           "subprogram (a line O<n> ... M99)");
    CHP(interp_to_int(in, bl->val['p' - 'a'], bl->col['p' - 'a'], "M98 P", &p));
    if (bl->col['l' - 'a'])
        CHP(interp_to_int(in, bl->val['l' - 'a'], bl->col['l' - 'a'], "M98 L", &l));
    if (p < 0 || l < 0)
        return interp_fail(in, INTERP_ERR_WORD, bl->col[p < 0 ? 'p' - 'a' : 'l' - 'a'], "M98: "
                           "P and L are not negative");
    char label[OWORD_LABEL_MAX];
    snprintf(label, sizeof label, "%d", p);
    int text = ow->text, at = find_bare(ow, text, label);
    if (at < 0 && text != 0)
        at = find_bare(ow, text = 0, label);
    if (at < 0)
        return interp_fail(in, INTERP_ERR_SYNTAX, bl->col['p' - 'a'], "M98 P%d: no line O%d "
                           "(the subprogram's start, ended by M99) in this program", p, p);
    if (l == 0)
        return 0;
    if (ow->ncalls == OWORD_MAX_CALLS)
        return interp_fail(in, INTERP_ERR_SYNTAX, 1, "M98 P%d: subprograms nested more than %d "
                           "deep (a recursion that never ends?)", p, OWORD_MAX_CALLS);
    if (!ow->calls && !(ow->calls = calloc(OWORD_MAX_CALLS, sizeof *ow->calls)))
        return interp_fail(in, INTERP_ERR_NOMEM, 1, "out of memory");
    struct ow_call *c = &ow->calls[ow->ncalls++];
    memset(c, 0, sizeof *c);
    snprintf(c->label, sizeof c->label, "%s", label);
    c->text = ow->text;
    c->idx = ow->idx;
    c->nctl = ow->nctl;
    c->m98 = 1;
    c->m98_left = l;
    c->sub_idx = at;
    c->sub_text = text;
    ow->text = text;
    oword_jump(ow, at + 1);
    snprintf(in->file, sizeof in->file, "%s", ow->texts[text].file);
    return 0;
}

int oword_m99(struct interp *in, int *end)
{
    struct oword *ow = &in->ow;
    *end = 0;
    if (ow->ncalls == 0) {
        *end = 1;            /* the main program's M99: its end (rs274 stops there) */
        return 0;
    }
    struct ow_call *c = &ow->calls[ow->ncalls - 1];
    if (!c->m98)
        return interp_fail(in, INTERP_ERR_SYNTAX, in->blk.mcol[4], "M99 inside o%s, which was "
                           "called with 'call': end it with 'o%s endsub' (M99 ends an M98 "
                           "subprogram)", c->label, c->label);
    if (--c->m98_left > 0) {
        CHP(oword_loop_count(in, c->label));
        ow->nctl = c->nctl;
        oword_jump(ow, c->sub_idx + 1);
        return 0;
    }
    ow->ncalls--;
    ow->nctl = c->nctl;
    ow->text = c->text;
    oword_jump(ow, c->idx);
    snprintf(in->file, sizeof in->file, "%s", ow->texts[c->text].file);
    return 0;
}
