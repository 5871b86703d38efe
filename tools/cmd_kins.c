/* cmd_kins.c: `hexcnc kins CONFIG.ini inverse X Y Z A B C | forward L1..L6`. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <ini.h>

#include "kins/kins.h"
#include "tools/cmd.h"

const char cmd_kins_usage[] =
    "kins CONFIG.ini inverse X Y Z A B C | forward L1..L6   pose (mm, deg) <-> legs (mm)";

/* One INI entry, with the line it came from for messages. */
struct kins_ini_entry {
    char *section;
    char *key;
    char *value;
    int line;
};

/* The whole INI file in memory: the kinematics reads it through kins_config. */
struct kins_ini {
    const char *path;              /* file name, for messages */
    FILE *f;                       /* open while parsing */
    int line;                      /* line number of the line being parsed */
    struct kins_ini_entry *items;  /* entries in file order */
    size_t n, cap;                 /* used and allocated entries */
    int nomem;                     /* set when an allocation failed */
};

/* Line reader for inih that counts lines, so entries know where they are. */
static char *kins_ini_read_line(char *str, int num, void *stream)
{
    struct kins_ini *ini = stream;
    char *s = fgets(str, num, ini->f);
    if (s)
        ini->line++;
    return s;
}

/* Stores one key; the first of duplicate keys wins, as in LinuxCNC's INI lookup. */
static int kins_ini_store(void *user, const char *section, const char *key, const char *value)
{
    struct kins_ini *ini = user;
    if (ini->n == ini->cap) {
        size_t cap = ini->cap ? 2 * ini->cap : 64;
        struct kins_ini_entry *p = realloc(ini->items, cap * sizeof *p);
        if (!p) {
            ini->nomem = 1;
            return 0;
        }
        ini->items = p;
        ini->cap = cap;
    }
    struct kins_ini_entry *e = &ini->items[ini->n];
    e->section = strdup(section);
    e->key = strdup(key);
    e->value = strdup(value);
    e->line = ini->line;
    if (!e->section || !e->key || !e->value) {
        free(e->section);
        free(e->key);
        free(e->value);
        ini->nomem = 1;
        return 0;
    }
    ini->n++;
    return 1;
}

/* Finds [section] key (case-sensitive, like LinuxCNC); NULL when absent. */
static const struct kins_ini_entry *kins_ini_find(const struct kins_ini *ini,
                                                  const char *section, const char *key)
{
    for (size_t i = 0; i < ini->n; i++)
        if (!strcmp(ini->items[i].section, section) && !strcmp(ini->items[i].key, key))
            return &ini->items[i];
    return NULL;
}

/* The kins_config lookup over the loaded file. */
static const char *kins_ini_get(void *ctx, const char *section, const char *key)
{
    const struct kins_ini_entry *e = kins_ini_find(ctx, section, key);
    return e ? e->value : NULL;
}

/* Frees every stored entry. */
static void kins_ini_free(struct kins_ini *ini)
{
    for (size_t i = 0; i < ini->n; i++) {
        free(ini->items[i].section);
        free(ini->items[i].key);
        free(ini->items[i].value);
    }
    free(ini->items);
}

/* Reads the INI file; 0 on success, else prints why. */
static int kins_ini_load(struct kins_ini *ini, const char *path)
{
    memset(ini, 0, sizeof *ini);
    ini->path = path;
    ini->f = fopen(path, "r");
    if (!ini->f) {
        fprintf(stderr, "hexcnc kins: %s: cannot open: %s\n", path, strerror(errno));
        return -1;
    }
    int rc = ini_parse_stream(kins_ini_read_line, ini, kins_ini_store, ini);
    fclose(ini->f);
    ini->f = NULL;
    if (ini->nomem) {
        fprintf(stderr, "hexcnc kins: %s: out of memory\n", path);
        return -1;
    }
    if (rc > 0) {
        fprintf(stderr, "hexcnc kins: %s:%d: not an INI line (expected [SECTION] or "
                "KEY = VALUE)\n", path, rc);
        return -1;
    }
    return rc == 0 ? 0 : -1;
}

/* Prints a kinematics message; one that starts "[SECTION] KEY:" gets the key's line. */
static void kins_report(const struct kins_ini *ini, const char *msg)
{
    char section[64], key[64];
    if (sscanf(msg, "[%63[^]]] %63[^:]:", section, key) == 2) {
        const struct kins_ini_entry *e = kins_ini_find(ini, section, key);
        if (e) {
            fprintf(stderr, "hexcnc kins: %s:%d: %s\n", ini->path, e->line, msg);
            return;
        }
    }
    fprintf(stderr, "hexcnc kins: %s: %s\n", ini->path, msg);
}

/* Parses n command-line numbers; prints which one is wrong. */
static int kins_parse_args(char **argv, int n, const char *const *names, double *out)
{
    for (int i = 0; i < n; i++) {
        char *end;
        errno = 0;
        out[i] = strtod(argv[i], &end);
        if (end == argv[i] || *end != '\0' || errno == ERANGE || !isfinite(out[i])) {
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
    fprintf(stderr, "hexcnc kins: unknown mode '%s' (expected inverse or forward)\n", mode);
    return 2;
}

/* Entry point: load the INI, load the kinematics by name, run one conversion. */
int cmd_kins(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: hexcnc %s\n", cmd_kins_usage);
        return 2;
    }
    struct kins_ini ini;
    if (kins_ini_load(&ini, argv[1]) != 0) {
        kins_ini_free(&ini);
        return 1;
    }
    int rc = 1;
    struct kins *k = NULL;
    char err[1024];
    const struct kins_ini_entry *name = kins_ini_find(&ini, "KINS", "KINEMATICS");
    if (!name) {
        fprintf(stderr, "hexcnc kins: %s: [KINS] KINEMATICS: missing (e.g. hexapod)\n",
                ini.path);
        goto done;
    }
    struct kins_config cfg = { kins_ini_get, &ini };
    int st = kins_load(name->value, &cfg, &k, err, sizeof err);
    if (st == KINS_ERR_PLUGIN) {
        fprintf(stderr, "hexcnc kins: %s:%d: [KINS] KINEMATICS: %s\n", ini.path, name->line,
                err);
        goto done;
    }
    if (st != KINS_OK) {
        kins_report(&ini, err[0] ? err : kins_strerror(st));
        goto done;
    }
    rc = kins_run(k, argv[2], argv + 3, argc - 3);
done:
    kins_free(k);
    kins_ini_free(&ini);
    return rc;
}
