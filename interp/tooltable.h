/* tooltable.h: the tool table (LinuxCNC's file format), with diameter and wear per tool. */
#ifndef HEXCNC_TOOLTABLE_H
#define HEXCNC_TOOLTABLE_H

#include <stddef.h>

/*
 * File format: LinuxCNC's, one tool a line, `T1 P1 D20.0 Z+0.0 ;comment`. Fields: T (tool,
 * required, 0 or more), P (pocket, defaults to T), X Y Z A B C U V W (offsets, mm / deg), D
 * (diameter, mm), I J (front / back angle, deg), Q (orientation 0..9). Letters in either case;
 * blank lines and `;` comment lines are kept. LinuxCNC's older headed format (a header line
 * `TOOLNO POCKET LENGTH DIAMETER COMMENT`, then rows of bare numbers) is read too. A letter
 * LinuxCNC does not know, a repeated letter or a bad number is an error naming the line.
 *
 * Wear follows LinuxCNC's wear-offset convention: the entry T(10000 + n), n = 1..9999, holds
 * the wear of tool n when tool n is in the table, its D the diameter wear delta (negative as
 * the tool wears down); its other fields are kept in the file but not used. Any other number
 * (T0, T10000, T99999, T10005 with no T5) is an ordinary tool, as LinuxCNC reads it. In
 * memory the wear entry is folded into tool n's wear_mm.
 *
 * tooltable_save() rewrites the file it replaces line by line: comment and blank lines, the
 * order of the entries and the text of every number that did not change stay as they were;
 * a changed field gets its new value (in the old number's style where that is exact); new
 * tools and wear entries are appended at the end.
 *
 * G10 L1 keeps LinuxCNC's meaning: R is a RADIUS. `G10 L1 P1 R10` sets tool 1's nominal
 * diameter to 20; `G10 L1 P10001 R-0.02` sets tool 1's diameter wear to -0.04 (see
 * tooltable_g10_l1()).
 */

#define TOOLTABLE_MAX 256        /* tools a table holds */
#define TOOLTABLE_WEAR_BASE 10000 /* T(WEAR_BASE + n) is the wear entry of tool n */

/* Bits of tool_entry.present: which letters a tool's line carried (so a save writes back
 * the same fields). T, P and D are always written. */
enum tooltable_field {
    TOOLTABLE_F_X = 1 << 0, TOOLTABLE_F_Y = 1 << 1, TOOLTABLE_F_Z = 1 << 2,
    TOOLTABLE_F_A = 1 << 3, TOOLTABLE_F_B = 1 << 4, TOOLTABLE_F_C = 1 << 5,
    TOOLTABLE_F_U = 1 << 6, TOOLTABLE_F_V = 1 << 7, TOOLTABLE_F_W = 1 << 8,
    TOOLTABLE_F_I = 1 << 9, TOOLTABLE_F_J = 1 << 10, TOOLTABLE_F_Q = 1 << 11,
};

struct tool_entry {
    int tool;                 /* T number (0 or more; see the wear convention above) */
    int pocket;               /* P */
    double z_offset_mm;       /* Z: tool length offset */
    double diameter_mm;       /* D: nominal diameter */
    double wear_mm;           /* diameter wear delta (negative as the tool wears down) */
    char comment[256];        /* text after ';' (longer comments are cut here) */
    /* The other fields LinuxCNC knows, kept so a load/save round trip loses nothing. */
    double offset[9];         /* X Y Z A B C U V W offsets, mm / deg ([2] unused: Z above) */
    double front_angle_deg;   /* I */
    double back_angle_deg;    /* J */
    int orientation;          /* Q (lathe tools) */
    unsigned present;         /* TOOLTABLE_F_* bits: letters the line carried */
    int duplicate_line;       /* the file defines this T again on that line (0: it does not);
                               * the first definition is used, as LinuxCNC does, but
                               * tooltable_radius() refuses the tool */
};

struct tooltable {
    struct tool_entry tools[TOOLTABLE_MAX];
    int count;
    int nwarnings;            /* lines the loader accepted but did not use */
    char warning[600];        /* the first of them, "file:line: what" ("" if none) */
    char path[4096];          /* file it came from ("" when built in memory); PATH_MAX: a
                               * longer name is refused by the loader, never cut */
};

enum tooltable_status {
    TOOLTABLE_OK = 0,
    TOOLTABLE_ERR_IO,         /* file cannot be read or written */
    TOOLTABLE_ERR_SYNTAX,     /* a line that does not parse (line number in err) */
    TOOLTABLE_ERR_DUPLICATE,  /* the same T twice */
    TOOLTABLE_ERR_FULL,       /* more than TOOLTABLE_MAX tools */
    TOOLTABLE_ERR_NO_TOOL,    /* no such tool */
    TOOLTABLE_ERR_VALUE,      /* a negative diameter or effective diameter */
    TOOLTABLE_STATUS_COUNT
};
const char *tooltable_strerror(int status);

void tooltable_init(struct tooltable *t);
/* Reads a table file; err gets "file:line: what" on failure. On failure the table is left
 * empty (never half-loaded). */
int tooltable_load(struct tooltable *t, const char *path, char *err, size_t errlen);
/* Reads a table from text in memory; `name` is used in messages. */
int tooltable_parse(struct tooltable *t, const char *text, const char *name, char *err,
                    size_t errlen);
/* Writes the table atomically (common/atomicfile: private temporary in the same folder, fsync,
 * rename), keeping the text of what did not change in the file it replaces. A read-only file
 * is refused (TOOLTABLE_ERR_IO, message naming it) and left as it is. */
int tooltable_save(const struct tooltable *t, const char *path, char *err, size_t errlen);
/* The entry of tool `tool`, or NULL. */
struct tool_entry *tooltable_find(struct tooltable *t, int tool);
/* Adds or replaces an entry (TOOLTABLE_ERR_DUPLICATE for a number that would read back as a
 * wear entry, or turn a tool into one). */
int tooltable_set(struct tooltable *t, const struct tool_entry *e);
/* Sets the diameter wear delta of an existing tool (mm, negative when worn). */
int tooltable_set_wear(struct tooltable *t, int tool, double wear_mm);
/* G10 L1 P.. R.. Z..: p = tool sets the nominal radius (diameter = 2 R) and length offset of
 * tool p, creating it if needed; p = TOOLTABLE_WEAR_BASE + n sets tool n's diameter wear to
 * 2 R (n must exist; Z is refused there). has_r / has_z say which words the block carried. */
int tooltable_g10_l1(struct tooltable *t, int p, int has_r, double r_mm, int has_z,
                     double z_mm);
/* Effective radius for compensation: (diameter + wear) / 2; TOOLTABLE_ERR_VALUE if <= 0,
 * TOOLTABLE_ERR_DUPLICATE if the file defines the tool twice. */
int tooltable_radius(const struct tooltable *t, int tool, double *radius_mm);

#endif
