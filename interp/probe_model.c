/* probe_model.c: the simulated workpiece of G38 probing: a plane or a block, read from [PROBE],
 * and where a straight probe move first touches or leaves it. */
#include "interp/probe_model.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "common/config.h"

/* Reads "x y z" from [PROBE] key into v; -1 with a message when absent or malformed. */
static int read_xyz(probe_model_get_fn get, void *ctx, const char *key, const char *model,
                    double v[3], char *err, size_t errlen)
{
    const char *t = get(ctx, "PROBE", key);
    char why[200];
    if (!t || !t[0]) {
        snprintf(err, errlen, "[PROBE] MODEL = %s needs [PROBE] %s: three numbers x y z, mm "
                 "in machine coordinates", model, key);
        return -1;
    }
    if (config_parse_numbers(t, v, 3, why, sizeof why) != 0) {
        snprintf(err, errlen, "[PROBE] %s = %s: %s (three numbers x y z, mm in machine "
                 "coordinates, are expected)", key, t, why);
        return -1;
    }
    return 0;
}

/* Refuses a key that belongs to the other model, so a typo does not go unnoticed. */
static int refuse_key(probe_model_get_fn get, void *ctx, const char *key, const char *model,
                      char *err, size_t errlen)
{
    const char *t = get(ctx, "PROBE", key);
    if (!t)
        return 0;
    snprintf(err, errlen, "[PROBE] %s is given but [PROBE] MODEL = %s does not use it", key,
             model);
    return -1;
}

int probe_model_read(struct probe_model *m, probe_model_get_fn get, void *ctx, char *err,
                     size_t errlen)
{
    memset(m, 0, sizeof *m);
    const char *kind = get(ctx, "PROBE", "MODEL");
    if (!kind || !kind[0] || strcasecmp(kind, "NONE") == 0) {
        kind = "NONE";
        if (refuse_key(get, ctx, "PLANE_POINT", kind, err, errlen) ||
            refuse_key(get, ctx, "PLANE_NORMAL", kind, err, errlen) ||
            refuse_key(get, ctx, "BOX_MIN", kind, err, errlen) ||
            refuse_key(get, ctx, "BOX_MAX", kind, err, errlen))
            return -1;
        return 0;
    }
    if (strcasecmp(kind, "PLANE") == 0) {
        m->kind = PROBE_MODEL_PLANE;
        if (read_xyz(get, ctx, "PLANE_POINT", kind, m->point_mm, err, errlen) ||
            read_xyz(get, ctx, "PLANE_NORMAL", kind, m->normal, err, errlen) ||
            refuse_key(get, ctx, "BOX_MIN", kind, err, errlen) ||
            refuse_key(get, ctx, "BOX_MAX", kind, err, errlen))
            return -1;
        double n = sqrt(m->normal[0] * m->normal[0] + m->normal[1] * m->normal[1] +
                        m->normal[2] * m->normal[2]);
        if (!(n > 1e-9)) {
            snprintf(err, errlen, "[PROBE] PLANE_NORMAL = %s: the normal has no length",
                     get(ctx, "PROBE", "PLANE_NORMAL"));
            return -1;
        }
        for (int i = 0; i < 3; i++)
            m->normal[i] /= n;
        return 0;
    }
    if (strcasecmp(kind, "BOX") == 0) {
        m->kind = PROBE_MODEL_BOX;
        if (read_xyz(get, ctx, "BOX_MIN", kind, m->min_mm, err, errlen) ||
            read_xyz(get, ctx, "BOX_MAX", kind, m->max_mm, err, errlen) ||
            refuse_key(get, ctx, "PLANE_POINT", kind, err, errlen) ||
            refuse_key(get, ctx, "PLANE_NORMAL", kind, err, errlen))
            return -1;
        for (int i = 0; i < 3; i++)
            if (!(m->max_mm[i] > m->min_mm[i])) {
                snprintf(err, errlen, "[PROBE] BOX_MAX must be larger than BOX_MIN in every "
                         "axis: %c is %g .. %g mm", "XYZ"[i], m->min_mm[i], m->max_mm[i]);
                return -1;
            }
        return 0;
    }
    snprintf(err, errlen, "[PROBE] MODEL = %s: use NONE, PLANE or BOX", kind);
    return -1;
}

/* Signed height of xyz above the plane (mm; <= 0 in the material). */
static double plane_height(const struct probe_model *m, const double xyz[3])
{
    double h = 0;
    for (int i = 0; i < 3; i++)
        h += (xyz[i] - m->point_mm[i]) * m->normal[i];
    return h;
}

bool probe_model_contact(const struct probe_model *m, const double xyz[3])
{
    switch (m->kind) {
    case PROBE_MODEL_PLANE:
        return plane_height(m, xyz) <= 0;
    case PROBE_MODEL_BOX:
        for (int i = 0; i < 3; i++)
            if (xyz[i] < m->min_mm[i] || xyz[i] > m->max_mm[i])
                return false;
        return true;
    default:
        return false;
    }
}

/* The part of the line a + s (b - a) inside the block: [*s0, *s1] (empty when s0 > s1). */
static void box_clip(const struct probe_model *m, const double a[3], const double b[3],
                     double *s0, double *s1)
{
    *s0 = -INFINITY, *s1 = INFINITY;
    for (int i = 0; i < 3; i++) {
        double d = b[i] - a[i];
        if (d == 0) {
            if (a[i] < m->min_mm[i] || a[i] > m->max_mm[i])
                *s0 = INFINITY;   /* parallel to this slab and outside it */
            continue;
        }
        double t0 = (m->min_mm[i] - a[i]) / d, t1 = (m->max_mm[i] - a[i]) / d;
        if (t0 > t1) {
            double t = t0;
            t0 = t1, t1 = t;
        }
        *s0 = fmax(*s0, t0);
        *s1 = fmin(*s1, t1);
    }
}

double probe_model_find(const struct probe_model *m, const double a[3], const double b[3],
                        bool contact)
{
    if (m->kind == PROBE_MODEL_NONE)
        return contact ? -1 : 0;
    if (probe_model_contact(m, a) == contact)
        return 0;
    if (m->kind == PROBE_MODEL_PLANE) {
        double ha = plane_height(m, a), hb = plane_height(m, b);
        bool reached = contact ? hb <= 0 : hb > 0;
        return reached ? ha / (ha - hb) : -1;   /* where the height is 0 */
    }
    double s0, s1;
    box_clip(m, a, b, &s0, &s1);
    if (contact)   /* from outside: where the line enters the block */
        return s0 <= s1 && s0 <= 1 && s1 >= 0 ? fmax(s0, 0) : -1;
    return s1 < 1 ? fmax(s1, 0) : -1;   /* from inside: where it leaves */
}
