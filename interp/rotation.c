/* rotation.c: G10 L2 R, the rotation of a coordinate system about Z, and the conversions
 * between program and machine coordinates it enters, in LinuxCNC's order. */
#include <math.h>
#include <string.h>

#include "interp/interp_int.h"

#define W(c) (in->blk.col[(c) - 'a'])
#define V(c) (in->blk.val[(c) - 'a'])

/*
 * LinuxCNC's frames, X and Y (Z, A, B, C are not rotated):
 *
 *     machine = R(rot) (program + G92) + G5x offset + tool offset
 *
 * R(rot) turns counter-clockwise by rot degrees about Z. The G92/G52 offset is measured in
 * the rotated frame; the work offset and the tool offset are not rotated (the rotation is
 * about the work offset's origin). rot is the active system's #5210+20n (#5230 for G54).
 */

/* (x, y) turned by deg degrees counter-clockwise, as LinuxCNC turns it. */
void interp_rotate_xy(double *x, double *y, double deg)
{
    double t = deg * (M_PI / 180.0);
    double xx = *x * cos(t) - *y * sin(t);
    double yy = *x * sin(t) + *y * cos(t);
    *x = xx;
    *y = yy;
}

/* The machine X Y (mm) of program X Y (program units) under the active rotation. */
void interp_xy_to_machine(const struct interp *in, double px, double py, double m[2])
{
    double x = interp_len_mm(in, px) + in->g92[AX_X], y = interp_len_mm(in, py) + in->g92[AX_Y];
    interp_rotate_xy(&x, &y, in->rot_deg);
    m[0] = x + in->g5x[AX_X] + in->tool[AX_X];
    m[1] = y + in->g5x[AX_Y] + in->tool[AX_Y];
}

/* The current point in the rotated frame, mm: program X Y plus the G92 offset. */
void interp_rotated_pos(const struct interp *in, double q[2])
{
    q[0] = in->pos[AX_X] - in->g5x[AX_X] - in->tool[AX_X];
    q[1] = in->pos[AX_Y] - in->g5x[AX_Y] - in->tool[AX_Y];
    interp_rotate_xy(&q[0], &q[1], -in->rot_deg);
}

/* Machine pose to program coordinates, offsets and the rotation removed, inch programs in
 * inches (G38's #5061.. from the pose where the probe stopped). */
void interp_machine_to_program(const struct interp *in, const double m[6], double out[6])
{
    struct interp_view v;
    memset(&v, 0, sizeof v);
    memcpy(v.g5x_mm, in->g5x, sizeof v.g5x_mm);
    memcpy(v.g92_mm, in->g92, sizeof v.g92_mm);
    memcpy(v.tool_mm, in->tool, sizeof v.tool_mm);
    v.xy_rotation_deg = in->rot_deg;
    v.inch = in->inch;
    interp_view_to_program(&v, m, out);
}

/* Machine pose to program coordinates of a view (printers, displays): offsets and the
 * rotation removed, inch programs in inches. */
void interp_view_to_program(const struct interp_view *v, const double m[6], double out[6])
{
    for (int i = 0; i < 6; i++)
        out[i] = m[i] - v->g5x_mm[i] - v->g92_mm[i] - v->tool_mm[i];
    if (v->xy_rotation_deg != 0.0) {
        double x = m[AX_X] - v->g5x_mm[AX_X] - v->tool_mm[AX_X];
        double y = m[AX_Y] - v->g5x_mm[AX_Y] - v->tool_mm[AX_Y];
        interp_rotate_xy(&x, &y, -v->xy_rotation_deg);
        out[AX_X] = x - v->g92_mm[AX_X];
        out[AX_Y] = y - v->g92_mm[AX_Y];
    }
    if (v->inch)
        for (int i = 0; i < 3; i++)
            out[i] /= MM_PER_INCH;
}

/* The current point in coordinate system sys (1..9) without the tool offset, mm, X and Y:
 * LinuxCNC's find_current_in_system, with the system's rotation as stored now. */
static void current_in_system(const struct interp *in, int sys, double c[2])
{
    int base = PARAM_G54 + 20 * (sys - 1);
    int g92 = in->params[PARAM_G92_ON] != 0.0;
    c[0] = in->pos[AX_X] - in->tool[AX_X] - in->params[base + AX_X];
    c[1] = in->pos[AX_Y] - in->tool[AX_Y] - in->params[base + AX_Y];
    interp_rotate_xy(&c[0], &c[1], -in->params[base + PARAM_ROT]);
    if (g92) {
        c[0] -= in->params[PARAM_G92 + AX_X];
        c[1] -= in->params[PARAM_G92 + AX_Y];
    }
}

/*
 * G10 L2 / L20 on X and Y when a rotation is involved (sys's, or the active one). L2 R sets
 * the rotation (#5210+20n) and X Y the offset as given; L20 (which takes no R) sets the
 * offset so the current point reads X Y in the system's rotated frame. Other axes are the
 * caller's. When sys is the active system, the current point is carried into the new frame
 * as LinuxCNC carries it: turned back by the old rotation, shifted by the change of offset,
 * turned by the new one, all without the G92 offset; with a G92 offset in force and the
 * rotation changed that is not where the machine is, and the next move starts from the
 * point LinuxCNC's interpreter believes in, as its motion then does.
 */
void interp_g10_rotated(struct interp *in, int l, int sys)
{
    int base = PARAM_G54 + 20 * (sys - 1);
    double c[2], prog[6];
    current_in_system(in, sys, c);
    interp_prog_pos(in, prog);     /* the active system's program point, before */
    if (W('r'))
        in->params[base + PARAM_ROT] = V('r');
    double r = in->params[base + PARAM_ROT];
    if (l == 20) {
        double x = W('x') ? interp_len_mm(in, V('x')) : c[0];
        double y = W('y') ? interp_len_mm(in, V('y')) : c[1];
        interp_rotate_xy(&c[0], &c[1], r);
        interp_rotate_xy(&x, &y, r);
        in->params[base + AX_X] = c[0] + in->params[base + AX_X] - x;
        in->params[base + AX_Y] = c[1] + in->params[base + AX_Y] - y;
    } else {
        if (W('x'))
            in->params[base + AX_X] = interp_len_mm(in, V('x'));
        if (W('y'))
            in->params[base + AX_Y] = interp_len_mm(in, V('y'));
    }
    if (sys != in->coord_system)
        return;
    double x = interp_len_mm(in, prog[AX_X]), y = interp_len_mm(in, prog[AX_Y]);
    interp_rotate_xy(&x, &y, in->rot_deg);
    x += in->g5x[AX_X] - in->params[base + AX_X];
    y += in->g5x[AX_Y] - in->params[base + AX_Y];
    interp_rotate_xy(&x, &y, -r);
    double off_x = in->g5x[AX_X], off_y = in->g5x[AX_Y];
    in->g5x[AX_X] = in->params[base + AX_X];
    in->g5x[AX_Y] = in->params[base + AX_Y];
    in->rot_deg = r;
    double m[2];
    x = in->inch ? x / MM_PER_INCH : x;
    y = in->inch ? y / MM_PER_INCH : y;
    interp_xy_to_machine(in, x, y, m);
    in->pos[AX_X] = m[0];
    in->pos[AX_Y] = m[1];
    in->g5x[AX_X] = off_x, in->g5x[AX_Y] = off_y;  /* the caller selects the system */
}

/* G28/G30 with one of X and Y under a rotation: LinuxCNC takes the home's program X (or Y)
 * and keeps the current program Y (or X), in the rotated frame, so both machine axes move.
 * base is the home's first parameter; t[0..1] gets the machine X Y. */
void interp_home_rotated(const struct interp *in, int base, double t[2])
{
    double hx = in->params[base + AX_X] - in->g5x[AX_X] - in->tool[AX_X];
    double hy = in->params[base + AX_Y] - in->g5x[AX_Y] - in->tool[AX_Y];
    interp_rotate_xy(&hx, &hy, -in->rot_deg);
    double home[2] = { hx - in->g92[AX_X], hy - in->g92[AX_Y] }, cur[6];
    interp_prog_pos(in, cur);
    if (in->inch)
        home[0] /= MM_PER_INCH, home[1] /= MM_PER_INCH;
    double p[2] = { W('x') ? home[0] : cur[AX_X], W('y') ? home[1] : cur[AX_Y] };
    interp_xy_to_machine(in, p[0], p[1], t);
}
