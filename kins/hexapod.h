/* hexapod.h: the 6-UPS Stewart platform model's instance and its internal helpers. */
#ifndef HEXCNC_HEXAPOD_H
#define HEXCNC_HEXAPOD_H

#include <stdbool.h>
#include <stddef.h>

#include "kins/kins.h"

#define HEXAPOD_LEGS 6

/* Which body the moving platform carries; the other (tool or work) is fixed on the frame. */
enum hexapod_carries {
    HEXAPOD_CARRIES_WORKPIECE = 0, /* tool fixed on the frame, table moves (the TMU machine) */
    HEXAPOD_CARRIES_SPINDLE,       /* spindle on the platform, workpiece on the frame */
};

/* One hexapod: geometry, limits and solver settings, all read once from configuration. */
struct hexapod {
    struct kins base;                  /* generic part; must stay first */
    double b_mm[HEXAPOD_LEGS][3];      /* base joint centres in the base frame, mm */
    double p_mm[HEXAPOD_LEGS][3];      /* platform joint centres in the platform frame, mm */
    double offset_mm[HEXAPOD_LEGS];    /* leg length offsets: joint value (the length the
                                        * drive reports) + offset = joint-centre distance, mm */
    double pdist_mm[HEXAPOD_LEGS][HEXAPOD_LEGS]; /* platform joint spacing, mm */
    double bdist_mm[HEXAPOD_LEGS][HEXAPOD_LEGS]; /* base joint spacing, mm */
    double char_len_mm;                /* turns angular Jacobian columns (mm/rad) into mm/mm */
    double inv_char_len;               /* 1 / char_len_mm, 1/mm */
    double fwd_tol_mm;                 /* forward solve: largest final Newton step, mm */
    int fwd_max_iter;                  /* forward solve: Newton iteration limit */
    double singular_condition;         /* condition number above which a pose is near-singular */
    enum hexapod_carries carries;      /* what the platform carries */
    double tool_tip_mm[3];             /* tool tip (gauge point + length along the tool axis):
                                        * base frame if the tool is fixed, else platform frame */
    double tool_axis[3];               /* [KINS] TOOL_AXIS, unit length, in the same frame */
    double tool_gauge_mm[3];           /* [KINS] TOOL_POINT, in the same frame */
    double tool_len_mm;                /* [KINS] TOOL_LENGTH */
    int program_tip;                   /* [KINS] PROGRAM_POINT = TOOL_TIP */
    /* The workspace beyond leg lengths (hexapod_workspace.c, docs/kinematics.md). */
    double base_max_deg, plat_max_deg; /* [KINS] BASE_/PLATFORM_JOINT_MAX_ANGLE; 0: none */
    double base_cos_max, plat_cos_max; /* their cosines (-2 when there is no limit) */
    double base_jaxis[HEXAPOD_LEGS][3]; /* [KINS] BASE_JOINT_AXIS(_n): each base joint's
                                         * mounting axis, unit, base frame (default +Z) */
    double plat_jaxis[HEXAPOD_LEGS][3]; /* PLATFORM_JOINT_AXIS(_n): platform frame (+Z) */
    double leg_diameter_mm;            /* [KINS] LEG_DIAMETER; 0: collisions not checked */
    double leg_clearance_mm;           /* [KINS] LEG_CLEARANCE, kept between two legs */
    double axis_min[KINS_POSE_DIM];    /* [AXIS_X..C] MIN_LIMIT, MAX_LIMIT: the pose's soft */
    double axis_max[KINS_POSE_DIM];    /* limits, machine coordinates (+-inf: none) */
    bool axis_limited;                 /* any of them set */
    bool ws_extra;                     /* any workspace limit beyond the assembly set */
};

struct hexapod_rot;
struct hexapod_legs;

/* The workspace limits at a pose whose legs are evaluated (hexapod_workspace.c): KINS_OK,
 * or KINS_ERR_WORKSPACE with, when msg is given, what is violated, by how much and where. */
int hexapod_workspace(const struct hexapod *h, const double pose[KINS_POSE_DIM],
                      const struct hexapod_rot *o, const struct hexapod_legs *lg, char *msg,
                      size_t len);
/* Reads BASE_/PLATFORM_JOINT_MAX_ANGLE, LEG_DIAMETER and LEG_CLEARANCE. */
int hexapod_read_workspace(struct hexapod *h, const struct kins_config *cfg, char *err,
                           size_t errlen);

/* Reads geometry, leg limits, solver settings and tool data from cfg into h (hexapod_geom.c).
 * On failure err names the section and key. */
int hexapod_configure(struct hexapod *h, const struct kins_config *cfg, char *err,
                      size_t errlen);

/* Four inverses at once, bit for bit hexapod_inverse's (hexapod_batch.c); the kins_ops
 * inverse4 entry. */
void hexapod_inverse4(struct kins *k, const double (*pose)[KINS_POSE_DIM],
                      double (*joints)[KINS_MAX_JOINTS], int *status);

/* Four of the planner's samples at once, bit for bit hexapod's inverse_path (the kins_ops
 * inverse_path4 entry, hexapod_batch.c). */
void hexapod_inverse_path4(struct kins *k, const double (*pose)[KINS_POSE_DIM],
                           const double (*dp)[KINS_POSE_DIM], const double (*d2p)[KINS_POSE_DIM],
                           double (*joints)[KINS_MAX_JOINTS], double (*dL)[KINS_MAX_JOINTS],
                           double (*d2L)[KINS_MAX_JOINTS], int *status);

/* Forward kinematics by Newton-Raphson (hexapod_fwd.c); the kins_ops forward entry. */
int hexapod_forward(struct kins *k, const double *joints, double pose[KINS_POSE_DIM],
                    struct kins_fwd_info *info);
/* The kins_ops forward_near entry: a first step within accept_mm ends the solve. */
int hexapod_forward_near(struct kins *k, const double *joints, double pose[KINS_POSE_DIM],
                         double accept_mm, struct kins_fwd_info *info);

#endif
