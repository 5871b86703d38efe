/* canopen.h: CiA 301 (CANopen application layer) frame encoding for a minimal master. */
#ifndef HEXCNC_CANOPEN_H
#define HEXCNC_CANOPEN_H

#include <linux/can.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/*
 * Only what a CSP master needs: NMT, SYNC, expedited SDO, PDO payloads, heartbeat and EMCY.
 * Every function here is pure (frames in, values out), so the master and the simulated node
 * share one encoding and the tests can check it byte by byte.
 *
 * The pre-defined connection set of CiA 301 (n = node-ID 1..127):
 *   0x000 NMT, 0x080 SYNC, 0x080+n EMCY, 0x180+n TPDO1, 0x200+n RPDO1,
 *   0x580+n SDO server -> client, 0x600+n SDO client -> server, 0x700+n NMT error control.
 */
#define CANOPEN_COB_NMT       0x000u
#define CANOPEN_COB_SYNC      0x080u
#define CANOPEN_COB_EMCY      0x080u  /* + node-ID */
#define CANOPEN_COB_TPDO1     0x180u  /* + node-ID */
#define CANOPEN_COB_RPDO1     0x200u  /* + node-ID */
#define CANOPEN_COB_SDO_TX    0x580u  /* + node-ID: the node's answers */
#define CANOPEN_COB_SDO_RX    0x600u  /* + node-ID: requests to the node */
#define CANOPEN_COB_HEARTBEAT 0x700u  /* + node-ID */
#define CANOPEN_FUNC_MASK     0x780u  /* function code bits of an 11-bit COB-ID */
#define CANOPEN_NODE_MASK     0x07Fu  /* node-ID bits */
#define CANOPEN_NODE_MAX      127

/* NMT command specifiers (CiA 301, NMT node control): byte 0 of a COB-ID 0 frame. */
enum canopen_nmt_cmd {
    CANOPEN_NMT_START = 0x01,          /* start remote node: -> Operational */
    CANOPEN_NMT_STOP = 0x02,           /* -> Stopped */
    CANOPEN_NMT_PREOP = 0x80,          /* -> Pre-operational */
    CANOPEN_NMT_RESET_NODE = 0x81,     /* reset application */
    CANOPEN_NMT_RESET_COMM = 0x82,     /* reset communication: boot-up follows */
};

/* NMT states as a heartbeat carries them (CiA 301, NMT error control: heartbeat). */
enum canopen_nmt_state {
    CANOPEN_STATE_BOOTUP = 0x00,
    CANOPEN_STATE_STOPPED = 0x04,
    CANOPEN_STATE_OPERATIONAL = 0x05,
    CANOPEN_STATE_PREOP = 0x7F,
};

/* Object dictionary indices used by the CSP master (CiA 301 and CiA 402). */
#define CANOPEN_OD_HEARTBEAT_PRODUCER 0x1017u  /* u16, ms */
#define CANOPEN_OD_RPDO1_COMM         0x1400u  /* sub 1 COB-ID u32, sub 2 transmission type u8 */
#define CANOPEN_OD_RPDO1_MAP          0x1600u  /* sub 0 count u8, sub 1.. entries u32 */
#define CANOPEN_OD_TPDO1_COMM         0x1800u
#define CANOPEN_OD_TPDO1_MAP          0x1A00u
#define CANOPEN_PDO_COBID_INVALID     0x80000000u  /* bit 31 of a PDO COB-ID: PDO off */
#define CANOPEN_PDO_TT_SYNC1          0x01u        /* synchronous, every SYNC */
/* A PDO mapping entry (CiA 301, objects 0x1600 / 0x1A00): index << 16, sub << 8, bits. */
#define CANOPEN_PDO_MAP_ENTRY(idx, sub, bits) (((uint32_t)(idx) << 16) | ((uint32_t)(sub) << 8) | (bits))

/* SDO command bytes (CiA 301, SDO protocols), expedited transfers only. */
#define CANOPEN_SDO_ABORT          0x80u
#define CANOPEN_SDO_DOWNLOAD_RESP  0x60u  /* scs = 3 */
#define CANOPEN_SDO_UPLOAD_REQ     0x40u  /* ccs = 2 */

/* What a frame from the node side is, by its COB-ID. */
enum canopen_kind {
    CANOPEN_KIND_OTHER = 0, CANOPEN_KIND_NMT, CANOPEN_KIND_SYNC, CANOPEN_KIND_EMCY,
    CANOPEN_KIND_TPDO1, CANOPEN_KIND_RPDO1, CANOPEN_KIND_SDO_TX, CANOPEN_KIND_SDO_RX,
    CANOPEN_KIND_HEARTBEAT,
};
/* Classifies a frame and returns its node-ID (0 for NMT, SYNC and unknown frames). */
enum canopen_kind canopen_classify(const struct can_frame *f, int *node);

/* Little-endian helpers: CANopen sends every multi-byte value least significant byte first. */
void canopen_put_u16(uint8_t *p, uint16_t v);
void canopen_put_u32(uint8_t *p, uint32_t v);
uint16_t canopen_get_u16(const uint8_t *p);
uint32_t canopen_get_u32(const uint8_t *p);

/* Frame builders. */
void canopen_nmt(struct can_frame *f, enum canopen_nmt_cmd cmd, int node);
void canopen_sync(struct can_frame *f);
void canopen_heartbeat(struct can_frame *f, int node, enum canopen_nmt_state st);
void canopen_emcy(struct can_frame *f, int node, uint16_t code, uint8_t reg);

/* An expedited SDO write (download) of `size` bytes (1, 2 or 4) of `value` to index:sub. */
void canopen_sdo_write(struct can_frame *f, int node, uint16_t index, uint8_t sub,
                       uint32_t value, int size);
/* An SDO answer from a server: a download response or an abort with its code. */
void canopen_sdo_write_ok(struct can_frame *f, int node, uint16_t index, uint8_t sub);
void canopen_sdo_abort(struct can_frame *f, int cob_base, int node, uint16_t index, uint8_t sub,
                       uint32_t code);

/* A decoded SDO frame (either direction). */
struct canopen_sdo {
    uint8_t cmd;        /* command byte */
    uint16_t index;     /* object index */
    uint8_t sub;        /* sub-index */
    uint32_t value;     /* expedited data, little-endian decoded; the abort code for aborts */
    int size;           /* data bytes of an expedited download (1..4), 0 if not indicated */
};
/* Decodes the fixed 8-byte SDO layout; false when the frame is shorter than 8 bytes. */
bool canopen_sdo_decode(const struct can_frame *f, struct canopen_sdo *out);
/* True for a client's expedited download request (ccs = 1, e = 1). */
bool canopen_sdo_is_expedited_write(const struct canopen_sdo *s);

/* The meaning of an SDO abort code (CiA 301) in words, "unknown abort code" else. */
const char *canopen_abort_text(uint32_t code);
/* The class of an EMCY error code (CiA 301, emergency error codes). */
const char *canopen_emcy_text(uint16_t code);

/* EMCY payload: error code u16, error register u8 (object 0x1001), 5 manufacturer bytes. */
struct canopen_emcy_msg {
    uint16_t code;      /* 0x0000 = error reset / no error */
    uint8_t reg;        /* error register bits: 0 generic, 1 current, 2 voltage, 3 temperature */
};
bool canopen_emcy_decode(const struct can_frame *f, struct canopen_emcy_msg *out);

/* Status codes of this module and the master built on it (0 = OK). */
enum canopen_status {
    CANOPEN_OK = 0,
    CANOPEN_ERR_ARG,          /* a bad configuration value */
    CANOPEN_ERR_SDO_ABORT,    /* a node refused an SDO write */
    CANOPEN_ERR_SDO_TIMEOUT,  /* a node did not answer an SDO write in time */
    CANOPEN_ERR_BOOT,         /* a node did not send its boot-up after reset communication */
    CANOPEN_ERR_HEARTBEAT,    /* a node's heartbeat stopped */
    CANOPEN_ERR_EMCY,         /* a node sent an emergency message */
    CANOPEN_ERR_DRIVE_FAULT,  /* the drive's statusword reports Fault */
    CANOPEN_ERR_PDO_TIMEOUT,  /* no TPDO from a node although its heartbeat goes on */
    CANOPEN_ERR_RANGE,        /* a position beyond the drive's 32-bit count range */
    CANOPEN_ERR_BUS_LOST,     /* the transport is gone (peer closed, socket error) */
    CANOPEN_STATUS_COUNT
};
const char *canopen_strerror(int status);

#endif
