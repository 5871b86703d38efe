/* atomicfile.c: replacing a file atomically through a private mkstemp() temporary (see atomicfile.h). */
#include "common/atomicfile.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/errbuf.h"

#define ATOMICFILE_TAG ".hexcnc-"   /* between the target's name and the PID */
#define ATOMICFILE_BASE_MAX 200     /* bytes of the target's name kept in the temporary's
                                     * (so it stays under NAME_MAX = 255) */

/* Length of the folder part of path, slash included (0 when there is none). */
static size_t atomicfile_dirlen(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? (size_t)(slash - path + 1) : 0;
}

/* "DIR/.NAME.hexcnc-" for target: the prefix of every temporary of that target. */
static char *atomicfile_prefix(const char *target)
{
    size_t dl = atomicfile_dirlen(target), bl = strlen(target + dl);
    if (bl > ATOMICFILE_BASE_MAX)
        bl = ATOMICFILE_BASE_MAX;
    size_t n = dl + 1 + bl + sizeof ATOMICFILE_TAG + 32;
    char *p = malloc(n);
    if (p)
        snprintf(p, n, "%.*s.%.*s" ATOMICFILE_TAG, (int)dl, target, (int)bl, target + dl);
    return p;
}

/* Whether `name` is a temporary of a process that no longer exists. */
static int atomicfile_is_stale(const char *name, const char *prefix)
{
    size_t pl = strlen(prefix);
    if (strncmp(name, prefix, pl))
        return 0;
    char *end;
    errno = 0;
    long pid = strtol(name + pl, &end, 10);
    if (errno || end == name + pl || pid <= 0 || *end != '-' || strlen(end + 1) != 6)
        return 0;
    if (pid == (long)getpid())
        return 0;
    return kill((pid_t)pid, 0) != 0 && errno == ESRCH;
}

/* Removes the temporaries of path left by processes that are gone. */
int atomicfile_clean_stale(const char *path)
{
    char *prefix = atomicfile_prefix(path);
    if (!prefix)
        return 0;
    size_t dl = atomicfile_dirlen(prefix);
    char *dir = strndup(prefix, dl ? dl : 1);
    int removed = 0;
    DIR *d = dir ? opendir(dl ? dir : ".") : NULL;
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (atomicfile_is_stale(e->d_name, prefix + dl) && unlinkat(dirfd(d), e->d_name, 0) == 0)
            removed++;
    if (d)
        closedir(d);
    free(dir);
    free(prefix);
    return removed;
}

/* The process's umask, read without changing it (umask() would race other threads). */
static mode_t atomicfile_umask(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[128];
    unsigned m = 022;
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "Umask: %o", &m) == 1)
            break;
    if (f)
        fclose(f);
    return (mode_t)(m & 0777);
}

/* Frees what a holds and zeroes it. */
static void atomicfile_release(struct atomicfile *a)
{
    free(a->target);
    free(a->tmp);
    free(a->name);
    memset(a, 0, sizeof *a);
}

/* Resolves a symlink, refuses non-regular or read-only targets; *st gets the old file's
 * status, *exists whether there is one. */
static int atomicfile_check_target(struct atomicfile *a, struct stat *st, int *exists,
                                   char *err, size_t errlen)
{
    *exists = 0;
    if (lstat(a->name, st) != 0) {
        if (errno != ENOENT)
            return errbuf_set(err, errlen, ATOMICFILE_ERR_IO, "%s: %s", a->name,
                              strerror(errno));
        a->target = strdup(a->name);
        return a->target ? ATOMICFILE_OK : ATOMICFILE_ERR_NOMEM;
    }
    if (S_ISLNK(st->st_mode)) {
        a->target = realpath(a->name, NULL);
        if (!a->target || stat(a->target, st) != 0)
            return errbuf_set(err, errlen, ATOMICFILE_ERR_IO, "%s: symbolic link to a file "
                              "that cannot be reached: %s", a->name, strerror(errno));
    } else if (!(a->target = strdup(a->name))) {
        return ATOMICFILE_ERR_NOMEM;
    }
    *exists = 1;
    if (!S_ISREG(st->st_mode))
        return errbuf_set(err, errlen, ATOMICFILE_ERR_NOT_FILE, "%s: not a regular file: "
                          "not replaced", a->name);
    if (!(st->st_mode & 0222) || access(a->target, W_OK) != 0)
        return errbuf_set(err, errlen, ATOMICFILE_ERR_READ_ONLY, "%s: the file is read-only "
                          "(mode %04o): not replaced", a->name, (unsigned)(st->st_mode & 07777));
    return ATOMICFILE_OK;
}

/* Creates the private temporary next to the target, with the old file's mode. */
int atomicfile_open(struct atomicfile *a, const char *path, char *err, size_t errlen)
{
    struct stat st;
    int exists, fd = -1, rc;
    memset(a, 0, sizeof *a);
    if (!(a->name = strdup(path)))
        return errbuf_set(err, errlen, ATOMICFILE_ERR_NOMEM, "%s: out of memory", path);
    if ((rc = atomicfile_check_target(a, &st, &exists, err, errlen)) != ATOMICFILE_OK)
        goto fail;
    atomicfile_clean_stale(a->target);
    char *prefix = atomicfile_prefix(a->target);
    size_t n = prefix ? strlen(prefix) + 32 : 0;
    if (prefix && (a->tmp = malloc(n)))
        snprintf(a->tmp, n, "%s%ld-XXXXXX", prefix, (long)getpid());
    free(prefix);
    rc = errbuf_set(err, errlen, ATOMICFILE_ERR_NOMEM, "%s: out of memory", path);
    if (!a->tmp)
        goto fail;
    if ((fd = mkstemp(a->tmp)) < 0) {
        rc = errbuf_set(err, errlen, ATOMICFILE_ERR_IO, "%s: cannot create a temporary file "
                        "next to it: %s", path, strerror(errno));
        free(a->tmp);
        a->tmp = NULL;
        goto fail;
    }
    if (exists && fchown(fd, st.st_uid, st.st_gid) != 0) {
        /* not ours to give away: the new file is ours, with the old mode */
    }
    if (fchmod(fd, exists ? st.st_mode & 07777 : 0666 & ~atomicfile_umask()) != 0 ||
        !(a->f = fdopen(fd, "w"))) {
        rc = errbuf_set(err, errlen, ATOMICFILE_ERR_IO, "%s: %s", a->tmp, strerror(errno));
        close(fd);
        goto fail;
    }
    return ATOMICFILE_OK;
fail:
    atomicfile_abort(a);
    return rc;
}

/* Closes and removes the temporary. */
void atomicfile_abort(struct atomicfile *a)
{
    if (a->f)
        fclose(a->f);
    if (a->tmp)
        unlink(a->tmp);
    atomicfile_release(a);
}

/* fsyncs the folder holding the target, so the rename itself survives a power cut. */
static int atomicfile_sync_dir(const char *target)
{
    size_t dl = atomicfile_dirlen(target);
    char *dir = dl ? strndup(target, dl) : strdup(".");
    int fd = dir ? open(dir, O_RDONLY | O_DIRECTORY) : -1, rc = 0;
    if (fd >= 0) {
        rc = fsync(fd) != 0 && errno != EINVAL ? -1 : 0;  /* EINVAL: no fsync for folders */
        close(fd);
    }
    free(dir);
    return rc;
}

/* Flush, fsync, close, rename, fsync the folder; the temporary goes on any failure. */
int atomicfile_commit(struct atomicfile *a, char *err, size_t errlen)
{
    int bad = ferror(a->f) != 0;
    int e = bad ? EIO : 0;
    if (!bad && (fflush(a->f) != 0 || fsync(fileno(a->f)) != 0))
        bad = 1, e = errno;
    if (fclose(a->f) != 0 && !bad)
        bad = 1, e = errno;
    a->f = NULL;
    if (!bad && rename(a->tmp, a->target) != 0)
        bad = 1, e = errno;
    if (bad) {
        int rc = errbuf_set(err, errlen, ATOMICFILE_ERR_IO, "%s: cannot write the file: %s "
                            "(left as it was)", a->name, strerror(e));
        atomicfile_abort(a);
        return rc;
    }
    free(a->tmp);
    a->tmp = NULL;                 /* renamed: nothing to remove any more */
    int rc = ATOMICFILE_OK;
    if (atomicfile_sync_dir(a->target) != 0)
        rc = errbuf_set(err, errlen, ATOMICFILE_ERR_IO, "%s: written, but its folder cannot "
                        "be synced: %s", a->name, strerror(errno));
    atomicfile_release(a);
    return rc;
}

/* The whole of data as the new contents of path. */
int atomicfile_write(const char *path, const void *data, size_t len, char *err, size_t errlen)
{
    struct atomicfile a;
    int rc = atomicfile_open(&a, path, err, errlen);
    if (rc != ATOMICFILE_OK)
        return rc;
    if (len && fwrite(data, 1, len, a.f) != len) {
        rc = errbuf_set(err, errlen, ATOMICFILE_ERR_IO, "%s: cannot write the file: %s (left "
                        "as it was)", path, strerror(errno));
        atomicfile_abort(&a);
        return rc;
    }
    return atomicfile_commit(&a, err, errlen);
}
