/* interp_setup.h: the interpreter's settings from a machine's INI ([RS274NGC] FEED_UNITS,
 * TOOL_TABLE, PARAMETER_FILE), read and applied in one place for every program that runs one. */
#ifndef HEXCNC_INTERP_SETUP_H
#define HEXCNC_INTERP_SETUP_H

#include <stddef.h>

#include "interp/probe_model.h"

struct interp;
struct tooltable;

/* How the settings are read: the same lookup as struct kins_config (NULL when absent). */
typedef const char *(*interp_setup_get_fn)(void *ctx, const char *section, const char *key);

/* The settings, read from the INI with paths resolved against the INI's folder. */
struct interp_settings {
    double feed_factor;            /* mm/min per F unit: 1 (mm/min, the default) or 1000 */
    char tool_table[1024];         /* [RS274NGC] TOOL_TABLE, else [EMCIO] TOOL_TABLE; "" = none */
    char param_file[1024];         /* [RS274NGC] PARAMETER_FILE; "" = none */
    char subroutine_path[4096];    /* [RS274NGC] SUBROUTINE_PATH, folders made absolute */
    long loop_limit;               /* [RS274NGC] LOOP_LIMIT: loop iterations in one program */
    struct probe_model probe;      /* [PROBE]: the workpiece G38 probes in interp and check */
};

/* Flags of interp_settings_apply() and interp_setup(). */
enum interp_setup_flag {
    /* Load the parameter file but remember no file to save to: even interp_setting_apply()
     * then leaves the offsets the machine will cut with alone (interpreting never writes). */
    INTERP_SETUP_PARAMS_READ_ONLY = 1 << 0,
};

/* Reads the settings; dir is the INI's folder (NULL or "" = paths as written). An unknown
 * FEED_UNITS fails with INTERP_ERR_CONFIG and "[RS274NGC] FEED_UNITS = furlongs: use mm/min
 * or m/min" (the message names the key, so the caller can point it at the INI's line). */
int interp_settings_read(struct interp_settings *s, interp_setup_get_fn get, void *ctx,
                         const char *dir, char *err, size_t errlen);

/* Applies them to in: the feed factor; the tool table loaded into tt and handed to in
 * (tt NULL: the table is the caller's business and TOOL_TABLE is not loaded); the parameter
 * file loaded (and, unless INTERP_SETUP_PARAMS_READ_ONLY, remembered as the file that
 * interp_setting_apply() saves to; interpreting itself never writes it).
 * Errors name the file and line (a missing tool table names its path). */
int interp_settings_apply(struct interp *in, const struct interp_settings *s,
                          struct tooltable *tt, unsigned flags, char *err, size_t errlen);

/* Both: reads the INI's settings and applies them, and gives the interpreter the INI for
 * #<_ini[SECTION]KEY> (get and ctx must outlive its runs). Returns INTERP_OK or an interp
 * status with the message in err. */
int interp_setup(struct interp *in, struct tooltable *tt, interp_setup_get_fn get, void *ctx,
                 const char *dir, unsigned flags, char *err, size_t errlen);

#endif
