/* bench_oword.c: interpreter speed on a program that is mostly O-word control flow
 * (subroutine calls with arguments, while / repeat / if, expressions), against rs274 -g. */
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

#define CALLS 4000       /* subroutine calls (each a polygon) */
#define SIDES 24         /* while-loop iterations per call */

/*
 * The program: a repeat loop calls o<poly> CALLS times with four arguments; o<poly> runs a
 * while loop over SIDES corners, each with an if / elseif / else, a nested call of a small
 * function subroutine (o<wave>, returning a value in #<_wave>), local and global named
 * parameters and trigonometric expressions, and feeds one move per corner whose X Y come
 * from that arithmetic: 4000 x 24 = 96,000 moves, each after a dozen lines of control flow.
 * Both interpreters print to a file in /tmp, so the comparison is like for like.
 */
static int generate(const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f,
            "(O-word control flow for bench_oword)\n"
            "G21 G90 G17 G94 F1500\n"
            "o<wave> sub\n"
            "  #<_wave> = [#1 * SIN[#2] + [#1 / 3] * SIN[3 * #2]]\n"
            "o<wave> endsub\n"
            "o<poly> sub\n"
            "  (#1 sides, #2 radius, #3 centre X, #4 centre Y)\n"
            "  #<k> = 0\n"
            "  o110 while [#<k> LT #1]\n"
            "    #<a> = [360 * #<k> / #1]\n"
            "    o<wave> call [#2 / 10] [#<a>]\n"
            "    o120 if [[#<k> MOD 3] EQ 0]\n"
            "      #<r> = [#2 + #<_wave>]\n"
            "    o120 elseif [[#<k> MOD 3] EQ 1]\n"
            "      #<r> = [#2 - ABS[#<_wave>]]\n"
            "    o120 else\n"
            "      #<r> = [SQRT[#2 * #2 + #<_wave> * #<_wave>]]\n"
            "    o120 endif\n"
            "    G1 X[#3 + #<r> * COS[#<a>]] Y[#4 + #<r> * SIN[#<a>]]\n"
            "    #<k> = [#<k> + 1]\n"
            "  o110 endwhile\n"
            "o<poly> endsub\n"
            "#<n> = 0\n"
            "o200 repeat [%d]\n"
            "  #<cx> = [[#<n> MOD 40] * 30 - 600]\n"
            "  #<cy> = [FIX[#<n> / 40] * 30 - 1500]\n"
            "  o<poly> call [%d] [10 + [#<n> MOD 7]] [#<cx>] [#<cy>]\n"
            "  #<n> = [#<n> + 1]\n"
            "o200 endrepeat\n"
            "M2\n", CALLS, SIDES);
    return fclose(f);
}

/* Best of three runs of the library on the file to a null sink; *moves its feed moves. */
static double time_library(const char *path, long *moves)
{
    double best = 1e30;
    for (int r = 0; r < 3; r++) {
        struct interp *in = interp_create();
        if (!in)
            exit(1);
        *moves = 0;
        double t0 = now_s();
        int rc = interp_run_file(in, path, null_sink, moves);
        double dt = now_s() - t0;
        if (rc) {
            fprintf(stderr, "bench_oword: the program failed: %s\n",
                    interp_last_error(in)->message);
            exit(1);
        }
        if (dt < best)
            best = dt;
        interp_destroy(in);
    }
    return best;
}

/* Moves a printed program holds (STRAIGHT_FEED lines of a file), -1 if it cannot be read. */
static long count_feeds(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return -1;
    char line[512];
    long n = 0;
    while (fgets(line, sizeof line, f))
        n += strstr(line, "STRAIGHT_FEED(") != NULL;
    fclose(f);
    return n;
}

/* The next STRAIGHT_FEED's arguments in f, a zero printed as -0.0000 made 0.0000; 0 at the
 * end. */
static int next_feed(FILE *f, char *args, size_t len)
{
    char line[512];
    while (fgets(line, sizeof line, f)) {
        const char *p = strstr(line, "STRAIGHT_FEED(");
        if (!p)
            continue;
        size_t n = 0;
        for (p += 14; *p && *p != '\n' && n + 1 < len; p++) {
            if (*p == '-' && strncmp(p, "-0.0000", 7) == 0 && (p[7] == ',' || p[7] == ')'))
                continue;
            args[n++] = *p;
        }
        args[n] = 0;
        return 1;
    }
    return 0;
}

/* Whether two printed programs have the same moves; prints the first difference. */
static int same_moves(const char *a_path, const char *b_path)
{
    FILE *a = fopen(a_path, "r"), *b = fopen(b_path, "r");
    int same = a && b;
    char la[512], lb[512];
    for (long k = 1; same; k++) {
        int ea = next_feed(a, la, sizeof la), eb = next_feed(b, lb, sizeof lb);
        if (!ea && !eb)
            break;
        if (ea != eb || strcmp(la, lb) != 0) {
            printf("move %ld differs: rs274 (%s) hexcnc (%s)\n", k, ea ? la : "none",
                   eb ? lb : "none");
            same = 0;
        }
    }
    if (a)
        fclose(a);
    if (b)
        fclose(b);
    return same;
}

/* Generates the program, times the library, `hexcnc interp` and rs274 -g, prints the ratio
 * (--generate FILE: writes the program only). */
int main(int argc, char **argv)
{
    if (argc == 3 && strcmp(argv[1], "--generate") == 0)   /* the program alone, to look at */
        return generate(argv[2]) ? 1 : 0;
    char path[] = "/tmp/bench_oword_XXXXXX", out[] = "/tmp/bench_oword_out_XXXXXX";
    char rs_out[] = "/tmp/bench_oword_rs_XXXXXX";
    int fd = mkstemp(path), fo = mkstemp(out), fr = mkstemp(rs_out);
    if (fd < 0 || fo < 0 || fr < 0)
        return 1;
    close(fd);
    close(fo);
    close(fr);
    if (generate(path)) {
        fprintf(stderr, "bench_oword: cannot write %s\n", path);
        return 1;
    }
    long moves = 0;
    double t_lib = time_library(path, &moves);
    printf("program: %d calls of a %d-corner subroutine (while, if/elseif/else, a nested "
           "function call, expressions): %ld moves; times are CPU seconds\n", CALLS, SIDES,
           moves);
    printf("library, null sink:          %.3f s  %10.0f moves/s\n", t_lib, moves / t_lib);
    const char *bin = getenv("HEXCNC_BIN");
    char cmd[1024];
    double t_cmd = -1;
    if (bin) {
        snprintf(cmd, sizeof cmd, "'%s' interp '%s' > '%s'", bin, path, out);
        t_cmd = time_command(cmd, 3);
        if (t_cmd > 0)
            printf("hexcnc interp > file:        %.3f s  %10.0f moves/s\n", t_cmd, moves / t_cmd);
        if (t_cmd > 0 && count_feeds(out) != moves)
            printf("hexcnc interp printed %ld moves, the library gave %ld\n", count_feeds(out),
                   moves);
    }
    if (system("command -v rs274 > /dev/null 2>&1") != 0) {
        printf("rs274 (LinuxCNC) not installed: comparison skipped\n");
        unlink(path);
        unlink(out);
        unlink(rs_out);
        return 0;
    }
    snprintf(cmd, sizeof cmd, "rs274 -g '%s' > '%s' 2>/dev/null", path, rs_out);
    double t_rs = time_command(cmd, 3);
    long rs_moves = count_feeds(rs_out);
    if (t_rs <= 0 || rs_moves != moves) {
        printf("rs274 -g %s (%ld moves, hexcnc %ld): comparison skipped\n",
               t_rs <= 0 ? "failed on the program" : "read the program differently",
               rs_moves, moves);
    } else {
        printf("rs274 -g > file:             %.3f s  %10.0f moves/s\n", t_rs, moves / t_rs);
        printf("ratio rs274 / hexcnc library: %.1fx\n", t_rs / t_lib);
        if (t_cmd > 0)
            printf("ratio rs274 / hexcnc interp:  %.1fx\n", t_rs / t_cmd);
        if (t_cmd > 0 && same_moves(rs_out, out))
            printf("the %ld moves hexcnc interp printed are rs274's, digit for digit\n", moves);
    }
    unlink(path);
    unlink(out);
    unlink(rs_out);
    return 0;
}
