/* experiment.h: the paper's experiment (Table 1 and its G142 run) in the cutting simulation. */
#ifndef HEXCNC_CHECK_EXPERIMENT_H
#define HEXCNC_CHECK_EXPERIMENT_H

#include <stddef.h>

#include "check/cut.h"

/*
 * Geometry (docs/experiment.md): in the workpiece (platform) frame the programmed contour is
 * where the fixed tool's tip sits when the platform is at the programmed pose. The wall runs
 * along it; n points from the cut into the material. The 100 x 210 x 240 mm block is placed
 * so that its edge parallel to the wall lies EXP_EDGE_MM beyond the contour and its top face
 * EXP_DEPTH_MM above the contour; the paper's reference line is EXP_REF_FROM_EDGE_MM in from
 * that edge, so d = (EXP_EDGE_MM - EXP_REF_FROM_EDGE_MM) - wall. Stations d1, d2 split the
 * first tool's own part of the wall (without the overlap) in thirds, d3, d4 the second's.
 */
#define EXP_EDGE_MM 38.0            /* block edge, mm beyond the programmed contour */
#define EXP_REF_FROM_EDGE_MM 30.0   /* the paper's reference line, mm in from the edge */
#define EXP_DEPTH_MM 5.0            /* cutting depth below the top face, mm */
#define EXP_WINDOW_MM 1.0           /* a station's wall is read over +- this length, mm */
#define EXP_WINDOW_POINTS 21        /* ... at this many points (0.1 mm apart) */

/* One run of the experiment. */
struct exp_run_def {
    const char *name;        /* "1".."4", "G142" */
    const char *program;     /* under examples/paper/experiment/ */
    const char *ini;         /* the machine, same folder */
    int path;                /* 1 or 2 (the paper's two paths) */
    int side;                /* 141 or 142 */
    int tool[2];             /* first and second tool (tool table numbers) */
    double x_mm, z_mm, b_deg; /* the path's program X, Z and table tilt B */
    double part[2][2];       /* program Y from..to of the first and second tool's part */
    double paper_d_mm[4];    /* the paper's d1..d4 (NAN where it gives none) */
    const char *real_ini;    /* the machine as built, when its geometry differs from the
                              * controller's (path as given; NULL: the same machine) */
    int tcp;                 /* programmed at the tool tip (G43.4): x_mm, z_mm and the part's
                              * Y are the contour in the workpiece's frame, not a pose */
};
/* The five runs: Table 1's runs 1..4 and the G142 run. */
const struct exp_run_def *exp_runs(int *count);

/* What a run gives. */
struct exp_result {
    double radius_mm[2];     /* the two tools' radii from the tool table */
    double d_mm[4];          /* simulated d1..d4 with G141/G142 */
    double wall_mm[4];       /* wall positions beyond the contour at the stations (mean over
                              * the window), mm */
    double spread_um;        /* largest difference between the four walls, um */
    double point_spread_um;  /* the same for single-point walls (no window), um */
    double part_diff_um;     /* second part's mean wall minus the first's, um */
    double nocomp_d_mm[4];   /* the same program with G1 and the tool centre on the contour */
    double nocomp_step_mm;   /* second part's wall minus the first's, without compensation */
    double station_s_mm[4];  /* where the stations are, mm along the wall from its start */
    double machining_time_s;
    double max_step_mm;      /* leg step of the drives (quantisation), mm */
};

/* Runs one experiment from the source tree root (the programs' folder is relative to it).
 * plot_dir (may be NULL) receives exp_run<name>_top.svg, _wall.svg and _3d.svg. */
int exp_run(const char *root, const struct exp_run_def *def, const char *plot_dir,
            struct exp_result *res, char *err, size_t errlen);

/* The wall frame of a run in the workpiece frame (origin: contour start). */
int exp_wall_frame(struct check_machine *mc, const struct exp_run_def *def, struct cut_wall *w);

#endif
