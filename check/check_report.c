/* check_report.c: the check's output: a short human table and one JSON object for tools. */
#include <math.h>
#include <stdio.h>

#include "check/check.h"
#include "check/check_priv.h"

/* Prints a JSON string with the characters JSON requires escaped. */
static void json_str(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

/* A number, or null when it is not finite (JSON has no inf/nan). */
static void json_num(FILE *f, double v)
{
    if (isfinite(v))
        fprintf(f, "%.9g", v);
    else
        fputs("null", f);
}

/* "key":number, with a leading comma unless first. */
static void json_field(FILE *f, const char *key, double v, int first)
{
    fprintf(f, "%s\"%s\":", first ? "" : ",", key);
    json_num(f, v);
}

/* The per-leg figures. */
static void json_legs(const struct check_result *r, FILE *f)
{
    fputs(",\"legs\":[", f);
    for (int i = 0; r->simulated && i < r->njoints; i++) {
        const struct check_leg *l = &r->leg[i];
        fprintf(f, "%s{\"leg\":%d", i ? "," : "", i + 1);
        json_field(f, "min_mm", l->min_mm, 0);
        json_field(f, "max_mm", l->max_mm, 0);
        json_field(f, "peak_vel_mm_s", l->peak_vel_mm_s, 0);
        json_field(f, "peak_acc_mm_s2", l->peak_acc_mm_s2, 0);
        json_field(f, "peak_jerk_mm_s3", l->peak_jerk_mm_s3, 0);
        json_field(f, "limit_jerk_mm_s3", l->limit_jerk_mm_s3, 0);
        json_field(f, "limit_min_mm", l->limit_min_mm, 0);
        json_field(f, "limit_max_mm", l->limit_max_mm, 0);
        json_field(f, "limit_vel_mm_s", l->limit_vel_mm_s, 0);
        json_field(f, "limit_acc_mm_s2", l->limit_acc_mm_s2, 0);
        json_field(f, "planned_acc_mm_s2", l->planned_acc_mm_s2, 0);
        fputs(",\"limit_vel_key\":", f);
        json_str(f, l->vel_key ? l->vel_key : "");
        fputs(",\"limit_acc_key\":", f);
        json_str(f, l->acc_key ? l->acc_key : "");
        fputc('}', f);
    }
    fputc(']', f);
}

/* The problems (or warnings), in the order found. */
static void json_problems(const char *name, const struct check_problem *list, size_t n, FILE *f)
{
    fprintf(f, ",\"%s\":[", name);
    for (size_t i = 0; i < n; i++) {
        const struct check_problem *p = &list[i];
        fprintf(f, "%s{\"kind\":\"%s\",\"file\":", i ? "," : "", check_kind_name(p->kind));
        json_str(f, p->file);
        fprintf(f, ",\"line\":%d,\"column\":%d,\"leg\":%d", p->line, p->column,
                p->leg >= 0 ? p->leg + 1 : 0);
        json_field(f, "value", p->value, 0);
        json_field(f, "limit", p->limit, 0);
        json_field(f, "time_s", p->time_s, 0);
        fprintf(f, ",\"count\":%d,\"message\":", p->count);
        json_str(f, p->message);
        fputc('}', f);
    }
    fputc(']', f);
}

/* One JSON object (docs/verification.md has the schema). */
void check_print_json(const struct check_result *r, FILE *f)
{
    fputs("{\"program\":", f);
    json_str(f, r->program);
    fputs(",\"config\":", f);
    json_str(f, r->config);
    fprintf(f, ",\"ok\":%s,\"simulated\":%s", r->nproblems ? "false" : "true",
            r->simulated ? "true" : "false");
    json_field(f, "servo_period_s", r->servo_period_s, 0);
    json_field(f, "machining_time_s", r->machining_time_s, 0);
    json_field(f, "planned_time_s", r->planned_time_s, 0);
    json_field(f, "length_mm", r->length_mm, 0);
    json_field(f, "jerk_window_s", r->jerk_window_s, 0);
    json_field(f, "jerk_full_window_s", r->jerk_full_window_s, 0);
    if (r->tip_measured) {
        json_field(f, "tip_deviation_mm", r->max_tip_deviation_mm, 0);
        fprintf(f, ",\"tip_deviation_line\":%d", r->max_tip_deviation_line);
    }
    fprintf(f, ",\"periods\":%ld,\"deviation\":{", r->periods);
    json_field(f, "max_mm", r->max_deviation_mm, 1);
    fprintf(f, ",\"line\":%d", r->max_deviation_line);
    json_field(f, "max_deg", r->max_deviation_deg, 0);
    json_field(f, "tolerance_mm", r->kin_tol_mm, 0);
    json_field(f, "every_s", r->deviation_every_s, 0);
    fprintf(f, ",\"evaluations\":%ld},\"condition\":{", r->deviation_evals);
    json_field(f, "max", r->max_condition, 1);
    fprintf(f, ",\"line\":%d", r->max_condition_line);
    json_field(f, "limit", r->condition_limit, 0);
    json_field(f, "every_s", r->condition_every_s, 0);
    fprintf(f, ",\"evaluations\":%ld,\"bounded\":%ld}", r->condition_evals,
            r->condition_bounded);
    json_legs(r, f);
    json_problems("problems", r->problems, r->nproblems, f);
    json_problems("warnings", r->warnings, r->nwarnings, f);
    fputs("}\n", f);
}

/* How often a measure was taken, in words (moved: the line changes the condition number
 * waits for, check_sim.c). */
static void schedule(char *buf, size_t len, double every_s, const char *moved)
{
    if (every_s > 0)
        snprintf(buf, len, "every %g ms and at each line change%s", every_s * 1e3, moved);
    else
        snprintf(buf, len, "at every servo period");
}

/* Minutes and seconds for people. */
static void print_duration(FILE *f, double s)
{
    if (s >= 60)
        fprintf(f, "%d min %.3f s", (int)(s / 60), fmod(s, 60));
    else
        fprintf(f, "%.3f s", s);
}

/* With jerk limits, the moving average's length and where it comes from; where it is shorter
 * than the full window, that one and the accelerations motion plans the legs to (the range
 * over the legs). */
static void print_jerk(const struct check_result *r, FILE *f)
{
    if (!(r->jerk_window_s > 0))
        return;
    fprintf(f, "jerk            a %g ms moving average of the set points (%s", r->jerk_window_s
            * 1e3, r->jerk_window_set ? "[TRAJ] JERK_WINDOW" : "the default");
    if (r->jerk_window_s >= r->jerk_full_window_s) {
        fputs("; every acceleration in full)\n", f);
        return;
    }
    double lo = HUGE_VAL, hi = 0;
    for (int i = 0; i < r->njoints; i++) {
        const struct check_leg *l = &r->leg[i];
        lo = fmin(lo, l->planned_acc_mm_s2), hi = fmax(hi, l->planned_acc_mm_s2);
    }
    char legs[64];
    snprintf(legs, sizeof legs, lo == hi ? "%g" : "%g..%g", lo, hi);
    fprintf(f, "; %g ms with every acceleration in full): accelerations planned to MAX_JERK x "
            "window / 2 at most, the legs' to %s mm/s^2\n", r->jerk_full_window_s * 1e3, legs);
}

/* The short table for people. */
void check_print_table(const struct check_result *r, FILE *f)
{
    fprintf(f, "check %s on %s\n", r->program, r->config);
    if (r->simulated) {
        fputs("machining time  ", f);
        print_duration(f, r->machining_time_s);
        fprintf(f, " (%ld servo periods of %.3f ms), path %.3f mm\n", r->periods,
                r->servo_period_s * 1e3, r->length_mm);
        char when[120];
        schedule(when, sizeof when, r->deviation_every_s, "");
        fprintf(f, "deviation       %.4g um max (line %d), %.3g deg; tolerance %g um; "
                "measured %s\n", r->max_deviation_mm * 1e3, r->max_deviation_line,
                r->max_deviation_deg, r->kin_tol_mm * 1e3, when);
        if (r->tip_measured)
            fprintf(f, "tool tip        %.4g um max from its path (line %d)\n",
                    r->max_tip_deviation_mm * 1e3, r->max_tip_deviation_line);
        char moved[64];
        snprintf(moved, sizeof moved, " %g mm or %g deg on from the last", CHECK_COND_STEP_MM,
                 CHECK_COND_STEP_DEG);
        schedule(when, sizeof when, r->condition_every_s, moved);
        fprintf(f, "condition       %.3f max (line %d), limit %.1f; measured %s\n",
                r->max_condition, r->max_condition_line, r->condition_limit, when);
        print_jerk(r, f);
        fputc('\n', f);
        int jerk = r->njoints > 0 && r->leg[0].limit_jerk_mm_s3 > 0;
        fprintf(f, "leg   min mm     max mm     range mm         peak mm/s  limit   "
                "peak mm/s^2  limit%s\n", jerk ? "    peak mm/s^3     limit" : "");
        for (int i = 0; i < r->njoints; i++) {
            const struct check_leg *l = &r->leg[i];
            fprintf(f, "%-3d %9.3f  %9.3f  %6.1f..%-7.1f %9.3f  %6.1f  %11.3f  %6.1f", i + 1,
                    l->min_mm, l->max_mm, l->limit_min_mm, l->limit_max_mm, l->peak_vel_mm_s,
                    l->limit_vel_mm_s, l->peak_acc_mm_s2, l->limit_acc_mm_s2);
            if (jerk)
                fprintf(f, "  %13.0f  %8.0f", l->peak_jerk_mm_s3, l->limit_jerk_mm_s3);
            fputc('\n', f);
        }
        fputc('\n', f);
    } else {
        fputs("not run through motion: the program cannot start (see below)\n\n", f);
    }
    for (size_t i = 0; i < r->nwarnings; i++) {
        const struct check_problem *p = &r->warnings[i];
        if (i == 0)
            fprintf(f, "%zu warning%s:\n", r->nwarnings, r->nwarnings == 1 ? "" : "s");
        fprintf(f, "  %s:%d: %s [%s]\n", p->file, p->line, p->message,
                check_kind_name(p->kind));
    }
    if (r->nwarnings)
        fputc('\n', f);
    if (!r->nproblems) {
        fputs("no problems: the program can be cut on this machine\n", f);
        return;
    }
    fprintf(f, "%zu problem%s:\n", r->nproblems, r->nproblems == 1 ? "" : "s");
    for (size_t i = 0; i < r->nproblems; i++) {
        const struct check_problem *p = &r->problems[i];
        if (p->kind == CHECK_INTERP || p->kind == CHECK_PLAN)
            fprintf(f, "  %s [%s]\n", p->message, check_kind_name(p->kind));
        else
            fprintf(f, "  %s:%d: %s [%s%s]\n", p->file, p->line, p->message,
                    check_kind_name(p->kind), p->count > 1 ? ", repeated" : "");
    }
}
