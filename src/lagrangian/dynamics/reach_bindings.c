/* Python bindings of reach_kernel.c's functions (frames, C(q, v), A_g, wrenches, inverse
 * dynamics): arrays (..., n) of float64 checked and handed to reach_batch.c's batches; a
 * function returns its output, or (output, count of NaN rows) where some state's inputs are
 * not all finite. */

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

/* a floating base's quaternions (entries 3..6 of each state) of norm within the tolerance, in
 * every state whose q is all finite (the others' rows are NaN, as the tree module's rule);
 * else ValueError, and numpy names the state */
static int rk_unit_quaternions(PyArrayObject *Q)
{
#if RK_FB
    npy_intp count = PyArray_SIZE(Q) / RK_NQ;
    const double *q = PyArray_DATA(Q);
    for (npy_intp k = 0; k < count; k++, q += RK_NQ) {
        double n2 = q[3] * q[3] + q[4] * q[4] + q[5] * q[5] + q[6] * q[6];
        if (rk_finite_row(q, RK_NQ) && (n2 < RK_QLOW || n2 > RK_QHIGH)) {
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
