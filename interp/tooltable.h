/* tooltable.h: the tool table (LinuxCNC's file format), with diameter and wear per tool. */
#ifndef HEXCNC_TOOLTABLE_H
#define HEXCNC_TOOLTABLE_H

#include <stddef.h>

#define TOOLTABLE_MAX 256     /* tools a table holds */

struct tool_entry {
    int tool;                 /* T number (> 0) */
    int pocket;               /* P */
    double z_offset_mm;       /* Z: tool length offset */
    double diameter_mm;       /* D: nominal diameter */
    double wear_mm;           /* diameter wear delta (negative as the tool wears down) */
    char comment[80];         /* text after ';' */
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
/* Reads a table file; err gets "file:line: what" on failure. */
int tooltable_load(struct tooltable *t, const char *path, char *err, size_t errlen);
/* Writes the table atomically (temporary file in the same folder, fsync, rename). */
int tooltable_save(const struct tooltable *t, const char *path, char *err, size_t errlen);
/* The entry of tool `tool`, or NULL. */
struct tool_entry *tooltable_find(struct tooltable *t, int tool);
/* Adds or replaces an entry. */
int tooltable_set(struct tooltable *t, const struct tool_entry *e);
/* Effective radius for compensation: (diameter + wear) / 2; TOOLTABLE_ERR_VALUE if <= 0. */
int tooltable_radius(const struct tooltable *t, int tool, double *radius_mm);

#endif
