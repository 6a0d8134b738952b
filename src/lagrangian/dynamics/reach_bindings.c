/* Python bindings of reach_kernel.c and reach_coriolis.c: arrays (..., n) of float64, one
 * output row per state. A batch runs on threads that take blocks of RK_BLOCK states from a
 * shared counter (as the tree module's batches), LG_LANES states at a time through the rk4_
 * functions (the same formulas on vector lanes), the block's last few one by one.
 *
 * A state whose inputs (q, v, a, its wrenches) are not all finite gets a row of NaN, as the
 * tree module's functions give (a NaN in one leg would otherwise leave the other legs' numbers
 * finite); where there are such rows a function returns (output, their count), for the
 * caller's one DynamicsWarning, else its output alone. */

#define RK_PTHREADS LG_PTHREADS  /* batch_threads.c, above this text */
#define RK_MAX_THREADS LG_MAX_THREADS
#define RK_THREAD_STATES 1024  /* fewer per thread: starting it costs more than it saves (A_g
                                  on the Panda, 1000 states: 43 us on one thread, 70 on two) */
#define RK_BLOCK 64  /* a multiple of LG_LANES: only the batch's last states run one by one */

enum { RK_DRIFT, RK_CENTROIDAL, RK_WRENCH, RK_CORIOLIS, RK_INVERSE, RK_PLACEMENT, RK_JACOBIAN,
       RK_COM, RK_COM_JACOBIAN };

/* one batch's inputs and output; ``next`` the shared counter of states handed out */
typedef struct {
    int kind, frame, ref, nw, stream;  /* stream: rows stored past the caches (lg_rows_streamed) */
    const double *q, *v, *a, *up;
    const int *frames;
    const double *const *w;
    const int *wshared;
    double sign, *y;
    npy_intp count, *next, bad;  /* bad: the NaN rows this job (thread) wrote */
} rk_job;

/* the numbers of a state's output row */
static int rk_width(int kind)
{
    return kind == RK_DRIFT ? 6 : kind == RK_CENTROIDAL || kind == RK_JACOBIAN ? 6 * RK_NV
           : kind == RK_CORIOLIS ? RK_NV * RK_NV : kind == RK_PLACEMENT ? 16
           : kind == RK_COM ? 3 : kind == RK_COM_JACOBIAN ? 3 * RK_NV : RK_NV;
}

static void rk_blank(const rk_job *job, npy_intp k)
{
    const int width = rk_width(job->kind);
    for (int i = 0; i < width; i++) job->y[k * width + i] = NAN;
}

/* whether x[0..width) are all finite: none with every exponent bit set, by an integer OR the
 * compiler vectorizes (a sum of x - x chains one addition after another: 60 ns of the 0.8 us
 * of a single ID with a wrench on Solo12) */
static int rk_finite_row(const double *x, int width)
{
    const unsigned long long exponent = 0x7ff0000000000000ULL;
    unsigned long long spoilt = 0;
    for (int i = 0; i < width; i++) {
        unsigned long long bits;
        __builtin_memcpy(&bits, x + i, sizeof bits);
        spoilt |= (bits & exponent) == exponent;
    }
    return !spoilt;
}

/* whether state k's inputs are all finite (and, adding wrenches, its row after the sum) */
static int rk_finite(const rk_job *job, npy_intp k)
{
    const int kind = job->kind;
    int fine = rk_finite_row(job->q + k * RK_NQ, RK_NQ);
    if (kind == RK_DRIFT || kind == RK_CORIOLIS || kind == RK_INVERSE)
        fine &= rk_finite_row(job->v + k * RK_NV, RK_NV);
    if (kind == RK_INVERSE) fine &= rk_finite_row(job->a + k * RK_NV, RK_NV);
    const int nw = kind == RK_WRENCH ? 1 : kind == RK_INVERSE ? job->nw : 0;
    for (int i = 0; i < nw; i++) fine &= rk_finite_row(job->w[i] + (job->wshared[i] ? 0 : 6 * k), 6);
    return fine;
}

/* state k alone; 1 where its row came out NaN */
static int rk_state(const rk_job *job, npy_intp k, rk_cwork *work)
{
    const double *q = job->q + k * RK_NQ;
    if (!rk_finite(job, k)) {
        rk_blank(job, k);
        return 1;
    }
    switch (job->kind) {
    case RK_DRIFT: rk_drift(q, job->v + k * RK_NV, job->frame, job->ref, job->y + 6 * k); break;
    case RK_CENTROIDAL: rk_centroidal(q, job->y + 6 * RK_NV * k); break;
    case RK_WRENCH: {
        double tau[RK_NV], *y = job->y + RK_NV * k;
        rk_wrench(q, job->frame, job->w[0] + (job->wshared[0] ? 0 : 6 * k), tau);
        for (int j = 0; j < RK_NV; j++) y[j] += job->sign * tau[j];
        break;
    }
    case RK_CORIOLIS: rk_coriolis(q, job->v + k * RK_NV, job->y + RK_NV * RK_NV * k, work); break;
    case RK_PLACEMENT: rk_placement(q, job->frame, job->y + 16 * k); break;
    case RK_JACOBIAN: rk_jacobian(q, job->frame, job->ref, job->y + 6 * RK_NV * k); break;
    case RK_COM: rk_com(q, job->y + 3 * k); break;
    case RK_COM_JACOBIAN: rk_com_jacobian(q, job->y + 3 * RK_NV * k); break;
    case RK_INVERSE: {
        double w[RK_MAX_WRENCHES][6];
        for (int i = 0; i < job->nw; i++)
            for (int j = 0; j < 6; j++) w[i][j] = job->w[i][(job->wshared[i] ? 0 : 6 * k) + j];
        rk_inverse(q, job->v + k * RK_NV, job->a + k * RK_NV, job->up, job->nw, job->frames,
                   (const double (*)[6])w, job->y + RK_NV * k);
        break;
    }
    }
    /* a row that was NaN before the wrench's forces were added (the caller's inverse dynamics
       of a state not finite) stays NaN whole */
    if (job->kind == RK_WRENCH && !rk_finite_row(job->y + RK_NV * k, RK_NV)) {
        rk_blank(job, k);
        return 1;
    }
    return 0;
}

/* lanes' inputs: rows k .. k + LG_LANES - 1 of x (``width`` numbers a row) as vectors */
static inline void rk_gather(const double *x, npy_intp k, int width, lg_v4 *out)
{
    lg_lanes(x + k * width, width, out);
}

/* lanes' outputs into rows k .. k + LG_LANES - 1 of y (``width`` numbers a row): y = x
 * (past the caches where ``stream``), or y += sign x where ``add`` */
static inline void rk_scatter(const lg_v4 *x, npy_intp k, int width, double *y, int add,
                              double sign, int stream)
{
    if (!add) {
        if (stream) lg_rows_streamed(x, width, y + k * width);
        else lg_rows(x, width, y + k * width);
        return;
    }
    for (int l = 0; l < LG_LANES; l++) {
        double *row = y + (k + l) * width;
        for (int i = 0; i < width; i++) row[i] += sign * x[i][l];
    }
}

/* x - x summed over an input's vectors: 0 in the lanes where it is finite (two sums, so that
   the additions do not wait one for another) */
static inline void rk_spoil(const lg_v4 *x, int width, lg_v4 *spoilt)
{
    lg_v4 odd = LG_V4(0.0);
    int i = 0;
    for (; i + 1 < width; i += 2) {
        *spoilt += x[i] - x[i];
        odd += x[i + 1] - x[i + 1];
    }
    if (i < width) odd += x[i] - x[i];
    *spoilt += odd;
}

/* states k .. k + LG_LANES - 1 at once (rk4_*); out: RK_OUT4 vectors of room; the count of
   NaN rows written */
#define RK_OUT4 (RK_NV * RK_NV > 6 * RK_NV ? RK_NV * RK_NV : 6 * RK_NV > 16 ? 6 * RK_NV : 16)
static int rk_lanes(const rk_job *job, npy_intp k, rk4_cwork *work, lg_v4 *out)
{
    lg_v4 q[RK_NQ], v[RK_NV], spoilt = LG_V4(0.0);
    rk_gather(job->q, k, RK_NQ, q);
    rk_spoil(q, RK_NQ, &spoilt);
    if (k + 2 * LG_LANES <= job->count) {  /* the next states' q and v, fetched meanwhile: a
                                              load of this group's was a sixth of C's time */
        const char *next = (const char *)(job->q + (k + LG_LANES) * RK_NQ);
        for (size_t b = 0; b < LG_LANES * RK_NQ * sizeof(double); b += 64)
            __builtin_prefetch(next + b, 0, 3);
        if (job->v && job->kind != RK_CENTROIDAL && job->kind != RK_WRENCH) {
            next = (const char *)(job->v + (k + LG_LANES) * RK_NV);
            for (size_t b = 0; b < LG_LANES * RK_NV * sizeof(double); b += 64)
                __builtin_prefetch(next + b, 0, 3);
        }
    }
    if (!job->stream) {  /* the rows these states will fill, fetched for writing while the
                            kernel computes (as the derivatives module's): a batch's outputs are
                            seldom in cache */
        const int width = rk_width(job->kind);
        const char *y = (const char *)(job->y + k * width);
        for (size_t b = 0; b < LG_LANES * width * sizeof(double); b += 64)
            __builtin_prefetch(y + b, 1, 2);
    }
    switch (job->kind) {
    case RK_DRIFT:
        rk_gather(job->v, k, RK_NV, v);
        rk_spoil(v, RK_NV, &spoilt);
        rk4_drift(q, v, job->frame, job->ref, out);
        rk_scatter(out, k, 6, job->y, 0, 0.0, job->stream);
        break;
    case RK_CENTROIDAL:
        rk4_centroidal(q, out);
        rk_scatter(out, k, 6 * RK_NV, job->y, 0, 0.0, job->stream);
        break;
    case RK_PLACEMENT:
        rk4_placement(q, job->frame, out);
        rk_scatter(out, k, 16, job->y, 0, 0.0, job->stream);
        break;
    case RK_JACOBIAN:
        rk4_jacobian(q, job->frame, job->ref, out);
        rk_scatter(out, k, 6 * RK_NV, job->y, 0, 0.0, job->stream);
        break;
    case RK_COM:
        rk4_com(q, out);
        rk_scatter(out, k, 3, job->y, 0, 0.0, job->stream);
        break;
    case RK_COM_JACOBIAN:
        rk4_com_jacobian(q, out);
        rk_scatter(out, k, 3 * RK_NV, job->y, 0, 0.0, job->stream);
        break;
    case RK_WRENCH: {
        lg_v4 w[6];
        if (job->wshared[0])
            for (int j = 0; j < 6; j++) w[j] = LG_V4(job->w[0][j]);
        else
            rk_gather(job->w[0], k, 6, w);
        rk_spoil(w, 6, &spoilt);
        rk4_wrench(q, job->frame, w, out);
        rk_scatter(out, k, RK_NV, job->y, 1, job->sign, job->stream);
        break;
    }
    case RK_CORIOLIS:
        rk_gather(job->v, k, RK_NV, v);
        rk_spoil(v, RK_NV, &spoilt);
        rk4_coriolis(q, v, out, work);
        rk_scatter(out, k, RK_NV * RK_NV, job->y, 0, 0.0, job->stream);
        break;
    case RK_INVERSE: {
        lg_v4 a[RK_NV], w[RK_MAX_WRENCHES][6];
        rk_gather(job->v, k, RK_NV, v);
        rk_gather(job->a, k, RK_NV, a);
        rk_spoil(v, RK_NV, &spoilt);
        rk_spoil(a, RK_NV, &spoilt);
        for (int i = 0; i < job->nw; i++) {
            if (job->wshared[i])
                for (int j = 0; j < 6; j++) w[i][j] = LG_V4(job->w[i][j]);
            else
                rk_gather(job->w[i], k, 6, w[i]);
            rk_spoil(w[i], 6, &spoilt);
        }
        rk4_inverse(q, v, a, job->up, job->nw, job->frames, (const lg_v4 (*)[6])w, out);
        rk_scatter(out, k, RK_NV, job->y, 0, 0.0, job->stream);
        break;
    }
    }
    int bad = 0;
    for (int l = 0; l < LG_LANES; l++)
        if (spoilt[l] != 0.0 || (job->kind == RK_WRENCH
                                 && !rk_finite_row(job->y + RK_NV * (k + l), RK_NV))) {
            rk_blank(job, k + l);
            bad++;
        }
    return bad;
}

/* a thread's work: blocks of RK_BLOCK states taken in turn until none is left, so that a
 * thread slowed by the machine's other work takes fewer rather than holding the others up */
static void *rk_run(void *argument)
{
    rk_job *job = (rk_job *)argument;
    rk_cwork *work = NULL;
    rk4_cwork *work4 = NULL;
    /* the lanes' outputs and C's workspace (vectors: aligned to theirs) */
    const size_t room = (RK_OUT4 * sizeof(lg_v4) + 63) / 64 * 64;
    const size_t space = job->kind == RK_CORIOLIS ? (sizeof(rk4_cwork) + 63) / 64 * 64 : 0;
    lg_v4 *out = job->count >= LG_LANES ? aligned_alloc(64, room + space) : NULL;
    job->bad = 0;
    if (out && space) work4 = (rk4_cwork *)((char *)out + room);
    if (job->kind == RK_CORIOLIS && !(work = malloc(sizeof(rk_cwork)))) {
        free(out);
        return NULL;
    }
    for (;;) {
#if RK_PTHREADS
        const npy_intp k0 = __atomic_fetch_add(job->next, RK_BLOCK, __ATOMIC_RELAXED);
#else
        const npy_intp k0 = *job->next;
        *job->next += RK_BLOCK;
#endif
        if (k0 >= job->count) break;
        const npy_intp k1 = k0 + RK_BLOCK < job->count ? k0 + RK_BLOCK : job->count;
        npy_intp k = k0;
        for (; out && k + LG_LANES <= k1; k += LG_LANES) job->bad += rk_lanes(job, k, work4, out);
        for (; k < k1; k++) job->bad += rk_state(job, k, work);
    }
    free(work);
    free(out);
    if (job->stream) lg_stream_fence();
    return NULL;
}

/* how many threads a batch of ``count`` states runs on (batch_threads.c) */
static int rk_threads(npy_intp count) { return lg_threads(count, RK_THREAD_STATES); }

/* the batch over threads, without the GIL; 0 with MemoryError set where a workspace failed */
static int rk_batch(rk_job *job)
{
    npy_intp next = 0;
    job->next = &next;
    job->stream = job->kind != RK_WRENCH
                  && (size_t)job->count * rk_width(job->kind) * sizeof(double) >= LG_STREAM_MIN;
    int parts = rk_threads(job->count);
    rk_job jobs[RK_MAX_THREADS];
    for (int t = 0; t < parts; t++) jobs[t] = *job;
    NPY_BEGIN_THREADS_DEF;
    if (job->count > 16) NPY_BEGIN_THREADS;
#if RK_PTHREADS
    lg_run_batch(rk_run, jobs, sizeof jobs[0], parts);
#else
    rk_run(&jobs[0]);
#endif
    if (job->count > 16) NPY_END_THREADS;
    job->bad = 0;
    for (int t = 0; t < parts; t++) job->bad += jobs[t].bad;
    /* a thread without its workspace took no block: the others took them, unless none ran */
    if (next < job->count) { PyErr_NoMemory(); return 0; }
    return 1;
}

static PyArrayObject *rk_input(PyObject *x, int last, const char *name)
{
    PyArrayObject *a;
    if (PyArray_CheckExact(x) && PyArray_TYPE((PyArrayObject *)x) == NPY_DOUBLE
            && PyArray_IS_C_CONTIGUOUS((PyArrayObject *)x) && PyArray_ISALIGNED((PyArrayObject *)x)
            && PyArray_NDIM((PyArrayObject *)x) >= 1) {
        a = (PyArrayObject *)x;  /* the usual case: taken as it is, no conversion */
        Py_INCREF(a);
    } else {
        a = (PyArrayObject *)PyArray_FROMANY(x, NPY_DOUBLE, 1, 0, NPY_ARRAY_IN_ARRAY);
    }
    if (!a) return NULL;
    int nd = PyArray_NDIM(a);
    if (PyArray_DIMS(a)[nd - 1] != last) {
        PyErr_Format(PyExc_ValueError, "%s: expected %d values along the last axis", name, last);
        Py_DECREF(a);
        return NULL;
    }
    return a;
}

/* a floating base's quaternions (entries 3..6 of each state) of norm within the tolerance (or
 * not finite: that row's NaN is the caller's); else ValueError, and numpy names the state */
static int rk_unit_quaternions(PyArrayObject *Q)
{
#if RK_FB
    npy_intp count = PyArray_SIZE(Q) / RK_NQ;
    const double *q = PyArray_DATA(Q);
    for (npy_intp k = 0; k < count; k++, q += RK_NQ) {
        double n2 = q[3] * q[3] + q[4] * q[4] + q[5] * q[5] + q[6] * q[6];
        if (rk_finite_row(q + 3, 4) && (n2 < RK_QLOW || n2 > RK_QHIGH)) {
            PyErr_SetString(PyExc_ValueError, "q: the base quaternion is not of unit norm");
            return 0;
        }
    }
#else
    (void)Q;
#endif
    return 1;
}

static PyObject *rk_output(PyArrayObject *like, int tail0, int tail1)
{
    npy_intp dims[NPY_MAXDIMS];
    int nd = PyArray_NDIM(like) - 1;
    for (int k = 0; k < nd; k++) dims[k] = PyArray_DIMS(like)[k];
    dims[nd++] = tail0;
    if (tail1) dims[nd++] = tail1;
    return lg_output(nd, dims);
}

/* the output where every row is defined, else (output, count of NaN rows); NULL with the
 * output's error (a tuple only then: building it cost a single call a fifth of its time) */
static PyObject *rk_result(PyObject *out, npy_intp bad)
{
    if (!out || !bad) return out;
    return Py_BuildValue("(Nn)", out, (Py_ssize_t)bad);
}

static int rk_same_batch(PyArrayObject *a, PyArrayObject *b, const char *name)
{
    int nd = PyArray_NDIM(a);
    if (PyArray_NDIM(b) != nd) goto bad;
    for (int k = 0; k < nd - 1; k++)
        if (PyArray_DIMS(a)[k] != PyArray_DIMS(b)[k]) goto bad;
    return 1;
bad:
    PyErr_Format(PyExc_ValueError, "%s: batch shapes differ", name);
    return 0;
}

/* a frame named by the kernel's dict {name: frame number} (the bound functions' self); -1
 * with KeyError (TypeError for a name not hashable) where there is none */
static int rk_frame_named(PyObject *index, PyObject *name)
{
    PyObject *number = PyDict_GetItemWithError(index, name);
    if (!number) {
        if (!PyErr_Occurred()) PyErr_SetObject(PyExc_KeyError, name);
        return -1;
    }
    const long f = PyLong_AsLong(number);
    if (f == -1 && PyErr_Occurred()) return -1;
    if (f < 0 || f >= RK_NF) { PyErr_SetString(PyExc_ValueError, "frame: out of range"); return -1; }
    return (int)f;
}

/* Pinocchio's ReferenceFrame by name: 0 world, 1 local, 2 local_world_aligned; -1 with
 * KeyError else. The names interned at import (rk_references): Python's literals are the same
 * objects, found by their address before any comparison of text */
static PyObject *rk_references[3];

static int rk_reference_named(PyObject *name)
{
    for (int k = 0; k < 3; k++)
        if (name == rk_references[k]) return k;
    if (PyUnicode_Check(name))
        for (int k = 0; k < 3; k++)
            if (PyUnicode_Compare(name, rk_references[k]) == 0) return k;
    if (!PyErr_Occurred()) PyErr_SetObject(PyExc_KeyError, name);
    return -1;
}

/* drift(Q, V, frame, reference) bound to the frames' dict -> [a; w_dot] (or with NaN rows) */
static PyObject *rk_py_drift(PyObject *index, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 4) { PyErr_SetString(PyExc_TypeError, "drift(Q, V, frame, reference)"); return NULL; }
    const int f = rk_frame_named(index, args[2]);
    if (f < 0) return NULL;
    const int ref = rk_reference_named(args[3]);
    if (ref < 0) return NULL;
    PyArrayObject *Q = rk_input(args[0], RK_NQ, "q");
    if (!Q) return NULL;
    if (!rk_unit_quaternions(Q)) { Py_DECREF(Q); return NULL; }
    PyArrayObject *V = rk_input(args[1], RK_NV, "v");
    if (!V || !rk_same_batch(Q, V, "v")) { Py_DECREF(Q); Py_XDECREF(V); return NULL; }
    PyObject *out = rk_output(Q, 6, 0);
    npy_intp bad = 0;
    if (out) {
        rk_job job = {.kind = RK_DRIFT, .frame = f, .ref = ref, .q = PyArray_DATA(Q),
                      .v = PyArray_DATA(V), .y = PyArray_DATA((PyArrayObject *)out),
                      .count = PyArray_SIZE(Q) / RK_NQ};
        if (!rk_batch(&job)) Py_CLEAR(out);
        bad = job.bad;
    }
    Py_DECREF(Q); Py_DECREF(V);
    return rk_result(out, bad);
}

/* a function of q alone on Q (frame f, reference ref where it has them) -> its rows (tail0 x
 * tail1 a state), or (rows, NaN rows). One state is computed here, without the batch's
 * machinery. */
static PyObject *rk_of_q(PyObject *Q_in, int kind, int f, int ref, int tail0, int tail1)
{
    PyArrayObject *Q = rk_input(Q_in, RK_NQ, "q");
    if (!Q) return NULL;
    if (!rk_unit_quaternions(Q)) { Py_DECREF(Q); return NULL; }
    PyObject *out = rk_output(Q, tail0, tail1);
    npy_intp bad = 0;
    if (out) {
        rk_job job = {.kind = kind, .frame = f, .ref = ref, .q = PyArray_DATA(Q),
                      .y = PyArray_DATA((PyArrayObject *)out), .count = PyArray_SIZE(Q) / RK_NQ};
        if (job.count == 1) bad = rk_state(&job, 0, NULL);
        else if (!rk_batch(&job)) Py_CLEAR(out);
        else bad = job.bad;
    }
    Py_DECREF(Q);
    return rk_result(out, bad);
}

/* placement(Q, frame) and jacobian(Q, frame, reference), bound to the frames' dict: the name
 * looked up here, not in Python (two dict lookups and an attribute there were a sixth of a
 * single Jacobian's call) */
static PyObject *rk_py_placement(PyObject *index, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 2) { PyErr_SetString(PyExc_TypeError, "placement(Q, frame)"); return NULL; }
    const int f = rk_frame_named(index, args[1]);
    return f < 0 ? NULL : rk_of_q(args[0], RK_PLACEMENT, f, 0, 4, 4);
}

static PyObject *rk_py_jacobian(PyObject *index, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 3) { PyErr_SetString(PyExc_TypeError, "jacobian(Q, frame, reference)"); return NULL; }
    const int f = rk_frame_named(index, args[1]);
    if (f < 0) return NULL;
    const int ref = rk_reference_named(args[2]);
    return ref < 0 ? NULL : rk_of_q(args[0], RK_JACOBIAN, f, ref, 6, RK_NV);
}

/* the functions of q alone, each rk_of_q with its kind and a state's output shape */
#define RK_OF_Q(name, kind, tail0, tail1)                                                      \
    static PyObject *rk_py_##name(PyObject *self, PyObject *const *args, Py_ssize_t nargs)    \
    {                                                                                          \
        (void)self;                                                                            \
        if (nargs != 1) { PyErr_SetString(PyExc_TypeError, #name "(Q)"); return NULL; }       \
        return rk_of_q(args[0], kind, 0, 0, tail0, tail1);                                     \
    }
RK_OF_Q(com, RK_COM, 3, 0)
RK_OF_Q(com_jacobian, RK_COM_JACOBIAN, 3, RK_NV)
RK_OF_Q(centroidal, RK_CENTROIDAL, 6, RK_NV)

static PyMethodDef rk_frame_methods[] = {
    {"placement", (PyCFunction)(void (*)(void))rk_py_placement, METH_FASTCALL, "(Q, frame) -> 4 x 4, or (4 x 4, NaN rows)"},
    {"jacobian", (PyCFunction)(void (*)(void))rk_py_jacobian, METH_FASTCALL, "(Q, frame, reference) -> 6 x n, or (6 x n, NaN rows)"},
    {"drift", (PyCFunction)(void (*)(void))rk_py_drift, METH_FASTCALL, "(Q, V, frame, reference) -> [a; w_dot], or ([a; w_dot], NaN rows)"},
};

/* frames(INDEX) -> (placement, jacobian, drift) bound to INDEX, a dict {frame name: frame
 * number} (a built-in function's self: called as fast as the module's own) */
static PyObject *rk_py_frames(PyObject *self, PyObject *index)
{
    (void)self;
    if (!PyDict_Check(index)) { PyErr_SetString(PyExc_TypeError, "frames(INDEX): a dict"); return NULL; }
    PyObject *out = PyTuple_New(3);
    if (!out) return NULL;
    for (int k = 0; k < 3; k++) {
        PyObject *bound = PyCFunction_NewEx(&rk_frame_methods[k], index, NULL);
        if (!bound) { Py_DECREF(out); return NULL; }
        PyTuple_SET_ITEM(out, k, bound);
    }
    return out;
}

/* wrench(Q, frame, W, OUT, sign): OUT += sign J^T w, in place (OUT float64, contiguous, of
 * Q's batch and RK_NV wide); W (6,) for every state or one row per state */
static PyObject *rk_py_wrench(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 5) { PyErr_SetString(PyExc_TypeError, "wrench(Q, frame, W, OUT, sign)"); return NULL; }
    int f = (int)PyLong_AsLong(args[1]);
    double sign = PyFloat_AsDouble(args[4]);
    if (PyErr_Occurred()) return NULL;
    if (f < 0 || f >= RK_NF) { PyErr_SetString(PyExc_ValueError, "frame: out of range"); return NULL; }
    if (!PyArray_Check(args[3])) { PyErr_SetString(PyExc_ValueError, "out: not an array"); return NULL; }
    PyArrayObject *out = (PyArrayObject *)args[3];
    PyArrayObject *Q = rk_input(args[0], RK_NQ, "q");
    if (!Q) return NULL;
    if (!rk_unit_quaternions(Q)) { Py_DECREF(Q); return NULL; }
    PyArrayObject *W = rk_input(args[2], 6, "f_ext");
    if (!W) { Py_DECREF(Q); return NULL; }
    int shared = PyArray_NDIM(W) == 1;
    if ((!shared && !rk_same_batch(Q, W, "f_ext"))
            || PyArray_TYPE(out) != NPY_DOUBLE || !PyArray_ISCARRAY(out)
            || PyArray_NDIM(out) != PyArray_NDIM(Q)
            || !PyArray_CompareLists(PyArray_DIMS(out), PyArray_DIMS(Q), PyArray_NDIM(Q) - 1)
            || PyArray_DIMS(out)[PyArray_NDIM(Q) - 1] != RK_NV) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "out: not of q's batch, nv wide");
        Py_DECREF(Q); Py_DECREF(W);
        return NULL;
    }
    const double *w = PyArray_DATA(W);
    rk_job job = {.kind = RK_WRENCH, .frame = f, .q = PyArray_DATA(Q), .w = &w,
                  .wshared = &shared, .sign = sign, .y = PyArray_DATA(out),
                  .count = PyArray_SIZE(Q) / RK_NQ};
    int fine = rk_batch(&job);
    Py_DECREF(Q); Py_DECREF(W);
    if (!fine) return NULL;
    return PyLong_FromSsize_t((Py_ssize_t)job.bad);
}

static PyObject *rk_py_coriolis(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 2) { PyErr_SetString(PyExc_TypeError, "coriolis(Q, V)"); return NULL; }
    PyArrayObject *Q = rk_input(args[0], RK_NQ, "q");
    if (!Q) return NULL;
    if (!rk_unit_quaternions(Q)) { Py_DECREF(Q); return NULL; }
    PyArrayObject *V = rk_input(args[1], RK_NV, "v");
    if (!V || !rk_same_batch(Q, V, "v")) { Py_DECREF(Q); Py_XDECREF(V); return NULL; }
    PyObject *out = rk_output(Q, RK_NV, RK_NV);
    npy_intp bad = 0;
    if (out) {
        rk_job job = {.kind = RK_CORIOLIS, .q = PyArray_DATA(Q), .v = PyArray_DATA(V),
                      .y = PyArray_DATA((PyArrayObject *)out), .count = PyArray_SIZE(Q) / RK_NQ};
        if (!rk_batch(&job)) Py_CLEAR(out);
        bad = job.bad;
    }
    Py_DECREF(Q); Py_DECREF(V);
    return rk_result(out, bad);
}

/* inverse(INDEX, UP, Q, V, A, F_EXT) -> tau: inverse dynamics less the wrenches of the dict
 * F_EXT (frame name -> W, INDEX: frame name -> frame number) in one pass (reach_inverse.c); UP
 * the ground's acceleration (3,), each W (6,) for every state or one row per state. KeyError or
 * ValueError where an input is not plain (the caller's numpy path names it). */
static PyObject *rk_py_inverse(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 6 || !PyDict_Check(args[0]) || !PyDict_Check(args[5])) {
        PyErr_SetString(PyExc_TypeError, "inverse(INDEX, UP, Q, V, A, F_EXT)");
        return NULL;
    }
    Py_ssize_t nw = PyDict_Size(args[5]);
    if (nw > RK_MAX_WRENCHES) { PyErr_SetString(PyExc_ValueError, "f_ext: too many"); return NULL; }
    PyArrayObject *in[3] = {NULL, NULL, NULL}, *U = NULL, *W[RK_MAX_WRENCHES] = {NULL};
    PyObject *out = NULL, *name, *value;
    npy_intp bad = 0;
    int frames[RK_MAX_WRENCHES], shared[RK_MAX_WRENCHES];
    const double *w[RK_MAX_WRENCHES];
    const char *names[3] = {"q", "v", "a"};
    for (int j = 0; j < 3; j++) {
        in[j] = rk_input(args[2 + j], j == 0 ? RK_NQ : RK_NV, names[j]);
        if (!in[j] || (j && !rk_same_batch(in[0], in[j], names[j]))) goto done;
    }
    if (!rk_unit_quaternions(in[0])) goto done;
    U = rk_input(args[1], 3, "up");
    if (!U) goto done;
    Py_ssize_t at = 0, k = 0;
    while (PyDict_Next(args[5], &at, &name, &value)) {
        PyObject *number = PyDict_GetItemWithError(args[0], name);
        if (!number) {
            if (!PyErr_Occurred()) PyErr_SetObject(PyExc_KeyError, name);
            goto done;
        }
        frames[k] = (int)PyLong_AsLong(number);
        if (PyErr_Occurred()) goto done;
        if (frames[k] < 0 || frames[k] >= RK_NF) {
            PyErr_SetString(PyExc_ValueError, "frame: out of range");
            goto done;
        }
        W[k] = rk_input(value, 6, "f_ext");
        if (!W[k]) goto done;
        shared[k] = PyArray_NDIM(W[k]) == 1;
        if (!shared[k] && !rk_same_batch(in[0], W[k], "f_ext")) goto done;
        w[k] = PyArray_DATA(W[k]);
        k++;
    }
    out = rk_output(in[0], RK_NV, 0);
    if (out) {
        rk_job job = {.kind = RK_INVERSE, .nw = (int)nw, .q = PyArray_DATA(in[0]),
                      .v = PyArray_DATA(in[1]), .a = PyArray_DATA(in[2]), .up = PyArray_DATA(U),
                      .frames = frames, .w = w, .wshared = shared,
                      .y = PyArray_DATA((PyArrayObject *)out), .count = PyArray_SIZE(in[0]) / RK_NQ};
        if (!rk_batch(&job)) Py_CLEAR(out);
        bad = job.bad;
    }
done:
    for (int j = 0; j < 3; j++) Py_XDECREF(in[j]);
    Py_XDECREF(U);
    for (Py_ssize_t j = 0; j < nw; j++) Py_XDECREF(W[j]);
    return rk_result(out, bad);
}

static PyMethodDef rk_methods[] = {
    {"frames", (PyCFunction)rk_py_frames, METH_O, "(INDEX) -> (placement, jacobian, drift) bound to INDEX {frame name: number}"},
    {"centroidal", (PyCFunction)(void (*)(void))rk_py_centroidal, METH_FASTCALL, "(Q) -> A_g, or (A_g, NaN rows)"},
    {"wrench", (PyCFunction)(void (*)(void))rk_py_wrench, METH_FASTCALL, "(Q, frame, W, OUT, sign): OUT += sign J^T w; -> NaN rows"},
    {"coriolis", (PyCFunction)(void (*)(void))rk_py_coriolis, METH_FASTCALL, "(Q, V) -> C(q, v), or (C(q, v), NaN rows)"},
    {"inverse", (PyCFunction)(void (*)(void))rk_py_inverse, METH_FASTCALL, "(INDEX, UP, Q, V, A, F_EXT) -> tau, or (tau, NaN rows)"},
    {"com", (PyCFunction)(void (*)(void))rk_py_com, METH_FASTCALL, "(Q) -> c, or (c, NaN rows)"},
    {"com_jacobian", (PyCFunction)(void (*)(void))rk_py_com_jacobian, METH_FASTCALL, "(Q) -> J_c, or (J_c, NaN rows)"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef rk_module = {PyModuleDef_HEAD_INIT, RK_STR(LG_MODULE), NULL, -1, rk_methods};

PyMODINIT_FUNC RK_PASTE(PyInit_, LG_MODULE)(void)
{
    import_array();
    const char *references[3] = {"world", "local", "local_world_aligned"};
    for (int k = 0; k < 3; k++)
        if (!rk_references[k] && !(rk_references[k] = PyUnicode_InternFromString(references[k])))
            return NULL;
    return PyModule_Create(&rk_module);
}
