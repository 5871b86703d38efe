/* ring.c: lock-free SPSC ring and bounded MPSC queue (C11 atomics, fixed slots). */
#include <stdlib.h>
#include <string.h>

#include "hal/ring.h"

/* Messages for enum ring_status. */
const char *ring_strerror(int status)
{
    static const char *const text[RING_STATUS_COUNT] = {
        [RING_OK] = "ok",
        [RING_ERR_SIZE] = "the number of slots must be a power of two (at least 2) and the "
                          "slot size above 0",
        [RING_ERR_NOMEM] = "out of memory for the ring buffer",
    };
    return status >= 0 && status < RING_STATUS_COUNT ? text[status] : "unknown ring status";
}

/* True for 2, 4, 8, ...: position & mask then picks the slot without a division. */
static bool ring_size_ok(size_t slots, size_t slot_size)
{
    return slots >= 2 && (slots & (slots - 1)) == 0 && slot_size > 0 &&
           slots <= SIZE_MAX / slot_size;
}

/* ---- single producer, single consumer ------------------------------------------------- */

/* Allocates the slots; counters start at 0. */
int ring_spsc_init(struct ring_spsc *r, size_t slots, size_t slot_size)
{
    memset(r, 0, sizeof *r);
    if (!ring_size_ok(slots, slot_size))
        return RING_ERR_SIZE;
    r->slots = calloc(slots, slot_size);
    if (!r->slots)
        return RING_ERR_NOMEM;
    r->mask = slots - 1;
    r->slot_size = slot_size;
    atomic_init(&r->head, 0);
    atomic_init(&r->tail, 0);
    atomic_init(&r->dropped, 0);
    return RING_OK;
}

/* Frees the slots (no thread may use the ring any more). */
void ring_spsc_free(struct ring_spsc *r)
{
    free(r->slots);
    r->slots = NULL;
}

/* The producer's next slot. The acquire load of tail pairs with the consumer's release in
 * ring_spsc_release: once we see the slot freed, the consumer has finished reading it. The
 * consumer's cache line is read only when the last look at tail says the ring is full. */
void *ring_spsc_claim(struct ring_spsc *r)
{
    uint64_t head = atomic_load_explicit(&r->head, memory_order_relaxed);
    if (head - r->tail_seen > r->mask)
        r->tail_seen = atomic_load_explicit(&r->tail, memory_order_acquire);
    if (head - r->tail_seen > r->mask) {
        /* Only the producer writes `dropped`, so a relaxed load-add-store is exact. */
        uint64_t d = atomic_load_explicit(&r->dropped, memory_order_relaxed);
        atomic_store_explicit(&r->dropped, d + 1, memory_order_relaxed);
        return NULL;
    }
    return r->slots + (size_t)(head & r->mask) * r->slot_size;
}

/* Publishes the claimed slot: the release store makes its contents visible before the new
 * head, to a consumer that loads head with acquire. */
void ring_spsc_commit(struct ring_spsc *r)
{
    uint64_t head = atomic_load_explicit(&r->head, memory_order_relaxed);
    atomic_store_explicit(&r->head, head + 1, memory_order_release);
}

/* Claim, copy, commit. */
bool ring_spsc_push(struct ring_spsc *r, const void *item)
{
    void *slot = ring_spsc_claim(r);
    if (!slot)
        return false;
    memcpy(slot, item, r->slot_size);
    ring_spsc_commit(r);
    return true;
}

/* The consumer's oldest slot; acquire on head pairs with the producer's commit. The
 * producer's line is read only when the last look at head says the ring is empty. */
const void *ring_spsc_peek(struct ring_spsc *r)
{
    uint64_t tail = atomic_load_explicit(&r->tail, memory_order_relaxed);
    if (tail == r->head_seen)
        r->head_seen = atomic_load_explicit(&r->head, memory_order_acquire);
    if (tail == r->head_seen)
        return NULL;
    return r->slots + (size_t)(tail & r->mask) * r->slot_size;
}

/* Hands the peeked slot back to the producer (release: our reads happen before). */
void ring_spsc_release(struct ring_spsc *r)
{
    uint64_t tail = atomic_load_explicit(&r->tail, memory_order_relaxed);
    atomic_store_explicit(&r->tail, tail + 1, memory_order_release);
}

/* Peek, copy, release. */
bool ring_spsc_pop(struct ring_spsc *r, void *item)
{
    const void *slot = ring_spsc_peek(r);
    if (!slot)
        return false;
    memcpy(item, slot, r->slot_size);
    ring_spsc_release(r);
    return true;
}

/* Counters, readable from any thread. */
uint64_t ring_spsc_pushed(const struct ring_spsc *r)
{
    return atomic_load_explicit(&r->head, memory_order_acquire);
}

uint64_t ring_spsc_popped(const struct ring_spsc *r)
{
    return atomic_load_explicit(&r->tail, memory_order_acquire);
}

uint64_t ring_spsc_dropped(const struct ring_spsc *r)
{
    return atomic_load_explicit(&r->dropped, memory_order_relaxed);
}

/* ---- many producers, single consumer --------------------------------------------------- */

/* Allocates the slots and marks slot i free for position i. */
int ring_mpsc_init(struct ring_mpsc *q, size_t slots, size_t slot_size)
{
    memset(q, 0, sizeof *q);
    if (!ring_size_ok(slots, slot_size))
        return RING_ERR_SIZE;
    q->slots = calloc(slots, slot_size);
    q->seq = calloc(slots, sizeof *q->seq);
    if (!q->slots || !q->seq) {
        ring_mpsc_free(q);
        return RING_ERR_NOMEM;
    }
    for (size_t i = 0; i < slots; i++)
        atomic_init(&q->seq[i], i);
    q->mask = slots - 1;
    q->slot_size = slot_size;
    atomic_init(&q->enq, 0);
    atomic_init(&q->deq, 0);
    atomic_init(&q->dropped, 0);
    return RING_OK;
}

/* Frees the slots (no thread may use the queue any more). */
void ring_mpsc_free(struct ring_mpsc *q)
{
    free(q->slots);
    free((void *)q->seq);
    q->slots = NULL;
    q->seq = NULL;
}

/* Claims position `pos` when its slot is free for it (seq == pos); a slot still holding the
 * item from one lap earlier (seq < pos) means the queue is full. */
bool ring_mpsc_push(struct ring_mpsc *q, const void *item)
{
    uint64_t pos = atomic_load_explicit(&q->enq, memory_order_relaxed);
    for (;;) {
        _Atomic uint64_t *seq = &q->seq[pos & q->mask];
        int64_t diff = (int64_t)(atomic_load_explicit(seq, memory_order_acquire) - pos);
        if (diff == 0) {
            /* On failure pos is reloaded with the current enq and we look again. */
            if (atomic_compare_exchange_weak_explicit(&q->enq, &pos, pos + 1,
                                                      memory_order_relaxed,
                                                      memory_order_relaxed)) {
                memcpy(q->slots + (size_t)(pos & q->mask) * q->slot_size, item, q->slot_size);
                atomic_store_explicit(seq, pos + 1, memory_order_release);
                return true;
            }
        } else if (diff < 0) {
            atomic_fetch_add_explicit(&q->dropped, 1, memory_order_relaxed);
            return false;
        } else {
            pos = atomic_load_explicit(&q->enq, memory_order_relaxed);
        }
    }
}

/* Takes position deq once its producer has marked it filled (seq == deq + 1), then frees the
 * slot for the position one lap later (seq = deq + slots). */
bool ring_mpsc_pop(struct ring_mpsc *q, void *item)
{
    uint64_t pos = atomic_load_explicit(&q->deq, memory_order_relaxed);
    _Atomic uint64_t *seq = &q->seq[pos & q->mask];
    if (atomic_load_explicit(seq, memory_order_acquire) != pos + 1)
        return false;
    memcpy(item, q->slots + (size_t)(pos & q->mask) * q->slot_size, q->slot_size);
    atomic_store_explicit(seq, pos + q->mask + 1, memory_order_release);
    atomic_store_explicit(&q->deq, pos + 1, memory_order_release);
    return true;
}

/* Counters, readable from any thread. */
uint64_t ring_mpsc_pushed(const struct ring_mpsc *q)
{
    return atomic_load_explicit(&q->enq, memory_order_acquire);
}

uint64_t ring_mpsc_popped(const struct ring_mpsc *q)
{
    return atomic_load_explicit(&q->deq, memory_order_acquire);
}

uint64_t ring_mpsc_dropped(const struct ring_mpsc *q)
{
    return atomic_load_explicit(&q->dropped, memory_order_relaxed);
}
