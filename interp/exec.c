/* exec.c: runs one checked block in LinuxCNC's order of execution, emitting canon commands. */
#include <stdbool.h>
#include <math.h>
#include <string.h>

#include "interp/interp_int.h"
#include "interp/tooltable.h"

#define W(c) (in->blk.col[(c) - 'a'])    /* column of word c, 0 if absent */
#define V(c) (in->blk.val[(c) - 'a'])    /* value of word c */

/* A command of type t stamped with the current file, line and N number. */
void interp_cmd_init(struct interp *in, struct canon_cmd *c, enum canon_type t)
{
    memset(c, 0, sizeof *c);
    c->type = t;
    c->line = in->line;
    c->file = in->file;
    c->has_n = in->blk.n_present;
    c->n_number = in->blk.n_number;
    c->n_digits = in->blk.n_digits;
}

/* Every command carries the tool centre point state its pose is written in. */
static void stamp_tcp(const struct interp *in, struct canon_cmd *c)
{
    c->tcp = in->tcp_on;
    c->tool_len_mm = in->tcp_on ? in->tcp_len_mm : 0;
}

/* Hands a command to the sink (or, behind a G41/G42 move that waits for its corner, to the
 * queue); a refusal stops the run. */
int interp_emit(struct interp *in, struct canon_cmd *c)
{
    stamp_tcp(in, c);
    if (c->type == CANON_TRAVERSE || c->type == CANON_FEED || c->type == CANON_ARC)
        in->cc.resync = 0;              /* (a move after G40: the tool is where it says) */
    if (ccomp_holds(in, c->type))
        return ccomp_hold(in, c);
    if (in->sink(in->sink_ctx, c))
        return interp_fail(in, INTERP_ERR_SINK, 0, "the command consumer stopped the program");
    return 0;
}

/* The sink G141/G142 emit through: their moves carry the tool centre point state too. */
int interp_comp_sink(void *ctx, const struct canon_cmd *cmd)
{
    struct interp *in = ctx;
    struct canon_cmd c = *cmd;
    stamp_tcp(in, &c);
    return in->sink(in->sink_ctx, &c);
}

/* Emits a command that carries only a value / ivalue. */
static int emit_simple(struct interp *in, enum canon_type t, double value, int ivalue)
{
    struct canon_cmd c;
    interp_cmd_init(in, &c, t);
    c.value = value;
    c.ivalue = ivalue;
    c.feed_mm_min = in->feed_mm_min;
    return interp_emit(in, &c);
}

int interp_emit_path_mode(struct interp *in)
{
    struct canon_cmd c;
    interp_cmd_init(in, &c, CANON_PATH_MODE);
    c.ivalue = in->path_mode;
    c.value = in->path_mode == 640 ? in->path_tol_mm : 0.0;
    c.naive_tol_mm = in->path_mode == 640 ? in->naive_cam_tol_mm : 0.0;
    c.feed_mm_min = in->feed_mm_min;
    return interp_emit(in, &c);
}

void interp_modal_save(const struct interp *in, struct modal_save *m)
{
    m->valid = 1;
    m->inch = in->inch, m->plane = in->plane, m->incremental = in->incremental;
    m->arc_absolute = in->arc_absolute, m->inverse_time = in->inverse_time;
    m->per_rev = in->per_rev;
    m->coord_system = in->coord_system, m->retract_old_z = in->retract_old_z;
    m->path_mode = in->path_mode, m->path_tol_mm = in->path_tol_mm;
    m->naive_cam_tol_mm = in->naive_cam_tol_mm;
    m->feed_mm_min = in->feed_mm_min, m->f_word = in->f_word;
    m->spindle_rpm = in->spindle_rpm, m->spindle_dir = in->spindle_dir;
    m->mist = in->mist, m->flood = in->flood;
    memcpy(m->tool, in->tool, sizeof m->tool);
}

/* Puts a saved state back; what the machine must know of (feed, feed mode, path mode,
 * spindle, coolant, offsets) is sent on as it is when programmed. */
int interp_modal_restore(struct interp *in, const struct modal_save *m)
{
    in->inch = m->inch, in->plane = m->plane, in->incremental = m->incremental;
    in->arc_absolute = m->arc_absolute, in->retract_old_z = m->retract_old_z;
    in->f_word = m->f_word;
    if (in->inverse_time != m->inverse_time || in->per_rev != m->per_rev) {
        in->inverse_time = m->inverse_time;
        in->per_rev = m->per_rev;
        CHP(emit_simple(in, CANON_FEED_MODE, interp_feed_mode_value(in), 0));
    }
    if (in->feed_mm_min != m->feed_mm_min) {
        in->feed_mm_min = m->feed_mm_min;
        CHP(emit_simple(in, CANON_FEED_RATE, in->f_word, in->per_rev));
    }
    if (in->path_mode != m->path_mode || in->path_tol_mm != m->path_tol_mm ||
        in->naive_cam_tol_mm != m->naive_cam_tol_mm) {
        in->path_mode = m->path_mode, in->path_tol_mm = m->path_tol_mm;
        in->naive_cam_tol_mm = m->naive_cam_tol_mm;
        CHP(interp_emit_path_mode(in));
    }
    if (in->spindle_rpm != m->spindle_rpm) {
        in->spindle_rpm = m->spindle_rpm;
        CHP(emit_simple(in, CANON_SPINDLE_SPEED, in->spindle_rpm, 0));
    }
    if (in->spindle_dir != m->spindle_dir) {
        in->spindle_dir = m->spindle_dir;
        CHP(emit_simple(in, in->spindle_dir ? CANON_SPINDLE_ON : CANON_SPINDLE_STOP,
                        in->spindle_dir, 0));
    }
    if (in->mist != m->mist || in->flood != m->flood) {
        in->mist = m->mist, in->flood = m->flood;
        CHP(emit_simple(in, CANON_COOLANT, 0, 9));
        if (in->mist)
            CHP(emit_simple(in, CANON_COOLANT, 0, 7));
        if (in->flood)
            CHP(emit_simple(in, CANON_COOLANT, 0, 8));
    }
    bool offsets = memcmp(in->tool, m->tool, sizeof m->tool) != 0;
    memcpy(in->tool, m->tool, sizeof in->tool);
    if (in->coord_system != m->coord_system) {
        interp_select_coord(in, m->coord_system);
        offsets = true;
    }
    return offsets ? interp_emit_offsets(in) : 0;
}

/* M70 save, M71 forget, M72 restore the modal state; M73 save it for the return of the
 * subroutine it is in (docs/gcode.md). */
static int exec_modal_state(struct interp *in, const struct interp_block *b)
{
    struct oword *ow = &in->ow;
    switch (b->m[9]) {
    case 70:
        interp_modal_save(in, &in->m70);
        return 0;
    case 71:
        in->m70.valid = 0;
        if (ow->ncalls > 0)
            ow->calls[ow->ncalls - 1].m73.valid = 0;
        return 0;
    case 72:
        if (!in->m70.valid)
            return interp_fail(in, INTERP_ERR_MODAL, b->mcol[9], "M72: no modal state to "
                               "restore (M70 saves it; M71 forgot it)");
        return interp_modal_restore(in, &in->m70);
    default:
        /* outside a subroutine there is no return to restore at: nothing, as in LinuxCNC */
        if (ow->ncalls > 0)
            interp_modal_save(in, &ow->calls[ow->ncalls - 1].m73);
        return 0;
    }
}

/* M66 P|E L Q: wait on an input; the machine's answer (interp_set_input_fn) is #5399. */
static int exec_wait(struct interp *in, const struct interp_block *b)
{
    int n, mode = 0;
    bool analog = W('e') != 0;
    if (W('p') && W('e'))
        return interp_fail(in, INTERP_ERR_WORD, W('e'), "M66: give a P word (digital input) "
                           "or an E word (analog input), not both");
    if (!W('p') && !W('e'))
        return interp_fail(in, INTERP_ERR_WORD, b->mcol[5], "M66 needs a P word (the digital "
                           "input's number) or an E word (the analog input's number)");
    char w = analog ? 'e' : 'p';
    CHP(interp_to_int(in, V(w), W(w), analog ? "E (analog input)" : "P (digital input)", &n));
    if (n < 0)
        return interp_fail(in, INTERP_ERR_WORD, W(w), "M66: input %d: inputs are numbered "
                           "from 0", n);
    if (W('l'))
        CHP(interp_to_int(in, V('l'), W('l'), "L (wait mode)", &mode));
    if (mode < 0 || mode > 4)
        return interp_fail(in, INTERP_ERR_WORD, W('l'), "M66 L%d: the wait mode is 0 (read at "
                           "once), 1 (rise), 2 (fall), 3 (high) or 4 (low)", mode);
    if (analog && mode != 0)
        return interp_fail(in, INTERP_ERR_WORD, W('l'), "M66 E%d L%d: an analog input can only "
                           "be read at once (L0)", n, mode);
    double timeout = W('q') ? V('q') : 0;
    if (mode != 0 && !(timeout > 0))
        return interp_fail(in, INTERP_ERR_WORD, W('q') ? W('q') : b->mcol[5], "M66 L%d needs a "
                           "Q word: the time-out in seconds, more than 0", mode);
    struct canon_cmd c;
    interp_cmd_init(in, &c, CANON_WAIT_INPUT);
    c.ivalue = n;
    c.analog = analog;
    c.wait_mode = mode;
    c.value = mode != 0 ? timeout : 0;
    c.feed_mm_min = in->feed_mm_min;
    CHP(interp_emit(in, &c));
    /* the lines after it see the machine's answer; without a machine (check, hexcnc interp)
     * it is 0, as LinuxCNC's rs274 reads it */
    in->params[5399] = in->input_fn ? in->input_fn(in->input_ctx, &c) : 0;
    return 0;
}

/* M62..M65 P: a digital output; M67/M68 E Q: an analog output (docs/gcode.md). */
static int exec_io(struct interp *in, const struct interp_block *b)
{
    int code = b->m[5], n;
    if (code == 66)
        return exec_wait(in, b);
    struct canon_cmd c;
    bool digital = code <= 65;
    char w = digital ? 'p' : 'e';
    if (!W(w))
        return interp_fail(in, INTERP_ERR_WORD, b->mcol[5], "M%d needs %s", code, digital
                           ? "a P word: the digital output's number" : "an E word (the analog "
                           "output's number) and a Q word (its value)");
    CHP(interp_to_int(in, V(w), W(w), digital ? "P (digital output)" : "E (analog output)",
                      &n));
    if (n < 0)
        return interp_fail(in, INTERP_ERR_WORD, W(w), "M%d: output %d: outputs are numbered "
                           "from 0", code, n);
    if (!digital && !W('q'))
        return interp_fail(in, INTERP_ERR_WORD, b->mcol[5], "M%d needs a Q word: the value "
                           "of analog output %d", code, n);
    interp_cmd_init(in, &c, digital ? CANON_DIGITAL_OUT : CANON_ANALOG_OUT);
    c.ivalue = n;
    c.value = digital ? (code == 62 || code == 64) : V('q');
    c.immediate = code == 64 || code == 65 || code == 68;
    c.feed_mm_min = in->feed_mm_min;
    return interp_emit(in, &c);
}

/* A length in program units (mm or inch) to mm. */
double interp_len_mm(const struct interp *in, double v)
{
    return in->inch ? v * MM_PER_INCH : v;
}

/* The current pose in program coordinates: offsets removed, program units. */
void interp_prog_pos(const struct interp *in, double prog[6])
{
    for (int i = 0; i < 6; i++)
        prog[i] = in->pos[i] - in->g5x[i] - in->g92[i] - in->tool[i];
    if (in->rot_deg != 0.0) {   /* X Y in the rotated frame (rotation.c) */
        double q[2];
        interp_rotated_pos(in, q);
        prog[AX_X] = q[0] - in->g92[AX_X];
        prog[AX_Y] = q[1] - in->g92[AX_Y];
    }
    if (in->inch)
        for (int i = 0; i < 3; i++)
            prog[i] /= MM_PER_INCH;
}

/* Axis words to a machine target: absent axes stay, G91 adds, G90 adds the offsets. */
void interp_target(struct interp *in, int machine, double t[6])
{
    static const char ax[6] = {'x', 'y', 'z', 'a', 'b', 'c'};
    for (int i = 0; i < 6; i++) {
        if (!W(ax[i])) {
            t[i] = in->pos[i];
            continue;
        }
        double v = i < 3 ? interp_len_mm(in, V(ax[i])) : V(ax[i]);
        if (machine)
            t[i] = v;
        else if (in->incremental && !(i < 2 && in->blk.polar_inc))
            t[i] = in->pos[i] + v;
        else
            t[i] = v + in->g5x[i] + in->g92[i] + in->tool[i];
    }
    if (in->rot_deg != 0.0 && !machine && (W('x') || W('y'))) {
        /* X Y in the rotated frame: G91 steps along the turned axes, as LinuxCNC */
        double cur[6], p[2];
        interp_prog_pos(in, cur);
        for (int i = 0; i < 2; i++) {
            p[i] = cur[i];
            if (W(ax[i]))
                p[i] = in->incremental && !in->blk.polar_inc ? cur[i] + V(ax[i]) : V(ax[i]);
        }
        interp_xy_to_machine(in, p[0], p[1], t);
    }
}

/* Emits a straight move (traverse or feed) to end and makes it the current pose. */
int interp_straight(struct interp *in, enum canon_type t, const double end[6])
{
    struct canon_cmd c;
    interp_cmd_init(in, &c, t);
    memcpy(c.end, end, sizeof c.end);
    c.feed_mm_min = in->feed_mm_min;
    if (t != CANON_TRAVERSE && in->inverse_time)
        c.inverse_time_min = 1.0 / in->f_word;
    memcpy(in->pos, end, sizeof in->pos);
    return interp_emit(in, &c);
}

/* Feed moves need a feed: a non-zero F in force, or F in this very block under G93. */
int interp_need_feed(struct interp *in, const char *what)
{
    int col = in->blk.g[1] >= 0 ? in->blk.gcol[1] : 0;
    if (in->inverse_time && !W('f'))
        return interp_fail(in, INTERP_ERR_WORD, col, "%s in inverse time mode (G93) needs an F "
                           "word in the same block", what);
    if (in->f_word <= 0.0)
        return interp_fail(in, INTERP_ERR_WORD, col, "%s with zero feed rate: give an F word "
                           "first", what);
    return in->per_rev ? interp_need_spindle(in, what, col) : 0;
}

/* F, S, T, M6, M3/M4/M5, M7/M8/M9 and G4: the first steps of LinuxCNC's order. */
static int exec_machine_words(struct interp *in)
{
    struct interp_block *b = &in->blk;
    if (b->g[5] >= 0) {
        in->inverse_time = b->g[5] == 930;
        in->per_rev = b->g[5] == 950;
        CHP(emit_simple(in, CANON_FEED_MODE, interp_feed_mode_value(in), 0));
    }
    if (W('f')) {
        if (V('f') < 0)
            return interp_fail(in, INTERP_ERR_WORD, W('f'), "negative F word (feed) %g", V('f'));
        in->f_word = V('f'); /* converted once the block's units are known */
    }
    if (W('s')) {
        if (V('s') < 0)
            return interp_fail(in, INTERP_ERR_WORD, W('s'), "negative S word (spindle speed) %g",
                               V('s'));
        in->spindle_rpm = V('s');
        CHP(emit_simple(in, CANON_SPINDLE_SPEED, in->spindle_rpm, 0));
    }
    if (W('t')) {
        int t;
        CHP(interp_to_int(in, V('t'), W('t'), "T (tool number)", &t));
        if (t < 0 || (t > 0 && in->tt && !tooltable_find(in->tt, t)))
            return interp_fail(in, INTERP_ERR_TOOL, W('t'), "tool T%d is not in the tool table%s%s",
                               t, in->tt && in->tt->path[0] ? " " : "",
                               in->tt ? in->tt->path : "");
        in->selected_tool = t;
    }
    if (b->m[5] >= 0)  /* M62..M68 after the tool selection, before M6 (LinuxCNC's order) */
        CHP(exec_io(in, b));
    if (b->m[6] == 6) {
        ccomp_tool_change(in);
        in->current_tool = in->selected_tool;
        CHP(emit_simple(in, CANON_TOOL_CHANGE, 0, in->current_tool));
    } else if (b->m[6] == 61) {  /* M61 Q: the tool in the spindle is n, nothing moves */
        int t;
        if (!W('q'))
            return interp_fail(in, INTERP_ERR_WORD, b->mcol[6], "M61 needs a Q word: the number "
                               "of the tool now in the spindle");
        CHP(interp_to_int(in, V('q'), W('q'), "M61 Q (tool number)", &t));
        if (t < 0 || (t > 0 && in->tt && !tooltable_find(in->tt, t)))
            return interp_fail(in, INTERP_ERR_TOOL, W('q'), "M61 Q%d: tool %d is not in the "
                               "tool table%s%s", t, t, in->tt && in->tt->path[0] ? " " : "",
                               in->tt ? in->tt->path : "");
        in->current_tool = t;
        CHP(emit_simple(in, CANON_TOOL_CHANGE, 1, in->current_tool));
    }
    if (b->m[7] == 3 || b->m[7] == 4) {
        in->spindle_dir = b->m[7] == 3 ? 1 : -1;
        CHP(emit_simple(in, CANON_SPINDLE_ON, in->spindle_dir, 0));
    } else if (b->m[7] == 5) {
        in->spindle_dir = 0;
        CHP(emit_simple(in, CANON_SPINDLE_STOP, 0, 0));
    }
    if (b->m[9] >= 0)  /* M70..M73 after the spindle, before coolant (LinuxCNC's order) */
        CHP(exec_modal_state(in, b));
    if (b->m[8] >= 0) {
        in->mist = b->m[8] == 7 || (b->m[8] == 8 && in->mist);
        in->flood = b->m[8] == 8 || (b->m[8] == 7 && in->flood);
        CHP(emit_simple(in, CANON_COOLANT, 0, b->m[8]));
    }
    if (b->g[0] == 40) {
        if (!W('p') || V('p') < 0)
            return interp_fail(in, INTERP_ERR_WORD, b->gcol[0], "G4 needs a P word: the dwell "
                               "time in seconds (0 or more)");
        CHP(emit_simple(in, CANON_DWELL, V('p'), 0));
    }
    return 0;
}

/* Plane, units, G40, tool length, coordinate system, path mode, distance, retract. */
static int exec_modes(struct interp *in)
{
    struct interp_block *b = &in->blk;
    if (b->g[2] >= 0)
        in->plane = b->g[2] / 10;
    if (b->g[6] >= 0 && in->inch != (b->g[6] == 200)) {
        in->inch = b->g[6] == 200;
        if (in->cc.side != CCOMP_OFF)  /* compensation works in program units */
            ccomp_scale(in, in->inch ? 1.0 / MM_PER_INCH : MM_PER_INCH);
    }
    /* F is in the units in force (inch/min under G20, else FEED_UNITS) */
    in->feed_mm_min = interp_feed_mm_min(in);
    if (W('f') && !in->inverse_time)
        CHP(emit_simple(in, CANON_FEED_RATE, in->f_word, in->per_rev));
    if (b->g[7] >= 0)
        CHP(ccomp_mode(in, b->g[7]));
    if (b->g[8] >= 0)
        CHP(interp_tool_length(in, b->g[8]));
    if (b->g[12] >= 0) {
        int c = b->g[12], sys = c < 591 ? (c - 540) / 10 + 1 : c - 591 + 7;
        interp_select_coord(in, sys);
        CHP(interp_emit_offsets(in));
    }
    if (b->g[13] >= 0) {
        in->path_mode = b->g[13];
        in->path_tol_mm = b->g[13] == 640 && W('p') ? interp_len_mm(in, V('p')) : 0.0;
        if (in->path_tol_mm < 0)
            return interp_fail(in, INTERP_ERR_WORD, W('p'), "G64 P (blend tolerance) must not "
                               "be negative");
        /* Q absent: P's value, as LinuxCNC takes it */
        in->naive_cam_tol_mm = b->g[13] != 640 ? 0.0 : W('q') ? interp_len_mm(in, V('q'))
                                                               : in->path_tol_mm;
        if (in->naive_cam_tol_mm < 0)
            return interp_fail(in, INTERP_ERR_WORD, W('q'), "G64 Q (naive CAM tolerance) must "
                               "not be negative");
        CHP(interp_emit_path_mode(in));
    }
    if (b->g[3] >= 0)
        in->incremental = b->g[3] == 910;
    if (b->g[4] >= 0)
        in->arc_absolute = b->g[4] == 901;
    if (b->g[10] >= 0)
        in->retract_old_z = b->g[10] == 980;
    return 0;
}

/* G141/G142: the programmed point, resolved as for G1, handed to the compensation. */
static int exec_comp5(struct interp *in, int g)
{
    struct comp5_block cb;
    memset(&cb, 0, sizeof cb);
    if (W('w') && W('d'))
        return interp_fail(in, INTERP_ERR_WORD, W('d'), "G%d with both W and D: give the tool "
                           "radius (W) or the tool whose radius to use (D), not both", g / 10);
    if (W('w')) {
        in->comp_radius_mm = interp_len_mm(in, V('w'));
    } else if (W('d')) {
        int t, rc;
        CHP(interp_to_int(in, V('d'), W('d'), "D (tool number)", &t));
        if (!in->tt)
            return interp_fail(in, INTERP_ERR_TOOL, W('d'), "D%d needs a tool table (give one "
                               "with -t or [EMCIO] TOOL_TABLE)", t);
        rc = tooltable_radius(in->tt, t, &in->comp_radius_mm);
        if (rc)
            return interp_fail(in, INTERP_ERR_TOOL, W('d'), "D%d: %s", t, tooltable_strerror(rc));
    }
    CHP(interp_need_feed(in, g == 1410 ? "G141" : "G142"));
    cb.side = g / 10;
    interp_target(in, 0, cb.point);
    cb.radius_mm = in->comp_radius_mm;
    cb.feed_mm_min = in->feed_mm_min;
    cb.line = in->line;
    cb.file = in->file;
    cb.unit_mm = interp_len_mm(in, 1.0);
    for (int i = 0; i < 3; i++)
        cb.prog_off_mm[i] = in->g5x[i] + in->g92[i] + in->tool[i];
    in->comp.tf = in->tcp_on ? &in->tf : NULL;  /* G43.4: the tool axis in the program's frame */
    if (in->contour_fn)
        in->contour_fn(in->contour_ctx, in->line, !in->comp.active, in->pos, cb.point);
    int rc = comp5_block(&in->comp, &cb, in->pos, interp_comp_sink, in);
    if (rc) {
        int col = rc == COMP5_ERR_RADIUS ? (W('w') ? W('w') : W('d')) : 0;
        interp_fail(in, INTERP_ERR_COMP5, col, "%s", comp5_errmsg(&in->comp));
        in->err.line = in->comp.err_line ? in->comp.err_line : in->line;
        return INTERP_ERR_COMP5;
    }
    memcpy(in->pos, cb.point, sizeof in->pos);
    return 0;
}

/* Ends an open G141/G142 run; the tool is then where the compensation left it. */
static int flush_comp5(struct interp *in)
{
    if (!in->comp.active)
        return 0;
    int rc = comp5_flush(&in->comp, interp_comp_sink, in);
    in->comp_radius_mm = 0;
    if (rc) {
        interp_fail(in, INTERP_ERR_COMP5, 0, "%s", comp5_errmsg(&in->comp));
        in->err.line = in->comp.err_line ? in->comp.err_line : in->line;
        return INTERP_ERR_COMP5;
    }
    memcpy(in->pos, comp5_tool_pos(&in->comp), sizeof in->pos);
    return 0;
}

#define DEG (M_PI / 180.0)

void interp_polar_step(const struct interp *in, double *x, double *y)
{
    const struct interp_block *b = &in->blk;
    double r = hypot(*x, *y) + (b->col[26] ? b->val[26] : 0);
    double a = atan2(*y, *x) + (b->col[27] ? b->val[27] * DEG : 0);
    *x = r * cos(a);
    *y = r * sin(a);
}

/* @ and ^ to X and Y words: G90 takes the radius and angle about the program origin (the
 * current one for a word left out), G91 adds them to the current point's (which must not be
 * the origin, where its angle is not defined). LinuxCNC's rules: in the XY plane, which must
 * be the plane in force when the block starts (a G18 in the same block does not count). */
int interp_polar_words(struct interp *in)
{
    struct interp_block *b = &in->blk;
    int col = b->col[26] ? b->col[26] : b->col[27];
    if (!col)
        return 0;
    if (b->plane_before != 17)  /* rs274 checks the plane the block starts in */
        return interp_fail(in, INTERP_ERR_WORD, col, "polar coordinates (@ ^) need the XY "
                           "plane (G17) in force before the block");
    if (W('x') || W('y'))
        return interp_fail(in, INTERP_ERR_WORD, W('x') ? W('x') : W('y'), "%c and polar "
                           "coordinates (@ ^) in one block: give the point one way",
                           W('x') ? 'X' : 'Y');
    double cur[6];
    interp_prog_pos(in, cur);
    double x = cur[0], y = cur[1];
    if (in->incremental) {
        if (fabs(x) < 1e-12 && fabs(y) < 1e-12)
            return interp_fail(in, INTERP_ERR_WORD, col, "G91 with polar coordinates at the "
                               "origin: the angle of the present point is not defined");
        interp_polar_step(in, &x, &y);
        b->polar_inc = 1;
    } else {
        double r = b->col[26] ? b->val[26] : hypot(x, y);
        double a = b->col[27] ? b->val[27] * DEG : atan2(y, x);
        x = r * cos(a);
        y = r * sin(a);
    }
    b->col['x' - 'a'] = b->col['y' - 'a'] = col;
    b->val['x' - 'a'] = x;
    b->val['y' - 'a'] = y;
    return 0;
}

/* The motion of the block: G0 G1 G2 G3, canned cycles, G53 moves. */
static int exec_motion(struct interp *in)
{
    struct interp_block *b = &in->blk;
    int g0 = b->g[0], prev_motion = in->motion;
    CHP(interp_polar_words(in));
    if (b->g[1] >= 0) {
        in->motion = b->g[1] == 800 ? -1 : b->g[1];
        if (b->g[1] == 0 || b->g[1] == 10 || b->g[1] == 20 || b->g[1] == 30 || b->g[1] == 800 ||
            (b->g[1] >= 382 && b->g[1] <= 385) || b->g[1] == 330 || b->g[1] == 331)
            in->cycle_mode = in->cycle_il_on = 0;
    }
    if (g0 == 100 || g0 == 280 || g0 == 300 || g0 == 920 || g0 == 520 || b->g[8] == 431 ||
        b->g[8] == 432)
        return 0; /* those blocks' axis words are not motion */
    int m = in->motion;
    int axis = W('x') || W('y') || W('z') || W('a') || W('b') || W('c');
    double t[6];
    if (m == 0 || m == 10) {
        if (!axis && b->g[1] < 0)
            return 0;  /* a G0/G1 word without axis words is a move where the tool is (rs274) */
        if (m == 10)
            CHP(interp_need_feed(in, "G1"));
        interp_target(in, g0 == 530, t);
        in->cc.arc_not_allowed = 0;
        if (ccomp_active(in))
            return ccomp_straight(in, m, t);
        return interp_straight(in, m == 0 ? CANON_TRAVERSE : CANON_FEED, t);
    }
    if (m == 20 || m == 30) {
        if (!axis && !W('i') && !W('j') && !W('k') && !W('r'))
            return 0;
        CHP(interp_need_feed(in, m == 20 ? "G2" : "G3"));
        return interp_arc(in, m);
    }
    if (m >= 382 && m <= 385) {
        if (!axis && b->g[1] >= 0)
            return interp_fail(in, INTERP_ERR_WORD, b->gcol[1], "G38.%d needs axis words: the "
                               "point to probe towards", m - 380);
        return axis ? interp_probe(in, m) : 0;
    }
    if (m == 50 || m == 51) {
        in->motion = prev_motion;   /* G5 and G5.1 leave the motion mode as it was (rs274) */
        if (!axis && !W('i') && !W('j') && !W('p') && !W('q'))
            return 0;
        CHP(interp_need_feed(in, m == 50 ? "G5" : "G5.1"));
        return m == 50 ? interp_spline_cubic(in) : interp_spline(in);
    }
    if (m == 52)
        return b->g[1] == 52 || axis ? interp_nurbs_point(in, prev_motion) : 0;
    if (m == 330 || m == 331)
        return interp_sync_move(in, m, axis);
    if (m >= 0 && axis)
        return interp_cycle(in, m);
    return 0;
}

/* M2/M30: LinuxCNC's end-of-program resets, then the end itself. M0/M1 pause. */
static int exec_stop(struct interp *in)
{
    int m = in->blk.m[4];
    if (m == 98)
        return oword_m98(in);
    if (m == 99) {
        int end;
        CHP(oword_m99(in, &end));
        if (!end)
            return 0;
        m = 2;               /* the main program's M99 ends it */
    }
    if (m == 0 || m == 1 || m == 2 || m == 30)
        CHP(ccomp_flush(in));  /* a stop sends the queued G41/G42 move, as rs274 */
    if (m == 0 || m == 1)
        return emit_simple(in, CANON_PAUSE, 0, m);
    if (m != 2 && m != 30)
        return 0;
    in->cc.side = CCOMP_OFF;  /* LinuxCNC's end-of-program resets */
    in->cc.first = 1;
    if (in->coord_system != 1) {
        interp_select_coord(in, 1);
        CHP(interp_emit_offsets(in));
    }
    in->plane = 17;
    in->incremental = 0;
    in->inverse_time = 0;
    in->per_rev = 0;
    in->motion = 10;
    in->spindle_dir = 0;
    CHP(emit_simple(in, CANON_SPINDLE_STOP, 0, 0));
    CHP(emit_simple(in, CANON_COOLANT, 0, 9));
    in->flood = in->mist = 0;
    in->ended = 1;
    CHP(interp_emit_param_changes(in)); /* the program end is the last thing motion passes */
    return emit_simple(in, CANON_PROGRAM_END, 0, m);
}

/* Whether the block holds anything but a comment (an empty block keeps a G141/G142 run open). */
static int block_empty(const struct interp_block *b)
{
    for (int i = 0; i < 26; i++)
        if (b->col[i])
            return 0;
    for (int i = 0; i < INTERP_GROUPS; i++)
        if (b->g[i] >= 0)
            return 0;
    for (int i = 0; i < INTERP_MGROUPS; i++)
        if (b->m[i] >= 0)
            return 0;
    return b->nassign == 0;
}

/* After a tool change, rs274 takes the position it last commanded as the current one, in
 * the coordinates of that command: a tool length offset changed in the M6 block itself (`T1
 * M6 G43 H1`, as CAM posts write it) then does not shift the current point, and the next
 * move without Z keeps the commanded Z. The same here, so that programs run as in LinuxCNC. */
static void tool_change_reread(struct interp *in, const double tool_before[6])
{
    for (int i = 0; i < 6; i++)
        in->pos[i] += in->tool[i] - tool_before[i];
}

/* Runs the block read last: checks, #settings, then LinuxCNC's order of execution. */
int interp_execute(struct interp *in)
{
    struct interp_block *b = &in->blk;
    CHP(interp_check_block(in));
    CHP(ccomp_check_block(in));
    for (int i = 0; i < b->nassign; i++) {
        if (b->assign_named[i])
            interp_named_set(in, b->assign_idx[i], b->assign_val[i]);
        else
            in->params[b->assign_idx[i]] = b->assign_val[i];
    }
    int g0 = b->g[0];
    int comp = g0 == 1410 || g0 == 1420;
    b->plane_before = in->plane;
    if (!comp && !block_empty(b))
        CHP(flush_comp5(in));
    if (b->has_comment)
        CHP(interp_comment(in, b->comment));
    double tool_before[6], pos_before[6];
    memcpy(tool_before, in->tool, sizeof tool_before);
    CHP(exec_machine_words(in));
    CHP(exec_modes(in));
    if (g0 == 100)
        CHP(interp_g10(in));
    else if (g0 == 280 || g0 == 281 || g0 == 300 || g0 == 301)
        CHP(interp_home(in, g0));
    else if ((g0 >= 920 && g0 <= 923) || g0 == 520)
        CHP(interp_g92(in, g0));
    else if (g0 == 53)
        CHP(interp_nurbs_end(in));
    if (comp && b->g[1] >= 0)
        in->motion = b->g[1]; /* G1 beside G141/G142 is modal as usual */
    if (comp)
        CHP(exec_comp5(in, g0));
    else {
        memcpy(pos_before, in->pos, sizeof pos_before);
        CHP(exec_motion(in));
        if (b->m[6] == 6 && !memcmp(pos_before, in->pos, sizeof pos_before))
            tool_change_reread(in, tool_before);
    }
    CHP(exec_stop(in));
    /* Only these blocks can change a persistent parameter: #n=, G10/G28.1/G30.1/G92.x
     * (group 0), G54..G59.3 (group 12), M2/M30 (back to G54, reported above). */
    if (!in->ended && (b->nassign || g0 >= 0 || b->g[12] >= 0))
        CHP(interp_emit_param_changes(in));
    return 0;
}
