/* ---- batched bindings: f(Q[, V[, X]], P), each input (..., n) or (n,), P = prepare(D) ----
   Inputs that are not already float64 C-ordered arrays of the tree's widths, with one batch
   shape and unit base quaternions, give NotImplemented: the Python front checks them. 
   (a floating base: Q (..., nq), the others and the outputs nv wide: tree_kernel.c)
   As tree_bindings.c: a state whose inputs are not all finite, or (forward dynamics) without
   a finite result, gives NaN in its own row and is counted; with none such the output array
   is returned, else (output, count). Batches run on threads. */
enum { TK_MASSM, TK_BIAS, TK_GRAVITY, TK_INVERSE, TK_FORWARD, TK_KINETIC, TK_POTENTIAL };
#define TK_PTHREADS LG_PTHREADS  /* batch_threads.c, before this text */
#define TK_MAX_THREADS LG_MAX_THREADS
#define TK_THREAD_WORK 8192  /* body-states (about 1 ms) per thread before another starts */

typedef struct {
    const tk_tree *tree;
    int kind, nin, size;
    npy_intp step[3];
    const double *x[3];
    double *y;
    npy_intp k0, k1, bad;
    int failed;
} tk_job;

/* Forward dynamics by M's factor, M = L D L^T with the bias from one RNEA, rather than the
   articulated-body algorithm: where mimic joints drive several bodies from one coordinate, and
   on a fixed base of one-number joints up to TK_FACTOR_MOST of them, where it is the faster
   (measured on the engine, ns: UR5 574 against 682, the locked Panda 662 against 820, a
   12-joint chain 1273 against 1416; even at 16 joints, ABA ahead from 24 and on Solo12's
   floating base: docs/benchmarks.md). Chosen by the tree alone: a batch's lanes and its single
   calls take the same one. */
#define TK_FACTOR_MOST 12
static inline int tk_by_factor(const tk_tree *t)
{
    return t->mimic || (!t->fb && !t->balls && !t->flyers && t->nv <= TK_FACTOR_MOST);
}

/* One state on the scalar functions into y (size numbers); 0 where it is defined. */
static int tk_one(const tk_tree *t, int kind, const double **a, double *W, double *L,
                  double *y)
{
    switch (kind) {
    case TK_MASSM: tk_mass(t, a[0], W, y); return 0;
    case TK_BIAS: tk_inverse(t, a[0], a[1], NULL, W, y); return 0;
    case TK_GRAVITY: tk_inverse(t, a[0], NULL, NULL, W, y); return 0;
    case TK_INVERSE: tk_inverse(t, a[0], a[1], a[2], W, y); return 0;
    case TK_FORWARD:
        return tk_by_factor(t) ? tk_forward_cholesky(t, a[0], a[1], a[2], W, L, y)
                        : tk_forward_aba(t, a[0], a[1], a[2], W, y);
    case TK_KINETIC: y[0] = tk_kinetic(t, a[0], a[1], W); return 0;
    default: y[0] = tk_potential(t, a[0], W); return 0;
    }
}

/* LG_LANES states at once on the lanes' functions into Y (size lanes); the failed lanes' mask */
static lg_i4 tk_lanes(const tk_tree *t, int kind, const lg_v4 **a, lg_v4 *W, lg_v4 *L,
                      lg_v4 *Y)
{
    const lg_i4 fine = {0};
    switch (kind) {
    case TK_MASSM: tk4_mass(t, a[0], W, Y); return fine;
    case TK_BIAS: tk4_inverse(t, a[0], a[1], NULL, W, Y); return fine;
    case TK_GRAVITY: tk4_inverse(t, a[0], NULL, NULL, W, Y); return fine;
    case TK_INVERSE: tk4_inverse(t, a[0], a[1], a[2], W, Y); return fine;
    case TK_FORWARD:
        return tk_by_factor(t) ? tk4_forward_cholesky(t, a[0], a[1], a[2], W, L, Y)
                        : tk4_forward_aba(t, a[0], a[1], a[2], W, Y);
    case TK_KINETIC: Y[0] = tk4_kinetic(t, a[0], a[1], W); return fine;
    default: Y[0] = tk4_potential(t, a[0], W); return fine;
    }
}

static int tk_finite(const double *x, int width)
{
    for (int i = 0; i < width; i++)
        if (!isfinite(x[i])) return 0;
    return 1;
}

/* A thread's share of a batch: LG_LANES states at a time on the lanes (each lane's numbers its
   state's own single call's, bit for bit), the rest one by one. A state whose inputs are not
   all finite rides its lanes as zeros, its row NaN after. */
static void *tk_run(void *argument)
{
    tk_job *job = (tk_job *)argument;
    const tk_tree *t = job->tree;
    const int size = job->size, nin = job->nin;
    const size_t need = (size_t)t->nb * TW_STRIDE + (size_t)t->nv * t->nv;
    /* scratch: on the stack for a small tree (a call on one state costs no malloc) */
    double small[4096];
    double *W = need <= 4096 ? small : malloc(need * sizeof(double));
    if (!W) { job->failed = 1; return NULL; }
    double *L = W + (size_t)t->nb * TW_STRIDE;
    npy_intp bad = 0, k = job->k0;
    const int width[3] = {t->nq, t->nv, t->nv};
    if (job->k1 - k >= LG_LANES) {
        /* the lanes' scratch, inputs and output: W, L, then X[j] (width[j]), then Y (size) */
        const size_t lanes = need + (size_t)t->nq + 2 * (size_t)t->nv + (size_t)size;
        lg_v4 *V = NULL;
        if (posix_memalign((void **)&V, 64, lanes * sizeof(lg_v4)) != 0) {
            if (W != small) free(W);
            job->failed = 1;
            return NULL;
        }
        lg_v4 *VL = V + (size_t)t->nb * TW_STRIDE, *X[3], *Y;
        X[0] = V + need;
        X[1] = X[0] + t->nq;
        X[2] = X[1] + t->nv;
        Y = X[2] + t->nv;
        const lg_v4 *args[3] = {X[0], X[1], X[2]};
        for (; k + LG_LANES <= job->k1; k += LG_LANES) {
            int lost[LG_LANES];
            for (int l = 0; l < LG_LANES; l++) {
                lost[l] = 0;
                for (int j = 0; j < nin; j++)
                    if (!tk_finite(job->x[j] + (k + l) * job->step[j], width[j])) lost[l] = 1;
            }
            for (int j = 0; j < nin; j++) {
                const double *x = job->x[j];
                for (int l = 0; l < LG_LANES; l++) {
                    const double *row = x + (k + l) * job->step[j];
                    for (int i = 0; i < width[j]; i++) X[j][i][l] = lost[l] ? 0.0 : row[i];
                }
            }
            const lg_i4 failed = tk_lanes(t, job->kind, args, V, VL, Y);
            double *y = job->y + k * size;
            for (int l = 0; l < LG_LANES; l++) {
                double *row = y + (npy_intp)l * size;
                if (lost[l] || failed[l]) {
                    for (int i = 0; i < size; i++) row[i] = NAN;
                    bad++;
                } else {
                    for (int i = 0; i < size; i++) row[i] = Y[i][l];
                }
            }
        }
        free(V);
    }
    for (; k < job->k1; k++) {
        const double *a[3] = {NULL, NULL, NULL};
        int fine = 1;
        for (int j = 0; j < nin; j++) {
            a[j] = job->x[j] + k * job->step[j];
            if (!tk_finite(a[j], width[j])) fine = 0;
        }
        double *y = job->y + k * size;
        if (fine) fine = tk_one(t, job->kind, a, W, L, y) == 0;
        if (!fine) {
            for (int i = 0; i < size; i++) y[i] = NAN;
            bad++;
        }
    }
    if (W != small) free(W);
    job->bad = bad;
    return NULL;
}

/* A batch's threads by its work (states times bodies), never more threads than states. */
static int tk_threads(npy_intp count, int nb)
{
    int parts = lg_threads(count * nb, TK_THREAD_WORK);
    return parts > count ? (int)(count < 1 ? 1 : count) : parts;
}

/* x as a float64 C-contiguous array (a new reference) when it already is one, else NULL with
   no error set: an input off the fast path makes the call answer NotImplemented, and the
   Python front (recursive.py) checks and shapes it; no error text is ever read. */
static PyArrayObject *tk_array(PyObject *x, int min_depth, int max_depth)
{
    if (PyArray_CheckExact(x) && PyArray_TYPE((PyArrayObject *)x) == NPY_DOUBLE
            && PyArray_IS_C_CONTIGUOUS((PyArrayObject *)x) && PyArray_ISALIGNED((PyArrayObject *)x)
            && PyArray_NDIM((PyArrayObject *)x) >= min_depth
            && (max_depth == 0 || PyArray_NDIM((PyArrayObject *)x) <= max_depth)) {
        Py_INCREF(x);
        return (PyArrayObject *)x;
    }
    return NULL;
}

/* A tree prepared once (prepare(D)): its description copied and checked, so that a call reads
   a capsule's pointer instead of checking every body again (a tenth of a small call). */
#define TK_CAPSULE "lagrangian.compact_tree"
typedef struct {
    tk_tree tree;
    double *numbers;  /* the description's copy, which tree points into */
} tk_prepared;

static void tk_release(PyObject *capsule)
{
    tk_prepared *p = (tk_prepared *)PyCapsule_GetPointer(capsule, TK_CAPSULE);
    if (p) {
        free(p->numbers);
        free(p);
    }
}

static PyObject *tk_py_prepare(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    PyArrayObject *D = nargs == 1 ? tk_array(args[0], 1, 1) : NULL;
    tk_tree tree;
    if (!D || tk_open((const double *)PyArray_DATA(D), PyArray_SIZE(D), &tree)
        || !tk_whole_balls(&tree)) {
        Py_XDECREF(D);
        PyErr_SetString(PyExc_TypeError, "tree: not a tree description (compact_kernel.py)");
        return NULL;
    }
    const Py_ssize_t size = PyArray_SIZE(D);
    tk_prepared *p = malloc(sizeof *p);
    double *numbers = malloc((size_t)size * sizeof(double));
    if (!p || !numbers) {
        free(p);
        free(numbers);
        Py_DECREF(D);
        return PyErr_NoMemory();
    }
    memcpy(numbers, PyArray_DATA(D), (size_t)size * sizeof(double));
    Py_DECREF(D);
    tk_open_marked(numbers, size, &p->tree);  /* the same numbers: checked above */
    p->numbers = numbers;
    PyObject *capsule = PyCapsule_New(p, TK_CAPSULE, tk_release);
    if (!capsule) {
        free(numbers);
        free(p);
    }
    return capsule;
}

/* One state, its inputs float64 vectors of their widths (tk_batch checked): the scalar
   function on it, its scratch on the stack; the quaternions checked as in a batch (else
   NotImplemented: the front names the joint); an input not finite, or no finite answer, gives
   (NaN output, 1) as a batch does. */
#define TK_ONE_SCRATCH 4096  /* numbers: 32 bodies and 25 velocities */
static int tk_one_fits(const tk_tree *t)
{
    return (size_t)t->nb * TW_STRIDE + (size_t)t->nv * t->nv <= TK_ONE_SCRATCH;
}

static PyObject *tk_single(const tk_tree *t, PyObject *const *args, int nin, int kind)
{
    const double *a[3] = {NULL, NULL, NULL};
    int fine = 1;
    for (int i = 0; i < nin; i++) {
        a[i] = (const double *)PyArray_DATA((PyArrayObject *)args[i]);
        fine &= tk_finite(a[i], i == 0 ? t->nq : t->nv);
    }
    /* a finite q's quaternions, whatever v and a hold (as a batch checks them) */
    if (((t->fb && !lg_unit_quaternions(a[0], 1, t->nq, t->nq, t->qtol))
         || ((t->balls || t->flyers) && !tk_unit_balls(t, a[0], 1, t->nq)))) {
        PyErr_Clear();  /* the front names the state and its norm */
        Py_RETURN_NOTIMPLEMENTED;
    }
    const int n = t->nv;
    npy_intp dims[2] = {n, n};
    const int nd = kind == TK_MASSM ? 2 : (kind == TK_KINETIC || kind == TK_POTENTIAL) ? 0 : 1;
    const int size = kind == TK_MASSM ? n * n : nd == 0 ? 1 : n;
    double W[TK_ONE_SCRATCH];
    PyObject *out = PyArray_SimpleNew(nd, dims, NPY_DOUBLE);
    if (!out) return NULL;
    double *y = (double *)PyArray_DATA((PyArrayObject *)out);
    if (fine) fine = tk_one(t, kind, a, W, W + (size_t)t->nb * TW_STRIDE, y) == 0;
    if (fine) return out;
    for (int i = 0; i < size; i++) y[i] = NAN;
    return Py_BuildValue("(Nn)", out, (Py_ssize_t)1);
}

static PyObject *tk_batch(PyObject *const *args, Py_ssize_t nargs, int nin, int kind)
{
    PyArrayObject *in[3] = {NULL, NULL, NULL};
    PyObject *out = NULL;
    npy_intp step[3] = {0, 0, 0};
    if (nargs != nin + 1) {
        PyErr_Format(PyExc_TypeError, "expected %d arguments", nin + 1);
        return NULL;
    }
    if (!PyCapsule_CheckExact(args[nin])) {
        PyErr_SetString(PyExc_TypeError, "tree: not a prepared tree (compact_kernel.py prepare)");
        return NULL;
    }
    const tk_prepared *prepared = (const tk_prepared *)PyCapsule_GetPointer(args[nin], TK_CAPSULE);
    if (!prepared) return NULL;  /* another capsule: its name's error */
    const tk_tree tree = prepared->tree;
    const int n = tree.nv;  /* q is nq wide (a floating base's quaternion), the rest nv */
    if (tk_one_fits(&tree)) {  /* one state, each input a vector of its width: straight */
        int one = 1;           /* to the scalar function, no batch set up */
        for (int i = 0; i < nin && one; i++) {
            PyObject *x = args[i];
            one = PyArray_CheckExact(x) && PyArray_NDIM((PyArrayObject *)x) == 1
                  && PyArray_TYPE((PyArrayObject *)x) == NPY_DOUBLE
                  && PyArray_DIMS((PyArrayObject *)x)[0] == (i == 0 ? tree.nq : n)
                  && PyArray_IS_C_CONTIGUOUS((PyArrayObject *)x)
                  && PyArray_ISALIGNED((PyArrayObject *)x);
        }
        if (one) return tk_single(&tree, args, nin, kind);
    }
#define TK_WIDTH(i) ((i) == 0 ? tree.nq : n)
    int base = 0;
    for (int i = 0; i < nin; i++) {
        in[i] = tk_array(args[i], 0, 0);
        if (!in[i]) goto slow;
        int nd = PyArray_NDIM(in[i]);
        if (nd == 0 || PyArray_DIMS(in[i])[nd - 1] != TK_WIDTH(i)) goto slow;
        if (PyArray_SIZE(in[i]) / TK_WIDTH(i) > PyArray_SIZE(in[base]) / TK_WIDTH(base)) base = i;
    }
    npy_intp count = PyArray_SIZE(in[base]) / TK_WIDTH(base);
    int nd = PyArray_NDIM(in[base]);
    for (int i = 0; i < nin; i++) {
        if (PyArray_SIZE(in[i]) == TK_WIDTH(i) && PyArray_NDIM(in[i]) == 1) {
            step[i] = count > 1 ? 0 : TK_WIDTH(i);
            continue;
        }
        if (PyArray_NDIM(in[i]) != nd  /* the batch axes, all but the last */
            || memcmp(PyArray_DIMS(in[i]), PyArray_DIMS(in[base]), (nd - 1) * sizeof(npy_intp)))
            goto slow;
        step[i] = TK_WIDTH(i);
    }
    if (tree.fb && !lg_unit_quaternions((const double *)PyArray_DATA(in[0]),
                                        step[0] ? count : 1, step[0], tree.nq, tree.qtol)) {
        PyErr_Clear();  /* the front names the state and its norm */
        goto slow;
    }
    if ((tree.balls || tree.flyers) && !tk_unit_balls(&tree, (const double *)PyArray_DATA(in[0]),
                                     step[0] ? count : 1, step[0]))
        goto slow;
#undef TK_WIDTH
    npy_intp dims[NPY_MAXDIMS];
    memcpy(dims, PyArray_DIMS(in[base]), (nd - 1) * sizeof(npy_intp));
    int od = nd - 1;
    if (kind == TK_MASSM) { dims[od++] = n; dims[od++] = n; }
    else if (kind != TK_KINETIC && kind != TK_POTENTIAL) dims[od++] = n;
    out = lg_output(od, dims);
    if (!out) goto done;
    const int size = kind == TK_MASSM ? n * n : (kind == TK_KINETIC || kind == TK_POTENTIAL) ? 1 : n;
    tk_job jobs[TK_MAX_THREADS];
    const int parts = tk_threads(count, tree.nb);
    const npy_intp share = (count + parts - 1) / parts;
    for (int t = 0; t < parts; t++) {
        tk_job job = {&tree, kind, nin, size, {step[0], step[1], step[2]},
                      {(const double *)PyArray_DATA(in[0]),
                       nin > 1 ? (const double *)PyArray_DATA(in[1]) : NULL,
                       nin > 2 ? (const double *)PyArray_DATA(in[2]) : NULL},
                      (double *)PyArray_DATA((PyArrayObject *)out),
                      t * share < count ? t * share : count,
                      (t + 1) * share < count ? (t + 1) * share : count, 0, 0};
        jobs[t] = job;
    }
    npy_intp bad = 0;
    int failed = 0;
    NPY_BEGIN_THREADS_DEF;
    if (count * tree.nb > 64) NPY_BEGIN_THREADS;
#if TK_PTHREADS
    lg_run_batch(tk_run, jobs, sizeof jobs[0], parts);
#else
    for (int t = 0; t < parts; t++) tk_run(&jobs[t]);
#endif
    for (int t = 0; t < parts; t++) { bad += jobs[t].bad; failed |= jobs[t].failed; }
    if (count * tree.nb > 64) NPY_END_THREADS;
    if (failed) {
        Py_CLEAR(out);
        PyErr_NoMemory();
        goto done;
    }
    if (bad > 0) {
        PyObject *pair = Py_BuildValue("(Nn)", out, (Py_ssize_t)bad);
        out = pair;  /* the pair owns the array (N), or NULL with the error set */
    }
done:
    for (int i = 0; i < 3; i++) Py_XDECREF(in[i]);
    return out;
slow:  /* not the fast path's inputs: the Python front checks and shapes them */
    for (int i = 0; i < 3; i++) Py_XDECREF(in[i]);
    Py_RETURN_NOTIMPLEMENTED;
}

#define TK_WRAP(name, nin, kind) \
    static PyObject *tk_py_##name(PyObject *self, PyObject *const *args, Py_ssize_t nargs) \
    { (void)self; return tk_batch(args, nargs, nin, kind); }
TK_WRAP(mass_matrix, 1, TK_MASSM)
TK_WRAP(bias_forces, 2, TK_BIAS)
TK_WRAP(gravity, 1, TK_GRAVITY)
TK_WRAP(inverse_dynamics, 3, TK_INVERSE)
TK_WRAP(forward_dynamics, 3, TK_FORWARD)
TK_WRAP(kinetic_energy, 2, TK_KINETIC)
TK_WRAP(potential_energy, 1, TK_POTENTIAL)

#define TK_METHOD(name, doc) \
    {#name, (PyCFunction)(void (*)(void))tk_py_##name, METH_FASTCALL, doc}
static PyMethodDef tk_methods[] = {
    TK_METHOD(mass_matrix, "(Q, D) -> M"),
    TK_METHOD(bias_forces, "(Q, V, D) -> b"),
    TK_METHOD(gravity, "(Q, D) -> g"),
    TK_METHOD(inverse_dynamics, "(Q, V, A, D) -> tau"),
    TK_METHOD(forward_dynamics, "(Q, V, TAU, D) -> q_ddot"),
    TK_METHOD(kinetic_energy, "(Q, V, D) -> T"),
    TK_METHOD(potential_energy, "(Q, D) -> V"),
    TK_METHOD(prepare, "(D) -> the tree prepared for the functions above (checked once)"),
    LG_BOUND_METHOD,
    {NULL, NULL, 0, NULL},
};

#define TK_STR_(x) #x
#define TK_STR(x) TK_STR_(x)
#define TK_PASTE_(a, b) a##b
#define TK_PASTE(a, b) TK_PASTE_(a, b)
static struct PyModuleDef tk_module = {PyModuleDef_HEAD_INIT, TK_STR(LG_MODULE), NULL, -1,
                                       tk_methods};

PyMODINIT_FUNC TK_PASTE(PyInit_, LG_MODULE)(void)
{
    import_array();
    PyObject *m = PyModule_Create(&tk_module);
    if (m) {
        PyModule_AddIntConstant(m, "header", TK_HEADER);
        PyModule_AddIntConstant(m, "stride", TK_STRIDE);
    }
    return m;
}
