/* calibration_main.c: `make calibration`: the simulated calibration experiment. The TMU
 * machine's nominal geometry, perturbed, is "the real machine"; it is measured at planned
 * poses with a simulated instrument, the geometry is fitted, and the nominal and the
 * calibrated geometry are compared on other poses over the working region.
 * argv[1]: the machine INI; argv[2]: folder for measurements.csv; argv[3] --paper: also
 * the paper's experiment cut by the real machine with either geometry in the controller
 * (INIs written to that folder; run from the source tree or with HEXCNC_ROOT set). */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/calib.h"
#include "calib/calib_ini.h"
#include "check/experiment.h"
#include "common/inifile.h"
#include "kins/hexapod_math.h"

#define CAL_POSES 60            /* planned measurement poses */
#define CAL_VALIDATE 200        /* validation poses */
#define CAL_JOINT_SIGMA_MM 0.3  /* perturbation of every joint coordinate */
#define CAL_OFFSET_SIGMA_MM 0.5 /* perturbation of every leg offset */
#define CAL_NOISE_MM 0.010      /* instrument: position noise per axis */
#define CAL_NOISE_DEG 0.001     /* instrument: orientation noise per angle */

/* splitmix64 uniform in [0, 1), and a standard normal by Box-Muller. */
static double cal_uniform(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return (double)((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
}
static double cal_gauss(uint64_t *s)
{
    double u1 = cal_uniform(s), u2 = cal_uniform(s);
    return sqrt(-2.0 * log(u1 > 0.0 ? u1 : 1e-300)) * cos(2.0 * M_PI * u2);
}

/* Pose error between commanded c and reached a: position (mm), orientation (deg, the
 * angle of the rotation between them) and the error at the tool tip (mm). */
static void cal_pose_error(const double c[6], const double a[6], const double tip[3],
                           double err[3])
{
    struct hexapod_rot rc, ra;
    hexapod_rot_from_rad(&rc, c[3] * HEXAPOD_RAD_PER_DEG, c[4] * HEXAPOD_RAD_PER_DEG,
                         c[5] * HEXAPOD_RAD_PER_DEG);
    hexapod_rot_from_rad(&ra, a[3] * HEXAPOD_RAD_PER_DEG, a[4] * HEXAPOD_RAD_PER_DEG,
                         a[5] * HEXAPOD_RAD_PER_DEG);
    double tr = 0.0, w[3], q[3], d2 = 0.0;
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            tr += ra.r[i][k] * rc.r[i][k]; /* trace of Ra Rc^T */
    err[1] = acos(fmax(-1.0, fmin(1.0, 0.5 * (tr - 1.0)))) * HEXAPOD_DEG_PER_RAD;
    err[0] = sqrt((a[0] - c[0]) * (a[0] - c[0]) + (a[1] - c[1]) * (a[1] - c[1]) +
                  (a[2] - c[2]) * (a[2] - c[2]));
    for (int i = 0; i < 3; i++) /* the workpiece point that should be at the tip */
        w[i] = rc.r[0][i] * (tip[0] - c[0]) + rc.r[1][i] * (tip[1] - c[1]) +
               rc.r[2][i] * (tip[2] - c[2]);
    for (int i = 0; i < 3; i++) {
        q[i] = a[i] + ra.r[i][0] * w[0] + ra.r[i][1] * w[1] + ra.r[i][2] * w[2] - tip[i];
        d2 += q[i] * q[i];
    }
    err[2] = sqrt(d2);
}

/* Validation: the controller with geometry g commands each pose; the real machine goes
 * where its own geometry puts those leg lengths. Prints mean and max errors; returns the
 * max position error (mm), or NAN if a pose failed. */
static double cal_validate(const char *what, struct kins *ctrl, struct kins *real,
                           const double (*pose)[6], double *max_deg)
{
    double sum[3] = { 0 }, max[3] = { 0 }, tip[3], legs[6];
    kins_tool_point(ctrl, ctrl->home, tip, NULL);
    for (int j = 0; j < CAL_VALIDATE; j++) {
        double reached[6], e[3];
        memcpy(reached, pose[j], sizeof reached);
        if (kins_inverse(ctrl, pose[j], legs) != KINS_OK ||
            kins_forward(real, legs, reached, NULL) != KINS_OK)
            return (double)NAN;
        cal_pose_error(pose[j], reached, tip, e);
        for (int i = 0; i < 3; i++) {
            sum[i] += e[i] / CAL_VALIDATE;
            max[i] = fmax(max[i], e[i]);
        }
    }
    printf("  %-10s position mean %8.4f max %8.4f mm | orientation mean %8.5f max %8.5f deg | "
           "tool tip mean %8.4f max %8.4f mm\n", what, sum[0], max[0], sum[1], max[1], sum[2],
           max[2]);
    *max_deg = max[1];
    return max[0];
}

/* The real machine and its measurements at the planned poses; writes measurements.csv. */
static int cal_measure(struct kins *k, const struct kins_config *cfg,
                       const struct calib_geom *nominal, const struct calib_geom *truth,
                       const char *dir, struct calib_meas *m)
{
    char err[512] = "", path[1024];
    double pose[CAL_POSES][6], cond;
    struct calib_plan_opts po;
    struct kins *real = NULL;
    calib_plan_opts_default(&po);
    if (calib_plan(k, nominal, &po, CAL_POSES, pose, &cond, err, sizeof err) != CALIB_OK ||
        calib_kins_create(cfg, truth, &real, err, sizeof err) != CALIB_OK) {
        fprintf(stderr, "calibration: %s\n", err);
        return -1;
    }
    printf("  %d planned poses (hexcnc calibrate plan's D-optimal choice), condition number "
           "%.1f\n", CAL_POSES, cond);
    snprintf(path, sizeof path, "%s/measurements.csv", dir);
    FILE *f = fopen(path, "w");
    if (f)
        fprintf(f, "# simulated: the perturbed TMU machine, instrument noise %.3f mm, %.4f "
                "deg\nL1,L2,L3,L4,L5,L6,X,Y,Z,A,B,C\n", CAL_NOISE_MM, CAL_NOISE_DEG);
    uint64_t rng = 151;
    for (int j = 0; j < CAL_POSES; j++) {
        if (kins_inverse(real, pose[j], m[j].legs_mm) != KINS_OK) {
            fprintf(stderr, "calibration: planned pose %d unreachable on the real machine\n", j);
            kins_free(real);
            return -1;
        }
        for (int a = 0; a < 6; a++)
            m[j].pose[a] = pose[j][a] + (a < 3 ? CAL_NOISE_MM : CAL_NOISE_DEG) * cal_gauss(&rng);
        m[j].line = j + 3;
        for (int c = 0; f && c < 12; c++)
            fprintf(f, "%.6f%c", c < 6 ? m[j].legs_mm[c] : m[j].pose[c - 6], c < 11 ? ',' : '\n');
    }
    if (f && fclose(f) == 0)
        printf("  measurements: %s\n", path);
    kins_free(real);
    return 0;
}

/* Reads a whole (small) file; NULL if it cannot. */
static char *cal_read(const char *path)
{
    FILE *f = fopen(path, "rb");
    char *s = f ? calloc(1, 1 << 20) : NULL;
    size_t n = s ? fread(s, 1, (1 << 20) - 1, f) : 0;
    if (f)
        fclose(f);
    if (s && n == 0) {
        free(s);
        s = NULL;
    }
    return s;
}

/* Writes the INI at src with geometry g to dst; its "../../../" paths (relative to the
 * source tree's examples/paper/experiment/) become root/. Returns 0 or -1. */
static int cal_write_ini(const char *src, const char *dst, const char *root,
                         const struct calib_geom *g)
{
    char *text = cal_read(src), *out = text ? calib_ini_rewrite(text, g, "for make "
                                                                "calibration") : NULL;
    FILE *f = out ? fopen(dst, "w") : NULL;
    int rc = f ? 0 : -1;
    for (const char *p = out; f && *p; ) {
        const char *hit = strstr(p, "= ../../../");
        size_t len = hit ? (size_t)(hit - p) : strlen(p);
        fwrite(p, 1, len, f);
        if (!hit)
            break;
        fprintf(f, "= %s/", root);
        p = hit + strlen("= ../../../");
    }
    if (f && fclose(f) != 0)
        rc = -1;
    free(text);
    free(out);
    return rc;
}

/* The paper's experiment (make experiment) cut by the real machine with the nominal and
 * with the calibrated geometry in the controller: the walls' d beside the paper's. */
static int cal_paper(const char *root, const char *dir, const struct calib_geom *truth,
                     const struct calib_geom *cal)
{
    char real_ini[PATH_MAX + 80], ctl_ini[2][PATH_MAX + 80], src[PATH_MAX + 80];
    int n, rc = 0;
    const struct exp_run_def *runs = exp_runs(&n);
    snprintf(src, sizeof src, "%s/configs/sim/tmu-hexapod.ini", root);
    snprintf(real_ini, sizeof real_ini, "%s/real-machine.ini", dir);
    for (int p = 0; p < 2; p++) {
        snprintf(ctl_ini[p], sizeof ctl_ini[p], "%s/calibrated-path%d.ini", dir, p + 1);
        char path_src[PATH_MAX + 80];
        snprintf(path_src, sizeof path_src, "%s/examples/paper/experiment/tmu-path%d.ini", root,
                 p + 1);
        if (cal_write_ini(path_src, ctl_ini[p], root, cal) != 0)
            return -1;
    }
    if (cal_write_ini(src, real_ini, root, truth) != 0)
        return -1;
    printf("\nThe paper's experiment (make experiment) cut by the real machine; d1..d4, mm:\n"
           "run   | paper                       | nominal geometry            | calibrated "
           "geometry\n");
    fflush(stdout);
    for (int i = 0; i < n; i++) {
        struct exp_run_def d[2] = { runs[i], runs[i] };
        struct exp_result r[2];
        char err[512] = "";
        d[0].real_ini = d[1].real_ini = real_ini;
        d[1].ini = ctl_ini[runs[i].path - 1];
        char prog[PATH_MAX + 80];
        snprintf(prog, sizeof prog, "%s/%s", root, runs[i].program);
        d[1].program = prog; /* both absolute: exp_run puts its root ("") in front */
        printf("%-5s |", runs[i].name);
        for (int k = 0; k < 4; k++) {
            if (isnan(runs[i].paper_d_mm[k]))
                printf(" %6s", "-");
            else
                printf(" %6.1f", runs[i].paper_d_mm[k]);
        }
        for (int c = 0; c < 2; c++) {
            if (exp_run(c ? "" : root, &d[c], NULL, &r[c], err, sizeof err) != 0) {
                fprintf(stderr, "calibration: paper run %s: %s\n", runs[i].name, err);
                rc = -1;
                break;
            }
            printf(" |");
            for (int k = 0; k < 4; k++)
                printf(" %6.3f", r[c].d_mm[k]);
        }
        printf("\n");
    }
    return rc;
}

/* The validation poses: uniform over the TMU working region (X, Y +-120 mm, Z 620..670 mm,
 * |A|, |B| <= 10 deg, |C| <= 15 deg), another seed than the plan's. */
static void cal_validation_poses(double (*pose)[6])
{
    static const double lo[6] = { -120, -120, 620, -10, -10, -15 };
    static const double hi[6] = { 120, 120, 670, 10, 10, 15 };
    uint64_t rng = 4242;
    for (int j = 0; j < CAL_VALIDATE; j++)
        for (int a = 0; a < 6; a++)
            pose[j][a] = lo[a] + (hi[a] - lo[a]) * cal_uniform(&rng);
}

/* "The real machine": every joint coordinate and leg offset perturbed, fixed seed. */
static struct calib_geom cal_perturb(const struct calib_geom *g)
{
    struct calib_geom t = *g;
    uint64_t rng = 15;
    for (int i = 0; i < CALIB_LEGS; i++) {
        for (int j = 0; j < 3; j++) {
            t.b_mm[i][j] += CAL_JOINT_SIGMA_MM * cal_gauss(&rng);
            t.p_mm[i][j] += CAL_JOINT_SIGMA_MM * cal_gauss(&rng);
        }
        t.offset_mm[i] += CAL_OFFSET_SIGMA_MM * cal_gauss(&rng);
    }
    return t;
}

/* Runs the experiment; the exit status is 1 when the calibrated geometry misses the goal
 * (at most twice the instrument noise), 2 on any other failure. */
int main(int argc, char **argv)
{
    const char *ini_path = argc > 1 ? argv[1] : "configs/sim/tmu-hexapod.ini";
    const char *dir = argc > 2 ? argv[2] : ".";
    int paper = argc > 3 && !strcmp(argv[3], "--paper");
    char err[1024] = "";
    struct inifile ini = { 0 };
    struct kins *k = NULL, *real = NULL, *cal = NULL;
    struct calib_geom nominal, truth;
    struct calib_meas m[CAL_POSES];
    struct calib_fit_result r = { 0 };
    struct calib_fit_opts o;
    static double val[CAL_VALIDATE][6];
    int rc = 2;
    if (inifile_load(&ini, ini_path, err, sizeof err) != INIFILE_OK)
        goto done;
    struct kins_config cfg = { inifile_config_get, &ini };
    if (kins_create(&kins_hexapod_ops, &cfg, &k, err, sizeof err) != KINS_OK ||
        calib_geom_from_kins(k, &nominal, err, sizeof err) != CALIB_OK)
        goto done;
    truth = cal_perturb(&nominal);
    printf("Simulated calibration of %s: joints perturbed by sigma %.1f mm, leg offsets by "
           "%.1f mm (seed 15);\ninstrument noise %.0f um per axis, %.4f deg per angle.\n",
           ini_path, CAL_JOINT_SIGMA_MM, CAL_OFFSET_SIGMA_MM, CAL_NOISE_MM * 1000,
           CAL_NOISE_DEG);
    if (cal_measure(k, &cfg, &nominal, &truth, dir, m) != 0)
        goto done;
    calib_fit_opts_default(&o);
    if (calib_fit(&nominal, m, CAL_POSES, &o, &r, err, sizeof err) != CALIB_OK ||
        calib_kins_create(&cfg, &truth, &real, err, sizeof err) != CALIB_OK ||
        calib_kins_create(&cfg, &r.geom, &cal, err, sizeof err) != CALIB_OK)
        goto done;
    double xt[CALIB_NPARAM], xc[CALIB_NPARAM], worst = 0.0, worst_sig = 0.0, sig_max = 0.0;
    calib_geom_to_params(&truth, xt);
    calib_geom_to_params(&r.geom, xc);
    for (int q = 0; q < CALIB_NPARAM; q++) {
        worst = fmax(worst, fabs(xc[q] - xt[q]));
        worst_sig = fmax(worst_sig, fabs(xc[q] - xt[q]) / r.sigma_mm[q]);
        sig_max = fmax(sig_max, r.sigma_mm[q]);
    }
    printf("  fit: leg residual rms %.4f -> %.4f mm, %d outliers; parameters off the truth "
           "by at most %.4f mm (%.1f std devs; largest std dev %.4f mm)\n", r.rms_before_mm,
           r.rms_after_mm, r.n_outliers, worst, worst_sig, sig_max);
    printf("Validation on %d other poses over the working region (X, Y +-120, Z 620..670, "
           "|A|, |B| <= 10, |C| <= 15):\n", CAL_VALIDATE);
    cal_validation_poses(val);
    double nom_deg, cal_deg;
    double nom_mm = cal_validate("nominal", k, real, val, &nom_deg);
    double cal_mm = cal_validate("calibrated", cal, real, val, &cal_deg);
    if (isnan(nom_mm) || isnan(cal_mm)) {
        snprintf(err, sizeof err, "a validation pose failed");
        goto done;
    }
    int ok = cal_mm <= 2.0 * CAL_NOISE_MM && cal_deg <= 2.0 * CAL_NOISE_DEG;
    char root[PATH_MAX], adir[PATH_MAX];
    const char *env_root = getenv("HEXCNC_ROOT");
    if (paper && (!realpath(env_root && *env_root ? env_root : ".", root) ||
                  !realpath(dir, adir) || cal_paper(root, adir, &truth, &r.geom) != 0)) {
        snprintf(err, sizeof err, "the paper's experiment failed");
        goto done;
    }
    printf("Goal (calibrated max error <= twice the instrument noise: %.3f mm, %.4f deg): "
           "%s\n", 2.0 * CAL_NOISE_MM, 2.0 * CAL_NOISE_DEG, ok ? "met" : "MISSED");
    rc = ok ? 0 : 1;
done:
    if (rc == 2)
        fprintf(stderr, "calibration: %s\n", err);
    calib_fit_result_free(&r);
    kins_free(cal);
    kins_free(real);
    kins_free(k);
    inifile_free(&ini);
    return rc;
}
