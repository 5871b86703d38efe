/* oword_priv.h: what oword.c (O-words) and oword_fanuc.c (M98/M99) share inside interp/. */
#ifndef HEXCNC_OWORD_PRIV_H
#define HEXCNC_OWORD_PRIV_H

#include <stddef.h>

#include "interp/interp_int.h"

/* Where line i of t starts and ends (b: past its newline, or the text's end). */
void oword_line_span(struct ow_text *t, int i, size_t *a, size_t *b);
/* Reads the label of an O-line from a raw line ("o100", "O<My Sub>") and its keyword:
 * label as normalised ("100", "<mysub>"), keyword lowercase ("" for a bare O<n>). 0 when
 * the line is no O-line. */
int oword_peek(const char *s, size_t len, char *label, char *kw);
/* One more loop iteration; too many is a runaway program (an error naming label). */
int oword_loop_count(struct interp *in, const char *label);
/* A bare O<n> line at idx of text: 1 when it starts a Fanuc subprogram (*end: its M99
 * line), 0 when it only numbers the program (oword_fanuc.c). */
int oword_fanuc_sub_end(struct oword *ow, int text, int idx, int *end);

/* Goes on at line idx of the current text (0-based). */
static inline void oword_jump(struct oword *ow, int idx)
{
    ow->idx = idx;
}

#endif
