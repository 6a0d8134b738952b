/* What the tree, reach and derivatives modules' bindings share (their builders put this text
 * before them): how many threads a batch runs on (one per processor, at most LG_MAX_THREADS,
 * once each thread has ``per_thread`` of the ``count`` states; LAGRANGIAN_THREADS caps it; one
 * thread without POSIX threads), how a thread starts, and a floating base's quaternion check. */

#if defined(__unix__) || defined(__APPLE__)
#define LG_PTHREADS 1
#include <pthread.h>
#include <unistd.h>
#include <sys/mman.h>
#else
#define LG_PTHREADS 0
#endif
#define LG_MAX_THREADS 8

#if LG_PTHREADS
/* A batch's thread, on a stack of its own size: a lane's work for the largest trees is a
   megabyte or two (eight lanes), more than some platforms' default thread stack (512 kB on
   macOS; 2 MB on Linux where the stack limit is unlimited). 1 where it started. */
#define LG_STACK ((size_t)16 << 20)
static int lg_start(pthread_t *thread, void *(*run)(void *), void *job)
{
    pthread_attr_t attr;
    if (pthread_attr_init(&attr) != 0) return pthread_create(thread, NULL, run, job) == 0;
    pthread_attr_setstacksize(&attr, LG_STACK);
    const int started = pthread_create(thread, &attr, run, job) == 0;
    pthread_attr_destroy(&attr);
    return started;
}

/* A helper thread's copy of its job: state 0 (waiting) becomes 1 (running) in the helper, or
   3 (closed) in the caller, whichever comes first; a helper that finds its job closed frees
   the copy and returns. */
typedef struct { int state; void *(*run)(void *); } lg_helper;
#define LG_HELPER_JOB(h) ((char *)(h) + 64)

static void *lg_helper_main(void *argument)
{
    lg_helper *h = (lg_helper *)argument;
    int waiting = 0;
    if (__atomic_compare_exchange_n(&h->state, &waiting, 1, 0, __ATOMIC_ACQ_REL,
                                    __ATOMIC_ACQUIRE))
        h->run(LG_HELPER_JOB(h));
    else
        free(h);
    return NULL;
}

/* A batch over ``parts`` jobs of ``size`` bytes each: the last on this thread, the others on
 * helper threads, each job's results in ``jobs`` after. A helper that has not started by the
 * time this thread is done is closed and its job run here instead: with the jobs' shared
 * counter of states it finds none left. An idle virtual processor can take a millisecond to
 * wake (measured on a 2-vCPU VM: 0.4-1.9 ms), longer than a whole batch of A_g, and the
 * batch no longer waits for it. */
static void lg_run_batch(void *(*run)(void *), void *jobs, size_t size, int parts)
{
    char *job = (char *)jobs;
    pthread_t threads[LG_MAX_THREADS];
    lg_helper *helpers[LG_MAX_THREADS] = {0};
    for (int t = 0; t < parts - 1; t++) {
        lg_helper *h = (lg_helper *)malloc(64 + size);
        if (!h) continue;
        h->state = 0;
        h->run = run;
        memcpy(LG_HELPER_JOB(h), job + t * size, size);
        if (lg_start(&threads[t], lg_helper_main, h)) helpers[t] = h;
        else free(h);
    }
    run(job + (parts - 1) * size);
    for (int t = 0; t < parts - 1; t++) {
        lg_helper *h = helpers[t];
        int waiting = 0;
        if (!h || __atomic_compare_exchange_n(&h->state, &waiting, 3, 0, __ATOMIC_ACQ_REL,
                                              __ATOMIC_ACQUIRE)) {
            if (h) pthread_detach(threads[t]);  /* it frees its copy when it wakes */
            run(job + t * size);
            continue;
        }
        pthread_join(threads[t], NULL);
        memcpy(job + t * size, LG_HELPER_JOB(h), size);
        free(h);
    }
}
#endif

static int lg_threads(npy_intp count, npy_intp per_thread)
{
#if LG_PTHREADS
    static int cap = 0;
    if (cap == 0) {
        long cpus = sysconf(_SC_NPROCESSORS_ONLN);
        const char *env = getenv("LAGRANGIAN_THREADS");
        long asked = env && *env ? strtol(env, NULL, 10) : cpus;
        if (asked < 1) asked = 1;
        if (cpus < 1) cpus = 1;
        cap = (int)(asked < cpus ? asked : cpus);
        if (cap > LG_MAX_THREADS) cap = LG_MAX_THREADS;
    }
    npy_intp parts = count / per_thread;
    if (parts > cap) parts = cap;
    return parts < 1 ? 1 : (int)parts;
#else
    (void)count;
    (void)per_thread;
    return 1;
#endif
}

/* Each finite state's base quaternion q[3..6] (``states`` states of ``nq`` numbers, ``step``
   apart) of unit norm to ``tolerance`` (free_flyer.py), checked in C rather than in Python (half
   a microsecond of a call); else 0 with a ValueError, and the caller's guarded path names the
   state and the norm. A state not finite is its row's NaN, not an error. */
static int lg_unit_quaternions(const double *q, npy_intp states, npy_intp step, int nq,
                               double tolerance)
{
    for (npy_intp k = 0; k < states; k++) {
        const double *x = q + k * step;
        int finite = 1;
        for (int i = 0; i < nq; i++) finite &= isfinite(x[i]) != 0;
        const double norm = sqrt(x[3] * x[3] + x[4] * x[4] + x[5] * x[5] + x[6] * x[6]);
        if (finite && !(fabs(norm - 1.0) <= tolerance)) {
            PyErr_SetString(PyExc_ValueError, "q: the base quaternion is not unit");
            return 0;
        }
    }
    return 1;
}

/* A batch's output array. A large one (LG_KEEP_MIN bytes or more) comes from blocks this module
 * keeps: a block above glibc's largest mmap threshold (32 MB: Solo12's derivatives for 10^4
 * states, 52 and 78 MB) is otherwise a fresh mapping on every call, its pages faulted in and
 * zeroed by the kernel while the threads write (a third of such a batch's CPU time, measured).
 * When the array and its views are gone, its block is kept for the next batch of about its
 * size: at most LG_KEEP_SLOTS blocks of at most LG_KEEP_MAX bytes each, so a module holds 256 MB
 * at most; the latest block freed replaces an older one when the slots are full. The slots are
 * swapped atomically, not under the GIL alone. The array does not own its data (its base is the
 * block's capsule); its contents are uninitialized, as PyArray_SimpleNew's, and the kernels
 * write every entry. */
#define LG_KEEP_MIN ((size_t)4 << 20)
/* a batch's outputs of this size or more are written past the caches (tree_c.py's
   lg_rows_streamed): larger than a core's cache, and seldom in the shared one when a batch
   starts (Solo12's A_g, 8.6 MB for 10^4 states: 10-20% faster so after other work) */
#define LG_STREAM_MIN ((size_t)4 << 20)
#define LG_KEEP_MAX ((size_t)128 << 20)
#define LG_KEEP_SLOTS 2
#define LG_HEAD 64 /* the block's size before its data, which stays 64-byte aligned */
static void *lg_kept[LG_KEEP_SLOTS];

static void lg_block_free(PyObject *capsule)
{
    char *block = (char *)PyCapsule_GetPointer(capsule, "lagrangian.output") - LG_HEAD;
    if (*(size_t *)block > LG_KEEP_MAX) {
        free(block);
        return;
    }
    for (int s = 0; s < LG_KEEP_SLOTS; s++) {
        void *empty = NULL;
        if (__atomic_compare_exchange_n(&lg_kept[s], &empty, block, 0, __ATOMIC_ACQ_REL,
                                        __ATOMIC_ACQUIRE))
            return;
    }
    /* the slots full: this block, the latest, takes the place of one kept longer (taking turns
       among the slots), so that blocks of a size no longer asked for do not stay */
    static unsigned turn = 0;
    const unsigned s = __atomic_fetch_add(&turn, 1, __ATOMIC_RELAXED) % LG_KEEP_SLOTS;
    free(__atomic_exchange_n((char **)&lg_kept[s], block, __ATOMIC_ACQ_REL));
}

/* a kept block of ``size`` to 5/4 ``size`` bytes of data, else a new one; NULL without memory */
static char *lg_block(size_t size)
{
    for (int s = 0; s < LG_KEEP_SLOTS; s++) {
        char *block = __atomic_exchange_n((char **)&lg_kept[s], NULL, __ATOMIC_ACQ_REL);
        if (!block) continue;
        const size_t held = *(size_t *)block;
        if (held >= size && held - size <= size / 4) return block;
        void *empty = NULL;  /* not this size: back to its slot, or freed if that was taken */
        if (!__atomic_compare_exchange_n(&lg_kept[s], &empty, block, 0, __ATOMIC_ACQ_REL,
                                         __ATOMIC_ACQUIRE))
            free(block);
    }
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    /* in 2 MB pages where the kernel has them for the asking (as numpy asks for its large
       arrays): 4 kB pages cost a batch writing 78 MB a TLB miss every 64 lines */
    const size_t huge = (size_t)2 << 20, whole = (LG_HEAD + size + huge - 1) & ~(huge - 1);
    char *block = aligned_alloc(huge, whole);
    if (block) madvise(block, whole, MADV_HUGEPAGE);
#else
    const size_t whole = (LG_HEAD + size + 63) & ~(size_t)63;
    char *block = aligned_alloc(64, whole);
#endif
    if (block) *(size_t *)block = size;
    return block;
}

static PyObject *lg_output(int nd, npy_intp *dims)
{
    size_t size = sizeof(double);
    for (int k = 0; k < nd; k++) size *= (size_t)dims[k];
    if (size < LG_KEEP_MIN) return PyArray_SimpleNew(nd, dims, NPY_DOUBLE);
    char *block = lg_block(size);
    if (!block) return PyErr_NoMemory();
    PyObject *capsule = PyCapsule_New(block + LG_HEAD, "lagrangian.output", lg_block_free);
    if (!capsule) {
        free(block);
        return NULL;
    }
    PyObject *out = PyArray_New(&PyArray_Type, nd, dims, NPY_DOUBLE, NULL, block + LG_HEAD, 0,
                                NPY_ARRAY_CARRAY, NULL);
    if (!out) {
        Py_DECREF(capsule);  /* its block back to the slots */
        return NULL;
    }
    if (PyArray_SetBaseObject((PyArrayObject *)out, capsule) < 0) {  /* (steals the capsule) */
        Py_DECREF(out);
        return NULL;
    }
    return out;
}
