// kins_svd.cpp: condition numbers by Eigen's JacobiSVD, behind a C API for the plugins.
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "kins/kins_svd.h"

// Condition number through the singular values; exact for the small Jacobians used here.
extern "C" int kins_svd_condition(const double *m, int rows, int cols, double *cond)
{
    if (!m || !cond || rows < 1 || rows > 9 || cols < 1 || cols > 9)
        return -1;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor, 9, 9> a(rows, cols);
    for (int r = 0; r < rows; r++)
        for (int c = 0; c < cols; c++) {
            double v = m[r * cols + c];
            if (!std::isfinite(v))
                return -1;
            a(r, c) = v;
        }
    Eigen::JacobiSVD<decltype(a)> svd(a);
    const auto &s = svd.singularValues();
    double smax = s(0);
    double smin = s(s.size() - 1);
    if (smin <= smax * std::numeric_limits<double>::epsilon())
        *cond = std::numeric_limits<double>::infinity();
    else
        *cond = smax / smin;
    return 0;
}
