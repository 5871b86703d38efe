/* lexer.c: one program line to a block: spaces and case removed, comments, words, #n= and
 * #<name>= settings. */
#include <math.h>
#include <string.h>

#include "interp/interp_int.h"

/* Empties the block before a line is read. */
static void block_reset(struct interp_block *b)
{
    memset(b->col, 0, sizeof b->col);
    b->polar_inc = 0;
    for (int i = 0; i < INTERP_GROUPS; i++)
        b->g[i] = -1;
    for (int i = 0; i < INTERP_MGROUPS; i++)
        b->m[i] = -1;
    b->nassign = 0;
    b->n_present = 0;
    b->has_comment = 0;
}

/* Copies a ( ) comment starting at raw[*i] == '(' into the block; LinuxCNC keeps the last. */
static int read_comment(struct interp *in, const char *raw, size_t len, size_t *i)
{
    size_t start = *i + 1, j = start;
    for (; j < len && raw[j] != ')'; j++)
        if (raw[j] == '(')
            return interp_fail(in, INTERP_ERR_SYNTAX, (int)j + 1,
                               "a comment inside a comment: '(' before the ')' that closes the "
                               "comment opened at column %d", (int)*i + 1);
    if (j >= len)
        return interp_fail(in, INTERP_ERR_SYNTAX, (int)*i + 1,
                           "comment not closed: '(' without a matching ')' on this line");
    size_t n = j - start;
    if (n >= sizeof in->blk.comment)
        n = sizeof in->blk.comment - 1;
    memcpy(in->blk.comment, raw + start, n);
    in->blk.comment[n] = 0;
    in->blk.has_comment = 1;
    *i = j;
    return 0;
}

/* What normalise does with a byte: copy it (lowercased), skip it, or look at it (a comment,
 * the end of the line, a NUL). */
enum { NORM_COPY, NORM_SKIP, NORM_LOOK };
static const unsigned char norm_class[256] = {
    [' '] = NORM_SKIP, ['\t'] = NORM_SKIP, ['\r'] = NORM_SKIP,
    ['('] = NORM_LOOK, [';'] = NORM_LOOK, ['\0'] = NORM_LOOK,
};

/* Builds in->norm: the line without blanks and comments, lowercased, columns remembered. */
static int normalise(struct interp *in, const char *raw, size_t len, size_t i, int *count)
{
    int n = 0;
    if (len - i < INTERP_LINE_MAX - 1) {
        /* the common line, short enough that no test of the length is needed, copied until
         * the first byte to look at (a dense CAM block has none) */
        for (; i < len; i++) {
            unsigned char c = (unsigned char)raw[i];
            int k = norm_class[c];
            if (k == NORM_SKIP)
                continue;
            if (k == NORM_LOOK)
                break;
            in->norm[n] = (char)(c >= 'A' && c <= 'Z' ? c + ('a' - 'A') : c);
            in->normcol[n] = (int)i + 1;
            n++;
        }
    }
    for (; i < len; i++) {
        char c = raw[i];
        if (c == ' ' || c == '\t' || c == '\r')
            continue;
        if (c == '(') {
            CHP(read_comment(in, raw, len, &i));
            continue;
        }
        if (c == ';')
            break;
        if (c == '\0')
            return interp_fail(in, INTERP_ERR_SYNTAX, (int)i + 1, "a NUL byte: the file holds "
                               "binary data here, not G-code text");
        if (n >= INTERP_LINE_MAX - 1)
            return interp_fail(in, INTERP_ERR_SYNTAX, (int)i + 1,
                               "line too long (more than %d characters)", INTERP_LINE_MAX - 1);
        if (c >= 'A' && c <= 'Z')
            c = (char)(c + ('a' - 'A'));
        in->norm[n] = c;
        in->normcol[n] = (int)i + 1;
        n++;
    }
    in->norm[n] = 0;
    in->normcol[n] = (int)len + 1;
    *count = n;
    return 0;
}

/* Reads "#n=value" or "#<name>=value" at norm[*pos] == '#'. The setting takes effect after the
 * whole line; a new name exists (as 0) from here on, as in LinuxCNC. */
static int read_assignment(struct interp *in, int *pos)
{
    struct interp_block *b = &in->blk;
    int col = in->normcol[*pos], named = 0, idx, nlen = 0;
    const char *name = NULL;
    double iv, v;
    (*pos)++;
    if (in->norm[*pos] == '<') {
        named = 1;
        CHP(interp_read_name(in, pos, col, &name, &nlen));
        CHP(interp_named_target(in, name, nlen, col, &idx));
    } else {
        CHP(interp_read_value(in, pos, &iv));
        CHP(interp_to_int(in, iv, col, "parameter number", &idx));
        if (idx < 1 || idx >= INTERP_NPARAMS)
            return interp_fail(in, INTERP_ERR_PARAM, col, "parameter number #%d out of range "
                               "(1 to %d)", idx, INTERP_NPARAMS - 1);
        if (idx >= PARAM_POS && idx <= PARAM_POS + 8)
            return interp_fail(in, INTERP_ERR_PARAM, col, "#%d is read-only: #5420..#5428 "
                               "tell the current position", idx);
    }
    if (in->norm[*pos] != '=') {
        if (named)
            return interp_fail(in, INTERP_ERR_SYNTAX, in->normcol[*pos], "'=' expected after "
                               "#<%.*s> (a parameter setting is #<name>=value)",
                               nlen > 60 ? 60 : nlen, name);
        return interp_fail(in, INTERP_ERR_SYNTAX, in->normcol[*pos],
                           "'=' expected after #%d (a parameter setting is #n=value)", idx);
    }
    (*pos)++;
    CHP(interp_read_value(in, pos, &v));
    if (!isfinite(v) && named)
        return interp_fail(in, INTERP_ERR_EXPR, col, "value for #<%.*s> is not a finite number "
                           "(overflow)", nlen > 60 ? 60 : nlen, name);
    if (!isfinite(v))
        return interp_fail(in, INTERP_ERR_EXPR, col, "value for #%d is not a finite number "
                           "(overflow)", idx);
    if (b->nassign >= INTERP_MAX_ASSIGN)
        return interp_fail(in, INTERP_ERR_PARAM, col, "more than %d parameter settings in one block",
                           INTERP_MAX_ASSIGN);
    b->assign_idx[b->nassign] = idx;
    b->assign_named[b->nassign] = (unsigned char)named;
    b->assign_val[b->nassign] = v;
    b->nassign++;
    return 0;
}

/* Reads one letter word at norm[*pos]. */
static int read_word(struct interp *in, int *pos)
{
    struct interp_block *b = &in->blk;
    char c = in->norm[*pos];
    int col = in->normcol[*pos], first = *pos == 0;
    if (c == 'o')
        return interp_fail(in, INTERP_ERR_UNSUPPORTED, col,
                           "an O-word (o100 if, o<name> call, ...) must start its line");
    if (c == 'u' || c == 'v')
        return interp_fail(in, INTERP_ERR_WORD, col,
                           "this machine has no %c axis (axes are X Y Z A B C)", c - 32);
    if ((c < ' ' || c > '~') && c != 0)  /* control or non-ASCII byte: shown as a code */
        return interp_fail(in, INTERP_ERR_SYNTAX, col, "byte 0x%02X is not G-code text (G-code "
                           "is ASCII)", (unsigned)(unsigned char)c);
    if ((c < 'a' || c > 'z') && c != '@' && c != '^')
        return interp_fail(in, INTERP_ERR_SYNTAX, col,
                           c >= '0' && c <= '9' ? "a number without a word letter before it"
                                                : "'%c' is not a G-code word",
                           c >= 'a' && c <= 'z' ? c - 32 : c);
    (*pos)++;
    int k = *pos;
    while (in->norm[k] >= 'a' && in->norm[k] <= 'z')
        k++;
    if (in->norm[*pos] == 0 || (k > *pos && in->norm[k] != '['))
        return interp_fail(in, INTERP_ERR_SYNTAX, col, "%c word without a value",
                           c >= 'a' ? c - 32 : c);
    int digits = 0;  /* an N word keeps the digits it was written with, as rs274 prints it */
    while (in->norm[*pos + digits] >= '0' && in->norm[*pos + digits] <= '9')
        digits++;
    double v;
    CHP(interp_read_value(in, pos, &v));
    if (!isfinite(v))
        return interp_fail(in, INTERP_ERR_EXPR, col, "%c word value is not a finite number "
                           "(overflow)", c - 32);
    if (c == 'g')
        return interp_add_g(in, v, col);
    if (c == 'm')
        return interp_add_m(in, v, col);
    if (c == 'n') {
        if (!first)
            return interp_fail(in, INTERP_ERR_WORD, col, "the N word (line number) must be the "
                               "first word of the block");
        CHP(interp_to_int(in, v, col, "N line number", &b->n_number));
        if (b->n_number < 0)
            return interp_fail(in, INTERP_ERR_WORD, col, "negative N line number %d",
                               b->n_number);
        b->n_present = 1;
        b->n_digits = digits;
        return 0;
    }
    k = c == '@' ? 26 : c == '^' ? 27 : c - 'a';
    if (b->col[k])
        return interp_fail(in, INTERP_ERR_WORD, col,
                           "two %c words in one block (the first is at column %d)",
                           k < 26 ? c - 32 : c, b->col[k]);
    b->col[k] = col;
    b->val[k] = v;
    return 0;
}

/* One line to in->blk: block delete, normalising, '%', then words and settings in order. */
int interp_read_line(struct interp *in, const char *raw, size_t len, int *kind)
{
    block_reset(&in->blk);
    *kind = 0;
    size_t i = 0;
    while (i < len && (raw[i] == ' ' || raw[i] == '\t'))
        i++;
    if (i < len && raw[i] == '/') {
        if (in->block_delete)
            return INTERP_OK;
        i++;
    }
    int n = 0;
    CHP(normalise(in, raw, len, i, &n));
    if (n == 1 && in->norm[0] == '%') {
        *kind = 2;
        return INTERP_OK;
    }
    if (in->norm[0] == 'o') {  /* an O-word line: control flow, run by oword.c */
        *kind = 3;
        return INTERP_OK;
    }
    for (int pos = 0; pos < n;) {
        char c = in->norm[pos];
        if (c == '%')
            return interp_fail(in, INTERP_ERR_SYNTAX, in->normcol[pos],
                               "'%%' must stand alone on its line (it marks the program's start "
                               "and end)");
        if (c == '#')
            CHP(read_assignment(in, &pos));
        else
            CHP(read_word(in, &pos));
    }
    *kind = 1;
    return INTERP_OK;
}
