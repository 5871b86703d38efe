/* hal_value.c: values as text (halcmd's setp, getp, sets, gets) and access by name. */
#include <errno.h>
#include <inttypes.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "common/config.h"
#include "hal/hal_priv.h"

/* Lower-case type name as halcmd shows it. */
const char *hal_type_name(enum hal_type type)
{
    switch (type) {
    case HAL_BIT: return "bit";
    case HAL_FLOAT: return "float";
    case HAL_S32: return "s32";
    case HAL_U32: return "u32";
    }
    return "?";
}

/* Direction name as halcmd shows it. */
const char *hal_dir_name(enum hal_dir dir)
{
    switch (dir) {
    case HAL_IN: return "IN";
    case HAL_OUT: return "OUT";
    case HAL_IO: return "I/O";
    }
    return "?";
}

/* Parses halcmd's text for a value of `type`. */
int hal_parse_value(enum hal_type type, const char *text, union hal_data *out)
{
    char *end;
    errno = 0;
    switch (type) {
    case HAL_BIT:
        if (!strcmp(text, "1") || !strcasecmp(text, "TRUE"))
            out->b = true;
        else if (!strcmp(text, "0") || !strcasecmp(text, "FALSE"))
            out->b = false;
        else
            return HAL_ERR_SYNTAX;
        return HAL_OK;
    case HAL_FLOAT:   /* the configuration's number rules: finite, decimal, nothing after */
        return config_parse_number(text, &out->f, NULL, 0) == 0 ? HAL_OK : HAL_ERR_SYNTAX;
    case HAL_S32: {
        long long v = strtoll(text, &end, 0);
        if (end == text || *end || errno == ERANGE || v < INT32_MIN || v > INT32_MAX)
            return HAL_ERR_SYNTAX;
        out->s = (int32_t)v;
        return HAL_OK;
    }
    case HAL_U32: {
        while (*text == ' ')
            text++;
        unsigned long long v = strtoull(text, &end, 0);
        if (*text == '-' || end == text || *end || errno == ERANGE || v > UINT32_MAX)
            return HAL_ERR_SYNTAX;
        out->u = (uint32_t)v;
        return HAL_OK;
    }
    }
    return HAL_ERR_SYNTAX;
}

/* Formats a value as halcmd shows it (bits TRUE/FALSE, floats %.9g). */
void hal_format_value(enum hal_type type, const void *data, char *buf, size_t len)
{
    switch (type) {
    case HAL_BIT: snprintf(buf, len, "%s", *(const bool *)data ? "TRUE" : "FALSE"); break;
    case HAL_FLOAT: snprintf(buf, len, "%.9g", *(const double *)data); break;
    case HAL_S32: snprintf(buf, len, "%" PRId32, *(const int32_t *)data); break;
    case HAL_U32: snprintf(buf, len, "%" PRIu32, *(const uint32_t *)data); break;
    default: snprintf(buf, len, "?"); break;
    }
}

/* Stores a value of `type` at dst. */
static void hal_store(enum hal_type type, void *dst, const union hal_data *v)
{
    switch (type) {
    case HAL_BIT: *(bool *)dst = v->b; break;
    case HAL_FLOAT: *(double *)dst = v->f; break;
    case HAL_S32: *(int32_t *)dst = v->s; break;
    case HAL_U32: *(uint32_t *)dst = v->u; break;
    }
}

/* The error for text that is not a value of `type`. */
static int hal_bad_value(struct hal *h, const char *cmd, const char *text, enum hal_type type,
                         const char *name)
{
    if (type == HAL_BIT)
        return hal_error(h, HAL_ERR_SYNTAX, "%s: '%s' is not a bit value (0, 1, TRUE or "
                         "FALSE) for '%s'", cmd, text, name);
    return hal_error(h, HAL_ERR_SYNTAX, "%s: '%s' is not a valid %s number for '%s'", cmd,
                     text, hal_type_name(type), name);
}

/* Current data of a pin, parameter or (as a convenience) signal. */
void *hal_data_ptr(struct hal *h, const char *name, enum hal_type *type)
{
    struct hal_pin *p = hal_map_get(&h->pins, name);
    if (p) {
        if (type)
            *type = p->type;
        return p->sig ? &p->sig->data : &p->own;
    }
    struct hal_param *pa = hal_map_get(&h->params, name);
    if (pa) {
        if (type)
            *type = pa->type;
        return pa->ptr;
    }
    struct hal_sig *s = hal_map_get(&h->sigs, name);
    if (s) {
        if (type)
            *type = s->type;
        return &s->data;
    }
    return NULL;
}

/* `setp NAME VALUE` on an unconnected input/IO pin or a writable parameter. */
int hal_setp(struct hal *h, const char *name, const char *value)
{
    union hal_data v;
    struct hal_pin *p = hal_map_get(&h->pins, name);
    if (p) {
        if (p->dir == HAL_OUT)
            return hal_error(h, HAL_ERR_DIR, "setp: pin '%s' is an output; its component "
                             "writes it", name);
        if (p->sig)
            return hal_error(h, HAL_ERR_DIR, "setp: pin '%s' is connected to signal '%s'; "
                             "set the signal with sets", name, p->sig->name);
        if (hal_parse_value(p->type, value, &v) != HAL_OK)
            return hal_bad_value(h, "setp", value, p->type, name);
        hal_store(p->type, &p->own, &v);
        return HAL_OK;
    }
    struct hal_param *pa = hal_map_get(&h->params, name);
    if (!pa)
        return hal_error(h, HAL_ERR_NOT_FOUND, "setp: no pin or parameter '%s'", name);
    if (pa->pdir == HAL_RO)
        return hal_error(h, HAL_ERR_DIR, "setp: parameter '%s' is read-only", name);
    if (hal_parse_value(pa->type, value, &v) != HAL_OK)
        return hal_bad_value(h, "setp", value, pa->type, name);
    hal_store(pa->type, pa->ptr, &v);
    return HAL_OK;
}

/* `getp NAME`: a pin's or parameter's value as text. */
int hal_getp(struct hal *h, const char *name, char *buf, size_t len)
{
    enum hal_type type;
    void *d = NULL;
    if (hal_map_get(&h->pins, name) || hal_map_get(&h->params, name))
        d = hal_data_ptr(h, name, &type);
    if (!d)
        return hal_error(h, HAL_ERR_NOT_FOUND, "getp: no pin or parameter '%s'", name);
    hal_format_value(type, d, buf, len);
    return HAL_OK;
}

/* `sets SIGNAL VALUE` on a signal no output pin writes. */
int hal_sets(struct hal *h, const char *signal, const char *value)
{
    struct hal_sig *s = hal_map_get(&h->sigs, signal);
    union hal_data v;
    if (!s)
        return hal_error(h, HAL_ERR_NOT_FOUND, "sets: signal '%s' does not exist", signal);
    if (s->writer)
        return hal_error(h, HAL_ERR_DIR, "sets: signal '%s' is written by pin '%s'",
                         signal, s->writer->name);
    if (hal_parse_value(s->type, value, &v) != HAL_OK)
        return hal_bad_value(h, "sets", value, s->type, signal);
    hal_store(s->type, &s->data, &v);
    return HAL_OK;
}

/* `gets SIGNAL`. */
int hal_gets(struct hal *h, const char *signal, char *buf, size_t len)
{
    struct hal_sig *s = hal_map_get(&h->sigs, signal);
    if (!s)
        return hal_error(h, HAL_ERR_NOT_FOUND, "gets: signal '%s' does not exist", signal);
    hal_format_value(s->type, &s->data, buf, len);
    return HAL_OK;
}
