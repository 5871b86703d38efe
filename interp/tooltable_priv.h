/* tooltable_priv.h: one parsed line of a tool table file, shared by the loader and the saver
 * (which rewrites a line field by field, keeping the text of what did not change). */
#ifndef HEXCNC_TOOLTABLE_PRIV_H
#define HEXCNC_TOOLTABLE_PRIV_H

#include <stddef.h>

#include "interp/tooltable.h"

#define TOOLTABLE_LINE_FIELDS 16  /* T P X Y Z A B C U V W D I J Q: at most 15 */
#define TOOLTABLE_COLS_MAX 8      /* columns of an old-format (headed) table */

/* One field of a line: its letter and where its number's text is. */
struct tooltable_span {
    char letter;              /* T P X Y Z A B C U V W D I J Q (upper case) */
    const char *num;          /* the number's text in the line */
    size_t len;               /* its length */
};

/* The format a file is written in. LinuxCNC 2.4+ writes letters (`T1 P1 D10 ;comment`); its
 * older tables (and two of its examples) have a header naming the columns, then rows of bare
 * numbers and a comment: `TOOLNO POCKET LENGTH DIAMETER COMMENT` / `1 1 +0.511 0.125 1/8 em`. */
struct tooltable_format {
    char cols[TOOLTABLE_COLS_MAX + 1]; /* the letters of a headed table's columns, "" if none */
};

/* One line as read. */
struct tooltable_line {
    int lineno;
    int is_entry;             /* a T line (tool or wear entry); else blank, comment, header */
    int headed;               /* a row of bare numbers under a header (no letters) */
    struct tool_entry e;      /* the entry's values (pocket defaults to T) */
    unsigned seen;            /* bits of "TPXYZABCUVWDIJQ": letters the line carried */
    struct tooltable_span f[TOOLTABLE_LINE_FIELDS];
    int nf;
    const char *fields_end;   /* just after the last field */
    const char *comment;      /* the ';' (letter format) or the comment text (headed), or NULL */
    const char *eol;          /* the line end ("\r\n", "\n" or the NUL) */
};

/* The letters a line may carry, in the bit order of tooltable_line.seen. */
#define TOOLTABLE_LETTERS "TPXYZABCUVWDIJQ"

/* Parses the line starting at s (name and l->lineno for messages). A header line sets fmt. */
int tooltable_parse_line(const char *s, struct tooltable_line *l,
                         struct tooltable_format *fmt, const char *name, char *err,
                         size_t errlen);
/* Whether T`tool` can be a wear entry: WEAR_BASE + n with n = 1 .. WEAR_BASE - 1. */
static inline int tooltable_is_wear_number(int tool)
{
    return tool > TOOLTABLE_WEAR_BASE && tool < 2 * TOOLTABLE_WEAR_BASE;
}
/* The value of field `letter` in e. */
double tooltable_field_value(const struct tool_entry *e, char letter);

#endif
