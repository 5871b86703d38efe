/* bench_session.c: the machine session's API on the wall clock (configs/sim, realtime):
 * the round trip of status.get against a bare Unix-socket echo of the same size (the
 * baseline, measured side by side in this run), the time from a jog.move request to its
 * answer (the servo thread has taken the jog) and to the first commanded motion seen in
 * status, and the time from program.run to motion on the demo program. Wall-clock figures:
 * median and 99th percentile of repeated trials. Then a 10-million-line program streamed:
 * the check's time and this process's peak resident memory, the time to first motion, set
 * beside `hexcnc check` planning a 1-million-line program whole (the baseline). */
#include <errno.h>
#include <fcntl.h>
#include <jansson.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "task/session.h"

#define RT_TRIALS 2000     /* round trips per measurement */
#define JOG_TRIALS 40      /* jogs */
#define RUN_TRIALS 5       /* program starts */

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Median and 99th percentile of v (sorted in place), in microseconds. */
static void stats_us(double *v, int n, double *med, double *p99)
{
    qsort(v, (size_t)n, sizeof *v, cmp_d);
    *med = v[n / 2] * 1e6;
    *p99 = v[(int)(0.99 * (n - 1))] * 1e6;
}

/* ---- a line client */
struct conn {
    int fd;
    char buf[1 << 20];
    size_t len;
    int id;
};

static int conn_open(struct conn *c, const char *path)
{
    struct sockaddr_un a = { .sun_family = AF_UNIX };
    snprintf(a.sun_path, sizeof a.sun_path, "%s", path);
    c->len = 0;
    c->id = 0;
    c->fd = socket(AF_UNIX, SOCK_STREAM, 0);
    for (int i = 0; i < 500; i++) {
        if (connect(c->fd, (struct sockaddr *)&a, sizeof a) == 0)
            return 0;
        usleep(10000);
    }
    fprintf(stderr, "bench_session: %s: %s\n", path, strerror(errno));
    return -1;
}

/* The next line (without its newline, NUL-terminated in c->buf); its length, -1 at EOF. */
static long conn_line(struct conn *c, char *out, size_t cap)
{
    for (;;) {
        char *nl = memchr(c->buf, '\n', c->len);
        if (nl) {
            size_t n = (size_t)(nl - c->buf);
            size_t k = n < cap - 1 ? n : cap - 1;
            memcpy(out, c->buf, k);
            out[k] = 0;
            memmove(c->buf, nl + 1, c->len - n - 1);
            c->len -= n + 1;
            return (long)n;
        }
        ssize_t r = read(c->fd, c->buf + c->len, sizeof c->buf - c->len);
        if (r <= 0)
            return -1;
        c->len += (size_t)r;
    }
}

/* One call; the result object (caller decrefs), NULL on an error (printed). */
static json_t *call(struct conn *c, const char *method, const char *params)
{
    char req[1024], line[1 << 16];
    int n = snprintf(req, sizeof req, "{\"jsonrpc\":\"2.0\",\"id\":%d,\"method\":\"%s\","
                     "\"params\":%s}\n", ++c->id, method, params ? params : "{}");
    if (write(c->fd, req, (size_t)n) != n)
        return NULL;
    for (;;) {
        if (conn_line(c, line, sizeof line) < 0)
            return NULL;
        json_t *j = json_loads(line, 0, NULL);
        json_t *id = json_object_get(j, "id");
        if (json_is_integer(id) && json_integer_value(id) == c->id) {
            json_t *res = json_incref(json_object_get(j, "result"));
            if (!res)
                fprintf(stderr, "bench_session: %s: %s\n", method,
                        json_string_value(json_object_get(json_object_get(j, "error"),
                                                          "message")));
            json_decref(j);
            return res;
        }
        json_decref(j);
    }
}

static double pose_x(json_t *st)
{
    return json_real_value(json_array_get(json_object_get(json_object_get(st, "machine_pose"),
                                                          "commanded"), 0));
}

static const char *str_of(json_t *st, const char *key)
{
    const char *v = json_string_value(json_object_get(st, key));
    return v ? v : "";
}

static int at_rest(json_t *st)
{
    return !strcmp(str_of(st, "interp"), "idle") &&
           !json_is_true(json_object_get(st, "homing")) &&
           (!strcmp(str_of(st, "motion"), "idle") || !strcmp(str_of(st, "motion"), "done"));
}

static void wait_rest(struct conn *c)
{
    for (int i = 0; i < 200000; i++) {
        json_t *st = call(c, "status.get", NULL);
        int rest = st && at_rest(st);
        json_decref(st);
        if (rest)
            return;
        usleep(1000);
    }
}

/* One call that sets the platform moving: seconds until its answer, and until status shows
 * the commanded X changed. */
static void call_until_moving(struct conn *c, const char *method, const char *params,
                              double *answer_s, double *moving_s)
{
    json_t *st = call(c, "status.get", NULL);
    double x0 = pose_x(st), x = x0;
    json_decref(st);
    double t0 = now_s();
    json_decref(call(c, method, params));
    *answer_s = now_s() - t0;
    while (fabs(x - x0) <= 1e-9) {
        st = call(c, "status.get", NULL);
        x = pose_x(st);
        json_decref(st);
    }
    *moving_s = now_s() - t0;
}

/* ---- the baseline: an echo server answering each line with a line of a given size */
struct echo {
    int lfd;
    size_t reply_len;
};

static void *echo_main(void *arg)
{
    struct echo *e = arg;
    int fd = accept(e->lfd, NULL, NULL);
    char *reply = malloc(e->reply_len + 1);
    memset(reply, 'x', e->reply_len);
    reply[e->reply_len] = '\n';
    static char buf[1 << 16];
    size_t len = 0;
    for (;;) {
        ssize_t r = read(fd, buf + len, sizeof buf - len);
        if (r <= 0)
            break;
        len += (size_t)r;
        char *nl;
        while ((nl = memchr(buf, '\n', len))) {
            size_t n = (size_t)(nl - buf) + 1;
            memmove(buf, buf + n, len - n);
            len -= n;
            if (write(fd, reply, e->reply_len + 1) < 0)
                goto out;
        }
    }
out:
    free(reply);
    close(fd);
    return NULL;
}

/* ---- a long program streamed through the session */
#define STREAM_LINES 10000000L   /* the 10-million-line program */
#define WHOLE_LINES 1000000L     /* the baseline: `hexcnc check` plans a whole program */

/* This process's VmHWM or VmRSS, kB. */
static long proc_kb(const char *key)
{
    FILE *f = fopen("/proc/self/status", "r");
    char l[256];
    long kb = -1;
    size_t n = strlen(key);
    while (f && fgets(l, sizeof l, f))
        if (!strncmp(l, key, n) && l[n] == ':')
            kb = atol(l + n + 1);
    if (f)
        fclose(f);
    return kb;
}

/* n moves of 0.1 mm round a 20 mm circle at Z645, G64 P0.01, F6000. */
static int write_program(const char *path, long n)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f, "G21 G90 G64 P0.01\nG0 X20 Y0 Z645 A0 B0 C0\nF6000\n");
    for (long k = 1; k <= n; k++)
        fprintf(f, "G1 X%.4f Y%.4f\n", 20 * cos(k * 0.005), 20 * sin(k * 0.005));
    fprintf(f, "M2\n");
    return fclose(f);
}

/* `hexcnc check` (the whole program in memory) on path: wall seconds and peak kB. */
static int whole_check(const char *path, double *wall_s, long *peak_kb)
{
    const char *bin = getenv("HEXCNC_BIN");
    double t0 = now_s();
    pid_t pid = fork();
    if (pid == 0) {
        int dn = open("/dev/null", O_WRONLY);
        dup2(dn, 1);
        execl(bin ? bin : "bin/hexcnc", "hexcnc", "check", "configs/sim/tmu-hexapod.ini",
              path, (char *)NULL);
        _exit(127);
    }
    int status;
    struct rusage ru;
    if (pid < 0 || wait4(pid, &status, 0, &ru) != pid)
        return -1;
    *wall_s = now_s() - t0;
    *peak_kb = ru.ru_maxrss;
    return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? 0 : -1;
}

static void bench_stream(struct conn *c, const char *dir)
{
    char big[200], mid[200], params[300];
    snprintf(big, sizeof big, "%s/big.ngc", dir);
    snprintf(mid, sizeof mid, "%s/mid.ngc", dir);
    if (write_program(big, STREAM_LINES) || write_program(mid, WHOLE_LINES)) {
        fprintf(stderr, "bench_session: cannot write the programs in %s\n", dir);
        return;
    }
    double ws;
    long wkb;
    if (whole_check(mid, &ws, &wkb) == 0)
        printf("baseline, the whole program in memory (hexcnc check, %ld lines): %.1f s, "
               "peak %.0f MB\n", WHOLE_LINES, ws, wkb / 1024.0);
    struct stat sb;
    double file_mb = stat(big, &sb) == 0 ? (double)sb.st_size / 1e6 : 0;
    long rss0 = proc_kb("VmRSS");
    snprintf(params, sizeof params, "{\"path\":\"%s\"}", big);
    json_decref(call(c, "program.open", params));
    double t0 = now_s();
    json_t *r = call(c, "program.check", NULL);
    double t_check = now_s() - t0;
    long hwm_check = proc_kb("VmHWM");
    printf("streamed (%ld lines, %.0f MB file): program.check %.1f s (%s, %.0f s of "
           "machining); this process before %.0f MB, peak %.0f MB\n", STREAM_LINES,
           file_mb, t_check, json_is_true(json_object_get(r, "ok")) ?
           "ok" : "refused", json_real_value(json_object_get(r, "time_s")), rss0 / 1024.0,
           hwm_check / 1024.0);
    json_decref(r);
    double ans, mov;
    call_until_moving(c, "program.run", NULL, &ans, &mov);
    usleep(3000000);                 /* 3 s of machining, windows planned meanwhile */
    json_decref(call(c, "program.abort", NULL));
    wait_rest(c);
    printf("  program.run: answer %.1f ms, first motion %.1f ms; peak resident after 3 s of "
           "the run %.0f MB\n", ans * 1e3, mov * 1e3, proc_kb("VmHWM") / 1024.0);
    unlink(big);
    unlink(mid);
}

static volatile sig_atomic_t session_stop;

static void *session_main(void *arg)
{
    session_run(arg, &session_stop);
    return NULL;
}

int main(void)
{
    char dir[] = "/tmp/hexcnc-bench-session.XXXXXX", sock[100], esock[100], err[1024];
    if (!mkdtemp(dir))
        return 1;
    snprintf(sock, sizeof sock, "%s/m.sock", dir);
    snprintf(esock, sizeof esock, "%s/echo.sock", dir);
    signal(SIGPIPE, SIG_IGN);
    struct session_opts o = { "configs/sim/tmu-hexapod.ini", RUNNER_CLOCK_REALTIME, sock, 1 };
    struct session *s;
    if (session_create(&o, &s, err, sizeof err) != 0) {
        fprintf(stderr, "bench_session: %s\n", err);
        return 1;
    }
    pthread_t th;
    pthread_create(&th, NULL, session_main, s);
    static struct conn c, e;
    if (conn_open(&c, sock))
        return 1;
    json_decref(call(&c, "machine.estop", "{\"active\":false}"));
    json_decref(call(&c, "machine.power", "{\"on\":true}"));
    json_decref(call(&c, "machine.home", NULL));
    wait_rest(&c);

    /* status.get and its baseline, interleaved in blocks so both see the same machine */
    json_t *st = call(&c, "status.get", NULL);
    char *text = json_dumps(st, JSON_COMPACT);
    size_t status_len = strlen(text);
    free(text);
    json_decref(st);
    struct echo ec = { socket(AF_UNIX, SOCK_STREAM, 0), status_len };
    struct sockaddr_un ea = { .sun_family = AF_UNIX };
    snprintf(ea.sun_path, sizeof ea.sun_path, "%s", esock);
    if (bind(ec.lfd, (struct sockaddr *)&ea, sizeof ea) || listen(ec.lfd, 1))
        return 1;
    pthread_t eth;
    pthread_create(&eth, NULL, echo_main, &ec);
    if (conn_open(&e, esock))
        return 1;
    static double rt[RT_TRIALS], base[RT_TRIALS];
    static char line[1 << 16];
    const char req[] = "{\"jsonrpc\":\"2.0\",\"id\":1,\"method\":\"status.get\"}\n";
    for (int k = 0; k < RT_TRIALS; k++) {
        double t0 = now_s();
        json_decref(call(&c, "status.get", NULL));
        rt[k] = now_s() - t0;
        t0 = now_s();
        if (write(e.fd, req, sizeof req - 1) < 0 || conn_line(&e, line, sizeof line) < 0)
            return 1;
        base[k] = now_s() - t0;
    }
    double rmed, rp99, bmed, bp99;
    stats_us(rt, RT_TRIALS, &rmed, &rp99);
    stats_us(base, RT_TRIALS, &bmed, &bp99);
    printf("status.get round trip (%zu-byte status, %d calls): median %.1f us, p99 %.1f us\n",
           status_len, RT_TRIALS, rmed, rp99);
    printf("  baseline, bare Unix-socket echo of the same size: median %.1f us, p99 %.1f us"
           "  -> ratio %.1fx\n", bmed, bp99, rmed / bmed);

    /* jog: answer (the servo thread took it) and first motion in status */
    static double jt_ans[JOG_TRIALS], jt_move[JOG_TRIALS];
    for (int k = 0; k < JOG_TRIALS; k++) {
        char p[128];
        snprintf(p, sizeof p, "{\"frame\":\"world\",\"axis\":\"X\",\"velocity\":%d,"
                 "\"distance\":0.5}", k % 2 ? -10 : 10);
        call_until_moving(&c, "jog.move", p, &jt_ans[k], &jt_move[k]);
        wait_rest(&c);
    }
    double am, ap, mm, mp;
    stats_us(jt_ans, JOG_TRIALS, &am, &ap);
    stats_us(jt_move, JOG_TRIALS, &mm, &mp);
    printf("jog.move (%d jogs, 1 ms servo period): answer median %.0f us (p99 %.0f), "
           "first motion in status median %.0f us (p99 %.0f)\n", JOG_TRIALS, am, ap, mm, mp);

    /* program.run: reading, planning and checking the demo from the present pose, then
     * motion */
    json_decref(call(&c, "program.open", "{\"path\":\"tmu-hexapod-demo.ngc\"}"));
    static double pr_ans[RUN_TRIALS], pr_move[RUN_TRIALS];
    for (int k = 0; k < RUN_TRIALS; k++) {
        call_until_moving(&c, "program.run", NULL, &pr_ans[k], &pr_move[k]);
        json_decref(call(&c, "program.abort", NULL));
        wait_rest(&c);
        json_decref(call(&c, "mdi.execute", "{\"line\":\"G0 X0 Y0 Z645 A0 B0 C0\"}"));
        wait_rest(&c);
    }
    stats_us(pr_ans, RUN_TRIALS, &am, &ap);
    stats_us(pr_move, RUN_TRIALS, &mm, &mp);
    printf("program.run (configs/sim demo, %d starts): answer median %.2f ms, first motion "
           "median %.2f ms (max %.2f ms)\n", RUN_TRIALS, am / 1000, mm / 1000,
           pr_move[RUN_TRIALS - 1] * 1000);

    bench_stream(&c, dir);

    json_decref(call(&c, "machine.shutdown", NULL));
    pthread_join(th, NULL);
    session_destroy(s);
    close(c.fd);
    close(e.fd);
    pthread_join(eth, NULL);
    close(ec.lfd);
    unlink(esock);
    rmdir(dir);
    return 0;
}
