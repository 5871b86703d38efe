/* plot.h: SVG line charts written by hand (no dependencies) and the check's sample trace. */
#ifndef HEXCNC_CHECK_PLOT_H
#define HEXCNC_CHECK_PLOT_H

#include <stddef.h>

#include "check/check.h"
#include "interp/canon.h"

/* One series of a chart: n points (x[i*stride], y[i*stride]); NaN in y breaks the line. */
struct svg_series {
    const char *name;        /* legend text */
    const double *x, *y;
    size_t n, stride;        /* stride 0 means 1 */
    const char *color;       /* CSS colour */
    int dashed;              /* 1: dashed line */
    int markers;             /* 1: a dot at every point instead of a line */
};

/* A chart: title, axis labels with units, and the series; equal_aspect keeps 1 mm = 1 mm on
 * both axes (paths seen from above). The file is replaced atomically (common/atomicfile).
 * Returns 0, or -1 with "PATH: what" in err when it cannot be written. */
struct svg_chart {
    const char *title;
    const char *xlabel, *ylabel;
    int equal_aspect;
};
int svg_write_chart(const char *path, const struct svg_chart *c, const struct svg_series *s,
                    int ns, char *err, size_t errlen);

/* Samples the check keeps for its plots: time series decimated to about CHECK_TRACE_POINTS
 * points, and every deviation measure (decimated the same way). */
#define CHECK_TRACE_POINTS 4000
struct check_trace {
    size_t n, cap;
    double *t_s;             /* machine time, s */
    double *legs_mm;         /* n x KINS_MAX_JOINTS leg lengths, mm */
    double *rates_mm_s;      /* n x KINS_MAX_JOINTS leg rates, mm/s */
    double *pose;            /* n x KINS_POSE_DIM commanded poses, mm / deg */
    int njoints;
    size_t ndev, capdev;
    double *dev_dist_mm;     /* path length done when the deviation was measured, mm */
    double *dev_t_s;         /* machine time, s */
    double *dev_mm;          /* the deviation, mm */
    long dev_every, dev_count; /* keep every dev_every-th measure */
    int failed;              /* an allocation failed: the trace is incomplete */
};
void check_trace_init(struct check_trace *t);
void check_trace_free(struct check_trace *t);
/* Prepares for a run of planned_s seconds at period_s; returns the period decimation. */
long check_trace_begin(struct check_trace *t, double planned_s, double period_s);
void check_trace_add(struct check_trace *t, double t_s, int nj, const double *legs,
                     const double *rates, const double *pose);
void check_trace_deviation(struct check_trace *t, double dist_mm, double t_s, double dev_mm);

/* A copy of G-code text with G141/G142 turned into G1 and their W/D words blanked: the same
 * contour with the tool centre on it (no compensation). Caller frees. NULL when out of memory. */
char *check_strip_compensation(const char *text, size_t len);

/* Writes the check's plots into dir: toolpath_top.svg, toolpath_3d.svg (programmed contour
 * against the compensated tool path), legs.svg, leg_rates.svg (against time), deviation.svg
 * (along the path). contour may be NULL when the contour is not known. Returns CHECK_OK or
 * CHECK_ERR_IO / CHECK_ERR_NOMEM with a message in err. */
int check_write_plots(const char *dir, const struct canon_prog *path,
                      const struct canon_prog *contour, const struct check_trace *trace,
                      const struct check_result *r, char *err, size_t errlen);

#endif
