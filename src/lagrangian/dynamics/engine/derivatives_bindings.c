/* The Python bindings of derivatives_kernel.c's functions (derivatives_c.py appends this text
 * after the kernel's core, emitted on one state and on vector lanes). */

/* -- Python bindings: tree(D, I) makes a tree's capsule once (its description and
 * derivatives_c.py's table);
 * the functions take (tree, Q, V, X, P) with Q, V, X (..., nq / nv) float64 (or (nq,), shared
 * by the batch), P = [g (3), tau_<joint> (nj), 13 per body]; outputs (..., nv, nv) each, as a
 * tuple, with the count of NaN rows appended where a state's inputs are not all finite (or,
 * forward, its M is not positive definite); NotImplemented for inputs of other widths, batch
 * shapes or quaternions off unit norm (the front checks and names them). A batch runs on threads taking DK_CHUNK states at a
 * time, each thread's work in one heap block (any tree's size, off the threads' stacks). */

#define DK_PTHREADS LG_PTHREADS  /* batch_threads.c, above this text */
#define DK_MAX_THREADS LG_MAX_THREADS
#define DK_THREAD_STATES 512
#define DK_HEADER 8  /* I's first numbers: nb, nj, ff, np, nnz, ltdl, once, sparse */

/* The states a thread takes at a time from the batch's shared counter (a multiple of
   LG_LANES): the threads share the batch as they go, so one slowed by the machine's other work
   does not hold the call back with half the batch. */
#define DK_CHUNK 128

/* the bytes of one state's work kept on a thread's stack, past which it is on the heap (the
   Panda's 13 kB; a 200-body chain's 1.3 MB) */
#define DK_LOCAL ((size_t)32 << 10)

static void dk_tree_free(PyObject *capsule)
{
    free(PyCapsule_GetPointer(capsule, "lagrangian.derivatives_tree"));
}

/* The tree of its description D (float64, tree/description.py's: joint.h's tk_open checks it)
 * and the table I (int32, derivatives_c.py's layout), copied into one block with the tree;
 * every index checked here once (the kernel trusts them). */
static PyObject *dk_py_tree(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    PyArrayObject *table_i = NULL, *table_d = NULL;
    PyObject *result = NULL;
    if (nargs != 2) {
        PyErr_SetString(PyExc_TypeError, "expected (D, I)");
        return NULL;
    }
    table_d = (PyArrayObject *)PyArray_FROMANY(args[0], NPY_DOUBLE, 1, 1, NPY_ARRAY_CARRAY_RO);
    table_i = (PyArrayObject *)PyArray_FROMANY(args[1], NPY_INT32, 1, 1, NPY_ARRAY_CARRAY_RO);
    if (!table_i || !table_d) goto done;
    const npy_intp ni = PyArray_SIZE(table_i), nd = PyArray_SIZE(table_d);
    const int *h = (const int *)PyArray_DATA(table_i);
    tk_tree t;
    /* a ball joint or a free flyer below the root only as its columns (derivatives_c.py's
       description) */
    if (ni < DK_HEADER || tk_open(PyArray_DATA(table_d), nd, &t)
        || ((t.balls || t.flyers) && tk_whole_balls(&t)))
        goto bad;
    const long nb = h[0], nj = h[1], ff = h[2], np = h[3], nnz = h[4];
    if (nb != t.nb || nj != t.n || ff != t.fb || np < nb || nnz < 0) goto bad;
    const long nv = nj + 6 * ff;
    const long nint = DK_HEADER + 2 * np + (nv + 1) + nnz + nv;
    if (ni != nint) goto bad;
    /* the block: the tree, D's copy, each body's multiplier, then I and each body's parent
       and coordinate */
    dk_tree *tree = malloc(sizeof(dk_tree) + ((size_t)nd + nb) * sizeof(double)
                           + ((size_t)nint + 5 * nb) * sizeof(int));
    if (!tree) {
        PyErr_NoMemory();
        goto done;
    }
    double *reals = (double *)(tree + 1);  /* the doubles first: aligned after the struct */
    double *mult = reals + nd;
    int *ints = (int *)(mult + nb), *parent = ints + nint, *coord = parent + nb;
    int *motion = coord + nb, *end = motion + nb, *group = end + nb;
    memcpy(reals, PyArray_DATA(table_d), (size_t)nd * sizeof(double));
    memcpy(ints, h, (size_t)nint * sizeof(int));
    *tree = (dk_tree){.nb = nb, .nj = nj, .ff = ff, .np = np, .nv = nv, .nq = t.nq,
                      .qo = 7 * ff, .vo = 6 * ff, .ltdl = h[5] != 0, .once = h[6] != 0,
                      .sparse = h[7] != 0};
    tk_open_marked(reals, nd, &tree->t);  /* the same numbers: checked above */
    int columns_fine = 1;
    for (long i = 0; i < nb; i++) {
        const double *b = DK_BODY_OF(tree, i);
        parent[i] = (int)b[TK_PARENT];
        coord[i] = TK_FREE(b) ? 0 : (int)b[TK_COORD];
        mult[i] = b[TK_MULT];
        /* a ball's or a flyer's columns: their motion from the joint's parent's, their ends
           at the last column (the body), one group; any other record its own */
        const int column = TK_BALL(b) || TK_FLYER(b) ? (int)b[TK_COLUMN] : 0;
        motion[i] = parent[i];
        end[i] = i;
        group[i] = column ? i : -1;
        if (column > 1) {
            const int p = parent[i];
            const double *bp = p >= 0 ? DK_BODY_OF(tree, p) : NULL;
            columns_fine &= p >= 0 && p < i && bp[TK_KIND] == b[TK_KIND]
                            && (int)bp[TK_COLUMN] == column - 1
                            && bp[TK_QCOORD] == b[TK_QCOORD] && (int)bp[TK_COORD] + 1 == coord[i];
            if (!columns_fine) break;
            motion[i] = motion[p];
            group[i] = group[p];
        }
        if (column == (TK_BALL(b) ? 3 : 6))  /* the last: the body */
            for (long k = i; k >= 0 && group[k] == group[i]; k = parent[k]) end[k] = (int)i;
    }
    for (long i = 0; columns_fine && i < nb; i++) {  /* every such joint ends in its last */
        const double *b = DK_BODY_OF(tree, i);
        if (TK_BALL(b) || TK_FLYER(b))
            columns_fine &= (int)DK_BODY_OF(tree, end[i])[TK_COLUMN] == (TK_BALL(b) ? 3 : 6);
    }
    if (!columns_fine) {
        free(tree);
        goto bad;
    }
    tree->bodies = 0;
    for (long i = 0; i < nb; i++) tree->bodies += end[i] == i;
    tree->parent = parent;
    tree->coord = coord;
    tree->mult = mult;
    tree->motion = motion;
    tree->end = end;
    tree->group = group;
    const int *at = ints + DK_HEADER;
    tree->pair = (const int (*)[2])at; at += 2 * np;
    tree->row0 = at; at += nv + 1;
    tree->rows = at; at += nnz;
    tree->lambda = at;
    int fine = tree->parent[0] == -1 && tree->row0[0] == 0 && tree->row0[nv] == nnz;
    for (long i = 0; i < nb; i++)
        fine &= tree->parent[i] >= -1 && tree->parent[i] < i
                && (i < ff || (tree->coord[i] >= 0 && tree->coord[i] < nj))
                && (ff == 0 || i == 0 || tree->parent[i] >= 0);
    for (long e = 0; e < np; e++)
        fine &= tree->pair[e][0] >= 0 && tree->pair[e][0] < nb && tree->pair[e][1] >= 0
                && tree->pair[e][1] <= tree->pair[e][0];
    for (long c = 0; c < nv; c++)
        fine &= tree->row0[c] <= tree->row0[c + 1] && tree->lambda[c] >= -1
                && tree->lambda[c] < c;
    for (long e = 0; e < nnz; e++) fine &= tree->rows[e] >= 0 && tree->rows[e] < nv;
    /* a thread's work: 126 numbers a body, 3 a coordinate and four nv x nv matrices (dk4_carve,
       checked on a block of that size) */
    tree->space = 126 * (size_t)nb + 3 * (size_t)nv + 4 * (size_t)nv * nv;
    lg_v4 *probe = malloc(tree->space * sizeof(lg_v4));
    dk4_work w;
    fine &= probe && (size_t)(dk4_carve(tree, probe, &w) - probe) <= tree->space;
    free(probe);
    if (!fine) {
        free(tree);
        goto bad;
    }
    result = PyCapsule_New(tree, "lagrangian.derivatives_tree", dk_tree_free);
    if (!result) free(tree);
    goto done;
bad:
    PyErr_SetString(PyExc_ValueError,
                    "tree: not a description (description.py) and table (derivatives_c.py)");
done:
    Py_XDECREF(table_i);
    Py_XDECREF(table_d);
    return result;
}

typedef struct {
    const dk_tree *tree;
    int kind, stream;  /* stream: the outputs stored past the caches (lg_rows_streamed) */
    npy_intp step[3], k0, k1, bad;
    const double *x[3], *p;
    double *y[3];
    npy_intp *next;  /* the batch's first state not yet taken (shared), or NULL: k0 to k1 */
    int nomemory;    /* the thread's work block could not be had */
} dk_job;

/* the numbers of input j: q nq (a floating base's 7 first), v, a and tau nv */
static inline int dk_width(const dk_tree *tree, int j) { return j == 0 ? tree->nq : tree->nv; }

/* Whether state k's inputs are all finite. */
static inline int dk_finite(const dk_job *job, npy_intp k)
{
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < dk_width(job->tree, j); i++)
            if (!isfinite(job->x[j][k * job->step[j] + i])) return 0;
    return 1;
}

enum { DK_INVERSE, DK_FORWARD, DK_REGRESSOR };
#define DK_OUTPUTS(kind) ((kind) == DK_INVERSE ? 2 : (kind) == DK_FORWARD ? 3 : 1)

/* the numbers of one output of one state */
static inline size_t dk_size(const dk_tree *tree, int kind)
{
    return (size_t)tree->nv * (kind == DK_REGRESSOR ? 10 * (size_t)tree->bodies : (size_t)tree->nv);
}

/* States k0 to k1 of the job: LG_LANES at a time through the dk4_ functions (out: their
   outputs, in: their inputs, or NULL), the rest one by one; ``space`` the work block; the
   count of NaN rows. */
static npy_intp dk_range(const dk_job *job, npy_intp k, npy_intp k1, lg_v4 *out, lg_v4 *in,
                         void *space)
{
    const dk_tree *tree = job->tree;
    const int kind = job->kind, nout = DK_OUTPUTS(kind), nq = tree->nq;
    const size_t size = dk_size(tree, kind);
    npy_intp bad = 0;
    for (; out && k + LG_LANES <= k1; k += LG_LANES) {
        for (int j = 0; j < 3; j++) {
            const int width = dk_width(tree, j);
            if (job->step[j] == width) {  /* a row per state */
                lg_lanes(job->x[j] + k * width, width, in + j * nq);
                continue;
            }
            for (int l = 0; l < LG_LANES; l++)  /* one state shared by the batch */
                for (int i = 0; i < width; i++)
                    in[j * nq + i][l] = job->x[j][(k + l) * job->step[j] + i];
        }
        /* the next group's inputs, fetched while this one computes (as the reach module's) */
        for (int j = 0; j < 3 && k + 2 * LG_LANES <= k1; j++) {
            const int width = dk_width(tree, j);
            if (job->step[j] != width) continue;
            const char *next = (const char *)(job->x[j] + (k + LG_LANES) * width);
            for (size_t b = 0; b < LG_LANES * width * sizeof(double); b += 64)
                __builtin_prefetch(next + b, 0, 3);
        }
        /* the rows these states will fill, fetched for writing while the kernel computes: a
           batch's outputs are seldom in cache, and its stores would otherwise each wait */
        for (int o = 0; o < nout && !job->stream; o++) {
            const char *y = (const char *)(job->y[o] + k * size);
            for (size_t b = 0; b < LG_LANES * size * sizeof(double); b += 64)
                __builtin_prefetch(y + b, 1, 2);
        }
        int failed = 0;
        if (kind == DK_FORWARD)
            failed = dk4_forward_derivatives(tree, space, in, in + nq, in + 2 * nq, job->p,
                                             out, out + size, out + 2 * size);
        else if (kind == DK_INVERSE)
            dk4_inverse(tree, space, in, in + nq, in + 2 * nq, job->p, out, out + size);
        else
            dk4_regressor(tree, space, in, in + nq, in + 2 * nq, job->p, out);
        /* x - x is NaN for an infinite or NaN x: the lanes with an input not finite */
        lg_v4 spoilt = LG_V4(0.0);
        for (int j = 0; j < 3; j++)
            for (int i = 0; i < dk_width(tree, j); i++)
                spoilt += in[j * nq + i] - in[j * nq + i];
        for (int o = 0; o < nout; o++)
            if (job->stream) lg_rows_streamed(out + o * size, size, job->y[o] + k * size);
            else lg_rows(out + o * size, size, job->y[o] + k * size);
        for (int l = 0; l < LG_LANES; l++) {
            const int fine = !((failed >> l) & 1) && spoilt[l] == 0.0;
            bad += !fine;
            if (!fine)
                for (int o = 0; o < nout; o++)
                    for (size_t i = 0; i < size; i++) job->y[o][(k + l) * size + i] = NAN;
        }
    }
    for (; k < k1; k++) {
        const double *a0 = job->x[0] + k * job->step[0], *a1 = job->x[1] + k * job->step[1],
                     *a2 = job->x[2] + k * job->step[2];
        double *y0 = job->y[0] + k * size;
        int fine = dk_finite(job, k);
        if (fine) {
            if (kind == DK_FORWARD)
                fine = !dk_forward_derivatives(tree, space, a0, a1, a2, job->p, y0,
                                               job->y[1] + k * size, job->y[2] + k * size);
            else if (kind == DK_INVERSE)
                dk_inverse(tree, space, a0, a1, a2, job->p, y0, job->y[1] + k * size);
            else
                dk_regressor(tree, space, a0, a1, a2, job->p, y0);
        }
        if (!fine) {
            for (int o = 0; o < nout; o++)
                for (size_t i = 0; i < size; i++) job->y[o][k * size + i] = NAN;
            bad++;
        }
    }
    return bad;
}

static void *dk_run(void *argument)
{
    dk_job *job = (dk_job *)argument;
    const dk_tree *tree = job->tree;
    /* one block: the work, then, with LG_LANES states or more, the lanes' outputs (a
       regressor's are nv x 10 bodies vectors) and inputs; one state's work in doubles alone */
    const int lanes = job->k1 - job->k0 >= LG_LANES;
    const size_t outputs = 3 * dk_size(tree, DK_FORWARD) > dk_size(tree, DK_REGRESSOR)
                           ? 3 * dk_size(tree, DK_FORWARD) : dk_size(tree, DK_REGRESSOR);
    const size_t bytes = lanes ? (tree->space + outputs + 3 * (size_t)tree->nq) * sizeof(lg_v4)
                               : (tree->space * sizeof(double) + 63) & ~(size_t)63;
    /* a small tree's states one by one (a single call's) on the stack: no allocation */
    _Alignas(64) char local[DK_LOCAL];
    char *block = !lanes && bytes <= DK_LOCAL ? local : aligned_alloc(lanes ? sizeof(lg_v4) : 64,
                                                                      bytes);
    job->bad = 0;
    job->nomemory = !block;
    if (!block) return NULL;
    lg_v4 *out = lanes ? (lg_v4 *)block + tree->space : NULL;
    lg_v4 *in = lanes ? out + outputs : NULL;
    npy_intp bad = 0;
    if (!job->next)
        bad = dk_range(job, job->k0, job->k1, out, in, block);
    else
        for (;;) {
            const npy_intp k = __atomic_fetch_add(job->next, DK_CHUNK, __ATOMIC_RELAXED);
            if (k >= job->k1) break;
            bad += dk_range(job, k, k + DK_CHUNK < job->k1 ? k + DK_CHUNK : job->k1, out, in,
                            block);
        }
    if (block != local) free(block);
    if (job->stream) lg_stream_fence();
    job->bad = bad;
    return NULL;
}

/* how many threads a batch of ``count`` states runs on (batch_threads.c) */
static int dk_threads(npy_intp count) { return lg_threads(count, DK_THREAD_STATES); }

static PyObject *dk_batch(PyObject *const *args, Py_ssize_t nargs, int kind)
{
    PyArrayObject *in[3] = {NULL, NULL, NULL}, *P = NULL;
    PyObject *out[3] = {NULL, NULL, NULL}, *block = NULL, *result = NULL;
    npy_intp step[3] = {0, 0, 0};
    const int nout = DK_OUTPUTS(kind);
    if (nargs != 5) {
        PyErr_SetString(PyExc_TypeError, "expected (tree, Q, V, X, P)");
        return NULL;
    }
    const dk_tree *tree = PyCapsule_GetPointer(args[0], "lagrangian.derivatives_tree");
    if (!tree) return NULL;
    args++;
    int base = 0;
    for (int i = 0; i < 3; i++) {
        in[i] = (PyArrayObject *)PyArray_FROMANY(args[i], NPY_DOUBLE, 0, 0, NPY_ARRAY_CARRAY_RO);
        if (!in[i]) goto front;
        int nd = PyArray_NDIM(in[i]);
        if (nd == 0 || PyArray_DIMS(in[i])[nd - 1] != dk_width(tree, i)) goto front;
        if (PyArray_SIZE(in[i]) / dk_width(tree, i)
            > PyArray_SIZE(in[base]) / dk_width(tree, base))
            base = i;
    }
    npy_intp count = PyArray_SIZE(in[base]) / dk_width(tree, base);
    int nd = PyArray_NDIM(in[base]);
    for (int i = 0; i < 3; i++) {
        if (PyArray_NDIM(in[i]) == 1) {  /* one state, shared by the batch */
            step[i] = count > 1 ? 0 : dk_width(tree, i);
            continue;
        }
        if (PyArray_NDIM(in[i]) != nd
            || memcmp(PyArray_DIMS(in[i]), PyArray_DIMS(in[base]), (nd - 1) * sizeof(npy_intp)))
            goto front;
        step[i] = dk_width(tree, i);
    }
    if (tree->ff && !lg_unit_quaternions((const double *)PyArray_DATA(in[0]),
                                         step[0] ? count : 1, step[0], tree->nq, DK_QTOL))
        goto front;
    if ((tree->t.balls || tree->t.flyers)
        && !tk_unit_balls(&tree->t, (const double *)PyArray_DATA(in[0]), step[0] ? count : 1,
                          step[0]))
        goto front;
    P = (PyArrayObject *)PyArray_FROMANY(args[3], NPY_DOUBLE, 1, 1, NPY_ARRAY_CARRAY_RO);
    if (!P) goto done;
    if (PyArray_SIZE(P) != 3 + tree->nj + 13 * tree->nb) {
        PyErr_SetString(PyExc_ValueError,
                        "parameters: expected g (3), the actuators and 13 per body");
        goto done;
    }
    /* the outputs as views of one block (nout, ..., nv, nv): one allocation (two large ones
       of a size freed and asked again each call cost glibc a trim and fresh pages); the
       regressor's (..., nv, 10 bodies) */
    npy_intp dims[NPY_MAXDIMS];
    dims[0] = nout;
    memcpy(dims + 1, PyArray_DIMS(in[base]), (nd - 1) * sizeof(npy_intp));
    dims[nd] = tree->nv;
    dims[nd + 1] = kind == DK_REGRESSOR ? 10 * tree->bodies : tree->nv;
    block = lg_output(nd + 2, dims);
    if (!block) goto done;
    for (int o = 0; o < nout; o++) {
        out[o] = PySequence_GetItem(block, o);
        if (!out[o]) goto done;
    }
    dk_job jobs[DK_MAX_THREADS];
    int parts = dk_threads(count);
    npy_intp next = 0;  /* the threads take DK_CHUNK states at a time from here */
    for (int t = 0; t < parts; t++) {
        dk_job job = {tree, kind,
                      (size_t)count * nout * dk_size(tree, kind) * sizeof(double) >= LG_STREAM_MIN,
                      {step[0], step[1], step[2]}, 0, count, 0,
                      {PyArray_DATA(in[0]), PyArray_DATA(in[1]), PyArray_DATA(in[2])},
                      PyArray_DATA(P),
                      {PyArray_DATA((PyArrayObject *)out[0]),
                       nout > 1 ? PyArray_DATA((PyArrayObject *)out[1]) : NULL,
                       nout > 2 ? PyArray_DATA((PyArrayObject *)out[2]) : NULL},
                      parts > 1 ? &next : NULL, 0};
        jobs[t] = job;
    }
    npy_intp bad = 0;
    int nomemory = 0;
    NPY_BEGIN_THREADS_DEF;
    if (count > 16) NPY_BEGIN_THREADS;
#if DK_PTHREADS
    lg_run_batch(dk_run, jobs, sizeof jobs[0], parts);
#else
    for (int t = 0; t < parts; t++) dk_run(&jobs[t]);
#endif
    for (int t = 0; t < parts; t++) { bad += jobs[t].bad; nomemory |= jobs[t].nomemory; }
    if (count > 16) NPY_END_THREADS;
    /* a thread without its work block left its states unwritten: no numbers at all */
    if (nomemory) {
        PyErr_NoMemory();
        goto done;
    }
    if (kind == DK_REGRESSOR) {
        if (bad > 0)
            result = Py_BuildValue("(On)", out[0], (Py_ssize_t)bad);
        else {
            result = out[0];
            Py_INCREF(result);
        }
    } else if (bad > 0)
        result = nout == 3 ? Py_BuildValue("(OOOn)", out[0], out[1], out[2], (Py_ssize_t)bad)
                           : Py_BuildValue("(OOn)", out[0], out[1], (Py_ssize_t)bad);
    else
        result = nout == 3 ? PyTuple_Pack(3, out[0], out[1], out[2])
                           : PyTuple_Pack(2, out[0], out[1]);
done:
    for (int i = 0; i < 3; i++) { Py_XDECREF(in[i]); Py_XDECREF(out[i]); }
    Py_XDECREF(block);
    Py_XDECREF(P);
    return result;
front:  /* inputs this call does not take (numbers, widths, batch shapes, quaternions): the
           Python front checks them and names the fault (tree_terms.py); no error is read */
    PyErr_Clear();
    for (int i = 0; i < 3; i++) Py_XDECREF(in[i]);
    Py_RETURN_NOTIMPLEMENTED;
}

static PyObject *dk_py_inverse(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    return dk_batch(args, nargs, DK_INVERSE);
}

static PyObject *dk_py_forward(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    return dk_batch(args, nargs, DK_FORWARD);
}

static PyObject *dk_py_regressor(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    return dk_batch(args, nargs, DK_REGRESSOR);
}

static PyMethodDef dk_methods[] = {
    {"inverse_derivatives", (PyCFunction)(void (*)(void))dk_py_inverse, METH_FASTCALL,
     "(tree, Q, V, A, P) -> (d tau/dq, d tau/dq_dot[, count of NaN rows])"},
    {"forward_derivatives", (PyCFunction)(void (*)(void))dk_py_forward, METH_FASTCALL,
     "(tree, Q, V, TAU, P) -> (d q_ddot/dq, d q_ddot/dq_dot, M^-1[, count of NaN rows])"},
    {"regressor", (PyCFunction)(void (*)(void))dk_py_regressor, METH_FASTCALL,
     "(tree, Q, V, A, P) -> Y (or (Y, count of NaN rows)), tau = Y pi"},
    {"tree", (PyCFunction)(void (*)(void))dk_py_tree, METH_FASTCALL,
     "(I, D) -> the tree's capsule, for the functions' first argument"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef dk_module = {PyModuleDef_HEAD_INIT, DK_STR(LG_MODULE), NULL, -1, dk_methods};

PyMODINIT_FUNC DK_PASTE(PyInit_, LG_MODULE)(void)
{
    import_array();
    return PyModule_Create(&dk_module);
}
