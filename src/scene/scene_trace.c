/* Nearest-hit search through a scene's two levels: the top BVH over geometries
 * and instances, then each mesh's BVH (instances in their own frame). */
#include "scene/scene.h"

#include "bvh/intersect.h"
#include "bvh/leaf4.h" /* rc__leaf4_have_avx2 */

#include <math.h>
#if defined(RC__HIT_DISTANCES_SSE2) && defined(RC__LEAF4_PAIR_AVX2)
#include <immintrin.h>
#endif

/* Slab test against a top-level node. Top-level boxes are few, so this is not
 * the hot loop; NaN from 0 * inf is avoided by the ordered min/max below. */
static int box_hit(const rc__ray *r, const float bmin[3], const float bmax[3], float tmax, float *tnear)
{
    float t0 = 0.0f, t1 = tmax;
    int k;
    for (k = 0; k < 3; ++k) {
        float a = (bmin[k] - r->org[k]) * r->inv_dir[k];
        float b = (bmax[k] - r->org[k]) * r->inv_dir[k];
        float lo = a < b ? a : b, hi = a < b ? b : a;
        if (a != a || b != b) { /* 0 * inf: origin on the slab plane with a parallel ray */
            if (r->org[k] < bmin[k] || r->org[k] > bmax[k]) return 0;
            continue;
        }
        if (lo > t0) t0 = lo;
        if (hi < t1) t1 = hi;
    }
    /* Ize's bound, as in the mesh trees: rounding never rejects a box the ray
     * meets (a smaller margin could cull a mesh that a grazing ray hits, and
     * the packet path, which tests every mesh, would then disagree) */
    *tnear = t0;
    return t0 <= t1 * RC__SLAB_FAR_SCALE;
}

static int instance_intersect(const rc__instance *in, uint32_t inst_id, const rc__ray *ray, rc__hit *hit)
{
    const rc_scene *src = in->source;
    rc__ray local;
    float o[3], d[3];
    uint32_t g;
    int found = 0;
    rc__rot_apply_f(in->to_local.r, ray->org, o);
    o[0] += in->to_local.t[0];
    o[1] += in->to_local.t[1];
    o[2] += in->to_local.t[2];
    rc__rot_apply_f(in->to_local.r, ray->dir, d);
    rc__ray_prepare(&local, o, d);
    /* Sources hold a few meshes: test each mesh's root through its own BVH. */
    for (g = 0; g < src->geom_count; ++g) found |= rc__mesh_intersect(&src->geoms[g].mesh, &local, g, inst_id, hit);
    return found;
}

int rc__scene_intersect_items(const rc_scene *scene, const rc__ray *ray, rc__hit *hit, uint32_t first)
{
    uint32_t stack[RC__BVH_MAX_DEPTH + 1];
    uint32_t sp = 0, ni = 0;
    int found = 0;
    const rc__bvh *top = &scene->top;

    if (scene->geom_count == 1 && scene->inst_count == 0)
        return rc__mesh_intersect(&scene->geoms[0].mesh, ray, 0, RC_INVALID_ID, hit);
    if (top->node_count == 0) return 0;
    for (;;) {
        const rc__bvh_node *n = &top->nodes[ni];
        float tn;
        if (box_hit(ray, n->bmin, n->bmax, hit->t, &tn)) {
            if (n->count == 0) {
                stack[sp++] = n->index + 1; /* depth is capped by the builder */
                ni = n->index;
                continue;
            } else {
                uint32_t k;
                for (k = 0; k < n->count; ++k) {
                    uint32_t item = top->refs[n->index + k];
                    if (item < first) continue;
                    if (item < scene->geom_count)
                        found |= rc__mesh_intersect(&scene->geoms[item].mesh, ray, item, RC_INVALID_ID, hit);
                    else
                        found |= instance_intersect(&scene->insts[item - scene->geom_count],
                                                    item - scene->geom_count, ray, hit);
                }
            }
        }
        if (sp == 0) break;
        ni = stack[--sp];
    }
    return found;
}

/* The mesh of a hit and its instance transform (NULL without one). */
static const rc__mesh *hit_mesh(const rc_scene *scene, const rc__hit *hit, const rc__xformf **x)
{
    if (hit->inst == RC_INVALID_ID) {
        *x = NULL;
        return &scene->geoms[hit->geom].mesh;
    }
    *x = &scene->insts[hit->inst].to_world;
    return &scene->insts[hit->inst].source->geoms[hit->geom].mesh;
}

void rc__scene_hit_normal(const rc_scene *scene, const rc__hit *hit, float n[3])
{
    const rc__xformf *x;
    const rc__mesh *mesh = hit_mesh(scene, hit, &x);
    float local[3];
    double len;
    rc__mesh_triangle_normal(mesh, hit->prim, local);
    if (x) {
        rc__rot_apply_f(scene->insts[hit->inst].normal_to_world, local, n);
    } else {
        n[0] = local[0];
        n[1] = local[1];
        n[2] = local[2];
    }
    len = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
    if (len > 0.0) {
        n[0] = (float)(n[0] / len);
        n[1] = (float)(n[1] / len);
        n[2] = (float)(n[2] / len);
    }
}

/* The hit triangle's vertex indices: the leaf-ordered copy was just read by
 * the built-in triangle test (cached); the mesh's own index array is a miss on
 * a large map. */
static const uint32_t *hit_triangle(const rc__mesh *mesh, const rc__hit *hit)
{
    return hit->slot != RC_INVALID_ID && mesh->leaf_tris ? mesh->leaf_tris + (size_t)3 * hit->slot
                                                         : mesh->indices + (size_t)3 * hit->prim;
}

/* r * (px, py, pz) in double, r row-major 3x3 (force-inlined: the results
 * stay in registers). */
static RC__FORCE_INLINE void rot_d(const double r[9], double px, double py, double pz, double *x, double *y,
                                   double *z)
{
    *x = r[0] * px + r[1] * py + r[2] * pz;
    *y = r[3] * px + r[4] * py + r[5] * pz;
    *z = r[6] * px + r[7] * py + r[8] * pz;
}

/* Written with scalar locals, not arrays: gcc pairs array elements into
 * 16-byte loads of values it had just stored 8 bytes at a time, and the CPU
 * cannot forward two stores into one load (a stall of a dozen cycles or
 * more, which made this function 18% of the time on a 1k map). */
double rc__scene_hit_distance_d(const rc_scene *scene, const rc__hit *hit, const rc__xformf *world,
                                const float dir_s[3], const float *org_s)
{
    const rc__xformf *x;
    const rc__mesh *mesh = hit_mesh(scene, hit, &x);
    const uint32_t *tri = hit_triangle(mesh, hit);
    const float *p0 = mesh->vertices + (size_t)tri[0] * mesh->stride;
    const float *p1 = mesh->vertices + (size_t)tri[1] * mesh->stride;
    const float *p2 = mesh->vertices + (size_t)tri[2] * mesh->stride;
    double dx, dy, dz, ox = world->td[0], oy = world->td[1], oz = world->td[2];
    double ax, ay, az, bx, by, bz, cx, cy, cz, e1x, e1y, e1z, e2x, e2y, e2z, nx, ny, nz, dn, w;
    /* the ray in the scene frame, in double */
    rot_d(world->rd, dir_s[0], dir_s[1], dir_s[2], &dx, &dy, &dz);
    if (org_s) {
        double px, py, pz;
        rot_d(world->rd, org_s[0], org_s[1], org_s[2], &px, &py, &pz);
        ox += px, oy += py, oz += pz;
    }
    if (x) {
        rot_d(x->rd, p0[0], p0[1], p0[2], &ax, &ay, &az);
        rot_d(x->rd, p1[0], p1[1], p1[2], &bx, &by, &bz);
        rot_d(x->rd, p2[0], p2[1], p2[2], &cx, &cy, &cz);
        ax += x->td[0], ay += x->td[1], az += x->td[2];
        bx += x->td[0], by += x->td[1], bz += x->td[2];
        cx += x->td[0], cy += x->td[1], cz += x->td[2];
    } else {
        ax = p0[0], ay = p0[1], az = p0[2];
        bx = p1[0], by = p1[1], bz = p1[2];
        cx = p2[0], cy = p2[1], cz = p2[2];
    }
    e1x = bx - ax, e1y = by - ay, e1z = bz - az;
    e2x = cx - ax, e2y = cy - ay, e2z = cz - az;
    nx = e1y * e2z - e1z * e2y;
    ny = e1z * e2x - e1x * e2z;
    nz = e1x * e2y - e1y * e2x;
    dn = nx * dx + ny * dy + nz * dz;
    w = nx * (ax - ox) + ny * (ay - oy) + nz * (az - oz);
    if (dn == 0.0 || !isfinite(w / dn)) return hit->t;
    return w / dn;
}

#if defined(RC__HIT_DISTANCES_SSE2)
/* Two hits' vertices, converted to double, one hit a lane */
#define PAIR_PD(p, q, k) _mm_setr_pd((double)(p)[k], (double)(q)[k])

/* rc__scene_hit_distance_d of hits i and j (own meshes, shared origin) in
 * the two lanes of SSE2 doubles: the same operations in the same order, so
 * each lane is the scalar function's value bit for bit. */
static void hit_distance_pair(const rc_scene *scene, const rc__hit *hi, const rc__hit *hj, const rc__xformf *world,
                              const float *di, const float *dj, double *ti, double *tj)
{
    const rc__mesh *mi = &scene->geoms[hi->geom].mesh, *mj = &scene->geoms[hj->geom].mesh;
    const uint32_t *tri_i = hit_triangle(mi, hi), *tri_j = hit_triangle(mj, hj);
    const float *a0 = mi->vertices + (size_t)tri_i[0] * mi->stride, *a1 = mj->vertices + (size_t)tri_j[0] * mj->stride;
    const float *b0 = mi->vertices + (size_t)tri_i[1] * mi->stride, *b1 = mj->vertices + (size_t)tri_j[1] * mj->stride;
    const float *c0 = mi->vertices + (size_t)tri_i[2] * mi->stride, *c1 = mj->vertices + (size_t)tri_j[2] * mj->stride;
    const double *r = world->rd;
    const __m128d px = PAIR_PD(di, dj, 0), py = PAIR_PD(di, dj, 1), pz = PAIR_PD(di, dj, 2);
    const __m128d dx = _mm_add_pd(_mm_add_pd(_mm_mul_pd(_mm_set1_pd(r[0]), px), _mm_mul_pd(_mm_set1_pd(r[1]), py)),
                                  _mm_mul_pd(_mm_set1_pd(r[2]), pz));
    const __m128d dy = _mm_add_pd(_mm_add_pd(_mm_mul_pd(_mm_set1_pd(r[3]), px), _mm_mul_pd(_mm_set1_pd(r[4]), py)),
                                  _mm_mul_pd(_mm_set1_pd(r[5]), pz));
    const __m128d dz = _mm_add_pd(_mm_add_pd(_mm_mul_pd(_mm_set1_pd(r[6]), px), _mm_mul_pd(_mm_set1_pd(r[7]), py)),
                                  _mm_mul_pd(_mm_set1_pd(r[8]), pz));
    const __m128d ax = PAIR_PD(a0, a1, 0), ay = PAIR_PD(a0, a1, 1), az = PAIR_PD(a0, a1, 2);
    const __m128d e1x = _mm_sub_pd(PAIR_PD(b0, b1, 0), ax), e1y = _mm_sub_pd(PAIR_PD(b0, b1, 1), ay);
    const __m128d e1z = _mm_sub_pd(PAIR_PD(b0, b1, 2), az), e2x = _mm_sub_pd(PAIR_PD(c0, c1, 0), ax);
    const __m128d e2y = _mm_sub_pd(PAIR_PD(c0, c1, 1), ay), e2z = _mm_sub_pd(PAIR_PD(c0, c1, 2), az);
    const __m128d nx = _mm_sub_pd(_mm_mul_pd(e1y, e2z), _mm_mul_pd(e1z, e2y));
    const __m128d ny = _mm_sub_pd(_mm_mul_pd(e1z, e2x), _mm_mul_pd(e1x, e2z));
    const __m128d nz = _mm_sub_pd(_mm_mul_pd(e1x, e2y), _mm_mul_pd(e1y, e2x));
    const __m128d dn = _mm_add_pd(_mm_add_pd(_mm_mul_pd(nx, dx), _mm_mul_pd(ny, dy)), _mm_mul_pd(nz, dz));
    const __m128d w =
        _mm_add_pd(_mm_add_pd(_mm_mul_pd(nx, _mm_sub_pd(ax, _mm_set1_pd(world->td[0]))),
                              _mm_mul_pd(ny, _mm_sub_pd(ay, _mm_set1_pd(world->td[1])))),
                   _mm_mul_pd(nz, _mm_sub_pd(az, _mm_set1_pd(world->td[2]))));
    double q[2], d[2];
    _mm_storeu_pd(q, _mm_div_pd(w, dn));
    _mm_storeu_pd(d, dn);
    *ti = d[0] == 0.0 || !isfinite(q[0]) ? (double)hi->t : q[0];
    *tj = d[1] == 0.0 || !isfinite(q[1]) ? (double)hj->t : q[1];
}
#undef PAIR_PD

#if defined(RC__LEAF4_PAIR_AVX2)
/* Four hits' vertex coordinate k, converted to double, one hit a lane */
#define QUAD_PD(p, k) _mm256_cvtps_pd(_mm_setr_ps((p)[0][k], (p)[1][k], (p)[2][k], (p)[3][k]))

/* hit_distance_pair for four hits (the hits[at[0..3]]) in AVX doubles, where
 * the CPU has AVX2 (rc__leaf4_have_avx2): again the scalar function's
 * operations in its order, lane for lane, without fused multiply-add (the
 * target does not enable it), so each value is its value bit for bit
 * (session 28: 12% fewer of the refinement's instructions on a 1k map than
 * two at a time; gathering the vertices is most of what is left). */
static __attribute__((target("avx2"))) void hit_distance_quad(const rc_scene *scene, const rc__hit *hits,
                                                             const uint32_t at[4], const rc__xformf *world,
                                                             const float *directions, const uint32_t *idx,
                                                             double *td)
{
    const float *a[4], *b[4], *c[4], *dir[4];
    const double *r = world->rd;
    const rc__mesh *one = &scene->geoms[0].mesh;
    uint32_t i;
    if (scene->geom_count == 1 && one->leaf_tris && hits[at[0]].slot != RC_INVALID_ID &&
        hits[at[1]].slot != RC_INVALID_ID && hits[at[2]].slot != RC_INVALID_ID && hits[at[3]].slot != RC_INVALID_ID) {
        /* one own mesh, every hit with its leaf slot (the built-in
         * backend's map): the mesh's fields read once, not once a hit */
        const float *vertices = one->vertices;
        const uint32_t *leaf_tris = one->leaf_tris;
        const size_t stride = one->stride;
        for (i = 0; i < 4; ++i) {
            const uint32_t *tri = leaf_tris + (size_t)3 * hits[at[i]].slot;
            a[i] = vertices + (size_t)tri[0] * stride;
            b[i] = vertices + (size_t)tri[1] * stride;
            c[i] = vertices + (size_t)tri[2] * stride;
            dir[i] = directions + (size_t)idx[at[i]] * 3u;
        }
    } else {
        for (i = 0; i < 4; ++i) {
            const rc__hit *h = &hits[at[i]];
            const rc__mesh *m = &scene->geoms[h->geom].mesh;
            const uint32_t *tri = hit_triangle(m, h);
            a[i] = m->vertices + (size_t)tri[0] * m->stride;
            b[i] = m->vertices + (size_t)tri[1] * m->stride;
            c[i] = m->vertices + (size_t)tri[2] * m->stride;
            dir[i] = directions + (size_t)idx[at[i]] * 3u;
        }
    }
    {
        const __m256d px = QUAD_PD(dir, 0), py = QUAD_PD(dir, 1), pz = QUAD_PD(dir, 2);
        const __m256d dx = _mm256_add_pd(
            _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(r[0]), px), _mm256_mul_pd(_mm256_set1_pd(r[1]), py)),
            _mm256_mul_pd(_mm256_set1_pd(r[2]), pz));
        const __m256d dy = _mm256_add_pd(
            _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(r[3]), px), _mm256_mul_pd(_mm256_set1_pd(r[4]), py)),
            _mm256_mul_pd(_mm256_set1_pd(r[5]), pz));
        const __m256d dz = _mm256_add_pd(
            _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(r[6]), px), _mm256_mul_pd(_mm256_set1_pd(r[7]), py)),
            _mm256_mul_pd(_mm256_set1_pd(r[8]), pz));
        __m256d ax, ay, az, nx, ny, nz, dn, w;
        double q[4];
        if (a[0] == a[1] && a[0] == a[2] && a[0] == a[3] && b[0] == b[1] && b[0] == b[2] && b[0] == b[3] &&
            c[0] == c[1] && c[0] == c[2] && c[0] == c[3]) {
            /* one triangle for all four (most groups on a small map): its
             * normal once, by the same operations in scalar doubles, so
             * the same values */
            const double sax = a[0][0], say = a[0][1], saz = a[0][2];
            const double e1x = b[0][0] - sax, e1y = b[0][1] - say, e1z = b[0][2] - saz;
            const double e2x = c[0][0] - sax, e2y = c[0][1] - say, e2z = c[0][2] - saz;
            ax = _mm256_set1_pd(sax), ay = _mm256_set1_pd(say), az = _mm256_set1_pd(saz);
            nx = _mm256_set1_pd(e1y * e2z - e1z * e2y);
            ny = _mm256_set1_pd(e1z * e2x - e1x * e2z);
            nz = _mm256_set1_pd(e1x * e2y - e1y * e2x);
        } else {
            __m256d e1x, e1y, e1z, e2x, e2y, e2z;
            ax = QUAD_PD(a, 0), ay = QUAD_PD(a, 1), az = QUAD_PD(a, 2);
            e1x = _mm256_sub_pd(QUAD_PD(b, 0), ax), e1y = _mm256_sub_pd(QUAD_PD(b, 1), ay);
            e1z = _mm256_sub_pd(QUAD_PD(b, 2), az), e2x = _mm256_sub_pd(QUAD_PD(c, 0), ax);
            e2y = _mm256_sub_pd(QUAD_PD(c, 1), ay), e2z = _mm256_sub_pd(QUAD_PD(c, 2), az);
            nx = _mm256_sub_pd(_mm256_mul_pd(e1y, e2z), _mm256_mul_pd(e1z, e2y));
            ny = _mm256_sub_pd(_mm256_mul_pd(e1z, e2x), _mm256_mul_pd(e1x, e2z));
            nz = _mm256_sub_pd(_mm256_mul_pd(e1x, e2y), _mm256_mul_pd(e1y, e2x));
        }
        dn = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(nx, dx), _mm256_mul_pd(ny, dy)), _mm256_mul_pd(nz, dz));
        w = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(nx, _mm256_sub_pd(ax, _mm256_set1_pd(world->td[0]))),
                                        _mm256_mul_pd(ny, _mm256_sub_pd(ay, _mm256_set1_pd(world->td[1])))),
                          _mm256_mul_pd(nz, _mm256_sub_pd(az, _mm256_set1_pd(world->td[2]))));
        {
            /* lanes the scalar function would not return w / dn for: dn
             * zero, or a quotient not finite (NaN or inf: not below inf) */
            const __m256d quot = _mm256_div_pd(w, dn);
            const __m256d mag = _mm256_andnot_pd(_mm256_set1_pd(-0.0), quot);
            const int odd = _mm256_movemask_pd(_mm256_or_pd(_mm256_cmp_pd(dn, _mm256_setzero_pd(), _CMP_EQ_OQ),
                                                            _mm256_cmp_pd(mag, _mm256_set1_pd(INFINITY), _CMP_NLT_UQ)));
            _mm256_storeu_pd(q, quot);
            for (i = 0; i < 4; ++i) td[at[i]] = (odd >> i) & 1 ? (double)hits[at[i]].t : q[i];
        }
    }
}
#undef QUAD_PD
#endif

/* hit_distance_pair for hits[a] and hits[b] */
static void pair_at(const rc_scene *scene, const rc__hit *hits, uint32_t a, uint32_t b, const rc__xformf *world,
                    const float *directions, const uint32_t *idx, double *td)
{
    hit_distance_pair(scene, &hits[a], &hits[b], world, directions + (size_t)idx[a] * 3u,
                      directions + (size_t)idx[b] * 3u, &td[a], &td[b]);
}

void rc__scene_hit_distances_d(const rc_scene *scene, const rc__hit *hits, const int *found, uint32_t n,
                               const rc__xformf *world, const float *directions, const uint32_t *idx, double *td)
{
    /* own-mesh hits wait in own[] for a group of lanes: four where the CPU
     * has AVX2, else two; the last ones go in pairs and alone (every path
     * gives the scalar function's values) */
    uint32_t own[4], k = 0, group = 2u, i;
#if defined(RC__LEAF4_PAIR_AVX2)
    if (rc__leaf4_have_avx2()) group = 4u;
#endif
    for (i = 0; i < n; ++i) {
        if (!found[i]) {
            td[i] = 0.0;
        } else if (hits[i].inst != RC_INVALID_ID) {
            td[i] = rc__scene_hit_distance_d(scene, &hits[i], world, directions + (size_t)idx[i] * 3u, NULL);
        } else {
            own[k++] = i;
            if (k < group) continue;
#if defined(RC__LEAF4_PAIR_AVX2)
            if (group == 4u)
                hit_distance_quad(scene, hits, own, world, directions, idx, td);
            else
#endif
                pair_at(scene, hits, own[0], own[1], world, directions, idx, td);
            k = 0;
        }
    }
    for (i = 0; i + 1u < k; i += 2u) pair_at(scene, hits, own[i], own[i + 1u], world, directions, idx, td);
    if (k & 1u)
        td[own[k - 1u]] =
            rc__scene_hit_distance_d(scene, &hits[own[k - 1u]], world, directions + (size_t)idx[own[k - 1u]] * 3u, NULL);
}
#endif
