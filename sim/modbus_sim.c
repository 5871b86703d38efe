/* modbus_sim.c: simulated Modbus drive servers: one thread per drive, libmodbus server API, fault injection. */
#include "sim/modbus_sim.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <modbus.h>

/* How often a waiting server thread looks at the stop flag, ms. */
#define MODBUS_SIM_POLL_MS 20

struct modbus_sim_drive {
    struct modbus_sim *sim;       /* owner (options, stop flag) */
    int index;                    /* drive number */
    modbus_t *ctx;                /* server context (TCP or RTU) */
    modbus_mapping_t *map;        /* the holding registers */
    int listen_fd;                /* TCP listening socket, -1 if none */
    int pty_fd;                   /* RTU: pseudo-terminal master, -1 if none */
    int port;                     /* TCP port actually bound */
    pthread_t thread;
    bool started;
    pthread_mutex_t lock;         /* guards everything below and the registers */
    struct modbus_sim_model model;
    enum modbus_sim_fault fault;  /* injected fault */
    long fault_arg;               /* exception code or delay, us */
    uint32_t requests, connections;
    int64_t last_ns;              /* wall time the model has been advanced to, ns */
};

struct modbus_sim {
    int n;                        /* drives */
    struct modbus_sim_opts opts;
    _Atomic bool stop;            /* asks every server thread to end */
    struct modbus_sim_drive *d;   /* n drives */
};

static const char *const modbus_sim_status_text[MODBUS_SIM_STATUS_COUNT] = {
    [MODBUS_SIM_OK] = "ok",
    [MODBUS_SIM_ERR_ARG] = "bad simulated drive argument",
    [MODBUS_SIM_ERR_NOMEM] = "out of memory",
    [MODBUS_SIM_ERR_LISTEN] = "cannot listen on the port (in use?)",
    [MODBUS_SIM_ERR_PTY] = "cannot create a pseudo-terminal",
    [MODBUS_SIM_ERR_THREAD] = "cannot start a server thread",
};

/* Text of a modbus_sim_status value. */
const char *modbus_sim_strerror(int status)
{
    if (status < 0 || status >= MODBUS_SIM_STATUS_COUNT)
        return "unknown simulated drive status";
    return modbus_sim_status_text[status];
}

/* Fault names as the command line and docs spell them. */
int modbus_sim_fault_parse(const char *name)
{
    static const char *const names[] = { "none", "no-answer", "exception", "delay",
                                         "disconnect", "drive" };
    for (int i = 0; i < (int)(sizeof(names) / sizeof(names[0])); i++)
        if (!strcmp(name, names[i]))
            return i;
    return -1;
}

/* Monotonic wall time, ns. */
static int64_t modbus_sim_now_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* Creates the drives and their register maps. */
int modbus_sim_create(struct modbus_sim **out, int ndrives, const struct modbus_sim_opts *opts)
{
    *out = NULL;
    const struct modbus_regmap *m = &opts->map;
    int nb = opts->nb_registers;
    if (ndrives < 1 || ndrives > 64 || nb < 1 || nb > 65536 || m->control < 0 ||
        m->control >= nb || m->status < 0 || m->status >= nb || m->target < 0 ||
        m->target + 1 >= nb || m->actual < 0 || m->actual + 1 >= nb)
        return MODBUS_SIM_ERR_ARG;
    struct modbus_sim *s = calloc(1, sizeof(*s));
    if (!s)
        return MODBUS_SIM_ERR_NOMEM;
    s->d = calloc((size_t)ndrives, sizeof(*s->d));
    if (!s->d) {
        free(s);
        return MODBUS_SIM_ERR_NOMEM;
    }
    s->n = ndrives;
    s->opts = *opts;
    for (int i = 0; i < ndrives; i++) {
        struct modbus_sim_drive *d = &s->d[i];
        d->sim = s;
        d->index = i;
        d->listen_fd = d->pty_fd = -1;
        d->last_ns = modbus_sim_now_ns();
        pthread_mutex_init(&d->lock, NULL);
        d->map = modbus_mapping_new(0, 0, nb, 0);
        if (!d->map) {
            s->n = i + 1;
            modbus_sim_destroy(s);
            return MODBUS_SIM_ERR_NOMEM;
        }
    }
    *out = s;
    return MODBUS_SIM_OK;
}

/* Advances the model to now (or one lockstep) and writes status and actual into the map.
 * Lockstep advances only on requests that read, i.e. once per client cycle (function 0:
 * not at all). On wall time the model covers the whole time since its last update, however
 * many connections came and went in between. Called with d->lock held. */
static void modbus_sim_drive_update(struct modbus_sim_drive *d, int function)
{
    const struct modbus_sim_opts *o = &d->sim->opts;
    double dt_s = 0.0;
    if (o->step_ns > 0) {
        if (function == MODBUS_FC_READ_HOLDING_REGISTERS ||
            function == MODBUS_FC_WRITE_AND_READ_REGISTERS)
            dt_s = o->step_ns * 1e-9;
    } else {
        int64_t now = modbus_sim_now_ns();
        dt_s = (now - d->last_ns) * 1e-9;
        d->last_ns = now;
    }
    modbus_sim_model_step(&d->model, o, dt_s);
    uint16_t *r = d->map->tab_registers;
    r[o->map.status] = modbus_sim_model_status(&d->model);
    int32_t act = (int32_t)lround(d->model.actual_counts);
    modbus_words_pack(act, o->map.order, &r[o->map.actual]);
}

/* Takes what the client wrote (target, control word) into the model. */
static void modbus_sim_drive_take_writes(struct modbus_sim_drive *d)
{
    const struct modbus_sim_opts *o = &d->sim->opts;
    const uint16_t *r = d->map->tab_registers;
    d->model.target_counts = modbus_words_unpack(&r[o->map.target], o->map.order);
    uint16_t ctl = r[o->map.control];
    if (ctl & MODBUS_CTRL_FAULT_RESET)
        d->model.fault = false;
    d->model.enabled = (ctl & MODBUS_CTRL_ENABLE) != 0;
}

/* Answers one request, or does the injected fault. Returns false to drop the connection. */
static bool modbus_sim_drive_handle(struct modbus_sim_drive *d, const uint8_t *req, int len)
{
    int function = req[modbus_get_header_length(d->ctx)];
    pthread_mutex_lock(&d->lock);
    d->requests++;
    enum modbus_sim_fault f = d->fault;
    long arg = d->fault_arg;
    if (f == MODBUS_SIM_FAULT_DISCONNECT)
        d->fault = MODBUS_SIM_FAULT_NONE;
    pthread_mutex_unlock(&d->lock);
    if (f == MODBUS_SIM_FAULT_DISCONNECT)
        return false;
    if (f == MODBUS_SIM_FAULT_NO_ANSWER)
        return true;
    if (f == MODBUS_SIM_FAULT_EXCEPTION) {
        modbus_reply_exception(d->ctx, req, (unsigned)arg);
        return true;
    }
    const struct modbus_sim_opts *o = &d->sim->opts;
    if (f == MODBUS_SIM_FAULT_DELAY && arg > 0 && o->step_ns > 0 && o->timeout_us > 0) {
        if (arg >= o->timeout_us)
            return true;    /* simulated time: the answer would come after the client gave up */
    } else if (f == MODBUS_SIM_FAULT_DELAY && arg > 0) {
        struct timespec ts = { arg / 1000000, (arg % 1000000) * 1000 };
        nanosleep(&ts, NULL);
    }
    pthread_mutex_lock(&d->lock);
    modbus_sim_drive_update(d, function);
    int rc = modbus_reply(d->ctx, req, len, d->map);
    modbus_sim_drive_take_writes(d);
    pthread_mutex_unlock(&d->lock);
    return rc != -1;
}

/* Serves requests on the open connection until it closes or the simulator stops. */
static void modbus_sim_drive_serve(struct modbus_sim_drive *d)
{
    uint8_t req[MODBUS_TCP_MAX_ADU_LENGTH > MODBUS_RTU_MAX_ADU_LENGTH ?
                MODBUS_TCP_MAX_ADU_LENGTH : MODBUS_RTU_MAX_ADU_LENGTH];
    struct pollfd pfd = { .fd = modbus_get_socket(d->ctx), .events = POLLIN };
    while (!atomic_load(&d->sim->stop)) {
        int pr = poll(&pfd, 1, MODBUS_SIM_POLL_MS);
        if (pr <= 0)
            continue;
        if (d->pty_fd >= 0 && (pfd.revents & POLLHUP) && !(pfd.revents & POLLIN)) {
            /* No client has the pty open: wait for one instead of spinning. */
            struct timespec ts = { 0, MODBUS_SIM_POLL_MS * 1000000L };
            nanosleep(&ts, NULL);
            continue;
        }
        int len = modbus_receive(d->ctx, req);
        if (len == 0)
            continue;           /* RTU: a frame for another unit */
        if (len < 0) {
            if (d->pty_fd >= 0)
                continue;       /* RTU: garbage or a bad CRC; the line stays */
            return;             /* TCP: closed by the client */
        }
        if (!modbus_sim_drive_handle(d, req, len) && d->pty_fd < 0)
            return;
    }
}

/* TCP server thread: accept one client at a time and serve it. */
static void *modbus_sim_tcp_thread(void *arg)
{
    struct modbus_sim_drive *d = arg;
    struct pollfd pfd = { .fd = d->listen_fd, .events = POLLIN };
    while (!atomic_load(&d->sim->stop)) {
        if (poll(&pfd, 1, MODBUS_SIM_POLL_MS) <= 0)
            continue;
        int lfd = d->listen_fd;
        if (modbus_tcp_accept(d->ctx, &lfd) == -1)
            continue;
        int one = 1;
        setsockopt(modbus_get_socket(d->ctx), IPPROTO_TCP, TCP_NODELAY, &one, sizeof(one));
        pthread_mutex_lock(&d->lock);
        d->connections++;
        pthread_mutex_unlock(&d->lock);
        modbus_sim_drive_serve(d);
        modbus_close(d->ctx);
    }
    return NULL;
}

/* RTU server thread: the pty line is always "connected". */
static void *modbus_sim_rtu_thread(void *arg)
{
    struct modbus_sim_drive *d = arg;
    modbus_sim_drive_serve(d);
    return NULL;
}

/* Opens drive d's listening socket on host:port (0 = ephemeral) and notes the real port. */
static int modbus_sim_listen(struct modbus_sim_drive *d, const char *host, int port)
{
    d->ctx = modbus_new_tcp(host, port);
    if (!d->ctx)
        return MODBUS_SIM_ERR_ARG;
    d->listen_fd = modbus_tcp_listen(d->ctx, 1);
    if (d->listen_fd == -1)
        return MODBUS_SIM_ERR_LISTEN;
    struct sockaddr_in sa;
    socklen_t sl = sizeof(sa);
    if (getsockname(d->listen_fd, (struct sockaddr *)&sa, &sl) == -1)
        return MODBUS_SIM_ERR_LISTEN;
    d->port = ntohs(sa.sin_port);
    return MODBUS_SIM_OK;
}

/* Starts drive i's TCP server on host:port (0 = ephemeral). */
int modbus_sim_start_tcp_port(struct modbus_sim *s, int i, const char *host, int port)
{
    if (i < 0 || i >= s->n || port < 0 || port > 65535 || s->d[i].ctx)
        return MODBUS_SIM_ERR_ARG;
    struct modbus_sim_drive *d = &s->d[i];
    int rc = modbus_sim_listen(d, host ? host : "127.0.0.1", port);
    if (rc)
        return rc;
    if (pthread_create(&d->thread, NULL, modbus_sim_tcp_thread, d))
        return MODBUS_SIM_ERR_THREAD;
    d->started = true;
    return MODBUS_SIM_OK;
}

/* Starts every drive's TCP server: drive i on base_port + i. */
int modbus_sim_start_tcp(struct modbus_sim *s, const char *host, int base_port)
{
    if (base_port < 0 || base_port + s->n - 1 > 65535)
        return MODBUS_SIM_ERR_ARG;
    for (int i = 0; i < s->n; i++) {
        int rc = modbus_sim_start_tcp_port(s, i, host, base_port ? base_port + i : 0);
        if (rc)
            return rc;
    }
    return MODBUS_SIM_OK;
}

/* Makes a raw pseudo-terminal and serves drive i as an RTU unit on its master side. */
int modbus_sim_start_rtu_pty(struct modbus_sim *s, int i, char *slave_path, size_t len)
{
    if (i < 0 || i >= s->n || s->d[i].ctx)
        return MODBUS_SIM_ERR_ARG;
    struct modbus_sim_drive *d = &s->d[i];
    int fd = posix_openpt(O_RDWR | O_NOCTTY);
    if (fd == -1)
        return MODBUS_SIM_ERR_PTY;
    struct termios t;
    if (grantpt(fd) || unlockpt(fd) || ptsname_r(fd, slave_path, len) || tcgetattr(fd, &t)) {
        close(fd);
        return MODBUS_SIM_ERR_PTY;
    }
    cfmakeraw(&t);
    tcsetattr(fd, TCSANOW, &t);
    /* The RTU context only frames and checks CRCs: its fd is the master, never "connected". */
    d->ctx = modbus_new_rtu(slave_path, 115200, 'N', 8, 1);
    if (!d->ctx) {
        close(fd);
        return MODBUS_SIM_ERR_PTY;
    }
    d->pty_fd = fd;
    modbus_set_socket(d->ctx, fd);
    modbus_set_slave(d->ctx, s->opts.unit);
    if (pthread_create(&d->thread, NULL, modbus_sim_rtu_thread, d))
        return MODBUS_SIM_ERR_THREAD;
    d->started = true;
    return MODBUS_SIM_OK;
}

/* Stops the threads, closes sockets and ptys, frees everything. */
void modbus_sim_destroy(struct modbus_sim *s)
{
    if (!s)
        return;
    atomic_store(&s->stop, true);
    for (int i = 0; i < s->n; i++) {
        struct modbus_sim_drive *d = &s->d[i];
        if (d->started)
            pthread_join(d->thread, NULL);
        if (d->listen_fd >= 0)
            close(d->listen_fd);
        if (d->pty_fd >= 0) {
            modbus_set_socket(d->ctx, -1);
            close(d->pty_fd);
        }
        if (d->ctx)
            modbus_free(d->ctx);
        if (d->map)
            modbus_mapping_free(d->map);
        pthread_mutex_destroy(&d->lock);
    }
    free(s->d);
    free(s);
}

int modbus_sim_count(const struct modbus_sim *s) { return s->n; }

/* Drive i's bound TCP port, or -1. */
int modbus_sim_port(const struct modbus_sim *s, int i)
{
    return i >= 0 && i < s->n && s->d[i].listen_fd >= 0 ? s->d[i].port : -1;
}

/* Sets drive i's injected fault; MODBUS_SIM_FAULT_DRIVE latches the model's fault bit. */
int modbus_sim_inject(struct modbus_sim *s, int i, enum modbus_sim_fault fault, long arg)
{
    if (i < 0 || i >= s->n || fault < MODBUS_SIM_FAULT_NONE || fault > MODBUS_SIM_FAULT_DRIVE ||
        (fault == MODBUS_SIM_FAULT_EXCEPTION && (arg < 1 || arg > 255)) ||
        (fault == MODBUS_SIM_FAULT_DELAY && (arg < 0 || arg > 10000000)))
        return MODBUS_SIM_ERR_ARG;
    struct modbus_sim_drive *d = &s->d[i];
    pthread_mutex_lock(&d->lock);
    if (fault == MODBUS_SIM_FAULT_DRIVE) {
        d->model.fault = true;
        d->fault = MODBUS_SIM_FAULT_NONE;
    } else {
        d->fault = fault;
        d->fault_arg = arg;
    }
    pthread_mutex_unlock(&d->lock);
    return MODBUS_SIM_OK;
}

/* A snapshot of drive i. */
int modbus_sim_state(struct modbus_sim *s, int i, struct modbus_sim_drive_state *st)
{
    if (i < 0 || i >= s->n)
        return MODBUS_SIM_ERR_ARG;
    struct modbus_sim_drive *d = &s->d[i];
    pthread_mutex_lock(&d->lock);
    modbus_sim_drive_update(d, 0);      /* on wall time: where the drive is now */
    st->target_counts = d->model.target_counts;
    st->actual_counts = d->model.actual_counts;
    st->control_word = d->map->tab_registers[s->opts.map.control];
    st->status_word = modbus_sim_model_status(&d->model);
    st->requests = d->requests;
    st->connections = d->connections;
    pthread_mutex_unlock(&d->lock);
    return MODBUS_SIM_OK;
}

/* Puts drive i at `counts` (target and actual) and mirrors it into the registers. */
int modbus_sim_set_position(struct modbus_sim *s, int i, int32_t counts)
{
    if (i < 0 || i >= s->n)
        return MODBUS_SIM_ERR_ARG;
    struct modbus_sim_drive *d = &s->d[i];
    const struct modbus_regmap *m = &s->opts.map;
    pthread_mutex_lock(&d->lock);
    d->model.actual_counts = counts;
    d->model.target_counts = counts;
    modbus_words_pack(counts, m->order, &d->map->tab_registers[m->target]);
    modbus_words_pack(counts, m->order, &d->map->tab_registers[m->actual]);
    pthread_mutex_unlock(&d->lock);
    return MODBUS_SIM_OK;
}
