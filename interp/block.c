/* block.c: G and M codes to modal groups, and the checks on a block as a whole. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "interp/interp_int.h"

/* G codes this interpreter runs, x10, with their modal group (LinuxCNC's numbering). */
static const struct { int code, group; } g_table[] = {
    {0, 1},    {10, 1},   {20, 1},   {30, 1},   {40, 0},   {100, 0},  {170, 2},  {180, 2},
    {190, 2},  {200, 6},  {210, 6},  {410, 7},  {411, 7},  {420, 7},  {421, 7},  {280, 0},
    {281, 0},  {300, 0},  {301, 0},  {400, 7},  {430, 8},  {431, 8},  {432, 8},  {434, 8},
    {490, 8},  {530, 0},  {540, 12}, {550, 12}, {560, 12}, {570, 12}, {580, 12}, {590, 12},
    {591, 12}, {592, 12}, {593, 12}, {610, 13}, {611, 13}, {640, 13}, {730, 1},  {800, 1},
    {810, 1},  {820, 1},  {830, 1},  {850, 1},  {890, 1},  {900, 3},  {901, 4},  {910, 3},
    {911, 4},  {920, 0},  {921, 0},  {922, 0},  {923, 0},  {930, 5},  {940, 5},  {980, 10},
    {990, 10}, {1410, 0}, {1420, 0}, {51, 1},   {520, 0},  {50, 1},   {52, 1},   {53, 0},
    {950, 5},  {382, 1},  {383, 1},  {384, 1},  {385, 1},  {330, 1},  {331, 1},
};

/* RS274/NGC codes LinuxCNC knows that this interpreter does not run. */
static const int g_unsupported[] = {55, 61, 840, 860, 870, 880};

/* LinuxCNC's lathe codes: refused as such, not as unknown or "not yet". */
#define LATHE ", a lathe code: a hexapod has no turning spindle axis to run it"
static const struct { int code; const char *what; } g_lathe[] = {
    {70, "lathe diameter mode" LATHE}, {80, "lathe radius mode" LATHE},
    {700, "a lathe finishing cycle" LATHE}, {710, "a lathe roughing cycle" LATHE},
    {711, "a lathe roughing cycle" LATHE}, {720, "a lathe roughing cycle" LATHE},
    {721, "a lathe roughing cycle" LATHE}, {760, "lathe threading" LATHE},
    {960, "constant surface speed" LATHE}, {970, "the end of constant surface speed (G96)" LATHE},
};

/* Formats a code stored x10 as "92.1" or "1". */
static const char *code_str(int c10, char *buf)
{
    if (c10 % 10)
        sprintf(buf, "%d.%d", c10 / 10, c10 % 10);
    else
        sprintf(buf, "%d", c10 / 10);
    return buf;
}

/* Files G<v> in its modal group; refuses unknown codes and a second code of a group. */
int interp_add_g(struct interp *in, double v, int column)
{
    struct interp_block *b = &in->blk;
    double r = floor(v * 10.0 + 0.5);
    char s[32];
    if (fabs(v * 10.0 - r) > 0.001 || v < 0 || v > 10000)
        return interp_fail(in, INTERP_ERR_WORD, column, "G%g is not a G code", v);
    int c = (int)r;
    for (size_t i = 0; i < sizeof g_table / sizeof g_table[0]; i++) {
        if (g_table[i].code != c)
            continue;
        int grp = g_table[i].group;
        if (b->g[grp] >= 0) {
            char s2[32];
            return interp_fail(in, INTERP_ERR_MODAL, column,
                               "G%s and G%s in one block: both belong to modal group %d, only one "
                               "may be used", code_str(b->g[grp], s2), code_str(c, s), grp);
        }
        b->g[grp] = c;
        b->gcol[grp] = column;
        return 0;
    }
    for (size_t i = 0; i < sizeof g_lathe / sizeof g_lathe[0]; i++)
        if (g_lathe[i].code == c)
            return interp_fail(in, INTERP_ERR_UNSUPPORTED, column, "G%s is %s",
                               code_str(c, s), g_lathe[i].what);
    for (size_t i = 0; i < sizeof g_unsupported / sizeof g_unsupported[0]; i++)
        if (g_unsupported[i] == c)
            return interp_fail(in, INTERP_ERR_UNSUPPORTED, column, "G%s is not supported yet",
                               code_str(c, s));
    return interp_fail(in, INTERP_ERR_WORD, column, "G%s is not a G code this interpreter knows",
                       code_str(c, s));
}

/* Files M<v> in its modal group, as interp_add_g. */
int interp_add_m(struct interp *in, double v, int column)
{
    struct interp_block *b = &in->blk;
    int c, grp;
    CHP(interp_to_int(in, v, column, "an M code", &c));
    switch (c) {
    case 0: case 1: case 2: case 30: case 98: case 99: grp = 4; break;
    case 6: case 61: grp = 6; break;
    case 3: case 4: case 5: grp = 7; break;
    case 7: case 8: case 9: grp = 8; break;
    case 62: case 63: case 64: case 65: case 67: case 68: grp = 5; break;
    case 70: case 71: case 72: case 73: grp = 9; break;
    case 66: grp = 5; break;
    case 48: case 49: case 50: case 51: case 52: case 53: case 60:
        return interp_fail(in, INTERP_ERR_UNSUPPORTED, column, "M%d is not supported yet", c);
    default:
        return interp_fail(in, INTERP_ERR_WORD, column, "M%d is not an M code this interpreter "
                           "knows", c);
    }
    if (b->m[grp] >= 0)
        return interp_fail(in, INTERP_ERR_MODAL, column, "M%d and M%d in one block: both belong "
                           "to modal group %d, only one may be used", b->m[grp], c, grp);
    b->m[grp] = c;
    b->mcol[grp] = column;
    return 0;
}

/* The motion this block will do: its group 1 code, else the modal one for axis words. */
static int block_motion(const struct interp *in)
{
    if (in->blk.g[1] == 800)
        return -1;
    return in->blk.g[1] >= 0 ? in->blk.g[1] : in->motion;
}

/* Whether the block has any of X Y Z A B C. */
static int has_axis(const struct interp_block *b)
{
    return b->col['x' - 'a'] || b->col['y' - 'a'] || b->col['z' - 'a'] || b->col['a' - 'a'] ||
           b->col['b' - 'a'] || b->col['c' - 'a'];
}

/* Column of the first axis word, to point at it in errors. */
static int first_axis_col(const struct interp_block *b)
{
    static const char ax[] = "xyzabc";
    for (int i = 0; i < 6; i++)
        if (b->col[ax[i] - 'a'])
            return b->col[ax[i] - 'a'];
    return 0;
}

/* G73 and G81..G89 (x10). */
static int is_cycle(int g)
{
    return g == 730 || (g >= 810 && g <= 890);
}

/* Group 0 codes and motion codes that claim the axis words: at most one per block. */
static int check_axis_users(struct interp *in)
{
    struct interp_block *b = &in->blk;
    int g0 = b->g[0], g1 = b->g[1];
    int g0_axes = g0 == 100 || g0 == 280 || g0 == 300 || g0 == 920 || g0 == 520 ||
                  g0 == 1410 || g0 == 1420 || b->g[8] == 431 || b->g[8] == 432;
    char s[32], s2[32];
    if (g0 == 1410 || g0 == 1420) {
        if (g1 >= 0 && g1 != 10)
            return interp_fail(in, INTERP_ERR_MODAL, b->gcol[1], "G%s cannot be used with G%d: "
                               "G141/G142 compensate straight feed moves only (no G0, arcs or "
                               "cycles)", code_str(g1, s), g0 / 10);
        return 0;
    }
    if (g0_axes && g1 >= 0 && g1 != 800)
        return interp_fail(in, INTERP_ERR_MODAL, b->gcol[1], "G%s and G%s in one block both use "
                           "the axis words; put them in separate blocks",
                           code_str(g0 >= 0 ? g0 : b->g[8], s), code_str(g1, s2));
    if (!g0_axes && has_axis(b) && block_motion(in) < 0)
        return interp_fail(in, INTERP_ERR_MODAL, first_axis_col(b), "axis words with no motion "
                           "mode in force (after G80 or G5.3 give G0, G1, G2, G3 or a cycle)");
    if (g0 == 530) {
        int m = block_motion(in);
        if ((m != 0 && m != 10) || !has_axis(b))
            return interp_fail(in, INTERP_ERR_MODAL, b->gcol[0], "G53 needs G0 or G1 and axis "
                               "words in its block");
        if (b->g[3] >= 0 ? b->g[3] == 910 : in->incremental) /* G90 in the block counts */
            return interp_fail(in, INTERP_ERR_MODAL, b->gcol[0], "G53 cannot be used in "
                               "incremental distance mode (G91)");
    }
    return 0;
}

/* Which codes in this block may use a word; LinuxCNC rejects a word that nothing uses. */
static int word_used(const struct interp *in, char w)
{
    const struct interp_block *b = &in->blk;
    int g0 = b->g[0], m = block_motion(in);
    int comp = g0 == 1410 || g0 == 1420;
    int ccomp = b->g[7] >= 410;   /* G41, G41.1, G42, G42.1 */
    int arc = !comp && g0 < 0 && (m == 20 || m == 30);
    int cycle = !comp && g0 < 0 && is_cycle(m);
    int spline = !comp && g0 < 0;                      /* G5, G5.1 (with m) */
    int nurbs = spline && m == 52 && (b->g[1] == 52 || has_axis(b));  /* a G5.2 point */
    int sync = !comp && g0 < 0 && (m == 330 || m == 331);      /* G33 K, G33.1 K I */
    switch (w) {
    case 'i': return arc || g0 == 100 || (spline && (m == 51 || m == 50)) ||
                     (sync && m == 331);
    case 'j': return arc || g0 == 100 || (spline && (m == 51 || m == 50));
    case 'k': return arc || g0 == 100 || sync;
    case 'r': return arc || cycle || g0 == 100;
    case 'p': return arc || g0 == 40 || g0 == 100 || b->g[13] == 640 || b->m[4] == 98 ||
                     (cycle && (m == 820 || m == 890)) || (b->m[5] >= 62 && b->m[5] <= 66) ||
                     (spline && m == 50) || nurbs;
    case 'q': return (cycle && (m == 730 || m == 830)) || g0 == 100 || b->g[13] == 640 ||
                     b->m[6] == 61 || b->m[5] == 66 || b->m[5] == 67 || b->m[5] == 68 ||
                     (spline && m == 50);
    case 'e': return b->m[5] >= 66 && b->m[5] <= 68;
    case 'l': return cycle || g0 == 100 || b->m[5] == 66 || b->m[4] == 98 || ccomp || nurbs;
    case 'h': return b->g[8] == 430 || b->g[8] == 432 || b->g[8] == 434;
    case 'd': return comp || ccomp;
    case 'w': return comp;
    default: return 1;
    }
}

/* Refuses I J K R P Q L H D W E when nothing in the block uses them. */
static int check_unused(struct interp *in)
{
    static const char words[] = "ijkrpqlhdwe";
    static const char *const why[] = {
        "I is an arc centre word of G2/G3, and G33.1's spindle speed multiple for the way out",
        "I, J and K are arc centre words: use them with G2 or G3",
        "K is an arc centre word of G2/G3, and the distance per revolution of G33 and G33.1",
        "R is used by G2/G3 (radius), canned cycles (retract plane) and G10",
        "P is used by G4 (dwell), G10, G64, G2/G3 (turns), G5, G5.2, G82/G89 (dwell) and "
        "M62..M66",
        "Q is used by the peck cycles G73 and G83, G5, G10, G64, M61, M66, M67 and M68",
        "L is used by G10, G5.2, canned cycles (repeats), G41.1/G42.1 and M66",
        "H is used by G43, G43.2 (tool length offsets) and G43.4 (tool centre point control)",
        "D is used by G41/G42 and G141/G142 (tool number) and G41.1/G42.1 (diameter)",
        "W (tool radius) is only used with G141/G142",
        "E is the analog input of M66 and the analog output of M67 and M68",
    };
    for (int i = 0; words[i]; i++) {
        char w = words[i];
        int col = in->blk.col[w - 'a'];
        if (col && !word_used(in, w))
            return interp_fail(in, INTERP_ERR_WORD, col, "%c word with nothing in this block to "
                               "use it (%s)", w - 32, why[i]);
    }
    return 0;
}

/* The checks on a block as a whole, before anything of it runs. */
int interp_check_block(struct interp *in)
{
    CHP(check_axis_users(in));
    CHP(check_unused(in));
    return 0;
}
