/* session_priv.h: the session's state, shared by session*.c. */
#ifndef HEXCNC_TASK_SESSION_PRIV_H
#define HEXCNC_TASK_SESSION_PRIV_H

#include <jansson.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include "interp/tooltable.h"
#include "task/runner_priv.h"
#include "task/session.h"

enum session_state { SESS_ESTOP, SESS_OFF, SESS_ON };
enum session_mode { SESS_MANUAL, SESS_AUTO, SESS_MDI };

/* JSON-RPC error codes (docs/api.md). */
enum {
    RPC_PARSE = -32700, RPC_INVALID = -32600, RPC_NO_METHOD = -32601, RPC_PARAMS = -32602,
    RPC_STATE = -32001, RPC_CONTROL = -32002, RPC_PROGRAM = -32003, RPC_NOT_FOUND = -32004,
    RPC_FAILED = -32005,
};

#define SESSION_MAX_CLIENTS 32
/* Periods the e-stop chain gets to close after machine.power {on: true}, and the servo
 * thread to take what the task queued. */
#define SESSION_POWER_PERIODS 20
/* Servo periods the drives have to report ready after the e-stop chain closed. */
#define SESSION_ENABLE_PERIODS 2000

struct session_client {
    int fd;
    unsigned id;                 /* for control and messages */
    char *in;                    /* bytes read, not yet a whole line */
    size_t inlen, incap;
    char *out;                   /* bytes to write */
    size_t outlen, outcap;
    double status_rate_hz;       /* status notifications (0: none) */
    int64_t next_status_ns;
    bool messages;               /* message notifications */
    bool closing;                /* close once out is written */
};

struct session {
    struct runner *r;
    struct hal *hal;
    struct motion *m;
    struct kins *k;
    int nj;
    bool sim;
    long period_ns;
    int quiet;
    enum session_state state;
    enum session_mode mode;
    bool running;                /* a program or MDI line is under way */
    bool run_is_mdi;
    int mdi_probe;               /* the running MDI line's G38 probe type (0..3), else -1 */
    bool stopping;               /* program.abort asked */
    char program[1024];          /* open program ("" when none) */
    long program_lines;
    char last_error[800];
    bool no_force_homing;
    bool shutdown;
    /* MDI: one interpreter for the session, so modal state carries from line to line */
    struct interp *mdi;
    struct tooltable mdi_tt;
    /* overrides and switches */
    double feed_ovr, rapid_ovr, spindle_ovr;
    bool optional_stop, block_delete;
    double *feed_ovr_pin;        /* motion.feed-override (NULL when wired by the HAL files) */
    double *spindle_ovr_pin;     /* spindle.0.override (likewise) */
    unsigned note_seq;           /* last manual-motion note reported */
    int last_mstate;             /* motion state at the last tick */
    /* the socket */
    char sock_path[512];
    int lfd;
    struct session_client *cl[SESSION_MAX_CLIENTS];
    unsigned next_id;
    unsigned holder;             /* client id holding control, 0: none */
    unsigned jogger;             /* client id whose continuous jog is the last one started,
                                  * 0: none (it stops when that client disconnects) */
    /* program.check runs on its own thread, so that a long file stalls nobody; its answer
     * goes to the client that asked when it ends (session_check_poll) */
    pthread_t check_thread;
    bool checking;
    _Atomic int check_done;
    volatile sig_atomic_t check_cancel;
    unsigned check_client;       /* who asked */
    bool check_then_run;         /* program.run asked: run from check_from_line if it passes */
    bool check_then_step;        /* program.step asked: then one block */
    int check_from_line;
    json_t *check_id;            /* their request's id (NULL: a notification) */
    int check_status;
    char check_err[800];
    struct motion_plan_info check_info;
};

/* A method's answer comes later (session_dispatch keeps the request's id). */
#define RPC_DEFERRED 1

/* session.c: commands (each returns 0 or an RPC error code with the message in err). */
int session_estop(struct session *s, bool active, char *err, size_t len);
int session_power(struct session *s, bool on, char *err, size_t len);
int session_home(struct session *s, int joint, char *err, size_t len);
int session_unhome(struct session *s, int joint, char *err, size_t len);
int session_set_mode(struct session *s, enum session_mode mode, char *err, size_t len);
int session_jog(struct session *s, int frame, int axis, double vel, double dist, char *err,
                size_t len);
int session_jog_stop(struct session *s, char *err, size_t len);
int session_tool_changed(struct session *s, char *err, size_t len);
/* tooltable.set: what to change in one tool's entry. */
struct session_tool_edit {
    int tool;
    int pocket;                  /* -1: keep (a new tool: its number) */
    bool has_length, has_diameter, has_wear;
    double length, diameter;     /* mm */
    double wear;                 /* diameter wear, mm (negative as the tool wears down) */
    const char *comment;         /* NULL: keep */
};
int session_tooltable_set(struct session *s, const struct session_tool_edit *e, char *err,
                          size_t len);
int session_mdi(struct session *s, const char *line, char *err, size_t len);
int session_open(struct session *s, const char *path, char *err, size_t len);
int session_check(struct session *s, json_t **result, char *err, size_t len);
/* The end of a program.check: its answer to the client that asked (session_tick). */
void session_check_poll(struct session *s, bool wait);
int session_run_program(struct session *s, int from_line, char *err, size_t len);
int session_pause(struct session *s, char *err, size_t len);
int session_resume(struct session *s, char *err, size_t len);
int session_step(struct session *s, char *err, size_t len);
int session_abort(struct session *s, char *err, size_t len);
int session_overrides(struct session *s, const double *feed, const double *rapid,
                      const double *spindle, char *err, size_t len);
/* One tick: machine state, program end, messages. */
void session_tick(struct session *s);
/* Whether anything moves or waits (the simulated clock then runs flat out). */
bool session_busy(const struct session *s);
/* Posts a message to subscribers (and stderr unless quiet). sev: info, warning, error. */
/* After an MDI line with a G38 probe move (session_prog.c): the machine's answer into the
 * MDI interpreter's #5061..#5066 and #5070, or the error of a probe that found nothing. */
void session_mdi_probe_done(struct session *s);
void session_message(struct session *s, const char *sev, const char *source,
                     const char *fmt, ...) __attribute__((format(printf, 4, 5)));

/* session_status.c */
json_t *session_status(struct session *s);
const char *session_state_name(enum session_state st);
const char *session_mode_name(enum session_mode md);

/* session_api.c: one request line in, the response (or NULL for a notification). */
json_t *session_dispatch(struct session *s, struct session_client *c, const char *line,
                         size_t len);

/* session_server.c */
int session_server_open(struct session *s, const char *path, char *err, size_t len);
void session_server_close(struct session *s);
/* Serves the socket for at most timeout_ms. */
void session_server_poll(struct session *s, int timeout_ms);
void session_server_send(struct session *s, struct session_client *c, json_t *msg);
/* Sends to every client subscribed to messages / due for a status. */
void session_server_broadcast_message(struct session *s, json_t *msg);
void session_server_status(struct session *s);

/* The state checks and the hand-over to the servo thread the commands share (session.c).
 * session_need_*: 0, or the refusal (RPC_STATE) in err naming `what` and what to do. */
struct motion_hal_cmd;
void session_wait_periods(struct session *s, int n);
enum motion_state session_mstate(const struct session *s);
bool session_at_rest(const struct session *s);
int session_need_homed(struct session *s, const char *what, char *err, size_t len);
int session_need_on(struct session *s, const char *what, char *err, size_t len);
int session_need_idle(struct session *s, const char *what, char *err, size_t len);
/* Waits until the servo thread has taken what was queued (a start, an abort, a command). */
void session_settle(struct session *s);
int session_push(struct session *s, const struct motion_hal_cmd *c, char *err, size_t len);
/* The machine went off under a program or MDI line: the run ends, saying why. */
void session_run_cut(struct session *s, const char *why);

#endif
