#include "core/radix_sort.h"

#include <string.h>

uint32_t rc__bit_width(uint32_t v)
{
    uint32_t bits = 0;
    while (bits < 32u && (v >> bits) != 0) ++bits;
    return bits;
}

void rc__radix_sort_pairs(uint32_t *keys, uint32_t *values, uint32_t *tmp_keys, uint32_t *tmp_values, uint32_t n,
                          uint32_t bits)
{
    uint32_t *src_k = keys, *src_v = values, *dst_k = tmp_keys, *dst_v = tmp_values, *t;
    uint32_t shift, passes = 0;
    if (bits > 32u) bits = 32u;
    for (shift = 0; shift < bits; shift += 8u, ++passes) {
        uint32_t start[256], i, sum = 0;
        memset(start, 0, sizeof start);
        for (i = 0; i < n; ++i) ++start[(src_k[i] >> shift) & 255u];
        for (i = 0; i < 256u; ++i) {
            const uint32_t count = start[i];
            start[i] = sum;
            sum += count;
        }
        for (i = 0; i < n; ++i) {
            const uint32_t at = start[(src_k[i] >> shift) & 255u]++;
            dst_k[at] = src_k[i];
            dst_v[at] = src_v[i];
        }
        t = src_k, src_k = dst_k, dst_k = t;
        t = src_v, src_v = dst_v, dst_v = t;
    }
    /* an odd number of passes left the result in the tmp arrays */
    if (passes & 1u) {
        memcpy(keys, tmp_keys, (size_t)n * sizeof *keys);
        memcpy(values, tmp_values, (size_t)n * sizeof *values);
    }
}
