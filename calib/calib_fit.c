/* calib_fit.c: the calibration's residuals, observability analysis and fit driver. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/calib.h"
#include "kins/hexapod_math.h"

/* Relative eigenvalue below which a leg's parameter combination counts as undetermined:
 * its standard deviation would be over 1e5 times the measurement noise. */
#define CALIB_NULL_REL 1e-10

static const char *const calib_status_text[CALIB_STATUS_COUNT] = {
    [CALIB_OK] = "ok",
    [CALIB_ERR_ARG] = "bad argument",
    [CALIB_ERR_TOO_FEW] = "too few measurements",
    [CALIB_ERR_UNOBSERVABLE] = "parameters not observable with these poses",
    [CALIB_ERR_SOLVE] = "least-squares solve failed",
    [CALIB_ERR_NOMEM] = "out of memory",
    [CALIB_ERR_GEOMETRY] = "geometry refused by the kinematics",
};

/* The text of a status. */
const char *calib_strerror(enum calib_status st)
{
    return (unsigned)st < CALIB_STATUS_COUNT ? calib_status_text[st] : "unknown status";
}

/* Flattens the geometry, seven parameters a leg. */
void calib_geom_to_params(const struct calib_geom *g, double x[CALIB_NPARAM])
{
    for (int i = 0; i < CALIB_LEGS; i++) {
        double *xi = x + CALIB_PER_LEG * i;
        memcpy(xi, g->b_mm[i], 3 * sizeof *xi);
        memcpy(xi + 3, g->p_mm[i], 3 * sizeof *xi);
        xi[6] = g->offset_mm[i];
    }
}

/* The inverse of calib_geom_to_params. */
void calib_params_to_geom(const double x[CALIB_NPARAM], struct calib_geom *g)
{
    for (int i = 0; i < CALIB_LEGS; i++) {
        const double *xi = x + CALIB_PER_LEG * i;
        memcpy(g->b_mm[i], xi, 3 * sizeof *xi);
        memcpy(g->p_mm[i], xi + 3, 3 * sizeof *xi);
        g->offset_mm[i] = xi[6];
    }
}

/* "BASE_2 y": the INI key (0-based joint index, as the kinematics reads it) and axis. */
const char *calib_param_name(int k, char *buf, size_t len)
{
    int leg = k / CALIB_PER_LEG, s = k % CALIB_PER_LEG;
    if (s == 6)
        snprintf(buf, len, "LEG_OFFSET %d", leg + 1);
    else
        snprintf(buf, len, "%s_%d %c", s < 3 ? "BASE" : "PLATFORM", leg, "xyz"[s % 3]);
    return buf;
}

/* r = |t + R p - b| - (L + offset), and its derivatives (see calib_solve.cpp). */
double calib_leg_residual(const struct calib_geom *g, const struct calib_meas *m, int leg,
                          double jac[CALIB_PER_LEG])
{
    struct hexapod_rot o;
    hexapod_rot_from_rad(&o, m->pose[KINS_A] * HEXAPOD_RAD_PER_DEG,
                         m->pose[KINS_B] * HEXAPOD_RAD_PER_DEG,
                         m->pose[KINS_C] * HEXAPOD_RAD_PER_DEG);
    const double *p = g->p_mm[leg];
    double v[3];
    for (int j = 0; j < 3; j++)
        v[j] = m->pose[j] + o.r[j][0] * p[0] + o.r[j][1] * p[1] + o.r[j][2] * p[2] -
               g->b_mm[leg][j];
    double d = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (jac) {
        for (int j = 0; j < 3; j++) {
            jac[j] = -v[j] / d;
            jac[3 + j] = (o.r[0][j] * v[0] + o.r[1][j] * v[1] + o.r[2][j] * v[2]) / d;
        }
        jac[6] = -1.0;
    }
    return d - m->legs_mm[leg] - g->offset_mm[leg];
}

/* Names the parameters that dominate a null direction: "BASE_0 x, PLATFORM_0 x". */
static void calib_name_null(int leg, const double dir[CALIB_PER_LEG], char *out, size_t len)
{
    size_t used = 0;
    out[0] = '\0';
    for (int s = 0; s < CALIB_PER_LEG && used < len; s++) {
        if (fabs(dir[s]) < 0.2)
            continue;
        char name[32];
        int w = snprintf(out + used, len - used, "%s%s", used ? ", " : "",
                         calib_param_name(CALIB_PER_LEG * leg + s, name, sizeof name));
        if (w < 0)
            break;
        used += (size_t)w;
    }
}

/* Builds each leg's information matrix and analyses it (see calib.h). */
enum calib_status calib_observe(const struct calib_geom *g, const struct calib_meas *m,
                                const int *use, int n, struct calib_observability *out, char *err,
                                size_t errlen)
{
    double lmin = INFINITY, lmax = 0.0;
    out->unobservable_leg = -1;
    for (int i = 0; i < CALIB_LEGS; i++) {
        double info[CALIB_PER_LEG * CALIB_PER_LEG] = { 0 }, jac[CALIB_PER_LEG];
        double vals[CALIB_PER_LEG], vecs[CALIB_PER_LEG * CALIB_PER_LEG];
        for (int j = 0; j < n; j++) {
            if (use && !use[j])
                continue;
            calib_leg_residual(g, &m[j], i, jac);
            for (int r = 0; r < CALIB_PER_LEG; r++)
                for (int c = 0; c < CALIB_PER_LEG; c++)
                    info[r * CALIB_PER_LEG + c] += jac[r] * jac[c];
        }
        if (calib_sym_eigen(info, CALIB_PER_LEG, vals, vecs) != 0) {
            snprintf(err, errlen, "leg %d: information matrix not finite", i + 1);
            return CALIB_ERR_ARG;
        }
        lmin = fmin(lmin, vals[0]);
        lmax = fmax(lmax, vals[CALIB_PER_LEG - 1]);
        if (!(vals[0] > CALIB_NULL_REL * vals[CALIB_PER_LEG - 1])) {
            char names[256];
            for (int s = 0; s < CALIB_PER_LEG; s++)
                out->null_dir[s] = vecs[s * CALIB_PER_LEG];
            out->unobservable_leg = i;
            calib_name_null(i, out->null_dir, names, sizeof names);
            snprintf(err, errlen, "leg %d: these poses cannot tell apart changes of %s (add "
                     "poses that turn the platform about all three axes, or use `hexcnc "
                     "calibrate plan`)", i + 1, names);
            out->condition = INFINITY;
            return CALIB_ERR_UNOBSERVABLE;
        }
        for (int s = 0; s < CALIB_PER_LEG; s++) {
            double var = 0.0; /* diag of info^-1 = sum_k vec_sk^2 / val_k */
            for (int k = 0; k < CALIB_PER_LEG; k++)
                var += vecs[s * CALIB_PER_LEG + k] * vecs[s * CALIB_PER_LEG + k] / vals[k];
            out->gain[CALIB_PER_LEG * i + s] = sqrt(var);
        }
    }
    out->condition = sqrt(lmax / lmin);
    return CALIB_OK;
}

/* Defaults: Huber at 0.05 mm (five times a good instrument's noise, far below the
 * nominal geometry's millimetre errors), outliers beyond 6 robust sigmas and 0.01 mm. */
void calib_fit_opts_default(struct calib_fit_opts *o)
{
    o->huber_mm = 0.05;
    o->outlier_k = 6.0;
    o->outlier_min_mm = 0.01;
    o->poor_gain = 10.0;
}

/* Frees the arrays of a result. */
void calib_fit_result_free(struct calib_fit_result *r)
{
    free(r->before_mm);
    free(r->after_mm);
    free(r->outlier);
    r->before_mm = r->after_mm = NULL;
    r->outlier = NULL;
}

/* Residuals of every measurement and leg with geometry g; rms and max over use[j] != 0. */
static void calib_residuals(const struct calib_geom *g, const struct calib_meas *m, int n,
                            const int *outlier, double *res, double *rms, double *max)
{
    double ss = 0.0;
    int cnt = 0;
    *max = 0.0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < CALIB_LEGS; i++) {
            double r = calib_leg_residual(g, &m[j], i, NULL);
            res[j * CALIB_LEGS + i] = r;
            if (outlier && outlier[j])
                continue;
            ss += r * r;
            cnt++;
            *max = fmax(*max, fabs(r));
        }
    *rms = cnt ? sqrt(ss / cnt) : 0.0;
}

/* Compares doubles for qsort. */
static int calib_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Sets aside measurements with a leg residual far beyond the robust noise level (1.4826 x
 * the median absolute residual). Returns how many, or -1 on allocation failure. */
static int calib_find_outliers(const double *res, int n, const struct calib_fit_opts *o,
                               int *outlier)
{
    int nr = n * CALIB_LEGS, cnt = 0;
    double *a = malloc((size_t)nr * sizeof *a);
    if (!a)
        return -1;
    for (int k = 0; k < nr; k++)
        a[k] = fabs(res[k]);
    qsort(a, (size_t)nr, sizeof *a, calib_cmp_double);
    double limit = fmax(o->outlier_k * 1.4826 * a[nr / 2], o->outlier_min_mm);
    free(a);
    for (int j = 0; j < n; j++) {
        outlier[j] = 0;
        for (int i = 0; i < CALIB_LEGS; i++)
            if (fabs(res[j * CALIB_LEGS + i]) > limit)
                outlier[j] = 1;
        cnt += outlier[j];
    }
    return cnt;
}

/* Checks the input before any work: finite numbers, enough measurements. */
static enum calib_status calib_fit_check(const struct calib_meas *m, int n, char *err,
                                         size_t errlen)
{
    if (n < CALIB_MIN_MEAS) {
        snprintf(err, errlen, "%d measurements: the fit needs at least %d (each gives one "
                 "equation per leg, and each leg has %d parameters: base joint x y z, "
                 "platform joint x y z, offset)", n, CALIB_MIN_MEAS, CALIB_PER_LEG);
        return CALIB_ERR_TOO_FEW;
    }
    for (int j = 0; j < n; j++)
        for (int k = 0; k < CALIB_LEGS; k++)
            if (!isfinite(m[j].legs_mm[k]) || !isfinite(m[j].pose[k])) {
                snprintf(err, errlen, "measurement %d (line %d): a number is not finite",
                         j + 1, m[j].line);
                return CALIB_ERR_ARG;
            }
    return CALIB_OK;
}

/* From a robust fit in x: sets outliers aside, refits the rest by plain least squares
 * (x, cov), and repeats with the residuals of that fit until the set of outliers stays
 * the same: a bad reading that pulled the robust fit can make good ones look bad once. */
static enum calib_status calib_fit_clean(const struct calib_meas *m, int n,
                                         const struct calib_fit_opts *opts,
                                         struct calib_fit_result *out, double *x, double *cov,
                                         struct calib_observability *ob, char *err,
                                         size_t errlen)
{
    enum calib_status st = CALIB_ERR_NOMEM;
    double rms, max;
    int *use = malloc((size_t)n * sizeof *use);
    if (!use)
        return st;
    for (int round = 0; round < 5; round++) {
        calib_residuals(&out->geom, m, n, NULL, out->after_mm, &rms, &max);
        int *prev = use; /* the previous round's outliers, as "use" flags */
        int changed = 0, cnt = calib_find_outliers(out->after_mm, n, opts, out->outlier);
        if (cnt < 0)
            break;
        for (int j = 0; j < n; j++) {
            changed |= round == 0 || prev[j] != !out->outlier[j];
            use[j] = !out->outlier[j];
        }
        out->n_outliers = cnt;
        if (!changed) {
            st = CALIB_OK;
            break;
        }
        if (n - cnt < CALIB_MIN_MEAS) {
            snprintf(err, errlen, "%d of %d measurements are outliers: too few left for a "
                     "fit", cnt, n);
            st = CALIB_ERR_TOO_FEW;
            break;
        }
        if ((st = calib_observe(&out->geom, m, use, n, ob, err, errlen)) != CALIB_OK ||
            (st = calib_ceres_solve(m, use, n, 0.0, x, cov, err, errlen)) != CALIB_OK)
            break;
        calib_params_to_geom(x, &out->geom);
        st = CALIB_ERR_SOLVE;
        snprintf(err, errlen, "the set of outliers did not settle in 5 rounds");
    }
    free(use);
    return st;
}

/* Robust fit, outliers set aside, plain refit with covariance (see calib.h). */
enum calib_status calib_fit(const struct calib_geom *nominal, const struct calib_meas *m, int n,
                            const struct calib_fit_opts *opts, struct calib_fit_result *out,
                            char *err, size_t errlen)
{
    double x[CALIB_NPARAM], cov[CALIB_NPARAM];
    struct calib_observability ob;
    memset(out, 0, sizeof *out);
    enum calib_status st = calib_fit_check(m, n, err, errlen);
    if (st != CALIB_OK)
        return st;
    out->n = n;
    out->before_mm = calloc((size_t)n * CALIB_LEGS, sizeof *out->before_mm);
    out->after_mm = calloc((size_t)n * CALIB_LEGS, sizeof *out->after_mm);
    out->outlier = calloc((size_t)n, sizeof *out->outlier);
    st = CALIB_ERR_NOMEM;
    if (!out->before_mm || !out->after_mm || !out->outlier)
        goto fail;
    if ((st = calib_observe(nominal, m, NULL, n, &ob, err, errlen)) != CALIB_OK)
        goto fail;
    calib_geom_to_params(nominal, x);
    if ((st = calib_ceres_solve(m, NULL, n, opts->huber_mm, x, NULL, err, errlen)) != CALIB_OK)
        goto fail;
    calib_params_to_geom(x, &out->geom);
    if ((st = calib_fit_clean(m, n, opts, out, x, cov, &ob, err, errlen)) != CALIB_OK)
        goto fail;
    calib_params_to_geom(x, &out->geom);
    calib_residuals(nominal, m, n, out->outlier, out->before_mm, &out->rms_before_mm,
                    &out->max_before_mm);
    calib_residuals(&out->geom, m, n, out->outlier, out->after_mm, &out->rms_after_mm,
                    &out->max_after_mm);
    /* Noise estimated from the residual sum of squares over its degrees of freedom. */
    int dof = (n - out->n_outliers) * CALIB_LEGS - CALIB_NPARAM;
    double s2 = 0.0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < CALIB_LEGS && !out->outlier[j]; i++)
            s2 += out->after_mm[j * CALIB_LEGS + i] * out->after_mm[j * CALIB_LEGS + i];
    out->noise_mm = dof > 0 ? sqrt(s2 / dof) : 0.0;
    out->condition = ob.condition;
    for (int k = 0; k < CALIB_NPARAM; k++) {
        out->gain[k] = sqrt(cov[k]);
        out->sigma_mm[k] = out->gain[k] * out->noise_mm;
    }
    return CALIB_OK;
fail:
    calib_fit_result_free(out);
    return st;
}
