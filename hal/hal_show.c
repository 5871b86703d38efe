/* hal_show.c: `show [pin|sig|param|funct|thread|comp|all] [pattern]` listings. */
#include <fnmatch.h>
#include <stdlib.h>
#include <string.h>

#include "hal/hal_priv.h"

/* A pattern with * ? [ is a glob; otherwise it matches names that start with it. */
static bool hal_match(const char *pattern, const char *name)
{
    if (!pattern)
        return true;
    if (strpbrk(pattern, "*?["))
        return fnmatch(pattern, name, 0) == 0;
    return !strncmp(pattern, name, strlen(pattern));
}

/* Every object struct here starts with `char *name`. */
static int hal_by_name(const void *a, const void *b)
{
    return strcmp(**(char *const *const *)a, **(char *const *const *)b);
}

/* A name-sorted copy of a list (NULL when empty or out of memory; n set to 0 then). */
static void **hal_sorted(const struct hal_vec *vec, int *n)
{
    *n = vec->n;
    void **v = vec->n ? malloc((size_t)vec->n * sizeof *v) : NULL;
    if (!v) {
        *n = 0;
        return NULL;
    }
    memcpy(v, vec->v, (size_t)vec->n * sizeof *v);
    qsort(v, (size_t)vec->n, sizeof *v, hal_by_name);
    return v;
}

/* The arrow halcmd draws from a pin to its signal. */
static const char *hal_arrow(enum hal_dir dir)
{
    return dir == HAL_IN ? "<==" : dir == HAL_OUT ? "==>" : "<=>";
}

static void hal_show_pins(struct hal *h, FILE *out, const char *pattern)
{
    int n;
    void **v = hal_sorted(&h->pin_list, &n);
    char val[64];
    fprintf(out, "Component Pins:\n  Type  Dir          Value  Name\n");
    for (int i = 0; i < n; i++) {
        struct hal_pin *p = v[i];
        if (!hal_match(pattern, p->name))
            continue;
        hal_format_value(p->type, p->sig ? &p->sig->data : &p->own, val, sizeof val);
        fprintf(out, "  %-5s %-3s %14s  %s", hal_type_name(p->type), hal_dir_name(p->dir), val,
                p->name);
        if (p->sig)
            fprintf(out, " %s %s", hal_arrow(p->dir), p->sig->name);
        fputc('\n', out);
    }
    free(v);
}

static void hal_show_params(struct hal *h, FILE *out, const char *pattern)
{
    int n;
    void **v = hal_sorted(&h->param_list, &n);
    char val[64];
    fprintf(out, "Parameters:\n  Type  Dir          Value  Name\n");
    for (int i = 0; i < n; i++) {
        struct hal_param *p = v[i];
        if (!hal_match(pattern, p->name))
            continue;
        hal_format_value(p->type, p->ptr, val, sizeof val);
        fprintf(out, "  %-5s %-3s %14s  %s\n", hal_type_name(p->type),
                p->pdir == HAL_RO ? "RO" : "RW", val, p->name);
    }
    free(v);
}

static void hal_show_sigs(struct hal *h, FILE *out, const char *pattern)
{
    int n, np;
    void **v = hal_sorted(&h->sig_list, &n);
    void **pins = hal_sorted(&h->pin_list, &np);
    char val[64];
    fprintf(out, "Signals:\n  Type           Value  Name  (linked to)\n");
    for (int i = 0; i < n; i++) {
        struct hal_sig *s = v[i];
        if (!hal_match(pattern, s->name))
            continue;
        hal_format_value(s->type, &s->data, val, sizeof val);
        fprintf(out, "  %-5s %14s  %s\n", hal_type_name(s->type), val, s->name);
        if (s->writer)          /* the writer first, then readers and I/O pins by name */
            fprintf(out, "%26s %s\n", "<==", s->writer->name);
        for (int k = 0; k < np; k++) {
            struct hal_pin *p = pins[k];
            if (p->sig == s && p != s->writer)
                fprintf(out, "%26s %s\n", p->dir == HAL_IN ? "==>" : "<=>", p->name);
        }
    }
    free(pins);
    free(v);
}

static void hal_show_functs(struct hal *h, FILE *out, const char *pattern)
{
    int n;
    void **v = hal_sorted(&h->funct_list, &n);
    fprintf(out, "Exported Functions:\n  Thread            Name\n");
    for (int i = 0; i < n; i++) {
        struct hal_funct *f = v[i];
        if (hal_match(pattern, f->name))
            fprintf(out, "  %-16s  %s\n", f->thread ? f->thread->name : "(none)", f->name);
    }
    free(v);
}

static void hal_show_threads(struct hal *h, FILE *out, const char *pattern)
{
    fprintf(out, "Threads:\n     Period_ns  Name  (time_ns, tmax_ns, overruns)\n");
    for (int i = 0; i < h->thread_list.n; i++) {
        struct hal_thread *t = h->thread_list.v[i];
        if (!hal_match(pattern, t->name))
            continue;
        fprintf(out, "  %12ld  %s  (%d, %d, %u)\n", t->period_ns, t->name, (int)*t->time_ns,
                (int)*t->tmax_ns, (unsigned)*t->overruns);
        for (int k = 0; k < t->nfuncts; k++)
            fprintf(out, "  %16d %s\n", k + 1, t->functs[k]->name);
    }
}

static void hal_show_comps(struct hal *h, FILE *out, const char *pattern)
{
    fprintf(out, "Loaded Components:\n    ID  Name\n");
    for (int i = 0; i < h->comp_list.n; i++) {
        struct hal_comp *c = h->comp_list.v[i];
        if (hal_match(pattern, c->name))
            fprintf(out, "  %4d  %s\n", c->id, c->name);
    }
}

/* `show`: one section, or all of them. */
int hal_show(struct hal *h, FILE *out, const char *what, const char *pattern)
{
    static const struct {
        const char *name, *alias;
        void (*fn)(struct hal *h, FILE *out, const char *pattern);
    } sections[] = {
        { "comp", "comps", hal_show_comps },
        { "pin", "pins", hal_show_pins },
        { "param", "parameter", hal_show_params },
        { "sig", "signal", hal_show_sigs },
        { "funct", "function", hal_show_functs },
        { "thread", "threads", hal_show_threads },
    };
    bool all = !what || !strcmp(what, "all");
    bool found = all;
    if (!out)
        out = stdout;
    for (size_t i = 0; i < sizeof sections / sizeof sections[0]; i++) {
        if (all || !strcmp(what, sections[i].name) || !strcmp(what, sections[i].alias)) {
            sections[i].fn(h, out, pattern);
            found = true;
            if (all)
                fputc('\n', out);
        }
    }
    if (!found)
        return hal_error(h, HAL_ERR_SYNTAX, "show: unknown section '%s' (pin, sig, param, "
                         "funct, thread, comp or all)", what);
    return HAL_OK;
}
