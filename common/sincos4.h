/* sincos4.h: sincos3.h's series on vectors of four doubles, lane by lane the same bits.
 *
 * Code that has four poses or four path places at once (hexapod_batch.c, motion_ahead.c,
 * kins_tcp.c) computes them as vectors of four (GCC's vector extension: one AVX2 register;
 * that code is built for AVX2 alone, common/simd.h). Each operation is the scalar one of sincos3.h in the same order, and C contracts
 * none (ISO C: -ffp-contract=off), so every lane holds the bits sincos1 gives for it.
 */
#ifndef HEXCNC_SINCOS4_H
#define HEXCNC_SINCOS4_H

#include <stdint.h>

#include "common/sincos3.h"

typedef double v4d __attribute__((vector_size(32)));
typedef int64_t v4l __attribute__((vector_size(32)));

#define SPLAT(c) ((v4d){ (c), (c), (c), (c) })
/* Lane by lane: a where mask (all ones), else b. */
#define SELECT(mask, a, b) ((v4d)(((v4l)(a) & (mask)) | ((v4l)(b) & ~(mask))))

/* The series of sincos3_short and sincos3_one on a vector, Horner as written there: the
 * last five steps, from q and p at the x^11 and x^12 terms, are both series' own. */
#define SINCOS_TAIL(x, z_, q_, p_, s, c)                                                         \
    do {                                                                                         \
        q_ = q_ * z_ + 2.7557319223985893e-06, p_ = p_ * z_ + 2.7557319223985888e-07;           \
        q_ = q_ * z_ - 0.00019841269841269841, p_ = p_ * z_ - 2.4801587301587302e-05;           \
        q_ = q_ * z_ + 0.0083333333333333332, p_ = p_ * z_ + 0.0013888888888888889;             \
        q_ = q_ * z_ - 0.16666666666666666, p_ = p_ * z_ - 0.041666666666666664;                \
        q_ = q_ * z_ + 1.0, p_ = p_ * z_ + 0.5;                                                  \
        (s) = q_ * (x);                                                                          \
        (c) = 1.0 - p_ * z_;                                                                     \
    } while (0)

#define SINCOS_SHORT(x, s, c)                                                                    \
    do {                                                                                         \
        v4d z_ = (x) * (x);                                                                      \
        v4d q_ = SPLAT(-2.505210838544172e-08), p_ = SPLAT(-2.08767569878681e-09);              \
        SINCOS_TAIL(x, z_, q_, p_, s, c);                                                        \
    } while (0)

#define SINCOS_ONE(x, s, c)                                                                      \
    do {                                                                                         \
        v4d z_ = (x) * (x);                                                                      \
        v4d q_ = SPLAT(2.8114572543455206e-15), p_ = SPLAT(1.5619206968586225e-16);            \
        q_ = q_ * z_ - 7.6471637318198164e-13, p_ = p_ * z_ - 4.7794773323873853e-14;           \
        q_ = q_ * z_ + 1.6059043836821613e-10, p_ = p_ * z_ + 1.1470745597729725e-11;           \
        q_ = q_ * z_ - 2.505210838544172e-08, p_ = p_ * z_ - 2.08767569878681e-09;              \
        SINCOS_TAIL(x, z_, q_, p_, s, c);                                                        \
    } while (0)

/* sincos1 of each lane, as a mask of the lanes it could not take (beyond pi/4, or not a
 * number: those lanes' sine and cosine are left undefined). */
#define SINCOS_LANES(x, s, c, bad)                                                               \
    do {                                                                                         \
        v4d m_ = (v4d)((v4l)(x) & INT64_MAX);  /* |x| */                                        \
        v4l short_ = m_ <= SINCOS3_SHORT_RAD;                                                    \
        (bad) |= ~(m_ <= SINCOS3_FAST_RAD);                                                      \
        SINCOS_SHORT(x, s, c);                                                                   \
        if (!(short_[0] & short_[1] & short_[2] & short_[3])) {                                  \
            v4d s1_, c1_;                                                                        \
            SINCOS_ONE(x, s1_, c1_);                                                             \
            (s) = SELECT(short_, s, s1_);                                                        \
            (c) = SELECT(short_, c, c1_);                                                        \
        }                                                                                        \
    } while (0)

#endif
