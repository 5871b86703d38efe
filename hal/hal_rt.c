/* hal_rt.c: real-time threads: absolute deadlines, SCHED_FIFO and mlockall where allowed. */
#include <errno.h>
#include <sched.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include "hal/hal_priv.h"

/* Stack of each real-time thread: room for deep component code, small enough that locking
 * it in memory (mlockall MCL_FUTURE) is quick. */
#define HAL_RT_STACK_BYTES (1024 * 1024)

/* CLOCK_MONOTONIC in ns. */
static int64_t hal_mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* Nanoseconds since hal_start (simulated or monotonic). */
int64_t hal_now_ns(const struct hal *h)
{
    if (h->running && !h->sim_clock)
        return hal_mono_ns() - h->start_mono_ns;
    return h->sim_now_ns;
}

/* One real-time thread: wait for the common origin, then sleep to each absolute deadline,
 * run, measure, and count missed deadlines while keeping the phase. */
static void *hal_rt_main(void *arg)
{
    struct hal_thread *t = arg;
    struct hal *h = t->h;
    pthread_mutex_lock(&h->rt_mutex);
    while (!h->rt_go)
        pthread_cond_wait(&h->rt_cond, &h->rt_mutex);
    pthread_mutex_unlock(&h->rt_mutex);
    int64_t next_ns = h->start_mono_ns + t->period_ns;
    while (!__atomic_load_n(&h->stop_flag, __ATOMIC_ACQUIRE)) {
        struct timespec ts = { .tv_sec = next_ns / 1000000000, .tv_nsec = next_ns % 1000000000 };
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR)
            ;
        if (__atomic_load_n(&h->stop_flag, __ATOMIC_ACQUIRE))
            break;
        pthread_mutex_lock(&t->lock);
        int64_t t0 = hal_mono_ns();
        hal_thread_run(t);
        int64_t t1 = hal_mono_ns();
        pthread_mutex_unlock(&t->lock);
        int64_t run_ns = t1 - t0;
        *t->time_ns = run_ns > INT32_MAX ? INT32_MAX : (int32_t)run_ns;
        if (*t->time_ns > *t->tmax_ns)
            *t->tmax_ns = *t->time_ns;
        next_ns += t->period_ns;
        if (t1 > next_ns) {              /* missed deadlines: count them, keep the phase */
            int64_t missed = (t1 - next_ns) / t->period_ns + 1;
            *t->overruns += (uint32_t)missed;
            next_ns += missed * t->period_ns;
        }
    }
    return NULL;
}

/* FIFO priority: the shorter the period, the higher. */
static int hal_rt_priority(struct hal *h, struct hal_thread *t)
{
    int prio = sched_get_priority_max(SCHED_FIFO) - 1;
    for (int i = 0; i < h->thread_list.n; i++) {
        struct hal_thread *o = h->thread_list.v[i];
        if (o->period_ns < t->period_ns)
            prio--;
    }
    return prio < 1 ? 1 : prio;
}

/* Starts one thread: SCHED_FIFO if permitted, else normal priority (*no_fifo set). */
static int hal_rt_spawn(struct hal *h, struct hal_thread *t, bool *no_fifo)
{
    pthread_attr_t attr;
    struct sched_param sp = { .sched_priority = hal_rt_priority(h, t) };
    pthread_attr_init(&attr);
    pthread_attr_setstacksize(&attr, HAL_RT_STACK_BYTES);
    int err = EPERM;
    if (!*no_fifo) {
        pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED);
        pthread_attr_setschedpolicy(&attr, SCHED_FIFO);
        pthread_attr_setschedparam(&attr, &sp);
        err = pthread_create(&t->tid, &attr, hal_rt_main, t);
        if (err == EPERM) {
            *no_fifo = true;
            pthread_attr_setinheritsched(&attr, PTHREAD_INHERIT_SCHED);
        }
    }
    if (err == EPERM)
        err = pthread_create(&t->tid, &attr, hal_rt_main, t);
    pthread_attr_destroy(&attr);
    if (err)
        return hal_error(h, HAL_ERR_RT, "start: cannot create thread '%s': %s", t->name,
                         strerror(err));
    t->tid_valid = true;
    return HAL_OK;
}

/* Locks memory only where the limit allows it; a partial lock would make thread creation
 * fail (their stacks count against RLIMIT_MEMLOCK). */
static bool hal_rt_lock_memory(void)
{
    struct rlimit rl;
    if (geteuid() != 0 && (getrlimit(RLIMIT_MEMLOCK, &rl) != 0 || rl.rlim_cur != RLIM_INFINITY))
        return false;
    /* MCL_ONFAULT: later mappings are locked page by page as they are touched, not read in
     * whole when mapped (a program file the interpreter maps, interp_run_file, would else be
     * read and locked entirely at once) */
#ifdef MCL_ONFAULT
    if (mlockall(MCL_CURRENT | MCL_FUTURE | MCL_ONFAULT) == 0)
        return true;
#endif
    return mlockall(MCL_CURRENT | MCL_FUTURE) == 0;
}

/* Starts every thread; they begin together once all exist, on one time origin. */
int hal_rt_start(struct hal *h)
{
    bool locked = hal_rt_lock_memory(), no_fifo = false;
    h->rt_locked = locked;
    int st = HAL_OK;
    __atomic_store_n(&h->stop_flag, 0, __ATOMIC_RELEASE);
    pthread_mutex_init(&h->rt_mutex, NULL);
    pthread_cond_init(&h->rt_cond, NULL);
    h->rt_go = false;
    for (int i = 0; i < h->thread_list.n && st == HAL_OK; i++)
        st = hal_rt_spawn(h, h->thread_list.v[i], &no_fifo);
    if ((!locked || no_fifo) && !h->rt_warned) {
        h->rt_warned = true;
        fprintf(stderr, "hal: warning: %s%s%s not permitted; threads run %s and their timing "
                "may jitter\n", no_fifo ? "real-time scheduling (SCHED_FIFO)" : "",
                no_fifo && !locked ? " and " : "", locked ? "" : "memory locking (mlockall)",
                no_fifo ? "with normal priority" : "unlocked in memory");
    }
    pthread_mutex_lock(&h->rt_mutex);
    h->start_mono_ns = hal_mono_ns();
    h->rt_go = true;
    pthread_cond_broadcast(&h->rt_cond);
    pthread_mutex_unlock(&h->rt_mutex);
    if (st != HAL_OK)
        hal_rt_stop(h);
    return st;
}

/* Asks every thread to finish its period and joins it. */
void hal_rt_stop(struct hal *h)
{
    __atomic_store_n(&h->stop_flag, 1, __ATOMIC_RELEASE);
    for (int i = 0; i < h->thread_list.n; i++) {
        struct hal_thread *t = h->thread_list.v[i];
        if (t->tid_valid)
            pthread_join(t->tid, NULL);
        t->tid_valid = false;
    }
    h->sim_now_ns = hal_mono_ns() - h->start_mono_ns;
    pthread_cond_destroy(&h->rt_cond);
    pthread_mutex_destroy(&h->rt_mutex);
    if (h->rt_locked)
        munlockall();
    h->rt_locked = false;
}
