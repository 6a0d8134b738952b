/* Python bindings of reach_kernel.c's functions (frames, C(q, v), A_g, wrenches, inverse
 * dynamics): tree(D, INTS, FLOATS, INDEX) reads a tree's description and tables once (their
 * layouts: tree/description.py, reach_c.py) into a Tree, whose methods take arrays (..., n) of float64, checked and handed to reach_batch.c's
 * batches; a method returns its output, or (output, count of NaN rows) where some state's
 * inputs are not all finite. */

/* a tree: its model (md's arrays point into ``tables``), {frame name: frame number} */
typedef struct {
    PyObject_HEAD
    rk_model md;
    PyObject *index;
    void *tables;
} rk_tree;

#define RK_MD(self) (&((rk_tree *)(self))->md)

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

/* a floating base's quaternions (entries 3..6 of each state) and each ball joint's (w x y z at
 * its q number) of norm within the tolerance, in every state whose q is all finite (the
 * others' rows are NaN, as the tree module's rule); else ValueError, and numpy names the
 * state */
static int rk_unit_quaternions(const rk_model *md, PyArrayObject *Q)
{
    if (!md->nquat) return 1;
    npy_intp count = PyArray_SIZE(Q) / md->nq;
    const double *q = PyArray_DATA(Q);
    for (npy_intp k = 0; k < count; k++, q += md->nq) {
        for (int j = 0; j < md->nquat; j++) {
            const double *e = q + md->quat[j];
            double n2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3];
            /* the row's finiteness read only for a quaternion off (a NaN's n2 is neither) */
            if ((n2 < md->qlow || n2 > md->qhigh) && rk_finite_row(q, md->nq)) {
                PyErr_SetString(PyExc_ValueError, "q: a quaternion is not of unit norm");
                return 0;
            }
        }
    }
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

/* a frame named by the tree's dict {name: frame number}; -1 with KeyError (TypeError for a
 * name not hashable) where there is none */
static int rk_frame_named(const rk_model *md, PyObject *index, PyObject *name)
{
    PyObject *number = PyDict_GetItemWithError(index, name);
    if (!number) {
        if (!PyErr_Occurred()) PyErr_SetObject(PyExc_KeyError, name);
        return -1;
    }
    const long f = PyLong_AsLong(number);
    if (f == -1 && PyErr_Occurred()) return -1;
    if (f < 0 || f >= md->nf) { PyErr_SetString(PyExc_ValueError, "frame: out of range"); return -1; }
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

/* drift(Q, V, frame, reference) -> [a; w_dot] (or with NaN rows) */
static PyObject *rk_py_drift(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    const rk_model *md = RK_MD(self);
    if (nargs != 4) { PyErr_SetString(PyExc_TypeError, "drift(Q, V, frame, reference)"); return NULL; }
    const int f = rk_frame_named(md, ((rk_tree *)self)->index, args[2]);
    if (f < 0) return NULL;
    const int ref = rk_reference_named(args[3]);
    if (ref < 0) return NULL;
    PyArrayObject *Q = rk_input(args[0], md->nq, "q");
    if (!Q) return NULL;
    if (!rk_unit_quaternions(md, Q)) { Py_DECREF(Q); return NULL; }
    PyArrayObject *V = rk_input(args[1], md->nv, "v");
    if (!V || !rk_same_batch(Q, V, "v")) { Py_DECREF(Q); Py_XDECREF(V); return NULL; }
    PyObject *out = rk_output(Q, 6, 0);
    npy_intp bad = 0;
    if (out) {
        rk_job job = {.md = md, .kind = RK_DRIFT, .frame = f, .ref = ref, .q = PyArray_DATA(Q),
                      .v = PyArray_DATA(V), .y = PyArray_DATA((PyArrayObject *)out),
                      .count = PyArray_SIZE(Q) / md->nq};
        if (!rk_go(&job)) Py_CLEAR(out);
        bad = job.bad;
    }
    Py_DECREF(Q); Py_DECREF(V);
    return rk_result(out, bad);
}

/* a function of q alone on Q (frame f, reference ref where it has them) -> its rows (tail0 x
 * tail1 a state), or (rows, NaN rows). One state is computed here, without the batch's
 * machinery. */
static PyObject *rk_of_q(PyObject *self, PyObject *Q_in, int kind, int f, int ref, int tail0,
                         int tail1)
{
    const rk_model *md = RK_MD(self);
    PyArrayObject *Q = rk_input(Q_in, md->nq, "q");
    if (!Q) return NULL;
    if (!rk_unit_quaternions(md, Q)) { Py_DECREF(Q); return NULL; }
    PyObject *out = rk_output(Q, tail0, tail1);
    npy_intp bad = 0;
    if (out) {
        rk_job job = {.md = md, .kind = kind, .frame = f, .ref = ref, .q = PyArray_DATA(Q),
                      .y = PyArray_DATA((PyArrayObject *)out), .count = PyArray_SIZE(Q) / md->nq};
        if (!rk_go(&job)) Py_CLEAR(out);
        bad = job.bad;
    }
    Py_DECREF(Q);
    return rk_result(out, bad);
}

/* placement(Q, frame) and jacobian(Q, frame, reference): the name looked up here, not in
 * Python (two dict lookups and an attribute there were a sixth of a single Jacobian's call) */
static PyObject *rk_py_placement(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 2) { PyErr_SetString(PyExc_TypeError, "placement(Q, frame)"); return NULL; }
    const int f = rk_frame_named(RK_MD(self), ((rk_tree *)self)->index, args[1]);
    return f < 0 ? NULL : rk_of_q(self, args[0], RK_PLACEMENT, f, 0, 4, 4);
}

static PyObject *rk_py_jacobian(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    if (nargs != 3) { PyErr_SetString(PyExc_TypeError, "jacobian(Q, frame, reference)"); return NULL; }
    const int f = rk_frame_named(RK_MD(self), ((rk_tree *)self)->index, args[1]);
    if (f < 0) return NULL;
    const int ref = rk_reference_named(args[2]);
    return ref < 0 ? NULL : rk_of_q(self, args[0], RK_JACOBIAN, f, ref, 6, RK_MD(self)->nv);
}

/* the functions of q alone, each rk_of_q with its kind and a state's output shape */
#define RK_OF_Q(name, kind, tail0, tail1)                                                      \
    static PyObject *rk_py_##name(PyObject *self, PyObject *const *args, Py_ssize_t nargs)    \
    {                                                                                          \
        if (nargs != 1) { PyErr_SetString(PyExc_TypeError, #name "(Q)"); return NULL; }       \
        return rk_of_q(self, args[0], kind, 0, 0, tail0, tail1);                               \
    }
RK_OF_Q(com, RK_COM, 3, 0)
RK_OF_Q(com_jacobian, RK_COM_JACOBIAN, 3, RK_MD(self)->nv)
RK_OF_Q(centroidal, RK_CENTROIDAL, 6, RK_MD(self)->nv)

/* wrench(Q, frame, W, OUT, sign): OUT += sign J^T w, in place (OUT float64, contiguous, of
 * Q's batch and nv wide); W (6,) for every state or one row per state */
static PyObject *rk_py_wrench(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    const rk_model *md = RK_MD(self);
    if (nargs != 5) { PyErr_SetString(PyExc_TypeError, "wrench(Q, frame, W, OUT, sign)"); return NULL; }
    int f = (int)PyLong_AsLong(args[1]);
    double sign = PyFloat_AsDouble(args[4]);
    if (PyErr_Occurred()) return NULL;
    if (f < 0 || f >= md->nf) { PyErr_SetString(PyExc_ValueError, "frame: out of range"); return NULL; }
    if (!PyArray_Check(args[3])) { PyErr_SetString(PyExc_ValueError, "out: not an array"); return NULL; }
    PyArrayObject *out = (PyArrayObject *)args[3];
    PyArrayObject *Q = rk_input(args[0], md->nq, "q");
    if (!Q) return NULL;
    if (!rk_unit_quaternions(md, Q)) { Py_DECREF(Q); return NULL; }
    PyArrayObject *W = rk_input(args[2], 6, "f_ext");
    if (!W) { Py_DECREF(Q); return NULL; }
    int shared = PyArray_NDIM(W) == 1;
    if ((!shared && !rk_same_batch(Q, W, "f_ext"))
            || PyArray_TYPE(out) != NPY_DOUBLE || !PyArray_ISCARRAY(out)
            || PyArray_NDIM(out) != PyArray_NDIM(Q)
            || !PyArray_CompareLists(PyArray_DIMS(out), PyArray_DIMS(Q), PyArray_NDIM(Q) - 1)
            || PyArray_DIMS(out)[PyArray_NDIM(Q) - 1] != md->nv) {
        if (!PyErr_Occurred()) PyErr_SetString(PyExc_ValueError, "out: not of q's batch, nv wide");
        Py_DECREF(Q); Py_DECREF(W);
        return NULL;
    }
    const double *w = PyArray_DATA(W);
    rk_job job = {.md = md, .kind = RK_WRENCH, .frame = f, .q = PyArray_DATA(Q), .w = &w,
                  .wshared = &shared, .sign = sign, .y = PyArray_DATA(out),
                  .count = PyArray_SIZE(Q) / md->nq};
    int fine = rk_go(&job);
    Py_DECREF(Q); Py_DECREF(W);
    if (!fine) return NULL;
    return PyLong_FromSsize_t((Py_ssize_t)job.bad);
}

static PyObject *rk_py_coriolis(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    const rk_model *md = RK_MD(self);
    if (nargs != 2) { PyErr_SetString(PyExc_TypeError, "coriolis(Q, V)"); return NULL; }
    PyArrayObject *Q = rk_input(args[0], md->nq, "q");
    if (!Q) return NULL;
    if (!rk_unit_quaternions(md, Q)) { Py_DECREF(Q); return NULL; }
    PyArrayObject *V = rk_input(args[1], md->nv, "v");
    if (!V || !rk_same_batch(Q, V, "v")) { Py_DECREF(Q); Py_XDECREF(V); return NULL; }
    PyObject *out = rk_output(Q, md->nv, md->nv);
    npy_intp bad = 0;
    if (out) {
        rk_job job = {.md = md, .kind = RK_CORIOLIS, .q = PyArray_DATA(Q), .v = PyArray_DATA(V),
                      .y = PyArray_DATA((PyArrayObject *)out), .count = PyArray_SIZE(Q) / md->nq};
        if (!rk_go(&job)) Py_CLEAR(out);
        bad = job.bad;
    }
    Py_DECREF(Q); Py_DECREF(V);
    return rk_result(out, bad);
}

/* inverse(UP, Q, V, A, F_EXT) -> tau: inverse dynamics less the wrenches of the dict F_EXT
 * (frame name -> W) in one pass (reach_inverse.c); UP the ground's acceleration (3,), each W
 * (6,) for every state or one row per state. KeyError or ValueError where an input is not
 * plain (the caller's numpy path names it). */
static PyObject *rk_py_inverse(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    const rk_model *md = RK_MD(self);
    PyObject *index = ((rk_tree *)self)->index;
    if (nargs != 5 || !PyDict_Check(args[4])) {
        PyErr_SetString(PyExc_TypeError, "inverse(UP, Q, V, A, F_EXT)");
        return NULL;
    }
    Py_ssize_t nw = PyDict_Size(args[4]);
    if (nw > RK_MAX_WRENCHES) { PyErr_SetString(PyExc_ValueError, "f_ext: too many"); return NULL; }
    PyArrayObject *in[3] = {NULL, NULL, NULL}, *U = NULL, *W[RK_MAX_WRENCHES] = {NULL};
    PyObject *out = NULL, *name, *value;
    npy_intp bad = 0;
    int frames[RK_MAX_WRENCHES], shared[RK_MAX_WRENCHES];
    const double *w[RK_MAX_WRENCHES];
    const char *names[3] = {"q", "v", "a"};
    for (int j = 0; j < 3; j++) {
        in[j] = rk_input(args[1 + j], j == 0 ? md->nq : md->nv, names[j]);
        if (!in[j] || (j && !rk_same_batch(in[0], in[j], names[j]))) goto done;
    }
    if (!rk_unit_quaternions(md, in[0])) goto done;
    U = rk_input(args[0], 3, "up");
    if (!U) goto done;
    Py_ssize_t at = 0, k = 0;
    while (PyDict_Next(args[4], &at, &name, &value)) {
        if ((frames[k] = rk_frame_named(md, index, name)) < 0) goto done;
        W[k] = rk_input(value, 6, "f_ext");
        if (!W[k]) goto done;
        shared[k] = PyArray_NDIM(W[k]) == 1;
        if (!shared[k] && !rk_same_batch(in[0], W[k], "f_ext")) goto done;
        w[k] = PyArray_DATA(W[k]);
        k++;
    }
    out = rk_output(in[0], md->nv, 0);
    if (out) {
        rk_job job = {.md = md, .kind = RK_INVERSE, .nw = (int)nw, .q = PyArray_DATA(in[0]),
                      .v = PyArray_DATA(in[1]), .a = PyArray_DATA(in[2]), .up = PyArray_DATA(U),
                      .frames = frames, .w = w, .wshared = shared,
                      .y = PyArray_DATA((PyArrayObject *)out), .count = PyArray_SIZE(in[0]) / md->nq};
        if (!rk_go(&job)) Py_CLEAR(out);
        bad = job.bad;
    }
done:
    for (int j = 0; j < 3; j++) Py_XDECREF(in[j]);
    Py_XDECREF(U);
    for (Py_ssize_t j = 0; j < nw; j++) Py_XDECREF(W[j]);
    return rk_result(out, bad);
}

/* A method's NULL for inputs it does not take (the checks above raise: a width, a
   batch shape, a quaternion off unit norm, a frame or a reference not the tree's):
   NotImplemented instead, the fault cleared, and the Python front (tree_frames.py) checks the
   inputs and names the fault in one line; no error is read there. Memory errors stay. */
static PyObject *rk_front(PyObject *out)
{
    if (out || PyErr_ExceptionMatches(PyExc_MemoryError)) return out;
    PyErr_Clear();
    Py_RETURN_NOTIMPLEMENTED;
}
#define RK_FRONTED(name)                                                                      \
    static PyObject *rk_fronted_##name(PyObject *self, PyObject *const *args, Py_ssize_t nargs) \
    { return rk_front(rk_py_##name(self, args, nargs)); }
RK_FRONTED(placement)
RK_FRONTED(jacobian)
RK_FRONTED(drift)
RK_FRONTED(centroidal)
RK_FRONTED(coriolis)
RK_FRONTED(com)
RK_FRONTED(com_jacobian)
RK_FRONTED(wrench)
RK_FRONTED(inverse)

#define RK_FAST(name) (PyCFunction)(void (*)(void))rk_py_##name, METH_FASTCALL
#define RK_FRONT(name) (PyCFunction)(void (*)(void))rk_fronted_##name, METH_FASTCALL
static PyMethodDef rk_tree_methods[] = {
    {"placement", RK_FRONT(placement), "(Q, frame) -> 4 x 4, or (4 x 4, NaN rows)"},
    {"jacobian", RK_FRONT(jacobian), "(Q, frame, reference) -> 6 x nv, or (6 x nv, NaN rows)"},
    {"drift", RK_FRONT(drift), "(Q, V, frame, reference) -> [a; w_dot], or ([a; w_dot], NaN rows)"},
    {"centroidal", RK_FRONT(centroidal), "(Q) -> A_g, or (A_g, NaN rows)"},
    {"wrench", RK_FRONT(wrench), "(Q, frame, W, OUT, sign): OUT += sign J^T w; -> NaN rows"},
    {"coriolis", RK_FRONT(coriolis), "(Q, V) -> C(q, v), or (C(q, v), NaN rows)"},
    {"inverse", RK_FRONT(inverse), "(UP, Q, V, A, F_EXT) -> tau, or (tau, NaN rows)"},
    {"com", RK_FRONT(com), "(Q) -> c, or (c, NaN rows)"},
    {"com_jacobian", RK_FRONT(com_jacobian), "(Q) -> J_c, or (J_c, NaN rows)"},
    {NULL, NULL, 0, NULL},
};

static void rk_tree_dealloc(PyObject *self)
{
    rk_tree *t = (rk_tree *)self;
    Py_XDECREF(t->index);
    free(t->tables);
    Py_TYPE(self)->tp_free(self);
}

static PyTypeObject rk_tree_type = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "lagrangian.reach.Tree",
    .tp_basicsize = sizeof(rk_tree),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "a tree's tables, read once (module.tree); its methods the reach functions",
    .tp_dealloc = rk_tree_dealloc,
    .tp_methods = rk_tree_methods,
};

/* md from the description D (float64, tree/description.py's layout: joint.h's tk_open checks
 * it), INTS (C int) and FLOATS (float64) of reach_c.py's layout, copied into one block of its
 * own (*tables; md's arrays point into it); 0 with ValueError where they are not a tree's */
static int rk_model_from(PyObject *description, PyObject *ints, PyObject *floats, rk_model *md,
                         void **tables)
{
    PyArrayObject *Da = (PyArrayObject *)PyArray_FROMANY(description, NPY_DOUBLE, 1, 1,
                                                         NPY_ARRAY_IN_ARRAY);
    PyArrayObject *Ia = Da ? (PyArrayObject *)PyArray_FROMANY(ints, NPY_INT, 1, 1,
                                                              NPY_ARRAY_IN_ARRAY) : NULL;
    PyArrayObject *Fa = Ia ? (PyArrayObject *)PyArray_FROMANY(floats, NPY_DOUBLE, 1, 1,
                                                            NPY_ARRAY_IN_ARRAY) : NULL;
    const char *fault = NULL;
    *tables = NULL;
    if (!Fa) goto done;
    const npy_intp nD = PyArray_SIZE(Da), ni = PyArray_SIZE(Ia), nd = PyArray_SIZE(Fa);
    tk_tree t;
    if (tk_open(PyArray_DATA(Da), nD, &t) || !tk_whole_balls(&t)) {
        fault = "D: not a tree description";
        goto done;
    }
    const int *head = PyArray_DATA(Ia);
    if (ni < 3) { fault = "INTS: no header"; goto done; }
    const int nb = t.nb, n = t.n, fb = t.fb, nf = head[0];
    if (nb > RK_MAX_BODIES || nf < 0 || nf > RK_MAX_BODIES || (head[1] != 0 && head[1] != 1)) {
        fault = "INTS: not a tree's header";
        goto done;
    }
    const long long nv = t.nv;
    if (head[2] < 0 || head[2] > nv * nv) { fault = "INTS: not a tree's header"; goto done; }
    if (ni != 3LL + nf + head[2] || nd != 2 + 12LL * nf) {
        fault = "INTS, FLOATS: not of the header's sizes";
        goto done;
    }
    /* the description's copy, the frames' numbers, then per body mult, m, h (3), J (9) */
    const size_t doubles = (size_t)nD + (size_t)nd + 14 * (size_t)nb;
    double *d = malloc(doubles * sizeof(double) + ((size_t)ni + 3 * (size_t)nb) * sizeof(int));
    if (!d) { PyErr_NoMemory(); goto done; }
    *tables = d;
    memcpy(d, PyArray_DATA(Da), (size_t)nD * sizeof(double));
    tk_open_marked(d, nD, &t);  /* the same numbers: checked above */
    double *fr = d + nD, *per = fr + nd;
    int *a = (int *)(d + doubles);
    memcpy(fr, PyArray_DATA(Fa), (size_t)nd * sizeof(double));
    memcpy(a, head, (size_t)ni * sizeof(int));
    *md = (rk_model){.nb = nb, .n = n, .fb = fb, .nf = nf, .cset = a[1], .nczero = a[2],
                     .bq = t.bq, .bv = t.bv, .nq = t.nq, .nv = t.nv, .t = t};
    md->fbody = a + 3;
    md->czero = a + 3 + nf;
    int *parent = a + ni, *coord = parent + nb, *quat = coord + nb, nquat = 0;
    double *mult = per, *m = per + nb, *h = per + 2 * (size_t)nb, *J = per + 5 * (size_t)nb;
    for (int i = 0; i < nb; i++) {
        const double *b = t.body + (size_t)i * TK_STRIDE;
        parent[i] = (int)b[TK_PARENT];
        coord[i] = TK_FREE(b) ? 0 : (int)b[TK_COORD];
        mult[i] = b[TK_MULT];
        if (TK_FREE(b)) quat[nquat++] = 3;  /* x y z w after the origin */
        else if (TK_BALL(b)) quat[nquat++] = t.bq + (int)b[TK_QCOORD];  /* w x y z */
        else if (TK_FLYER(b)) quat[nquat++] = t.bq + (int)b[TK_QCOORD] + 3;  /* x y z w */
        m[i] = b[TK_MASS];
        for (int j = 0; j < 3; j++) h[3 * i + j] = b[TK_H + j];
        for (int j = 0; j < 9; j++) J[9 * i + j] = b[TK_J + j];
    }
    md->parent = parent, md->coord = coord, md->mult = mult, md->m = m, md->h = h, md->J = J;
    md->quat = quat, md->nquat = nquat;
    md->qlow = fr[0], md->qhigh = fr[1];
    md->fR = fr + 2;
    md->ft = fr + 2 + 9 * (size_t)nf;
    for (size_t k = 0; k < (size_t)nD + (size_t)nd; k++)
        if (!isfinite(d[k])) {
            fault = "D, FLOATS: not all finite";
            goto done;
        }
    for (int f = 0; f < nf; f++)
        if (md->fbody[f] < -1 || md->fbody[f] >= nb) { fault = "INTS: a frame's body"; goto done; }
    for (int j = 0; j < md->nczero; j++)
        if (md->czero[j] < 0 || md->czero[j] >= nv * nv) {
            fault = "INTS: an entry of C";
            goto done;
        }
done:
    Py_XDECREF(Da);
    Py_XDECREF(Ia);
    Py_XDECREF(Fa);
    if (fault) PyErr_SetString(PyExc_ValueError, fault);
    if (PyErr_Occurred()) {
        free(*tables);
        *tables = NULL;
        return 0;
    }
    return 1;
}

/* tree(D, INTS, FLOATS, INDEX) -> Tree: the description and tables read once, INDEX {frame
 * name: frame number} */
static PyObject *rk_py_tree(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 4 || !PyDict_Check(args[3])) {
        PyErr_SetString(PyExc_TypeError, "tree(D, INTS, FLOATS, INDEX): INDEX a dict");
        return NULL;
    }
    rk_model md;
    void *tables;
    if (!rk_model_from(args[0], args[1], args[2], &md, &tables)) return NULL;
    md.work1 = rk_work_size(&md);
    rk_tree *t = PyObject_New(rk_tree, &rk_tree_type);
    if (!t) { free(tables); return NULL; }
    t->md = md;
    t->tables = tables;
    Py_INCREF(args[3]);
    t->index = args[3];
    return (PyObject *)t;
}

static PyMethodDef rk_methods[] = {
    {"tree", RK_FAST(tree), "(D, INTS, FLOATS, INDEX) -> Tree, its methods the reach functions"},
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
    if (PyType_Ready(&rk_tree_type) < 0) return NULL;
    return PyModule_Create(&rk_module);
}
