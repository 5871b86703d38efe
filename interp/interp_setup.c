/* interp_setup.c: reads [RS274NGC] FEED_UNITS, TOOL_TABLE, PARAMETER_FILE, SUBROUTINE_PATH and
 * LOOP_LIMIT, and the probe model of [PROBE], and applies them. */
#include "interp/interp_setup.h"

#include <stdio.h>
#include <string.h>

#include "common/config.h"
#include "common/errbuf.h"
#include "interp/interp.h"
#include "interp/tooltable.h"

/* A path from [section]key made relative to the INI's folder unless absolute; "" when the
 * key is absent or empty. */
static int setup_path(const char *section, const char *key, const char *value, const char *dir,
                      char *out, size_t len, char *err, size_t errlen)
{
    out[0] = '\0';
    if (!value || !value[0])
        return INTERP_OK;
    if (inifile_resolve(dir, value, out, len))
        return errbuf_set(err, errlen, INTERP_ERR_CONFIG, "[%s] %s = %s: the path is longer "
                          "than %zu characters", section, key, value, len - 1);
    return INTERP_OK;
}

/* Reads the three settings; LinuxCNC also takes the tool table from [EMCIO]. */
int interp_settings_read(struct interp_settings *s, interp_setup_get_fn get, void *ctx,
                         const char *dir, char *err, size_t errlen)
{
    memset(s, 0, sizeof *s);
    s->feed_factor = 1.0;
    const char *units = get(ctx, "RS274NGC", "FEED_UNITS");
    if (units && units[0] && interp_feed_units_parse(units, &s->feed_factor) != 0)
        return errbuf_set(err, errlen, INTERP_ERR_CONFIG, "[RS274NGC] FEED_UNITS = %s: use "
                          "mm/min or m/min", units);
    const char *table_section = "RS274NGC";
    const char *table = get(ctx, "RS274NGC", "TOOL_TABLE");
    if (!table || !table[0]) {
        table_section = "EMCIO";
        table = get(ctx, "EMCIO", "TOOL_TABLE");
    }
    int st = setup_path(table_section, "TOOL_TABLE", table, dir, s->tool_table,
                        sizeof s->tool_table, err, errlen);
    if (st == INTERP_OK)
        st = setup_path("RS274NGC", "PARAMETER_FILE", get(ctx, "RS274NGC", "PARAMETER_FILE"),
                        dir, s->param_file, sizeof s->param_file, err, errlen);
    /* SUBROUTINE_PATH: ':'-separated folders, each relative to the INI's folder */
    const char *sp = get(ctx, "RS274NGC", "SUBROUTINE_PATH");
    for (size_t used = 0; st == INTERP_OK && sp && *sp;) {
        const char *e = strchr(sp, ':');
        size_t l = e ? (size_t)(e - sp) : strlen(sp);
        char one[1024], folder[1100];
        snprintf(one, sizeof one, "%.*s", (int)(l < sizeof one ? l : sizeof one - 1), sp);
        st = setup_path("RS274NGC", "SUBROUTINE_PATH", one, dir, folder, sizeof folder, err,
                        errlen);
        int n = st ? 0 : snprintf(s->subroutine_path + used, sizeof s->subroutine_path - used,
                                  "%s%s", used ? ":" : "", folder);
        if (!st && (n < 0 || used + (size_t)n >= sizeof s->subroutine_path))
            st = errbuf_set(err, errlen, INTERP_ERR_CONFIG, "[RS274NGC] SUBROUTINE_PATH is "
                            "longer than %zu characters", sizeof s->subroutine_path - 1);
        used += st ? 0 : (size_t)n;
        sp = e ? e + 1 : sp + l;
    }
    const char *lim = get(ctx, "RS274NGC", "LOOP_LIMIT");
    if (st == INTERP_OK && lim && lim[0]) {
        char why[200];
        long v = 0;
        if (config_parse_integer(lim, &v, why, sizeof why) != 0 || v <= 0)
            st = errbuf_set(err, errlen, INTERP_ERR_CONFIG, "[RS274NGC] LOOP_LIMIT = %s: a "
                            "whole number of loop iterations above 0 is expected", lim);
        s->loop_limit = v;
    }
    if (st == INTERP_OK && probe_model_read(&s->probe, get, ctx, err, errlen) != 0)
        st = INTERP_ERR_CONFIG;
    return st;
}

/* Feed factor, tool table, parameter file, in that order. */
int interp_settings_apply(struct interp *in, const struct interp_settings *s,
                          struct tooltable *tt, unsigned flags, char *err, size_t errlen)
{
    interp_set_feed_factor(in, s->feed_factor);
    if (s->subroutine_path[0] && interp_set_subroutine_path(in, s->subroutine_path))
        return errbuf_set(err, errlen, INTERP_ERR_NOMEM, "out of memory");
    if (s->loop_limit > 0)
        interp_set_loop_limit(in, s->loop_limit);
    interp_set_probe_model(in, &s->probe);
    if (tt && s->tool_table[0]) {
        char msg[600];
        if (tooltable_load(tt, s->tool_table, msg, sizeof msg) != TOOLTABLE_OK)
            return errbuf_set(err, errlen, INTERP_ERR_TOOL, "%s", msg);
        interp_set_tooltable(in, tt);
    }
    if (s->param_file[0]) {
        int st = flags & INTERP_SETUP_PARAMS_READ_ONLY
                     ? interp_load_param_file(in, s->param_file)
                     : interp_set_param_file(in, s->param_file);
        if (st != INTERP_OK) {
            char msg[600];
            return errbuf_set(err, errlen, st, "%s",
                              interp_error_format(interp_last_error(in), msg, sizeof msg));
        }
    }
    return INTERP_OK;
}

/* Reads the INI's settings and applies them. */
int interp_setup(struct interp *in, struct tooltable *tt, interp_setup_get_fn get, void *ctx,
                 const char *dir, unsigned flags, char *err, size_t errlen)
{
    struct interp_settings s;
    int st = interp_settings_read(&s, get, ctx, dir, err, errlen);
    if (st == INTERP_OK)
        interp_set_ini(in, get, ctx);   /* #<_ini[..]..>: ctx lives as long as the INI */
    return st != INTERP_OK ? st : interp_settings_apply(in, &s, tt, flags, err, errlen);
}
