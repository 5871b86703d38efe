// kins_svd.cpp: condition numbers of small matrices (Eigen), behind a C API for the plugins.
#include <cmath>
#include <limits>

// GCC 12 warns of a "maybe uninitialized" temporary inside Eigen 3.4's tridiagonalization
// (SelfadjointMatrixVector.h), a false positive in the library's code, not in this file's.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <Eigen/Dense>

#include "kins/kins_svd.h"

namespace {

using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor, 9, 9>;

// Beyond this estimate the Gram matrix's eigenvalues have lost too many digits (their
// relative error grows as eps * cond^2: 1e-8 here) and the singular values are computed.
constexpr double GRAM_TRUSTED = 1e4;

// Largest and smallest singular value by Jacobi SVD, and their ratio: exact, about 6 us for
// a 6 x 6.
void by_svd(const Small &a, double *smax, double *smin, double *cond)
{
    Eigen::JacobiSVD<Small> svd(a);
    const auto &s = svd.singularValues();
    *smax = s(0), *smin = s(s.size() - 1);
    if (*smin <= *smax * std::numeric_limits<double>::epsilon())
        *cond = std::numeric_limits<double>::infinity();
    else
        *cond = *smax / *smin;
}

// Condition from the Gram matrix's extreme eigenvalues (their square roots are the extreme
// singular values): a third of the SVD's time. Nothing when it cannot be trusted (returns
// false): the estimate passes GRAM_TRUSTED, or the solver failed.
bool by_gram(const Eigen::Matrix<double, 6, 6, Eigen::RowMajor> &a, double *smax,
             double *smin, double *cond)
{
    Eigen::Matrix<double, 6, 6> g = a.transpose() * a;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(g, Eigen::EigenvaluesOnly);
    const auto &l = eig.eigenvalues();   // ascending
    double lmax = l(5), lmin = l(0);
    if (eig.info() != Eigen::Success || !(lmin > 0) || !(lmax < lmin * GRAM_TRUSTED * GRAM_TRUSTED))
        return false;
    *cond = std::sqrt(lmax / lmin);
    *smax = std::sqrt(lmax), *smin = std::sqrt(lmin);
    return true;
}

}  // namespace

// The hexapods' 6 x 6 Jacobians go by the Gram matrix, which the SVD checks where the
// estimate says the matrix is ill-conditioned; other sizes by the SVD alone.
extern "C" int kins_svd_extremes(const double *m, int rows, int cols, double *smax,
                                 double *smin, double *cond)
{
    if (!m || !cond || !smax || !smin || rows < 1 || rows > 9 || cols < 1 || cols > 9)
        return -1;
    for (int i = 0; i < rows * cols; i++)
        if (!std::isfinite(m[i]))
            return -1;
    if (rows == 6 && cols == 6 &&
        by_gram(Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(m), smax, smin,
                cond))
        return 0;
    Small a(rows, cols);
    for (int r = 0; r < rows; r++)
        for (int c = 0; c < cols; c++)
            a(r, c) = m[r * cols + c];
    by_svd(a, smax, smin, cond);
    return 0;
}

extern "C" int kins_svd_condition(const double *m, int rows, int cols, double *cond)
{
    double smax, smin;
    return kins_svd_extremes(m, rows, cols, &smax, &smin, cond);
}
