/* hal_map.c: the name tables (chained hash) and pointer arrays behind every lookup. */
#include <stdlib.h>
#include <string.h>

#include "hal/hal_priv.h"

/* FNV-1a: short names, few collisions, no setup. */
static size_t hal_map_hash(const char *s)
{
    uint64_t hsh = 1469598103934665603ULL;
    for (; *s; s++)
        hsh = (hsh ^ (unsigned char)*s) * 1099511628211ULL;
    return (size_t)hsh;
}

/* Doubles the bucket array once the table averages one entry per bucket. */
static int hal_map_grow(struct hal_map *m)
{
    size_t nb = m->nbuckets ? m->nbuckets * 2 : 64;
    struct hal_map_node **b = calloc(nb, sizeof *b);
    if (!b)
        return HAL_ERR_NOMEM;
    for (size_t i = 0; i < m->nbuckets; i++) {
        struct hal_map_node *n = m->buckets[i], *next;
        for (; n; n = next) {
            next = n->next;
            size_t k = hal_map_hash(n->key) & (nb - 1);
            n->next = b[k];
            b[k] = n;
        }
    }
    free(m->buckets);
    m->buckets = b;
    m->nbuckets = nb;
    return HAL_OK;
}

/* Adds key -> val; the caller has checked that key is new. */
int hal_map_put(struct hal_map *m, const char *key, void *val)
{
    if (m->count >= m->nbuckets && hal_map_grow(m) != HAL_OK)
        return HAL_ERR_NOMEM;
    struct hal_map_node *n = malloc(sizeof *n);
    if (!n)
        return HAL_ERR_NOMEM;
    size_t k = hal_map_hash(key) & (m->nbuckets - 1);
    n->key = key;
    n->val = val;
    n->next = m->buckets[k];
    m->buckets[k] = n;
    m->count++;
    return HAL_OK;
}

/* The value stored under key, or NULL. */
void *hal_map_get(const struct hal_map *m, const char *key)
{
    if (!m->nbuckets || !key)
        return NULL;
    for (struct hal_map_node *n = m->buckets[hal_map_hash(key) & (m->nbuckets - 1)]; n;
         n = n->next)
        if (!strcmp(n->key, key))
            return n->val;
    return NULL;
}

/* Removes key if present. */
void hal_map_del(struct hal_map *m, const char *key)
{
    if (!m->nbuckets)
        return;
    struct hal_map_node **pp = &m->buckets[hal_map_hash(key) & (m->nbuckets - 1)];
    for (; *pp; pp = &(*pp)->next) {
        if (!strcmp((*pp)->key, key)) {
            struct hal_map_node *n = *pp;
            *pp = n->next;
            free(n);
            m->count--;
            return;
        }
    }
}

/* Frees the table (not the values). */
void hal_map_free(struct hal_map *m)
{
    for (size_t i = 0; i < m->nbuckets; i++) {
        struct hal_map_node *n = m->buckets[i], *next;
        for (; n; n = next) {
            next = n->next;
            free(n);
        }
    }
    free(m->buckets);
    memset(m, 0, sizeof *m);
}

/* Appends p. */
int hal_vec_push(struct hal_vec *vec, void *p)
{
    if (vec->n == vec->cap) {
        int cap = vec->cap ? vec->cap * 2 : 16;
        void **v = realloc(vec->v, (size_t)cap * sizeof *v);
        if (!v)
            return HAL_ERR_NOMEM;
        vec->v = v;
        vec->cap = cap;
    }
    vec->v[vec->n++] = p;
    return HAL_OK;
}

/* Removes p, keeping the order of the rest. */
void hal_vec_remove(struct hal_vec *vec, void *p)
{
    for (int i = 0; i < vec->n; i++) {
        if (vec->v[i] == p) {
            memmove(&vec->v[i], &vec->v[i + 1], (size_t)(vec->n - i - 1) * sizeof *vec->v);
            vec->n--;
            return;
        }
    }
}

/* Frees the array (not the elements). */
void hal_vec_free(struct hal_vec *vec)
{
    free(vec->v);
    memset(vec, 0, sizeof *vec);
}
