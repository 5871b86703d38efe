/* can_bus.h: non-blocking CAN frame transport: a SocketCAN raw socket or a simulated pair. */
#ifndef HEXCNC_CAN_BUS_H
#define HEXCNC_CAN_BUS_H

#include <linux/can.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/*
 * One `struct can_frame` per read() and write(), the SocketCAN CAN_RAW convention. The
 * interface name "sim" gives instead one end of socketpair(AF_UNIX, SOCK_SEQPACKET), which
 * keeps message boundaries and so carries exactly the same frames through the same calls;
 * the other end (sim_peer_fd) belongs to the simulated drives. Everything after opening is
 * shared: what the tests exercise over the pair is what runs on a real bus. "unix:PATH"
 * connects to an AF_UNIX SOCK_SEQPACKET socket listening at PATH that carries the same
 * frames, one per message: CANopen nodes in another process (`hexcnc can_sim`, a bridge to
 * hardware, another stack). A peer that closes (a zero-length message, EPIPE) sets
 * peer_closed; the bus then stays quiet instead of retrying.
 */

#define CAN_BUS_SIM "sim"   /* the interface name that selects the simulated pair */
#define CAN_BUS_UNIX "unix:"  /* prefix of a unix socket path to connect to */

enum can_bus_status {
    CAN_BUS_OK = 0,
    CAN_BUS_ERR_NO_SOCKETCAN,   /* the kernel has no SocketCAN (socket(PF_CAN) failed) */
    CAN_BUS_ERR_NO_IFACE,       /* no network interface of that name */
    CAN_BUS_ERR_SOCKET,         /* socket, socketpair, setsockopt or bind failed */
    CAN_BUS_ERR_IO,             /* read or write failed for another reason than "would block" */
    CAN_BUS_STATUS_COUNT
};
const char *can_bus_strerror(int status);

/* An open bus and its counters. */
struct can_bus {
    int fd;                    /* the master's socket, non-blocking; -1 when closed */
    int sim_peer_fd;           /* the simulated drives' end of the pair, else -1 */
    char ifname[120];          /* the interface name as given (unix: and a socket path) */
    uint32_t tx_frames;        /* frames written */
    uint32_t tx_dropped;       /* frames not written: the socket's queue was full */
    uint32_t rx_frames;        /* data frames read */
    uint32_t rx_errors;        /* short reads and read errors */
    uint32_t err_frames;       /* SocketCAN error frames (controller, bus-off, ...) */
    bool bus_off;              /* an error frame reported bus-off */
    bool peer_closed;          /* the other end of a pair or unix socket is gone */
    int last_errno;            /* errno of the last failed call */
};

/* Opens `ifname` (a SocketCAN interface, or CAN_BUS_SIM). On failure returns a status and
 * writes into err a message that names the interface and what to do. */
int can_bus_open(struct can_bus *b, const char *ifname, char *err, size_t errlen);
/* Closes both ends (a peer fd already handed over must be set to -1 by its new owner). */
void can_bus_close(struct can_bus *b);

/* Writes n frames, one write() each; returns how many went out (the rest are counted as
 * dropped: never waits). */
int can_bus_send(struct can_bus *b, const struct can_frame *f, int n);
/* Reads up to max frames, one read() each, until the socket is empty; never waits. Error
 * frames are counted, not returned. */
int can_bus_recv(struct can_bus *b, struct can_frame *f, int max);
/* The same with one sendmmsg() / recvmmsg() call for the whole batch. */
int can_bus_send_batch(struct can_bus *b, const struct can_frame *f, int n);
int can_bus_recv_batch(struct can_bus *b, struct can_frame *f, int max);

/* Raw frame I/O on any descriptor (the simulated drives' end uses these too). */
int can_fd_write(int fd, const struct can_frame *f);   /* 1 written, 0 would block, -1 error */
int can_fd_read(int fd, struct can_frame *f);  /* 1 read, 0 empty, -1 error (EMSGSIZE: short) */

#endif
