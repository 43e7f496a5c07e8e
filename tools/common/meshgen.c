#include "meshgen.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#define RCU_PI 3.14159265358979323846

void rcu_mesh_free(rcu_mesh *mesh)
{
    if (!mesh) return;
    free(mesh->vertices);
    free(mesh->indices);
    memset(mesh, 0, sizeof *mesh);
}

int rcu_mesh_reserve(rcu_mesh *mesh, uint64_t vertices, uint64_t triangles)
{
    memset(mesh, 0, sizeof *mesh);
    if (vertices > UINT32_MAX || triangles > UINT32_MAX || vertices * 3u > SIZE_MAX / sizeof(float))
        return rcu_fail("mesh too large (%llu vertices, %llu triangles)",
                        (unsigned long long)vertices, (unsigned long long)triangles);
    mesh->vertices = (float *)malloc((size_t)(vertices ? vertices : 1) * 3u * sizeof(float));
    mesh->indices = (uint32_t *)malloc((size_t)(triangles ? triangles : 1) * 3u * sizeof(uint32_t));
    if (!mesh->vertices || !mesh->indices) {
        rcu_mesh_free(mesh);
        return rcu_fail("out of memory for a mesh of %llu vertices and %llu triangles",
                        (unsigned long long)vertices, (unsigned long long)triangles);
    }
    return 0;
}

static void put_vertex(rcu_mesh *m, double x, double y, double z)
{
    float *v = m->vertices + 3u * (size_t)m->vertex_count++;
    v[0] = (float)x;
    v[1] = (float)y;
    v[2] = (float)z;
}

static void put_triangle(rcu_mesh *m, uint32_t a, uint32_t b, uint32_t c)
{
    uint32_t *t = m->indices + 3u * (size_t)m->triangle_count++;
    t[0] = a;
    t[1] = b;
    t[2] = c;
}

/* Adds triangle a b c wound so that its normal has a positive dot product with
 * the direction `out`. */
static void put_triangle_facing(rcu_mesh *m, uint32_t a, uint32_t b, uint32_t c, const double out[3])
{
    const float *pa = m->vertices + 3u * (size_t)a, *pb = m->vertices + 3u * (size_t)b,
                *pc = m->vertices + 3u * (size_t)c;
    double e1[3], e2[3], n[3];
    int k;
    for (k = 0; k < 3; k++) {
        e1[k] = (double)pb[k] - pa[k];
        e2[k] = (double)pc[k] - pa[k];
    }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    if (n[0] * out[0] + n[1] * out[1] + n[2] * out[2] < 0.0)
        put_triangle(m, a, c, b);
    else
        put_triangle(m, a, b, c);
}

int rcu_mesh_uv_sphere(float radius, uint32_t segments_around, uint32_t rings, rcu_mesh *out)
{
    uint64_t nv, nt;
    uint32_t i, j, S = segments_around, R = rings, south;
    memset(out, 0, sizeof *out);
    if (!(radius > 0.0f) || S < 3 || R < 2)
        return rcu_fail("uv sphere: need radius > 0, segments >= 3, rings >= 2 (got %g, %u, %u)",
                        (double)radius, S, R);
    nv = (uint64_t)S * (R - 1) + 2;
    nt = 2ull * S * (R - 1);
    if (rcu_mesh_reserve(out, nv, nt) != 0) return -1;

    put_vertex(out, 0.0, 0.0, radius);
    for (i = 1; i < R; i++) {
        double polar = RCU_PI * (double)i / (double)R;
        double s = sin(polar), c = cos(polar);
        for (j = 0; j < S; j++) {
            double az = 2.0 * RCU_PI * (double)j / (double)S;
            put_vertex(out, radius * s * cos(az), radius * s * sin(az), radius * c);
        }
    }
    put_vertex(out, 0.0, 0.0, -(double)radius);
    south = out->vertex_count - 1;

/* vertex of ring i (1 .. R-1), segment j (wraps around) */
#define RING(i_, j_) (1u + ((i_) - 1u) * S + ((j_) % S))
    for (j = 0; j < S; j++) put_triangle(out, 0, RING(1u, j), RING(1u, j + 1u));
    for (i = 1; i + 1 < R; i++) {
        for (j = 0; j < S; j++) {
            uint32_t a = RING(i, j), b = RING(i + 1u, j), c = RING(i + 1u, j + 1u), d = RING(i, j + 1u);
            put_triangle(out, a, b, c);
            put_triangle(out, a, c, d);
        }
    }
    for (j = 0; j < S; j++) put_triangle(out, south, RING(R - 1u, j + 1u), RING(R - 1u, j));
#undef RING
    return 0;
}

void rcu_uv_sphere_shape(uint64_t approx_triangles, uint32_t *segments_around, uint32_t *rings)
{
    double t = (double)(approx_triangles ? approx_triangles : 1);
    double r = floor(sqrt(t / 4.0) + 0.5);
    double s;
    if (r < 2.0) r = 2.0;
    s = floor(t / (2.0 * (r - 1.0)) + 0.5);
    if (s < 3.0) s = 3.0;
    *segments_around = (uint32_t)s;
    *rings = (uint32_t)r;
}

int rcu_mesh_uv_sphere_triangles(float radius, uint64_t approx_triangles, rcu_mesh *out)
{
    uint32_t s, r;
    rcu_uv_sphere_shape(approx_triangles, &s, &r);
    return rcu_mesh_uv_sphere(radius, s, r, out);
}

int rcu_mesh_box(const float min[3], const float max[3], rcu_mesh *out)
{
    /* Faces as corner indices (bit 0 = x, bit 1 = y, bit 2 = z), each with its
     * outward normal axis. */
    static const uint32_t faces[6][4] = {
        {0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    static const double normals[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0},
                                         {0, 1, 0},  {0, 0, -1}, {0, 0, 1}};
    uint32_t i;
    if (rcu_mesh_reserve(out, 8, 12) != 0) return -1;
    for (i = 0; i < 8; i++)
        put_vertex(out, (i & 1u) ? max[0] : min[0], (i & 2u) ? max[1] : min[1],
                   (i & 4u) ? max[2] : min[2]);
    for (i = 0; i < 6; i++) {
        put_triangle_facing(out, faces[i][0], faces[i][1], faces[i][2], normals[i]);
        put_triangle_facing(out, faces[i][0], faces[i][2], faces[i][3], normals[i]);
    }
    return 0;
}

int rcu_mesh_quad(const float p0[3], const float p1[3], const float p2[3], const float p3[3],
                  rcu_mesh *out)
{
    if (rcu_mesh_reserve(out, 4, 2) != 0) return -1;
    put_vertex(out, p0[0], p0[1], p0[2]);
    put_vertex(out, p1[0], p1[1], p1[2]);
    put_vertex(out, p2[0], p2[1], p2[2]);
    put_vertex(out, p3[0], p3[1], p3[2]);
    put_triangle(out, 0, 1, 2);
    put_triangle(out, 0, 2, 3);
    return 0;
}

int rcu_mesh_plane(const float center[3], float half_size, rcu_mesh *out)
{
    float h = half_size;
    float p0[3], p1[3], p2[3], p3[3];
    p0[0] = center[0] - h; p0[1] = center[1] - h; p0[2] = center[2];
    p1[0] = center[0] + h; p1[1] = center[1] - h; p1[2] = center[2];
    p2[0] = center[0] + h; p2[1] = center[1] + h; p2[2] = center[2];
    p3[0] = center[0] - h; p3[1] = center[1] + h; p3[2] = center[2];
    return rcu_mesh_quad(p0, p1, p2, p3, out);
}

int rcu_mesh_cylinder(const float base[3], float radius, float height, uint32_t segments,
                      rcu_mesh *out)
{
    static const double up[3] = {0, 0, 1}, down[3] = {0, 0, -1};
    uint32_t j, bc, tc;
    memset(out, 0, sizeof *out);
    if (segments < 3 || !(radius > 0.0f) || !(height > 0.0f))
        return rcu_fail("cylinder: need segments >= 3, radius > 0, height > 0");
    if (rcu_mesh_reserve(out, 2ull * segments + 2, 4ull * segments) != 0) return -1;
    for (j = 0; j < segments; j++) {
        double a = 2.0 * RCU_PI * (double)j / (double)segments;
        double x = base[0] + radius * cos(a), y = base[1] + radius * sin(a);
        put_vertex(out, x, y, base[2]);
        put_vertex(out, x, y, (double)base[2] + height);
    }
    bc = out->vertex_count;
    put_vertex(out, base[0], base[1], base[2]);
    tc = out->vertex_count;
    put_vertex(out, base[0], base[1], (double)base[2] + height);
    for (j = 0; j < segments; j++) {
        uint32_t k = (j + 1u) % segments;
        uint32_t b0 = 2u * j, t0 = 2u * j + 1u, b1 = 2u * k, t1 = 2u * k + 1u;
        double a = 2.0 * RCU_PI * ((double)j + 0.5) / (double)segments;
        double side[3];
        side[0] = cos(a);
        side[1] = sin(a);
        side[2] = 0.0;
        put_triangle_facing(out, b0, b1, t1, side);
        put_triangle_facing(out, b0, t1, t0, side);
        put_triangle_facing(out, bc, b0, b1, down);
        put_triangle_facing(out, tc, t0, t1, up);
    }
    return 0;
}

int rcu_mesh_wedge(const float min[3], const float max[3], rcu_mesh *out)
{
    /* 0..3 bottom (x0y0, x1y0, x1y1, x0y1), 4 = x1y0 top, 5 = x1y1 top */
    static const double nx[3] = {1, 0, 0}, ny0[3] = {0, -1, 0}, ny1[3] = {0, 1, 0},
                        nz0[3] = {0, 0, -1};
    double slope[3];
    if (rcu_mesh_reserve(out, 6, 8) != 0) return -1;
    put_vertex(out, min[0], min[1], min[2]);
    put_vertex(out, max[0], min[1], min[2]);
    put_vertex(out, max[0], max[1], min[2]);
    put_vertex(out, min[0], max[1], min[2]);
    put_vertex(out, max[0], min[1], max[2]);
    put_vertex(out, max[0], max[1], max[2]);
    slope[0] = -((double)max[2] - min[2]);
    slope[1] = 0.0;
    slope[2] = (double)max[0] - min[0];
    put_triangle_facing(out, 0, 1, 2, nz0);
    put_triangle_facing(out, 0, 2, 3, nz0);
    put_triangle_facing(out, 1, 2, 5, nx);
    put_triangle_facing(out, 1, 5, 4, nx);
    put_triangle_facing(out, 0, 1, 4, ny0);
    put_triangle_facing(out, 3, 2, 5, ny1);
    put_triangle_facing(out, 0, 4, 5, slope);
    put_triangle_facing(out, 0, 5, 3, slope);
    return 0;
}

int rcu_mesh_append(rcu_mesh *dst, const rcu_mesh *src)
{
    uint64_t nv = (uint64_t)dst->vertex_count + src->vertex_count;
    uint64_t nt = (uint64_t)dst->triangle_count + src->triangle_count;
    float *v;
    uint32_t *t;
    uint32_t i, base = dst->vertex_count;
    if (nv > UINT32_MAX || nt > UINT32_MAX) return rcu_fail("mesh append: more than 2^32 elements");
    v = (float *)realloc(dst->vertices, (size_t)(nv ? nv : 1) * 3u * sizeof(float));
    if (!v) return rcu_fail("mesh append: out of memory");
    dst->vertices = v;
    t = (uint32_t *)realloc(dst->indices, (size_t)(nt ? nt : 1) * 3u * sizeof(uint32_t));
    if (!t) return rcu_fail("mesh append: out of memory");
    dst->indices = t;
    memcpy(v + 3u * (size_t)dst->vertex_count, src->vertices, (size_t)src->vertex_count * 3u * sizeof(float));
    for (i = 0; i < 3u * src->triangle_count; i++)
        t[3u * (size_t)dst->triangle_count + i] = src->indices[i] + base;
    dst->vertex_count = (uint32_t)nv;
    dst->triangle_count = (uint32_t)nt;
    return 0;
}

uint32_t rcu_mesh_part_first(uint32_t triangles, uint32_t parts, uint32_t k)
{
    return (uint32_t)((uint64_t)triangles * k / parts);
}

int rcu_mesh_split(const rcu_mesh *mesh, uint32_t parts, rcu_mesh *out)
{
    uint32_t *map, k, j, c;
    if (parts == 0 || parts > mesh->triangle_count)
        return rcu_fail("cannot cut %u triangles into %u meshes", mesh->triangle_count, parts);
    map = (uint32_t *)malloc((size_t)(mesh->vertex_count ? mesh->vertex_count : 1) * sizeof *map);
    if (!map) return rcu_fail("out of memory for a vertex map of %u vertices", mesh->vertex_count);
    memset(map, 0xFF, (size_t)mesh->vertex_count * sizeof *map);
    for (k = 0; k < parts; ++k) {
        const uint32_t first = rcu_mesh_part_first(mesh->triangle_count, parts, k);
        const uint32_t count = rcu_mesh_part_first(mesh->triangle_count, parts, k + 1u) - first;
        const uint32_t *tri = mesh->indices + 3u * (size_t)first;
        uint32_t used = 0;
        /* the vertices this part uses, numbered as first met */
        for (j = 0; j < 3u * count; ++j)
            if (map[tri[j]] == UINT32_MAX) map[tri[j]] = used++;
        if (rcu_mesh_reserve(&out[k], used, count) != 0) {
            while (k-- > 0) rcu_mesh_free(&out[k]);
            free(map);
            return -1;
        }
        for (j = 0; j < 3u * count; ++j) {
            const uint32_t v = map[tri[j]];
            out[k].indices[j] = v;
            for (c = 0; c < 3u; ++c) out[k].vertices[3u * (size_t)v + c] = mesh->vertices[3u * (size_t)tri[j] + c];
        }
        out[k].vertex_count = used;
        out[k].triangle_count = count;
        for (j = 0; j < 3u * count; ++j) map[tri[j]] = UINT32_MAX;
    }
    free(map);
    return 0;
}

void rcu_mesh_transform(rcu_mesh *mesh, float yaw, const float translation[3])
{
    double c = cos((double)yaw), s = sin((double)yaw);
    uint32_t i;
    for (i = 0; i < mesh->vertex_count; i++) {
        float *p = mesh->vertices + 3u * (size_t)i;
        double x = p[0], y = p[1];
        p[0] = (float)(c * x - s * y + translation[0]);
        p[1] = (float)(s * x + c * y + translation[1]);
        p[2] = (float)((double)p[2] + translation[2]);
    }
}

void rcu_mesh_bounds(const rcu_mesh *mesh, float bounds[6])
{
    uint32_t i;
    int k;
    if (mesh->vertex_count == 0) {
        for (k = 0; k < 6; k++) bounds[k] = 0.0f;
        return;
    }
    for (k = 0; k < 3; k++) bounds[k] = bounds[k + 3] = mesh->vertices[k];
    for (i = 1; i < mesh->vertex_count; i++) {
        const float *p = mesh->vertices + 3u * (size_t)i;
        for (k = 0; k < 3; k++) {
            if (p[k] < bounds[k]) bounds[k] = p[k];
            if (p[k] > bounds[k + 3]) bounds[k + 3] = p[k];
        }
    }
}

/* ---- the demo warehouse ------------------------------------------------- */

/* Appends a generated part to the map and frees it; keeps the first error. */
static int take(rcu_mesh *map, rcu_mesh *part, int status)
{
    if (status == 0) status = rcu_mesh_append(map, part);
    rcu_mesh_free(part);
    return status;
}

static int add_box(rcu_mesh *map, float x0, float y0, float z0, float x1, float y1, float z1)
{
    rcu_mesh part;
    float lo[3], hi[3];
    lo[0] = x0; lo[1] = y0; lo[2] = z0;
    hi[0] = x1; hi[1] = y1; hi[2] = z1;
    return take(map, &part, rcu_mesh_box(lo, hi, &part));
}

/* A box of size sx, sy, sz standing on z = z0 at centre (cx, cy), turned by yaw. */
static int add_turned_box(rcu_mesh *map, float cx, float cy, float z0, float sx, float sy, float sz,
                          float yaw)
{
    rcu_mesh part;
    float lo[3], hi[3], t[3];
    int st;
    lo[0] = -0.5f * sx; lo[1] = -0.5f * sy; lo[2] = 0.0f;
    hi[0] = 0.5f * sx; hi[1] = 0.5f * sy; hi[2] = sz;
    t[0] = cx; t[1] = cy; t[2] = z0;
    st = rcu_mesh_box(lo, hi, &part);
    if (st == 0) rcu_mesh_transform(&part, yaw, t);
    return take(map, &part, st);
}

/* A pallet rack: 4 uprights, `levels` shelf boards, crates on some shelves. */
static int add_rack(rcu_mesh *map, float x0, float y0, float length, float depth, float height,
                    int levels, uint32_t seed)
{
    const float post = 0.08f, board = 0.05f;
    int st = 0, level, k;
    float x1 = x0 + length, y1 = y0 + depth;
    st |= add_box(map, x0, y0, 0, x0 + post, y0 + post, height);
    st |= add_box(map, x1 - post, y0, 0, x1, y0 + post, height);
    st |= add_box(map, x0, y1 - post, 0, x0 + post, y1, height);
    st |= add_box(map, x1 - post, y1 - post, 0, x1, y1, height);
    for (level = 0; level < levels && st == 0; level++) {
        float z = 0.15f + (height - 0.4f) * (float)level / (float)(levels - 1);
        st |= add_box(map, x0, y0, z, x1, y1, z + board);
        /* crates: sizes and gaps from a tiny LCG, so the shelves are not uniform */
        if (level + 1 < levels) {
            float x = x0 + post + 0.05f;
            for (k = 0; k < 6 && st == 0; k++) {
                float w, d, h;
                seed = seed * 1664525u + 1013904223u;
                w = 0.35f + 0.35f * (float)((seed >> 8) & 255u) / 255.0f;
                d = 0.45f + 0.35f * (float)((seed >> 16) & 255u) / 255.0f;
                h = 0.25f + 0.35f * (float)((seed >> 24) & 255u) / 255.0f;
                if (d > depth - 0.1f) d = depth - 0.1f;
                if (x + w > x1 - post - 0.05f) break;
                if ((seed & 3u) != 0u) /* leave about one slot in four empty */
                    st |= add_box(map, x, y0 + 0.05f, z + board, x + w, y0 + 0.05f + d, z + board + h);
                x += w + 0.08f;
            }
        }
    }
    return st;
}

int rcu_mesh_demo_map(rcu_mesh *out)
{
    rcu_mesh part;
    int st = 0, i;
    float p[3], lo[3], hi[3];
    memset(out, 0, sizeof *out);
    memset(&part, 0, sizeof part);

    /* The hall: one closed box seen from inside (floor, walls, ceiling). */
    st |= add_box(out, -10.0f, -6.0f, 0.0f, 10.0f, 6.0f, 4.0f);

    /* Pillars along the middle. */
    for (i = 0; i < 4 && st == 0; i++) {
        float x = -6.0f + 4.0f * (float)i;
        st |= add_box(out, x - 0.2f, -0.2f, 0.0f, x + 0.2f, 0.2f, 4.0f);
    }

    /* Racks along the north wall, one along the west wall. */
    st |= add_rack(out, -9.2f, 4.6f, 4.2f, 1.1f, 3.2f, 4, 11u);
    st |= add_rack(out, -4.4f, 4.6f, 4.2f, 1.1f, 3.2f, 4, 23u);
    st |= add_rack(out, 0.4f, 4.6f, 4.2f, 1.1f, 3.2f, 4, 37u);
    if (st == 0) {
        rcu_mesh rack;
        float t[3];
        memset(&rack, 0, sizeof rack);
        st = add_rack(&rack, -2.0f, 0.0f, 4.0f, 1.0f, 2.4f, 3, 53u);
        t[0] = -9.0f; t[1] = -1.0f; t[2] = 0.0f;
        if (st == 0) rcu_mesh_transform(&rack, (float)(-0.5 * RCU_PI), t); /* along the west wall */
        st = take(out, &rack, st);
    }

    /* A ramp up to a loading platform in the south-east corner. */
    lo[0] = 3.0f; lo[1] = -5.6f; lo[2] = 0.0f;
    hi[0] = 6.5f; hi[1] = -3.6f; hi[2] = 1.0f;
    st = take(out, &part, st == 0 ? rcu_mesh_wedge(lo, hi, &part) : st);
    st |= add_box(out, 6.5f, -5.8f, 0.0f, 9.8f, -2.2f, 1.0f);
    st |= add_box(out, 6.5f, -2.3f, 1.0f, 9.8f, -2.2f, 2.0f);     /* a railing plate */
    st |= add_turned_box(out, 8.6f, -4.6f, 1.0f, 1.2f, 1.0f, 0.9f, 0.3f); /* crate on it */

    /* Stacked boxes near the south-west. */
    st |= add_turned_box(out, -6.5f, -3.8f, 0.0f, 1.2f, 1.2f, 1.0f, 0.0f);
    st |= add_turned_box(out, -5.2f, -3.9f, 0.0f, 1.2f, 1.0f, 0.8f, 0.2f);
    st |= add_turned_box(out, -6.4f, -3.7f, 1.0f, 1.0f, 1.0f, 0.7f, -0.25f);
    st |= add_turned_box(out, -3.0f, -2.2f, 0.0f, 1.6f, 0.6f, 0.5f, 0.7f);
    /* A pallet with a tall crate in the open floor. */
    st |= add_turned_box(out, 2.3f, 1.8f, 0.0f, 1.2f, 1.0f, 0.15f, -0.4f);
    st |= add_turned_box(out, 2.3f, 1.8f, 0.15f, 0.9f, 0.8f, 1.4f, -0.4f);

    /* Barrels. */
    for (i = 0; i < 7 && st == 0; i++) {
        static const float spots[7][2] = {{-1.2f, -4.9f}, {-0.5f, -5.1f}, {-0.9f, -4.3f},
                                          {0.2f, -4.8f},  {7.2f, 2.5f},   {7.9f, 2.9f},
                                          {7.4f, 3.4f}};
        p[0] = spots[i][0];
        p[1] = spots[i][1];
        p[2] = 0.0f;
        st = take(out, &part, rcu_mesh_cylinder(p, 0.3f, 0.9f, 24, &part));
    }
    /* A ball on a plinth. */
    st |= add_box(out, 4.6f, 1.4f, 0.0f, 5.4f, 2.2f, 0.6f);
    if (st == 0) {
        float t[3];
        t[0] = 5.0f; t[1] = 1.8f; t[2] = 1.0f;
        st = rcu_mesh_uv_sphere(0.4f, 32, 16, &part);
        if (st == 0) rcu_mesh_transform(&part, 0.0f, t);
        st = take(out, &part, st);
    }
    if (st != 0) {
        rcu_mesh_free(out);
        return -1;
    }
    return 0;
}
