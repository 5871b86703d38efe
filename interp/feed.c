/* feed.c: G95, feed per revolution, at the commanded spindle speed. */
#include "interp/interp_int.h"

/*
 * LinuxCNC's motion follows the spindle's measured speed under G95. Here only G33 and G33.1
 * follow the spindle's encoder (motion/motion_sync.c), so a G95 move runs at F times the
 * commanded S, in mm/min: what the spindle turns at when it keeps its speed. The check below
 * refuses a G95 feed with the spindle stopped, where LinuxCNC's motion would wait for the
 * spindle and this machine would otherwise feed as if it turned.
 */

/* The feed a feed move of this block runs at, mm/min: F (units/min, FEED_UNITS in metric
 * programs) under G94 and G93, F (units/rev) times S (rpm) under G95. */
double interp_feed_mm_min(const struct interp *in)
{
    if (in->per_rev)
        return (in->inch ? in->f_word * MM_PER_INCH : in->f_word) * in->spindle_rpm;
    return in->inch ? in->f_word * MM_PER_INCH : in->f_word * in->feed_factor;
}

/* CANON_FEED_MODE's value: 0 G94, 1 G93, 2 G95. */
int interp_feed_mode_value(const struct interp *in)
{
    return in->inverse_time ? 1 : in->per_rev ? 2 : 0;
}

/* A feed move under G95 needs a spindle speed (LinuxCNC's rule) and, here, a turning
 * spindle. */
int interp_need_spindle(struct interp *in, const char *what, int col)
{
    if (in->spindle_rpm <= 0.0)
        return interp_fail(in, INTERP_ERR_WORD, col, "%s in feed per revolution mode (G95) "
                           "with spindle speed 0: give an S word first", what);
    if (in->spindle_dir == 0)
        return interp_fail(in, INTERP_ERR_MODAL, col, "%s in feed per revolution mode (G95) "
                           "with the spindle stopped: start it with M3 or M4 (this machine "
                           "feeds F x S under G95, the commanded speed, not the measured one)",
                           what);
    return 0;
}
