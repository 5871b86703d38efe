/* hal_load.c: `loadrt`: built-in types, plugins (<plugindir>/hal/NAME.so), kinematics, and
 * the loadrt argument helpers components share. */
#include <dlfcn.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "common/plugin_dirs.h"
#include "hal/hal_priv.h"
#include "kins/kins.h"

/* Runs a type's load inside a component record; a failure unwinds what it registered. */
static int hal_load_type(struct hal *h, const struct hal_comp_type *t, int argc, char **argv)
{
    int prev = h->owner;
    int id = hal_comp_begin(h, t->name);
    if (id < 0)
        return HAL_ERR_NOMEM;
    int st = t->load(h, argc, argv);
    hal_comp_end(h, prev);
    if (st != HAL_OK) {
        if (!h->err[0])
            hal_error(h, st, "loadrt %s: %s", t->name, hal_strerror(st));
        hal_comp_unwind(h, id);
    }
    return st;
}

/* dlclose as a cleanup. */
static void hal_dlclose_cb(void *handle)
{
    dlclose(handle);
}

/* Loads <dir>/hal/NAME.so and registers its type. 1 = no such file, else a status. */
static int hal_load_plugin(struct hal *h, const char *path, const char *name,
                           const struct hal_comp_type **out)
{
    if (access(path, F_OK) != 0)
        return 1;
    void *dl = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!dl)
        return hal_error(h, HAL_ERR_COMPONENT, "loadrt %s: cannot load %s: %s", name, path,
                         dlerror());
    char sym[HAL_NAME_MAX];
    snprintf(sym, sizeof sym, "hal_comp_%s", name);
    for (char *c = sym; *c; c++)
        if (*c == '-')
            *c = '_';
    const struct hal_comp_type *t = dlsym(dl, sym);
    if (!t || !t->name || strcmp(t->name, name)) {
        dlclose(dl);
        return hal_error(h, HAL_ERR_COMPONENT, "loadrt %s: %s does not export '%s' for a "
                         "component named '%s'", name, path, sym, name);
    }
    int prev = h->owner;
    h->owner = 0;
    int st = hal_on_destroy(h, hal_dlclose_cb, dl);
    h->owner = prev;
    if (st != HAL_OK) {
        dlclose(dl);
        return st;
    }
    *out = t;
    return hal_register_type(h, t);
}

static void hal_kins_free_cb(void *k)
{
    kins_free(k);
}

/* Creates the machine's kinematics from the INI, stores it as "kins" and loads the kins
 * component, all as one unit that unwinds on failure. */
static int hal_load_kins(struct hal *h, const char *name, int argc, char **argv)
{
    const struct hal_comp_type *t = hal_map_get(&h->types, "kins");
    if (!t)
        return hal_error(h, HAL_ERR_COMPONENT, "loadrt %s: the kins component is not built "
                         "in", name);
    if (hal_get_object(h, "kins"))
        return hal_error(h, HAL_ERR_EXISTS, "loadrt %s: a kinematics is already loaded; a "
                         "machine has one", name);
    struct kins_config cfg = { inifile_config_get, &h->ini };
    struct kins *k = NULL;
    char err[512], where[768];
    int kst = kins_load(name, &cfg, &k, err, sizeof err);
    if (kst != KINS_OK)   /* "[SECTION] KEY: ..." gets the INI file and the key's line */
        return hal_error(h, HAL_ERR_COMPONENT, "loadrt %s: %s", name,
                         inifile_locate_msg(&h->ini, err[0] ? err : kins_strerror(kst), where,
                                            sizeof where));
    int prev = h->owner;
    int id = hal_comp_begin(h, name);
    if (id < 0) {
        kins_free(k);
        return HAL_ERR_NOMEM;
    }
    int st = hal_on_destroy(h, hal_kins_free_cb, k);
    if (st != HAL_OK)
        kins_free(k);
    if (st == HAL_OK)
        st = hal_set_object(h, "kins", k);
    if (st == HAL_OK)
        st = t->load(h, argc, argv);
    hal_comp_end(h, prev);
    if (st != HAL_OK)
        hal_comp_unwind(h, id);
    return st;
}

/* `loadrt NAME args...`. */
int hal_loadrt(struct hal *h, const char *name, int argc, char **argv)
{
    h->err[0] = '\0';
    const struct hal_comp_type *t = hal_map_get(&h->types, name);
    if (t)
        return hal_load_type(h, t, argc, argv);
    if (!*name || strlen(name) > 64 || strchr(name, '/'))
        return hal_error(h, HAL_ERR_ARG, "loadrt: '%s' is not a component name", name);
    char dirs[PLUGIN_DIRS_MAX][PATH_MAX];
    char tried[PLUGIN_DIRS_MAX * (PATH_MAX + 2)] = "";
    int ndirs = plugin_dirs(dirs, "hal");
    for (int i = 0; i < ndirs; i++) {
        char path[PATH_MAX + 80];
        if (snprintf(path, sizeof path, "%s/%s.so", dirs[i], name) >= (int)sizeof path)
            continue;
        int st = hal_load_plugin(h, path, name, &t);
        if (st == HAL_OK)
            return hal_load_type(h, t, argc, argv);
        if (st != 1)
            return st;
        size_t used = strlen(tried);
        if (snprintf(tried + used, sizeof tried - used, "%s%s", used ? ", " : "", path) < 0)
            break;
    }
    void *dl = NULL;
    char err[512];
    if (kins_find(name, &dl, err, sizeof err)) {
        if (dl)
            dlclose(dl);
        return hal_load_kins(h, name, argc, argv);
    }
    return hal_error(h, HAL_ERR_NOT_FOUND, "loadrt: no component '%s': it is not built in, "
                     "no plugin at %s, and no kinematics of that name (%s)", name, tried, err);
}

/* The VALUE of KEY=VALUE among loadrt's arguments, or NULL. */
const char *hal_arg(int argc, char **argv, const char *key)
{
    size_t n = strlen(key);
    for (int i = 0; i < argc; i++)
        if (!strncmp(argv[i], key, n) && argv[i][n] == '=')
            return argv[i] + n + 1;
    return NULL;
}

/* Every argument must be KEY=VALUE with KEY in the comma-separated list `known`. */
int hal_args_check(struct hal *h, const char *comp, int argc, char **argv, const char *known)
{
    for (int i = 0; i < argc; i++) {
        const char *eq = strchr(argv[i], '=');
        size_t n = eq ? (size_t)(eq - argv[i]) : 0;
        bool ok = false;
        for (const char *k = known; eq && n && *k;) {
            size_t kl = strcspn(k, ",");
            if (kl == n && !strncmp(k, argv[i], n))
                ok = true;
            k += kl + (k[kl] == ',');
        }
        if (!ok && !*known)
            return hal_error(h, HAL_ERR_ARG, "loadrt %s: unknown argument '%s' (it takes "
                             "none)", comp, argv[i]);
        if (!ok)
            return hal_error(h, HAL_ERR_ARG, "loadrt %s: unknown argument '%s' (it takes %s)",
                             comp, argv[i], known);
    }
    return HAL_OK;
}

/* Instance names from count=N (comp.0 .. comp.N-1) or names=a,b,c; one by default. */
int hal_arg_instances(struct hal *h, const char *comp, int argc, char **argv, int max,
                      char (*names)[HAL_INST_NAME_MAX], int *count)
{
    const char *cnt = hal_arg(argc, argv, "count");
    const char *nms = hal_arg(argc, argv, "names");
    *count = 0;
    if (cnt && nms)
        return hal_error(h, HAL_ERR_ARG, "loadrt %s: give count= or names=, not both", comp);
    if (nms) {
        for (const char *p = nms; *p;) {
            size_t n = strcspn(p, ",");
            if (n == 0 || n >= HAL_INST_NAME_MAX || *count >= max)
                return hal_error(h, HAL_ERR_ARG, "loadrt %s: names=%s: empty or too long "
                                 "name, or more than %d", comp, nms, max);
            memcpy(names[*count], p, n);
            names[(*count)++][n] = '\0';
            p += n + (p[n] == ',');
        }
        return HAL_OK;
    }
    long n = 1;
    if (cnt) {
        char *end;
        n = strtol(cnt, &end, 10);
        if (end == cnt || *end || n < 1 || n > max)
            return hal_error(h, HAL_ERR_ARG, "loadrt %s: count=%s must be a whole number "
                             "from 1 to %d", comp, cnt, max);
    }
    for (int i = 0; i < n; i++)
        snprintf(names[i], HAL_INST_NAME_MAX, "%s.%d", comp, i);
    *count = (int)n;
    return HAL_OK;
}

/* `loadrt threads name1=servo-thread period1=1000000 [name2=... period2=...]`. */
static int hal_threads_load(struct hal *h, int argc, char **argv)
{
    int made = 0;
    for (int i = 1; i <= 9; i++) {
        char nk[24], pk[24];  /* "period" and any int fit */
        snprintf(nk, sizeof nk, "name%d", i);
        snprintf(pk, sizeof pk, "period%d", i);
        const char *name = hal_arg(argc, argv, nk), *per = hal_arg(argc, argv, pk);
        if (!name && !per)
            continue;
        if (!name || !per)
            return hal_error(h, HAL_ERR_ARG, "loadrt threads: %s= needs %s=", name ? nk : pk,
                             name ? pk : nk);
        char *end;
        long period_ns = strtol(per, &end, 10);
        if (end == per || *end || period_ns <= 0)
            return hal_error(h, HAL_ERR_ARG, "loadrt threads: %s=%s is not a positive "
                             "number of nanoseconds", pk, per);
        int st = hal_thread_new(h, name, period_ns);
        if (st != HAL_OK)
            return st;
        made++;
    }
    for (int i = 0; i < argc; i++)
        if (strncmp(argv[i], "name", 4) && strncmp(argv[i], "period", 6) &&
            strncmp(argv[i], "fp", 2))
            return hal_error(h, HAL_ERR_ARG, "loadrt threads: unknown argument '%s' (it takes "
                             "nameN=, periodN=, fpN=)", argv[i]);
    if (!made)
        return hal_error(h, HAL_ERR_ARG, "loadrt threads: give name1= and period1= (ns)");
    return HAL_OK;
}

const struct hal_comp_type hal_comp_threads = { "threads", hal_threads_load };
