/* Forward dynamics' dense algebra at one state (lane), part of derivatives_kernel.c's core
 * (derivatives_c.py puts this text at its DK_FACTOR line, emitted with it on one state and on
 * LG_LANES states): M's factor (along the tree, M = L^T D L, or a dense Cholesky M = L L^T),
 * its solve, M^-1 from it, and the products -M^-1 d tau/dq, -M^-1 d tau/dq_dot. DK_T, DK_FN,
 * DK_C, DK_MASK, DK_FAILED and DK_BITS as the kernel's; n = nv, row-major n x n. */

/* A branching tree (a floating base's legs): M = L^T D L with L unit lower triangular and
 * nonzero only where a column is an ancestor of its row (lambda: each coordinate's parent
 * coordinate, -1 at a root; parents numbered first), which the factor keeps (no fill-in:
 * Featherstone, Rigid Body Dynamics Algorithms, 6.5): its work follows the tree, Solo12's legs
 * factored apart, and no square roots. In place: L below M's diagonal (on the tree's pattern
 * only; the entries off it are neither read nor written), 1 / D_k into inverse; the lanes, as
 * bits, where M is not positive definite (some D_k not > 0). */
static int DK_FN(ltdl_factor)(const dk_tree *tree, DK_T *H, DK_T *inverse)
{
    const int n = tree->nv, *lambda = tree->lambda;
    DK_MASK failed = {0};
    for (int k = n - 1; k >= 0; k--) {
        const DK_T d = H[k * n + k];
        failed |= DK_FAILED(d);
        const DK_T r = 1.0 / d;
        inverse[k] = r;
        for (int i = lambda[k]; i >= 0; i = lambda[i]) {
            const DK_T a = H[k * n + i] * r;
            for (int j = i; j >= 0; j = lambda[j]) H[i * n + j] -= a * H[k * n + j];
            H[k * n + i] = a;
        }
    }
    return DK_BITS(failed);
}

/* x = M^-1 b in b from ltdl_factor's L and 1 / D: L^T y = b from the leaves up, D^-1, then
   L x = y from the root down */
static void DK_FN(ltdl_solve)(const dk_tree *tree, const DK_T *L, const DK_T *inverse, DK_T *b)
{
    const int n = tree->nv, *lambda = tree->lambda;
    for (int i = n - 1; i >= 0; i--)
        for (int j = lambda[i]; j >= 0; j = lambda[j]) b[j] -= L[i * n + j] * b[i];
    for (int i = 0; i < n; i++) b[i] *= inverse[i];
    for (int i = 0; i < n; i++) {
        DK_T x = b[i];
        for (int j = lambda[i]; j >= 0; j = lambda[j]) x -= L[i * n + j] * b[j];
        b[i] = x;
    }
}

/* M^-1 = W D^-1 W^T (both triangles) with W = L^-1 (unit lower, nonzero where a column is an
   ancestor of its row, as L): W's rows from the root down into X (dense, zeros off the
   pattern), then entry (i, j) summed over j's ancestors (those of i among them: W_ik is 0
   where k is not one of i's) */
static void DK_FN(ltdl_inverse)(const dk_tree *tree, const DK_T *L, const DK_T *inverse,
                                DK_T *X, DK_T *Minv)
{
    const int n = tree->nv, *lambda = tree->lambda;
    for (int i = 0; i < n; i++) {
        DK_T *row = X + i * n;
        for (int k = 0; k < n; k++) row[k] = DK_C(0.0);
        row[i] = DK_C(1.0);
        /* W_ik = -sum over m of L_im W_mk (L W = 1; m on i's path, so above i: done) */
        for (int m = lambda[i]; m >= 0; m = lambda[m]) {
            const DK_T a = L[i * n + m];
            row[m] -= a;
            for (int k = lambda[m]; k >= 0; k = lambda[k]) row[k] -= a * X[m * n + k];
        }
    }
    for (int i = 0; i < n; i++)
        for (int j = 0; j <= i; j++) {
            DK_T s = DK_C(0.0);
            for (int k = j; k >= 0; k = lambda[k]) s += X[i * n + k] * inverse[k] * X[j * n + k];
            Minv[i * n + j] = Minv[j * n + i] = s;
        }
}

/* sum of a_k b_k over k < len, from 16 terms in eight partial sums: a single sum's
   multiply-adds wait on each other (the compiler may not reorder them), eight keep the units
   busy (3.5 times faster on a 200-joint chain's factor); an arm's few terms in one */
static inline DK_T DK_FN(dot)(const DK_T *a, const DK_T *b, int len)
{
    if (len < 16) {
        DK_T s = DK_C(0.0);
        for (int k = 0; k < len; k++) s += a[k] * b[k];
        return s;
    }
    DK_T s[8] = {DK_C(0.0), DK_C(0.0), DK_C(0.0), DK_C(0.0),
                 DK_C(0.0), DK_C(0.0), DK_C(0.0), DK_C(0.0)};
    int k = 0;
    for (; k + 8 <= len; k += 8)
        for (int l = 0; l < 8; l++) s[l] += a[k + l] * b[k + l];
    for (; k < len; k++) s[0] += a[k] * b[k];
    return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

/* A chain, or coordinates that move several bodies (mimic): L L^T = M in place (lower
 * triangle), 1 / L_jj into inverse; the lanes (bits) where M is not positive definite. */
static int DK_FN(factor)(int n, DK_T *M, DK_T *inverse)
{
    DK_MASK failed = {0};
    for (int j = 0; j < n; j++) {
        const DK_T *Lj = M + j * n;
        DK_T d = M[j * n + j] - DK_FN(dot)(Lj, Lj, j);
        failed |= DK_FAILED(d);
        d = DK_SQRT(d);
        M[j * n + j] = d;
        inverse[j] = 1.0 / d;
        for (int i = j + 1; i < n; i++)
            M[i * n + j] = (M[i * n + j] - DK_FN(dot)(M + i * n, Lj, j)) * inverse[j];
    }
    return DK_BITS(failed);
}

/* x = M^-1 b from the factor L and 1 / L_jj (b overwritten), a column of L at a time: each
   x_k found is taken from the rest at once (independent multiply-adds), rather than each x_i
   summed over the ones before it (a chain of dependent ones: 4% of a state on Solo12) */
static void DK_FN(solve)(int n, const DK_T *L, const DK_T *inverse, DK_T *b)
{
    for (int k = 0; k < n; k++) {
        const DK_T x = b[k] * inverse[k];
        b[k] = x;
        for (int i = k + 1; i < n; i++) b[i] -= L[i * n + k] * x;
    }
    for (int i = n - 1; i >= 0; i--) {
        const DK_T x = b[i] * inverse[i];
        b[i] = x;
        for (int k = 0; k < i; k++) b[k] -= L[i * n + k] * x;
    }
}

/* M^-1 = L^-T L^-1 (both triangles) from the factor L and 1 / L_jj: X = L^-1 row by row,
   each row a sum of the rows above (X_ic = -sum over k < i of L_ik X_kc / L_ii), then X^T X as
   a sum over X's rows of their outer products: every inner loop along a row (contiguous, no
   chain of dependent sums), where column by column each step was a cache line apart */
static void DK_FN(inverse_from_factor)(int n, const DK_T *M, const DK_T *diagonal, DK_T *X,
                                       DK_T *Minv)
{
    if (n < 16) {  /* an arm's few coordinates: the sums along columns, no loops of a term or
                      two (the rows' loops below spent twice the time on the Panda) */
        for (int i = 0; i < n; i++) {
            for (int c = 0; c < i; c++) {
                DK_T s = DK_C(0.0);
                for (int k = c; k < i; k++) s -= M[i * n + k] * X[k * n + c];
                X[i * n + c] = s * diagonal[i];
            }
            X[i * n + i] = diagonal[i];
        }
        for (int i = 0; i < n; i++)
            for (int j = 0; j <= i; j++) {
                DK_T s = DK_C(0.0);
                for (int k = i; k < n; k++) s += X[k * n + i] * X[k * n + j];
                Minv[i * n + j] = Minv[j * n + i] = s;
            }
        return;
    }
    for (int i = 0; i < n; i++) {
        DK_T *restrict y = X + i * n;
        for (int c = 0; c < i; c++) y[c] = DK_C(0.0);
        for (int k = 0; k < i; k++) {
            const DK_T a = M[i * n + k], *restrict x = X + k * n;
            for (int c = 0; c <= k; c++) y[c] += a * x[c];
        }
        for (int c = 0; c < i; c++) y[c] *= -diagonal[i];
        y[i] = diagonal[i];
    }
    for (int i = 0; i < n; i++)
        for (int j = 0; j <= i; j++) Minv[i * n + j] = DK_C(0.0);
    for (int k = 0; k < n; k++) {
        const DK_T *restrict x = X + k * n;
        for (int i = 0; i <= k; i++) {
            const DK_T a = x[i];
            DK_T *restrict y = Minv + i * n;
            for (int j = 0; j <= i; j++) y[j] += a * x[j];
        }
    }
    for (int i = 0; i < n; i++)
        for (int j = 0; j < i; j++) Minv[j * n + i] = Minv[i * n + j];
}

/* columns j0 .. j0 + w of row i of -A B (n x n) into y: their sums held in registers (w a
   constant where inlined), each step a multiply-add on them, not a load and a store of out */
static inline __attribute__((always_inline)) void DK_FN(row_block)(int n, const DK_T *a,
                                                                  const DK_T *B, DK_T *y,
                                                                  const int w)
{
    DK_T x[32];
    for (int jj = 0; jj < w; jj++) x[jj] = DK_C(0.0);
    for (int k = 0; k < n; k++) {
        const DK_T m = a[k], *row = B + k * n;
        for (int jj = 0; jj < w; jj++) x[jj] -= m * row[jj];
    }
    for (int jj = 0; jj < w; jj++) y[jj] = x[jj];
}

/* rows i0 .. i0 + w of column j of -A B over B's entries e0 .. e1 of the column (rows[e]),
   A symmetric, into out: their sums held in registers (w a constant where inlined) */
static inline __attribute__((always_inline)) void DK_FN(column_block)(
    const dk_tree *tree, const DK_T *A, const DK_T *B, int i0, int j, int e0, int e1, DK_T *out,
    const int w)
{
    const int n = tree->nv;
    DK_T x[8];
    for (int ii = 0; ii < w; ii++) x[ii] = DK_C(0.0);
    for (int e = e0; e < e1; e++) {
        const int k = tree->rows[e];
        const DK_T b = B[k * n + j], *a = A + k * n + i0;
        for (int ii = 0; ii < w; ii++) x[ii] -= a[ii] * b;
    }
    for (int ii = 0; ii < w; ii++) out[(i0 + ii) * n + j] = x[ii];
}

/* out = -A B (n x n), B's columns before ``first`` 0 (a floating base's translation: out's
   too). Row by row, eight columns at a time (one block's sums in registers: on eight lanes
   two blocks would spill past the 32). ``sparse`` (the lanes of a tree whose pattern is a
   quarter or more zeros): column by column over the entries of B that can be nonzero
   (rows[row0[j] ..]: the coordinates on a path through j's joint), A symmetric (M^-1: its
   row k is its column k), eight rows at a time likewise. */
static void DK_FN(minus_product)(const dk_tree *tree, int sparse, const DK_T *A, const DK_T *B,
                                 DK_T *out, int first)
{
    const int n = tree->nv;
    if (sparse) {
        for (int j = 0; j < n; j++) {
            const int e0 = j < first ? tree->row0[j + 1] : tree->row0[j], e1 = tree->row0[j + 1];
            for (int i = 0; i < n; i += 8) {
                switch (n - i < 8 ? n - i : 8) {
                case 1: DK_FN(column_block)(tree, A, B, i, j, e0, e1, out, 1); break;
                case 2: DK_FN(column_block)(tree, A, B, i, j, e0, e1, out, 2); break;
                case 3: DK_FN(column_block)(tree, A, B, i, j, e0, e1, out, 3); break;
                case 4: DK_FN(column_block)(tree, A, B, i, j, e0, e1, out, 4); break;
                case 5: DK_FN(column_block)(tree, A, B, i, j, e0, e1, out, 5); break;
                case 6: DK_FN(column_block)(tree, A, B, i, j, e0, e1, out, 6); break;
                case 7: DK_FN(column_block)(tree, A, B, i, j, e0, e1, out, 7); break;
                default: DK_FN(column_block)(tree, A, B, i, j, e0, e1, out, 8); break;
                }
            }
        }
        return;
    }
    for (int i = 0; i < n; i++) {
        const DK_T *a = A + i * n;
        DK_T *y = out + i * n;
        int j = 0;
        for (; j < first; j++) y[j] = DK_C(0.0);
#if !DK_ON_LANES
        /* one state: 32 columns at a time, four vectors' sums (eight columns, one vector,
           would wait on each multiply-add) */
        for (; j + 32 <= n; j += 32) DK_FN(row_block)(n, a, B + j, y + j, 32);
#endif
        for (; j < n; j += 8) {
            switch (n - j < 8 ? n - j : 8) {
            case 1: DK_FN(row_block)(n, a, B + j, y + j, 1); break;
            case 2: DK_FN(row_block)(n, a, B + j, y + j, 2); break;
            case 3: DK_FN(row_block)(n, a, B + j, y + j, 3); break;
            case 4: DK_FN(row_block)(n, a, B + j, y + j, 4); break;
            case 5: DK_FN(row_block)(n, a, B + j, y + j, 5); break;
            case 6: DK_FN(row_block)(n, a, B + j, y + j, 6); break;
            case 7: DK_FN(row_block)(n, a, B + j, y + j, 7); break;
            default: DK_FN(row_block)(n, a, B + j, y + j, 8); break;
            }
        }
    }
}
