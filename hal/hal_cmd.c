/* hal_cmd.c: the HAL command language: comments, [SECTION]KEY substitution, words, commands,
 * and HAL files (`source`). */
#include <ctype.h>
#include <errno.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "hal/hal_priv.h"

#define HAL_LINE_MAX 4096
#define HAL_WORDS_MAX 128

/* Copies line into buf without its comment: `#` at the start or after a blank, outside
 * quotes. */
static void hal_strip_comment(const char *line, char *buf, size_t len)
{
    bool quoted = false;
    size_t n = 0;
    for (const char *c = line; *c && n + 1 < len; c++) {
        if (*c == '"')
            quoted = !quoted;
        if (*c == '#' && !quoted && (c == line || isspace((unsigned char)c[-1])))
            break;
        buf[n++] = *c;
    }
    buf[n] = '\0';
}

/* Replaces every [SECTION]KEY by its INI value; an unknown key is an error naming it. */
static int hal_substitute(struct hal *h, const char *in, char *out, size_t len)
{
    size_t n = 0;
    for (const char *c = in; *c;) {
        size_t sl = 0, kl = 0;
        if (*c == '[') {
            while (isalnum((unsigned char)c[1 + sl]) || c[1 + sl] == '_' || c[1 + sl] == '-')
                sl++;
            if (sl && c[1 + sl] == ']')
                while (isalnum((unsigned char)c[2 + sl + kl]) || c[2 + sl + kl] == '_')
                    kl++;
        }
        if (!kl) {
            if (n + 1 >= len)
                return hal_error(h, HAL_ERR_SYNTAX, "line longer than %zu characters", len);
            out[n++] = *c++;
            continue;
        }
        char sec[HAL_NAME_MAX], key[HAL_NAME_MAX];
        snprintf(sec, sizeof sec, "%.*s", (int)sl, c + 1);
        snprintf(key, sizeof key, "%.*s", (int)kl, c + 2 + sl);
        if (!hal_ini_path(h))
            return hal_error(h, HAL_ERR_NOT_FOUND, "[%s]%s: no INI file is loaded (give one "
                             "with -i CONFIG.ini)", sec, key);
        const char *v = hal_ini_get(h, sec, key);
        if (!v)
            return hal_error(h, HAL_ERR_NOT_FOUND, "[%s]%s: no such key in %s", sec, key,
                             hal_ini_path(h));
        size_t vl = strlen(v);
        if (n + vl + 1 >= len)
            return hal_error(h, HAL_ERR_SYNTAX, "line longer than %zu characters", len);
        memcpy(out + n, v, vl);
        n += vl;
        c += 2 + sl + kl;
    }
    out[n] = '\0';
    return HAL_OK;
}

/* Splits buf in place into words; "double quotes" keep blanks inside one word. */
static int hal_split(struct hal *h, char *buf, char **words, int max)
{
    int n = 0;
    char *c = buf;
    for (;;) {
        while (isspace((unsigned char)*c))
            c++;
        if (!*c)
            return n;
        if (n == max)
            return hal_error(h, HAL_ERR_SYNTAX, "more than %d words on one line", max), -1;
        if (*c == '"') {
            words[n++] = ++c;
            while (*c && *c != '"')
                c++;
            if (!*c)
                return hal_error(h, HAL_ERR_SYNTAX, "missing closing quote"), -1;
        } else {
            words[n++] = c;
            while (*c && !isspace((unsigned char)*c))
                c++;
        }
        if (!*c)
            return n;
        *c++ = '\0';
    }
}

/* Parses a whole decimal number for a command argument. */
static int hal_word_long(struct hal *h, const char *cmd, const char *what, const char *w,
                         long *out)
{
    char *end;
    errno = 0;
    *out = strtol(w, &end, 10);
    if (end == w || *end || errno == ERANGE)
        return hal_error(h, HAL_ERR_SYNTAX, "%s: %s '%s' is not a whole number", cmd, what, w);
    return HAL_OK;
}

/* `show`-free commands that change nothing print through here. */
static int hal_cmd_print(FILE *out, const char *text)
{
    if (out)
        fprintf(out, "%s\n", text);
    return HAL_OK;
}

/* `start`: then, if asked (halcmd --run-ms), runs the threads for a while. */
static int hal_cmd_start(struct hal *h)
{
    int st = hal_start(h);
    if (st != HAL_OK || h->start_run_ns <= 0)
        return st;
    if (h->sim_clock)
        return hal_sim_advance(h, (long)h->start_run_ns);
    struct timespec ts = { .tv_sec = h->start_run_ns / 1000000000,
                           .tv_nsec = h->start_run_ns % 1000000000 };
    while (nanosleep(&ts, &ts) == -1 && errno == EINTR)
        ;
    return HAL_OK;
}

/* Commands that change the graph (run with the threads locked out in real-time mode). */
static int hal_cmd_graph(struct hal *h, int n, char **w)
{
    const char *c = w[0];
    long v;
    if (!strcmp(c, "net")) {
        int k = 0;
        char *pins[HAL_WORDS_MAX];
        for (int i = 2; i < n; i++)
            if (strcmp(w[i], "=>") && strcmp(w[i], "<=") && strcmp(w[i], "<=>"))
                pins[k++] = w[i];
        return n < 2 ? hal_error(h, HAL_ERR_SYNTAX, "net: needs a signal name and pins")
                     : hal_net(h, w[1], k, pins);
    }
    if (!strcmp(c, "linkps") || !strcmp(c, "linksp")) {
        if (n != 3)
            return hal_error(h, HAL_ERR_SYNTAX, "%s: needs a pin and a signal", c);
        bool ps = !strcmp(c, "linkps");
        return hal_net(h, ps ? w[2] : w[1], 1, ps ? &w[1] : &w[2]);
    }
    if (!strcmp(c, "newsig")) {
        static const char *const types[] = { "", "bit", "float", "s32", "u32" };
        for (int t = HAL_BIT; n == 3 && t <= HAL_U32; t++)
            if (!strcmp(w[2], types[t]))
                return hal_newsig(h, w[1], (enum hal_type)t);
        return hal_error(h, HAL_ERR_SYNTAX, "newsig: needs a name and a type (bit, float, "
                         "s32 or u32)");
    }
    if (!strcmp(c, "setp") || !strcmp(c, "sets")) {
        if (n != 3)
            return hal_error(h, HAL_ERR_SYNTAX, "%s: needs a name and a value", c);
        return c[3] == 'p' ? hal_setp(h, w[1], w[2]) : hal_sets(h, w[1], w[2]);
    }
    if (n == 3 && !strcmp(w[1], "="))
        return hal_setp(h, w[0], w[2]);
    if (!strcmp(c, "unlinkp"))
        return n != 2 ? hal_error(h, HAL_ERR_SYNTAX, "unlinkp: needs a pin name")
                      : hal_unlinkp(h, w[1]);
    if (!strcmp(c, "addf")) {
        if (n < 3 || n > 4)
            return hal_error(h, HAL_ERR_SYNTAX, "addf: needs a function, a thread and "
                             "optionally a position");
        v = 0;
        if (n == 4 && hal_word_long(h, "addf", "position", w[3], &v) != HAL_OK)
            return HAL_ERR_SYNTAX;
        return hal_addf(h, w[1], w[2], v);
    }
    if (!strcmp(c, "delf"))
        return n < 2 || n > 3 ? hal_error(h, HAL_ERR_SYNTAX, "delf: needs a function name")
                              : hal_delf(h, w[1], n == 3 ? w[2] : NULL);
    if (!strcmp(c, "newthread")) {
        if (n < 3 || n > 4)
            return hal_error(h, HAL_ERR_SYNTAX, "newthread: needs a name and a period (ns)");
        if (hal_word_long(h, "newthread", "period", w[2], &v) != HAL_OK)
            return HAL_ERR_SYNTAX;
        return hal_thread_new(h, w[1], v);
    }
    return -1;
}

/* Runs one command from its words. */
static int hal_cmd_words(struct hal *h, int n, char **w, FILE *out)
{
    const char *c = w[0];
    char buf[256];
    if (!strcmp(c, "getp") || !strcmp(c, "gets")) {
        if (n != 2)
            return hal_error(h, HAL_ERR_SYNTAX, "%s: needs one name", c);
        int st = c[3] == 'p' ? hal_getp(h, w[1], buf, sizeof buf)
                             : hal_gets(h, w[1], buf, sizeof buf);
        return st != HAL_OK ? st : hal_cmd_print(out, buf);
    }
    if (!strcmp(c, "show"))
        return n > 3 ? hal_error(h, HAL_ERR_SYNTAX, "show: [pin|sig|funct|thread|param|comp] "
                                 "[pattern]")
                     : hal_show(h, out, n > 1 ? w[1] : NULL, n > 2 ? w[2] : NULL);
    if (!strcmp(c, "start"))
        return n != 1 ? hal_error(h, HAL_ERR_SYNTAX, "start: takes no arguments")
                      : hal_cmd_start(h);
    if (!strcmp(c, "stop"))
        return n != 1 ? hal_error(h, HAL_ERR_SYNTAX, "stop: takes no arguments")
                      : hal_stop(h);
    if (!strcmp(c, "source"))
        return n != 2 ? hal_error(h, HAL_ERR_SYNTAX, "source: needs a file name")
                      : hal_source_to(h, w[1], out);
    if (!strcmp(c, "loadusr"))
        return hal_error(h, HAL_ERR_SYNTAX, "loadusr: not supported; hexcnc runs every "
                         "component in one process with loadrt");
    /* A new component touches nothing a running thread uses, and its load may be slow
     * (a drive connecting): the threads keep running. */
    if (!strcmp(c, "loadrt"))
        return n < 2 ? hal_error(h, HAL_ERR_SYNTAX, "loadrt: needs a component name")
                     : hal_loadrt(h, w[1], n - 2, w + 2);
    hal_lock_all(h);
    int st = hal_cmd_graph(h, n, w);
    hal_unlock_all(h);
    if (st == -1)
        return hal_error(h, HAL_ERR_SYNTAX, "unknown command '%s'", c);
    return st;
}

/* Puts "file:line: " in front of the last error, once. */
static int hal_locate_error(struct hal *h, int st, const char *file, int lineno)
{
    if (st == HAL_OK || !file || h->err_located)
        return st;
    char msg[sizeof h->err];
    snprintf(msg, sizeof msg, "%s", h->err);
    hal_error(h, st, "%s:%d: %s", file, lineno, msg);
    h->err_located = true;
    return st;
}

/* One command line. */
int hal_cmd(struct hal *h, const char *line, const char *file, int lineno, FILE *out)
{
    char stripped[HAL_LINE_MAX], subst[HAL_LINE_MAX];
    char *words[HAL_WORDS_MAX];
    h->err_located = false;
    if (strlen(line) >= HAL_LINE_MAX)
        return hal_locate_error(h, hal_error(h, HAL_ERR_SYNTAX, "line longer than %d "
                                             "characters", HAL_LINE_MAX - 1), file, lineno);
    hal_strip_comment(line, stripped, sizeof stripped);
    int st = hal_substitute(h, stripped, subst, sizeof subst);
    if (st != HAL_OK)
        return hal_locate_error(h, st, file, lineno);
    int n = hal_split(h, subst, words, HAL_WORDS_MAX);
    if (n < 0)
        return hal_locate_error(h, HAL_ERR_SYNTAX, file, lineno);
    if (n == 0)
        return HAL_OK;
    return hal_locate_error(h, hal_cmd_words(h, n, words, out), file, lineno);
}
