/* File checks for the case reader and for spline-dyn's output file, where Fortran has no
 * portable access: the type of a file before it is opened (INQUIRE cannot tell a FIFO or a
 * device from a file, and opening a FIFO blocks), whether two names are the same file, an
 * atomic rename, the process id (for a temporary name) and the version of the build.
 * Every function is reentrant; messages are strerror's text (as Python's os.strerror). */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef SPLINE_VERSION
#define SPLINE_VERSION "unknown"
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

/* 1 if both names exist and are the same file (device and inode), else 0. */
int spline_same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (stat(a, &sa) != 0 || stat(b, &sb) != 0) return 0;
    return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
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

/* The version of this build (meson's project version), NUL-terminated in buf. */
void spline_version(char *buf, int len)
{
    if (len <= 0) return;
    snprintf(buf, (size_t)len, "%s", SPLINE_VERSION);
}
