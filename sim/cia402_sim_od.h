/* cia402_sim_od.h: the simulated drive's object dictionary and SDO server (sim internals). */
#ifndef HEXCNC_CIA402_SIM_OD_H
#define HEXCNC_CIA402_SIM_OD_H

#include "sim/cia402_sim.h"

/* One object of the dictionary: where it lives in struct cia402_sim. */
struct cia402_sim_obj {
    uint16_t index;       /* object index */
    uint8_t sub;          /* sub-index */
    uint8_t size;         /* bytes: 1, 2 or 4 */
    uint8_t flags;        /* CIA402_SIM_RO, CIA402_SIM_MAPPABLE */
    size_t offset;        /* offsetof(struct cia402_sim, field) */
};
#define CIA402_SIM_RO 1u        /* read-only: writes abort with 0x06010002 */
#define CIA402_SIM_MAPPABLE 2u  /* may appear in a PDO mapping */

/* The object index:sub, or NULL. */
const struct cia402_sim_obj *cia402_sim_od_find(uint16_t index, uint8_t sub);
/* An object's value, zero-extended to 32 bits (the raw little-endian bytes). */
uint32_t cia402_sim_od_get(const struct cia402_sim *s, const struct cia402_sim_obj *o);
/* Stores a value into an object (truncated to its size). */
void cia402_sim_od_set(struct cia402_sim *s, const struct cia402_sim_obj *o, uint32_t v);
/* Answers one SDO request frame: a download response or an abort; false if no answer. */
bool cia402_sim_sdo(struct cia402_sim *s, const struct can_frame *in, struct can_frame *out);

#endif
