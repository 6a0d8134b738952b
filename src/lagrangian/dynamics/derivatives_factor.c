/* Forward dynamics' dense algebra at one state (lane), part of derivatives_kernel.c's core
 * (derivatives_c.py puts this text at its DK_FACTOR line, emitted with it on one state and on
 * LG_LANES states): M's factor (along the tree, M = L^T D L, or a dense Cholesky M = L L^T),
 * its solve, M^-1 from it, and the products -M^-1 d tau/dq, -M^-1 d tau/dq_dot. DK_T, DK_FN,
 * DK_C, DK_MASK, DK_FAILED, DK_BITS and the unrolling macros as the kernel's. */

#if DK_LTDL
/* A branching tree (a floating base's legs): M = L^T D L with L unit lower triangular and
 * nonzero only where a column is an ancestor of its row (dk_lambda: each coordinate's parent
 * coordinate, -1 at a root; parents numbered first), which the factor keeps (no fill-in:
 * Featherstone, Rigid Body Dynamics Algorithms, 6.5). Its work follows the tree: Solo12's legs
 * are factored apart, a third of the dense Cholesky's multiply-adds and no square roots.
 * derivatives_c.py writes the three functions out for the tree, its indices constants (loops
 * over dk_lambda's chains ran slower than the dense Cholesky): factor(H, inverse), in place
 * (L below M's diagonal, 1 / D_k into inverse; the lanes, as bits, where M is not positive
 * definite: some D_k not > 0); solve(L, inverse, b), x = M^-1 b in b (L^T w = b from the
 * leaves up, D^-1, L x = w from the root); inverse_from_factor(L, inverse, Minv), M^-1 =
 * W D^-1 W^T in both triangles, W = L^-1 (unit, nonzero where L is), entry (i, j) summed over
 * the common ancestors of i and j. */
DK_TREE_FACTOR
#else
/* L L^T = M in place (lower triangle), 1 / L_jj into inverse; the lanes (bits) where M is not
 * positive definite */
static int DK_FN(factor)(DK_T *M, DK_T *inverse)
{
    DK_MASK failed = {0};
    DK_UNROLL
    for (int j = 0; j < DK_NV; j++) {
        DK_T d = M[j * DK_NV + j];
        DK_UNROLL
        for (int k = 0; k < j; k++) d -= M[j * DK_NV + k] * M[j * DK_NV + k];
        failed |= DK_FAILED(d);
        d = DK_SQRT(d);
        M[j * DK_NV + j] = d;
        inverse[j] = 1.0 / d;
        DK_UNROLL
        for (int i = j + 1; i < DK_NV; i++) {
            DK_T s = M[i * DK_NV + j];
            DK_UNROLL
            for (int k = 0; k < j; k++) s -= M[i * DK_NV + k] * M[j * DK_NV + k];
            M[i * DK_NV + j] = s * inverse[j];
        }
    }
    return DK_BITS(failed);
}

/* x = M^-1 b from the factor L and 1 / L_jj (b overwritten), a column of L at a time: each
   x_k found is taken from the rest at once (independent multiply-adds), rather than each x_i
   summed over the ones before it (a chain of dependent ones: 4% of a state on Solo12) */
static void DK_FN(solve)(const DK_T *L, const DK_T *inverse, DK_T *b)
{
    DK_UNROLL
    for (int k = 0; k < DK_NV; k++) {
        const DK_T x = b[k] * inverse[k];
        b[k] = x;
        DK_UNROLL
        for (int i = k + 1; i < DK_NV; i++) b[i] -= L[i * DK_NV + k] * x;
    }
    DK_UNROLL
    for (int i = DK_NV - 1; i >= 0; i--) {
        const DK_T x = b[i] * inverse[i];
        b[i] = x;
        DK_UNROLL
        for (int k = 0; k < i; k++) b[k] -= L[i * DK_NV + k] * x;
    }
}

/* M^-1 = L^-T L^-1 (both triangles) from the factor L and 1 / L_jj: X = L^-1 row by row (the
   columns of a row independent: no chain of dependent operations as in solving column by
   column), then X^T X */
static void DK_FN(inverse_from_factor)(const DK_T *M, const DK_T *diagonal, DK_T *Minv)
{
    DK_T X[DK_NV * DK_NV];
    DK_UNROLL
    for (int i = 0; i < DK_NV; i++) {
        DK_UNROLL
        for (int c = 0; c < i; c++) {
            DK_T s = DK_C(0.0);
            DK_UNROLL
            for (int k = c; k < i; k++) s -= M[i * DK_NV + k] * X[k * DK_NV + c];
            X[i * DK_NV + c] = s * diagonal[i];
        }
        X[i * DK_NV + i] = diagonal[i];
    }
    DK_UNROLL
    for (int i = 0; i < DK_NV; i++)
        DK_UNROLL
        for (int j = 0; j <= i; j++) {
            DK_T s = DK_C(0.0);
            DK_UNROLL
            for (int k = i; k < DK_NV; k++) s += X[k * DK_NV + i] * X[k * DK_NV + j];
            Minv[i * DK_NV + j] = Minv[j * DK_NV + i] = s;
        }
}

#endif

/* out = -A B (DK_NV x DK_NV), B's columns before ``first`` 0 (a floating base's translation:
   out's too). Row by row (a row's sums held in registers), one product at a time: two rows'
   sums at once (36 vectors on eight lanes) spill past the 32 registers, and each step then
   waits on a store (a fifth of Solo12's state). With DK_SPARSE, on the lanes, column by
   column over the entries of B that can be nonzero (dk_rows[dk_row0[j] ..]: the coordinates
   on a path through j's joint), A symmetric (M^-1: its row k is its column k); one state's
   rows stay dense (the compiler vectorizes them along j: 10% faster per call on Solo12). */
static void DK_FN(minus_product)(const DK_T *A, const DK_T *B, DK_T *out, int first)
{
#if DK_SPARSE && DK_ON_LANES
    for (int j = 0; j < DK_NV; j++) {
        DK_T x[DK_NV];
        DK_UNROLL_ROW
        for (int i = 0; i < DK_NV; i++) x[i] = DK_C(0.0);
        for (int e = j < first ? dk_row0[j + 1] : dk_row0[j]; e < dk_row0[j + 1]; e++) {
            const int k = dk_rows[e];
            const DK_T b = B[k * DK_NV + j], *a = A + k * DK_NV;
            DK_UNROLL_ROW
            for (int i = 0; i < DK_NV; i++) x[i] -= a[i] * b;
        }
        DK_UNROLL_ROW
        for (int i = 0; i < DK_NV; i++) out[i * DK_NV + j] = x[i];
    }
#else
    for (int i = 0; i < DK_NV; i++) {
        DK_T x[DK_NV];
        DK_UNROLL_ROW
        for (int j = 0; j < DK_NV; j++) x[j] = DK_C(0.0);
        DK_UNROLL
        for (int k = 0; k < DK_NV; k++) {
            const DK_T m = A[i * DK_NV + k];
            DK_UNROLL_ROW
            for (int j = first; j < DK_NV; j++) x[j] -= m * B[k * DK_NV + j];
        }
        DK_UNROLL_ROW
        for (int j = 0; j < DK_NV; j++) out[i * DK_NV + j] = x[j];
    }
#endif
}
