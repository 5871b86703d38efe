/* kins_svd.h: C API to the singular values of a small matrix (Eigen, in kins_svd.cpp). */
#ifndef HEXCNC_KINS_SVD_H
#define HEXCNC_KINS_SVD_H

#ifdef __cplusplus
extern "C" {
#endif

/* Condition number (largest / smallest singular value) of the rows x cols matrix m, stored
 * row by row; rows, cols in 1..9. Writes +inf when the smallest singular value is zero.
 * Returns 0, or -1 on a bad size or a non-finite entry. About 2 us for a 6 x 6 (from the
 * Gram matrix; relative error below 1e-8, the SVD where the condition passes 1e4). Not for
 * the servo hot path. */
int kins_svd_condition(const double *m, int rows, int cols, double *cond);
/* The same, with the largest and smallest singular values (cond is the same bits as
 * kins_svd_condition's). By Weyl's inequality a singular value of m + E lies within the
 * spectral norm of E (at most its Frobenius norm) of m's: what a caller bounds the
 * condition number of a nearby matrix with. */
int kins_svd_extremes(const double *m, int rows, int cols, double *smax, double *smin,
                      double *cond);

#ifdef __cplusplus
}
#endif

#endif
