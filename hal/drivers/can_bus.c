/* can_bus.c: SocketCAN CAN_RAW socket (or a simulated socketpair) with non-blocking frame I/O. */
#include "hal/drivers/can_bus.h"

#include <errno.h>
#include <fcntl.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include "hal/drivers/canopen.h"

/* Status texts. */
static const char *const status_texts[CAN_BUS_STATUS_COUNT] = {
    [CAN_BUS_OK] = "ok",
    [CAN_BUS_ERR_NO_SOCKETCAN] = "this system has no SocketCAN support",
    [CAN_BUS_ERR_NO_IFACE] = "no CAN interface of that name",
    [CAN_BUS_ERR_SOCKET] = "the CAN socket could not be set up",
    [CAN_BUS_ERR_IO] = "CAN read or write failed",
};

/* Text of a status code. */
const char *can_bus_strerror(int status)
{
    if (status < 0 || status >= CAN_BUS_STATUS_COUNT)
        return "unknown CAN bus status";
    return status_texts[status];
}

/* The simulated bus: a message-preserving pair, both ends non-blocking. */
static int open_sim(struct can_bus *b, char *err, size_t errlen)
{
    int sv[2];
    if (socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_NONBLOCK | SOCK_CLOEXEC, 0, sv) < 0) {
        b->last_errno = errno;
        snprintf(err, errlen, "simulated CAN bus: socketpair failed: %s", strerror(errno));
        return CAN_BUS_ERR_SOCKET;
    }
    b->fd = sv[0];
    b->sim_peer_fd = sv[1];
    return CAN_BUS_OK;
}

/* "unix:PATH": a connection to nodes served by another process on a SEQPACKET socket. */
static int open_unix(struct can_bus *b, const char *path, char *err, size_t errlen)
{
    struct sockaddr_un sa = { .sun_family = AF_UNIX };
    if (!path[0] || strlen(path) >= sizeof sa.sun_path) {
        snprintf(err, errlen, "CAN over unix socket: path '%s' is empty or longer than %zu "
                 "bytes", path, sizeof sa.sun_path - 1);
        return CAN_BUS_ERR_SOCKET;
    }
    memcpy(sa.sun_path, path, strlen(path) + 1);
    int fd = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
    if (fd < 0 || connect(fd, (struct sockaddr *)&sa, sizeof sa) < 0 ||
        fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK) < 0) {
        b->last_errno = errno;
        snprintf(err, errlen, "CAN over unix socket '%s': cannot connect: %s (is the other "
                 "side running, e.g. `hexcnc can_sim CONFIG.ini --listen unix:%s`?)", path,
                 strerror(errno), path);
        if (fd >= 0)
            close(fd);
        return CAN_BUS_ERR_SOCKET;
    }
    b->fd = fd;
    return CAN_BUS_OK;
}

/*
 * Receive filters: only what a master listens to (EMCY 0x081-0x0FF, TPDO1 0x181-0x1FF,
 * SDO answers 0x581-0x5FF, heartbeats 0x701-0x77F; each as id/mask on the function code),
 * plus error frames for bus-off and controller problems.
 */
static int set_filters(int fd)
{
    struct can_filter flt[4] = {
        { CANOPEN_COB_EMCY, CAN_EFF_FLAG | CAN_RTR_FLAG | CANOPEN_FUNC_MASK },
        { CANOPEN_COB_TPDO1, CAN_EFF_FLAG | CAN_RTR_FLAG | CANOPEN_FUNC_MASK },
        { CANOPEN_COB_SDO_TX, CAN_EFF_FLAG | CAN_RTR_FLAG | CANOPEN_FUNC_MASK },
        { CANOPEN_COB_HEARTBEAT, CAN_EFF_FLAG | CAN_RTR_FLAG | CANOPEN_FUNC_MASK },
    };
    can_err_mask_t errmask = CAN_ERR_BUSOFF | CAN_ERR_CRTL | CAN_ERR_ACK | CAN_ERR_BUSERROR;
    if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, flt, sizeof flt) < 0 ||
        setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &errmask, sizeof errmask) < 0)
        return -1;
    return 0;
}

/* A real interface: CAN_RAW socket, filters, bound to the interface's index. */
static int open_socketcan(struct can_bus *b, const char *ifname, char *err, size_t errlen)
{
    int fd = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (fd < 0) {
        b->last_errno = errno;
        snprintf(err, errlen, "CAN interface '%s': this system has no SocketCAN "
                 "(socket(PF_CAN) failed: %s); load the kernel modules can and can_raw, or "
                 "set [CAN]INTERFACE = sim to run on simulated drives", ifname, strerror(errno));
        return CAN_BUS_ERR_NO_SOCKETCAN;
    }
    unsigned idx = if_nametoindex(ifname);
    if (idx == 0) {
        b->last_errno = errno;
        snprintf(err, errlen, "CAN interface '%s' does not exist (see `ip link show`; a real "
                 "adapter needs `ip link set %s up type can bitrate ...`)", ifname, ifname);
        close(fd);
        return CAN_BUS_ERR_NO_IFACE;
    }
    struct sockaddr_can addr;
    memset(&addr, 0, sizeof addr);
    addr.can_family = AF_CAN;
    addr.can_ifindex = (int)idx;
    if (set_filters(fd) < 0 || bind(fd, (struct sockaddr *)&addr, sizeof addr) < 0) {
        b->last_errno = errno;
        snprintf(err, errlen, "CAN interface '%s': cannot set up the socket: %s", ifname,
                 strerror(errno));
        close(fd);
        return CAN_BUS_ERR_SOCKET;
    }
    b->fd = fd;
    return CAN_BUS_OK;
}

/* Opens a real interface or, for "sim", the simulated pair: the only place they differ. */
int can_bus_open(struct can_bus *b, const char *ifname, char *err, size_t errlen)
{
    memset(b, 0, sizeof *b);
    b->fd = b->sim_peer_fd = -1;
    snprintf(b->ifname, sizeof b->ifname, "%s", ifname);
    if (strcmp(ifname, CAN_BUS_SIM) == 0)
        return open_sim(b, err, errlen);
    if (strncmp(ifname, CAN_BUS_UNIX, strlen(CAN_BUS_UNIX)) == 0)
        return open_unix(b, ifname + strlen(CAN_BUS_UNIX), err, errlen);
    return open_socketcan(b, ifname, err, errlen);
}

/* Closes whatever is still open. */
void can_bus_close(struct can_bus *b)
{
    if (b->fd >= 0)
        close(b->fd);
    if (b->sim_peer_fd >= 0)
        close(b->sim_peer_fd);
    b->fd = b->sim_peer_fd = -1;
}

/* One frame out without waiting (MSG_NOSIGNAL: a closed peer is EPIPE, not a SIGPIPE). */
int can_fd_write(int fd, const struct can_frame *f)
{
    ssize_t r = send(fd, f, sizeof *f, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (r == (ssize_t)sizeof *f)
        return 1;
    if (r < 0 && (errno == EAGAIN || errno == EWOULDBLOCK || errno == ENOBUFS))
        return 0;  /* queue full: CAN_RAW says ENOBUFS, a socketpair EAGAIN */
    return -1;
}

/* One frame in without waiting. */
int can_fd_read(int fd, struct can_frame *f)
{
    ssize_t r = read(fd, f, sizeof *f);
    if (r == (ssize_t)sizeof *f)
        return 1;
    if (r < 0 && (errno == EAGAIN || errno == EWOULDBLOCK))
        return 0;
    if (r == 0)
        errno = EPIPE;     /* end of stream: no CAN frame is zero bytes long */
    else if (r > 0)
        errno = EMSGSIZE;  /* a message that is not one frame: skipped by the callers */
    return -1;
}

/* True (and the bus marked) when errno says the other end is gone. */
static bool peer_gone(struct can_bus *b, int e)
{
    if (e == EPIPE || e == ECONNRESET || e == ENOTCONN)
        b->peer_closed = true;
    return b->peer_closed;
}

/* Counts an error frame; true if the frame was one. */
static bool take_error_frame(struct can_bus *b, const struct can_frame *f)
{
    if (!(f->can_id & CAN_ERR_FLAG))
        return false;
    b->err_frames++;
    if (f->can_id & CAN_ERR_BUSOFF)
        b->bus_off = true;
    return true;
}

/* Per-frame writes. */
int can_bus_send(struct can_bus *b, const struct can_frame *f, int n)
{
    int sent = 0;
    for (int i = 0; i < n; i++) {
        int r = b->peer_closed ? -1 : can_fd_write(b->fd, &f[i]);
        if (r <= 0) {
            if (r < 0 && !b->peer_closed) {
                b->last_errno = errno;
                peer_gone(b, errno);
            }
            b->tx_dropped += (uint32_t)(n - i);
            break;
        }
        sent++;
    }
    b->tx_frames += (uint32_t)sent;
    return sent;
}

/* Per-frame reads until empty or max. */
int can_bus_recv(struct can_bus *b, struct can_frame *f, int max)
{
    int k = 0;
    while (k < max) {
        int r = b->peer_closed ? 0 : can_fd_read(b->fd, &f[k]);
        if (r == 0)
            break;
        if (r < 0) {
            b->last_errno = errno;
            b->rx_errors++;
            if (peer_gone(b, errno))
                break;
            if (errno == EMSGSIZE || errno == EINTR)
                continue;  /* skip the odd message, keep reading */
            break;
        }
        if (!take_error_frame(b, &f[k]))
            k++;
    }
    b->rx_frames += (uint32_t)k;
    return k;
}

#define CAN_BUS_BATCH 64  /* frames per sendmmsg / recvmmsg call */

/* All frames in one sendmmsg (in chunks of CAN_BUS_BATCH). */
int can_bus_send_batch(struct can_bus *b, const struct can_frame *f, int n)
{
    struct mmsghdr msg[CAN_BUS_BATCH];
    struct iovec iov[CAN_BUS_BATCH];
    int sent = 0;
    while (sent < n && !b->peer_closed) {
        int m = n - sent < CAN_BUS_BATCH ? n - sent : CAN_BUS_BATCH;
        memset(msg, 0, sizeof(msg[0]) * (size_t)m);
        for (int i = 0; i < m; i++) {
            iov[i].iov_base = (void *)(uintptr_t)&f[sent + i];
            iov[i].iov_len = sizeof f[0];
            msg[i].msg_hdr.msg_iov = &iov[i];
            msg[i].msg_hdr.msg_iovlen = 1;
        }
        int r = sendmmsg(b->fd, msg, (unsigned)m, MSG_DONTWAIT | MSG_NOSIGNAL);
        if (r <= 0) {
            if (r < 0) {
                b->last_errno = errno;
                peer_gone(b, errno);
            }
            break;
        }
        sent += r;
        if (r < m)
            break;
    }
    b->tx_frames += (uint32_t)sent;
    b->tx_dropped += (uint32_t)(n - sent);
    return sent;
}

/* As many frames as are waiting (up to max) in one recvmmsg per CAN_BUS_BATCH. */
int can_bus_recv_batch(struct can_bus *b, struct can_frame *f, int max)
{
    struct mmsghdr msg[CAN_BUS_BATCH];
    struct iovec iov[CAN_BUS_BATCH];
    int k = 0;
    while (k < max && !b->peer_closed) {
        int m = max - k < CAN_BUS_BATCH ? max - k : CAN_BUS_BATCH;
        memset(msg, 0, sizeof(msg[0]) * (size_t)m);
        for (int i = 0; i < m; i++) {
            iov[i].iov_base = &f[k + i];
            iov[i].iov_len = sizeof f[0];
            msg[i].msg_hdr.msg_iov = &iov[i];
            msg[i].msg_hdr.msg_iovlen = 1;
        }
        int r = recvmmsg(b->fd, msg, (unsigned)m, MSG_DONTWAIT, NULL);
        if (r <= 0) {
            if (r < 0 && errno != EAGAIN && errno != EWOULDBLOCK) {
                b->last_errno = errno;
                b->rx_errors++;
                peer_gone(b, errno);
            }
            break;
        }
        /* Compact in place: drop short messages and error frames. A zero-length message is
         * the end of the stream (peer closed): recvmmsg would return it again and again. */
        int got = 0;
        for (int i = 0; i < r; i++) {
            if (msg[i].msg_len == 0) {
                b->peer_closed = true;
                b->last_errno = EPIPE;
                r = i;
                break;
            }
            if (msg[i].msg_len != sizeof f[0]) {
                b->rx_errors++;
                continue;
            }
            if (take_error_frame(b, &f[k + i]))
                continue;
            if (got != i)
                f[k + got] = f[k + i];
            got++;
        }
        k += got;
        b->rx_frames += (uint32_t)got;
        if (r < m)
            break;
    }
    return k;
}
