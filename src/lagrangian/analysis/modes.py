"""Natural frequencies, damping ratios and mode shapes of a linear model about an equilibrium.

Undamped, non-gyroscopic models solve the symmetric K phi = omega^2 M phi; models with damping,
gyroscopic coupling, circulatory stiffness or velocity constraints solve the quadratic
eigenproblem through its first-order (state-space) form. Each mode comes from a pair of
eigenvalues s1, s2: natural frequency sqrt(s1 s2) (rad/s), damping ratio -(s1 + s2) / (2 sqrt|s1 s2|),
growth rate max Re s (1/s, > 0 when the mode grows). A pair with s1 s2 <= 0 (a rigid-body or
divergent mode) has zero frequency.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..errors import DerivationError
from ..kinds import ModeKind
from .linearization import LinearModel

# Eigenvalues smaller than this fraction of the largest are zero (rigid-body modes).
ZERO_TOLERANCE = 1e-6
# Real or imaginary parts smaller than this fraction of the largest eigenvalue are round-off.
ROUND_OFF_TOLERANCE = 1e-10
# omega^2 smaller than this fraction of the largest counts as zero in the symmetric problem.
ZERO_SQUARED_TOLERANCE = 1e-10


@dataclass(frozen=True)
class Mode:
    """One mode: frequency (rad/s), damping ratio, growth rate (1/s) and its shape.

    ``shape`` is real, in the user's coordinates, scaled so that the first component of largest
    magnitude is +1; ``complex_shape`` keeps the phases of a damped or gyroscopic mode.
    """

    frequency: float
    damping_ratio: float | None
    growth_rate: float
    shape: dict[str, float]
    complex_shape: tuple[complex, ...]
    eigenvalues: tuple[complex, ...]

    @property
    def frequency_hz(self) -> float:
        return self.frequency / (2 * math.pi)

    @property
    def period(self) -> float | None:
        """2 pi / frequency in s; None for a zero-frequency (rigid-body or divergent) mode."""
        return 2 * math.pi / self.frequency if self.frequency > 0 else None

    @property
    def kind(self) -> ModeKind:
        """'oscillating', 'rigid-body', 'divergent' (grows without oscillating) or 'overdamped'."""
        if self.frequency > 0:
            return ModeKind.OVERDAMPED if (self.damping_ratio or 0) >= 1 and all(
                abs(s.imag) == 0 for s in self.eigenvalues) else ModeKind.OSCILLATING
        return ModeKind.DIVERGENT if self.growth_rate > 0 else ModeKind.RIGID_BODY

    def __repr__(self) -> str:
        shape = ", ".join(f"{k}={v:.4g}" for k, v in self.shape.items())
        zeta = "None" if self.damping_ratio is None else f"{self.damping_ratio:.4g}"
        return (f"Mode({self.frequency:.6g} rad/s, zeta={zeta}, growth={self.growth_rate:.4g} 1/s; "
                f"{shape})")


@dataclass(frozen=True)
class ModalAnalysis:
    """The modes of a linear model, in ascending frequency, with the model they came from."""

    model_name: str
    linear_model: LinearModel
    modes: tuple[Mode, ...]
    stable: bool

    @property
    def equilibrium(self) -> dict[str, float]:
        return self.linear_model.equilibrium

    @property
    def coordinates(self) -> tuple[str, ...]:
        return self.linear_model.coordinates

    @property
    def mass_matrix(self) -> np.ndarray:
        return self.linear_model.mass_matrix

    @property
    def damping_matrix(self) -> np.ndarray:
        return self.linear_model.damping_matrix

    @property
    def stiffness_matrix(self) -> np.ndarray:
        return self.linear_model.stiffness_matrix

    @property
    def natural_frequencies(self) -> np.ndarray:
        """Each mode's frequency in rad/s, ascending."""
        return np.array([m.frequency for m in self.modes])

    @property
    def mode_shapes(self) -> np.ndarray:
        """Columns: each mode's real shape in the user's coordinates."""
        names = self.linear_model.user_coordinates
        return np.array([[m.shape[n] for m in self.modes] for n in names]).reshape(len(names), -1)

    def __iter__(self):
        return iter(self.modes)

    def __len__(self) -> int:
        return len(self.modes)

    def __getitem__(self, index: int) -> Mode:
        return self.modes[index]

    def _repr_latex_(self) -> str:
        """Jupyter: a table of frequency (rad/s), f (Hz), damping ratio and shape per mode."""
        names = self.linear_model.user_coordinates
        heads = " & ".join(sp.latex(sp.Symbol(n)) for n in names)
        rows = []
        for i, m in enumerate(self.modes, 1):
            zeta = "-" if m.damping_ratio is None else f"{m.damping_ratio:.4g}"
            shape = " & ".join(f"{m.shape[n]:.4g}" for n in names)
            rows.append(f"{i} & {m.frequency:.6g} & {m.frequency_hz:.6g} & {zeta} & "
                        f"{m.growth_rate:.4g} & {shape}")
        columns = "r" * (5 + len(names))
        state = "stable" if self.stable else "unstable"
        return (rf"$\begin{{array}}{{{columns}}}"
                rf"\text{{mode}} & \omega\ [\mathrm{{rad/s}}] & f\ [\mathrm{{Hz}}] & \zeta"
                rf" & \sigma\ [1/\mathrm{{s}}] & {heads} \\ \hline "
                + r" \\ ".join(rows) + rf"\end{{array}}\quad\text{{({state})}}$")

    def __repr__(self) -> str:
        about = ", ".join(f"{k}={v:.6g}" for k, v in self.equilibrium.items())
        lines = [f"Modes of {self.model_name!r} about {about} "
                 f"({'stable' if self.stable else 'unstable'}):"]
        lines += [f"  {i}. {m!r}" for i, m in enumerate(self.modes, 1)]
        return "\n".join(lines)


def modal_analysis(linear: LinearModel, model_name: str = "") -> ModalAnalysis:
    """Modes of ``linear``: symmetric eigenproblem when it applies, state-space otherwise."""
    if _symmetric_undamped(linear):
        modes = _symmetric_modes(linear)
    else:
        modes = _state_space_modes(linear)
    modes = tuple(sorted(modes, key=lambda m: (m.frequency, -m.growth_rate)))
    stable = not any(m.growth_rate > 0 for m in modes)
    return ModalAnalysis(model_name, linear, modes, stable)


def is_stable(linear: LinearModel) -> bool:
    """True when no mode of the linear model grows (rigid-body modes are neutral)."""
    return modal_analysis(linear).stable


# -- the two eigenproblems ----------------------------------------------------------------------


def _symmetric_undamped(linear: LinearModel) -> bool:
    K, C = linear.stiffness_matrix, linear.damping_matrix
    scale = max(np.abs(K).max(initial=0.0), 1e-300)
    return (linear.velocity_constraints.size == 0 and not np.any(C)
            and np.allclose(K, K.T, rtol=0, atol=1e-10 * scale))


def _symmetric_modes(linear: LinearModel) -> list[Mode]:
    import scipy.linalg

    M = (linear.mass_matrix + linear.mass_matrix.T) / 2
    K = (linear.stiffness_matrix + linear.stiffness_matrix.T) / 2
    if K.shape[0] == 0:
        return []
    try:
        squared, vectors = scipy.linalg.eigh(K, M)
    except np.linalg.LinAlgError:
        raise DerivationError("the mass matrix is not positive definite at this equilibrium "
                              "(is the kinetic energy complete and positive?)") from None
    for k, w2 in enumerate(squared):
        _require_accurate(k, K @ vectors[:, k] - w2 * (M @ vectors[:, k]),
                          (np.linalg.norm(K, 2) + abs(w2) * np.linalg.norm(M, 2))
                          * np.linalg.norm(vectors[:, k]))
    zero = ZERO_SQUARED_TOLERANCE * max(np.abs(squared).max(), 1e-300)
    modes = []
    for w2, vector in zip(squared, vectors.T, strict=True):
        if abs(w2) <= zero:
            frequency, growth, pair = 0.0, 0.0, (0j, 0j)
        elif w2 > 0:
            frequency, growth = math.sqrt(w2), 0.0
            pair = (1j * frequency, -1j * frequency)
        else:
            frequency, growth = 0.0, math.sqrt(-w2)
            pair = (complex(growth), complex(-growth))
        modes.append(_mode(linear, vector.astype(complex), frequency, 0.0, growth, pair))
    return modes


def _state_space_modes(linear: LinearModel) -> list[Mode]:
    import scipy.linalg

    A = linear.A
    p = linear.mass_matrix.shape[0]
    if A.shape[0] == 0:
        return []
    A = structural_zeros_cleaned(A)
    rows = linear.state_constraints
    Z = None
    if rows.size:
        # Only states that satisfy the linearized velocity constraints are motions: A restricted
        # to that invariant subspace (orthonormal basis Z, A Z = Z (Z^T A Z)); outside it A has
        # spurious s = 0 vectors (a heading offset alone, which the rolling constraint forbids).
        Z = scipy.linalg.null_space(rows)
        A = structural_zeros_cleaned(Z.T @ A @ Z)
    raw, vectors = scipy.linalg.eig(A)
    scale = max(np.abs(raw).max(), 1e-300)
    # Defective zero eigenvalues (rigid-body modes) scatter by ~sqrt(eps); others by ~eps.
    values = np.where(np.abs(raw) <= ZERO_TOLERANCE * scale, 0j, raw)
    noise = ROUND_OFF_TOLERANCE * scale
    values = np.where(np.abs(values.real) <= noise, 1j * values.imag, values)
    values = np.where(np.abs(values.imag) <= noise, values.real + 0j, values)
    values, vectors = verified_eigenpairs(A, values, raw, vectors)
    rigid = _rigid_body_vectors(A, values, p, Z)
    if Z is not None:
        vectors = Z @ vectors
    full = structural_zeros_cleaned(linear.A)
    modes: list[Mode] = []

    def add(vector: np.ndarray, s: complex, s1: complex, s2: complex | None) -> None:
        _require_printed(full, rows, vector, s, len(modes))
        modes.append(_pair_mode(linear, vector, s1, s2))

    real = []
    for k, s in enumerate(values):
        if s.imag > 0:
            add(vectors[:p, k], s, s, np.conj(s))
        elif s.imag == 0:
            real.append(k)
    if rigid is not None:
        # The zero eigenvalues pair up as before (one mode per pair, a lone one with the real
        # value of the most alike shape: a free coordinate with a damper), each mode showing
        # another independent shift.
        zeros = [k for k in real if values[k] == 0]
        real = [k for k in real if values[k] != 0]
        for j in range((len(zeros) + 1) // 2):
            vector = rigid[:p, j % rigid.shape[1]]
            if 2 * j + 1 < len(zeros):
                add(vector, 0j, 0j, 0j)
            elif real:
                likeness = [_likeness(vector, vectors[:p, i]) for i in real]
                add(vector, 0j, 0j, values[real.pop(int(np.argmax(likeness)))])
            else:
                add(vector, 0j, 0j, None)
    # Real eigenvalues pair up by the likeness of their displacement shapes.
    while real:
        k = real.pop(0)
        if not real:
            add(vectors[:p, k], values[k], values[k], None)
            break
        likeness = [_likeness(vectors[:p, k], vectors[:p, j]) for j in real]
        j = real.pop(int(np.argmax(likeness)))
        dominant = k if values[k].real >= values[j].real else j
        add(vectors[:p, dominant], values[dominant], values[k], values[j])
    return modes


def _rigid_body_vectors(A: np.ndarray, values: np.ndarray, p: int, Z: np.ndarray | None
                        ) -> np.ndarray | None:
    """For the zero eigenvalues, a real basis of the null space of A (over the full state) with
    an identity on pivot coordinates (x, y, spin: each shift alone), in the coordinates'
    order; None where there is none or it is larger than the zeros counted. LAPACK's vectors
    for a defective zero are nearly parallel: they repeat one motion, miss others and carry
    ~sqrt(eps) of the generalized vectors, which then show in the printed shape."""
    import scipy.linalg

    count = int(np.sum(values == 0))
    if not count:
        return None
    null = scipy.linalg.null_space(A, rcond=EIGEN_RESIDUAL_TOLERANCE)
    states = null if Z is None else Z @ null
    shifts = states[:p]
    if not 0 < null.shape[1] <= count or np.linalg.matrix_rank(shifts) < null.shape[1]:
        return None
    _, _, pivots = scipy.linalg.qr(shifts.T, pivoting=True)
    pivots = np.sort(pivots[:null.shape[1]])
    canonical = states @ np.linalg.inv(shifts[pivots])
    scale = np.abs(canonical).max(axis=0, keepdims=True)
    canonical[np.abs(canonical) <= 1e-13 * scale] = 0.0
    return canonical


def _require_printed(A: np.ndarray, rows: np.ndarray, shape: np.ndarray, s: complex,
                     k: int) -> None:
    """Refuse a mode whose printed shape u (largest component 1, entries under 1e-12 dropped,
    as printed) does not satisfy A x = s x with x = [u; s u], nor the linearized constraints
    ``rows`` x = 0, to EIGEN_RESIDUAL_TOLERANCE relative."""
    u = normalized_shape(shape)
    u = np.where(np.abs(u) >= 1e-12, u, 0)
    x = np.concatenate([u, s * u])
    size = np.linalg.norm(x)
    _require_accurate(k, A @ x - s * x, np.linalg.norm(A, 2) * size)
    if rows.size:
        _require_accurate(k, rows @ x, np.linalg.norm(rows, 2) * size)


# A printed eigenpair satisfies its equation to this relative residual, or is refused.
EIGEN_RESIDUAL_TOLERANCE = 1e-9


def structural_zeros_cleaned(A: np.ndarray) -> np.ndarray:
    """A with round-off entries (|a| <= 64 eps max|A|, the remains of cancelled symbolic terms
    such as 1e-31 beside entries of 65) set to exact zeros: LAPACK balances and reduces A by
    its entries, and such noise can steer it to eigenvectors that break A's own kinematic rows."""
    A = np.array(A, dtype=float)
    scale = np.abs(A).max(initial=0.0)
    A[np.abs(A) <= 64 * np.finfo(float).eps * scale] = 0.0
    return A


def verified_eigenvectors(A: np.ndarray, values: np.ndarray, vectors: np.ndarray) -> np.ndarray:
    """The eigenvectors with each pair's relative residual |A v - s v| / (|A| |v|) checked; a
    vector that fails is replaced by its projection on the null space of A - s I (or, where
    that is empty, the smallest singular vector), and a pair that still fails is refused
    (DerivationError)."""
    return verified_eigenpairs(A, values, values, vectors)[1]


def verified_eigenpairs(A: np.ndarray, values: np.ndarray, raw: np.ndarray, vectors: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray]:
    """Eigenpairs that satisfy A v = s v to EIGEN_RESIDUAL_TOLERANCE: each with its rounded
    value ``values`` (0 for a rigid-body mode, pure imaginary without damping) where a vector
    satisfies it, else with LAPACK's ``raw`` value; refined vectors where LAPACK's do not."""
    values = np.array(values, dtype=complex)
    vectors = np.array(vectors, dtype=complex)
    norm = max(np.linalg.norm(A, 2), 1e-300)
    for k in range(len(values)):
        candidates = [values[k]] if values[k] == raw[k] else [values[k], raw[k]]
        for s in candidates:
            v = _refined(A, s, vectors[:, k], norm)
            if v is not None:
                values[k], vectors[:, k] = s, v
                break
        else:
            v = vectors[:, k]
            _require_accurate(k, A @ v - raw[k] * v, norm * np.linalg.norm(v))
    return values, vectors


def _refined(A: np.ndarray, s: complex, v: np.ndarray, norm: float) -> np.ndarray | None:
    """v if A v = s v holds, else v projected on the null space of A - s I (a defective
    eigenvalue's vectors carry ~sqrt(eps) of the generalized ones), else the smallest singular
    vector; None where no vector satisfies it."""
    import scipy.linalg

    if _residual(A, s, v, norm) <= EIGEN_RESIDUAL_TOLERANCE:
        return v
    shifted = A - s * np.eye(A.shape[0])
    null = scipy.linalg.null_space(shifted, rcond=1e-12)
    if null.shape[1]:
        projected = null @ (null.conj().T @ v)
        if np.linalg.norm(projected) > 1e-3 * np.linalg.norm(v):
            candidate = projected
        else:
            candidate = null[:, -1]
    else:
        candidate = scipy.linalg.svd(shifted)[2][-1].conj()
    return candidate if _residual(A, s, candidate, norm) <= EIGEN_RESIDUAL_TOLERANCE else None


def _residual(A: np.ndarray, s: complex, v: np.ndarray, norm: float) -> float:
    size = np.linalg.norm(v)
    return float(np.linalg.norm(A @ v - s * v) / (norm * size)) if size else np.inf


def _require_accurate(k: int, residual: np.ndarray, scale: float) -> None:
    relative = np.linalg.norm(residual) / max(scale, 1e-300)
    if not relative <= EIGEN_RESIDUAL_TOLERANCE:
        raise DerivationError(f"eigenpair {k + 1} of the linear model cannot be computed "
                              f"accurately (relative residual {relative:.1e}, more than "
                              f"{EIGEN_RESIDUAL_TOLERANCE:g}): the model is ill-conditioned "
                              "about this point; its mode shapes are not printed")


def _pair_mode(linear: LinearModel, vector: np.ndarray, s1: complex, s2: complex | None) -> Mode:
    if s2 is None:  # a lone real eigenvalue (velocity constraints make the count odd)
        growth = float(s1.real)
        return _mode(linear, vector, 0.0, 0.0 if growth == 0 else None, growth, (s1,))
    product = float((s1 * s2).real)
    total = float((s1 + s2).real)
    growth = float(max(s1.real, s2.real))
    if product > 0:
        frequency = math.sqrt(product)
        zeta: float | None = -total / (2 * frequency)
    else:
        frequency = 0.0
        zeta = -total / (2 * math.sqrt(-product)) if product < 0 else (0.0 if total == 0 else None)
    return _mode(linear, vector, frequency, zeta, growth, (s1, s2))


def _mode(linear: LinearModel, vector: np.ndarray, frequency: float, zeta: float | None,
          growth: float, eigenvalues) -> Mode:
    shape = normalized_shape(linear.basis @ vector)
    names = linear.user_coordinates
    return Mode(
        frequency=float(frequency),
        damping_ratio=None if zeta is None else float(zeta) + 0.0,
        growth_rate=float(growth) + 0.0,
        shape={n: _clean(v.real) for n, v in zip(names, shape, strict=True)},
        complex_shape=tuple(complex(v) if abs(v) >= 1e-12 else 0j for v in shape),
        eigenvalues=tuple(complex(s) for s in eigenvalues),
    )


def normalized_shape(vector: np.ndarray) -> np.ndarray:
    """Scale so that the first component of largest magnitude is exactly +1."""
    vector = np.asarray(vector, dtype=complex)
    magnitude = np.abs(vector)
    if not magnitude.size or magnitude.max() == 0:
        return vector
    reference = int(np.flatnonzero(magnitude >= magnitude.max() * (1 - 1e-9))[0])
    shape = vector / vector[reference]
    shape[reference] = 1.0
    return shape


def _likeness(a: np.ndarray, b: np.ndarray) -> float:
    na, nb = np.linalg.norm(a), np.linalg.norm(b)
    if na == 0 or nb == 0:
        return 1.0 if na == nb else 0.0
    return float(abs(np.vdot(a, b)) / (na * nb))


def _clean(value: float) -> float:
    value = float(value)
    return 0.0 if abs(value) < 1e-12 else value
