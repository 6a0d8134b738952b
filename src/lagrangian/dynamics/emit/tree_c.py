"""The C text of a tree's dynamics functions for a prefix: scalar, and on vector lanes
for batches (the standalone C and the compiled module share it)."""

from __future__ import annotations

from ...compile.codegen import sincos_kernel
from ...model.tree import KinematicTree
from .tree_algorithms import (
    _articulated,
    _forward_dynamics,
    _inverse_dynamics,
    _kinetic_energy,
    _mass_matrix,
    _potential_energy,
)
from .tree_emitter import _cholesky_solve, _Emitter, _Layout


def _inputs(name: str, n: int) -> list[str]:
    return [f"{name}[{i}]" for i in range(n)]


_SINCOS = r"""
/* sin and cos of x (fdlibm's kernels on [-pi/4, pi/4] after a three-part reduction by pi/2;
   libm beyond |x| = 1e5 and for NaN): within an ulp or two, no library call. Always written
   out where called (lg_sincos_inline: a single frame's placement), or left to the compiler
   (lg_sincos: an unrolled tree's many joints). */
static inline __attribute__((always_inline)) void lg_sincos_inline(double x, double *sine,
                                                                  double *cosine)
{
    if (!(fabs(x) < 1.0e5)) { *sine = sin(x); *cosine = cos(x); return; }
""" + sincos_kernel("double") + r"""
    /* the quadrant k = n mod 4 picks (s, c, -s, -c) by selects: from a table on the stack the
       load waited on the store (a tenth of a frame's placement) */
    const long k = (long)n;
    const double odd_s = (k & 1) ? c : s, odd_c = (k & 1) ? s : c;
    *sine = (k & 2) ? -odd_s : odd_s;
    *cosine = ((k + 1) & 2) ? -odd_c : odd_c;
}

static inline void lg_sincos(double x, double *sine, double *cosine)
{
    lg_sincos_inline(x, sine, cosine);
}
"""


def dynamics_functions(tree: KinematicTree, parameters: tuple[str, ...], prefix: str,
                       storage: str = "static ", vector: bool = False,
                       vector_forward: bool = False) -> str:
    """C99 functions <prefix>_mass_matrix, _bias_forces, _gravity, _inverse_dynamics,
    _forward_dynamics, _kinetic_energy, _potential_energy (the standalone API); with
    ``vector``, also <prefix>4_<name> on LG_LANES states at once (GCC/Clang vector extensions, for
    the compiled module's batches); with ``vector_forward``, <prefix>4_forward_dynamics alone (a
    floating base's batches: one function compiled twice, not seven)."""
    layout = _Layout(tree, parameters)
    n = layout.n
    q, v, a = _inputs("q", layout.nq), _inputs("v", n), _inputs("a", n)
    zeros = [0.0] * n
    P, S = prefix, storage
    R = "const double *restrict"
    sections = [_SINCOS]
    straight = []  # (name, inputs, emitter, [(output index, term)]) for the vector variants

    def function(signature: str, E: _Emitter, outputs, extra: str = "") -> None:
        sections.append(f"{S}{signature}\n{{\n    (void)p;\n{E.body(outputs)}\n{extra}}}\n")

    E = _Emitter()
    entries = _mass_matrix(E, tree, layout, q)
    outputs = []
    for r in range(n):
        for c in range(r + 1):
            outputs.append((r * n + c, entries.get((r, c), 0.0)))
    mirror = "".join(f"    M[{c * n + r}] = M[{r * n + c}];\n"
                     for r in range(n) for c in range(r))
    function(f"void {P}_mass_matrix({R} q, {R} p, double *restrict M)", E,
             [(f"M[{k}]", t) for k, t in outputs], mirror)
    straight.append(("mass_matrix", ("q",), E, outputs))
    for name, args, rates, accels, inputs in (
            ("inverse_dynamics", f"{R} q, {R} v, {R} a, {R} p, double *restrict tau", v, a,
             ("q", "v", "a")),
            ("bias_forces", f"{R} q, {R} v, {R} p, double *restrict tau", v, zeros, ("q", "v")),
            ("gravity", f"{R} q, {R} p, double *restrict tau", zeros, zeros, ("q",))):
        E = _Emitter()
        tau = _inverse_dynamics(E, tree, layout, q, rates, accels)
        function(f"void {P}_{name}({args})", E, [(f"tau[{i}]", t) for i, t in enumerate(tau)])
        straight.append((name, inputs, E, list(enumerate(tau))))
    E = _Emitter()
    T = _kinetic_energy(E, tree, q, v)
    function(f"double {P}_kinetic_energy({R} q, {R} v, {R} p)", E, [("double T", T)],
             "    return T;\n")
    straight.append(("kinetic_energy", ("q", "v"), E, [(0, T)]))
    E = _Emitter()
    V = _potential_energy(E, tree, layout, q)
    function(f"double {P}_potential_energy({R} q, {R} p)", E, [("double V", V)],
             "    return V;\n")
    straight.append(("potential_energy", ("q",), E, [(0, V)]))
    # forward dynamics: the articulated-body algorithm or M = L L^T straight-line (M and b
    # sharing their kinematics), whichever takes fewer operations; loops for a big M
    candidates = []
    tau_in = _inputs("tau", n)
    if _articulated(tree):
        E = _Emitter()
        try:
            qdd = _forward_dynamics(E, tree, layout, q, v, tau_in)
            candidates.append((E.count([(f"qdd[{i}]", x) for i, x in enumerate(qdd)]), E, qdd,
                               "the articulated-body algorithm"))
        except ZeroDivisionError:  # a joint that moves no mass: singular at every state
            pass
    if n <= 24:
        E = _Emitter()
        try:
            mass = _mass_matrix(E, tree, layout, q)
            bias = _inverse_dynamics(E, tree, layout, q, v, zeros)
            qdd = _cholesky_solve(E, mass, [E.sub(t, b) for t, b in zip(tau_in, bias, strict=True)])
            candidates.append((E.count([(f"qdd[{i}]", x) for i, x in enumerate(qdd)]), E, qdd,
                               "M = L L^T"))
        except ZeroDivisionError:
            pass
    qdd = None
    if candidates:
        _, E, qdd, algorithm = min(candidates, key=lambda c: c[0])
    if qdd is not None:
        sections.append(f"/* forward dynamics: {algorithm}, straight-line */")
        check = "".join(f"    if (!isfinite(qdd[{i}])) return -1;\n" for i in range(n))
        function(f"int {P}_forward_dynamics({R} q, {R} v, {R} tau, {R} p, double *restrict qdd)",
                 E, [(f"qdd[{i}]", x) for i, x in enumerate(qdd)], check + "    return 0;\n")
        straight.append(("forward_dynamics", ("q", "v", "tau"), E, list(enumerate(qdd))))
    else:
        sections.append(_cholesky_forward(P, S, R, n))
    if vector or vector_forward:
        sections.append(_VECTOR)
        for name, inputs, E, outs in straight:
            if not vector and name != "forward_dynamics":
                continue
            body = E.body([(f"out[{k}]", t) for k, t in outs], vector=True)
            if name == "mass_matrix":
                body += "\n" + "".join(f"    out[{c * n + r}] = out[{r * n + c}];\n"
                                        for r in range(n) for c in range(r))
            args = ", ".join(f"const lg_v4 *restrict {x}" for x in inputs)
            sections.append(f"static void {P}4_{name}({args}, {R} p, lg_v4 *restrict out)\n"
                            f"{{\n    (void)p;\n{body}\n}}\n")
    return "\n".join(sections)


_VECTOR = r"""
/* Several states at once, each operation on all lanes: eight with AVX-512 (a native build, see
   compiled.NATIVE_CFLAGS; 1.1-1.6 times four lanes' batches on a Zen 4, docs/benchmarks.md),
   four with AVX, else two (one SSE2 instruction; wider vectors without AVX are split through
   memory by the compiler, slower than scalar code). */
#if defined(__AVX512F__)
#define LG_LANES 8
typedef double lg_v4 __attribute__((vector_size(64)));
#elif defined(__AVX__)
#define LG_LANES 4
typedef double lg_v4 __attribute__((vector_size(32)));
#else
#define LG_LANES 2
typedef double lg_v4 __attribute__((vector_size(16)));
#endif
#define LG_V4(x) ((lg_v4){0.0} + (x))
typedef unsigned long long lg_u4 __attribute__((vector_size(sizeof(lg_v4))));

static inline lg_v4 lg_vsqrt(lg_v4 x)
{
    lg_v4 r;
    for (int l = 0; l < LG_LANES; l++) r[l] = sqrt(x[l]);
    return r;
}

/* sine and cosine on every lane, always written out where called (lg_vsincos_inline: a call
   spills every vector register the caller holds, a quarter of a frame's placement on a batch)
   or left to the compiler (lg_vsincos: an unrolled tree's many joints) */
static inline __attribute__((always_inline)) void lg_vsincos_inline(lg_v4 x, lg_v4 *sine,
                                                                    lg_v4 *cosine)
{
    int reducible = 1;
    for (int l = 0; l < LG_LANES; l++) reducible &= fabs(x[l]) < 1.0e5;
    if (!reducible) {
        for (int l = 0; l < LG_LANES; l++) {
            double s, c;
            lg_sincos(x[l], &s, &c);
            (*sine)[l] = s;
            (*cosine)[l] = c;
        }
        return;
    }
""" + sincos_kernel("lg_v4") + r"""
    /* the quadrant k = n mod 4 picks (s, c, -s, -c) by bit operations on all lanes at once:
       odd k swaps sine and cosine, bit 2 of k (of k + 1 for the cosine) flips the sign */
    const lg_u4 k = (lg_u4)shifted;
    const lg_u4 odd = -(k & 1), si = (lg_u4)s, ci = (lg_u4)c;
    *sine = (lg_v4)(((odd & ci) | (~odd & si)) ^ ((k & 2) << 62));
    *cosine = (lg_v4)(((odd & si) | (~odd & ci)) ^ (((k + 1) & 2) << 62));
}

static inline void lg_vsincos(lg_v4 x, lg_v4 *sine, lg_v4 *cosine)
{
    lg_vsincos_inline(x, sine, cosine);
}

/* The lanes' outputs as the states' rows: row l (``width`` doubles at y + l width) gets
   x[i][l], i < width; the LG_LANES rows are contiguous (consecutive states of a batch). A
   transpose, LG_LANES x LG_LANES at a time by shuffles and whole-vector stores, the rest one
   by one: element by element it cost the Panda's A_g a third of its time. */
#if defined(__clang__) || (defined(__GNUC__) && __GNUC__ >= 12)
#define LG_SHUFFLE(a, b, ...) __builtin_shufflevector(a, b, __VA_ARGS__)
static inline void lg_transpose(const lg_v4 *x, lg_v4 *t)
{
#if LG_LANES == 8
    lg_v4 u[8], v[8];
    for (int r = 0; r < 8; r += 2) {
        u[r] = LG_SHUFFLE(x[r], x[r + 1], 0, 8, 2, 10, 4, 12, 6, 14);
        u[r + 1] = LG_SHUFFLE(x[r], x[r + 1], 1, 9, 3, 11, 5, 13, 7, 15);
    }
    for (int r = 0; r < 8; r += 4)
        for (int c = 0; c < 2; c++) {
            v[r + c] = LG_SHUFFLE(u[r + c], u[r + c + 2], 0, 1, 8, 9, 4, 5, 12, 13);
            v[r + c + 2] = LG_SHUFFLE(u[r + c], u[r + c + 2], 2, 3, 10, 11, 6, 7, 14, 15);
        }
    for (int c = 0; c < 4; c++) {
        t[c] = LG_SHUFFLE(v[c], v[c + 4], 0, 1, 2, 3, 8, 9, 10, 11);
        t[c + 4] = LG_SHUFFLE(v[c], v[c + 4], 4, 5, 6, 7, 12, 13, 14, 15);
    }
#elif LG_LANES == 4
    const lg_v4 u0 = LG_SHUFFLE(x[0], x[1], 0, 4, 2, 6), u1 = LG_SHUFFLE(x[0], x[1], 1, 5, 3, 7),
                u2 = LG_SHUFFLE(x[2], x[3], 0, 4, 2, 6), u3 = LG_SHUFFLE(x[2], x[3], 1, 5, 3, 7);
    t[0] = LG_SHUFFLE(u0, u2, 0, 1, 4, 5);
    t[1] = LG_SHUFFLE(u1, u3, 0, 1, 4, 5);
    t[2] = LG_SHUFFLE(u0, u2, 2, 3, 6, 7);
    t[3] = LG_SHUFFLE(u1, u3, 2, 3, 6, 7);
#else
    t[0] = LG_SHUFFLE(x[0], x[1], 0, 2);
    t[1] = LG_SHUFFLE(x[0], x[1], 1, 3);
#endif
}
#endif

/* The inverse: the states' rows (row l: ``width`` doubles at y + l width) as lanes,
   x[i][l] = y[l width + i] (the transpose is its own inverse). */
static inline void lg_lanes(const double *y, int width, lg_v4 *x)
{
    int i = 0;
#ifdef LG_SHUFFLE
    for (; i + LG_LANES <= width; i += LG_LANES) {
        lg_v4 rows[LG_LANES];
        for (int l = 0; l < LG_LANES; l++) __builtin_memcpy(&rows[l], y + l * width + i, sizeof rows[l]);
        lg_transpose(rows, x + i);
    }
#endif
    for (int l = 0; l < LG_LANES; l++)
        for (int j = i; j < width; j++) x[j][l] = y[l * width + j];
}

static inline void lg_rows(const lg_v4 *x, int width, double *y)
{
    int i = 0;
#ifdef LG_SHUFFLE
    for (; i + LG_LANES <= width; i += LG_LANES) {
        lg_v4 t[LG_LANES];
        lg_transpose(x + i, t);
        for (int l = 0; l < LG_LANES; l++) __builtin_memcpy(y + l * width + i, &t[l], sizeof t[l]);
    }
#endif
    for (int l = 0; l < LG_LANES; l++)
        for (int j = i; j < width; j++) y[l * width + j] = x[j][l];
}

/* lg_rows for a batch whose outputs are larger than the caches (batch_threads.c's LG_STREAM_MIN):
   the LG_LANES rows transposed into a buffer, then stored past the caches (non-temporal) into
   y when it is 64-byte aligned. With ordinary stores each line of such an output is first read
   from memory, then written back: Solo12's derivatives for 10^4 states, 52 and 78 MB, took
   12-20% longer so (docs/benchmarks.md). A thread that streamed calls lg_stream_fence before
   its results are read by another. */
#define LG_STREAM_MAX 4096 /* doubles in the LG_LANES rows: the buffer, 32 kB */
#if (defined(__x86_64__) || defined(__i386__)) && defined(__SSE2__) && defined(LG_SHUFFLE)
#include <immintrin.h>
#define LG_STREAMS 1
#endif
static inline void lg_rows_streamed(const lg_v4 *x, int width, double *y)
{
#ifdef LG_STREAMS
#if LG_LANES == 8 && defined(__AVX512F__)
    /* rows of a multiple of four numbers from a 32-byte boundary: the transposed vectors
       stored past the caches as they are, a row's line whole (64 bytes) or in two halves,
       with no buffer between (Solo12's d q_ddot: 4% less per state) */
    if ((((size_t)y) & 31) == 0 && width % 4 == 0) {
        int i = 0;
        for (; i + 8 <= width; i += 8) {
            lg_v4 t[8];
            lg_transpose(x + i, t);
            for (int l = 0; l < 8; l++) {
                double *row = y + l * width + i;
                if ((((size_t)row) & 63) == 0) {
                    _mm512_stream_pd(row, (__m512d)t[l]);
                } else {
                    _mm256_stream_pd(row, _mm512_castpd512_pd256((__m512d)t[l]));
                    _mm256_stream_pd(row + 4, _mm512_extractf64x4_pd((__m512d)t[l], 1));
                }
            }
        }
        if (i < width) {  /* a row's last four numbers: a block padded with zeros */
            lg_v4 pad[8], t[8];
            for (int c = 0; c < 8; c++) pad[c] = c < 4 ? x[i + c] : LG_V4(0.0);
            lg_transpose(pad, t);
            for (int l = 0; l < 8; l++)
                _mm256_stream_pd(y + l * width + i, _mm512_castpd512_pd256((__m512d)t[l]));
        }
        return;
    }
#endif
    const int whole = LG_LANES * width;
    if ((((size_t)y) & 63) == 0 && whole % 8 == 0 && whole <= LG_STREAM_MAX) {
        double t[LG_STREAM_MAX] __attribute__((aligned(64)));
        lg_rows(x, width, t);
        for (int i = 0; i < whole; i += 8) {
#if defined(__AVX512F__)
            _mm512_stream_pd(y + i, _mm512_load_pd(t + i));
#elif defined(__AVX__)
            _mm256_stream_pd(y + i, _mm256_load_pd(t + i));
            _mm256_stream_pd(y + i + 4, _mm256_load_pd(t + i + 4));
#else
            for (int h = 0; h < 8; h += 2) _mm_stream_pd(y + i + h, _mm_load_pd(t + i + h));
#endif
        }
        return;
    }
#endif
    lg_rows(x, width, y);
}

static inline void lg_stream_fence(void)
{
#ifdef LG_STREAMS
    _mm_sfence();
#endif
}
"""



def _cholesky_forward(P: str, S: str, R: str, n: int) -> str:
    """Forward dynamics by Cholesky of M (a tree with mimic joints)."""
    return f"""/* q_ddot = M^-1 (tau - b): Cholesky M = L L^T on the stack; -1 where M is not
   positive definite (a massless branch), else 0. */
{S}int {P}_forward_dynamics({R} q, {R} v, {R} tau, {R} p, double *restrict qdd)
{{
    double L[{n * n}], b[{n}];
    {P}_mass_matrix(q, p, L);
    {P}_bias_forces(q, v, p, b);
    for (int i = 0; i < {n}; i++) qdd[i] = tau[i] - b[i];
    for (int j = 0; j < {n}; j++) {{
        double d = L[j * {n} + j];
        for (int k = 0; k < j; k++) d -= L[j * {n} + k] * L[j * {n} + k];
        if (!(d > 0.0)) return -1;
        d = sqrt(d);
        L[j * {n} + j] = d;
        const double inv = 1.0 / d;
        for (int i = j + 1; i < {n}; i++) {{
            double s = L[i * {n} + j];
            for (int k = 0; k < j; k++) s -= L[i * {n} + k] * L[j * {n} + k];
            L[i * {n} + j] = s * inv;
        }}
    }}
    for (int i = 0; i < {n}; i++) {{
        double s = qdd[i];
        for (int k = 0; k < i; k++) s -= L[i * {n} + k] * qdd[k];
        qdd[i] = s / L[i * {n} + i];
    }}
    for (int i = {n} - 1; i >= 0; i--) {{
        double s = qdd[i];
        for (int k = i + 1; k < {n}; k++) s -= L[k * {n} + i] * qdd[k];
        qdd[i] = s / L[i * {n} + i];
    }}
    return 0;
}}
"""
