/* test_interp.c: lexer, expressions, parameters, modal checks and error behaviour. */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "interp/interp_int.h"
#include "tests/test_interp_util.h"

/* X of the first traverse of a one-line program "G0 X<expr>". */
static double eval(const char *expr)
{
    char prog[256];
    struct canon_prog p;
    snprintf(prog, sizeof prog, "G0 X%s\nM2\n", expr);
    int rc = run_text(prog, &p, NULL);
    ck_assert_msg(rc == INTERP_OK, "%s did not run", expr);
    double x = nth(&p, CANON_TRAVERSE, 0)->end[0];
    canon_prog_free(&p);
    return x;
}

/* The error of a program expected to fail. */
static struct interp_error fail_of(const char *text)
{
    struct canon_prog p;
    struct interp_error e;
    int rc = run_text(text, &p, &e);
    ck_assert_msg(rc != INTERP_OK, "program was accepted: %s", text);
    ck_assert_int_eq(rc, e.status);
    canon_prog_free(&p);
    return e;
}

START_TEST(lexer_case_spaces_numbers)
{
    ck_assert_double_eq(eval("1 2 . 5"), 12.5);
    ck_assert_double_eq(eval("-.5"), -0.5);
    ck_assert_double_eq(eval("+3."), 3.0);
    struct canon_prog p;
    ck_assert_int_eq(run_text("g1 x 1 y-2 z 3 a4 b 5 c6 f 100\nm2\n", &p, NULL), 0);
    ck_assert_pose(nth(&p, CANON_FEED, 0)->end, 1, -2, 3, 4, 5, 6, 1e-12);
    canon_prog_free(&p);
}
END_TEST

START_TEST(lexer_comments_n_percent)
{
    struct canon_prog p;
    ck_assert_int_eq(run_text("%\n(first) G0 X1 (second)\nN20 G0 X2 ; not a comment command\n%\n"
                              "G0 X99\n", &p, NULL), 0);
    ck_assert_int_eq(count_type(&p, CANON_COMMENT), 1);
    ck_assert_str_eq(nth(&p, CANON_COMMENT, 0)->text, "second");
    ck_assert_int_eq(count_type(&p, CANON_TRAVERSE), 2); /* nothing after the closing % */
    const struct canon_cmd *c = nth(&p, CANON_TRAVERSE, 1);
    ck_assert_int_eq(c->has_n, 1);
    ck_assert_int_eq(c->n_number, 20);
    ck_assert_int_eq(c->line, 3);
    ck_assert_int_eq(nth(&p, CANON_TRAVERSE, 0)->has_n, 0);
    canon_prog_free(&p);
}
END_TEST

/* A UTF-8 byte order mark before line 1 is skipped: the same moves, columns counted after
 * it; a BOM anywhere else is an error that names the byte. */
START_TEST(lexer_utf8_bom)
{
    static const char plain[] = "G21 G90\nG0 X1 Y2 Z3\nG1 X4 F100\nM2\n";
    char bom[sizeof plain + 3] = "\xEF\xBB\xBF";
    memcpy(bom + 3, plain, sizeof plain);
    struct canon_prog p, q;
    ck_assert_int_eq(run_text(plain, &p, NULL), 0);
    ck_assert_int_eq(run_text(bom, &q, NULL), 0);
    ck_assert_uint_eq(p.count, q.count);
    ck_assert_pose(nth(&q, CANON_TRAVERSE, 0)->end, 1, 2, 3, 0, 0, 0, 1e-12);
    ck_assert_pose(nth(&q, CANON_FEED, 0)->end, 4, 2, 3, 0, 0, 0, 1e-12);
    ck_assert_int_eq(nth(&q, CANON_FEED, 0)->line, 3);
    canon_prog_free(&p);
    canon_prog_free(&q);
    struct interp_error e;
    ck_assert_int_ne(run_text("\xEF\xBB\xBFG21 Q1\nM2\n", &p, &e), 0);
    ck_assert_int_eq(e.line, 1);
    ck_assert_int_eq(e.column, 5);  /* Q is the fifth character after the mark */
    canon_prog_free(&p);
    ck_assert_int_ne(run_text("G21\n\xEF\xBB\xBFG0 X1\nM2\n", &p, &e), 0);
    ck_assert_int_eq(e.line, 2);
    ck_assert_int_eq(e.column, 1);
    ck_assert_str_eq(e.message, "byte 0xEF is not G-code text (G-code is ASCII)");
    canon_prog_free(&p);
}
END_TEST

/* G64 Q (LinuxCNC's naive CAM tolerance, written by Fusion 360's post) is accepted and kept
 * beside P; a G64 without Q, or G61, clears it. */
START_TEST(g64_q_is_stored)
{
    struct interp *in = interp_create();
    ck_assert_ptr_nonnull(in);
    struct canon_prog p;
    struct interp_view v;
    ck_assert_int_eq(run_on(in, "G21 G64 P0.02 Q0.005\nM2\n", &p), 0);
    interp_get_view(in, &v);
    ck_assert_int_eq(v.path_mode, 640);
    ck_assert_double_eq_tol(v.path_tol_mm, 0.02, 1e-15);
    ck_assert_double_eq_tol(v.naive_cam_tol_mm, 0.005, 1e-15);
    canon_prog_free(&p);
    ck_assert_int_eq(run_on(in, "G20 G64 P0.001 Q0.0005\nM2\n", &p), 0);
    interp_get_view(in, &v);
    ck_assert_double_eq_tol(v.naive_cam_tol_mm, 0.0127, 1e-12);  /* inch to mm */
    canon_prog_free(&p);
    ck_assert_int_eq(run_on(in, "G21 G64 P0.02\nM2\n", &p), 0);   /* no Q: P's, as rs274 */
    interp_get_view(in, &v);                                       /* prints it */
    ck_assert_double_eq_tol(v.naive_cam_tol_mm, 0.02, 1e-15);
    canon_prog_free(&p);
    ck_assert_int_eq(run_on(in, "G21 G64\nM2\n", &p), 0);
    interp_get_view(in, &v);
    ck_assert_double_eq(v.naive_cam_tol_mm, 0.0);
    canon_prog_free(&p);
    interp_destroy(in);
}
END_TEST

/* A sink that stands for Ctrl-C: it sets the cancel flag when the command of line `at`
 * arrives, as a signal handler would between two lines. */
struct cancel_at {
    volatile sig_atomic_t flag;
    int at;
    struct canon_prog prog;
};
static int cancel_sink(void *ctx, const struct canon_cmd *c)
{
    struct cancel_at *k = ctx;
    if (c->line == k->at)
        k->flag = 1;
    return canon_prog_sink(&k->prog, c);
}

/* The cancel flag stops the line loop before the next line: nothing of it or after it is
 * emitted, and the error says where and why. */
START_TEST(cancel_flag_stops_before_the_next_line)
{
    struct interp *in = interp_create();
    ck_assert_ptr_nonnull(in);
    struct cancel_at k = { .flag = 0, .at = 3 };
    canon_prog_init(&k.prog);
    interp_set_cancel(in, &k.flag);
    static const char prog[] = "G21 G90\nG0 X1\nG0 X2\nG0 X3\nG0 X4\nM2\n";
    ck_assert_int_eq(interp_run_text(in, "c.ngc", prog, strlen(prog), cancel_sink, &k),
                     INTERP_ERR_CANCELLED);
    const struct interp_error *e = interp_last_error(in);
    ck_assert_int_eq(e->line, 4);
    ck_assert_str_eq(e->message, "stopped by the operator while reading the program");
    ck_assert_int_eq(count_type(&k.prog, CANON_TRAVERSE), 2);  /* X1 and X2 only */
    canon_prog_free(&k.prog);
    /* the flag cleared, the same interpreter runs the program to its end */
    k.flag = 0;
    k.at = -1;
    canon_prog_init(&k.prog);
    ck_assert_int_eq(interp_run_text(in, "c.ngc", prog, strlen(prog), cancel_sink, &k), 0);
    ck_assert_int_eq(count_type(&k.prog, CANON_TRAVERSE), 4);
    canon_prog_free(&k.prog);
    interp_destroy(in);
}
END_TEST

START_TEST(lexer_block_delete)
{
    const char *prog = "G0 X1\n/G0 X2\n  / G0 X3\nM2\n";
    struct canon_prog p;
    struct interp *in = interp_create();
    ck_assert_int_eq(run_on(in, prog, &p), 0);
    ck_assert_int_eq(count_type(&p, CANON_TRAVERSE), 3); /* switch off: lines run */
    canon_prog_free(&p);
    interp_set_block_delete(in, 1);
    ck_assert_int_eq(run_on(in, prog, &p), 0);
    ck_assert_int_eq(count_type(&p, CANON_TRAVERSE), 1);
    canon_prog_free(&p);
    interp_destroy(in);
}
END_TEST

START_TEST(expr_precedence)
{
    ck_assert_double_eq(eval("[1+2*3]"), 7);
    ck_assert_double_eq(eval("[2**3**2]"), 64);     /* left to right, as LinuxCNC */
    ck_assert_double_eq(eval("[2*3**2]"), 18);      /* ** binds tighter than * */
    ck_assert_double_eq(eval("[10-4-3]"), 3);
    ck_assert_double_eq(eval("[8/4/2]"), 1);
    ck_assert_double_eq(eval("[7 MOD 3]"), 1);
    ck_assert_double_eq(eval("[-7 MOD 3]"), 2);     /* LinuxCNC: never negative */
    ck_assert_double_eq(eval("[1+2 EQ 3]"), 1);     /* + before EQ */
    ck_assert_double_eq(eval("[1 OR 0 AND 0]"), 0); /* same level: left to right */
    ck_assert_double_eq(eval("[2 GT 1 AND 3 LT 2]"), 0);
    ck_assert_double_eq(eval("[1 XOR 1]"), 0);
    ck_assert_double_eq(eval("[1 NE 1.00001]"), 0); /* EQ/NE tolerance 0.0001 */
    ck_assert_double_eq(eval("[2 GE 2]"), 1);
    ck_assert_double_eq(eval("[2 LE 1]"), 0);
    ck_assert_double_eq(eval("[[1+2]*[3+4]]"), 21);
    ck_assert_double_eq(eval("-[2*3]"), -6);
}
END_TEST

START_TEST(expr_functions)
{
    ck_assert_double_eq_tol(eval("[SIN[30]]"), 0.5, 1e-12);
    ck_assert_double_eq_tol(eval("[COS[60]]"), 0.5, 1e-12);
    ck_assert_double_eq_tol(eval("[TAN[45]]"), 1.0, 1e-12);
    ck_assert_double_eq_tol(eval("[ASIN[1]]"), 90.0, 1e-12);
    ck_assert_double_eq_tol(eval("[ACOS[0]]"), 90.0, 1e-12);
    ck_assert_double_eq_tol(eval("[ATAN[1]/[-1]]"), 135.0, 1e-12);
    ck_assert_double_eq_tol(eval("[SQRT[2]]"), sqrt(2.0), 1e-15);
    ck_assert_double_eq(eval("[ABS[-3.5]]"), 3.5);
    ck_assert_double_eq_tol(eval("[EXP[1]]"), exp(1.0), 1e-15);
    ck_assert_double_eq_tol(eval("[LN[10]]"), log(10.0), 1e-15);
    ck_assert_double_eq(eval("[FIX[-2.5]]"), -3);
    ck_assert_double_eq(eval("[FUP[-2.5]]"), -2);
    ck_assert_double_eq(eval("[ROUND[2.5]]"), 3);
    ck_assert_double_eq(eval("[ROUND[-2.5]]"), -3);
    ck_assert_double_eq(eval("[ROUND[1444444444444444444444444444444.5]]"), 1.4444444444444444e30);
    ck_assert_double_eq(eval("[ROUND[-100000000000000000000]]"), -1e20); /* fuzzer find */
    ck_assert_double_eq(eval("sin[90]"), 1);
}
END_TEST

START_TEST(expr_errors)
{
    struct interp_error e = fail_of("G0 X[1/0]\nM2\n");
    ck_assert_int_eq(e.status, INTERP_ERR_EXPR);
    ck_assert_int_eq(e.line, 1);
    ck_assert_int_eq(e.column, 7);
    ck_assert_int_eq(fail_of("G0 X[SQRT[-1]]\nM2\n").status, INTERP_ERR_EXPR);
    ck_assert_int_eq(fail_of("G0 X[LN[0]]\nM2\n").status, INTERP_ERR_EXPR);
    ck_assert_int_eq(fail_of("G0 X[ASIN[1.5]]\nM2\n").status, INTERP_ERR_EXPR);
    ck_assert_int_eq(fail_of("G0 X[1 MOD 0]\nM2\n").status, INTERP_ERR_EXPR);
    ck_assert_int_eq(fail_of("G0 X[1+2\nM2\n").status, INTERP_ERR_SYNTAX);
    ck_assert_int_eq(fail_of("G0 X[1 ? 2]\nM2\n").status, INTERP_ERR_SYNTAX);
    ck_assert_int_eq(fail_of("G0 X[FOO[1]]\nM2\n").status, INTERP_ERR_SYNTAX);
    ck_assert_int_eq(fail_of("G0 X[ATAN[1]]\nM2\n").status, INTERP_ERR_SYNTAX);
    char deep[200] = "G0 X";
    for (int i = 0; i < 40; i++)
        strcat(deep, "[");
    strcat(deep, "1\nM2\n");
    ck_assert_int_eq(fail_of(deep).status, INTERP_ERR_EXPR);
}
END_TEST

START_TEST(params_read_after_line)
{
    struct canon_prog p;
    ck_assert_int_eq(run_text("#1=5 #2=#1 #3=1 G0 X#1 Y#2\nG0 X#1 Y[#2+1] Z##3\nM2\n", &p, NULL),
                     0);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 0)->end, 0, 0, 0, 0, 0, 0, 1e-12); /* old values */
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 1)->end, 5, 1, 5, 0, 0, 0, 1e-12);
    canon_prog_free(&p);
    ck_assert_int_eq(fail_of("#0=1\nM2\n").status, INTERP_ERR_PARAM);
    ck_assert_int_eq(fail_of("#1.5=1\nM2\n").status, INTERP_ERR_WORD);
    ck_assert_int_eq(fail_of("G0 X#<x>\nM2\n").status, INTERP_ERR_PARAM); /* never set */
}
END_TEST

/* The value parameter n has in a CANON_SETTING, or -999 when the setting leaves it alone. */
static double setting_param(const struct canon_cmd *c, int n)
{
    for (size_t i = 0; i < c->setting->nparams; i++)
        if (c->setting->params[i].number == n)
            return c->setting->params[i].value;
    return -999;
}

/* Each line that changes persistent parameters reports exactly its changes, at its place in
 * the stream; lines that change none report nothing; later lines see the new values. */
START_TEST(settings_in_stream)
{
    struct canon_prog p;
    interp_ok("G10 L2 P2 X5 Y-6 A7\nG0 X1\nG92 Z3\nG55\nG0 X0 Y0\n#5221=4\nG1 X2 F100\nM2\n", &p);
    ck_assert_int_eq(count_type(&p, CANON_SETTING), 5); /* G10, G92, G55, #5221, M2 (G54) */
    const struct canon_cmd *c = nth(&p, CANON_SETTING, 0);
    ck_assert_int_eq(c->line, 1);
    ck_assert_int_eq((int)c->setting->nparams, 3);
    ck_assert_double_eq(setting_param(c, 5241), 5);
    ck_assert_double_eq(setting_param(c, 5242), -6);
    ck_assert_double_eq(setting_param(c, 5244), 7);
    ck_assert_ptr_null(c->setting->tool);
    c = nth(&p, CANON_SETTING, 1);
    ck_assert_int_eq(c->line, 3);
    ck_assert_int_eq((int)c->setting->nparams, 2);
    ck_assert_double_eq(setting_param(c, 5213), -3);
    ck_assert_double_eq(setting_param(c, 5210), 1);
    ck_assert_double_eq(setting_param(nth(&p, CANON_SETTING, 2), 5220), 2);
    ck_assert_int_eq(nth(&p, CANON_SETTING, 3)->line, 6);
    ck_assert_double_eq(setting_param(nth(&p, CANON_SETTING, 3), 5221), 4);
    c = nth(&p, CANON_SETTING, 4);
    ck_assert_int_eq(c->line, 8);
    ck_assert_double_eq(setting_param(c, 5220), 1);
    ck_assert_int_eq(p.cmds[p.count - 2].type, CANON_SETTING); /* before PROGRAM_END */
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 1)->end, 5, -6, 0, 0, 0, 0, 1e-12); /* G55 seen */
    canon_prog_free(&p);
    interp_ok("G0 X1\n#1=2\nG54\nG1 X2 F100\nM2\n", &p);  /* nothing persistent changes */
    ck_assert_int_eq(count_type(&p, CANON_SETTING), 0);
    canon_prog_free(&p);
}
END_TEST

/* Interpreting writes no parameter file; applying the stream's settings (what the runner does
 * as the machine executes them) writes it atomically, and it loads back. */
START_TEST(params_file_persistence)
{
    char dir[] = "/tmp/hexcnc_interp_XXXXXX", path[128], tmp[140], err[512];
    ck_assert_ptr_nonnull(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/hexcnc.var", dir);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    struct interp *in = interp_create(), *store = interp_create();
    ck_assert_int_eq(interp_set_param_file(in, path), 0); /* missing: starts from zero */
    ck_assert_int_eq(interp_set_param_file(store, path), 0);
    struct canon_prog p;
    ck_assert_int_eq(run_on(in, "G10 L2 P2 X5 Y-6 A7\nG0 X1\nG92 Z3\nM2\n", &p), 0);
    interp_destroy(in);
    ck_assert_int_eq(access(path, F_OK), -1);   /* the interpreter wrote nothing */
    for (size_t i = 0; i < p.count; i++)
        if (p.cmds[i].type == CANON_SETTING)
            ck_assert_msg(interp_setting_apply(store, p.cmds[i].setting, err, sizeof err) == 0,
                          "%s", err);
    canon_prog_free(&p);
    interp_destroy(store);
    ck_assert_int_ne(access(path, R_OK), -1);
    ck_assert_int_eq(access(tmp, F_OK), -1);
    FILE *f = fopen(path, "r");
    char line[64];
    int found = 0;
    while (fgets(line, sizeof line, f))
        found += strcmp(line, "5241\t5.000000\n") == 0 || strcmp(line, "5244\t7.000000\n") == 0 ||
                 strcmp(line, "5213\t-3.000000\n") == 0 || strcmp(line, "5210\t1.000000\n") == 0;
    fclose(f);
    ck_assert_int_eq(found, 4);
    in = interp_create();
    ck_assert_int_eq(interp_set_param_file(in, path), 0);
    ck_assert_double_eq(interp_param(in, 5242), -6);
    ck_assert_int_eq(run_on(in, "G55 G0 X0 Y0 Z0\nM2\n", &p), 0);
    ck_assert_pose(nth(&p, CANON_TRAVERSE, 0)->end, 5, -6, -3, 0, 0, 0, 1e-12); /* G92 back */
    canon_prog_free(&p);
    interp_destroy(in);
    unlink(path);
    rmdir(dir);
}
END_TEST

/* A setting whose file cannot be written is found before anything is saved. */
START_TEST(settings_file_check)
{
    char err[512];
    struct canon_param prm = { 5221, 1.0 };
    struct canon_setting s = { .tool = NULL, .nparams = 1, .params = &prm };
    struct interp *in = interp_create();
    ck_assert_int_eq(interp_setting_check(in, &s, err, sizeof err), 0); /* no file: no save */
    ck_assert_int_eq(interp_set_param_file(in, "/nonexistent-dir/hexcnc.var"), 0);
    ck_assert_int_eq(interp_setting_check(in, &s, err, sizeof err), INTERP_ERR_IO);
    ck_assert_msg(strstr(err, "/nonexistent-dir/hexcnc.var") != NULL, "%s", err);
    ck_assert_int_ne(interp_setting_apply(in, &s, err, sizeof err), 0);
    ck_assert_msg(strstr(err, "/nonexistent-dir/hexcnc.var") != NULL, "%s", err);
    ck_assert_int_eq(interp_load_param_file(in, "/nonexistent-dir/hexcnc.var"), 0);
    ck_assert_int_eq(interp_setting_check(in, &s, err, sizeof err), 0); /* read only */
    interp_destroy(in);
}
END_TEST

START_TEST(params_file_errors)
{
    char dir[] = "/tmp/hexcnc_interp_XXXXXX", path[128];
    ck_assert_ptr_nonnull(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/bad.var", dir);
    FILE *f = fopen(path, "w");
    fputs("5161 0.0\nabc\n", f);
    fclose(f);
    struct interp *in = interp_create();
    ck_assert_int_eq(interp_set_param_file(in, path), INTERP_ERR_PARAM);
    ck_assert_int_eq(interp_last_error(in)->line, 2);
    ck_assert_str_eq(interp_last_error(in)->file, path);
    interp_destroy(in);
    unlink(path);
    rmdir(dir);
}
END_TEST

START_TEST(modal_groups)
{
    struct interp_error e = fail_of("G0 G1 X1 F1\nM2\n");
    ck_assert_int_eq(e.status, INTERP_ERR_MODAL);
    ck_assert_int_eq(e.column, 4);
    ck_assert_ptr_nonnull(strstr(e.message, "modal group 1"));
    ck_assert_int_eq(fail_of("G90 G91\nM2\n").status, INTERP_ERR_MODAL);
    ck_assert_int_eq(fail_of("G54 G55\nM2\n").status, INTERP_ERR_MODAL);
    ck_assert_int_eq(fail_of("G4 P1 G10 L2 P1\nM2\n").status, INTERP_ERR_MODAL); /* group 0 */
    ck_assert_int_eq(fail_of("M7 M9\nM2\n").status, INTERP_ERR_MODAL);
    ck_assert_int_eq(fail_of("G1 G92 X1 F1\nM2\n").status, INTERP_ERR_MODAL);
    ck_assert_int_eq(fail_of("G80 X1\nM2\n").status, INTERP_ERR_MODAL);
    ck_assert_int_eq(fail_of("G2 G141 X1 W1 F1\nM2\n").status, INTERP_ERR_MODAL);
    ck_assert_int_eq(fail_of("G1 X1 R2 F1\nM2\n").status, INTERP_ERR_WORD);
    ck_assert_int_eq(fail_of("G1 X1 X2 F1\nM2\n").status, INTERP_ERR_WORD);
    e = fail_of("G41 G42 G1 X1 F1\nM2\n");  /* G40..G42 are modal group 7 */
    ck_assert_int_eq(e.status, INTERP_ERR_MODAL);
    ck_assert_ptr_nonnull(strstr(e.message, "modal group 7"));
    e = fail_of("G1 X1 F1 O100\nM2\n");  /* an O-word is a line of its own */
    ck_assert_ptr_nonnull(strstr(e.message, "must start its line"));
}
END_TEST

/* Nothing is emitted from the failing line on, and the error names file, line and column. */
START_TEST(error_stops_output)
{
    struct canon_prog p;
    struct interp_error e;
    ck_assert_int_eq(run_text("G0 X1\nG1 X2 F10\nG1 X3 Y[1/0]\nG0 X4\nM2\n", &p, &e),
                     INTERP_ERR_EXPR);
    for (size_t i = 0; i < p.count; i++)
        ck_assert_int_lt(p.cmds[i].line, 3);
    ck_assert_int_eq(count_type(&p, CANON_PROGRAM_END), 0);
    char buf[400];
    interp_error_format(&e, buf, sizeof buf);
    ck_assert_str_eq(buf, "t.ngc:3:10: error: division by zero in expression");
    canon_prog_free(&p);
    e = fail_of("G0 X1\n");
    ck_assert_ptr_nonnull(strstr(e.message, "M2"));
    ck_assert_str_eq(interp_strerror(INTERP_ERR_ARC), "impossible arc");
}
END_TEST

/* A sink that stops after n commands. */
static int stop_after(void *ctx, const struct canon_cmd *c)
{
    (void)c;
    int *n = ctx;
    return --*n < 0;
}

START_TEST(sink_can_stop)
{
    struct interp *in = interp_create();
    int n = 1;
    const char *prog = "G0 X1\nG0 X2\nG0 X3\nM2\n";
    ck_assert_int_eq(interp_run_text(in, "s.ngc", prog, strlen(prog), stop_after, &n),
                     INTERP_ERR_SINK);
    ck_assert_int_eq(interp_last_error(in)->line, 2);
    interp_destroy(in);
}
END_TEST

/* Two interpreters, interleaved, keep their own state. */
/* A loop that never ends is refused at the loop bound, naming its label and line; the count
 * covers every loop of the program, and a program under the bound runs. */
START_TEST(oword_loop_bound)
{
    struct interp *in = interp_create();
    ck_assert_ptr_nonnull(in);
    interp_set_loop_limit(in, 100);
    struct canon_prog p;
    int rc = run_on(in, "G21 F100\n#1=0\no7 while [1]\n#1=[#1+1]\no7 endwhile\nM2\n", &p);
    canon_prog_free(&p);
    ck_assert_int_eq(rc, INTERP_ERR_SYNTAX);
    const struct interp_error *e = interp_last_error(in);
    ck_assert_int_eq(e->line, 3);                    /* the 101st time the body would start */
    ck_assert_msg(strstr(e->message, "o7: more than 100 loop iterations"), "%s", e->message);
    ck_assert_double_eq(interp_param(in, 1), 100);
    /* 60 + 40 iterations are within 100; 61 + 61 are not */
    rc = run_on(in, "G21 F100\no1 repeat [60]\no1 endrepeat\no2 repeat [40]\no2 endrepeat\nM2\n",
                &p);
    canon_prog_free(&p);
    ck_assert_int_eq(rc, INTERP_OK);
    rc = run_on(in, "G21 F100\no1 repeat [61]\no1 endrepeat\no2 repeat [61]\no2 endrepeat\nM2\n",
                &p);
    canon_prog_free(&p);
    ck_assert_int_eq(rc, INTERP_ERR_SYNTAX);
    interp_destroy(in);
}
END_TEST

/* A subroutine's #1..#30 and local names are its own; the caller's come back on return, and
 * globals (#<_name>) are shared. */
START_TEST(oword_call_scope)
{
    struct interp *in = interp_create();
    ck_assert_ptr_nonnull(in);
    struct canon_prog p;
    int rc = run_on(in, "G21 F100\n"
                        "o<s> sub\n#<loc>=5\n#<_glob>=[#1+#2]\n#3=9\no<s> endsub [#<loc>]\n"
                        "#1=1\n#3=3\n#<loc>=2\no<s> call [10] [20]\n"
                        "#10=#<_value>\n#11=#<loc>\n#12=#<_glob>\n#13=#1\n#14=#3\n"
                        "#15=#<_value_returned>\n#16=#<_call_level>\nM2\n", &p);
    canon_prog_free(&p);
    ck_assert_msg(rc == INTERP_OK, "%s", interp_last_error(in)->message);
    ck_assert_double_eq(interp_param(in, 10), 5);   /* the returned value */
    ck_assert_double_eq(interp_param(in, 11), 2);   /* the caller's #<loc> untouched */
    ck_assert_double_eq(interp_param(in, 12), 30);  /* the global the sub set */
    ck_assert_double_eq(interp_param(in, 13), 1);   /* #1 restored */
    ck_assert_double_eq(interp_param(in, 14), 3);   /* #3 restored */
    ck_assert_double_eq(interp_param(in, 15), 1);
    ck_assert_double_eq(interp_param(in, 16), 0);
    /* M61 Q sets the tool in the spindle (#<_current_tool> reads it, as LinuxCNC's task
     * does; rs274 alone keeps the old number there) */
    rc = run_on(in, "T2 M6\nM61 Q3\n#21=#<_current_tool>\nM2\n", &p);
    canon_prog_free(&p);
    ck_assert_msg(rc == INTERP_OK, "%s", interp_last_error(in)->message);
    ck_assert_double_eq(interp_param(in, 21), 3);
    /* a definition met again and again (inside a loop) is kept once */
    rc = run_on(in, "G21 F100\no1 repeat [1000]\no<d> sub\no<d> endsub [7]\no1 endrepeat\n"
                    "o<d> call\n#20=#<_value>\nM2\n", &p);
    canon_prog_free(&p);
    ck_assert_msg(rc == INTERP_OK, "%s", interp_last_error(in)->message);
    ck_assert_double_eq(interp_param(in, 20), 7);
    ck_assert_int_eq(in->ow.nsubs, 1);
    interp_destroy(in);
}
END_TEST

START_TEST(two_interpreters)
{
    struct interp *a = interp_create(), *b = interp_create();
    struct canon_prog pa, pb;
    ck_assert_int_eq(run_on(a, "%\nG20 G10 L2 P1 X1\n%\n", &pa), 0);
    ck_assert_int_eq(run_on(b, "%\nG21 G91 G0 X1\n%\n", &pb), 0);
    canon_prog_free(&pa);
    canon_prog_free(&pb);
    ck_assert_int_eq(run_on(a, "G0 X1\nM2\n", &pa), 0);
    ck_assert_int_eq(run_on(b, "G0 X1\nM2\n", &pb), 0);
    ck_assert_double_eq_tol(nth(&pa, CANON_TRAVERSE, 0)->end[0], 50.8, 1e-12);
    ck_assert_double_eq_tol(nth(&pb, CANON_TRAVERSE, 0)->end[0], 2.0, 1e-12);
    canon_prog_free(&pa);
    canon_prog_free(&pb);
    interp_destroy(a);
    interp_destroy(b);
}
END_TEST

/* Lines are found through a sparse index (every 64th line) and a cursor: loops that jump
 * back across many lines, a subroutine defined 500 lines after its call, and a mapped file
 * (interp_run_file) read the same lines as the text in memory. */
START_TEST(long_jumps_across_the_line_index)
{
    size_t cap = 1 << 16, n = 0;
    char *text = malloc(cap);
    ck_assert_ptr_nonnull(text);
    n += (size_t)snprintf(text + n, cap - n, "G21 G90 F100\n#1=0\no100 repeat [3]\n");
    for (int i = 0; i < 150; i++)        /* a body of 150 lines: the loop jumps back 150 */
        n += (size_t)snprintf(text + n, cap - n, "#1=[#1+1]\n");
    n += (size_t)snprintf(text + n, cap - n, "G1 X#1\no100 endrepeat\no<far> call [7]\n");
    for (int i = 0; i < 500; i++)        /* 500 lines before the subroutine */
        n += (size_t)snprintf(text + n, cap - n, "(filler %d)\n", i);
    n += (size_t)snprintf(text + n, cap - n, "M2\no<far> sub\nG1 Y#1\no<far> endsub\n");
    struct canon_prog p;
    ck_assert_int_eq(run_text(text, &p, NULL), INTERP_OK);
    ck_assert_double_eq(nth(&p, CANON_FEED, 0)->end[0], 150);
    ck_assert_double_eq(nth(&p, CANON_FEED, 2)->end[0], 450);
    ck_assert_double_eq(nth(&p, CANON_FEED, 3)->end[1], 7);
    size_t count = p.count;
    canon_prog_free(&p);
    char path[] = "/tmp/hexcnc-test-lines-XXXXXX";
    int fd = mkstemp(path);
    ck_assert_int_ge(fd, 0);
    ck_assert_int_eq(write(fd, text, n), (ssize_t)n);
    close(fd);
    struct interp *in = interp_create();
    canon_prog_init(&p);
    ck_assert_int_eq(interp_run_file(in, path, canon_prog_sink, &p), INTERP_OK);
    ck_assert_uint_eq(p.count, count);
    ck_assert_double_eq(nth(&p, CANON_FEED, 2)->end[0], 450);
    ck_assert_double_eq(nth(&p, CANON_FEED, 3)->end[1], 7);
    canon_prog_free(&p);
    interp_destroy(in);
    unlink(path);
    free(text);
}
END_TEST

static Suite *interp_suite(void)
{
    Suite *s = suite_create("interp");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, lexer_case_spaces_numbers);
    tcase_add_test(tc, lexer_comments_n_percent);
    tcase_add_test(tc, lexer_utf8_bom);
    tcase_add_test(tc, g64_q_is_stored);
    tcase_add_test(tc, cancel_flag_stops_before_the_next_line);
    tcase_add_test(tc, long_jumps_across_the_line_index);
    tcase_add_test(tc, lexer_block_delete);
    tcase_add_test(tc, expr_precedence);
    tcase_add_test(tc, expr_functions);
    tcase_add_test(tc, expr_errors);
    tcase_add_test(tc, params_read_after_line);
    tcase_add_test(tc, params_file_persistence);
    tcase_add_test(tc, settings_in_stream);
    tcase_add_test(tc, settings_file_check);
    tcase_add_test(tc, params_file_errors);
    tcase_add_test(tc, modal_groups);
    tcase_add_test(tc, error_stops_output);
    tcase_add_test(tc, sink_can_stop);
    tcase_add_test(tc, two_interpreters);
    tcase_add_test(tc, oword_loop_bound);
    tcase_add_test(tc, oword_call_scope);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(interp_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
