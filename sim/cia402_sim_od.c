/* cia402_sim_od.c: the simulated drive's object dictionary subset and its SDO server. */
#include "sim/cia402_sim_od.h"

#include <stddef.h>
#include <string.h>

#define OBJ(idx, sub, size, flags, field) \
    { idx, sub, size, flags, offsetof(struct cia402_sim, field) }
#define MAP CIA402_SIM_MAPPABLE
#define RO CIA402_SIM_RO

/* The objects a CSP master touches, CiA 301 communication area and CiA 402 profile area. */
static const struct cia402_sim_obj od[] = {
    OBJ(0x1017, 0, 2, 0, heartbeat_ms),
    OBJ(0x1400, 1, 4, 0, rpdo_cob),
    OBJ(0x1400, 2, 1, 0, rpdo_tt),
    OBJ(0x1600, 0, 1, 0, rpdo_count),
    OBJ(0x1600, 1, 4, 0, rpdo_map[0]),
    OBJ(0x1600, 2, 4, 0, rpdo_map[1]),
    OBJ(0x1600, 3, 4, 0, rpdo_map[2]),
    OBJ(0x1600, 4, 4, 0, rpdo_map[3]),
    OBJ(0x1800, 1, 4, 0, tpdo_cob),
    OBJ(0x1800, 2, 1, 0, tpdo_tt),
    OBJ(0x1A00, 0, 1, 0, tpdo_count),
    OBJ(0x1A00, 1, 4, 0, tpdo_map[0]),
    OBJ(0x1A00, 2, 4, 0, tpdo_map[1]),
    OBJ(0x1A00, 3, 4, 0, tpdo_map[2]),
    OBJ(0x1A00, 4, 4, 0, tpdo_map[3]),
    OBJ(0x6040, 0, 2, MAP, controlword),
    OBJ(0x6041, 0, 2, MAP | RO, statusword),
    OBJ(0x605A, 0, 2, 0, quick_stop_option),
    OBJ(0x6060, 0, 1, MAP, mode),
    OBJ(0x6061, 0, 1, MAP | RO, mode_display),
    OBJ(0x6064, 0, 4, MAP | RO, actual_counts),
    OBJ(0x607A, 0, 4, MAP, target_counts),
    OBJ(0x60C2, 1, 1, 0, interp_value),
    OBJ(0x60C2, 2, 1, 0, interp_index),
};

/* Looks an object up. */
const struct cia402_sim_obj *cia402_sim_od_find(uint16_t index, uint8_t sub)
{
    for (size_t i = 0; i < sizeof od / sizeof od[0]; i++)
        if (od[i].index == index && od[i].sub == sub)
            return &od[i];
    return NULL;
}

/* True if any object has this index (to tell "no object" from "no sub-index"). */
static bool index_exists(uint16_t index)
{
    for (size_t i = 0; i < sizeof od / sizeof od[0]; i++)
        if (od[i].index == index)
            return true;
    return false;
}

/* Reads an object's field by its size (host order in memory, value semantics out). */
uint32_t cia402_sim_od_get(const struct cia402_sim *s, const struct cia402_sim_obj *o)
{
    const unsigned char *p = (const unsigned char *)s + o->offset;
    uint8_t u8;
    uint16_t u16;
    uint32_t u32;
    switch (o->size) {
    case 1: memcpy(&u8, p, 1); return u8;
    case 2: memcpy(&u16, p, 2); return u16;
    default: memcpy(&u32, p, 4); return u32;
    }
}

/* Writes an object's field by its size. */
void cia402_sim_od_set(struct cia402_sim *s, const struct cia402_sim_obj *o, uint32_t v)
{
    unsigned char *p = (unsigned char *)s + o->offset;
    uint8_t u8 = (uint8_t)v;
    uint16_t u16 = (uint16_t)v;
    switch (o->size) {
    case 1: memcpy(p, &u8, 1); break;
    case 2: memcpy(p, &u16, 2); break;
    default: memcpy(p, &v, 4); break;
    }
}

/* A mapping entry is valid if it names a mappable object with its exact length; an RPDO
 * cannot carry a read-only object (CiA 301: abort 0x06040041 otherwise). */
static bool map_entry_ok(uint32_t entry, bool rpdo)
{
    const struct cia402_sim_obj *o =
        cia402_sim_od_find((uint16_t)(entry >> 16), (uint8_t)(entry >> 8));
    return o && (o->flags & MAP) && (entry & 0xFFu) == 8u * o->size && !(rpdo && (o->flags & RO));
}

/* The sum of the mapped lengths of the first count entries, in bits. */
static uint32_t map_bits(const uint32_t *map, uint32_t count)
{
    uint32_t bits = 0;
    for (uint32_t i = 0; i < count; i++)
        bits += map[i] & 0xFFu;
    return bits;
}

/* The abort code a write of v to o earns, or 0 if it is accepted. */
static uint32_t write_check(const struct cia402_sim *s, const struct cia402_sim_obj *o,
                            uint32_t v)
{
    if (o->index == 0x6060 && (int8_t)v != CIA402_MODE_CSP)
        return 0x06090030u;  /* this drive simulates CSP only */
    if (o->index == 0x605A && ((int16_t)v < 0 || (int16_t)v > 8))
        return 0x06090030u;  /* manufacturer-specific codes are not simulated */
    bool map = o->index == 0x1600 || o->index == 0x1A00;
    if (map && o->sub >= 1 && !map_entry_ok(v, o->index == 0x1600))
        return 0x06040041u;
    if (o->index == 0x1600 && o->sub == 0 && (v > 4 || map_bits(s->rpdo_map, v) > 64))
        return 0x06040042u;
    if (o->index == 0x1A00 && o->sub == 0 && (v > 4 || map_bits(s->tpdo_map, v) > 64))
        return 0x06040042u;
    return 0;
}

/* Answers one SDO request (expedited download only; anything else is aborted). */
bool cia402_sim_sdo(struct cia402_sim *s, const struct can_frame *in, struct can_frame *out)
{
    struct canopen_sdo q;
    int n = s->cfg.node_id;
    if (!canopen_sdo_decode(in, &q) || q.cmd == CANOPEN_SDO_ABORT)
        return false;  /* a client abort needs no answer */
    uint32_t code = 0;
    const struct cia402_sim_obj *o = cia402_sim_od_find(q.index, q.sub);
    if (!canopen_sdo_is_expedited_write(&q))
        code = 0x05040001u;  /* only expedited downloads are simulated */
    else if (!o)
        code = index_exists(q.index) ? 0x06090011u : 0x06020000u;
    else if (o->flags & RO)
        code = 0x06010002u;
    else if (q.size && q.size != o->size)
        code = 0x06070010u;
    else if ((s->inject & CIA402_SIM_SDO_ABORT) && q.index == s->abort_index &&
             q.sub == s->abort_sub)
        code = s->abort_code;
    else
        code = write_check(s, o, q.value);
    if (code) {
        canopen_sdo_abort(out, CANOPEN_COB_SDO_TX, n, q.index, q.sub, code);
        return true;
    }
    cia402_sim_od_set(s, o, q.value);
    s->sdo_writes++;
    canopen_sdo_write_ok(out, n, q.index, q.sub);
    return true;
}
