/* modbus_link.h: a drive's lock-free mailbox between the servo thread and its Modbus I/O thread. */
#ifndef HEXCNC_MODBUS_LINK_H
#define HEXCNC_MODBUS_LINK_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include "hal/drivers/modbus_drive.h"

/*
 * Two sides, never waiting on each other:
 *
 *   servo thread (every servo period)          I/O thread (every set-point period)
 *   modbus_link_command(pos_mm, enable) ──►  cmd atomics ──► modbus_link_cycle():
 *   modbus_link_reset()                 ──►  reset counter    reconnect / clear fault,
 *   modbus_link_feedback(&fb)           ◄──  fb atomics  ◄──  one exchange (FC23), publish
 *
 * Every shared value is a C11 atomic no wider than 64 bits (position and status word share
 * one 64-bit word so they are never torn apart). The I/O side alone touches `drive`.
 * The fault message is written before the fault flag is released, and is not written again
 * until the servo side has asked for a reset, so a reader that saw the flag sees the text.
 * With the simulated clock the HAL shell calls modbus_link_cycle() itself instead of
 * starting the thread, so runs are deterministic.
 */

/* What the servo side reads back. */
struct modbus_feedback {
    double pos_mm;           /* actual position of the last good exchange, mm */
    uint16_t status_word;    /* status word of the last good exchange */
    bool fault;              /* latched; reads false from modbus_link_reset() until the I/O
                              * side has retried (and true again if the retry fails) */
    bool connected;          /* a connection is open */
    double rtt_us;           /* round trip of the last good exchange, us */
    double rtt_max_us;       /* largest round trip since start, us */
    uint32_t errors;         /* failed connects and exchanges since start */
    uint32_t exchanges;      /* good exchanges since start */
    uint32_t fault_seq;      /* counts faults raised: a change means a new message */
};

/* Called on the I/O side each time a fault is raised (e.g. to print the message). */
typedef void (*modbus_link_report_fn)(void *arg, const char *msg);

struct modbus_link {
    struct modbus_drive drive;          /* the connection (I/O side only) */
    _Atomic uint64_t cmd_pos_bits;      /* commanded position, the bits of a double, mm */
    _Atomic uint32_t cmd_enable;        /* 1: enable the drive */
    _Atomic uint32_t cmd_posted;        /* 1 once the servo side has posted a command */
    _Atomic uint32_t reset_req;         /* bumped by modbus_link_reset() */
    _Atomic uint32_t reset_ack;         /* the reset_req the I/O side has acted on */
    _Atomic uint64_t fb_word;           /* actual counts (low 32) | status word << 32 */
    _Atomic uint32_t rtt_ns;            /* last round trip, ns */
    _Atomic uint32_t rtt_max_ns;        /* largest round trip, ns */
    _Atomic uint32_t errors;            /* failed connects + exchanges */
    _Atomic uint32_t exchanges;         /* good exchanges */
    _Atomic uint32_t fault;             /* 1 while a fault is latched */
    _Atomic uint32_t fault_seq;         /* faults raised so far */
    _Atomic uint32_t connected;         /* 1 while connected */
    char fault_msg[320];                /* why, valid while fault is set */
    bool send_fault_reset;              /* I/O side: set FAULT_RESET in the next exchange */
    modbus_link_report_fn report;       /* optional fault reporter (I/O side) */
    void *report_arg;
    pthread_t thread;                   /* the I/O thread when started */
    bool thread_started;
    _Atomic bool stop;                  /* asks the I/O thread to end */
};

/* Opens the drive (no connection yet: the first cycle connects). */
int modbus_link_init(struct modbus_link *l, const struct modbus_drive_cfg *cfg);
/* Stops the thread if started, closes the drive. */
void modbus_link_fini(struct modbus_link *l);
/* Starts the I/O thread: one cycle per cfg.period_ns on absolute deadlines. */
int modbus_link_start(struct modbus_link *l);
/* Asks the thread to end and joins it (at most one period + one timeout). */
void modbus_link_stop(struct modbus_link *l);

/* ---- servo side: lock-free, never blocks -------------------------------------------------- */

void modbus_link_command(struct modbus_link *l, double pos_mm, bool enable);
/* Clears a latched fault and reconnects at the next cycle. */
void modbus_link_reset(struct modbus_link *l);
void modbus_link_feedback(struct modbus_link *l, struct modbus_feedback *fb);
/* The fault message (valid while fb.fault is set). */
const char *modbus_link_fault_message(const struct modbus_link *l);

/* ---- I/O side ---------------------------------------------------------------------------- */

/* One set-point cycle: act on a reset, connect if needed, exchange, publish. Does nothing
 * while a fault is latched. Until the first command is posted it only reads (FC3): the
 * feedback is then the drive's own position and a drive never sees a made-up target.
 * Returns the exchange status (MODBUS_DRIVE_OK when idle). */
int modbus_link_cycle(struct modbus_link *l);

#endif
