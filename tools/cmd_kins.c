/* cmd_kins.c: `hexcnc kins CONFIG.ini inverse X Y Z A B C | forward L1..L6`. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common/config.h"
#include "kins/kins.h"
#include "tools/cmd.h"

const char cmd_kins_usage[] =
    "kins CONFIG.ini inverse X Y Z A B C | forward L1..L6 | workspace [A B C]   pose (mm, deg) "
    "<-> legs (mm); how far the machine reaches from HOME";

/* Parses n command-line numbers; prints which one is wrong. */
static int kins_parse_args(char **argv, int n, const char *const *names, double *out)
{
    for (int i = 0; i < n; i++) {
        if (config_parse_number(argv[i], &out[i], NULL, 0) != 0) {
            fprintf(stderr, "hexcnc kins: %s: '%s' is not a number\n", names[i], argv[i]);
            return -1;
        }
    }
    return 0;
}

/* Prints numbers with 9 decimals on one line. */
static void kins_print(const double *v, int n)
{
    for (int i = 0; i < n; i++) /* below the last digit: print 0, not -0.000000000 */
        printf("%s%.9f", i ? " " : "", fabs(v[i]) < 5e-10 ? 0.0 : v[i]);
    printf("\n");
}

/* Names every leg outside its limits and by how much; verb is "would be" or "is". */
static void kins_report_legs(const struct kins *k, const double *legs, const char *what,
                             const char *verb)
{
    for (int i = 0; i < k->njoints; i++) {
        if (legs[i] > k->joint_max[i])
            fprintf(stderr, "hexcnc kins: %s: leg %d %s %.3f mm, %.3f mm above its "
                    "maximum %.3f mm ([JOINT_%d] MAX_LIMIT)\n", what, i + 1, verb, legs[i],
                    legs[i] - k->joint_max[i], k->joint_max[i], i);
        else if (legs[i] < k->joint_min[i])
            fprintf(stderr, "hexcnc kins: %s: leg %d %s %.3f mm, %.3f mm below its "
                    "minimum %.3f mm ([JOINT_%d] MIN_LIMIT)\n", what, i + 1, verb, legs[i],
                    k->joint_min[i] - legs[i], k->joint_min[i], i);
    }
}

/* How far the pose can go from `from` along axis j in direction sign (mm or deg), every pose
 * on the way reachable, to within 0.01; `why` says what stops it there. */
static double kins_reach(struct kins *k, const double from[KINS_POSE_DIM], int j, int sign,
                         char *why, size_t len)
{
    double step = j < 3 ? 1.0 : 0.1, limit = j < 3 ? 3000.0 : 180.0, ok = 0, bad = -1;
    double pose[KINS_POSE_DIM], legs[KINS_MAX_JOINTS];
    memcpy(pose, from, sizeof pose);
    for (double d = step; d <= limit + 1e-9; d += step) {
        pose[j] = from[j] + sign * d;
        if (kins_inverse(k, pose, legs) != KINS_OK) {
            bad = d;
            break;
        }
        ok = d;
    }
    if (bad < 0) {
        snprintf(why, len, "nothing within %g %s", limit, j < 3 ? "mm" : "deg");
        return ok;
    }
    while (bad - ok > 0.005) {
        double mid = 0.5 * (ok + bad);
        pose[j] = from[j] + sign * mid;
        if (kins_inverse(k, pose, legs) == KINS_OK)
            ok = mid;
        else
            bad = mid;
    }
    pose[j] = from[j] + sign * bad;
    if (kins_describe(k, pose, why, len) == KINS_OK || !why[0])   /* a model without words */
        snprintf(why, len, "%s", kins_strerror(kins_inverse(k, pose, legs)));
    return ok;
}

/* `workspace [A B C]`: the reach from HOME along each axis, and what limits it. */
static int kins_workspace(struct kins *k, char **args, int nargs)
{
    static const char *const names[] = { "X", "Y", "Z", "A", "B", "C" };
    double from[KINS_POSE_DIM], legs[KINS_MAX_JOINTS];
    memcpy(from, k->home, sizeof from);
    if (nargs != 0 && nargs != 3) {
        fprintf(stderr, "hexcnc kins: workspace takes no argument or the orientation A B C\n");
        return 2;
    }
    if (nargs == 3 && kins_parse_args(args, 3, names + 3, from + 3) != 0)
        return 2;
    char why[300];
    if (kins_inverse(k, from, legs) != KINS_OK) {
        kins_describe(k, from, why, sizeof why);
        fprintf(stderr, "hexcnc kins: HOME's position at A%g B%g C%g is outside the workspace: "
                "%s\n", from[3], from[4], from[5], why[0] ? why : "unreachable");
        return 1;
    }
    printf("reach from X%g Y%g Z%g A%g B%g C%g, every pose on the way reachable:\n",
           from[0], from[1], from[2], from[3], from[4], from[5]);
    printf("%-4s %12s   %s\n", "axis", "reach", "limited by");
    for (int j = 0; j < KINS_POSE_DIM; j++)
        for (int sign = 1; sign >= -1; sign -= 2) {
            double r = kins_reach(k, from, j, sign, why, sizeof why);
            printf("%s%-3s %9.2f %-3s  %s\n", sign > 0 ? "+" : "-", names[j], r,
                   j < 3 ? "mm" : "deg", why);
        }
    return 0;
}

/* Runs one inverse or forward and prints the result; returns the exit status. */
static int kins_run(struct kins *k, const char *mode, char **args, int nargs)
{
    static const char *const pose_names[] = { "X", "Y", "Z", "A", "B", "C" };
    static const char *const leg_names[] = { "L1", "L2", "L3", "L4", "L5", "L6", "L7", "L8",
                                             "L9" };
    double in[KINS_MAX_JOINTS], out[KINS_MAX_JOINTS];
    if (!strcmp(mode, "inverse")) {
        if (nargs != KINS_POSE_DIM || kins_parse_args(args, nargs, pose_names, in) != 0) {
            if (nargs != KINS_POSE_DIM)
                fprintf(stderr, "hexcnc kins: inverse needs 6 numbers: X Y Z A B C\n");
            return 2;
        }
        int st = kins_inverse(k, in, out);
        if (st == KINS_ERR_UNREACHABLE) {
            kins_report_legs(k, out, "pose unreachable", "would be");
            return 1;
        }
        char why[300];
        if (st == KINS_ERR_WORKSPACE && kins_describe(k, in, why, sizeof why) != KINS_OK) {
            fprintf(stderr, "hexcnc kins: pose outside the workspace: %s\n", why);
            return 1;
        }
        if (st != KINS_OK) {
            fprintf(stderr, "hexcnc kins: inverse: %s\n", kins_strerror(st));
            return 1;
        }
        kins_print(out, k->njoints);
        return 0;
    }
    if (!strcmp(mode, "forward")) {
        if (nargs != k->njoints || kins_parse_args(args, nargs, leg_names, in) != 0) {
            if (nargs != k->njoints)
                fprintf(stderr, "hexcnc kins: forward needs %d leg lengths\n", k->njoints);
            return 2;
        }
        struct kins_fwd_info info = { 0, 0.0 };
        memcpy(out, k->home, sizeof k->home);
        int st = kins_forward(k, in, out, &info);
        if (st == KINS_ERR_LEG_RANGE) {
            kins_report_legs(k, in, "leg length out of range", "is");
            return 1;
        }
        if (st != KINS_OK) {
            fprintf(stderr, "hexcnc kins: forward: %s (after %d iterations, leg residual "
                    "%.3g mm)\n", kins_strerror(st), info.iterations, info.residual_mm);
            return 1;
        }
        kins_print(out, KINS_POSE_DIM);
        return 0;
    }
    if (!strcmp(mode, "workspace"))
        return kins_workspace(k, args, nargs);
    fprintf(stderr, "hexcnc kins: unknown mode '%s' (expected inverse, forward or workspace)\n",
            mode);
    return 2;
}

/* Entry point: load the INI, load the kinematics by name, run one conversion. */
int cmd_kins(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: hexcnc %s\n", cmd_kins_usage);
        return 2;
    }
    struct inifile ini = { 0 };
    char err[1024], msg[1536];
    if (config_load(&ini, argv[1], err, sizeof err) != CONFIG_OK) {
        fprintf(stderr, "hexcnc kins: %s\n", err);
        return 1;
    }
    int rc = 1;
    struct kins *k = NULL;
    const char *name = inifile_get(&ini, "KINS", "KINEMATICS");
    if (!name) {
        fprintf(stderr, "hexcnc kins: %s: [KINS] KINEMATICS: missing (e.g. hexapod)\n",
                ini.path);
        goto done;
    }
    struct kins_config cfg = { inifile_config_get, &ini };
    int st = kins_load(name, &cfg, &k, err, sizeof err);
    if (st == KINS_ERR_PLUGIN) {
        fprintf(stderr, "hexcnc kins: %s:%d: [KINS] KINEMATICS: %s\n", ini.path,
                inifile_line(&ini, "KINS", "KINEMATICS"), err);
        goto done;
    }
    if (st != KINS_OK) {   /* "[SECTION] KEY: ..." is pointed at the key's line */
        fprintf(stderr, "hexcnc kins: %s\n",
                inifile_locate_msg(&ini, err[0] ? err : kins_strerror(st), msg, sizeof msg));
        goto done;
    }
    rc = kins_run(k, argv[2], argv + 3, argc - 3);
done:
    kins_free(k);
    inifile_free(&ini);
    return rc;
}
