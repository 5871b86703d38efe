/* test_file_util.h: scratch folders and whole-file reads and writes for tests of code that
 * saves files (tool table, parameter file, atomic saves). Check assertions on every failure. */
#ifndef HEXCNC_TEST_FILE_UTIL_H
#define HEXCNC_TEST_FILE_UTIL_H

#include <check.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* A fresh folder for one test (removed by rm_dir). */
static inline void make_dir(char *dir, size_t len)
{
    snprintf(dir, len, "/tmp/hexcnc_test_XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(dir));
}

/* Replaces path's content with text. */
static inline void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    ck_assert_ptr_nonnull(f);
    fputs(text, f);
    fclose(f);
}

/* Reads path into buf (at most len - 1 bytes), NUL-terminated. */
static inline void read_file(const char *path, char *buf, size_t len)
{
    FILE *f = fopen(path, "r");
    ck_assert_ptr_nonnull(f);
    size_t n = fread(buf, 1, len - 1, f);
    buf[n] = '\0';
    fclose(f);
}

/* Entries in dir whose name contains `part` ("" for all): to see that no temporary is left. */
static inline int count_entries(const char *dir, const char *part)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    int n = 0;
    ck_assert_ptr_nonnull(d);
    while ((e = readdir(d)))
        n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..") && strstr(e->d_name, part);
    closedir(d);
    return n;
}

/* Removes dir and the files in it (one level). */
static inline void rm_dir(const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    char p[4200];
    while (d && (e = readdir(d))) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
        unlink(p);
    }
    if (d)
        closedir(d);
    rmdir(dir);
}

#endif
