/* test_kins_util.h: configurations for the kinematics tests (key tables, INI files), PRNG. */
#ifndef HEXCNC_TEST_KINS_UTIL_H
#define HEXCNC_TEST_KINS_UTIL_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <ini.h>

#include "kins/kins.h"

#define TK_MAX_KEYS 256

/* A configuration held as a table of section/key/value strings. */
struct tk_cfg {
    int n;                          /* entries used */
    char sec[TK_MAX_KEYS][24];      /* section names */
    char key[TK_MAX_KEYS][40];      /* key names */
    char val[TK_MAX_KEYS][160];     /* values */
};

/* Looks a key up, as struct kins_config wants. */
static inline const char *tk_get(void *ctx, const char *sec, const char *key)
{
    const struct tk_cfg *c = ctx;
    for (int i = 0; i < c->n; i++)
        if (!strcmp(c->sec[i], sec) && !strcmp(c->key[i], key))
            return c->val[i];
    return NULL;
}

/* Sets (or with val NULL removes) one key. */
static inline void tk_set(struct tk_cfg *c, const char *sec, const char *key, const char *val)
{
    for (int i = 0; i < c->n; i++)
        if (!strcmp(c->sec[i], sec) && !strcmp(c->key[i], key)) {
            if (val) {
                snprintf(c->val[i], sizeof c->val[i], "%s", val);
                return;
            }
            c->n--; /* removal: the last entry takes this place */
            memmove(c->sec[i], c->sec[c->n], sizeof c->sec[i]);
            memmove(c->key[i], c->key[c->n], sizeof c->key[i]);
            memmove(c->val[i], c->val[c->n], sizeof c->val[i]);
            return;
        }
    if (!val || c->n >= TK_MAX_KEYS)
        return;
    snprintf(c->sec[c->n], sizeof c->sec[0], "%s", sec);
    snprintf(c->key[c->n], sizeof c->key[0], "%s", key);
    snprintf(c->val[c->n], sizeof c->val[0], "%s", val);
    c->n++;
}

/* Sets a key to a formatted number. */
static inline void tk_setf(struct tk_cfg *c, const char *sec, const char *key, double v)
{
    char buf[64];
    snprintf(buf, sizeof buf, "%.17g", v);
    tk_set(c, sec, key, buf);
}

/* Sets key to the number v in each of the six legs' sections, [JOINT_0] .. [JOINT_5]. */
static inline void tk_setf_joints(struct tk_cfg *c, const char *key, double v)
{
    for (int i = 0; i < 6; i++) {
        char sec[24];
        snprintf(sec, sizeof sec, "JOINT_%d", i);
        tk_setf(c, sec, key, v);
    }
}

/* A fresh parametric hexapod: radii (mm), pair half-angles (deg), leg limits (mm). */
static inline struct tk_cfg *tk_hexapod(double rb, double rp, double hb, double hp,
                                        double lmin, double lmax)
{
    struct tk_cfg *c = calloc(1, sizeof *c);
    if (!c)
        abort();
    tk_set(c, "KINS", "KINEMATICS", "hexapod");
    tk_setf(c, "KINS", "BASE_RADIUS", rb);
    tk_setf(c, "KINS", "PLATFORM_RADIUS", rp);
    tk_setf(c, "KINS", "BASE_HALF_ANGLE", hb);
    tk_setf(c, "KINS", "PLATFORM_HALF_ANGLE", hp);
    tk_setf_joints(c, "MIN_LIMIT", lmin);
    tk_setf_joints(c, "MAX_LIMIT", lmax);
    return c;
}

/* inih handler storing into a tk_cfg (first duplicate wins, as in the tool). */
static inline int tk_ini_store(void *user, const char *sec, const char *key, const char *val)
{
    struct tk_cfg *c = user;
    if (!tk_get(c, sec, key))
        tk_set(c, sec, key, val);
    return 1;
}

/* Path of a file in the source tree ($HEXCNC_ROOT, set by make test, else "."). */
static inline void tk_tree_path(char *buf, size_t len, const char *rel)
{
    const char *root = getenv("HEXCNC_ROOT");
    snprintf(buf, len, "%s/%s", root && *root ? root : ".", rel);
}

/* Reads an INI file of the tree into a fresh tk_cfg; NULL if it cannot be read. */
static inline struct tk_cfg *tk_ini(const char *rel)
{
    char path[1024];
    tk_tree_path(path, sizeof path, rel);
    struct tk_cfg *c = calloc(1, sizeof *c);
    if (c && ini_parse(path, tk_ini_store, c) != 0) {
        free(c);
        return NULL;
    }
    return c;
}

/* The configuration interface over a table. */
static inline struct kins_config tk_config(struct tk_cfg *c)
{
    struct kins_config k = { tk_get, c };
    return k;
}

/* splitmix64: a small reproducible generator for random poses. */
static inline uint64_t tk_rand_u64(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Uniform in [lo, hi]. */
static inline double tk_rand(uint64_t *state, double lo, double hi)
{
    return lo + (hi - lo) * (double)(tk_rand_u64(state) >> 11) * 0x1.0p-53;
}

/* The TMU machine's working region: X, Y +-120 mm, Z 620..670 mm, |A|, |B| <= 10 deg,
 * |C| <= 15 deg. */
static const double tk_region_lo[6] = { -120, -120, 620, -10, -10, -15 };
static const double tk_region_hi[6] = { 120, 120, 670, 10, 10, 15 };

/* A random pose in the working region. */
static inline void tk_rand_pose(uint64_t *state, double pose[6])
{
    for (int j = 0; j < 6; j++)
        pose[j] = tk_rand(state, tk_region_lo[j], tk_region_hi[j]);
}

#endif
