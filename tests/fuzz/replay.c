/* main for the fuzz targets without libFuzzer: feeds every file named on the
 * command line (or found directly in a directory named there) to the target
 * once, in name order, so a run is the same everywhere. Exits 0 when all ran;
 * a finding aborts (FZ_REQUIRE) or trips a sanitizer on its own. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
/* 32-bit targets: stat() of a file with a 64-bit inode number (qemu on a
 * large host disk) fails with EOVERFLOW without it */
#define _FILE_OFFSET_BITS 64
#include "fuzz_target.h"

#include <dirent.h>
#include <string.h>
#include <sys/stat.h>

/* libFuzzer stops at an allocation above its memory limit; the replay build
 * links with -Wl,--wrap=malloc,--wrap=calloc,--wrap=realloc (GNU ld) so that
 * the same input fails here too: nothing reading a corpus file this small
 * has a reason to ask for a gibibyte. */
#define FZ_ALLOC_LIMIT ((size_t)1 << 30)

void *__real_malloc(size_t size);
void *__real_calloc(size_t count, size_t size);
void *__real_realloc(void *p, size_t size);
void *__wrap_malloc(size_t size);
void *__wrap_calloc(size_t count, size_t size);
void *__wrap_realloc(void *p, size_t size);

void *__wrap_malloc(size_t size)
{
    FZ_REQUIRE(size <= FZ_ALLOC_LIMIT, "an allocation of over 1 GiB");
    return __real_malloc(size);
}

void *__wrap_calloc(size_t count, size_t size)
{
    FZ_REQUIRE(size == 0 || count <= FZ_ALLOC_LIMIT / size, "an allocation of over 1 GiB");
    return __real_calloc(count, size);
}

void *__wrap_realloc(void *p, size_t size)
{
    FZ_REQUIRE(size <= FZ_ALLOC_LIMIT, "an allocation of over 1 GiB");
    return __real_realloc(p, size);
}

static int run_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    unsigned char *data;
    long size;
    if (f == NULL || fseek(f, 0, SEEK_END) != 0 || (size = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fprintf(stderr, "replay: cannot read %s\n", path);
        if (f) fclose(f);
        return -1;
    }
    data = (unsigned char *)malloc(size > 0 ? (size_t)size : 1u);
    if (data == NULL || fread(data, 1, (size_t)size, f) != (size_t)size) {
        fprintf(stderr, "replay: cannot read %s\n", path);
        free(data);
        fclose(f);
        return -1;
    }
    fclose(f);
    LLVMFuzzerTestOneInput(data, (size_t)size);
    free(data);
    return 0;
}

static int by_name(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

static int run_dir(const char *dir, unsigned *count)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    char **names = NULL;
    size_t n = 0, cap = 0, i;
    int rc = 0;
    if (d == NULL) {
        fprintf(stderr, "replay: cannot open %s\n", dir);
        return -1;
    }
    while ((e = readdir(d)) != NULL) {
        char *p;
        struct stat st;
        if (e->d_name[0] == '.') continue;
        p = (char *)malloc(strlen(dir) + strlen(e->d_name) + 2u);
        if (p == NULL) break;
        sprintf(p, "%s/%s", dir, e->d_name);
        if (stat(p, &st) != 0 || !S_ISREG(st.st_mode)) {
            free(p);
            continue;
        }
        if (n == cap) {
            char **grown = (char **)realloc(names, (cap ? cap * 2u : 16u) * sizeof *names);
            if (grown == NULL) {
                free(p);
                break;
            }
            names = grown;
            cap = cap ? cap * 2u : 16u;
        }
        names[n++] = p;
    }
    closedir(d);
    if (n > 0) qsort(names, n, sizeof *names, by_name);
    for (i = 0; i < n; ++i) {
        if (run_file(names[i]) != 0) rc = -1;
        ++*count;
        free(names[i]);
    }
    free(names);
    return rc;
}

int main(int argc, char **argv)
{
    unsigned count = 0;
    int i, rc = 0;
    if (argc < 2) {
        fprintf(stderr, "usage: %s FILE|DIR ...  (each file once through the fuzz target)\n", argv[0]);
        return 2;
    }
    for (i = 1; i < argc; ++i) {
        struct stat st;
        if (stat(argv[i], &st) == 0 && S_ISDIR(st.st_mode)) {
            if (run_dir(argv[i], &count) != 0) rc = 1;
        } else {
            if (run_file(argv[i]) != 0) rc = 1;
            ++count;
        }
    }
    if (count == 0) {
        fprintf(stderr, "replay: no inputs found\n");
        return 1;
    }
    printf("replay: %u inputs, none broke a promise\n", count);
    return rc;
}
