/* ring.h: lock-free queues that carry data out of real-time threads without blocking them. */
#ifndef HEXCNC_RING_H
#define HEXCNC_RING_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/*
 * Both queues hold a power-of-two number of fixed-size slots, allocated once at init. After
 * that, pushing and popping take no lock, allocate nothing and make no system call, so a
 * servo thread can push while another thread pops, and a full queue never makes the pusher
 * wait: the item is dropped and counted instead.
 *
 * Positions are 64-bit counters that only grow (they never wrap in practice: 2^64 pushes at
 * 1 MHz take half a million years); the slot is position & mask.
 */

enum ring_status {
    RING_OK = 0,
    RING_ERR_SIZE,        /* slot count not a power of two >= 2, or slot size 0 */
    RING_ERR_NOMEM,       /* allocation failed */
    RING_STATUS_COUNT
};
const char *ring_strerror(int status);

/* Keeps the producer's and the consumer's counters on different cache lines, so the two
 * threads do not invalidate each other's line on every push and pop. */
#define RING_CACHE_LINE 64

/* Single producer, single consumer. */
struct ring_spsc {
    _Atomic uint64_t head;          /* next position the producer fills (producer writes) */
    uint64_t tail_seen;             /* producer's last look at tail: most pushes need no other */
    char pad0[RING_CACHE_LINE - 2 * sizeof(uint64_t)];
    _Atomic uint64_t tail;          /* next position the consumer reads (consumer writes) */
    uint64_t head_seen;             /* consumer's last look at head */
    char pad1[RING_CACHE_LINE - 2 * sizeof(uint64_t)];
    _Atomic uint64_t dropped;       /* pushes refused because the ring was full */
    uint64_t mask;                  /* slots - 1 */
    size_t slot_size;               /* bytes per slot */
    unsigned char *slots;           /* slots * slot_size bytes */
};

/* Allocates `slots` slots (a power of two) of slot_size bytes. */
int ring_spsc_init(struct ring_spsc *r, size_t slots, size_t slot_size);
void ring_spsc_free(struct ring_spsc *r);
/* Producer: the slot to fill next, or NULL (and one more drop counted) when full. Fill it,
 * then ring_spsc_commit() makes it visible to the consumer. */
void *ring_spsc_claim(struct ring_spsc *r);
void ring_spsc_commit(struct ring_spsc *r);
/* Producer: copies one item in; false (counted as dropped) when full. */
bool ring_spsc_push(struct ring_spsc *r, const void *item);
/* Consumer: the oldest slot, or NULL when empty; ring_spsc_release() frees it. */
const void *ring_spsc_peek(struct ring_spsc *r);
void ring_spsc_release(struct ring_spsc *r);
/* Consumer: copies the oldest item out; false when empty. */
bool ring_spsc_pop(struct ring_spsc *r, void *item);
/* Items pushed so far (drops not counted), and items dropped; any thread. */
uint64_t ring_spsc_pushed(const struct ring_spsc *r);
uint64_t ring_spsc_popped(const struct ring_spsc *r);
uint64_t ring_spsc_dropped(const struct ring_spsc *r);

/* Many producers, single consumer: a bounded queue where each slot carries a sequence
 * number that says whether it is free for position p (seq == p) or filled (seq == p + 1).
 * A producer claims a position with one compare-and-swap; no producer ever waits for
 * another to finish. */
struct ring_mpsc {
    _Atomic uint64_t enq;           /* next position producers claim */
    char pad0[RING_CACHE_LINE - sizeof(uint64_t)];
    _Atomic uint64_t deq;           /* next position the consumer reads */
    char pad1[RING_CACHE_LINE - sizeof(uint64_t)];
    _Atomic uint64_t dropped;       /* pushes refused because the queue was full */
    uint64_t mask;                  /* slots - 1 */
    size_t slot_size;               /* bytes per slot */
    _Atomic uint64_t *seq;          /* per slot: its sequence number */
    unsigned char *slots;           /* slots * slot_size bytes */
};

int ring_mpsc_init(struct ring_mpsc *q, size_t slots, size_t slot_size);
void ring_mpsc_free(struct ring_mpsc *q);
/* Any thread: copies one item in; false (counted as dropped) when full. */
bool ring_mpsc_push(struct ring_mpsc *q, const void *item);
/* The one consumer: copies the oldest item out; false when empty (or when the oldest
 * position is claimed but its producer has not finished copying yet). */
bool ring_mpsc_pop(struct ring_mpsc *q, void *item);
/* Positions claimed so far, items popped, items dropped; any thread. */
uint64_t ring_mpsc_pushed(const struct ring_mpsc *q);
uint64_t ring_mpsc_popped(const struct ring_mpsc *q);
uint64_t ring_mpsc_dropped(const struct ring_mpsc *q);

#endif
