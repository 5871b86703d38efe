/* can_load.h: CAN bus load arithmetic: bits per frame, per cycle, load at a rate and bitrate. */
#ifndef HEXCNC_CAN_LOAD_H
#define HEXCNC_CAN_LOAD_H

#include <stdbool.h>

/*
 * A classic CAN data frame with an 11-bit identifier (ISO 11898-1): SOF 1, identifier 11,
 * RTR 1, IDE 1, r0 1, DLC 4, data 8*n, CRC 15, CRC delimiter 1, ACK slot and delimiter 2,
 * EOF 7 = 44 + 8n bits; then 3 bits of intermission before the next frame may start.
 * Bit stuffing inserts one bit after five equal bits in SOF..CRC (34 + 8n bits); the worst
 * case is one stuff bit per four bits after the first: floor((34 + 8n - 1) / 4).
 */
/* Bus time of one frame of n data bytes (0..8) in bits, intermission included; with
 * worst_stuffing the worst-case stuff bits are added. */
int can_frame_bits(int data_bytes, bool worst_stuffing);

/* The fraction of the bus (1.0 = 100 %) that `frames` frames of `data_bytes` each, sent
 * rate_hz times a second, take at bitrate_bps, with worst-case stuffing. */
double can_bus_load(int frames, int data_bytes, double rate_hz, double bitrate_bps);

/* The load of a CSP cycle: one SYNC (0 bytes) plus an RPDO and a TPDO per drive, at the
 * SYNC rate, plus one heartbeat (1 byte) per drive per heartbeat period. */
double can_csp_load(int drives, int rpdo_bytes, int tpdo_bytes, double sync_hz,
                    double heartbeat_hz, double bitrate_bps);

#endif
