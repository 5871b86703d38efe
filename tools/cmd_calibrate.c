/* cmd_calibrate.c: `hexcnc calibrate plan|fit`: the shell around calib/ (files in and out,
 * the report). See docs/calibration.md. */
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "calib/calib.h"
#include "calib/calib_csv.h"
#include "calib/calib_ini.h"
#include "common/inifile.h"
#include "kins/kins.h"
#include "tools/cmd.h"

const char cmd_calibrate_usage[] =
    "calibrate plan CONFIG.ini N [-o POSES.csv] [--seed S] [--force] | "
    "fit CONFIG.ini MEAS.csv [-o CALIBRATED.ini] [--force]   kinematic calibration";

/* Command-line settings shared by both verbs. */
struct calibrate_args {
    const char *verb, *config, *input;  /* plan|fit, the INI, N or the measurement file */
    const char *out;                    /* -o target, NULL: print only */
    int force;                          /* --force: replace an existing -o target */
    unsigned long long seed;            /* --seed for plan */
    int has_seed;
};

/* Reads a whole file; NULL with a message on failure. */
static char *calibrate_read_text(const char *path, char *err, size_t errlen)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, errlen, "%s: %s", path, strerror(errno));
        return NULL;
    }
    char *s = NULL;
    size_t n = 0, cap = 0;
    for (;;) {
        if (cap - n < 4096) {
            char *g = realloc(s, cap = 2 * cap + 8192);
            if (!g)
                break;
            s = g;
        }
        size_t got = fread(s + n, 1, cap - n - 1, f);
        n += got;
        if (got == 0)
            break;
    }
    int bad = ferror(f) || !s;
    fclose(f);
    if (bad) {
        snprintf(err, errlen, "%s: cannot read it", path);
        free(s);
        return NULL;
    }
    s[n] = '\0';
    return s;
}

/* Refuses a target that is the input, or that exists without --force. */
static int calibrate_check_target(const char *out, const char *input, int force, char *err,
                                  size_t errlen)
{
    struct stat so, si;
    if (stat(out, &so) != 0)
        return 0;
    if (input && stat(input, &si) == 0 && so.st_dev == si.st_dev && so.st_ino == si.st_ino) {
        snprintf(err, errlen, "%s: is the input file; write the result to a new file", out);
        return -1;
    }
    if (!force) {
        snprintf(err, errlen, "%s: exists; give --force to replace it", out);
        return -1;
    }
    return 0;
}

/* Writes text to path atomically: a temporary in the same folder, then rename. */
static int calibrate_write_atomic(const char *path, const char *text, char *err, size_t errlen)
{
    char tmp[PATH_MAX];
    if (snprintf(tmp, sizeof tmp, "%s.XXXXXX", path) >= (int)sizeof tmp) {
        snprintf(err, errlen, "%s: path too long", path);
        return -1;
    }
    int fd = mkstemp(tmp);
    if (fd < 0) {
        snprintf(err, errlen, "%s: cannot create a temporary beside it: %s", path,
                 strerror(errno));
        return -1;
    }
    size_t len = strlen(text), done = 0;
    while (done < len) {
        ssize_t w = write(fd, text + done, len - done);
        if (w <= 0)
            break;
        done += (size_t)w;
    }
    int ok = done == len && fchmod(fd, 0644) == 0 && fsync(fd) == 0;
    ok = close(fd) == 0 && ok;
    if (!ok || rename(tmp, path) != 0) {
        snprintf(err, errlen, "%s: cannot write it: %s", path, strerror(errno));
        unlink(tmp);
        return -1;
    }
    return 0;
}

/* Loads the machine's INI and its hexapod; prints the reason on failure. */
static int calibrate_load(const char *path, struct inifile *ini, struct kins **k,
                          struct calib_geom *g)
{
    char err[1024], msg[1536];
    if (inifile_load(ini, path, err, sizeof err) != INIFILE_OK) {
        fprintf(stderr, "hexcnc calibrate: %s\n", err);
        return -1;
    }
    const char *name = inifile_get(ini, "KINS", "KINEMATICS");
    if (!name || strcmp(name, "hexapod")) {
        fprintf(stderr, "hexcnc calibrate: %s:%d: [KINS] KINEMATICS: '%s': calibration "
                "needs the hexapod model\n", path, inifile_line(ini, "KINS", "KINEMATICS"),
                name ? name : "");
        return -1;
    }
    struct kins_config cfg = { inifile_config_get, ini };
    err[0] = '\0';
    int st = kins_create(&kins_hexapod_ops, &cfg, k, err, sizeof err);
    if (st != KINS_OK) {
        fprintf(stderr, "hexcnc calibrate: %s\n",
                inifile_locate_msg(ini, err[0] ? err : kins_strerror(st), msg, sizeof msg));
        return -1;
    }
    calib_geom_from_kins(*k, g, err, sizeof err);
    return 0;
}

/* `plan`: N poses as CSV on stdout or into -o; the condition number on stderr. */
static int calibrate_plan(const struct calibrate_args *a, struct kins *k,
                          const struct calib_geom *g)
{
    char *end, err[1024] = "";
    long n = strtol(a->input, &end, 10);
    if (end == a->input || *end || n < 1 || n > 100000) {
        fprintf(stderr, "hexcnc calibrate plan: N: '%s' is not a count of poses\n", a->input);
        return 2;
    }
    struct calib_plan_opts po;
    calib_plan_opts_default(&po);
    if (a->has_seed)
        po.seed = a->seed;
    if (po.candidates < 20 * n)
        po.candidates = (int)(20 * n);
    double (*pose)[KINS_POSE_DIM] = calloc((size_t)n, sizeof *pose), cond;
    char *csv = NULL;  /* the CSV text, built in memory, then printed or written */
    size_t csv_len = 0;
    FILE *mem = NULL;
    int rc = 1;
    if (!pose || !(mem = open_memstream(&csv, &csv_len)))
        goto done;
    enum calib_status st = calib_plan(k, g, &po, (int)n, pose, &cond, err, sizeof err);
    if (st != CALIB_OK) {
        fprintf(stderr, "hexcnc calibrate plan: %s\n", err[0] ? err : calib_strerror(st));
        goto done;
    }
    fprintf(mem, "# %ld calibration poses for %s (D-optimal among %d reachable candidates, "
            "seed %llu); condition number of the identification %.1f\nX,Y,Z,A,B,C\n", n,
            a->config, po.candidates, (unsigned long long)po.seed, cond);
    for (long j = 0; j < n; j++)
        fprintf(mem, "%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n", pose[j][0], pose[j][1], pose[j][2],
                pose[j][3], pose[j][4], pose[j][5]);
    fclose(mem);
    mem = NULL;
    if (!a->out)
        fputs(csv, stdout);
    else if (calibrate_write_atomic(a->out, csv, err, sizeof err) != 0) {
        fprintf(stderr, "hexcnc calibrate plan: %s\n", err);
        goto done;
    }
    fprintf(stderr, "hexcnc calibrate plan: %ld poses, condition number of the "
            "identification %.1f%s%s\n", n, cond, a->out ? ", written to " : "",
            a->out ? a->out : "");
    rc = 0;
done:
    if (mem)
        fclose(mem);
    free(csv);
    free(pose);
    return rc;
}

/* Root mean square of measurement j's six leg residuals. */
static double calibrate_row_rms(const double *res, int j)
{
    double s = 0.0;
    for (int i = 0; i < CALIB_LEGS; i++)
        s += res[j * CALIB_LEGS + i] * res[j * CALIB_LEGS + i];
    return sqrt(s / CALIB_LEGS);
}

/* Prints the fit: residuals per measurement and in total, outliers, parameters. */
static void calibrate_report(const char *path, const struct calib_meas *m,
                             const struct calib_geom *nominal, const struct calib_fit_result *r,
                             double poor_gain)
{
    char name[32];
    printf("# residuals (mm): leg length at the measured pose - (drive length + offset), rms "
           "of the six legs\n# line  before     after\n");
    for (int j = 0; j < r->n; j++)
        printf("%6d  %9.6f  %9.6f%s\n", m[j].line, calibrate_row_rms(r->before_mm, j),
               calibrate_row_rms(r->after_mm, j), r->outlier[j] ? "  outlier (set aside)" : "");
    printf("total: %d measurements, %d outliers set aside; rms %.6f -> %.6f mm, max %.6f -> "
           "%.6f mm; noise estimate %.6f mm; condition number %.1f\n", r->n, r->n_outliers,
           r->rms_before_mm, r->rms_after_mm, r->max_before_mm, r->max_after_mm, r->noise_mm,
           r->condition);
    for (int j = 0; j < r->n; j++)
        for (int i = 0; i < CALIB_LEGS && r->outlier[j]; i++)
            if (fabs(r->after_mm[j * CALIB_LEGS + i]) > 3.0 * r->noise_mm)
                printf("outlier: %s:%d: leg %d residual %.4f mm\n", path, m[j].line, i + 1,
                       r->after_mm[j * CALIB_LEGS + i]);
    double xn[CALIB_NPARAM], xc[CALIB_NPARAM];
    calib_geom_to_params(nominal, xn);
    calib_geom_to_params(&r->geom, xc);
    printf("# parameter       nominal (mm)  calibrated (mm)  change (mm)  std dev (mm)\n");
    int poor = 0;
    for (int k = 0; k < CALIB_NPARAM; k++) {
        printf("%-14s %14.6f %16.6f %12.6f %13.6f%s\n", calib_param_name(k, name, sizeof name),
               xn[k], xc[k], xc[k] - xn[k], r->sigma_mm[k],
               r->gain[k] > poor_gain ? "  poorly observable" : "");
        poor += r->gain[k] > poor_gain;
    }
    if (poor)
        printf("%d parameters poorly observable (std dev over %.0f x the noise): add or plan "
               "more poses (`hexcnc calibrate plan`)\n", poor, poor_gain);
    else
        printf("every parameter observable (std dev at most %.0f x the noise)\n", poor_gain);
}

/* Writes the calibrated INI, checked by loading its kinematics before it takes the name. */
static int calibrate_write_ini(const struct calibrate_args *a, const char *ini_text,
                               const struct calib_fit_result *r, struct kins_config *base)
{
    char note[512], err[1024] = "";
    snprintf(note, sizeof note, "by `hexcnc calibrate fit` from %s: %d measurements, rms "
             "residual %.6f -> %.6f mm", a->input, r->n - r->n_outliers, r->rms_before_mm,
             r->rms_after_mm);
    struct kins *check = NULL;
    if (calib_kins_create(base, &r->geom, &check, err, sizeof err) != CALIB_OK) {
        fprintf(stderr, "hexcnc calibrate fit: the calibrated geometry is refused: %s\n", err);
        return -1;
    }
    kins_free(check);
    char *text = calib_ini_rewrite(ini_text, &r->geom, note);
    int rc = text ? calibrate_write_atomic(a->out, text, err, sizeof err) : -1;
    if (rc != 0)
        fprintf(stderr, "hexcnc calibrate fit: %s\n", text ? err : "out of memory");
    else
        fprintf(stderr, "hexcnc calibrate fit: calibrated configuration written to %s\n",
                a->out);
    free(text);
    return rc;
}

/* `fit`: identification from the measurement file, report, optional calibrated INI. */
static int calibrate_fit(const struct calibrate_args *a, struct inifile *ini,
                         const struct calib_geom *nominal)
{
    char err[1024] = "";
    struct calib_meas *m = NULL;
    int n = 0, rc = 1;
    struct calib_fit_result r = { 0 };
    char *csv = calibrate_read_text(a->input, err, sizeof err);
    char *ini_text = calibrate_read_text(a->config, err, sizeof err);
    if (!csv || !ini_text) {
        fprintf(stderr, "hexcnc calibrate fit: %s\n", err);
        goto done;
    }
    enum calib_status st = calib_csv_parse(csv, a->input, &m, &n, err, sizeof err);
    struct calib_fit_opts o;
    calib_fit_opts_default(&o);
    if (st == CALIB_OK)
        st = calib_fit(nominal, m, n, &o, &r, err, sizeof err);
    if (st != CALIB_OK) {
        fprintf(stderr, "hexcnc calibrate fit: %s%s%s\n", st == CALIB_ERR_ARG ? "" : a->input,
                st == CALIB_ERR_ARG ? "" : ": ", err[0] ? err : calib_strerror(st));
        goto done;
    }
    calibrate_report(a->input, m, nominal, &r, o.poor_gain);
    struct kins_config base = { inifile_config_get, ini };
    rc = a->out && calibrate_write_ini(a, ini_text, &r, &base) != 0;
done:
    calib_fit_result_free(&r);
    free(m);
    free(csv);
    free(ini_text);
    return rc;
}

/* Reads the command line; -1 after printing what is wrong. */
static int calibrate_parse(int argc, char **argv, struct calibrate_args *a)
{
    int pos = 0;
    const char **positional[3] = { &a->verb, &a->config, &a->input };
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "-o") && i + 1 < argc) {
            a->out = argv[++i];
        } else if (!strcmp(argv[i], "--force")) {
            a->force = 1;
        } else if (!strcmp(argv[i], "--seed") && i + 1 < argc) {
            char *end;
            a->seed = strtoull(argv[++i], &end, 10);
            a->has_seed = 1;
            if (*end || end == argv[i]) {
                fprintf(stderr, "hexcnc calibrate: --seed: '%s' is not a number\n", argv[i]);
                return -1;
            }
        } else if (argv[i][0] == '-' && argv[i][1]) {
            fprintf(stderr, "hexcnc calibrate: unknown option '%s'\n", argv[i]);
            return -1;
        } else if (pos < 3) {
            *positional[pos++] = argv[i];
        } else {
            fprintf(stderr, "hexcnc calibrate: unexpected argument '%s'\n", argv[i]);
            return -1;
        }
    }
    if (pos < 3 || (strcmp(a->verb, "plan") && strcmp(a->verb, "fit"))) {
        fprintf(stderr, "usage: hexcnc %s\n", cmd_calibrate_usage);
        return -1;
    }
    return 0;
}

/* Entry point. */
int cmd_calibrate(int argc, char **argv)
{
    struct calibrate_args a = { 0 };
    if (calibrate_parse(argc, argv, &a) != 0)
        return 2;
    char err[1024];
    if (a.out && calibrate_check_target(a.out, a.config, a.force, err, sizeof err) != 0) {
        fprintf(stderr, "hexcnc calibrate %s: %s\n", a.verb, err);
        return 1;
    }
    if (a.out && !strcmp(a.verb, "fit") &&
        calibrate_check_target(a.out, a.input, a.force, err, sizeof err) != 0) {
        fprintf(stderr, "hexcnc calibrate %s: %s\n", a.verb, err);
        return 1;
    }
    struct inifile ini = { 0 };
    struct kins *k = NULL;
    struct calib_geom g;
    int rc = 1;
    if (calibrate_load(a.config, &ini, &k, &g) == 0)
        rc = !strcmp(a.verb, "plan") ? calibrate_plan(&a, k, &g) : calibrate_fit(&a, &ini, &g);
    kins_free(k);
    inifile_free(&ini);
    return rc;
}
