/* ---- batched bindings: each input (..., N) or (N,), outputs shaped like the largest ----
   A state whose inputs are not all finite, or (forward dynamics) whose M is not positive
   definite, gives NaN in its own output row and is counted; the other states are computed as
   alone. With none such the output array is returned, else (output, count). */
enum { RT_MASS, RT_BIAS, RT_GRAVITY, RT_INVERSE, RT_FORWARD, RT_KINETIC, RT_POTENTIAL };
#define RT_PTHREADS LG_PTHREADS  /* batch_threads.c, above this text */
#define RT_MAX_THREADS LG_MAX_THREADS
#define RT_THREAD_STATES 1024
#ifndef LG_LANES
#define LG_LANES 1
#endif
/* the numbers of input j: q has RT_NQ (LG_N + 1 for a floating base's quaternion), v, a and
   tau LG_N */
#define RT_WIDTH(j) ((j) == 0 ? RT_NQ : LG_N)

typedef struct {
    int kind, nin, size, stream;  /* stream: rows stored past the caches (lg_rows_streamed) */
    npy_intp step[3];
    const double *x0, *x1, *x2, *p;
    double *y;
    npy_intp count, bad;  /* the batch's states; how many came out NaN */
    npy_intp *next;  /* the first state no thread has taken yet (shared by the threads) */
} rt_job;

/* Whether state k's inputs are all finite. */
static inline int rt_finite(int nin, const npy_intp *step, const double *x0, const double *x1,
                            const double *x2, npy_intp k)
{
    for (int j = 0; j < nin; j++) {
        const double *x = (j == 0 ? x0 : j == 1 ? x1 : x2) + k * step[j];
        for (int i = 0; i < RT_WIDTH(j); i++)
            if (!isfinite(x[i])) return 0;
    }
    return 1;
}

/* NaN over state k's output row. */
static inline void rt_blank(double *y, int size, npy_intp k)
{
    for (int i = 0; i < size; i++) y[k * size + i] = NAN;
}

/* States k..count - 1 of the job; gives how many came out NaN. */
static npy_intp rt_range(const rt_job *job, npy_intp k, npy_intp count)
{
    const int kind = job->kind, nin = job->nin, size = job->size;
    const npy_intp *step = job->step;
    const double *x0 = job->x0, *x1 = job->x1, *x2 = job->x2, *p = job->p;
    double *y = job->y;
    npy_intp bad = 0;
    (void)nin; (void)size;
#if RT_VECTOR || RT_VECTOR_FORWARD
    /* LG_LANES states at a time through the vector variants (every function's, or forward
       dynamics' alone), the rest one by one */
    for (; k + LG_LANES <= count && (kind == RT_FORWARD ? RT_VECTOR_FORWARD : RT_VECTOR);
         k += LG_LANES) {
        lg_v4 in[3][RT_NQ], out4[LG_N * LG_N];
        /* the rows these states will fill, fetched for writing while the kernel computes
           (as the reach and derivatives modules'): a batch's outputs are seldom in cache */
        for (size_t b = 0; !job->stream && b < LG_LANES * size * sizeof(double); b += 64)
            __builtin_prefetch((const char *)(y + k * size) + b, 1, 2);
        for (int j = 0; j < nin; j++) {
            const double *x = j == 0 ? x0 : j == 1 ? x1 : x2;
            if (step[j] == RT_WIDTH(j)) {  /* a row per state */
                lg_lanes(x + k * RT_WIDTH(j), RT_WIDTH(j), in[j]);
                continue;
            }
            for (int l = 0; l < LG_LANES; l++)  /* one state shared by the batch */
                for (int i = 0; i < RT_WIDTH(j); i++) in[j][i][l] = x[(k + l) * step[j] + i];
        }
        switch (kind) {
#if RT_VECTOR
        case RT_MASS: rt4_mass_matrix(in[0], p, out4); break;
        case RT_BIAS: rt4_bias_forces(in[0], in[1], p, out4); break;
        case RT_GRAVITY: rt4_gravity(in[0], p, out4); break;
        case RT_INVERSE: rt4_inverse_dynamics(in[0], in[1], in[2], p, out4); break;
        case RT_KINETIC: rt4_kinetic_energy(in[0], in[1], p, out4); break;
        case RT_POTENTIAL: rt4_potential_energy(in[0], p, out4); break;
#endif
#if RT_VECTOR_FORWARD
        case RT_FORWARD: rt4_forward_dynamics(in[0], in[1], in[2], p, out4); break;
#endif
        default: break;
        }
        /* x - x is NaN for an infinite or NaN x: the lanes with an input (or, forward
           dynamics, a result) not finite, checked on the lanes rather than state by state
           from memory (7% of a floating base's M), in two sums not waiting one for another */
        lg_v4 spoilt[2] = {LG_V4(0.0), LG_V4(0.0)};
        for (int j = 0; j < nin; j++)
            for (int i = 0; i < RT_WIDTH(j); i++) spoilt[i & 1] += in[j][i] - in[j][i];
        if (kind == RT_FORWARD)
            for (int i = 0; i < size; i++) spoilt[i & 1] += out4[i] - out4[i];
        spoilt[0] += spoilt[1];
        if (job->stream) lg_rows_streamed(out4, size, y + k * size);
        else lg_rows(out4, size, y + k * size);
        for (int l = 0; l < LG_LANES; l++)
            if (spoilt[0][l] != 0.0) {
                rt_blank(y, size, k + l);
                bad++;
            }
    }
#endif
    for (; k < count; k++) {
        const double *a0 = x0 + k * step[0], *a1 = x1 + k * step[1], *a2 = x2 + k * step[2];
        if (!rt_finite(nin, step, x0, x1, x2, k)) {
            rt_blank(y, size, k);
            bad++;
            continue;
        }
        switch (kind) {
        case RT_MASS: rt_mass_matrix(a0, p, y + k * LG_N * LG_N); break;
        case RT_BIAS: rt_bias_forces(a0, a1, p, y + k * LG_N); break;
        case RT_GRAVITY: rt_gravity(a0, p, y + k * LG_N); break;
        case RT_INVERSE: rt_inverse_dynamics(a0, a1, a2, p, y + k * LG_N); break;
        case RT_FORWARD:
            if (rt_forward_dynamics(a0, a1, a2, p, y + k * LG_N)) {
                rt_blank(y, size, k);
                bad++;
            }
            break;
        case RT_KINETIC: y[k] = rt_kinetic_energy(a0, a1, p); break;
        case RT_POTENTIAL: y[k] = rt_potential_energy(a0, p); break;
        }
    }
    return bad;
}

/* A thread's work: blocks of RT_BLOCK states taken in turn from the shared counter until
   none is left, so that a thread slowed by the machine's other work (a shared processor)
   takes fewer rather than holding the others up. */
#define RT_BLOCK 64  /* a multiple of LG_LANES: only the batch's last states run one by one */
static void *rt_run(void *argument)
{
    rt_job *job = (rt_job *)argument;
    npy_intp bad = 0;
    for (;;) {
#if RT_PTHREADS
        const npy_intp k = __atomic_fetch_add(job->next, RT_BLOCK, __ATOMIC_RELAXED);
#else
        const npy_intp k = *job->next;
        *job->next += RT_BLOCK;
#endif
        if (k >= job->count) break;
        bad += rt_range(job, k, k + RT_BLOCK < job->count ? k + RT_BLOCK : job->count);
    }
#if RT_VECTOR || RT_VECTOR_FORWARD
    if (job->stream) lg_stream_fence();
#endif
    job->bad = bad;
    return NULL;
}

/* How many threads a batch of ``count`` states runs on (batch_threads.c). */
static int rt_threads(npy_intp count) { return lg_threads(count, RT_THREAD_STATES); }

/* An argument that already is C-ordered doubles (a new reference), else NULL with no error
   set: the caller answers NotImplemented and the Python front checks and shapes the inputs
   (recursive.py), so no error text here is ever read. */
static PyArrayObject *rt_doubles(PyObject *x)
{
    if (PyArray_CheckExact(x)) {
        PyArrayObject *a = (PyArrayObject *)x;
        if (PyArray_TYPE(a) == NPY_DOUBLE && PyArray_ISCARRAY_RO(a) && PyArray_ISNOTSWAPPED(a)) {
            Py_INCREF(x);
            return a;
        }
    }
    return NULL;
}

static PyObject *rt_batch(PyObject *const *args, Py_ssize_t nargs, int nin, int kind)
{
    PyArrayObject *in[3] = {NULL, NULL, NULL}, *P = NULL;
    PyObject *out = NULL;
    npy_intp step[3] = {0, 0, 0};
    if (nargs != nin + 1) {
        PyErr_Format(PyExc_TypeError, "expected %d arguments", nin + 1);
        return NULL;
    }
    int base = 0;
    for (int i = 0; i < nin; i++) {
        in[i] = rt_doubles(args[i]);
        if (!in[i]) goto slow;
        int nd = PyArray_NDIM(in[i]);
        if (nd == 0 || PyArray_DIMS(in[i])[nd - 1] != RT_WIDTH(i)) goto slow;
        if (PyArray_SIZE(in[i]) / RT_WIDTH(i) > PyArray_SIZE(in[base]) / RT_WIDTH(base))
            base = i;
    }
    npy_intp count = PyArray_SIZE(in[base]) / RT_WIDTH(base);
    int nd = PyArray_NDIM(in[base]);
    for (int i = 0; i < nin; i++) {
        if (PyArray_SIZE(in[i]) == RT_WIDTH(i) && PyArray_NDIM(in[i]) == 1) {
            step[i] = count > 1 ? 0 : RT_WIDTH(i);
            continue;
        }
        if (PyArray_NDIM(in[i]) != nd  /* the batch axes, all but the last */
            || memcmp(PyArray_DIMS(in[i]), PyArray_DIMS(in[base]), (nd - 1) * sizeof(npy_intp)))
            goto slow;
        step[i] = RT_WIDTH(i);
    }
#if RT_FLOATING
    if (!lg_unit_quaternions((const double *)PyArray_DATA(in[0]), step[0] ? count : 1, step[0],
                             RT_NQ, RT_QUATERNION_TOLERANCE)) {
        PyErr_Clear();  /* the front names the state and its norm */
        goto slow;
    }
#endif
    P = lg_doubles(args[nin], LG_NP, "parameters");
    if (!P) goto done;
    npy_intp dims[NPY_MAXDIMS];
    memcpy(dims, PyArray_DIMS(in[base]), (nd - 1) * sizeof(npy_intp));
    int od = nd - 1;
    if (kind == RT_MASS) { dims[od++] = LG_N; dims[od++] = LG_N; }
    else if (kind != RT_KINETIC && kind != RT_POTENTIAL) dims[od++] = LG_N;
    out = lg_output(od, dims);
    if (!out) goto done;
    const double *x0 = (const double *)PyArray_DATA(in[0]);
    const double *x1 = nin > 1 ? (const double *)PyArray_DATA(in[1]) : NULL;
    const double *x2 = nin > 2 ? (const double *)PyArray_DATA(in[2]) : NULL;
    const double *p = (const double *)PyArray_DATA(P);
    double *y = (double *)PyArray_DATA((PyArrayObject *)out);
    const int size = kind == RT_MASS ? LG_N * LG_N
                     : (kind == RT_KINETIC || kind == RT_POTENTIAL) ? 1 : LG_N;
    rt_job jobs[RT_MAX_THREADS];
    int parts = rt_threads(count);
    npy_intp next = 0;
    for (int t = 0; t < parts; t++) {
        rt_job job = {kind, nin, size, (size_t)count * size * sizeof(double) >= LG_STREAM_MIN,
                      {step[0], step[1], step[2]}, x0, x1, x2, p, y, count, 0, &next};
        jobs[t] = job;
    }
    npy_intp bad = 0;
    NPY_BEGIN_THREADS_DEF;
    if (count > 16) NPY_BEGIN_THREADS;
    /* the batch on threads of their own (the functions keep no state), this thread one of
       them; a thread that cannot start leaves its blocks to the others */
#if RT_PTHREADS
    lg_run_batch(rt_run, jobs, sizeof jobs[0], parts);
#else
    for (int t = 0; t < parts; t++) rt_run(&jobs[t]);
#endif
    for (int t = 0; t < parts; t++) bad += jobs[t].bad;
    if (count > 16) NPY_END_THREADS;
    if (bad > 0) {
        PyObject *pair = Py_BuildValue("(Nn)", out, (Py_ssize_t)bad);
        out = pair;  /* the pair owns the array (N), or NULL with the error set */
    }
done:
    for (int i = 0; i < 3; i++) Py_XDECREF(in[i]);
    Py_XDECREF(P);
    return out;
slow:  /* not the fast path's inputs: the Python front checks and shapes them */
    for (int i = 0; i < 3; i++) Py_XDECREF(in[i]);
    Py_RETURN_NOTIMPLEMENTED;
}

#define RT_WRAP(name, nin, kind) \
    static PyObject *rt_py_##name(PyObject *self, PyObject *const *args, Py_ssize_t nargs) \
    { (void)self; return rt_batch(args, nargs, nin, kind); }
RT_WRAP(mass_matrix, 1, RT_MASS)
RT_WRAP(bias_forces, 2, RT_BIAS)
RT_WRAP(gravity, 1, RT_GRAVITY)
RT_WRAP(inverse_dynamics, 3, RT_INVERSE)
RT_WRAP(forward_dynamics, 3, RT_FORWARD)
RT_WRAP(kinetic_energy, 2, RT_KINETIC)
RT_WRAP(potential_energy, 1, RT_POTENTIAL)
