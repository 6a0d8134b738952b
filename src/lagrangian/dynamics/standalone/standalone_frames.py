"""Frame placements and Jacobians of a URDF tree as standalone C99 (libm only, no allocation),
added to standalone.py's tree source: ``<P>_frame_placement(q, frame, T)`` (4 x 4, row-major:
rotation and origin in m, world) and ``<P>_frame_jacobian(q, frame, reference, J)`` (6 x N,
row-major, linear rows first; reference 0 world, 1 local, 2 local_world_aligned, as
Pinocchio's), ``<P>_frame_jacobian_dot_times_v(q, v, frame, reference, out)`` (the classical
acceleration at a = 0), ``<P>_center_of_mass(q, c)`` with its Jacobian and the centroidal
momentum matrix ``<P>_centroidal_momentum_matrix(q, Ag)`` (6 x N, as Pinocchio's ccrba), the
frames by index in ``<P>_frame_names``: frames.py's and centroidal.py's formulas over the
tree's numbers written as static tables, a floating base's free flyer as body 0. A ball joint
(q w x y z, v the child's angular velocity in its axes) and a free flyer below the root (q x y z
qx qy qz qw, v its twist in its axes, linear then angular) place their body by their quaternion
and give three or six columns, the numpy reference's (dynamics/algorithms/frames.py).
"""

from __future__ import annotations

from ...compile.codegen import c_comment_text, c_table
from ...kinds import JointKind
from ...model.tree import KinematicTree
from ..tree.joint_models import joint_model


def _kind(joint) -> int:
    """fr_kind: 0 a joint of one number, 1 a ball joint, 2 a free flyer (the base's or below)."""
    return {JointKind.SPHERICAL: 1, JointKind.FREE_FLYER: 2}.get(joint.kind, 0)


def _first(tree: KinematicTree, joint) -> tuple[int, int]:
    """The joint's first number in the full q and in the full v."""
    if joint.coordinate < 0:  # the floating base: q[0:7], v[0:6]
        return 0, 0
    return (tree.base_nq + joint.coordinate,
            tree.base_nv + tree.velocity_index(joint.coordinate))


def c_string(text: str) -> str:
    """A C string literal of ``text``: letters, digits and _ as they are, every other byte
    (UTF-8) as a three-digit octal escape, so a name from a file never reaches C as code."""
    out = []
    for byte in text.encode("utf-8"):
        char = chr(byte)
        out.append(char if char.isascii() and (char.isalnum() or char == "_") else f"\\{byte:03o}")
    return '"' + "".join(out) + '"'


def frame_declarations(P: str, tree: KinematicTree) -> str:
    """The header's lines for the frames (inside its extern "C" block)."""
    names = c_comment_text(", ".join(f"{k} {f.name}" for k, f in enumerate(tree.frames)),
                           limit=4000)
    U = P.upper()
    return f"""
#define {U}_NF {max(len(tree.frames), 1)}
/* Frames (URDF links and joints), by index: {names}. */
extern const char *const {P}_frame_names[{U}_NF];
/* The frame's placement in the world, T row-major 4 x 4: [R p; 0 1], R frame -> world axes,
   p its origin (m). frame: an index below {U}_NF. */
void {P}_frame_placement(const double *q, int frame, double *T);
/* The frame's Jacobian, J row-major 6 x {U}_N, [v; w] = J v (linear rows first): reference 0
   world (the point at the world's origin moving with the frame), 1 local (the frame's origin,
   its axes), 2 local_world_aligned (its origin, world axes), as Pinocchio's ReferenceFrame. */
void {P}_frame_jacobian(const double *q, int frame, int reference, double *J);
/* J_dot v: the frame's classical acceleration at a = 0, out = [a; w_dot] (m/s^2, rad/s^2),
   reference as for the Jacobian (Pinocchio's getFrameClassicalAcceleration). */
void {P}_frame_jacobian_dot_times_v(const double *q, const double *v, int frame, int reference,
                                    double *out);
/* The moving bodies' centre of mass in the world, c (3, m), and its Jacobian, Jc row-major
   3 x {U}_N (c_dot = Jc v); NaN without moving mass. */
void {P}_center_of_mass(const double *q, double *c);
void {P}_center_of_mass_jacobian(const double *q, double *Jc);
/* The centroidal momentum matrix, Ag row-major 6 x {U}_N: h_g = Ag v, the linear momentum
   (kg m/s) then the angular momentum about the centre of mass (kg m^2/s), world axes, as
   Pinocchio's ccrba; its angular rows NaN without moving mass. */
void {P}_centroidal_momentum_matrix(const double *q, double *Ag);
"""


def frame_functions(P: str, tree: KinematicTree) -> str:
    """The source's tables and functions for the frames (after the dynamics)."""
    joints, frames = tree.joints, tree.frames
    models = [joint_model(j.kind) for j in joints]
    names = ", ".join(c_string(f.name) for f in frames) or '""'
    tables = "\n".join([
        c_table("fr_parent", "int", [j.parent for j in joints]),
        c_table("fr_kind", "int", [_kind(j) for j in joints]),
        c_table("fr_iq", "int", [_first(tree, j)[0] for j in joints]),
        c_table("fr_iv", "int", [_first(tree, j)[1] for j in joints]),
        c_table("fr_turns", "int", [getattr(m, "turns", False) for m in models]),
        c_table("fr_slides", "int", [getattr(m, "slides", False) for m in models]),
        # the slide per unit th: 1 prismatic, the pitch (m/rad) helical (turns and slides)
        c_table("fr_lead", "double", [m.lead(j.pitch) if getattr(m, "slides", False) else 0.0
                                      for m, j in zip(models, joints, strict=True)]),
        c_table("fr_mult", "double", [j.multiplier for j in joints]),
        c_table("fr_off", "double", [j.offset for j in joints]),
        c_table("fr_R0", "double", [[x for row in j.rotation for x in row] for j in joints]),
        c_table("fr_t0", "double", [list(j.translation) for j in joints]),
        c_table("fr_u", "double", [list(j.axis) for j in joints]),
        c_table("fr_m", "double", [j.mass for j in joints]),
        c_table("fr_h", "double", [list(j.first_moment) for j in joints]),
        c_table("fr_J", "double", [[x for row in j.inertia for x in row] for j in joints]),
        c_table("fr_fbody", "int", [f.body for f in frames] or [-1]),
        c_table("fr_fR", "double", [[x for row in f.rotation for x in row] for f in frames]
               or [[1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0]]),
        c_table("fr_ft", "double", [list(f.translation) for f in frames] or [[0.0, 0, 0]]),
    ])
    return f"""
/* -- frames: placements and Jacobians (standalone_frames.py) -- */
#define FR_NB {len(joints)}
#define FR_NV {tree.nv}
{tables}

const char *const {P}_frame_names[{P.upper()}_NF] = {{{names}}};

static void fr_matmul(const double *A, const double *B, double *out)
{{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            out[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
}}

static void fr_apply(const double *R, const double *x, double *out)
{{
    for (int i = 0; i < 3; i++) out[i] = R[3 * i] * x[0] + R[3 * i + 1] * x[1] + R[3 * i + 2] * x[2];
}}

static void fr_cross(const double *a, const double *b, double *out)
{{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}}

/* each body's rotation (body -> world) and origin (m, world) */
static void fr_bodies(const double *q, double (*R)[9], double (*o)[3])
{{
    for (int i = 0; i < FR_NB; i++) {{
        double Rl[9], pl[3], Rj[9], d[3];
        const double *u = fr_u[i];
        for (int j = 0; j < 9; j++) Rj[j] = (j % 4 == 0) ? 1.0 : 0.0;
        for (int j = 0; j < 3; j++) pl[j] = fr_t0[i][j];
        if (fr_kind[i]) {{  /* a unit quaternion: a free flyer's x y z w after its position,
                               a ball joint's w x y z */
            const double *e = q + fr_iq[i];
            const int flyer = fr_kind[i] == 2;
            double x = flyer ? e[3] : e[1], y = flyer ? e[4] : e[2], z = flyer ? e[5] : e[3],
                   w = flyer ? e[6] : e[0];
            double k = 1.0 / (x * x + y * y + z * z + w * w);
            Rj[0] = 1 - 2 * k * (y * y + z * z); Rj[1] = 2 * k * (x * y - z * w);
            Rj[2] = 2 * k * (x * z + y * w); Rj[3] = 2 * k * (x * y + z * w);
            Rj[4] = 1 - 2 * k * (x * x + z * z); Rj[5] = 2 * k * (y * z - x * w);
            Rj[6] = 2 * k * (x * z - y * w); Rj[7] = 2 * k * (y * z + x * w);
            Rj[8] = 1 - 2 * k * (x * x + y * y);
            if (flyer) {{
                fr_apply(fr_R0[i], e, d);
                for (int j = 0; j < 3; j++) pl[j] += d[j];
            }}
        }} else {{
            double th = fr_mult[i] * q[fr_iq[i]] + fr_off[i];
            if (fr_turns[i]) {{  /* Rot(u, th) = u u^T + cos th (1 - u u^T) + sin th [u]x */
                double c = cos(th), s = sin(th);
                double S[9] = {{0.0, -u[2], u[1], u[2], 0.0, -u[0], -u[1], u[0], 0.0}};
                for (int a = 0; a < 3; a++)
                    for (int b = 0; b < 3; b++)
                        Rj[3 * a + b] = u[a] * u[b] + c * ((a == b) - u[a] * u[b]) + s * S[3 * a + b];
            }}
            if (fr_slides[i]) {{
                fr_apply(fr_R0[i], u, d);
                for (int j = 0; j < 3; j++) pl[j] += (fr_lead[i] * th) * d[j];
            }}
        }}
        fr_matmul(fr_R0[i], Rj, Rl);
        int p = fr_parent[i];
        if (p < 0) {{
            for (int j = 0; j < 9; j++) R[i][j] = Rl[j];
            for (int j = 0; j < 3; j++) o[i][j] = pl[j];
        }} else {{
            fr_matmul(R[p], Rl, R[i]);
            fr_apply(R[p], pl, d);
            for (int j = 0; j < 3; j++) o[i][j] = o[p][j] + d[j];
        }}
    }}
}}

static void fr_frame(int f, double (*R)[9], double (*o)[3], double *Rf, double *p)
{{
    int b = fr_fbody[f];
    if (b < 0) {{
        for (int j = 0; j < 9; j++) Rf[j] = fr_fR[f][j];
        for (int j = 0; j < 3; j++) p[j] = fr_ft[f][j];
        return;
    }}
    double d[3];
    fr_matmul(R[b], fr_fR[f], Rf);
    fr_apply(R[b], fr_ft[f], d);
    for (int j = 0; j < 3; j++) p[j] = o[b][j] + d[j];
}}

void {P}_frame_placement(const double *q, int frame, double *T)
{{
    double R[FR_NB][9], o[FR_NB][3], Rf[9], p[3];
    fr_bodies(q, R, o);
    fr_frame(frame, R, o, Rf, p);
    for (int i = 0; i < 3; i++) {{
        for (int j = 0; j < 3; j++) T[4 * i + j] = Rf[3 * i + j];
        T[4 * i + 3] = p[i];
        T[12 + i] = 0.0;
    }}
    T[15] = 1.0;
}}

/* one column [v; w] at the world's origin, world axes, added to J's column c at the point p */
static void fr_column(double *J, int c, const double *v, const double *w, double k)
{{
    for (int j = 0; j < 3; j++) {{
        J[j * FR_NV + c] += k * v[j];
        J[(3 + j) * FR_NV + c] += k * w[j];
    }}
}}

/* joint i's world columns at the origin, [v; w] each (a free flyer's six: its body's axes,
   linear then angular; a ball joint's three angular; else one, its multiplier in), and the first
   velocity number; returns the count */
static int fr_columns(int i, double (*R)[9], double (*o)[3], double (*S)[6], int *first)
{{
    if (fr_kind[i]) {{
        const int flyer = fr_kind[i] == 2, turns = flyer ? 3 : 0;
        for (int c = 0; c < 3; c++) {{
            double e[3] = {{R[i][c], R[i][3 + c], R[i][6 + c]}}, v[3];
            fr_cross(o[i], e, v);
            for (int j = 0; j < 3; j++) {{
                if (flyer) {{ S[c][j] = e[j]; S[c][3 + j] = 0.0; }}
                S[turns + c][j] = v[j]; S[turns + c][3 + j] = e[j];
            }}
        }}
        *first = fr_iv[i];
        return flyer ? 6 : 3;
    }}
    double v[3] = {{0.0, 0.0, 0.0}}, w[3] = {{0.0, 0.0, 0.0}};
    if (fr_turns[i]) {{
        fr_apply(R[i], fr_u[i], w);
        fr_cross(o[i], w, v);
    }}
    if (fr_slides[i]) {{
        double d[3];
        fr_apply(R[i], fr_u[i], d);
        for (int j = 0; j < 3; j++) v[j] += fr_lead[i] * d[j];
    }}
    for (int j = 0; j < 3; j++) {{ S[0][j] = fr_mult[i] * v[j]; S[0][3 + j] = fr_mult[i] * w[j]; }}
    *first = fr_iv[i];
    return 1;
}}

void {P}_frame_jacobian(const double *q, int frame, int reference, double *J)
{{
    double R[FR_NB][9], o[FR_NB][3], Rf[9], p[3];
    for (int j = 0; j < 6 * FR_NV; j++) J[j] = 0.0;
    int b = fr_fbody[frame];
    if (b < 0) return;
    fr_bodies(q, R, o);
    fr_frame(frame, R, o, Rf, p);
    for (int i = b; i >= 0; i = fr_parent[i]) {{  /* world columns: velocity at the origin */
        double S[6][6];
        int first, count = fr_columns(i, R, o, S, &first);
        for (int c = 0; c < count; c++) fr_column(J, first + c, S[c], S[c] + 3, 1.0);
    }}
    if (reference == 0) return;
    for (int c = 0; c < FR_NV; c++) {{  /* at the frame's origin: v(p) = v(0) + w x p */
        double w[3] = {{J[3 * FR_NV + c], J[4 * FR_NV + c], J[5 * FR_NV + c]}}, t[3];
        fr_cross(w, p, t);
        for (int j = 0; j < 3; j++) J[j * FR_NV + c] += t[j];
        if (reference == 1) {{  /* in the frame's axes: R^T */
            double lin[3] = {{J[c], J[FR_NV + c], J[2 * FR_NV + c]}};
            for (int j = 0; j < 3; j++) {{
                J[j * FR_NV + c] = Rf[j] * lin[0] + Rf[3 + j] * lin[1] + Rf[6 + j] * lin[2];
                J[(3 + j) * FR_NV + c] = Rf[j] * w[0] + Rf[3 + j] * w[1] + Rf[6 + j] * w[2];
            }}
        }}
    }}
}}

void {P}_frame_jacobian_dot_times_v(const double *q, const double *v, int frame, int reference,
                                    double *out)
{{
    double R[FR_NB][9], o[FR_NB][3], V[FR_NB][6], A[FR_NB][6], Rf[9], p[3];
    int b = fr_fbody[frame];
    for (int j = 0; j < 6; j++) out[j] = 0.0;
    if (b < 0) return;
    fr_bodies(q, R, o);
    fr_frame(frame, R, o, Rf, p);
    for (int i = 0; i <= b; i++) {{  /* V_i = V_parent + S v, A_i = A_parent + V_i x (S v) */
        double S[6][6], m[6] = {{0.0, 0.0, 0.0, 0.0, 0.0, 0.0}}, t1[3], t2[3], t3[3];
        int first, count = fr_columns(i, R, o, S, &first), parent = fr_parent[i];
        for (int c = 0; c < count; c++)
            for (int j = 0; j < 6; j++) m[j] += S[c][j] * v[first + c];
        for (int j = 0; j < 6; j++) {{
            V[i][j] = (parent < 0 ? 0.0 : V[parent][j]) + m[j];
            A[i][j] = parent < 0 ? 0.0 : A[parent][j];
        }}
        fr_cross(V[i] + 3, m, t1);
        fr_cross(V[i], m + 3, t2);
        fr_cross(V[i] + 3, m + 3, t3);
        for (int j = 0; j < 3; j++) {{ A[i][j] += t1[j] + t2[j]; A[i][3 + j] += t3[j]; }}
    }}
    /* the frame's origin: p_dot = v_O + w x p, p_ddot = a_O + w_dot x p + w x p_dot */
    const double *w = V[b] + 3, *wd = A[b] + 3;
    double pd[3], pdd[3], t[3];
    fr_cross(w, p, t);
    for (int j = 0; j < 3; j++) pd[j] = V[b][j] + t[j];
    fr_cross(wd, p, t);
    for (int j = 0; j < 3; j++) pdd[j] = A[b][j] + t[j];
    fr_cross(w, pd, t);
    for (int j = 0; j < 3; j++) pdd[j] += t[j];
    if (reference == 0) {{  /* the point at the world's origin: p_ddot - w_dot x p - w x (w x p) */
        double wp[3], wwp[3];
        fr_cross(wd, p, t);
        fr_cross(w, p, wp);
        fr_cross(w, wp, wwp);
        for (int j = 0; j < 3; j++) {{ out[j] = pdd[j] - t[j] - wwp[j]; out[3 + j] = wd[j]; }}
    }} else if (reference == 1) {{
        for (int j = 0; j < 3; j++) {{
            out[j] = Rf[j] * pdd[0] + Rf[3 + j] * pdd[1] + Rf[6 + j] * pdd[2];
            out[3 + j] = Rf[j] * wd[0] + Rf[3 + j] * wd[1] + Rf[6 + j] * wd[2];
        }}
    }} else {{
        for (int j = 0; j < 3; j++) {{ out[j] = pdd[j]; out[3 + j] = wd[j]; }}
    }}
}}

/* each subtree's mass and first moment about the world's origin (world axes), leaves first */
static double fr_subtrees(const double *q, double (*R)[9], double (*o)[3], double *M,
                          double (*H)[3])
{{
    double total = 0.0;
    fr_bodies(q, R, o);
    for (int i = 0; i < FR_NB; i++) {{
        double hr[3];
        fr_apply(R[i], fr_h[i], hr);
        M[i] = fr_m[i];
        for (int j = 0; j < 3; j++) H[i][j] = hr[j] + fr_m[i] * o[i][j];
        total += fr_m[i];
    }}
    for (int i = FR_NB - 1; i >= 0; i--) {{
        int parent = fr_parent[i];
        if (parent < 0) continue;
        M[parent] += M[i];
        for (int j = 0; j < 3; j++) H[parent][j] += H[i][j];
    }}
    return total;
}}

void {P}_center_of_mass(const double *q, double *c)
{{
    double R[FR_NB][9], o[FR_NB][3], M[FR_NB], H[FR_NB][3];
    double total = fr_subtrees(q, R, o, M, H);
    for (int j = 0; j < 3; j++) {{
        c[j] = 0.0;
        for (int i = 0; i < FR_NB; i++)
            if (fr_parent[i] < 0) c[j] += H[i][j];
        c[j] = total > 0.0 ? c[j] / total : NAN;
    }}
}}

void {P}_center_of_mass_jacobian(const double *q, double *Jc)
{{
    double R[FR_NB][9], o[FR_NB][3], M[FR_NB], H[FR_NB][3];
    double total = fr_subtrees(q, R, o, M, H);
    for (int j = 0; j < 3 * FR_NV; j++) Jc[j] = 0.0;
    for (int i = 0; i < FR_NB; i++) {{  /* a unit rate moves the subtree: M s_v + s_w x H */
        double S[6][6], t[3];
        int first, count = fr_columns(i, R, o, S, &first);
        for (int c = 0; c < count; c++) {{
            fr_cross(S[c] + 3, H[i], t);
            for (int j = 0; j < 3; j++)
                Jc[j * FR_NV + first + c] += (M[i] * S[c][j] + t[j]) / (total > 0.0 ? total : NAN);
        }}
    }}
}}

void {P}_centroidal_momentum_matrix(const double *q, double *Ag)
{{
    double R[FR_NB][9], o[FR_NB][3], M[FR_NB], H[FR_NB][3], I[FR_NB][9], G[3];
    double total = fr_subtrees(q, R, o, M, H);
    for (int i = 0; i < FR_NB; i++) {{  /* J_O about the world's origin, world axes */
        double RJ[9], hr[3], oo = 0.0, oh = 0.0;
        fr_matmul(R[i], fr_J[i], RJ);
        fr_apply(R[i], fr_h[i], hr);
        for (int j = 0; j < 3; j++) {{ oo += o[i][j] * o[i][j]; oh += o[i][j] * hr[j]; }}
        for (int a = 0; a < 3; a++)  /* R J R^T + m (|o|^2 1 - o o^T) + 2 (o.h) 1 - o h^T - h o^T */
            for (int b = 0; b < 3; b++)
                I[i][3 * a + b] = RJ[3 * a] * R[i][3 * b] + RJ[3 * a + 1] * R[i][3 * b + 1]
                                  + RJ[3 * a + 2] * R[i][3 * b + 2]
                                  + fr_m[i] * ((a == b) * oo - o[i][a] * o[i][b])
                                  + (a == b) * 2.0 * oh - o[i][a] * hr[b] - hr[a] * o[i][b];
    }}
    for (int i = FR_NB - 1; i >= 0; i--)  /* the subtrees' inertias, leaves first */
        if (fr_parent[i] >= 0)
            for (int j = 0; j < 9; j++) I[fr_parent[i]][j] += I[i][j];
    for (int j = 0; j < 6 * FR_NV; j++) Ag[j] = 0.0;
    for (int i = 0; i < FR_NB; i++) {{  /* a unit rate: [M s_v + s_w x h; h x s_v + I s_w] */
        double S[6][6], l[3], k[3], t[3];
        int first, count = fr_columns(i, R, o, S, &first);
        for (int c = 0; c < count; c++) {{
            fr_cross(S[c] + 3, H[i], t);
            for (int j = 0; j < 3; j++) l[j] = M[i] * S[c][j] + t[j];
            fr_cross(H[i], S[c], t);
            fr_apply(I[i], S[c] + 3, k);
            for (int j = 0; j < 3; j++) {{
                Ag[j * FR_NV + first + c] += l[j];
                Ag[(3 + j) * FR_NV + first + c] += k[j] + t[j];
            }}
        }}
    }}
    for (int j = 0; j < 3; j++) {{  /* the centre of mass G */
        G[j] = 0.0;
        for (int i = 0; i < FR_NB; i++)
            if (fr_parent[i] < 0) G[j] += H[i][j];
        G[j] = total > 0.0 ? G[j] / total : NAN;
    }}
    for (int c = 0; c < FR_NV; c++) {{  /* about G: k_G = k_O - G x l */
        double l[3] = {{Ag[c], Ag[FR_NV + c], Ag[2 * FR_NV + c]}}, t[3];
        fr_cross(G, l, t);
        for (int j = 0; j < 3; j++) Ag[(3 + j) * FR_NV + c] -= t[j];
    }}
}}
"""


__all__ = ["c_string", "frame_declarations", "frame_functions"]
