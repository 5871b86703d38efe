/* hal_core.c: the runtime's lifetime, errors, component records and their unwinding. */
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "hal/hal_priv.h"

/* The built-in component types, listed by HAL_COMPS in the module.mk files. */
#define HAL_COMP(n) extern const struct hal_comp_type hal_comp_##n;
#include "hal_comps.h"
#undef HAL_COMP
extern const struct hal_comp_type hal_comp_threads;

static const struct hal_comp_type *const hal_builtin_types[] = {
#define HAL_COMP(n) &hal_comp_##n,
#include "hal_comps.h"
#undef HAL_COMP
    &hal_comp_threads,
    NULL
};

static const char *const hal_status_text[HAL_STATUS_COUNT] = {
    [HAL_OK] = "success",
    [HAL_ERR_NOMEM] = "out of memory",
    [HAL_ERR_EXISTS] = "name already exists",
    [HAL_ERR_NOT_FOUND] = "not found",
    [HAL_ERR_TYPE] = "type mismatch",
    [HAL_ERR_DIR] = "direction or writer conflict",
    [HAL_ERR_SYNTAX] = "syntax error",
    [HAL_ERR_ARG] = "bad argument",
    [HAL_ERR_STATE] = "not allowed in this state",
    [HAL_ERR_COMPONENT] = "component failed to load",
    [HAL_ERR_IO] = "file could not be read",
    [HAL_ERR_RT] = "thread creation or scheduling failed",
};

/* Text of a status code. */
const char *hal_strerror(int status)
{
    if (status < 0 || status >= HAL_STATUS_COUNT)
        return "unknown HAL status";
    return hal_status_text[status];
}

/* strdup that the strict C11 mode does not hide. */
char *hal_strdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

/* A new runtime with every built-in component type registered. */
struct hal *hal_create(void)
{
    struct hal *h = calloc(1, sizeof *h);
    if (!h)
        return NULL;
    h->next_comp_id = 1;
    if (hal_msg_init(h) != HAL_OK) {
        free(h);
        return NULL;
    }
    for (int i = 0; hal_builtin_types[i]; i++) {
        if (hal_register_type(h, hal_builtin_types[i]) != HAL_OK) {
            hal_destroy(h);
            return NULL;
        }
    }
    return h;
}

/* Runs and drops the cleanups of one owner (all owners when id < 0), newest first. */
static void hal_run_cleanups(struct hal *h, int id)
{
    for (int i = h->cleanup_list.n - 1; i >= 0; i--) {
        struct hal_cleanup *c = h->cleanup_list.v[i];
        if (id >= 0 && c->owner != id)
            continue;
        c->fn(c->arg);
        hal_vec_remove(&h->cleanup_list, c);
        free(c);
    }
}

/* Stops threads, runs the cleanups, frees everything. */
void hal_destroy(struct hal *h)
{
    if (!h)
        return;
    hal_stop(h);
    hal_run_cleanups(h, -1);
    hal_msg_free(h);
    hal_threads_free(h);
    while (h->funct_list.n)
        hal_funct_remove(h, h->funct_list.v[h->funct_list.n - 1]);
    while (h->pin_list.n)
        hal_pin_remove(h, h->pin_list.v[h->pin_list.n - 1]);
    while (h->param_list.n)
        hal_param_remove(h, h->param_list.v[h->param_list.n - 1]);
    for (int i = 0; i < h->sig_list.n; i++) {
        struct hal_sig *s = h->sig_list.v[i];
        free(s->name);
        free(s);
    }
    for (int i = 0; i < h->comp_list.n; i++) {
        struct hal_comp *c = h->comp_list.v[i];
        free(c->name);
        free(c);
    }
    for (int i = 0; i < h->object_list.n; i++) {
        struct hal_object *o = h->object_list.v[i];
        free(o->name);
        free(o);
    }
    struct hal_map *maps[] = { &h->pins, &h->params, &h->sigs, &h->functs, &h->threads,
                               &h->types, &h->objects };
    for (size_t i = 0; i < sizeof maps / sizeof maps[0]; i++)
        hal_map_free(maps[i]);
    struct hal_vec *vecs[] = { &h->pin_list, &h->param_list, &h->sig_list, &h->funct_list,
                               &h->thread_list, &h->comp_list, &h->cleanup_list,
                               &h->object_list, &h->type_list };
    for (size_t i = 0; i < sizeof vecs / sizeof vecs[0]; i++)
        hal_vec_free(vecs[i]);
    hal_ini_free(h);
    free(h);
}

/* The last error message. */
const char *hal_last_error(const struct hal *h)
{
    return h->err;
}

/* Sets the last error message and returns status. */
int hal_error(struct hal *h, int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(h->err, sizeof h->err, fmt, ap);
    va_end(ap);
    h->err_located = false;
    return status;
}

/* Formats an object name; too long a name is an error rather than a silent cut. */
int hal_vformat_name(struct hal *h, char *buf, size_t len, const char *fmt, va_list ap)
{
    int n = vsnprintf(buf, len, fmt, ap);
    if (n < 0 || (size_t)n >= len)
        return hal_error(h, HAL_ERR_ARG, "name '%.40s...' is longer than %zu characters",
                         buf, len - 1);
    if (n == 0)
        return hal_error(h, HAL_ERR_ARG, "empty name");
    return HAL_OK;
}

/* Adds a component type that `loadrt NAME` can create. */
int hal_register_type(struct hal *h, const struct hal_comp_type *t)
{
    if (!t || !t->name || !t->load)
        return hal_error(h, HAL_ERR_ARG, "component type without a name or load function");
    if (hal_map_get(&h->types, t->name))
        return hal_error(h, HAL_ERR_EXISTS, "component type '%s' is already registered",
                         t->name);
    if (hal_vec_push(&h->type_list, (void *)t) != HAL_OK)
        return hal_error(h, HAL_ERR_NOMEM, "out of memory");
    if (hal_map_put(&h->types, t->name, (void *)t) != HAL_OK) {
        hal_vec_remove(&h->type_list, (void *)t);
        return hal_error(h, HAL_ERR_NOMEM, "out of memory");
    }
    return HAL_OK;
}

/* Registers a cleanup run at hal_destroy, or when the loading component fails. */
int hal_on_destroy(struct hal *h, void (*fn)(void *arg), void *arg)
{
    struct hal_cleanup *c = malloc(sizeof *c);
    if (!c || hal_vec_push(&h->cleanup_list, c) != HAL_OK) {
        free(c);
        return hal_error(h, HAL_ERR_NOMEM, "out of memory registering a cleanup");
    }
    c->fn = fn;
    c->arg = arg;
    c->owner = h->owner;
    return HAL_OK;
}

/* Stores a named object for other components and the shell. */
int hal_set_object(struct hal *h, const char *name, void *obj)
{
    if (hal_map_get(&h->objects, name))
        return hal_error(h, HAL_ERR_EXISTS, "object '%s' already exists", name);
    struct hal_object *o = calloc(1, sizeof *o);
    if (!o || !(o->name = hal_strdup(name)))
        goto fail;
    o->obj = obj;
    o->owner = h->owner;
    if (hal_vec_push(&h->object_list, o) != HAL_OK)
        goto fail;
    if (hal_map_put(&h->objects, o->name, o) != HAL_OK) {
        hal_vec_remove(&h->object_list, o);
        goto fail;
    }
    return HAL_OK;
fail:
    if (o)
        free(o->name);
    free(o);
    return hal_error(h, HAL_ERR_NOMEM, "out of memory");
}

/* A named object, or NULL. */
void *hal_get_object(const struct hal *h, const char *name)
{
    struct hal_object *o = hal_map_get(&h->objects, name);
    return o ? o->obj : NULL;
}

/* Opens a component record; what is registered until hal_comp_end belongs to it. Returns
 * its id (> 0) or a negative value when out of memory. */
int hal_comp_begin(struct hal *h, const char *name)
{
    struct hal_comp *c = calloc(1, sizeof *c);
    if (!c || !(c->name = hal_strdup(name)) || hal_vec_push(&h->comp_list, c) != HAL_OK) {
        if (c)
            free(c->name);
        free(c);
        hal_error(h, HAL_ERR_NOMEM, "out of memory loading '%s'", name);
        return -1;
    }
    c->id = h->next_comp_id++;
    h->owner = c->id;
    return c->id;
}

/* Closes the component record: later registrations belong to prev_owner again. */
void hal_comp_end(struct hal *h, int prev_owner)
{
    h->owner = prev_owner;
}

/* Undoes everything component `id` registered: cleanups (run), functs, pins, params,
 * objects, and the record itself. */
void hal_comp_unwind(struct hal *h, int id)
{
    hal_run_cleanups(h, id);
    for (int i = h->funct_list.n - 1; i >= 0; i--) {
        struct hal_funct *f = h->funct_list.v[i];
        if (f->owner == id)
            hal_funct_remove(h, f);
    }
    for (int i = h->pin_list.n - 1; i >= 0; i--) {
        struct hal_pin *p = h->pin_list.v[i];
        if (p->owner == id)
            hal_pin_remove(h, p);
    }
    for (int i = h->param_list.n - 1; i >= 0; i--) {
        struct hal_param *p = h->param_list.v[i];
        if (p->owner == id)
            hal_param_remove(h, p);
    }
    for (int i = h->object_list.n - 1; i >= 0; i--) {
        struct hal_object *o = h->object_list.v[i];
        if (o->owner != id)
            continue;
        hal_map_del(&h->objects, o->name);
        hal_vec_remove(&h->object_list, o);
        free(o->name);
        free(o);
    }
    for (int i = h->comp_list.n - 1; i >= 0; i--) {
        struct hal_comp *c = h->comp_list.v[i];
        if (c->id != id)
            continue;
        hal_vec_remove(&h->comp_list, c);
        free(c->name);
        free(c);
    }
}
