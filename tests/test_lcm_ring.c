/* test_lcm_ring.c: the lock-free rings of lcm-status: order, full-ring drops, two threads. */
#include <check.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdint.h>
#include <string.h>

#include "hal/ring.h"

#define N_ITEMS 50000u              /* items per producer in the threaded tests */

/* An item whose words all derive from its sequence number, so a torn copy shows. */
struct item {
    uint64_t seq;
    uint64_t word[7];
};

/* Fills an item for sequence number n (and producer p). */
static void item_make(struct item *it, uint64_t n, uint64_t p)
{
    it->seq = n | (p << 48);
    for (int i = 0; i < 7; i++)
        it->word[i] = it->seq * 2654435761u + (uint64_t)i;
}

/* True when every word matches the sequence number. */
static bool item_ok(const struct item *it)
{
    for (int i = 0; i < 7; i++)
        if (it->word[i] != it->seq * 2654435761u + (uint64_t)i)
            return false;
    return true;
}

START_TEST(test_spsc_sizes)
{
    struct ring_spsc r;
    ck_assert_int_eq(ring_spsc_init(&r, 6, 8), RING_ERR_SIZE);
    ck_assert_int_eq(ring_spsc_init(&r, 1, 8), RING_ERR_SIZE);
    ck_assert_int_eq(ring_spsc_init(&r, 8, 0), RING_ERR_SIZE);
    ck_assert_int_eq(ring_spsc_init(&r, 8, 8), RING_OK);
    ring_spsc_free(&r);
    struct ring_mpsc q;
    ck_assert_int_eq(ring_mpsc_init(&q, 12, 8), RING_ERR_SIZE);
    ck_assert_str_eq(ring_strerror(RING_ERR_SIZE), "the number of slots must be a power of two "
                     "(at least 2) and the slot size above 0");
}
END_TEST

/* A full ring refuses and counts; what was in it comes out in order, across the wrap. */
START_TEST(test_spsc_full_drops_and_order)
{
    struct ring_spsc r;
    ck_assert_int_eq(ring_spsc_init(&r, 4, sizeof(struct item)), RING_OK);
    struct item it, out;
    uint64_t next_out = 0;
    for (uint64_t n = 0; n < 4; n++) {
        item_make(&it, n, 0);
        ck_assert(ring_spsc_push(&r, &it));
    }
    item_make(&it, 99, 0);
    ck_assert(!ring_spsc_push(&r, &it));
    ck_assert(ring_spsc_claim(&r) == NULL);
    ck_assert_uint_eq(ring_spsc_dropped(&r), 2);
    /* Three laps round the 4 slots: pop two, push two. */
    for (uint64_t n = 4; n < 16; n += 2) {
        for (int k = 0; k < 2; k++) {
            ck_assert(ring_spsc_pop(&r, &out));
            ck_assert_uint_eq(out.seq, next_out++);
            ck_assert(item_ok(&out));
        }
        for (uint64_t k = 0; k < 2; k++) {
            item_make(&it, n + k, 0);
            ck_assert(ring_spsc_push(&r, &it));
        }
    }
    while (ring_spsc_pop(&r, &out))
        ck_assert_uint_eq(out.seq, next_out++);
    ck_assert_uint_eq(next_out, 16);
    ck_assert(ring_spsc_peek(&r) == NULL);
    ck_assert_uint_eq(ring_spsc_pushed(&r), 16);
    ck_assert_uint_eq(ring_spsc_popped(&r), 16);
    ck_assert_uint_eq(ring_spsc_dropped(&r), 2);
    ring_spsc_free(&r);
}
END_TEST

struct spsc_run {
    struct ring_spsc r;
    bool retry;                     /* producer retries a full ring instead of dropping */
    uint64_t refused;               /* pushes that found the ring full */
    _Atomic bool done;              /* the producer has finished */
};

/* Producer: N_ITEMS items in sequence, retrying or dropping when full. */
static void *spsc_producer(void *arg)
{
    struct spsc_run *run = arg;
    struct item it;
    for (uint64_t n = 0; n < N_ITEMS; n++) {
        item_make(&it, n, 0);
        while (!ring_spsc_push(&run->r, &it)) {
            run->refused++;
            if (!run->retry)
                break;
            sched_yield();
        }
    }
    atomic_store(&run->done, true);
    return NULL;
}

/* Runs producer and consumer on two threads; the consumer checks that sequence numbers only
 * grow (by exactly one when nothing is dropped) and that no item is torn. */
static void spsc_two_threads(bool retry)
{
    struct spsc_run run = { .retry = retry };
    ck_assert_int_eq(ring_spsc_init(&run.r, 64, sizeof(struct item)), RING_OK);
    pthread_t t;
    ck_assert_int_eq(pthread_create(&t, NULL, spsc_producer, &run), 0);
    uint64_t got = 0, last = 0;
    struct item out;
    for (;;) {
        if (!ring_spsc_pop(&run.r, &out)) {
            /* done is read before the last look, so nothing pushed before it is missed */
            if (atomic_load(&run.done) && ring_spsc_peek(&run.r) == NULL)
                break;
            sched_yield();
            continue;
        }
        ck_assert_msg(item_ok(&out), "torn item %llu", (unsigned long long)out.seq);
        if (got > 0)
            ck_assert_msg(retry ? out.seq == last + 1 : out.seq > last,
                          "item %llu after %llu", (unsigned long long)out.seq,
                          (unsigned long long)last);
        else if (retry)
            ck_assert_uint_eq(out.seq, 0);
        last = out.seq;
        got++;
    }
    pthread_join(t, NULL);
    ck_assert_uint_eq(got + ring_spsc_dropped(&run.r) - (retry ? run.refused : 0), N_ITEMS);
    if (retry)
        ck_assert_uint_eq(got, N_ITEMS);
    else
        ck_assert_uint_eq(ring_spsc_dropped(&run.r), run.refused);
    ring_spsc_free(&run.r);
}

START_TEST(test_spsc_threads_no_loss)
{
    spsc_two_threads(true);
}
END_TEST

START_TEST(test_spsc_threads_drop_and_count)
{
    spsc_two_threads(false);
}
END_TEST

#define MPSC_PRODUCERS 3

struct mpsc_run {
    struct ring_mpsc q;
    int id;
};

/* One of several producers: N_ITEMS / 4 items tagged with its id; full = drop. */
static void *mpsc_producer(void *arg)
{
    struct mpsc_run *run = arg;
    struct item it;
    int id = __atomic_fetch_add(&run->id, 1, __ATOMIC_RELAXED);
    for (uint64_t n = 0; n < N_ITEMS / 4; n++) {
        item_make(&it, n, (uint64_t)id);
        ring_mpsc_push(&run->q, &it);
    }
    return NULL;
}

/* Every producer's items arrive in its order, untorn; received + dropped = pushed. */
START_TEST(test_mpsc_threads)
{
    static struct mpsc_run run;
    ck_assert_int_eq(ring_mpsc_init(&run.q, 128, sizeof(struct item)), RING_OK);
    run.id = 0;
    pthread_t t[MPSC_PRODUCERS];
    for (int i = 0; i < MPSC_PRODUCERS; i++)
        ck_assert_int_eq(pthread_create(&t[i], NULL, mpsc_producer, &run), 0);
    int64_t last[MPSC_PRODUCERS] = { -1, -1, -1 };
    uint64_t got = 0, total = (uint64_t)MPSC_PRODUCERS * (N_ITEMS / 4);
    struct item out;
    while (got + ring_mpsc_dropped(&run.q) < total) {
        if (!ring_mpsc_pop(&run.q, &out)) {
            sched_yield();
            continue;
        }
        ck_assert(item_ok(&out));
        int p = (int)(out.seq >> 48);
        int64_t n = (int64_t)(out.seq & 0xffffffffffffu);
        ck_assert(p >= 0 && p < MPSC_PRODUCERS);
        ck_assert_msg(n > last[p], "producer %d: %lld after %lld", p, (long long)n,
                      (long long)last[p]);
        last[p] = n;
        got++;
    }
    for (int i = 0; i < MPSC_PRODUCERS; i++)
        pthread_join(t[i], NULL);
    ck_assert(!ring_mpsc_pop(&run.q, &out));
    ck_assert_uint_eq(got + ring_mpsc_dropped(&run.q), total);
    ck_assert_uint_eq(ring_mpsc_popped(&run.q), got);
    ring_mpsc_free(&run.q);
}
END_TEST

/* One thread: a full queue drops and counts; order is kept across laps. */
START_TEST(test_mpsc_full)
{
    struct ring_mpsc q;
    ck_assert_int_eq(ring_mpsc_init(&q, 2, sizeof(struct item)), RING_OK);
    struct item it, out;
    for (uint64_t n = 0; n < 3; n++) {
        item_make(&it, n, 0);
        ck_assert(ring_mpsc_push(&q, &it) == (n < 2));
    }
    ck_assert_uint_eq(ring_mpsc_dropped(&q), 1);
    for (uint64_t n = 0; n < 2; n++) {
        ck_assert(ring_mpsc_pop(&q, &out));
        ck_assert_uint_eq(out.seq, n);
    }
    item_make(&it, 7, 0);
    ck_assert(ring_mpsc_push(&q, &it));
    ck_assert(ring_mpsc_pop(&q, &out));
    ck_assert_uint_eq(out.seq, 7);
    ck_assert(!ring_mpsc_pop(&q, &out));
    ring_mpsc_free(&q);
}
END_TEST

int main(void)
{
    Suite *s = suite_create("lcm_ring");
    TCase *tc = tcase_create("ring");
    tcase_set_timeout(tc, 60);      /* two threads on a loaded machine: never a tight limit */
    tcase_add_test(tc, test_spsc_sizes);
    tcase_add_test(tc, test_spsc_full_drops_and_order);
    tcase_add_test(tc, test_spsc_threads_no_loss);
    tcase_add_test(tc, test_spsc_threads_drop_and_count);
    tcase_add_test(tc, test_mpsc_threads);
    tcase_add_test(tc, test_mpsc_full);
    suite_add_tcase(s, tc);
    SRunner *sr = srunner_create(s);
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? 1 : 0;
}
