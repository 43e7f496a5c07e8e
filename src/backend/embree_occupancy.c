#include "backend/embree_occupancy.h"

#include "scene/scene.h"

#include <math.h>
#include <string.h>

#define N RC__OCC_N

static int cell_of(const rc__occupancy *g, int axis, float v)
{
    const float c = (v - g->min[axis]) * g->scale[axis];
    if (!(c > 0.0f)) return 0; /* NaN too */
    return c >= (float)(N - 1u) ? (int)(N - 1u) : (int)c;
}

static void set_bit(rc__occupancy *g, uint32_t x, uint32_t y, uint32_t z)
{
    const uint32_t i = (z * N + y) * N + x;
    g->bits[i >> 3] = (uint8_t)(g->bits[i >> 3] | (1u << (i & 7u)));
}

static int get_bit(const rc__occupancy *g, uint32_t x, uint32_t y, uint32_t z)
{
    const uint32_t i = (z * N + y) * N + x;
    return (g->bits[i >> 3] >> (i & 7u)) & 1u;
}

void rc__occupancy_build(rc__occupancy *g, const rc_scene *scene)
{
    uint32_t k, geom, t;
    memset(g->bits, 0, sizeof g->bits);
    g->triangles = scene->triangle_count;
    memcpy(g->bounds, &scene->bounds, sizeof g->bounds);
    for (k = 0; k < 3; ++k) {
        const float ext = scene->bounds.max[k] - scene->bounds.min[k];
        g->min[k] = scene->bounds.min[k];
        /* a little more than the extent, so the far face falls in the last cell */
        g->scale[k] = ext > 0.0f && isfinite(ext) ? (float)N / (ext * 1.0001f) : 0.0f;
    }
    for (geom = 0; geom < scene->geom_count; ++geom) {
        const rc__mesh *m = &scene->geoms[geom].mesh;
        for (t = 0; t < m->triangle_count; ++t) {
            const float *v[3];
            uint32_t lo[3], hi[3], x, y, z, c;
            for (c = 0; c < 3; ++c) v[c] = m->vertices + (size_t)m->indices[3u * t + c] * m->stride;
            for (k = 0; k < 3; ++k) {
                float mn = v[0][k], mx = v[0][k];
                for (c = 1; c < 3; ++c) {
                    mn = v[c][k] < mn ? v[c][k] : mn;
                    mx = v[c][k] > mx ? v[c][k] : mx;
                }
                lo[k] = (uint32_t)cell_of(g, (int)k, mn);
                hi[k] = (uint32_t)cell_of(g, (int)k, mx);
            }
            for (z = lo[2]; z <= hi[2]; ++z)
                for (y = lo[1]; y <= hi[1]; ++y)
                    for (x = lo[0]; x <= hi[0]; ++x) set_bit(g, x, y, z);
        }
    }
}

/* Spreads the low 6 bits of v to every third bit. */
static uint32_t spread3(uint32_t v)
{
    uint32_t r = 0, b;
    for (b = 0; b < 6u; ++b) r |= ((v >> b) & 1u) << (3u * b);
    return r;
}

uint32_t rc__occupancy_key(const rc__occupancy *g, const float org[3], const float dir[3], float tmax)
{
    float t0 = 0.0f, t1 = tmax, next[3], delta[3];
    int cell[3], step[3], k, steps;
    for (k = 0; k < 3; ++k)
        if (!isfinite(org[k]) || !isfinite(dir[k])) return UINT32_MAX;
    for (k = 0; k < 3; ++k) {
        const float lo = g->min[k], hi = g->scale[k] > 0.0f ? g->min[k] + (float)N / g->scale[k] : g->min[k];
        if (dir[k] != 0.0f) {
            float a = (lo - org[k]) / dir[k], b = (hi - org[k]) / dir[k];
            if (a > b) {
                const float s = a;
                a = b, b = s;
            }
            t0 = a > t0 ? a : t0;
            t1 = b < t1 ? b : t1;
        } else if (!(org[k] >= lo && org[k] <= hi)) {
            return UINT32_MAX;
        }
    }
    if (!(t0 <= t1)) return UINT32_MAX; /* misses the grid, or NaN */
    for (k = 0; k < 3; ++k) {
        const float p = org[k] + dir[k] * t0, size = g->scale[k] > 0.0f ? 1.0f / g->scale[k] : 0.0f;
        cell[k] = cell_of(g, k, p);
        step[k] = dir[k] > 0.0f ? 1 : -1;
        if (dir[k] == 0.0f || size == 0.0f) {
            next[k] = delta[k] = INFINITY;
        } else {
            /* distance to the cell's exit face along the ray */
            const float face = g->min[k] + (float)(cell[k] + (dir[k] > 0.0f ? 1 : 0)) * size;
            next[k] = (face - org[k]) / dir[k];
            delta[k] = size / fabsf(dir[k]);
        }
    }
    /* a ray crosses at most 3N cells; the bound also ends a NaN walk */
    for (steps = 0; steps < 3 * (int)N; ++steps) {
        if (get_bit(g, (uint32_t)cell[0], (uint32_t)cell[1], (uint32_t)cell[2]))
            return spread3((uint32_t)cell[0]) | spread3((uint32_t)cell[1]) << 1 | spread3((uint32_t)cell[2]) << 2;
        k = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
        if (!(next[k] <= t1)) return UINT32_MAX;
        cell[k] += step[k];
        if (cell[k] < 0 || cell[k] >= (int)N) return UINT32_MAX;
        next[k] += delta[k];
    }
    return UINT32_MAX;
}
