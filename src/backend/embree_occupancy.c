#include "backend/embree_occupancy.h"

#include "bvh/intersect.h"
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

static uint32_t cell_index(uint32_t x, uint32_t y, uint32_t z) { return (z * N + y) * N + x; }

/* One pass of the chessboard distance transform: each cell takes one more
 * than the least of its already visited neighbours (the 13 that come before
 * it in the pass's order). A forward and a backward pass give the exact
 * distance (unit weights on the 3x3x3 neighbourhood). */
static void distance_pass(uint8_t *dist, int backward)
{
    const int first = backward ? (int)N - 1 : 0, last = backward ? -1 : (int)N, dir = backward ? -1 : 1;
    int x, y, z, dx, dy, dz;
    for (z = first; z != last; z += dir)
        for (y = first; y != last; y += dir)
            for (x = first; x != last; x += dir) {
                uint8_t *c = &dist[cell_index((uint32_t)x, (uint32_t)y, (uint32_t)z)];
                uint32_t best = *c;
                if (best == 0) continue;
                for (dz = -1; dz <= 0; ++dz)
                    for (dy = -1; dy <= 1; ++dy)
                        for (dx = -1; dx <= 1; ++dx) {
                            /* the neighbours before this cell in the pass's order */
                            const int nx = x + dir * dx, ny = y + dir * dy, nz = z + dir * dz;
                            if (dz == 0 && (dy > 0 || (dy == 0 && dx >= 0))) continue;
                            if (nx < 0 || ny < 0 || nz < 0 || nx >= (int)N || ny >= (int)N || nz >= (int)N) continue;
                            {
                                const uint32_t d = dist[cell_index((uint32_t)nx, (uint32_t)ny, (uint32_t)nz)] + 1u;
                                best = d < best ? d : best;
                            }
                        }
                *c = (uint8_t)best;
            }
}

void rc__occupancy_build(rc__occupancy *g, const rc_scene *scene)
{
    uint32_t k, geom, t;
    memset(g->dist, (int)RC__OCC_FAR, sizeof g->dist);
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
                    for (x = lo[0]; x <= hi[0]; ++x) g->dist[cell_index(x, y, z)] = 0;
        }
    }
    distance_pass(g->dist, 0);
    distance_pass(g->dist, 1);
}

/* Spreads the low 6 bits of v to every third bit. */
static uint32_t spread3(uint32_t v)
{
    uint32_t r = 0, b;
    for (b = 0; b < 6u; ++b) r |= ((v >> b) & 1u) << (3u * b);
    return r;
}

/* A ray's walk through the grid: per axis its origin, the reciprocal of its
 * direction (0 along an axis it does not move on, or where the grid is flat)
 * and the cell's size, so that each step multiplies instead of divides. */
typedef struct occ_walk {
    float org[3], inv[3], size[3];
    int cell[3];
    float next[3]; /* t where the ray leaves the cell on each axis (INFINITY: never) */
} occ_walk;

/* Puts the walk at t along the ray (dir): the cell there, and where the ray
 * leaves that cell on each axis. */
static RC__FORCE_INLINE void enter_cell(const rc__occupancy *g, occ_walk *w, const float dir[3], float t)
{
    int k;
    for (k = 0; k < 3; ++k) {
        w->cell[k] = cell_of(g, k, w->org[k] + dir[k] * t);
        w->next[k] = w->inv[k] == 0.0f ? INFINITY
                                       : (g->min[k] + (float)(w->cell[k] + (w->inv[k] > 0.0f)) * w->size[k] - w->org[k]) *
                                             w->inv[k];
    }
}

uint32_t rc__occupancy_key(const rc__occupancy *g, const float org[3], const float dir[3], float tmax)
{
    float t0 = 0.0f, t1 = tmax, delta[3];
    occ_walk w;
    int k, steps;
    for (k = 0; k < 3; ++k)
        if (!isfinite(org[k]) || !isfinite(dir[k])) return UINT32_MAX;
    for (k = 0; k < 3; ++k) {
        const float lo = g->min[k], hi = g->scale[k] > 0.0f ? g->min[k] + (float)N / g->scale[k] : g->min[k];
        w.org[k] = org[k];
        w.size[k] = g->scale[k] > 0.0f ? 1.0f / g->scale[k] : 0.0f;
        w.inv[k] = dir[k] != 0.0f && g->scale[k] > 0.0f ? 1.0f / dir[k] : 0.0f;
        delta[k] = w.size[k] * fabsf(w.inv[k]);
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
    enter_cell(g, &w, dir, t0);
    /* a ray crosses at most 3N cells, and a leap passes one at least; the
     * bound also ends a NaN walk */
    for (steps = 0; steps < 3 * (int)N; ++steps) {
        const int *c = w.cell;
        const uint32_t d = g->dist[cell_index((uint32_t)c[0], (uint32_t)c[1], (uint32_t)c[2])];
        if (d == 0) return spread3((uint32_t)c[0]) | spread3((uint32_t)c[1]) << 1 | spread3((uint32_t)c[2]) << 2;
        if (d >= 2u) {
            /* every cell within d - 1 of this one is empty: go to where the
             * ray leaves that cube (at least a cell on) */
            float leave = INFINITY;
            for (k = 0; k < 3; ++k) {
                if (w.inv[k] != 0.0f) {
                    const int face = w.inv[k] > 0.0f ? c[k] + (int)d : c[k] - (int)d + 1;
                    const float tk = (g->min[k] + (float)face * w.size[k] - w.org[k]) * w.inv[k];
                    leave = tk < leave ? tk : leave;
                }
            }
            if (!(leave <= t1)) return UINT32_MAX;
            enter_cell(g, &w, dir, leave);
            continue;
        }
        k = w.next[0] < w.next[1] ? (w.next[0] < w.next[2] ? 0 : 2) : (w.next[1] < w.next[2] ? 1 : 2);
        if (!(w.next[k] <= t1)) return UINT32_MAX;
        w.cell[k] += w.inv[k] > 0.0f ? 1 : -1;
        if (w.cell[k] < 0 || w.cell[k] >= (int)N) return UINT32_MAX;
        w.next[k] += delta[k];
    }
    return UINT32_MAX;
}
