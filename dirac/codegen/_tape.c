/* The tape machine's loop, compiled ahead of time (at the package's install).
 *
 * The same machine as dirac/codegen/tape_machine.py's _execute, which numba compiles on a
 * machine where this extension was not built: the same instructions (op, a, b, c, d) over a
 * float64 register file and one float64 memory, the same operation numbers
 * (dirac.codegen.tape_source.OPS), the same error codes (tape_machine.ERRORS). Each
 * instruction is one IEEE 754 double operation in the order of the tape, and the functions
 * of math.h are the libm CPython's math module and numba call: the results are those of the
 * interpreter and of numba, bit for bit. The build keeps the compiler from contracting a
 * product and a sum into a fused multiply-add (-ffp-contract=off, setup.py), which would
 * round once where the interpreter rounds twice.
 *
 * run_tape(code, reg, mem, base, rows, cols) -> int: code, base, rows and cols are
 * contiguous int64 buffers, reg and mem writable contiguous float64 buffers.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#include <stdint.h>

static int
take(PyObject *obj, Py_buffer *view, int writable, char kind, const char *name)
{
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, view, flags) < 0)
        return -1;
    const char *format = view->format ? view->format : "B";
    if (format[0] == '<' || format[0] == '=' || format[0] == '@')
        format++;
    int ok = view->itemsize == 8 && format[1] == '\0'
             && (kind == 'd' ? format[0] == 'd' : (format[0] == 'q' || format[0] == 'l'));
    if (!ok) {
        PyErr_Format(PyExc_TypeError, "run_tape: %s must be a contiguous %s array", name,
                     kind == 'd' ? "float64" : "int64");
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

/* execute's status when it cannot allocate its work (run_tape raises MemoryError) */
#define NO_MEMORY (-2)

static int64_t
index_of(double x, int64_t size)
{
    /* Python's int(x), truncated towards zero, when 0 <= int(x) < size; else -1 (NaN fails
       the comparison, and -1 < x < 0 truncates to 0, which an empty array does not hold) */
    if (!(x > -1.0 && x < (double)size))
        return -1;
    int64_t i = (int64_t)x;
    return i < size ? i : -1;
}

/* The unary functions of math.h by operation number (15 .. 26), and the check of a result
   where Python's math raises: shared by both dispatches below. */
static int
unary(int64_t op, double x, double *out)
{
    double y;
    switch (op) {
    case 15: y = sqrt(x); break;
    case 16: y = sin(x); break;
    case 17: y = cos(x); break;
    case 18: y = tan(x); break;
    case 19: y = exp(x); break;
    case 20: y = log(x); break;
    case 21: y = asin(x); break;
    case 22: y = acos(x); break;
    case 23: y = atan(x); break;
    case 24: y = sinh(x); break;
    case 25: y = cosh(x); break;
    case 26: y = tanh(x); break;
    default: return 4;
    }
    if ((y != y && x == x) || (isinf(y) && isfinite(x))) /* where Python's math raises */
        return 3;
    *out = y;
    return 0;
}

#if (defined(__GNUC__) || defined(__clang__)) && !defined(DIRAC_TAPE_SWITCH)
/* Direct threading (GCC's labels as values; Ertl & Gregg 2003, Sect. 3): before the run, each
   instruction (op, a, b, c, d) is copied into an array of (address of its operation's code, a,
   b, c, d) ending with a stop; each operation then ends with its own indirect jump to the
   next one's code. The processor predicts each such jump from the operation it ends (a RATTLE
   sub-step is the same sequence again and again) instead of from the one shared jump of a
   switch, and the table lookup and the bounds tests of the operation number and of the
   position are done once per instruction per call, not once per instruction executed. The
   operations, their order and their checks are those of the switch below (kept for other
   compilers, and built with -DDIRAC_TAPE_SWITCH to compare the two), so the results are the
   same, bit for bit; an operation number outside the table stops the run with code 4 where it
   is reached, and a jump at or beyond the end ends it, as in the switch.
   A call of 20 rattle-8 steps (the same captured tape, registers and memory, alternated with
   the former build, a switch only, in one process, median of 20 ratios, load average 4
   on 2 cores) took 0.51 times its time for the double pendulum in angles, 0.38 in Cartesian
   coordinates, 0.53 for the triple pendulum in angles, 0.50 for the symmetric top in Euler
   angles, 0.71 for the pendulum in its angle (a call of 46 us: the copy of the tape counts).
   A table of addresses looked up at each instruction (threading without the copy) took
   0.75, 0.64, 0.58, 0.56, 0.75. */
typedef struct {
    const void *go; /* the code of the operation */
    int64_t a, b, c, d;
} threaded_t;

static int
execute(const int64_t *code, Py_ssize_t n, double *reg, double *mem, const int64_t *base,
        const int64_t *rows, const int64_t *cols)
{
    static const void *const labels[28] = {
        &&op_mov, &&op_add, &&op_sub, &&op_mul, &&op_div, &&op_neg, &&op_load, &&op_store, &&op_load2,
        &&op_store2, &&op_jmp, &&op_jlt, &&op_jle, &&op_jeq, &&op_abs, &&op_unary, &&op_unary, &&op_unary,
        &&op_unary, &&op_unary, &&op_unary, &&op_unary, &&op_unary, &&op_unary, &&op_unary, &&op_unary,
        &&op_unary, &&op_atan2};
    Py_ssize_t count = n / 5; /* the switch runs the same whole instructions */
    threaded_t *tape = (threaded_t *)PyMem_RawMalloc((size_t)(count + 1) * sizeof(threaded_t));
    if (tape == NULL)
        return NO_MEMORY;
    for (Py_ssize_t k = 0; k < count; k++) {
        const int64_t *in = code + 5 * k;
        tape[k].go = (uint64_t)in[0] > 27 ? &&op_unknown : labels[in[0]];
        tape[k].a = in[1], tape[k].b = in[2], tape[k].c = in[3], tape[k].d = in[4];
    }
    tape[count].go = &&op_end;
    tape[count].a = tape[count].b = tape[count].c = tape[count].d = 0;
    const threaded_t *next = tape, *now;
    int64_t a, b, c, d;
    int status = 0;
#define NEXT                                                                                                     \
    do {                                                                                                         \
        now = next++;                                                                                            \
        a = now->a, b = now->b, c = now->c, d = now->d;                                                          \
        goto *now->go;                                                                                           \
    } while (0)
/* the switch's pc = 5 * target: the run ends when that is at or beyond the end */
#define JUMP(target) (next = tape + ((uint64_t)(target) < (uint64_t)count ? (target) : count))
#define STOP(code_)                                                                                              \
    do {                                                                                                         \
        status = (code_);                                                                                        \
        goto done;                                                                                               \
    } while (0)
    NEXT;
op_mul: reg[a] = reg[b] * reg[c]; NEXT;
op_add: reg[a] = reg[b] + reg[c]; NEXT;
op_sub: reg[a] = reg[b] - reg[c]; NEXT;
op_mov: reg[a] = reg[b]; NEXT;
op_load: { /* LOAD reg a <- array b [reg c] */
        int64_t i = index_of(reg[c], rows[b]);
        if (i < 0)
            STOP(2);
        reg[a] = mem[base[b] + i];
        NEXT;
    }
op_jlt: /* JLT: to a when (reg b < reg c) is not d */
    if ((reg[b] < reg[c]) != (d != 0))
        JUMP(a);
    NEXT;
op_jeq: /* JEQ */
    if ((reg[b] == reg[c]) != (d != 0))
        JUMP(a);
    NEXT;
op_jmp: JUMP(a); NEXT;
op_div: /* DIV */
    if (reg[c] == 0.0)
        STOP(1);
    reg[a] = reg[b] / reg[c];
    NEXT;
op_neg: reg[a] = -reg[b]; NEXT;
op_store: { /* STORE array a [reg b] <- reg c */
        int64_t i = index_of(reg[b], rows[a]);
        if (i < 0)
            STOP(2);
        mem[base[a] + i] = reg[c];
        NEXT;
    }
op_load2: { /* LOAD2 reg a <- array b [reg c, reg d] */
        int64_t i = index_of(reg[c], rows[b]), j = index_of(reg[d], cols[b]);
        if (i < 0 || j < 0)
            STOP(2);
        reg[a] = mem[base[b] + i * cols[b] + j];
        NEXT;
    }
op_store2: { /* STORE2 array a [reg b, reg c] <- reg d */
        int64_t i = index_of(reg[b], rows[a]), j = index_of(reg[c], cols[a]);
        if (i < 0 || j < 0)
            STOP(2);
        mem[base[a] + i * cols[a] + j] = reg[d];
        NEXT;
    }
op_jle: /* JLE */
    if ((reg[b] <= reg[c]) != (d != 0))
        JUMP(a);
    NEXT;
op_abs: reg[a] = fabs(reg[b]); NEXT;
op_atan2: reg[a] = atan2(reg[b], reg[c]); NEXT;
op_unary: { /* the operation number from the tape as given */
        int failed = unary(code[5 * (now - tape)], reg[b], &reg[a]);
        if (failed)
            STOP(failed);
        NEXT;
    }
op_unknown: STOP(4);
op_end: STOP(0);
done:
    PyMem_RawFree(tape);
    return status;
#undef NEXT
#undef JUMP
#undef STOP
}
#else
static int
execute(const int64_t *code, Py_ssize_t n, double *reg, double *mem, const int64_t *base,
        const int64_t *rows, const int64_t *cols)
{
    Py_ssize_t pc = 0;
    while (pc < n) {
        int64_t op = code[pc], a = code[pc + 1], b = code[pc + 2], c = code[pc + 3], d = code[pc + 4];
        pc += 5;
        switch (op) {
        case 3: reg[a] = reg[b] * reg[c]; break;
        case 1: reg[a] = reg[b] + reg[c]; break;
        case 2: reg[a] = reg[b] - reg[c]; break;
        case 0: reg[a] = reg[b]; break;
        case 6: { /* LOAD reg a <- array b [reg c] */
            int64_t i = index_of(reg[c], rows[b]);
            if (i < 0)
                return 2;
            reg[a] = mem[base[b] + i];
            break;
        }
        case 11: /* JLT: to a when (reg b < reg c) is not d */
            if ((reg[b] < reg[c]) != (d != 0))
                pc = 5 * a;
            break;
        case 13: /* JEQ */
            if ((reg[b] == reg[c]) != (d != 0))
                pc = 5 * a;
            break;
        case 10: pc = 5 * a; break; /* JMP */
        case 4: /* DIV */
            if (reg[c] == 0.0)
                return 1;
            reg[a] = reg[b] / reg[c];
            break;
        case 5: reg[a] = -reg[b]; break;
        case 7: { /* STORE array a [reg b] <- reg c */
            int64_t i = index_of(reg[b], rows[a]);
            if (i < 0)
                return 2;
            mem[base[a] + i] = reg[c];
            break;
        }
        case 8: { /* LOAD2 reg a <- array b [reg c, reg d] */
            int64_t i = index_of(reg[c], rows[b]), j = index_of(reg[d], cols[b]);
            if (i < 0 || j < 0)
                return 2;
            reg[a] = mem[base[b] + i * cols[b] + j];
            break;
        }
        case 9: { /* STORE2 array a [reg b, reg c] <- reg d */
            int64_t i = index_of(reg[b], rows[a]), j = index_of(reg[c], cols[a]);
            if (i < 0 || j < 0)
                return 2;
            mem[base[a] + i * cols[a] + j] = reg[d];
            break;
        }
        case 12: /* JLE */
            if ((reg[b] <= reg[c]) != (d != 0))
                pc = 5 * a;
            break;
        case 14: reg[a] = fabs(reg[b]); break;
        case 27: reg[a] = atan2(reg[b], reg[c]); break;
        default: {
            int status = unary(op, reg[b], &reg[a]);
            if (status)
                return status;
        }
        }
    }
    return 0;
}

#endif

static PyObject *
run_tape(PyObject *self, PyObject *args)
{
    PyObject *objects[6];
    if (!PyArg_ParseTuple(args, "OOOOOO:run_tape", &objects[0], &objects[1], &objects[2], &objects[3],
                          &objects[4], &objects[5]))
        return NULL;
    static const char kinds[6] = {'q', 'd', 'd', 'q', 'q', 'q'};
    static const int writable[6] = {0, 1, 1, 0, 0, 0};
    static const char *names[6] = {"code", "reg", "mem", "base", "rows", "cols"};
    Py_buffer views[6];
    int taken = 0;
    for (; taken < 6; taken++) {
        if (take(objects[taken], &views[taken], writable[taken], kinds[taken], names[taken]) < 0)
            break;
    }
    int status = -1;
    if (taken == 6) {
        Py_BEGIN_ALLOW_THREADS
        status = execute((const int64_t *)views[0].buf, views[0].len / 8, (double *)views[1].buf,
                         (double *)views[2].buf, (const int64_t *)views[3].buf, (const int64_t *)views[4].buf,
                         (const int64_t *)views[5].buf);
        Py_END_ALLOW_THREADS
    }
    for (int k = 0; k < taken; k++)
        PyBuffer_Release(&views[k]);
    if (taken < 6)
        return NULL;
    if (status == NO_MEMORY)
        return PyErr_NoMemory();
    return PyLong_FromLong(status);
}

static PyMethodDef methods[] = {
    {"run_tape", run_tape, METH_VARARGS,
     "run_tape(code, reg, mem, base, rows, cols) -> int: run a tape; 0, or an error code of "
     "dirac.codegen.tape_machine.ERRORS."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_tape", "The tape machine's loop, compiled ahead of time.",
                                    -1, methods};

PyMODINIT_FUNC
PyInit__tape(void)
{
    return PyModule_Create(&module);
}
