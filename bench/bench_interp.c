/* bench_interp.c: interpreter speed on a 200,000-block five-axis program (against rs274 -g) and on G142 pockets. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "interp/interp.h"
#include "interp/printer.h"
#include "bench/bench_interp_util.h"

#define BLOCKS 200000

/* xorshift64: the same program on every run. */
static uint64_t next_rand(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

/* A value like a CAM post prints: up to `dec` decimals, trailing zeros dropped. */
static int put_value(char *out, double lo, double hi, int dec, uint64_t *s)
{
    double v = lo + (hi - lo) * (double)(next_rand(s) % 1000000) / 1e6;
    int n = sprintf(out, "%.*f", dec, v);
    while (n > 1 && out[n - 1] == '0')
        n--;
    if (out[n - 1] == '.')
        n--;
    out[n] = 0;
    return n;
}

/* Writes the benchmark program: G1 with X Y Z A B C F on every line. */
static int generate(const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    uint64_t s = 0x853c49e6748fea9bu;
    fprintf(f, "(five-axis feed moves for bench_interp)\nG21 G90 G17 G94 G64 P0.01\n");
    for (int i = 0; i < BLOCKS; i++) {
        char x[32], y[32], z[32], a[32], b[32], c[32], fe[32];
        put_value(x, -150, 150, 4, &s);
        put_value(y, -150, 150, 4, &s);
        put_value(z, 560, 680, 4, &s);
        put_value(a, -15, 15, 3, &s);
        put_value(b, -15, 15, 3, &s);
        put_value(c, -180, 180, 3, &s);
        put_value(fe, 200, 3000, 0, &s);
        fprintf(f, "G1 X%s Y%s Z%s A%s B%s C%s F%s\n", x, y, z, a, b, c, fe);
    }
    fprintf(f, "M2\n");
    return fclose(f);
}

#define COMP_SIDES 500   /* sides of each polygonal pocket of the compensated program */
#define COMP_RUNS 400    /* pockets: 400 x 502 blocks */

/* Writes the compensated benchmark program: COMP_RUNS closed G142 pockets (a 500-gon of
 * radius 60 mm, sides 0.75 mm, table tilted B-4 as in the paper), each started mid-edge
 * from the centre at the cutting depth, tool radius 5 mm. Every block is checked against the
 * pocket's contour near it (docs/compensation.md, gouge check). */
static int generate_comp(const char *path, long *blocks)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    *blocks = 0;
    fprintf(f, "(G142 pockets for bench_interp)\nG21 G90 G17 G94\n");
    for (int r = 0; r < COMP_RUNS; r++) {
        double cx = (r % 20) * 130.0 - 1300.0, cy = (r / 20) * 130.0 - 1300.0;
        fprintf(f, "G0 X%.4f Y%.4f Z630 A0 B-4\n", cx, cy);
        double a0 = 0.0, a1 = 2.0 * M_PI / COMP_SIDES;
        fprintf(f, "G142 X%.4f Y%.4f W5 F1000\n", cx + 30.0 * (cos(a0) + cos(a1)),
                cy + 30.0 * (sin(a0) + sin(a1)));
        for (int k = 1; k <= COMP_SIDES; k++) {
            double a = 2.0 * M_PI * (k % COMP_SIDES) / COMP_SIDES;
            fprintf(f, "G142 X%.4f Y%.4f\n", cx + 60.0 * cos(a), cy + 60.0 * sin(a));
        }
        fprintf(f, "G142 X%.4f Y%.4f\n", cx + 30.0 * (cos(a0) + cos(a1)),
                cy + 30.0 * (sin(a0) + sin(a1)));
        *blocks += COMP_SIDES + 3;
    }
    fprintf(f, "M2\n");
    return fclose(f);
}

/* Drops the printed text. */
static int null_write(void *ctx, const char *buf, size_t len)
{
    (void)ctx;
    (void)buf;
    (void)len;
    return 0;
}

/* Best of three runs of the library on the file: to a null sink, or through the printer. */
static double time_library(const char *path, int print, long *moves)
{
    double best = 1e30;
    for (int r = 0; r < 3; r++) {
        struct interp *in = interp_create();
        struct interp_printer *pr = malloc(sizeof *pr);
        if (!in || !pr)
            exit(1);
        interp_printer_init(pr, in, 4, null_write, NULL);
        *moves = 0;
        double t0 = now_s();
        int rc = print ? interp_run_file(in, path, interp_printer_sink, pr)
                       : interp_run_file(in, path, null_sink, moves);
        double dt = now_s() - t0;
        if (rc) {
            fprintf(stderr, "bench_interp: the program failed: %s\n",
                    interp_last_error(in)->message);
            exit(1);
        }
        if (dt < best)
            best = dt;
        free(pr);
        interp_destroy(in);
    }
    return best;
}

/* Generates the program, times each way of running it, prints the figures and the ratio. */
int main(int argc, char **argv)
{
    char path[] = "/tmp/bench_interp_XXXXXX";
    int fd = mkstemp(path);
    if (fd < 0)
        return 1;
    close(fd);
    if (argc == 3 && strcmp(argv[1], "--generate") == 0)
        return generate(argv[2]) ? 1 : (unlink(path), 0);
    if (generate(path)) {
        fprintf(stderr, "bench_interp: cannot write %s\n", path);
        return 1;
    }
    long moves = 0;
    double t_lib = time_library(path, 0, &moves);
    double t_print = time_library(path, 1, &moves);
    printf("program: %d five-axis G1 blocks (X Y Z A B C F on each); times are CPU seconds\n",
           BLOCKS);
    printf("library, null sink:        %.3f s  %10.0f blocks/s\n", t_lib, BLOCKS / t_lib);
    printf("library + rs274 printer:   %.3f s  %10.0f blocks/s\n", t_print, BLOCKS / t_print);
    long comp_blocks = 0;
    if (generate_comp(path, &comp_blocks)) {
        fprintf(stderr, "bench_interp: cannot write %s\n", path);
        return 1;
    }
    double t_comp = time_library(path, 0, &moves);
    printf("G142 pockets (%ld blocks, %ld moves), library, null sink: %.3f s  %10.0f blocks/s\n",
           comp_blocks, moves, t_comp, comp_blocks / t_comp);
    if (generate(path)) {
        fprintf(stderr, "bench_interp: cannot write %s\n", path);
        return 1;
    }
    const char *bin = getenv("HEXCNC_BIN");
    char cmd[1024];
    double t_cmd = -1;
    if (bin) {
        snprintf(cmd, sizeof cmd, "'%s' interp '%s' > /dev/null", bin, path);
        t_cmd = time_command(cmd, 3);
        if (t_cmd > 0)
            printf("hexcnc interp > /dev/null: %.3f s  %10.0f blocks/s\n", t_cmd, BLOCKS / t_cmd);
    }
    if (system("command -v rs274 > /dev/null 2>&1") == 0) {
        snprintf(cmd, sizeof cmd, "rs274 -g '%s' > /dev/null 2>&1", path);
        double t_rs = time_command(cmd, 1);
        if (t_rs > 0) {
            printf("rs274 -g > /dev/null:      %.3f s  %10.0f blocks/s\n", t_rs, BLOCKS / t_rs);
            if (t_cmd > 0)
                printf("ratio rs274 / hexcnc interp: %.1fx\n", t_rs / t_cmd);
        } else {
            printf("rs274 -g failed on the program: comparison skipped\n");
        }
    } else {
        printf("rs274 (LinuxCNC) not installed: comparison skipped\n");
    }
    unlink(path);
    return 0;
}
