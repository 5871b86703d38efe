/* svg.c: line charts as SVG files: axes, ticks, labels with units, legend; no dependencies. */
#include <math.h>
#include <stdio.h>

#include "check/plot.h"
#include "common/atomicfile.h"

#define W_PX 900.0           /* drawing size, px */
#define H_PX 560.0
#define LEFT_PX 90.0         /* margins: room for tick labels, axis labels and the legend */
#define RIGHT_PX 250.0
#define TOP_PX 50.0
#define BOTTOM_PX 60.0

/* Plot area and data window. */
struct frame {
    double x0, x1, y0, y1;   /* data range shown */
    double px0, px1, py0, py1; /* plot area, px (py0 top) */
};

/* Writes text with XML's special characters escaped. */
static void xml_text(FILE *f, const char *s)
{
    for (; s && *s; s++) {
        if (*s == '&')
            fputs("&amp;", f);
        else if (*s == '<')
            fputs("&lt;", f);
        else if (*s == '>')
            fputs("&gt;", f);
        else
            fputc(*s, f);
    }
}

/* A tick step of 1, 2 or 5 times a power of ten giving about n ticks over span. */
static double nice_step(double span, int n)
{
    double raw = span / n, p = pow(10, floor(log10(raw))), m = raw / p;
    return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

/* Data range of all series (finite points only). */
static int data_range(const struct svg_series *s, int ns, struct frame *fr)
{
    fr->x0 = fr->y0 = HUGE_VAL, fr->x1 = fr->y1 = -HUGE_VAL;
    for (int k = 0; k < ns; k++) {
        size_t st = s[k].stride ? s[k].stride : 1;
        for (size_t i = 0; i < s[k].n; i++) {
            double x = s[k].x[i * st], y = s[k].y[i * st];
            if (!isfinite(x) || !isfinite(y))
                continue;
            fr->x0 = fmin(fr->x0, x), fr->x1 = fmax(fr->x1, x);
            fr->y0 = fmin(fr->y0, y), fr->y1 = fmax(fr->y1, y);
        }
    }
    return fr->x0 <= fr->x1;
}

/* Pads the range, widens flat ranges, and equalises the scales when asked. */
static void fit_frame(struct frame *fr, int equal)
{
    double dx = fr->x1 - fr->x0, dy = fr->y1 - fr->y0;
    if (dx <= 0)
        dx = fabs(fr->x0) > 0 ? fabs(fr->x0) * 0.1 : 1, fr->x0 -= dx / 2, fr->x1 += dx / 2;
    if (dy <= 0)
        dy = fabs(fr->y0) > 0 ? fabs(fr->y0) * 0.1 : 1, fr->y0 -= dy / 2, fr->y1 += dy / 2;
    fr->x0 -= 0.04 * dx, fr->x1 += 0.04 * dx, fr->y0 -= 0.06 * dy, fr->y1 += 0.06 * dy;
    fr->px0 = LEFT_PX, fr->px1 = W_PX - RIGHT_PX, fr->py0 = TOP_PX, fr->py1 = H_PX - BOTTOM_PX;
    if (!equal)
        return;
    double sx = (fr->px1 - fr->px0) / (fr->x1 - fr->x0), sy = (fr->py1 - fr->py0) / (fr->y1 - fr->y0);
    if (sx > sy) {           /* widen x so that 1 unit is as long on both axes */
        double w = (fr->px1 - fr->px0) / sy, c = 0.5 * (fr->x0 + fr->x1);
        fr->x0 = c - w / 2, fr->x1 = c + w / 2;
    } else {
        double h = (fr->py1 - fr->py0) / sx, c = 0.5 * (fr->y0 + fr->y1);
        fr->y0 = c - h / 2, fr->y1 = c + h / 2;
    }
}

/* Data x to drawing x, px. */
static double px(const struct frame *fr, double x)
{
    return fr->px0 + (x - fr->x0) / (fr->x1 - fr->x0) * (fr->px1 - fr->px0);
}
/* Data y to drawing y, px (SVG y grows downwards). */
static double py(const struct frame *fr, double y)
{
    return fr->py1 - (y - fr->y0) / (fr->y1 - fr->y0) * (fr->py1 - fr->py0);
}

/* Frame, grid, ticks with labels, axis labels and the title. */
static void axes(FILE *f, const struct frame *fr, const struct svg_chart *c)
{
    fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" fill=\"white\" "
            "stroke=\"black\"/>\n", fr->px0, fr->py0, fr->px1 - fr->px0, fr->py1 - fr->py0);
    double sx = nice_step(fr->x1 - fr->x0, 8), sy = nice_step(fr->y1 - fr->y0, 6);
    for (double x = ceil(fr->x0 / sx) * sx; x <= fr->x1 + 1e-9 * sx; x += sx) {
        double X = px(fr, x), v = fabs(x) < 1e-9 * sx ? 0 : x;
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n"
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n"
                "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%g</text>\n", X, fr->py0, X,
                fr->py1, X, fr->py1, X, fr->py1 + 5, X, fr->py1 + 19, v);
    }
    for (double y = ceil(fr->y0 / sy) * sy; y <= fr->y1 + 1e-9 * sy; y += sy) {
        double Y = py(fr, y), v = fabs(y) < 1e-9 * sy ? 0 : y;
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n"
                "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"black\"/>\n"
                "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">%g</text>\n", fr->px0, Y, fr->px1,
                Y, fr->px0 - 5, Y, fr->px0, Y, fr->px0 - 8, Y + 4, v);
    }
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">", 0.5 * (fr->px0 + fr->px1),
            H_PX - 18);
    xml_text(f, c->xlabel);
    fprintf(f, "</text>\n<text x=\"18\" y=\"%.1f\" text-anchor=\"middle\" "
            "transform=\"rotate(-90 18 %.1f)\">", 0.5 * (fr->py0 + fr->py1),
            0.5 * (fr->py0 + fr->py1));
    xml_text(f, c->ylabel);
    fprintf(f, "</text>\n<text x=\"%.1f\" y=\"30\" text-anchor=\"middle\" font-size=\"16\">",
            0.5 * (fr->px0 + fr->px1));
    xml_text(f, c->title);
    fputs("</text>\n", f);
}

/* One series as a polyline (broken at NaN) or as dots, clipped to the plot area. */
static void series(FILE *f, const struct frame *fr, const struct svg_series *s)
{
    size_t st = s->stride ? s->stride : 1;
    int open = 0;
    for (size_t i = 0; i < s->n; i++) {
        double x = s->x[i * st], y = s->y[i * st];
        if (!isfinite(x) || !isfinite(y)) {
            if (open)
                fputs("\"/>\n", f);
            open = 0;
            continue;
        }
        if (s->markers) {
            fprintf(f, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"1.6\" fill=\"%s\"/>\n", px(fr, x),
                    py(fr, y), s->color);
            continue;
        }
        if (!open)
            fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.6\"%s "
                    "clip-path=\"url(#plot)\" points=\"", s->color,
                    s->dashed ? " stroke-dasharray=\"6 4\"" : "");
        fprintf(f, "%.2f,%.2f ", px(fr, x), py(fr, y));
        open = 1;
    }
    if (open)
        fputs("\"/>\n", f);
}

/* The legend to the right of the plot area. */
static void legend(FILE *f, const struct frame *fr, const struct svg_series *s, int ns)
{
    for (int k = 0; k < ns; k++) {
        double y = fr->py0 + 14 + 20 * k, x = fr->px1 + 14;
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"%s\" "
                "stroke-width=\"%s\"%s/>\n<text x=\"%.1f\" y=\"%.1f\">", x, y, x + 26, y,
                s[k].color, s[k].markers ? "4" : "2",
                s[k].dashed ? " stroke-dasharray=\"6 4\"" : "", x + 32, y + 4);
        xml_text(f, s[k].name);
        fputs("</text>\n", f);
    }
}

/* Writes one chart: frame, grid, ticks, labels, series, legend; atomically. */
int svg_write_chart(const char *path, const struct svg_chart *c, const struct svg_series *s,
                    int ns, char *err, size_t errlen)
{
    struct frame fr;
    struct atomicfile a;
    if (!data_range(s, ns, &fr))
        fr.x0 = fr.y0 = 0, fr.x1 = fr.y1 = 1;
    fit_frame(&fr, c->equal_aspect);
    if (atomicfile_open(&a, path, err, errlen) != ATOMICFILE_OK)
        return -1;
    FILE *f = a.f;
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" "
            "width=\"%.0f\" height=\"%.0f\" viewBox=\"0 0 %.0f %.0f\" font-family=\"sans-serif\" "
            "font-size=\"12\">\n<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n"
            "<defs><clipPath id=\"plot\"><rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" "
            "height=\"%.1f\"/></clipPath></defs>\n", W_PX, H_PX, W_PX, H_PX, fr.px0, fr.py0,
            fr.px1 - fr.px0, fr.py1 - fr.py0);
    axes(f, &fr, c);
    for (int k = 0; k < ns; k++)
        series(f, &fr, &s[k]);
    legend(f, &fr, s, ns);
    fputs("</svg>\n", f);
    return atomicfile_commit(&a, err, errlen) == ATOMICFILE_OK ? 0 : -1;
}
