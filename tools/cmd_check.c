/* cmd_check.c: `hexcnc check`: verifies a program on the simulated machine before cutting. */
#include <errno.h>
#include <malloc.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "check/check.h"
#include "check/plot.h"
#include "tools/cmd.h"

const char cmd_check_usage[] =
    "check [--json] [--plot DIR] [--every-period] CONFIG.ini PROGRAM\n"
    "                                verify a program before cutting: reach, leg limits,\n"
    "                                singularity, kinematic deviation, machining time";

/* Command-line options. */
struct args {
    int json;
    int every_period;        /* deviation and condition at every servo period */
    const char *plot_dir;
    const char *ini, *program;
};

/* Options and the two paths; -1 on a usage error. */
static int parse_args(int argc, char **argv, struct args *a)
{
    memset(a, 0, sizeof *a);
    for (int i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--json") == 0)
            a->json = 1;
        else if (strcmp(argv[i], "--every-period") == 0)
            a->every_period = 1;
        else if (strcmp(argv[i], "--plot") == 0 && i + 1 < argc)
            a->plot_dir = argv[++i];
        else if (argv[i][0] == '-' && argv[i][1])
            return -1;
        else if (!a->ini)
            a->ini = argv[i];
        else if (!a->program)
            a->program = argv[i];
        else
            return -1;
    }
    return a->ini && a->program ? 0 : -1;
}

/* Reads a whole file into memory (for the no-compensation contour of the plots). */
static char *read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    if (!f)
        return NULL;
    if (fseek(f, 0, SEEK_END) == 0) {
        long n = ftell(f);
        if (n >= 0 && fseek(f, 0, SEEK_SET) == 0 && (buf = malloc((size_t)n + 1))) {
            *len = fread(buf, 1, (size_t)n, f);
            buf[*len] = 0;
        }
    }
    fclose(f);
    return buf;
}

/* The programmed contour: the program with G141/G142 as G1 (NULL-safe on failure). */
static int contour_of(struct check_machine *mc, const char *path, struct canon_prog *contour)
{
    size_t len = 0;
    char *text = read_file(path, &len), *plain = text ? check_strip_compensation(text, len) : NULL;
    struct check_problem p;
    int st = plain ? check_machine_interpret_text(mc, path, plain, len, contour, &p) : -1;
    free(text);
    free(plain);
    return st;
}

/* Interprets, checks and (with --plot) writes the plots. */
static int run_check(struct check_machine *mc, const struct args *a, struct check_result *res)
{
    struct check_opts o;
    struct check_trace trace;
    struct canon_prog prog, contour;
    struct check_problem p;
    check_opts_default(&o);
    if (a->every_period)
        o.deviation_every_s = o.condition_every_s = 0;
    check_trace_init(&trace);
    canon_prog_init(&prog);
    canon_prog_init(&contour);
    if (!a->plot_dir)   /* streamed: bounded memory, planner and servo pass side by side */
        return check_program(mc, a->program, &o, res);
    o.trace = &trace;
    snprintf(res->program, sizeof res->program, "%s", a->program);
    int st = check_machine_interpret(mc, a->program, &prog, &p);
    if (st != CHECK_OK) {
        check_add_problem(res, &p);
        snprintf(res->config, sizeof res->config, "%s", a->ini);
    } else {
        st = check_canon(mc, &prog, &o, res);
    }
    if (res->simulated) {
        char err[512];
        if (mkdir(a->plot_dir, 0777) != 0 && errno != EEXIST)   /* one level, like mkdir */
            fprintf(stderr, "hexcnc check: cannot create %s: %s\n", a->plot_dir,
                    strerror(errno));
        int have_contour = contour_of(mc, a->program, &contour) == CHECK_OK;
        if (check_write_plots(a->plot_dir, &prog, have_contour ? &contour : NULL, &trace, res,
                              err, sizeof err) != CHECK_OK) {
            fprintf(stderr, "hexcnc check: %s\n", err);
            st = st == CHECK_OK ? CHECK_ERR_IO : st;
        }
    }
    canon_prog_free(&prog);
    canon_prog_free(&contour);
    check_trace_free(&trace);
    return st;
}

/* hexcnc check: exit 0 clean, 1 problems, 2 the check could not run. */
int cmd_check(int argc, char **argv)
{
    struct args a;
    if (parse_args(argc, argv, &a) != 0) {
        fprintf(stderr, "usage: hexcnc %s\n", cmd_check_usage);
        return 2;
    }
    /* The planner frees each window's plan and allocates the next one's: memory freed is
     * kept for it (below 64 MB) instead of going back to the system and coming again as
     * fresh zeroed pages, a page fault each 4 kB. */
    mallopt(M_MMAP_THRESHOLD, 64 << 20);
    mallopt(M_TRIM_THRESHOLD, 64 << 20);
    char err[1024];
    struct check_machine *mc;
    if (check_machine_open(a.ini, &mc, err, sizeof err) != CHECK_OK) {
        fprintf(stderr, "hexcnc check: %s\n", err);
        return 2;
    }
    struct check_result res;
    check_result_init(&res);
    int st = run_check(mc, &a, &res);
    if (a.json)
        check_print_json(&res, stdout);
    else
        check_print_table(&res, stdout);
    check_result_free(&res);
    check_machine_close(mc);
    return st == CHECK_OK ? 0 : st == CHECK_ERR_VIOLATION ? 1 : 2;
}
