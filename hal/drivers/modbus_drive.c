/* modbus_drive.c: one Modbus drive: word packing, request planning, the cyclic exchange, error texts. */
#include "hal/drivers/modbus_drive.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include <modbus.h>

static const char *const modbus_drive_status_text[MODBUS_DRIVE_STATUS_COUNT] = {
    [MODBUS_DRIVE_OK] = "ok",
    [MODBUS_DRIVE_ERR_CONFIG] = "bad Modbus drive configuration",
    [MODBUS_DRIVE_ERR_CONNECT] = "drive cannot be reached",
    [MODBUS_DRIVE_ERR_TIMEOUT] = "no answer from the drive in time",
    [MODBUS_DRIVE_ERR_EXCEPTION] = "drive answered with a Modbus exception",
    [MODBUS_DRIVE_ERR_CLOSED] = "connection to the drive closed",
    [MODBUS_DRIVE_ERR_PROTOCOL] = "malformed answer from the drive",
    [MODBUS_DRIVE_ERR_RANGE] = "position beyond the drive's count range",
    [MODBUS_DRIVE_ERR_FAULT] = "drive reports a fault",
    [MODBUS_DRIVE_ERR_NOMEM] = "out of memory",
    [MODBUS_DRIVE_ERR_THREAD] = "drive I/O thread could not start",
};

/* Text of a modbus_drive_status value. */
const char *modbus_drive_strerror(int status)
{
    if (status < 0 || status >= MODBUS_DRIVE_STATUS_COUNT || !modbus_drive_status_text[status])
        return "unknown Modbus drive status";
    return modbus_drive_status_text[status];
}

/* Exception names from the Modbus application protocol specification V1.1b3, section 7. */
const char *modbus_exception_text(int code)
{
    switch (code) {
    case 1: return "illegal function";
    case 2: return "illegal data address";
    case 3: return "illegal data value";
    case 4: return "server device failure";
    case 5: return "acknowledge";
    case 6: return "server device busy";
    case 8: return "memory parity error";
    case 10: return "gateway path unavailable";
    case 11: return "gateway target device failed to respond";
    default: return "unknown exception";
    }
}

/* The default register map (documented in docs/modbus.md). */
void modbus_regmap_default(struct modbus_regmap *m)
{
    m->control = 0;
    m->target = 1;
    m->status = 10;
    m->actual = 11;
    m->order = MODBUS_WORDS_HIGH_FIRST;
}

/* Defaults for drive `index`; the INI overrides them key by key. */
void modbus_drive_cfg_default(struct modbus_drive_cfg *c, int index)
{
    memset(c, 0, sizeof(*c));
    c->index = index;
    c->transport = MODBUS_DRIVE_TCP;
    snprintf(c->host, sizeof(c->host), "127.0.0.1");
    c->port = 502;
    c->baud = 115200;
    c->parity = 'N';
    c->data_bits = 8;
    c->stop_bits = 1;
    c->unit = 1;
    modbus_regmap_default(&c->map);
    c->counts_per_mm = 1000.0;
    c->period_ns = 1000000;
    c->timeout_us = 20000;
    c->exchange = MODBUS_EXCHANGE_FC23;
}

/* The drive's address as people write it. */
void modbus_drive_cfg_where(const struct modbus_drive_cfg *c, char *buf, size_t len)
{
    if (c->transport == MODBUS_DRIVE_TCP)
        snprintf(buf, len, "%s:%d", c->host, c->port);
    else
        snprintf(buf, len, "%s@%d,%d%c%d", c->device, c->baud, c->data_bits, c->parity,
                 c->stop_bits);
}

/* Splits a 32-bit value into two registers in the drive's word order. */
void modbus_words_pack(int32_t value, enum modbus_word_order order, uint16_t regs[2])
{
    uint32_t u = (uint32_t)value;
    uint16_t hi = (uint16_t)(u >> 16), lo = (uint16_t)(u & 0xffffu);
    regs[0] = order == MODBUS_WORDS_HIGH_FIRST ? hi : lo;
    regs[1] = order == MODBUS_WORDS_HIGH_FIRST ? lo : hi;
}

/* Joins two registers into a 32-bit value in the drive's word order. */
int32_t modbus_words_unpack(const uint16_t regs[2], enum modbus_word_order order)
{
    uint32_t hi = order == MODBUS_WORDS_HIGH_FIRST ? regs[0] : regs[1];
    uint32_t lo = order == MODBUS_WORDS_HIGH_FIRST ? regs[1] : regs[0];
    return (int32_t)((hi << 16) | lo);
}

/* mm to drive counts, rounded to nearest; out of int32 range is an error, not a wrap. */
int modbus_mm_to_counts(double pos_mm, double counts_per_mm, int32_t *counts)
{
    double c = nearbyint(pos_mm * counts_per_mm);
    if (!(c >= (double)INT32_MIN)) {      /* also catches NaN */
        *counts = isnan(c) ? 0 : INT32_MIN;
        return MODBUS_DRIVE_ERR_RANGE;
    }
    if (c > (double)INT32_MAX) {
        *counts = INT32_MAX;
        return MODBUS_DRIVE_ERR_RANGE;
    }
    *counts = (int32_t)c;
    return MODBUS_DRIVE_OK;
}

/* Drive counts to mm. */
double modbus_counts_to_mm(int32_t counts, double counts_per_mm)
{
    return (double)counts / counts_per_mm;
}

/* Formats d->msg as "modbus drive N (where): ..." and returns `status`. */
__attribute__((format(printf, 3, 4)))
static int modbus_drive_fail(struct modbus_drive *d, int status, const char *fmt, ...)
{
    char cause[192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cause, sizeof(cause), fmt, ap);
    va_end(ap);
    snprintf(d->msg, sizeof(d->msg), "modbus drive %d (%s): %s", d->cfg.index, d->where, cause);
    return status;
}

/* Plans the requests from the register map; rejects overlapping or too-wide layouts. */
static int modbus_drive_plan(struct modbus_drive *d)
{
    const struct modbus_regmap *m = &d->cfg.map;
    struct modbus_plan *p = &d->plan;
    if (m->control < 0 || m->target < 0 || m->status < 0 || m->actual < 0 ||
        m->control > 65535 || m->target > 65534 || m->status > 65535 || m->actual > 65534)
        return modbus_drive_fail(d, MODBUS_DRIVE_ERR_CONFIG,
                                 "register addresses must lie in 0..65535");
    if (m->control == m->target || m->control == m->target + 1)
        return modbus_drive_fail(d, MODBUS_DRIVE_ERR_CONFIG,
                                 "control word register %d overlaps target position %d..%d",
                                 m->control, m->target, m->target + 1);
    if (m->status == m->actual || m->status == m->actual + 1)
        return modbus_drive_fail(d, MODBUS_DRIVE_ERR_CONFIG,
                                 "status word register %d overlaps actual position %d..%d",
                                 m->status, m->actual, m->actual + 1);
    p->write_split = !(m->target == m->control + 1 || m->control == m->target + 2);
    p->write_addr = m->control < m->target ? m->control : m->target;
    p->write_nb = 3;
    int lo = m->status < m->actual ? m->status : m->actual;
    int hi = m->status > m->actual + 1 ? m->status : m->actual + 1;
    p->read_addr = lo;
    p->read_nb = hi - lo + 1;
    if (p->read_nb > MODBUS_MAX_WR_READ_REGISTERS)
        return modbus_drive_fail(d, MODBUS_DRIVE_ERR_CONFIG,
                                 "status word (%d) and actual position (%d) are more than %d "
                                 "registers apart", m->status, m->actual,
                                 MODBUS_MAX_WR_READ_REGISTERS);
    if (p->write_split && d->cfg.exchange == MODBUS_EXCHANGE_FC23)
        return modbus_drive_fail(d, MODBUS_DRIVE_ERR_CONFIG,
                                 "EXCHANGE = fc23 needs the control word (%d) right before or "
                                 "after the target position (%d); use EXCHANGE = separate",
                                 m->control, m->target);
    return MODBUS_DRIVE_OK;
}

/* Checks the values a drive needs before any I/O. */
static int modbus_drive_check_cfg(struct modbus_drive *d)
{
    const struct modbus_drive_cfg *c = &d->cfg;
    if (!(c->counts_per_mm != 0.0) || !isfinite(c->counts_per_mm))
        return modbus_drive_fail(d, MODBUS_DRIVE_ERR_CONFIG, "COUNTS_PER_MM must be non-zero");
    if (c->period_ns <= 0)
        return modbus_drive_fail(d, MODBUS_DRIVE_ERR_CONFIG, "the set-point period must be > 0");
    if (c->timeout_us <= 0)
        return modbus_drive_fail(d, MODBUS_DRIVE_ERR_CONFIG, "the response timeout must be > 0");
    if (c->unit < 0 || c->unit > 255)
        return modbus_drive_fail(d, MODBUS_DRIVE_ERR_CONFIG, "unit id %d is not in 0..255",
                                 c->unit);
    if (c->transport == MODBUS_DRIVE_TCP && (c->port <= 0 || c->port > 65535))
        return modbus_drive_fail(d, MODBUS_DRIVE_ERR_CONFIG, "port %d is not in 1..65535",
                                 c->port);
    if (c->transport == MODBUS_DRIVE_RTU && (!c->device[0] || c->baud <= 0 ||
        !strchr("NEO", c->parity) || c->data_bits < 5 || c->data_bits > 8 ||
        (c->stop_bits != 1 && c->stop_bits != 2)))
        return modbus_drive_fail(d, MODBUS_DRIVE_ERR_CONFIG,
                                 "serial settings need a device, a baud rate, parity N/E/O, "
                                 "5..8 data bits and 1 or 2 stop bits");
    return modbus_drive_plan(d);
}

/* Checks the config and creates the libmodbus context for TCP or RTU. */
int modbus_drive_open(struct modbus_drive *d, const struct modbus_drive_cfg *cfg)
{
    memset(d, 0, sizeof(*d));
    d->cfg = *cfg;
    modbus_drive_cfg_where(cfg, d->where, sizeof(d->where));
    int rc = modbus_drive_check_cfg(d);
    if (rc)
        return rc;
    if (cfg->transport == MODBUS_DRIVE_TCP)
        d->ctx = modbus_new_tcp(cfg->host, cfg->port);
    else
        d->ctx = modbus_new_rtu(cfg->device, cfg->baud, cfg->parity, cfg->data_bits,
                                cfg->stop_bits);
    if (!d->ctx)
        return modbus_drive_fail(d, MODBUS_DRIVE_ERR_CONFIG, "cannot set up the connection: %s",
                                 modbus_strerror(errno));
    long wait_us = cfg->wait_us > 0 ? cfg->wait_us : cfg->timeout_us;
    uint32_t sec = (uint32_t)(wait_us / 1000000), usec = (uint32_t)(wait_us % 1000000);
    if (modbus_set_slave(d->ctx, cfg->unit) || modbus_set_response_timeout(d->ctx, sec, usec) ||
        modbus_set_byte_timeout(d->ctx, sec, usec) ||
        modbus_set_error_recovery(d->ctx, MODBUS_ERROR_RECOVERY_NONE)) {
        rc = modbus_drive_fail(d, MODBUS_DRIVE_ERR_CONFIG, "cannot apply unit id %d / timeout: %s",
                               cfg->unit, modbus_strerror(errno));
        modbus_drive_close(d);
        return rc;
    }
    return MODBUS_DRIVE_OK;
}

/* Opens the socket or serial line. */
int modbus_drive_connect(struct modbus_drive *d)
{
    if (!d->ctx)
        return modbus_drive_fail(d, MODBUS_DRIVE_ERR_CONFIG, "not configured");
    if (d->connected)
        return MODBUS_DRIVE_OK;
    if (modbus_connect(d->ctx) == -1)
        return modbus_drive_fail(d, MODBUS_DRIVE_ERR_CONNECT, "cannot connect: %s",
                                 modbus_strerror(errno));
    d->connected = true;
    return MODBUS_DRIVE_OK;
}

/* Closes the socket or serial line; the context stays for the next connect. */
void modbus_drive_disconnect(struct modbus_drive *d)
{
    if (d->ctx && d->connected)
        modbus_close(d->ctx);
    d->connected = false;
}

/* Releases everything. */
void modbus_drive_close(struct modbus_drive *d)
{
    modbus_drive_disconnect(d);
    if (d->ctx)
        modbus_free(d->ctx);
    d->ctx = NULL;
}

/* Turns a failed libmodbus call (errno) into a status and a message; drops the connection. */
static int modbus_drive_io_error(struct modbus_drive *d, int err)
{
    const struct modbus_plan *p = &d->plan;
    int rc;
    if (err == ETIMEDOUT) {
        long t = d->cfg.timeout_us;
        rc = t % 1000 ? modbus_drive_fail(d, MODBUS_DRIVE_ERR_TIMEOUT, "no answer within %ld us", t)
                      : modbus_drive_fail(d, MODBUS_DRIVE_ERR_TIMEOUT, "no answer within %ld ms",
                                          t / 1000);
    } else if (err >= EMBXILFUN && err <= EMBXGTAR) {
        d->last_exception = err - MODBUS_ENOBASE;
        rc = modbus_drive_fail(d, MODBUS_DRIVE_ERR_EXCEPTION,
                               "exception %d %s at register %d (write %d..%d, read %d..%d)",
                               d->last_exception, modbus_exception_text(d->last_exception),
                               p->write_addr, p->write_addr, p->write_addr + p->write_nb - 1,
                               p->read_addr, p->read_addr + p->read_nb - 1);
    } else if (err == ECONNRESET || err == EPIPE || err == ENOTCONN || err == EBADF ||
               err == ECONNREFUSED || err == ECONNABORTED) {
        rc = modbus_drive_fail(d, MODBUS_DRIVE_ERR_CLOSED, "connection closed (%s)",
                               modbus_strerror(err));
    } else {
        rc = modbus_drive_fail(d, MODBUS_DRIVE_ERR_PROTOCOL, "bad answer: %s",
                               modbus_strerror(err));
    }
    modbus_drive_disconnect(d);
    return rc;
}

/* Writes target and control word: one FC16 when adjacent, else FC16 + FC6. */
static int modbus_drive_write(struct modbus_drive *d, const uint16_t wr[3])
{
    const struct modbus_regmap *m = &d->cfg.map;
    if (!d->plan.write_split) {
        d->requests++;
        return modbus_write_registers(d->ctx, d->plan.write_addr, 3, wr) == -1 ? -1 : 0;
    }
    uint16_t tgt[2] = { wr[1], wr[2] };
    d->requests++;
    if (modbus_write_registers(d->ctx, m->target, 2, tgt) == -1)
        return -1;
    d->requests++;
    return modbus_write_register(d->ctx, m->control, wr[0]) == -1 ? -1 : 0;
}

/* Checks a read's result (rc: registers read or -1) and unpacks actual and status. */
static int modbus_drive_unpack(struct modbus_drive *d, int rc, const uint16_t *rd,
                               int32_t *actual_counts, uint16_t *status_word)
{
    const struct modbus_regmap *m = &d->cfg.map;
    if (rc == -1)
        return modbus_drive_io_error(d, errno);
    if (rc != d->plan.read_nb)
        return modbus_drive_io_error(d, EMBBADDATA);
    *actual_counts = modbus_words_unpack(&rd[m->actual - d->plan.read_addr], m->order);
    *status_word = rd[m->status - d->plan.read_addr];
    return MODBUS_DRIVE_OK;
}

/* One cycle: the write and read as planned, then unpack actual position and status word. */
int modbus_drive_exchange(struct modbus_drive *d, int32_t target_counts, uint16_t control,
                          int32_t *actual_counts, uint16_t *status_word)
{
    const struct modbus_regmap *m = &d->cfg.map;
    const struct modbus_plan *p = &d->plan;
    if (!d->ctx || !d->connected)
        return modbus_drive_fail(d, MODBUS_DRIVE_ERR_CLOSED, "connection closed");
    /* wr[] in register order of the write block when contiguous; [0]=control,[1..2]=target
     * otherwise (modbus_drive_write then splits). */
    uint16_t wr[3], pos[2], rd[MODBUS_MAX_WR_READ_REGISTERS];
    modbus_words_pack(target_counts, m->order, pos);
    if (p->write_split || m->control < m->target) {
        wr[0] = control; wr[1] = pos[0]; wr[2] = pos[1];
    } else {
        wr[0] = pos[0]; wr[1] = pos[1]; wr[2] = control;
    }
    int rc;
    if (d->cfg.exchange == MODBUS_EXCHANGE_FC23) {
        d->requests++;
        rc = modbus_write_and_read_registers(d->ctx, p->write_addr, 3, wr, p->read_addr,
                                             p->read_nb, rd);
    } else {
        rc = modbus_drive_write(d, wr);
        if (rc != -1) {
            d->requests++;
            rc = modbus_read_registers(d->ctx, p->read_addr, p->read_nb, rd);
        }
    }
    return modbus_drive_unpack(d, rc, rd, actual_counts, status_word);
}

/* Reads status and actual position alone (see modbus_drive.h). */
int modbus_drive_read(struct modbus_drive *d, int32_t *actual_counts, uint16_t *status_word)
{
    uint16_t rd[MODBUS_MAX_WR_READ_REGISTERS];
    if (!d->ctx || !d->connected)
        return modbus_drive_fail(d, MODBUS_DRIVE_ERR_CLOSED, "connection closed");
    d->requests++;
    int rc = modbus_read_registers(d->ctx, d->plan.read_addr, d->plan.read_nb, rd);
    return modbus_drive_unpack(d, rc, rd, actual_counts, status_word);
}

/* The last error message. */
const char *modbus_drive_message(const struct modbus_drive *d)
{
    return d->msg;
}
