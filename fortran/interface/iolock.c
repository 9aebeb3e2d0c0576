/* One process-wide lock around the core's I/O on internal files (fortran/input/case_parse.f90: taken by
 * case_parse, for its list-directed internal reads of reals, subscripts and repeat counts, and by
 * case_write_text, for its namelist write; no routine that holds it takes it again).
 *
 * Why: libgfortran (GCC 12, Debian 12) is not safe when two threads read internal units at
 * once. Two threads parsing cases (api_load, called with the GIL released) then corrupt each
 * other: in 6400 loads on 2 threads, 12 were refused ("Invalid string input in item 1") and 4
 * loaded a different model without an error (tests/test_api.py repeats this). Formatted writes
 * did not race in the same test. */
#include <pthread.h>

static pthread_mutex_t io_lock = PTHREAD_MUTEX_INITIALIZER;

void spline_io_lock(void)
{
    pthread_mutex_lock(&io_lock);
}

void spline_io_unlock(void)
{
    pthread_mutex_unlock(&io_lock);
}
