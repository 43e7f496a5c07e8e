#include "scan_names.h"

#include <stdio.h>
#include <string.h>

#include "util.h"

/* The pattern's one conversion: where it starts, how long it is and its
 * zero-padded width (0 for %d); -1 when the pattern is not one. */
static int find_conversion(const char *p, size_t *at, size_t *len, int *width)
{
    const char *pct = strchr(p, '%'), *q;
    if (!pct) return 0;
    q = pct + 1;
    *width = 0;
    if (*q == '0' && q[1] >= '1' && q[1] <= '9' && q[2] == 'd') {
        *width = q[1] - '0';
        q += 2;
    } else if (*q != 'd') {
        return -1;
    }
    if (strchr(q + 1, '%')) return -1;
    *at = (size_t)(pct - p);
    *len = (size_t)(q + 1 - pct);
    return 1;
}

int rcu_scan_pattern(const char *path)
{
    size_t at, len;
    int width;
    const int k = find_conversion(path, &at, &len, &width);
    if (k < 0) return rcu_fail("%s: a per-scan name takes one %%d or %%0Nd (N from 1 to 9) and no other '%%'", path);
    return k;
}

int rcu_scan_name(const char *pattern, uint32_t index, char *out, size_t size)
{
    size_t at, len, rest;
    int width, n;
    char digits[16];
    if (find_conversion(pattern, &at, &len, &width) != 1) return rcu_fail("%s: not a per-scan name", pattern);
    n = snprintf(digits, sizeof digits, "%0*lu", width, (unsigned long)index);
    rest = strlen(pattern + at + len);
    if (n < 0 || at + (size_t)n + rest + 1u > size) return rcu_fail("%s: the name of scan %lu is too long", pattern,
                                                                     (unsigned long)index);
    memcpy(out, pattern, at);
    memcpy(out + at, digits, (size_t)n);
    memcpy(out + at + (size_t)n, pattern + at + len, rest + 1u);
    return 0;
}
