/* What the tree, reach and derivatives modules' bindings share (their builders put this text
 * before them): how many threads a batch runs on (one per processor, at most LG_MAX_THREADS,
 * once each thread has ``per_thread`` of the ``count`` states; LAGRANGIAN_THREADS caps it; one
 * thread without POSIX threads), how a thread starts, and a floating base's quaternion check. */

#if defined(__unix__) || defined(__APPLE__)
#define LG_PTHREADS 1
#include <pthread.h>
#include <unistd.h>
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
