/* hal_priv.h: the runtime's internal structures, shared by the files of hal/ only. */
#ifndef HEXCNC_HAL_PRIV_H
#define HEXCNC_HAL_PRIV_H

#include <pthread.h>
#include <stdarg.h>

#include "common/inifile.h"
#include "hal/hal.h"
#include "hal/ring.h"

/* The value a pin, parameter or signal holds. */
union hal_data {
    bool b;
    double f;
    int32_t s;
    uint32_t u;
};

/* A name -> pointer table (chained hash); keys point into the objects, never copied. */
struct hal_map_node {
    const char *key;
    void *val;
    struct hal_map_node *next;
};
struct hal_map {
    struct hal_map_node **buckets;
    size_t nbuckets;                 /* a power of two, or 0 before the first put */
    size_t count;
};
int hal_map_put(struct hal_map *m, const char *key, void *val);
void *hal_map_get(const struct hal_map *m, const char *key);
void hal_map_del(struct hal_map *m, const char *key);
void hal_map_free(struct hal_map *m);

/* A growable array of pointers, in insertion order (what `show` and unwinding walk). */
struct hal_vec {
    void **v;
    int n, cap;
};
int hal_vec_push(struct hal_vec *vec, void *p);
void hal_vec_remove(struct hal_vec *vec, void *p);
void hal_vec_free(struct hal_vec *vec);

struct hal_sig;
struct hal_thread;

struct hal_pin {
    char *name;
    enum hal_type type;
    enum hal_dir dir;
    void *owner_ptr;                 /* the component's `T **`: where its data pointer lives */
    union hal_data own;              /* the pin's storage while unlinked */
    struct hal_sig *sig;             /* linked signal or NULL */
    int owner;                       /* component id (0 = the runtime itself) */
};

struct hal_param {
    char *name;
    enum hal_type type;
    enum hal_pdir pdir;
    void *ptr;                       /* storage in the component instance */
    int owner;
};

struct hal_sig {
    char *name;
    enum hal_type type;
    union hal_data data;             /* the storage every linked pin points at */
    struct hal_pin *writer;          /* the OUT pin, or NULL */
    int nreaders;                    /* IN pins */
    int nio;                         /* IO pins */
};

struct hal_funct {
    char *name;
    hal_funct_fn fn;
    void *arg;
    int owner;
    struct hal_thread *thread;       /* the thread it is on, or NULL */
};

struct hal_thread {
    char *name;
    long period_ns;
    struct hal_funct **functs;       /* called in this order every period */
    int nfuncts, cap;
    int32_t *time_ns;                /* pin <name>.time: duration of the last run, ns */
    int32_t *tmax_ns;                /* pin <name>.tmax: longest run so far, ns */
    uint32_t *overruns;              /* pin <name>.overruns: deadlines missed */
    int64_t next_ns;                 /* next deadline on the simulated clock, ns */
    struct hal *h;
    pthread_t tid;                   /* real-time mode */
    bool tid_valid;
    pthread_mutex_t lock;            /* held while the functs run; commands take it too */
};

/* A loadrt'ed component (or a runtime-owned group), the unit of unwinding. */
struct hal_comp {
    char *name;
    int id;
};

struct hal_cleanup {
    void (*fn)(void *arg);
    void *arg;
    int owner;
};

struct hal_object {
    char *name;
    void *obj;
    int owner;
};

struct hal {
    char err[1024];                  /* last error message */
    bool err_located;                /* err already starts with file:line */
    struct hal_map pins, params, sigs, functs, threads, types, objects;
    struct hal_vec pin_list, param_list, sig_list, funct_list, thread_list;
    struct hal_vec comp_list, cleanup_list, object_list, type_list;
    int owner;                       /* component id being loaded (0 = runtime) */
    int next_comp_id;
    struct inifile ini;              /* the machine's INI file (empty before hal_load_ini) */
    /* files being sourced, innermost last (for relative paths and messages) */
    const char *source_stack[16];
    int source_depth;
    /* time */
    bool sim_clock;
    bool running;
    int64_t sim_now_ns;              /* simulated time since start, ns */
    int64_t start_mono_ns;           /* CLOCK_MONOTONIC at hal_start, ns */
    int64_t start_run_ns;            /* after `start`, advance (or sleep) this long */
    int stop_flag;                   /* real-time threads exit when set (atomic access) */
    bool rt_warned;                  /* the "no real-time scheduling" warning was printed */
    pthread_mutex_t rt_mutex;        /* with rt_cond: holds new threads until all exist */
    pthread_cond_t rt_cond;
    bool rt_go;                      /* the time origin is set: threads may begin */
    bool rt_locked;                  /* this runtime called mlockall (munlockall at stop) */
    struct ring_mpsc msgs;           /* messages from components to the shell (hal_msg.c) */
};

/* Internal helpers across files. */
char *hal_strdup(const char *s);
int hal_vformat_name(struct hal *h, char *buf, size_t len, const char *fmt, va_list ap);
int hal_comp_begin(struct hal *h, const char *name);
void hal_comp_unwind(struct hal *h, int id);
void hal_comp_end(struct hal *h, int prev_owner);
void hal_unlink_pin(struct hal_pin *p);
void hal_funct_remove(struct hal *h, struct hal_funct *f);
void hal_pin_remove(struct hal *h, struct hal_pin *p);
void hal_param_remove(struct hal *h, struct hal_param *p);
void hal_threads_free(struct hal *h);
void hal_thread_run(struct hal_thread *t);
int hal_msg_init(struct hal *h);
void hal_msg_free(struct hal *h);
int hal_rt_start(struct hal *h);
void hal_rt_stop(struct hal *h);
void hal_ini_free(struct hal *h);
int hal_parse_value(enum hal_type type, const char *text, union hal_data *out);
void hal_format_value(enum hal_type type, const void *data, char *buf, size_t len);
const char *hal_type_name(enum hal_type type);
const char *hal_dir_name(enum hal_dir dir);
int hal_show(struct hal *h, FILE *out, const char *what, const char *pattern);
/* Lock every thread (real-time mode) around a graph change. */
void hal_lock_all(struct hal *h);
void hal_unlock_all(struct hal *h);

#define HAL_NAME_MAX 128

extern const struct hal_comp_type hal_comp_threads;

#endif
