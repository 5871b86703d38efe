/* bench_dense.h: the dense five-axis CAM program of the benches (bench_check_dense, bench_jerk):
 * blocks of 0.5 mm with X Y Z A B C on every block, G64 P0.01, F2000, in the TMU's region. */
#ifndef HEXCNC_BENCH_DENSE_H
#define HEXCNC_BENCH_DENSE_H

#include <math.h>
#include <stdio.h>

#define STEP_MM 0.5

/* The program: a path that wanders (its direction turns by up to 0.3 rad a block) inside
 * X, Y +-90 mm while Z, A, B, C follow slow waves, every block with all six words; `last` (a
 * line of its own, or NULL) before the M2. The benches' program is seed 12345. */
static inline int bench_dense_write_seed(const char *path, int blocks, unsigned long long seed,
                                         const char *last)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "G21 G90 G64 P0.01\nG1 X0 Y0 Z645 A0 B0 C0 F2000\n");
    double x = 0, y = 0, ang = 0;
    for (int i = 0; i < blocks; i++) {
        seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
        ang += 0.6 * ((double)(seed >> 11) / 9007199254740992.0 - 0.5);
        double dx = STEP_MM * cos(ang), dy = STEP_MM * sin(ang);
        if (fabs(x + dx) > 90 || fabs(y + dy) > 90)
            ang += M_PI, dx = -dx, dy = -dy;
        x += dx, y += dy;
        fprintf(f, "X%.3f Y%.3f Z%.3f A%.3f B%.3f C%.3f\n", x, y, 645 + 10 * sin(i * 1e-3),
                6 * sin(i * 7e-4), 6 * cos(i * 9e-4), 8 * sin(i * 5e-4));
    }
    if (last)
        fprintf(f, "%s\n", last);
    fprintf(f, "M2\n");
    return fclose(f);
}

static inline int bench_dense_write(const char *path, int blocks)
{
    return bench_dense_write_seed(path, blocks, 12345, NULL);
}

#endif
