/* atomicfile.h: the one way hexcnc replaces a file (tool table, parameter file, plots, sampler
 * output): a private temporary next to it, fsync, rename, fsync of the folder. */
#ifndef HEXCNC_ATOMICFILE_H
#define HEXCNC_ATOMICFILE_H

#include <stddef.h>
#include <stdio.h>
#include <sys/types.h>

/*
 * The temporary is made by mkstemp() in the target's folder (so rename() stays on one file
 * system) and is named `.NAME.hexcnc-PID-XXXXXX`: nobody can plant a symlink at a name known
 * in advance, two processes saving the same file each have their own temporary (the last
 * rename wins and the file is always one complete version), and a temporary left by a killed
 * process can be recognised by the PID in its name and removed (atomicfile_clean_stale(),
 * which atomicfile_open() calls).
 *
 * The new file gets the old file's mode (and owner, when we may set it); a new file gets
 * 0666 less the umask. A target that is read-only (no write bit, or not writable by us) or
 * not a regular file is refused, never replaced. A symbolic link is followed: the file it
 * names is replaced and the link stays. Any write error, including one that only shows at
 * fflush, fsync or close, fails the save and removes the temporary; the target is untouched.
 */

enum atomicfile_status {
    ATOMICFILE_OK = 0,
    ATOMICFILE_ERR_IO,         /* cannot create, write, sync or rename (errno in the message) */
    ATOMICFILE_ERR_READ_ONLY,  /* the target is read-only: refused, left as it is */
    ATOMICFILE_ERR_NOT_FILE,   /* the target exists and is not a regular file */
    ATOMICFILE_ERR_NOMEM,
};

/* A save in progress: write to f, then atomicfile_commit() or atomicfile_abort(). */
struct atomicfile {
    FILE *f;                   /* the temporary, open for writing */
    char *target;              /* the file to replace (symlinks resolved) */
    char *tmp;                 /* the temporary's name */
    char *name;                /* the caller's name of the target, for messages */
};

/* Refuses a read-only or non-regular target, removes stale temporaries, creates the
 * temporary. On failure err gets "PATH: what" and a holds nothing to free. */
int atomicfile_open(struct atomicfile *a, const char *path, char *err, size_t errlen);
/* Flushes, fsyncs and closes the temporary, renames it over the target and fsyncs the
 * folder. On any failure the temporary is removed and the target left as it was. Either
 * way a is released. */
int atomicfile_commit(struct atomicfile *a, char *err, size_t errlen);
/* Closes and removes the temporary; the target is untouched. Safe on a zeroed struct. */
void atomicfile_abort(struct atomicfile *a);
/* open + write len bytes + commit. */
int atomicfile_write(const char *path, const void *data, size_t len, char *err,
                     size_t errlen);
/* Removes `.NAME.hexcnc-PID-*` next to path whose process PID no longer exists (a
 * temporary of a killed run); returns how many were removed. */
int atomicfile_clean_stale(const char *path);

#endif
