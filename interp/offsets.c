/* offsets.c: G10 (tool table, work offsets), G28/G30 homes, G92 family, G43/G49 tool length. */
#include <math.h>
#include <string.h>

#include "interp/interp_int.h"
#include "interp/tooltable.h"

#define W(c) (in->blk.col[(c) - 'a'])
#define V(c) (in->blk.val[(c) - 'a'])

static const char axis_letter[6] = {'x', 'y', 'z', 'a', 'b', 'c'};

/* The value of axis word i in mm (X Y Z) or deg (A B C). */
static double axis_mm(const struct interp *in, int i)
{
    return i < 3 ? interp_len_mm(in, V(axis_letter[i])) : V(axis_letter[i]);
}

/* Whether the block has any axis word. */
static int any_axis(const struct interp *in)
{
    for (int i = 0; i < 6; i++)
        if (W(axis_letter[i]))
            return 1;
    return 0;
}

/* G10 L1 P R Z: a tool's radius and length into the tool table in memory; the entry goes out
 * as a CANON_SETTING, saved to the table's file when the machine executes the line. */
static int g10_l1(struct interp *in, int p)
{
    if (!in->tt)
        return interp_fail(in, INTERP_ERR_TOOL, in->blk.gcol[0], "G10 L1 needs a tool table "
                           "(give one with -t or [EMCIO] TOOL_TABLE)");
    int rc = tooltable_g10_l1(in->tt, p, W('r') != 0, interp_len_mm(in, V('r')), W('z') != 0,
                              interp_len_mm(in, V('z')));
    if (rc)
        return interp_fail(in, INTERP_ERR_TOOL, W('p'), "G10 L1 P%d: %s", p, tooltable_strerror(rc));
    return interp_emit_tool_setting(in, p >= TOOLTABLE_WEAR_BASE ? p - TOOLTABLE_WEAR_BASE : p);
}

/* G10 L10 / L11 P R Z: tool P's length such that, with it in force, the current point reads
 * Z in the current coordinate system (L10: its work offset and G92) or in G59.3's (L11:
 * that fixture's offset alone), as LinuxCNC sets it; R its radius. The table keeps a mill
 * tool's length and diameter only, so other axis words are refused. */
static int g10_l10(struct interp *in, int l, int p)
{
    if (!in->tt)
        return interp_fail(in, INTERP_ERR_TOOL, in->blk.gcol[0], "G10 L%d needs a tool table "
                           "(give one with -t or [EMCIO] TOOL_TABLE)", l);
    static const char others[] = "xyabc";
    for (int k = 0; k < 5; k++)
        if (W(others[k]))
            return interp_fail(in, INTERP_ERR_WORD, W(others[k]), "G10 L%d: a tool here has a "
                               "length (Z) and a radius (R) only, no %c offset", l,
                               others[k] - 'a' + 'A');
    if (in->tcp_on)
        return interp_fail(in, INTERP_ERR_MODAL, in->blk.gcol[0], "G10 L%d under G43.4: the "
                           "position is the tool tip there; measure the tool with G49", l);
    double z = 0;
    if (W('z'))
        z = l == 10 ? in->pos[AX_Z] - in->g5x[AX_Z] - in->g92[AX_Z] - axis_mm(in, AX_Z)
                    : in->pos[AX_Z] - in->params[PARAM_G54 + 20 * 8 + AX_Z] - axis_mm(in, AX_Z);
    int rc = tooltable_g10_l1(in->tt, p, W('r') != 0, interp_len_mm(in, V('r')), W('z') != 0,
                              z);
    if (rc)
        return interp_fail(in, INTERP_ERR_TOOL, W('p'), "G10 L%d P%d: %s", l, p,
                           tooltable_strerror(rc));
    return interp_emit_tool_setting(in, p >= TOOLTABLE_WEAR_BASE ? p - TOOLTABLE_WEAR_BASE : p);
}

/* G10 L2 / L20 P: a work offset set directly, or so that the current point reads as given. */
static int g10_coord(struct interp *in, int l, int p)
{
    if (p < 0 || p > 9)
        return interp_fail(in, INTERP_ERR_WORD, W('p'), "G10 L%d P%d: P selects the coordinate "
                           "system, 1 (G54) to 9 (G59.3), or 0 for the active one", l, p);
    if (W('r') && l == 20)
        return interp_fail(in, INTERP_ERR_WORD, W('r'), "G10 L20 takes no R word: set the "
                           "rotation of the coordinate system with G10 L2 P%d R", p);
    int sys = p == 0 ? in->coord_system : p, base = PARAM_G54 + 20 * (sys - 1);
    /* a rotation (the system's, the one given, or the active one) turns X and Y */
    int rotated = (W('r') && V('r') != 0.0) || in->params[base + PARAM_ROT] != 0.0 ||
                  (sys == in->coord_system && in->rot_deg != 0.0);
    if (rotated)
        interp_g10_rotated(in, l, sys);
    else if (W('r'))
        in->params[base + PARAM_ROT] = V('r');   /* R0 */
    for (int i = 0; i < 6; i++) {
        if (!W(axis_letter[i]) || (rotated && i < 2))
            continue;
        double v = axis_mm(in, i);
        in->params[base + i] = l == 2 ? v : in->pos[i] - in->g92[i] - in->tool[i] - v;
    }
    if (sys == in->coord_system) {
        interp_select_coord(in, sys);
        return interp_emit_offsets(in);
    }
    return 0;
}

/* G10: L1 to the tool table, L2/L20 to a work offset. */
int interp_g10(struct interp *in)
{
    int l, p;
    if (!W('l'))
        return interp_fail(in, INTERP_ERR_WORD, in->blk.gcol[0], "G10 needs an L word: L1 (tool "
                           "table), L2 or L20 (work offsets)");
    if (!W('p'))
        return interp_fail(in, INTERP_ERR_WORD, in->blk.gcol[0], "G10 needs a P word (the tool "
                           "or the coordinate system)");
    CHP(interp_to_int(in, V('l'), W('l'), "G10 L", &l));
    CHP(interp_to_int(in, V('p'), W('p'), "G10 P", &p));
    if (l == 1)
        return g10_l1(in, p);
    if (l == 2 || l == 20)
        return g10_coord(in, l, p);
    if (l == 10 || l == 11)
        return g10_l10(in, l, p);
    return interp_fail(in, INTERP_ERR_UNSUPPORTED, W('l'), "G10 L%d is not supported (L1, L2, "
                       "L10, L11 and L20 are)", l);
}

/* G28/G30: rapid through the point given (if any) to the stored home; .1 stores the home. */
int interp_home(struct interp *in, int g)
{
    int base = g < 300 ? PARAM_G28 : PARAM_G30;
    if (g == 281 || g == 301) {
        if (any_axis(in))
            return interp_fail(in, INTERP_ERR_WORD, in->blk.gcol[0], "G%d.1 takes no axis words: "
                               "it stores the current position", g / 10);
        for (int i = 0; i < 6; i++)
            in->params[base + i] = in->pos[i];
        return 0;
    }
    double t[6];
    int all = !any_axis(in);
    interp_target(in, 0, t); /* the intermediate point (LinuxCNC moves there even when it is
                              * the current point) */
    CHP(interp_straight(in, CANON_TRAVERSE, t));
    for (int i = 0; i < 6; i++)
        t[i] = all || W(axis_letter[i]) ? in->params[base + i] : in->pos[i];
    if (in->rot_deg != 0.0 && !all && W('x') != W('y'))
        interp_home_rotated(in, base, t);
    return interp_straight(in, CANON_TRAVERSE, t);
}

/* G92 sets the offset so the current point reads as given; .1 clears it and its parameters,
 * .2 clears it keeping the parameters, .3 brings it back from them. */
int interp_g92(struct interp *in, int g)
{
    if (g == 920) {
        if (!any_axis(in))
            return interp_fail(in, INTERP_ERR_WORD, in->blk.gcol[0], "G92 needs at least one "
                               "axis word (the value the current point should have)");
        double q[2];
        interp_rotated_pos(in, q);  /* G92 is measured in the rotated frame */
        for (int i = 0; i < 6; i++) {
            if (!W(axis_letter[i]))
                continue;
            if (i < 2 && in->rot_deg != 0.0)
                in->g92[i] = q[i] - axis_mm(in, i);
            else
                in->g92[i] = in->pos[i] - in->g5x[i] - in->tool[i] - axis_mm(in, i);
        }
        for (int i = 0; i < 6; i++)
            in->params[PARAM_G92 + i] = in->g92[i];
        in->params[PARAM_G92_ON] = 1;
    } else if (g == 520) {   /* G52: a local offset, kept in G92's registers (LinuxCNC) */
        for (int i = 0; i < 6; i++)
            if (W(axis_letter[i]))
                in->g92[i] = axis_mm(in, i);
        for (int i = 0; i < 6; i++)
            in->params[PARAM_G92 + i] = in->g92[i];
        in->params[PARAM_G92_ON] = 1;
    } else if (g == 921 || g == 922) {
        memset(in->g92, 0, sizeof in->g92);
        if (g == 921)
            for (int i = 0; i < 6; i++)
                in->params[PARAM_G92 + i] = 0;
        in->params[PARAM_G92_ON] = 0;
    } else {
        for (int i = 0; i < 6; i++)
            in->g92[i] = in->params[PARAM_G92 + i];
        in->params[PARAM_G92_ON] = 1;
    }
    return interp_emit_offsets(in);
}

void interp_pos_platform(const struct interp *in, double plat[6])
{
    if (in->tcp_on)
        kins_tcp_to_pose(&in->tf, in->tcp_len_mm, in->pos, plat);
    else
        memcpy(plat, in->pos, 6 * sizeof *plat);
}

void interp_pos_from_platform(struct interp *in, const double plat[6])
{
    if (in->tcp_on)
        kins_tcp_from_pose(&in->tf, in->tcp_len_mm, plat, in->pos);
    else
        memcpy(in->pos, plat, sizeof in->pos);
}

/* G43.4 H: tool centre point control with tool h's length (the machine stays where it is;
 * its position is now the tip's): [KINS] TOOL_LENGTH, the reference tool's, plus the tool
 * table's Z of tool h, as G43 H shifts by it. H0, or no H with no tool in the spindle:
 * TOOL_LENGTH alone. */
static int tcp_on(struct interp *in)
{
    if (!in->have_tf)
        return interp_fail(in, INTERP_ERR_CONFIG, in->blk.gcol[8], "G43.4 (tool centre "
                           "point control) needs the machine's kinematics with its tool "
                           "([KINS] TOOL_POINT, TOOL_AXIS): give the machine's INI file");
    if (in->comp.active)
        return interp_fail(in, INTERP_ERR_MODAL, in->blk.gcol[8], "G43.4 inside a G141/G142 "
                           "run: switch tool centre point control before the run");
    int h = in->current_tool;
    if (W('h'))
        CHP(interp_to_int(in, V('h'), W('h'), "H (tool number)", &h));
    if (h < 0)
        return interp_fail(in, INTERP_ERR_WORD, W('h'), "negative H word H%d", h);
    double len = in->tf.length_mm;
    if (h > 0) {
        struct tool_entry *e = in->tt ? tooltable_find(in->tt, h) : NULL;
        if (!e)
            return interp_fail(in, INTERP_ERR_TOOL, W('h') ? W('h') : in->blk.gcol[8],
                               "G43.4 H%d: tool %d is not in the tool table", h, h);
        len += e->z_offset_mm;
    }
    double plat[6];
    interp_pos_platform(in, plat);
    memset(in->tool, 0, sizeof in->tool);
    in->tcp_on = 1;
    in->tcp_len_mm = len;
    interp_pos_from_platform(in, plat);
    return interp_emit_offsets(in);
}

/* G43 H (tool table Z), G43.1 (offsets given in the block), G43.4 (tool centre point
 * control), G49 (none). Leaving G43.4 keeps the machine where it is. */
int interp_tool_length(struct interp *in, int g)
{
    if (g == 434)
        return tcp_on(in);
    if (g == 432 && in->tcp_on)
        return interp_fail(in, INTERP_ERR_MODAL, in->blk.gcol[8], "G43.2 under G43.4: the tool "
                           "length is the tool centre point's; switch with G43.4 H instead");
    if (in->tcp_on) {
        double plat[6];
        interp_pos_platform(in, plat);
        in->tcp_on = 0;
        interp_pos_from_platform(in, plat);
    }
    if (g == 490) {
        memset(in->tool, 0, sizeof in->tool);
    } else if (g == 431) {
        for (int i = 0; i < 6; i++)
            if (W(axis_letter[i]))
                in->tool[i] = axis_mm(in, i);
    } else if (g == 432) {   /* G43.2: another tool's length, or the axis words, added */
        if (!W('h') && !any_axis(in))
            return interp_fail(in, INTERP_ERR_WORD, in->blk.gcol[8], "G43.2 needs H (the tool "
                               "whose length is added) or axis words (the offsets added)");
        if (W('h')) {
            int h;
            CHP(interp_to_int(in, V('h'), W('h'), "H (tool number)", &h));
            struct tool_entry *e = h > 0 && in->tt ? tooltable_find(in->tt, h) : NULL;
            if (h != 0 && !e)
                return interp_fail(in, INTERP_ERR_TOOL, W('h'), "G43.2 H%d: tool %d is not in "
                                   "the tool table", h, h);
            if (e)
                in->tool[AX_Z] += e->z_offset_mm;
        }
        for (int i = 0; i < 6; i++)
            if (W(axis_letter[i]))
                in->tool[i] += axis_mm(in, i);
    } else {
        int h = in->current_tool;
        if (W('h'))
            CHP(interp_to_int(in, V('h'), W('h'), "H (tool number)", &h));
        memset(in->tool, 0, sizeof in->tool);
        if (h < 0)
            return interp_fail(in, INTERP_ERR_WORD, W('h'), "negative H word H%d", h);
        if (h > 0) {
            struct tool_entry *e = in->tt ? tooltable_find(in->tt, h) : NULL;
            if (!e)
                return interp_fail(in, INTERP_ERR_TOOL, W('h') ? W('h') : in->blk.gcol[8],
                                   "G43 H%d: tool %d is not in the tool table", h, h);
            in->tool[AX_Z] = e->z_offset_mm;
        }
    }
    return interp_emit_offsets(in);
}
