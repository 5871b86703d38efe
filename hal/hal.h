/* hal.h: the component-graph runtime: pins, parameters, signals, functions, threads. */
#ifndef HEXCNC_HAL_H
#define HEXCNC_HAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/*
 * The model is LinuxCNC's HAL, in one process, with all state in a `struct hal`:
 *  - a component instance holds pointers to its pins' data (`double *pos_cmd;`), and reads
 *    and writes them as `*inst->pos_cmd`. hal_pin_*_newf() points them at the pin's own
 *    storage; `net` re-points every linked pin at the signal's storage.
 *  - a signal has at most one writer (an OUT pin) and any number of readers (IN pins);
 *    IO pins may share a signal with no OUT pin. Types must match.
 *  - a function (funct) is a C function exported by an instance; `addf` puts it on a thread;
 *    a thread calls its functs in order every period.
 *  - names are `comp.N.pin-name` (or `comp.pin-name` for single-instance components).
 */

enum hal_type { HAL_BIT = 1, HAL_FLOAT, HAL_S32, HAL_U32 };
enum hal_dir { HAL_IN = 1, HAL_OUT = 2, HAL_IO = 3 };
enum hal_pdir { HAL_RO = 1, HAL_RW = 2 };     /* parameter access from halcmd */

enum hal_status {
    HAL_OK = 0,
    HAL_ERR_NOMEM,        /* allocation failed */
    HAL_ERR_EXISTS,       /* a pin, signal, funct, thread or component of that name exists */
    HAL_ERR_NOT_FOUND,    /* no such pin, signal, funct, thread, component, INI key or file */
    HAL_ERR_TYPE,         /* pin and signal types differ */
    HAL_ERR_DIR,          /* a second writer on a signal, setp on a connected pin, ... */
    HAL_ERR_SYNTAX,       /* a HAL command or value that does not parse */
    HAL_ERR_ARG,          /* a bad argument (period 0, count out of range, ...) */
    HAL_ERR_STATE,        /* not allowed now (e.g. addf to a running thread) */
    HAL_ERR_COMPONENT,    /* a component failed to load; the message says why */
    HAL_ERR_IO,           /* a file could not be read */
    HAL_ERR_RT,           /* thread creation or scheduling failed */
    HAL_STATUS_COUNT
};
const char *hal_strerror(int status);

struct hal;

/* ---- lifetime ------------------------------------------------------------------------- */

struct hal *hal_create(void);
/* Stops threads, runs every registered cleanup in reverse order, frees everything. */
void hal_destroy(struct hal *h);
/* The last error message (file:line prefix included when it came from a HAL file). */
const char *hal_last_error(const struct hal *h);
/* Sets the last error message; returns `status` so callers can `return hal_error(...)`. */
int hal_error(struct hal *h, int status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* ---- INI ------------------------------------------------------------------------------- */

/* Reads an INI file (libinih) into the runtime; `[SECTION]KEY` in HAL files and
 * hal_ini_get() then refer to it. Errors name the file and line. */
int hal_load_ini(struct hal *h, const char *path);
/* hal_load_ini, then the whole-file check of every section and key against hexcnc's table
 * (common/config.h, docs/ini.md): what every command that runs a machine calls, so that a
 * misspelt or out-of-range key stops it before anything starts. HAL_ERR_SYNTAX with every
 * problem ("PATH:LINE: [SECTION] KEY ...", one per line) in the message. */
int hal_load_machine_ini(struct hal *h, const char *path);
/* Value of the first KEY in SECTION, or NULL. */
const char *hal_ini_get(const struct hal *h, const char *section, const char *key);
/* hal_ini_get for callers that hold the runtime as a void *: the one lookup behind the get()
 * of struct kins_config, interp_setup() and the Modbus configuration reader. */
const char *hal_ini_lookup(void *h, const char *section, const char *key);
/* Value of the n-th (0-based) occurrence of a repeated key (e.g. [HAL] HALFILE), or NULL. */
const char *hal_ini_get_n(const struct hal *h, const char *section, const char *key, int n);
/* Typed readers: HAL_OK, HAL_ERR_NOT_FOUND when absent (out = def), HAL_ERR_SYNTAX when
 * present but not a number (with a message naming [SECTION]KEY and the file). */
int hal_ini_double(struct hal *h, const char *section, const char *key, double def, double *out);
int hal_ini_int(struct hal *h, const char *section, const char *key, long def, long *out);
/* The INI file's path and folder (for relative paths in it), or NULL before hal_load_ini. */
const char *hal_ini_path(const struct hal *h);
const char *hal_ini_dir(const struct hal *h);
/* The INI file itself (common/inifile.h), for the line of a key in messages. */
struct inifile;
const struct inifile *hal_ini_file(const struct hal *h);

/* ---- components ------------------------------------------------------------------------ */

/* A component type, as `loadrt NAME args...` knows it. */
struct hal_comp_type {
    const char *name;
    /* Creates the instances, pins, params and functs from the loadrt arguments
     * (argv[0..argc-1], e.g. "count=6", "names=a,b", "port=5020"). On failure it sets the
     * error (hal_error) and returns a status; what it registered so far is undone by the
     * runtime. It may read the INI through hal_ini_get(). */
    int (*load)(struct hal *h, int argc, char **argv);
};

/* Built-in component types are registered explicitly (hal_create registers the ones
 * linked into the library, listed by HAL_COMPS in the module.mk files). */
int hal_register_type(struct hal *h, const struct hal_comp_type *t);

/* `loadrt NAME args`: a registered type; else the shared object <plugindir>/hal/NAME.so
 * exporting `const struct hal_comp_type hal_comp_<name>` ('-' -> '_'); else a kinematics
 * plugin of that name (kins_find), which becomes the machine's kinematics: the runtime
 * creates it from the INI, stores it as the object "kins" and loads the `kins` component
 * (forward kinematics of joint feedback to pose pins, see hal/components/kins.c). */
int hal_loadrt(struct hal *h, const char *name, int argc, char **argv);

/* Registers a cleanup to run at hal_destroy (reverse order of registration). */
int hal_on_destroy(struct hal *h, void (*fn)(void *arg), void *arg);

/* Named objects shared between the shell and components: "kins" (struct kins *),
 * "motion" (the motion instance), ... set_object fails with HAL_ERR_EXISTS on a duplicate. */
int hal_set_object(struct hal *h, const char *name, void *obj);
void *hal_get_object(const struct hal *h, const char *name);

/* ---- pins and parameters (names via printf formats) ------------------------------------ */

int hal_pin_bit_newf(struct hal *h, enum hal_dir dir, bool **pp, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
int hal_pin_float_newf(struct hal *h, enum hal_dir dir, double **pp, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
int hal_pin_s32_newf(struct hal *h, enum hal_dir dir, int32_t **pp, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
int hal_pin_u32_newf(struct hal *h, enum hal_dir dir, uint32_t **pp, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* Parameters: storage owned by the instance (ptr), set with setp, read with getp. */
int hal_param_bit_newf(struct hal *h, enum hal_pdir dir, bool *p, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
int hal_param_float_newf(struct hal *h, enum hal_pdir dir, double *p, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
int hal_param_s32_newf(struct hal *h, enum hal_pdir dir, int32_t *p, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
int hal_param_u32_newf(struct hal *h, enum hal_pdir dir, uint32_t *p, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* ---- functions and threads ------------------------------------------------------------- */

typedef void (*hal_funct_fn)(void *arg, long period_ns);
int hal_export_functf(struct hal *h, hal_funct_fn fn, void *arg, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* A thread calling its functs every period_ns. Creates pins <name>.time (s32, ns of the
 * last run), <name>.tmax (s32, ns) and <name>.overruns (u32). On the simulated clock they
 * stay 0 (a measured CPU time would make runs differ). */
int hal_thread_new(struct hal *h, const char *name, long period_ns);
/* `addf funct thread [position]`: position 1-based, negative from the end, 0 = append. */
int hal_addf(struct hal *h, const char *funct, const char *thread, long position);

/* Time: the simulated clock (default off) runs every thread in exact simulated time, as
 * fast as the CPU allows, deterministically; tests and offline checks use it. */
void hal_set_sim_clock(struct hal *h, bool on);
bool hal_sim_clock(const struct hal *h);
/* Real time: starts one pthread per thread on absolute deadlines (clock_nanosleep,
 * TIMER_ABSTIME), SCHED_FIFO and mlockall where permitted (a warning on stderr where not).
 * Simulated clock: marks the threads running; hal_sim_advance() then runs them. */
int hal_start(struct hal *h);
int hal_stop(struct hal *h);
bool hal_running(const struct hal *h);
/* Simulated clock only: advances time by dt_ns, calling every thread whose next deadline
 * falls within it, in deadline order (ties: the thread created first). */
int hal_sim_advance(struct hal *h, long dt_ns);
/* Nanoseconds since hal_start: simulated or CLOCK_MONOTONIC. */
int64_t hal_now_ns(const struct hal *h);

/* ---- access by name (halcmd, tests, the run loop) -------------------------------------- */

/* The current data of a pin (its signal's when linked) or a parameter; NULL if none. */
void *hal_data_ptr(struct hal *h, const char *name, enum hal_type *type);
/* Text get/set as halcmd does (bits: 0/1/TRUE/FALSE). setp on an IN pin linked to a
 * signal is an error (set the signal with `sets`). */
int hal_setp(struct hal *h, const char *name, const char *value);
int hal_getp(struct hal *h, const char *name, char *buf, size_t len);
int hal_sets(struct hal *h, const char *signal, const char *value);
/* `net SIGNAL pin pin ...` (creates the signal if new). */
int hal_net(struct hal *h, const char *signal, int npins, char **pins);
/* Additions (after the first contract):
 * `gets SIGNAL`; `newsig NAME TYPE` (a signal with no pins yet); `unlinkp PIN` (the pin keeps
 * the signal's last value); `delf FUNCT [THREAD]` (thread may be NULL). */
int hal_gets(struct hal *h, const char *signal, char *buf, size_t len);
int hal_newsig(struct hal *h, const char *name, enum hal_type type);
int hal_unlinkp(struct hal *h, const char *pin);
int hal_delf(struct hal *h, const char *funct, const char *thread);

/* ---- messages from components ----------------------------------------------------------- */

/* A component's message to the machinist (a drive fault, a lost node, a warning), carried
 * from any thread, the servo thread included, to the shell that prints it. Posting takes
 * no lock, allocates nothing and makes no system call; a full queue drops the message and
 * counts it. The shell (hexcnc run, halcmd) takes them with hal_msg_take(). */
enum hal_msg_severity { HAL_MSG_INFO = 0, HAL_MSG_WARNING, HAL_MSG_FAULT };
#define HAL_MSG_TEXT_MAX 240
struct hal_msg {
    enum hal_msg_severity severity;
    char source[32];             /* who says it: "cia402.3", "modbus.0", ... */
    char text[HAL_MSG_TEXT_MAX]; /* what happened, in words a machinist understands */
};
int hal_msg_post(struct hal *h, enum hal_msg_severity sev, const char *source,
                 const char *fmt, ...) __attribute__((format(printf, 4, 5)));
/* One consumer only (the shell): the oldest message; false when none. */
bool hal_msg_take(struct hal *h, struct hal_msg *out);
/* Messages dropped because the queue was full. */
uint64_t hal_msg_dropped(const struct hal *h);
/* The severity's word: "info", "warning", "fault". */
const char *hal_msg_severity_name(enum hal_msg_severity sev);

/* ---- the HAL command language ---------------------------------------------------------- */

/* One command line (loadrt, net, setp, sets, getp, addf, newthread, start, stop, show,
 * source, unlinkp, ...); `[SECTION]KEY` is replaced from the INI first. file/lineno go
 * into error messages (file may be NULL). Output of show/getp goes to `out`. */
int hal_cmd(struct hal *h, const char *line, const char *file, int lineno, FILE *out);
/* Runs a HAL file: `#` comments, `\` continuation; stops at the first error, whose
 * message names the file and line. */
int hal_source(struct hal *h, const char *path);
/* Additions: hal_source with show/getp output to `out` (hal_source uses stdout). */
int hal_source_to(struct hal *h, const char *path, FILE *out);
/* A file name written in a HAL file (or a loadrt argument) is relative to that file's
 * folder: resolves `name` against the innermost file being sourced, else leaves it as is. */
int hal_path_resolve(const struct hal *h, const char *name, char *buf, size_t len);
/* After each `start` command: on the simulated clock advance run_ns; in real time sleep
 * run_ns (halcmd --run-ms). 0 (the default) returns at once. */
void hal_set_start_run(struct hal *h, int64_t run_ns);

/* ---- loadrt argument helpers for components (additions) ------------------------------ */

#define HAL_INST_NAME_MAX 64
/* VALUE of the KEY=VALUE argument, or NULL. */
const char *hal_arg(int argc, char **argv, const char *key);
/* Fails, naming the component and the argument, unless every argument is KEY=VALUE with KEY
 * in the comma-separated list `known` (e.g. "count,names"). */
int hal_args_check(struct hal *h, const char *comp, int argc, char **argv, const char *known);
/* Instance names from count=N (comp.0 .. comp.N-1, default 1) or names=a,b (a, b), at most
 * max of them. */
int hal_arg_instances(struct hal *h, const char *comp, int argc, char **argv, int max,
                      char (*names)[HAL_INST_NAME_MAX], int *count);

#endif
