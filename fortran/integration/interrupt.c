/* SIGINT during a run of the core (spline_solver): a handler that counts the signal instead of
 * acting on it while a watched run is in progress, so that the run can stop cleanly at its
 * next right-hand-side call and Python can raise KeyboardInterrupt; with no watched run in
 * progress it passes the signal on to whatever handler was there before (Python's).
 *
 * Why C: the Python layer calls the core with the GIL released, so Python's own handler can
 * only act after the call returns; and Fortran has no portable access to sigaction.
 * The standalone executable never watches: there SIGINT keeps its default action. */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <string.h>

static atomic_int sigint_count;   /* SIGINTs received while a watched run was in progress */
static atomic_int watchers;       /* watched runs in progress, in every thread */
static struct sigaction previous; /* the handler before ours, called when nobody watches */
static pthread_mutex_t install_lock = PTHREAD_MUTEX_INITIALIZER;

static void on_sigint(int sig, siginfo_t *info, void *uctx)
{
    if (atomic_load(&watchers) > 0) {
        atomic_fetch_add(&sigint_count, 1);
        return;
    }
    if (previous.sa_flags & SA_SIGINFO) {
        if (previous.sa_sigaction) previous.sa_sigaction(sig, info, uctx);
    } else if (previous.sa_handler == SIG_DFL) {
        signal(sig, SIG_DFL);
        raise(sig);
    } else if (previous.sa_handler != SIG_IGN && previous.sa_handler) {
        previous.sa_handler(sig);
    }
}

/* Begin a watched run: (re)install the handler if someone replaced it (Python's
 * signal.signal does), unless SIGINT is ignored. Returns the count to compare against. */
int spline_sigint_watch(void)
{
    struct sigaction now, ours;
    pthread_mutex_lock(&install_lock);
    if (sigaction(SIGINT, NULL, &now) == 0 && !((now.sa_flags & SA_SIGINFO) && now.sa_sigaction == on_sigint)
        && now.sa_handler != SIG_IGN) {
        memset(&ours, 0, sizeof ours);
        ours.sa_sigaction = on_sigint;
        ours.sa_flags = SA_SIGINFO | SA_RESTART;
        sigemptyset(&ours.sa_mask);
        previous = now;
        sigaction(SIGINT, &ours, NULL);
    }
    atomic_fetch_add(&watchers, 1);
    pthread_mutex_unlock(&install_lock);
    return atomic_load(&sigint_count);
}

/* End a watched run. */
void spline_sigint_unwatch(void)
{
    atomic_fetch_sub(&watchers, 1);
}

/* SIGINTs received so far while watched runs were in progress. */
int spline_sigint_count(void)
{
    return atomic_load(&sigint_count);
}
