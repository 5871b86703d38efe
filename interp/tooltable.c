/* tooltable.c: LinuxCNC-format tool table: parse, look up, wear, G10 L1 (file I/O: tooltable_file.c). */
#include "interp/tooltable.h"
#include "interp/tooltable_priv.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/errbuf.h"

static const char *const tooltable_msgs[TOOLTABLE_STATUS_COUNT] = {
    [TOOLTABLE_OK] = "ok",
    [TOOLTABLE_ERR_IO] = "tool table file cannot be read or written",
    [TOOLTABLE_ERR_SYNTAX] = "tool table line does not parse",
    [TOOLTABLE_ERR_DUPLICATE] = "the same tool number appears twice in the tool table",
    [TOOLTABLE_ERR_FULL] = "the tool table is full",
    [TOOLTABLE_ERR_NO_TOOL] = "no such tool in the tool table",
    [TOOLTABLE_ERR_VALUE] = "tool diameter (with wear) is missing, zero or negative",
};

/* The text of a status. */
const char *tooltable_strerror(int status)
{
    if (status < 0 || status >= TOOLTABLE_STATUS_COUNT)
        return "unknown tool table status";
    return tooltable_msgs[status];
}

/* An empty table. */
void tooltable_init(struct tooltable *t)
{
    memset(t, 0, sizeof *t);
}

/* Index of tool `tool` in t, or -1 (const-friendly core of tooltable_find). */
static int tooltable_index(const struct tooltable *t, int tool)
{
    for (int i = 0; i < t->count; i++)
        if (t->tools[i].tool == tool)
            return i;
    return -1;
}

/* The entry of tool `tool`, or NULL. */
struct tool_entry *tooltable_find(struct tooltable *t, int tool)
{
    int i = tooltable_index(t, tool);
    return i < 0 ? NULL : &t->tools[i];
}

/* Adds or replaces an entry. A number that would read back as something else is refused:
 * T(WEAR_BASE + n) while tool n exists (that is n's wear entry), and a new tool n while
 * T(WEAR_BASE + n) exists as a tool (it would turn into n's wear entry). */
int tooltable_set(struct tooltable *t, const struct tool_entry *e)
{
    if (e->tool < 0)
        return TOOLTABLE_ERR_NO_TOOL;
    if (!(e->diameter_mm >= 0.0))
        return TOOLTABLE_ERR_VALUE;
    int i = tooltable_index(t, e->tool);
    if (i < 0) {
        if (tooltable_is_wear_number(e->tool) &&
            tooltable_index(t, e->tool - TOOLTABLE_WEAR_BASE) >= 0)
            return TOOLTABLE_ERR_DUPLICATE;
        if (e->tool > 0 && e->tool < TOOLTABLE_WEAR_BASE &&
            tooltable_index(t, e->tool + TOOLTABLE_WEAR_BASE) >= 0)
            return TOOLTABLE_ERR_DUPLICATE;
        if (t->count >= TOOLTABLE_MAX)
            return TOOLTABLE_ERR_FULL;
        i = t->count++;
    }
    t->tools[i] = *e;
    return TOOLTABLE_OK;
}

/* Sets the diameter wear delta of an existing tool. */
int tooltable_set_wear(struct tooltable *t, int tool, double wear_mm)
{
    struct tool_entry *e = tooltable_find(t, tool);
    if (!e)
        return TOOLTABLE_ERR_NO_TOOL;
    if (!isfinite(wear_mm))
        return TOOLTABLE_ERR_VALUE;
    e->wear_mm = wear_mm;
    return TOOLTABLE_OK;
}

/* G10 L1: nominal radius / length of tool p, or the wear of tool p - WEAR_BASE. */
int tooltable_g10_l1(struct tooltable *t, int p, int has_r, double r_mm, int has_z,
                     double z_mm)
{
    if (tooltable_is_wear_number(p) && tooltable_index(t, p) < 0) {
        if (tooltable_index(t, p - TOOLTABLE_WEAR_BASE) < 0)
            return TOOLTABLE_ERR_NO_TOOL;  /* neither a wear entry nor a tool: ambiguous */
        if (has_z)
            return TOOLTABLE_ERR_VALUE; /* only diameter wear is kept */
        return has_r ? tooltable_set_wear(t, p - TOOLTABLE_WEAR_BASE, 2.0 * r_mm)
                     : TOOLTABLE_OK;
    }
    if (p <= 0)
        return TOOLTABLE_ERR_NO_TOOL;
    struct tool_entry e;
    struct tool_entry *old = tooltable_find(t, p);
    if (old) {
        e = *old;
    } else {
        memset(&e, 0, sizeof e);
        e.tool = p;
        e.pocket = p;
    }
    if (has_r) {
        if (!(r_mm >= 0.0))
            return TOOLTABLE_ERR_VALUE;
        e.diameter_mm = 2.0 * r_mm;
    }
    if (has_z) {
        e.z_offset_mm = z_mm;
        e.present |= TOOLTABLE_F_Z;
    }
    return tooltable_set(t, &e);
}

/* Effective radius for compensation: (diameter + wear) / 2, which must be > 0. */
int tooltable_radius(const struct tooltable *t, int tool, double *radius_mm)
{
    int i = tooltable_index(t, tool);
    if (i < 0)
        return TOOLTABLE_ERR_NO_TOOL;
    if (t->tools[i].duplicate_line)
        return TOOLTABLE_ERR_DUPLICATE; /* two diameters for one number: which one is meant? */
    double d_mm = t->tools[i].diameter_mm + t->tools[i].wear_mm;
    if (!(d_mm > 0.0))
        return TOOLTABLE_ERR_VALUE;
    *radius_mm = 0.5 * d_mm;
    return TOOLTABLE_OK;
}
