/* printer.h: prints the canonical stream in the text format of LinuxCNC's `rs274 -g`. */
#ifndef HEXCNC_PRINTER_H
#define HEXCNC_PRINTER_H

#include <stddef.h>

#include "interp/canon.h"

struct interp;

/* Where the text goes: return 0 on success. The printer itself does no I/O. */
typedef int (*interp_write_fn)(void *ctx, const char *buf, size_t len);

#define INTERP_PRINTER_BUF 65536

struct interp_printer {
    const struct interp *in;     /* queried for units and offsets (program coordinates) */
    interp_write_fn write;
    void *write_ctx;
    int digits;                  /* decimals of coordinates (rs274: 4) */
    long seq;                    /* output line counter, as rs274's first column */
    int inch;                    /* units last announced */
    int coord;                   /* offsets last announced: coordinate system, */
    double g5x[6], g92[6], tool[6]; /* work, G92 and tool offsets (mm, deg) */
    double rot_deg;              /* rotation about Z (G10 L2 R), deg */
    int failed;                  /* a write failed */
    size_t len;                  /* bytes waiting in buf */
    char buf[INTERP_PRINTER_BUF];
};

void interp_printer_init(struct interp_printer *p, const struct interp *in, int digits,
                         interp_write_fn write, void *write_ctx);
/* The lines rs274 prints before the program's own (units, offsets, reset). */
int interp_printer_preamble(struct interp_printer *p);
/* A canon_sink_fn; ctx is the struct interp_printer. */
int interp_printer_sink(void *ctx, const struct canon_cmd *cmd);
/* Writes out what is buffered; returns 0 or -1 if any write failed. */
int interp_printer_flush(struct interp_printer *p);

/* printf("%.*f", digits, v) exactly, faster; out needs digits + 330 bytes for huge values,
 * 48 for |v| < 2^52 / 10^digits. Returns the length. */
size_t interp_format_fixed(double v, int digits, char *out);

#endif
