/* expr.c: real values: numbers, #n, [expressions] with LinuxCNC's operators, and functions. */
#include <math.h>
#include <string.h>

#include "interp/interp_int.h"

#define DEG_PER_RAD (180.0 / M_PI)
#define EQ_TOLERANCE 0.0001      /* LinuxCNC's EQ/NE tolerance */

/* Binary operators, with LinuxCNC's precedence (higher binds tighter). */
enum op { OP_NONE, OP_POW, OP_MUL, OP_DIV, OP_MOD, OP_ADD, OP_SUB,
          OP_EQ, OP_NE, OP_GT, OP_GE, OP_LT, OP_LE, OP_AND, OP_OR, OP_XOR, OP_END };

static const struct { const char *name; enum op op; int prec; } op_table[] = {
    {"**", OP_POW, 6}, {"*", OP_MUL, 5}, {"/", OP_DIV, 5}, {"mod", OP_MOD, 5},
    {"+", OP_ADD, 4},  {"-", OP_SUB, 4}, {"eq", OP_EQ, 3}, {"ne", OP_NE, 3},
    {"gt", OP_GT, 3},  {"ge", OP_GE, 3}, {"lt", OP_LT, 3}, {"le", OP_LE, 3},
    {"and", OP_AND, 2}, {"or", OP_OR, 2}, {"xor", OP_XOR, 2},
};

/* Checks v is an integer (within LinuxCNC's 0.0001) and stores it. */
int interp_to_int(struct interp *in, double v, int column, const char *what, int *out)
{
    double r = floor(v + 0.5);
    if (!(fabs(v - r) < 0.0001) || fabs(r) > 2e9)
        return interp_fail(in, INTERP_ERR_WORD, column, "%s must be a whole number, not %g",
                           what, v);
    *out = (int)r;
    return 0;
}

/* Reads a binary operator at norm[*pos]; OP_END at ']'. */
static int read_op(struct interp *in, int *pos, enum op *op, int *prec)
{
    const char *s = in->norm + *pos;
    if (*s == ']') {
        (*pos)++;
        *op = OP_END;
        *prec = 1;
        return 0;
    }
    for (size_t i = 0; i < sizeof op_table / sizeof op_table[0]; i++) {
        size_t n = strlen(op_table[i].name);
        if (strncmp(s, op_table[i].name, n) == 0) {
            *pos += (int)n;
            *op = op_table[i].op;
            *prec = op_table[i].prec;
            return 0;
        }
    }
    if (*s == 0)
        return interp_fail(in, INTERP_ERR_SYNTAX, in->normcol[*pos],
                           "expression not closed: ']' missing at the end of the line");
    return interp_fail(in, INTERP_ERR_SYNTAX, in->normcol[*pos],
                       "unknown operator in expression at '%.6s' (operators: + - * / ** MOD "
                       "EQ NE GT GE LT LE AND OR XOR)", s);
}

/* Applies one binary operator; column locates domain errors. */
static int apply(struct interp *in, enum op op, double a, double b, int column, double *out)
{
    switch (op) {
    case OP_POW:
        if (a < 0 && floor(b) != b)
            return interp_fail(in, INTERP_ERR_EXPR, column,
                               "negative number %g raised to a non-integer power %g", a, b);
        *out = pow(a, b);
        break;
    case OP_MUL: *out = a * b; break;
    case OP_DIV:
    case OP_MOD:
        if (b == 0.0)
            return interp_fail(in, INTERP_ERR_EXPR, column, "division by zero in expression");
        if (op == OP_DIV) {
            *out = a / b;
        } else { /* LinuxCNC: the result takes the sign of neither: it is made positive */
            *out = fmod(a, b);
            if (*out < 0)
                *out += fabs(b);
        }
        break;
    case OP_ADD: *out = a + b; break;
    case OP_SUB: *out = a - b; break;
    case OP_EQ: *out = fabs(a - b) < EQ_TOLERANCE; break;
    case OP_NE: *out = !(fabs(a - b) < EQ_TOLERANCE); break;
    case OP_GT: *out = a > b; break;
    case OP_GE: *out = a >= b; break;
    case OP_LT: *out = a < b; break;
    case OP_LE: *out = a <= b; break;
    case OP_AND: *out = a != 0.0 && b != 0.0; break;
    case OP_OR: *out = a != 0.0 || b != 0.0; break;
    case OP_XOR: *out = (a != 0.0) != (b != 0.0); break;
    default: *out = 0; break;
    }
    return 0;
}

/* The body of "[...]" after '[': an operator-precedence stack (left-associative); with
 * six precedence levels the stack never holds more than six pending operators. */
static int expression_body(struct interp *in, int *pos, double *out)
{
    double vals[8];
    enum op ops[8];
    int cols[8], prec[8];
    int n = 0;
    CHP(interp_read_value(in, pos, &vals[0]));
    for (;;) {
        enum op op = OP_END;
        int p = 1, ocol = in->normcol[*pos];
        CHP(read_op(in, pos, &op, &p));
        while (n > 0 && prec[n - 1] >= p) {
            double r = 0;
            CHP(apply(in, ops[n - 1], vals[n - 1], vals[n], cols[n - 1], &r));
            vals[--n] = r;
        }
        if (op == OP_END)
            break;
        ops[n] = op;
        prec[n] = p;
        cols[n] = ocol;
        n++;
        CHP(interp_read_value(in, pos, &vals[n]));
    }
    *out = vals[0];
    return 0;
}

/* Reads "[...]" at norm[*pos] == '['; nesting is bounded so that no line can exhaust the stack. */
static int read_expression(struct interp *in, int *pos, double *out)
{
    if (in->depth >= 32)
        return interp_fail(in, INTERP_ERR_EXPR, in->normcol[*pos],
                           "expression nested too deeply (more than 32 levels of [ ])");
    in->depth++;
    (*pos)++;
    int rc = expression_body(in, pos, out);
    in->depth--;
    return rc;
}

/* EXISTS[#<name>]: 1 when the name can be read now, else 0 (EXISTS[#n] is 1, as LinuxCNC).
 * *pos is at the '['. */
static int read_exists(struct interp *in, int *pos, int col, double *out)
{
    const char *name;
    int len, pcol = in->normcol[*pos + 1];
    if (in->norm[*pos + 1] != '#')
        return interp_fail(in, INTERP_ERR_SYNTAX, pcol, "EXISTS takes a parameter: "
                           "EXISTS[#<name>]");
    if (in->norm[*pos + 2] == '<') {
        *pos += 2;
        CHP(interp_read_name(in, pos, pcol, &name, &len));
        *out = interp_named_exists(in, name, len);
    } else {
        double v;
        (*pos)++;
        CHP(interp_read_value(in, pos, &v)); /* a bad number is still an error */
        *out = 1.0;
    }
    if (in->norm[*pos] != ']')
        return interp_fail(in, INTERP_ERR_SYNTAX, in->normcol[*pos], "']' expected to close "
                           "EXISTS[ opened at column %d", col);
    (*pos)++;
    return 0;
}

/* Reads a function call: NAME[arg] (ATAN[y]/[x]) at norm[*pos]. */
static int read_function(struct interp *in, int *pos, double *out)
{
    static const char *const names[] = {"abs", "acos", "asin", "atan", "cos", "exp", "fix",
                                        "fup", "ln", "round", "sin", "sqrt", "tan", "exists"};
    int col = in->normcol[*pos], f = -1;
    const char *s = in->norm + *pos;
    for (int i = 0; i < (int)(sizeof names / sizeof names[0]); i++) {
        size_t n = strlen(names[i]);
        if (strncmp(s, names[i], n) == 0 && s[n] == '[') {
            f = i;
            *pos += (int)n;
            break;
        }
    }
    if (f < 0)
        return interp_fail(in, INTERP_ERR_SYNTAX, col, "unknown word or function at '%.8s'", s);
    if (f == 13)
        return read_exists(in, pos, col, out);
    double a;
    CHP(read_expression(in, pos, &a));
    switch (f) {
    case 0: *out = fabs(a); return 0;
    case 1:
    case 2:
        if (a < -1.0 || a > 1.0)
            return interp_fail(in, INTERP_ERR_EXPR, col, "%s of %g: the value must be between "
                               "-1 and 1", f == 1 ? "ACOS" : "ASIN", a);
        *out = (f == 1 ? acos(a) : asin(a)) * DEG_PER_RAD;
        return 0;
    case 3: {
        if (in->norm[*pos] != '/' || in->norm[*pos + 1] != '[')
            return interp_fail(in, INTERP_ERR_SYNTAX, in->normcol[*pos],
                               "ATAN needs two values: ATAN[y]/[x]");
        (*pos)++;
        double x;
        CHP(read_expression(in, pos, &x));
        *out = atan2(a, x) * DEG_PER_RAD;
        return 0;
    }
    case 4: *out = cos(a / DEG_PER_RAD); return 0;
    case 5: *out = exp(a); return 0;
    case 6: *out = floor(a); return 0;
    case 7: *out = ceil(a); return 0;
    case 8:
        if (a <= 0.0)
            return interp_fail(in, INTERP_ERR_EXPR, col, "LN of %g: the value must be positive", a);
        *out = log(a);
        return 0;
    case 9: /* to nearest, halves away from zero; no integer cast, any magnitude */
        *out = a < 0 ? ceil(a - 0.5) : floor(a + 0.5);
        return 0;
    case 10: *out = sin(a / DEG_PER_RAD); return 0;
    case 11:
        if (a < 0.0)
            return interp_fail(in, INTERP_ERR_EXPR, col, "SQRT of negative number %g", a);
        *out = sqrt(a);
        return 0;
    default: *out = tan(a / DEG_PER_RAD); return 0;
    }
}

/* Reads #n (n itself a value: #[1+2], ##1) or #<name> and returns the parameter's current
 * value. */
static int read_parameter(struct interp *in, int *pos, double *out)
{
    int col = in->normcol[*pos], idx = 0;
    (*pos)++;
    if (in->norm[*pos] == '<') {
        const char *name;
        int len;
        CHP(interp_read_name(in, pos, col, &name, &len));
        return interp_named_get(in, name, len, col, out);
    }
    double v;
    CHP(interp_read_value(in, pos, &v));
    CHP(interp_to_int(in, v, col, "parameter number", &idx));
    if (idx < 1 || idx >= INTERP_NPARAMS)
        return interp_fail(in, INTERP_ERR_PARAM, col, "parameter number #%d out of range "
                           "(1 to %d)", idx, INTERP_NPARAMS - 1);
    if (idx >= PARAM_POS && idx < PARAM_POS + 6) { /* the current point, as #<_x> .. */
        double prog[6];
        interp_prog_pos(in, prog);
        *out = prog[idx - PARAM_POS];
        return 0;
    }
    *out = in->params[idx];
    return 0;
}

/* A real value: number, [expression], #parameter, unary sign or function call. */
int interp_read_value(struct interp *in, int *pos, double *out)
{
    char c = in->norm[*pos];
    if ((c >= '0' && c <= '9') || c == '.' ||
        ((c == '-' || c == '+') && ((in->norm[*pos + 1] >= '0' && in->norm[*pos + 1] <= '9') ||
                                    in->norm[*pos + 1] == '.'))) {
        size_t n = interp_parse_decimal(in->norm + *pos, INTERP_LINE_MAX, out);
        if (n == 0)
            return interp_fail(in, INTERP_ERR_SYNTAX, in->normcol[*pos], "bad number");
        *pos += (int)n;
        return 0;
    }
    if (c == '[')
        return read_expression(in, pos, out);
    if (c == '#')
        return read_parameter(in, pos, out);
    if (c == '-' || c == '+') {
        (*pos)++;
        CHP(interp_read_value(in, pos, out));
        if (c == '-')
            *out = -*out;
        return 0;
    }
    if (c >= 'a' && c <= 'z')
        return read_function(in, pos, out);
    if (c == 0)
        return interp_fail(in, INTERP_ERR_SYNTAX, in->normcol[*pos],
                           "a value is missing at the end of the line");
    return interp_fail(in, INTERP_ERR_SYNTAX, in->normcol[*pos],
                       "a value is expected here, not '%c'", c);
}
