/* The Python bindings of derivatives_kernel.c's functions (derivatives_c.py appends this text
 * after the kernel's core, emitted on one state and on vector lanes). */

/* -- Python bindings: (Q, V, X, P) with Q, V, X (..., DK_NV) float64 (or (DK_NV,), shared by
 * the batch), P = [g (3), tau_<joint> (DK_NV)]; outputs (..., DK_NV, DK_NV) each, as a tuple,
 * with the count of NaN rows appended where a state's inputs are not all finite (or, forward,
 * its M is not positive definite). A batch runs on threads taking DK_CHUNK states at a time. */

#define DK_PTHREADS LG_PTHREADS  /* batch_threads.c, above this text */
#define DK_MAX_THREADS LG_MAX_THREADS
#define DK_THREAD_STATES 512

/* the numbers of input j: q DK_NQ (a floating base's 7 first), v, a and tau DK_NV */
#define DK_WIDTH(j) ((j) == 0 ? DK_NQ : DK_NV)

/* The states a thread takes at a time from the batch's shared counter (a multiple of
   LG_LANES): the threads share the batch as they go, so one slowed by the machine's other work
   does not hold the call back with half the batch. */
#define DK_CHUNK 128

typedef struct {
    int kind, stream;  /* stream: the outputs stored past the caches (lg_rows_streamed) */
    npy_intp step[3], k0, k1, bad;
    const double *x[3], *p;
    double *y[3];
    npy_intp *next;  /* the batch's first state not yet taken (shared), or NULL: k0 to k1 */
} dk_job;

/* Whether state k's inputs are all finite. */
static inline int dk_finite(const dk_job *job, npy_intp k)
{
    for (int j = 0; j < 3; j++)
        for (int i = 0; i < DK_WIDTH(j); i++)
            if (!isfinite(job->x[j][k * job->step[j] + i])) return 0;
    return 1;
}

enum { DK_INVERSE, DK_FORWARD, DK_REGRESSOR };
#define DK_SIZE(kind) ((kind) == DK_REGRESSOR ? DK_NV * 10 * DK_NB : DK_NV * DK_NV)
#define DK_OUTPUTS(kind) ((kind) == DK_INVERSE ? 2 : (kind) == DK_FORWARD ? 3 : 1)
#define DK_SPACE (3 * DK_NV * DK_NV > DK_NV * 10 * DK_NB ? 3 * DK_NV * DK_NV : DK_NV * 10 * DK_NB)

/* States k0 to k1 of the job: LG_LANES at a time through the dk4_ functions (out: their
   outputs, or NULL), the rest one by one; the count of NaN rows. */
static npy_intp dk_range(const dk_job *job, npy_intp k, npy_intp k1, lg_v4 *out)
{
    const int kind = job->kind, size = DK_SIZE(kind), nout = DK_OUTPUTS(kind);
    npy_intp bad = 0;
    for (; out && k + LG_LANES <= k1; k += LG_LANES) {
        lg_v4 in[3][DK_NQ];
        for (int j = 0; j < 3; j++) {
            if (job->step[j] == DK_WIDTH(j)) {  /* a row per state */
                lg_lanes(job->x[j] + k * DK_WIDTH(j), DK_WIDTH(j), in[j]);
                continue;
            }
            for (int l = 0; l < LG_LANES; l++)  /* one state shared by the batch */
                for (int i = 0; i < DK_WIDTH(j); i++)
                    in[j][i][l] = job->x[j][(k + l) * job->step[j] + i];
        }
        /* the next group's inputs, fetched while this one computes (as the reach module's) */
        for (int j = 0; j < 3 && k + 2 * LG_LANES <= k1; j++) {
            if (job->step[j] != DK_WIDTH(j)) continue;
            const char *next = (const char *)(job->x[j] + (k + LG_LANES) * DK_WIDTH(j));
            for (size_t b = 0; b < LG_LANES * DK_WIDTH(j) * sizeof(double); b += 64)
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
            failed = dk4_forward_derivatives(in[0], in[1], in[2], job->p, out, out + size,
                                             out + 2 * size);
        else if (kind == DK_INVERSE)
            dk4_inverse(in[0], in[1], in[2], job->p, out, out + size);
        else
            dk4_regressor(in[0], in[1], in[2], job->p, out);
        /* x - x is NaN for an infinite or NaN x: the lanes with an input not finite */
        lg_v4 spoilt = LG_V4(0.0);
        for (int j = 0; j < 3; j++)
            for (int i = 0; i < DK_WIDTH(j); i++) spoilt += in[j][i] - in[j][i];
        for (int o = 0; o < nout; o++)
            if (job->stream) lg_rows_streamed(out + o * size, size, job->y[o] + k * size);
            else lg_rows(out + o * size, size, job->y[o] + k * size);
        for (int l = 0; l < LG_LANES; l++) {
            const int fine = !((failed >> l) & 1) && spoilt[l] == 0.0;
            bad += !fine;
            if (!fine)
                for (int o = 0; o < nout; o++)
                    for (int i = 0; i < size; i++) job->y[o][(k + l) * size + i] = NAN;
        }
    }
    for (; k < k1; k++) {
        const double *a0 = job->x[0] + k * job->step[0], *a1 = job->x[1] + k * job->step[1],
                     *a2 = job->x[2] + k * job->step[2];
        double *y0 = job->y[0] + k * size;
        int fine = dk_finite(job, k);
        if (fine) {
            if (kind == DK_FORWARD)
                fine = !dk_forward_derivatives(a0, a1, a2, job->p, y0, job->y[1] + k * size,
                                               job->y[2] + k * size);
            else if (kind == DK_INVERSE)
                dk_inverse(a0, a1, a2, job->p, y0, job->y[1] + k * size);
            else
                dk_regressor(a0, a1, a2, job->p, y0);
        }
        if (!fine) {
            for (int o = 0; o < nout; o++)
                for (int i = 0; i < size; i++) job->y[o][k * size + i] = NAN;
            bad++;
        }
    }
    return bad;
}

static void *dk_run(void *argument)
{
    dk_job *job = (dk_job *)argument;
    /* the lanes' outputs on the heap (a regressor's are DK_NV x 10 DK_NB vectors) */
    lg_v4 *out = job->k1 - job->k0 >= LG_LANES
                 ? aligned_alloc(sizeof(lg_v4), DK_SPACE * sizeof(lg_v4)) : NULL;
    npy_intp bad = 0;
    if (!job->next)
        bad = dk_range(job, job->k0, job->k1, out);
    else
        for (;;) {
            const npy_intp k = __atomic_fetch_add(job->next, DK_CHUNK, __ATOMIC_RELAXED);
            if (k >= job->k1) break;
            bad += dk_range(job, k, k + DK_CHUNK < job->k1 ? k + DK_CHUNK : job->k1, out);
        }
    free(out);
    if (job->stream) lg_stream_fence();
    job->bad = bad;
    return NULL;
}

/* how many threads a batch of ``count`` states runs on (batch_threads.c) */
static int dk_threads(npy_intp count) { return lg_threads(count, DK_THREAD_STATES); }

static PyObject *dk_batch(PyObject *const *args, Py_ssize_t nargs, int kind)
{
    const char *names[3] = {"q", "v", kind == DK_FORWARD ? "tau" : "a"};
    PyArrayObject *in[3] = {NULL, NULL, NULL}, *P = NULL;
    PyObject *out[3] = {NULL, NULL, NULL}, *block = NULL, *result = NULL;
    npy_intp step[3] = {0, 0, 0};
    const int nout = DK_OUTPUTS(kind);
    if (nargs != 4) {
        PyErr_SetString(PyExc_TypeError, "expected (Q, V, X, P)");
        return NULL;
    }
    int base = 0;
    for (int i = 0; i < 3; i++) {
        in[i] = (PyArrayObject *)PyArray_FROMANY(args[i], NPY_DOUBLE, 0, 0, NPY_ARRAY_CARRAY_RO);
        if (!in[i]) goto done;
        int nd = PyArray_NDIM(in[i]);
        if (nd == 0 || PyArray_DIMS(in[i])[nd - 1] != DK_WIDTH(i)) {
            PyErr_Format(PyExc_ValueError, "%s: expected %d values along the last axis",
                         names[i], DK_WIDTH(i));
            goto done;
        }
        if (PyArray_SIZE(in[i]) / DK_WIDTH(i) > PyArray_SIZE(in[base]) / DK_WIDTH(base)) base = i;
    }
    npy_intp count = PyArray_SIZE(in[base]) / DK_WIDTH(base);
    int nd = PyArray_NDIM(in[base]);
    for (int i = 0; i < 3; i++) {
        if (PyArray_NDIM(in[i]) == 1) {  /* one state, shared by the batch */
            step[i] = count > 1 ? 0 : DK_WIDTH(i);
            continue;
        }
        if (PyArray_NDIM(in[i]) != nd
            || memcmp(PyArray_DIMS(in[i]), PyArray_DIMS(in[base]), (nd - 1) * sizeof(npy_intp))) {
            PyErr_SetString(PyExc_ValueError, "the batch shapes of the inputs differ");
            goto done;
        }
        step[i] = DK_WIDTH(i);
    }
#if DK_FF
    if (!lg_unit_quaternions((const double *)PyArray_DATA(in[0]), step[0] ? count : 1, step[0],
                             DK_NQ, DK_QTOL))
        goto done;
#endif
    P = (PyArrayObject *)PyArray_FROMANY(args[3], NPY_DOUBLE, 1, 1, NPY_ARRAY_CARRAY_RO);
    if (!P) goto done;
    if (PyArray_SIZE(P) != 3 + DK_NJ + 13 * DK_NB) {
        PyErr_SetString(PyExc_ValueError,
                        "parameters: expected g (3), the actuators and 13 per body");
        goto done;
    }
    /* the outputs as views of one block (nout, ..., DK_NV, DK_NV): one allocation (two large
       ones of a size freed and asked again each call cost glibc a trim and fresh pages);
       the regressor's (..., DK_NV, 10 DK_NB) */
    npy_intp dims[NPY_MAXDIMS];
    dims[0] = nout;
    memcpy(dims + 1, PyArray_DIMS(in[base]), (nd - 1) * sizeof(npy_intp));
    dims[nd] = DK_NV;
    dims[nd + 1] = kind == DK_REGRESSOR ? 10 * DK_NB : DK_NV;
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
        dk_job job = {kind, (size_t)count * nout * DK_SIZE(kind) * sizeof(double) >= LG_STREAM_MIN,
                      {step[0], step[1], step[2]}, 0, count, 0,
                      {PyArray_DATA(in[0]), PyArray_DATA(in[1]), PyArray_DATA(in[2])},
                      PyArray_DATA(P),
                      {PyArray_DATA((PyArrayObject *)out[0]),
                       nout > 1 ? PyArray_DATA((PyArrayObject *)out[1]) : NULL,
                       nout > 2 ? PyArray_DATA((PyArrayObject *)out[2]) : NULL},
                      parts > 1 ? &next : NULL};
        jobs[t] = job;
    }
    npy_intp bad = 0;
    NPY_BEGIN_THREADS_DEF;
    if (count > 16) NPY_BEGIN_THREADS;
#if DK_PTHREADS
    lg_run_batch(dk_run, jobs, sizeof jobs[0], parts);
#else
    for (int t = 0; t < parts; t++) dk_run(&jobs[t]);
#endif
    for (int t = 0; t < parts; t++) bad += jobs[t].bad;
    if (count > 16) NPY_END_THREADS;
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
     "(Q, V, A, P) -> (d tau/dq, d tau/dq_dot[, count of NaN rows])"},
    {"forward_derivatives", (PyCFunction)(void (*)(void))dk_py_forward, METH_FASTCALL,
     "(Q, V, TAU, P) -> (d q_ddot/dq, d q_ddot/dq_dot, M^-1[, count of NaN rows])"},
    {"regressor", (PyCFunction)(void (*)(void))dk_py_regressor, METH_FASTCALL,
     "(Q, V, A, P) -> Y (or (Y, count of NaN rows)), tau = Y pi"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef dk_module = {PyModuleDef_HEAD_INIT, DK_STR(LG_MODULE), NULL, -1, dk_methods};

PyMODINIT_FUNC DK_PASTE(PyInit_, LG_MODULE)(void)
{
    import_array();
    return PyModule_Create(&dk_module);
}
