/* kins.h: the kinematics plugin boundary (one ops table per model, loaded by name). */
#ifndef HEXCNC_KINS_H
#define HEXCNC_KINS_H

#include <stddef.h>

/* A pose: X Y Z in mm, A B C in degrees, R = Rz(C)·Ry(B)·Rx(A). Index with KINS_X.. KINS_C. */
enum { KINS_X, KINS_Y, KINS_Z, KINS_A, KINS_B, KINS_C, KINS_POSE_DIM };

/* Most joints any model has (the hexapod has 6; trivial may have up to 9 for tests). */
#define KINS_MAX_JOINTS 9

/* Every kinematics call returns one of these; 0 is success. kins_strerror() gives the text. */
enum kins_status {
    KINS_OK = 0,
    KINS_ERR_CONFIG,         /* a configuration key is missing or wrong (message names it) */
    KINS_ERR_NOMEM,          /* allocation failed */
    KINS_ERR_PLUGIN,         /* plugin not found, not loadable, or without its ops table */
    KINS_ERR_UNREACHABLE,    /* pose outside the workspace: some leg length out of range */
    KINS_ERR_LEG_RANGE,      /* a given leg length is outside [min, max] */
    KINS_ERR_IMPOSSIBLE,     /* leg lengths no pose can have (assembly impossible) */
    KINS_ERR_SINGULAR,       /* Jacobian singular: forward met a pivot too small to divide
                              * by (check() reports the condition number against the
                              * configured threshold instead of failing) */
    KINS_ERR_NO_CONVERGE,    /* forward solve hit its iteration limit without converging */
    KINS_ERR_ARG,            /* bad argument (NaN, wrong count) */
    KINS_ERR_WORKSPACE,      /* legs in range, but the pose breaks another limit of the
                              * workspace: a joint's angle, two legs too close, the mirror
                              * assembly (describe() says which) */
    KINS_STATUS_COUNT
};
const char *kins_strerror(int status);

/* Configuration is read through a lookup function so kins/ needs no INI library:
 * get(ctx, "KINS", "BASE_RADIUS") returns the value text or NULL when the key is absent. */
struct kins_config {
    const char *(*get)(void *ctx, const char *section, const char *key);
    void *ctx;
};

/* Extra results of a forward solve. */
struct kins_fwd_info {
    int iterations;          /* Newton iterations used */
    double residual_mm;      /* largest leg-length residual at the end, mm */
};

/* Result of kins_check(). */
struct kins_check {
    int reachable;           /* 1 if every leg is within [min, max] */
    int worst_leg;           /* leg (0-based) closest to or beyond its limit */
    double leg_margin_mm;    /* distance of the worst leg to its nearest limit; < 0 beyond it */
    double condition;        /* condition number of the Jacobian (1 = perfect, inf = singular) */
    int near_singular;       /* 1 if condition exceeds the configured threshold */
};

/* Where the tool is on the machine: what tool centre point control needs (kins_tcp.c). */
struct kins_tool_frame {
    int on_platform;         /* 1: the spindle is on the platform (PLATFORM_CARRIES = SPINDLE),
                              * its data in the platform frame; 0: the tool is fixed on the
                              * machine frame (WORKPIECE), its data in the base frame */
    double gauge_mm[3];      /* [KINS] TOOL_POINT: the spindle's gauge point */
    double axis[3];          /* [KINS] TOOL_AXIS, unit: from the gauge point to the tip */
    double length_mm;        /* [KINS] TOOL_LENGTH: the tool length when no G43.4 H gave one */
    int program_tip;         /* [KINS] PROGRAM_POINT = TOOL_TIP: tool centre point control is
                              * the machine's default (else PLATFORM: the platform's pose) */
};

struct kins;

/* The ops table a plugin exports as `const struct kins_ops kins_<name>_ops` ('-' -> '_'). */
struct kins_ops {
    const char *name;        /* "hexapod", "trivial" */
    /* Builds an instance from configuration; on failure writes a message naming the
     * section and key into err and returns a status. */
    int (*create)(const struct kins_config *cfg, struct kins **out, char *err, size_t errlen);
    void (*destroy)(struct kins *k);
    /* pose[6] -> joints[njoints] (mm). Fails with KINS_ERR_UNREACHABLE when a leg is out
     * of range; joints are still written so callers can report by how much. */
    int (*inverse)(struct kins *k, const double pose[KINS_POSE_DIM], double *joints);
    /* joints -> pose. pose holds the starting guess on entry (warm start) and the result
     * on KINS_OK only; on failure it is left unchanged. info may be NULL. */
    int (*forward)(struct kins *k, const double *joints, double pose[KINS_POSE_DIM],
                   struct kins_fwd_info *info);
    /* Optional: forward from a guess known to lie close to the answer (a check's mid-chord
     * deviation starts from the commanded chord's midpoint, within about 1e-7 mm): a first
     * Newton step within accept_mm ends the solve, as its error is of the order of the
     * step's square over the machine's size; otherwise as forward. NULL: forward. */
    int (*forward_near)(struct kins *k, const double *joints, double pose[KINS_POSE_DIM],
                        double accept_mm, struct kins_fwd_info *info);
    /* Leg rates (mm/s) from pose and pose velocity (mm/s, deg/s) through the Jacobian. */
    int (*leg_rates)(struct kins *k, const double pose[KINS_POSE_DIM],
                     const double pose_vel[KINS_POSE_DIM], double *rates);
    /* Reachability and singularity measure of a pose (not on the servo hot path). */
    int (*check)(struct kins *k, const double pose[KINS_POSE_DIM], struct kins_check *out);
    /* Where the tool tip is at this pose: in the base (machine frame) and in the platform
     * frame, mm; either output may be NULL. NULL when the model has no tool (trivial). */
    int (*tool_point)(struct kins *k, const double pose[KINS_POSE_DIM], double tip_base_mm[3],
                      double tip_platform_mm[3]);
    /* Optional: inverse and leg rates from one evaluation of the pose (the servo thread
     * needs both every period). Statuses as inverse; rates are written only on KINS_OK.
     * NULL: kins_inverse_rates() calls inverse, then leg_rates. */
    int (*inverse_rates)(struct kins *k, const double pose[KINS_POSE_DIM],
                         const double pose_vel[KINS_POSE_DIM], double *joints, double *rates);
    /* Optional: why a pose is outside the workspace, in words for a machinist (which limit,
     * by how much, which joint or legs), or "" and KINS_OK when it is inside. NULL: the
     * model has no limits beyond the joints'. */
    int (*describe)(struct kins *k, const double pose[KINS_POSE_DIM], char *msg, size_t len);
    /* Optional: where the tool is (for tool centre point control). NULL: the model has no
     * tool, and G43.4 is refused on it. */
    int (*tool_frame)(struct kins *k, struct kins_tool_frame *out);
    /* Optional: joints at pose (statuses as inverse) and their first and second
     * derivatives along a path whose pose changes by dpose per unit of path and dpose by
     * d2pose (mm, deg per unit; the planner's samples), exact; written whatever the reach.
     * NULL: the planner differences three inverse solutions along the path. */
    int (*inverse_path)(struct kins *k, const double pose[KINS_POSE_DIM],
                        const double dpose[KINS_POSE_DIM], const double d2pose[KINS_POSE_DIM],
                        double *joints, double *djoints, double *d2joints);
    /* Optional: the Jacobian d joint_i / d pose_j at pose, row-major njoints x 6 (mm/mm,
     * mm/deg), analytic. Statuses as inverse (written whatever the reach). NULL: the planner
     * differences the inverse. */
    int (*jacobian)(struct kins *k, const double pose[KINS_POSE_DIM], double *jac);
    /* Optional: the matrix whose condition number `check` reports, row-major njoints x 6
     * (the hexapod's: its Jacobian with the angle columns scaled by the lever arm), cheaply,
     * so that a caller can bound the number between poses (kins_svd_extremes). Statuses:
     * KINS_ERR_ARG for a pose that is not a number, else KINS_OK whatever the reach. NULL:
     * no bound; check each pose. */
    int (*condition_matrix)(struct kins *k, const double pose[KINS_POSE_DIM], double *m);
    /* Optional: the inverse of four poses at once (pose[4] to joints[4] and status[4]),
     * each exactly as inverse gives it, joints and status, for a caller with poses ahead;
     * faster than four calls. NULL: kins_inverse4() calls inverse four times. */
    void (*inverse4)(struct kins *k, const double (*pose)[KINS_POSE_DIM],
                     double (*joints)[KINS_MAX_JOINTS], int *status);
    /* Optional, with inverse_path: inverse_path of four samples at once, each exactly as
     * inverse_path gives it. NULL: kins_inverse_path4() calls inverse_path four times. */
    void (*inverse_path4)(struct kins *k, const double (*pose)[KINS_POSE_DIM],
                          const double (*dpose)[KINS_POSE_DIM],
                          const double (*d2pose)[KINS_POSE_DIM],
                          double (*joints)[KINS_MAX_JOINTS], double (*djoints)[KINS_MAX_JOINTS],
                          double (*d2joints)[KINS_MAX_JOINTS], int *status);
};

/* Base of every instance; concrete models embed it first. */
struct kins {
    const struct kins_ops *ops;
    int njoints;                       /* number of joints (legs) */
    double joint_min[KINS_MAX_JOINTS]; /* leg length limits, mm */
    double joint_max[KINS_MAX_JOINTS];
    double home[KINS_POSE_DIM];        /* home pose: the forward solver's cold start */
    void *plugin_handle;               /* dlopen handle when loaded from a .so, else NULL */
};

/* Finds the ops table of kinematics `name` in its shared object: the first of
 *   $HEXCNC_PLUGIN_DIR/kins/<name>.so, <dir of /proc/self/exe>/../lib/kins/<name>.so,
 *   <install prefix>/lib/hexcnc/kins/<name>.so
 * that exists is dlopen()ed and its symbol kins_<name>_ops ('-' -> '_') returned; *handle
 * receives the dlopen handle (close it with dlclose, or let kins_free do it). Models linked
 * into the program are not searched: a program that wants them statically passes
 * &kins_<name>_ops to kins_create(). NULL with a message in err naming the plugin and every
 * path tried when no file exists, the file does not load, or it lacks the ops symbol. */
const struct kins_ops *kins_find(const char *name, void **handle, char *err, size_t errlen);

/* Loads kinematics `name` (e.g. from [KINS] KINEMATICS) through kins_find() and creates an
 * instance from cfg; the instance owns the plugin handle. KINS_ERR_PLUGIN or the model's
 * create status on failure, with the message in err. */
int kins_load(const char *name, const struct kins_config *cfg, struct kins **out,
              char *err, size_t errlen);
/* Creates an instance of a model linked into the program (e.g. &kins_hexapod_ops), without
 * dlopen: for tests and tools. Same statuses and messages as kins_load(). */
int kins_create(const struct kins_ops *ops, const struct kins_config *cfg, struct kins **out,
                char *err, size_t errlen);
/* Destroys an instance and closes its plugin. NULL is fine. */
void kins_free(struct kins *k);

/* Thin wrappers for callers. */
static inline int kins_inverse(struct kins *k, const double *pose, double *joints)
{ return k->ops->inverse(k, pose, joints); }
/* Four inverses, pose[4] to joints[4] and status[4] (see kins_ops.inverse4). */
void kins_inverse4(struct kins *k, const double (*pose)[KINS_POSE_DIM],
                   double (*joints)[KINS_MAX_JOINTS], int *status);
/* Four inverse_path samples (see kins_ops.inverse_path4; the model has inverse_path). */
void kins_inverse_path4(struct kins *k, const double (*pose)[KINS_POSE_DIM],
                        const double (*dpose)[KINS_POSE_DIM],
                        const double (*d2pose)[KINS_POSE_DIM], double (*joints)[KINS_MAX_JOINTS],
                        double (*djoints)[KINS_MAX_JOINTS], double (*d2joints)[KINS_MAX_JOINTS],
                        int *status);
static inline int kins_forward(struct kins *k, const double *joints, double *pose,
                               struct kins_fwd_info *info)
{ return k->ops->forward(k, joints, pose, info); }
static inline int kins_forward_near(struct kins *k, const double *joints, double *pose,
                                    double accept_mm, struct kins_fwd_info *info)
{
    return k->ops->forward_near ? k->ops->forward_near(k, joints, pose, accept_mm, info)
                                : k->ops->forward(k, joints, pose, info);
}
static inline int kins_leg_rates(struct kins *k, const double *pose, const double *vel,
                                 double *rates)
{ return k->ops->leg_rates(k, pose, vel, rates); }
/* Why pose is outside the workspace (see kins_ops.describe); "" when it is not. */
int kins_describe(struct kins *k, const double *pose, char *msg, size_t len);
static inline int kins_check_pose(struct kins *k, const double *pose, struct kins_check *out)
{ return k->ops->check(k, pose, out); }
/* Leg lengths and leg rates of a pose and its velocity, in one evaluation where the model
 * offers it. */
static inline int kins_inverse_rates(struct kins *k, const double *pose, const double *vel,
                                     double *joints, double *rates)
{
    if (k->ops->inverse_rates)
        return k->ops->inverse_rates(k, pose, vel, joints, rates);
    int st = k->ops->inverse(k, pose, joints);
    return st == KINS_OK ? k->ops->leg_rates(k, pose, vel, rates) : st;
}
static inline int kins_tool_point(struct kins *k, const double *pose, double *tip_base_mm,
                                  double *tip_platform_mm)
{ return k->ops->tool_point ? k->ops->tool_point(k, pose, tip_base_mm, tip_platform_mm)
                            : KINS_ERR_ARG; }

/* The matrix of kins_ops.condition_matrix; KINS_ERR_ARG when the model has none. */
static inline int kins_condition_matrix(struct kins *k, const double *pose, double *m)
{ return k->ops->condition_matrix ? k->ops->condition_matrix(k, pose, m) : KINS_ERR_ARG; }

/* The model's tool frame; KINS_ERR_ARG when it has none. */
static inline int kins_get_tool_frame(struct kins *k, struct kins_tool_frame *out)
{ return k->ops->tool_frame ? k->ops->tool_frame(k, out) : KINS_ERR_ARG; }

/*
 * Tool centre point control (G43.4, docs/kinematics.md): a "program pose" X Y Z A B C is the
 * tool tip and the orientation, in the frame that holds the workpiece: the base (machine)
 * frame when the platform carries the spindle, the platform (workpiece) frame when it carries
 * the workpiece. A B C stay the platform's orientation R = Rz(C) Ry(B) Rx(A). len_mm is the
 * tool's length beyond the gauge point along the tool axis. These are exact, rigid-body maps.
 */
/* The platform pose that puts the tip of a tool len_mm long at the program pose. */
void kins_tcp_to_pose(const struct kins_tool_frame *f, double len_mm,
                      const double prog[KINS_POSE_DIM], double pose[KINS_POSE_DIM]);
/* The same with velocities: prog_vel (mm/s, deg/s) -> pose_vel. */
void kins_tcp_to_pose_vel(const struct kins_tool_frame *f, double len_mm,
                          const double prog[KINS_POSE_DIM], const double prog_vel[KINS_POSE_DIM],
                          double pose[KINS_POSE_DIM], double pose_vel[KINS_POSE_DIM]);
/* The program pose (tip and orientation) of a platform pose: the inverse of the above. */
void kins_tcp_from_pose(const struct kins_tool_frame *f, double len_mm,
                        const double pose[KINS_POSE_DIM], double prog[KINS_POSE_DIM]);
/* The tips (kins_tcp_from_pose's first three values) of four poses at once, the same bits;
 * 1; 0, nothing written, when an angle lies beyond +-45 deg or is not finite, or the
 * processor has no AVX2 (the single call takes those: common/simd.h). */
int kins_tcp_tips4(const struct kins_tool_frame *f, double len_mm,
                   const double (*pose)[KINS_POSE_DIM], double (*tip)[3]);
/* The tool's direction from the tip back to the spindle, unit, in the program's frame at
 * orientation abc (deg): what G141/G142 take as the tool axis N under G43.4. */
void kins_tcp_tool_dir(const struct kins_tool_frame *f, const double abc[3], double n[3]);

/* The models this library links in, for kins_create(). */
extern const struct kins_ops kins_hexapod_ops;
extern const struct kins_ops kins_trivial_ops;

#endif
