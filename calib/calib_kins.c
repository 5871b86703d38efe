/* calib_kins.c: the calibration geometry read from, and put into, the hexapod kinematics. */
#include <stdio.h>
#include <string.h>

#include "calib/calib.h"
#include "kins/hexapod.h"

/* Copies the joint centres and offsets out of a hexapod instance. */
enum calib_status calib_geom_from_kins(const struct kins *k, struct calib_geom *g, char *err,
                                       size_t errlen)
{
    if (!k || k->ops != &kins_hexapod_ops) {
        snprintf(err, errlen, "[KINS] KINEMATICS: calibration needs the hexapod model");
        return CALIB_ERR_GEOMETRY;
    }
    const struct hexapod *h = (const struct hexapod *)k;
    memcpy(g->b_mm, h->b_mm, sizeof g->b_mm);
    memcpy(g->p_mm, h->p_mm, sizeof g->p_mm);
    memcpy(g->offset_mm, h->offset_mm, sizeof g->offset_mm);
    return CALIB_OK;
}

/* Formats one explicit-geometry key's value for g (see calib.h). */
const char *calib_geom_key_value(const struct calib_geom *g, const char *key, char *buf,
                                 size_t len)
{
    int i;
    char tail;
    if (!strcmp(key, "LEG_OFFSET")) {
        const double *o = g->offset_mm;
        snprintf(buf, len, "%.9f %.9f %.9f %.9f %.9f %.9f", o[0], o[1], o[2], o[3], o[4],
                 o[5]);
        return buf;
    }
    const double (*set)[3] = NULL;
    if (sscanf(key, "BASE_%d%c", &i, &tail) == 1)
        set = g->b_mm;
    else if (sscanf(key, "PLATFORM_%d%c", &i, &tail) == 1)
        set = g->p_mm;
    if (!set || i < 0 || i >= CALIB_LEGS)
        return NULL;
    snprintf(buf, len, "%.9f %.9f %.9f", set[i][0], set[i][1], set[i][2]);
    return buf;
}

/* A configuration that answers the explicit-geometry keys from a geometry and every other
 * key from the base configuration. */
struct calib_overlay {
    const struct kins_config *base;    /* the machine's own configuration */
    const struct calib_geom *g;        /* the geometry that replaces its own */
    char buf[CALIB_LEGS * 2 + 1][160]; /* formatted values, one slot per key */
};

/* kins_config get(): geometry keys from the overlay, the rest from the base. */
static const char *calib_overlay_get(void *ctx, const char *section, const char *key)
{
    struct calib_overlay *ov = ctx;
    if (!strcmp(section, "KINS")) {
        int slot = 0;
        int i;
        char tail;
        if (sscanf(key, "BASE_%d%c", &i, &tail) == 1 && i >= 0 && i < CALIB_LEGS)
            slot = 1 + i;
        else if (sscanf(key, "PLATFORM_%d%c", &i, &tail) == 1 && i >= 0 && i < CALIB_LEGS)
            slot = 1 + CALIB_LEGS + i;
        const char *v = calib_geom_key_value(ov->g, key, ov->buf[slot], sizeof ov->buf[slot]);
        if (v)
            return v;
    }
    return ov->base->get(ov->base->ctx, section, key);
}

/* Builds a hexapod with the base configuration's settings and geometry g. */
enum calib_status calib_kins_create(const struct kins_config *base, const struct calib_geom *g,
                                    struct kins **out, char *err, size_t errlen)
{
    struct calib_overlay ov = { .base = base, .g = g };
    struct kins_config cfg = { calib_overlay_get, &ov };
    int st = kins_create(&kins_hexapod_ops, &cfg, out, err, errlen);
    return st == KINS_OK ? CALIB_OK : CALIB_ERR_GEOMETRY;
}
