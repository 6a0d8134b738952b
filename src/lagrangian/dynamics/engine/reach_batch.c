/* The batches of reach_kernel.c's functions, to which reach_bindings.c's Python functions hand
 * arrays (..., n) of float64 and an output row per state. A batch runs on threads that take
 * blocks of RK_BLOCK states from a shared counter (as the tree module's batches), LG_LANES
 * states at a time through the rk4_ functions (the same formulas on vector lanes), the block's
 * last few one by one.
 *
 * A state whose inputs (q, v, a, its wrenches) are not all finite gets a row of NaN, as the
 * tree module's functions give (a NaN in one leg would otherwise leave the other legs' numbers
 * finite); job.bad counts them for the caller's one DynamicsWarning. */

#define RK_PTHREADS LG_PTHREADS  /* batch_threads.c, above this text */
#define RK_MAX_THREADS LG_MAX_THREADS
#define RK_THREAD_STATES 1024  /* fewer per thread: starting it costs more than it saves (A_g
                                  on the Panda, 1000 states: 43 us on one thread, 70 on two) */
#define RK_BLOCK 64  /* a multiple of LG_LANES: only the batch's last states run one by one */
#define RK_STACK_BYTES 32768  /* a thread's workspaces up to this on its stack: no allocation
                                 per call (one state of up to about 60 bodies; a malloc was a
                                 fifth of a single J_dot v's call) */

enum { RK_DRIFT, RK_CENTROIDAL, RK_WRENCH, RK_CORIOLIS, RK_INVERSE, RK_PLACEMENT, RK_JACOBIAN,
       RK_COM, RK_COM_JACOBIAN };

/* one batch's inputs and output; ``next`` the shared counter of states handed out */
typedef struct {
    const rk_model *md;
    int kind, frame, ref, nw, stream;  /* stream: rows stored past the caches (lg_rows_streamed) */
    const double *q, *v, *a, *up;
    const int *frames;
    const double *const *w;
    const int *wshared;
    double sign, *y;
    npy_intp count, *next, bad;  /* bad: the NaN rows this job (thread) wrote */
} rk_job;

/* the numbers of a state's output row */
static int rk_width(const rk_model *md, int kind)
{
    return kind == RK_DRIFT ? 6 : kind == RK_CENTROIDAL || kind == RK_JACOBIAN ? 6 * md->nv
           : kind == RK_CORIOLIS ? md->nv * md->nv : kind == RK_PLACEMENT ? 16
           : kind == RK_COM ? 3 : kind == RK_COM_JACOBIAN ? 3 * md->nv : md->nv;
}

static void rk_blank(const rk_job *job, npy_intp k)
{
    const int width = rk_width(job->md, job->kind);
    for (int i = 0; i < width; i++) job->y[k * width + i] = NAN;
}

/* whether x[0..width) are all finite: none with every exponent bit set, by an integer OR the
 * compiler vectorizes (a sum of x - x chains one addition after another: 60 ns of the 0.8 us
 * of a single ID with a wrench on Solo12) */
static int rk_finite_row(const double *x, int width)
{
    const unsigned long long exponent = 0x7ff0000000000000ULL;
    unsigned long long spoilt = 0;
    for (int i = 0; i < width; i++) {
        unsigned long long bits;
        __builtin_memcpy(&bits, x + i, sizeof bits);
        spoilt |= (bits & exponent) == exponent;
    }
    return !spoilt;
}

/* whether state k's inputs are all finite (and, adding wrenches, its row after the sum) */
static int rk_finite(const rk_job *job, npy_intp k)
{
    const rk_model *md = job->md;
    const int kind = job->kind;
    int fine = rk_finite_row(job->q + k * md->nq, md->nq);
    if (kind == RK_DRIFT || kind == RK_CORIOLIS || kind == RK_INVERSE)
        fine &= rk_finite_row(job->v + k * md->nv, md->nv);
    if (kind == RK_INVERSE) fine &= rk_finite_row(job->a + k * md->nv, md->nv);
    const int nw = kind == RK_WRENCH ? 1 : kind == RK_INVERSE ? job->nw : 0;
    for (int i = 0; i < nw; i++) fine &= rk_finite_row(job->w[i] + (job->wshared[i] ? 0 : 6 * k), 6);
    return fine;
}

/* state k alone (in ``work``: rk_work_size bytes); 1 where its row came out NaN */
static int rk_state(const rk_job *job, npy_intp k, rk_work *work)
{
    const rk_model *md = job->md;
    const double *q = job->q + k * md->nq;
    if (!rk_finite(job, k)) {
        rk_blank(job, k);
        return 1;
    }
    switch (job->kind) {
    case RK_DRIFT:
        rk_drift(md, work, q, job->v + k * md->nv, job->frame, job->ref, job->y + 6 * k);
        break;
    case RK_CENTROIDAL: rk_centroidal(md, work, q, job->y + 6 * md->nv * k); break;
    case RK_WRENCH: {
        double *tau = work->x, *y = job->y + md->nv * k;  /* x: a wrench has no arrays of its own */
        rk_wrench(md, work, q, job->frame, job->w[0] + (job->wshared[0] ? 0 : 6 * k), tau);
        for (int j = 0; j < md->nv; j++) y[j] += job->sign * tau[j];
        break;
    }
    case RK_CORIOLIS:
        rk_coriolis(md, work, q, job->v + k * md->nv, job->y + md->nv * md->nv * k);
        break;
    case RK_PLACEMENT: rk_placement(md, work, q, job->frame, job->y + 16 * k); break;
    case RK_JACOBIAN:
        rk_jacobian(md, work, q, job->frame, job->ref, job->y + 6 * md->nv * k);
        break;
    case RK_COM: rk_com(md, work, q, job->y + 3 * k); break;
    case RK_COM_JACOBIAN: rk_com_jacobian(md, work, q, job->y + 3 * md->nv * k); break;
    case RK_INVERSE: {
        double w[RK_MAX_WRENCHES][6];
        for (int i = 0; i < job->nw; i++)
            for (int j = 0; j < 6; j++) w[i][j] = job->w[i][(job->wshared[i] ? 0 : 6 * k) + j];
        rk_inverse(md, work, q, job->v + k * md->nv, job->a + k * md->nv, job->up, job->nw,
                   job->frames, (const double (*)[6])w, job->y + md->nv * k);
        break;
    }
    }
    /* a row that was NaN before the wrench's forces were added (the caller's inverse dynamics
       of a state not finite) stays NaN whole */
    if (job->kind == RK_WRENCH && !rk_finite_row(job->y + md->nv * k, md->nv)) {
        rk_blank(job, k);
        return 1;
    }
    return 0;
}

/* lanes' inputs: rows k .. k + LG_LANES - 1 of x (``width`` numbers a row) as vectors */
static inline void rk_gather(const double *x, npy_intp k, int width, lg_v4 *out)
{
    const double *y = x + k * width;
    int i = 0;
#ifdef LG_SHUFFLE
    for (; i + LG_LANES <= width; i += LG_LANES) {
        lg_v4 rows[LG_LANES];
        for (int l = 0; l < LG_LANES; l++)
            __builtin_memcpy(&rows[l], y + l * width + i, sizeof rows[l]);
        lg_transpose(rows, out + i);
    }
#endif
    /* the rest a vector at a time, built in a register: lane by lane into memory, each vector's
       load then waits on its lanes' stores (lg_lanes': 5-7% of the Panda's CoM and J_dot v
       batches) */
    for (; i < width; i++) {
        lg_v4 lanes;
        for (int l = 0; l < LG_LANES; l++) lanes[l] = y[l * width + i];
        out[i] = lanes;
    }
}

/* lanes' outputs into rows k .. k + LG_LANES - 1 of y (``width`` numbers a row): y = x
 * (past the caches where ``stream``), or y += sign x where ``add`` */
static inline void rk_scatter(const lg_v4 *x, npy_intp k, int width, double *y, int add,
                              double sign, int stream)
{
    if (!add) {
        if (stream) lg_rows_streamed(x, width, y + k * width);
        else lg_rows(x, width, y + k * width);
        return;
    }
    for (int l = 0; l < LG_LANES; l++) {
        double *row = y + (k + l) * width;
        for (int i = 0; i < width; i++) row[i] += sign * x[i][l];
    }
}

/* x - x summed over an input's vectors: 0 in the lanes where it is finite (two sums, so that
   the additions do not wait one for another) */
static inline void rk_spoil(const lg_v4 *x, int width, lg_v4 *spoilt)
{
    lg_v4 odd = LG_V4(0.0);
    int i = 0;
    for (; i + 1 < width; i += 2) {
        *spoilt += x[i] - x[i];
        odd += x[i + 1] - x[i + 1];
    }
    if (i < width) odd += x[i] - x[i];
    *spoilt += odd;
}

/* a thread's workspaces: one state's, and the lanes' with their inputs q, v, a and output (of
 * the widest row, rk_out4 vectors) */
typedef struct {
    rk_work one;
    rk4_work four;
    lg_v4 *q, *v, *a, *out;
} rk_space;

static size_t rk_out4(const rk_model *md)
{
    const size_t nv = (size_t)md->nv;
    return nv * nv > 6 * nv ? nv * nv : 6 * nv > 16 ? 6 * nv : 16;
}

/* the bytes of a thread's workspaces (the lanes' where ``lanes``) */
static size_t rk_space_size(const rk_model *md, int lanes)
{
    size_t size = RK_ROUND(rk_work_size(md));
    if (lanes)
        size += RK_ROUND(rk4_work_size(md))
                + RK_ROUND((size_t)(md->nq + 2 * md->nv) * sizeof(lg_v4))
                + RK_ROUND(rk_out4(md) * sizeof(lg_v4));
    return size;
}

static void rk_space_at(const rk_model *md, int lanes, char *block, rk_space *space)
{
    rk_work_at(md, block, &space->one);
    if (!lanes) return;
    block += RK_ROUND(rk_work_size(md));
    rk4_work_at(md, block, &space->four);
    block += RK_ROUND(rk4_work_size(md));
    space->q = (lg_v4 *)block;
    space->v = space->q + md->nq;
    space->a = space->v + md->nv;
    block += RK_ROUND((size_t)(md->nq + 2 * md->nv) * sizeof(lg_v4));
    space->out = (lg_v4 *)block;
}

/* states k .. k + LG_LANES - 1 at once (rk4_*); the count of NaN rows written */
static int rk_lanes(const rk_job *job, npy_intp k, rk_space *space)
{
    const rk_model *md = job->md;
    rk4_work *work = &space->four;
    lg_v4 *q = space->q, *v = space->v, *out = space->out, spoilt = LG_V4(0.0);
    rk_gather(job->q, k, md->nq, q);
    rk_spoil(q, md->nq, &spoilt);
    if (k + 2 * LG_LANES <= job->count) {  /* the next states' q and v, fetched meanwhile: a
                                              load of this group's was a sixth of C's time */
        const char *next = (const char *)(job->q + (k + LG_LANES) * md->nq);
        for (size_t b = 0; b < LG_LANES * md->nq * sizeof(double); b += 64)
            __builtin_prefetch(next + b, 0, 3);
        if (job->v && job->kind != RK_CENTROIDAL && job->kind != RK_WRENCH) {
            next = (const char *)(job->v + (k + LG_LANES) * md->nv);
            for (size_t b = 0; b < LG_LANES * md->nv * sizeof(double); b += 64)
                __builtin_prefetch(next + b, 0, 3);
        }
    }
    if (!job->stream) {  /* the rows these states will fill, fetched for writing while the
                            kernel computes (as the derivatives module's): a batch's outputs are
                            seldom in cache */
        const int width = rk_width(md, job->kind);
        const char *y = (const char *)(job->y + k * width);
        for (size_t b = 0; b < LG_LANES * width * sizeof(double); b += 64)
            __builtin_prefetch(y + b, 1, 2);
    }
    switch (job->kind) {
    case RK_DRIFT:
        rk_gather(job->v, k, md->nv, v);
        rk_spoil(v, md->nv, &spoilt);
        rk4_drift(md, work, q, v, job->frame, job->ref, out);
        break;
    case RK_CENTROIDAL:
        rk4_centroidal(md, work, q, out);
        break;
    case RK_PLACEMENT:
        rk4_placement(md, work, q, job->frame, out);
        break;
    case RK_JACOBIAN:
        rk4_jacobian(md, work, q, job->frame, job->ref, out);
        break;
    case RK_COM:
        rk4_com(md, work, q, out);
        break;
    case RK_COM_JACOBIAN:
        rk4_com_jacobian(md, work, q, out);
        break;
    case RK_WRENCH: {
        lg_v4 w[6];
        if (job->wshared[0])
            for (int j = 0; j < 6; j++) w[j] = LG_V4(job->w[0][j]);
        else
            rk_gather(job->w[0], k, 6, w);
        rk_spoil(w, 6, &spoilt);
        rk4_wrench(md, work, q, job->frame, w, out);
        rk_scatter(out, k, md->nv, job->y, 1, job->sign, job->stream);
        break;
    }
    case RK_CORIOLIS:
        rk_gather(job->v, k, md->nv, v);
        rk_spoil(v, md->nv, &spoilt);
        rk4_coriolis(md, work, q, v, out);
        break;
    case RK_INVERSE: {
        lg_v4 *a = space->a, w[RK_MAX_WRENCHES][6];
        rk_gather(job->v, k, md->nv, v);
        rk_gather(job->a, k, md->nv, a);
        rk_spoil(v, md->nv, &spoilt);
        rk_spoil(a, md->nv, &spoilt);
        for (int i = 0; i < job->nw; i++) {
            if (job->wshared[i])
                for (int j = 0; j < 6; j++) w[i][j] = LG_V4(job->w[i][j]);
            else
                rk_gather(job->w[i], k, 6, w[i]);
            rk_spoil(w[i], 6, &spoilt);
        }
        rk4_inverse(md, work, q, v, a, job->up, job->nw, job->frames, (const lg_v4 (*)[6])w, out);
        break;
    }
    }
    /* the lanes' rows out (the wrench's added in place above) */
    if (job->kind != RK_WRENCH)
        rk_scatter(out, k, rk_width(md, job->kind), job->y, 0, 0.0, job->stream);
    int bad = 0;
    for (int l = 0; l < LG_LANES; l++)
        if (spoilt[l] != 0.0 || (job->kind == RK_WRENCH
                                 && !rk_finite_row(job->y + md->nv * (k + l), md->nv))) {
            rk_blank(job, k + l);
            bad++;
        }
    return bad;
}

/* a thread's work: blocks of RK_BLOCK states taken in turn until none is left, so that a
 * thread slowed by the machine's other work takes fewer rather than holding the others up */
static void *rk_run(void *argument)
{
    rk_job *job = (rk_job *)argument;
    /* sized from the model: on the stack where small, else on the heap (a large tree's lanes'
       work is more than a stack) */
    const int lanes = job->count >= LG_LANES;
    const size_t size = rk_space_size(job->md, lanes);
    _Alignas(64) char stack[RK_STACK_BYTES];
    rk_space space;
    char *block = size <= sizeof stack ? stack : aligned_alloc(64, size);
    job->bad = 0;
    if (!block) return NULL;
    rk_space_at(job->md, lanes, block, &space);
    for (;;) {
#if RK_PTHREADS
        const npy_intp k0 = __atomic_fetch_add(job->next, RK_BLOCK, __ATOMIC_RELAXED);
#else
        const npy_intp k0 = *job->next;
        *job->next += RK_BLOCK;
#endif
        if (k0 >= job->count) break;
        const npy_intp k1 = k0 + RK_BLOCK < job->count ? k0 + RK_BLOCK : job->count;
        npy_intp k = k0;
        for (; lanes && k + LG_LANES <= k1; k += LG_LANES) job->bad += rk_lanes(job, k, &space);
        for (; k < k1; k++) job->bad += rk_state(job, k, &space.one);
    }
    if (block != stack) free(block);
    if (job->stream) lg_stream_fence();
    return NULL;
}

/* how many threads a batch of ``count`` states runs on (batch_threads.c) */
static int rk_threads(npy_intp count) { return lg_threads(count, RK_THREAD_STATES); }

/* the batch over threads, without the GIL; 0 with MemoryError set where a workspace failed */
static int rk_batch(rk_job *job)
{
    npy_intp next = 0;
    job->next = &next;
    job->stream = job->kind != RK_WRENCH
                  && (size_t)job->count * rk_width(job->md, job->kind) * sizeof(double)
                     >= LG_STREAM_MIN;
    int parts = rk_threads(job->count);
    rk_job jobs[RK_MAX_THREADS];
    for (int t = 0; t < parts; t++) jobs[t] = *job;
    NPY_BEGIN_THREADS_DEF;
    if (job->count > 16) NPY_BEGIN_THREADS;
#if RK_PTHREADS
    lg_run_batch(rk_run, jobs, sizeof jobs[0], parts);
#else
    rk_run(&jobs[0]);
#endif
    if (job->count > 16) NPY_END_THREADS;
    job->bad = 0;
    for (int t = 0; t < parts; t++) job->bad += jobs[t].bad;
    /* a thread without its workspace took no block: the others took them, unless none ran */
    if (next < job->count) { PyErr_NoMemory(); return 0; }
    return 1;
}

/* one state (job->count 1) here, on a workspace of the stack where it fits, else of the heap,
 * without the batch's threads; its NaN rows, or -1 with MemoryError */
static npy_intp rk_one(rk_job *job)
{
    _Alignas(64) char stack[RK_STACK_BYTES];
    const size_t size = job->md->work1;
    char *block = size <= sizeof stack ? stack : aligned_alloc(64, RK_ROUND(size));
    if (!block) { PyErr_NoMemory(); return -1; }
    rk_work work;
    rk_work_at(job->md, block, &work);
    const int bad = rk_state(job, 0, &work);
    if (block != stack) free(block);
    return bad;
}

/* the job: one state by rk_one, more by rk_batch; job->bad its NaN rows, 0 with MemoryError */
static int rk_go(rk_job *job)
{
    if (job->count != 1) return rk_batch(job);
    const npy_intp bad = rk_one(job);
    job->bad = bad < 0 ? 0 : bad;
    return bad >= 0;
}
