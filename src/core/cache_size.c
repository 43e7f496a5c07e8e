/* Last-level cache size from /sys/devices/system/cpu/cpu0/cache/index<i>/size
 * (text such as "32K", "2048K" or "260M"): the largest over the indices is
 * the last level. Instruction caches are listed too but are never the
 * largest. Elsewhere (or with no sysfs, as in some containers) 0. */
#if defined(__linux__) && !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 200809L
#endif
#include "core/cache_size.h"

#if defined(__linux__)
#include <fcntl.h>
#include <unistd.h>

/* "<digits>[K|M|G]" -> bytes; 0 for anything else. */
static uint64_t parse_size(const char *s, long n)
{
    uint64_t v = 0;
    long i = 0;
    while (i < n && s[i] >= '0' && s[i] <= '9' && v < ((uint64_t)1 << 40)) v = v * 10u + (uint64_t)(s[i++] - '0');
    if (i == 0) return 0;
    if (i < n && s[i] == 'K') return v << 10;
    if (i < n && s[i] == 'M') return v << 20;
    if (i < n && s[i] == 'G') return v << 30;
    return v;
}

uint64_t rc__last_level_cache_bytes(void)
{
    char path[] = "/sys/devices/system/cpu/cpu0/cache/index0/size";
    const size_t digit = sizeof "/sys/devices/system/cpu/cpu0/cache/index" - 1;
    uint64_t best = 0;
    unsigned i;
    for (i = 0; i < 8; ++i) {
        char text[32];
        long got;
        uint64_t v;
        int fd;
        path[digit] = (char)('0' + i);
        fd = open(path, O_RDONLY);
        if (fd < 0) continue;
        got = (long)read(fd, text, sizeof text);
        close(fd);
        v = got > 0 ? parse_size(text, got) : 0;
        if (v > best) best = v;
    }
    return best;
}
#else
uint64_t rc__last_level_cache_bytes(void) { return 0; }
#endif
