/* motion_hal.h: what the runner calls on the `motion` HAL component (loadrt motion). */
#ifndef HEXCNC_MOTION_HAL_H
#define HEXCNC_MOTION_HAL_H

#include <stddef.h>

#include "hal/hal.h"
#include "interp/canon.h"
#include "motion/motion.h"

/* The motion instance of the `motion` component (the HAL object "motion"), or NULL when
 * `loadrt motion` has not run. */
struct motion *motion_hal_get(const struct hal *h);

/* Plans prog on the component's motion instance (motion_load: every move checked through
 * the kinematics first). It starts at the next motion.update that sees motion.enable true.
 * MOTION_ERR_* with a message naming file and line in err on failure. */
int motion_hal_load(struct hal *h, const struct canon_prog *prog, char *err, size_t errlen);

/* The fault or last error text ("" when none): what the runner shows the machinist. */
const char *motion_hal_fault(const struct hal *h);

#endif
