/* hal_funct.c: functions, threads, addf/delf, and the simulated clock. */
#include <stdlib.h>
#include <string.h>

#include "hal/hal_priv.h"

/* Exports a function that `addf` can put on a thread. */
int hal_export_functf(struct hal *h, hal_funct_fn fn, void *arg, const char *fmt, ...)
{
    char name[HAL_NAME_MAX];
    va_list ap;
    va_start(ap, fmt);
    int st = hal_vformat_name(h, name, sizeof name, fmt, ap);
    va_end(ap);
    if (st != HAL_OK)
        return st;
    if (!fn)
        return hal_error(h, HAL_ERR_ARG, "function '%s' has no code", name);
    if (hal_map_get(&h->functs, name))
        return hal_error(h, HAL_ERR_EXISTS, "function '%s' already exists", name);
    struct hal_funct *f = calloc(1, sizeof *f);
    if (!f || !(f->name = hal_strdup(name)) || hal_vec_push(&h->funct_list, f) != HAL_OK)
        goto nomem;
    if (hal_map_put(&h->functs, f->name, f) != HAL_OK) {
        hal_vec_remove(&h->funct_list, f);
        goto nomem;
    }
    f->fn = fn;
    f->arg = arg;
    f->owner = h->owner;
    return HAL_OK;
nomem:
    if (f)
        free(f->name);
    free(f);
    return hal_error(h, HAL_ERR_NOMEM, "out of memory creating function '%s'", name);
}

/* Takes a funct off its thread, if any. */
static void hal_funct_detach(struct hal_funct *f)
{
    struct hal_thread *t = f->thread;
    if (!t)
        return;
    for (int i = 0; i < t->nfuncts; i++) {
        if (t->functs[i] == f) {
            memmove(&t->functs[i], &t->functs[i + 1],
                    (size_t)(t->nfuncts - i - 1) * sizeof *t->functs);
            t->nfuncts--;
            break;
        }
    }
    f->thread = NULL;
}

/* Deletes a funct (its component is going away). */
void hal_funct_remove(struct hal *h, struct hal_funct *f)
{
    hal_funct_detach(f);
    hal_map_del(&h->functs, f->name);
    hal_vec_remove(&h->funct_list, f);
    free(f->name);
    free(f);
}

/* Creates a thread and its time, tmax and overruns pins (owned by the runtime). */
int hal_thread_new(struct hal *h, const char *name, long period_ns)
{
    if (period_ns <= 0)
        return hal_error(h, HAL_ERR_ARG, "thread '%s': period must be a positive number of "
                         "nanoseconds, not %ld", name, period_ns);
    if (h->running)
        return hal_error(h, HAL_ERR_STATE, "thread '%s': threads cannot be created while "
                         "running; stop first", name);
    if (hal_map_get(&h->threads, name))
        return hal_error(h, HAL_ERR_EXISTS, "thread '%s' already exists", name);
    struct hal_thread *t = calloc(1, sizeof *t);
    if (!t || !(t->name = hal_strdup(name)))
        goto nomem;
    int prev = h->owner;
    h->owner = 0;
    int st = hal_pin_s32_newf(h, HAL_OUT, &t->time_ns, "%s.time", name);
    if (st == HAL_OK)
        st = hal_pin_s32_newf(h, HAL_OUT, &t->tmax_ns, "%s.tmax", name);
    if (st == HAL_OK)
        st = hal_pin_u32_newf(h, HAL_OUT, &t->overruns, "%s.overruns", name);
    h->owner = prev;
    if (st != HAL_OK) {
        free(t->name);
        free(t);
        return st;         /* the pins made so far stay, owned by the runtime, unused */
    }
    if (hal_vec_push(&h->thread_list, t) != HAL_OK)
        goto nomem;
    if (hal_map_put(&h->threads, t->name, t) != HAL_OK) {
        hal_vec_remove(&h->thread_list, t);
        goto nomem;
    }
    t->period_ns = period_ns;
    t->h = h;
    pthread_mutex_init(&t->lock, NULL);
    return HAL_OK;
nomem:
    if (t)
        free(t->name);
    free(t);
    return hal_error(h, HAL_ERR_NOMEM, "out of memory creating thread '%s'", name);
}

/* Frees every thread (they are stopped). */
void hal_threads_free(struct hal *h)
{
    for (int i = 0; i < h->thread_list.n; i++) {
        struct hal_thread *t = h->thread_list.v[i];
        for (int k = 0; k < t->nfuncts; k++)
            t->functs[k]->thread = NULL;
        pthread_mutex_destroy(&t->lock);
        free(t->functs);
        free(t->name);
        free(t);
    }
    hal_vec_free(&h->thread_list);
    hal_map_free(&h->threads);
}

/* `addf FUNCT THREAD [POSITION]`: 1-based position, negative from the end, 0 appends. */
int hal_addf(struct hal *h, const char *funct, const char *thread, long position)
{
    struct hal_funct *f = hal_map_get(&h->functs, funct);
    struct hal_thread *t = hal_map_get(&h->threads, thread);
    if (!f)
        return hal_error(h, HAL_ERR_NOT_FOUND, "addf: function '%s' does not exist", funct);
    if (!t)
        return hal_error(h, HAL_ERR_NOT_FOUND, "addf: thread '%s' does not exist", thread);
    if (f->thread)
        return hal_error(h, HAL_ERR_EXISTS, "addf: function '%s' is already on thread '%s'",
                         funct, f->thread->name);
    /* The range is checked on the long the command gave: no wrap onto a valid position. */
    if (position > (long)t->nfuncts + 1 || position < -((long)t->nfuncts + 1))
        return hal_error(h, HAL_ERR_ARG, "addf: position %ld is outside thread '%s', which "
                         "has %d functions", position, thread, t->nfuncts);
    int idx = position > 0 ? (int)position - 1 : t->nfuncts + (int)position + (position < 0);
    if (t->nfuncts == t->cap) {
        int cap = t->cap ? t->cap * 2 : 8;
        struct hal_funct **v = realloc(t->functs, (size_t)cap * sizeof *v);
        if (!v)
            return hal_error(h, HAL_ERR_NOMEM, "out of memory");
        t->functs = v;
        t->cap = cap;
    }
    memmove(&t->functs[idx + 1], &t->functs[idx], (size_t)(t->nfuncts - idx) * sizeof *t->functs);
    t->functs[idx] = f;
    t->nfuncts++;
    f->thread = t;
    return HAL_OK;
}

/* `delf FUNCT [THREAD]`: takes a function off its thread. */
int hal_delf(struct hal *h, const char *funct, const char *thread)
{
    struct hal_funct *f = hal_map_get(&h->functs, funct);
    if (!f)
        return hal_error(h, HAL_ERR_NOT_FOUND, "delf: function '%s' does not exist", funct);
    if (!f->thread || (thread && strcmp(thread, f->thread->name)))
        return hal_error(h, HAL_ERR_NOT_FOUND, "delf: function '%s' is not on thread '%s'",
                         funct, thread ? thread : "(any)");
    hal_funct_detach(f);
    return HAL_OK;
}

/* One period of a thread: its functs in order (no lookups here). */
void hal_thread_run(struct hal_thread *t)
{
    for (int i = 0; i < t->nfuncts; i++)
        t->functs[i]->fn(t->functs[i]->arg, t->period_ns);
}

/* Turns the simulated clock on or off (not while running). */
void hal_set_sim_clock(struct hal *h, bool on)
{
    if (!h->running)
        h->sim_clock = on;
}

bool hal_sim_clock(const struct hal *h)
{
    return h->sim_clock;
}

bool hal_running(const struct hal *h)
{
    return h->running;
}

/* Starts the threads: pthreads in real time, or arms the simulated clock at t = 0. */
int hal_start(struct hal *h)
{
    if (h->running)
        return hal_error(h, HAL_ERR_STATE, "start: threads are already running");
    if (h->sim_clock) {
        h->sim_now_ns = 0;
        for (int i = 0; i < h->thread_list.n; i++) {
            struct hal_thread *t = h->thread_list.v[i];
            t->next_ns = t->period_ns;
        }
        h->running = true;
        return HAL_OK;
    }
    int st = hal_rt_start(h);
    if (st == HAL_OK)
        h->running = true;
    return st;
}

/* Stops the threads (a no-op when stopped). */
int hal_stop(struct hal *h)
{
    if (!h->running)
        return HAL_OK;
    if (!h->sim_clock)
        hal_rt_stop(h);
    h->running = false;
    return HAL_OK;
}

/* Simulated clock: runs every thread deadline in (now, now + dt_ns], earliest first; on a
 * tie the thread created first runs first. */
int hal_sim_advance(struct hal *h, long dt_ns)
{
    if (!h->sim_clock)
        return hal_error(h, HAL_ERR_STATE, "the simulated clock is off");
    if (!h->running)
        return hal_error(h, HAL_ERR_STATE, "threads are not started");
    if (dt_ns < 0)
        return hal_error(h, HAL_ERR_ARG, "cannot advance time by %ld ns", dt_ns);
    int64_t end_ns = h->sim_now_ns + dt_ns;
    for (;;) {
        struct hal_thread *next = NULL;
        for (int i = 0; i < h->thread_list.n; i++) {
            struct hal_thread *t = h->thread_list.v[i];
            if (t->next_ns <= end_ns && (!next || t->next_ns < next->next_ns))
                next = t;
        }
        if (!next)
            break;
        h->sim_now_ns = next->next_ns;
        hal_thread_run(next);
        next->next_ns += next->period_ns;
    }
    h->sim_now_ns = end_ns;
    return HAL_OK;
}

/* Locks every thread out of its functs while the graph changes (real-time mode only). */
void hal_lock_all(struct hal *h)
{
    if (!h->running || h->sim_clock)
        return;
    for (int i = 0; i < h->thread_list.n; i++)
        pthread_mutex_lock(&((struct hal_thread *)h->thread_list.v[i])->lock);
}

void hal_unlock_all(struct hal *h)
{
    if (!h->running || h->sim_clock)
        return;
    for (int i = h->thread_list.n - 1; i >= 0; i--)
        pthread_mutex_unlock(&((struct hal_thread *)h->thread_list.v[i])->lock);
}
