/* probe_model.h: a simulated workpiece for G38 probing ([PROBE] in the INI): where a probe
 * moving in a straight line first touches it, or first leaves it. Pure geometry. */
#ifndef HEXCNC_PROBE_MODEL_H
#define HEXCNC_PROBE_MODEL_H

#include <stdbool.h>
#include <stddef.h>

enum probe_model_kind {
    PROBE_MODEL_NONE,      /* no workpiece: probing behaves as LinuxCNC's rs274 */
    PROBE_MODEL_PLANE,     /* a half-space: material below a plane */
    PROBE_MODEL_BOX,       /* a solid block with faces parallel to the machine's axes */
};

/* The workpiece, in machine coordinates (mm). The probe is the point the program moves
 * (X Y Z of the machine pose); it is in contact when that point is in the material or on
 * its surface. */
struct probe_model {
    enum probe_model_kind kind;
    double point_mm[3];    /* PLANE: a point of the surface */
    double normal[3];      /* PLANE: unit normal, pointing out of the material */
    double min_mm[3];      /* BOX: corner with the smallest X Y Z */
    double max_mm[3];      /* BOX: corner with the largest X Y Z */
};

/* The INI lookup (the same as interp_setup_get_fn). */
typedef const char *(*probe_model_get_fn)(void *ctx, const char *section, const char *key);

/* Reads [PROBE] MODEL (NONE, PLANE, BOX), PLANE_POINT, PLANE_NORMAL, BOX_MIN, BOX_MAX.
 * Absent MODEL: NONE. 0, or -1 with a message naming the key in err. */
int probe_model_read(struct probe_model *m, probe_model_get_fn get, void *ctx, char *err,
                     size_t errlen);

/* Whether the probe at xyz (mm, machine frame) touches the workpiece. */
bool probe_model_contact(const struct probe_model *m, const double xyz[3]);

/* On the straight move from a to b (mm), the first fraction s in [0, 1] of the way at which
 * the contact state becomes `contact` (s = 0: it already is at a); -1 when it never does. */
double probe_model_find(const struct probe_model *m, const double a[3], const double b[3],
                        bool contact);

#endif
