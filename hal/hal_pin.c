/* hal_pin.c: pins, parameters and signals: creation, linking (`net`), unlinking. */
#include <stdlib.h>
#include <string.h>

#include "hal/hal_priv.h"

/* Points the component's data pointer at d (the pin's own storage or a signal's). */
static void hal_pin_point(struct hal_pin *p, union hal_data *d)
{
    switch (p->type) {
    case HAL_BIT: *(bool **)p->owner_ptr = &d->b; break;
    case HAL_FLOAT: *(double **)p->owner_ptr = &d->f; break;
    case HAL_S32: *(int32_t **)p->owner_ptr = &d->s; break;
    case HAL_U32: *(uint32_t **)p->owner_ptr = &d->u; break;
    }
}

/* Creates a pin of any type; the public typed functions wrap it. */
static int hal_pin_vnew(struct hal *h, enum hal_type type, enum hal_dir dir, void *pp,
                        const char *fmt, va_list ap)
{
    char name[HAL_NAME_MAX];
    int st = hal_vformat_name(h, name, sizeof name, fmt, ap);
    if (st != HAL_OK)
        return st;
    if (!pp || dir < HAL_IN || dir > HAL_IO)
        return hal_error(h, HAL_ERR_ARG, "pin '%s': bad direction or NULL pointer", name);
    if (hal_map_get(&h->pins, name) || hal_map_get(&h->params, name))
        return hal_error(h, HAL_ERR_EXISTS, "pin '%s' already exists", name);
    struct hal_pin *p = calloc(1, sizeof *p);
    if (!p || !(p->name = hal_strdup(name)))
        goto nomem;
    p->type = type;
    p->dir = dir;
    p->owner_ptr = pp;
    p->owner = h->owner;
    if (hal_vec_push(&h->pin_list, p) != HAL_OK)
        goto nomem;
    if (hal_map_put(&h->pins, p->name, p) != HAL_OK) {
        hal_vec_remove(&h->pin_list, p);
        goto nomem;
    }
    hal_pin_point(p, &p->own);
    return HAL_OK;
nomem:
    if (p)
        free(p->name);
    free(p);
    return hal_error(h, HAL_ERR_NOMEM, "out of memory creating pin '%s'", name);
}

#define HAL_PIN_NEWF(fname, ctype, htype)                                                  \
    int fname(struct hal *h, enum hal_dir dir, ctype **pp, const char *fmt, ...)           \
    {                                                                                      \
        va_list ap;                                                                        \
        va_start(ap, fmt);                                                                 \
        int st = hal_pin_vnew(h, htype, dir, pp, fmt, ap);                                 \
        va_end(ap);                                                                        \
        return st;                                                                         \
    }
/* Pin constructors by type: point *pp at the new pin's storage. */
HAL_PIN_NEWF(hal_pin_bit_newf, bool, HAL_BIT)
HAL_PIN_NEWF(hal_pin_float_newf, double, HAL_FLOAT)
HAL_PIN_NEWF(hal_pin_s32_newf, int32_t, HAL_S32)
HAL_PIN_NEWF(hal_pin_u32_newf, uint32_t, HAL_U32)

/* Creates a parameter on storage the instance owns. */
static int hal_param_vnew(struct hal *h, enum hal_type type, enum hal_pdir pdir, void *ptr,
                          const char *fmt, va_list ap)
{
    char name[HAL_NAME_MAX];
    int st = hal_vformat_name(h, name, sizeof name, fmt, ap);
    if (st != HAL_OK)
        return st;
    if (!ptr || (pdir != HAL_RO && pdir != HAL_RW))
        return hal_error(h, HAL_ERR_ARG, "parameter '%s': bad access or NULL pointer", name);
    if (hal_map_get(&h->pins, name) || hal_map_get(&h->params, name))
        return hal_error(h, HAL_ERR_EXISTS, "parameter '%s' already exists", name);
    struct hal_param *p = calloc(1, sizeof *p);
    if (!p || !(p->name = hal_strdup(name)))
        goto nomem;
    p->type = type;
    p->pdir = pdir;
    p->ptr = ptr;
    p->owner = h->owner;
    if (hal_vec_push(&h->param_list, p) != HAL_OK)
        goto nomem;
    if (hal_map_put(&h->params, p->name, p) != HAL_OK) {
        hal_vec_remove(&h->param_list, p);
        goto nomem;
    }
    return HAL_OK;
nomem:
    if (p)
        free(p->name);
    free(p);
    return hal_error(h, HAL_ERR_NOMEM, "out of memory creating parameter '%s'", name);
}

#define HAL_PARAM_NEWF(fname, ctype, htype)                                                \
    int fname(struct hal *h, enum hal_pdir dir, ctype *p, const char *fmt, ...)            \
    {                                                                                      \
        va_list ap;                                                                        \
        va_start(ap, fmt);                                                                 \
        int st = hal_param_vnew(h, htype, dir, p, fmt, ap);                                \
        va_end(ap);                                                                        \
        return st;                                                                         \
    }
/* Parameter constructors by type. */
HAL_PARAM_NEWF(hal_param_bit_newf, bool, HAL_BIT)
HAL_PARAM_NEWF(hal_param_float_newf, double, HAL_FLOAT)
HAL_PARAM_NEWF(hal_param_s32_newf, int32_t, HAL_S32)
HAL_PARAM_NEWF(hal_param_u32_newf, uint32_t, HAL_U32)

/* Drops a pin from its signal's counts, without touching the component's pointer. */
static void hal_sig_detach(struct hal_pin *p)
{
    struct hal_sig *s = p->sig;
    if (!s)
        return;
    if (s->writer == p)
        s->writer = NULL;
    else if (p->dir == HAL_IO)
        s->nio--;
    else
        s->nreaders--;
    p->sig = NULL;
}

/* Unlinks a pin; it keeps the signal's last value in its own storage. */
void hal_unlink_pin(struct hal_pin *p)
{
    if (!p->sig)
        return;
    p->own = p->sig->data;
    hal_sig_detach(p);
    hal_pin_point(p, &p->own);
}

/* Deletes a pin (its component is going away, so its pointer is left alone). */
void hal_pin_remove(struct hal *h, struct hal_pin *p)
{
    hal_sig_detach(p);
    hal_map_del(&h->pins, p->name);
    hal_vec_remove(&h->pin_list, p);
    free(p->name);
    free(p);
}

/* Deletes a parameter. */
void hal_param_remove(struct hal *h, struct hal_param *p)
{
    hal_map_del(&h->params, p->name);
    hal_vec_remove(&h->param_list, p);
    free(p->name);
    free(p);
}

/* Creates an unlinked signal. */
static struct hal_sig *hal_sig_new(struct hal *h, const char *name, enum hal_type type)
{
    struct hal_sig *s = calloc(1, sizeof *s);
    if (!s || !(s->name = hal_strdup(name)) || hal_vec_push(&h->sig_list, s) != HAL_OK)
        goto nomem;
    if (hal_map_put(&h->sigs, s->name, s) != HAL_OK) {
        hal_vec_remove(&h->sig_list, s);
        goto nomem;
    }
    s->type = type;
    return s;
nomem:
    if (s)
        free(s->name);
    free(s);
    hal_error(h, HAL_ERR_NOMEM, "out of memory creating signal '%s'", name);
    return NULL;
}

/* `newsig NAME TYPE`: a signal with no pins yet. */
int hal_newsig(struct hal *h, const char *name, enum hal_type type)
{
    if (hal_map_get(&h->sigs, name))
        return hal_error(h, HAL_ERR_EXISTS, "newsig: signal '%s' already exists", name);
    if (hal_map_get(&h->pins, name) || hal_map_get(&h->params, name))
        return hal_error(h, HAL_ERR_EXISTS, "newsig: '%s' is already a pin name", name);
    return hal_sig_new(h, name, type) ? HAL_OK : HAL_ERR_NOMEM;
}

/* Checks that every pin may join the signal (type, one writer, IO rules) before any does. */
static int hal_net_check(struct hal *h, const char *signal, struct hal_sig *s, int npins,
                         char **pins, enum hal_type *type)
{
    struct hal_pin *writer = s ? s->writer : NULL;
    int nio = s ? s->nio : 0;
    for (int i = 0; i < npins; i++) {
        struct hal_pin *p = hal_map_get(&h->pins, pins[i]);
        if (!p) {
            if (hal_map_get(&h->sigs, pins[i]))
                return hal_error(h, HAL_ERR_NOT_FOUND, "net: '%s' is a signal, not a pin; "
                                 "a signal cannot be connected to another signal", pins[i]);
            return hal_error(h, HAL_ERR_NOT_FOUND, "net: pin '%s' does not exist", pins[i]);
        }
        if (p->sig && strcmp(p->sig->name, signal))
            return hal_error(h, HAL_ERR_EXISTS, "net: pin '%s' is already connected to "
                             "signal '%s'", p->name, p->sig->name);
        if (i == 0 && !s)
            *type = p->type;
        if (p->type != *type)
            return hal_error(h, HAL_ERR_TYPE, "net: signal '%s' is %s but pin '%s' is %s",
                             signal, hal_type_name(*type), p->name, hal_type_name(p->type));
        if (p->sig || p == writer)       /* linked already, or named twice */
            continue;
        if (p->dir == HAL_OUT) {
            if (writer)
                return hal_error(h, HAL_ERR_DIR, "net: signal '%s' already has a writer "
                                 "'%s'; '%s' cannot also write it", signal, writer->name,
                                 p->name);
            if (nio)
                return hal_error(h, HAL_ERR_DIR, "net: signal '%s' has I/O pins; output "
                                 "pin '%s' cannot also write it", signal, p->name);
            writer = p;
        } else if (p->dir == HAL_IO) {
            if (writer)
                return hal_error(h, HAL_ERR_DIR, "net: signal '%s' already has a writer "
                                 "'%s'; I/O pin '%s' cannot also write it", signal,
                                 writer->name, p->name);
            nio++;
        }
    }
    return HAL_OK;
}

/* Links one pin; the signal takes the value of its first pin and of its writer. */
static void hal_link(struct hal_sig *s, struct hal_pin *p)
{
    bool first = !s->writer && !s->nreaders && !s->nio;
    if (first || p->dir == HAL_OUT)
        s->data = p->own;
    if (p->dir == HAL_OUT)
        s->writer = p;
    else if (p->dir == HAL_IO)
        s->nio++;
    else
        s->nreaders++;
    p->sig = s;
    hal_pin_point(p, &s->data);
}

/* `net SIGNAL pin...`: all pins join or none does. */
int hal_net(struct hal *h, const char *signal, int npins, char **pins)
{
    if (npins < 1)
        return hal_error(h, HAL_ERR_SYNTAX, "net: needs a signal name and at least one pin");
    if (hal_map_get(&h->pins, signal) || hal_map_get(&h->params, signal))
        return hal_error(h, HAL_ERR_SYNTAX, "net: '%s' is a pin; the first word after net "
                         "is the signal's name", signal);
    struct hal_sig *s = hal_map_get(&h->sigs, signal);
    enum hal_type type = s ? s->type : HAL_FLOAT;
    int st = hal_net_check(h, signal, s, npins, pins, &type);
    if (st != HAL_OK)
        return st;
    if (!s && !(s = hal_sig_new(h, signal, type)))
        return HAL_ERR_NOMEM;
    for (int i = 0; i < npins; i++) {
        struct hal_pin *p = hal_map_get(&h->pins, pins[i]);
        if (!p->sig)
            hal_link(s, p);
    }
    return HAL_OK;
}

/* `unlinkp PIN`. */
int hal_unlinkp(struct hal *h, const char *pin)
{
    struct hal_pin *p = hal_map_get(&h->pins, pin);
    if (!p)
        return hal_error(h, HAL_ERR_NOT_FOUND, "unlinkp: pin '%s' does not exist", pin);
    hal_unlink_pin(p);
    return HAL_OK;
}
