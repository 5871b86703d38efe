/* tooltable_file.c: reading a tool table file, and writing one atomically (temp file, fsync, rename). */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common/errbuf.h"
#include "interp/tooltable.h"

#define TOOLTABLE_MAX_FILE_BYTES (4L << 20) /* a table file larger than 4 MiB is refused */

/* The offset letters in the order a save writes them (as LinuxCNC does). */
static const char tooltable_offset_letters[] = "XYZABCUVW";

/* Reads the whole file into a NUL-terminated buffer the caller frees. */
static char *tooltable_slurp(const char *path, char *err, size_t errlen, int *rc)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    long n;
    *rc = TOOLTABLE_ERR_IO;
    if (!f) {
        errbuf_set(err, errlen, *rc, "%s: cannot open the tool table: %s", path,
                       strerror(errno));
        return NULL;
    }
    if (fseek(f, 0, SEEK_END) || (n = ftell(f)) < 0 || n > TOOLTABLE_MAX_FILE_BYTES ||
        fseek(f, 0, SEEK_SET)) {
        errbuf_set(err, errlen, *rc, "%s: cannot read the tool table (too large?)", path);
        goto out;
    }
    buf = malloc((size_t)n + 1);
    if (!buf || fread(buf, 1, (size_t)n, f) != (size_t)n) {
        errbuf_set(err, errlen, *rc, "%s: cannot read the tool table", path);
        free(buf);
        buf = NULL;
        goto out;
    }
    buf[n] = '\0';
    *rc = TOOLTABLE_OK;
out:
    fclose(f);
    return buf;
}

/* Reads a table file; err gets "file:line: what" on failure. */
int tooltable_load(struct tooltable *t, const char *path, char *err, size_t errlen)
{
    int rc;
    char *text = tooltable_slurp(path, err, errlen, &rc);
    tooltable_init(t);
    if (!text)
        return rc;
    rc = tooltable_parse(t, text, path, err, errlen);
    free(text);
    if (rc == TOOLTABLE_OK)
        snprintf(t->path, sizeof t->path, "%s", path);
    return rc;
}

/* ---- saving ---- */

/* The shortest of %.15g / %.17g that reads back as exactly v (so a save loses nothing
 * and -0.04 stays "-0.04"). */
static const char *tooltable_num(char *buf, size_t len, double v, int plus)
{
    snprintf(buf, len, plus ? "%+.15g" : "%.15g", v);
    if (strtod(buf, NULL) != v)
        snprintf(buf, len, plus ? "%+.17g" : "%.17g", v);
    return buf;
}

/* Writes one tool (and its wear entry, if any) in LinuxCNC's format. */
static int tooltable_write_tool(FILE *f, const struct tool_entry *e)
{
    char n[40];
    fprintf(f, "T%d P%d", e->tool, e->pocket);
    for (int k = 0; k < 9; k++) {
        if (!(e->present & (1u << k)))
            continue;
        double v = k == 2 ? e->z_offset_mm : e->offset[k];
        fprintf(f, " %c%s", tooltable_offset_letters[k], tooltable_num(n, sizeof n, v, 1));
    }
    fprintf(f, " D%s", tooltable_num(n, sizeof n, e->diameter_mm, 0));
    if (e->present & TOOLTABLE_F_I)
        fprintf(f, " I%s", tooltable_num(n, sizeof n, e->front_angle_deg, 0));
    if (e->present & TOOLTABLE_F_J)
        fprintf(f, " J%s", tooltable_num(n, sizeof n, e->back_angle_deg, 0));
    if (e->present & TOOLTABLE_F_Q)
        fprintf(f, " Q%d", e->orientation);
    fprintf(f, " ;%s\n", e->comment);
    if (e->wear_mm != 0.0)
        fprintf(f, "T%d P0 D%s ;wear of T%d\n", e->tool + TOOLTABLE_WEAR_BASE,
                tooltable_num(n, sizeof n, e->wear_mm, 0), e->tool);
    return ferror(f) ? -1 : 0;
}

/* Makes "DIR/.NAME.tmpXXXXXX" next to path, so rename() stays on one file system. */
static int tooltable_temp_name(const char *path, char *tmp, size_t tmplen)
{
    const char *slash = strrchr(path, '/');
    int dirlen = slash ? (int)(slash - path + 1) : 0;
    int n = snprintf(tmp, tmplen, "%.*s.%s.tmpXXXXXX", dirlen, path, slash ? slash + 1 : path);
    return n < 0 || (size_t)n >= tmplen ? -1 : 0;
}

/* Flushes the folder holding path, so the rename itself survives a power cut. */
static void tooltable_sync_dir(const char *path)
{
    char dir[1024];
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(dir, sizeof dir, ".");
    else
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path) ? (int)(slash - path) : 1, path);
    int fd = open(dir, O_RDONLY | O_DIRECTORY);
    if (fd >= 0) {
        (void)fsync(fd);
        close(fd);
    }
}

/* Writes the table atomically: temporary file in the same folder, fsync, rename. */
int tooltable_save(const struct tooltable *t, const char *path, char *err, size_t errlen)
{
    char tmp[1100];
    if (tooltable_temp_name(path, tmp, sizeof tmp))
        return errbuf_set(err, errlen, TOOLTABLE_ERR_IO, "%s: path too long", path);
    int fd = mkstemp(tmp);
    if (fd < 0)
        return errbuf_set(err, errlen, TOOLTABLE_ERR_IO,
                              "%s: cannot create a temporary file next to it: %s", path,
                              strerror(errno));
    (void)fchmod(fd, 0644);
    FILE *f = fdopen(fd, "w");
    if (!f) {
        close(fd);
        unlink(tmp);
        return errbuf_set(err, errlen, TOOLTABLE_ERR_IO, "%s: %s", tmp, strerror(errno));
    }
    int bad = 0;
    for (int i = 0; i < t->count && !bad; i++)
        bad = tooltable_write_tool(f, &t->tools[i]);
    bad = bad || fflush(f) != 0 || fsync(fileno(f)) != 0;
    bad = fclose(f) != 0 || bad;
    if (bad || rename(tmp, path) != 0) {
        int e = errno;
        unlink(tmp);
        return errbuf_set(err, errlen, TOOLTABLE_ERR_IO,
                              "%s: cannot write the tool table: %s", path, strerror(e));
    }
    tooltable_sync_dir(path);
    return TOOLTABLE_OK;
}
