#include "util.h"

#include <ctype.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>

static char rcu_error_text[512];

const char *rcu_last_error(void)
{
    return rcu_error_text;
}

int rcu_fail(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(rcu_error_text, sizeof rcu_error_text, fmt, ap);
    va_end(ap);
    return -1;
}

double rcu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

uint64_t rcu_peak_rss_bytes(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0) return 0;
#if defined(__APPLE__)
    return (uint64_t)ru.ru_maxrss;        /* bytes on macOS */
#else
    return (uint64_t)ru.ru_maxrss * 1024u; /* kilobytes on Linux and the BSDs */
#endif
}

void rcu_store_le32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}

uint32_t rcu_load_le32(const unsigned char *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

void rcu_store_le16(unsigned char *p, uint16_t v)
{
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
}

void rcu_store_f32le(unsigned char *p, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    rcu_store_le32(p, u);
}

float rcu_load_f32le(const unsigned char *p)
{
    uint32_t u = rcu_load_le32(p);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

void rcu_remove_partial(const char *path)
{
    struct stat st;
    /* a regular file only: -o /dev/full must not delete the device */
    if (stat(path, &st) == 0 && S_ISREG(st.st_mode)) remove(path);
}

int rcu_read_file(const char *path, unsigned char **data, size_t *size)
{
    FILE *f = fopen(path, "rb");
    unsigned char *buf;
    long len;
    if (!f) return rcu_fail("%s: %s", path, strerror(errno));
    if (fseek(f, 0, SEEK_END) != 0 || (len = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        return rcu_fail("%s: cannot determine the file size", path);
    }
    buf = (unsigned char *)malloc((size_t)len + 1);
    if (!buf) {
        fclose(f);
        return rcu_fail("%s: out of memory (%ld bytes)", path, len);
    }
    if (len > 0 && fread(buf, 1, (size_t)len, f) != (size_t)len) {
        free(buf);
        fclose(f);
        return rcu_fail("%s: read error", path);
    }
    fclose(f);
    buf[len] = 0;
    *data = buf;
    *size = (size_t)len;
    return 0;
}

void rcu_path_extension(const char *path, char *ext, size_t ext_size)
{
    const char *dot = strrchr(path, '.');
    const char *slash = strrchr(path, '/');
    size_t n = 0;
    if (ext_size == 0) return;
    if (dot && (!slash || dot > slash)) {
        for (dot++; *dot && n + 1 < ext_size; dot++)
            ext[n++] = (char)tolower((unsigned char)*dot);
    }
    ext[n] = 0;
}
