/* bench_interp_util.h: what the interpreter benches share: CPU clocks of the process and its
 * children, a counting sink, and a shell command timed best of n. */
#ifndef HEXCNC_BENCH_INTERP_UTIL_H
#define HEXCNC_BENCH_INTERP_UTIL_H

#include <stdlib.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>

#include "interp/canon.h"

/* CPU seconds of this process. */
static inline double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

/* CPU seconds (user + system) used by the finished children so far. */
static inline double children_s(void)
{
    struct rusage u;
    getrusage(RUSAGE_CHILDREN, &u);
    return (double)(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
           (double)(u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-6;
}

/* Counts feed moves, so the work cannot be optimised away. */
static inline int null_sink(void *ctx, const struct canon_cmd *c)
{
    (*(long *)ctx) += c->type == CANON_FEED;
    return 0;
}

/* CPU time of a shell command and its children (best of `runs`); < 0 if it fails. */
static inline double time_command(const char *cmd, int runs)
{
    double best = -1;
    for (int r = 0; r < runs; r++) {
        double t0 = children_s();
        int st = system(cmd);
        double dt = children_s() - t0;
        if (st == -1 || !WIFEXITED(st) || WEXITSTATUS(st) != 0)
            return -1;
        if (best < 0 || dt < best)
            best = dt;
    }
    return best;
}

#endif
