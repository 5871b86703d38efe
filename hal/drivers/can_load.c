/* can_load.c: CAN bus load arithmetic (see can_load.h for the frame layout it counts). */
#include "hal/drivers/can_load.h"

/* Bits of one standard frame with n data bytes, intermission included. */
int can_frame_bits(int data_bytes, bool worst_stuffing)
{
    if (data_bytes < 0)
        data_bytes = 0;
    if (data_bytes > 8)
        data_bytes = 8;
    int bits = 44 + 8 * data_bytes + 3;
    if (worst_stuffing)
        bits += (34 + 8 * data_bytes - 1) / 4;
    return bits;
}

/* Bits per second taken over bits per second available. */
double can_bus_load(int frames, int data_bytes, double rate_hz, double bitrate_bps)
{
    if (bitrate_bps <= 0.0)
        return 0.0;
    return (double)frames * can_frame_bits(data_bytes, true) * rate_hz / bitrate_bps;
}

/* SYNC + RPDOs + TPDOs per cycle, heartbeats on top. */
double can_csp_load(int drives, int rpdo_bytes, int tpdo_bytes, double sync_hz,
                    double heartbeat_hz, double bitrate_bps)
{
    return can_bus_load(1, 0, sync_hz, bitrate_bps) +
           can_bus_load(drives, rpdo_bytes, sync_hz, bitrate_bps) +
           can_bus_load(drives, tpdo_bytes, sync_hz, bitrate_bps) +
           can_bus_load(drives, 1, heartbeat_hz, bitrate_bps);
}
