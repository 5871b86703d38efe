/* ccomp.c: G40/G41/G42/G41.1/G42.1 and compensated straight moves (LinuxCNC's algorithm). */
#include <math.h>
#include <string.h>

#include "interp/ccomp_priv.h"
#include "interp/tooltable.h"

#define W(c) (in->blk.col[(c) - 'a'])
#define V(c) (in->blk.val[(c) - 'a'])

void ccomp_prog_point(struct interp *in, double p[3])
{
    static const char letter[6] = {'x', 'y', 'z', 'a', 'b', 'c'};
    double cur[6];
    int ax[3];
    interp_prog_pos(in, cur);
    ccomp_axes(in, ax);
    for (int i = 0; i < 3; i++) {
        int a = ax[i];
        char w = letter[a];
        /* after the entry move, from the programmed point as it was computed (in->pos in
         * mm and back is not always the same last bit in inches) */
        double from = ccomp_active(in) && !in->cc.first ? in->cc.prog[i] : cur[a];
        if (!W(w))
            p[i] = from;
        else if (in->incremental && !(a < 2 && in->blk.polar_inc))
            p[i] = from + V(w);
        else
            p[i] = V(w);
    }
}

int ccomp_start(const struct interp *in, double s[2])
{
    if (!ccomp_active(in) || in->cc.first)
        return 0;
    s[0] = in->cc.prog[0], s[1] = in->cc.prog[1];
    return 1;
}

/* The radius (program units) G41/G42 D<tool> take: half the tool's diameter (with its wear),
 * as LinuxCNC; a negative one swaps the side. D absent or D0: the tool in the spindle. */
static int tool_radius(struct interp *in, int g, double *r)
{
    int t = in->current_tool, col = W('d') ? W('d') : in->blk.gcol[7];
    if (W('d')) {
        CHP(interp_to_int(in, V('d'), W('d'), "D (tool number)", &t));
        if (t < 0)
            return interp_fail(in, INTERP_ERR_WORD, col, "G%d D%d: tool numbers are 0 or more",
                               g / 10, t);
    }
    *r = 0.0;
    int spindle = t == 0 || !W('d');
    if (t == 0)     /* D0 is the tool in the spindle too, as in LinuxCNC */
        t = in->current_tool;
    if (t == 0)
        return 0;   /* no tool in the spindle: LinuxCNC's empty spindle has diameter 0 */
    if (!in->tt)
        return interp_fail(in, INTERP_ERR_TOOL, col, "G%d: the radius of tool %d%s comes from "
                           "the tool table, and there is none (give one with -t or [EMCIO] "
                           "TOOL_TABLE), or give the diameter with G%d.1 D<diameter>", g / 10, t,
                           spindle ? " (in the spindle)" : "", g / 10);
    const struct tool_entry *e = tooltable_find(in->tt, t);
    if (!e)
        return interp_fail(in, INTERP_ERR_TOOL, col, "G%d: tool %d is not in the tool table%s%s",
                           g / 10, t, in->tt->path[0] ? " " : "", in->tt->path);
    if (e->duplicate_line)
        return interp_fail(in, INTERP_ERR_TOOL, col, "G%d: tool %d: %s", g / 10, t,
                           tooltable_strerror(TOOLTABLE_ERR_DUPLICATE));
    double d = e->diameter_mm + e->wear_mm;
    *r = (in->inch ? d / MM_PER_INCH : d) / 2.0;
    return 0;
}

/* G41/G42 (g 410/420) or G41.1/G42.1 (411/421): the side and the radius. */
static int comp_on(struct interp *in, int g)
{
    struct ccomp *cc = &in->cc;
    int col = in->blk.gcol[7], code = g / 10;
    char nm[8];
    double r;
    ccomp_name(nm, g);
    if (in->mdi)
        return interp_fail(in, INTERP_ERR_UNSUPPORTED, col, "%s in MDI: cutter compensation "
                           "places each corner when the next move is known; run it in a "
                           "program", nm);
    if (in->plane == 19)
        return interp_fail(in, INTERP_ERR_CCOMP, col, "%s in the YZ plane (G19): cutter "
                           "compensation works in the XY (G17) and XZ (G18) planes only", nm);
    if (cc->side != CCOMP_OFF)
        return interp_fail(in, INTERP_ERR_CCOMP, col, "%s: cutter compensation is already on "
                           "(%s); turn it off with G40 first", nm, cc->name);
    if (g == 411 || g == 421) {
        if (!W('d'))
            return interp_fail(in, INTERP_ERR_WORD, col, "%s needs a D word: the tool "
                               "diameter", nm);
        if (W('l') && V('l') != 0 && V('l') != 9)
            return interp_fail(in, INTERP_ERR_UNSUPPORTED, W('l'), "%s L%g is a lathe tool "
                               "orientation: a hexapod has no turning spindle axis to run it",
                               nm, V('l'));
        r = V('d') / 2;
    } else {
        CHP(tool_radius(in, g, &r));
    }
    cc->side = code == 41 ? CCOMP_LEFT : CCOMP_RIGHT;
    if (r < 0.0) {  /* a negative diameter: the other side (LinuxCNC) */
        r = -r;
        cc->side = cc->side == CCOMP_LEFT ? CCOMP_RIGHT : CCOMP_LEFT;
    }
    memcpy(cc->name, nm, sizeof nm);
    cc->radius = r;
    cc->first = 1;
    return 0;
}

int ccomp_mode(struct interp *in, int g)
{
    struct ccomp *cc = &in->cc;
    if (g != 400)
        return comp_on(in, g);
    if (cc->side != CCOMP_OFF && cc->radius > 0.0 && !cc->first) {
        /* the last move ends where it was placed; the next one starts from there to its
         * programmed point; in->pos is the programmed point already (as LinuxCNC's
         * interpreter keeps it, until a tool change reads back where the tool is:
         * ccomp_tool_change) */
        cc->sent_valid = 0;
        CHP(ccomp_flush(in));
        cc->resync = cc->sent_valid;
        cc->arc_not_allowed = 1;
    }
    cc->side = CCOMP_OFF;
    cc->first = 1;
    return 0;
}

void ccomp_tool_change(struct interp *in)
{
    struct ccomp *cc = &in->cc;
    if (cc->resync) {
        int ax[3];
        ccomp_axes(in, ax);
        in->pos[ax[0]] = cc->sent_end[ax[0]];
        in->pos[ax[1]] = cc->sent_end[ax[1]];
    }
    cc->resync = 0;
}

/* The error for code `what` (at column col) while compensation is on. */
static int refuse(struct interp *in, int col, const char *what)
{
    return interp_fail(in, INTERP_ERR_CCOMP, col, "%s while cutter compensation (%s) is on: "
                       "turn it off with G40 first", what, in->cc.name);
}

/* Codes executed before G40/G41/G42 in LinuxCNC's order see the state before the block. */
static int check_before(struct interp *in)
{
    const struct interp_block *b = &in->blk;
    if (b->g[2] >= 0 && b->g[2] / 10 != in->plane)
        return refuse(in, b->gcol[2], "a change of plane");
    if (b->m[6] == 6)
        return refuse(in, b->mcol[6], "a tool change (M6)");
    if (b->m[9] == 72 && in->m70.valid &&
        (in->m70.plane != in->plane || in->m70.coord_system != in->coord_system ||
         memcmp(in->m70.tool, in->tool, sizeof in->tool)))
        return refuse(in, b->mcol[9], "M72 restoring another plane, coordinate system or "
                      "tool length offset");
    if (b->m[5] >= 62 && b->m[5] <= 68)
        return refuse(in, b->mcol[5], b->m[5] == 66 ? "waiting on an input (M66)"
                                                   : "setting an output (M62..M65, M67, M68)");
    return 0;
}

/* Codes executed after G40/G41/G42 see the state the block leaves. */
static int check_after(struct interp *in)
{
    const struct interp_block *b = &in->blk;
    int g0 = b->g[0], m = b->g[1] >= 0 ? b->g[1] : in->motion;
    int axis = W('x') || W('y') || W('z') || W('a') || W('b') || W('c');
    if (b->g[8] >= 0)
        return refuse(in, b->gcol[8], "a tool length offset change (G43/G49)");
    if (b->g[12] >= 0)
        return refuse(in, b->gcol[12], "a change of coordinate system (G54..G59.3)");
    if (b->g[13] >= 0)
        return refuse(in, b->gcol[13], "a change of path mode (G61/G64)");
    if (b->g[10] >= 0)
        return refuse(in, b->gcol[10], "a change of canned cycle retract mode (G98/G99)");
    if (g0 == 530)
        return refuse(in, b->gcol[0], "a move in machine coordinates (G53)");
    if (g0 == 280 || g0 == 300 || g0 == 281 || g0 == 301)
        return refuse(in, b->gcol[0], "G28/G30 (or G28.1/G30.1)");
    if ((g0 >= 920 && g0 <= 923) || g0 == 520)
        return refuse(in, b->gcol[0], "a change of axis offsets (G52, G92..G92.3)");
    if (g0 == 1410 || g0 == 1420)
        return refuse(in, b->gcol[0], "five-axis compensation G141/G142 (one compensation at "
                      "a time)");
    if (g0 == 100 && W('l') && (V('l') == 2 || V('l') == 20) && W('p') &&
        (V('p') == 0 || V('p') == in->coord_system))
        return refuse(in, b->gcol[0], "a change of the coordinate system in use (G10 L2/L20)");
    if (g0 < 0 && axis && (m == 730 || (m >= 810 && m <= 890)))
        return refuse(in, b->g[1] >= 0 ? b->gcol[1] : 0, "a canned cycle");
    if (g0 < 0 && m == 51 && (axis || W('i') || W('j')))
        return refuse(in, b->g[1] >= 0 ? b->gcol[1] : 0, "a spline (G5.1)");
    return 0;
}

int ccomp_check_block(struct interp *in)
{
    const struct interp_block *b = &in->blk;
    int g7 = b->g[7];
    char nm[8];
    if (g7 >= 410 && (b->g[0] == 1410 || b->g[0] == 1420)) {
        ccomp_name(nm, g7);
        return interp_fail(in, INTERP_ERR_CCOMP, b->gcol[0], "%s and G%d in one block: "
                           "cutter compensation G41/G42 and five-axis compensation G141/G142 "
                           "cannot be used together", nm, b->g[0] / 10);
    }
    if (in->cc.side != CCOMP_OFF)
        CHP(check_before(in));
    if (g7 >= 0 ? g7 != 400 : in->cc.side != CCOMP_OFF) {
        if (in->cc.side == CCOMP_OFF)
            ccomp_name(in->cc.name, g7);  /* for the message: the code that turns it on */
        CHP(check_after(in));
    }
    return 0;
}

/* The entry move: from where the tool is to the point a radius beside the programmed end,
 * square to the move (LinuxCNC's convert_straight_comp1). */
static int straight_first(struct interp *in, int move, const double p[3], const double end6[6])
{
    struct ccomp *cc = &in->cc;
    double cx = cc->cur[0], cy = cc->cur[1];
    double dist = hypot(p[0] - cx, p[1] - cy);
    const char *u = in->inch ? "in" : "mm";
    if (dist <= cc->radius)
        return interp_fail(in, INTERP_ERR_CCOMP, in->blk.g[1] >= 0 ? in->blk.gcol[1] : 0,
                           "%s entry move is %.4f %s long in the plane: it must be longer "
                           "than the tool radius %.4f %s", cc->name, dist, u, cc->radius, u);
    double a = (double)(atan2(p[1] - cy, p[0] - cx) +
                        (cc->side == CCOMP_LEFT ? CC_PI_L / 2. : -CC_PI_L / 2.));
    double ex = p[0] + cc->radius * cos(a), ey = p[1] + cc->radius * sin(a);
    ccomp_set_endpoint(in, cx, cy);
    CHP(ccomp_push_line(in, move, cos(a), sin(a), ex, ey, p[2], end6));
    cc->first = 0;
    cc->cur[0] = ex, cc->cur[1] = ey, cc->cur[2] = p[2];
    return 0;
}

/* An inside corner after a queued arc: where the arc, offset, meets this line offset. */
static int arc_line_corner(struct interp *in, const double p[3], double *mx, double *my)
{
    struct ccomp *cc = &in->cc;
    const struct ccomp_item *prev = &cc->q[0];
    double op0 = cc->prog[0], op1 = cc->prog[1], r = cc->radius;
    double oldrad = hypot(prev->center[1] - prev->end[1], prev->center[0] - prev->end[0]);
    double base = atan2(p[1] - op1, p[0] - op0);
    double th = prev->turn > 0 ? (double)(base + CC_PI_2L) : (double)(base - CC_PI_2L);
    double phi = atan2(prev->center[1] - op1, prev->center[0] - op0);
    int inside = CC_INSIDE(cc->side, prev->turn);
    double uncomp = inside ? oldrad + r : oldrad - r;
    double d = uncomp * cos(th - phi);  /* arc centre to the programmed line */
    double l = (inside ? d - r : d + r) / oldrad, ang;
    if (l > 1.0 || l < -1.0)
        return interp_fail(in, INTERP_ERR_CCOMP, 0, "%s: the arc of line %d and this line "
                           "make an inside corner the tool (radius %.4f %s) cannot fit in "
                           "without gouging", cc->name, prev->cmd.line, r,
                           in->inch ? "in" : "mm");
    if ((prev->turn > 0) == inside)
        ang = (double)(-acos(l) + th + CC_PI_L);
    else
        ang = (double)(acos(l) + th + CC_PI_L);
    *mx = prev->center[0] + oldrad * cos(ang);
    *my = prev->center[1] + oldrad * sin(ang);
    return 0;
}

/* The corner between the queued move and this line (LinuxCNC's convert_straight_comp2): an
 * arc of the tool radius about the programmed corner outside, the meeting point inside. */
static int line_corner(struct interp *in, int move, const double p[3], const double end6[6],
                       double *ex, double *ey)
{
    struct ccomp *cc = &in->cc;
    double cx = cc->cur[0], cy = cc->cur[1], op0 = cc->prog[0], op1 = cc->prog[1];
    double r = cc->radius, beta, gamma, mx, my;
    double theta = atan2(cy - op1, cx - op0), alpha = atan2(p[1] - op1, p[0] - op0);
    if (cc->side == CCOMP_LEFT) {
        if (theta < alpha)
            theta = (double)(theta + 2 * CC_PI_L);
        beta = (double)((theta - alpha) - CC_PI_2L);
        gamma = M_PI_2;
    } else {
        if (alpha < theta)
            alpha = (double)(alpha + 2 * CC_PI_L);
        beta = (double)((alpha - theta) - CC_PI_2L);
        gamma = -M_PI_2;
    }
    *ex = p[0] + r * cos(alpha + gamma);
    *ey = p[1] + r * sin(alpha + gamma);
    mx = op0 + r * cos(alpha + gamma);
    my = op1 + r * sin(alpha + gamma);
    int front_arc = cc->n > 0 && cc->q[0].move == 2;
    int concave = beta < -CC_SMALL_RAD || beta > CC_PI_L + CC_SMALL_RAD;
    /* an "h": over the round top, then down beside the stem: stay outside the stem */
    if (!concave && beta > CC_PI_L - CC_SMALL_RAD && front_arc &&
        ((cc->side == CCOMP_RIGHT && cc->q[0].turn > 0) ||
         (cc->side == CCOMP_LEFT && cc->q[0].turn < 0)))
        concave = 1;
    if (!concave && beta > CC_SMALL_RAD) {  /* outside corner: an arc around it */
        CHP(ccomp_move_endpoint_and_flush(in, cx, cy));
        if (move == 0)  /* no rapid arc: a straight rapid to the arc's end */
            CHP(ccomp_push_line(in, 0, 0.0, 0.0, mx, my, cc->cur[2], end6));
        else
            CHP(ccomp_push_arc(in, 0.0, mx, my, op0, op1, cc->side == CCOMP_LEFT ? -1 : 1,
                               cc->cur[2], end6));
        CHP(ccomp_dequeue(in));
        ccomp_set_endpoint(in, mx, my);
    } else if (concave && !front_arc) {     /* inside corner after a line */
        double half = (double)((beta + CC_PI_L) / 2.0);
        if (half == 0.0)
            return interp_fail(in, INTERP_ERR_CCOMP, 0, "%s: a zero-degree inside corner "
                               "(the path turns straight back) cannot be compensated",
                               cc->name);
        double back = r / tan(half);
        mx = cx + back * cos(theta + gamma);
        my = cy + back * sin(theta + gamma);
        CHP(ccomp_move_endpoint_and_flush(in, mx, my));
    } else if (concave) {                   /* inside corner after an arc */
        CHP(arc_line_corner(in, p, &mx, &my));
        CHP(ccomp_move_endpoint_and_flush(in, mx, my));
    } else {                                /* straight on, or tangent */
        CHP(ccomp_dequeue(in));
        ccomp_set_endpoint(in, cx, cy);
    }
    return 0;
}

void ccomp_take_position(struct interp *in)
{
    double cur[6];
    int ax[3];
    interp_prog_pos(in, cur);
    ccomp_axes(in, ax);
    for (int i = 0; i < 3; i++)
        in->cc.cur[i] = cur[ax[i]];
}

int ccomp_straight(struct interp *in, int move, const double end6[6])
{
    struct ccomp *cc = &in->cc;
    double p[3], ex, ey;
    ccomp_prog_point(in, p);
    if (cc->first) {
        ccomp_take_position(in);
        CHP(straight_first(in, move, p, end6));
    } else if (p[0] == cc->prog[0] && p[1] == cc->prog[1]) {
        /* no motion in the plane: the tool stays beside the programmed point */
        CHP(ccomp_push_line(in, move, p[0] - cc->prog[0], p[1] - cc->prog[1], cc->cur[0],
                            cc->cur[1], p[2], end6));
        cc->cur[2] = p[2];
    } else {
        CHP(line_corner(in, move, p, end6, &ex, &ey));
        CHP(ccomp_push_line(in, move, p[0] - cc->prog[0], p[1] - cc->prog[1], ex, ey, p[2],
                            end6));
        cc->cur[0] = ex, cc->cur[1] = ey, cc->cur[2] = p[2];
    }
    memcpy(cc->prog, p, sizeof cc->prog);
    memcpy(in->pos, end6, sizeof in->pos);  /* the programmed point: G91 and the next
                                             * corner start from it, as in LinuxCNC */
    return 0;
}
