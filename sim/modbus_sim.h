/* modbus_sim.h: simulated Modbus position drives (libmodbus servers on loopback or a pty) with fault injection. */
#ifndef HEXCNC_MODBUS_SIM_H
#define HEXCNC_MODBUS_SIM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "hal/drivers/modbus_drive.h"

/*
 * Each simulated drive is one server thread on its own TCP port (or one pseudo-terminal for
 * RTU), serving one client connection at a time with libmodbus's server API
 * (modbus_tcp_listen, modbus_receive, modbus_reply on a modbus_mapping_t). The holding
 * registers follow the same map as the client (struct modbus_regmap). Before each reply the
 * drive model runs: the actual position follows the target through a first-order lag
 * (time constant tau) with a velocity limit: on wall time (the model is brought up to the
 * present before every reply and every state read, whether or not a client stays connected,
 * so a client that connects per request sees the drive move), or a fixed step per read
 * request ("lockstep", the simulated clock) for deterministic runs.
 */

enum modbus_sim_status {
    MODBUS_SIM_OK = 0,
    MODBUS_SIM_ERR_ARG,         /* a bad count, index or option */
    MODBUS_SIM_ERR_NOMEM,       /* allocation failed */
    MODBUS_SIM_ERR_LISTEN,      /* the port could not be opened (in use?) */
    MODBUS_SIM_ERR_PTY,         /* no pseudo-terminal could be made */
    MODBUS_SIM_ERR_THREAD,      /* a server thread could not start */
    MODBUS_SIM_STATUS_COUNT
};
const char *modbus_sim_strerror(int status);

/* What a drive does wrong, set from tests or the command line. */
enum modbus_sim_fault {
    MODBUS_SIM_FAULT_NONE = 0,
    MODBUS_SIM_FAULT_NO_ANSWER,   /* read requests and never answer (until cleared) */
    MODBUS_SIM_FAULT_EXCEPTION,   /* answer every request with exception `arg` */
    MODBUS_SIM_FAULT_DELAY,       /* answer after `arg` us */
    MODBUS_SIM_FAULT_DISCONNECT,  /* close the connection at the next request (once) */
    MODBUS_SIM_FAULT_DRIVE,       /* set the status word's fault bit (until FAULT_RESET) */
};
/* Parses "none", "no-answer", "exception", "delay", "disconnect", "drive"; -1 if unknown. */
int modbus_sim_fault_parse(const char *name);

/* Drive model and register layout, the same for all drives of one simulator. */
struct modbus_sim_opts {
    struct modbus_regmap map;     /* register layout (default: modbus_regmap_default) */
    int nb_registers;             /* holding registers 0..nb-1 (default 64) */
    double tau_s;                 /* first-order lag time constant, s (default 0.002) */
    double vmax_counts_s;         /* velocity limit, counts/s (default 1e9) */
    long step_ns;                 /* > 0: lockstep, model time advances this much per read
                                   * request; 0: the model runs on wall time */
    long timeout_us;              /* lockstep: the client's TIMEOUT, us; > 0 makes an injected
                                   * delay simulated (answer at once, or none when later than
                                   * this); 0: a delay sleeps on the wall clock */
    int unit;                     /* RTU unit id (default 1); TCP answers any unit */
};
void modbus_sim_opts_default(struct modbus_sim_opts *o);

/* What a test can read back from one drive. */
struct modbus_sim_drive_state {
    int32_t target_counts;        /* last target written */
    double actual_counts;         /* model position, counts (not rounded) */
    uint16_t control_word;
    uint16_t status_word;
    uint32_t requests;            /* requests received (answered or not) */
    uint32_t connections;         /* connections accepted */
};

struct modbus_sim;

/* Creates `ndrives` drives, no server running yet. */
int modbus_sim_create(struct modbus_sim **out, int ndrives, const struct modbus_sim_opts *opts);
/* Starts TCP servers on 127.0.0.1 (or `host`): drive i on base_port + i; base_port 0 gives
 * every drive an ephemeral port (read it with modbus_sim_port). */
int modbus_sim_start_tcp(struct modbus_sim *s, const char *host, int base_port);
/* Starts drive i alone on host:port (0 = ephemeral). */
int modbus_sim_start_tcp_port(struct modbus_sim *s, int i, const char *host, int port);
/* Starts drive i as an RTU server on a new pseudo-terminal; `slave_path` receives the
 * device the client opens (e.g. /dev/pts/7). */
int modbus_sim_start_rtu_pty(struct modbus_sim *s, int i, char *slave_path, size_t len);
/* Stops every server thread and frees everything. */
void modbus_sim_destroy(struct modbus_sim *s);

int modbus_sim_count(const struct modbus_sim *s);
int modbus_sim_port(const struct modbus_sim *s, int i);
/* Sets drive i's fault (arg: exception code, or delay in us). */
int modbus_sim_inject(struct modbus_sim *s, int i, enum modbus_sim_fault fault, long arg);
int modbus_sim_state(struct modbus_sim *s, int i, struct modbus_sim_drive_state *st);
/* Moves drive i's model to `counts` (target and actual), e.g. a homed start position. */
int modbus_sim_set_position(struct modbus_sim *s, int i, int32_t counts);

/* ---- the drive model alone (pure, for tests) -------------------------------------------- */

struct modbus_sim_model {
    double actual_counts;         /* position, counts */
    int32_t target_counts;        /* set point, counts */
    bool enabled;                 /* control word ENABLE seen */
    bool fault;                   /* latched drive fault */
};
/* Advances the model by dt_s toward its target (nothing while disabled or faulted). */
void modbus_sim_model_step(struct modbus_sim_model *m, const struct modbus_sim_opts *o, double dt_s);
/* Status word of the model (MODBUS_STAT_* bits). */
uint16_t modbus_sim_model_status(const struct modbus_sim_model *m);

#endif
