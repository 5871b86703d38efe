/* canopen_config.h: the list of SDO writes that configure a node for CSP (master internals). */
#ifndef HEXCNC_CANOPEN_CONFIG_H
#define HEXCNC_CANOPEN_CONFIG_H

#include "hal/drivers/canopen_master.h"

/* One expedited SDO write of the configuration sequence. */
struct canopen_write {
    uint16_t index;       /* object index */
    uint8_t sub;          /* sub-index */
    int size;             /* bytes: 1, 2 or 4 */
    uint32_t value;       /* resolved for this node and bus */
    const char *what;     /* the object in words, for messages */
};

/* Number of configuration writes per node. */
int canopen_config_count(void);
/* The step-th write for node n (0-based); false past the end. */
bool canopen_config_write(const struct canopen_master *m, const struct canopen_node *n, int step,
                          struct canopen_write *w);

#endif
