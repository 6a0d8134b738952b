/* ---- a recursion bound to its tables and its front: bound(function, tables, fallback, report)
   The object is what TreeDynamics holds as its method (recursive.py): called with the inputs
   alone, f(*inputs), it calls the module's function (a METH_FASTCALL function of this module)
   on them and the tables, with no Python frame between; where the function answers
   NotImplemented (inputs the front must check and shape) it returns fallback(*inputs) (the
   front's own method), where it answers (outputs, count) report(that) (the NaN rows' one
   warning), and any other call (a keyword, another count of inputs) goes to fallback whole.
   A Python method in front of the kernel cost a tenth of a microsecond of a 0.6 us call. */
#include <structmember.h>
typedef struct {
    PyObject_HEAD
    vectorcallfunc vectorcall;
    PyObject *function, *tables, *fallback, *report;
    _PyCFunctionFast fast;
    PyObject *module;  /* the function's self */
} lg_bound;

static PyObject *lg_bound_call(PyObject *self, PyObject *const *args, size_t nargsf,
                               PyObject *kwnames)
{
    lg_bound *b = (lg_bound *)self;
    const Py_ssize_t nargs = PyVectorcall_NARGS(nargsf);
    if ((kwnames && PyTuple_GET_SIZE(kwnames)) || nargs < 1 || nargs > 3)
        return PyObject_Vectorcall(b->fallback, args, nargsf, kwnames);
    PyObject *full[4];
    for (Py_ssize_t i = 0; i < nargs; i++) full[i] = args[i];
    full[nargs] = b->tables;
    PyObject *out = b->fast(b->module, full, nargs + 1);
    if (!out) return NULL;
    if (out == Py_NotImplemented) {
        Py_DECREF(out);
        return PyObject_Vectorcall(b->fallback, args, nargs, NULL);
    }
    if (PyTuple_CheckExact(out)) {
        PyObject *reported = PyObject_CallOneArg(b->report, out);
        Py_DECREF(out);
        return reported;
    }
    return out;
}

static int lg_bound_traverse(PyObject *self, visitproc visit, void *arg)
{
    lg_bound *b = (lg_bound *)self;
    Py_VISIT(Py_TYPE(self));
    Py_VISIT(b->function);
    Py_VISIT(b->tables);
    Py_VISIT(b->fallback);
    Py_VISIT(b->report);
    return 0;
}

static int lg_bound_clear(PyObject *self)
{
    lg_bound *b = (lg_bound *)self;
    Py_CLEAR(b->function);
    Py_CLEAR(b->tables);
    Py_CLEAR(b->fallback);
    Py_CLEAR(b->report);
    return 0;
}

static void lg_bound_dealloc(PyObject *self)
{
    PyTypeObject *type = Py_TYPE(self);
    PyObject_GC_UnTrack(self);
    lg_bound_clear(self);
    type->tp_free(self);
    Py_DECREF(type);
}

/* the front's method's name and text (help() on the bound object reads the method's) */
static PyObject *lg_bound_doc(PyObject *self, void *closure)
{
    (void)closure;
    return PyObject_GetAttrString(((lg_bound *)self)->fallback, "__doc__");
}

static PyObject *lg_bound_repr(PyObject *self)
{
    PyObject *name = PyObject_GetAttrString(((lg_bound *)self)->fallback, "__qualname__");
    if (!name) return NULL;
    PyObject *text = PyUnicode_FromFormat("<compiled %U>", name);
    Py_DECREF(name);
    return text;
}

static PyMemberDef lg_bound_members[] = {
    {"__vectorcalloffset__", T_PYSSIZET, offsetof(lg_bound, vectorcall), READONLY, NULL},
    {NULL, 0, 0, 0, NULL},
};
static PyGetSetDef lg_bound_getset[] = {{"__doc__", lg_bound_doc, NULL, NULL, NULL},
                                        {NULL, NULL, NULL, NULL, NULL}};
static PyType_Slot lg_bound_slots[] = {
    {Py_tp_call, PyVectorcall_Call}, {Py_tp_traverse, lg_bound_traverse},
    {Py_tp_clear, lg_bound_clear}, {Py_tp_dealloc, lg_bound_dealloc},
    {Py_tp_repr, lg_bound_repr}, {Py_tp_members, lg_bound_members},
    {Py_tp_getset, lg_bound_getset}, {0, NULL}};
static PyType_Spec lg_bound_spec = {
    "lagrangian.compiled_recursion", sizeof(lg_bound), 0,
    Py_TPFLAGS_DEFAULT | Py_TPFLAGS_HAVE_GC | Py_TPFLAGS_HAVE_VECTORCALL, lg_bound_slots};
static PyObject *lg_bound_type;

static PyObject *lg_py_bound(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    (void)self;
    if (nargs != 4 || !PyCFunction_Check(args[0])
        || PyCFunction_GET_FLAGS(args[0]) != METH_FASTCALL
        || !PyCallable_Check(args[2]) || !PyCallable_Check(args[3])) {
        PyErr_SetString(PyExc_TypeError,
                        "bound(function, tables, fallback, report): a fast function of this "
                        "module, its tables and two callables");
        return NULL;
    }
    if (!lg_bound_type && !(lg_bound_type = PyType_FromSpec(&lg_bound_spec))) return NULL;
    lg_bound *b = PyObject_GC_New(lg_bound, (PyTypeObject *)lg_bound_type);
    if (!b) return NULL;
    Py_INCREF(lg_bound_type);  /* each instance holds its heap type */
    b->vectorcall = lg_bound_call;
    b->fast = (_PyCFunctionFast)(void (*)(void))PyCFunction_GET_FUNCTION(args[0]);
    b->module = PyCFunction_GET_SELF(args[0]);
    Py_INCREF(args[0]);
    Py_INCREF(args[1]);
    Py_INCREF(args[2]);
    Py_INCREF(args[3]);
    b->function = args[0];
    b->tables = args[1];
    b->fallback = args[2];
    b->report = args[3];
    PyObject_GC_Track((PyObject *)b);
    return (PyObject *)b;
}
#define LG_BOUND_METHOD \
    {"bound", (PyCFunction)(void (*)(void))lg_py_bound, METH_FASTCALL, \
     "(function, tables, fallback, report) -> function(*inputs, tables), one call"}
