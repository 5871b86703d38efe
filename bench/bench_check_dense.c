/* bench_check_dense.c: hexcnc check on an hour of dense five-axis CAM code (240,000 blocks of
 * 0.5 mm, X Y Z A B C on every block, G64 P0.01, F2000 on the TMU machine): streamed (as
 * `hexcnc check` runs it) against the whole program held in memory, each in a child process
 * so that its peak memory is its own. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "bench/bench_dense.h"
#include "check/check.h"

#define BLOCKS 240000

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The child: one check, its figures on one line of the pipe. */
static void child(const char *ini, const char *prog, int whole, int fd)
{
    char err[1024], line[256];
    struct check_machine *mc;
    if (check_machine_open(ini, &mc, err, sizeof err) != CHECK_OK) {
        fprintf(stderr, "bench_check_dense: %s\n", err);
        _exit(1);
    }
    struct check_result r;
    check_result_init(&r);
    double t0 = now_s();
    int st;
    if (whole) {                 /* interpreted into memory, planned whole, then the servo pass */
        struct canon_prog p;
        struct check_problem pb;
        canon_prog_init(&p);
        st = check_machine_interpret(mc, prog, &p, &pb);
        if (st == CHECK_OK)
            st = check_canon(mc, &p, NULL, &r);
        canon_prog_free(&p);
    } else {
        st = check_program(mc, prog, NULL, &r);
    }
    double wall = now_s() - t0;
    int n = snprintf(line, sizeof line, "%d %.6f %.3f %ld %.4f %.3f %.3f\n", st, wall,
                     r.machining_time_s, r.periods, r.max_condition, r.servo_cpu_s,
                     r.plan_cpu_s);
    if (write(fd, line, (size_t)n) != n)
        _exit(1);
    check_result_free(&r);
    check_machine_close(mc);
    _exit(st == CHECK_OK ? 0 : 1);
}

/* Runs one check in a child; prints its row. Returns the wall time, or -1. */
static double run(const char *ini, const char *prog, int whole, const char *what)
{
    int fds[2];
    if (pipe(fds) != 0)
        return -1;
    pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        close(fds[0]);
        child(ini, prog, whole, fds[1]);
    }
    close(fds[1]);
    char buf[256] = "";
    ssize_t got = read(fds[0], buf, sizeof buf - 1);
    close(fds[0]);
    int status;
    struct rusage ru;
    if (wait4(pid, &status, 0, &ru) != pid || got <= 0 || !WIFEXITED(status) ||
        WEXITSTATUS(status) != 0) {
        fprintf(stderr, "bench_check_dense: the %s check failed\n", what);
        return -1;
    }
    int st;
    long periods;
    double wall, machining, cond, servo_cpu, plan_cpu;
    buf[got] = 0;
    if (sscanf(buf, "%d %lf %lf %ld %lf %lf %lf", &st, &wall, &machining, &periods, &cond,
               &servo_cpu, &plan_cpu) != 7)
        return -1;
    double cpu = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
                 (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
    printf("%-34s %9.1f s %8.3f s %8.3f s %8.0fx %8.0fx %8.1f MB %8.3f s %8.3f s\n", what,
           machining, wall, cpu, machining / wall, machining / cpu,
           (double)ru.ru_maxrss / 1024.0, servo_cpu, plan_cpu);
    return wall;
}

int main(void)
{
    const char *ini = "configs/sim/tmu-hexapod.ini";
    char prog[64];
    snprintf(prog, sizeof prog, "/tmp/hexcnc_bench_dense_%d.ngc", (int)getpid());
    if (bench_dense_write(prog, BLOCKS) != 0) {
        fprintf(stderr, "bench_check_dense: cannot write %s\n", prog);
        return 1;
    }
    printf("\ndense five-axis CAM code: %d blocks of %.1f mm, X Y Z A B C on every block, "
           "G64 P0.01, F2000, TMU machine, 1 kHz servo (%ld cores online)\n", BLOCKS, STEP_MM,
           sysconf(_SC_NPROCESSORS_ONLN));
    printf("%-34s %11s %10s %10s %9s %9s %11s %10s %10s\n", "check", "machining", "wall",
           "CPU", "x real", "x CPU", "peak mem", "servo CPU", "plan CPU");
    printf("(servo CPU: the servo-rate pass's thread; plan CPU: the reach pass and the "
           "planner, with the interpreter when streamed)\n");
    double s = run(ini, prog, 0, "streamed (hexcnc check)");
    double w = run(ini, prog, 1, "whole program in memory");
    if (s > 0 && w > 0)
        printf("streamed over whole, wall: %.2fx faster\n", w / s);
    unlink(prog);
    return s > 0 && w > 0 ? 0 : 1;
}
