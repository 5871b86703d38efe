/* errbuf.h: the one way a library writes an error message into its caller's buffer. */
#ifndef HEXCNC_ERRBUF_H
#define HEXCNC_ERRBUF_H

#include <stddef.h>

/* Formats the message into err (when the caller gave one: err may be NULL or errlen 0) and
 * returns status, so that an error path is one line: `return errbuf_set(err, len, ST, ...)`. */
int errbuf_set(char *err, size_t errlen, int status, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

#endif
