/* tooltable_int.h: what tooltable.c and tooltable_file.c share (not part of the API). */
#ifndef HEXCNC_TOOLTABLE_INT_H
#define HEXCNC_TOOLTABLE_INT_H

#include <stddef.h>

/* Formats an error message into err (when the caller gave one) and returns status. */
__attribute__((format(printf, 4, 5)))
int tooltable_fail(char *err, size_t errlen, int status, const char *fmt, ...);

#endif
