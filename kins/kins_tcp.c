/* kins_tcp.c: tool centre point control's map between the tool tip and the platform pose. */
#include <math.h>
#include <string.h>

#include "common/simd.h"
#include "common/sincos4.h"
#include "kins/kins.h"

#define DEG (M_PI / 180.0)

/* R = Rz(C) Ry(B) Rx(A), row-major. */
static void rot(const double abc[3], double r[3][3])
{
    double x[3] = { abc[0] * DEG, abc[1] * DEG, abc[2] * DEG }, s[3], c[3];
    sincos3(x, s, c);
    double sa = s[0], ca = c[0], sb = s[1], cb = c[1], sc = s[2], cc = c[2];
    r[0][0] = cc * cb, r[0][1] = cc * sb * sa - sc * ca, r[0][2] = cc * sb * ca + sc * sa;
    r[1][0] = sc * cb, r[1][1] = sc * sb * sa + cc * ca, r[1][2] = sc * sb * ca - cc * sa;
    r[2][0] = -sb, r[2][1] = cb * sa, r[2][2] = cb * ca;
}

static void mul(const double r[3][3], const double v[3], double out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2];
}

static void mul_t(const double r[3][3], const double v[3], double out[3])
{
    for (int i = 0; i < 3; i++)
        out[i] = r[0][i] * v[0] + r[1][i] * v[1] + r[2][i] * v[2];
}

/* The tip in the frame the tool is on: gauge point + length along the axis. */
static void tip_on_tool(const struct kins_tool_frame *f, double len_mm, double d[3])
{
    for (int i = 0; i < 3; i++)
        d[i] = f->gauge_mm[i] + len_mm * f->axis[i];
}

/* Spindle on the platform: t = x - R d (d the tip in the platform frame).
 * Tool on the frame:       t = tip - R p (p the program's tip in the platform frame). */
void kins_tcp_to_pose(const struct kins_tool_frame *f, double len_mm,
                      const double prog[KINS_POSE_DIM], double pose[KINS_POSE_DIM])
{
    double r[3][3], d[3], rd[3];
    rot(prog + 3, r);
    tip_on_tool(f, len_mm, d);
    if (f->on_platform) {
        mul(r, d, rd);
        for (int i = 0; i < 3; i++)
            pose[i] = prog[i] - rd[i];
    } else {
        mul(r, prog, rd);
        for (int i = 0; i < 3; i++)
            pose[i] = d[i] - rd[i];
    }
    memmove(pose + 3, prog + 3, 3 * sizeof *pose);
}

/* Angular velocity of R (rad/s, base frame) from the A B C rates (deg/s):
 * w = C' z + B' Rz(C) y + A' Rz(C) Ry(B) x. */
static void omega(const double abc[3], const double rate[3], double w[3])
{
    double cb, sb, cc, sc;
    sincos(abc[1] * DEG, &sb, &cb);
    sincos(abc[2] * DEG, &sc, &cc);
    double a = rate[0] * DEG, b = rate[1] * DEG, c = rate[2] * DEG;
    w[0] = -sc * b + cc * cb * a;
    w[1] = cc * b + sc * cb * a;
    w[2] = c - sb * a;
}

void kins_tcp_to_pose_vel(const struct kins_tool_frame *f, double len_mm,
                          const double prog[KINS_POSE_DIM], const double prog_vel[KINS_POSE_DIM],
                          double pose[KINS_POSE_DIM], double pose_vel[KINS_POSE_DIM])
{
    double r[3][3], d[3], rd[3], w[3], rpv[3] = { 0, 0, 0 };
    rot(prog + 3, r);
    tip_on_tool(f, len_mm, d);
    omega(prog + 3, prog_vel + 3, w);
    mul(r, f->on_platform ? d : prog, rd);
    if (!f->on_platform)
        mul(r, prog_vel, rpv);
    /* d/dt (R v) = w x (R v) + R v' */
    double wx[3] = { w[1] * rd[2] - w[2] * rd[1], w[2] * rd[0] - w[0] * rd[2],
                     w[0] * rd[1] - w[1] * rd[0] };
    for (int i = 0; i < 3; i++) {
        if (f->on_platform) {
            pose[i] = prog[i] - rd[i];
            pose_vel[i] = prog_vel[i] - wx[i];
        } else {
            pose[i] = d[i] - rd[i];
            pose_vel[i] = -wx[i] - rpv[i];
        }
        pose[3 + i] = prog[3 + i];
        pose_vel[3 + i] = prog_vel[3 + i];
    }
}

void kins_tcp_from_pose(const struct kins_tool_frame *f, double len_mm,
                        const double pose[KINS_POSE_DIM], double prog[KINS_POSE_DIM])
{
    double r[3][3], d[3], v[3];
    rot(pose + 3, r);
    tip_on_tool(f, len_mm, d);
    if (f->on_platform) {
        mul(r, d, v);
        for (int i = 0; i < 3; i++)
            prog[i] = pose[i] + v[i];
    } else {
        for (int i = 0; i < 3; i++)
            v[i] = d[i] - pose[i];
        mul_t(r, v, prog);
    }
    memmove(prog + 3, pose + 3, 3 * sizeof *prog);
}

void kins_tcp_tool_dir(const struct kins_tool_frame *f, const double abc[3], double n[3])
{
    double r[3][3], up[3] = { -f->axis[0], -f->axis[1], -f->axis[2] };
    rot(abc, r);
    if (f->on_platform)
        mul(r, up, n);
    else
        mul_t(r, up, n);
}

/* kins_tcp_from_pose's tip for four poses at once (a check's tool tip in every period),
 * lane by lane rot(), tip_on_tool() and mul() or mul_t() on vectors of four: the same
 * operations in the same order, so the same bits (sincos4.h). */
HEXCNC_AVX2
static int tips4_avx2(const struct kins_tool_frame *f, double len_mm,
                      const double (*pose)[KINS_POSE_DIM], double (*tip)[3])
{
    v4d x[KINS_POSE_DIM], s[3], c[3];
    v4l bad = { 0, 0, 0, 0 };
    for (int i = 0; i < KINS_POSE_DIM; i++)
        x[i] = (v4d){ pose[0][i], pose[1][i], pose[2][i], pose[3][i] };
    for (int j = 0; j < 3; j++) {
        v4d a = x[3 + j] * DEG;
        SINCOS_LANES(a, s[j], c[j], bad);
    }
    if (bad[0] | bad[1] | bad[2] | bad[3])
        return 0;
    v4d sa = s[0], ca = c[0], sb = s[1], cb = c[1], sc = s[2], cc = c[2], r[3][3], out[3];
    r[0][0] = cc * cb, r[0][1] = cc * sb * sa - sc * ca, r[0][2] = cc * sb * ca + sc * sa;
    r[1][0] = sc * cb, r[1][1] = sc * sb * sa + cc * ca, r[1][2] = sc * sb * ca - cc * sa;
    r[2][0] = -sb, r[2][1] = cb * sa, r[2][2] = cb * ca;
    double d[3];
    tip_on_tool(f, len_mm, d);
    if (f->on_platform) {
        for (int i = 0; i < 3; i++)
            out[i] = x[i] + (r[i][0] * d[0] + r[i][1] * d[1] + r[i][2] * d[2]);
    } else {
        v4d v[3];
        for (int i = 0; i < 3; i++)
            v[i] = d[i] - x[i];
        for (int i = 0; i < 3; i++)
            out[i] = r[0][i] * v[0] + r[1][i] * v[1] + r[2][i] * v[2];
    }
    for (int l = 0; l < 4; l++)
        for (int i = 0; i < 3; i++)
            tip[l][i] = out[i][l];
    return 1;
}

int kins_tcp_tips4(const struct kins_tool_frame *f, double len_mm,
                   const double (*pose)[KINS_POSE_DIM], double (*tip)[3])
{
    return hexcnc_avx2() && tips4_avx2(f, len_mm, pose, tip);   /* (common/simd.h) */
}
