/* SPDX-License-Identifier: MIT */
/* POSIX calls Fortran cannot make portably (yarnfort_output_filesystem): an exclusive
 * advisory lock on a file (flock: the kernel drops it when the process ends, however it
 * ends, so a killed run leaves no stale lock), fsync of a written file, creation of a
 * file that never follows a link, and the error text of the last failed call. Every
 * function returns 0 on success.
 * No call here writes, truncates or removes through a symbolic link: files are created
 * with O_CREAT | O_EXCL | O_NOFOLLOW after the old name is removed, and opened with
 * O_NOFOLLOW, so a link planted in the output folder can never redirect a write out of
 * it (a hard link keeps its old content: the name gets a new file). */
#define _GNU_SOURCE
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/file.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <time.h>
#include <unistd.h>

/* Lock `path` (created if missing) for this process. On success *fd is the open file
 * that holds the lock and the file holds "pid <pid> host <host> since <UTC time>".
 * Returns 0 when locked, 1 when another process holds the lock (its line is copied to
 * holder, at most holder_length - 1 bytes, NUL-terminated), 2 when `path` is a symbolic
 * link, 3 when it is not a regular file or has other names (hard links), -1 on any other
 * failure (errno set). */
int yarnfort_lock_file(const char *path, int *fd, char *holder, int holder_length)
{
    char line[512], host[256];
    struct stat info;
    time_t now;
    struct tm utc;
    ssize_t n;
    int file, length;

    *fd = -1;
    if (holder_length > 0) holder[0] = '\0';
    file = open(path, O_RDWR | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0644);
    if (file < 0) return errno == ELOOP ? 2 : -1;
    /* Its line is written into the file: a file other names share (a hard link) or
     * anything but a regular file is refused, as a symbolic link is (O_NOFOLLOW). */
    if (fstat(file, &info) != 0 || !S_ISREG(info.st_mode) || info.st_nlink != 1) {
        close(file);
        return 3;
    }
    if (flock(file, LOCK_EX | LOCK_NB) != 0) {
        int saved = errno;
        if (saved == EWOULDBLOCK) {
            n = pread(file, line, sizeof line - 1, 0);
            if (n < 0) n = 0;
            line[n] = '\0';
            line[strcspn(line, "\n")] = '\0';
            if (holder_length > 0) {
                strncpy(holder, line, (size_t)holder_length - 1);
                holder[holder_length - 1] = '\0';
            }
            close(file);
            return 1;
        }
        close(file);
        errno = saved;
        return -1;
    }
    if (gethostname(host, sizeof host) != 0) strcpy(host, "unknown");
    host[sizeof host - 1] = '\0';
    now = time(NULL);
    gmtime_r(&now, &utc);
    length = snprintf(line, sizeof line, "pid %ld host %s since %04d-%02d-%02d %02d:%02d:%02d UTC\n",
                      (long)getpid(), host, utc.tm_year + 1900, utc.tm_mon + 1, utc.tm_mday,
                      utc.tm_hour, utc.tm_min, utc.tm_sec);
    if (ftruncate(file, 0) != 0 || pwrite(file, line, (size_t)length, 0) != length) {
        int saved = errno;
        close(file);
        errno = saved;
        return -1;
    }
    *fd = file;
    return 0;
}

/* Release a lock taken by yarnfort_lock_file (the file stays). */
int yarnfort_unlock_file(int fd)
{
    if (fd < 0) return 0;
    return close(fd);
}

/* Flush a closed file's data to the device (fsync through a new descriptor). */
int yarnfort_sync_file(const char *path)
{
    int file = open(path, O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
    int status;
    if (file < 0) return -1;
    status = fsync(file);
    if (status != 0) {
        int saved = errno;
        close(file);
        errno = saved;
        return -1;
    }
    return close(file);
}

/* Flush a folder's entries (e.g. a rename in it) to the device. A file system that
 * cannot fsync a folder (EINVAL) keeps its entries its own way: no error. */
int yarnfort_sync_folder(const char *path)
{
    int folder = open(path, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    int status;
    if (folder < 0) return -1;
    status = fsync(folder);
    if (status != 0 && errno != EINVAL) {
        int saved = errno;
        close(folder);
        errno = saved;
        return -1;
    }
    return close(folder);
}

/* Give the file `old` the second name `new` (a hard link). Returns 0, 1 when the file
 * system has no hard links (FAT, some network shares), -1 on any other failure. */
int yarnfort_link_file(const char *old, const char *new)
{
    if (link(old, new) == 0) return 0;
    if (errno == EPERM || errno == ENOTSUP || errno == EOPNOTSUPP || errno == ENOSYS) return 1;
    return -1;
}

/* Remove a file; a missing file is no error. */
int yarnfort_remove_file(const char *path)
{
    if (unlink(path) == 0 || errno == ENOENT) return 0;
    return -1;
}

/* Make a write past the file size limit (ulimit -f) fail with EFBIG, reported like any
 * failed write, instead of killing the process with SIGXFSZ. */
void yarnfort_ignore_file_size_signal(void)
{
    signal(SIGXFSZ, SIG_IGN);
}

/* The largest file this process may write (ulimit -f), in bytes; -1 for no limit. */
long long yarnfort_file_size_limit(void)
{
    struct rlimit limit;
    if (getrlimit(RLIMIT_FSIZE, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return -1;
    return (long long)limit.rlim_cur;
}

/* Cut the file `path` to `size` bytes (never the file a link at `path` points to). */
int yarnfort_truncate_file(const char *path, long long size)
{
    int file = open(path, O_WRONLY | O_NOFOLLOW | O_CLOEXEC);
    if (file < 0) return -1;
    if (ftruncate(file, (off_t)size) != 0) {
        int saved = errno;
        close(file);
        errno = saved;
        return -1;
    }
    return close(file);
}

/* What is at `path`, not following a link: 0 nothing, 1 a regular file, 2 a symbolic
 * link, 3 anything else (a folder, a pipe, ...); -1 if it cannot be told (errno set). */
int yarnfort_file_kind(const char *path)
{
    struct stat info;
    if (lstat(path, &info) != 0) return errno == ENOENT ? 0 : -1;
    if (S_ISREG(info.st_mode)) return 1;
    if (S_ISLNK(info.st_mode)) return 2;
    return 3;
}

/* Create `path` anew, empty, for writing: a regular file of that name is removed first,
 * then the name is created exclusively (O_EXCL: never through a link, even one planted
 * in between). Returns 0, 2 when `path` is a symbolic link and 3 when it is something
 * else than a regular file (both left alone), -1 on any other failure (errno set). */
int yarnfort_create_file(const char *path)
{
    int kind = yarnfort_file_kind(path);
    int file;

    if (kind < 0 || kind > 1) return kind;
    if (kind == 1 && unlink(path) != 0 && errno != ENOENT) return -1;
    file = open(path, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (file < 0) return -1;
    return close(file);
}

/* Remove `path` if it is a regular file; anything else (a link, a folder) is left alone
 * and gives 1; a missing file is no error. */
int yarnfort_remove_regular_file(const char *path)
{
    int kind = yarnfort_file_kind(path);
    if (kind <= 0) return kind;
    if (kind != 1) return 1;
    return yarnfort_remove_file(path);
}

/* The names of the symbolic links in `folder`, each followed by a NUL, copied to
 * `names` as far as `length` bytes allow. Returns the bytes all of them need (call
 * again with that length when it is larger), -1 if the folder cannot be read. */
long long yarnfort_list_links(const char *folder, char *names, long long length)
{
    DIR *listing = opendir(folder);
    struct dirent *entry;
    struct stat info;
    long long used = 0, n;
    int link;

    if (listing == NULL) return -1;
    while ((entry = readdir(listing)) != NULL) {
        if (entry->d_type == DT_UNKNOWN)
            link = fstatat(dirfd(listing), entry->d_name, &info, AT_SYMLINK_NOFOLLOW) == 0
                   && S_ISLNK(info.st_mode);
        else
            link = entry->d_type == DT_LNK;
        if (!link) continue;
        n = (long long)strlen(entry->d_name) + 1;
        if (used + n <= length) memcpy(names + used, entry->d_name, (size_t)n);
        used += n;
    }
    closedir(listing);
    return used;
}

/* The size in bytes of the file `path` on its device, -1 if it cannot be told. */
long long yarnfort_file_size(const char *path)
{
    struct stat info;
    if (stat(path, &info) != 0) return -1;
    return (long long)info.st_size;
}

/* Bytes still free for this user on the device of `path`, -1 if it cannot be told. */
long long yarnfort_free_space(const char *path)
{
    struct statvfs info;
    if (statvfs(path, &info) != 0) return -1;
    return (long long)info.f_bavail * (long long)info.f_frsize;
}

/* The text of errno (the reason of the last failed call), NUL-terminated. */
void yarnfort_last_error(char *text, int length)
{
    if (length <= 0) return;
    strncpy(text, strerror(errno), (size_t)length - 1);
    text[length - 1] = '\0';
}
