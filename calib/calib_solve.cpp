// calib_solve.cpp: the calibration's least squares (Ceres) and small eigen-decompositions
// (Eigen) behind the C API of calib.h. Analytic Jacobians of the leg-length residuals.
#include <ceres/ceres.h>
#include <Eigen/Dense>

#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

extern "C" {
#include "calib/calib.h"
#include "kins/hexapod_math.h"
}

namespace {

// One leg at one measurement: r = |t + R p - b| - (L + offset), parameters b (3), p (3),
// offset (1). d r/d b = -u, d r/d p = R^T u, d r/d offset = -1, u the leg's unit vector.
class LegResidual : public ceres::SizedCostFunction<1, 3, 3, 1> {
public:
    LegResidual(const double t_mm[3], const double r[3][3], double len_mm) : len_mm_(len_mm)
    {
        for (int j = 0; j < 3; j++) {
            t_mm_[j] = t_mm[j];
            for (int c = 0; c < 3; c++)
                r_[j][c] = r[j][c];
        }
    }
    bool Evaluate(double const *const *x, double *res, double **jac) const override
    {
        const double *b = x[0], *p = x[1];
        double v[3];
        for (int j = 0; j < 3; j++)
            v[j] = t_mm_[j] + r_[j][0] * p[0] + r_[j][1] * p[1] + r_[j][2] * p[2] - b[j];
        double d = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (!(d > 0.0))
            return false;
        res[0] = d - len_mm_ - x[2][0];
        if (!jac)
            return true;
        double u[3] = { v[0] / d, v[1] / d, v[2] / d };
        if (jac[0])
            for (int j = 0; j < 3; j++)
                jac[0][j] = -u[j];
        if (jac[1])
            for (int c = 0; c < 3; c++)
                jac[1][c] = r_[0][c] * u[0] + r_[1][c] * u[1] + r_[2][c] * u[2];
        if (jac[2])
            jac[2][0] = -1.0;
        return true;
    }

private:
    double t_mm_[3];
    double r_[3][3];
    double len_mm_;
};

void put_err(char *err, size_t errlen, const char *msg)
{
    if (err && errlen)
        std::snprintf(err, errlen, "%s", msg);
}

} // namespace

extern "C" enum calib_status calib_ceres_solve(const struct calib_meas *m, const int *use, int n,
                                               double huber_mm, double x[CALIB_NPARAM],
                                               double *cov_diag, char *err, size_t errlen)
{
    try {
        ceres::Problem::Options popts;
        ceres::Problem problem(popts);
        // Each leg's parameters: x + 7i (b), x + 7i + 3 (p), x + 7i + 6 (offset).
        for (int j = 0; j < n; j++) {
            if (use && !use[j])
                continue;
            struct hexapod_rot o;
            hexapod_rot_from_rad(&o, m[j].pose[KINS_A] * HEXAPOD_RAD_PER_DEG,
                                 m[j].pose[KINS_B] * HEXAPOD_RAD_PER_DEG,
                                 m[j].pose[KINS_C] * HEXAPOD_RAD_PER_DEG);
            for (int i = 0; i < CALIB_LEGS; i++) {
                double *xi = x + CALIB_PER_LEG * i;
                ceres::LossFunction *loss =
                    huber_mm > 0.0 ? new ceres::HuberLoss(huber_mm) : nullptr;
                problem.AddResidualBlock(new LegResidual(m[j].pose, o.r, m[j].legs_mm[i]), loss,
                                         xi, xi + 3, xi + 6);
            }
        }
        ceres::Solver::Options sopts;
        sopts.linear_solver_type = ceres::DENSE_QR;
        sopts.logging_type = ceres::SILENT;
        sopts.max_num_iterations = 200;
        sopts.function_tolerance = 1e-16;
        sopts.gradient_tolerance = 1e-16;
        sopts.parameter_tolerance = 1e-14;
        sopts.num_threads = 1;
        ceres::Solver::Summary summary;
        ceres::Solve(sopts, &problem, &summary);
        if (!summary.IsSolutionUsable()) {
            put_err(err, errlen, ("least squares failed: " + summary.message).c_str());
            return CALIB_ERR_SOLVE;
        }
        if (!cov_diag)
            return CALIB_OK;
        ceres::Covariance::Options copts;
        copts.algorithm_type = ceres::DENSE_SVD;
        copts.num_threads = 1;
        ceres::Covariance cov(copts);
        std::vector<std::pair<const double *, const double *>> blocks;
        for (int i = 0; i < CALIB_LEGS; i++)
            for (int s : { 0, 3, 6 }) {
                const double *blk = x + CALIB_PER_LEG * i + s;
                blocks.emplace_back(blk, blk);
            }
        if (!cov.Compute(blocks, &problem)) {
            put_err(err, errlen, "the covariance of the fit cannot be computed (Jacobian rank "
                                 "deficient)");
            return CALIB_ERR_UNOBSERVABLE;
        }
        for (int i = 0; i < CALIB_LEGS; i++)
            for (int s : { 0, 3, 6 }) {
                const double *blk = x + CALIB_PER_LEG * i + s;
                int sz = s == 6 ? 1 : 3;
                double c[9];
                cov.GetCovarianceBlock(blk, blk, c);
                for (int k = 0; k < sz; k++)
                    cov_diag[CALIB_PER_LEG * i + s + k] = c[k * sz + k];
            }
        return CALIB_OK;
    } catch (const std::bad_alloc &) {
        put_err(err, errlen, "out of memory");
        return CALIB_ERR_NOMEM;
    }
}

extern "C" int calib_sym_eigen(const double *a, int n, double *vals, double *vecs)
{
    if (n < 1 || n > 16)
        return -1;
    Eigen::MatrixXd m(n, n);
    for (int r = 0; r < n; r++)
        for (int c = 0; c < n; c++) {
            if (!std::isfinite(a[r * n + c]))
                return -1;
            m(r, c) = a[r * n + c];
        }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(m);
    if (es.info() != Eigen::Success)
        return -1;
    for (int k = 0; k < n; k++) {
        vals[k] = es.eigenvalues()(k);
        for (int r = 0; r < n; r++)
            vecs[r * n + k] = es.eigenvectors()(r, k);
    }
    return 0;
}
