/* printer.c: canonical commands as text, line for line in the format of LinuxCNC's `rs274 -g`. */
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "interp/interp.h"
#include "interp/printer.h"

#define MM_PER_INCH 25.4

/* Appends raw bytes, writing the buffer out when it fills. */
static void put(struct interp_printer *p, const char *s, size_t n)
{
    if (p->len + n > sizeof p->buf) {
        interp_printer_flush(p);
        if (n > sizeof p->buf) {
            if (p->write(p->write_ctx, s, n))
                p->failed = 1;
            return;
        }
    }
    memcpy(p->buf + p->len, s, n);
    p->len += n;
}

/* Appends a C string. */
static void puts_(struct interp_printer *p, const char *s)
{
    put(p, s, strlen(s));
}

/* A coordinate with the printer's digits, exactly as printf's %.Nf would print it. */
static void put_num(struct interp_printer *p, double v, int digits)
{
    char tmp[400];
    put(p, tmp, interp_format_fixed(v, digits, tmp));
}

/* Writes n right-aligned in a field of `width` (wider if it needs), returns the length. */
static size_t put_int(char *out, long n, int width, int left)
{
    char tmp[24], *e = tmp + sizeof tmp, *q = e;
    unsigned long u = n < 0 ? 0UL - (unsigned long)n : (unsigned long)n;
    do {
        *--q = (char)('0' + u % 10);
        u /= 10;
    } while (u);
    if (n < 0)
        *--q = '-';
    size_t len = (size_t)(e - q), pad = len < (size_t)width ? (size_t)width - len : 0;
    if (left) {
        memcpy(out, q, len);
        memset(out + len, ' ', pad);
    } else {
        memset(out, ' ', pad);
        memcpy(out + pad, q, len);
    }
    return len + pad;
}

/* The first columns: rs274's output counter (%5d) and the N number as written (leading
 * zeros kept, left-aligned in 5 columns) or "N.....". */
static void line_start(struct interp_printer *p, const struct canon_cmd *c)
{
    char tmp[112];  /* counter, 'N', at most 30 leading zeros and an int, blanks */
    size_t n = put_int(tmp, ++p->seq, 5, 0);
    tmp[n++] = ' ';
    tmp[n++] = 'N';
    if (c && c->has_n) {
        size_t start = n;
        int len = snprintf(tmp + n, 32, "%d", c->n_number);
        for (int z = len; z < c->n_digits && z < 30; z++)
            tmp[n++] = '0';          /* the leading zeros it was written with */
        n += (size_t)snprintf(tmp + n, 32, "%d", c->n_number);
        while (n - start < 5)
            tmp[n++] = ' ';
    } else {
        memcpy(tmp + n, ".....", 5);
        n += 5;
    }
    tmp[n++] = ' ';
    put(p, tmp, n);
}

/* NAME(v1, v2, ...) with the given values and digits, then a newline. */
static void put_call(struct interp_printer *p, const char *name, const double *v, int n,
                     int digits)
{
    puts_(p, name);
    put(p, "(", 1);
    for (int i = 0; i < n; i++) {
        if (i)
            put(p, ", ", 2);
        put_num(p, v[i], digits);
    }
    put(p, ")\n", 2);
}

/* Machine pose to program coordinates: what rs274 prints (offsets and rotation removed,
 * inch units). */
static void to_program(const struct interp_view *v, const double m[6], double out[6])
{
    interp_view_to_program(v, m, out);
}

/* ARC_FEED(first end, second end, first centre, second centre, turns, axis end, A, B, C). */
static void put_arc(struct interp_printer *p, const struct interp_view *v,
                    const struct canon_cmd *c)
{
    double e[6], ctr6[6] = {0}, ctr[6];
    to_program(v, c->end, e);
    memcpy(ctr6, c->arc.center, sizeof c->arc.center);
    to_program(v, ctr6, ctr);
    int a1 = 0, a2 = 1, n = 2;
    if (c->arc.plane == 18) {
        a1 = 2; a2 = 0; n = 1;
    } else if (c->arc.plane == 19) {
        a1 = 1; a2 = 2; n = 0;
    } else if (c->arc.plane == 0) { /* 3-D arc of the compensation: no rs274 equivalent */
        double vals[12] = {e[0], e[1], e[2], ctr[0], ctr[1], ctr[2], c->arc.normal[0],
                           c->arc.normal[1], c->arc.normal[2], e[3], e[4], e[5]};
        put_call(p, "ARC_FEED_3D", vals, 12, p->digits);
        return;
    }
    char tmp[32];
    puts_(p, "ARC_FEED(");
    double first[4] = {e[a1], e[a2], ctr[a1], ctr[a2]};
    for (int i = 0; i < 4; i++) {
        put_num(p, first[i], p->digits);
        put(p, ", ", 2);
    }
    put(p, tmp, (size_t)snprintf(tmp, sizeof tmp, "%d, ", c->arc.rotation));
    double rest[4] = {e[n], e[3], e[4], e[5]};
    for (int i = 0; i < 4; i++) {
        if (i)
            put(p, ", ", 2);
        put_num(p, rest[i], p->digits);
    }
    put(p, ")\n", 2);
}

/* Six values scaled to program units (X Y Z), separated by sep. */
static void put_six(struct interp_printer *p, const double v[6], double k, const char *sep)
{
    for (int i = 0; i < 6; i++) {
        if (i)
            puts_(p, i == 3 ? ", " : sep);
        put_num(p, v[i] * (i < 3 ? k : 1.0), 4);
    }
}

/* The offsets that changed, in program units, as rs274's SET_G5X_OFFSET, SET_G92_OFFSET and
 * USE_TOOL_LENGTH_OFFSET lines (all of them when all is set). */
static void put_offsets(struct interp_printer *p, const struct interp_view *v, int all)
{
    double k = v->inch ? 1.0 / MM_PER_INCH : 1.0;
    char tmp[48];
    int g5x = all || v->coord_system != p->coord || memcmp(v->g5x_mm, p->g5x, sizeof p->g5x);
    if (g5x) {
        line_start(p, NULL);
        put(p, tmp, (size_t)snprintf(tmp, sizeof tmp, "SET_G5X_OFFSET(%d, ", v->coord_system));
        put_six(p, v->g5x_mm, k, ", ");
        put(p, ")\n", 2);
    }
    if (all || memcmp(v->g92_mm, p->g92, sizeof p->g92)) {
        line_start(p, NULL);
        puts_(p, "SET_G92_OFFSET(");
        put_six(p, v->g92_mm, k, ", ");
        put(p, ")\n", 2);
    }
    if (!all && memcmp(v->tool_mm, p->tool, sizeof p->tool)) {
        line_start(p, NULL);
        puts_(p, "USE_TOOL_LENGTH_OFFSET(");
        put_six(p, v->tool_mm, k, " ");
        puts_(p, ", 0.0000 0.0000 0.0000)\n");
    }
    if (all || v->xy_rotation_deg != p->rot_deg || g5x) {  /* rs274: after each SET_G5X */
        line_start(p, NULL);
        put(p, tmp, (size_t)snprintf(tmp, sizeof tmp, "SET_XY_ROTATION(%.4f)\n",
                                     v->xy_rotation_deg));
    }
    p->rot_deg = v->xy_rotation_deg;
    p->coord = v->coord_system;
    memcpy(p->g5x, v->g5x_mm, sizeof p->g5x);
    memcpy(p->g92, v->g92_mm, sizeof p->g92);
    memcpy(p->tool, v->tool_mm, sizeof p->tool);
}

/* Everything but the moves. */
static void put_other(struct interp_printer *p, const struct interp_view *v,
                      const struct canon_cmd *c)
{
    char tmp[700];
    double k = v->inch ? 1.0 / MM_PER_INCH : 1.0;
    switch (c->type) {
    case CANON_DWELL: put_call(p, "DWELL", &c->value, 1, 4); return;
    case CANON_FEED_RATE: {   /* G95 (ivalue 1): F per revolution as written */
        double f = c->ivalue ? c->value : c->feed_mm_min * (v->inch ? k : 1.0 / v->feed_factor);
        put_call(p, "SET_FEED_RATE", &f, 1, 4);
        return;
    }
    case CANON_FEED_MODE:
        snprintf(tmp, sizeof tmp, "SET_FEED_MODE(0, %d)\n", c->value == 2.0); /* rs274: 1 G95 */
        break;
    case CANON_PATH_MODE:
        if (c->ivalue == 640) {   /* and the naive CAM tolerance, on a line of its own */
            snprintf(tmp, sizeof tmp, "SET_MOTION_CONTROL_MODE(CANON_CONTINUOUS, %f)\n",
                     c->value * k);
            puts_(p, tmp);
            line_start(p, c);
            snprintf(tmp, sizeof tmp, "SET_NAIVECAM_TOLERANCE(%.4f)\n", c->naive_tol_mm * k);
        }
        else
            snprintf(tmp, sizeof tmp, "SET_MOTION_CONTROL_MODE(%s)\n",
                     c->ivalue == 611 ? "CANON_EXACT_STOP" : "CANON_EXACT_PATH");
        break;
    case CANON_SPINDLE_SPEED:
        snprintf(tmp, sizeof tmp, "SET_SPINDLE_SPEED(0, %.4f)\n", c->value);
        break;
    case CANON_SPINDLE_ON:
        snprintf(tmp, sizeof tmp, "START_SPINDLE_%sCLOCKWISE(0)\n", c->value < 0 ? "COUNTER" : "");
        break;
    case CANON_SPINDLE_STOP: snprintf(tmp, sizeof tmp, "STOP_SPINDLE_TURNING(0)\n"); break;
    case CANON_TOOL_CHANGE:
        snprintf(tmp, sizeof tmp, c->value != 0.0 ? "CHANGE_TOOL_NUMBER(%d)\n" : "CHANGE_TOOL(%d)\n",
                 c->ivalue);
        break;
    case CANON_COOLANT:
        snprintf(tmp, sizeof tmp, "%s\n", c->ivalue == 7 ? "MIST_ON()" : c->ivalue == 8 ?
                 "FLOOD_ON()" : "FLOOD_OFF()");
        break;
    case CANON_DIGITAL_OUT:
        snprintf(tmp, sizeof tmp, "%s_%s_OUTPUT_BIT(%d)\n", c->value != 0 ? "SET" : "CLEAR",
                 c->immediate ? "AUX" : "MOTION", c->ivalue);
        break;
    case CANON_ANALOG_OUT:
        snprintf(tmp, sizeof tmp, "SET_%s_OUTPUT_VALUE(%d,%f)\n", c->immediate ? "AUX" :
                 "MOTION", c->ivalue, c->value);
        break;
    case CANON_COMMENT: {
        static const char *const call[] = {
            [CANON_NOTE_NONE] = "COMMENT", [CANON_NOTE_MSG] = "MESSAGE",
            [CANON_NOTE_DEBUG] = "MESSAGE", [CANON_NOTE_LOGOPEN] = "LOGOPEN",
            [CANON_NOTE_LOGAPPEND] = "LOGAPPEND", [CANON_NOTE_LOG] = "LOG",
        };
        if (c->ivalue == CANON_NOTE_LOGCLOSE)
            snprintf(tmp, sizeof tmp, "LOGCLOSE()\n");
        else
            snprintf(tmp, sizeof tmp, "%s(\"%s\")\n", c->ivalue > 0 && c->ivalue <=
                     CANON_NOTE_LOG && call[c->ivalue] ? call[c->ivalue] : "COMMENT",
                     c->text ? c->text : "");
        break;
    }
    case CANON_PAUSE:
        snprintf(tmp, sizeof tmp, "%s\n", c->ivalue ? "OPTIONAL_PROGRAM_STOP()" : "PROGRAM_STOP()");
        break;
    case CANON_PROGRAM_END: snprintf(tmp, sizeof tmp, "PROGRAM_END()\n"); break;
    default: snprintf(tmp, sizeof tmp, "%s()\n", canon_type_name(c->type)); break;
    }
    puts_(p, tmp);
}

/* A synchronised move as rs274 prints it: START_SPEED_FEED_SYNC(K, 0), the move (a rigid
 * tap's way in as RIGID_TAP(x, y, z); its way out, which rs274 leaves to the machine, as
 * nothing), STOP_SPEED_FEED_SYNCH(). */
static void put_sync(struct interp_printer *p, const struct interp_view *v,
                     const struct canon_cmd *c)
{
    if (c->sync == CANON_SYNC_TAP_OUT)
        return;
    double e[6];
    char tmp[64];
    to_program(v, c->end, e);
    line_start(p, c);
    put(p, tmp, (size_t)snprintf(tmp, sizeof tmp, "START_SPEED_FEED_SYNC(%f,0)\n",
                                 c->pitch_word));
    line_start(p, c);
    if (c->sync == CANON_SYNC_TAP_IN)
        put_call(p, "RIGID_TAP", e, 3, p->digits);
    else
        put_call(p, "STRAIGHT_FEED", e, 6, p->digits);
    line_start(p, c);
    puts_(p, "STOP_SPEED_FEED_SYNCH()\n");
}

/* Prints one command (and a units or offsets line first when they changed). */
int interp_printer_sink(void *ctx, const struct canon_cmd *c)
{
    struct interp_printer *p = ctx;
    struct interp_view v;
    if (c->type == CANON_COMMENT && c->ivalue == CANON_NOTE_PRINT) {   /* rs274: the text, */
        puts_(p, c->text ? c->text : "");                            /* no call */
        puts_(p, "\n");
        return p->failed ? -1 : 0;
    }
    if (c->type == CANON_SETTING || c->type == CANON_WAIT_INPUT)  /* rs274 prints no such call */
        return 0;
    interp_get_view(p->in, &v);
    if (v.inch != p->inch) {
        p->inch = v.inch;
        line_start(p, NULL);
        puts_(p, v.inch ? "USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n" : "USE_LENGTH_UNITS(CANON_UNITS_MM)\n");
    }
    if (c->type == CANON_OFFSETS) {
        put_offsets(p, &v, 0);
        return p->failed ? -1 : 0;
    }
    if (c->type == CANON_FEED && c->spline) {   /* rs274 prints a spline as one line */
        if (c->spline == 1) {
            line_start(p, c);
            char tmp[40];
            put(p, tmp, (size_t)snprintf(tmp, sizeof tmp, "NURBS_FEED(%d, ...)\n", c->ivalue));
        }
        return p->failed ? -1 : 0;
    }
    if (c->type == CANON_FEED && c->sync) {
        put_sync(p, &v, c);
        return p->failed ? -1 : 0;
    }
    line_start(p, c);
    if (c->type == CANON_TRAVERSE || c->type == CANON_FEED) {
        double e[6];
        to_program(&v, c->end, e);
        put_call(p, c->type == CANON_TRAVERSE ? "STRAIGHT_TRAVERSE" : "STRAIGHT_FEED", e, 6,
                 p->digits);
    } else if (c->type == CANON_PROBE) {   /* rs274: the probe is switched on around it */
        double e[6];
        to_program(&v, c->end, e);
        puts_(p, "TURN_PROBE_ON()\n");
        line_start(p, c);
        put_call(p, "STRAIGHT_PROBE", e, 6, p->digits);
        line_start(p, c);
        puts_(p, "TURN_PROBE_OFF()\n");
    } else if (c->type == CANON_ARC) {
        put_arc(p, &v, c);
    } else {
        put_other(p, &v, c);
    }
    return p->failed ? -1 : 0;
}

void interp_printer_init(struct interp_printer *p, const struct interp *in, int digits,
                         interp_write_fn write, void *write_ctx)
{
    p->in = in;
    p->write = write;
    p->write_ctx = write_ctx;
    p->digits = digits;
    p->seq = 0;
    p->failed = 0;
    p->len = 0;
    struct interp_view v;
    interp_get_view(in, &v);
    p->inch = v.inch;
    p->rot_deg = v.xy_rotation_deg;
}

/* The set-up lines rs274 prints before the program. */
int interp_printer_preamble(struct interp_printer *p)
{
    struct interp_view v;
    interp_get_view(p->in, &v);
    line_start(p, NULL);
    puts_(p, v.inch ? "USE_LENGTH_UNITS(CANON_UNITS_INCHES)\n" : "USE_LENGTH_UNITS(CANON_UNITS_MM)\n");
    put_offsets(p, &v, 1);
    line_start(p, NULL);
    puts_(p, "SET_FEED_REFERENCE(CANON_XYZ)\n");
    return p->failed ? -1 : 0;
}

/* Writes what is buffered. */
int interp_printer_flush(struct interp_printer *p)
{
    if (p->len && p->write(p->write_ctx, p->buf, p->len))
        p->failed = 1;
    p->len = 0;
    return p->failed ? -1 : 0;
}
