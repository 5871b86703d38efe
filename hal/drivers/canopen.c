/* canopen.c: CiA 301 frame encoding and decoding (NMT, SYNC, SDO, EMCY, heartbeat). */
#include "hal/drivers/canopen.h"

#include <string.h>

/* Classifies a frame by its function code; node-ID 0 where the frame has none. */
enum canopen_kind canopen_classify(const struct can_frame *f, int *node)
{
    uint32_t id = f->can_id;
    *node = 0;
    if (id & (CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_ERR_FLAG))
        return CANOPEN_KIND_OTHER;  /* CANopen's predefined set uses 11-bit data frames only */
    id &= CAN_SFF_MASK;
    int n = (int)(id & CANOPEN_NODE_MASK);
    switch (id & CANOPEN_FUNC_MASK) {
    case CANOPEN_COB_NMT:
        return id == CANOPEN_COB_NMT ? CANOPEN_KIND_NMT : CANOPEN_KIND_OTHER;
    case CANOPEN_COB_SYNC:
        if (n == 0)
            return CANOPEN_KIND_SYNC;
        *node = n;
        return CANOPEN_KIND_EMCY;
    case CANOPEN_COB_TPDO1: *node = n; return n ? CANOPEN_KIND_TPDO1 : CANOPEN_KIND_OTHER;
    case CANOPEN_COB_RPDO1: *node = n; return n ? CANOPEN_KIND_RPDO1 : CANOPEN_KIND_OTHER;
    case CANOPEN_COB_SDO_TX: *node = n; return n ? CANOPEN_KIND_SDO_TX : CANOPEN_KIND_OTHER;
    case CANOPEN_COB_SDO_RX: *node = n; return n ? CANOPEN_KIND_SDO_RX : CANOPEN_KIND_OTHER;
    case CANOPEN_COB_HEARTBEAT: *node = n; return n ? CANOPEN_KIND_HEARTBEAT : CANOPEN_KIND_OTHER;
    default:
        return CANOPEN_KIND_OTHER;
    }
}

/* Stores v least significant byte first. */
void canopen_put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
}

/* Stores v least significant byte first. */
void canopen_put_u32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}

/* Reads a little-endian u16. */
uint16_t canopen_get_u16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (p[1] << 8));
}

/* Reads a little-endian u32. */
uint32_t canopen_get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
           ((uint32_t)p[3] << 24);
}

/* Starts a standard data frame with the given COB-ID and length, data zeroed. */
static void frame_init(struct can_frame *f, uint32_t cob, int len)
{
    memset(f, 0, sizeof *f);
    f->can_id = cob;
    f->can_dlc = (uint8_t)len;
}

/* NMT node control: command byte, then the node-ID (0 = all nodes). */
void canopen_nmt(struct can_frame *f, enum canopen_nmt_cmd cmd, int node)
{
    frame_init(f, CANOPEN_COB_NMT, 2);
    f->data[0] = (uint8_t)cmd;
    f->data[1] = (uint8_t)node;
}

/* SYNC without the optional counter byte: zero data bytes, the cheapest frame on the bus. */
void canopen_sync(struct can_frame *f)
{
    frame_init(f, CANOPEN_COB_SYNC, 0);
}

/* A heartbeat (or, with state 0, the boot-up message). */
void canopen_heartbeat(struct can_frame *f, int node, enum canopen_nmt_state st)
{
    frame_init(f, CANOPEN_COB_HEARTBEAT + (uint32_t)node, 1);
    f->data[0] = (uint8_t)st;
}

/* An emergency message: error code, error register, manufacturer bytes left zero. */
void canopen_emcy(struct can_frame *f, int node, uint16_t code, uint8_t reg)
{
    frame_init(f, CANOPEN_COB_EMCY + (uint32_t)node, 8);
    canopen_put_u16(f->data, code);
    f->data[2] = reg;
}

/* The common SDO layout: command, index (LE), sub-index, four data bytes. */
static void sdo_frame(struct can_frame *f, uint32_t cob, uint8_t cmd, uint16_t index,
                      uint8_t sub, uint32_t data)
{
    frame_init(f, cob, 8);
    f->data[0] = cmd;
    canopen_put_u16(f->data + 1, index);
    f->data[3] = sub;
    canopen_put_u32(f->data + 4, data);
}

/* Expedited download request: ccs = 1, n = 4 - size unused bytes, e = 1, s = 1. */
void canopen_sdo_write(struct can_frame *f, int node, uint16_t index, uint8_t sub,
                       uint32_t value, int size)
{
    if (size != 1 && size != 2)
        size = 4;
    uint32_t mask = size == 4 ? 0xFFFFFFFFu : (1u << (8 * size)) - 1u;
    uint8_t cmd = (uint8_t)(0x20u | ((uint32_t)(4 - size) << 2) | 0x03u);
    sdo_frame(f, CANOPEN_COB_SDO_RX + (uint32_t)node, cmd, index, sub, value & mask);
}

/* Download response: the server confirms the write. */
void canopen_sdo_write_ok(struct can_frame *f, int node, uint16_t index, uint8_t sub)
{
    sdo_frame(f, CANOPEN_COB_SDO_TX + (uint32_t)node, CANOPEN_SDO_DOWNLOAD_RESP, index, sub, 0);
}

/* Abort transfer, from either side (cob_base picks the direction). */
void canopen_sdo_abort(struct can_frame *f, int cob_base, int node, uint16_t index, uint8_t sub,
                       uint32_t code)
{
    sdo_frame(f, (uint32_t)(cob_base + node), CANOPEN_SDO_ABORT, index, sub, code);
}

/* Splits an SDO frame into its fields. */
bool canopen_sdo_decode(const struct can_frame *f, struct canopen_sdo *out)
{
    if (f->can_dlc < 8)
        return false;  /* CiA 301: SDO frames always carry 8 bytes */
    out->cmd = f->data[0];
    out->index = canopen_get_u16(f->data + 1);
    out->sub = f->data[3];
    out->value = canopen_get_u32(f->data + 4);
    out->size = 0;
    if ((out->cmd & 0xE0u) == 0x20u && (out->cmd & 0x03u) == 0x03u) {
        out->size = 4 - (int)((out->cmd >> 2) & 0x03u);
        if (out->size < 4)
            out->value &= (1u << (8 * out->size)) - 1u;
    }
    return true;
}

/* Expedited download request: ccs = 1 with the e bit set. */
bool canopen_sdo_is_expedited_write(const struct canopen_sdo *s)
{
    return (s->cmd & 0xE0u) == 0x20u && (s->cmd & 0x02u);
}

/* The SDO abort codes of CiA 301 that a drive is likely to send. */
static const struct { uint32_t code; const char *text; } abort_texts[] = {
    { 0x05030000u, "toggle bit not alternated" },
    { 0x05040000u, "SDO protocol timed out" },
    { 0x05040001u, "command specifier not valid or unknown" },
    { 0x05040005u, "out of memory" },
    { 0x06010000u, "unsupported access to an object" },
    { 0x06010001u, "attempt to read a write-only object" },
    { 0x06010002u, "attempt to write a read-only object" },
    { 0x06020000u, "object does not exist in the object dictionary" },
    { 0x06040041u, "object cannot be mapped to the PDO" },
    { 0x06040042u, "the mapped objects would exceed the PDO length" },
    { 0x06040043u, "general parameter incompatibility" },
    { 0x06040047u, "general internal incompatibility in the device" },
    { 0x06060000u, "access failed due to a hardware error" },
    { 0x06070010u, "data type or length does not match" },
    { 0x06070012u, "data type does not match, length too high" },
    { 0x06070013u, "data type does not match, length too low" },
    { 0x06090011u, "sub-index does not exist" },
    { 0x06090030u, "value range of parameter exceeded" },
    { 0x06090031u, "value of parameter written too high" },
    { 0x06090032u, "value of parameter written too low" },
    { 0x06090036u, "maximum value is less than minimum value" },
    { 0x08000000u, "general error" },
    { 0x08000020u, "data cannot be transferred or stored to the application" },
    { 0x08000021u, "data cannot be transferred because of local control" },
    { 0x08000022u, "data cannot be transferred in the present device state" },
    { 0x08000024u, "no data available" },
};

/* Looks an abort code up in the table. */
const char *canopen_abort_text(uint32_t code)
{
    for (size_t i = 0; i < sizeof abort_texts / sizeof abort_texts[0]; i++)
        if (abort_texts[i].code == code)
            return abort_texts[i].text;
    return "unknown abort code";
}

/* Emergency error code classes of CiA 301; the most specific matching prefix wins. */
static const struct { uint16_t code, mask; const char *text; } emcy_texts[] = {
    { 0x0000, 0xFFFF, "error reset or no error" },
    { 0x8110, 0xFFFF, "CAN overrun, frames lost" },
    { 0x8120, 0xFFFF, "CAN in error passive mode" },
    { 0x8130, 0xFFFF, "life guard or heartbeat error" },
    { 0x8140, 0xFFFF, "recovered from bus off" },
    { 0x8210, 0xFFFF, "PDO not processed due to length error" },
    { 0x2100, 0xFF00, "current, device input side" },
    { 0x2200, 0xFF00, "current inside the device" },
    { 0x2300, 0xFF00, "current, device output side (motor over-current)" },
    { 0x3100, 0xFF00, "mains voltage" },
    { 0x3200, 0xFF00, "voltage inside the device (DC link)" },
    { 0x3300, 0xFF00, "output voltage" },
    { 0x4100, 0xFF00, "ambient temperature" },
    { 0x4200, 0xFF00, "device temperature" },
    { 0x6100, 0xFF00, "internal software" },
    { 0x6200, 0xFF00, "user software" },
    { 0x6300, 0xFF00, "data set" },
    { 0x8100, 0xFF00, "communication" },
    { 0x8200, 0xFF00, "protocol error" },
    { 0x1000, 0xF000, "generic error" },
    { 0x2000, 0xF000, "current" },
    { 0x3000, 0xF000, "voltage" },
    { 0x4000, 0xF000, "temperature" },
    { 0x5000, 0xF000, "device hardware" },
    { 0x6000, 0xF000, "device software" },
    { 0x7000, 0xF000, "additional modules (motor, encoder)" },
    { 0x8000, 0xF000, "monitoring (e.g. following error)" },
    { 0x9000, 0xF000, "external error" },
    { 0xF000, 0xFF00, "additional functions" },
    { 0xFF00, 0xFF00, "device specific" },
};

/* Names the class of an EMCY error code. */
const char *canopen_emcy_text(uint16_t code)
{
    for (size_t i = 0; i < sizeof emcy_texts / sizeof emcy_texts[0]; i++)
        if ((code & emcy_texts[i].mask) == emcy_texts[i].code)
            return emcy_texts[i].text;
    return "unknown error code";
}

/* EMCY: code (LE u16) and the error register; needs at least three bytes. */
bool canopen_emcy_decode(const struct can_frame *f, struct canopen_emcy_msg *out)
{
    if (f->can_dlc < 3)
        return false;
    out->code = canopen_get_u16(f->data);
    out->reg = f->data[2];
    return true;
}

/* Status texts, one per enum canopen_status value. */
static const char *const status_texts[CANOPEN_STATUS_COUNT] = {
    [CANOPEN_OK] = "ok",
    [CANOPEN_ERR_ARG] = "bad CANopen configuration value",
    [CANOPEN_ERR_SDO_ABORT] = "the drive refused a configuration write (SDO abort)",
    [CANOPEN_ERR_SDO_TIMEOUT] = "the drive did not answer a configuration write (SDO timeout)",
    [CANOPEN_ERR_BOOT] = "the drive did not come back after a communication reset",
    [CANOPEN_ERR_HEARTBEAT] = "the drive's heartbeat stopped",
    [CANOPEN_ERR_EMCY] = "the drive sent an emergency message",
    [CANOPEN_ERR_DRIVE_FAULT] = "the drive reports a fault",
    [CANOPEN_ERR_PDO_TIMEOUT] = "no position feedback from the drive",
    [CANOPEN_ERR_RANGE] = "position beyond the drive's count range",
    [CANOPEN_ERR_BUS_LOST] = "the CAN connection is gone",
};

/* Text of a status code. */
const char *canopen_strerror(int status)
{
    if (status < 0 || status >= CANOPEN_STATUS_COUNT || !status_texts[status])
        return "unknown CANopen status";
    return status_texts[status];
}
