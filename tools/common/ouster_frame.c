#include "ouster_frame.h"

#include <math.h>

int rcu_ouster_in_window(uint32_t column, uint32_t start, uint32_t end)
{
    return start <= end ? column >= start && column <= end : column >= start || column <= end;
}

uint64_t rcu_ouster_mask_window(uint32_t rows, uint32_t columns, uint32_t start, uint32_t end, uint8_t *hits,
                                float *ranges, float *points)
{
    uint64_t marked = 0;
    uint32_t u, v;
    for (v = 0; v < columns; ++v) {
        if (rcu_ouster_in_window(v, start, end)) continue;
        for (u = 0; u < rows; ++u) {
            const uint64_t k = (uint64_t)u * columns + v;
            if (hits) hits[k] = 0;
            if (ranges) ranges[k] = NAN;
            if (points) points[3u * k] = points[3u * k + 1u] = points[3u * k + 2u] = NAN;
            ++marked;
        }
    }
    return marked;
}

void rcu_ouster_destagger(const float *in, float *out, uint32_t rows, uint32_t columns, const int32_t *shift)
{
    uint32_t u, v;
    for (u = 0; u < rows; ++u) {
        /* shift mod columns, as a non-negative offset (shifts may be negative) */
        const int64_t s = ((int64_t)shift[u] % (int64_t)columns + (int64_t)columns) % (int64_t)columns;
        for (v = 0; v < columns; ++v)
            out[(uint64_t)u * columns + (uint32_t)(((int64_t)v + s) % (int64_t)columns)] =
                in[(uint64_t)u * columns + v];
    }
}
