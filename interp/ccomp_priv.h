/* ccomp_priv.h: what the G41/G42 files share (queue, plane axes, LinuxCNC's constants). */
#ifndef HEXCNC_CCOMP_PRIV_H
#define HEXCNC_CCOMP_PRIV_H

#include "interp/ccomp.h"
#include "interp/interp_int.h"

/* pi in long double: LinuxCNC adds its angles in long double (M_PIl), and the last bit of an
 * offset point depends on it, so the same sums are made here. */
#define CC_PI_L 3.141592653589793238462643383279502884L
#define CC_PI_2L (CC_PI_L / 2)
/* Angles (rad) below which two directions count as one: a corner needs no arc (LinuxCNC's
 * TOLERANCE_CONCAVE_CORNER). */
#define CC_SMALL_RAD 0.05
/* LinuxCNC's TOLERANCE_EQUAL. */
#define CC_EQUAL 0.0001

/* Tool inside the arc: left of a counter-clockwise arc or right of a clockwise one. */
#define CC_INSIDE(side, turn) \
    (((side) == CCOMP_LEFT && (turn) > 0) || ((side) == CCOMP_RIGHT && (turn) < 0))

void ccomp_axes(const struct interp *in, int ax[3]);
double ccomp_machine(const struct interp *in, int i, double v);
int ccomp_push_line(struct interp *in, int move, double dx, double dy, double x, double y,
                    double z, const double end6[6]);
int ccomp_push_arc(struct interp *in, double sweep_rad, double x, double y, double cx, double cy,
                   int turn, double z, const double end6[6]);
double ccomp_sweep(double x1, double y1, double cx, double cy, int turn, double x2, double y2);
int ccomp_dequeue(struct interp *in);
void ccomp_set_endpoint(struct interp *in, double x, double y);
int ccomp_move_endpoint_and_flush(struct interp *in, double x, double y);
/* The block's programmed point in plane order (program units, offsets removed). */
void ccomp_prog_point(struct interp *in, double p[3]);
/* The entry move starts where the program stands: that point, in plane order, into cc.cur. */
void ccomp_take_position(struct interp *in);

#endif
