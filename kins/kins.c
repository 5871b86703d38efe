/* kins.c: status texts and the plugin loader (dlopen by name, or a linked-in ops table). */
#include <dlfcn.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "kins/kins.h"
#include "common/plugin_dirs.h"


/* Longest model name accepted: keeps every path and symbol in fixed buffers. */
#define KINS_NAME_MAX 64

static const struct {
    int status;
    const char *text;
} kins_status_texts[] = {
    { KINS_OK, "ok" },
    { KINS_ERR_CONFIG, "kinematics configuration key missing or wrong" },
    { KINS_ERR_NOMEM, "out of memory" },
    { KINS_ERR_PLUGIN, "kinematics plugin not found or not loadable" },
    { KINS_ERR_UNREACHABLE, "pose unreachable: a leg would be outside its length limits" },
    { KINS_ERR_LEG_RANGE, "leg length outside its limits" },
    { KINS_ERR_IMPOSSIBLE, "leg lengths no platform pose can have" },
    { KINS_ERR_SINGULAR, "singular configuration: the legs cannot hold or move the platform" },
    { KINS_ERR_NO_CONVERGE, "forward kinematics did not converge within its iteration limit" },
    { KINS_ERR_ARG, "bad argument (not a number, or wrong count)" },
    { KINS_ERR_WORKSPACE, "pose outside the workspace: a joint angle, leg clearance or "
      "assembly limit" },
};

/* Text of a kinematics status, for messages. */
const char *kins_strerror(int status)
{
    for (size_t i = 0; i < sizeof kins_status_texts / sizeof kins_status_texts[0]; i++)
        if (kins_status_texts[i].status == status)
            return kins_status_texts[i].text;
    return "unknown kinematics status";
}

/* Creates an instance from an ops table, checking that the model filled in the base. */
int kins_create(const struct kins_ops *ops, const struct kins_config *cfg, struct kins **out,
                char *err, size_t errlen)
{
    if (err && errlen)
        err[0] = '\0';
    if (!ops || !ops->create || !out) {
        if (err && errlen)
            snprintf(err, errlen, "kinematics: no ops table given");
        return KINS_ERR_ARG;
    }
    *out = NULL;
    struct kins *k = NULL;
    int st = ops->create(cfg, &k, err, errlen);
    if (st != KINS_OK)
        return st;
    k->ops = ops;
    k->plugin_handle = NULL;
    *out = k;
    return KINS_OK;
}

/* Appends text to the list of tried paths kept for the error message. */
static void kins_note_tried(char *tried, size_t len, const char *path, const char *why)
{
    size_t used = strlen(tried);
    if (used + 1 >= len)
        return;
    /* A list too long for the buffer is cut; the message stays readable. */
    if (snprintf(tried + used, len - used, "%s%s (%s)", used ? ", " : "", path, why) < 0)
        tried[used] = '\0';
}

/* Tries one directory: dlopen <dir>/<name>.so and look up its ops symbol. */
static const struct kins_ops *kins_try_dir(const char *dir, const char *name, const char *sym,
                                           void **handle, char *tried, size_t triedlen)
{
    char path[PATH_MAX + KINS_NAME_MAX];
    int w = snprintf(path, sizeof path, "%s/%s.so", dir, name);
    if (w < 0 || (size_t)w >= sizeof path) {
        kins_note_tried(tried, triedlen, dir, "path too long");
        return NULL;
    }
    if (access(path, F_OK) != 0) {
        kins_note_tried(tried, triedlen, path, "no such file");
        return NULL;
    }
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        const char *why = dlerror();
        kins_note_tried(tried, triedlen, path, why ? why : "dlopen failed");
        return NULL;
    }
    dlerror();
    const struct kins_ops *ops = (const struct kins_ops *)dlsym(h, sym);
    if (!ops || !ops->create) {
        char why[KINS_NAME_MAX + 32];
        snprintf(why, sizeof why, "no symbol %s", sym);
        kins_note_tried(tried, triedlen, path, why);
        dlclose(h);
        return NULL;
    }
    *handle = h;
    return ops;
}

/* Finds kinematics `name` as a shared object along the search path (see kins.h). */
const struct kins_ops *kins_find(const char *name, void **handle, char *err, size_t errlen)
{
    if (err && errlen)
        err[0] = '\0';
    size_t nlen = name ? strlen(name) : 0;
    if (!handle || nlen == 0 || nlen >= KINS_NAME_MAX || strchr(name, '/') || name[0] == '.') {
        if (err && errlen)
            snprintf(err, errlen, "kinematics '%s': not a valid plugin name", name ? name : "");
        return NULL;
    }
    *handle = NULL;
    char sym[KINS_NAME_MAX + 16];
    snprintf(sym, sizeof sym, "kins_%s_ops", name);
    for (char *c = sym; *c; c++)
        if (*c == '-')
            *c = '_';

    char dirs[PLUGIN_DIRS_MAX][PATH_MAX];
    int ndirs = plugin_dirs(dirs, "kins");

    char tried[2048] = "";
    for (int i = 0; i < ndirs; i++) {
        const struct kins_ops *ops = kins_try_dir(dirs[i], name, sym, handle, tried, sizeof tried);
        if (ops)
            return ops;
    }
    if (err && errlen)
        snprintf(err, errlen, "kinematics plugin '%s' not found; tried: %s", name, tried);
    return NULL;
}

/* Loads a plugin by name and creates an instance that owns the plugin handle. */
int kins_load(const char *name, const struct kins_config *cfg, struct kins **out,
              char *err, size_t errlen)
{
    if (out)
        *out = NULL;
    void *handle = NULL;
    const struct kins_ops *ops = kins_find(name, &handle, err, errlen);
    if (!ops)
        return KINS_ERR_PLUGIN;
    int st = kins_create(ops, cfg, out, err, errlen);
    if (st != KINS_OK) {
        dlclose(handle);
        return st;
    }
    (*out)->plugin_handle = handle;
    return KINS_OK;
}

/* Destroys an instance, then closes the plugin its code lives in. */
void kins_free(struct kins *k)
{
    if (!k)
        return;
    void *handle = k->plugin_handle;
    k->ops->destroy(k);
    if (handle)
        dlclose(handle);
}

int kins_describe(struct kins *k, const double *pose, char *msg, size_t len)
{
    if (msg && len)
        msg[0] = '\0';
    if (!k->ops->describe)
        return KINS_OK;
    return k->ops->describe(k, pose, msg, len);
}

void kins_inverse4(struct kins *k, const double (*pose)[KINS_POSE_DIM],
                   double (*joints)[KINS_MAX_JOINTS], int *status)
{
    if (k->ops->inverse4) {
        k->ops->inverse4(k, pose, joints, status);
        return;
    }
    for (int l = 0; l < 4; l++)
        status[l] = k->ops->inverse(k, pose[l], joints[l]);
}

void kins_inverse_path4(struct kins *k, const double (*pose)[KINS_POSE_DIM],
                        const double (*dpose)[KINS_POSE_DIM],
                        const double (*d2pose)[KINS_POSE_DIM], double (*joints)[KINS_MAX_JOINTS],
                        double (*djoints)[KINS_MAX_JOINTS], double (*d2joints)[KINS_MAX_JOINTS],
                        int *status)
{
    if (k->ops->inverse_path4) {
        k->ops->inverse_path4(k, pose, dpose, d2pose, joints, djoints, d2joints, status);
        return;
    }
    for (int l = 0; l < 4; l++)
        status[l] = k->ops->inverse_path(k, pose[l], dpose[l], d2pose[l], joints[l], djoints[l],
                                         d2joints[l]);
}
