/* bench_plan_dense.c: the planner alone on the dense five-axis hour (bench_dense.h): the
 * program interpreted into memory, then planned window by window as `hexcnc check` streams it
 * (motion_stream, no executor), its CPU time apart from the interpreter's. bench_check_dense's
 * plan CPU also holds the servo pass's measures the planner's thread computes while it waits,
 * which move between the threads with the load: this is the planning's own. */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include <unistd.h>

#include "bench/bench_dense.h"
#include "check/check.h"
#include "check/check_priv.h"

#define BLOCKS 240000
#define RUNS 3

static double thread_cpu_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(void)
{
    char prog[64], err[1024];
    snprintf(prog, sizeof prog, "/tmp/hexcnc_bench_plan_%d.ngc", (int)getpid());
    if (bench_dense_write(prog, BLOCKS) != 0) {
        fprintf(stderr, "bench_plan_dense: cannot write %s\n", prog);
        return 1;
    }
    struct check_machine *mc;
    if (check_machine_open("configs/sim/tmu-hexapod.ini", &mc, err, sizeof err) != CHECK_OK) {
        fprintf(stderr, "bench_plan_dense: %s\n", err);
        unlink(prog);
        return 1;
    }
    struct canon_prog p;
    struct check_problem pb;
    canon_prog_init(&p);
    double t0 = thread_cpu_s();
    int st = check_machine_interpret(mc, prog, &p, &pb);
    double interp_s = thread_cpu_s() - t0;
    unlink(prog);
    if (st != CHECK_OK) {
        fprintf(stderr, "bench_plan_dense: %s\n", pb.message);
        return 1;
    }
    printf("\nthe planner alone on the dense hour: %d blocks of %.1f mm, G64 P0.01, F2000, TMU "
           "machine, streamed windows (interpreted into memory first: %.3f s)\n", BLOCKS,
           STEP_MM, interp_s);
    printf("%-6s %10s %12s %10s %8s\n", "run", "plan CPU", "planned", "knots", "windows");
    for (int run = 0; run < RUNS && st == CHECK_OK; run++) {
        struct motion_stream *s;
        if (motion_stream_create(mc->motion, mc->kins->home, NULL, &s, err, sizeof err) !=
            MOTION_OK) {
            fprintf(stderr, "bench_plan_dense: %s\n", err);
            return 1;
        }
        t0 = thread_cpu_s();
        int ms = MOTION_OK;
        for (size_t i = 0; i < p.count && !ms; i++)
            ms = motion_stream_add(s, &p.cmds[i]);
        if (!ms)
            ms = motion_stream_finish(s);
        double cpu = thread_cpu_s() - t0;
        struct motion_stream_info si;
        motion_stream_info(s, &si);
        if (ms)
            fprintf(stderr, "bench_plan_dense: %s\n", motion_stream_error(s));
        else
            printf("%-6d %8.3f s %10.4f s %10zu %8zu\n", run + 1, cpu, si.plan.time_s,
                   si.plan.samples, si.windows);
        motion_stream_destroy(s);
        st = ms ? CHECK_ERR_VIOLATION : CHECK_OK;
    }
    canon_prog_free(&p);
    check_machine_close(mc);
    return st == CHECK_OK ? 0 : 1;
}
