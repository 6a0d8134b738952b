/* The 3-vector algebra of every engine module, once (spatial.h): as macros, so that each takes
   a table's doubles or a state's numbers (SP_T: one double, or LG_LANES of them, the including
   module's number type) in any place, and a module's core compiled twice (one state, then the
   lanes) uses them unchanged. Each result is held in temporaries first, so an output may be an
   input. Row-major 3x3 matrices. */
#define SP_CROSS(a, b, c) do {  /* c = a x b */                      \
        SP_T c0_ = (a)[1] * (b)[2] - (a)[2] * (b)[1];                \
        SP_T c1_ = (a)[2] * (b)[0] - (a)[0] * (b)[2];                \
        SP_T c2_ = (a)[0] * (b)[1] - (a)[1] * (b)[0];                \
        (c)[0] = c0_; (c)[1] = c1_; (c)[2] = c2_;                    \
    } while (0)
#define SP_APPLY(R, x, y) do {  /* y = R x */                                        \
        SP_T y0_ = (R)[0] * (x)[0] + (R)[1] * (x)[1] + (R)[2] * (x)[2];              \
        SP_T y1_ = (R)[3] * (x)[0] + (R)[4] * (x)[1] + (R)[5] * (x)[2];              \
        SP_T y2_ = (R)[6] * (x)[0] + (R)[7] * (x)[1] + (R)[8] * (x)[2];              \
        (y)[0] = y0_; (y)[1] = y1_; (y)[2] = y2_;                                    \
    } while (0)
#define SP_APPLY_T(R, x, y) do {  /* y = R^T x */                                    \
        SP_T y0_ = (R)[0] * (x)[0] + (R)[3] * (x)[1] + (R)[6] * (x)[2];              \
        SP_T y1_ = (R)[1] * (x)[0] + (R)[4] * (x)[1] + (R)[7] * (x)[2];              \
        SP_T y2_ = (R)[2] * (x)[0] + (R)[5] * (x)[1] + (R)[8] * (x)[2];              \
        (y)[0] = y0_; (y)[1] = y1_; (y)[2] = y2_;                                    \
    } while (0)
#define SP_DOT(a, b) ((a)[0] * (b)[0] + (a)[1] * (b)[1] + (a)[2] * (b)[2])
#define SP_MATMUL(A, B, C) do {  /* C = A B; C neither A nor B */                    \
        for (int i_ = 0; i_ < 3; i_++)                                               \
            for (int j_ = 0; j_ < 3; j_++)                                           \
                (C)[3 * i_ + j_] = (A)[3 * i_] * (B)[j_] + (A)[3 * i_ + 1] * (B)[3 + j_] \
                                   + (A)[3 * i_ + 2] * (B)[6 + j_];                  \
    } while (0)
