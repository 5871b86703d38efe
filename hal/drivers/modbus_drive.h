/* modbus_drive.h: one position drive over Modbus TCP or RTU (libmodbus): config, word packing, exchange. */
#ifndef HEXCNC_MODBUS_DRIVE_H
#define HEXCNC_MODBUS_DRIVE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/*
 * The pure core of the Modbus drive component: no HAL, no threads. A `struct modbus_drive`
 * owns one libmodbus connection to one drive and does one cyclic exchange per call:
 * write the target position (32 bits, two holding registers) and the control word, read the
 * actual position (32 bits) and the status word. The I/O thread and mailbox are in
 * modbus_link.h; the INI reader in modbus_cfg.h; the HAL shell in modbus_hal.c.
 */

enum modbus_drive_status {
    MODBUS_DRIVE_OK = 0,
    MODBUS_DRIVE_ERR_CONFIG,      /* a bad configuration value; the message names the key */
    MODBUS_DRIVE_ERR_CONNECT,     /* the drive could not be reached (refused, no device) */
    MODBUS_DRIVE_ERR_TIMEOUT,     /* no answer within the response timeout */
    MODBUS_DRIVE_ERR_EXCEPTION,   /* the drive answered with a Modbus exception */
    MODBUS_DRIVE_ERR_CLOSED,      /* the connection was closed or reset by the drive */
    MODBUS_DRIVE_ERR_PROTOCOL,    /* a malformed or mismatched answer (CRC, length, id) */
    MODBUS_DRIVE_ERR_RANGE,       /* a position beyond the drive's 32-bit count range */
    MODBUS_DRIVE_ERR_FAULT,       /* the drive's status word reports a fault */
    MODBUS_DRIVE_ERR_NOMEM,       /* allocation failed */
    MODBUS_DRIVE_ERR_THREAD,      /* the I/O thread could not be started */
    MODBUS_DRIVE_STATUS_COUNT
};
const char *modbus_drive_strerror(int status);

enum modbus_transport { MODBUS_DRIVE_TCP = 0, MODBUS_DRIVE_RTU };

/* Order of the two 16-bit registers holding a 32-bit value. */
enum modbus_word_order {
    MODBUS_WORDS_HIGH_FIRST = 0,  /* register n = bits 31..16, n+1 = bits 15..0 (big-endian) */
    MODBUS_WORDS_LOW_FIRST        /* register n = bits 15..0, n+1 = bits 31..16 */
};

/* How one cycle talks to the drive. */
enum modbus_exchange {
    MODBUS_EXCHANGE_FC23 = 0,     /* one write-and-read request (function 23): one round trip */
    MODBUS_EXCHANGE_SEPARATE      /* write (FC16/FC6) then read (FC3): two or more round trips */
};

/* Control word bits written by the client (a small subset in the spirit of CiA 402). */
#define MODBUS_CTRL_ENABLE       0x0001u  /* power stage on, follow the target */
#define MODBUS_CTRL_FAULT_RESET  0x0080u  /* clear a latched drive fault */
/* Status word bits read from the drive. */
#define MODBUS_STAT_READY        0x0001u  /* ready to be enabled */
#define MODBUS_STAT_ENABLED      0x0002u  /* following the target */
#define MODBUS_STAT_FAULT        0x0008u  /* the drive has a fault latched */
#define MODBUS_STAT_AT_TARGET    0x0400u  /* actual position within one count of the target */

/* Holding-register addresses (0-based protocol addresses) and 32-bit word order. */
struct modbus_regmap {
    int control;                  /* control word, 1 register */
    int target;                   /* target position, counts, 2 registers */
    int status;                   /* status word, 1 register */
    int actual;                   /* actual position, counts, 2 registers */
    enum modbus_word_order order; /* order of the two registers of a 32-bit value */
};
/* The default map: control 0, target 1..2, status 10, actual 11..12, high word first. */
void modbus_regmap_default(struct modbus_regmap *m);

/* One drive's configuration (filled from the INI by modbus_cfg_read, or by tests). */
struct modbus_drive_cfg {
    int index;                    /* drive number, as in the pin names modbus.N.* */
    enum modbus_transport transport;
    char host[64];                /* TCP: IPv4 address of the drive */
    int port;                     /* TCP: port */
    char device[64];              /* RTU: serial device, e.g. /dev/ttyUSB0 */
    int baud;                     /* RTU: bits per second */
    char parity;                  /* RTU: 'N', 'E' or 'O' */
    int data_bits;                /* RTU: 7 or 8 */
    int stop_bits;                /* RTU: 1 or 2 */
    int unit;                     /* Modbus unit (slave) id, 1..247 (TCP: usually 1 or 255) */
    struct modbus_regmap map;     /* where the values live */
    double counts_per_mm;         /* drive counts per mm of leg travel (sign sets direction) */
    long period_ns;               /* set-point period: one exchange per period */
    long timeout_us;              /* response timeout, us (TIMEOUT) */
    long wait_us;                 /* wall time to wait for an answer, us; 0 = timeout_us.
                                   * Simulated clock: MODBUS_DRIVE_INLINE_WAIT_US, because an
                                   * exchange takes no simulated time (see below) */
    enum modbus_exchange exchange;
};
/* With the simulated clock (exchanges inline in modbus.update) an answer takes no simulated
 * time however long the computer takes to produce it: an answer that comes at all comes
 * within TIMEOUT. Wall time is then only a guard against a drive that never answers, long
 * enough that no load on the computer reaches it (the simulated drives model delays in
 * simulated time, see modbus_sim_opts.timeout_us). */
#define MODBUS_DRIVE_INLINE_WAIT_US 2000000L
/* Defaults: TCP 127.0.0.1:502 unit 1, default map, 1000 counts/mm, 1 ms, 20 ms, FC23. */
void modbus_drive_cfg_default(struct modbus_drive_cfg *c, int index);
/* "127.0.0.1:5023" or "/dev/ttyUSB0@115200,8N1": the address as messages show it. */
void modbus_drive_cfg_where(const struct modbus_drive_cfg *c, char *buf, size_t len);

/* ---- 32-bit values in two registers (libmodbus's float helpers are not used) ------------ */

void modbus_words_pack(int32_t value, enum modbus_word_order order, uint16_t regs[2]);
int32_t modbus_words_unpack(const uint16_t regs[2], enum modbus_word_order order);
/* mm -> counts, rounded; MODBUS_DRIVE_ERR_RANGE when beyond int32 (counts then clamped). */
int modbus_mm_to_counts(double pos_mm, double counts_per_mm, int32_t *counts);
double modbus_counts_to_mm(int32_t counts, double counts_per_mm);

/* ---- the connection --------------------------------------------------------------------- */

struct _modbus;

/* The request layout planned from the register map at open time. */
struct modbus_plan {
    int write_addr, write_nb;     /* control + target when contiguous (3 registers) */
    bool write_split;             /* control and target not adjacent: two writes */
    int read_addr, read_nb;       /* one read covering status and actual */
};

struct modbus_drive {
    struct modbus_drive_cfg cfg;  /* copy of the configuration */
    struct _modbus *ctx;          /* libmodbus context, NULL until opened */
    bool connected;               /* modbus_connect succeeded and no error since */
    struct modbus_plan plan;      /* request layout */
    char where[96];               /* address for messages */
    char msg[320];                /* the last error, "modbus drive N (where): cause" */
    int last_exception;           /* Modbus exception code of the last exception, else 0 */
    uint32_t requests;            /* Modbus requests sent (round trips attempted) */
};

/* Checks the config and prepares the libmodbus context (no connection yet). */
int modbus_drive_open(struct modbus_drive *d, const struct modbus_drive_cfg *cfg);
/* Connects (TCP connect or serial open); on failure the message says why. */
int modbus_drive_connect(struct modbus_drive *d);
/* Closes the connection (kept openable: connect again to retry). */
void modbus_drive_disconnect(struct modbus_drive *d);
/* Frees the context. Safe on a zeroed or failed drive. */
void modbus_drive_close(struct modbus_drive *d);

/* One cycle: write target (counts) and control word, read actual (counts) and status word.
 * Not connected: returns MODBUS_DRIVE_ERR_CLOSED without trying. On any error the
 * connection is closed (a later connect starts clean) and d->msg names drive and cause. */
int modbus_drive_exchange(struct modbus_drive *d, int32_t target_counts, uint16_t control,
                          int32_t *actual_counts, uint16_t *status_word);
/* Reads actual position and status word only (FC3), writing nothing: what a drive reports
 * before the controller has a command for it. Errors as modbus_drive_exchange. */
int modbus_drive_read(struct modbus_drive *d, int32_t *actual_counts, uint16_t *status_word);
/* The last error message ("modbus drive 3 (127.0.0.1:5023): no answer within 20 ms"). */
const char *modbus_drive_message(const struct modbus_drive *d);
/* Text of a Modbus exception code ("illegal data address"). */
const char *modbus_exception_text(int code);

#endif
