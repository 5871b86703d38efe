/* experiment_main.c: `make experiment`: the paper's Table 1 and G142 run, simulated, beside the paper's d1..d4. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "check/experiment.h"

/* A d value, or a dash where the paper gives none. */
static void print_d(double v)
{
    if (isnan(v))
        printf(" %7s", "-");
    else
        printf(" %7.1f", v);
}

/* Run 1 again on two other machines: drives with 0.25 nm steps (no quantisation), and the
 * head left vertical on the tilted table (the paper tilted it by hand). */
static void extra(const char *root)
{
    static const char *const ini[2] = { "tests/check/tmu-path1-fine.ini",
                                        "tests/check/tmu-path1-vertical.ini" };
    static const char *const what[2] = { "drives with 0.25 nm steps", "head left vertical" };
    int n;
    printf("\nrun 1 on other machines:\n");
    for (int i = 0; i < 2; i++) {
        struct exp_run_def d = exp_runs(&n)[0];
        struct exp_result r;
        char err[512];
        d.ini = ini[i];
        if (exp_run(root, &d, NULL, &r, err, sizeof err) != 0) {
            fprintf(stderr, "run 1, %s: %s\n", what[i], err);
            continue;
        }
        printf("  %-26s d1..d4 %.4f %.4f %.4f %.4f mm; second part's wall minus the first's "
               "%+.4f um (single points agree within %.4f um)\n", what[i], r.d_mm[0], r.d_mm[1],
               r.d_mm[2], r.d_mm[3], r.part_diff_um, r.point_spread_um);
    }
}

/* Runs every experiment and prints the table; argv[1]: folder for the plots. */
int main(int argc, char **argv)
{
    const char *root = getenv("HEXCNC_ROOT"), *out = argc > 1 ? argv[1] : NULL;
    int n, failed = 0;
    const struct exp_run_def *runs = exp_runs(&n);
    if (!root)
        root = ".";
    printf("The paper's experiment in the cutting simulation (TMU hexapod, stepgens, 1 kHz).\n"
           "d = distance of the wall from the reference line 30 mm in from the block's edge, mm,\n"
           "at the top face; d1, d2 on the first tool's part, d3, d4 on the second's.\n\n");
    printf("run   path tools  code |     simulated d1..d4 (mm)          | paper d1..d4 (mm)"
           "               | agree, um   | without compensation d1..d4 (mm)  step\n");
    for (int i = 0; i < n; i++) {
        const struct exp_run_def *d = &runs[i];
        struct exp_result r;
        char err[512];
        if (exp_run(root, d, out, &r, err, sizeof err) != 0) {
            fprintf(stderr, "run %s: %s\n", d->name, err);
            failed = 1;
            continue;
        }
        printf("%-5s %4d  %2.0f-%2.0f  G%d |", d->name, d->path, 2 * r.radius_mm[1],
               2 * r.radius_mm[0], d->side);
        for (int k = 0; k < 4; k++)
            printf(" %8.4f", r.d_mm[k]);
        printf("  |");
        for (int k = 0; k < 4; k++)
            print_d(d->paper_d_mm[k]);
        printf("  | %5.2f (%4.2f) |", r.spread_um, r.point_spread_um);
        for (int k = 0; k < 4; k++)
            printf(" %7.3f", r.nocomp_d_mm[k]);
        printf("  %+6.3f mm (radii %+.1f)\n", r.nocomp_step_mm, r.radius_mm[1] - r.radius_mm[0]);
    }
    printf("\n'agree': largest difference between the four compensated walls, each read over "
           "+-%.1f mm\n(in brackets: single points); the drives step %.4f mm per leg.\n'step': second part's wall minus the first's when the same "
           "contour is cut with G1 and the tool centre on it.\n", EXP_WINDOW_MM, 1 / 400.0);
    extra(root);
    if (out)
        printf("plots: %s/exp_run*_top.svg, _wall.svg, _3d.svg\n", out);
    return failed;
}
