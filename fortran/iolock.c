/* One process-wide lock around the core's reads from internal files (fortran/case.f90: the
 * case parser's list-directed reads and its namelist reads and writes).
 *
 * Why: libgfortran (GCC 12, Debian 12) is not safe when two threads read internal units at
 * once. Two threads parsing cases (api_load, called with the GIL released) then corrupt each
 * other: in 6400 loads on 2 threads, 12 were refused ("Invalid string input in item 1") and 4
 * loaded a different model without an error (tests/test_api.py repeats this). Formatted writes
 * did not race in the same test. Recursive, so that a locked routine may call another. */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>

static pthread_mutex_t io_lock;
static pthread_once_t io_lock_once = PTHREAD_ONCE_INIT;

static void io_lock_init(void)
{
    pthread_mutexattr_t attr;
    pthread_mutexattr_init(&attr);
    pthread_mutexattr_settype(&attr, PTHREAD_MUTEX_RECURSIVE);
    pthread_mutex_init(&io_lock, &attr);
    pthread_mutexattr_destroy(&attr);
}

void spline_io_lock(void)
{
    pthread_once(&io_lock_once, io_lock_init);
    pthread_mutex_lock(&io_lock);
}

void spline_io_unlock(void)
{
    pthread_mutex_unlock(&io_lock);
}
