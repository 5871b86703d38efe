/* tooltable.h: the tool table (LinuxCNC's file format), with diameter and wear per tool. */
#ifndef HEXCNC_TOOLTABLE_H
#define HEXCNC_TOOLTABLE_H

#include <stddef.h>

/*
 * File format: LinuxCNC's, one tool a line, `T1 P1 D20.0 Z+0.0 ;comment`. Fields: T (tool,
 * required), P (pocket, defaults to T), X Y Z A B C U V W (offsets, mm / deg), D (diameter,
 * mm), I J (front / back angle, deg), Q (orientation 0..9). Letters in either case; a letter
 * LinuxCNC does not know, a repeated letter or a bad number is an error naming the line.
 *
 * Wear follows LinuxCNC's wear-offset convention: the entry T(10000 + n) holds the wear of
 * tool n, its D the diameter wear delta (negative as the tool wears down). In memory the
 * wear entry is folded into tool n's wear_mm; tooltable_save() writes it back the same way,
 * so the file still loads in LinuxCNC. A worn tool is absorbed by the wear entry alone: the
 * program and the nominal D stay as they are.
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
    int tool;                 /* T number (1 .. TOOLTABLE_WEAR_BASE - 1) */
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
};

struct tooltable {
    struct tool_entry tools[TOOLTABLE_MAX];
    int count;
    char path[512];           /* file it came from ("" when built in memory) */
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
/* Writes the table atomically (temporary file in the same folder, fsync, rename). */
int tooltable_save(const struct tooltable *t, const char *path, char *err, size_t errlen);
/* The entry of tool `tool`, or NULL. */
struct tool_entry *tooltable_find(struct tooltable *t, int tool);
/* Adds or replaces an entry. */
int tooltable_set(struct tooltable *t, const struct tool_entry *e);
/* Sets the diameter wear delta of an existing tool (mm, negative when worn). */
int tooltable_set_wear(struct tooltable *t, int tool, double wear_mm);
/* G10 L1 P.. R.. Z..: p = tool sets the nominal radius (diameter = 2 R) and length offset of
 * tool p, creating it if needed; p = TOOLTABLE_WEAR_BASE + n sets tool n's diameter wear to
 * 2 R (n must exist; Z is refused there). has_r / has_z say which words the block carried. */
int tooltable_g10_l1(struct tooltable *t, int p, int has_r, double r_mm, int has_z,
                     double z_mm);
/* Effective radius for compensation: (diameter + wear) / 2; TOOLTABLE_ERR_VALUE if <= 0. */
int tooltable_radius(const struct tooltable *t, int tool, double *radius_mm);

#endif
