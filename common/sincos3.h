/* sincos3.h: sines and cosines of the small angles of a pose's rotation and of arcs.
 *
 * The servo pass evaluates the platform's rotation every period, and the C library's
 * sincos() (about 15 ns each, one angle at a time, with its range reduction) was a tenth of
 * `hexcnc check`'s time. Orientation angles of a hexapod lie well within +-45 deg, where no
 * range reduction is needed: there the Taylor series of sin through x^17 and of cos through
 * x^18 leave out less than 1e-19 (the next terms, (pi/4)^19/19! and (pi/4)^20/20!), so the
 * result differs from sincos() by rounding only (test_kins_shortcuts finds at most 1 ulp
 * over the range). Within +-0.25 rad a shorter series does. Any angle beyond +-pi/4 (or not
 * finite) takes the C library's sincos().
 */
#ifndef HEXCNC_SINCOS3_H
#define HEXCNC_SINCOS3_H

#include <math.h>

#define SINCOS3_FAST_RAD 0.78539816339744828  /* pi/4: the polynomial's range */
#define SINCOS3_SHORT_RAD 0.25                 /* the shorter polynomial's */

/* sin x and cos x for |x| <= pi/4: sin x = x Q(x^2), cos x = 1 - x^2 P(x^2), with the
 * series' terms (-1)^k / (2k+1)! and (-1)^k / (2k+2)! (Horner, written out: three calls
 * side by side are independent chains the processor overlaps). */
static inline void sincos3_one(double x, double *s, double *c)
{
    double z = x * x;
    double q = 2.8114572543455206e-15, p = 1.5619206968586225e-16;
    q = q * z - 7.6471637318198164e-13, p = p * z - 4.7794773323873853e-14;
    q = q * z + 1.6059043836821613e-10, p = p * z + 1.1470745597729725e-11;
    q = q * z - 2.505210838544172e-08, p = p * z - 2.08767569878681e-09;
    q = q * z + 2.7557319223985893e-06, p = p * z + 2.7557319223985888e-07;
    q = q * z - 0.00019841269841269841, p = p * z - 2.4801587301587302e-05;
    q = q * z + 0.0083333333333333332, p = p * z + 0.0013888888888888889;
    q = q * z - 0.16666666666666666, p = p * z - 0.041666666666666664;
    q = q * z + 1.0, p = p * z + 0.5;
    *s = q * x;
    *c = 1.0 - p * z;
}

/* The same within +-0.25 rad (14 deg), where the series through x^11 and x^12 leave out
 * less than 1e-17 of the value: a third fewer steps for the common pose. */
static inline void sincos3_short(double x, double *s, double *c)
{
    double z = x * x;
    double q = -2.505210838544172e-08, p = -2.08767569878681e-09;
    q = q * z + 2.7557319223985893e-06, p = p * z + 2.7557319223985888e-07;
    q = q * z - 0.00019841269841269841, p = p * z - 2.4801587301587302e-05;
    q = q * z + 0.0083333333333333332, p = p * z + 0.0013888888888888889;
    q = q * z - 0.16666666666666666, p = p * z - 0.041666666666666664;
    q = q * z + 1.0, p = p * z + 0.5;
    *s = q * x;
    *c = 1.0 - p * z;
}

/* sin x and cos x for any x: a series within +-pi/4 (an angle of a pose, or of an arc on a
 * blend arc or a short arc), the C library beyond. */
static inline void sincos1(double x, double *s, double *c)
{
    double m = fabs(x);
    if (m <= SINCOS3_SHORT_RAD)
        sincos3_short(x, s, c);
    else if (m <= SINCOS3_FAST_RAD)
        sincos3_one(x, s, c);
    else
        sincos(x, s, c);
}

/* s[i] = sin(x[i]), c[i] = cos(x[i]) for i < 3 (three independent chains, which the
 * processor runs side by side). */
static inline void sincos3(const double x[3], double s[3], double c[3])
{
    sincos1(x[0], &s[0], &c[0]);
    sincos1(x[1], &s[1], &c[1]);
    sincos1(x[2], &s[2], &c[2]);
}

#endif
