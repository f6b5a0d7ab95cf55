/* File-system calls whose every failure is reported, for io_file_writer, io_lock and
 * io_paths (src/io/file_writer.f90, src/io/lock.f90, src/io/paths.f90), and the listing of a
 * folder (Fortran has none).
 *
 * libgfortran does not report some write errors of a formatted or stream unit: what it keeps
 * in its buffer and writes at a FLUSH or CLOSE fails without an error (writing to /dev/full,
 * a full disk, a file size limit: iostat 0 from WRITE, FLUSH and CLOSE, and a truncated or
 * empty file). These functions call write(2), fsync(2) and close(2) themselves and return the
 * errno of the first that fails (0: none), for a message with its strerror text.
 *
 * Functions return 0 or a positive errno; a created file descriptor is returned as is, or as
 * minus the errno. */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Open `path` for writing, created with mode 0666 (less the umask); with `exclusive` /= 0 it
 * must not exist (O_EXCL: EEXIST), else it is truncated. The descriptor, or -errno. */
int multicor_file_create(const char *path, int exclusive)
{
    int flags = O_WRONLY | O_CREAT | O_CLOEXEC | (exclusive ? O_EXCL : O_TRUNC);
    int fd;
    do {
        fd = open(path, flags, 0666);
    } while (fd < 0 && errno == EINTR);
    return fd >= 0 ? fd : -errno;
}

/* Write the `n` bytes of `buf` to `fd`, through short writes and interruptions; 0 or errno
 * (a write that writes nothing without an error is reported as EIO). */
int multicor_file_write(int fd, const char *buf, long n)
{
    while (n > 0) {
        ssize_t done = write(fd, buf, (size_t)n);
        if (done < 0) {
            if (errno == EINTR) continue;
            return errno;
        }
        if (done == 0) return EIO;
        buf += done;
        n -= (long)done;
    }
    return 0;
}

/* Commit `fd`'s data to the device (fsync: a network file system reports a full disk or a
 * quota there, or at the close), then close it; 0 or the errno of the first call that failed.
 * A file that cannot be synced (a device or a pipe: EINVAL; ENOTSUP) is only closed. */
int multicor_file_close(int fd)
{
    int status = 0;
    if (fsync(fd) != 0 && errno != EINVAL && errno != ENOTSUP && errno != EROFS) status = errno;
    /* a close interrupted by a signal has closed the descriptor anyway (Linux): no retry */
    if (close(fd) != 0 && status == 0 && errno != EINTR) status = errno;
    return status;
}

/* Close `fd` without caring about errors (a file given up after a failure). */
void multicor_file_discard(int fd) { (void)close(fd); }

/* Give the file `old` the second name `new`, which must not exist (link(2): EEXIST); 0 or
 * errno. On NFS a link that was made can still be reported as failed (the reply was lost and
 * the retried request finds the name taken): the link count of `old` says whether it was made. */
int multicor_link_new(const char *old, const char *new)
{
    struct stat st;
    int err;
    if (link(old, new) == 0) return 0;
    err = errno;
    if (stat(old, &st) == 0 && st.st_nlink == 2) return 0;
    return err;
}

/* 1 when a failed link(2)'s errno says the file system has no hard links (FAT, some network
 * shares: EPERM, ENOTSUP, ENOSYS), else 0. */
int multicor_no_hard_links(int err)
{
    return err == EPERM || err == ENOTSUP || err == EOPNOTSUPP || err == ENOSYS;
}

/* Create the folder `path` with mode 0755 (less the umask); 0 or errno. */
int multicor_make_dir(const char *path) { return mkdir(path, 0755) == 0 ? 0 : errno; }

/* Give the file `old` the name `new` (rename(2), which replaces `new`); 0 or errno. */
int multicor_rename(const char *old, const char *new) { return rename(old, new) == 0 ? 0 : errno; }

/* 1 when `path` names a folder (stat(2), which needs no permission on the folder itself), else 0. */
int multicor_is_dir(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

/* The names of the entries of folder `path` that begin with `prefix` ("." and ".." never),
 * each followed by a NUL, written to buf[n] as far as they fit. Returns the bytes all of them
 * take (larger than n: call again with a buffer that size), or -errno when the folder cannot
 * be read. */
long multicor_folder_names(const char *path, const char *prefix, char *buf, long n)
{
    DIR *dir = opendir(path);
    struct dirent *entry;
    size_t lp = strlen(prefix);
    long used = 0;
    if (dir == NULL) return -(long)errno;
    while ((entry = readdir(dir)) != NULL) {
        long len = (long)strlen(entry->d_name);
        if (strncmp(entry->d_name, prefix, lp) != 0) continue;
        if (strcmp(entry->d_name, ".") == 0 || strcmp(entry->d_name, "..") == 0) continue;
        if (used + len + 1 <= n) memcpy(buf + used, entry->d_name, (size_t)len + 1);
        used += len + 1;
    }
    closedir(dir);
    return used;
}

/* The system's text for an errno ('No space left on device'), NUL-terminated in buf[n]. */
void multicor_errno_text(int err, char *buf, long n)
{
    if (n <= 0) return;
    snprintf(buf, (size_t)n, "%s", strerror(err));
}

/* Errno values the callers test. */
int multicor_eexist(void) { return EEXIST; }

/* Whether process pid may still run on this host: kill(pid, 0) succeeds or is refused for
   permission (another user's process). Only ESRCH (no such process) says it is gone; any
   other failure is taken as alive, the safe side for a lock. */
int multicor_process_alive(int pid)
{
    if (pid <= 0) return 1;
    if (kill((pid_t)pid, 0) == 0) return 1;
    return errno == ESRCH ? 0 : 1;
}
