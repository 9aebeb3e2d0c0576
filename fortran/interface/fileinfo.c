/* File checks for the case reader and for spline-dyn's output file, where Fortran has no
 * portable access: the type of a file before it is opened (INQUIRE cannot tell a FIFO or a
 * device from a file, and opening a FIFO blocks), whether two names are the same file, an
 * atomic rename, the process id (for a temporary name) and the version of the build.
 * Every function is reentrant; messages are strerror's text (as Python's os.strerror). */
#define _XOPEN_SOURCE 700      /* POSIX.1-2008 with XSI: realpath is declared by stdlib.h */
#include <errno.h>
#include <limits.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef SPLINE_VERSION
#define SPLINE_VERSION "unknown"
#endif
#ifndef SPLINE_BUILD
#define SPLINE_BUILD "unknown"
#endif

static void put_error(int err, char *errbuf, int errlen)
{
    if (errlen <= 0) return;
    if (strerror_r(err, errbuf, (size_t)errlen) != 0) snprintf(errbuf, (size_t)errlen, "error %d", err);
    errbuf[errlen - 1] = '\0';
}

/* Kind of the file a path names, following symbolic links: 0 regular file, 1 directory,
 * 2 FIFO, 3 character device, 4 block device, 5 socket, 6 other; -1 nothing there, -2 a
 * dangling symbolic link, -3 a symbolic-link loop, -4 another error (errbuf: its text).
 * size: the length of a regular file in bytes. */
int spline_file_kind(const char *path, long long *size, char *errbuf, int errlen)
{
    struct stat st, lst;
    *size = 0;
    if (errlen > 0) errbuf[0] = '\0';
    if (stat(path, &st) != 0) {
        int err = errno;
        put_error(err, errbuf, errlen);
        if (err == ENOENT) return lstat(path, &lst) == 0 ? -2 : -1;
        if (err == ELOOP) return -3;
        return -4;
    }
    if (S_ISREG(st.st_mode)) {
        *size = (long long)st.st_size;
        return 0;
    }
    if (S_ISDIR(st.st_mode)) return 1;
    if (S_ISFIFO(st.st_mode)) return 2;
    if (S_ISCHR(st.st_mode)) return 3;
    if (S_ISBLK(st.st_mode)) return 4;
    if (S_ISSOCK(st.st_mode)) return 5;
    return 6;
}

/* The canonical name of a path whose last part may not exist yet: realpath of its directory,
 * then its last part; 0 on success, -1 if the directory cannot be resolved. */
static int canonical(const char *path, char *out, size_t len)
{
    char dir[PATH_MAX], resolved[PATH_MAX];
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    size_t n = slash ? (size_t)(slash - path) : 0;
    if (n >= sizeof dir) return -1;
    if (slash == NULL) strcpy(dir, ".");
    else if (n == 0) strcpy(dir, "/");
    else { memcpy(dir, path, n); dir[n] = '\0'; }
    if (realpath(dir, resolved) == NULL) return -1;
    return snprintf(out, len, "%s/%s", resolved, base) < (int)len ? 0 : -1;
}

/* 1 if two names are the same file: both exist and have the same device and inode, or
 * neither exists and both name the same new file (the same canonical name); else 0. */
int spline_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    char ca[PATH_MAX + 1], cb[PATH_MAX + 1];
    int ha = stat(a, &sa) == 0, hb = stat(b, &sb) == 0;
    if (ha && hb) return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    if (ha || hb) return 0;
    if (canonical(a, ca, sizeof ca) != 0 || canonical(b, cb, sizeof cb) != 0) return 0;
    return strcmp(ca, cb) == 0;
}

/* rename(2): 0, or -1 with the reason in errbuf. */
int spline_rename(const char *from, const char *to, char *errbuf, int errlen)
{
    if (errlen > 0) errbuf[0] = '\0';
    if (rename(from, to) == 0) return 0;
    put_error(errno, errbuf, errlen);
    return -1;
}

/* unlink(2), ignoring errors (a temporary file that is already gone). */
void spline_unlink(const char *path)
{
    (void)unlink(path);
}

int spline_getpid(void)
{
    return (int)getpid();
}

/* The version of this build (meson's project version) and what its core is compiled for
   (meson.build's build_kind): "0.1.0, portable build", NUL-terminated in buf. */
void spline_version(char *buf, int len)
{
    if (len <= 0) return;
    snprintf(buf, (size_t)len, "%s, %s build", SPLINE_VERSION, SPLINE_BUILD);
}
