/* calib.h: kinematic calibration of the hexapod: the 42 geometry parameters from measured
 * poses and leg lengths (fit), and the measurement poses that make them observable (plan).
 * Pure: no file I/O, no HAL; the shell is tools/cmd_calibrate.c. See docs/calibration.md. */
#ifndef HEXCNC_CALIB_H
#define HEXCNC_CALIB_H

#include <stddef.h>
#include <stdint.h>

#include "kins/kins.h"

#define CALIB_LEGS 6
#define CALIB_PER_LEG 7                            /* base joint xyz, platform joint xyz, offset */
#define CALIB_NPARAM (CALIB_LEGS * CALIB_PER_LEG)  /* 42 */
#define CALIB_MIN_MEAS (CALIB_PER_LEG + 1)         /* fewest measurements a fit accepts */

/* What went wrong. 0 = OK; details go to the caller's err buffer. */
enum calib_status {
    CALIB_OK = 0,
    CALIB_ERR_ARG,           /* caller passed something unusable (non-finite number, ...) */
    CALIB_ERR_TOO_FEW,       /* fewer measurements than the parameters need */
    CALIB_ERR_UNOBSERVABLE,  /* the poses leave some parameter combination undetermined */
    CALIB_ERR_SOLVE,         /* the least-squares solver or its covariance failed */
    CALIB_ERR_NOMEM,         /* out of memory */
    CALIB_ERR_GEOMETRY,      /* the kinematics refused the geometry */
    CALIB_STATUS_COUNT
};
const char *calib_strerror(enum calib_status st);

/* The geometry being identified, in the kinematics' conventions (kins/hexapod.h). */
struct calib_geom {
    double b_mm[CALIB_LEGS][3];     /* base joint centres, base frame, mm */
    double p_mm[CALIB_LEGS][3];     /* platform joint centres, platform frame, mm */
    double offset_mm[CALIB_LEGS];   /* joint-centre distance - drive length, mm */
};

/* One measurement: what the drives report and where the instrument saw the platform. */
struct calib_meas {
    double legs_mm[CALIB_LEGS];     /* leg lengths as the drives report them, mm */
    double pose[KINS_POSE_DIM];     /* measured platform pose X Y Z (mm) A B C (deg) */
    int line;                       /* line of the measurement file it came from, 0 if none */
};

/* Parameter vector order: leg i's seven parameters at 7i: b xyz, p xyz, offset. */
void calib_geom_to_params(const struct calib_geom *g, double x[CALIB_NPARAM]);
void calib_params_to_geom(const double x[CALIB_NPARAM], struct calib_geom *g);
/* The INI name of parameter k ("BASE_2 y", "PLATFORM_0 z", "LEG_OFFSET 4" (1-based leg)). */
const char *calib_param_name(int k, char *buf, size_t len);

/* Leg i's residual (mm): joint-centre distance at the measured pose - (drive length +
 * offset); jac (may be NULL) gets its derivative by leg i's seven parameters. */
double calib_leg_residual(const struct calib_geom *g, const struct calib_meas *m, int leg,
                          double jac[CALIB_PER_LEG]);

/* Observability of leg parameters with a set of poses: the 7x7 information matrix of each
 * leg (J^T J) and what it says. */
struct calib_observability {
    double condition;                   /* sqrt(largest / smallest eigenvalue), all legs */
    double gain[CALIB_NPARAM];          /* standard deviation per mm of residual noise */
    int unobservable_leg;               /* first leg (0-based) with a null direction, or -1 */
    double null_dir[CALIB_PER_LEG];     /* that direction (unit), over the leg's parameters */
};
/* Builds the information matrices of geometry g at the measurements with use[j] != 0
 * (use NULL = all) and analyses them. Returns CALIB_ERR_UNOBSERVABLE (err names the
 * parameters involved) when some combination is undetermined. */
enum calib_status calib_observe(const struct calib_geom *g, const struct calib_meas *m,
                                const int *use, int n, struct calib_observability *out, char *err,
                                size_t errlen);

/* Fit settings. */
struct calib_fit_opts {
    double huber_mm;        /* robust loss: residuals beyond this count linearly, mm */
    double outlier_k;       /* an outlier has a leg residual > k x the robust noise level */
    double outlier_min_mm;  /* ... and above this floor, mm */
    double poor_gain;       /* a parameter whose gain exceeds this is poorly observable */
};
void calib_fit_opts_default(struct calib_fit_opts *o);

/* What a fit found. Arrays are owned by the result (calib_fit_result_free). */
struct calib_fit_result {
    struct calib_geom geom;             /* identified geometry */
    double sigma_mm[CALIB_NPARAM];      /* standard deviation of each parameter, mm */
    double gain[CALIB_NPARAM];          /* standard deviation per mm of noise */
    double noise_mm;                    /* residual noise level estimated after the fit, mm */
    double condition;                   /* condition of the identification */
    int n;                              /* measurements */
    double *before_mm;                  /* [n * 6] residuals with the starting geometry */
    double *after_mm;                   /* [n * 6] residuals with the identified geometry */
    int *outlier;                       /* [n] 1 when measurement j was set aside */
    int n_outliers;
    double rms_before_mm, rms_after_mm; /* over the measurements kept */
    double max_before_mm, max_after_mm;
};
void calib_fit_result_free(struct calib_fit_result *r);

/* Identifies the geometry from n measurements, starting at nominal: a robust (Huber) fit,
 * outliers set aside, then a plain least-squares fit of the rest with its covariance. */
enum calib_status calib_fit(const struct calib_geom *nominal, const struct calib_meas *m, int n,
                            const struct calib_fit_opts *opts, struct calib_fit_result *out,
                            char *err, size_t errlen);

/* Least squares with Ceres (calib_solve.cpp): x holds the start and gets the solution.
 * use[j] == 0 leaves measurement j out; huber_mm <= 0 is plain least squares. cov_diag
 * (may be NULL) gets the diagonal of (J^T J)^-1. */
enum calib_status calib_ceres_solve(const struct calib_meas *m, const int *use, int n,
                                    double huber_mm, double x[CALIB_NPARAM], double *cov_diag,
                                    char *err, size_t errlen);
/* Eigenvalues (ascending) and eigenvectors (column k of vecs, row-major n x n) of a
 * symmetric n x n matrix, n <= 16 (Eigen, calib_solve.cpp). 0, or -1 on failure. */
int calib_sym_eigen(const double *a, int n, double *vals, double *vecs);

/* Planning settings: where candidates are drawn (around home) and how many. */
struct calib_plan_opts {
    double half_range[KINS_POSE_DIM];   /* +- range about home: mm for X Y Z, deg for A B C */
    double leg_margin_mm;               /* keep legs this far inside their limits */
    int candidates;                     /* random reachable candidates to choose from */
    uint64_t seed;                      /* random generator seed */
};
void calib_plan_opts_default(struct calib_plan_opts *o);

/* Chooses n poses (pose[n][6]) among random reachable candidates of kinematics k (whose
 * geometry is g), greedily maximising the determinant of the information matrix
 * (D-optimal); *condition gets the identification's condition number. */
enum calib_status calib_plan(struct kins *k, const struct calib_geom *g,
                             const struct calib_plan_opts *opts, int n,
                             double (*pose)[KINS_POSE_DIM], double *condition, char *err,
                             size_t errlen);

/* Geometry <-> kinematics: reads a hexapod instance's geometry; builds a hexapod from base
 * configuration with the geometry replaced by g (explicit joints and offsets). */
enum calib_status calib_geom_from_kins(const struct kins *k, struct calib_geom *g, char *err,
                                       size_t errlen);
enum calib_status calib_kins_create(const struct kins_config *base, const struct calib_geom *g,
                                    struct kins **out, char *err, size_t errlen);
/* The value text of the explicit-geometry key `key` ([KINS] BASE_n, PLATFORM_n, LEG_OFFSET)
 * for g, 9 decimals; NULL for any other key. */
const char *calib_geom_key_value(const struct calib_geom *g, const char *key, char *buf,
                                 size_t len);

#endif
