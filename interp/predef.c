/* predef.c: LinuxCNC's read-only named parameters (#<_x>, #<_metric>, ...) that tell the
 * interpreter's state, for those this machine has. */
#include <string.h>

#include "interp/interp_int.h"

enum predef {
    PD_X, PD_Y, PD_Z, PD_A, PD_B, PD_C,                         /* program frame */
    PD_ABS_X, PD_ABS_Y, PD_ABS_Z, PD_ABS_A, PD_ABS_B, PD_ABS_C, /* machine frame */
    PD_METRIC, PD_IMPERIAL, PD_ABSOLUTE, PD_INCREMENTAL, PD_INVERSE_TIME, PD_UNITS_PER_MINUTE,
    PD_UNITS_PER_REV,
    PD_PLANE, PD_COORD_SYSTEM, PD_RETRACT_R_PLANE, PD_RETRACT_OLD_Z, PD_IJK_ABSOLUTE,
    PD_MOTION_MODE, PD_FEED, PD_RPM, PD_SPINDLE_ON, PD_SPINDLE_CW, PD_CURRENT_TOOL,
    PD_SELECTED_TOOL, PD_FLOOD, PD_MIST, PD_TASK, PD_CALL_LEVEL, PD_LINE,
};

static const struct { const char *name; enum predef id; } predef_table[] = {
    {"_x", PD_X}, {"_y", PD_Y}, {"_z", PD_Z}, {"_a", PD_A}, {"_b", PD_B}, {"_c", PD_C},
    {"_abs_x", PD_ABS_X}, {"_abs_y", PD_ABS_Y}, {"_abs_z", PD_ABS_Z},
    {"_abs_a", PD_ABS_A}, {"_abs_b", PD_ABS_B}, {"_abs_c", PD_ABS_C},
    {"_metric", PD_METRIC}, {"_imperial", PD_IMPERIAL}, {"_absolute", PD_ABSOLUTE},
    {"_incremental", PD_INCREMENTAL}, {"_inverse_time", PD_INVERSE_TIME},
    {"_units_per_minute", PD_UNITS_PER_MINUTE}, {"_units_per_rev", PD_UNITS_PER_REV},
    {"_plane", PD_PLANE},
    {"_coord_system", PD_COORD_SYSTEM}, {"_retract_r_plane", PD_RETRACT_R_PLANE},
    {"_retract_old_z", PD_RETRACT_OLD_Z}, {"_ijk_absolute_mode", PD_IJK_ABSOLUTE},
    {"_motion_mode", PD_MOTION_MODE}, {"_feed", PD_FEED}, {"_rpm", PD_RPM},
    {"_spindle_on", PD_SPINDLE_ON}, {"_spindle_cw", PD_SPINDLE_CW},
    {"_current_tool", PD_CURRENT_TOOL}, {"_selected_tool", PD_SELECTED_TOOL},
    {"_flood", PD_FLOOD}, {"_mist", PD_MIST}, {"_task", PD_TASK},
    {"_call_level", PD_CALL_LEVEL}, {"_line", PD_LINE},
};

/* G54..G59.3 as LinuxCNC reports them: 540, 550, ... 590, 591, 592, 593. */
static double coord_code(int system)
{
    return system <= 6 ? 530 + 10 * system : 584 + system;
}

/* The position in the program frame (offsets removed) or the machine frame, program units. */
static double position(const struct interp *in, int axis, int machine)
{
    double prog[6];
    if (!machine) {
        interp_prog_pos(in, prog);
        return prog[axis];
    }
    return axis < 3 && in->inch ? in->pos[axis] / MM_PER_INCH : in->pos[axis];
}

/* The value of one predefined parameter, from the state before the current line runs. */
static double predef_value(const struct interp *in, enum predef id)
{
    switch (id) {
    case PD_X: case PD_Y: case PD_Z: case PD_A: case PD_B: case PD_C:
        return position(in, (int)(id - PD_X), 0);
    case PD_ABS_X: case PD_ABS_Y: case PD_ABS_Z: case PD_ABS_A: case PD_ABS_B: case PD_ABS_C:
        return position(in, (int)(id - PD_ABS_X), 1);
    case PD_METRIC: return !in->inch;
    case PD_IMPERIAL: return in->inch;
    case PD_ABSOLUTE: return !in->incremental;
    case PD_INCREMENTAL: return in->incremental;
    case PD_INVERSE_TIME: return in->inverse_time;
    case PD_UNITS_PER_MINUTE: return !in->inverse_time && !in->per_rev;
    case PD_UNITS_PER_REV: return in->per_rev;
    case PD_PLANE: return in->plane * 10;
    case PD_COORD_SYSTEM: return coord_code(in->coord_system);
    case PD_RETRACT_R_PLANE: return !in->retract_old_z;
    case PD_RETRACT_OLD_Z: return in->retract_old_z;
    case PD_IJK_ABSOLUTE: return in->arc_absolute;
    case PD_MOTION_MODE: return in->motion < 0 ? 800 : in->motion;
    case PD_FEED: return in->f_word;
    case PD_RPM: return in->spindle_rpm;
    case PD_SPINDLE_ON: return in->spindle_dir != 0;
    case PD_SPINDLE_CW: return in->spindle_dir == 1;
    case PD_CURRENT_TOOL: return in->current_tool;
    case PD_SELECTED_TOOL: return in->selected_tool;
    case PD_FLOOD: return in->flood;
    case PD_MIST: return in->mist;
    /* _task is 1 in LinuxCNC's task and 0 in its previews and rs274; hexcnc's interp, check
     * and run read it as 0 alike, so a program verified is the program run */
    case PD_TASK: return 0.0;
    case PD_CALL_LEVEL: return in->ow.ncalls;
    default: return in->line; /* PD_LINE */
    }
}

/* Whether name (lowercase, len characters) is predefined; if so *out is its value now. */
int interp_predefined(const struct interp *in, const char *name, int len, double *out)
{
    for (size_t i = 0; i < sizeof predef_table / sizeof predef_table[0]; i++) {
        const char *p = predef_table[i].name;
        if ((int)strlen(p) == len && memcmp(p, name, (size_t)len) == 0) {
            *out = predef_value(in, predef_table[i].id);
            return 1;
        }
    }
    return 0;
}
