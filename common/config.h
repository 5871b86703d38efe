/* config.h: the one configuration reader on top of inifile.c: the table of every INI key
 * hexcnc reads (type, unit, range, default, meaning), one set of value rules, the whole-file
 * check run at load by every command that reads an INI, and the reference (docs/ini.md). */
#ifndef HEXCNC_CONFIG_H
#define HEXCNC_CONFIG_H

#include <stdio.h>

#include "common/inifile.h"

/* 0 = OK; the message, naming file, line and key, is in the caller's err buffer. */
enum config_status {
    CONFIG_OK = 0,
    CONFIG_ERR_VALUE,        /* a value of the wrong type or out of its range */
    CONFIG_ERR_UNKNOWN,      /* a section or key hexcnc does not know */
    CONFIG_ERR_MISSING,      /* a required key is absent */
    CONFIG_ERR_FILE,         /* the file cannot be read or has a bad line (inifile.c) */
    CONFIG_STATUS_COUNT
};
const char *config_strerror(int status);

/* What a value is. */
enum config_type {
    CONFIG_NUMBER,           /* one finite decimal number */
    CONFIG_NUMBERS,          /* `count` numbers separated by blanks or commas */
    CONFIG_INTEGER,          /* a whole number, decimal or 0x hexadecimal */
    CONFIG_BOOL,             /* 0/1, TRUE/FALSE, YES/NO, ON/OFF (any case) */
    CONFIG_STRING,           /* any text */
    CONFIG_PATH,             /* a file, relative to the INI file's folder unless absolute */
    CONFIG_ENUM,             /* one of the words in `choices` ("a|b|c", any case) */
};

/* Flags of a key. */
enum {
    CONFIG_REQUIRED = 1 << 0,  /* no default: absent is an error when its section is there */
    CONFIG_REPEAT = 1 << 1,    /* may appear more than once (HALFILE) */
    CONFIG_IGNORED = 1 << 2,   /* LinuxCNC's key, accepted and not used by hexcnc */
};

/* One key. `section` may hold one '#', standing for a decimal index (JOINT_# = JOINT_0, ..). */
struct config_key {
    const char *section;
    const char *key;
    enum config_type type;
    const char *unit;        /* "mm/s", "" when none */
    const char *range;       /* numbers: "", "> A", ">= A", "A..B" (inclusive); enum: choices */
    int count;               /* CONFIG_NUMBERS: how many numbers */
    unsigned flags;
    const char *def;         /* default as text, "" when absent means "not used" */
    const char *doc;         /* one line */
};

/* Kinds of section. */
enum config_section_kind {
    CONFIG_STRICT,           /* hexcnc's own: every key must be in the table */
    CONFIG_OPEN,             /* shared with other LinuxCNC programs: keys in the table are
                              * checked, the others are theirs and ignored */
    CONFIG_FOREIGN,          /* another program's: ignored as a whole */
};

struct config_section {
    const char *name;        /* may hold one '#' as config_key.section */
    enum config_section_kind kind;
    const char *doc;
};

/* The table (common/config_keys.c). */
extern const struct config_key config_keys[];
extern const int config_nkeys;
extern const struct config_section config_sections[];
extern const int config_nsections;

/* Value rules, one set for everything that reads configuration. Each returns 0 on success,
 * else -1 with a short reason in why ("not a number", "must be > 0"). */
int config_parse_number(const char *text, double *out, char *why, size_t whylen);
int config_parse_numbers(const char *text, double *out, int n, char *why, size_t whylen);
int config_parse_integer(const char *text, long *out, char *why, size_t whylen);
int config_parse_bool(const char *text, int *out, char *why, size_t whylen);
/* Checks x against a range text of the table ("> 0", "1..1000"); 0 inside, -1 outside with
 * "must be > 0" in why. */
int config_in_range(double x, const char *range, char *why, size_t whylen);

/* The table's entry for [section] key, NULL when unknown. */
const struct config_key *config_find(const char *section, const char *key);
/* The table's section entry matching a concrete name (JOINT_3), NULL when unknown. */
const struct config_section *config_find_section(const char *section);
/* Checks one value against its entry: 0, or -1 with "must be > 0 (mm/s)" in why. */
int config_check_value(const struct config_key *k, const char *value, char *why,
                       size_t whylen);

/* Checks a whole loaded file: unknown sections and keys (with the closest known name),
 * repeated keys, values, required keys of present sections. Every problem is one line
 * "PATH:LINE: [SECTION] KEY ..." in err (as many as fit); returns the first status. */
int config_check(const struct inifile *ini, char *err, size_t errlen);
/* inifile_load, then config_check: what every command that reads an INI calls. */
int config_load(struct inifile *ini, const char *path, char *err, size_t errlen);

/* Edit distance between two names (for "did you mean"). */
int config_edit_distance(const char *a, const char *b);

/* Writes the reference of every section and key (docs/ini.md) in Markdown. */
int config_write_doc(FILE *out);

#endif
