"""The compiled Python extension module of a tree's dynamics: the functions of tree_c.py,
batched bindings over states (tree_bindings.c) and template.c, cached by a key of the tree's
numbers taken before any code is generated."""

from __future__ import annotations

import hashlib
from functools import lru_cache
from pathlib import Path

from ...model.tree import KinematicTree
from ..emit.tree_c import dynamics_functions
from ..emit.tree_emitter import VECTOR_LIMIT
from ..tree.free_flyer import QUATERNION_TOLERANCE
from ..tree.spherical import quaternion_slices

# The Python bindings of the batched functions (threads over states, vector lanes): real C.
# batch_threads.c first: the thread count the three compiled modules' batches share
# bound_call.c: each recursion bound to its tables as TreeDynamics's method
_THREADS, _BOUND, _BINDINGS = ("\n" + Path(__file__).with_name(name).read_text(encoding="utf-8")
                               for name in ("batch_threads.c", "bound_call.c", "tree_bindings.c"))


def _quaternion_check(starts: list[int], floating: bool) -> str:
    """C that widens tree_bindings.c's check of the base quaternion (batch_threads.c's
    lg_unit_quaternions, under RT_FLOATING) to every quaternion in q: the base's and each ball
    joint's or free flyer's at ``starts``; a state not finite is its row's NaN, not an error."""
    return f"""
/* each finite state's quaternions q[s..s+3], s in rt_quaternions (ball joints, free flyers
   below the root), of unit norm to ``tolerance``, and the base's (lg_unit_quaternions); else 0
   with a ValueError, and the front names the joint, the state and the norm */
static const int rt_quaternions[{len(starts)}] = {{{", ".join(map(str, starts))}}};
static int rt_unit_quaternions(const double *q, npy_intp states, npy_intp step, int nq,
                               double tolerance)
{{
    if ({int(floating)} && !lg_unit_quaternions(q, states, step, nq, tolerance)) return 0;
    for (npy_intp k = 0; k < states; k++) {{
        const double *x = q + k * step;
        int finite = 1;
        for (int i = 0; i < nq; i++) finite &= isfinite(x[i]) != 0;
        for (int j = 0; finite && j < {len(starts)}; j++) {{
            const double *e = x + rt_quaternions[j];
            const double norm = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2] + e[3] * e[3]);
            if (!(fabs(norm - 1.0) <= tolerance)) {{
                PyErr_SetString(PyExc_ValueError, "q: a joint's quaternion is not unit");
                return 0;
            }}
        }}
    }}
    return 1;
}}
#define lg_unit_quaternions rt_unit_quaternions
"""

_DECLARE = "\n".join(
    f"static PyObject *rt_py_{name}(PyObject *, PyObject *const *, Py_ssize_t);"
    for name in ("mass_matrix", "bias_forces", "gravity", "inverse_dynamics", "forward_dynamics",
                 "kinetic_energy", "potential_energy")) + (
    "\nstatic PyObject *lg_py_bound(PyObject *, PyObject *const *, Py_ssize_t);")

_METHODS = " ".join(
    f'{{"{name}", (PyCFunction)(void (*)(void))rt_py_{name}, METH_FASTCALL, "{doc}"}},'
    for name, doc in (("mass_matrix", "(Q, P) -> M"), ("bias_forces", "(Q, V, P) -> b"),
                      ("gravity", "(Q, P) -> g"), ("inverse_dynamics", "(Q, V, A, P) -> tau"),
                      ("forward_dynamics", "(Q, V, TAU, P) -> q_ddot"),
                      ("kinetic_energy", "(Q, V, P) -> T"), ("potential_energy", "(Q, P) -> V"))
) + ' {"bound", (PyCFunction)(void (*)(void))lg_py_bound, METH_FASTCALL, "(function, P, fallback, ' \
    'report) -> function(*inputs, P)"},'



def module_source(tree: KinematicTree, parameters: tuple[str, ...]):
    """The compiled module's C: the recursive functions, lg_parts/lg_energy/lg_residual for
    template.c (simulation, accelerations), and batched bindings for each function."""
    from ...compile.codegen import GeneratedSource, template_text

    n = tree.nv  # v's numbers; q's are RT_NQ (a floating base's, ball joints' quaternions)
    starts = [iq for *_, iq, _ in quaternion_slices(tree)]  # ball joints', free flyers' below
    # vector variants (LG_LANES states at once) for batches up to VECTOR_LIMIT coordinates; a
    # long chain's code is big enough that compiling it twice costs minutes, so there the batch
    # runs the scalar functions; a floating base's forward dynamics (the articulated-body
    # algorithm, linear in the bodies) on lanes at any size: the batches that simulate and plan
    # walking robots
    functions = dynamics_functions(tree, parameters, "rt", vector=n <= VECTOR_LIMIT,
                                   vector_forward=tree.floating_base)
    source = "\n".join([
        f"/* lagrangian: recursive dynamics of a tree of {len(tree.joints)} bodies, {n} "
        "coordinates */",
        f"#define LG_N {n}",
        f"#define RT_NQ {tree.nq}",
        "#define LG_M 0",
        # the check of the quaternions in q before the C call: the base's, or every one's
        f"#define RT_FLOATING {int(tree.floating_base or bool(starts))}",
        f"#define RT_QUATERNION_TOLERANCE {QUATERNION_TOLERANCE!r}",
        f"#define LG_NP {len(parameters)}",
        "#define PY_SSIZE_T_CLEAN",
        "#include <Python.h>",
        "#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION",
        "#include <numpy/arrayobject.h>",
        "#include <math.h>",
        "",
        functions,
        """
static void lg_parts(const double *restrict q, const double *restrict v, double t,
                     const double *restrict p, double *restrict M, double *restrict f,
                     double *restrict J, double *restrict g)
{
    (void)t; (void)J; (void)g;
    rt_mass_matrix(q, p, M);
    rt_bias_forces(q, v, p, f);
    for (int i = 0; i < LG_N; i++) f[i] = -f[i];
}

static double lg_energy(const double *restrict q, const double *restrict v, double t,
                        const double *restrict p)
{
    (void)t;
    return rt_kinetic_energy(q, v, p) + rt_potential_energy(q, p);
}

static void lg_residual(const double *restrict q, const double *restrict v, double t,
                        const double *restrict p, double *restrict r)
{
    (void)q; (void)v; (void)t; (void)p; (void)r;
}
""",
        _DECLARE,
        f"#define LG_EXTRA_METHODS {_METHODS}",
        "#define RT_VECTOR_FORWARD " + ("1" if "rt4_forward_dynamics" in functions else "0"),
        "#define RT_VECTOR " + ("1" if "rt4_mass_matrix" in functions else "0"),
        template_text(),
        _THREADS,
        _BOUND,
        _quaternion_check(starts, tree.floating_base) if starts else "",
        _BINDINGS,
    ])
    return GeneratedSource(source=source, parameters=parameters, n=n, m=0)


@lru_cache(maxsize=1)
def _generator_key() -> str:
    """The tree generator itself: a change to any of its files, or to the numerics template its
    module carries (compile/template*.c), is a new module."""
    from ...compile.codegen import TEMPLATES

    here = Path(__file__).parents[1]  # dynamics/: the generator spans emit/, tree/, engine/
    files = ("emit/tree_emitter.py", "emit/tree_algorithms.py", "emit/tree_floating.py",
             "tree/joint_models.py", "emit/tree_c.py", "engine/tree_module.py",
             "engine/batch_threads.c", "engine/bound_call.c", "engine/tree_bindings.c")
    return hashlib.sha256(b"".join((here / f).read_bytes() for f in files)
                          + b"".join(path.read_bytes() for path in TEMPLATES)).hexdigest()


def tree_key(tree: KinematicTree, parameters: tuple[str, ...]) -> str:
    """What the generated module is a function of: the tree's numbers (exact reprs) and the
    parameters' order, and this generator."""
    return "\n".join(["recursive", _generator_key(), repr(parameters), repr(tree)])
